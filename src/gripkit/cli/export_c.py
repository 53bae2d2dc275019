"""``gripkit export c MODEL.json --out DIR [--name NAME] [--float32] [--dt S] [--json]``: the
model's step as C99 code, ``NAME.h`` and ``NAME.c`` (:mod:`gripkit.export.c_code`,
docs/deploy.md)."""

from __future__ import annotations

import warnings
from pathlib import Path

import typer

from .app import app
from .common import JsonOpt, emit_json, report_warnings

export_app = typer.Typer(no_args_is_help=True, pretty_exceptions_enable=False,
                         help="Code for the target: a saved model as C (docs/deploy.md).")
app.add_typer(export_app, name="export")


@export_app.command("c")
def export_c(model: Path = typer.Argument(..., help="Model file written by identify --out (.json).",
                                          show_default=False),
             out: Path = typer.Option(..., "--out", help="Folder to write NAME.h and NAME.c into.",
                                      show_default=False),
             name: str = typer.Option(None, "--name",
                                      help="C identifier prefixing the generated names "
                                           "(default: the model file's stem)."),
             float32: bool = typer.Option(False, "--float32",
                                          help="Single-precision state, coefficients and "
                                               "arithmetic."),
             dt: float = typer.Option(None, "--dt",
                                      help="Sample time in s for a continuous (tfest) model."),
             json_out: bool = JsonOpt):
    """Write the model's step as C99 (NAME_init, NAME_step; SI in and out, offsets applied)."""
    from ..errors import ArgumentError
    from ..export.c_code import export_c as write, float32_error_bound
    from ..sysid import load_model

    if name is None:
        name = model.stem
        if not name.isidentifier() or not name.isascii():
            raise ArgumentError(f"--name: the model file's stem {name!r} is no C identifier",
                                hint="give one: --name gripper_model")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        m = load_model(model)
        paths = write(m, out, name, float32=float32, dt=dt)
        bound = float32_error_bound(m, dt) if float32 else None
    res = {"model": str(model), "files": [str(p) for p in paths], "name": name, "float32": float32,
           "inputs": list(m.inputs), "outputs": list(m.outputs),
           "units": {"inputs": list(m.system.input_units), "outputs": list(m.system.output_units)},
           "float32_error_bound": bound, "warnings": report_warnings(caught)}
    if json_out:
        emit_json(res)
        return
    typer.echo(f"{m.structure}: wrote {', '.join(map(str, paths))} (inputs and outputs in SI)")
