"""numba kernels of the hysteresis family (:mod:`.hysteresis`), scalar and allocation-free.

Bouc-Wen, actuator form (``001_0b92a7da96e7aa46.txt`` eq 3 with the exponent n of the generic
model)::

    y = d u − h,     dh/dt = α d du/dt − β |du/dt| h |h|^(n−1) − γ du/dt |h|^n

is rate independent: divided by du/dt (sign s) it is an ODE in the input itself,
``dh/du = α d − β s h |h|^(n−1) − γ |h|^n``. For n = 1 the step from one sample to the next is
exact (:func:`gripkit.models.hysteresis.bouc_wen_advance`, λ = α d); for n ≠ 1 it is integrated
by classical Runge-Kutta in the input, with as many sub-steps as keep the local rate times the
sub-step below :data:`RK4_STEP` (the rate is ``n (β + |γ|) max(|h|, h_sat)^(n−1)``, h_sat =
(α d / (β + γ))^(1/n) the level a long monotone sweep tends to).

Prandtl–Ishlinskii: the play operator of threshold r on a sampled input,
``z(k) = max(x(k) − r, min(x(k) + r, z(k−1)))``, exact on piecewise-monotone inputs.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ...models.hysteresis import bouc_wen_advance

__all__ = ["RK4_STEP", "bw_advance_rk4", "bw_simulate", "bwo_sample", "bwo_simulate",
           "count_reversals", "play_matrix", "pi_simulate"]

#: largest (local rate × input sub-step) of the Runge-Kutta integration (local error ~ step⁵/120)
RK4_STEP = 0.02
#: most sub-steps per sample (a sample whose move needs more is integrated with this many)
MAX_SUBSTEPS = 20000


@njit(cache=True)
def _bw_rate(h, s, lam, beta, gamma, n):  # pragma: no cover - compiled
    """dh/du on a segment of direction s."""
    a = abs(h)
    p = a ** n
    hp = p if h >= 0.0 else -p  # h |h|^(n−1)
    return lam - beta * s * hp - gamma * p


@njit(cache=True)
def bw_advance_rk4(h, du, lam, beta, gamma, n):  # pragma: no cover - compiled
    """h after the input moves monotonically by ``du``, by RK4 in the input (any n > 0)."""
    if du == 0.0:
        return h
    s = 1.0 if du > 0.0 else -1.0
    c = beta + abs(gamma)
    ref = abs(h)
    if beta + gamma > 0.0 and lam > 0.0:
        sat = (lam / (beta + gamma)) ** (1.0 / n)
        if sat > ref:
            ref = sat
    k = n * c * ref ** (n - 1.0) if ref > 0.0 else (c if n == 1.0 else 0.0)
    m = int(math.ceil(abs(du) * k / RK4_STEP))
    if m < 1:
        m = 1
    if m > MAX_SUBSTEPS:
        m = MAX_SUBSTEPS
    step = du / m
    for _ in range(m):
        k1 = _bw_rate(h, s, lam, beta, gamma, n)
        k2 = _bw_rate(h + 0.5 * step * k1, s, lam, beta, gamma, n)
        k3 = _bw_rate(h + 0.5 * step * k2, s, lam, beta, gamma, n)
        k4 = _bw_rate(h + step * k3, s, lam, beta, gamma, n)
        h = h + step * (k1 + 2.0 * k2 + 2.0 * k3 + k4) / 6.0
    return h


@njit(cache=True)
def bw_simulate(u, d, alpha, beta, gamma, n, offset, h0, u0, y):  # pragma: no cover - compiled
    """y[k] = d u[k] − h[k] + offset from h = ``h0`` at input ``u0``; returns the first sample
    where y is not finite, −1 if none (the rest is NaN)."""
    lam = alpha * d
    h = h0
    up = u0
    exact = n == 1.0
    for k in range(u.shape[0]):
        du = u[k] - up
        if exact:
            h = bouc_wen_advance(h, du, lam, beta, gamma)
        else:
            h = bw_advance_rk4(h, du, lam, beta, gamma, n)
        up = u[k]
        v = d * u[k] - h + offset
        y[k] = v
        if not math.isfinite(v):
            for j in range(k + 1, u.shape[0]):
                y[j] = np.nan
            return k
    return -1


@njit(cache=True, inline="always")
def _play_step(z, x, r):  # pragma: no cover - compiled
    """The play operator of threshold r at one sample: its last output z held within
    [x − r, x + r]."""
    lo = x - r
    hi = x + r
    if z < lo:
        return lo
    if z > hi:
        return hi
    return z


@njit(cache=True)
def play_matrix(x, r, out):  # pragma: no cover - compiled
    """out[k, i] = play operator of threshold r[i] on x, each relaxed at x[0] (z = x[0])."""
    for i in range(r.shape[0]):
        z = x[0]
        ri = r[i]
        for k in range(x.shape[0]):
            z = _play_step(z, x[k], ri)
            out[k, i] = z


@njit(cache=True)
def pi_simulate(x, r, w, offset, y):  # pragma: no cover - compiled
    """y[k] = offset + Σ w[i] play_r[i][x](k), each play relaxed at x[0] (no play matrix)."""
    nop = r.shape[0]
    for k in range(x.shape[0]):
        y[k] = offset
    for i in range(nop):
        z = x[0]
        ri = r[i]
        wi = w[i]
        for k in range(x.shape[0]):
            z = _play_step(z, x[k], ri)
            y[k] += wi * z


@njit(cache=True)
def count_reversals(x, band):  # pragma: no cover - compiled
    """How often x turns back by more than ``band`` from its last extreme (noise below the band
    is no reversal)."""
    n = x.shape[0]
    if n == 0:
        return 0
    hi = x[0]
    lo = x[0]
    direction = 0  # +1 rising, −1 falling, 0 not yet moved by more than band
    turns = 0
    for k in range(1, n):
        v = x[k]
        if direction >= 0:
            if v > hi:
                hi = v
            if direction == 0 and v < lo:
                lo = v
            if direction == 0 and hi - x[0] > band:
                direction = 1
            elif direction == 0 and x[0] - lo > band:
                direction = -1
                continue
            if direction == 1 and hi - v > band:
                direction = -1
                lo = v
                turns += 1
        else:
            if v < lo:
                lo = v
            if v - lo > band:
                direction = 1
                hi = v
                turns += 1
    return turns


@njit(cache=True)
def bwo_rates(x, v, z, u, m, c, ke, kh, beta, gamma, n):  # pragma: no cover - compiled
    """(ẋ, v̇, ż) of the Bouc-Wen oscillator (A = 1)."""
    a = abs(z) if n == 1.0 else abs(z) ** n
    zp = a if z >= 0.0 else -a  # z |z|^(n−1)
    return v, (u - c * v - ke * x - kh * z) / m, v - beta * abs(v) * zp - gamma * v * a


@njit(cache=True)
def bwo_sample(x, v, z, u, h, substeps, p):  # pragma: no cover - compiled
    """(x, ẋ, z) of the Bouc-Wen oscillator one sample on: ``substeps`` classical RK4 steps of
    length h with the input u held; p = (m, c, k_e, k_h, β, γ, n) as in :func:`bwo_rates`."""
    m, c, ke, kh, beta, gamma, n = p
    for _ in range(substeps):
        a1, b1, c1 = bwo_rates(x, v, z, u, m, c, ke, kh, beta, gamma, n)
        a2, b2, c2 = bwo_rates(x + 0.5 * h * a1, v + 0.5 * h * b1, z + 0.5 * h * c1, u,
                                m, c, ke, kh, beta, gamma, n)
        a3, b3, c3 = bwo_rates(x + 0.5 * h * a2, v + 0.5 * h * b2, z + 0.5 * h * c2, u,
                                m, c, ke, kh, beta, gamma, n)
        a4, b4, c4 = bwo_rates(x + h * a3, v + h * b3, z + h * c3, u,
                                m, c, ke, kh, beta, gamma, n)
        x += h * (a1 + 2.0 * a2 + 2.0 * a3 + a4) / 6.0
        v += h * (b1 + 2.0 * b2 + 2.0 * b3 + b4) / 6.0
        z += h * (c1 + 2.0 * c2 + 2.0 * c3 + c4) / 6.0
    return x, v, z


@njit(cache=True)
def bwo_simulate(u, dt, substeps, p, offset, start, y):  # pragma: no cover - compiled
    """Bouc-Wen oscillator with ``p = (m, c, k_e, k_h, β, γ, n)`` from (x, ẋ, z) = ``start`` at
    the first sample ((0, 0, 0): from rest), the input held over each sample, ``substeps`` RK4
    steps per sample: y[k] = x(t_k) + offset. Returns the first sample where y is not finite, −1
    if none (the rest is NaN)."""
    x, v, z = start
    h = dt / substeps
    N = u.shape[0]
    y[0] = x + offset
    for k in range(N - 1):
        x, v, z = bwo_sample(x, v, z, u[k], h, substeps, p)
        val = x + offset
        y[k + 1] = val
        if not (math.isfinite(val) and math.isfinite(v) and math.isfinite(z)):
            for j in range(k + 2, N):
                y[j] = np.nan
            return k + 1
    return -1
