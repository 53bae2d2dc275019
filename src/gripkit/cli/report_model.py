"""``gripkit report MODEL.json DATA --out DIR``: one self-contained HTML page of a saved model on a
record (:mod:`gripkit.sysid.model_report`)."""

from __future__ import annotations

import warnings
from pathlib import Path

import typer

from .app import app
from .common import FillOpt, FsOpt, JsonOpt, TimeOpt, emit_json, report_warnings


@app.command("report")
def report_model(model: Path = typer.Argument(..., help="Model file written by identify --out (.json).",
                                              show_default=False),
                 data: Path = typer.Argument(..., help="Data file with the model's input and output columns.",
                                             show_default=False),
                 out: Path = typer.Option(..., "--out", help="Folder for index.html."),
                 fs: float = FsOpt, time: str = TimeOpt, fill: str = FillOpt, json_out: bool = JsonOpt):
    """HTML report: measured vs simulated per output, residual correlations, poles with σ, Bode with σ."""
    from ..errors import ModelError
    from ..sysid.model_protocol import file_schema
    from ..sysid.model_report import write_model_report
    from .compare import _model_and_data

    schema = file_schema(model)
    if schema not in (None, "gripkit.linear-model"):  # residual, pole and Bode pages are linear
        raise ModelError(f"report: {str(model)!r} is a {schema}; gripkit report draws linear "
                         "models",
                         hint="use gripkit compare MODEL DATA (fit) or gripkit simulate MODEL "
                              "--data DATA for it")

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        m, tr = _model_and_data(model, data, fs, time, fill, outputs=True)
        index = write_model_report(m, tr, out, data_name=Path(data).name)
    res = {"model": str(model), "data": str(data), "report": str(index), "warnings": report_warnings(caught)}
    if json_out:
        emit_json(res)
        return
    typer.echo(f"report written to {index}")
