"""``gripkit export c MODEL.json --out DIR [--name NAME] [--float32] [--dt S] [--json]``: the
model's step as C99 code, ``NAME.h`` and ``NAME.c`` (:mod:`gripkit.export.c_code`,
docs/deploy.md); ``--kind kalman [--noise NOISE.json]``: its steady-state Kalman filter
(:mod:`gripkit.export.c_kalman`); ``gripkit export c CONTROLLER.json --kind pid|rst|lqr`` and
``gripkit export c --rls --na NA --nb NB --nk NK`` write a controller's step and the RLS update
(:mod:`gripkit.export.c_controllers`, :mod:`gripkit.export.c_rls`)."""

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
def export_c(model: Path = typer.Argument(None, show_default=False,
                                          help="Model file written by identify --out (.json), "
                                               "or a controller file with --kind."),
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
             kind: str = typer.Option("model", "--kind",
                                      help="What to export: model (its step), kalman (its "
                                           "steady-state Kalman filter, NAME_kf_step), or pid, "
                                           "rst, lqr (MODEL is then a controller file, "
                                           "save_controller)."),
             noise: Path = typer.Option(None, "--noise",
                                        help="--kind kalman: JSON file with the noise "
                                             "covariances Q, R (and S); default: the model's own "
                                             "innovation gain K."),
             rls: bool = typer.Option(False, "--rls", help="The RLS update of an ARX model "
                                                           "(no MODEL; --na, --nb, --nk)."),
             na: int = typer.Option(None, "--na", help="RLS: output lags."),
             nb: int = typer.Option(None, "--nb", help="RLS: input coefficients."),
             nk: int = typer.Option(1, "--nk", help="RLS: input delay in samples."),
             lam: float = typer.Option(1.0, "--lam", help="RLS: forgetting factor λ in (0, 1]."),
             p0: float = typer.Option(1e4, "--p0", help="RLS: initial covariance P0 = p0·I."),
             windup: str = typer.Option("trace", "--windup",
                                        help="RLS: trace, directional or none."),
             json_out: bool = JsonOpt):
    """Write the model's step as C99 (NAME_init, NAME_step; SI in and out, offsets applied), with
    --kind kalman its steady-state Kalman filter (NAME_kf_init, NAME_kf_step), with --kind
    pid|rst|lqr a controller's step, with --rls the RLS update (docs/deploy.md)."""
    from ..errors import ArgumentError
    from .common import check_choice
    from .paths import output_folder

    check_choice(kind, "--kind", ("model", "kalman", "pid", "rst", "lqr"))
    output_folder(out, "--out", [model, noise])
    if rls or kind in ("pid", "rst", "lqr"):
        from .export_c_controllers import export_command

        if float32 or dt is not None:
            raise ArgumentError("--float32 and --dt apply to model files, not to --kind or --rls")
        res = export_command(model, out, name, kind=None if kind == "model" else kind, rls=rls,
                             na=na, nb=nb, nk=nk, lam=lam,
                             p0=p0, windup=windup)
        if json_out:
            emit_json(res)
        else:
            typer.echo(f"{res['what']}: wrote {', '.join(res['files'])}")
        return
    if model is None:
        raise ArgumentError("MODEL: give a model file (or --kind with a controller file, or --rls)")
    from ..export.c_code import export_c as write, float32_error_bound
    from ..sysid import load_model

    if kind != "kalman" and noise is not None:
        raise ArgumentError("--noise: only with --kind kalman")
    if kind == "kalman" and float32:
        raise ArgumentError("--float32: the Kalman filter is exported in double precision only",
                            hint="drop --float32")

    if name is None:
        name = model.stem
        if not name.isidentifier() or not name.isascii():
            raise ArgumentError(f"--name: the model file's stem {name!r} is no C identifier",
                                hint="give one: --name gripper_model")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        m = load_model(model)
        if kind == "kalman":
            paths = _write_kalman(m, out, name, noise, dt)
        else:
            paths = write(m, out, name, float32=float32, dt=dt)
        bound = float32_error_bound(m, dt) if float32 else None
    res = {"model": str(model), "kind": kind, "files": [str(p) for p in paths], "name": name,
           "float32": float32,
           "inputs": list(m.inputs), "outputs": list(m.outputs),
           "units": {"inputs": list(m.input_units), "outputs": list(m.output_units)},
           "float32_error_bound": bound, "warnings": report_warnings(caught)}
    if json_out:
        emit_json(res)
        return
    typer.echo(f"{m.structure}: wrote {', '.join(map(str, paths))} (inputs and outputs in SI)")


def _write_kalman(m, out, name, noise, dt):
    """``--kind kalman``: the filter's C files, with the gains of ``--noise`` or the model's K."""
    from ..export.c_kalman import export_kalman_c, load_noise

    Q = R = S = None
    if noise is not None and (m.dt or dt):  # a continuous model without --dt: export says so
        ss = m.to_ss(m.dt if dt is None else dt)
        Q, R, S = load_noise(noise, ss.n_states, ss.n_outputs)
    return export_kalman_c(m, out, name, Q, R, S, dt=dt)
