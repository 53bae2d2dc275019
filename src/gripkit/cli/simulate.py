"""``gripkit simulate MODEL.toml [--out FILE.parquet] [--json]``: simulate a model described in
TOML (:mod:`gripkit.description`) and write the trajectory (CSV, Parquet or HDF5 by suffix)."""

from __future__ import annotations

from pathlib import Path

import typer

from .app import app
from .common import JsonOpt, emit_json, report_warnings


@app.command()
def simulate(model: Path = typer.Argument(..., help="Model description (.toml).", show_default=False),
             out: Path = typer.Option(None, "--out", help="Write the trajectory here (.parquet, .csv, .h5); "
                                                          "default: [output] file of the description."),
             json_out: bool = JsonOpt):
    """Simulate a model described in a TOML file."""
    import warnings

    import numpy as np

    from ..io import save
    from ..progress import status
    from ..description import load_description
    from .paths import output_file

    output_file(out, "--out")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        d = load_description(model)
        if out is None:
            output_file(d.output, f"[output] file of {model.name}")
        status(f"simulating {d.model.name}: {d.inputs.n} samples at {d.inputs.fs:g} Hz")
        tr = d.model.simulate(d.inputs)
    lines = report_warnings(caught)
    target = out or d.output
    if target is not None:
        save(tr, target)
    summary = {n: {"unit": tr.unit(n), "min": float(np.min(tr[n])), "max": float(np.max(tr[n])),
                   "final": float(tr[n][-1])} for n in tr.names}
    res = {"model": d.model.name, "description": str(model), "samples": tr.n, "fs": tr.fs,
           "duration_s": tr.duration, "out": None if target is None else str(target), "channels": summary,
           "warnings": lines}
    if json_out:
        emit_json(res)
        return
    typer.echo(f"{d.model.name}: {tr.n} samples at {tr.fs:g} Hz" + (f", written to {target}" if target else ""))
    for n, s in summary.items():
        typer.echo(f"  {n} [{s['unit']}]: min {s['min']:.6g}, max {s['max']:.6g}, final {s['final']:.6g}")
