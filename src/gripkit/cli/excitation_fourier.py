"""``gripkit excitation fourier URDF --out TRAJ.csv [--f0 HZ] [--harmonics H] [--fs HZ]
[--periods P] [--velocity-limit V] [--acceleration-limit A] [--restarts R] [--seed S]
[--time-limit SECONDS] [--json]``: design a periodic
Fourier-series excitation of every actuated joint of a URDF chain that minimises the condition
number of the identification regressor within the position (URDF), velocity and acceleration
limits (:func:`gripkit.sysid.fourier_trajectory`), and write it (columns ``t``,
``q_<joint>``, ``qd_<joint>``, ``qdd_<joint>``; SI units) in the format ``--out``'s suffix names:
``.csv`` (a plain header of names), ``.parquet`` or ``.h5`` (:func:`gripkit.io.save`, with units);
another suffix is refused before the design starts. Every format is written atomically. A design
estimated to take longer than the time limit is refused before it starts; one above 10 s shows
its progress."""

from __future__ import annotations

from pathlib import Path

import typer

from .app import app
from .common import JsonOpt, emit_json

excitation_app = typer.Typer(no_args_is_help=True, pretty_exceptions_enable=False,
                             help="Design excitation trajectories.")
app.add_typer(excitation_app, name="excitation")


@excitation_app.command("fourier")
def excitation_fourier(
    urdf: Path = typer.Argument(..., help="URDF file of the chain."),
    out: Path = typer.Option(..., "--out", help="File for the trajectory (.csv, .parquet or .h5)."),
    f0: float = typer.Option(0.1, "--f0", help="Base frequency in Hz (the period is 1/f0)."),
    harmonics: int = typer.Option(5, "--harmonics", help="Number of harmonics per joint."),
    fs: float = typer.Option(100.0, "--fs", help="Sampling rate of the written trajectory, Hz."),
    periods: int = typer.Option(1, "--periods", help="Number of periods written."),
    velocity_limit: float = typer.Option(None, "--velocity-limit",
                                         help="|q̇| limit for every joint "
                                              "(default: URDF, else 2)."),
    acceleration_limit: float = typer.Option(None, "--acceleration-limit",
                                             help="|q̈| limit for every joint (default 10)."),
    base_link: str = typer.Option(None, "--base-link", help="Base link of the chain."),
    tip_link: str = typer.Option(None, "--tip-link", help="Tip link of the chain."),
    restarts: int = typer.Option(0, "--restarts", min=0,
                                 help="Extra random starting points of the optimisation."),
    seed: int = typer.Option(0, "--seed", min=0,
                             help="Seed of the starting points (0, 1, 2, ...)."),
    time_limit: float = typer.Option(None, "--time-limit",
                                     help="Seconds the design may take, estimated before it starts "
                                          "(default 1800); a longer design is refused."),
    json_out: bool = JsonOpt,
):
    """Design an optimal Fourier excitation trajectory for a URDF chain and write it as CSV."""
    from ..sysid import fourier_trajectory
    from ..multibody import from_urdf
    from ..progress import status
    from .paths import output_file

    output_file(out, "--out", [urdf])
    chain = from_urdf(urdf, base_link=base_link, tip_link=tip_link)
    status(f"optimising {2 * chain.dof * harmonics} Fourier coefficients of {chain.name} ...")
    tr = fourier_trajectory(chain, f0=f0, harmonics=harmonics, dt=1.0 / fs, periods=periods,
                            velocity_limits=velocity_limit, acceleration_limits=acceleration_limit,
                            restarts=restarts, seed=seed, time_limit=time_limit)
    if out.suffix.lower() == ".csv":
        tr.to_csv(out)
    else:
        _save_with_units(tr, chain, out)
    d = tr.to_dict()
    d["out"] = str(out)
    if json_out:
        emit_json(d)
        return
    typer.echo(f"wrote {out}: {tr.t.size} samples at {fs:g} Hz of joints "
               f"{', '.join(tr.joint_names)}; "
               f"regressor condition number {tr.condition_number:.3g} (start "
               f"{tr.initial_condition_number:.3g})")


def _save_with_units(tr, chain, out: Path) -> None:
    """``tr`` through :func:`gripkit.io.save` (Parquet or HDF5), each column with its SI unit: a
    coordinate that moves revolute joints only is in rad, prismatic only in m, else unitless."""
    import numpy as np

    from ..io import save
    from ..signals import Trajectory

    units = {}
    for j, name in enumerate(tr.joint_names):
        kinds = {chain.joint_types[i] for i in np.flatnonzero(chain.coupling[:, j])}
        base = {"R": "rad", "P": "m"}.get(kinds.pop()) if len(kinds) == 1 else None
        for prefix, per in (("q", ""), ("qd", "/s"), ("qdd", "/s**2")):
            units[f"{prefix}_{name}"] = base + per if base else "1"
    cols = tr.columns()
    t = cols.pop("t")
    save(Trajectory(t, cols, units), out)
