"""``gripkit report MODEL.json DATA --out DIR``: one self-contained HTML page of a saved model on a
record, ``model.report(data, out)`` (:class:`gripkit.sysid.model_protocol.ReportMixin`): a linear
model's poles and Bode, every other family's page through the model protocol."""

from __future__ import annotations

import warnings
from pathlib import Path

import typer

from .app import app
from .common import FillOpt, FsOpt, JsonOpt, TimeOpt, emit_json, report_warnings


@app.command("report")
def report_model(model: Path = typer.Argument(..., help="Model file written by "
                                                        "identify --out (.json).",
                                              show_default=False),
                 data: Path = typer.Argument(..., help="Data file with the model's input and "
                                                       "output columns.",
                                             show_default=False),
                 out: Path = typer.Option(..., "--out", help="Folder for index.html."),
                 fs: float = FsOpt, time: str = TimeOpt, fill: str = FillOpt,
                 json_out: bool = JsonOpt):
    """HTML report: measured vs simulated per output, residual correlations, parameters with σ;
    for linear models also poles and Bode with σ."""
    from .compare import _model_and_data
    from .paths import report_folder

    report_folder(out, "--out", [model, data])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        m, tr = _model_and_data(model, data, fs, time, fill, outputs=True)
        index = m.report(tr, out, data_name=Path(data).name)
        fit = m.compare(tr) if json_out else None
    res = {"model": str(model), "data": str(data), "report": str(index)}
    if fit is not None:
        res.update(structure=m.structure, outputs=list(m.outputs),
                   fit_percent=list(fit.fit_percent), definition=fit.definition)
    res["warnings"] = report_warnings(caught)
    if json_out:
        emit_json(res)
        return
    typer.echo(f"report written to {index}")
