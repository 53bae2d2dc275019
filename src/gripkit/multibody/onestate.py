"""One-state inverse dynamics and mass matrix with the least call overhead.

A controller or an estimator calls ``chain.rnea(q, qd, qdd)`` on one state at a time; there the
cost is the call, not the arithmetic. The batched path validates and stacks its inputs and
passes 17 arrays to the kernel (the figures: docs/performance.md, "One-state RNEA and CRBA").
This path packs the model and its scratch memory once into one float64 array
(:func:`pack`) kept with the chain, so a call is one ``np.empty`` and one call of a kernel compiled
for float64 arrays only, with three (mass matrix) or five (RNEA) arguments: unboxing an argument
is most of the cost of a call. Other argument types raise TypeError
at the call, and the kernel reports a state of the wrong length or with NaN/inf: the caller then
takes the validating path, which raises the error. The scratch is shared by the calls on one
chain, which is safe because the kernels hold the GIL (compiled without ``nogil``): calls from
several threads run one after the other. The buffer is for these two kernels only; the batched
and ``prange`` kernels take their own scratch per state, never this buffer. The mass matrix
(:func:`mass_matrix_one`, CRBA) takes the same path. Measured in ``benchmarks/bench_urdf.py`` and
``benchmarks/bench_multibody.py`` against one ``pinocchio.rnea`` / ``pinocchio.crba`` call.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .kernels import (WORK_PER_LINK, ChainArrays, chain_links, crba, hot_inline, links_of,
                      project_mass, rnea_pass)

__all__ = ["mass_matrix_entry", "mass_matrix_one", "pack", "prepare", "rnea_one"]

#: header of the packed buffer: n, m, dh width, then the offsets of dh, mass, com, inertia,
#: arm_q, Γ, q₀, arm_p, gravity, joint types and the scratch
_HEADER = 14


def pack(arrays) -> np.ndarray:
    """One float64 buffer for :func:`rnea_one` and :func:`mass_matrix_one` from a system's
    ``kernel_arrays()``: a header of sizes and offsets (small integers, exact as floats), the
    model, and the scratch the kernels write. One array is one argument to unbox per call."""
    dh, jt, mass, com, inertia, arm_q, G, q0, arm_p, g = arrays
    n, w = dh.shape
    m = arm_p.shape[0]
    parts = [dh.ravel(), mass, com.ravel(), inertia.ravel(), arm_q, G.ravel(), q0, arm_p, g,
             np.asarray(jt, dtype=np.float64),
             np.zeros(12 * n + WORK_PER_LINK * n + 4 * n + n * n)]
    offsets = _HEADER + np.cumsum([0] + [p.size for p in parts])
    return np.concatenate([[n, m, w], offsets[:11], *parts]).astype(np.float64)




@hot_inline
def _model(buf):  # pragma: no cover - compiled
    """Views of the packed buffer (no allocation): sizes, the model as a :data:`ChainArrays`
    record (joint types as floats) and the scratch."""
    n = int(buf[0])
    m = int(buf[1])
    w = int(buf[2])
    o = buf[3:_HEADER]
    dh = buf[int(o[0]):int(o[0]) + n * w].reshape((n, w))
    mass = buf[int(o[1]):int(o[1]) + n]
    com = buf[int(o[2]):int(o[2]) + 3 * n].reshape((n, 3))
    inertia = buf[int(o[3]):int(o[3]) + 6 * n].reshape((n, 6))
    arm_q = buf[int(o[4]):int(o[4]) + n]
    G = buf[int(o[5]):int(o[5]) + n * m]
    q0 = buf[int(o[6]):int(o[6]) + n]
    arm_p = buf[int(o[7]):int(o[7]) + m]
    g = buf[int(o[8]):int(o[8]) + 3]
    jtype = buf[int(o[9]):int(o[9]) + n]
    work = buf[int(o[10]):]
    return n, m, ChainArrays(dh, jtype, mass, com, inertia, arm_q, G, q0, arm_p, g), work


@hot_inline
def _finite(m, q):  # pragma: no cover - compiled
    if q.shape[0] != m:
        return False
    for i in range(m):
        if not math.isfinite(q[i]):
            return False
    return True


@hot_inline
def _links(n, m, ch, q, work):  # pragma: no cover - compiled
    """Joint positions Γ p + q₀ into the scratch and the link transforms R, P for them."""
    G, q0 = ch.G, ch.q0
    R = work[0:9 * n].reshape((n, 9))
    P = work[9 * n:12 * n].reshape((n, 3))
    qq = work[12 * n + WORK_PER_LINK * n:13 * n + WORK_PER_LINK * n]
    for k in range(n):
        s = q0[k]
        for a in range(m):
            s += G[k * m + a] * q[a]
        qq[k] = s
    chain_links(n, ch.links, ch.jtype, qq, R, P)
    return R, P


@numba.njit("b1(f8[::1], f8[::1], f8[::1], "
            "f8[::1], f8[::1])", cache=True, error_model="numpy", _nrt=False)
def rnea_one(buf, q, qd, qdd, out):  # pragma: no cover - compiled
    """τ_p = Γᵀ RNEA(Γ p + q₀, Γ ṗ, Γ p̈) + armature_p·p̈ for one state; False when the state has
    NaN or inf or the wrong length, or ``out`` is not of length m (out untouched). Compiled for 1-D
    float64 arrays only
    (other types raise TypeError at the call)."""
    n, m, ch, work = _model(buf)
    if out.shape[0] != m or not (_finite(m, q) and _finite(m, qd) and _finite(m, qdd)):
        return False
    G, g, arm_p = ch.G, ch.g, ch.arm_p
    R, P = _links(n, m, ch, q, work)
    b = 12 * n + WORK_PER_LINK * n
    qqd = work[b + n:b + 2 * n]
    qqdd = work[b + 2 * n:b + 3 * n]
    tau = work[b + 3 * n:b + 4 * n]
    for k in range(n):
        sd = 0.0
        sdd = 0.0
        for a in range(m):
            gk = G[k * m + a]
            sd += gk * qd[a]
            sdd += gk * qdd[a]
        qqd[k] = sd
        qqdd[k] = sdd
    rnea_pass(n, links_of(ch), R, P, qqd, qqdd, g[0], g[1], g[2], True, tau, work[12 * n:b])
    for a in range(m):
        s = arm_p[a] * qdd[a]
        for k in range(n):
            s += G[k * m + a] * tau[k]
        out[a] = s
    return True


@numba.njit("b1(f8[::1], f8[::1], f8[:, ::1])", cache=True, error_model="numpy", _nrt=False)
def mass_matrix_one(buf, q, out):  # pragma: no cover - compiled
    """M_p = Γᵀ M(Γ p + q₀) Γ + diag(armature_p) (CRBA, thesis eqs 4.14–4.16) for one state into
    ``out`` (m×m); False when q has NaN or inf or the wrong length, or ``out`` is not m×m (out
    untouched)."""
    n, m, ch, work = _model(buf)
    if out.shape[0] != m or out.shape[1] != m or not _finite(m, q):
        return False
    R, P = _links(n, m, ch, q, work)
    b = 12 * n + WORK_PER_LINK * n
    Mq = work[b + 4 * n:b + 4 * n + n * n].reshape((n, n))
    crba(n, links_of(ch), R, P, Mq, work[12 * n:b])
    project_mass(n, m, Mq, ch.G, ch.arm_p, out)
    return True


def mass_matrix_entry():
    """The compiled :func:`mass_matrix_one`'s own CPython wrapper (numba's ``entry_point`` for its
    one signature): it unboxes its three arguments as the declared types without the
    dispatcher's type resolution (docs/performance.md, CRBA). It does not check them: numba reads
    any array with 8-byte items as float64 and an array of more dimensions past the declared ones,
    so only :meth:`~gripkit.multibody.dh.Dynamics.mass_matrix` calls it, with the chain's packed
    buffer, a fresh C-contiguous (m, m) float64 array, and a state that is an exact 1-D float64
    ndarray of stride 8 (checked in Python first). The dispatcher where numba has no
    ``entry_point``."""
    sig = next(iter(mass_matrix_one.overloads))
    return getattr(mass_matrix_one.overloads[sig], "entry_point", mass_matrix_one)


def prepare(system):
    """(packed buffer, m, (m, m), :func:`mass_matrix_entry`) of ``system`` for ``Dynamics.rnea``
    and ``Dynamics.mass_matrix`` (the shape tuple made once: building it per call is a
    measurable part of a call)."""
    m = system.dof
    return pack(system.kernel_arrays()), m, (m, m), mass_matrix_entry()
