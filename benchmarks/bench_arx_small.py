"""ARX [2 2 2] at N = 10⁴ beside the bare normal equations (issue 24 target: ``arx`` ≤ 1.5× their
time), and where ``arx``'s time goes.

The bare route is what a user would write for one fit: Φ by ``np.column_stack`` of shifted
slices, ``np.linalg.solve(ΦᵀΦ, ΦᵀY)``, nothing else (no checks, σ, residuals or model object).
``arx`` rows: the default call (at this size, 2¹⁵ < ``m·(p+1)`` ≤ ``arx.QR_MAX_ELEMENTS``, the
normal equations of the materialised ``[Φ | Y]``'s BLAS Gram matrix when κ ≤
``arx.blas_gram_cond_limit(m)``, else QR) and the same call routed through the numba lagged-sums
normal equations (``QR_MAX_ELEMENTS = 0``, as the default does from 2¹⁸ elements on). The QR
route's pieces (as the default took them at this size before issue 24) are timed alone in the
``extra`` of the first row. All sides alternate
(``measure_alternating``), BLAS on one thread, median and min of 15, in wall-clock time and (in
``extra``) in thread CPU time.
"""

from __future__ import annotations

import importlib
import time

import numpy as np
from common import measure_alternating, row
from scipy.signal import lfilter

N = 10_000


def _data(n: int, seed: int = 3):
    """Table II [2 2 2] system (A = [1, −1.5, 0.7], B = [0, 0, 1, 0.5]) with white input and
    equation noise."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    a = [1.0, -1.5, 0.7]
    y = lfilter([0.0, 0.0, 1.0, 0.5], a, u) + lfilter([1.0], a, 0.1 * rng.standard_normal(n))
    return u, y


def _bare(u, y):
    """θ = (ΦᵀΦ)⁻¹ΦᵀY for ARX [2 2 2]: rows t = 3 … N−1, φ = [−y(t−1), −y(t−2), u(t−2), u(t−3)]."""
    n = y.size
    phi = np.column_stack([-y[2:n - 1], -y[1:n - 2], u[1:n - 2], u[0:n - 3]])
    Y = y[3:]
    return np.linalg.solve(phi.T @ phi, phi.T @ Y)


def run(quick: bool) -> list[dict]:
    from gripkit.sysid import arx
    arx_mod = importlib.import_module("gripkit.sysid.linear.arx")
    from gripkit.sysid.regression import arx_regression, qr_solve

    u, y = _data(N)
    names = ("a1", "a2", "b2", "b3")
    limit = arx_mod.QR_MAX_ELEMENTS

    def gram_route():
        arx_mod.QR_MAX_ELEMENTS = 0
        try:
            return arx(u, y, 2, 2, 2)
        finally:
            arx_mod.QR_MAX_ELEMENTS = limit

    m_qr, m_gram, th_bare = arx(u, y, 2, 2, 2), gram_route(), _bare(u, y)
    runs = 7 if quick else 15
    fns = [lambda: arx(u, y, 2, 2, 2), gram_route, lambda: _bare(u, y),
           lambda: qr_solve(arx_regression(u, y, 2, 2, 2), names, overwrite=True),
           lambda: arx_regression(u, y, 2, 2, 2),
           lambda: m_qr.prediction_errors(u, y)]
    t_qr, t_gram, t_bare, t_solve, t_reg, t_pe = measure_alternating(fns, runs=runs)
    # thread CPU time as well: steadier than the wall clock on a loaded machine
    c_qr, c_gram, c_bare = measure_alternating(fns[:3], runs=runs, clock=time.thread_time)

    def cpu_note(c):
        return {"cpu_time_s": [c.median, c.min], "peer_cpu_time_s": [c_bare.median, c_bare.min],
                "cpu_ratio_of_minima": c_bare.min / c.min}
    th_qr = qr_solve(arx_regression(u, y, 2, 2, 2), names).theta  # QR of [Φ | Y] as reference

    def dev(theta):
        return f"{np.max(np.abs(theta - th_qr)):.1e}"
    acc = (f"max |θ − θ_QR|: arx {dev(m_qr.theta)}, lagged-sums route {dev(m_gram.theta)}, "
           f"bare {dev(th_bare)}")
    target = "≤ 1.5× the bare normal equations"
    peer = "bare normal equations (column_stack, np.linalg.solve), θ only"
    us = {"unit": "s"}
    return [row("arx_small", f"arx [2 2 2], N = {N:.0e}, default (BLAS normal equations)", t_qr,
                peer, t_bare, target=target, gripkit_accuracy=acc,
                notes=f"checks, scaling, Gram and Cholesky, σ, prediction errors, fit, model "
                      f"object; route: {m_qr.info['method']}, κ = {m_qr.info['cond']:.3g}",
                extra={"arx_regression_s": [t_reg, t_reg.min],
                       "qr_solve_incl_regression_s": [t_solve, t_solve.min],
                       "prediction_errors_s": [t_pe, t_pe.min], **cpu_note(c_qr), **us}),
            row("arx_small", f"arx [2 2 2], N = {N:.0e}, lagged-sums normal equations (numba)",
                t_gram, peer, t_bare, target=target, gripkit_accuracy=acc,
                notes="arx.QR_MAX_ELEMENTS = 0: the route the default takes from 2^18 elements",
                extra=cpu_note(c_gram))]


if __name__ == "__main__":
    import json
    import sys

    for r in run(quick="--quick" in sys.argv):
        print(json.dumps(r, default=str))
