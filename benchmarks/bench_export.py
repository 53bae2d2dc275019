"""The exported C step (``gripkit export c``, issue 27) on the target-like path: latency and jitter
of ``NAME_step`` for a 2×2 state-space model of order 6, compiled with ``gcc -O2``, over 10⁶
steps timed in blocks of 16 (``clock_gettime``), reported as min, median, p99, p99.9 and max ns
per step; beside it, the same model's free run per sample in gripkit's numba kernel
(``lti.simulate_ss``), the route a Python user has. Issue 27's target: ≤ 150 ns median.

Both sides compute the same outputs (checked to 1e-12 relative before timing).

Controllers and the RLS update (:func:`controller_rows`): the exported ``NAME_update`` of an RLS
[3 3 1] estimator (target ≤ 100 ns median), and the ``NAME_step`` of a PID, an RST controller
(a third-order plant's design) and a 2-input, 3-state LQR state feedback, each timed the same
way over 10⁶ steps (min, median, p99, p99.9, max ns per step, blocks of 16); beside each, the
numba ``.update``/``.step`` called from Python per sample, timed with the same blocks and
percentiles (``time.perf_counter_ns``)."""

from __future__ import annotations

import json
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np
from common import measure, row

ORDER, M, P = 6, 2, 2
STEPS, BLOCK = 1_000_000, 16

_HARNESS = r"""
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "bench.h"
static double now_ns(void) {
    struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t);
    return 1e9 * (double)t.tv_sec + (double)t.tv_nsec;
}
static int cmp(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b; return (x > y) - (x < y);
}
int main(int argc, char **argv) {
    if (argc < 4) return 2;
    long steps = atol(argv[1]), block = atol(argv[2]), nb = steps / block;
    double *per = malloc(sizeof(double) * (size_t)nb), u[BENCH_NU], y[BENCH_NY], sink = 0.0;
    bench_state s; bench_init(&s);
    FILE *f = fopen(argv[3], "w");  /* the first 1000 outputs, to check against Python */
    for (long k = 0; k < 1000; ++k) {
        for (int i = 0; i < BENCH_NU; ++i) u[i] = (double)((k * (i + 3)) % 17) / 17.0 - 0.5;
        bench_step(&s, u, y);
        for (int j = 0; j < BENCH_NY; ++j)
            fprintf(f, "%.17g%c", y[j], j + 1 < BENCH_NY ? ',' : '\n');
    }
    fclose(f);
    for (long b = 0; b < nb; ++b) {
        double t0 = now_ns();
        for (long k = 0; k < block; ++k) {
            u[0] = (double)(k & 7) * 0.1; u[1] = -u[0];
            bench_step(&s, u, y);
            sink += y[0];
        }
        per[b] = (now_ns() - t0) / (double)block;
    }
    qsort(per, (size_t)nb, sizeof(double), cmp);
    printf("{\"min\": %.3f, \"median\": %.3f, \"p99\": %.3f, \"p999\": %.3f, "
           "\"max\": %.3f, \"sink\": %g}\n",
           per[0], per[nb / 2], per[(long)(0.99 * nb)], per[(long)(0.999 * nb)], per[nb - 1], sink);
    return 0;
}
"""


_KF_HARNESS = r"""
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "kf.h"
static double now_ns(void) {
    struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t);
    return 1e9 * (double)t.tv_sec + (double)t.tv_nsec;
}
static int cmp(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b; return (x > y) - (x < y);
}
static void input(long k, double u[KF_NU], double y[KF_NY]) {
    for (int i = 0; i < KF_NU; ++i) u[i] = (double)((k * (i + 3)) % 17) / 17.0 - 0.5;
    for (int i = 0; i < KF_NY; ++i) y[i] = (double)((k * (i + 5)) % 13) / 13.0 + 1.0;
}
int main(int argc, char **argv) {
    if (argc < 4) return 2;
    long steps = atol(argv[1]), block = atol(argv[2]), nb = steps / block;
    double *per = malloc(sizeof(double) * (size_t)nb), u[KF_NU], y[KF_NY], x[KF_NX], sink = 0.0;
    kf_kf_state s; kf_kf_init(&s);
    FILE *f = fopen(argv[3], "w");  /* the first 1000 estimates, to check against Python */
    for (long k = 0; k < 1000; ++k) {
        input(k, u, y);
        kf_kf_step(&s, u, y, x);
        for (int j = 0; j < KF_NX; ++j) fprintf(f, "%.17g%c", x[j], j + 1 < KF_NX ? ',' : '\n');
    }
    fclose(f);
    for (long b = 0; b < nb; ++b) {
        double t0 = now_ns();
        for (long k = 0; k < block; ++k) {
            u[0] = (double)(k & 7) * 0.1; u[1] = -u[0]; y[0] = 1.0 + u[0]; y[1] = 2.0 - u[0];
            kf_kf_step(&s, u, y, x);
            sink += x[0];
        }
        per[b] = (now_ns() - t0) / (double)block;
    }
    qsort(per, (size_t)nb, sizeof(double), cmp);
    printf("{\"min\": %.3f, \"median\": %.3f, \"p99\": %.3f, \"p999\": %.3f, "
           "\"max\": %.3f, \"sink\": %g}\n",
           per[0], per[nb / 2], per[(long)(0.99 * nb)], per[(long)(0.999 * nb)], per[nb - 1], sink);
    return 0;
}
"""


def _model():
    """A stable 2×2 model of order 6 (poles of modulus 0.6–0.95) with offsets."""
    from gripkit.lti import StateSpace
    from gripkit.sysid import LinearModel

    rng = np.random.default_rng(7)
    Q, _ = np.linalg.qr(rng.standard_normal((ORDER, ORDER)))
    A = Q @ np.diag(np.linspace(0.6, 0.95, ORDER)) @ Q.T
    ss = StateSpace(A, rng.standard_normal((ORDER, M)), rng.standard_normal((P, ORDER)),
                    np.zeros((P, M)), dt=0.001, inputs=("u1", "u2"), outputs=("y1", "y2"))
    return LinearModel(ss, "n4sid", u_offset=(0.5, -0.25), y_offset=(1.0, 2.0))


def run(quick: bool) -> list[dict]:
    """The model's C step, the controllers' and RLS update's (:func:`controller_rows`) and the
    Kalman filter's (:func:`run_kalman`)."""
    return model_rows(quick) + controller_rows(quick) + run_kalman(quick)


def model_rows(quick: bool) -> list[dict]:
    from gripkit.export import export_c

    gcc = shutil.which("gcc")
    if gcc is None:
        return [row("export", "C step, 2x2 order 6", None, "numba simulate_ss", None,
                    notes="gcc not found: not measured")]
    model = _model()
    steps = STEPS // 10 if quick else STEPS
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        export_c(model, d, "bench")
        (d / "harness.c").write_text(_HARNESS)
        exe = d / "bench"
        cc = subprocess.run([gcc, "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-o", str(exe),
                             str(d / "harness.c"), str(d / "bench.c"), "-lm"], capture_output=True,
                             text=True)
        if cc.returncode:
            raise RuntimeError(cc.stderr)
        res = subprocess.run([str(exe), str(steps), str(BLOCK), str(d / "y.csv")], check=True,
                             capture_output=True, text=True)
        stats = json.loads(res.stdout)
        y_c = np.loadtxt(d / "y.csv", delimiter=",")
    k = np.arange(1000)
    u = np.column_stack([((k * (i + 3)) % 17) / 17.0 - 0.5 for i in range(M)])
    y_py = model.simulate(u - np.asarray(model.u_offset)) + np.asarray(model.y_offset)
    err = float(np.max(np.abs(y_c - y_py) / np.maximum(np.abs(y_py), 1e-300)))
    if err > 1e-12:
        raise AssertionError(f"exported step differs from Python by {err:.3g} relative")
    uu = np.ascontiguousarray(np.tile(u, (steps // 1000, 1)))
    numba_run = measure(lambda: model.simulate(uu))
    per_numba = numba_run.median / uu.shape[0]
    return [row("export", f"C step of a 2x2 order-{ORDER} model, ns per step (gcc -O2, blocks of "
                f"{BLOCK}, {steps} steps)", stats["median"] * 1e-9, "numba simulate_ss, per sample "
                "of a batch free run", per_numba, target="<= 150 ns median (issue 27)",
                gripkit_accuracy=f"outputs = Python to {err:.1e} relative",
                extra={k: stats[k] for k in ("min", "median", "p99", "p999", "max")})]


_CTRL_HARNESS = r"""
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "HEADER"
static double now_ns(void) {
    struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t);
    return 1e9 * (double)t.tv_sec + (double)t.tv_nsec;
}
static int cmp(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b; return (x > y) - (x < y);
}
int main(int argc, char **argv) {
    if (argc < 3) return 2;
    long steps = atol(argv[1]), block = atol(argv[2]), nb = steps / block;
    double *per = malloc(sizeof(double) * (size_t)nb), sink = 0.0, yv = 0.0, up = 0.0;
    DECLARE
    for (long b = 0; b < nb; ++b) {
        double t0 = now_ns();
        for (long k = 0; k < block; ++k) {
            double in = (double)((k * 7 + b) % 17) / 17.0 - 0.5;
            yv = 0.7 * yv + 0.5 * up; up = in;
            STEP
        }
        per[b] = (now_ns() - t0) / (double)block;
    }
    qsort(per, (size_t)nb, sizeof(double), cmp);
    printf("{\"min\": %.3f, \"median\": %.3f, \"p99\": %.3f, \"p999\": %.3f, \"max\": %.3f, "
           "\"sink\": %g}\n", per[0], per[nb / 2], per[(long)(0.99 * nb)],
           per[(long)(0.999 * nb)], per[nb - 1], sink);
    return 0;
}
"""


def _percentiles(per: np.ndarray) -> dict:
    per = np.sort(per)
    nb = per.size
    return {"min": float(per[0]), "median": float(per[nb // 2]), "p99": float(per[int(0.99 * nb)]),
            "p999": float(per[int(0.999 * nb)]), "max": float(per[-1])}


def _python_per_step(fn, steps: int) -> dict:
    """ns per call of ``fn(k)`` in blocks of BLOCK calls, percentiles over the blocks."""
    import gc
    import time

    nb = steps // BLOCK
    per = np.empty(nb)
    ins = [((k * 7) % 17) / 17.0 - 0.5 for k in range(BLOCK)]
    for k in range(200):
        fn(ins[k % BLOCK])
    gc.disable()
    try:
        for b in range(nb):
            t0 = time.perf_counter_ns()
            for x in ins:
                fn(x)
            per[b] = (time.perf_counter_ns() - t0) / BLOCK
    finally:
        gc.enable()
    return _percentiles(per)


def _controllers():
    """(label, files, DECLARE, STEP, python step, target) for each timed controller."""
    from gripkit.control import PID, design_rst, lqr_controller
    from gripkit.export import controller_c_sources, rls_c_sources
    from gripkit.lti import StateSpace, TransferFunction
    from gripkit.sysid import RLS

    est = RLS(3, 3, 1, forgetting=0.99, p0=100.0)
    state = {"y": 0.0, "u": 0.0}

    def rls_py(x):
        state["y"] = 0.7 * state["y"] + 0.5 * state["u"]
        state["u"] = x
        est.update(x, state["y"])
    pid = PID(2.0, 40.0, 0.05, dt=0.001, u_min=-1.0, u_max=1.0)
    g = TransferFunction.from_polynomials([1.0, -2.2, 1.61, -0.392], [0.0, 0.1, 0.05, 0.01],
                                          dt=0.001)
    rst = design_rst(g, wn=40.0, zeta=0.8, u_min=-1.0, u_max=1.0)
    A = np.array([[0.9, 0.1, 0.0], [0.0, 0.8, 0.2], [0.05, 0.0, 0.7]])
    B = np.array([[1.0, 0.0], [0.2, 0.5], [0.0, 1.0]])
    sf = lqr_controller(StateSpace(A, B, np.array([[1.0, 0, 0], [0, 0, 1.0]]), np.zeros((2, 2)),
                                   dt=0.001), np.eye(3), 0.1 * np.eye(2), u_min=-1.0, u_max=1.0)
    xs, rs, us = np.zeros(3), np.array([0.2, -0.1]), np.empty(2)

    def lqr_py(x):
        xs[0], xs[1], xs[2] = x, -x, 0.5 * x
        sf.step(xs, rs, out=us)
    return [
        ("RLS [3 3 1] update (lambda 0.99, trace windup)", rls_c_sources(est, "bench"),
         "bench_state s; bench_init(&s);", "sink += bench_update(&s, in, yv);", rls_py,
         "<= 100 ns median (issue 27)"),
        ("PID step (filtered D, limits, anti-windup)", controller_c_sources(pid, "bench"),
         "bench_state s; bench_init(&s);", "sink += bench_step(&s, 0.2, in, 0.0);",
         lambda x: pid.step(0.2, x), ""),
        (f"RST step (third-order plant, n = {rst.R.size})", controller_c_sources(rst, "bench"),
         "bench_state s; bench_init(&s);", "sink += bench_step(&s, 0.2, in);",
         lambda x: rst.step(0.2, x), ""),
        ("LQR state feedback step (2 inputs, 3 states, reference)",
         controller_c_sources(sf, "bench"),
         "double x[3], r[2] = {0.2, -0.1}, u[2];",
         "x[0] = in; x[1] = -in; x[2] = 0.5 * in; bench_step(x, r, u); sink += u[0];",
         lqr_py, ""),
    ]


def controller_rows(quick: bool) -> list[dict]:
    gcc = shutil.which("gcc")
    steps = STEPS // 10 if quick else STEPS
    rows = []
    for label, files, declare, step, py_step, target in _controllers():
        py = _python_per_step(py_step, steps)
        if gcc is None:
            rows.append(row("export", f"C {label}", None, "numba step from Python", None,
                            notes="gcc not found: not measured", extra={"python": py}))
            continue
        with tempfile.TemporaryDirectory() as tmp:
            d = Path(tmp)
            for fname, text in files.items():
                (d / fname).write_text(text)
            (d / "harness.c").write_text(_CTRL_HARNESS.replace("HEADER", "bench.h")
                                         .replace("DECLARE", declare).replace("STEP", step))
            exe = d / "bench"
            cc = subprocess.run([gcc, "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-o",
                                 str(exe), str(d / "harness.c"), str(d / "bench.c"), "-lm"],
                                capture_output=True, text=True)
            if cc.returncode:
                raise RuntimeError(cc.stderr)
            res = subprocess.run([str(exe), str(steps), str(BLOCK)], check=True,
                                 capture_output=True, text=True)
        stats = json.loads(res.stdout)
        c = {k: stats[k] for k in ("min", "median", "p99", "p999", "max")}
        rows.append(row("export", f"C {label}, ns per step (gcc -O2, blocks of {BLOCK}, {steps} "
                        "steps)", c["median"] * 1e-9, "the numba step called from Python, "
                        "per call", py["median"] * 1e-9, target=target,
                        gripkit_accuracy="C = Python to 1e-12 (tests/export/test_c_controllers.py)",
                        extra={"c": c, "python": py}))
    return rows


if __name__ == "__main__":
    import sys

    quick = "--quick" in sys.argv
    for r in run(quick=quick):
        print(json.dumps(r))


def _python_kf_steps(kf, u, y, steps: int) -> dict:
    """``kf.step(u_k, y_k, copy=False)`` from Python, timed in blocks of BLOCK calls."""
    import time

    nb = steps // BLOCK
    per = np.empty(nb)
    clock = time.perf_counter_ns
    for k in range(1000):  # warm: compiled, caches filled
        kf.step(u[k % BLOCK], y[k % BLOCK], copy=False)
    for b in range(nb):
        t0 = clock()
        for k in range(BLOCK):
            kf.step(u[k], y[k], copy=False)
        per[b] = (clock() - t0) / BLOCK
    return _percentiles(per)


def run_kalman(quick: bool) -> list[dict]:
    """The steady-state Kalman filter's C step and its numba step from Python."""
    from gripkit.estimation import KalmanFilter
    from gripkit.export import export_kalman_c

    gcc = shutil.which("gcc")
    if gcc is None:
        return [row("export", "C Kalman step, 2x2 order 6", None, "numba KalmanFilter.step", None,
                    notes="gcc not found: not measured")]
    model = _model()
    Qn, Rn = 1e-3 * np.eye(ORDER), 1e-2 * np.eye(P)
    steps = STEPS // 10 if quick else STEPS
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        export_kalman_c(model, d, "kf", Qn, Rn)
        (d / "harness.c").write_text(_KF_HARNESS)
        exe = d / "kf"
        cc = subprocess.run([gcc, "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-o", str(exe),
                             str(d / "harness.c"), str(d / "kf.c"), "-lm"],
                            capture_output=True, text=True)
        if cc.returncode:
            raise RuntimeError(cc.stderr)
        res = subprocess.run([str(exe), str(steps), str(BLOCK), str(d / "x.csv")], check=True,
                             capture_output=True, text=True)
        stats = json.loads(res.stdout)
        x_c = np.loadtxt(d / "x.csv", delimiter=",")
    k = np.arange(1000)
    u = np.column_stack([((k * (i + 3)) % 17) / 17.0 - 0.5 for i in range(M)])
    y = np.column_stack([((k * (i + 5)) % 13) / 13.0 + 1.0 for i in range(P)])
    x_py = KalmanFilter(model, Qn, Rn, steady_state=True).run_arrays(u, y).x
    err = float(np.max(np.abs(x_c - x_py)) / np.max(np.abs(x_py)))
    if err > 1e-12:
        raise AssertionError(f"exported Kalman step differs from Python by {err:.3g} relative")
    kf = KalmanFilter(model, Qn, Rn, steady_state=True)
    py = _python_kf_steps(kf, np.ascontiguousarray(u), np.ascontiguousarray(y), steps)
    return [row("export", f"C steady-state Kalman step of a 2x2 order-{ORDER} model, ns per step "
                f"(gcc -O2, blocks of {BLOCK}, {steps} steps)", stats["median"] * 1e-9,
                f"numba KalmanFilter.step(copy=False) called from Python ({steps} steps)",
                py["median"] * 1e-9, target="<= 400 ns median (issue 27)",
                gripkit_accuracy=f"x_hat = Python to {err:.1e} relative",
                extra={"c": {k: stats[k] for k in ("min", "median", "p99", "p999", "max")},
                       "python_step": py})]


if __name__ == "__main__":
    for r in run(quick=False):
        print(json.dumps(r))
