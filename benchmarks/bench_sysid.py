"""Linear identification benchmarks: gripkit beside sysidentpy, sippy_unipi and bare numpy.

Problem: ARX ``[4 4 2]`` (Table II's largest structure of 000_8f66dcc7ab06470c.txt, with its
coefficients) on N = 10⁶ samples of white-noise input with equation noise; batch RLS with 6
parameters (ARX ``[3 3 1]``); the streaming RLS update from Python.

Fairness notes (also written into each row):

* gripkit ``arx()`` is the full user call: input checks, Gram matrix of the regressor (no Φ),
  Cholesky, covariance, loss and fit from a pass over the one-step errors. The residual array
  itself is computed on first access to ``model.estimation_residuals`` (not in the timed call; the
  memory
  row times that access separately).
* bare numpy: build Φ with ``np.column_stack`` of shifted slices and ``np.linalg.lstsq`` (LAPACK
  ``gelsd``) on exactly the same 8-column regression — no checks, no covariance, no residuals.
* sysidentpy: its ARX path, ``FROLS(order_selection=False, n_terms=9, ylag=[1..4], xlag=[2..5],
  basis_function=Polynomial(degree=1), estimator=LeastSquares())``: the same 8 regressors plus
  the constant term its polynomial basis always includes (9 columns).
* sippy_unipi: ``system_identification(y, u, 'ARX', ARX_orders=[4, 4, 1])`` (sippy's delay θ is
  MATLAB's nk − 1); it builds Φ row by row in Python and solves with ``pinv`` (SVD). When a peer
  is too slow at 10⁶ samples it is timed at a smaller N and compared per sample (the row says so).
* RLS peers: sysidentpy's ``RecursiveLeastSquares.optimize(psi, y)`` on the same 6-column
  regressor, sippy's ``ARX_mod='RLLS'``, both per sample; the streaming update is compared with
  the textbook numpy update written in Python.

Estimates are checked to agree before timing (a benchmark of a wrong answer is worthless).
"""

from __future__ import annotations

import contextlib
import io
import time
import warnings

import numpy as np
from common import measure, row
from numba import njit
from scipy.signal import lfilter

A442 = np.array([1.0, -2.8040, 3.3595, -2.1409, 0.6073])  # Table II [4 4 2], S1
B442 = np.array([0.0, 0.0, -0.3256, 0.5611, -0.0449, -0.2394])


def _data(n: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = lfilter(B442, A442, u) + lfilter([1.0], A442, 0.01 * rng.standard_normal(n))
    return u, y


def _numpy_lstsq(u, y):
    n = y.size
    t0 = 5
    phi = (np.column_stack([-y[t0 - i:n - i] for i in range(1, 5)]
                           + [u[t0 - 2 - j:n - 2 - j] for j in range(4)]))
    return np.linalg.lstsq(phi, y[t0:], rcond=None)[0]


def _sysidentpy_arx(u, y):
    from sysidentpy.basis_function import Polynomial
    from sysidentpy.model_structure_selection import FROLS
    from sysidentpy.parameter_estimation import LeastSquares

    m = FROLS(order_selection=False, n_terms=9, ylag=[1, 2, 3, 4], xlag=[2, 3, 4, 5],
              basis_function=Polynomial(degree=1), estimator=LeastSquares(), model_type="NARMAX")
    m.fit(X=u.reshape(-1, 1), y=y.reshape(-1, 1))
    return m


def _sysidentpy_theta(m) -> np.ndarray:
    """sysidentpy's coefficients in gripkit's order [a1..a4, b2..b5] (its y terms carry a +
    sign)."""
    codes = m.final_model.ravel()
    th = m.theta.ravel()
    out = np.zeros(8)
    for c, v in zip(codes, th):
        if 1001 <= c <= 1004:
            out[c - 1001] = -v
        elif 2002 <= c <= 2005:
            out[4 + c - 2002] = v
    return out


def _sippy_arx(u, y):
    from sippy_unipi import system_identification

    with contextlib.redirect_stdout(io.StringIO()):
        return system_identification(y, u, "ARX", ARX_orders=[4, 4, 1], tsample=1.0)


def _sippy_theta(s) -> np.ndarray:
    den = np.asarray(s.DENOMINATOR).ravel()
    num = np.asarray(s.NUMERATOR).ravel()
    return np.r_[den[1:5], num[1:5]]


def _timed_per_sample(fn, sizes, budget_s: float):
    """Time ``fn(n)`` for increasing ``sizes``, stopping before a size whose projected run time
    (per-sample rate × size) exceeds ``budget_s``; returns (n, Timing per call at that n), timed
    by :func:`common.measure` like every other call."""
    n = sizes[0]
    for i, size in enumerate(sizes):
        t0 = time.perf_counter()
        fn(size)
        n, dt = size, time.perf_counter() - t0
        if i + 1 < len(sizes) and dt * sizes[i + 1] / size > budget_s:
            break
    return n, measure(lambda: fn(n), budget_s=budget_s)


def _normal_equations(u, y):
    """The expert's numpy route: Φ from shifted slices, ΦᵀΦ θ = ΦᵀY (Cholesky-free solve)."""
    n = y.size
    t0 = 5
    phi = (np.column_stack([-y[t0 - i:n - i] for i in range(1, 5)]
                           + [u[t0 - 2 - j:n - 2 - j] for j in range(4)]))
    return np.linalg.solve(phi.T @ phi, phi.T @ y[t0:])


def _scipy_lstsq(u, y, driver):
    from scipy.linalg import lstsq

    n = y.size
    t0 = 5
    phi = (np.column_stack([-y[t0 - i:n - i] for i in range(1, 5)]
                           + [u[t0 - 2 - j:n - 2 - j] for j in range(4)]))
    return lstsq(phi, y[t0:], lapack_driver=driver, check_finite=False, overwrite_a=True)[0]


_CHILD = r"""
import json, statistics, sys, time
import numpy as np
sys.path.insert(0, {here!r})
from bench_sysid import _data, _normal_equations
from gripkit.sysid import arx
what, n = sys.argv[1], int(sys.argv[2])
if what == "memory":  # data from a file: generating them here would set the peak before the call
    uy = np.load(sys.argv[3])
    u, y = uy[0], uy[1]
else:
    u, y = _data(n)
# warm-up above arx's QR_MAX_ELEMENTS (2000 rows would take the QR route and leave numba's
# kernels to load inside the measured call)
arx(u[:100000], y[:100000], 4, 4, 2); _normal_equations(u[:2000], y[:2000])
if what == "memory":
    def status(key):
        for line in open("/proc/self/status"):
            if line.startswith(key):
                return int(line.split()[1]) * 1024
    open("/proc/self/clear_refs", "w").write("5")  # reset the peak (VmHWM) to the current RSS
    cur = status("VmRSS:")
    m = arx(u, y, 4, 4, 2)
    peak = status("VmHWM:")
    t0 = time.perf_counter(); e = m.estimation_residuals; t_res = time.perf_counter() - t0
    print(json.dumps(dict(input=u.nbytes + y.nbytes, rss_before=cur, peak=peak, residuals=e.nbytes,
                          residuals_s=t_res)))
else:
    out = {{}}
    for name, f in (("gripkit", lambda: arx(u, y, 4, 4, 2)),
                    ("numpy", lambda: _normal_equations(u, y))):
        ts = []
        for _ in range(7):
            t0 = time.perf_counter(); f(); ts.append(time.perf_counter() - t0)
        out[name] = statistics.median(ts)
    print(json.dumps(out))
"""


def _child(what: str, n: int) -> dict:
    """Run one measurement in a fresh process (same environment, so the same BLAS threads)."""
    import json
    import os
    import subprocess
    import sys
    import tempfile
    from pathlib import Path

    here = str(Path(__file__).resolve().parent)
    with tempfile.TemporaryDirectory() as tmp:
        args = [what, str(n)]
        if what == "memory":
            path = os.path.join(tmp, "uy.npy")
            np.save(path, np.stack(_data(n)))
            args.append(path)
        out = subprocess.run([sys.executable, "-c", _CHILD.format(here=here), *args],
                             env=os.environ.copy(),
                             capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


@njit(cache=True)
def _rls_update(th, P, phi, q, lam, y):
    """The expert's textbook RLS update with exponential forgetting, scalar loops (no
    allocation)."""
    p = th.shape[0]
    r = 0.0
    e = y
    for i in range(p):
        acc = 0.0
        for j in range(p):
            acc += P[i, j] * phi[j]
        q[i] = acc
        r += phi[i] * acc
        e -= phi[i] * th[i]
    inv = 1.0 / (lam + r)
    for i in range(p):
        th[i] += q[i] * inv * e
        for j in range(p):
            P[i, j] = (P[i, j] - q[i] * q[j] * inv) / lam
    return e, r


@njit(cache=True)
def _numba_rls(u, y, lam, p0, theta_hist, std_hist):
    """The expert's batch RLS [3 3 1]; stores θ and σ per step when the history arrays have N
    rows."""
    n = u.shape[0]
    p = 6
    th = np.zeros(p)
    P = p0 * np.eye(p)
    phi = np.zeros(p)
    q = np.zeros(p)
    V, w1, w2 = 0.0, 0.0, 0.0
    store = theta_hist.shape[0] == n
    for t in range(3, n):
        for i in range(3):
            phi[i] = -y[t - 1 - i]
            phi[3 + i] = u[t - 1 - i]
        e, r = _rls_update(th, P, phi, q, lam, y[t])
        V = lam * (V + e * e / (lam + r))
        w1 = lam * w1 + 1.0
        w2 = lam * lam * w2 + 1.0
        if store:
            f = V / (w1 - p) * (w2 / w1) if w1 > p else np.nan
            for i in range(p):
                theta_hist[t, i] = th[i]
                std_hist[t, i] = np.sqrt(f * P[i, i])
    return th


def run(quick: bool = False) -> list[dict]:
    from gripkit.sysid import RLS, arx, rls

    warnings.simplefilter("ignore")
    rows = []
    n = 100_000 if quick else 1_000_000
    u, y = _data(n)
    m = arx(u, y, 4, 4, 2)
    truth = np.r_[A442[1:], B442[2:]]
    assert np.allclose(m.theta, truth, atol=1e-2), m.theta
    ref = _scipy_lstsq(u, y, "gelsd")
    assert np.allclose(m.theta, ref, rtol=1e-8, atol=1e-10)

    def acc(theta):
        return f"max |θ − θ_gelsd| = {np.max(np.abs(theta - ref)):.1e}"

    t_gk = measure(lambda: arx(u, y, 4, 4, 2))
    label = f"ARX [4 4 2] LS, N = {n:.0e}"
    gk_acc = acc(m.theta) + f"; cond {m.info['cond']:.3g}"
    for peer, fn, target in (("numpy normal equations "
                              "(same regression)", _normal_equations, "ratio ≥ 0.8 (≤ 1.25×)"),
                             ("scipy lstsq gelsy", lambda a, b: _scipy_lstsq(a, b, "gelsy"), ""),
                             ("scipy lstsq gelsd", lambda a, b: _scipy_lstsq(a, b, "gelsd"), "")):
        t_p = measure(lambda: fn(u, y))
        rows.append(row("sysid", label, t_gk, peer, t_p, target=target, gripkit_accuracy=gk_acc,
                        peer_accuracy=acc(fn(u, y)),
                        notes="gripkit: checks + Gram from compensated lagged sums (no "
                              "Φ) + Cholesky + "
                              "covariance + loss + fit (the residual array on demand); "
                              "peer: Φ + solve only"))
    if not quick:
        spread = [_child("spread", n) for _ in range(3)]
        g = [s["gripkit"] for s in spread]
        p_ = [s["numpy"] for s in spread]
        rows.append(row("sysid", f"ARX [4 4 2], N = {n:.0e}: spread of the median "
                                 "between 3 processes", None,
                        "numpy normal equations", None, target="≤ 2×",
                        notes=f"gripkit medians "
                              f"{', '.join(f'{x * 1e3:.3g}' for x in g)} ms (max/min "
                              f"{max(g) / min(g):.2f}); numpy "
                              f"{', '.join(f'{x * 1e3:.3g}' for x in p_)} ms "
                              f"(max/min {max(p_) / min(p_):.2f})",
                        extra={"gripkit_spread": max(g) / min(g),
                               "numpy_spread": max(p_) / min(p_)}))
        mem = _child("memory", 10_000_000)
        over = (mem["peak"] - mem["rss_before"]) / mem["input"]
        rows.append(row("sysid", "ARX [4 4 2], N = 1e7: peak RSS during the call", None, "—", None,
                        target="≤ 1.3× the input arrays",
                        notes=f"inputs u, y {mem['input'] / 1e6:.0f} MB; peak RSS = "
                              f"{mem['peak'] / 1e6:.0f} MB; "
                              f"peak RSS − RSS before the call = "
                              f"{(mem['peak'] - mem['rss_before']) / 1e6:.1f} MB = "
                              f"{over:.3f}× the inputs "
                              f"(peak/inputs ≤ {1 + over:.3f}×); the residual array "
                              f"({mem['residuals'] / 1e6:.0f} MB) is computed on first access to "
                              "model.estimation_residuals, after the call: "
                              f"{mem['residuals_s'] * 1e3:.0f} ms; measured in a fresh process "
                              "(/proc/self/status VmHWM after resetting it through "
                              "/proc/self/clear_refs)",
                        extra=mem))

    # sysidentpy, sippy_unipi: pure-Python per-row work, timed at a smaller N when too slow
    sm = _sysidentpy_arx(u[:20000], y[:20000])
    assert np.allclose(_sysidentpy_theta(sm), arx(u[:20000], y[:20000], 4, 4, 2).theta, atol=1e-4)
    ns, t_s = _timed_per_sample(lambda k: _sysidentpy_arx(u[:k], y[:k]), [n // 10, n], budget_s=30)
    rows.append(row("sysid", label, t_gk, "sysidentpy FROLS+LeastSquares", t_s * n / ns,
                    pure_python_peer=True,
                    gripkit_accuracy=gk_acc,
                    peer_accuracy=acc(_sysidentpy_theta(sm)) + " (at N = 2e4)",
                    notes=(f"timed at N = {ns:.0e}"
                           + ("" if ns == n else f", scaled ×{n // ns} (per sample)")
                           + "; sysidentpy adds a constant column (9 regressors)")))
    sp = _sippy_arx(u[:20000], y[:20000])
    assert np.allclose(_sippy_theta(sp), arx(u[:20000], y[:20000], 4, 4, 2).theta, atol=1e-4)
    ns, t_p = (_timed_per_sample(lambda k: _sippy_arx(u[:k], y[:k]), [n // 100, n // 10, n],
                                 budget_s=30))
    rows.append(row("sysid", label, t_gk, "sippy_unipi ARX (LLS)", t_p * n / ns,
                    pure_python_peer=True,
                    notes=f"timed at N = {ns:.0e}"
                    + ("" if ns == n else f", scaled ×{n // ns} (per sample)")
                    + "; Python row loop + pinv"))

    # batch RLS, 6 parameters: the expert's numba RLS, with and without history
    nr = 100_000 if quick else 1_000_000
    ur, yr = _data(nr, seed=1)
    res = rls(ur, yr, 3, 3, 1, forgetting=0.999, p0=1e4, windup="none")
    hist = (np.empty((nr, 6)), np.empty((nr, 6)))
    th_nb = _numba_rls(ur, yr, 0.999, 1e4, *hist)
    rls_acc = f"max |θ_N − θ_numba| = {np.max(np.abs(res.theta_final - th_nb)):.1e}"
    t_rls = measure(lambda: rls(ur, yr, 3, 3, 1, forgetting=0.999, windup="none"))
    t_rls_nostore = (measure(lambda: RLS(3, 3, 1, forgetting=0.999,
                                         windup="none").run(ur, yr, store=False)))
    t_nb = measure(lambda: _numba_rls(ur, yr, 0.999, 1e4, np.empty((nr, 6)), np.empty((nr, 6))))
    none = np.empty((0, 6))
    t_nb0 = measure(lambda: _numba_rls(ur, yr, 0.999, 1e4, none, none))
    rate, rate0 = nr / t_rls.median, nr / t_rls_nostore.median
    lab = f"batch RLS, 6 parameters, N = {nr:.0e}"
    rows.append(row("sysid", lab + ", θ and σ history", t_rls, "numba RLS, 20 lines, history "
                                                               "arrays allocated",
                    t_nb, target="≥ 1e7 samples/s", gripkit_accuracy=rls_acc,
                    notes=f"gripkit {rate:.3g} samples/s (rls(): checks, history, errors, result "
                          f"object; windup='none' like the peer); peer {nr / t_nb.median:.3g}/s "
                          "(exponential forgetting only)",
                    extra={"gripkit_samples_per_s": rate}))
    rows.append(row("sysid", lab + ", no history", t_rls_nostore, "numba RLS, 20 lines, no history",
                    t_nb0,
                    target="≥ 1e7 samples/s", gripkit_accuracy=rls_acc,
                    notes=f"gripkit {rate0:.3g} samples/s (RLS.run(store=False)); peer "
                          f"{nr / t_nb0.median:.3g}/s",
                    extra={"gripkit_samples_per_s": rate0}))

    def sysidentpy_rls(k):
        from sysidentpy.parameter_estimation import RecursiveLeastSquares

        t0 = 3
        psi = np.column_stack([y_ for y_ in ([yr[t0 - i:k - i] for i in range(1, 4)]
                                             + [ur[t0 - 1 - j:k - 1 - j] for j in range(3)])])
        return RecursiveLeastSquares(lam=0.999, delta=0.01).optimize(psi, yr[t0:k].reshape(-1, 1))

    ns, t_srls = _timed_per_sample(sysidentpy_rls, [nr // 100, nr // 10, nr], budget_s=20)
    rows.append(row("sysid", lab + ", θ and σ history", t_rls, "sysidentpy RecursiveLeastSquares",
                    t_srls * nr / ns, pure_python_peer=True,
                    notes=f"peer timed at N = {ns:.0e}"
                    + ("" if ns == nr else f", scaled ×{nr // ns} (per sample)")))

    # streaming update: against a numba step function called from Python (the expert's route)
    k = 20_000 if quick else 200_000
    us, ys = ur[:k].tolist(), yr[:k].tolist()
    est = RLS(3, 3, 1, forgetting=0.999)
    est.update(0.0, 0.0)
    upd = est.update

    def stream():
        for a, b in zip(us, ys):
            upd(a, b)

    t_stream = measure(stream) / k
    st = np.zeros(60)
    st[6:42] = 1e4 * np.eye(6).ravel()
    _numba_rls_step(st, 0.0, 0.0, 0.999)

    def numba_stream():
        for a, b in zip(us, ys):
            _numba_rls_step(st, a, b, 0.999)

    t_nb_stream = measure(numba_stream) / k
    rows.append(row("sysid", "streaming RLS update(u, y), 6 parameters (per call)", t_stream,
                    "numba step function on a state array, called from Python", t_nb_stream,
                    target="≤ 0.5 µs per call", notes="called from a Python loop, one "
                                                      "sample per call; "
                    "gripkit's update also checks its input and keeps θ, P recoverable"))
    return rows


@njit(cache=True)
def _numba_rls_step(s, u, y, lam):
    """The expert's streaming RLS [3 3 1] step on one state array [θ(6), P(36), y(3), u(3), φ(6),
    q(6)]."""
    th = s[0:6]
    P = s[6:42].reshape((6, 6))
    yb = s[42:45]
    ub = s[45:48]
    phi = s[48:54]
    ub[2], ub[1], ub[0] = ub[1], ub[0], u
    for i in range(3):
        phi[i] = -yb[i]
        phi[3 + i] = ub[i]
    e, _ = _rls_update(th, P, phi, s[54:60], lam, y)
    yb[2], yb[1], yb[0] = yb[1], yb[0], y
    return e
