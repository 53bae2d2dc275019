"""``gripkit identify hw DATA --input U --output Y [--input-nonlinearity KIND[:N]]
[--output-nonlinearity KIND[:N]] [--linear oe|ss] [--nb NB --nf NF | --order N] [--nk NK]
[--periods P] [--validate DATA2] [--out MODEL.json] [--json]``: Hammerstein, Wiener and
Hammerstein–Wiener models around an output-error (B/F) or a state-space linear block, through
``gripkit.sysid.identify(data, "hw", ...)`` (:func:`gripkit.sysid.hammerstein_wiener`)."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from .common import collected_warnings, emit_json, report_warnings
from .identify_common import RecordOptions, data_field, record_command, records_field
from .identify_linear import DataArgs, _echo_records


def _summary(m) -> str:
    fmt = lambda v: "diverged" if v is None else f"{v:.2f} %"  # noqa: E731
    block = (f"state-space order {m.order}, nk = {m.nk}" if m.linear == "ss" else
             f"[nb nf nk] = [{m.nb} {m.nf} {m.nk}]")
    lines = [f"{m.kind} model: input {m.input_nl.label}, output {m.output_nl.label}, "
             f"{block} ({m.criterion})"]
    lines += [f"  {n:<10s} {v: .6g} ± {s:.3g}" for n, v, s in zip(m.names, m.theta, m.theta_std)]
    lines.append(f"free-run fit (estimation): {fmt(m.fit_percent)}")
    if m.validation_fit_percent is not None or "validation" in m.criterion:
        lines.append(f"free-run fit (validation): {fmt(m.validation_fit_percent)}")
    return "\n".join(lines)


@record_command("hw")
def identify_hw(data: list[Path] = DataArgs,
                input_col: str = typer.Option(..., "--input", help="Input column."),
                output_col: str = typer.Option(..., "--output", help="Output column."),
                input_nl: Optional[str] = typer.Option(
                    None, "--input-nonlinearity",
                    help="pwl, deadzone, saturation, poly, sigmoid or none, with :N for pwl, "
                         "poly, sigmoid (default: chosen with the output one)."),
                output_nl: Optional[str] = typer.Option(
                    None, "--output-nonlinearity", help="As --input-nonlinearity, after B/F."),
                nb: Optional[int] = typer.Option(None, "--nb", help="B coefficients (searched)."),
                nf: Optional[int] = typer.Option(None, "--nf", help="F coefficients (searched)."),
                nk: Optional[int] = typer.Option(None, "--nk", help="Input delay (searched); "
                                                 "with --linear ss 0 gives a feedthrough."),
                linear: str = typer.Option(
                    "oe", "--linear", help="Linear block: oe (B/F) or ss (state space in "
                                           "observer canonical form, from the subspace estimate)."),
                order: Optional[int] = typer.Option(
                    None, "--order", help="State dimension of --linear ss (searched: 1, 2, 3)."),
                periods: Optional[int] = typer.Option(
                    None, "--periods", help="The record is P (≥ 3) whole periods of a periodic "
                                            "input: the linear block starts from the fit of its "
                                            "FRF (best linear approximation, the first period "
                                            "dropped)."),
                *, opts: RecordOptions):
    """Hammerstein / Wiener / Hammerstein–Wiener: static nonlinearities around B/F or a state-space
    block, PEM, σ.
    Several DATA files: one model of all the records, each from its own steady state
    (``records``: each file's fit and w₋)."""
    from ..sysid.nonlinear.hammerstein_wiener import (check_periods, linear_orders,
                                                      parse_nonlinearity)

    for spec, name in ((input_nl, "--input-nonlinearity"), (output_nl, "--output-nonlinearity")):
        if spec is not None:
            parse_nonlinearity(spec, name)
    linear_orders(linear, order, nb, nf, nk, flag="--")
    if periods is not None:
        check_periods(periods, len(data), flag="--")
    with collected_warnings() as caught:
        # several files: one model of every file's record, each from its own steady state
        m, tr, tv = opts.identify(data, "hw", input_col, output_col, detrend="none", nb=nb,
                                  nf=nf, nk=nk, linear=linear, order=order, periods=periods,
                                  input_nonlinearity=input_nl, output_nonlinearity=output_nl,
                                  progress=True)
        page = opts.save(m, tr, tv, data)
    lines = report_warnings(caught)
    if opts.json_out:
        emit_json({"data": data_field(data),
                   "input": input_col, "output": output_col,
                   "input_unit": m.input_unit, "output_unit": m.output_unit,
                   "structure": {"kind": m.kind, "input_nonlinearity": m.input_nl.label,
                                 "output_nonlinearity": m.output_nl.label, "linear": m.linear,
                                 "order": m.order, "nb": m.nb, "nf": m.nf, "nk": m.nk,
                                 "criterion": m.criterion,
                                 "gain_normalisation": "unit slope of every nonlinearity in its "
                                                       "linear part; the gain is in "
                                                       + ("b (and d)" if m.linear == "ss"
                                                          else "B")},
                   "parameters": [{"name": n, "value": float(v), "std": float(s)}
                                  for n, v, s in zip(m.names, m.theta, m.theta_std)],
                   "poles": [[float(z.real), float(z.imag)] for z in m.poles],
                   "fit_percent": m.fit_percent, "fit_definition": m.fit_definition,
                   "validation": None if opts.validate is None else
                   {"data": str(opts.validate), "fit_percent": m.validation_fit_percent,
                    "definition": m.fit_definition},
                   "candidates": m.candidates,
                   **({"records": records_field(data, m.records)} if len(data) > 1 else {}),
                   "model": None if opts.out is None else str(opts.out), "report": page,
                   "warnings": lines})
    else:
        typer.echo(_summary(m))
        if len(data) > 1:
            _echo_records(records_field(data, m.records), free_run=True)
