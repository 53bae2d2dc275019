"""``gripkit identify nlss DATA --input U[,U2…] --output Y[,Y2…] [--order N] [--degree D]
[--validate DATA2] [--out MODEL.json] [--report DIR] [--json]``: polynomial nonlinear
state-space model, through ``gripkit.sysid.identify(data, "nlss", ...)``
(:func:`gripkit.sysid.nlss`)."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from .common import collected_warnings, emit_json, report_warnings
from .identify_common import RecordOptions, data_field, record_command, records_field
from .identify_linear import DataArgs, _echo_records


def _names(value: str, option: str) -> list[str]:
    from ..errors import DataError

    cols = [c.strip() for c in value.split(",")]
    if not all(cols):
        raise DataError(f"{option}: an empty column name in {value!r}; give NAME or NAME1,NAME2")
    return cols


def _fmt(fits) -> str:
    if fits is None:
        return "–"
    return ", ".join("diverged" if f is None else f"{f:.2f} %" for f in fits)


def _summary(m) -> str:
    free = m.parameters
    n_free = sum(not p.fixed for p in free.values())
    lines = [f"NLSS order {m.order}, degree {m.degree}: {n_free} free parameters "
             f"({m.criterion})",
             f"state monomials ζ: {', '.join(m.zeta_terms) or 'none'}",
             f"output monomials η: {', '.join(m.eta_terms) or 'none'}",
             "output-equation parameters (σ in the model's state basis):"]
    for p in free.values():
        if p.name[0] in "CDF" and not p.fixed:
            lines.append(f"  {p.name:<10s} {p.value: .6g} ± {p.std:.3g}   {p.doc}")
    lines.append(f"free-run fit (estimation): {_fmt(m.fit_percent)} (linear start "
                 f"{_fmt(m.linear_fit_percent)})")
    if m.validation_fit_percent is not None:
        lines.append(f"free-run fit (validation): {_fmt(m.validation_fit_percent)} (linear start "
                     f"{_fmt(m.linear_validation_fit_percent)})")
    return "\n".join(lines)


@record_command("nlss")
def identify_nlss(data: list[Path] = DataArgs,
                  input_cols: str = typer.Option(..., "--input", help="Input column(s), U or "
                                                 "U1,U2."),
                  output_cols: str = typer.Option(..., "--output", help="Output column(s), Y or "
                                                  "Y1,Y2."),
                  order: Optional[int] = typer.Option(None, "--order",
                                                      help="States (default: the largest gap of "
                                                           "the subspace singular values, or "
                                                           "the validation fit)."),
                  degree: int = typer.Option(3, "--degree", help="Highest monomial degree (≥ 2)."),
                  max_order: int = typer.Option(4, "--max-order", help="Largest order tried."),
                  window: Optional[int] = typer.Option(None, "--window",
                                                       help="Samples per truncated simulation "
                                                            "window (default 10 time constants)."),
                  *, opts: RecordOptions):
    """Polynomial nonlinear state space (PNLSS) from the subspace start, simulation error, σ.
    Several DATA files: one model of all the records, each with its own initial state
    (``records``: each file's fit)."""
    ins, outs = _names(input_cols, "--input"), _names(output_cols, "--output")
    with collected_warnings() as caught:
        # several files: one model of every file's record, each with its own initial state
        m, tr, vtr = opts.identify(data, "nlss", ins, outs, detrend="none", order=order,
                                   degree=degree, max_order=max_order, window=window)
        page = opts.save(m, tr, vtr, data)
    lines = report_warnings(caught)
    if opts.json_out:
        params = [{"name": p.name, "value": p.value, "std": p.std, "unit": p.unit,
                   "fixed": p.fixed, "meaning": p.doc} for p in m.parameters.values()]
        emit_json({"data": data_field(data),
                   "inputs": ins, "outputs": outs, "input_units": list(m.input_units),
                   "output_units": list(m.output_units),
                   "structure": {"model": "nlss", "order": m.order, "degree": m.degree,
                                 "zeta_terms": m.zeta_terms, "eta_terms": m.eta_terms,
                                 "criterion": m.criterion},
                   "parameters": params, "fit_percent": m.fit_percent,
                   "linear_fit_percent": m.linear_fit_percent,
                   "fit_definition": m.fit_definition,
                   "validation": None if opts.validate is None else
                   {"data": str(opts.validate), "fit_percent": m.validation_fit_percent,
                    "linear_fit_percent": m.linear_validation_fit_percent},
                   "info": {k: v for k, v in m.info.items()
                            if k not in ("linear_start", "records")},
                   **({"records": records_field(data, m.info["records"])}
                      if len(data) > 1 else {}),
                   "model": None if opts.out is None else str(opts.out), "report": page,
                   "warnings": lines})
    else:
        typer.echo(_summary(m))
        if len(data) > 1:
            _echo_records(records_field(data, m.info["records"]), free_run=True)
