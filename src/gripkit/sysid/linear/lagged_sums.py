"""ARX normal equations from lagged sums, without forming the regressor.

Every column of the augmented ARX regressor ``[Φ | Y]`` (see :mod:`.regression`) is a signal
``x ∈ {y, u}`` delayed by a lag ``L`` and multiplied by a sign: ``-y(t-1) … -y(t-na)``,
``u(t-nk) … u(t-nk-nb+1)``, ``y(t)``. Its Gram matrix ``G = [Φ | Y]ᵀ[Φ | Y]`` therefore needs
only the lagged products ``C_xz(d) = Σ_s x(s) z(s−d)`` over a common core range, plus at most
``t0`` edge terms per entry (for the column with the smaller lag ``L_a``, ``s = t − L_a`` runs over
``t0 − L_a … N−1−L_a``, which contains the core ``t0 … N−1−t0``):

    G_ab = σ_a σ_b [ C_{x_a x_b}(L_b − L_a) + Σ_{edges} x_a(s) x_b(s − L_b + L_a) ].

Memory is O(q²) beyond the data (no N×q array). The sums are compensated: blocks of
:data:`BLOCK` products are summed in vector registers, and the block sums are added with Kahan's
compensation, so the rounding error is about ``BLOCK·u`` relative to ``Σ|x z|`` whatever N.

:func:`arx_residuals` is the second pass: the one-step prediction errors
``e(t) = y(t) − φ(t)ᵀθ`` with ``Σ e²`` and ``Σ (y − ȳ)²`` (compensated the same way).
"""

from __future__ import annotations

import functools

import numpy as np
from numba import njit

from ..regression import scaled_condition

__all__ = ["BLOCK", "GRAM_COND_LIMIT", "arx_gram", "arx_residuals", "gram_triangle"]

#: Products summed in plain floating point before a compensated addition.
BLOCK = 256


@functools.lru_cache(maxsize=64)
def _columns(na: int, nb: int, nk: int):
    """(signal, lag, sign) of each column of ``[Φ | Y]``: signal 0 = y, 1 = u. Built once per
    structure (three list-to-array conversions are a visible cost at N ≈ 10⁴); the kernels only
    read them (left writable: a read-only array is another numba signature to compile)."""
    kind = np.array([0] * na + [1] * nb + [0], dtype=np.int64)
    lag = np.array([1 + i for i in range(na)] + [nk + j for j in range(nb)] + [0], dtype=np.int64)
    sign = np.array([-1.0] * na + [1.0] * nb + [1.0])
    return kind, lag, sign


@njit(cache=True, fastmath=True)
def _dot(x, z, d, s0, s1):
    # slices, not x[s - d]: a possibly negative index defeats vectorisation
    a = x[s0:s1]
    b = z[s0 - d:s1 - d]
    acc = 0.0
    for i in range(a.shape[0]):
        acc += a[i] * b[i]
    return acc


@njit(cache=True)
def _kahan_add(total, comp, i, v):
    v = v - comp[i]
    t = total[i] + v
    comp[i] = (t - total[i]) - v
    total[i] = t


@njit(cache=True)
def _compensated_dot(x, z, d, s0, s1):
    total = np.zeros(1)
    comp = np.zeros(1)
    b = s0
    while b < s1:
        e = min(b + BLOCK, s1)
        _kahan_add(total, comp, 0, _dot(x, z, d, b, e))
        b = e
    return total[0]


@njit(cache=True)
def _gram(u, y, kind, lag, sign, t0):
    n = y.shape[0]
    q = kind.shape[0]
    sig = (y, u)
    # which lagged products the columns need: need[first signal, second signal, d]
    need = np.zeros((2, 2, t0 + 1), dtype=np.bool_)
    for a in range(q):
        for b in range(a, q):
            i, j = (a, b) if lag[a] <= lag[b] else (b, a)
            need[kind[i], kind[j], lag[j] - lag[i]] = True
    s0, s1 = t0, n - t0  # core: s = t0 … N−1−t0, common to every column pair
    if s1 < s0:
        s1 = s0
    core = np.zeros((2, 2, t0 + 1))
    comp = np.zeros((2, 2, t0 + 1))
    b = s0
    while b < s1:  # block outer, lags inner: the block stays in L1 for all products
        e = min(b + BLOCK, s1)
        for k1 in range(2):
            for k2 in range(2):
                for d in range(t0 + 1):
                    if need[k1, k2, d]:
                        _kahan_add(core[k1, k2], comp[k1, k2], d, _dot(sig[k1], sig[k2], d, b, e))
        b = e
    G = np.empty((q, q))
    for a in range(q):
        for c in range(a, q):
            i, j = (a, c) if lag[a] <= lag[c] else (c, a)
            d = lag[j] - lag[i]
            x, z = sig[kind[i]], sig[kind[j]]
            lo, hi = t0 - lag[i], n - lag[i]  # s range of this pair (hi exclusive)
            g = core[kind[i], kind[j], d]
            g += _compensated_dot(x, z, d, lo, s0) + _compensated_dot(x, z, d, s1, hi)
            G[a, c] = G[c, a] = sign[a] * sign[c] * g
    return G


def arx_gram(u: np.ndarray, y: np.ndarray, na: int, nb: int, nk: int, t0: int) -> np.ndarray:
    """``[Φ | Y]ᵀ[Φ | Y]``, shape (q, q), q = na + nb + 1, for the rows ``t = t0 … N−1`` of
    :func:`gripkit.sysid.regression.arx_regression` (same column order), from lagged sums."""
    kind, lag, sign = _columns(na, nb, nk)
    return _gram(_read_only(u), _read_only(y), kind, lag, sign, t0)


def _read_only(x: np.ndarray) -> np.ndarray:
    """A read-only view (no copy): the kernel indexes the tuple ``(y, u)`` with a run-time index,
    which numba compiles only when both arrays have the same type, writable or not."""
    v = x.view()
    v.flags.writeable = False
    return v


@njit(cache=True, fastmath=True)
def _residual_block(u, y, theta, kind, lag, sign, ybar, b, e, out):
    p = theta.shape[0]
    yb = y[b:e]
    out[:] = yb
    for k in range(p):
        c = theta[k] * sign[k]
        xk = (y if kind[k] == 0 else u)[b - lag[k]:e - lag[k]]
        for i in range(out.shape[0]):
            out[i] -= c * xk[i]
    se = 0.0
    sy = 0.0
    for i in range(out.shape[0]):
        se += out[i] * out[i]
        dy = yb[i] - ybar
        sy += dy * dy
    return se, sy


@njit(cache=True)
def _residuals(u, y, theta, kind, lag, sign, t0, ybar, res):
    """Block by block into ``res``: all N − t0 errors, or, when ``res`` holds only one block, that
    block reused (the sums alone)."""
    n = y.shape[0]
    keep = res.shape[0] == n - t0
    total = np.zeros(2)
    comp = np.zeros(2)
    b = t0
    while b < n:
        e = min(b + BLOCK, n)
        se, sy = _residual_block(u, y, theta, kind, lag, sign, ybar, b, e,
                                 res[b - t0:e - t0] if keep else res[:e - b])
        _kahan_add(total, comp, 0, se)
        _kahan_add(total, comp, 1, sy)
        b = e
    return total[0], total[1]


def arx_residuals(u: np.ndarray, y: np.ndarray, theta: np.ndarray, na: int, nb: int, nk: int,
                  t0: int, keep: bool = True) -> tuple[np.ndarray | None, float, float]:
    """One-step prediction errors ``e(t) = y(t) − φ(t)ᵀθ`` for ``t = t0 … N−1``, with ``Σ e²``
    and ``Σ (y(t) − ȳ)²`` (ȳ the mean of ``y[t0:]``); ``keep=False``: the sums only (None for the
    errors, one block of scratch memory)."""
    kind, lag, sign = _columns(na, nb, nk)
    m = y.shape[0] - t0
    res = np.empty(m if keep else min(m, BLOCK))
    ybar = float(np.mean(y[t0:]))
    see, syy = _residuals(u, y, np.ascontiguousarray(theta, dtype=np.float64), kind[:-1], lag[:-1],
                          sign[:-1], t0, ybar, res)
    return (res if keep else None), float(see), float(syy)


#: Largest column-scaled condition number κ of Φ for which the normal equations are used: their
#: rounding error in θ is about κ²·δ with δ ≤ BLOCK·u the relative error of the compensated Gram
#: entries; at this κ it is 1e-8, below the statistical error of any noisy record (beyond it,
#: :func:`gripkit.sysid.linear.arx` factors the regressor by QR instead).
GRAM_COND_LIMIT = float(np.sqrt(1e-8 / (BLOCK * 2.0**-53)))


def gram_triangle(G: np.ndarray, with_condition: bool = False):
    """Upper Cholesky factor ``R1`` of ``ΦᵀΦ = G[:p, :p]`` (``R1ᵀR1 = ΦᵀΦ``), or None when Φ is
    too ill-conditioned for the normal equations (not positive definite, or column-scaled
    condition number above :data:`GRAM_COND_LIMIT`). ``with_condition``: ``(R1, scaled_condition
    of R1)``, or ``(None, None)``, for a caller that needs both."""
    p = G.shape[0] - 1
    try:
        r1 = np.linalg.cholesky(G[:p, :p]).T
    except np.linalg.LinAlgError:
        return (None, None) if with_condition else None
    sc = scaled_condition(r1)
    if sc[0] > GRAM_COND_LIMIT or sc[0] != sc[0]:  # NaN: refused as before (not <=)
        return (None, None) if with_condition else None
    return (r1, sc) if with_condition else r1
