"""``gripkit identify dynamics URDF DATA --position COLS [--velocity COLS] --effort COLS [--fs HZ]
[--out MODEL.json] [--report DIR] [--json]``: identify the base inertial parameters and per-joint
friction of a URDF chain from a log (:func:`gripkit.sysid.identify_dynamics`).

COLS are comma-separated column names, one per actuated joint in the chain's order (``gripkit``
prints the order in the error when the count is wrong). The signal chain is IDIM-LS's
(:func:`gripkit.sysid.rigid_body.friction.idim_samples`, the one ``identify friction`` uses for the
EMPS and
DLR/HIT logs): the same zero-phase Butterworth filter on positions (or measured velocities) and
efforts, central differences, the filter's edges cut, decimation; the rows of a joint within the
guard band of its velocity reversals or slower than 2 % of its peak speed are left out
(:func:`gripkit.sysid.rigid_body.dynamics_data.dynamics_data`, the library does it); σ is the
Newey-West (HAC) one, since filtering and decimation leave the residuals correlated.

``--out`` writes the model file (:mod:`gripkit.sysid.rigid_body.dynamics_file`: the URDF text, the
parameters with their covariance, the log's name and SHA-256), ``--report`` an HTML page
(:mod:`gripkit.sysid.rigid_body.dynamics_report`); both paths are checked before the work starts.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import typer

from .app import identify_app
from .common import (FillOpt, FsOpt, JsonOpt, TimeOpt, check_effort_scale, emit_json, load_data,
                     report_warnings, table_console)
from .identify_common import ModelOutOpt, ReportOpt, check_outputs, echo_written


def _columns(option: str, text: str | None, joints) -> list[str] | None:
    from ..errors import ConfigError

    if text is None:
        return None
    cols = [c.strip() for c in text.split(",") if c.strip()]
    if len(cols) != len(joints):
        raise ConfigError(f"{option}: {len(cols)} column(s) {cols} for the {len(joints)} "
                          "actuated joints "
                          f"{', '.join(joints)}", hint="give one column per joint, "
                                                       "comma-separated, in that order")
    return cols


def _vector(option: str, text: str) -> np.ndarray:
    from ..errors import ConfigError

    try:
        v = np.array([float(x) for x in text.split(",")])
    except ValueError:
        v = np.zeros(0)
    if v.shape != (3,) or not np.isfinite(v).all():
        raise ConfigError(f"{option}: expected three comma-separated numbers, found {text!r}")
    return v


def _write_model_and_report(res, dd, lines, *, urdf: Path, data: Path, provenance: dict,
                            base_link, tip_link, out: Path | None, report: Path | None) -> None:
    """``--out``: the model file with the URDF text and the log's name and SHA-256 (recorded by
    gripkit.io.load); ``--report``: the HTML page of the identification on ``dd``
    (:class:`~gripkit.sysid.rigid_body.dynamics_data.DynamicsData`)."""
    if out is not None:
        out.parent.mkdir(parents=True, exist_ok=True)
        res.replace(urdf_text=Path(urdf).read_text(), base_link=base_link, tip_link=tip_link,
                    **provenance).save(out)
    if report is not None:
        from ..sysid.rigid_body.dynamics_report import write_dynamics_report

        write_dynamics_report(res, dd.t, dd.q, dd.qd, dd.qdd, dd.effort, report,
                              weights=dd.weights, data_name=Path(data).name,
                              warnings_list=list(dd.samples.notes) + lines)


def _print_tables(res, chain, data: Path, notes) -> None:
    """The base parameters and the friction as tables on stdout; the consistency and the notes
    on stderr."""
    from rich.table import Table

    con = table_console()
    t = Table("base parameter (combination of standard parameters)", "value", "std",
              title=f"{chain.name} from {data.name}: {res.n_samples} samples, {res.n_base} "
                    "base parameters "
                    f"(of {len(res.structure.standard_names)}), relative error "
                    f"{res.relative_error_percent:.2f} %")
    for name, v in res.base_parameters.items():
        t.add_row(name, f"{v:.6g}", f"{res.base_parameters_std[name]:.2g}")
    con.print(t)
    if res.friction:
        kinds = [k for k in next(iter(res.friction.values())) if not k.endswith("_std")]
        ft = Table("joint", *kinds, "residual std", title="friction (N·m, N·m·s/rad; N, N·s/m for "
                                                          "prismatic joints)")
        for j, f in res.friction.items():
            ft.add_row(j, *(f"{f[k]:.4g} ± {f[k + '_std']:.2g}" for k in kinds),
                       f"{res.residual_std[j]:.3g}")
        con.print(ft)
    if res.consistency is not None and res.consistency.consistent:
        typer.echo(res.consistency.message(), err=True)
    for n in notes:
        typer.echo(f"note: {n}", err=True)


@identify_app.command("dynamics")
def identify_dynamics_cmd(
    urdf: Path = typer.Argument(..., help="URDF file of the chain."),
    data: Path = typer.Argument(..., help="CSV/Parquet/HDF5 log with joint positions and efforts."),
    position: str = typer.Option(..., "--position", help="Position columns, one per actuated joint "
                                                         "(comma-separated)."),
    effort: str = typer.Option(..., "--effort", help="Effort columns (N·m or N), one per "
                                                     "actuated joint."),
    velocity: str = typer.Option(None, "--velocity", help="Measured velocity columns (default: "
                                                          "differentiate the positions)."),
    fs: float = FsOpt,
    json_out: bool = JsonOpt,
    friction: str = typer.Option("coulomb-viscous", "--friction",
                                 help="coulomb-viscous, coulomb-viscous-offset or none."),
    armature: bool = typer.Option(False, "--armature", help="Also identify a rotor "
                                                            "inertia per joint."),
    constrained: bool = typer.Option(False, "--constrained", help="Report the nearest physically "
                                                                  "consistent estimate."),
    base_link: str = typer.Option(None, "--base-link", help="Base link of the chain (default: "
                                                            "the URDF's root)."),
    tip_link: str = typer.Option(None, "--tip-link", help="Tip link of the chain "
                                                          "(default: its end)."),
    gravity: str = typer.Option("0,0,-9.81", "--gravity", help="Gravity in the base link frame, "
                                                               "m/s² (gx,gy,gz)."),
    effort_scale: float = typer.Option(1.0, "--effort-scale", help="K: effort = K × column (e.g. "
                                                                   "k_t·N for a current)."),
    cutoff: float = typer.Option(None, "--cutoff", help="Low-pass cutoff in Hz (default fs/50; "
                                                        "5-10x the motion bandwidth)."),
    decimate: int = typer.Option(None, "--decimate", help="Keep every q-th filtered sample "
                                                          "(default from the cutoff)."),
    time: str = TimeOpt,
    fill: str = FillOpt,
    out: Path = ModelOutOpt,
    report: Path = ReportOpt,
):
    """Identify the base inertial parameters and the friction of every joint of a URDF chain."""
    from ..multibody import from_urdf
    from ..sysid.io_data import records_provenance
    from ..sysid.rigid_body.dynamics import identify_dynamics
    from ..sysid.rigid_body.dynamics_data import dynamics_data

    check_outputs(out, report, [urdf, data])
    check_effort_scale(effort_scale)
    chain = (from_urdf(urdf, base_link=base_link, tip_link=tip_link,
                       gravity=_vector("--gravity", gravity)))
    joints = chain.joint_names
    pcols = _columns("--position", position, joints)
    ecols = _columns("--effort", effort, joints)
    vcols = _columns("--velocity", velocity, joints)
    tr = load_data(data, list(dict.fromkeys(pcols + ecols + (vcols or []))), fs, time, fill)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        dd = dynamics_data(tr, joints, pcols, ecols, vcols, effort_scale=effort_scale,
                           cutoff=cutoff, decimate=decimate)
        res = identify_dynamics(chain, dd.q, dd.qd, dd.qdd, dd.effort, friction=friction,
                                weights=dd.weights, armature=armature, covariance="hac",
                                constrained=constrained)
    lines = report_warnings(caught)
    st = dd.samples
    notes = list(st.notes) + list(res.warnings)
    _write_model_and_report(res, dd, lines, urdf=urdf, data=data,
                            provenance=records_provenance(tr), base_link=base_link,
                            tip_link=tip_link, out=out, report=report)
    summary = dict(urdf=str(urdf), data=str(data), chain=chain.name,
                   columns=dict(position=pcols, effort=ecols, velocity=vcols), fs=1.0 / st.dt,
                   cutoff_hz=st.cutoff, decimation=st.decimation, **res.to_dict())
    summary["notes"] = notes
    summary["warnings"] = lines
    if json_out:
        emit_json(summary)
        return
    _print_tables(res, chain, data, notes)
    echo_written(out, report)
