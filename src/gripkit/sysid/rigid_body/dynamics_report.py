"""One self-contained HTML report of an identified rigid-body dynamics model on its log
(``gripkit identify dynamics URDF DATA --report DIR``, :func:`gripkit.sysid.identify_dynamics`).

Sections: measured against predicted effort per joint, τ̂ = X(q, q̇, q̈) θ̂ on the filtered,
decimated samples the fit used; the residuals τ − τ̂ per joint with their RMS over the rows the
fit kept (weight > 0: away from velocity reversals and standstill); the base parameters with σ
and units; the friction per joint with σ; the condition number of the weighted regressor; the
physical-consistency verdict; the warnings raised on the way.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...report.html import Report
from ...report.plots import measured_vs_model, plain, pyplot

__all__ = ["dynamics_report", "parameter_unit", "write_dynamics_report"]

_UNITS = {"m": "kg", "mx": "kg·m", "my": "kg·m", "mz": "kg·m"}


def parameter_unit(name: str) -> str:
    """SI unit of a (base) parameter from the name of its leading standard parameter
    (``m_link2`` kg, ``mx_link2`` kg·m, ``Izz_link2 + …`` kg·m², ``armature_j`` kg·m² or kg)."""
    lead = name.split(" ", 1)[0]
    if lead.startswith("armature_"):
        return "kg·m² (kg: prismatic)"
    return _UNITS.get(lead.split("_", 1)[0], "kg·m²")


def _residual_figure(t, r, joints, rms):
    plt = pyplot()
    fig, axes = (plt.subplots(len(joints), 1, figsize=(10, 2.2 * len(joints)), squeeze=False,
                              sharex=True))
    for j, name in enumerate(joints):
        ax = axes[j, 0]
        ax.plot(t, r[:, j], lw=0.8)
        ax.axhline(0.0, color="k", lw=0.6)
        ax.set_ylabel(plain(name), fontsize=8)
        ax.set_title(plain(f"{name}: residual RMS {rms[j]:.3g}"), fontsize=8)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("time [s]")
    fig.tight_layout()
    return fig


def dynamics_report(result, t, q, qd, qdd, tau, *, weights=None, data_name: str = "data",
                    warnings_list=()) -> Report:
    """Build the :class:`~gripkit.report.html.Report` of ``result`` on the samples it was fitted to
    (``t`` (N,) s; ``q``, ``qd``, ``qdd``, ``tau`` (N, m); ``weights`` (N, m), > 0 for the rows
    used)."""
    joints = list(result.chain.coordinate_names)
    t = np.asarray(t, dtype=np.float64)
    t = t - t[0]
    tau = np.atleast_2d(np.asarray(tau, dtype=np.float64))
    pred = result.predict(q, qd, qdd)
    r = tau - pred
    used = np.ones_like(r, dtype=bool) if weights is None else np.asarray(weights) > 0
    rms = np.array([np.sqrt(np.mean(r[used[:, j], j] ** 2)) if used[:, j].any() else np.nan
                    for j in range(len(joints))])
    rep = Report(f"gripkit dynamics report: {result.chain.name}",
                 f"data {data_name}: {result.n_samples} samples, {result.n_base} base parameters "
                 f"(of {len(result.structure.standard_names)} standard), friction "
                 f"{result.friction_model}")
    sec = rep.section("Measured and predicted efforts",
                      "Effort of each joint (N·m, N for prismatic joints) measured and predicted "
                      "by the identified "
                      "model, τ̂ = X(q, q̇, q̈) θ̂, on the filtered, decimated samples of the fit.")
    for j, name in enumerate(joints):
        sec.figure(measured_vs_model(t, tau[:, j], {"model": pred[:, j]}, ylabel=f"{name} effort",
                                     title=f"{name}: residual "
                                           f"RMS {rms[j]:.3g}"), name, name=f"effort-{j}")
    sec = rep.section("Residuals", "τ − τ̂ per joint; the RMS is over the rows the fit kept "
                                   "(away from velocity "
                      "reversals and standstill), the residual std over those rows "
                      "weighted as in the fit.")
    sec.table(["joint", "residual RMS", "residual std"],
              [[name, f"{rms[j]:.4g}", f"{result.residual_std[name]:.4g}"]
               for j, name in enumerate(joints)])
    sec.figure(_residual_figure(t, r, joints, rms), "residuals", name="residuals")
    std = result.base_parameters_std
    rep.section("Base parameters", "Each base parameter is the combination of standard "
                                   "parameters it is named "
                "after (SI units of its leading term).").table(
        ["base parameter", "value", "σ", "unit"],
        [[n, f"{v:.6g}", f"{std[n]:.3g}", parameter_unit(n)]
         for n, v in result.base_parameters.items()])
    sec = rep.section("Friction")
    if result.friction:
        kinds = [k for k in next(iter(result.friction.values())) if not k.endswith("_std")]
        sec.table(["joint", *kinds], [[j, *(f"{f[k]:.4g} ± {f[k + '_std']:.2g}" for k in kinds)]
                                      for j, f in result.friction.items()],
                  caption="value ± σ: Coulomb and offset N·m, viscous N·m·s/rad (N, N·s/m for "
                          "prismatic joints)")
    else:
        sec.text("not identified (friction model none)")
    cons = result.consistency
    rep.section("Conditioning and physical consistency").table(["item", "value"], [
        ["condition number (weighted regressor)", f"{result.condition_number:.4g}"],
        ["relative error %", f"{result.relative_error_percent:.3g}"],
        ["physical consistency", "not checked" if cons is None else cons.message()],
        ["nearest consistent parameters: search", "not checked" if cons is None else cons.solver],
        ["constrained estimate", "yes" if result.constrained else "no"]])
    lines = list(dict.fromkeys(list(warnings_list) + list(result.warnings)))
    sec = rep.section("Warnings")
    if lines:
        sec.table(["warning"], [[ln] for ln in lines])
    else:
        sec.text("none")
    return rep


def write_dynamics_report(result, t, q, qd, qdd, tau, out_dir, *, weights=None,
                          data_name: str = "data",
                          warnings_list=()) -> Path:
    """Write ``out_dir/index.html`` (self-contained: figures inline); returns its path."""
    return dynamics_report(result, t, q, qd, qdd, tau, weights=weights, data_name=data_name,
                           warnings_list=warnings_list).write(Path(out_dir))
