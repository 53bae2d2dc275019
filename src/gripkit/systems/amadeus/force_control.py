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
:func:`simulate_finger_grasp` closes the loop around the whole finger: the valve's static
characteristic
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


def simulate_finger_grasp(controller: RSTController, plant=None,
                          scenario: GraspScenario | None = None, *,
                          valve=None, sensor=None, contact=None, detector=None,
                          kalman_q: float = 400.0,
                          rng=None) -> FingerGraspResult:
    """Closed-loop grasp with a guarded approach, force control, force sensing and the slip reflex.

    ``controller`` is an :class:`RSTController` for ``plant`` (valve current deviation in A →
    blocked force in N); ``valve`` a :class:`~gripkit.systems.amadeus.valve.ProportionalValve`
    (static characteristic used), ``sensor`` a
    :class:`~gripkit.systems.amadeus.strain_gauge_sensor.StrainGaugeSensor`
    (``None`` and ``scenario.sensor_noise=False``: the controller sees the true force),
    ``contact`` a :class:`~gripkit.systems.amadeus.pvdf.StickSlipContact`, ``detector`` a calibrated
    :class:`~gripkit.systems.amadeus.slip.SlipDetector` (required when ``scenario.slip``).
    """
    sc = scenario or GraspScenario()
    p = controller.resolve_plant(plant)
    rng = np.random.default_rng(sc.seed if rng is None else rng)
    N = _check_grasp(p, sc, detector)
    h = p.dt
    cap = sc.force_limit - sc.limit_margin
    finger = _ValveFinger(p, valve or ProportionalValve(check=False), sc)
    sensing = _ForceSensing(sc, sensor, kalman_q, h)
    slip = _SlipChannel(sc, contact, detector, h, N, rng) if sc.slip else None
    supervisor = _Supervisor(sc, controller, SlipReflex(step=sc.reflex_step, rate=sc.reflex_rate,
                                                        max_force=cap),
                             cap, finger.i_start, h)
    lt, lv = np.array([x[0] for x in sc.load]), np.array([x[1] for x in sc.load])
    out = {k: np.zeros(N) for k in ("force", "force_est", "force_std", "ref", "current", "mode",
                                    "slipping", "slip_alarm", "load", "x_obj")}
    for k in range(N):
        t = k * h
        yb, F = finger.force()
        load = float(np.interp(t, lt, lv))
        Ft = slip.period(k, F, load, supervisor, out) if slip is not None else 0.0
        Fm, Fs = sensing.measure(F, Ft, rng)
        i_cmd = supervisor.step(t, Fm)
        finger.advance(i_cmd, yb)
        out["force"][k] = F
        out["force_est"][k] = Fm
        out["force_std"][k] = Fs
        out["ref"][k] = supervisor.ref_now if supervisor.mode == 1 else np.nan
        out["current"][k] = i_cmd
        out["mode"][k] = supervisor.mode
        out["load"][k] = load
    pv = slip.pv if slip is not None else np.zeros(0)
    alarms = slip.alarms if slip is not None else []
    return FingerGraspResult(np.arange(N) * h, out["force"], out["force_est"], out["force_std"],
                             out["ref"],
                             out["current"], out["mode"], out["slipping"], out["slip_alarm"],
                             out["load"],
                             out["x_obj"], pv, sc.pvdf_rate, alarms, supervisor.contact_t,
                             float(out["force"].max()))


def _check_grasp(p, sc: GraspScenario, detector) -> int:
    """The number of control samples, after checking the plant and the scenario."""
    N = int(round(sc.duration / p.dt))
    if N < 10:
        raise SimulationError(f"duration {sc.duration} s is shorter than 10 control samples")
    if p.relative_degree() < 1:
        raise ModelError("simulate_finger_grasp needs a plant with at least one sample of input "
                         "delay (nk >= 1)")
    if sc.force_limit <= sc.force_target:
        raise DataError(f"force_limit {sc.force_limit} N must exceed force_target "
                        f"{sc.force_target} N")
    if sc.slip and (detector is None or detector.threshold is None):
        raise DataError("scenario.slip needs a calibrated SlipDetector (detector=...)")
    return N


class _ValveFinger:
    """The finger seen by the controller: the plant's difference equation in deviation variables
    around the operating current (blocked force from past effective currents), behind the valve's
    static characteristic (play and saturation), starting steady at ``i_max`` (finger straight)."""

    def __init__(self, p, valve, sc: GraspScenario):
        self.sc = sc
        self.A, self.B = p.den_zinv(), p.num_zinv()
        self.u_hist = np.zeros(self.B.size)
        self.y_hist = np.zeros(self.A.size)
        G0 = float(p.dc_gain()[0, 0])
        self.i_start = sc.i_max
        ie0 = float(valve.demand_current(np.array([self.i_start]))[0])
        self.u_hist[:] = ie0 - sc.i_op
        self.y_hist[:] = G0 * (ie0 - sc.i_op)
        self.play = self.i_start
        self.valve = valve
        self.hw = valve.parameters.value("hysteresis")
        self.i_lo, self.p_min, self.kv = (valve.parameters.value("i_lo"),
                                          valve.parameters.value("p_min"), valve.gain)
        self.fb0 = (-G0 * (ie0 - sc.i_op) if sc.blocked_force_at_op is None
                    else sc.blocked_force_at_op)
        self.g_obj = 1.0 if math.isinf(sc.k_object) else sc.k_object / (sc.k_finger + sc.k_object)

    def force(self) -> tuple[float, float]:
        """(blocked-force deviation, contact force on the object) at this sample."""
        A, B, sc = self.A, self.B, self.sc
        acc = 0.0
        for i in range(1, B.size):
            acc += B[i] * self.u_hist[i - 1]
        for i in range(1, A.size):
            acc -= A[i] * self.y_hist[i - 1]
        return acc, self.g_obj * max(0.0, self.fb0 + acc - sc.k_finger * sc.gap)

    def advance(self, i_cmd: float, yb: float) -> None:
        """The commanded current through the valve's play and static curve into the histories."""
        self.play = min(max(self.play, i_cmd - self.hw), i_cmd + self.hw)
        ie = self.i_lo + (float(self.valve.static_pressure(self.play)) - self.p_min) / self.kv
        self.u_hist[1:] = self.u_hist[:-1]
        self.u_hist[0] = ie - self.sc.i_op
        self.y_hist[1:] = self.y_hist[:-1]
        self.y_hist[0] = yb


class _ForceSensing:
    """The force the controller sees: the true force, or the Kalman estimate from six noisy
    strain-gauge bridge readings (``scenario.sensor_noise``)."""

    def __init__(self, sc: GraspScenario, sensor, kalman_q: float, h: float):
        self.kf = None
        if sc.sensor_noise:
            self.sensor = sensor if sensor is not None else StrainGaugeSensor()
            self.kf = ForceKalmanFilter(self.sensor,
                                        ForceDynamics.random_walk([50.0, 50.0, kalman_q], h),
                                        x0=np.zeros(3), P0=np.eye(3) * 0.01)

    def measure(self, F: float, Ft: float, rng) -> tuple[float, float]:
        """(estimated normal force, its σ) for normal force F and tangential force Ft."""
        if self.kf is None:
            return F, 0.0
        Rt = self.sensor.H @ np.array([0.0, Ft, F])
        reading = Rt + rng.standard_normal(6) * np.sqrt(self.sensor.noise_variance(Rt))
        f_est, cov = self.kf.step(reading)
        return float(f_est[2]), math.sqrt(max(cov[2, 2], 0.0))


class _SlipChannel:
    """The stick-slip contact, the PVDF film with its noise and the streaming slip detector, run
    at the PVDF rate over each control period."""

    def __init__(self, sc: GraspScenario, contact, detector, h: float, N: int, rng):
        self.sc, self.h = sc, h
        self.contact = contact if contact is not None else StickSlipContact(check=False)
        self.stream = detector.stream()
        self.state = self.contact.new_state()
        self.n_sub = int(round(sc.pvdf_rate * h))
        self.ns_contact = self.contact.substeps(1.0 / sc.pvdf_rate, self.contact.theta()[None, :])
        self.pv = np.zeros(N * self.n_sub)
        self.alarms = []
        self.noise = pvdf_noise(N * self.n_sub, dt=1.0 / sc.pvdf_rate, rng=rng)

    def period(self, k: int, F: float, load: float, supervisor: "_Supervisor", out: dict) -> float:
        """Advance the contact over control period k; record the film voltage, slipping fraction,
        object position and alarms, and let the supervisor's slip reflex act on them. Returns the
        tangential force at the period's end."""
        n, h = self.n_sub, self.h
        yc = (self.contact.advance(self.state, np.full(n, F), np.full(n, load), h / n,
                                   self.ns_contact))
        seg = yc[:, 0] + self.noise[k * n:(k + 1) * n]
        self.pv[k * n:(k + 1) * n] = seg
        out["slipping"][k] = yc[:, 2].mean()
        out["x_obj"][k] = yc[-1, 4]
        slipping_now, new_alarms = self.stream.update(seg)
        out["slip_alarm"][k] = slipping_now
        self.alarms.extend(new_alarms)
        supervisor.on_slip_signal(k * h, slipping_now, new_alarms, h)
        return float(yc[-1, 5])


class _Supervisor:
    """Guarded approach (close at ``approach_rate`` until the measured force passes
    ``contact_force``), then force control on a rate-limited reference, raised by the slip
    reflex."""

    def __init__(self, sc: GraspScenario, controller: RSTController, reflex: SlipReflex, cap: float,
                 i_start: float, h: float):
        self.sc, self.controller, self.reflex, self.cap, self.h = sc, controller, reflex, cap, h
        self.mode = 0
        self.i_cmd = i_start
        self.contact_t = None
        self.ref_now = 0.0
        self.u_lo, self.u_hi = sc.i_min - sc.i_op, sc.i_max - sc.i_op

    def on_slip_signal(self, t: float, slipping_now: bool, new_alarms, h: float) -> None:
        """Slip alarms raise the force demand once armed (in contact for ``slip_blanking``)."""
        armed = self.mode == 1 and t - self.contact_t >= self.sc.slip_blanking
        if armed:
            for _ in new_alarms:
                self.reflex.on_slip()
            if slipping_now and not new_alarms:
                self.reflex.while_slipping(h)

    def step(self, t: float, Fm: float) -> float:
        """The commanded valve current for this sample, from the measured force."""
        sc, h = self.sc, self.h
        if self.mode == 0:
            if Fm > sc.contact_force:
                self.mode = 1
                self.contact_t = t
                self.ref_now = Fm
                self.controller.reset(self.i_cmd - sc.i_op, Fm)
            else:
                self.i_cmd = max(sc.i_min, self.i_cmd - sc.approach_rate * h)
        if self.mode == 1:
            target = min(self.reflex.demand(sc.force_target), self.cap)
            step_max = sc.ramp_rate * h
            r = self.ref_now
            self.ref_now = min(target, r + step_max) if target > r else max(target, r - step_max)
            u = self.controller.step(self.ref_now, Fm)
            self.i_cmd = sc.i_op + min(max(u, self.u_lo), self.u_hi)
        return self.i_cmd
