"""``gripkit identify friction DATA --position COL --effort COL [--effort-scale K] [--fs HZ]
[--json]``: single-axis inverse-dynamics least squares (IDIM-LS) of joint friction and inertia.

Model: effort = K·column = J·q̈ + F_v·q̇ + F_c·sign(q̇) + τ₀, with q̇, q̈ from the zero-phase
Butterworth-filtered position, the effort filtered alike, decimated (see
:func:`gripkit.sysid.rigid_body.friction.idim_ls`). The JSON holds ``params`` and ``std``
(``inertia``,
``viscous``, ``coulomb``, ``offset``, in the SI units of the data) and
``relative_error_percent`` of the fitted effort.
"""

from __future__ import annotations

from pathlib import Path

import typer

from .app import identify_app
from .common import (FillOpt, FsOpt, JsonOpt, TimeOpt, check_data_options, check_effort_scale,
                     check_number, collected_warnings, emit_json, load_data, report_warnings,
                     table_console)


@identify_app.command("friction")
def identify_friction(
    data: Path = typer.Argument(..., help="CSV/Parquet/HDF5 log with position and effort columns."),
    position: str = typer.Option(..., "--position", help="Position column (rad or m after "
                                                         "unit conversion)."),
    effort: str = typer.Option(..., "--effort", help="Effort column (torque, force, "
                                                     "current, PWM ...)."),
    effort_scale: float = typer.Option(1.0, "--effort-scale", help="K: effort = K × column (e.g. "
                                                                   "k_t·N for a current)."),
    fs: float = FsOpt,
    json_out: bool = JsonOpt,
    cutoff: float = typer.Option(None, "--cutoff", help="Low-pass cutoff in Hz (default fs/50; "
                                                        "5-10x the motion bandwidth)."),
    decimate: int = typer.Option(None, "--decimate", help="Keep every q-th filtered sample "
                                                          "(default from the cutoff)."),
    velocity_threshold: float = typer.Option(None, "--velocity-threshold",
                                             help="Drop samples slower than this (default 2 % of "
                                                  "the peak speed)."),
    time: str = TimeOpt,
    fill: str = FillOpt,
):
    """Identify inertia, viscous and Coulomb friction and an offset of one axis (IDIM-LS)."""
    from ..sysid.checks import FORCE_OR_TORQUE, LENGTH_OR_ANGLE, check_dimension
    from ..sysid.rigid_body.friction import idim_ls

    check_data_options(fs, fill)
    check_effort_scale(effort_scale)
    check_number(cutoff, "--cutoff", above=0)
    check_number(decimate, "--decimate", minimum=1, integer=True)
    check_number(velocity_threshold, "--velocity-threshold", minimum=0)
    with collected_warnings() as caught:
        tr = load_data(data, [position, effort], fs, time, fill)
        check_dimension(position, tr.unit(position), LENGTH_OR_ANGLE, "position")
        if effort_scale == 1.0:  # with --effort-scale the column may be a current, a PWM count ...
            check_dimension(effort, tr.unit(effort), FORCE_OR_TORQUE, "effort")
        dt = tr.require_uniform(why="IDIM-LS (filtering and differentiation)")
        res = idim_ls(tr[position], tr[effort], dt=dt, effort_scale=effort_scale, cutoff=cutoff,
                      decimation=decimate, velocity_threshold=velocity_threshold,
                      position_unit=tr.unit(position) or "1", effort_unit=tr.unit(effort) or "1")
    units = res.units
    out = {"params": res.params, "std": res.std,
           "relative_error_percent": res.relative_error_percent,
           "units": units, "n_samples": res.n_samples, "fs": 1.0 / res.dt, "cutoff_hz": res.cutoff,
           "decimation": res.decimation, "condition_number": res.condition_number,
           "notes": res.notes, "warnings": report_warnings(caught)}
    if json_out:
        emit_json(out)
        return
    from rich.table import Table

    t = Table("parameter", "value", "std", "unit",
              title=f"IDIM-LS of {data.name}: {res.n_samples} samples, relative error "
                    f"{res.relative_error_percent:.2f} %")
    for k in ("inertia", "viscous", "coulomb", "offset"):
        t.add_row(k, f"{res.params[k]:.6g}", f"{res.std[k]:.2g}", units[k])
    table_console().print(t)
    for n in res.notes:
        typer.echo(f"note: {n}", err=True)
