"""``gripkit zoo discretize NAME --fs HZ [--form canonical|physical] [--json]``: the zero-order-hold
discrete state space of a linear zoo model (FT-G100: the controllable canonical form of eqs 10, 17
and the block form of eq 18)."""

from __future__ import annotations

import math

import numpy as np
import typer

from .app import zoo_app
from .common import JsonOpt, complex_pairs, emit_json


@zoo_app.command("discretize")
def zoo_discretize(name: str = typer.Argument(..., help="Zoo model name (gripkit zoo list)."),
                   fs: float = typer.Option(..., "--fs", help="Sampling rate in Hz (the "
                                                              "seed uses 20000)."),
                   form: str = typer.Option("canonical", "--form",
                                            help="'canonical' (the seed's controllable "
                                                 "form) or 'physical' "
                                                 "(exact ZOH of the physical states)."),
                   json_out: bool = JsonOpt):
    """Discretise a linear zoo model with a zero-order hold; prints A, B, C, D, poles and DC
    gain."""
    from ..errors import ModelError
    from .zoo import _build

    if not (math.isfinite(fs) and fs > 0):
        raise ModelError(f"--fs: expected a positive sampling rate in Hz, found {fs!r}")
    model = _build(name)
    if not hasattr(model, "discrete"):
        from .. import zoo

        ok = ([e.name for e in zoo.entries() if e.name.startswith("ftg100")
               and hasattr(_build(e.name), "discrete")])
        raise ModelError(f"zoo model {name!r} has no linear continuous-time form to discretise",
                         hint=f"discretize works on: {', '.join(ok)}")
    sys = model.discrete(dt=1.0 / fs, form=form)
    dc = sys.dc_gain()
    dc_out = float(dc[0, 0]) if dc.shape == (1, 1) else dc[:, 0].tolist()
    out = {"name": name, "fs": float(fs), "dt": float(sys.dt), "form": sys.meta.get("form", form),
           "A": sys.A.tolist(), "B": sys.B.tolist(), "C": sys.C.tolist(), "D": sys.D.tolist(),
           "poles": complex_pairs(sys.poles()), "dc_gain": dc_out,
           "inputs": list(sys.inputs), "outputs": list(sys.outputs),
           "input_units": list(sys.input_units), "output_units": list(sys.output_units),
           "dc_gain_units": [f"{o}/{i}" for o in sys.output_units for i in sys.input_units[:1]]}
    if "scale" in sys.meta:
        out["scale"] = float(sys.meta["scale"])
    if json_out:
        emit_json(out)
        return
    np.set_printoptions(precision=6, suppress=False)
    typer.echo(f"{name}: zero-order hold at {fs:g} Hz ({out['form']}); inputs {out['inputs']} "
               f"[{', '.join(out['input_units'])}], outputs {out['outputs']} "
               f"[{', '.join(out['output_units'])}]")
    for k in ("A", "B", "C", "D"):
        typer.echo(f"{k} =\n{np.array(out[k])}")
    typer.echo("poles = " + ", ".join(f"{re:.6f}{im:+.6f}j" for re, im in out["poles"]))
    typer.echo(f"DC gain = {out['dc_gain']} ({', '.join(out['dc_gain_units'])})")
