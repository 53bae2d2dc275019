"""Corrupt samples: isolated values far outside the rest of a channel (a bit flip, a sentinel such
as
-9999 or 1e30 written by a logger, a transmission error).

A sample is flagged when both hold:

* it lies more than :data:`THRESHOLD` robust standard deviations from the channel's median,
  ``|x_i − med(x)| > K·s``, with the robust scale taken from order statistics that exclude the
  ``m`` most extreme samples on each side,

      s = (x_(N−1−m) − x_(m)) / (2 z_p),   z_p = Φ⁻¹(1 − p),  p = (m + ½)/N,
      m = max(MAX_RUN + 1, ⌈10⁻³ N⌉),

  which equals σ for Gaussian data and is not moved by up to ``m`` corrupt values; when the
  median absolute deviation (MAD) of the channel is not zero, the smaller of that scale and
  ``1.4826·MAD`` (also σ for Gaussian data, and not moved by corrupt values in up to half of the
  samples) is tried first, so that more than ``m`` corrupt values cannot widen the scale and hide
  themselves, for samples that also lie beyond the range of all the others by more than ``K·s``
  (on a channel of two levels the MAD is the quiet level's noise alone); when it flags nothing (or
  a pulse train, below) the order-statistic scale decides;
* it belongs to a run of at most :data:`MAX_RUN` consecutive such samples, and the run jumps away
  from the samples next to it by more than ``K·s`` as well. A step, a longer pulse or a decaying
  transient lasts longer than that or joins the rest of the record smoothly; a corrupt value does
  neither.

More than ``2m`` such samples are a property of the signal (a trigger or pulse train), not
corruption, and are not reported, unless every one of them lies more than :data:`GROSS` times
the range of all the other samples from the median (that range not zero): values ten thousand
times further out than anything else the channel holds are sentinels or bit flips, not pulses of
the signal, however many there are (up to a quarter of the samples).

Whole signals at extreme but valid scales (1e300, 1e-300) are never flagged: the test is
scale-free.
"""

from __future__ import annotations

import math
from statistics import NormalDist

import numpy as np

__all__ = ["corrupt_samples", "THRESHOLD", "MAX_RUN", "GROSS"]

#: K, in robust standard deviations. For Gaussian data the chance that any of N samples lies beyond
#: K·σ is N·2Φ(−K); with N up to 1e9 samples per channel and a false-alarm probability of 1e-6 per
#: channel, K = Φ⁻¹(1 − 1e-6 / (2·1e9)) = 8.03. The corrupt values this check is meant for sit
#: orders of magnitude further out.
THRESHOLD = -NormalDist().inv_cdf(1e-6 / (2.0 * 1e9))
#: Longest run of consecutive outlying samples still reported as corrupt samples.
MAX_RUN = 3
#: Factor beyond the range of the other samples past which many outlying samples (more than 2m)
#: are still reported as corrupt. A trigger or pulse channel logged through a 16-bit converter
#: spans a few thousand of its noise ranges; a sentinel (1e6 in a ±1 channel) far more.
GROSS = 1e4
#: 1/Φ⁻¹(3/4): the MAD of Gaussian data times this is σ.
_MAD_TO_SIGMA = 1.0 / NormalDist().inv_cdf(0.75)


def corrupt_samples(x: np.ndarray) -> np.ndarray:
    """Indices of the corrupt samples of the finite 1-D array ``x`` (see the module docstring);
    empty when there are none or when ``x`` is too short (fewer than ``4·MAX_RUN + 5`` samples) to
    tell."""
    x = np.asarray(x, dtype=np.float64)
    n = x.size
    m = max(MAX_RUN + 1, math.ceil(1e-3 * n))
    if n < 2 * m + 2 * MAX_RUN + 1:
        return np.empty(0, dtype=np.intp)
    lo, mid, hi = np.partition(x, [m, n // 2, n - 1 - m])[[m, n // 2, n - 1 - m]]
    z = -NormalDist().inv_cdf((m + 0.5) / n)
    with np.errstate(over="ignore", invalid="ignore"):
        dev = np.abs(x - mid)
        mad = _MAD_TO_SIGMA * float(np.partition(dev, n // 2)[n // 2])
        scale = (hi - lo) / (2.0 * z)
    # the MAD scale first where it is the smaller; the order-statistic one when that finds none
    scales = [mad, scale] if 0.0 < mad < scale else [scale]
    for s in scales:
        keep = _flagged(x, dev, THRESHOLD * s, m)
        if keep.size and s == mad and s != scale:
            keep = _beyond_the_rest(x, keep, THRESHOLD * s)
        if keep.size:
            return keep
    return keep


def _beyond_the_rest(x: np.ndarray, keep: np.ndarray, bound: float) -> np.ndarray:
    """The samples of ``keep`` that lie beyond the range of all the other samples by more than
    ``bound``. The MAD measures the noise of the level where most samples sit; on a channel of two
    levels (a contact force: zero, then pressing) the small chatter around the quiet level lies
    many MADs out but within what the channel holds; a corrupt value lies outside it."""
    rest = np.ones(x.size, dtype=bool)
    rest[keep] = False
    lo, hi = float(np.min(x[rest])), float(np.max(x[rest]))
    with np.errstate(over="ignore", invalid="ignore"):
        out = (x[keep] > hi + bound) | (x[keep] < lo - bound)
    return keep[out]


def _flagged(x: np.ndarray, dev: np.ndarray, bound: float, m: int) -> np.ndarray:
    """The corrupt samples of ``x`` for the bound ``K·s`` on ``dev = |x − med(x)|``."""
    with np.errstate(invalid="ignore"):
        out = dev > bound
    if not out.any():
        return np.empty(0, dtype=np.intp)
    keep = _isolated_runs(x, out, bound)
    # more than the scale estimate sets aside: pulses of the signal, not corruption, unless all
    # of them are gross (GROSS times the range of the other samples from the median)
    if len(keep) > 2 * m and not (len(keep) <= x.size // 4 and _gross(x, dev, keep)):
        return np.empty(0, dtype=np.intp)
    return np.asarray(keep, dtype=np.intp)


def _gross(x: np.ndarray, dev: np.ndarray, keep: list[int]) -> bool:
    """Whether every sample of ``keep`` deviates (``dev``, from the median) by more than
    :data:`GROSS` times the range of the other samples of ``x``, that range not zero."""
    rest = np.ones(x.size, dtype=bool)
    rest[keep] = False
    with np.errstate(over="ignore", invalid="ignore"):
        span = float(np.ptp(x[rest]))
        return span > 0.0 and bool((dev[keep] > GROSS * span).all())


def _isolated_runs(x: np.ndarray, out: np.ndarray, bound: float) -> list[int]:
    """The indices of the runs of ``out`` of at most :data:`MAX_RUN` samples that jump away from
    their neighbours by more than ``bound`` (not the tail of a fast transient)."""
    n = x.size
    edges = np.diff(np.concatenate([[0], out.astype(np.int8), [0]]))
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    keep: list[int] = []
    with np.errstate(over="ignore", invalid="ignore"):
        for a, b in zip(starts, stops):
            if b - a > MAX_RUN:
                continue
            if a > 0 and not abs(x[a] - x[a - 1]) > bound:
                continue
            if b < n and not abs(x[b - 1] - x[b]) > bound:
                continue
            keep.extend(range(a, b))
    return keep
