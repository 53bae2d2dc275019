"""Contact detection on a noisy force signal with a threshold and hysteresis
(``001_0b92a7da96e7aa46.txt`` §V-C: force-sensor noise below 2 µN, threshold 5 µN).

A raw threshold of 5 µN on samples with 2 µN Gaussian noise fires falsely on 0.6 % of the
samples — over a hundred times a second at 20 kHz. :class:`ContactDetector` therefore compares a
moving average of the last ``window`` samples (8 by default: noise /√8, 0.4 ms of delay at 20 kHz)
with the threshold, and releases the contact only when the average falls below ``release``
(default half the threshold), so noise around the threshold cannot make it chatter.
:func:`detector_step` is the numba step, callable inside control loops.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ..errors import DataError

__all__ = ["ContactDetector", "detector_step", "false_alarm_probability"]


@numba.njit(cache=True)
def detector_step(st, buf, F, threshold, release):  # pragma: no cover - compiled
    """One sample. st = [in_contact, running sum, index, count, filtered force];
    buf (window,) the last samples. Returns 1.0 in contact, else 0.0."""
    w = buf.shape[0]
    i = int(st[2])
    if st[3] >= w:
        st[1] -= buf[i]
    else:
        st[3] += 1.0
    buf[i] = F
    st[1] += F
    st[2] = (i + 1) % w
    avg = st[1] / st[3]
    st[4] = avg
    if st[0] > 0.5:
        if avg < release:
            st[0] = 0.0
    elif avg > threshold and st[3] >= w:
        st[0] = 1.0
    return st[0]


@numba.njit(cache=True)
def _detector_run(st, buf, F, threshold, release, out, avg):  # pragma: no cover - compiled
    for k in range(F.shape[0]):
        out[k] = detector_step(st, buf, F[k], threshold, release)
        avg[k] = st[4]


def false_alarm_probability(threshold: float, noise_std: float, window: int) -> float:
    """Probability that the moving average of ``window`` samples of zero-mean Gaussian noise
    exceeds ``threshold`` on one sample."""
    return 0.5 * math.erfc(threshold / (noise_std / math.sqrt(window)) / math.sqrt(2.0))


class ContactDetector:
    """Contact from a force signal (N): on when the ``window``-sample average exceeds
    ``threshold``, off when it falls below ``release`` (default ``threshold/2``).

    >>> det = ContactDetector(5e-6)
    >>> [det.update(f) for f in [0.0] * 8 + [8e-6] * 8]
    [False, False, False, False, False, False, False, False, False, False, False, False, False,
    True, True, True]
    """

    def __init__(self, threshold: float = 5e-6, release: float | None = None, window: int = 8):
        if not (np.isfinite(threshold) and threshold > 0):
            raise DataError(f"threshold: expected a positive force in N, found {threshold!r}")
        release = threshold / 2.0 if release is None else float(release)
        if not 0 <= release < threshold:
            raise DataError(f"release: expected 0 <= release < threshold ({threshold:g} N), "
                            f"found {release!r}")
        if int(window) < 1:
            raise DataError(f"window: expected >= 1 sample, found {window!r}")
        self.threshold, self.release, self.window = float(threshold), release, int(window)
        self.state = np.zeros(5)
        self.buffer = np.zeros(self.window)

    def reset(self) -> None:
        self.state[:] = 0.0
        self.buffer[:] = 0.0

    @property
    def in_contact(self) -> bool:
        return bool(self.state[0] > 0.5)

    @property
    def filtered(self) -> float:
        """The moving average of the force (N)."""
        return float(self.state[4])

    def update(self, F: float) -> bool:
        return (bool(detector_step(self.state, self.buffer, float(F), self.threshold,
                                   self.release) > 0.5))

    def run(self, F) -> tuple[np.ndarray, np.ndarray]:
        """(in_contact (bool, N), moving average (N)) for a whole record."""
        F = np.ascontiguousarray(F, dtype=np.float64)
        if F.ndim != 1 or not np.isfinite(F).all():
            raise DataError("F: expected a finite 1-D force record")
        out = np.empty(F.size)
        avg = np.empty(F.size)
        _detector_run(self.state, self.buffer, F, self.threshold, self.release, out, avg)
        return out > 0.5, avg
