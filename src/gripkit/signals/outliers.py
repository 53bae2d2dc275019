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
  samples) is used, so that more than ``m`` corrupt values cannot widen the scale and hide
  themselves;
* it belongs to a run of at most :data:`MAX_RUN` consecutive such samples, and the run jumps away
  from the samples next to it by more than ``K·s`` as well. A step, a longer pulse or a decaying
  transient lasts longer than that or joins the rest of the record smoothly; a corrupt value does
  neither.

More than ``2m`` such samples are a property of the signal (a trigger or pulse train), not
corruption, and are not reported, unless every one of them lies more than :data:`GROSS` times
further out than that (``|x_i − med(x)| > GROSS·K·s``, with ``s`` from the MAD): values a
thousand times beyond the eight-σ bound of a channel with spread are sentinels or bit flips, not
pulses of the signal, however many there are (up to a quarter of the samples).

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
#: Factor beyond the K·s bound (s from the MAD) past which many outlying samples (more than 2m)
#: are still reported as corrupt: three orders of magnitude beyond eight σ.
GROSS = 1e3
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
        if mad > 0.0:
            scale = min(scale, mad)
        out = dev > THRESHOLD * scale
    if not out.any():
        return np.empty(0, dtype=np.intp)
    keep = _isolated_runs(x, out, THRESHOLD * scale)
    # more than the scale estimate sets aside: pulses of the signal, not corruption, unless all
    # of them are gross (a channel with spread, and values a thousand times past its bound)
    if len(keep) > 2 * m:
        gross = mad > 0.0 and len(keep) <= n // 4 and bool(
            (dev[keep] > GROSS * THRESHOLD * mad).all())
        if not gross:
            return np.empty(0, dtype=np.intp)
    return np.asarray(keep, dtype=np.intp)


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
