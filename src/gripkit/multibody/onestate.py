"""One-state inverse dynamics with the least call overhead.

A controller or an estimator calls ``chain.rnea(q, qd, qdd)`` on one state at a time; there the
cost is the call, not the arithmetic (a 4-link RNEA is ~0.1 µs). The batched path validates and
stacks its inputs and passes 17 arrays to the kernel (~11 µs per call, measured on the DLR/HIT
finger). This path packs the model once into one float and one integer array (:func:`pack`) and
keeps the scratch memory with the chain, so a call is one ``np.empty`` and one call of a kernel
compiled for 1-D float64 arrays only, with seven arguments; other argument types raise TypeError
at the call, and the kernel reports a state of the wrong length or with NaN/inf: the caller then
takes the validating path, which raises the error. The scratch is shared by the calls on one
chain, which is safe because the kernel holds the GIL. Measured in
``benchmarks/bench_urdf.py`` against one ``pinocchio.rnea`` call.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .kernels import WORK_PER_LINK, chain_links, rnea_pass

__all__ = ["pack", "rnea_one", "prepare"]

_HEADER = 12


def pack(arrays):
    """(floats, ints, work) for :func:`rnea_one` from a system's ``kernel_arrays()``."""
    dh, jt, mass, com, inertia, arm_q, G, q0, arm_p, g = arrays
    n, w = dh.shape
    m = arm_p.shape[0]
    parts = [dh.ravel(), mass, com.ravel(), inertia.ravel(), arm_q, G.ravel(), q0, arm_p, g]
    offsets = np.cumsum([0] + [p.size for p in parts])
    fl = np.ascontiguousarray(np.concatenate(parts), dtype=np.float64)
    it = np.zeros(_HEADER + n, dtype=np.int64)
    it[:3] = n, m, w
    it[3:_HEADER] = offsets[:9]
    it[_HEADER:] = jt
    work = np.empty(12 * n + WORK_PER_LINK * n + 4 * n)
    return fl, it, work


@numba.njit("b1(f8[::1], i8[::1], f8[::1], f8[::1], f8[::1], f8[::1], f8[::1])", cache=True,
            error_model="numpy", _nrt=False)
def rnea_one(fl, it, q, qd, qdd, out, work):  # pragma: no cover - compiled
    """τ_p = Γᵀ RNEA(Γ p + q₀, Γ ṗ, Γ p̈) + armature_p·p̈ for one state; False when the state has
    NaN or inf or the wrong length (out untouched). Compiled for 1-D float64 arrays only
    (other types raise TypeError at the call)."""
    n = it[0]
    m = it[1]
    w = it[2]
    if q.shape[0] != m or qd.shape[0] != m or qdd.shape[0] != m:
        return False
    for i in range(m):
        if not (math.isfinite(q[i]) and math.isfinite(qd[i]) and math.isfinite(qdd[i])):
            return False
    dh = fl[it[3]:it[3] + n * w].reshape((n, w))
    mass = fl[it[4]:it[4] + n]
    com = fl[it[5]:it[5] + 3 * n].reshape((n, 3))
    inertia = fl[it[6]:it[6] + 6 * n].reshape((n, 6))
    arm_q = fl[it[7]:it[7] + n]
    G = fl[it[8]:it[8] + n * m]
    q0 = fl[it[9]:it[9] + n]
    arm_p = fl[it[10]:it[10] + m]
    o = it[11]
    jtype = it[_HEADER:_HEADER + n]
    R = work[0:9 * n].reshape((n, 9))
    P = work[9 * n:12 * n].reshape((n, 3))
    wk = work[12 * n:12 * n + WORK_PER_LINK * n]
    b = 12 * n + WORK_PER_LINK * n
    qq = work[b:b + n]
    qqd = work[b + n:b + 2 * n]
    qqdd = work[b + 2 * n:b + 3 * n]
    tau = work[b + 3 * n:b + 4 * n]
    for k in range(n):
        s = q0[k]
        sd = 0.0
        sdd = 0.0
        for a in range(m):
            gk = G[k * m + a]
            s += gk * q[a]
            sd += gk * qd[a]
            sdd += gk * qdd[a]
        qq[k] = s
        qqd[k] = sd
        qqdd[k] = sdd
    chain_links(n, dh, jtype, qq, R, P)
    rnea_pass(n, R, P, jtype, mass, com, inertia, arm_q, qqd, qqdd, fl[o], fl[o + 1], fl[o + 2],
              True, tau, wk)
    for a in range(m):
        s = arm_p[a] * qdd[a]
        for k in range(n):
            s += G[k * m + a] * tau[k]
        out[a] = s
    return True


def prepare(system):
    """(kernel, floats, ints, work, m) of ``system`` for ``Dynamics.rnea``."""
    fl, it, work = pack(system.kernel_arrays())
    return rnea_one, fl, it, work, system.dof
