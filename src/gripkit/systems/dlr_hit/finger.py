"""The complete DLR/HIT Hand II finger (``002_ddea254371185ad3.txt`` chapter 7, Fig. 7.1):
PWM → BLDC motor → transmission → friction → coupled multibody dynamics, with the velocity fed
back into the motor and friction models, and compliant end stops.

Coordinates. Three actuators (base motor 1, base motor 2, proximal/distal motor) with output
angles p = (p₁, p₂, p₃) drive the four DH joints q = (θ₁ abduction, θ₂ flexion, θ₃ proximal,
θ₄ distal) through q = Γ p: the bevel-gear differential maps the two base motors at ±45° onto
abduction and flexion (Fig. 7.2) and the distal joint follows the proximal one (θ₄ = θ₃), see
:mod:`gripkit.multibody.coupling`. Each actuator k sees

    M_p(p) p̈ = τ_m,k(PWM_k, N_k ṗ_k, T_k) + τ_stop + τ_ext − h_p(p, ṗ) − F_k(ṗ_k, p_k)

with M_p = Γᵀ M Γ + diag(I_m N_k²) (Appendix A), τ_m the motor torque of eq 5.10 (Appendix E's
guard, PWM clipped to ±4096) through the reduction N_k (208.3 distal, 234.3 base; optional
efficiency), h_p the Coriolis/centrifugal and gravity torques, and F_k friction:

* ``friction='table'`` (the thesis's model): Appendix G's lookup tables, the base table scaled by
  a correction factor for base joint 2 (§6.3, §7), stiction 0.36 N·m (Appendix F) with Karnopp
  stick-slip solved jointly for the coupled actuators (a stuck actuator is a constraint p̈_k = 0;
  it breaks away when its holding torque exceeds its stiction);
* ``friction='stribeck'``: eq 6.5 per actuator plus a cubic velocity term (the harmonic-drive
  friction model of [50] quoted in §3.2.2), with the same stiction logic;
* ``friction='lugre'``: LuGre per actuator (gripkit's addition, not the thesis's; no state
  machine; moves by a pre-sliding displacement under loads below stiction);
* ``friction='none'``: frictionless (energy-conservation studies).

An optional harmonic-drive ripple A·sin(k·p)·sign(ṗ) adds to F (§3.2.2).

End stops. The thesis's Simulink model zeroes the velocity at the end of the movement range and
notes that "the real finger has a high negative slope ... a result of the elasticity of the belts"
with "resilience ... after the braking" (§7.1). gripkit models that elasticity: beyond a joint
limit a one-sided spring-damper (k_stop, d_stop) acts on the joint; with the rotors' reflected
inertia it brakes the finger within tens of milliseconds and lets it bounce back.

Motor temperature. By default the winding stays at T_ref, where eq 5.10 holds (the thesis assumes
the operating temperature, §5.4.3); ``thermal=True`` integrates each motor's first-order thermal
model (:mod:`gripkit.models.bldc`; gripkit's, calibrated on Fig. 5.7) from the initial temperature
in the state.

Integration. Fixed steps (``substeps`` per sample): semi-implicit Euler (default; one
force evaluation per step; its speed is in docs/performance.md) or RK4
(``integrator='rk4'``) with the stick/slip set held over a step and events detected at step
boundaries.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numba
import numpy as np
from numba import prange

from ...errors import ModelError, SimulationError
from ...estimation.friction_adaptation import FrictionEstimator, friction_rls_step
from ...models.bldc import BLDCMotor, bldc_torque, motor_heat_step, temperature_factor
from ...models.friction import (FrictionTable, Stribeck, TableArrays, lugre_force, lugre_update,
                                ripple, stribeck, table_arrays, table_friction)
from ...models.transmission import transmit_torque
from ...multibody.coupling import CoupledChain, Coupling, differential_matrix
from ...multibody.dh import DHChain
from ...multibody.kernels import (WORK_PER_LINK, chain_links, cholesky_solve, coupled_mass_bias,
                                  frames_into, hot, hot_inline, joints_from_actuators, links_of,
                                  point_jacobian, rnea_pass)
from ...params import ParameterSet
from ...sim.model import Model, Signal

__all__ = ["FINGER_PARAMETERS", "ACTUATORS", "JOINTS", "FRICTION_MODES", "DLRFinger",
           "finger_step", "finger_step_rk4", "finger_setup", "finger_context", "finger_run",
           "finger_loop", "run_open_loop"]

# : parameter names in kernel order (see
# gripkit.systems.dlr_hit.parameters.thesis_finger_parameters for meaning/units)
FINGER_PARAMETERS = (
    "l1", "l2", "l3", "m1", "m2", "m3",
    "pc1_x", "pc1_y", "pc1_z", "pc2_x", "pc2_y", "pc2_z", "pc3_x", "pc3_y", "pc3_z",
    "I1_xx", "I1_yy", "I1_zz", "I2_xx", "I2_yy", "I2_zz", "I3_xx", "I3_yy", "I3_zz",
    "I_m", "beta", "g_x", "g_y", "g_z",
    "N_hd", "N_belt", "N_belt_base", "eta",
    "c_pwm", "b_pwm", "b_0", "pwm_max", "T_ref", "T_amb", "alpha_R", "k_t", "R_0", "R_th", "C_th",
    "fs_base1", "fs_base2", "fs_distal", "scale_base1", "scale_base2", "scale_distal",
    "fc_base1", "fc_base2", "fc_distal", "visc_base1", "visc_base2", "visc_distal",
    "cubic_base1", "cubic_base2", "cubic_distal", "v_s", "delta", "sigma0", "sigma1", "ripple_amp",
    "ripple_cycles", "v_stick",
    "abd_min", "abd_max", "flex_min", "flex_max", "prox_min", "prox_max", "k_stop", "d_stop",
)
NTH = len(FINGER_PARAMETERS)
ACTUATORS = ("base1", "base2", "distal")
JOINTS = ("abd", "flex", "prox")
#: friction model codes of the kernels' ``mode`` (module-level ints: numba folds them)
TABLE, STRIBECK, LUGRE, NO_FRICTION = 0, 1, 2, 3
FRICTION_MODES = {"table": TABLE, "stribeck": STRIBECK, "lugre": LUGRE, "none": NO_FRICTION}
#: integrator codes (``integ``)
SEMI_IMPLICIT, RK4 = 0, 1
INTEGRATORS = {"semi-implicit": SEMI_IMPLICIT, "rk4": RK4}
#: controller codes of :data:`ImpedanceLoop` ``ctrl``
OPEN_LOOP, JOINT_IMPEDANCE, CARTESIAN_IMPEDANCE = 0, 1, 2

#: the index of each parameter in the vector ``th`` the kernels take, by name: ``th[IX.l1]``,
#: ``th[IX.fs_base1 + k]`` for actuator k. A module-level namedtuple of ints, generated from
#: FINGER_PARAMETERS: numba freezes it as a constant, so each index folds into the address.
IX = namedtuple("FingerParameterIndex", FINGER_PARAMETERS)(*range(len(FINGER_PARAMETERS)))

# state layout: p(3) pd(3) T(3) z(3) stuck(3)
NX = 15

#: the first column of each three-column block of the closed-loop outputs (one column per joint,
#: axis or actuator), by name: ``y[n, YL.scale_hat + k]``; the column names and units are
#: :data:`gripkit.systems.dlr_hit.impedance.LOOP_OUTPUTS`, generated from the same table
LOOP_OUTPUT_BLOCKS = ("angle", "velocity", "tip", "tip_velocity", "force", "pwm", "tau_cmd",
                      "fric", "tau", "scale_hat", "offset_hat", "adapt_status", "fric_ff")
YL = namedtuple("LoopOutputIndex", LOOP_OUTPUT_BLOCKS)(*range(0, 3 * len(LOOP_OUTPUT_BLOCKS), 3))
#: the same for the 18 open-loop outputs of one finger (DLRFinger.outputs), from column ycol on
FINGER_OUTPUT_BLOCKS = ("angle", "velocity", "actuator_velocity", "tau", "fric", "temperature")
YF = (namedtuple("FingerOutputIndex", FINGER_OUTPUT_BLOCKS)(*range(0, 3 * len(FINGER_OUTPUT_BLOCKS),
                                                                   3)))

# Named records of arrays the kernels take (namedtuples: numba resolves each field at compile
# time, and without NRT taking an array out of one costs nothing; docs/performance.md).
#: one finger's constant arrays (:func:`finger_setup`): the fields of
#: :data:`gripkit.multibody.kernels.ChainArrays` (DH table, joint types, link masses, centres of
#: mass, inertias, joint armatures, coupling Γ (4×3 row-major), joint offsets, actuator armatures
#: I_m·N², gravity) and the reductions N
FingerChain = namedtuple("FingerChain", "links jtype mass com inertia arm_q G q0 arm_p g ratio")
#: scratch of the chain: link rotations and positions, RNEA/CRBA work, joint angles and rates,
#: zeros, joint-space mass matrix and torques
ChainWork = namedtuple("ChainWork", "R P work q qd zq Mq tau")
#: scratch of the actuator-space solve: M_p, h_p, Cholesky factor, applied torques, the free
#: subsystem (matrix, solution, right side) and the breakaway directions
SolveWork = namedtuple("SolveWork", "Mp hp L rhs Ms xs rs dirn")
#: the state one force evaluation reads (views of the state vector, or an RK4 stage): actuator
#: positions and rates, motor temperatures, LuGre bristles and the stuck flags (3 each)
FingerState = namedtuple("FingerState", "p pd T z stuck")
#: a run of the time loop: PWM input u (N, ·) read from column ``ucol`` on, outputs y written
#: from column ``ycol`` on, the sample time dt and the integration substeps per sample
FingerRun = namedtuple("FingerRun", "u ucol y ycol dt substeps")
#: what one force evaluation writes: accelerations, motor torques (output side), shaft torques,
#: friction torques (all per actuator)
Forces = namedtuple("Forces", "acc taum tshaft fric")
#: scratch of one integration step: the two records above, the accelerations and shaft torques,
#: the start-of-step state, the RK4 stage accelerations (4×3), stage state and stage torques
StepWork = namedtuple("StepWork", "chain solve acc tshaft p0 v0 ka ps vs taum2 tshaft2 fric2")
#: scratch of the time loop and the impedance controller: joint angles and rates, link frames,
#: homogeneous transforms, Jacobians (joint and actuator space), tip position and velocity,
#: commanded torques, gravity torques, RNEA work, zeros, the state at t_n, the PWM, external and
#: motor torques, friction, the bias torques of the friction estimator, the friction feed-forward
#: and the wall's contact force
LoopWork = namedtuple("LoopWork", "q qd R P T J Jp tip tipd tauq gp work zq xs pwm "
                                  "ext taum fric hb "
                                  "ff force")
#: a closed loop: ``ctrl`` (0 open loop, 1 joint, 2 Cartesian impedance), its gains vector, the
#: friction tables it compensates with (TableArrays), the reference and its velocity (N, 3), the
#: wall (nx, ny, nz, px, py, pz, k, d, on), the controller's sensing and thermal observer state
#: ``sensor`` (3, 7) per actuator = (T̂_lo, T̂_hi, last quantised angle, filtered velocity, ρ̂,
#: guard: 1 while the torque factor is too uncertain to adapt, the estimator's updates so far)
#: and the measured state ``xm`` (NX)
ImpedanceLoop = namedtuple("ImpedanceLoop", "ctrl gains tables ref refd wall sensor xm")
#: indices of the gains vector beyond the impedance gains (see gripkit.systems.dlr_hit.impedance)
G_ADAPT = 13
G_THERMAL = 14
G_QUANTUM = 15
G_VALPHA = 16
G_GUARD = 17
G_COMMAND = 18
G_OBS_ALPHA = 19
G_OBS_RTH = 20
G_OBS_CTH = 21
#: the thermal observer's significance band on the friction estimate, and the compensation
#: tables' kinetic friction at the band's reference speed (3 slots, N·m)
G_BAND = 22
G_FREF = 23
#: the number of estimator updates after which an estimate counts as settled (band test)
G_SETTLE = 26
N_GAINS = 27
#: the plant's friction drift: schedule (N, 6) = (s_k, Δ_k) or (0, 6), and working copies of the
#: parameter vector and the table values
PlantDrift = namedtuple("PlantDrift", "schedule th values")


@hot
def finger_setup(th, fc):  # pragma: no cover - compiled
    """Fill the chain, coupling and drive arrays of one finger (:data:`FingerChain`) from its
    parameter vector."""
    dh, mass, com, inertia, G, arm_p, grav, ratio = (fc.links, fc.mass, fc.com, fc.inertia, fc.G,
                                                     fc.arm_p, fc.g, fc.ratio)
    for k in range(4):
        for j in range(4):
            dh[k, j] = 0.0
        dh[k, 4] = 1.0  # cos α
        dh[k, 5] = 0.0  # sin α
        mass[k] = 0.0
        for j in range(3):
            com[k, j] = 0.0
        for j in range(6):
            inertia[k, j] = 0.0
    dh[1, 0] = -0.5 * math.pi  # α1 = −90°: flexion axis ⟂ abduction axis (Appendix A, Rx(−90°))
    dh[1, 4] = 0.0
    dh[1, 5] = -1.0
    dh[2, 1] = th[IX.l1]  # a2 = l1
    dh[3, 1] = th[IX.l2]  # a3 = l2
    for k in range(3):
        mass[k + 1] = th[IX.m1 + k]
        for j in range(3):
            com[k + 1, j] = th[IX.pc1_x + 3 * k + j]
            inertia[k + 1, j] = th[IX.I1_xx + 3 * k + j]
    # Γ (4×3, row-major): differential on (abd, flex) × (base1, base2), θ3 = θ4 = p3
    b = th[IX.beta]
    a00 = math.sin(-b)
    a01 = math.sin(b)
    a10 = math.cos(-b)
    a11 = math.cos(b)
    det = a00 * a11 - a01 * a10
    # Γ = A^{-T}: inv(A) = [[a11, -a01], [-a10, a00]]/det, transposed
    for k in range(12):
        G[k] = 0.0
    G[0] = a11 / det
    G[1] = -a10 / det
    G[3] = -a01 / det
    G[4] = a00 / det
    G[8] = 1.0
    G[11] = 1.0
    nd = th[IX.N_hd] * th[IX.N_belt]
    nb = nd * th[IX.N_belt_base]
    ratio[0] = nb
    ratio[1] = nb
    ratio[2] = nd
    for k in range(3):
        arm_p[k] = th[IX.I_m] * ratio[k] * ratio[k]
        grav[k] = th[IX.g_x + k]


@hot
def _kinetic(th, k, v, p, mode, tab):  # pragma: no cover - compiled
    """Kinetic friction of actuator k at velocity v (never 0 for v ≠ 0)."""
    if mode == TABLE:
        f = th[IX.scale_base1 + k] * table_friction(v, tab.velocity[k], tab.values[k],
                                                    tab.length[k],
                                                    tab.ipos[k])
    else:
        f = (stribeck(v, th[IX.fc_base1 + k], th[IX.fs_base1 + k], th[IX.v_s], th[IX.delta],
                      th[IX.visc_base1 + k])
             + th[IX.cubic_base1 + k] * v * v * v)
    return f + ripple(p, v, th[IX.ripple_amp], th[IX.ripple_cycles], 0.0)


@hot_inline
def _drive_torques(th, thermal, ratio, T, pwm, pd, taum, tshaft):  # pragma: no cover - compiled
    """Each motor through its transmission (eqs 5.7, 5.9; thermal derating with ``thermal``):
    shaft torques ``tshaft`` and the output-side torques ``taum``."""
    for k in range(3):
        rho = 1.0
        if thermal:
            rho = temperature_factor(T[k], th[IX.T_ref], th[IX.T_amb], th[IX.alpha_R])
        ts = bldc_torque(pwm[k], ratio[k] * pd[k], th[IX.c_pwm], th[IX.b_pwm], th[IX.b_0],
                         th[IX.pwm_max],
                         rho)
        tshaft[k] = ts
        taum[k] = transmit_torque(ts, pd[k], ratio[k], th[IX.eta])


@hot_inline
def _add_end_stops(th, q, qd, G, rhs):  # pragma: no cover - compiled
    """Spring-damper end stops on θ1, θ2, θ3 (θ4 = θ3), one-sided, mapped onto the actuators."""
    ks = th[IX.k_stop]
    ds = th[IX.d_stop]
    for j in range(3):
        lo = th[IX.abd_min + 2 * j]
        hi = th[IX.abd_min + 2 * j + 1]
        ts = 0.0
        if q[j] > hi:
            ts = -ks * (q[j] - hi) - ds * qd[j]
            if ts > 0.0:
                ts = 0.0
        elif q[j] < lo:
            ts = ks * (lo - q[j]) - ds * qd[j]
            if ts < 0.0:
                ts = 0.0
        if ts != 0.0:
            for k in range(3):
                rhs[k] += G[j * 3 + k] * ts


@hot
def _karnopp(th, n_stuck_iter, mode, tab, p, pd, stuck, out, sw):  # pragma: no cover - compiled
    """Karnopp stick-slip: actuators at rest (flagged, or exactly zero velocity) are constraints;
    the free subsystem is solved, and the stuck actuator whose holding torque exceeds its stiction
    most is released, up to ``n_stuck_iter`` times (0: the set stays frozen, for RK4 stages).
    Writes ``out.acc`` and ``out.fric`` (the holding torque of a stuck actuator)."""
    acc, fric = out.acc, out.fric
    Mp, L, rhs, Ms, xs, rs, dirn = sw.Mp, sw.L, sw.rhs, sw.Ms, sw.xs, sw.rs, sw.dirn
    m = 3
    frozen = n_stuck_iter == 0
    if not frozen:
        for k in range(m):
            dirn[k] = 0.0
            if pd[k] == 0.0:
                stuck[k] = 1.0
            elif stuck[k] != 0.0:
                stuck[k] = 0.0
    for _ in range(max(n_stuck_iter, 1)):
        # solve the free subsystem
        nf = 0
        for k in range(m):
            if stuck[k] == 0.0:
                v = pd[k]
                if v == 0.0:
                    v = dirn[k] * 1e-300
                fric[k] = _kinetic(th, k, v, p[k], mode, tab)
        for i in range(m):
            if stuck[i] != 0.0:
                continue
            ni = 0
            for j in range(m):
                if stuck[j] == 0.0:
                    Ms[nf, ni] = Mp[i, j]
                    ni += 1
            rs[nf] = rhs[i] - fric[i]
            nf += 1
        if nf > 0:
            if not cholesky_solve(nf, Ms, rs, xs, L):
                return False
        c = 0
        for k in range(m):
            if stuck[k] == 0.0:
                acc[k] = xs[c]
                c += 1
            else:
                acc[k] = 0.0
        # holding torque of each stuck actuator; release the one that exceeds stiction most
        worst = -1
        excess = 1.0
        for k in range(m):
            if stuck[k] == 0.0:
                continue
            lam = rhs[k]
            for j in range(m):
                if stuck[j] == 0.0:
                    lam -= Mp[k, j] * acc[j]
            fric[k] = lam
            fs = th[IX.fs_base1 + k]
            r = abs(lam) / fs if fs > 0.0 else (math.inf if lam != 0.0 else 0.0)
            if r > excess:
                excess = r
                worst = k
        if worst < 0 or frozen:
            return True
        stuck[worst] = 0.0
        dirn[worst] = 1.0 if fric[worst] > 0.0 else -1.0
    return True


@hot
def _forces(th, n_stuck_iter, mode, thermal, fc, tab, st, pwm, ext, out, cw,
            sw):  # pragma: no cover - compiled
    """Accelerations ``out.acc`` for the state ``st`` (:data:`FingerState`: p, ṗ, T, z) with the
    stuck set ``st.stuck``; fills the motor torques (output side and shaft) and friction of ``out``
    (:data:`Forces`). ``fc`` is the finger's :data:`FingerChain`, ``tab`` its friction tables,
    ``cw``/``sw`` scratch
    (:data:`ChainWork`, :data:`SolveWork`). With ``n_stuck_iter > 0`` actuators at rest are
    flagged and those whose holding torque exceeds stiction are released (the flags change in
    place, ``sw.dirn`` records the breakaway direction); ``n_stuck_iter = 0`` keeps the set
    frozen (RK4 stages)."""
    m = 3
    G = fc.G
    p, pd, T, z, stuck = st.p, st.pd, st.T, st.z, st.stuck
    q, qd, zq = cw.q, cw.qd, cw.zq
    Mp, hp, rhs, rs = sw.Mp, sw.hp, sw.rhs, sw.rs
    joints_from_actuators(4, m, G, fc.q0, p, q)
    joints_from_actuators(4, m, G, zq, pd, qd)
    chain_links(4, fc.links, fc.jtype, q, cw.R, cw.P)
    coupled_mass_bias(4, m, links_of(fc), G, fc.arm_p, cw, qd, fc.g[0], fc.g[1], fc.g[2], Mp, hp)
    taum, fric = out.taum, out.fric
    _drive_torques(th, thermal, fc.ratio, T, pwm, pd, taum, out.tshaft)
    # applied torque on each actuator (before friction): motor + end stops + external − bias
    for k in range(m):
        rhs[k] = taum[k] + ext[k] - hp[k]
    _add_end_stops(th, q, qd, G, rhs)
    if mode >= LUGRE:  # LuGre or none: no stick-slip constraint
        for k in range(m):
            if mode == LUGRE:
                f = (lugre_force(z[k], pd[k], th[IX.fc_base1 + k], th[IX.fs_base1 + k], th[IX.v_s],
                                 th[IX.sigma0],
                                 th[IX.sigma1], th[IX.visc_base1 + k])
                     + ripple(p[k], pd[k], th[IX.ripple_amp], th[IX.ripple_cycles], 0.0))
            else:
                f = 0.0
            fric[k] = f
            rs[k] = rhs[k] - f
        return cholesky_solve(m, Mp, rs, out.acc, sw.L)
    return _karnopp(th, n_stuck_iter, mode, tab, p, pd, stuck, out, sw)


def _make_context(th):
    """Constant arrays of one finger (:data:`FingerChain`), the plant's scratch
    (:data:`StepWork`) and the time loop's (:data:`LoopWork`): ``(fc, ws, cs)``. Plain numpy
    code, run by Python for single simulations (no compilation) and compiled as
    :func:`finger_context` for the parallel kernels."""
    fc = FingerChain(np.empty((4, 6)), np.zeros(4, dtype=np.int64), np.empty(4), np.empty((4, 3)),
                     np.empty((4, 6)), np.zeros(4), np.empty(12), np.zeros(4), np.empty(3),
                     np.empty(3), np.empty(3))
    finger_setup(th, fc)
    cw = ChainWork(np.empty((4, 9)), np.empty((4, 3)), np.empty(WORK_PER_LINK * 4), np.empty(4),
                   np.empty(4), np.zeros(4), np.empty((4, 4)), np.empty(4))
    sw = SolveWork(np.empty((3, 3)), np.empty(3), np.empty((3, 3)), np.empty(3), np.empty((3, 3)),
                   np.empty(3), np.empty(3), np.empty(3))
    ws = StepWork(cw, sw, np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty(12),
                  np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty(3))
    cs = LoopWork(np.empty(4), np.empty(4), np.empty((4, 9)), np.empty((4, 3)), np.empty((4, 16)),
                  np.empty((6, 4)), np.empty((3, 3)), np.empty(3), np.empty(3), np.empty(3),
                  np.empty(4), np.empty(WORK_PER_LINK * 4), np.zeros(4), np.empty(NX), np.empty(3),
                  np.zeros(3), np.zeros(3), np.zeros(3), np.empty(4), np.zeros(3), np.zeros(3))
    return fc, ws, cs


finger_context = numba.njit(cache=True, error_model="numpy")(_make_context)


@hot
def _slow_states(th, mode, thermal, x, v0, tshaft, h):  # pragma: no cover - compiled
    """Motor temperatures (explicit step) and LuGre bristles (exact for v held over the step)."""
    if thermal:
        for k in range(3):
            x[6 + k] = motor_heat_step(x[6 + k], tshaft[k], h, th[IX.T_amb], th[IX.alpha_R],
                                       th[IX.R_0],
                                       th[IX.k_t], th[IX.R_th], th[IX.C_th])
    if mode == LUGRE:
        for k in range(3):
            x[9 + k] = lugre_update(x[9 + k], v0[k], h, th[IX.fc_base1 + k], th[IX.fs_base1 + k],
                                    th[IX.v_s],
                                    th[IX.sigma0])


@hot
def _stick(th, mode, x, v0):  # pragma: no cover - compiled
    """Karnopp: a sliding actuator whose velocity crosses zero comes to rest; if its holding torque
    exceeds stiction it breaks away again at the next step."""
    if mode < LUGRE:  # table or Stribeck: Karnopp stick-slip
        vst = th[IX.v_stick]
        for k in range(3):
            if x[12 + k] == 0.0 and (x[3 + k] * v0[k] < 0.0 or abs(x[3 + k]) <= vst):
                x[3 + k] = 0.0
                x[12 + k] = 1.0


@hot
def finger_step(th, mode, thermal, fc, tab, x, pwm, ext, h, taum, fric,
                ws):  # pragma: no cover - compiled
    """Advance one finger's state ``x`` (15) by one semi-implicit Euler step h under PWM (3) and
    external actuator torques ``ext`` (3); ``taum``/``fric`` receive the motor and friction
    torques at the start of the step. ``fc``, ``ws`` come from :func:`finger_context`, ``tab``
    is the finger's :data:`~gripkit.models.friction.TableArrays`. Returns False if the mass
    matrix lost positive definiteness."""
    acc, v0 = ws.acc, ws.v0
    st = FingerState(x[0:3], x[3:6], x[6:9], x[9:12], x[12:15])
    if not _forces(th, 4, mode, thermal, fc, tab, st, pwm, ext, Forces(acc, taum, ws.tshaft, fric),
                   ws.chain, ws.solve):
        return False
    for k in range(3):
        v0[k] = x[3 + k]
        x[3 + k] = v0[k] + h * acc[k]
    _stick(th, mode, x, v0)
    for k in range(3):
        x[k] += h * x[3 + k]
    _slow_states(th, mode, thermal, x, v0, ws.tshaft, h)
    return True


@hot
def finger_step_rk4(th, mode, thermal, fc, tab, x, pwm, ext, h, taum, fric,
                    ws):  # pragma: no cover - compiled
    """As :func:`finger_step` with classical RK4 on (p, ṗ); the stick/slip set is decided at the
    start of the step and frozen over it (stuck actuators keep v = 0, a = 0); sticking is
    detected at the end."""
    acc, p0, v0, ka, ps, vs = ws.acc, ws.p0, ws.v0, ws.ka, ws.ps, ws.vs
    stuck = x[12:15]
    T = x[6:9]
    z = x[9:12]
    st = FingerState(x[0:3], x[3:6], T, z, stuck)
    if not _forces(th, 4, mode, thermal, fc, tab, st, pwm, ext, Forces(acc, taum, ws.tshaft, fric),
                   ws.chain, ws.solve):
        return False
    for k in range(3):
        p0[k] = x[k]
        v0[k] = x[3 + k]
        ka[k] = acc[k]
    # stage s uses p = p0 + c·v_s, v = v0 + c·a_s with c = h/2, h/2, h
    for stage in range(3):
        c = 0.5 * h if stage < 2 else h
        for k in range(3):
            if stuck[k] != 0.0:
                ps[k] = p0[k]
                vs[k] = 0.0
                continue
            ps[k] = p0[k] + c * (v0[k] if stage == 0 else vs[k])
            vs[k] = v0[k] + c * ka[3 * stage + k]
        _forces(th, 0, mode, thermal, fc, tab, FingerState(ps, vs, T, z, stuck), pwm, ext,
                Forces(acc, ws.taum2, ws.tshaft2, ws.fric2), ws.chain, ws.solve)
        for k in range(3):
            ka[3 * (stage + 1) + k] = acc[k]
    for k in range(3):
        if stuck[k] != 0.0:
            x[3 + k] = 0.0
            continue
        a1 = ka[k]
        a2 = ka[3 + k]
        a3 = ka[6 + k]
        a4 = ka[9 + k]
        x[k] = p0[k] + h * v0[k] + h * h / 6.0 * (a1 + a2 + a3)
        x[3 + k] = v0[k] + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
    _stick(th, mode, x, v0)
    _slow_states(th, mode, thermal, x, v0, ws.tshaft, h)
    return True


@hot
def finger_outputs(G, q0, x, taum, fric, y, yrow, ycol):  # pragma: no cover - compiled
    """Write the 18 outputs of one finger (see DLRFinger.outputs) into y[yrow, ycol:ycol+18]."""
    for j in range(3):
        s = q0[j]
        sd = 0.0
        for k in range(3):
            s += G[j * 3 + k] * x[k]
            sd += G[j * 3 + k] * x[3 + k]
        y[yrow, ycol + YF.angle + j] = s
        y[yrow, ycol + YF.velocity + j] = sd
    for k in range(3):
        y[yrow, ycol + YF.actuator_velocity + k] = x[3 + k]
        y[yrow, ycol + YF.tau + k] = taum[k]
        y[yrow, ycol + YF.fric + k] = fric[k]
        y[yrow, ycol + YF.temperature + k] = x[6 + k]


# --- impedance control (used by gripkit.systems.dlr_hit.impedance)
# ----------------------------------------

@hot
def _tip(fc, th, q, R, P, T, J, Jp, tip):  # pragma: no cover - compiled
    """Fingertip position ``tip`` (3, finger base frame) and actuator-space linear Jacobian
    ``Jp`` (3×3) at the joint angles ``q`` (scratch: link frames R, P, transforms T, Jacobian J)."""
    jt, G = fc.jtype, fc.G
    chain_links(4, fc.links, jt, q, R, P)
    frames_into(4, R, P, T)
    l3 = th[IX.l3]
    px = T[3, 3] + T[3, 0] * l3
    py = T[3, 7] + T[3, 4] * l3
    pz = T[3, 11] + T[3, 8] * l3
    tip[0] = px
    tip[1] = py
    tip[2] = pz
    point_jacobian(4, jt, T, px, py, pz, J)
    for r in range(3):
        for j in range(3):
            s = 0.0
            for k in range(4):
                s += J[r, k] * G[k * 3 + j]
            Jp[r, j] = s


@hot
def _pwm_for(tau_out, omega_m, N, th):  # pragma: no cover - compiled
    """PWM that yields output torque ``tau_out`` at motor speed omega_m (inverse of eq 5.10 at
    T_ref), clipped to ±pwm_max."""
    c = th[IX.c_pwm]
    b1 = th[IX.b_pwm]
    b0 = th[IX.b_0]
    pmax = th[IX.pwm_max]
    tm = tau_out / N
    den = c + b1 * omega_m
    u = (tm - b0 * omega_m) / den if den > 0.0 else pmax
    if u < 0.0:
        den = c - b1 * omega_m
        u = (tm - b0 * omega_m) / den if den > 0.0 else -pmax
        if u > 0.0:
            u = 0.0
    if u > pmax:
        u = pmax
    elif u < -pmax:
        u = -pmax
    return u


@hot_inline
def _impedance(th, fc, cs, x, n, loop, fhat):  # pragma: no cover - compiled
    """Impedance law (joint: loop.ctrl = 1, Cartesian: 2) with gravity and friction compensation
    F̂(v) = s·F_table(v) + o·sign(v), (s, o) = ``fhat[k]`` → PWM in ``cs.pwm``; the commanded
    torques stay in ``cs.tauq``, the friction feed-forward in ``cs.ff`` (see
    gripkit.systems.dlr_hit.impedance)."""
    G, ratio, grav = fc.G, fc.ratio, fc.g
    q, qd, R, P, Jp, tip, tipd, tauq, zq = (cs.q, cs.qd, cs.R, cs.P, cs.Jp, cs.tip, cs.tipd,
                                            cs.tauq, cs.zq)
    ctrl, gains, ref, refd, ctab = loop.ctrl, loop.gains, loop.ref, loop.refd, loop.tables
    joints_from_actuators(4, 3, G, fc.q0, x[0:3], q)
    joints_from_actuators(4, 3, G, zq, x[3:6], qd)
    _tip(fc, th, q, R, P, cs.T, cs.J, Jp, tip)
    for r in range(3):
        s = 0.0
        for j in range(3):
            s += Jp[r, j] * x[3 + j]
        tipd[r] = s
        tauq[r] = 0.0
    if ctrl == CARTESIAN_IMPEDANCE:
        for r in range(3):
            f = gains[r] * (ref[n, r] - tip[r]) + gains[3 + r] * (refd[n, r] - tipd[r])
            for j in range(3):
                tauq[j] += Jp[r, j] * f
    else:
        for j in range(3):  # τ_p = Γ_qᵀ τ_q on (θ1, θ2, θ3)
            f = gains[j] * (ref[n, j] - q[j]) + gains[3 + j] * (refd[n, j] - qd[j])
            for k in range(3):
                tauq[k] += G[j * 3 + k] * f
    for k in range(3):  # joint-space damping on the actuators (damps directions J_p makes soft)
        tauq[k] -= gains[10 + k] * x[3 + k]
    if gains[6] != 0.0:
        gp = cs.gp
        rnea_pass(4, links_of(fc), R, P, zq, zq, grav[0], grav[1], grav[2], False, gp, cs.work)
        for k in range(3):
            s = 0.0
            for j in range(4):
                s += G[j * 3 + k] * gp[j]
            tauq[k] += s
    vdb = gains[8]
    eps = gains[9]
    ff = cs.ff
    pwm = cs.pwm
    for k in range(3):
        tau = tauq[k]
        ff[k] = 0.0
        if gains[7] != 0.0 and tau != 0.0:
            # compensate only in the direction the impedance pushes (never into a reversal)
            v = x[3 + k]
            if v * tau >= 0.0:
                if abs(v) < vdb:
                    v = vdb if tau > 0.0 else -vdb
                s_k, o_k = _applied_estimate(fhat, gains, loop.sensor, k)
                fk = s_k * table_friction(v, ctab.velocity[k], ctab.values[k], ctab.length[k],
                                          ctab.ipos[k])
                fk += o_k if v > 0.0 else -o_k
                ff[k] = fk * math.tanh(abs(tau) / eps)
                tau += ff[k]
        tauq[k] = tau
        # with gains[G_COMMAND] the thermal observer's torque factor ρ̂ corrects the inversion
        rho = loop.sensor[k, 4] if gains[G_COMMAND] != 0.0 else 1.0
        pwm[k] = _pwm_for(tau / rho, ratio[k] * x[3 + k], ratio[k], th)


@hot_inline
def _wall(th, fc, cs, x, wall):  # pragma: no cover - compiled
    """Contact force of a planar wall (nx, ny, nz, px, py, pz, k, d, on) on the fingertip, mapped
    to the actuators: ``cs.ext`` = J_pᵀ F; ``cs.force`` receives F (finger base frame)."""
    Jp, tip, ext, force = cs.Jp, cs.tip, cs.ext, cs.force
    for k in range(3):
        ext[k] = 0.0
        force[k] = 0.0
    if wall[8] == 0.0:
        return
    joints_from_actuators(4, 3, fc.G, fc.q0, x[0:3], cs.q)
    _tip(fc, th, cs.q, cs.R, cs.P, cs.T, cs.J, cs.Jp, cs.tip)
    pen = (-(wall[0] * (tip[0] - wall[3]) + wall[1] * (tip[1] - wall[4]) + wall[2]
             * (tip[2] - wall[5])))
    if pen <= 0.0:
        return
    vn = 0.0
    for r in range(3):
        s = 0.0
        for j in range(3):
            s += Jp[r, j] * x[3 + j]
        vn += wall[r] * s
    fmag = wall[6] * pen - wall[7] * vn  # δ̇ = −n·ẋ
    if fmag < 0.0:
        fmag = 0.0
    for r in range(3):
        force[r] = fmag * wall[r]
    for j in range(3):
        ext[j] = Jp[0, j] * force[0] + Jp[1, j] * force[1] + Jp[2, j] * force[2]


@hot_inline
def _applied_estimate(fhat, gains, sensor, k):  # pragma: no cover - compiled
    """The (scale, offset) the compensation applies for actuator k: the estimate, unless a
    band gains[G_BAND] > 0 is set and the estimate is not yet settled (fewer than
    gains[G_SETTLE] updates, ``sensor[k, 6]``) or not significant (the estimated kinetic friction
    at the band's reference speed, ŝ·F_ref + ô, within ±band of the table's
    F_ref = gains[G_FREF + k]): then the table is applied as identified, (1, 0)."""
    s_k, o_k = fhat[k, 0], fhat[k, 1]
    band = gains[G_BAND]
    if band > 0.0:
        if sensor[k, 6] < gains[G_SETTLE]:
            return 1.0, 0.0
        if abs(s_k + o_k / gains[G_FREF + k] - 1.0) <= band:
            return 1.0, 0.0
    return s_k, o_k


@hot
def _adapt_friction(th, fc, cs, x, ctab, est, sensor, y, n):  # pragma: no cover - compiled
    """One step of the online friction estimator ``est`` (:data:`FrictionEstimator`) per actuator
    (after :func:`_impedance`, whose chain arrays R, P still hold the current configuration):
    motor torque from the PWM just commanded and the measured speed through eq 5.10 times the
    thermal observer's torque factor ρ̂ = ``sensor[k, 4]`` (1: eq 5.10 at T_ref) and the
    transmission, bias torque Γᵀ(C(q, q̇)q̇ + G(q)) by RNEA; writes the estimates and each
    sample's status into the blocks YL.scale_hat, YL.offset_hat, YL.adapt_status of y[n]. While
    ``sensor[k, 5]`` ≠ 0 (the observer's torque factor
    is too uncertain: a torque loss and a friction change cannot be told apart) the filters run
    but θ, P and σ̂² keep their values (status 0, frozen)."""
    G, ratio, grav, pwm, hb = fc.G, fc.ratio, fc.g, cs.pwm, cs.hb
    theta, P, sig2 = est.theta, est.P, est.sig2
    rnea_pass(4, links_of(fc), cs.R, cs.P, cs.qd, cs.zq, grav[0], grav[1], grav[2], True, hb,
              cs.work)
    for k in range(3):
        v = x[3 + k]
        ts = bldc_torque(pwm[k], ratio[k] * v, th[IX.c_pwm], th[IX.b_pwm], th[IX.b_0],
                         th[IX.pwm_max], sensor[k, 4])
        tm = transmit_torque(ts, v, ratio[k], th[IX.eta])
        h = 0.0
        for j in range(4):
            h += G[j * 3 + k] * hb[j]
        s0, o0, sg = theta[k, 0], theta[k, 1], sig2[k]
        p00, p01, p11 = P[k, 0, 0], P[k, 0, 1], P[k, 1, 1]
        st = friction_rls_step(k, tm, h, v, ctab, est)
        if sensor[k, 5] != 0.0 and st == 1.0:  # guard: undo the update, keep the filters
            theta[k, 0], theta[k, 1], sig2[k] = s0, o0, sg
            P[k, 0, 0], P[k, 0, 1], P[k, 1, 0], P[k, 1, 1] = p00, p01, p01, p11
            st = 0.0
        if st == 1.0:
            sensor[k, 6] += 1.0  # updates so far (the band's settling count)
        y[n, YL.adapt_status + k] = st
        y[n, YL.scale_hat + k] = theta[k, 0]
        y[n, YL.offset_hat + k] = theta[k, 1]


@hot
def _measure(x, loop, n, dt):  # pragma: no cover - compiled
    """The controller's view of the state (gains[G_QUANTUM] > 0): actuator angles quantised to
    the sensor resolution Δ, velocities by backward difference of the quantised angles through a
    first-order low-pass (α = gains[G_VALPHA]); written into ``loop.xm``. At n = 0 the filter
    starts at the true velocity (a finger at rest reads 0)."""
    xm, sen, dq, al = loop.xm, loop.sensor, loop.gains[G_QUANTUM], loop.gains[G_VALPHA]
    for k in range(NX):
        xm[k] = x[k]
    for k in range(3):
        pq = math.floor(x[k] / dq + 0.5) * dq
        if n == 0:
            sen[k, 3] = x[3 + k]
        else:
            sen[k, 3] += al * ((pq - sen[k, 2]) / dt - sen[k, 3])
        sen[k, 2] = pq
        xm[k] = pq
        xm[3 + k] = sen[k, 3]


@hot
def _thermal_observer(th, fc, x, pwm, loop, dt):  # pragma: no cover - compiled
    """The controller's motor-temperature band (gains[G_THERMAL] ≠ 0): T̂_lo and T̂_hi (sensor[k,
    0:2]) advance by the thermal model of :mod:`gripkit.models.bldc` under the PWM just commanded
    and the measured speed, each with its own torque factor; then ρ̂ (sensor[k, 4]) = the mean of
    ρ(T̂_lo) and ρ(T̂_hi) for the next step, and the guard (sensor[k, 5]) = 1 while
    (ρ(T̂_lo) − ρ(T̂_hi))/ρ̂ exceeds gains[G_GUARD]. The plant's temperature obeys the same
    scalar ODE, whose solutions do not cross: a band that holds it at the start holds it always
    (when the observer's α, R_th, C_th = gains[G_OBS_*] are the plant's)."""
    sen, ratio = loop.sensor, fc.ratio
    # the observer's own α, R_th, C_th (the finger's unless told otherwise)
    gains = loop.gains
    Tr, Ta, al = th[IX.T_ref], th[IX.T_amb], gains[G_OBS_ALPHA]
    Rth, Cth = gains[G_OBS_RTH], gains[G_OBS_CTH]
    for k in range(3):
        w = ratio[k] * x[3 + k]
        for j in range(2):
            r = temperature_factor(sen[k, j], Tr, Ta, al)
            ts = bldc_torque(pwm[k], w, th[IX.c_pwm], th[IX.b_pwm], th[IX.b_0], th[IX.pwm_max], r)
            sen[k, j] = motor_heat_step(sen[k, j], ts, dt, Ta, al, th[IX.R_0], th[IX.k_t], Rth,
                                        Cth)
        r_lo = temperature_factor(sen[k, 1], Tr, Ta, al)
        r_hi = temperature_factor(sen[k, 0], Tr, Ta, al)
        sen[k, 4] = 0.5 * (r_lo + r_hi)
        sen[k, 5] = 1.0 if (r_hi - r_lo) > gains[G_GUARD] * sen[k, 4] else 0.0


@hot
def _drift_friction(th, mode, tab, plant, n):  # pragma: no cover - compiled
    """The plant's friction at sample n of its drift schedule (:data:`PlantDrift`) (N, 6) =
    (s_k, Δ_k): F_k(v) = s_k·F_k,0(v) + Δ_k·sign(v), F_s,k = s_k·F_s,k,0 + Δ_k, written into the
    working copies ``plant.th`` (parameters) and ``plant.values`` (table values)."""
    drift, thw, tfw = plant.schedule, plant.th, plant.values
    tv, tf, tn = tab.velocity, tab.values, tab.length
    for k in range(3):
        s = drift[n, k]
        d = drift[n, 3 + k]
        thw[IX.fs_base1 + k] = s * th[IX.fs_base1 + k] + d
        if mode == TABLE:
            sc = s * th[IX.scale_base1 + k]
            thw[IX.scale_base1 + k] = 1.0
            for i in range(tn[k]):
                b = tv[k, i]
                tfw[k, i] = sc * tf[k, i] + (d if b > 0.0 else (-d if b < 0.0 else 0.0))
        else:
            thw[IX.fc_base1 + k] = s * th[IX.fc_base1 + k] + d
            thw[IX.visc_base1 + k] = s * th[IX.visc_base1 + k]
            thw[IX.cubic_base1 + k] = s * th[IX.cubic_base1 + k]


@hot
def finger_loop(th, mode, thermal, fc, ws, cs, tab, run, x, loop, plant,
                est):  # pragma: no cover - compiled
    """The time loop (allocation-free, semi-implicit Euler) of the run ``run`` (:data:`FingerRun`).
    ``loop.ctrl = 0``: PWM from u[:, ucol:], outputs as DLRFinger.outputs at
    y[:, ycol:ycol+18]; ``loop.ctrl = 1/2``:
    joint/Cartesian impedance (:data:`ImpedanceLoop`), closed-loop outputs (the blocks of
    :data:`YL`, named in gripkit.systems.dlr_hit.impedance.LOOP_OUTPUTS). ``plant``
    (:data:`PlantDrift`): the plant's friction drift
    (:func:`_drift_friction`); ``est`` (:data:`FrictionEstimator`): the online friction
    estimator, run when gains[G_ADAPT] ≠ 0; the controller sees the state through
    :func:`_measure` when gains[G_QUANTUM] > 0 and corrects eq 5.10 by its thermal observer
    (:func:`_thermal_observer`) when gains[G_THERMAL] ≠ 0."""
    G, q0 = fc.G, fc.q0
    u, ucol, y, ycol, dt, substeps = run
    pwm, ext, taum, fric, xs, force = cs.pwm, cs.ext, cs.taum, cs.fric, cs.xs, cs.force
    ctrl, gains = loop.ctrl, loop.gains
    drifting = plant.schedule.shape[0] > 0
    thp = plant.th if drifting else th
    tabp = TableArrays(tab.velocity, plant.values, tab.length, tab.ipos) if drifting else tab
    fhat = est.theta
    h = dt / substeps
    N = loop.ref.shape[0] if ctrl else u.shape[0]
    for n in range(N):
        if drifting:
            _drift_friction(th, mode, tab, plant, n)
        if ctrl:
            xc = x
            if gains[G_QUANTUM] > 0.0:
                _measure(x, loop, n, dt)
                xc = loop.xm
            _impedance(th, fc, cs, xc, n, loop, fhat)
            if gains[G_ADAPT] != 0.0:
                _adapt_friction(th, fc, cs, xc, loop.tables, est, loop.sensor, y, n)
            else:
                for k in range(3):
                    y[n, YL.scale_hat + k] = fhat[k, 0]
                    y[n, YL.offset_hat + k] = fhat[k, 1]
                    y[n, YL.adapt_status + k] = 0.0
            if gains[G_THERMAL] != 0.0:
                _thermal_observer(th, fc, xc, pwm, loop, dt)
            for k in range(3):
                y[n, YL.fric_ff + k] = cs.ff[k]
        else:
            for k in range(3):
                pwm[k] = u[n, ucol + k]
        for k in range(NX):
            xs[k] = x[k]
        for s in range(substeps):
            if ctrl:
                _wall(th, fc, cs, x, loop.wall)
                if s == 0:
                    for k in range(3):
                        y[n, YL.force + k] = force[k]
            if not finger_step(thp, mode, thermal, fc, tabp, x, pwm, ext, h, taum, fric, ws):
                return n + 1
            if s == 0 and not ctrl:
                # sample n reports the state at t_n and the torques acting at t_n
                finger_outputs(G, q0, xs, taum, fric, y, n, ycol)
        if ctrl:
            q, qd, Jp, tip = cs.q, cs.qd, cs.Jp, cs.tip
            joints_from_actuators(4, 3, G, q0, xs[0:3], q)
            joints_from_actuators(4, 3, G, cs.zq, xs[3:6], qd)
            _tip(fc, th, cs.q, cs.R, cs.P, cs.T, cs.J, cs.Jp, cs.tip)
            for k in range(3):
                y[n, YL.angle + k] = q[k]
                y[n, YL.velocity + k] = qd[k]
                y[n, YL.tip + k] = tip[k]
                s = 0.0
                for j in range(3):
                    s += Jp[k, j] * xs[3 + j]
                y[n, YL.tip_velocity + k] = s
                y[n, YL.pwm + k] = pwm[k]
                y[n, YL.tau_cmd + k] = cs.tauq[k]
                y[n, YL.fric + k] = fric[k]
                y[n, YL.tau + k] = taum[k]
    return 0


@hot
def finger_loop_rk4(th, mode, thermal, fc, ws, cs, tab, run, x):  # pragma: no cover - compiled
    """Open-loop time loop with RK4 steps (``run``: :data:`FingerRun`)."""
    u, ucol, y, ycol, dt, substeps = run
    pwm, ext, taum, fric, xs = cs.pwm, cs.ext, cs.taum, cs.fric, cs.xs
    h = dt / substeps
    for n in range(u.shape[0]):
        for k in range(3):
            pwm[k] = u[n, ucol + k]
            ext[k] = 0.0
        for k in range(NX):
            xs[k] = x[k]
        for s in range(substeps):
            if not finger_step_rk4(th, mode, thermal, fc, tab, x, pwm, ext, h, taum, fric, ws):
                return n + 1
            if s == 0:
                finger_outputs(fc.G, fc.q0, xs, taum, fric, y, n, ycol)
    return 0


def finger_run(th, mode, thermal, tab, u, ucol, dt, substeps, x, y, ycol, loop, plant, est) -> int:
    """Simulate one finger (open loop: ``loop.ctrl = 0`` with PWM columns ucol..ucol+2 of ``u``;
    closed loop: ``loop.ctrl = 1`` joint or ``2`` Cartesian impedance). Returns the index of the
    first failed sample + 1, or 0. Scratch arrays are allocated here, in Python, so the only
    compiled function is the time loop itself."""
    fc, ws, cs = _make_context(th)
    run = FingerRun(u, ucol, y, ycol, dt, substeps)
    return int(finger_loop(th, mode, thermal, fc, ws, cs, tab, run, x, loop, plant, est))


def finger_run_rk4(th, mode, thermal, tab, u, ucol, dt, substeps, x, y, ycol) -> int:
    """Open-loop simulation with RK4 steps (compiled only when asked for)."""
    fc, ws, cs = _make_context(th)
    run = FingerRun(u, ucol, y, ycol, dt, substeps)
    return int(finger_loop_rk4(th, mode, thermal, fc, ws, cs, tab, run, x))


def _open_loop_records():
    """The records of an open loop: no controller, no drift, no estimator (plain numpy code, run
    by Python and compiled as :func:`open_loop_records` for the parallel kernel)."""
    tables = TableArrays(np.zeros((3, 4)), np.zeros((3, 4)), np.full(3, 4, dtype=np.int64),
                         np.full(3, 2, dtype=np.int64))
    theta = np.zeros((3, 2))
    theta[:, 0] = 1.0
    return (ImpedanceLoop(OPEN_LOOP, np.zeros(N_GAINS), tables, np.zeros((1, 3)), np.zeros((1, 3)),
                          np.zeros(9), np.zeros((3, 7)), np.zeros(NX)),
            PlantDrift(np.zeros((0, 6)), np.zeros(NTH), np.zeros((3, 1))),
            FrictionEstimator(np.zeros(10), np.ones(3), theta, np.zeros((3, 2, 2)),
                              np.zeros((3, 5)),
                              np.zeros(3)))


open_loop_records = numba.njit(cache=True, error_model="numpy")(_open_loop_records)
_OPEN_LOOP = _open_loop_records()


def run_open_loop(th, mode, integ, thermal, tab, u, dt, substeps, x, y, ucol=0, ycol=0) -> int:
    """One finger, open loop (Python entry used by the models and the hand)."""
    if integ == RK4:
        return int(finger_run_rk4(th, mode, thermal, tab, u, ucol, dt, substeps, x, y, ycol))
    return int(finger_run(th, mode, thermal, tab, u, ucol, dt, substeps, x, y, ycol, *_OPEN_LOOP))


@numba.njit(cache=True, parallel=True, error_model="numpy")
def _jobs_parallel(thetas, u, ucols, dt, substeps, x0, y, yidx, ycols, tab, mode,
                   thermal):  # pragma: no cover - compiled
    """Open-loop finger simulations in parallel: job j simulates thetas[j] from x0[j] on PWM
    columns ucols[j].. of u, writing y[yidx[j], :, ycols[j]:ycols[j]+18]. (A prange body takes
    arrays, not records: each job builds its own.)"""
    J = thetas.shape[0]
    fail = np.zeros(J, dtype=np.int64)
    tv, tf, tn, tipos = tab.velocity, tab.values, tab.length, tab.ipos
    for j in prange(J):
        x = x0[j].copy()
        fc, ws, cs = finger_context(thetas[j])
        loop, plant, est = open_loop_records()
        fail[j] = finger_loop(thetas[j], mode, thermal, fc, ws, cs, TableArrays(tv, tf, tn, tipos),
                              FingerRun(u, ucols[j], y[yidx[j]], ycols[j], dt, substeps), x, loop,
                              plant, est)
    return fail


def run_jobs(thetas, u, ucols, dt, substeps, x0, y, yidx, ycols, tab, mode, integ, thermal,
             parallel: bool) -> np.ndarray:
    """Several open-loop finger simulations (a batch of parameter vectors, or the fingers of a
    hand); parallel threads only when asked for (and semi-implicit), else one after another."""
    J = thetas.shape[0]
    if parallel and integ == SEMI_IMPLICIT and J > 1:
        return _jobs_parallel(thetas, u, np.asarray(ucols, dtype=np.int64), dt, substeps, x0, y,
                              np.asarray(yidx, dtype=np.int64), np.asarray(ycols, dtype=np.int64),
                              tab, mode, thermal)
    return np.array([run_open_loop(thetas[j], mode, integ, thermal, tab, u, dt, substeps,
                                   x0[j].copy(), y[yidx[j]], int(ucols[j]), int(ycols[j]))
                     for j in range(J)])


class DLRFinger(Model):
    """The complete finger of Fig. 7.1 (see the module docstring).

    Parameters
    ----------
    parameters
        A ParameterSet holding every name of :data:`FINGER_PARAMETERS` (in that order), e.g.
        :func:`gripkit.systems.dlr_hit.parameters.thesis_finger_parameters`.
    tables
        Friction lookup tables (base motor 1, base motor 2, distal), :class:`FrictionTable`,
        used by ``friction='table'``; their ``scale`` multiplies the ``scale_*`` parameters.
    friction
        ``'table'`` (default, the thesis's model), ``'stribeck'``, ``'lugre'`` or ``'none'``.
    integrator
        ``'semi-implicit'`` (default) or ``'rk4'``.
    thermal
        Integrate the motor temperatures (default False: windings at T_ref, eq 5.10 as printed).

    Inputs: ``pwm_base1``, ``pwm_base2``, ``pwm_distal`` (counts, ±4096). Outputs (18): joint
    angles ``abd``, ``flex``, ``prox`` (rad; the distal joint equals ``prox``), their velocities
    ``abd_vel``, ``flex_vel``, ``prox_vel`` (rad/s), actuator velocities ``base1_vel``,
    ``base2_vel``, ``distal_vel`` (rad/s, the "base joint 1/2" velocities of Figs 7.4–7.5),
    motor torques at the actuator outputs ``tau_base1``.. (N·m), friction torques ``fric_base1``..
    (N·m), winding temperatures ``T_base1``.. (K).
    """

    name = "dlr-hit-finger"
    description = "DLR/HIT Hand II finger: PWM → BLDC → transmission → friction → coupled dynamics"
    inputs = tuple(Signal(f"pwm_{a}", "1", f"PWM count of the {a} motor") for a in ACTUATORS)
    outputs = (tuple(Signal(j, "rad", f"joint angle {j}") for j in JOINTS)
               + tuple(Signal(f"{j}_vel", "rad/s", f"joint velocity {j}") for j in JOINTS)
               + tuple(Signal(f"{a}_vel", "rad/s", f"{a} actuator velocity") for a in ACTUATORS)
               + tuple(Signal(f"tau_{a}", "N*m", f"{a} motor torque at the "
                                                 "actuator output") for a in ACTUATORS)
               + tuple(Signal(f"fric_{a}", "N*m",
                              f"{a} friction torque (opposing)") for a in ACTUATORS)
               + tuple(Signal(f"T_{a}", "K", f"{a} winding temperature") for a in ACTUATORS))
    states = (tuple(Signal(f"p_{a}", "rad") for a in ACTUATORS)
              + tuple(Signal(f"v_{a}", "rad/s") for a in ACTUATORS)
              + tuple(Signal(f"T_{a}", "K") for a in ACTUATORS)
              + tuple(Signal(f"z_{a}", "rad", "LuGre bristle deflection") for a in ACTUATORS)
              + tuple(Signal(f"stuck_{a}", "1", "1 while held by stiction") for a in ACTUATORS))

    def __init__(self, parameters: ParameterSet, tables=None, *, friction: str = "table",
                 integrator: str = "semi-implicit", thermal: bool = False, check: bool = True,
                 name: str | None = None):
        if not isinstance(parameters, ParameterSet):
            raise ModelError("DLRFinger: expected a ParameterSet, found "
                             f"{type(parameters).__name__}")
        if parameters.names != FINGER_PARAMETERS:
            missing = [n for n in FINGER_PARAMETERS if n not in parameters.names]
            raise ModelError("DLRFinger: the parameter set must hold FINGER_PARAMETERS in order",
                             hint=f"missing: {missing}" if missing else "reorder the set")
        if friction not in FRICTION_MODES:
            raise ModelError(f"friction: expected one of {sorted(FRICTION_MODES)}, "
                             f"found {friction!r}")
        if integrator not in INTEGRATORS:
            raise ModelError(f"integrator: expected 'semi-implicit' or 'rk4', found {integrator!r}")
        if tables is None and friction == "table":
            raise ModelError("friction='table' needs three FrictionTables (base1, base2, distal)")
        if tables is not None:
            if len(tables) != 3 or not all(isinstance(t, FrictionTable) for t in tables):
                raise ModelError("tables: expected three FrictionTables (base1, base2, distal)")
            self.tables = tuple(tables)
        else:
            dummy = FrictionTable([-2.0, -1.0, 1.0, 2.0], [-1.0, -1.0, 1.0, 1.0], name="unused")
            self.tables = (dummy, dummy, dummy)
        self._tab = table_arrays(self.tables)
        self.friction = friction
        self.integrator = integrator
        self.thermal = bool(thermal)
        if name:
            self.name = name
        super().__init__(parameters, check=check)

    # --- structure ------------------------------------------------------------------------------
    def chain(self, params: ParameterSet | None = None, base=None) -> CoupledChain:
        """The coupled multibody model (actuator coordinates) of this finger."""
        p = (params or self.parameters)
        v = p.value
        I = np.zeros((4, 3, 3))  # noqa: E741
        com = np.zeros((4, 3))
        for k in range(3):
            I[k + 1] = np.diag([v(f"I{k + 1}_xx"), v(f"I{k + 1}_yy"), v(f"I{k + 1}_zz")])
            com[k + 1] = [v(f"pc{k + 1}_x"), v(f"pc{k + 1}_y"), v(f"pc{k + 1}_z")]
        tool = np.eye(4)
        tool[0, 3] = v("l3")
        ch = DHChain(alpha=[0.0, -math.pi / 2, 0.0, 0.0], a=[0.0, 0.0, v("l1"), v("l2")],
                     d=np.zeros(4), mass=[0.0, v("m1"), v("m2"), v("m3")], com=com, inertia=I,
                     gravity=[v("g_x"), v("g_y"), v("g_z")], tool=tool, base=base,
                     names=("theta1", "theta2", "theta3", "theta4"), name=self.name)
        ratios = self.ratios(p)
        G = np.zeros((4, 3))
        G[:2, :2] = differential_matrix(v("beta"))
        G[2, 2] = G[3, 2] = 1.0
        cp = Coupling(G, np.zeros(4), v("I_m") * ratios ** 2, ACTUATORS)
        return CoupledChain(ch, cp, name=self.name)

    def ratios(self, params: ParameterSet | None = None) -> np.ndarray:
        """Reductions (base1, base2, distal): N_belt·N_hd·N_belt_base for the base, N_belt·N_hd
        distal."""
        v = (params or self.parameters).value
        nd = v("N_hd") * v("N_belt")
        return np.array([nd * v("N_belt_base"), nd * v("N_belt_base"), nd])

    def state(self, q=(0.0, 0.0, 0.0), qd=(0.0, 0.0, 0.0), T=None, *,
              degrees: bool = False) -> np.ndarray:
        """Initial state vector (15) from joint angles (abd, flex, prox) and velocities; motors at
        ``T`` (K, default T_ref); at rest → held by stiction."""
        q = np.asarray(q, dtype=np.float64)
        qd = np.asarray(qd, dtype=np.float64)
        if q.shape != (3,) or qd.shape != (3,):
            raise SimulationError("q and qd: expected 3 joint values (abd, flex, prox), found "
                                  f"{q.shape}, {qd.shape}")
        if degrees:
            q, qd = np.radians(q), np.radians(qd)
        G = self.chain().coupling.matrix[:3]
        p = np.linalg.solve(G, q)
        pd = np.linalg.solve(G, qd)
        Tm = self.parameters.value("T_ref") if T is None else float(T)
        x = np.zeros(NX)
        x[0:3] = p
        x[3:6] = pd
        x[6:9] = Tm
        x[12:15] = (pd == 0).astype(float)
        return x

    def initial_state(self, theta):
        return self.state()

    # --- simulation -----------------------------------------------------------------------------
    def _simulate_batch(self, thetas, u, dt, substeps, x0, y):
        P = thetas.shape[0]
        fail = run_jobs(thetas, u, np.zeros(P), dt, substeps, x0, y, np.arange(P), np.zeros(P),
                        self._tab, FRICTION_MODES[self.friction], INTEGRATORS[self.integrator],
                        self.thermal, parallel=P >= 4)
        if fail.any():
            raise SimulationError(f"{self.name}: the mass matrix lost positive "
                                  "definiteness at sample "
                                  f"{int(fail[fail > 0][0]) - 1}",
                                  hint="check the inertial parameters")

    def modes(self, theta):
        """End-stop contact mode (belt elasticity on the rotor inertia), LuGre bristles, and the
        motor/friction velocity time constant, at the lightest actuator."""
        v = dict(zip(FINGER_PARAMETERS, theta))
        nd = v["N_hd"] * v["N_belt"]
        J = v["I_m"] * nd * nd
        out = []
        if v["k_stop"] > 0:
            out.append((math.sqrt(v["k_stop"] / J), v["d_stop"] / (2 * math.sqrt(v["k_stop"] * J))))
        if self.friction == "lugre":
            out.append((math.sqrt(v["sigma0"] / J),
                        (v["sigma1"] + v["visc_distal"]) / (2 * math.sqrt(v["sigma0"] * J))))
        # back-EMF damping of eq 5.8 reflected: |b(0)|·N²
        out.append((abs(v["b_0"]) * nd * nd / J, 1.0))
        return out

    # --- analysis -------------------------------------------------------------------------------
    def kinetic_friction(self, actuator: str, v) -> np.ndarray:
        """Kinetic friction of an actuator at velocities v (rad/s), as the simulation uses it."""
        k = ACTUATORS.index(actuator)
        p = self.parameters.value
        v = np.asarray(v, dtype=np.float64)
        if self.friction == "table":
            return p(f"scale_{actuator}") * self.tables[k](v)
        if self.friction in ("stribeck", "lugre"):
            s = Stribeck(p(f"fc_{actuator}"), p(f"fs_{actuator}"), p("v_s"),
                         p("delta") if self.friction == "stribeck" else 2.0, p(f"visc_{actuator}"))
            cubic = p(f"cubic_{actuator}") * v ** 3 if self.friction == "stribeck" else 0.0
            return s(v) + cubic
        return np.zeros_like(v)

    def motor_torque(self, actuator: str, pwm, v, T=None) -> np.ndarray:
        """Motor torque at the actuator output (N·m) for PWM and actuator velocity v (rad/s)."""
        k = ACTUATORS.index(actuator)
        N = self.ratios()[k]
        ps = ParameterSet([self.parameters[n] for n in ("c_pwm", "b_pwm", "b_0", "pwm_max", "T_ref",
                                                         "T_amb", "alpha_R", "k_t", "R_0", "R_th",
                                                         "C_th")])
        tau = BLDCMotor(ps).torque(pwm, N * np.asarray(v, dtype=np.float64), T)
        eta = self.parameters.value("eta")
        drive = tau * np.asarray(v) >= 0
        return np.where(drive, N * eta * tau, N * tau / eta)

    def steady_velocity(self, actuator: str, pwm: float, load: float = 0.0) -> float:
        """Velocity (rad/s) at which motor torque balances kinetic friction plus a constant
        ``load`` torque (N·m) for a constant PWM — the plateau of Figs 7.3–7.5 without gravity:
        the first balance reached when accelerating from rest (a table with a spike can hold the
        joint below a faster balance). 0 when the motor cannot overcome stiction."""
        from scipy.optimize import brentq

        k = ACTUATORS.index(actuator)
        sgn = 1.0 if pwm >= 0 else -1.0
        if abs(self.motor_torque(actuator, pwm,
                                 0.0) - load) <= self.parameters.value(f"fs_{actuator}"):
            return 0.0
        N = self.ratios()[k]
        p = self.parameters.value
        c, b1, b0 = p("c_pwm"), p("b_pwm"), p("b_0")
        u = min(abs(pwm), p("pwm_max"))
        slope = -(b1 * u + b0)
        v_guard = c * u / (slope * N) if slope > 0 else 1e3

        def f(v):
            return (self.motor_torque(actuator, pwm, sgn * v) - load
                    - self.kinetic_friction(actuator, sgn * v)) * sgn

        grid = np.linspace(1e-9, v_guard * (1 - 1e-12), 4001)
        vals = f(grid)
        neg = np.flatnonzero(vals <= 0)
        if neg.size == 0:
            return sgn * grid[-1]
        i = int(neg[0])
        if i == 0:
            return 0.0
        return sgn * brentq(lambda v: float(f(np.array(v))), grid[i - 1], grid[i], xtol=1e-12)
