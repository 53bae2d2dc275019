"""The two-finger grasp of ``001_0b92a7da96e7aa46.txt`` §I with the TSFM: force sensing on both
fingers, no position sensor.

"When a micropart is placed between microgripper fingers, a contact may appear between one finger
and the micropart before the other which can lead to the loss of the micropart ... stopping the
movement of the finger in contact with the micropart if the other finger has not reached the
contact yet." The strategy, per finger, sample by sample at 20 kHz:

1. **approach** under position control: the reference closes at ``approach_speed``; the position
   fed back is the eq-11 estimate (:class:`~gripkit.systems.tsfm.TipPositionEstimator`) from the
   voltage and the measured force;
2. **hold**: once the finger's force exceeds the threshold (5 µN, :class:`ContactDetector`) it
   holds the position it had at contact — it does not push — until the other finger touches;
3. **squeeze**: with both in contact, both close under force control to ``grip_force``: the
   force error (ramped reference) moves the position reference, r ← r + dt ω_f (F_ref − F)/k̂,
   with k̂ the contact stiffness seen so far, (F − F_contact)/(ŷ − ŷ_contact) from the position
   estimates (clipped to [k_min, k_max]) — so the loop speed does not depend on how soft the part
   is.

The inner position loop is an integral controller, U̇ = ω_p (r − ŷ)/g, g the finger's static
gain (m/V), with the voltage clipped to the actuator's range. ``wait_for_other=False`` gives the
naive grasp (the first finger keeps closing until the second touches) for comparison: on a part
held by substrate friction it pushes the part away.

:func:`grasp_step` is the numba step (detectors, estimators and controller of both fingers),
used by :class:`TwoFingerGrasp` for a real loop and by :func:`simulate_two_finger_grasp`, which
closes the loop on the hybrid two-finger model :class:`~gripkit.systems.tsfm.gripper.TSFMGripper`.
"""

from __future__ import annotations

import math
from collections import namedtuple
from dataclasses import asdict, dataclass, field

import numba
import numpy as np

from ...errors import DataError, IdentificationError, SimulationError
from ...estimation.contact_detection import detector_step
from ...signals.trajectory import Trajectory
from .end_effector import lever_coefficients
from .gripper import (TSFMGripper, GripperState, gripper_advance, gripper_measure, gripper_model,
                      gripper_work)
from .micropart import MicropartEstimate, estimate_micropart
from .tip_position import estimator_arrays, estimator_step

__all__ = ["GraspSettings", "TwoFingerGrasp", "TwoFingerGraspResult", "simulate_two_finger_grasp",
           "grasp_step",
           "Estimators", "GraspLoop"]

# controller state columns (per finger)
_PHASE, _REF, _U, _YC, _FC, _FREF, _CONTACT_T = range(7)
APPROACH, HOLD, SQUEEZE = 0, 1, 2
#: the entries of the settings vector (:meth:`GraspSettings.vector`): closing speed (m/s), the
#: position and force loop gains ω (rad/s), the commanded force (N), its ramp time (s), the
#: voltage range (V), the fingers' static gains, the approach limit (m), the stiffness bounds
#: (N/m), wait-for-the-other flag, contact threshold and release (N) and the sample time (s)
SETTINGS_VECTOR = ("approach_speed", "position_gain", "force_gain", "grip_force",
                   "force_ramp_time", "u_min", "u_max", "gain1", "gain2", "max_closing", "k_min",
                   "k_max", "wait_for_other", "threshold", "release", "dt")
#: index of each entry: ``cp[SX.dt]``; a module-level namedtuple of ints generated from
#: SETTINGS_VECTOR, which numba folds as constants
SX = namedtuple("GraspSettingIndex", SETTINGS_VECTOR)(*range(len(SETTINGS_VECTOR)))

#: the tip-position estimators of both fingers (:func:`estimator_arrays`, stacked): ``bw`` (2, 4),
#: ``Phi`` (2, 4, 4), ``Gam`` (2, 4, 2), ``cy`` (2, 4)
Estimators = namedtuple("Estimators", "bw Phi Gam cy")
#: the grasp loop of both fingers: detector states ``det`` (2, 5) and windows ``buf`` (2, window),
#: estimator states ``est`` (2, 6), controller states ``cs`` (2, 7), estimator scratch ``xt`` (4),
#: and ``out`` (2, 5) = [U (V), ŷ (m), filtered force (N), contact flag, phase] per finger
GraspLoop = namedtuple("GraspLoop", "det buf est cs xt out")


@dataclass(frozen=True)
class GraspSettings:
    """Settings of the grasp (SI units)."""

    grip_force: float = 200e-6           #: N, force to squeeze with
    approach_speed: float = 40e-6        #: m/s, closing speed of the position reference
    position_bandwidth_hz: float = 100.0  #: integral position loop on the estimate
    force_bandwidth_hz: float = 20.0     #: force loop (normalised by the stiffness seen)
    force_ramp_time: float = 0.3         #: s, ramp of the force reference
    threshold: float = 5e-6              #: N, contact threshold (§V-C)
    release: float = 2.5e-6              #: N, contact released below this
    window: int = 8                      #: samples averaged by the contact detector
    u_min: float = -100.0                #: V
    u_max: float = 100.0                 #: V
    max_closing: float = 150e-6          #: m, the approach reference stops here
    k_min: float = 5.0                   #: N/m, bounds of the stiffness used by the force loop
    k_max: float = 2000.0
    wait_for_other: bool = True          #: False: the naive grasp (no hold)

    def vector(self, gains: tuple[float, float], dt: float) -> np.ndarray:
        """The settings vector the kernels take, in :data:`SETTINGS_VECTOR` order
        (``cp[SX.dt]``)."""
        v = dict(approach_speed=self.approach_speed,
                 position_gain=2 * math.pi * self.position_bandwidth_hz,
                 force_gain=2 * math.pi * self.force_bandwidth_hz, grip_force=self.grip_force,
                 force_ramp_time=self.force_ramp_time, u_min=self.u_min, u_max=self.u_max,
                 gain1=gains[0], gain2=gains[1], max_closing=self.max_closing, k_min=self.k_min,
                 k_max=self.k_max, wait_for_other=1.0 if self.wait_for_other else 0.0,
                 threshold=self.threshold, release=self.release, dt=dt)
        return np.array([v[k] for k in SETTINGS_VECTOR])


@numba.njit(cache=True, _nrt=False)
def grasp_step(F1, F2, loop, e, cp):  # pragma: no cover - compiled
    """One sample of the grasp for both fingers.

    F1, F2: measured forces (N); ``loop``: the states of both fingers (:class:`GraspLoop`);
    ``e``: the estimators (:class:`Estimators`); cp: :meth:`GraspSettings.vector`. Writes
    loop.out[i] = [U (V), ŷ (m), filtered force (N), contact flag, phase] and returns nothing.
    """
    det, buf, est, cs, out = loop.det, loop.buf, loop.est, loop.cs, loop.out
    cy = e.cy
    dt = cp[SX.dt]
    for i in range(2):
        F = F1 if i == 0 else F2
        c = detector_step(det[i], buf[i], F, cp[SX.threshold], cp[SX.release])
        out[i, 2] = det[i, 4]
        out[i, 3] = c
        y = 0.0
        for j in range(4):
            y += cy[i, j] * est[i, 2 + j]
        out[i, 1] = y
    both = cs[0, _CONTACT_T] >= 0.0 and cs[1, _CONTACT_T] >= 0.0
    for i in range(2):
        y = out[i, 1]
        Ff = out[i, 2]
        c = out[i, 3]
        ph = cs[i, _PHASE]
        if c > 0.5 and cs[i, _CONTACT_T] < 0.0:       # first contact of this finger
            cs[i, _CONTACT_T] = 1.0
            cs[i, _YC] = y
            cs[i, _FC] = Ff
            if cp[SX.wait_for_other] > 0.5:
                cs[i, _PHASE] = HOLD
                cs[i, _REF] = y
        ph = cs[i, _PHASE]
        if ph == APPROACH:
            if cs[i, _REF] < cp[SX.max_closing]:
                cs[i, _REF] += cp[SX.approach_speed] * dt
        # lost it before the other touched: close again
        elif ph == HOLD and c < 0.5:
            cs[i, _PHASE] = APPROACH
            cs[i, _CONTACT_T] = -1.0
    both_now = cs[0, _CONTACT_T] >= 0.0 and cs[1, _CONTACT_T] >= 0.0
    if both_now and not both:
        for i in range(2):
            cs[i, _PHASE] = SQUEEZE
            cs[i, _FREF] = out[i, 2]
    for i in range(2):
        y = out[i, 1]
        if cs[i, _PHASE] == SQUEEZE:
            # (conditional expressions, not builtin max/min: numba.cuda cannot compile those in an
            # @njit callee, and gripkit.systems.tsfm.grasp_gpu runs this step on the GPU; same
            # values)
            ramp = cp[SX.force_ramp_time]
            step = (cp[SX.grip_force] - cs[i, _FREF]) * dt / (dt if dt > ramp else ramp)
            if abs(cp[SX.grip_force] - cs[i, _FREF]) <= abs(step):
                cs[i, _FREF] = cp[SX.grip_force]
            else:
                cs[i, _FREF] += step
            d = y - cs[i, _YC]
            k = cp[SX.k_max]
            if d > 50e-9:
                k = (out[i, 2] - cs[i, _FC]) / d
                k = cp[SX.k_min] if cp[SX.k_min] > k else k
                k = cp[SX.k_max] if cp[SX.k_max] < k else k
            cs[i, _REF] += dt * cp[SX.force_gain] * (cs[i, _FREF] - out[i, 2]) / k
        # inner loop: integral position control on the estimate, voltage clipped
        U = cs[i, _U] + dt * cp[SX.position_gain] * (cs[i, _REF] - y) / cp[SX.gain1 + i]
        U = cp[SX.u_min] if cp[SX.u_min] > U else U
        U = cp[SX.u_max] if cp[SX.u_max] < U else U
        cs[i, _U] = U
        out[i, 0] = U
        out[i, 4] = cs[i, _PHASE]
        F = F1 if i == 0 else F2
        estimator_step(est[i], e.bw[i], e.Phi[i], e.Gam[i], cy[i], U, F, loop.xt)


def _init_state(n_window: int) -> GraspLoop:
    cs = np.zeros((2, 7))
    cs[:, _CONTACT_T] = -1.0
    return (GraspLoop(np.zeros((2, 5)), np.zeros((2, n_window)), np.zeros((2, 6)), cs, np.empty(4),
                      np.zeros((2, 5))))


def _est_stack(fingers, dt) -> tuple[Estimators, list]:
    arrs = [estimator_arrays(f, dt) for f in fingers]
    return (Estimators(*(np.ascontiguousarray(np.stack([a[k] for a in arrs]))
                         for k in Estimators._fields)), arrs)


def _static_gain(values) -> float:
    L = values["L_r"] + values["L_s"]
    return lever_coefficients(L, values["L_a"]).alpha_u * values["d_p"]


def _values(f) -> dict:
    if hasattr(f, "values") and callable(f.values) and not isinstance(f, dict):
        return f.values()
    if hasattr(f, "value"):
        return {n: f.value(n) for n in f}
    return dict(f)


class TwoFingerGrasp:
    """The grasp controller for a real loop: call :meth:`step` once per sample with the two
    measured forces; it returns the two voltages to apply.

    ``finger1``, ``finger2``: the models used by the position estimators (TSFMFinger, its
    ParameterSet or a mapping of values); ``dt``: sample time (s).
    """

    def __init__(self, finger1, finger2, dt: float, settings: GraspSettings = GraspSettings()):
        if not (np.isfinite(dt) and dt > 0):
            raise DataError(f"dt: expected a positive sample time in s, found {dt!r}")
        self.settings = settings
        vals = [_values(finger1), _values(finger2)]
        self._e, _ = _est_stack(vals, dt)
        self._cp = settings.vector((_static_gain(vals[0]), _static_gain(vals[1])), dt)
        self._loop = _init_state(settings.window)

    def step(self, F1: float, F2: float) -> tuple[float, float]:
        grasp_step(float(F1), float(F2), self._loop, self._e, self._cp)
        out = self._loop.out
        return float(out[0, 0]), float(out[1, 0])

    @property
    def phases(self) -> tuple[str, str]:
        names = ("approach", "hold", "squeeze")
        cs = self._loop.cs
        return names[int(cs[0, _PHASE])], names[int(cs[1, _PHASE])]

    @property
    def positions(self) -> tuple[float, float]:
        """Estimated tip positions (m) at the last step."""
        out = self._loop.out
        return float(out[0, 1]), float(out[1, 1])


@numba.njit(cache=True)
def _grasp_run(model, x0, noise, loop, e, cp, rec, work):  # pragma: no cover - compiled
    """The grasp loop on the gripper ``model`` (:class:`~gripkit.systems.tsfm.gripper.GripperModel`)
    from x0 (3, n) = [finger 1, finger 2, [X_p, ...]], force noise (N, 2): one row of ``rec`` per
    sample (:data:`_COLUMNS`)."""
    n = model.Phi.shape[4]
    state = GripperState(np.empty((2, n)), np.empty(2, dtype=np.int64), np.zeros(4), np.empty(1))
    X, modes, ps = state.X, state.modes, state.ps
    for i in range(2):
        for j in range(n):
            X[i, j] = x0[i, j]
        modes[i] = 0
    ps[0] = x0[2, 0]
    out, yout = loop.out, work.yout
    gripper_measure(state, model, work)
    for k in range(noise.shape[0]):
        F1 = yout[0, 3] + noise[k, 0]
        F2 = yout[1, 3] + noise[k, 1]
        grasp_step(F1, F2, loop, e, cp)
        rec[k, 0] = out[0, 0]
        rec[k, 1] = out[1, 0]
        rec[k, 2] = yout[0, 0]
        rec[k, 3] = yout[1, 0]
        rec[k, 4] = out[0, 1]
        rec[k, 5] = out[1, 1]
        rec[k, 6] = yout[0, 2]
        rec[k, 7] = yout[1, 2]
        rec[k, 8] = F1
        rec[k, 9] = F2
        rec[k, 10] = ps[0]
        rec[k, 11] = out[0, 4]
        rec[k, 12] = out[1, 4]
        rec[k, 13] = modes[0]
        rec[k, 14] = modes[1]
        gripper_advance(out[0, 0], out[1, 0], state, model, work)


_COLUMNS = (("U1", "V"), ("U2", "V"), ("y_C1", "m"), ("y_C2", "m"), ("y_hat1", "m"),
            ("y_hat2", "m"),
            ("F_g1", "N"), ("F_g2", "N"), ("F_meas1", "N"), ("F_meas2", "N"), ("X_p", "m"),
            ("phase1", "1"),
            ("phase2", "1"), ("contact1", "1"), ("contact2", "1"))


@dataclass(frozen=True)
class TwoFingerGraspResult:
    """A simulated grasp: the record (voltages, true and estimated tips, true and measured forces,
    part centre, phases 0/1/2 = approach/hold/squeeze, true contacts), the part's displacement,
    the contact times, the final forces and the micropart estimate (None if not grasped)."""

    trajectory: Trajectory
    part_displacement: float
    contact_times: tuple[float, float]
    final_forces: tuple[float, float]
    estimate: MicropartEstimate | None
    settings: GraspSettings = field(default_factory=GraspSettings)

    @property
    def grasped(self) -> bool:
        return self.estimate is not None

    def summary(self) -> dict:
        d = {"part_displacement_um": self.part_displacement * 1e6,
             "contact_times_s": list(self.contact_times),
             "final_forces_uN": [f * 1e6 for f in self.final_forces]}
        if self.estimate is not None:
            d.update(width_um=self.estimate.width * 1e6, width_std_um=self.estimate.width_std * 1e6,
                     stiffness=self.estimate.stiffness, stiffness_std=self.estimate.stiffness_std,
                     width_threshold_um=self.estimate.width_threshold * 1e6)
        return d

    def to_dict(self) -> dict:
        return {**self.summary(), "settings": asdict(self.settings)}


def simulate_two_finger_grasp(gripper: TSFMGripper, *, estimator_fingers=None,
                              settings: GraspSettings = GraspSettings(),
                              duration: float = 4.0, dt: float = 5e-05, noise_std: float = 2e-6,
                              seed: int = 0) -> TwoFingerGraspResult:
    """Close the grasp loop on the gripper model (see the module docstring).

    ``estimator_fingers``: the two finger models the estimators use (default: the gripper's own,
    i.e. a perfect model; pass identified ones to see the effect of model errors). Force noise:
    white, ``noise_std`` (N) on each sensor. Returns the record and the micropart estimate from
    the estimated positions and the measured forces (:func:`estimate_micropart`).
    """
    if not (np.isfinite(duration) and duration > 0 and np.isfinite(dt) and dt > 0):
        raise SimulationError(f"duration and dt must be positive, found {duration!r} s, {dt!r} s")
    if noise_std < 0:
        raise SimulationError(f"noise_std: expected >= 0 N, found {noise_std!r}")
    N = int(round(duration / dt))
    th = gripper.theta()
    d = gripper.arrays(th[None, :], dt)
    fingers = estimator_fingers or gripper.fingers
    vals = [_values(f) for f in fingers]
    e, _ = _est_stack(vals, dt)
    cp = settings.vector((_static_gain(vals[0]), _static_gain(vals[1])), dt)
    loop = _init_state(settings.window)
    rng = np.random.default_rng(seed)
    noise = np.ascontiguousarray(rng.standard_normal((N, 2)) * noise_std)
    x0 = np.zeros((3, d["Phi"].shape[-1]))
    x0[2, 0] = th[gripper.parameters.names.index("X_p")]
    rec = np.empty((N, len(_COLUMNS)))
    _grasp_run(gripper_model(d, 0), x0, noise, loop, e, cp, rec,
               gripper_work(d["Phi"].shape[-1], d["C"].shape[-2]))
    if not np.isfinite(rec).all():
        raise SimulationError("the grasp simulation diverged", hint="lower the loop bandwidths")
    t = np.arange(N) * dt
    tr = (Trajectory(t, {n: rec[:, i] for i, (n, _) in enumerate(_COLUMNS)}, dict(_COLUMNS),
                     {"dt": dt}))
    ct = []
    for i in (13, 14):
        hit = np.flatnonzero(rec[:, i] > 0.5)
        ct.append(float(t[hit[0]]) if hit.size else math.nan)
    gap = th[gripper.parameters.names.index("gap")]
    try:
        est_mp = estimate_micropart(rec[:, 4], rec[:, 8], rec[:, 5], rec[:, 9], gap,
                                    threshold=settings.threshold,
                                    window=settings.window)
    except (DataError, IdentificationError):  # not grasped (no squeeze with both fingers)
        est_mp = None
    return TwoFingerGraspResult(tr, float(rec[-1, 10] - rec[0, 10]), (ct[0], ct[1]),
                                (float(rec[-1, 6]), float(rec[-1, 7])), est_mp, settings)
