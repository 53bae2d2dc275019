"""``gripkit simulate MODEL.toml [--out FILE.parquet] [--json]``: simulate a model described in
TOML (:mod:`gripkit.description`) and write the trajectory (CSV, Parquet or HDF5 by suffix).
``gripkit simulate MODEL.json --data DATA [--out FILE]`` simulates an identified model file on the
input columns of DATA (:func:`gripkit.cli.compare.simulate_model_file`)."""

from __future__ import annotations

from pathlib import Path

import typer

from .app import app
from .common import FillOpt, FsOpt, JsonOpt, TimeOpt, emit_json, report_warnings


@app.command()
def simulate(model: Path = typer.Argument(..., help="Model description (.toml) or "
                                                    "identified model (.json).",
                                          show_default=False),
             out: Path = typer.Option(None, "--out", help="Write the trajectory here "
                                                          "(.parquet, .csv, .h5); "
                                                          "default: [output] file of "
                                                          "the description."),
             data: Path = typer.Option(None, "--data", help="Input data for a .json model "
                                                            "(columns by name)."),
             fs: float = FsOpt, time: str = TimeOpt, fill: str = FillOpt,
             json_out: bool = JsonOpt):
    """Simulate a model described in a TOML file, or an identified model file on DATA's inputs."""
    import warnings

    if model.suffix.lower() == ".json":
        from .compare import simulate_model_file
        from .paths import output_file

        output_file(out, "--out", [model, data])
        return simulate_model_file(model, data, out, fs, time, fill, json_out)

    import numpy as np

    from ..io import save
    from ..progress import status
    from ..description import load_description
    from .paths import output_file

    output_file(out, "--out", [model])  # before loading the description (it builds the model)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        d = load_description(model)
        inputs = [model, *_input_files(d, model)]  # the description's input files, known now
        output_file(out, "--out", inputs)  # again: --out must not be one of those files
        if out is None:
            output_file(d.output, f"[output] file of {model.name}", inputs)
        status(f"simulating {d.model.name}: {d.inputs.n} samples at {1.0 / d.inputs.dt:g} Hz")
        tr = d.model.simulate(d.inputs)
    lines = report_warnings(caught)
    target = out or d.output
    if target is not None:
        save(tr, target)
    summary = {n: {"unit": tr.unit(n), "min": float(np.min(tr[n])), "max": float(np.max(tr[n])),
                   "final": float(tr[n][-1])} for n in tr.names}
    res = {"model": d.model.name, "description": str(model), "samples": tr.n, "fs": 1.0 / tr.dt,
           "duration_s": tr.duration, "out": None if target is None else str(target),
           "channels": summary,
           "warnings": lines}
    if json_out:
        emit_json(res)
        return
    typer.echo(f"{d.model.name}: {tr.n} samples at "
               f"{1.0 / tr.dt:g} Hz" + (f", written to {target}" if target else ""))
    for n, s in summary.items():
        typer.echo(f"  {n} [{s['unit']}]: min {s['min']:.6g}, max {s['max']:.6g}, final "
                   f"{s['final']:.6g}")


def _input_files(description, path: Path) -> list[Path]:
    """The files the inputs of kind 'file' of the description ``path`` read (relative to its
    folder)."""
    files = []
    for spec in (description.raw.get("inputs") or {}).values():
        if isinstance(spec, dict) and spec.get("kind") == "file" and isinstance(spec.get("path"),
                                                                                 str):
            files.append(path.parent / spec["path"])
    return files
