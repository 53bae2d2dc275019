"""``gripkit identify narx DATA --input U --output Y [--degree D] [--lags L | --ylags LY --ulags LU]
[--terms N|auto] [--refine none|simulation] [--forgetting λ] [--basis polynomial|rational
[--den-degree DD]] [--validate DATA2] [--out MODEL.json] [--json]``:
polynomial or rational NARX by forward regression with the error reduction ratio
(:func:`gripkit.sysid.narx`)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Optional

import typer

from .common import collected_warnings, emit_json, report_warnings
from .identify_common import KeywordOrNumber, RecordOptions, record_command, validation


TERMS = KeywordOrNumber("--terms", "auto", "auto", int, 1, math.inf,
                        "'auto' or a positive integer", "Number of terms, or auto (BIC; with "
                        "--validate the free-run validation fit).", "--terms auto chooses the "
                        "number by BIC (or by --validate's fit)")


def _summary(m) -> str:
    head = ("NARX" if m.basis != "rational" else
            f"rational NARX y = N/D (D = 1 + …, degree {m.den_degree}), numerator")
    lines = [f"{head} degree {m.degree}, ylags {m.ylags}, ulags {m.ulags}: {len(m.terms)} terms "
             f"({m.criterion})"]
    lines += [f"  {name:<28s} {th: .6g} ± {sd:.3g}"
              for name, th, sd in zip(m.terms, m.theta, m.theta_std)]
    fmt = lambda v: "diverged" if v is None else f"{v:.2f} %"  # noqa: E731
    lines.append(f"free-run fit (estimation): {fmt(m.fit_percent)}; one-step prediction fit: "
                 f"{fmt(m.prediction_fit_percent)}")
    if m.validation_fit_percent is not None or m.criterion.startswith("validation"):
        lines.append(f"free-run fit (validation): {fmt(m.validation_fit_percent)}")
    return "\n".join(lines)


def _rational_structure(m) -> dict:
    """The JSON ``structure`` entries of a rational model (none for a polynomial one)."""
    if m.basis != "rational":
        return {}
    return {"basis": "rational", "den_degree": m.den_degree,
            "numerator_terms": m.numerator_terms, "denominator_terms": m.denominator_terms}


def _parameters(m) -> list:
    """The JSON ``parameters``: term, value, σ (and for a rational model its name and part)."""
    out = [{"term": t, "value": float(v), "std": float(s)}
           for t, v, s in zip(m.terms, m.theta, m.theta_std)]
    if m.basis == "rational":
        for p, name in zip(out, m.parameters.names):
            p.update(name=name, part="numerator" if name.startswith("num") else "denominator")
    return out


@record_command("narx")
def identify_narx(data: Path = typer.Argument(..., help="CSV, Parquet or HDF5 file, the record."),
                  input_col: str = typer.Option(..., "--input", help="Input column."),
                  output_col: str = typer.Option(..., "--output", help="Output column."),
                  degree: int = typer.Option(2, "--degree", help="Highest degree of a term."),
                  lags: int = typer.Option(2, "--lags", help="Output and input lags."),
                  ylags: Optional[int] = typer.Option(None, "--ylags", help="Output lags."),
                  ulags: Optional[int] = typer.Option(None, "--ulags", help="Input lags."),
                  terms: str = TERMS.option(),
                  refine: str = typer.Option("none", "--refine",
                                             help="none (one-step least squares) or simulation "
                                                  "(θ refined on the free-run error)."),
                  forgetting: float = typer.Option(1.0, "--forgetting",
                                                   help="λ in (0, 1]: below 1, θ by exponentially "
                                                        "weighted least squares (memory about "
                                                        "1/(1 − λ) rows) for a drifting system."),
                  basis: str = typer.Option("polynomial", "--basis",
                                            help="polynomial (y = Σ θ·terms) or rational "
                                                 "(y = N/D, D = 1 + Σ d·terms)."),
                  den_degree: Optional[int] = typer.Option(None, "--den-degree",
                                                           help="Degree of the rational "
                                                                "denominator (default --degree)."),
                  *, opts: RecordOptions):
    """Polynomial NARX: terms by error reduction ratio (FROLS), θ with σ, pruning, free-run fit;
    --basis rational: y = N/D (D = 1 + …), FROLS on y·D = N, θ refined on the one-step error;
    --report: the model's page on the --validate record (else on the record)."""
    n_terms = TERMS.parse(terms)
    if refine not in ("none", "simulation"):
        from ..errors import DataError

        raise DataError(f"--refine: expected 'none' or 'simulation', found {refine!r}",
                        hint="--refine simulation fits θ to the free run (output-error noise)")
    if basis not in ("polynomial", "rational"):
        from ..errors import DataError

        raise DataError(f"--basis: expected 'polynomial' or 'rational', found {basis!r}",
                        hint="--basis rational fits y = N/D")
    if den_degree is not None and basis != "rational":
        from ..errors import DataError

        raise DataError(f"--den-degree {den_degree} is the degree of a rational model's "
                        f"denominator, but --basis is {basis!r}",
                        hint="add --basis rational or leave --den-degree out")
    extra = {} if basis == "polynomial" else {"basis": basis, "den_degree": den_degree}
    with collected_warnings() as caught:
        m, tr, vtr = opts.identify([data], "narx", input_col, output_col, degree=degree,
                                   lags=lags, ylags=ylags, ulags=ulags, terms=n_terms,
                                   refine=None if refine == "none" else refine,
                                   forgetting=forgetting, progress=True, **extra)
        val = validation(m, vtr, opts.validate)
        page = opts.save(m, tr, vtr, [data])
    lines = report_warnings(caught)
    if opts.json_out:
        emit_json({"data": str(data), "input": input_col, "output": output_col,
                   "input_unit": m.input_unit, "output_unit": m.output_unit,
                   "structure": {"degree": m.degree, "ylags": m.ylags, "ulags": m.ulags,
                                 "terms": m.terms, "criterion": m.criterion,
                                 "refine": refine, "forgetting": forgetting,
                                 **_rational_structure(m)},
                   "parameters": _parameters(m),
                   "fit_percent": m.fit_percent, "prediction_fit_percent": m.prediction_fit_percent,
                   "validation": None if val is None else val.to_dict(),
                   "model": None if opts.out is None else str(opts.out), "report": page,
                   "warnings": lines})
    else:
        typer.echo(_summary(m))
