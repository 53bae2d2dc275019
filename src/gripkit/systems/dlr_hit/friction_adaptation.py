"""Online friction adaptation on the DLR/HIT II finger (``002_ddea254371185ad3.txt`` abstract and
§6.3: "an algorithm to adjust the friction model", since friction "differs from finger to finger
and the parameters may change over time").

Provenance: the recursive estimator is gripkit's addition, not the thesis's content. What the
thesis does to adjust its friction model is a correcting factor on the lookup tables per drive
(§6.3, §7: base 2 uses base 1's table times a factor); it gives no online algorithm.

Two uses of the generic estimator (:mod:`gripkit.estimation.friction_adaptation`):

* after the fact, on a log (:func:`adapt_finger_friction`): the finger's motor torques (eq 5.10),
  multibody bias torques and drive inertias fed to a :class:`FrictionAdapter`;
* inside the closed loop (:func:`compare_adaptation`, and ``ImpedanceController(adaptation=...)``
  in :mod:`gripkit.systems.dlr_hit.impedance`): the estimate is updated at every control step and
  the impedance controller's friction compensation uses it. :func:`compare_adaptation` runs the
  loop with and without adaptation, with and without a friction drift of the plant
  (:mod:`gripkit.systems.dlr_hit.friction_drift`), and reports the tracking errors.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ...errors import ModelError
from ...estimation.friction_adaptation import AdaptationSettings, FrictionAdapter
from .finger import ACTUATORS, JOINTS
from .friction_drift import FrictionDrift, stiction_step, warmup_drift
from .impedance import (LOOP_ADAPTATION, POTENTIOMETERS, ImpedanceController, Sensing,
                        ThermalObserver, model_friction_tables, simulate_impedance)

__all__ = ["adapt_finger_friction", "compare_adaptation", "LoopComparison", "tracking_reference",
           "thermal_adaptation_study", "ThermalStudy", "THERMAL_CASES", "THERMAL_MODES",
           "V_COMPARE"]


def adapt_finger_friction(finger, trajectory, *, forgetting: float = 0.999, filter_hz: float = 10.0,
                          v_min: float = 0.05, tables=None, adapter: FrictionAdapter | None = None,
                          nonfinite: str = "raise"):
    """Run a :class:`FrictionAdapter` on a DLR/HIT finger log (a Trajectory with the finger's
    PWM inputs and joint angle/velocity outputs, as :meth:`DLRFinger.simulate` returns or a real
    log with the same channel names). The motor torque comes from eq 5.10 at the logged speed, the
    bias torque from the multibody model, the inertia from the diagonal of M_p at the log's
    median configuration. ``nonfinite`` as :meth:`FrictionAdapter.update`. Returns
    ``(adapter, result)``."""
    dt = trajectory.require_uniform(why="friction adaptation")
    ch = finger.chain()
    G = ch.coupling.matrix[:3]
    q = np.column_stack([trajectory[j] for j in JOINTS])
    qd = np.column_stack([trajectory[f"{j}_vel"] for j in JOINTS])
    p = np.linalg.solve(G, q.T).T
    pd = np.linalg.solve(G, qd.T).T
    pwm = np.column_stack([trajectory[f"pwm_{a}"] for a in ACTUATORS])
    tau = (np.column_stack([finger.motor_torque(a, pwm[:, k],
                                                pd[:, k]) for k, a in enumerate(ACTUATORS)]))
    h = ch.bias(p, pd)
    if adapter is None:
        J = np.diag(ch.mass_matrix(np.median(p, axis=0)))
        tabs = tables if tables is not None else tuple(
            t.scaled(finger.parameters.value(f"scale_{a}")) for t, a in zip(finger.tables,
                                                                            ACTUATORS))
        adapter = FrictionAdapter(tabs, J, dt, forgetting=forgetting, filter_hz=filter_hz,
                                  v_min=v_min, names=ACTUATORS)
    return adapter, adapter.update(tau, h, pd, nonfinite=nonfinite)


def tracking_reference(duration: float, dt: float = 1e-3) -> np.ndarray:
    """(N, 3) joint reference (rad) that keeps all three drives sliding both ways: abduction
    10° at 0.4 Hz, flexion 40 ± 30° at 0.5 Hz, proximal 45 ± 35° at 0.7 Hz (inside the joint
    ranges, speeds up to ≈ 150 °/s as in Figs 7.3–7.5)."""
    if not (math.isfinite(duration) and duration > 0 and math.isfinite(dt) and 0 < dt < duration):
        raise ModelError("duration and dt: expected 0 < dt < duration (s), found "
                         f"{duration!r}, {dt!r}")
    t = np.arange(int(round(duration / dt))) * dt
    deg = math.pi / 180
    return np.column_stack([10 * deg * np.sin(2 * np.pi * 0.4 * t),
                            (40 + 30 * np.sin(2 * np.pi * 0.5 * t)) * deg,
                            (45 + 35 * np.sin(2 * np.pi * 0.7 * t + 1)) * deg])


def _errors(tr, skip: int):
    e = np.column_stack([tr[j] - tr[f"ref_{j}"] for j in JOINTS])[skip:]
    return float(np.sqrt(np.mean(e ** 2))), float(np.abs(e).max())


@dataclass(frozen=True)
class LoopComparison:
    """Joint tracking errors of the impedance loop with a fixed and with an adapted friction
    compensation, on the nominal plant and on the drifting one.

    ``runs[(mode, plant)]``: the closed-loop Trajectory, mode ∈ {'fixed', 'adaptive'}, plant ∈
    {'nominal', 'drift'}; ``rms`` and ``max`` (rad) under the same keys: RMS over samples and the
    three joints, and the largest absolute joint error, both after ``t_skip`` s."""

    runs: dict
    rms: dict
    max: dict
    t_skip: float
    drift: FrictionDrift

    @property
    def rms_ratio(self) -> float:
        """RMS error with a fixed compensation over that with adaptation, on the drifting plant
        (> 1: adaptation helps)."""
        return self.rms["fixed", "drift"] / self.rms["adaptive", "drift"]

    @property
    def max_ratio(self) -> float:
        """As :attr:`rms_ratio` for the largest error."""
        return self.max["fixed", "drift"] / self.max["adaptive", "drift"]

    @property
    def recovered(self) -> float:
        """Fraction of the error the drift adds (fixed compensation, RMS) that adaptation removes:
        (e_fixed − e_adaptive)/(e_fixed − e_nominal), nominal = fixed compensation without drift."""
        added = self.rms["fixed", "drift"] - self.rms["fixed", "nominal"]
        return ((self.rms["fixed", "drift"] - self.rms["adaptive",
                                                       "drift"]) / added if added > 0 else math.nan)


def compare_adaptation(finger, controller: ImpedanceController, reference, drift: FrictionDrift, *,
                       settings: AdaptationSettings = LOOP_ADAPTATION, dt: float = 1e-3,
                       t_skip: float = 5.0) -> LoopComparison:
    """Run the joint impedance loop on ``reference`` (N, 3 joint angles, rad) four times: the
    controller's friction compensation fixed or adapted online (``settings``), on the nominal
    plant and on the plant whose friction follows ``drift``; errors after ``t_skip`` s (the
    initial transient)."""
    if controller.kind != "joint":
        raise ModelError("compare_adaptation: expected a joint impedance controller (errors "
                         "are joint errors)")
    if not isinstance(drift, FrictionDrift):
        raise ModelError(f"drift: expected a FrictionDrift, found {type(drift).__name__}")
    skip = int(round(t_skip / dt))
    if not 0 <= skip < np.shape(reference)[0] - 1:
        raise ModelError(f"t_skip: expected 0 <= t_skip < the reference's duration, "
                         f"found {t_skip!r} s")
    modes = {"fixed": replace(controller, adaptation=None),
             "adaptive": replace(controller, adaptation=settings)}
    runs, rms, mx = {}, {}, {}
    for mode, c in modes.items():
        for plant, d in (("nominal", None), ("drift", drift)):
            tr = simulate_impedance(finger, c, reference, dt=dt, friction_drift=d)
            runs[mode, plant] = tr
            rms[mode, plant], mx[mode, plant] = _errors(tr, skip)
    return LoopComparison(runs, rms, mx, t_skip, drift)


#: the cases of :func:`thermal_adaptation_study`: the winding starts at room temperature (T_amb)
#: or at the operating temperature (T_ref), the plant's friction fixed or drifting
THERMAL_CASES = ("cold", "hot", "cold+drift")
#: actuator speed (rad/s) at which :class:`ThermalStudy` compares estimated and true friction
V_COMPARE = 1.0
#: its compensations: the fixed tables; the estimator on eq 5.10 as printed (it reads a torque
#: change as a friction change); the estimator with the thermal observer's torque factor and guard
THERMAL_MODES = ("fixed", "adaptive-eq5.10", "adaptive-thermal")


@dataclass(frozen=True)
class ThermalStudy:
    """Tracking errors of the impedance loop on a finger whose motors heat and cool (thermal
    model on): ``rms[(case, mode)]`` (rad, after ``t_skip``), ``scale[(case, mode)]`` (3,) the
    estimated friction scale ŝ per actuator averaged over the last 10 s (1 for 'fixed'),
    ``friction[(case, mode)]`` (3,) the estimated over the plant's kinetic friction at
    :data:`V_COMPARE` (ŝ·F_table(v) + ô)/(s·F_table(v) + Δ), both averaged over the last 10 s
    (ŝ and ô are nearly collinear where the table is flat, so ŝ alone can be off while the
    friction is right), ``updated[(case, mode)]`` the fraction of samples the estimator updated
    (all actuators), and ``runs`` the closed-loop Trajectories."""

    rms: dict
    scale: dict
    friction: dict
    updated: dict
    runs: dict
    t_skip: float


def thermal_adaptation_study(finger, controller: ImpedanceController, reference, *,
                             settings=LOOP_ADAPTATION, observer: ThermalObserver | None = None,
                             sensing: Sensing | None = POTENTIOMETERS, dt: float = 1e-3,
                             t_skip: float = 5.0) -> ThermalStudy:
    """Friction adaptation against a motor-torque change.

    Fig. 5.7 (§5.4.3) shows the motor torque at PWM 4000 falling from 1.0 to 0.57 N·cm as the
    winding warms from room temperature to about 80 °C; the finger has no torque or current
    sensor (§3.1), so the estimator, fed eq 5.10 as printed (valid at T_ref), sees the motor's
    torque change as a friction change: cold, the motor delivers ρ > 1 times eq 5.10 and the
    estimate falls to ≈ 1/ρ. :class:`~gripkit.systems.dlr_hit.impedance.ThermalObserver` removes
    that confound: its torque factor ρ̂, from the PWM history through the thermal model, enters
    the estimator's regressor, and its guard freezes the estimator while the band of possible
    start temperatures leaves ρ uncertain by more than ``guard``.

    ``finger`` must integrate its motor temperatures (``thermal=True``). Runs the loop on
    ``reference`` for each of :data:`THERMAL_CASES` (cold: winding at T_amb, hot: at T_ref,
    cold+drift: T_amb with the warm-up friction drift of
    :func:`~gripkit.systems.dlr_hit.friction_drift.warmup_drift` and a stiction step halfway)
    and each of :data:`THERMAL_MODES`; the controller measures through ``sensing`` (default the
    0.1° potentiometers, velocity differentiated; None: the exact state). ``observer`` defaults
    to ``ThermalObserver()`` (start temperature unknown between T_amb and T_ref)."""
    if not getattr(finger, "thermal", False):
        raise ModelError("thermal_adaptation_study: the finger's motor temperatures are not "
                         "integrated",
                         hint="build it with finger(thermal=True)")
    if controller.kind != "joint":
        raise ModelError("thermal_adaptation_study: expected a joint impedance controller "
                         "(errors are joint errors)")
    observer = observer if observer is not None else ThermalObserver()
    ref = np.asarray(reference, dtype=np.float64)
    skip = int(round(t_skip / dt))
    if ref.ndim != 2 or not 0 <= skip < ref.shape[0] - 1:
        raise ModelError(f"t_skip: expected 0 <= t_skip < the reference's duration, "
                         f"found {t_skip!r} s")
    duration = ref.shape[0] * dt
    base = replace(controller, sensing=sensing, adaptation=None, thermal=None)
    modes = {"fixed": base, "adaptive-eq5.10": replace(base, adaptation=settings),
             "adaptive-thermal": replace(base, adaptation=settings, thermal=observer)}
    v = finger.parameters.value
    cases = {"cold": (v("T_amb"), None), "hot": (v("T_ref"), None),
             "cold+drift": (v("T_amb"),
                            warmup_drift(duration).combine(stiction_step(duration / 2)))}
    last = max(ref.shape[0] - int(round(10.0 / dt)), 0)
    f_tab = np.array([float(t(V_COMPARE)) for t in model_friction_tables(finger)])
    rms, scale, fric, upd, runs = {}, {}, {}, {}, {}
    for case, (T0, drift) in cases.items():
        x0 = finger.state(q=ref[0], T=T0)
        for mode, c in modes.items():
            tr = simulate_impedance(finger, c, ref, dt=dt, x0=x0, friction_drift=drift)
            runs[case, mode] = tr
            rms[case, mode] = _errors(tr, skip)[0]
            scale[case, mode] = np.array([float(np.mean(tr[f"scale_hat_{a}"][last:]))
                                          for a in ACTUATORS])
            fric[case, mode] = np.array([_friction_ratio(tr, a, f_tab[k], last)
                                         for k, a in enumerate(ACTUATORS)])
            upd[case, mode] = float(np.mean([tr[f"adapt_status_{a}"] == 1.0 for a in ACTUATORS]))
    return ThermalStudy(rms, scale, fric, upd, runs, t_skip)


def _friction_ratio(tr, a, f_table, last) -> float:
    """Estimated over true kinetic friction of actuator ``a`` at a speed where the compensation
    table reads ``f_table`` (N·m), each averaged over the samples from ``last`` on."""
    est = np.mean(tr[f"scale_hat_{a}"][last:] * f_table + tr[f"offset_hat_{a}"][last:])
    if f"drift_scale_{a}" in tr:
        true = np.mean(tr[f"drift_scale_{a}"][last:] * f_table + tr[f"drift_offset_{a}"][last:])
    else:
        true = f_table
    return float(est / true)
