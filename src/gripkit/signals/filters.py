"""Butterworth filtering in second-order sections, causal or zero-phase.

The AMADEUS identification (``000_8f66dcc7ab06470c.txt`` §V-D) filters force data with a
second-order low-pass Butterworth, f_c = 9 Hz at 200 Hz (dt = 5 ms), "adding two poles at
z = 0.8021 ± j0.1648 and two zeros at z = -1": :func:`butter_zpk` reproduces those numbers.

Filtering functions accept a 1-D array (with its sample interval ``dt`` in s) or a
:class:`Trajectory` (with the channel names to filter; ``dt`` is taken from the trajectory, which
must be uniformly sampled). Cutoff frequencies are in Hz.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..arguments import sample_interval
from ..errors import DataError
from .trajectory import Trajectory


def _signal():
    """``scipy.signal``, imported on first use: it costs more than the rest of ``import
    gripkit`` (docs/performance.md, "Start-up")."""
    from scipy import signal

    return signal


__all__ = ["butter_sos", "butter_zpk", "butter_ba", "apply_sos", "lowpass", "highpass", "bandpass"]


def _check_design(order: int, cutoff, dt: float, btype: str) -> tuple[np.ndarray, float]:
    """(cutoff frequencies in Hz, sampling rate 1/dt) after the checks."""
    if int(order) != order or order < 1:
        raise DataError(f"filter order: expected a positive integer, found {order!r}")
    rate = 1.0 / sample_interval(dt)
    wn = np.atleast_1d(np.asarray(cutoff, dtype=np.float64))
    need = 2 if btype in ("bandpass", "bandstop") else 1
    if wn.size != need:
        raise DataError(f"{btype} filter needs {need} cutoff frequencies, found {wn.size}")
    nyq = rate / 2
    if (wn <= 0).any() or (wn >= nyq).any():
        raise DataError(f"cutoff {cutoff} Hz must lie strictly between 0 and the Nyquist frequency "
                        f"1/(2 dt) = {nyq:g} Hz")
    if need == 2 and wn[0] >= wn[1]:
        raise DataError(f"band edges must increase, found {wn[0]:g} >= {wn[1]:g} Hz")
    return wn, rate


def butter_sos(order: int, cutoff, *, dt: float, btype: str = "lowpass") -> np.ndarray:
    """Digital Butterworth design as second-order sections, shape (ceil(order/2), 6).

    ``cutoff`` in Hz (a pair for band filters); bilinear transform with pre-warping at the
    sampling rate 1/``dt``.
    """
    wn, rate = _check_design(order, cutoff, dt, btype)
    return (_signal().butter(int(order), wn if wn.size > 1 else wn[0], btype=btype, fs=rate,
                             output="sos"))


def butter_zpk(order: int, cutoff, *, dt: float, btype: str = "lowpass"):
    """Zeros, poles and gain of the digital Butterworth filter (z-plane)."""
    wn, rate = _check_design(order, cutoff, dt, btype)
    return (_signal().butter(int(order), wn if wn.size > 1 else wn[0], btype=btype, fs=rate,
                             output="zpk"))


def butter_ba(order: int, cutoff, *, dt: float, btype: str = "lowpass"):
    """Transfer-function coefficients (b, a) in powers of z^-1 (for analysis; filter with SOS)."""
    wn, rate = _check_design(order, cutoff, dt, btype)
    return (_signal().butter(int(order), wn if wn.size > 1 else wn[0], btype=btype, fs=rate,
                             output="ba"))


def apply_sos(sos: np.ndarray, x: np.ndarray, zero_phase: bool = False) -> np.ndarray:
    """Filter ``x`` (shape (N,) or (N, C), along time) with second-order sections.

    Causal filtering starts from the filter's steady state for the first sample, so a DC offset
    does not ring. ``zero_phase`` runs forward and backward (squared magnitude, no phase lag,
    not causal).
    """
    x = np.asarray(x, dtype=np.float64)
    if x.ndim not in (1, 2):
        raise DataError(f"expected samples of shape (N,) or (N, C), found {x.shape}")
    if zero_phase:
        padlen = 3 * (2 * sos.shape[0] + 1)
        if x.shape[0] <= padlen:
            raise DataError(f"zero-phase filtering needs more than {padlen} samples, "
                            f"found {x.shape[0]}")
        return _signal().sosfiltfilt(sos, x, axis=0)
    zi = _signal().sosfilt_zi(sos)
    zi = zi * x[0] if x.ndim == 1 else zi[:, :, None] * x[0][None, None, :]
    y, _ = _signal().sosfilt(sos, x, axis=0, zi=zi)
    return y


def _filter(x, btype, order, cutoff, dt, zero_phase, channels):
    if isinstance(x, Trajectory):
        dt_tr = x.require_uniform(why="digital filtering")
        if dt is not None and abs(dt - dt_tr) > 1e-9 * dt_tr:
            raise DataError(f"dt={dt:g} s given, but the trajectory is sampled every {dt_tr:g} s")
        sos = butter_sos(order, cutoff, dt=dt_tr, btype=btype)
        names = channels if channels is not None else x.names
        return x.with_channels(**{n: apply_sos(sos, x[n], zero_phase) for n in names})
    if dt is None:
        raise DataError("dt (the sample interval in s) is required to filter a plain array")
    return apply_sos(butter_sos(order, cutoff, dt=dt, btype=btype), x, zero_phase)


def lowpass(x, cutoff: float, *, dt: float | None = None, order: int = 2, zero_phase: bool = False,
            channels: Sequence[str] | None = None):
    """Butterworth low-pass (``cutoff`` Hz). Causal by default; ``zero_phase`` for offline use."""
    return _filter(x, "lowpass", order, cutoff, dt, zero_phase, channels)


def highpass(x, cutoff: float, *, dt: float | None = None, order: int = 2, zero_phase: bool = False,
             channels: Sequence[str] | None = None):
    """Butterworth high-pass (``cutoff`` Hz)."""
    return _filter(x, "highpass", order, cutoff, dt, zero_phase, channels)


def bandpass(x, band: tuple[float, float], *, dt: float | None = None, order: int = 2,
             zero_phase: bool = False, channels: Sequence[str] | None = None):
    """Butterworth band-pass between ``band = (f_low, f_high)`` Hz."""
    return _filter(x, "bandpass", order, band, dt, zero_phase, channels)
