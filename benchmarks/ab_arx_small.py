"""``arx`` at N = 10⁴ and 10⁶ beside the bare normal equations, for an A/B of two source trees
(issue 24: ARX at N = 10⁴ ≤ 1.5× the bare normal equations; N = 10⁶ as fast as before).

``python benchmarks/ab_arx_small.py [runs]`` with ``PYTHONPATH`` set to the ``src`` of the tree
to time; run it for each tree in turn (A B A B …), BLAS on one thread. In one process it times,
alternating, one call each per run (warm: one call of each before):

* ``arx(u, y, 2, 2, 2)`` at N = 10⁴ (``bench_arx_small._data``, Table II's [2 2 2] system) and
  the bare normal equations of the same regression (``bench_arx_small._bare``);
* ``arx(u, y, 4, 4, 2)`` at N = 10⁶ (``bench_sysid._data``, the big-N ARX row's data) and
  that row's numpy normal equations (``bench_sysid._normal_equations``), in a second phase.

It prints wall-clock and thread-CPU median and min per call, the ratios to the bare route, the
route ``arx`` took, and the CPU model.
"""

import os
import sys
import time
from pathlib import Path

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).parent))

from bench_arx_small import _bare  # noqa: E402
from bench_arx_small import _data as small_data  # noqa: E402
from bench_sysid import _data as big_data  # noqa: E402


def _cpu() -> str:
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return "?"


def _alternate(fns: dict, runs: int) -> dict:
    """{name: {"wall": (median, min), "cpu": (median, min)}} per call, the callables in turn."""
    for fn in fns.values():
        fn()
    wall = {k: [] for k in fns}
    cpu = {k: [] for k in fns}
    for _ in range(runs):
        for k, fn in fns.items():
            w0, c0 = time.perf_counter(), time.thread_time()
            fn()
            c1, w1 = time.thread_time(), time.perf_counter()
            wall[k].append(w1 - w0)
            cpu[k].append(c1 - c0)
    return {k: {"wall": (float(np.median(wall[k])), min(wall[k])),
                "cpu": (float(np.median(cpu[k])), min(cpu[k]))} for k in fns}


def main(runs: int = 15) -> dict:
    from bench_sysid import _normal_equations

    from gripkit.sysid import arx

    u, y = small_data(10_000)
    ub, yb = big_data(1_000_000)
    # two phases: a 10⁶-sample call between the small ones would leave them cold (caches and
    # branch predictors refilled by 16 MB of data), which is not how repeated small fits run
    out = _alternate({"arx N=1e4": lambda: arx(u, y, 2, 2, 2), "bare N=1e4": lambda: _bare(u, y)},
                     runs)
    out |= _alternate({"arx N=1e6": lambda: arx(ub, yb, 4, 4, 2),
                       "numpy NE N=1e6": lambda: _normal_equations(ub, yb)}, runs)
    m = arx(u, y, 2, 2, 2)
    print(f"src {arx.__code__.co_filename}; CPU {_cpu()}; load {os.getloadavg()[0]:.1f}; "
          f"BLAS threads {os.environ['OPENBLAS_NUM_THREADS']}; {runs} runs")
    print(f"N=1e4 route: {m.info['method']} (cond {m.info['cond']:.3g}); "
          f"N=1e6 route: {arx(ub, yb, 4, 4, 2).info['method']}")
    for k, v in out.items():
        print(f"{k:14s} wall median {v['wall'][0] * 1e6:9.1f} µs min {v['wall'][1] * 1e6:9.1f} µs"
              f" | cpu median {v['cpu'][0] * 1e6:9.1f} µs min {v['cpu'][1] * 1e6:9.1f} µs")
    for clock in ("wall", "cpu"):
        a, b = out["arx N=1e4"][clock], out["bare N=1e4"][clock]
        print(f"ratio arx/bare N=1e4 ({clock}): median {a[0] / b[0]:.2f}, min {a[1] / b[1]:.2f}")
    return out


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 15)
