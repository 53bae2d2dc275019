"""Detrending, AC coupling, decimation, resampling and segmenting of trajectories.

"AC coupling" follows ``000_8f66dcc7ab06470c.txt`` §V-F: the average force measured at a fixed
pressure demand is subtracted from the force data. :func:`ac_couple` subtracts either the mean of
the record itself or the mean of a separate reference record.
"""

from __future__ import annotations

from collections.abc import Sequence
from fractions import Fraction

import numpy as np

from ..arguments import sample_interval
from ..errors import DataError
from .filters import _signal, apply_sos, butter_sos
from .trajectory import Trajectory

__all__ = ["remove_mean", "ac_couple", "detrend", "decimate", "resample", "to_uniform", "split",
           "segment_by"]


def _channels(tr: Trajectory, channels: Sequence[str] | None) -> Sequence[str]:
    return tr.names if channels is None else channels


def remove_mean(tr: Trajectory, channels: Sequence[str] | None = None) -> Trajectory:
    """Subtract each selected channel's mean."""
    names = _channels(tr, channels)
    return tr.with_channels(**{n: tr[n] - tr[n].mean() for n in names})


def ac_couple(tr: Trajectory, channels: Sequence[str],
              reference: Trajectory | None = None) -> Trajectory:
    """Subtract the average level of ``reference`` (a record at a fixed operating point), or of
    the record itself when no reference is given (§V-F of the AMADEUS seed)."""
    ref = tr if reference is None else reference
    return tr.with_channels(**{n: tr[n] - float(np.mean(ref[n])) for n in channels})


def detrend(tr: Trajectory, channels: Sequence[str] | None = None,
            kind: str = "linear") -> Trajectory:
    """Remove a least-squares line (``kind='linear'``) or the mean (``'constant'``) against time."""
    if kind not in ("linear", "constant"):
        raise DataError(f"detrend kind: expected 'linear' or 'constant', found {kind!r}")
    names = _channels(tr, channels)
    if kind == "constant":
        return remove_mean(tr, names)
    tc = tr.t - tr.t.mean()
    out = {}
    for n in names:
        y = tr[n]
        slope = float(np.dot(tc, y - y.mean()) / max(np.dot(tc, tc), 1e-300))
        out[n] = y - y.mean() - slope * tc
    return tr.with_channels(**out)


def decimate(tr: Trajectory, q: int, order: int = 8, zero_phase: bool = True) -> Trajectory:
    """Keep every ``q``-th sample after a Butterworth anti-alias low-pass at 0.8/(2q·dt)."""
    if int(q) != q or q < 1:
        raise DataError(f"decimation factor q: expected a positive integer, found {q!r}")
    q = int(q)
    if q == 1:
        return tr
    dt = tr.require_uniform(why="decimation")
    sos = butter_sos(order, 0.8 / dt / (2 * q), dt=dt)
    data = {n: apply_sos(sos, tr[n], zero_phase)[::q] for n in tr.names}
    meta = {**tr.meta, "dt": dt * q}
    return Trajectory(tr.t[::q], data, tr.units, meta)


def to_uniform(tr: Trajectory, dt: float) -> Trajectory:
    """Linear interpolation of a (possibly non-uniform) record onto a uniform grid every ``dt``
    s."""
    dt = sample_interval(dt)
    n = int(np.floor(tr.duration / dt + 1e-9)) + 1
    t = tr.t[0] + np.arange(n) * dt
    data = {k: np.interp(t, tr.t, tr[k]) for k in tr.names}
    return Trajectory(t, data, tr.units, {**tr.meta, "dt": dt})


def resample(tr: Trajectory, dt: float) -> Trajectory:
    """Resample to one sample every ``dt`` s: polyphase filtering for uniform data (rational
    ratio of the intervals), linear interpolation onto a uniform grid otherwise."""
    dt = sample_interval(dt)
    if not tr.is_uniform():
        return to_uniform(tr, dt)
    ratio = Fraction(tr.dt / dt).limit_denominator(1000)
    up, down = ratio.numerator, ratio.denominator
    data = {k: _signal().resample_poly(tr[k], up, down, padtype="line") for k in tr.names}
    n = len(next(iter(data.values())))
    t = tr.t[0] + np.arange(n) * dt
    return Trajectory(t, data, tr.units, {**tr.meta, "dt": dt})


def split(tr: Trajectory, n_segments: int) -> list[Trajectory]:
    """Cut into ``n_segments`` consecutive records of (nearly) equal length, e.g. an
    estimation and a validation record."""
    if int(n_segments) != n_segments or n_segments < 1:
        raise DataError(f"n_segments: expected a positive integer, found {n_segments!r}")
    if tr.n < 2 * n_segments:
        raise DataError(f"cannot split {tr.n} samples into {n_segments} segments")
    return [tr.take(idx) for idx in np.array_split(np.arange(tr.n), int(n_segments))]


def segment_by(tr: Trajectory, boundaries: Sequence[float]) -> list[Trajectory]:
    """Cut at the given times (s): ``[t0, b0), [b0, b1), ..., [b_last, end]``."""
    edges = [tr.t[0], *sorted(boundaries), np.nextafter(tr.t[-1], np.inf)]
    return ([tr.window(a, b) for a, b in zip(edges[:-1],
                                             edges[1:]) if ((tr.t >= a) & (tr.t < b)).any()])
