"""Where the batch RLS time goes on this machine: gripkit's compiled batch kernel alone (no ŷ/e,
ŷ/e into reused arrays, into a new (2, N) block), the plain numba RLS of ``bench_rls`` and two
layouts of it (P, θ, φ and q in one buffer at constant offsets, as gripkit's kernel keeps them;
P as a flat array of its own), the cost of a new (2, N) block (page faults and writes) and the
whole ``RLS.run(store=False)``; [3 3 1], N = 1e6, λ = 0.999, windup 'none', 9 alternating runs
each, wall and thread CPU time.

    PYTHONPATH=src python benchmarks/ab_rls_kernel.py
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import bench_rls as B  # noqa: E402
from ab_rls_strip import make_variant  # noqa: E402
import numpy as np  # noqa: E402
from common import print_alternating  # noqa: E402
from numba import njit  # noqa: E402

P6 = 6


@njit(cache=True)
def _plain_split(u, y, lam, p0):  # pragma: no cover - compiled
    """The plain RLS with P as a flat row-major array of its own and θ, φ, q separate."""
    n = u.shape[0]
    P = np.zeros(36)
    th = np.zeros(P6)
    phi = np.zeros(P6)
    q = np.zeros(P6)
    for i in range(P6):
        P[i * P6 + i] = p0
    for t in range(3, n):
        for i in range(3):
            phi[i] = -y[t - 1 - i]
            phi[3 + i] = u[t - 1 - i]
        e = y[t]
        for i in range(P6):
            acc = 0.0
            for j in range(P6):
                acc += P[i * P6 + j] * phi[j]
            q[i] = acc
            e -= phi[i] * th[i]
        r = 0.0
        for i in range(P6):
            r += phi[i] * q[i]
        inv = 1.0 / (lam + r)
        g = e * inv
        for i in range(P6):
            th[i] += q[i] * g
        scale = 1.0 / lam
        for i in range(P6):
            qi = -inv * q[i]
            for j in range(i, P6):
                v = (P[i * P6 + j] + qi * q[j]) * scale
                P[i * P6 + j] = v
                P[j * P6 + i] = v
    return th.copy()


def main() -> None:
    _plain_flat = make_variant("plain", stats=False, trace=False)  # one buffer, constant offsets
    from gripkit.sysid import RLS
    from gripkit.sysid.linear.rls import _rls_run

    n = 1_000_000
    u, y = B._data(n)
    est = RLS(3, 3, 1, forgetting=B.LAM, p0=B.P0, windup="none")
    s0 = est._s.copy()
    size = est._kernel_size(n)
    none, none1 = np.empty((0, 6)), np.empty(0)
    keep = np.empty((2, n))

    def fresh():
        a, b = np.empty((2, n))
        _rls_run(s0.copy(), u, y, none, none, a, b, size)

    fns = {"kernel, no ŷ/e": lambda: _rls_run(s0.copy(), u, y, none, none, none1, none1, size),
           "kernel, ŷ/e into reused arrays":
               lambda: _rls_run(s0.copy(), u, y, none, none, keep[0], keep[1], size),
           "kernel, ŷ/e into a new (2,N) block": fresh,
           "plain numba RLS": lambda: B._plain_rls(u, y, B.LAM, B.P0, none, none),
           "plain, one buffer at constant offsets": lambda: _plain_flat(u, y, B.LAM, B.P0),
           "plain, P a flat array of its own": lambda: _plain_split(u, y, B.LAM, B.P0),
           "new (2,N) block filled (page faults + writes)": lambda: np.empty((2, n)).fill(1.0),
           "RLS.run(store=False)": lambda: RLS(3, 3, 1, forgetting=B.LAM, p0=B.P0,
                                               windup="none").run(u, y, store=False)}
    th = B._plain_rls(u, y, B.LAM, B.P0, none, none)[0]
    print("max |θ| difference of the layouts:",
          max(np.max(np.abs(_plain_flat(u, y, B.LAM, B.P0) - th)),
              np.max(np.abs(_plain_split(u, y, B.LAM, B.P0) - th))))
    print_alternating(fns)


if __name__ == "__main__":
    main()
