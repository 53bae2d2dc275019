"""``gripkit identify step DATA --input COL --output COL [--fs HZ] [--json]``: second-order
step-response identification (gain, natural frequency, damping ratio, each with its σ)."""

from __future__ import annotations

from pathlib import Path

import typer

from .app import identify_app
from .common import (FillOpt, FsOpt, JsonOpt, TimeOpt, check_data_options, collected_warnings,
                     emit_json, load_data, report_warnings)


@identify_app.command("step")
def identify_step(data: Path = typer.Argument(..., help="CSV, Parquet or HDF5 file with "
                                                        "the step record."),
                  input_col: str = typer.Option(..., "--input", help="Input column (the "
                                                                     "commanded step)."),
                  output_col: str = typer.Option(..., "--output",
                                                 help="Output column (the response)."),
                  fs: float = FsOpt, time: str = TimeOpt, fill: str = FillOpt,
                  method: str = typer.Option("lm", "--method",
                                             help="Least squares: lm (Levenberg-Marquardt) or "
                                                  "trf (trust-region "
                                                  "reflective, keeps the parameters "
                                                  "within their bounds)."),
                  json_out: bool = JsonOpt):
    """Fit K ω_n²/(s² + 2ζω_n s + ω_n²) to a step response (gain, natural frequency, damping, σ)."""
    from ..errors import DataError
    from ..sysid.physical.step_response import STEP_METHODS
    from ..sysid.physical.step_response import identify_step as _identify

    if method not in STEP_METHODS:  # before the data are read
        raise DataError(f"--method: expected one of {', '.join(STEP_METHODS)}, found {method!r}",
                        hint="lm (Levenberg-Marquardt) or trf (bounded trust-region reflective)")
    check_data_options(fs, fill)
    with collected_warnings() as caught:
        tr = load_data(data, [input_col, output_col], fs, time, fill)
        res = _identify(tr, input=input_col, output=output_col, method=method)
    lines = report_warnings(caught)
    if json_out:
        emit_json({"data": str(data), "input": input_col, "output": output_col, "method": method,
                   **res.to_dict(), "warnings": lines})
    else:
        typer.echo(res.summary())
