"""Excitation design: multisine, band-limited noise, PRBS, chirp and steps, each placed around an
operating point inside amplitude limits.

The AMADEUS finger identification (``000_8f66dcc7ab06470c.txt`` §V-E) uses two inputs:

* S1: 400 samples at 200 Hz (2 s), a sum of sines from 1 to 10 Hz at 1 Hz steps, driving a valve
  between 600 and 1100 mA around 850 mA (Fig. 17): ``multisine(range(1, 11), 2.0, 200.0,
  operating_point=0.850, limits=(0.600, 1.100), unit='A')``;
* S2: 4000 samples at 200 Hz (20 s) of band-pass random noise, 0.3–10 Hz (Fig. 18):
  ``bandlimited_noise(0.3, 10.0, 20.0, 200.0, operating_point=0.850, limits=(0.600, 1.100))``.

Every generator returns an :class:`Excitation` whose signal never leaves ``limits``: the
deviation from the operating point is scaled so that its extreme just reaches the nearer limit
(or to ``amplitude`` when given, which must then fit).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .arguments import sample_interval
from .errors import DataError
from .signals.filters import apply_sos, butter_sos
from .signals.trajectory import Trajectory

__all__ = ["Excitation", "multisine", "periodic_multisine", "bandlimited_noise", "prbs", "chirp",
           "steps",
           "crest_factor"]


@dataclass(frozen=True)
class Excitation:
    """A designed input signal.

    Attributes
    ----------
    kind
        'multisine', 'noise', 'prbs', 'chirp' or 'steps'.
    t, u
        Time (s) and signal (in ``unit``), shape (N,).
    dt
        Sample interval (s).
    operating_point, limits
        Centre value and (lower, upper) bounds, in ``unit``; ``limits[0] <= u <= limits[1]``.
    unit
        Unit of ``u`` (e.g. 'A' for a valve current).
    info
        Design details: frequencies, phases, seed, crest factor.
    """

    kind: str
    t: np.ndarray
    u: np.ndarray
    dt: float
    operating_point: float
    limits: tuple[float, float]
    unit: str = "1"
    info: dict = field(default_factory=dict)

    @property
    def crest_factor(self) -> float:
        return crest_factor(self.u - self.operating_point)

    def to_trajectory(self, name: str = "u") -> Trajectory:
        return Trajectory(self.t, {name: self.u}, {name: self.unit},
                          {"dt": self.dt, "excitation": self.kind, **self.info})


def crest_factor(x: np.ndarray) -> float:
    """Peak over RMS of ``x`` (√2 for a single sine)."""
    x = np.asarray(x, dtype=np.float64)
    rms = math.sqrt(float(np.mean(x * x)))
    return float(np.max(np.abs(x)) / rms) if rms > 0 else math.inf


def _check_dt(dt) -> float:
    """1/dt, the sampling rate the designs' frequency grids use, after checking dt."""
    return 1.0 / sample_interval(dt)


def _check_common(duration: float, dt: float, operating_point: float,
                  limits) -> tuple[int, float, float, float]:
    """(samples, lower limit, upper limit, sampling rate 1/dt) of a design, after the checks."""
    rate = _check_dt(dt)
    if not (np.isfinite(duration) and duration > 0):
        raise DataError(f"duration: expected a positive number of seconds, found {duration!r}")
    n = int(round(duration * rate))
    if n < 2:
        raise DataError(f"duration {duration} s at dt = {dt:g} s gives {n} samples; "
                        "need at least 2")
    lo, hi = (float(limits[0]), float(limits[1]))
    if not lo < hi:
        raise DataError(f"limits: expected (lower, upper) with lower < upper, found {limits!r}")
    if not lo <= operating_point <= hi:
        raise DataError(f"operating point {operating_point:g} lies outside the limits "
                        f"[{lo:g}, {hi:g}]")
    return n, lo, hi, rate


def _place(dev: np.ndarray, operating_point: float, lo: float, hi: float,
           amplitude: float | None) -> np.ndarray:
    """Scale a zero-centred deviation so the signal stays in [lo, hi] and return the signal."""
    pos, neg = float(dev.max()), float(-dev.min())
    room = min((hi - operating_point) / pos if pos > 0 else math.inf,
               (operating_point - lo) / neg if neg > 0 else math.inf)
    if amplitude is None:
        if not math.isfinite(room):
            raise DataError("the designed deviation is identically zero")
        scale = room
    else:
        peak = max(pos, neg)
        scale = float(amplitude) / peak
        if scale > room * (1 + 1e-12):
            raise DataError(
                f"amplitude {amplitude:g} around {operating_point:g} leaves the limits "
                f"[{lo:g}, {hi:g}]",
                hint=f"the largest amplitude that fits is {room * peak:.6g}",
            )
    return np.clip(operating_point + scale * dev, lo, hi)


def multisine(frequencies: Sequence[float], duration: float, *, dt: float,
              operating_point: float = 0.0,
              limits: tuple[float, float] = (-1.0, 1.0), amplitude: float | None = None,
              phases: str = "min-crest", seed: int = 0, iterations: int = 200,
              unit: str = "1") -> Excitation:
    """Sum of equal-amplitude sines  u(t) = u0 + A·Σ_k cos(2π f_k t + φ_k).

    ``phases``: 'min-crest' (Schroeder start, then iterative clipping to lower the crest factor;
    needs the frequencies on the grid 1/(N·dt) of the record), 'schroeder' (φ_k = -π k(k-1)/K),
    'random' (uniform, ``seed``) or 'zero'.
    """
    n, lo, hi, rate = _check_common(duration, dt, operating_point, limits)
    f = np.asarray(list(frequencies), dtype=np.float64)
    if f.size == 0:
        raise DataError("multisine needs at least one frequency")
    if (f <= 0).any() or (f >= rate / 2).any():
        raise DataError(f"multisine frequencies must lie in (0, 1/(2 dt) = {rate / 2:g}) Hz, "
                        f"found {f.tolist()}")
    t = np.arange(n) / rate
    k = np.arange(1, f.size + 1)
    if phases == "zero":
        phi = np.zeros(f.size)
    elif phases == "random":
        phi = np.random.default_rng(seed).uniform(-np.pi, np.pi, f.size)
    elif phases in ("schroeder", "min-crest"):
        phi = -np.pi * k * (k - 1) / f.size
    else:
        raise DataError("phases: expected 'min-crest', 'schroeder', 'random' or 'zero', "
                        f"found {phases!r}")
    bins = f * n / rate
    on_grid = np.allclose(bins, np.round(bins), atol=1e-6)
    if phases == "min-crest" and on_grid:
        phi = _min_crest_phases(np.round(bins).astype(int), phi, n, iterations)
    dev = np.cos(2 * np.pi * f[None, :] * t[:, None] + phi[None, :]).sum(axis=1)
    u = _place(dev, operating_point, lo, hi, amplitude)
    info = {"frequencies_hz": f.tolist(), "phases_rad": phi.tolist(), "phase_method": phases,
            "periodic": bool(on_grid), "crest_factor": crest_factor(u - operating_point)}
    return Excitation("multisine", t, u, float(dt), float(operating_point), (lo, hi), unit, info)


def periodic_multisine(f_min: float, f_max: float, period_samples: int, periods: int, *, dt: float,
                       lines: str = "all", operating_point: float = 0.0,
                       limits: tuple[float, float] = (-1.0, 1.0),
                       amplitude: float | None = None, seed: int = 0, iterations: int = 200,
                       unit: str = "1") -> Excitation:
    """A crest-factor-optimised multisine on chosen DFT lines of one period, repeated an integer
    number of times: the design that :func:`gripkit.sysid.linear.frf` with ``periods`` expects.

    One period has L = ``period_samples`` samples; line k is the frequency k/(L·dt) (Hz), so every
    period is exactly periodic and leakage-free. Lines between ``f_min`` and ``f_max``:
    ``'all'``; ``'odd'`` (odd k only: even nonlinear distortions fall on the even lines);
    ``'random-odd'`` (odd k with one of every three consecutive odd lines left out at random,
    ``seed``: detection lines for odd distortions; Pintelon & Schoukens 2012, §3.7). Phases: the
    minimum crest factor found by iterative clipping from Schroeder phases (:func:`multisine`).

    ``info`` records ``lines`` (the excited k), ``period_samples`` and ``periods``.

    Examples
    --------
    >>> from gripkit.excitation import periodic_multisine
    >>> ex = periodic_multisine(1.0, 20.0, 400, 4, dt=0.005, lines="odd")
    >>> ex.u.size, ex.info["lines"][:3], ex.info["periods"]
    (1600, [3, 5, 7], 4)
    """
    L = int(period_samples)
    P = int(periods)
    if L < 4 or L != period_samples:
        raise DataError(f"period_samples: expected an integer >= 4, found {period_samples!r}")
    if P < 1 or P != periods:
        raise DataError(f"periods: expected a positive integer, found {periods!r}")
    rate = _check_dt(dt)
    k = np.arange(max(1, int(math.ceil(f_min * L / rate))), int(math.floor(f_max * L / rate)) + 1)
    k = k[k < L / 2]
    if lines == "odd" or lines == "random-odd":
        k = k[k % 2 == 1]
        if lines == "random-odd" and k.size >= 3:
            rng = np.random.default_rng(seed)
            drop = [g + rng.integers(0, 3) for g in range(0, k.size - 2, 3)]
            k = np.delete(k, drop)
    elif lines != "all":
        raise DataError(f"lines: expected 'all', 'odd' or 'random-odd', found {lines!r}")
    if k.size == 0:
        raise DataError(f"no DFT line of a {L}-sample period at dt = {dt:g} s (resolution "
                        f"{rate / L:g} Hz) lies in "
                        f"[{f_min:g}, {f_max:g}] Hz", hint="lengthen the period or widen the band")
    one = multisine(k * rate / L, L / rate, dt=dt, operating_point=operating_point, limits=limits,
                    amplitude=amplitude,
                    phases="min-crest", seed=seed, iterations=iterations, unit=unit)
    u = np.tile(one.u, P)
    t = np.arange(u.size) / rate
    info = ({**one.info, "lines": k.tolist(), "line_selection": lines, "period_samples": L,
             "periods": P})
    return Excitation("multisine", t, u, float(dt), float(operating_point), one.limits, unit, info)


def _min_crest_phases(bins: np.ndarray, phi0: np.ndarray, n: int, iterations: int) -> np.ndarray:
    """Iterative clipping (Van der Ouderaa et al., 1988): clip the peaks, keep only the phases of
    the excited bins, restore equal amplitudes; keep the best crest factor seen."""
    spec = np.zeros(n // 2 + 1, dtype=complex)
    spec[bins] = np.exp(1j * phi0)
    best_phi, best_cf = phi0.copy(), crest_factor(np.fft.irfft(spec, n))
    phi = phi0.copy()
    for it in range(iterations):
        x = np.fft.irfft(spec, n)
        clip = (0.9 - 0.3 * it / max(iterations, 1)) * np.max(np.abs(x))
        xc = np.clip(x, -clip, clip)
        phi = np.angle(np.fft.rfft(xc)[bins])
        spec[:] = 0
        spec[bins] = np.exp(1j * phi)
        cf = crest_factor(np.fft.irfft(spec, n))
        if cf < best_cf:
            best_cf, best_phi = cf, phi.copy()
    return best_phi


def bandlimited_noise(f_low: float, f_high: float, duration: float, *, dt: float,
                      operating_point: float = 0.0, limits: tuple[float, float] = (-1.0, 1.0),
                      amplitude: float | None = None, order: int = 4, seed: int = 0,
                      unit: str = "1") -> Excitation:
    """Gaussian white noise through a zero-phase Butterworth band-pass ``[f_low, f_high]`` Hz
    (``f_low = 0`` gives a low-pass), scaled so its extreme just fits the limits."""
    n, lo, hi, rate = _check_common(duration, dt, operating_point, limits)
    if not 0 <= f_low < f_high < rate / 2:
        raise DataError(f"band: expected 0 <= f_low < f_high < 1/(2 dt) = {rate / 2:g} Hz, found "
                        f"({f_low}, {f_high})")
    rng = np.random.default_rng(seed)
    pad = int(3 * rate / max(f_low, f_high / 10, 1e-3))
    w = rng.standard_normal(n + 2 * pad)
    sos = (butter_sos(order, f_high, dt=dt) if f_low == 0 else butter_sos(order, (f_low, f_high),
                                                                          dt=dt, btype="bandpass"))
    dev = apply_sos(sos, w, zero_phase=True)[pad:pad + n]
    dev -= dev.mean()
    t = np.arange(n) / rate
    u = _place(dev, operating_point, lo, hi, amplitude)
    info = {"band_hz": [float(f_low), float(f_high)], "order": order, "seed": seed,
            "crest_factor": crest_factor(u - operating_point)}
    return Excitation("noise", t, u, float(dt), float(operating_point), (lo, hi), unit, info)


# Feedback taps (1-based) of maximal-length Fibonacci LFSRs, register length 2..20.
_LFSR_TAPS = {2: (2, 1), 3: (3, 2), 4: (4, 3), 5: (5, 3), 6: (6, 5), 7: (7, 6), 8: (8, 6, 5, 4),
              9: (9, 5), 10: (10, 7), 11: (11, 9), 12: (12, 11, 10, 4), 13: (13, 12, 11, 8),
              14: (14, 13, 12, 2), 15: (15, 14), 16: (16, 15, 13, 4), 17: (17, 14), 18: (18, 11),
              19: (19, 18, 17, 14), 20: (20, 17)}


def prbs(register: int, duration: float, *, dt: float, samples_per_bit: int = 1,
         operating_point: float = 0.0, limits: tuple[float, float] = (-1.0, 1.0),
         amplitude: float | None = None, unit: str = "1") -> Excitation:
    """Maximum-length pseudo-random binary sequence (period 2^register - 1 bits), each bit held
    for ``samples_per_bit`` samples, switching between operating_point ± amplitude."""
    if register not in _LFSR_TAPS:
        raise DataError(f"register length: expected 2..20, found {register!r}")
    if int(samples_per_bit) != samples_per_bit or samples_per_bit < 1:
        raise DataError(f"samples_per_bit: expected a positive integer, found {samples_per_bit!r}")
    n, lo, hi, rate = _check_common(duration, dt, operating_point, limits)
    taps = _LFSR_TAPS[register]
    period = 2 ** register - 1
    state = [1] * register
    bits = np.empty(period, dtype=np.float64)
    for i in range(period):
        bits[i] = state[-1]
        fb = 0
        for tp in taps:
            fb ^= state[tp - 1]
        state = [fb] + state[:-1]
    seq = np.repeat(2 * bits - 1, int(samples_per_bit))
    dev = np.resize(seq, n)
    t = np.arange(n) / rate
    u = _place(dev, operating_point, lo, hi, amplitude)
    info = {"register": register, "period_bits": period, "samples_per_bit": int(samples_per_bit)}
    return Excitation("prbs", t, u, float(dt), float(operating_point), (lo, hi), unit, info)


def chirp(f0: float, f1: float, duration: float, *, dt: float, method: str = "logarithmic",
          operating_point: float = 0.0, limits: tuple[float, float] = (-1.0, 1.0),
          amplitude: float | None = None, unit: str = "1") -> Excitation:
    """Swept sine from ``f0`` to ``f1`` Hz ('linear' or 'logarithmic' sweep)."""
    from scipy.signal import chirp as _chirp

    n, lo, hi, rate = _check_common(duration, dt, operating_point, limits)
    if not (0 < f0 < rate / 2 and 0 < f1 < rate / 2):
        raise DataError(f"chirp frequencies must lie in (0, 1/(2 dt) = {rate / 2:g}) Hz, "
                        f"found {f0}, {f1}")
    if method not in ("linear", "logarithmic"):
        raise DataError(f"method: expected 'linear' or 'logarithmic', found {method!r}")
    t = np.arange(n) / rate
    dev = _chirp(t, f0, t[-1], f1, method=method)
    u = _place(dev, operating_point, lo, hi, amplitude)
    return Excitation("chirp", t, u, float(dt), float(operating_point), (lo, hi), unit,
                      {"f0_hz": f0, "f1_hz": f1, "method": method})


def steps(levels: Sequence[float], durations: Sequence[float] | float, *, dt: float,
          limits: tuple[float, float] | None = None, operating_point: float | None = None,
          unit: str = "1") -> Excitation:
    """Piecewise-constant input: hold ``levels[i]`` for ``durations[i]`` s (absolute values, in
    ``unit``). Every level must lie within ``limits`` (default: the levels' own range)."""
    levels = [float(v) for v in levels]
    if not levels:
        raise DataError("steps needs at least one level")
    durs = ([float(durations)] * len(levels) if np.isscalar(durations)
            else [float(d) for d in durations])
    if len(durs) != len(levels):
        raise DataError(f"steps: {len(levels)} levels but {len(durs)} durations")
    lo, hi = (limits if limits is not None else (min(levels), max(levels)
                                                 if max(levels) > min(levels) else min(levels) + 1))
    op = levels[0] if operating_point is None else float(operating_point)
    rate = _check_common(sum(durs), dt, op, (lo, hi))[3]
    for v in levels:
        if not lo <= v <= hi:
            raise DataError(f"step level {v:g} lies outside the limits [{lo:g}, {hi:g}]")
    u = np.concatenate([np.full(int(round(d * rate)), v) for v, d in zip(levels, durs)])
    t = np.arange(u.size) / rate
    return Excitation("steps", t, u, float(dt), op, (float(lo), float(hi)), unit,
                      {"levels": levels, "durations_s": durs})

