"""Butterworth filtering in second-order sections, causal or zero-phase.

The AMADEUS identification (``000_8f66dcc7ab06470c.txt`` §V-D) filters force data with a
second-order low-pass Butterworth, f_c = 9 Hz at 200 Hz (dt = 5 ms), "adding two poles at
z = 0.8021 ± j0.1648 and two zeros at z = -1": :func:`butter_zpk` reproduces those numbers.

Filtering functions accept a 1-D array (with its sample interval ``dt`` in s) or a
:class:`Trajectory` (with the channel names to filter; ``dt`` is taken from the trajectory, which
must be uniformly sampled). Cutoff frequencies are in Hz.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence

import numpy as np

from ..arguments import real_array, sample_interval
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


def samples(x, name: str = "x") -> np.ndarray:
    """``x`` as a finite, non-empty float64 array of shape (N,) or (N, C), or a DataError naming
    ``name``: complex numbers, no samples, NaN or ±inf (count and first sample; a filter would
    spread each over every sample after it)."""
    a = real_array(x, name, "an array of samples")
    if a.ndim not in (1, 2):
        raise DataError(f"{name}: expected samples of shape (N,) or (N, C), found {a.shape}")
    if a.shape[0] == 0 or a.size == 0:
        raise DataError(f"{name}: the signal holds no samples (shape {a.shape})")
    if not (np.isfinite(a.min()) and np.isfinite(a.max())):  # min and max carry NaN and inf
        bad = ~np.isfinite(a)
        rows = bad if a.ndim == 1 else bad.any(axis=1)
        raise DataError(f"{name} has {int(bad.sum())} NaN or infinite values (first at sample "
                        f"{int(np.argmax(rows))}); a filter spreads each over every sample after "
                        "it", hint="drop or interpolate them before filtering (CLI: --fill)")
    return a


def _check_sections(sos, btype: str, order: int, cutoff, dt: float, n: int) -> None:
    """A DataError when the cut-off is too low for the order at this sample rate: the sections'
    coefficients round so that the pass-band gain (at DC for a low-pass and a band-stop, at
    Nyquist for a high-pass, at the band's pre-warped centre frequency for a band-pass) is off
    by more than 1e-3, or the steady state for the first sample is singular. The message gives
    the lowest cut-off that works at this order (searched in quarter decades upward; a band is
    scaled as a whole, keeping the ratio of its edges)."""
    def gain(s, wn):
        if btype == "bandpass":  # Butterworth gain 1 at sqrt of the pre-warped edges' product
            w = np.exp(-2j * np.arctan(np.sqrt(np.prod(np.tan(np.pi * wn * dt)))))
        else:
            w = -1.0 if btype == "highpass" else 1.0
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            return float(abs(np.prod([(b0 + b1 * w + b2 * w * w) / (a0 + a1 * w + a2 * w * w)
                                      for b0, b1, b2, a0, a1, a2 in s])))

    def fault(s, wn):
        """Why the sections are unusable, or None."""
        if not abs(gain(s, wn) - 1.0) <= 1e-3:
            return f"its sections round to a pass-band gain of {gain(s, wn):.6g} instead of 1"
        try:
            settled = bool(np.isfinite(_signal().sosfilt_zi(s)).all())
        except np.linalg.LinAlgError:  # a singular steady state
            settled = False
        return None if settled else ("its poles round to z = 1 (the steady state for the first "
                                     "sample is singular)")

    why = fault(sos, np.atleast_1d(np.asarray(cutoff, dtype=np.float64)))
    if why is None:
        return
    nyq, wn = 0.5 / dt, np.atleast_1d(np.asarray(cutoff, dtype=np.float64))
    fc, lo = float(wn.max()), None
    for k in range(1, 80):  # the whole band scaled up together: its ratio stays as given
        trial = wn * 10 ** (k / 4)
        if trial.max() >= nyq:
            break
        with warnings.catch_warnings():  # scipy's BadCoefficients for the trials below it
            warnings.simplefilter("ignore")
            if fault(_signal().butter(order, trial if trial.size > 1 else trial[0], btype=btype,
                                      fs=1 / dt, output="sos"), trial) is None:
                lo = trial
                break
    if lo is None:
        works = "no cut-off works at this order"
    elif lo.size == 1:
        works = (f"a cut-off from about {lo[0]:.3g} Hz up to the Nyquist frequency {nyq:g} Hz "
                 "works at this order")
    else:
        works = (f"the band scaled up to about ({lo[0]:.3g}, {lo[1]:.3g}) Hz (the same ratio of "
                 f"its edges, {wn[1] / wn[0]:.3g}) works at this order")
    raise DataError(f"{btype} cut-off {np.squeeze(cutoff)} Hz is too low for an order-{order} "
                    f"Butterworth at dt = {dt:g} s (cut-off × dt = {fc * dt:.2g}): {why}; {works}",
                    hint=f"raise the cut-off, lower the order or decimate the record first; below "
                         f"1/(N dt) = {1 / (n * dt):.3g} Hz a cut-off lies under the lowest "
                         f"frequency that these {n} samples resolve")


def apply_sos(sos: np.ndarray, x: np.ndarray, zero_phase: bool = False,
              name: str = "x") -> np.ndarray:
    """Filter ``x`` (shape (N,) or (N, C), along time) with second-order sections.

    Causal filtering starts from the filter's steady state for the first sample, so a DC offset
    does not ring. ``zero_phase`` runs forward and backward (squared magnitude, no phase lag,
    not causal). ``x`` must be finite (:func:`samples`; ``name`` in its errors).
    """
    return _run_sos(sos, samples(x, name), zero_phase)


def _run_sos(sos: np.ndarray, x: np.ndarray, zero_phase: bool) -> np.ndarray:
    """:func:`apply_sos` on samples already checked by :func:`samples`."""
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
        _check_sections(sos, btype, int(order), cutoff, dt_tr, x.n)
        names = channels if channels is not None else x.names
        return x.with_channels(**{n: apply_sos(sos, x[n], zero_phase, f"column {n!r}")
                                  for n in names})
    if dt is None:
        raise DataError("dt (the sample interval in s) is required to filter a plain array")
    x = samples(x)
    sos = butter_sos(order, cutoff, dt=dt, btype=btype)
    _check_sections(sos, btype, int(order), cutoff, dt, x.shape[0])
    return _run_sos(sos, x, zero_phase)  # x is checked: samples() once


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
