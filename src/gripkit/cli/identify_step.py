"""``gripkit identify step DATA --input COL --output COL [--fs HZ] [--method lm|trf]
[--out MODEL.json] [--report DIR] [--validate DATA2] [--json]``: second-order step-response
identification (gain, natural frequency, damping ratio, each with its σ), a thin shell over
``gripkit.sysid.identify(data, "step", …)``: the model (a continuous transfer function with the
record's offsets) saves, and ``gripkit compare``, ``simulate``, ``report`` and ``export c`` take
its file.

JSON fields: ``data``, ``input``, ``output``, ``method``, the step fit's own fields
(``StepResponseResult.to_dict``: ``gain``, ``natural_frequency_hz``, ``damping_ratio``,
``offset`` with their ``_std``, ``fit_percent`` of the free run from rest, the step metrics, the
covariance), ``model_fit_percent`` (the model's validation fit on DATA, as ``gripkit compare``
gives it), ``out``, ``validation`` (with ``--validate``) and ``warnings``."""

from __future__ import annotations

from pathlib import Path

import typer

from .app import identify_app
from .common import (FillOpt, FsOpt, JsonOpt, TimeOpt, check_data_options, collected_warnings,
                     emit_json, report_warnings)
from .identify_common import (ModelOutOpt, ReportOpt, ValidateOpt, check_outputs, echo_written,
                              run_identify, save_and_report, validation)


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
                  out: Path = ModelOutOpt, report: Path = ReportOpt,
                  validate: Path = ValidateOpt,
                  json_out: bool = JsonOpt):
    """Fit K ω_n²/(s² + 2ζω_n s + ω_n²) to a step response (gain, natural frequency, damping, σ)."""
    from ..errors import DataError
    from ..sysid.physical.step_response import STEP_METHODS, step_summary

    if method not in STEP_METHODS:  # before the data are read
        raise DataError(f"--method: expected one of {', '.join(STEP_METHODS)}, found {method!r}",
                        hint="lm (Levenberg-Marquardt) or trf (bounded trust-region reflective)")
    check_data_options(fs, fill)
    check_outputs(out, report, [data, validate])
    with collected_warnings() as caught:
        model, tr, vtr = run_identify([data], "step", input_col, output_col, fs=fs, time=time,
                                      fill=fill, validate=validate, solver=method)
        save_and_report(model, tr, [data], out, report)
        val = validation(model, vtr, validate)
    lines = report_warnings(caught)
    step = model.info["step"]
    if json_out:
        res = {"data": str(data), "input": input_col, "output": output_col, "method": method,
               **step, "model_fit_percent": model.fit_percent,
               "out": None if out is None else str(out), "warnings": lines}
        if val is not None:
            res["validation"] = val.to_dict()
        emit_json(res)
        return
    typer.echo(step_summary(step))
    if val is not None:
        fit = "—" if val.fit_percent is None else ", ".join(f"{v:.2f}" for v in val.fit_percent)
        typer.echo(f"validation free-run fit: {fit} % ({val.definition})")
    echo_written(out, report)
