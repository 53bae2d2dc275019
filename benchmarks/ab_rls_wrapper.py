"""Where ``RLS(...).run(u, y, store=False)`` spends its time beyond the plain numba RLS, piece by
piece: the input checks as they were (numpy's min and max of each signal for finiteness and
peaks) beside the one scan per signal that now does them and the corrupt-sample test, the scale
check, the batch
kernel with and without the a-priori prediction ŷ and error e (into reused arrays and into a new
(2, N) block), a second pass for the loss e·e (which the kernel now sums as it goes) and the
whole call; beside them the plain numba RLS of ``bench_rls``
(final θ and σ only). [3 3 1], N = 1e6, λ = 0.999, windup 'none', 9 alternating runs each, wall
and thread CPU time.

    PYTHONPATH=src python benchmarks/ab_rls_wrapper.py
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import bench_rls as B  # noqa: E402
import numpy as np  # noqa: E402
from common import print_alternating  # noqa: E402


def main() -> None:
    from gripkit.sysid import RLS
    from gripkit.sysid.checks import check_io_peaks
    from gripkit.sysid.linear.rls import _rls_run, _scan_record

    n = 1_000_000
    u, y = B._data(n)

    def fresh():
        return RLS(3, 3, 1, forgetting=B.LAM, p0=B.P0, windup="none")

    est = fresh()
    uu, yy, scans = _scan_record(u, y, 0.0, 0.0)
    peaks = tuple((sc[2], sc[3]) for sc in scans)
    s0 = est._s.copy()
    size = est._kernel_size(n)
    none, none1 = np.empty((0, 6)), np.empty(0)
    block = np.empty((2, n))

    def new_block():
        a, b = np.empty((2, n))
        _rls_run(s0.copy(), u, y, none, none, a, b, size)

    fns = {
        "numpy min and max of u and y (the checks before)": lambda: check_io_peaks(u, y),
        "one scan per signal (finite, min, max, corrupt samples)":
            lambda: _scan_record(u, y, 0.0, 0.0),
        "scale check (norms)": lambda: est._check_scale(uu, yy, peaks),
        "kernel, no ŷ/e": lambda: _rls_run(s0.copy(), u, y, none, none, none1, none1, size),
        "kernel, ŷ/e into reused arrays":
            lambda: _rls_run(s0.copy(), u, y, none, none, block[0], block[1], size),
        "kernel, ŷ/e into a new (2,N) block": new_block,
        "loss e·e as a second pass (now in the kernel)": lambda: float(block[1] @ block[1]),
        "RLS.run(store=False), whole call": lambda: fresh().run(u, y, store=False),
        "plain numba RLS, final θ and σ": lambda: B._plain_rls(u, y, B.LAM, B.P0, none, none),
    }
    print_alternating(fns)


if __name__ == "__main__":
    main()
