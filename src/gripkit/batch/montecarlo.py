"""Monte Carlo statistics for robustness studies: probabilities with confidence intervals,
quantiles with distribution-free intervals, and probability against a swept parameter.

Probabilities use the Wilson score interval (well behaved for p near 0 or 1, unlike the normal
approximation): for k successes in n trials and z the normal quantile,

    p̃ = (k + z²/2)/(n + z²),   half-width = z √(k(n−k)/n + z²/4) / (n + z²).

Quantile intervals use order statistics: the q-quantile lies between the order statistics of
ranks given by the binomial(n, q) distribution's (α/2, 1−α/2) quantiles.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats

from ..errors import DataError

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
        return (f"{self.value:.4g} [{self.low:.4g}, {self.high:.4g}] ({100 * self.confidence:.0f} "
                f"% CI, n={self.n})")


def probability(flags, confidence: float = 0.95) -> Estimate:
    """Probability that ``flags`` is True, with the Wilson interval. NaN entries are excluded."""
    f = np.asarray(flags, dtype=np.float64)
    f = f[np.isfinite(f)]
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
    or a bound that falls on such entries is inf."""
    x = np.asarray(x, dtype=np.float64)
    v = np.sort(x[~np.isnan(x)])
    n = v.size
    if n == 0:
        raise DataError("a quantile needs at least one finite value")
    if not 0 < q < 1:
        raise DataError(f"q: expected 0 < q < 1, found {q}")
    a = (1 - confidence) / 2
    lo_rank = int(stats.binom.ppf(a, n, q))
    hi_rank = int(stats.binom.ppf(1 - a, n, q)) + 1
    lo = v[max(lo_rank - 1, 0)] if lo_rank >= 1 else -math.inf
    hi = v[hi_rank - 1] if hi_rank <= n else math.inf
    value = np.quantile(v, q, method="inverted_cdf" if np.isinf(v).any() else "linear")
    return Estimate(float(value), float(lo), float(hi), n, confidence)


def binned_probability(x, flags, bins, confidence: float = 0.95) -> list[dict]:
    """P(flag) in each bin of ``x`` (e.g. damage probability against object stiffness)."""
    x = np.asarray(x, dtype=np.float64)
    flags = np.asarray(flags, dtype=np.float64)
    edges = np.asarray(bins, dtype=np.float64)
    rows = []
    for a, b in zip(edges[:-1], edges[1:]):
        m = (x >= a) & (x < b) & np.isfinite(flags)
        if m.sum() == 0:
            continue
        e = probability(flags[m], confidence)
        rows.append(dict(low=a, high=b, centre=0.5 * (a + b), p=e.value, p_low=e.low, p_high=e.high,
                         n=e.n))
    return rows
