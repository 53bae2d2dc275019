"""Finger force control for the AMADEUS finger (``000_8f66dcc7ab06470c.txt`` §V-F/G, Table II).

The identified ``[2 2 2]`` model (valve current → fingertip force, 200 Hz, 9 Hz-filtered data)

    A(q) = 1 − 1.8732 q⁻¹ + 0.8996 q⁻²,     B(q) = q⁻² (0.1950 − 0.2276 q⁻¹)

has lightly damped poles (|z| = 0.948, 5.0 Hz, ζ ≈ 0.32), a two-sample delay and a zero at
z = 0.2276/0.1950 = 1.167 — outside the unit circle (non-minimum phase). §V-F warns that pole
placement that cancels zeros is "a risky endeavor" here. gripkit's design keeps B(q) — NMP zero and
delay — in the closed loop and never cancels it.

The loop is the generic RST design of :mod:`gripkit.control.rst` (integral action, B kept in
the loop, anti-windup against the valve-current limits, 600–1100 mA, §V-E; operated above 12 bar,
§II-D). The achievable speed is limited by the NMP zero: its continuous equivalent is a
right-half-plane zero at ln(1.167)·200 ≈ 31 rad/s, so the default ω_n = 15 rad/s (about half of it)
trades a 0.19 s rise time against a 7 % undershoot and keeps 60° of phase margin.

Grasping a compliant object
---------------------------
:func:`simulate_finger_grasp` closes the loop around the whole finger: the valve's static characteristic
(hysteresis, leakage floor, supply), the identified force dynamics as the *blocked* force of the
finger, an object at a gap with stiffness k_o in series with the finger's lateral stiffness k_f
(contact force = k_o/(k_f + k_o) · max(0, F_blocked − k_f·gap)), the six-bridge force sensor with
eq-19 noise and a Kalman filter, and the PVDF slip sensor on a stick-slip contact, with the slip
reflex raising the force demand. A guarded approach (a slow current ramp until contact), bumpless
transfer to force control, a rate-limited reference and a hard cap keep the force under the limit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...control.rst import RSTController
from ...errors import DataError, ModelError, SimulationError
from .force_sensor import ForceDynamics, ForceKalmanFilter
from .pvdf import StickSlipContact, pvdf_noise
from .slip import SlipReflex
from .strain_gauge_sensor import StrainGaugeSensor
from .valve import ProportionalValve

__all__ = [
    "GraspScenario",
    "FingerGraspResult",
    "simulate_finger_grasp",
]


# ------------------------------------------------------------------------------- grasp scenario
@dataclass
class GraspScenario:
    """A fingertip grasp of a compliant object (SI units; defaults: a fragile 2 kN/m object).

    The blocked force of the finger is F_b = F_b0 + G(q)(i_e − i_op) with G the identified force
    model and i_e the valve's effective current; F_b0 (``blocked_force_at_op``, default chosen so
    that F_b = 0 at ``i_max``, where all tubes are at the supply pressure and the finger is
    straight). ``k_finger`` is the finger's lateral stiffness (N/m, default 15.45 N / 20 mm, the
    peak force over the maximum deflection of Fig. 2(c)); the object sits ``gap`` m from the
    straight fingertip with stiffness ``k_object`` (``math.inf`` for a rigid plate).
    """

    duration: float = 4.0
    force_target: float = 2.0
    force_limit: float = 4.0
    limit_margin: float = 0.3
    ramp_rate: float = 8.0
    gap: float = 0.004
    k_object: float = 2000.0
    k_finger: float = 15.45 / 0.020
    i_op: float = 0.85
    i_min: float = 0.60
    i_max: float = 1.10
    approach_rate: float = 0.6
    contact_force: float = 0.3
    blocked_force_at_op: float | None = None
    load: tuple = ((0.0, 0.0), (0.9, 0.0), (1.3, 0.6), (2.2, 0.6), (2.6, 1.6), (4.0, 1.6))
    sensor_noise: bool = True
    slip: bool = True
    reflex_step: float = 0.5
    reflex_rate: float = 2.0
    slip_blanking: float = 0.25
    pvdf_rate: float = 2000.0
    seed: int = 0


@dataclass(frozen=True)
class FingerGraspResult:
    """Time series of :func:`simulate_finger_grasp` at the control rate (arrays of length N):
    ``t``, true contact force ``force``, its estimate ``force_est`` and ``force_std``, reference
    ``ref``, valve ``current`` (A), ``mode`` (0 approach, 1 force control), ``slipping`` (true
    slip fraction), ``slip_alarm`` (detector state), tangential ``load`` (N), object ``x_obj`` (m),
    plus the PVDF record ``pvdf`` at ``pvdf_rate``, the alarm times and the contact time."""

    t: np.ndarray
    force: np.ndarray
    force_est: np.ndarray
    force_std: np.ndarray
    ref: np.ndarray
    current: np.ndarray
    mode: np.ndarray
    slipping: np.ndarray
    slip_alarm: np.ndarray
    load: np.ndarray
    x_obj: np.ndarray
    pvdf: np.ndarray
    pvdf_rate: float
    alarms: list
    contact_time: float | None
    max_force: float


def simulate_finger_grasp(controller: RSTController, plant=None, scenario: GraspScenario | None = None, *,
                          valve=None, sensor=None, contact=None, detector=None, kalman_q: float = 400.0,
                          rng=None) -> FingerGraspResult:
    """Closed-loop grasp with a guarded approach, force control, force sensing and the slip reflex.

    ``controller`` is an :class:`RSTController` for ``plant`` (valve current deviation in A →
    blocked force in N); ``valve`` a :class:`~gripkit.systems.amadeus.valve.ProportionalValve` (static
    characteristic used), ``sensor`` a :class:`~gripkit.systems.amadeus.strain_gauge_sensor.StrainGaugeSensor`
    (``None`` and ``scenario.sensor_noise=False``: the controller sees the true force),
    ``contact`` a :class:`~gripkit.systems.amadeus.pvdf.StickSlipContact`, ``detector`` a calibrated
    :class:`~gripkit.systems.amadeus.slip.SlipDetector` (required when ``scenario.slip``).
    """
    sc = scenario or GraspScenario()
    p = controller.resolve_plant(plant)
    rng = np.random.default_rng(sc.seed if rng is None else rng)
    valve = valve or ProportionalValve(check=False)
    h = p.dt
    N = int(round(sc.duration / h))
    if N < 10:
        raise SimulationError(f"duration {sc.duration} s is shorter than 10 control samples")
    if p.relative_degree() < 1:
        raise ModelError("simulate_finger_grasp needs a plant with at least one sample of input delay (nk >= 1)")
    if sc.force_limit <= sc.force_target:
        raise DataError(f"force_limit {sc.force_limit} N must exceed force_target {sc.force_target} N")
    if sc.slip and (detector is None or detector.threshold is None):
        raise DataError("scenario.slip needs a calibrated SlipDetector (detector=...)")
    if sc.slip and contact is None:
        contact = StickSlipContact(check=False)
    cap = sc.force_limit - sc.limit_margin
    g_obj = 1.0 if math.isinf(sc.k_object) else sc.k_object / (sc.k_finger + sc.k_object)
    # plant in deviation variables around the operating current
    A, B = p.den_zinv(), p.num_zinv()
    na, nb = A.size, B.size
    u_hist = np.zeros(nb)
    y_hist = np.zeros(na)
    u_lo, u_hi = sc.i_min - sc.i_op, sc.i_max - sc.i_op
    G0 = float(p.dc_gain()[0, 0])
    # steady start at i_max (finger straight): pre-fill histories
    i_start = sc.i_max
    ie0 = float(valve.demand_current(np.array([i_start]))[0])
    u_hist[:] = ie0 - sc.i_op
    y_hist[:] = G0 * (ie0 - sc.i_op)
    play = i_start
    hw = valve.parameters.value("hysteresis")
    i_lo_v, p_min_v, kv = valve.parameters.value("i_lo"), valve.parameters.value("p_min"), valve.gain
    fb0 = -G0 * (ie0 - sc.i_op) if sc.blocked_force_at_op is None else sc.blocked_force_at_op
    # sensing
    kf = None
    if sc.sensor_noise:
        if sensor is None:
            sensor = StrainGaugeSensor()
        H_sensor = sensor.H
        kf = ForceKalmanFilter(sensor, ForceDynamics.random_walk([50.0, 50.0, kalman_q], h),
                               x0=np.zeros(3), P0=np.eye(3) * 0.01)
    reflex = SlipReflex(step=sc.reflex_step, rate=sc.reflex_rate, max_force=cap)
    stream = detector.stream() if sc.slip else None
    cstate = contact.new_state() if sc.slip else None
    n_sub = int(round(sc.pvdf_rate * h)) if sc.slip else 0
    ns_contact = contact.substeps(1.0 / sc.pvdf_rate, contact.theta()[None, :]) if sc.slip else 0
    lt, lv = np.array([x[0] for x in sc.load]), np.array([x[1] for x in sc.load])
    out = {k: np.zeros(N) for k in ("force", "force_est", "force_std", "ref", "current", "mode",
                                    "slipping", "slip_alarm", "load", "x_obj")}
    pv = np.zeros(N * n_sub)
    mode = 0
    i_cmd = i_start
    contact_t = None
    ref_now = 0.0
    alarms = []

    noise_pv = pvdf_noise(N * n_sub, sc.pvdf_rate, rng) if sc.slip else None
    for k in range(N):
        t = k * h
        # plant: blocked force from past effective currents
        acc = 0.0
        for i in range(1, nb):
            acc += B[i] * u_hist[i - 1]
        for i in range(1, na):
            acc -= A[i] * y_hist[i - 1]
        yb = acc
        Fb = fb0 + yb
        F = g_obj * max(0.0, Fb - sc.k_finger * sc.gap)
        load = float(np.interp(t, lt, lv))
        # slip contact over this control period
        Ft = 0.0
        if sc.slip:
            yc = contact.advance(cstate, np.full(n_sub, F), np.full(n_sub, load), h / n_sub, ns_contact)
            seg = yc[:, 0] + noise_pv[k * n_sub:(k + 1) * n_sub]
            pv[k * n_sub:(k + 1) * n_sub] = seg
            Ft = float(yc[-1, 5])
            out["slipping"][k] = yc[:, 2].mean()
            out["x_obj"][k] = yc[-1, 4]
            slipping_now, new_alarms = stream.update(seg)
            out["slip_alarm"][k] = slipping_now
            armed = mode == 1 and t - contact_t >= sc.slip_blanking
            for a in new_alarms:
                alarms.append(a)
                if armed:
                    reflex.on_slip()
            if armed and slipping_now and not new_alarms:
                reflex.while_slipping(h)
        # force measurement
        if kf is not None:
            Rt = H_sensor @ np.array([0.0, Ft, F])
            reading = Rt + rng.standard_normal(6) * np.sqrt(sensor.noise_variance(Rt))
            f_est, cov = kf.step(reading)
            Fm, Fs = float(f_est[2]), math.sqrt(max(cov[2, 2], 0.0))
        else:
            Fm, Fs = F, 0.0
        # supervisor: guarded approach, then force control
        if mode == 0:
            if Fm > sc.contact_force:
                mode = 1
                contact_t = t
                ref_now = Fm
                controller.reset(i_cmd - sc.i_op, Fm)
            else:
                i_cmd = max(sc.i_min, i_cmd - sc.approach_rate * h)
        if mode == 1:
            target = min(reflex.demand(sc.force_target), cap)
            step_max = sc.ramp_rate * h
            ref_now = min(target, ref_now + step_max) if target > ref_now else max(target, ref_now - step_max)
            u = controller.step(ref_now, Fm)
            i_cmd = sc.i_op + min(max(u, u_lo), u_hi)
        # valve static characteristic (play + saturation) -> effective current into the plant
        play = min(max(play, i_cmd - hw), i_cmd + hw)
        ie = i_lo_v + (float(valve.static_pressure(play)) - p_min_v) / kv
        u_hist[1:] = u_hist[:-1]
        u_hist[0] = ie - sc.i_op
        y_hist[1:] = y_hist[:-1]
        y_hist[0] = yb
        out["force"][k] = F
        out["force_est"][k] = Fm
        out["force_std"][k] = Fs
        out["ref"][k] = ref_now if mode == 1 else np.nan
        out["current"][k] = i_cmd
        out["mode"][k] = mode
        out["load"][k] = load
    return FingerGraspResult(np.arange(N) * h, out["force"], out["force_est"], out["force_std"], out["ref"],
                             out["current"], out["mode"], out["slipping"], out["slip_alarm"], out["load"],
                             out["x_obj"], pv, sc.pvdf_rate, alarms, contact_t, float(out["force"].max()))
