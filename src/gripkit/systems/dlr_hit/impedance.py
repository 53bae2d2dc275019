"""Joint and Cartesian impedance control of the DLR/HIT II finger with gravity and friction
compensation, simulated in closed loop with the complete finger model, and its stability margins.

Cartesian impedance (``002_ddea254371185ad3.txt`` eq 3.1, after Hogan [9]) prescribes the
mass-damper-spring relation F = M_I ẍ + D_k ẋ + K_k x between the fingertip displacement x from
its set point and the external force F. Without a fingertip force sensor (the DLR/HIT II's was
removed, §3.1) the inertia is left as the finger's own, M_I = Λ(q) = (J M⁻¹ Jᵀ)⁻¹, and the
control law is the compliance form used on the hand (§3.1: "joint and Cartesian impedance control
with friction and gravity compensation", [40])::

    τ_p = J_pᵀ [K_k (x_d − x) + D_k (ẋ_d − ẋ)] − D_a ṗ + G_p(p) + F̂(ṗ)     (Cartesian)
    τ_p = Γ_qᵀ [K (q_d − q) + D (q̇_d − q̇)] − D_a ṗ + G_p(p) + F̂(ṗ)         (joint)

in actuator coordinates p (J_p = J Γ, Γ_q the joint rows of the coupling). G_p is the gravity
torque of the multibody model and F̂ the identified kinetic friction (a lookup table), applied in
the direction the impedance torque τ pushes: at the measured speed while the actuator moves that
way, at the lowest tabulated speed while it rests (so breaking away needs F_s − F_c instead of
F_s), faded in as tanh(|τ|/ε), and not at all while the actuator moves against τ (friction then
brakes it; compensating along the measured velocity would push every reversal — a bounce off a
wall — further and sustain a limit cycle). The commanded actuator
torque becomes a PWM count through the inverse of eq 5.10 at the measured motor speed, clipped to
±4096, held over the 1 kHz control period.

Online friction adaptation (§6.3: "an algorithm to adjust the friction model"; abstract; the
estimator, the thermal observer and the sensing model are gripkit's additions). With
``ImpedanceController(adaptation=AdaptationSettings(...))`` the friction estimator of
:mod:`gripkit.estimation.friction_adaptation` runs inside the loop: at every control step k, after
the PWM command u_k is computed,

    τ_m,k = eq 5.10(u_k, N·ṗ_k) through the transmission,   h_k = Γᵀ(C(q, q̇)q̇ + G(q)),
    (ŝ, ô) ← RLS step(τ_m,k, h_k, ṗ_k)

(the finger has no torque sensor: the motor torque is the model's, from the command and the
measured speed), and the compensation of the next step uses F̂(ṗ) = ŝ·F_table(ṗ) + ô·sign(ṗ). The
estimator's inertia J is the diagonal of M_p at the initial configuration. Before any update
(ŝ, ô) = (1, 0): the loop without adaptation. The plant's friction can drift during the run
(``friction_drift``, :mod:`gripkit.systems.dlr_hit.friction_drift`), unknown to the controller.

The control law and the wall run inside the finger's own simulation kernel
(:func:`gripkit.systems.dlr_hit.finger.finger_run` with ``ctrl`` = 1 or 2), so closed-loop studies
cost no extra compilation.

Contact: a planar wall (unit normal n pointing out of the wall, a point on it) of stiffness k_w
and damping d_w pushes on the fingertip when it penetrates: F = (k_w δ − d_w δ̇)·n with
δ = −nᵀ(x_tip − x_w) > 0 (never pulling); it enters the actuators as Γᵀ Jᵀ F.

Stability margins (:func:`stability_margins`): per actuator the loop is linearised around rest:
plant 1/(J s² + b s + k_e) with J the actuator's apparent inertia, b its viscous friction, k_e the
environment stiffness reflected to the actuator, controller K + D s, sampled with a zero-order
hold at dt and one sample of computation delay. The gain and phase margins are read from the
discrete loop's frequency response.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import ModelError, SimulationError
from ...estimation.friction_adaptation import AdaptationSettings
from ...models.friction import FrictionTable, table_arrays
from ...signals.trajectory import Trajectory
from .finger import (ACTUATORS, CARTESIAN_IMPEDANCE, FRICTION_MODES, G_BAND, G_COMMAND, G_FREF,
                     G_GUARD, G_OBS_ALPHA, G_OBS_CTH, G_OBS_RTH, G_QUANTUM, G_SETTLE, G_THERMAL,
                     G_VALPHA, JOINT_IMPEDANCE, LOOP_OUTPUT_BLOCKS, N_GAINS, NX, YL,
                     DLRFinger,
                     FrictionEstimator, ImpedanceLoop, PlantDrift, finger_run)
from .friction_drift import FrictionDrift

__all__ = ["ImpedanceController", "Wall", "simulate_impedance", "stability_margins",
           "impedance_margins", "model_friction_tables", "LOOP_ADAPTATION", "Sensing",
           "ThermalObserver", "POTENTIOMETERS"]


@dataclass(frozen=True)
class Sensing:
    """How the controller measures the finger: angles quantised to ``resolution`` (rad) and the
    velocity by backward difference of the quantised angles (1 kHz) through a first-order low-pass
    at ``filter_hz`` — the DLR/HIT hand has no velocity sensor, "the speed can be calculated by
    differentiation of the position signal", and its potentiometers resolve 0.1° (§2, the DLR
    Hand II paragraph of ``002_ddea254371185ad3.txt``). gripkit applies the resolution to the
    three actuator output angles (the controller's coordinates), an assumption: the seed gives the
    joints' resolution, not the motors' Hall sensors'."""

    resolution: float = 0.1 * math.pi / 180
    filter_hz: float = 50.0

    def __post_init__(self):
        if not (math.isfinite(self.resolution) and self.resolution > 0):
            raise ModelError(f"resolution: expected a positive angle in rad, "
                             f"found {self.resolution!r}")
        if not (math.isfinite(self.filter_hz) and self.filter_hz > 0):
            raise ModelError(f"filter_hz: expected a positive frequency in Hz, "
                             f"found {self.filter_hz!r}")


#: the DLR/HIT potentiometers: 0.1° (§2), velocity differentiated and low-passed at 50 Hz
POTENTIOMETERS = Sensing()


#: the speed (rad/s) at which :class:`ThermalObserver`'s band compares the estimated kinetic
#: friction with the table's
BAND_SPEED = 1.0


@dataclass(frozen=True)
class ThermalObserver:
    """The controller's estimate of each motor's winding temperature, from the PWM it commanded
    and the measured speed through gripkit's thermal model (:mod:`gripkit.models.bldc`: eq 5.4's
    Joule heat, eq 5.5's R(T), the first-order model calibrated on Fig. 5.7). The start
    temperature is unknown, so two estimates run from the ends of ``initial`` = (T_lo, T_hi) (K;
    default None: the finger's T_amb and T_ref, room to operating temperature); both see the same
    PWM history and converge (time constant ≈ R_th·C_th = 39.6 s), and the plant's temperature
    stays between them (the solutions of the scalar ODE do not cross).

    The PWM inversion divides the commanded torque by ρ̂, the mean of the two torque factors
    ρ = R(T_ref)/R(T), and the friction estimator's motor torque is ρ̂ times eq 5.10. The estimator
    is frozen (:data:`gripkit.estimation.friction_adaptation.FROZEN`) while the band is wider than
    ``guard`` relative to ρ̂: then a torque loss and a friction change cannot be told apart (the
    finger has no torque or current sensor, §3.1).

    ``band`` (relative, default 0.2; 0: none) decides when the estimate replaces the identified
    table in the compensation: only once it is *settled*, after ln 20/(−ln λ) estimator updates
    (2994, 3.0 s of sliding at λ = 0.999: before, more than 5 % of the start-up transient is left;
    when the guard first opens the estimate swings to 3.2-3.5 times the table for a few ms), and
    *significant*, the estimated kinetic friction at :data:`BAND_SPEED`, ŝ·F_ref + ô, more than
    ``band`` away from the table's F_ref. Inside the band the table is applied as identified, so
    on an unchanged plant adaptation can never do worse than the fixed compensation. The default
    sits above the estimator's errors-in-variables bias with the potentiometers' differentiated
    velocity (it reads the unchanged friction 2-17 % high, exact velocities within ±2.3 %) and
    well below the warm-up drift it is meant to follow (the plant's friction reaches 1.43-1.52
    times the table); a drift smaller than the band is not compensated.

    ``alpha_R`` (1/K), ``R_th`` (K/W), ``C_th`` (J/K): the observer's own thermal parameters
    (default None: the finger's), to study a thermal model that differs from the motor's."""

    initial: tuple | None = None
    guard: float = 0.05
    band: float = 0.2
    command: bool = False
    alpha_R: float | None = None
    R_th: float | None = None
    C_th: float | None = None

    def __post_init__(self):
        if self.initial is not None:
            try:
                lo, hi = (float(x) for x in self.initial)
            except (TypeError, ValueError):
                raise ModelError(f"initial: expected (T_lo, T_hi) in K, "
                                 f"found {self.initial!r}") from None
            if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo <= hi):
                raise ModelError(f"initial: expected 0 < T_lo <= T_hi in K, found {self.initial!r}")
            object.__setattr__(self, "initial", (lo, hi))
        if not (math.isfinite(self.guard) and self.guard > 0):
            raise ModelError(f"guard: expected a positive relative width, found {self.guard!r}")
        band = self.band
        if not (isinstance(band, (int, float)) and math.isfinite(band) and band >= 0):
            raise ModelError(f"band: expected a relative width >= 0 (0: no band), found {band!r}")
        for name in ("alpha_R", "R_th", "C_th"):
            x = getattr(self, name)
            if x is not None and not (isinstance(x, (int, float)) and math.isfinite(x) and x > 0):
                raise ModelError(f"{name}: expected a positive number or None (the finger's), "
                                 f"found {x!r}")

@dataclass(frozen=True)
class ImpedanceController:
    """Impedance gains and compensation switches.

    ``kind='joint'``: stiffness (N·m/rad) and damping (N·m·s/rad) per joint (abduction, flexion,
    proximal). ``kind='cartesian'``: per fingertip axis of the finger base frame, N/m and N·s/m.
    ``friction_tables``: the identified kinetic friction of (base1, base2, distal) used for
    compensation (default: the finger model's own friction, :func:`model_friction_tables`);
    ``velocity_deadband`` (rad/s): below
    it an actuator counts as at rest; ``smoothing`` (N·m): at rest the friction compensation
    fades in as tanh(|τ|/smoothing) of the impedance torque τ. ``actuator_damping``
    (N·m·s/rad per actuator) adds −D_a·ṗ: a Cartesian stiffness acts weakly along the directions
    J_p maps to small fingertip motion, and this damps them. ``adaptation``: settings of the
    online friction estimator whose (scale, offset) the compensation uses (default None: the
    tables as given); see :data:`LOOP_ADAPTATION` for the DLR/HIT defaults. ``sensing``: a
    :class:`Sensing` (quantised angles, differentiated velocity; default None: the exact state).
    ``thermal``: a :class:`ThermalObserver` that corrects eq 5.10 for the winding temperature
    and guards the adaptation (default None: eq 5.10 at T_ref as printed).
    """

    kind: str = "joint"
    stiffness: tuple = (2.0, 2.0, 2.0)
    damping: tuple = (0.3, 0.3, 0.3)
    gravity_compensation: bool = True
    friction_compensation: bool = True
    friction_tables: tuple | None = None
    velocity_deadband: float = 0.02
    smoothing: float = 0.02
    actuator_damping: tuple = (0.0, 0.0, 0.0)
    adaptation: AdaptationSettings | None = None
    sensing: Sensing | None = None
    thermal: ThermalObserver | None = None

    def __post_init__(self):
        if self.sensing is not None and not isinstance(self.sensing, Sensing):
            raise ModelError(f"sensing: expected a Sensing or None, "
                             f"found {type(self.sensing).__name__}")
        if self.thermal is not None and not isinstance(self.thermal, ThermalObserver):
            raise ModelError(f"thermal: expected a ThermalObserver or None, found "
                             f"{type(self.thermal).__name__}")
        if self.kind not in ("joint", "cartesian"):
            raise ModelError(f"kind: expected 'joint' or 'cartesian', found {self.kind!r}")
        for name in ("stiffness", "damping", "actuator_damping"):
            v = np.asarray(getattr(self, name), dtype=np.float64)
            if v.shape != (3,) or not np.isfinite(v).all() or (v < 0).any():
                raise ModelError(f"{name}: expected three non-negative gains, found "
                                 f"{getattr(self, name)!r}")
            object.__setattr__(self, name, tuple(float(x) for x in v))
        if self.friction_tables is not None and (len(self.friction_tables) != 3 or not all(
                isinstance(t, FrictionTable) for t in self.friction_tables)):
            raise ModelError("friction_tables: expected three FrictionTables "
                             "(base1, base2, distal)")
        if self.adaptation is not None and not isinstance(self.adaptation, AdaptationSettings):
            raise ModelError(f"adaptation: expected AdaptationSettings or None, found "
                             f"{type(self.adaptation).__name__}")
        if self.adaptation is not None and not self.friction_compensation:
            raise ModelError("adaptation needs friction_compensation=True (the "
                             "estimate is used there)")
        if not self.velocity_deadband > 0 or not self.smoothing > 0:
            raise ModelError(f"velocity_deadband (rad/s) and smoothing (N·m) must be > 0, found "
                             f"{self.velocity_deadband!r}, {self.smoothing!r}")


#: online friction adaptation on the DLR/HIT finger: λ = 0.999 (3.0 s to 95 % at 1 kHz), H at
#: 10 Hz, sliding above 0.05 rad/s; the scale kept in [0, 5] and the offset within ±1 N·m (the
#: thesis's friction spans 0.2–1 N·m, §6.3), so a bad estimate cannot command a runaway torque
LOOP_ADAPTATION = AdaptationSettings(forgetting=0.999, filter_hz=10.0, v_min=0.05, p0=100.0,
                                     scale_bounds=(0.0, 5.0), offset_bounds=(-1.0, 1.0))


@dataclass(frozen=True)
class Wall:
    """A planar wall: ``normal`` (unit vector out of the wall, finger base frame), ``point`` on
    its surface (m), ``stiffness`` (N/m) and ``damping`` (N·s/m)."""

    normal: tuple
    point: tuple
    stiffness: float
    damping: float = 0.0

    def __post_init__(self):
        n = np.asarray(self.normal, dtype=np.float64)
        if n.shape != (3,) or not np.isfinite(n).all() or np.linalg.norm(n) == 0:
            raise ModelError(f"wall normal: expected a non-zero 3-vector, found {self.normal!r}")
        object.__setattr__(self, "normal", tuple(n / np.linalg.norm(n)))
        p = np.asarray(self.point, dtype=np.float64)
        if p.shape != (3,) or not np.isfinite(p).all():
            raise ModelError(f"wall point: expected a 3-vector, found {self.point!r}")
        object.__setattr__(self, "point", tuple(p))
        if not (self.stiffness > 0 and self.damping >= 0):
            raise ModelError("wall stiffness must be > 0 and damping >= 0, found "
                             f"{self.stiffness!r}, {self.damping!r}")


def model_friction_tables(finger: DLRFinger, v_max: float = 8.0, n: int = 200) -> tuple:
    """The finger's own kinetic friction as lookup tables (base1, base2, distal): its Appendix G
    tables with their scale factors, or its Stribeck/LuGre/no-friction curve tabulated on
    ±[v_max/n·…, v_max] rad/s — the default model of the controller's friction compensation."""
    if finger.friction == "table":
        return tuple(t.scaled(finger.parameters.value(f"scale_{a}"))
                     for t, a in zip(finger.tables, ACTUATORS))
    v = np.geomspace(v_max / n, v_max, n)
    v = np.r_[-v[::-1], v]
    return tuple(FrictionTable(v, finger.kinetic_friction(a, v),
                               name=f"{finger.friction} friction, {a}")
                 for a in ACTUATORS)


#: the closed loop's output columns: (names, unit) of each block of
#: :data:`~gripkit.systems.dlr_hit.finger.LOOP_OUTPUT_BLOCKS`, in that order (the kernels write
#: block b from column ``YL.b`` on)
LOOP_OUTPUTS = {
    "angle": (["abd", "flex", "prox"], "rad"),
    "velocity": (["abd_vel", "flex_vel", "prox_vel"], "rad/s"),
    "tip": (["tip_x", "tip_y", "tip_z"], "m"),
    "tip_velocity": (["tip_vx", "tip_vy", "tip_vz"], "m/s"),
    "force": (["force_x", "force_y", "force_z"], "N"),
    "pwm": ([f"pwm_{a}" for a in ACTUATORS], "1"),
    "tau_cmd": ([f"tau_cmd_{a}" for a in ACTUATORS], "N*m"),
    "fric": ([f"fric_{a}" for a in ACTUATORS], "N*m"),
    "tau": ([f"tau_{a}" for a in ACTUATORS], "N*m"),
    "scale_hat": ([f"scale_hat_{a}" for a in ACTUATORS], "1"),
    "offset_hat": ([f"offset_hat_{a}" for a in ACTUATORS], "N*m"),
    "adapt_status": ([f"adapt_status_{a}" for a in ACTUATORS], "1"),
    "fric_ff": ([f"fric_ff_{a}" for a in ACTUATORS], "N*m"),
}


def simulate_impedance(finger: DLRFinger, controller: ImpedanceController, reference,
                       reference_velocity=None, *, dt: float = 1e-3, x0=None,
                       wall: Wall | None = None, substeps: int = 1,
                       friction_drift: FrictionDrift | None = None) -> Trajectory:
    """Closed-loop simulation of ``finger`` under ``controller``.

    Parameters
    ----------
    reference
        (N, 3) set points sampled at ``dt``: joint angles (rad; abduction, flexion, proximal) for a
        joint controller, fingertip positions in the finger base frame (m) for a Cartesian one.
    reference_velocity
        (N, 3) their time derivatives (default: central differences of ``reference``).
    x0
        Initial finger state (default: at rest at the first joint reference, or at the finger's
        default state for a Cartesian reference).
    wall
        Optional :class:`Wall`.
    friction_drift
        Optional :class:`~gripkit.systems.dlr_hit.friction_drift.FrictionDrift`: the plant's
        friction changes over time (s from the first sample), unknown to the controller.

    Returns a Trajectory with joint angles (``abd``, ``flex``, ``prox``) and velocities, fingertip
    position and velocity (``tip_x``..), contact force on the finger (``force_x``.., N), PWM
    commands (``pwm_base1``..), commanded actuator torques (``tau_cmd_*``), friction (``fric_*``)
    and the motor torques delivered (``tau_*``, N·m), the friction estimate after each step
    (``scale_hat_*``, ``offset_hat_*`` in N·m; 1 and 0 without adaptation), the estimator's status
    (``adapt_status_*``: 1 updated, 0 frozen, −1 skipped), the friction feed-forward torque
    (``fric_ff_*``, N·m), the references (``ref_*``) and, with a drift, the plant's friction
    scale and offset (``drift_scale_*``, ``drift_offset_*``).
    """
    ref, refd, x = (_checked_loop_inputs(finger, controller, reference, reference_velocity, dt, x0,
                                         substeps))
    th = finger.theta()
    tables = controller.friction_tables or model_friction_tables(finger)
    N = ref.shape[0]
    t = np.arange(N) * dt
    drift = _drift_schedule(finger, friction_drift, t)
    plant = PlantDrift(drift, th.copy(), finger._tab.values.copy())
    ad = controller.adaptation
    settings = ad if ad is not None else AdaptationSettings()
    J = np.ascontiguousarray(np.diag(finger.chain().mass_matrix(x[:3])))
    cfg = settings.vector(float(dt)) if ad is not None else np.zeros(10)
    estimator = FrictionEstimator(cfg, J, *settings.initial_state(3))
    y = np.empty((N, 3 * len(LOOP_OUTPUT_BLOCKS)))
    gains = np.zeros(N_GAINS)
    gains[:14] = [*controller.stiffness, *controller.damping,
                  float(controller.gravity_compensation),
                  float(controller.friction_compensation), controller.velocity_deadband,
                  controller.smoothing, *controller.actuator_damping, float(ad is not None)]
    sensor = _sensor_state(finger, controller, x, gains, dt)
    ctrl = CARTESIAN_IMPEDANCE if controller.kind == "cartesian" else JOINT_IMPEDANCE
    loop = ImpedanceLoop(ctrl, gains, table_arrays(tables), ref, refd, _wall_vector(wall), sensor,
                         np.zeros(NX))
    fail = finger_run(th, FRICTION_MODES[finger.friction], finger.thermal, finger._tab,
                      np.zeros((1, 3)), 0,
                      float(dt), int(substeps), x, y, 0, loop, plant, estimator)
    if fail or not np.isfinite(y).all():
        raise SimulationError(f"closed loop diverged at sample {max(int(fail) - 1, 0)}",
                              hint="lower the gains or check stability_margins")
    return _loop_trajectory(t, y, ref, drift, finger, controller, dt)


def _sensor_state(finger, controller, x, gains, dt) -> np.ndarray:
    """The controller's sensing and thermal-observer settings (into ``gains``) and initial state
    (3, 7): T̂_lo, T̂_hi, the last quantised angle, the filtered velocity, ρ̂, the guard flag and
    the estimator's update count
    (ρ̂ = 1 and no guard without an observer)."""
    sensor = np.zeros((3, 7))
    sensor[:, 4] = 1.0
    if controller.sensing is not None:
        gains[G_QUANTUM] = controller.sensing.resolution
        gains[G_VALPHA] = 1.0 - math.exp(-2 * math.pi * controller.sensing.filter_hz * dt)
    ob = controller.thermal
    if ob is not None:
        v = finger.parameters.value
        lo, hi = ob.initial if ob.initial is not None else (v("T_amb"), v("T_ref"))
        a = v("alpha_R") if ob.alpha_R is None else ob.alpha_R
        T_ref, T_amb = v("T_ref"), v("T_amb")
        r_lo, r_hi = ((1 + a * (T_ref - T_amb)) / (1 + a * (T - T_amb)) for T in (hi, lo))
        sensor[:, 0], sensor[:, 1] = lo, hi
        sensor[:, 4] = 0.5 * (r_lo + r_hi)
        sensor[:, 5] = float(r_hi - r_lo > ob.guard * sensor[0, 4])
        gains[G_THERMAL] = 1.0
        gains[G_GUARD] = ob.guard
        gains[G_COMMAND] = float(bool(ob.command))
        gains[G_OBS_ALPHA] = a
        gains[G_OBS_RTH] = v("R_th") if ob.R_th is None else ob.R_th
        gains[G_OBS_CTH] = v("C_th") if ob.C_th is None else ob.C_th
        gains[G_BAND] = ob.band
        tables = controller.friction_tables or model_friction_tables(finger)
        gains[G_FREF:G_FREF + 3] = [float(t(BAND_SPEED)) for t in tables]
        lam = (controller.adaptation or AdaptationSettings()).forgetting
        gains[G_SETTLE] = math.log(20.0) / -math.log(lam) if lam < 1.0 else 3.0 / dt
    return sensor


def _checked_loop_inputs(finger, controller, reference, reference_velocity, dt, x0, substeps):
    """The reference (N, 3), its velocity and the initial state as contiguous float64 arrays,
    after checking the finger, the step and every value."""
    if not isinstance(finger, DLRFinger):
        raise ModelError(f"finger: expected a DLRFinger, found {type(finger).__name__}")
    if finger.integrator != "semi-implicit":
        raise SimulationError("closed-loop simulation integrates the finger with "
                              "semi-implicit Euler",
                              hint="build the finger with integrator='semi-implicit'")
    ref = np.ascontiguousarray(np.asarray(reference, dtype=np.float64))
    if ref.ndim != 2 or ref.shape[1] != 3 or ref.shape[0] < 2:
        raise SimulationError(f"reference: expected shape (N, 3) with N >= 2, found {ref.shape}")
    if not np.isfinite(ref).all():
        raise SimulationError("reference contains NaN or inf")
    if not (math.isfinite(dt) and dt > 0) or int(substeps) != substeps or substeps < 1:
        raise SimulationError("dt must be > 0 s and substeps a positive integer; found "
                              f"{dt!r}, {substeps!r}")
    refd = (np.gradient(ref, dt, axis=0) if reference_velocity is None
            else np.asarray(reference_velocity, dtype=np.float64))
    if refd.shape != ref.shape or not np.isfinite(refd).all():
        raise SimulationError(f"reference_velocity: expected a finite array of shape {ref.shape}")
    if x0 is None:
        x0 = finger.state(q=ref[0]) if controller.kind == "joint" else finger.state()
    x = np.array(x0, dtype=np.float64)
    if x.shape != (NX,):
        raise SimulationError(f"x0: expected a finger state of {NX} values, found {x.shape}")
    return ref, np.ascontiguousarray(refd), x


def _wall_vector(wall: Wall | None) -> np.ndarray:
    """The kernel's wall: normal, point, stiffness, damping and a 1 when present (zeros: none)."""
    w = np.zeros(9)
    if wall is not None:
        w[:3] = wall.normal
        w[3:6] = wall.point
        w[6] = wall.stiffness
        w[7] = wall.damping
        w[8] = 1.0
    return w


def _drift_schedule(finger, friction_drift, t) -> np.ndarray:
    """The plant's friction scale and offset per sample (N, 6), or (0, 6) without a drift."""
    if friction_drift is None:
        return np.zeros((0, 6))
    if not isinstance(friction_drift, FrictionDrift):
        raise SimulationError("friction_drift: expected a FrictionDrift, found "
                              f"{type(friction_drift).__name__}")
    if finger.friction == "none":
        raise SimulationError("friction_drift: the finger has no friction to drift",
                              hint="build it with friction='table', 'stribeck' or 'lugre'")
    return np.ascontiguousarray(friction_drift.at(t))


def _loop_trajectory(t, y, ref, drift, finger, controller, dt) -> Trajectory:
    """The closed loop's output columns, the references and the plant's drift as a Trajectory."""
    ch, units = {}, {}
    for block, (names, unit) in LOOP_OUTPUTS.items():
        for k, nme in enumerate(names):
            ch[nme] = y[:, getattr(YL, block) + k]
            units[nme] = unit
    suffix = ("x", "y", "z") if controller.kind == "cartesian" else ("abd", "flex", "prox")
    for i, sfx in enumerate(suffix):
        ch[f"ref_{sfx}"] = ref[:, i]
        units[f"ref_{sfx}"] = "m" if controller.kind == "cartesian" else "rad"
    if drift.shape[0]:
        for k, a in enumerate(ACTUATORS):
            ch[f"drift_scale_{a}"], units[f"drift_scale_{a}"] = drift[:, k], "1"
            ch[f"drift_offset_{a}"], units[f"drift_offset_{a}"] = drift[:, 3 + k], "N*m"
    return Trajectory(t, ch, units, {"dt": dt, "model": finger.name, "controller": controller.kind})


# --- stability margins ----------------------------------------------------------------------------

def stability_margins(J: float, K: float, D: float, dt: float, *, viscous: float = 0.0,
                      k_env: float = 0.0, delay: int = 1, n_freq: int = 4000) -> dict:
    """Gain and phase margins of one linearised impedance axis.

    Plant P(s) = 1/(J s² + b s + k_e) sampled with a zero-order hold at ``dt``; controller
    C = K + D·(1 − z⁻¹)/dt (backward-difference velocity, as a sampled controller measures it)
    with ``delay`` samples of computation delay. Returns the gain margin (factor; inf when the
    phase never crosses −180°), phase margin (deg), the crossover frequencies (Hz), the delay
    margin (s) and whether the closed loop is stable (all closed-loop poles inside the unit
    circle)."""
    from scipy import signal as sig

    if not (J > 0 and dt > 0 and K >= 0 and D >= 0 and viscous >= 0 and k_env >= 0):
        raise ModelError("stability_margins: need J > 0, dt > 0 and non-negative gains")
    num_c = [1.0]
    den_c = [J, viscous, k_env]
    Pd = sig.cont2discrete((num_c, den_c), dt, method="zoh")
    bp = np.trim_zeros(np.ravel(Pd[0]), "f")
    ap = np.ravel(Pd[1])
    # controller in z⁻¹: C = (K + D/dt) − (D/dt) z⁻¹, times z^-delay
    bc = np.array([K + D / dt, -D / dt])
    w = np.logspace(-2, math.log10(math.pi / dt * 0.999), n_freq)
    z = np.exp(1j * w * dt)
    P = np.polyval(bp, z) / np.polyval(ap, z)
    C = (bc[0] + bc[1] / z) * z ** (-delay)
    L = P * C
    mag = np.abs(L)
    ph = np.unwrap(np.angle(L))
    # closed-loop poles: 1 + L = 0 -> ap(z)·z^(delay+1) + bp(z)·(bc0 z + bc1)·... in z
    num_L = np.polymul(bp, bc)  # bp(z)·(bc0 z + bc1) / (ap(z)·z·z^delay)
    den_L = np.polymul(ap, np.r_[1.0, np.zeros(delay + 1)])
    num_pad = np.r_[np.zeros(len(den_L) - len(num_L)), num_L] if len(num_L) < len(den_L) else num_L
    char = np.polyadd(den_L, num_pad)
    poles = np.roots(char)
    stable = bool(np.all(np.abs(poles) < 1.0))
    out = dict(gain_margin=math.inf, phase_margin_deg=math.inf, gain_crossover_hz=math.nan,
               phase_crossover_hz=math.nan, delay_margin_s=math.inf, stable=stable,
               max_pole_radius=float(np.max(np.abs(poles))))
    idx = np.flatnonzero((mag[:-1] >= 1.0) & (mag[1:] < 1.0))
    if idx.size:
        i = idx[-1]
        wc = w[i] + (w[i + 1] - w[i]) * (mag[i] - 1) / (mag[i] - mag[i + 1])
        phc = np.interp(wc, w, ph)
        pm = math.degrees(phc) + 180.0
        pm = (pm + 180.0) % 360.0 - 180.0
        out.update(phase_margin_deg=pm, gain_crossover_hz=wc / (2 * math.pi),
                   delay_margin_s=math.radians(pm) / wc if pm > 0 else 0.0)
    cross = np.flatnonzero(np.diff(np.floor((ph + math.pi) / (2 * math.pi))) != 0)
    if cross.size:
        i = cross[0]
        w180 = w[i]
        out.update(gain_margin=1.0 / float(np.interp(w180, w, mag)),
                   phase_crossover_hz=w180 / (2 * math.pi))
    return out


def impedance_margins(finger: DLRFinger, controller: ImpedanceController, q=(0.0, 0.3, 0.3), *,
                      dt: float = 1e-3, wall: Wall | None = None) -> list[dict]:
    """Stability margins per actuator at joint configuration ``q`` (rad), free or against
    ``wall``: the impedance and the wall stiffness are mapped to actuator space and the diagonal
    of each is used with the actuator's apparent inertia (diagonal of M_p)."""
    ch = finger.chain()
    G = ch.coupling.matrix
    p = np.linalg.solve(G[:3], np.asarray(q, dtype=np.float64))
    M = ch.mass_matrix(p)
    K = np.diag(controller.stiffness)
    D = np.diag(controller.damping)
    if controller.kind == "cartesian":
        Jp = ch.jacobian(p)[:3]
        Kp = Jp.T @ K @ Jp
        Dp = Jp.T @ D @ Jp
    else:
        Kp = G[:3].T @ K @ G[:3]
        Dp = G[:3].T @ D @ G[:3]
    Dp = Dp + np.diag(controller.actuator_damping)
    Ke = np.zeros((3, 3))
    if wall is not None:
        Jp = ch.jacobian(p)[:3]
        n = np.asarray(wall.normal)
        Ke = wall.stiffness * (Jp.T @ np.outer(n, n) @ Jp)
    v = finger.parameters.value
    out = []
    for k, a in enumerate(ACTUATORS):
        visc = v(f"visc_{a}") if finger.friction in ("stribeck", "lugre") else 0.0
        m = stability_margins(M[k, k], Kp[k, k], Dp[k, k], dt, viscous=visc, k_env=Ke[k, k])
        out.append(dict(actuator=a, inertia=float(M[k, k]), stiffness=float(Kp[k, k]),
                        damping=float(Dp[k, k]), k_env=float(Ke[k, k]), **m))
    return out
