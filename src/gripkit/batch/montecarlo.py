"""Monte Carlo statistics for robustness studies: probabilities with confidence intervals,
quantiles with distribution-free intervals, and probability against a swept parameter.

Probabilities use the Wilson score interval (well behaved for p near 0 or 1, unlike the normal
approximation): for k successes in n trials and z the normal quantile,

    p̃ = (k + z²/2)/(n + z²),   half-width = z √(k(n−k)/n + z²/4) / (n + z²).

Quantile intervals use order statistics: the q-quantile lies between the order statistics of
ranks given by the binomial(n, q) distribution's (α/2, 1−α/2) quantiles, widened where needed to
hold the point estimate (:func:`quantile`).
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np
from scipy import stats

from ..arguments import real_array
from ..errors import ArgumentError, DataError

__all__ = ["Estimate", "probability", "quantile", "binned_probability"]


@dataclass(frozen=True)
class Estimate:
    """A point estimate with a two-sided confidence interval."""

    value: float
    low: float
    high: float
    n: int
    confidence: float

    def __str__(self) -> str:
        return (f"{self.value:.4g} [{self.low:.4g}, {self.high:.4g}] ({100 * self.confidence:.4g} "
                f"% CI, n={self.n})")


def _level(value, name: str, closed: bool = False) -> float:
    """``value`` as a float strictly between 0 and 1 (``closed``: 0 and 1 included), or an
    ArgumentError naming ``name``."""
    ok = (not isinstance(value, bool) and isinstance(value, numbers.Real)
          and (0 <= value <= 1 if closed else 0 < value < 1))
    if not ok:
        span = "from 0 to 1" if closed else "strictly between 0 and 1"
        raise ArgumentError(f"{name}: expected a number {span}, found {value!r}",
                            hint="a level, not a percentage: 0.95 for a 95 % interval, 0.9 for "
                                 "the 90th percentile")
    return float(value)


def _outcome_array(flags) -> np.ndarray:
    """``flags`` as float 0/1 outcomes, NaN for a run without one, in the caller's order and
    shape (raveled), or a DataError naming the first bad entry's index in ``flags``: anything
    but booleans, 0, 1 or NaN (±inf included) is not the outcome of a trial."""
    a = np.asarray(flags)
    if a.dtype.kind not in "biuf":
        kind = {"c": "complex", "U": "text", "S": "text"}.get(a.dtype.kind, str(a.dtype))
        raise DataError(f"flags: expected outcomes True/False or 1/0, found {kind} values")
    a = a.astype(np.float64).ravel()
    bad = np.flatnonzero(~np.isnan(a) & (a != 0.0) & (a != 1.0))
    if bad.size:
        raise DataError(f"flags: expected outcomes True/False or 1/0 (NaN for a run without one), "
                        f"found {bad.size} other values (first {a[bad[0]]:g} at index {bad[0]})",
                        hint="pass the event as booleans, e.g. probability(x > limit); for the "
                             "distribution of values use quantile")
    return a


def _outcomes(flags) -> np.ndarray:
    """The outcomes of :func:`_outcome_array` that are not NaN (a run without one)."""
    a = _outcome_array(flags)
    return a[~np.isnan(a)]


def probability(flags, confidence: float = 0.95) -> Estimate:
    """Probability that ``flags`` is True, with the Wilson interval. ``flags``: booleans or 0/1
    (NaN entries, runs without an outcome, are excluded); ``confidence`` in (0, 1)."""
    confidence = _level(confidence, "confidence")
    f = _outcomes(flags)
    n = f.size
    if n == 0:
        raise DataError("probability of an event needs at least one finite outcome")
    k = float(f.sum())
    z = stats.norm.ppf(0.5 + confidence / 2)
    denom = n + z * z
    centre = (k + z * z / 2) / denom
    half = z * math.sqrt(k * (n - k) / n + z * z / 4) / denom
    return Estimate(k / n, max(0.0, centre - half), min(1.0, centre + half), n, confidence)


def quantile(x, q: float, confidence: float = 0.95) -> Estimate:
    """The ``q`` quantile of ``x`` with an order-statistic confidence interval. NaN entries are
    excluded; +inf is kept as a value larger than all others (e.g. "never settled"), so a quantile
    or a bound that falls on such entries is inf. ``q`` in [0, 1] (0: the least value, whose
    interval reaches −inf; 1: the greatest, up to +inf), ``confidence`` in (0, 1).

    The interval is the distribution-free one of order statistics (Hahn & Meeker, *Statistical
    Intervals*, 1991, §5.2; David & Nagaraja, *Order Statistics*, 2003, §7.1):
    [x₍ₗ₎, x₍ᵤ₎] with l, u from the binomial(n, q) distribution's α/2 and 1 − α/2 quantiles, so
    that P(x₍ₗ₎ ≤ ξ_q ≤ x₍ᵤ₎) ≥ confidence for any continuous distribution (rank 0 is −inf,
    rank n + 1 is +inf). The point is numpy's linear interpolation between x₍ⱼ₎ and x₍ⱼ₊₁₎,
    j = ⌊(n − 1) q⌋ + 1 (with an infinite value: x₍⌈nq⌉₎); where the interval would leave it out
    (a q near 0 or 1 at a low confidence: q = 0.999 of 1 … 100 at 50 % gave 99.9 in [100, inf])
    it is widened to those order statistics, which only raises its coverage."""
    q = _level(q, "q", closed=True)
    confidence = _level(confidence, "confidence")
    x = real_array(x, "x")
    v = np.sort(x[~np.isnan(x)].ravel())
    n = v.size
    if n == 0:
        raise DataError("a quantile needs at least one finite value")
    value, (r_lo, r_hi) = _point(v, q)
    a = (1 - confidence) / 2
    lo_rank = min(int(stats.binom.ppf(a, n, q)), r_lo)
    hi_rank = max(int(stats.binom.ppf(1 - a, n, q)) + 1, r_hi)
    lo = v[lo_rank - 1] if lo_rank >= 1 else -math.inf
    hi = v[hi_rank - 1] if hi_rank <= n else math.inf
    return Estimate(value, float(lo), float(hi), n, confidence)


def _point(v: np.ndarray, q: float) -> tuple[float, tuple[int, int]]:
    """The ``q`` quantile of the sorted ``v`` and the ranks (1-based) of the order statistics
    around it: numpy's ``linear`` method, or ``inverted_cdf`` x₍⌈nq⌉₎ when ``v`` holds ±inf
    (interpolating toward inf gives inf or NaN). Interpolated as a (1 − g) + b g, which stays
    in [a, b] (numpy's a + (b − a) g overflows to −inf for −1e308 and 1e308)."""
    n = v.size
    if np.isinf(v[0]) or np.isinf(v[-1]):
        k = max(math.ceil(n * q), 1)
        return float(v[k - 1]), (k, k)
    h = (n - 1) * q
    j = min(int(math.floor(h)), n - 1)
    g = h - j
    if g == 0.0:
        return float(v[j]), (j + 1, j + 1)
    a, b = float(v[j]), float(v[j + 1])
    return min(max(a * (1 - g) + b * g, a), b), (j + 1, j + 2)


def binned_probability(x, flags, bins, confidence: float = 0.95) -> list[dict]:
    """P(flag) in each bin of ``x`` (e.g. damage probability against object stiffness).
    ``flags`` as for :func:`probability` (NaN: a run without an outcome, left out; anything else
    but 0/1, ±inf included, a DataError whose index is the entry's in ``flags``), one per
    ``x``."""
    x = np.asarray(x, dtype=np.float64).ravel()
    flags = _outcome_array(flags)
    if flags.size != x.size:
        raise DataError(f"flags: expected one outcome per value of x ({x.size}), found "
                        f"{flags.size}")
    edges = np.asarray(bins, dtype=np.float64)
    rows = []
    for a, b in zip(edges[:-1], edges[1:]):
        m = (x >= a) & (x < b) & ~np.isnan(flags)
        if m.sum() == 0:
            continue
        e = probability(flags[m], confidence)
        rows.append(dict(low=a, high=b, centre=0.5 * (a + b), p=e.value, p_low=e.low, p_high=e.high,
                         n=e.n))
    return rows
