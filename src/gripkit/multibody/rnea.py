"""Batched rigid-body dynamics: inverse dynamics (RNEA), mass matrix, Coriolis/centrifugal and
gravity terms, forward dynamics, energy, and fixed-step simulation.

Every function takes a *system* — a :class:`~gripkit.multibody.DHChain` or a
:class:`~gripkit.multibody.CoupledChain` — and states of shape ``(m,)`` or ``(B, m)`` in the
system's coordinates (joint coordinates of a chain, actuator coordinates of a coupled chain), and
returns arrays of the matching shape. Batches run in parallel (numba ``prange`` over chunks of
states; each chunk allocates its scratch arrays once).

The equation of motion (thesis eq 4.17) is

    τ = M(θ) θ̈ + C(θ, θ̇) + G(θ)

with ``C`` the Coriolis/centrifugal *vector* (the thesis's "centrifugal term", N·m) and ``G`` the
gravity vector. :func:`rnea` evaluates the right-hand side, :func:`mass_matrix` ``M`` (from RNEA
columns: q̇ = 0, g = 0, q̈ = e_j), :func:`coriolis` ``C``, :func:`gravity` ``G``, :func:`bias`
``C + G`` and :func:`forward_dynamics` θ̈ = M⁻¹(τ − C − G) (Cholesky).
"""

from __future__ import annotations

import math
from collections import namedtuple

import numba
import numpy as np
from numba import prange

from ..errors import ModelError, SimulationError
from .kernels import (WORK_PER_LINK, ChainArrays, DynamicsWork, chain_links, cholesky_solve,
                      coupled_mass_bias, frames_into, hot, joints_from_actuators, links_of,
                      point_jacobian, rnea_pass)

__all__ = ["rnea", "mass_matrix", "coriolis", "gravity", "bias", "forward_dynamics",
           "kinetic_energy", "potential_energy", "simulate_free"]

_CHUNK = 128
#: batches at least this large run in parallel (prange) unless told otherwise; smaller ones on one
#: thread, so that a script that evaluates a few thousand states never pays the parallel
#: kernel's compile time (docs/performance.md)
PARALLEL_MIN = 100_000

OP_RNEA, OP_MASS_BIAS, OP_BIAS, OP_FD, OP_POTENTIAL, OP_FRAMES, OP_JACOBIAN = range(7)

#: scratch of the fixed-step integrator: state, stage state and the four RK4 stage accelerations
RK4Work = namedtuple("RK4Work", "x v xs vs k1 k2 k3 k4")
#: what the fixed-step integrator writes: positions and velocities (B, N, m) and, per initial
#: state, the first sample whose step failed + 1 (0: none)
Trajectory = namedtuple("Trajectory", "pos vel fail")
#: scratch of the kinematics kernel (n links): link rotations and positions, joint positions,
#: base-to-link transforms (n, 16) and a point Jacobian (6, n)
KinematicsWork = namedtuple("KinematicsWork", "R P q T J")
#: integration methods of :func:`simulate_free` (the kernels' ``method`` code)
RK4, SEMI_IMPLICIT = 0, 1


@numba.njit(cache=True, error_model="numpy")
def dynamics_work(n, m):  # pragma: no cover - compiled
    """Scratch of the dynamics kernels for n links and m coordinates (:data:`DynamicsWork`)."""
    return DynamicsWork(np.empty((n, 9)), np.empty((n, 3)), np.empty(WORK_PER_LINK * n),
                        np.empty(n),
                        np.empty(n), np.empty(n), np.zeros(n), np.empty((n, n)), np.empty(n),
                        np.empty((m, m)), np.empty(m), np.empty((m, m)), np.empty(m), np.empty(m))


@hot
def _accel(n, m, ch, p, pd, tau_p, a, w):  # pragma: no cover - compiled
    """Accelerations ``a`` = M_p⁻¹(τ_p − h_p) at (p, ṗ) for the chain ``ch`` (:data:`ChainArrays`);
    False if M_p is not positive definite."""
    G, g, q, qd, zq, hp, rhs = ch.G, ch.g, w.q, w.qd, w.zq, w.hp, w.rhs
    joints_from_actuators(n, m, G, ch.q0, p, q)
    joints_from_actuators(n, m, G, zq, pd, qd)
    chain_links(n, ch.links, ch.jtype, q, w.R, w.P)
    coupled_mass_bias(n, m, links_of(ch), G, ch.arm_p, w, qd, g[0], g[1], g[2], w.Mp, hp)
    for i in range(m):
        rhs[i] = tau_p[i] - hp[i]
    return cholesky_solve(m, w.Mp, rhs, a, w.L)


@hot
def _range_dyn(op, b0, b1, ch, gscale, pos, vel, acc, vout, mout, w):  # pragma: no cover - compiled
    """Inverse dynamics (OP_RNEA), bias (OP_BIAS) or mass matrix and bias (OP_MASS_BIAS) for
    states b0..b1−1 (allocation-free; scratch ``w``): ``vout`` (B, m), ``mout`` (B, m, m)."""
    n = ch.links.shape[0]
    m = pos.shape[1]
    G, zq, q, qd, qdd, tau, Mp, hp = ch.G, w.zq, w.q, w.qd, w.qdd, w.tau, w.Mp, w.hp
    gx = gscale * ch.g[0]
    gy = gscale * ch.g[1]
    gz = gscale * ch.g[2]
    for b in range(b0, b1):
        joints_from_actuators(n, m, G, ch.q0, pos[b], q)
        joints_from_actuators(n, m, G, zq, vel[b], qd)
        chain_links(n, ch.links, ch.jtype, q, w.R, w.P)
        if op == OP_MASS_BIAS:
            coupled_mass_bias(n, m, links_of(ch), G, ch.arm_p, w, qd, gx, gy, gz, Mp, hp)
            for i in range(m):
                vout[b, i] = hp[i]
                for j in range(m):
                    mout[b, i, j] = Mp[i, j]
            continue
        if op == OP_RNEA:
            joints_from_actuators(n, m, G, zq, acc[b], qdd)
        else:
            for k in range(n):
                qdd[k] = 0.0
        rnea_pass(n, links_of(ch), w.R, w.P, qd, qdd, gx, gy, gz, True, tau, w.work)
        for i in range(m):
            s = ch.arm_p[i] * acc[b, i] if op == OP_RNEA else 0.0
            for k in range(n):
                s += G[k * m + i] * tau[k]
            vout[b, i] = s


@hot
def _range_kin(op, b0, b1, ch, tool, pos, vout, fout, kw):  # pragma: no cover - compiled
    """Link frames (OP_FRAMES → fout (B, n, 16)), the tool point's Jacobian (OP_JACOBIAN → fout
    (B, 6, m)) or the potential energy (OP_POTENTIAL → vout (B, 1)); scratch ``kw``
    (:data:`KinematicsWork`)."""
    n = ch.links.shape[0]
    m = pos.shape[1]
    G, g, mass, com = ch.G, ch.g, ch.mass, ch.com
    R, P, q, T, J = kw.R, kw.P, kw.q, kw.T, kw.J
    for b in range(b0, b1):
        joints_from_actuators(n, m, G, ch.q0, pos[b], q)
        chain_links(n, ch.links, ch.jtype, q, R, P)
        frames_into(n, R, P, T)
        if op == OP_FRAMES:
            for k in range(n):
                for i in range(16):
                    fout[b, k, i] = T[k, i]
        elif op == OP_POTENTIAL:
            u = 0.0
            for k in range(n):
                for i in range(3):
                    pc = T[k, 4 * i + 3]
                    for j in range(3):
                        pc += T[k, 4 * i + j] * com[k, j]
                    u -= mass[k] * g[i] * pc
            vout[b, 0] = u
        else:
            e = n - 1
            px = T[e, 3] + T[e, 0] * tool[0] + T[e, 1] * tool[1] + T[e, 2] * tool[2]
            py = T[e, 7] + T[e, 4] * tool[0] + T[e, 5] * tool[1] + T[e, 6] * tool[2]
            pz = T[e, 11] + T[e, 8] * tool[0] + T[e, 9] * tool[1] + T[e, 10] * tool[2]
            point_jacobian(n, ch.jtype, T, px, py, pz, J)
            for r in range(6):
                for j in range(m):
                    s = 0.0
                    for k in range(n):
                        s += J[r, k] * G[k * m + j]
                    fout[b, r, j] = s


@hot
def _range_fd(b0, b1, ch, pos, vel, tau_p, vout, ok, w):  # pragma: no cover - compiled
    """Forward dynamics q̈ = M⁻¹(τ − h) for states b0..b1−1."""
    n = ch.links.shape[0]
    m = pos.shape[1]
    a = w.a
    for b in range(b0, b1):
        ok[b] = _accel(n, m, ch, pos[b], vel[b], tau_p[b], a, w)
        for i in range(m):
            vout[b, i] = a[i]


@numba.njit(cache=True, error_model="numpy")
def _dyn_serial(op, ch, gscale, pos, vel, acc, vout, mout):  # pragma: no cover - compiled
    _range_dyn(op, 0, pos.shape[0], ch, gscale, pos, vel, acc, vout, mout,
               dynamics_work(ch.links.shape[0], pos.shape[1]))


@numba.njit(cache=True, parallel=True, error_model="numpy")
def _dyn_parallel(op, ch, gscale, pos, vel, acc, vout, mout):  # pragma: no cover - compiled
    # a prange body takes arrays, not records: each chunk builds its own
    links, jtype, mass, com, inertia, arm_q, G, q0, arm_p, g = ch
    n = links.shape[0]
    m = pos.shape[1]
    B = pos.shape[0]
    for c in prange((B + _CHUNK - 1) // _CHUNK):
        _range_dyn(op, c * _CHUNK, min(B, (c + 1) * _CHUNK),
                   ChainArrays(links, jtype, mass, com, inertia, arm_q, G, q0, arm_p, g), gscale,
                   pos,
                   vel, acc, vout, mout, dynamics_work(n, m))


@numba.njit(cache=True, error_model="numpy")
def _kin_serial(op, ch, tool, pos, vout, fout):  # pragma: no cover - compiled
    n = ch.links.shape[0]
    _range_kin(op, 0, pos.shape[0], ch, tool, pos, vout, fout,
               KinematicsWork(np.empty((n, 9)), np.empty((n, 3)), np.empty(n), np.empty((n, 16)),
                              np.empty((6, n))))


@numba.njit(cache=True, error_model="numpy")
def _fd_serial(ch, pos, vel, tau_p, vout, ok):  # pragma: no cover - compiled
    _range_fd(0, pos.shape[0], ch, pos, vel, tau_p, vout, ok,
              dynamics_work(ch.links.shape[0], pos.shape[1]))


def run_op(system, op: int, pos, vel=None, acc=None, *, gscale: float = 1.0, tool=None,
           vout=None, mout=None, fout=None, parallel: bool | None = None):
    """Evaluate a kernel operation over a batch of states. Inverse dynamics, bias and mass
    matrices use all cores from PARALLEL_MIN states on (or as ``parallel`` says); forward
    dynamics and kinematics run on one thread. Returns the solver flags (forward dynamics)."""
    ch = system.kernel_arrays()
    B = pos.shape[0]
    vel = pos if vel is None else vel
    acc = pos if acc is None else acc
    vout = np.empty((1, 1)) if vout is None else vout
    ok = np.ones(B, dtype=np.bool_)
    if op in (OP_RNEA, OP_BIAS, OP_MASS_BIAS):
        mout = np.empty((1, 1, 1)) if mout is None else mout
        fn = _dyn_parallel if (B >= PARALLEL_MIN if parallel is None else parallel) else _dyn_serial
        fn(op, ch, float(gscale), pos, vel, acc, vout, mout)
    elif op == OP_FD:
        _fd_serial(ch, pos, vel, acc, vout, ok)
    else:
        fout = np.empty((1, 1, 1)) if fout is None else fout
        tool = np.zeros(3) if tool is None else np.ascontiguousarray(tool, dtype=np.float64)
        _kin_serial(op, ch, tool, pos, vout, fout)
    return ok


@hot
def _simulate_range(b0, b1, ch, p0, pd0, torque, dt, substeps, method, out, w,
                    rk):  # pragma: no cover - compiled
    """Fixed-step integration of τ_p = M_p p̈ + h_p from initial states b0..b1−1, torque held
    over each sample (N, m), into ``out`` (:data:`Trajectory`). ``method``: :data:`RK4`
    (classical Runge-Kutta) or :data:`SEMI_IMPLICIT` (symplectic Euler). Scratch: ``w``
    (:data:`DynamicsWork`), ``rk`` (:data:`RK4Work`)."""
    pos_out, vel_out, fail = out.pos, out.vel, out.fail
    n = ch.links.shape[0]
    m = p0.shape[1]
    N = torque.shape[0]
    h = dt / substeps
    x, v, xs, vs, k1, k2, k3, k4 = rk.x, rk.v, rk.xs, rk.vs, rk.k1, rk.k2, rk.k3, rk.k4
    for b in range(b0, b1):
        for i in range(m):
            x[i] = p0[b, i]
            v[i] = pd0[b, i]
        for s in range(N):
            for i in range(m):
                pos_out[b, s, i] = x[i]
                vel_out[b, s, i] = v[i]
            for _ in range(substeps):
                if method == SEMI_IMPLICIT:
                    if not _accel(n, m, ch, x, v, torque[s], k1, w):
                        fail[b] = s + 1
                    for i in range(m):
                        v[i] += h * k1[i]
                        x[i] += h * v[i]
                    continue
                # classical RK4 on (x, v); stage c uses x + c·v_prev, v + c·a_prev
                for st in range(4):
                    if st == 0:
                        for i in range(m):
                            xs[i] = x[i]
                            vs[i] = v[i]
                        kk = k1
                    elif st == 1:
                        for i in range(m):
                            xs[i] = x[i] + 0.5 * h * v[i]
                            vs[i] = v[i] + 0.5 * h * k1[i]
                        kk = k2
                    elif st == 2:
                        for i in range(m):
                            xs[i] = x[i] + 0.5 * h * (v[i] + 0.5 * h * k1[i])
                            vs[i] = v[i] + 0.5 * h * k2[i]
                        kk = k3
                    else:
                        for i in range(m):
                            xs[i] = x[i] + h * (v[i] + 0.5 * h * k2[i])
                            vs[i] = v[i] + h * k3[i]
                        kk = k4
                    if not _accel(n, m, ch, xs, vs, torque[s], kk, w):
                        fail[b] = s + 1
                for i in range(m):
                    x[i] += h * v[i] + h * h / 6.0 * (k1[i] + k2[i] + k3[i])
                    v[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])


@numba.njit(cache=True, error_model="numpy")
def _rk4_work(m):  # pragma: no cover - compiled
    return RK4Work(np.empty(m), np.empty(m), np.empty(m), np.empty(m), np.empty(m), np.empty(m),
                   np.empty(m), np.empty(m))


@numba.njit(cache=True, parallel=True, error_model="numpy")
def _simulate_parallel(ch, p0, pd0, torque, dt, substeps, method, pos_out, vel_out,
                       fail):  # pragma: no cover - compiled
    # a prange body takes arrays, not records: each initial state builds its own
    links, jtype, mass, com, inertia, arm_q, G, q0, arm_p, g = ch
    n = links.shape[0]
    m = p0.shape[1]
    for b in prange(p0.shape[0]):
        _simulate_range(b, b + 1, ChainArrays(links, jtype, mass, com, inertia, arm_q, G, q0, arm_p,
                                              g),
                        p0, pd0, torque, dt, substeps, method, Trajectory(pos_out, vel_out, fail),
                        dynamics_work(n, m), _rk4_work(m))


@numba.njit(cache=True, error_model="numpy")
def _simulate_serial(ch, p0, pd0, torque, dt, substeps, method, pos_out, vel_out,
                     fail):  # pragma: no cover - compiled
    m = p0.shape[1]
    _simulate_range(0, p0.shape[0], ch, p0, pd0, torque, dt, substeps, method,
                    Trajectory(pos_out, vel_out, fail), dynamics_work(ch.links.shape[0], m),
                    _rk4_work(m))


# ---------------------------------------------------------------------------------------------
# Python API
# ---------------------------------------------------------------------------------------------

def _states(system, *arrays, names=("q",)):
    """Stack states to (B, m) float64 C arrays; return them and whether the input was 1-D."""
    m = system.dof
    out = []
    single = None
    B = None
    for name, a in zip(names, arrays):
        x = np.asarray(a, dtype=np.float64)
        if x.ndim not in (1, 2) or x.shape[-1] != m:
            raise ModelError(f"{name}: expected shape ({m},) or (B, {m}) for the {m} coordinates "
                             f"{', '.join(system.coordinate_names)}, found {x.shape}")
        if not np.isfinite(x).all():
            raise ModelError(f"{name}: contains NaN or inf")
        s = x.ndim == 1
        x = np.ascontiguousarray(np.atleast_2d(x))
        if B is None:
            B, single = x.shape[0], s
        elif x.shape[0] != B:
            if x.shape[0] == 1:
                x = np.ascontiguousarray(np.broadcast_to(x, (B, m)))
            elif B == 1:
                out = [np.ascontiguousarray(np.broadcast_to(o, (x.shape[0], m))) for o in out]
                B = x.shape[0]
            else:
                raise ModelError(f"{name}: batch of {x.shape[0]} states does not match {B}")
        single = single and s
        out.append(x)
    return out, single


def rnea(system, q, qd, qdd, *, gravity: bool = True, parallel: bool | None = None) -> np.ndarray:
    """Inverse dynamics τ = M q̈ + C(q, q̇) + G(q) (thesis eqs 4.8–4.17), shape like ``q``.
    ``parallel``: run a batch on all cores (default: from PARALLEL_MIN states on)."""
    (q, qd, qdd), single = _states(system, q, qd, qdd, names=("q", "qd", "qdd"))
    out = np.empty_like(q)
    run_op(system, OP_RNEA, q, qd, qdd, gscale=1.0 if gravity else 0.0, vout=out, parallel=parallel)
    return out[0] if single else out


def _mass_bias(system, q, qd, gscale, want_mass):
    (q, qd), single = _states(system, q, qd, names=("q", "qd"))
    B, m = q.shape
    h = np.empty((B, m))
    if want_mass:
        M = np.empty((B, m, m))
        run_op(system, OP_MASS_BIAS, q, qd, gscale=gscale, vout=h, mout=M)
        return (M[0] if single else M), (h[0] if single else h)
    run_op(system, OP_BIAS, q, qd, gscale=gscale, vout=h)
    return None, (h[0] if single else h)


def mass_matrix(system, q) -> np.ndarray:
    """Joint-space (or actuator-space) mass matrix M(q), shape (m, m) or (B, m, m); includes the
    reflected rotor inertia (``armature``)."""
    q = np.asarray(q, dtype=np.float64)
    return _mass_bias(system, q, np.zeros_like(q), 0.0, True)[0]


def coriolis(system, q, qd) -> np.ndarray:
    """Coriolis and centrifugal torques C(q, q̇) (a vector, as in thesis eq 4.17)."""
    return _mass_bias(system, q, qd, 0.0, False)[1]


def gravity(system, q) -> np.ndarray:
    """Gravity torques G(q) (the torques that hold the chain still)."""
    q = np.asarray(q, dtype=np.float64)
    return _mass_bias(system, q, np.zeros_like(q), 1.0, False)[1]


def bias(system, q, qd) -> np.ndarray:
    """C(q, q̇) + G(q) in one pass."""
    return _mass_bias(system, q, qd, 1.0, False)[1]


def forward_dynamics(system, q, qd, tau) -> np.ndarray:
    """Accelerations q̈ = M⁻¹ (τ − C − G)."""
    (q, qd, tau), single = _states(system, q, qd, tau, names=("q", "qd", "tau"))
    out = np.empty_like(q)
    ok = run_op(system, OP_FD, q, qd, tau, vout=out)
    if not ok.all():
        raise ModelError(f"{system.name}: the mass matrix is not positive definite at state "
                         f"{int(np.argmin(ok))}", hint="check masses, inertias and the armature")
    return out[0] if single else out


def kinetic_energy(system, q, qd) -> np.ndarray:
    """T = ½ q̇ᵀ M(q) q̇ (J), including the rotor inertia."""
    M = mass_matrix(system, q)
    qd = np.asarray(qd, dtype=np.float64)
    return 0.5 * np.einsum("...i,...ij,...j->...", qd, M, qd)


def potential_energy(system, q) -> np.ndarray:
    """U = −Σ m_k gᵀ p_Ck (J), zero at the base origin."""
    (q,), single = _states(system, q)
    out = np.empty((q.shape[0], 1))
    run_op(system, OP_POTENTIAL, q, vout=out)
    return out[0, 0] if single else out[:, 0]


def simulate_free(system, q0, qd0, torque, dt: float, *, substeps: int = 1,
                  method: str = "rk4") -> tuple[np.ndarray, np.ndarray]:
    """Integrate the rigid chain (no friction) under held torques.

    Parameters
    ----------
    q0, qd0
        Initial positions and velocities, shape (m,) or (B, m).
    torque
        Torques held over each sample, shape (N, m) (N samples, the same for every initial state).
    dt
        Sample time (s); ``substeps`` internal steps per sample.
    method
        ``'rk4'`` (classical Runge-Kutta, 4th order) or ``'semi-implicit'`` (symplectic Euler).

    Returns
    -------
    positions, velocities
        Shape (N, m), or (B, N, m) for a batch of initial states; sample k is the state at k·dt.
    """
    if method not in ("rk4", "semi-implicit"):
        raise SimulationError(f"method: expected 'rk4' or 'semi-implicit', found {method!r}")
    if not (math.isfinite(dt) and dt > 0) or int(substeps) != substeps or substeps < 1:
        raise SimulationError(f"dt must be > 0 s and substeps a positive integer; found dt={dt!r}, "
                              f"substeps={substeps!r}")
    (q0, qd0), single = _states(system, q0, qd0, names=("q0", "qd0"))
    tq = np.ascontiguousarray(np.asarray(torque, dtype=np.float64))
    if tq.ndim != 2 or tq.shape[1] != system.dof:
        raise SimulationError(f"torque: expected shape (N, {system.dof}), found {tq.shape}")
    B, m = q0.shape
    N = tq.shape[0]
    pos = np.empty((B, N, m))
    vel = np.empty((B, N, m))
    fail = np.zeros(B, dtype=np.int64)
    fn = _simulate_parallel if B >= 8 else _simulate_serial
    fn(system.kernel_arrays(), q0, qd0, tq, float(dt), int(substeps),
       RK4 if method == "rk4" else SEMI_IMPLICIT, pos, vel, fail)
    if fail.any() or not np.isfinite(pos).all():
        raise SimulationError(f"{system.name}: the simulation diverged or met a "
                              "singular mass matrix",
                              hint="reduce dt or check the inertial parameters")
    return (pos[0], vel[0]) if single else (pos, vel)
