"""Batch and streaming RLS [3 3 1] (6 parameters) on N = 10⁶ samples beside a plain numba RLS of
the same, fixed size with the same symmetric P update: what an expert would write by hand
(issue 24 target: gripkit ≥ 0.9× its speed, i.e. ratio peer/gripkit ≥ 0.9, in each row).

The reference (``_plain_rls``) knows p = 6 at compile time, updates the upper triangle of P and
mirrors it (as gripkit does, so both keep P exactly symmetric and give the same θ to rounding),
and tracks the same noise variance (V, w₁, w₂) for σ. Rows: with θ and σ history (``rls()``,
the full user call: checks, history, errors, result object), without history
(``RLS(...).run(store=False)``), and the streaming ``RLS.update`` from a Python loop beside a
numba step function on one state array. All runs alternate (``measure_alternating``), BLAS on one
thread, median and min of 7.
"""

from __future__ import annotations

import math
import time

import numpy as np
from common import measure_alternating, row
from numba import njit
from scipy.signal import lfilter

P6 = 6
LAM = 0.999
P0 = 1e4


def _data(n: int, seed: int = 1):
    """ARX [3 3 1] data: white input, equation noise (poles 0.8, 0.5 ± 0.3i)."""
    rng = np.random.default_rng(seed)
    a = np.poly([0.8, 0.5 + 0.3j, 0.5 - 0.3j]).real
    u = rng.standard_normal(n)
    y = lfilter([0.0, 1.0, 0.5, 0.25], a, u) + lfilter([1.0], a, 0.01 * rng.standard_normal(n))
    return u, y


@njit(cache=True, inline="always")
def _sym_update(th, P, phi, q, lam, y):  # pragma: no cover - compiled
    """RLS update with exponential forgetting for p = 6 (fixed): q = Pφ, K = q/(λ + r), and P ←
    (P − q qᵀ/(λ + r))/λ on the upper triangle, mirrored. Returns (e, r)."""
    e = y
    r = 0.0
    for i in range(P6):
        acc = 0.0
        for j in range(P6):
            acc += P[i, j] * phi[j]
        q[i] = acc
        e -= phi[i] * th[i]
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
            v = (P[i, j] + qi * q[j]) * scale
            P[i, j] = v
            P[j, i] = v
    return e, r


@njit(cache=True)
def _plain_rls(u, y, lam, p0, theta_hist, std_hist):  # pragma: no cover - compiled
    """The plain batch RLS [3 3 1]; θ and σ per step when the history arrays have N rows; returns
    the final θ and σ (so that the noise variance is tracked without history too, as gripkit
    must)."""
    n = u.shape[0]
    th = np.zeros(P6)
    P = np.zeros((P6, P6))
    for i in range(P6):
        P[i, i] = p0
    phi = np.zeros(P6)
    q = np.zeros(P6)
    V, w1, w2 = 0.0, 0.0, 0.0
    store = theta_hist.shape[0] == n
    for t in range(3, n):
        for i in range(3):
            phi[i] = -y[t - 1 - i]
            phi[3 + i] = u[t - 1 - i]
        e, r = _sym_update(th, P, phi, q, lam, y[t])
        V = lam * (V + e * e / (lam + r))
        w1 = lam * w1 + 1.0
        w2 = lam * lam * w2 + 1.0
        if store:
            f = V / (w1 - P6) * (w2 / w1) if w1 > P6 else np.nan
            for i in range(P6):
                theta_hist[t, i] = th[i]
                std_hist[t, i] = math.sqrt(f * P[i, i])
    f = V / (w1 - P6) * (w2 / w1)
    std = np.empty(P6)
    for i in range(P6):
        std[i] = math.sqrt(f * P[i, i])
    return th, std


@njit(cache=True)
def _plain_step(s, u, y, lam):  # pragma: no cover - compiled
    """The plain streaming step on one state array [θ(6), P(36), y(3), u(3), φ(6), q(6)]."""
    th = s[0:6]
    P = s[6:42].reshape((6, 6))
    yb = s[42:45]
    ub = s[45:48]
    phi = s[48:54]
    ub[2], ub[1], ub[0] = ub[1], ub[0], u
    for i in range(3):
        phi[i] = -yb[i]
        phi[3 + i] = ub[i]
    e, _ = _sym_update(th, P, phi, s[54:60], lam, y)
    yb[2], yb[1], yb[0] = yb[1], yb[0], y
    return e


def streaming_calls(u, y, k: int):
    """(gripkit's ``RLS.update``, the plain numba step) over the first ``k`` samples, each one
    call per sample from a Python loop (the plain step compiled first)."""
    from gripkit.sysid import RLS

    us, ys = u[:k].tolist(), y[:k].tolist()
    upd = RLS(3, 3, 1, forgetting=LAM, p0=P0, windup="none").update
    st = np.zeros(60)
    st[6:42] = P0 * np.eye(6).ravel()
    _plain_step(st, 0.0, 0.0, LAM)

    def stream():
        for a, b in zip(us, ys):
            upd(a, b)

    def plain_stream():
        for a, b in zip(us, ys):
            _plain_step(st, a, b, LAM)
    return stream, plain_stream


def run(quick: bool) -> list[dict]:
    """The three rows; ``quick``: N = 1e5 and 2·10⁴ streaming calls (else 1e6 and 2·10⁵)."""
    from gripkit.sysid import RLS, rls

    n = 100_000 if quick else 1_000_000
    u, y = _data(n)
    lab = f"batch RLS [3 3 1], N = {n:.0e}"
    res = rls(u, y, 3, 3, 1, forgetting=LAM, p0=P0, windup="none")
    hist = (np.empty((n, 6)), np.empty((n, 6)))
    th, _ = _plain_rls(u, y, LAM, P0, *hist)
    acc = (f"max |θ_N − θ_plain| = {np.max(np.abs(res.theta_final - th)):.1e}, "
           f"max |σ − σ_plain| over the history = "
           f"{np.nanmax(np.abs(res.theta_std[10:] - hist[1][10:])):.1e}")
    none = np.empty((0, 6))
    batch = [lambda: rls(u, y, 3, 3, 1, forgetting=LAM, p0=P0, windup="none"),
             lambda: _plain_rls(u, y, LAM, P0, np.empty((n, 6)), np.empty((n, 6))),
             lambda: RLS(3, 3, 1, forgetting=LAM, p0=P0, windup="none").run(u, y, store=False),
             lambda: _plain_rls(u, y, LAM, P0, none, none)]
    t_g, t_p, t_g0, t_p0 = measure_alternating(batch)
    cpu = measure_alternating(batch, clock=time.thread_time)  # steadier under load

    def cpu_note(a, b):
        return {"cpu_time_s": [cpu[a].median, cpu[a].min],
                "peer_cpu_time_s": [cpu[b].median, cpu[b].min],
                "cpu_ratio_of_minima": cpu[b].min / cpu[a].min}
    target = "≥ 0.9× the plain numba RLS (ratio ≥ 0.9)"
    peer = "plain numba RLS, p = 6 fixed, symmetric P"
    rows = [row("rls", lab + ", θ and σ history", t_g, peer + ", history", t_p, target=target,
                gripkit_accuracy=acc,
                notes="rls(): checks, history arrays, a-priori errors, result object; "
                      "windup='none' as the peer", extra=cpu_note(0, 1)),
            row("rls", lab + ", no history", t_g0, peer + ", final θ and σ only", t_p0,
                target=target, gripkit_accuracy=acc, notes="RLS(...).run(u, y, store=False)",
                extra=cpu_note(2, 3))]
    k = 20_000 if quick else 200_000
    stream, plain_stream = streaming_calls(u, y, k)
    t_s, t_ps = measure_alternating([stream, plain_stream])
    c_s, c_ps = measure_alternating([stream, plain_stream], clock=time.thread_time)
    rows.append(row("rls", "streaming RLS.update(u, y), [3 3 1] (per call)", t_s / k,
                    "plain numba step (p = 6 fixed, symmetric P) called from Python", t_ps / k,
                    target=target,
                    notes=f"{k} calls from a Python loop per run; gripkit's update also refuses "
                          "non-finite samples and keeps θ, P recoverable",
                    extra={"cpu_time_s": [c_s.median / k, c_s.min / k],
                           "peer_cpu_time_s": [c_ps.median / k, c_ps.min / k],
                           "cpu_ratio_of_minima": c_ps.min / c_s.min}))
    return rows


if __name__ == "__main__":
    import json
    import sys

    for r in run(quick="--quick" in sys.argv):
        print(json.dumps(r, default=str))
