"""Where the batch RLS time goes on this machine: gripkit's compiled batch kernel alone (no ŷ/e,
ŷ/e into reused arrays, into a new (2, N) block), the plain numba RLS of ``bench_rls``, the cost
of a new (2, N) block (page faults and writes) and the whole ``RLS.run(store=False)``; [3 3 1],
N = 1e6, λ = 0.999, windup 'none', 9 alternating runs each, wall and thread CPU time.

    PYTHONPATH=src python benchmarks/ab_rls_kernel.py
"""

from __future__ import annotations

import os
import time

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import bench_rls as B  # noqa: E402
import numpy as np  # noqa: E402
from common import measure_alternating  # noqa: E402


def main() -> None:
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
           "new (2,N) block filled (page faults + writes)": lambda: np.empty((2, n)).fill(1.0),
           "RLS.run(store=False)": lambda: RLS(3, 3, 1, forgetting=B.LAM, p0=B.P0,
                                               windup="none").run(u, y, store=False)}
    for clock, label in ((time.perf_counter, "wall"), (time.thread_time, "thread cpu")):
        times = measure_alternating(list(fns.values()), runs=9, clock=clock)
        print(f"--- {label}, median (min) ms")
        for name, t in zip(fns, times):
            print(f"{name:50s} {float(t) * 1e3:8.2f} ({t.min * 1e3:8.2f})")


if __name__ == "__main__":
    main()
