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

import numba
import numpy as np
from numba import prange

from ..errors import ModelError, SimulationError
from .kernels import (WORK_PER_LINK, chain_links, cholesky_solve, coupled_mass_bias, frames_into,
                      joints_from_actuators, rnea_pass)

__all__ = ["rnea", "mass_matrix", "coriolis", "gravity", "bias", "forward_dynamics",
           "kinetic_energy", "potential_energy", "simulate_free"]

_CHUNK = 128


@numba.njit(cache=True)
def _nchunks(B):  # pragma: no cover - compiled
    return (B + _CHUNK - 1) // _CHUNK


@numba.njit(cache=True, parallel=True)
def _rnea_batch(dh, jtype, mass, com, inertia, arm_q, G, q0, arm_p, g, pos, vel, acc, gscale,
                out):  # pragma: no cover - compiled
    n = dh.shape[0]
    m = pos.shape[1]
    B = pos.shape[0]
    for c in prange(_nchunks(B)):
        R = np.empty((n, 9))
        P = np.empty((n, 3))
        work = np.empty(WORK_PER_LINK * n)
        q = np.empty(n)
        qd = np.empty(n)
        qdd = np.empty(n)
        tau = np.empty(n)
        zq = np.zeros(n)
        for b in range(c * _CHUNK, min(B, (c + 1) * _CHUNK)):
            joints_from_actuators(n, m, G, q0, pos[b], q)
            joints_from_actuators(n, m, G, zq, vel[b], qd)
            joints_from_actuators(n, m, G, zq, acc[b], qdd)
            chain_links(n, dh, jtype, q, R, P)
            rnea_pass(n, R, P, jtype, mass, com, inertia, arm_q, qd, qdd, gscale * g[0],
                      gscale * g[1], gscale * g[2], True, tau, work)
            for i in range(m):
                s = arm_p[i] * acc[b, i]
                for k in range(n):
                    s += G[k * m + i] * tau[k]
                out[b, i] = s


@numba.njit(cache=True, parallel=True)
def _mass_bias_batch(dh, jtype, mass, com, inertia, arm_q, G, q0, arm_p, g, pos, vel, gscale,
                     want_mass, Mout, hout):  # pragma: no cover - compiled
    n = dh.shape[0]
    m = pos.shape[1]
    B = pos.shape[0]
    for c in prange(_nchunks(B)):
        R = np.empty((n, 9))
        P = np.empty((n, 3))
        work = np.empty(WORK_PER_LINK * n)
        q = np.empty(n)
        qd = np.empty(n)
        zq = np.zeros(n)
        Mq = np.empty((n, n))
        tau = np.empty(n)
        Mp = np.empty((m, m))
        hp = np.empty(m)
        for b in range(c * _CHUNK, min(B, (c + 1) * _CHUNK)):
            joints_from_actuators(n, m, G, q0, pos[b], q)
            joints_from_actuators(n, m, G, zq, vel[b], qd)
            chain_links(n, dh, jtype, q, R, P)
            if want_mass:
                coupled_mass_bias(n, m, R, P, jtype, mass, com, inertia, arm_q, G, arm_p, qd,
                                  gscale * g[0], gscale * g[1], gscale * g[2], Mp, hp, zq, Mq,
                                  tau, work)
                for i in range(m):
                    hout[b, i] = hp[i]
                    for j in range(m):
                        Mout[b, i, j] = Mp[i, j]
            else:
                rnea_pass(n, R, P, jtype, mass, com, inertia, arm_q, qd, zq, gscale * g[0],
                          gscale * g[1], gscale * g[2], True, tau, work)
                for i in range(m):
                    s = 0.0
                    for k in range(n):
                        s += G[k * m + i] * tau[k]
                    hout[b, i] = s


@numba.njit(cache=True)
def _accel(n, m, dh, jtype, mass, com, inertia, arm_q, G, q0, arm_p, g, p, pd, tau_p, a, R, P,
           work, q, qd, zq, Mq, tau, Mp, hp, L, rhs):  # pragma: no cover - compiled
    joints_from_actuators(n, m, G, q0, p, q)
    joints_from_actuators(n, m, G, zq, pd, qd)
    chain_links(n, dh, jtype, q, R, P)
    coupled_mass_bias(n, m, R, P, jtype, mass, com, inertia, arm_q, G, arm_p, qd, g[0], g[1],
                      g[2], Mp, hp, zq, Mq, tau, work)
    for i in range(m):
        rhs[i] = tau_p[i] - hp[i]
    return cholesky_solve(m, Mp, rhs, a, L)


@numba.njit(cache=True, parallel=True)
def _fd_batch(dh, jtype, mass, com, inertia, arm_q, G, q0, arm_p, g, pos, vel, torque,
              out):  # pragma: no cover - compiled
    n = dh.shape[0]
    m = pos.shape[1]
    B = pos.shape[0]
    ok_all = np.ones(B, dtype=np.bool_)
    for c in prange(_nchunks(B)):
        R = np.empty((n, 9))
        P = np.empty((n, 3))
        work = np.empty(WORK_PER_LINK * n)
        q = np.empty(n)
        qd = np.empty(n)
        zq = np.zeros(n)
        Mq = np.empty((n, n))
        tau = np.empty(n)
        Mp = np.empty((m, m))
        hp = np.empty(m)
        L = np.empty((m, m))
        rhs = np.empty(m)
        a = np.empty(m)
        for b in range(c * _CHUNK, min(B, (c + 1) * _CHUNK)):
            ok = _accel(n, m, dh, jtype, mass, com, inertia, arm_q, G, q0, arm_p, g, pos[b],
                        vel[b], torque[b], a, R, P, work, q, qd, zq, Mq, tau, Mp, hp, L, rhs)
            ok_all[b] = ok
            for i in range(m):
                out[b, i] = a[i]
    return ok_all


@numba.njit(cache=True, parallel=True)
def _simulate_batch(dh, jtype, mass, com, inertia, arm_q, G, q0, arm_p, g, p0, pd0, torque, dt,
                    substeps, method, pos_out, vel_out):  # pragma: no cover - compiled
    """Fixed-step integration of τ_p = M_p p̈ + h_p from each initial state (B of them), torque
    held over each sample (N, m). method 0: classical RK4; 1: semi-implicit (symplectic) Euler."""
    n = dh.shape[0]
    m = p0.shape[1]
    B = p0.shape[0]
    N = torque.shape[0]
    h = dt / substeps
    fail = np.zeros(B, dtype=np.int64)
    for b in prange(B):
        R = np.empty((n, 9))
        P = np.empty((n, 3))
        work = np.empty(WORK_PER_LINK * n)
        q = np.empty(n)
        qd = np.empty(n)
        zq = np.zeros(n)
        Mq = np.empty((n, n))
        tau = np.empty(n)
        Mp = np.empty((m, m))
        hp = np.empty(m)
        L = np.empty((m, m))
        rhs = np.empty(m)
        x = np.empty(m)
        v = np.empty(m)
        xs = np.empty(m)
        vs = np.empty(m)
        k1 = np.empty(m)
        k2 = np.empty(m)
        k3 = np.empty(m)
        k4 = np.empty(m)
        for i in range(m):
            x[i] = p0[b, i]
            v[i] = pd0[b, i]
        for s in range(N):
            for i in range(m):
                pos_out[b, s, i] = x[i]
                vel_out[b, s, i] = v[i]
            for _ in range(substeps):
                if method == 1:
                    if not _accel(n, m, dh, jtype, mass, com, inertia, arm_q, G, q0, arm_p, g, x,
                                  v, torque[s], k1, R, P, work, q, qd, zq, Mq, tau, Mp, hp, L,
                                  rhs):
                        fail[b] = s + 1
                    for i in range(m):
                        v[i] += h * k1[i]
                        x[i] += h * v[i]
                    continue
                # RK4 on (x, v)
                _accel(n, m, dh, jtype, mass, com, inertia, arm_q, G, q0, arm_p, g, x, v,
                       torque[s], k1, R, P, work, q, qd, zq, Mq, tau, Mp, hp, L, rhs)
                for i in range(m):
                    xs[i] = x[i] + 0.5 * h * v[i]
                    vs[i] = v[i] + 0.5 * h * k1[i]
                _accel(n, m, dh, jtype, mass, com, inertia, arm_q, G, q0, arm_p, g, xs, vs,
                       torque[s], k2, R, P, work, q, qd, zq, Mq, tau, Mp, hp, L, rhs)
                for i in range(m):
                    xs[i] = x[i] + 0.5 * h * (v[i] + 0.5 * h * k1[i])
                    vs[i] = v[i] + 0.5 * h * k2[i]
                _accel(n, m, dh, jtype, mass, com, inertia, arm_q, G, q0, arm_p, g, xs, vs,
                       torque[s], k3, R, P, work, q, qd, zq, Mq, tau, Mp, hp, L, rhs)
                for i in range(m):
                    xs[i] = x[i] + h * (v[i] + 0.5 * h * k2[i])
                    vs[i] = v[i] + h * k3[i]
                _accel(n, m, dh, jtype, mass, com, inertia, arm_q, G, q0, arm_p, g, xs, vs,
                       torque[s], k4, R, P, work, q, qd, zq, Mq, tau, Mp, hp, L, rhs)
                for i in range(m):
                    x[i] += h * v[i] + h * h / 6.0 * (k1[i] + k2[i] + k3[i])
                    v[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
    return fail


@numba.njit(cache=True, parallel=True)
def _potential_batch(dh, jtype, mass, com, G, q0, g, pos, out):  # pragma: no cover - compiled
    """U = −Σ m_k gᵀ p_Ck (base frame)."""
    n = dh.shape[0]
    m = pos.shape[1]
    B = pos.shape[0]
    for c in prange(_nchunks(B)):
        R = np.empty((n, 9))
        P = np.empty((n, 3))
        T = np.empty((n, 16))
        q = np.empty(n)
        for b in range(c * _CHUNK, min(B, (c + 1) * _CHUNK)):
            joints_from_actuators(n, m, G, q0, pos[b], q)
            chain_links(n, dh, jtype, q, R, P)
            frames_into(n, R, P, T)
            u = 0.0
            for k in range(n):
                for i in range(3):
                    pc = T[k, 4 * i + 3]
                    for j in range(3):
                        pc += T[k, 4 * i + j] * com[k, j]
                    u -= mass[k] * g[i] * pc
            out[b] = u


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


def rnea(system, q, qd, qdd, *, gravity: bool = True) -> np.ndarray:
    """Inverse dynamics τ = M q̈ + C(q, q̇) + G(q) (thesis eqs 4.8–4.17), shape like ``q``."""
    (q, qd, qdd), single = _states(system, q, qd, qdd, names=("q", "qd", "qdd"))
    out = np.empty_like(q)
    _rnea_batch(*system.kernel_arrays(), q, qd, qdd, 1.0 if gravity else 0.0, out)
    return out[0] if single else out


def _mass_bias(system, q, qd, gscale, want_mass):
    (q, qd), single = _states(system, q, qd, names=("q", "qd"))
    B, m = q.shape
    M = np.empty((B, m, m)) if want_mass else np.empty((1, m, m))
    h = np.empty((B, m))
    _mass_bias_batch(*system.kernel_arrays(), q, qd, gscale, want_mass, M, h)
    return (M[0] if single else M), (h[0] if single else h)


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
    ok = _fd_batch(*system.kernel_arrays(), q, qd, tau, out)
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
    out = np.empty(q.shape[0])
    a = system.kernel_arrays()
    # dh, jtype, mass, com, G, q0, g
    _potential_batch(a[0], a[1], a[2], a[3], a[6], a[7], a[9], q, out)
    return out[0] if single else out


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
    fail = _simulate_batch(*system.kernel_arrays(), q0, qd0, tq, float(dt), int(substeps),
                           0 if method == "rk4" else 1, pos, vel)
    if fail.any() or not np.isfinite(pos).all():
        raise SimulationError(f"{system.name}: the simulation diverged or met a singular mass matrix",
                              hint="reduce dt or check the inertial parameters")
    return (pos[0], vel[0]) if single else (pos, vel)
