"""Butterworth filtering in second-order sections, causal or zero-phase.

The AMADEUS identification (``000_8f66dcc7ab06470c.txt`` §V-D) filters force data with a
second-order low-pass Butterworth, f_c = 9 Hz at fs = 200 Hz, "adding two poles at
z = 0.8021 ± j0.1648 and two zeros at z = -1": :func:`butter_zpk` reproduces those numbers.

Filtering functions accept a 1-D array (with ``fs``) or a :class:`Trajectory` (with the
channel names to filter; ``fs`` is taken from the trajectory, which must be uniformly sampled).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import DataError
from .trajectory import Trajectory

def _signal():
    """``scipy.signal``, imported on first use: it costs ~0.7 s, more than the rest of ``import gripkit``."""
    from scipy import signal

    return signal


__all__ = ["butter_sos", "butter_zpk", "butter_ba", "apply_sos", "lowpass", "highpass", "bandpass"]


def _check_design(order: int, cutoff, fs: float, btype: str) -> np.ndarray:
    if int(order) != order or order < 1:
        raise DataError(f"filter order: expected a positive integer, found {order!r}")
    if not (np.isfinite(fs) and fs > 0):
        raise DataError(f"fs: expected a positive sampling rate in Hz, found {fs!r}")
    wn = np.atleast_1d(np.asarray(cutoff, dtype=np.float64))
    need = 2 if btype in ("bandpass", "bandstop") else 1
    if wn.size != need:
        raise DataError(f"{btype} filter needs {need} cutoff frequencies, found {wn.size}")
    nyq = fs / 2
    if (wn <= 0).any() or (wn >= nyq).any():
        raise DataError(f"cutoff {cutoff} Hz must lie strictly between 0 and fs/2 = {nyq:g} Hz")
    if need == 2 and wn[0] >= wn[1]:
        raise DataError(f"band edges must increase, found {wn[0]:g} >= {wn[1]:g} Hz")
    return wn


def butter_sos(order: int, cutoff, fs: float, btype: str = "lowpass") -> np.ndarray:
    """Digital Butterworth design as second-order sections, shape (ceil(order/2), 6).

    ``cutoff`` in Hz (a pair for band filters); bilinear transform with pre-warping at ``fs``.
    """
    wn = _check_design(order, cutoff, fs, btype)
    return _signal().butter(int(order), wn if wn.size > 1 else wn[0], btype=btype, fs=fs, output="sos")


def butter_zpk(order: int, cutoff, fs: float, btype: str = "lowpass"):
    """Zeros, poles and gain of the digital Butterworth filter (z-plane)."""
    wn = _check_design(order, cutoff, fs, btype)
    return _signal().butter(int(order), wn if wn.size > 1 else wn[0], btype=btype, fs=fs, output="zpk")


def butter_ba(order: int, cutoff, fs: float, btype: str = "lowpass"):
    """Transfer-function coefficients (b, a) in powers of z^-1 (for analysis; filter with SOS)."""
    wn = _check_design(order, cutoff, fs, btype)
    return _signal().butter(int(order), wn if wn.size > 1 else wn[0], btype=btype, fs=fs, output="ba")


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
            raise DataError(f"zero-phase filtering needs more than {padlen} samples, found {x.shape[0]}")
        return _signal().sosfiltfilt(sos, x, axis=0)
    zi = _signal().sosfilt_zi(sos)
    zi = zi * x[0] if x.ndim == 1 else zi[:, :, None] * x[0][None, None, :]
    y, _ = _signal().sosfilt(sos, x, axis=0, zi=zi)
    return y


def _filter(x, sos_fn, order, cutoff, fs, zero_phase, channels):
    if isinstance(x, Trajectory):
        fs_tr = x.require_uniform(why="digital filtering")
        if fs is not None and abs(fs - fs_tr) > 1e-9 * fs_tr:
            raise DataError(f"fs={fs} Hz given, but the trajectory is sampled at {fs_tr:g} Hz")
        sos = sos_fn(order, cutoff, fs_tr)
        names = channels if channels is not None else x.names
        return x.with_channels(**{n: apply_sos(sos, x[n], zero_phase) for n in names})
    if fs is None:
        raise DataError("fs is required to filter a plain array")
    sos = sos_fn(order, cutoff, fs)
    return apply_sos(sos, x, zero_phase)


def lowpass(x, cutoff: float, fs: float | None = None, order: int = 2, zero_phase: bool = False,
            channels: Sequence[str] | None = None):
    """Butterworth low-pass (``cutoff`` Hz). Causal by default; ``zero_phase`` for offline use."""
    return _filter(x, lambda o, c, f: butter_sos(o, c, f, "lowpass"), order, cutoff, fs, zero_phase, channels)


def highpass(x, cutoff: float, fs: float | None = None, order: int = 2, zero_phase: bool = False,
             channels: Sequence[str] | None = None):
    """Butterworth high-pass (``cutoff`` Hz)."""
    return _filter(x, lambda o, c, f: butter_sos(o, c, f, "highpass"), order, cutoff, fs, zero_phase, channels)


def bandpass(x, band: tuple[float, float], fs: float | None = None, order: int = 2,
             zero_phase: bool = False, channels: Sequence[str] | None = None):
    """Butterworth band-pass between ``band = (f_low, f_high)`` Hz."""
    return _filter(x, lambda o, c, f: butter_sos(o, c, f, "bandpass"), order, band, fs, zero_phase, channels)
