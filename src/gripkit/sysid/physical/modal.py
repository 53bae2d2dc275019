"""Natural frequency and damping ratio from a free vibration (``001_0b92a7da96e7aa46.txt`` §IV-B,
Fig. 8: the force sensor released from a 150 µN preload rings at 8.52 kHz with ζ = 0.006,
recorded at 20 kHz).

A free vibration of a lightly damped mode is y(t) = A e^{−σ t} cos(ω_d t + φ) + c with
σ = ζ ω_n and ω_d = ω_n √(1 − ζ²). :func:`free_vibration` estimates (f_n, ζ) five ways:

* **FFT peak**: the record (from the release on, mean removed) zero-padded to ≥ 16× its
  length; the peak bin refined by a parabola through the log-magnitudes of the three bins around
  it. Gives f_d.
* **half-power bandwidth**: the width Δf of the peak at half its power; ζ = Δf/(2 f_d) (the
  spectrum of a decaying exponential is a Lorentzian of half-width σ/2π). Exact when the record
  outlasts the decay; a truncated record widens the peak.
* **Hilbert envelope**: |analytic signal| decays as A e^{−σ t}: a straight-line fit to its log
  (where it stands 5× above the noise, ends excluded) gives σ; the unwrapped phase's slope gives
  ω_d.
* **log decrement**: δ = ln(a_i / a_{i+k})/k over the peaks a_i of the signal upsampled 16× by
  band-limited (polyphase) interpolation — needed because 20 kHz samples an 8.52 kHz ringing only
  2.3 times per period — and ζ = δ/√(4π² + δ²).
* **damped-sine least squares** (the reported result): the five parameters (A, σ, ω_d, φ, c)
  fitted to the samples, started from the estimates above. Its covariance σ̂²(JᵀJ)⁻¹ gives the
  standard deviations of f_n = √(ω_d² + σ²)/2π and ζ = σ/ω_n (delta method). This is the
  estimator to trust: it uses every sample and attains the Cramér-Rao bound for white noise.

The other estimates are reported next to it (``methods``); an :class:`AccuracyWarning` says when
they disagree with the fit by more than their expected scatter.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np
from scipy.optimize import least_squares
from scipy.signal import find_peaks, hilbert, resample_poly

from ...arguments import entry_point, sample_interval
from ...errors import AccuracyWarning, DataError, IdentificationError, emit_warning
from ..scaling import unit_scale

__all__ = ["ModalResult", "free_vibration"]


@dataclass(frozen=True)
class ModalResult:
    """Natural frequency (Hz) and damping ratio with standard deviations, and each method's
    estimate in ``methods`` (``fft_peak``, ``half_power``, ``hilbert``, ``log_decrement``,
    ``damped_sine_fit``)."""

    natural_frequency_hz: float
    damping_ratio: float
    natural_frequency_std_hz: float
    damping_ratio_std: float
    amplitude: float
    offset: float
    start_time: float
    n_samples: int
    dt: float
    residual_std: float
    methods: dict = field(default_factory=dict)

    @property
    def omega_n(self) -> float:
        return 2.0 * math.pi * self.natural_frequency_hz

    def to_dict(self) -> dict:
        return asdict(self)

    def summary(self) -> str:
        lines = [f"free vibration: f_n = {self.natural_frequency_hz:.6g} ± "
                 f"{self.natural_frequency_std_hz:.2g} Hz, "
                 f"ζ = {self.damping_ratio:.5g} ± {self.damping_ratio_std:.2g} "
                 f"({self.n_samples} samples every {self.dt:g} s from t = {self.start_time:.6g} s)"]
        for k, v in self.methods.items():
            lines.append(f"  {k}: " + ", ".join(f"{a} = {b:.6g}" for a, b in v.items()
                                                if isinstance(b, float)))
        return "\n".join(lines)


def _start_index(y: np.ndarray) -> int:
    """The release: first sample whose step exceeds 20 % of the largest step."""
    d = np.abs(np.diff(y))
    if d.max() == 0:
        raise DataError("the signal is constant: no free vibration to analyse")
    return max(int(np.argmax(d > 0.2 * d.max())), 0)


def _fft_peak(x: np.ndarray, rate: float) -> tuple[float, np.ndarray, np.ndarray, int]:
    n = x.size
    nfft = 1 << int(math.ceil(math.log2(16 * n)))
    X = np.abs(np.fft.rfft(x, nfft))
    f = np.fft.rfftfreq(nfft, 1.0 / rate)
    lo = max(int(np.ceil(2.0 * rate / n * nfft / rate)), 1)  # ignore the lowest 2 natural bins (DC)
    k = lo + int(np.argmax(X[lo:-1]))
    la, lb, lc = np.log(X[k - 1:k + 2] + 1e-300)
    den = la - 2 * lb + lc
    delta = 0.5 * (la - lc) / den if den != 0 else 0.0
    return float(f[k] + delta * (f[1] - f[0])), f, X, k


def _half_power(f: np.ndarray, X: np.ndarray, k: int) -> float:
    P = X**2
    half = P[k] / 2.0
    i = k
    while i > 0 and P[i] > half:
        i -= 1
    j = k
    while j < P.size - 1 and P[j] > half:
        j += 1
    if i == 0 or j == P.size - 1:
        return math.nan
    fl = f[i] + (half - P[i]) / (P[i + 1] - P[i]) * (f[i + 1] - f[i])
    fr = f[j - 1] + (half - P[j - 1]) / (P[j] - P[j - 1]) * (f[j] - f[j - 1])
    return float(fr - fl)


def _checked_signal(y, dt: float) -> np.ndarray:
    """``y`` as a flat float64 array, refused for a non-positive ``dt``, NaN/inf values or fewer
    than 64 samples."""
    y = np.asarray(y, dtype=np.float64).ravel()
    sample_interval(dt)
    if not np.isfinite(y).all():
        bad = int(np.argmax(~np.isfinite(y)))
        raise DataError(f"the signal has {int((~np.isfinite(y)).sum())} NaN/inf values (first "
                        f"at sample {bad})",
                        hint="drop or interpolate them (CLI: --fill)")
    if y.size < 64:
        raise DataError(f"free-vibration analysis needs at least 64 samples, found {y.size}")
    return y


def _release_segment(y: np.ndarray, start: int | None, end: int | None) -> tuple[int, np.ndarray]:
    """The first sample analysed (default: the release, :func:`_start_index`) and the samples from
    there to ``end``; at least 64 of them."""
    i0 = _start_index(y) if start is None else int(start)
    i1 = y.size if end is None else int(end)
    seg = y[i0:i1]
    if seg.size < 64:
        raise DataError(f"only {seg.size} samples after the release (sample {i0}); "
                        "need at least 64",
                        hint="record longer, or pass start=")
    return i0, seg


def _spectral_peak(x: np.ndarray, rate: float):
    """:func:`_fft_peak` (f_d, frequencies, magnitudes, peak bin), refused when the peak stands
    less than 10× above the median of the spectrum or lies at the Nyquist frequency."""
    f_fft, f, X, k = _fft_peak(x, rate)
    floor = float(np.median(X))
    if X[k] < 10.0 * floor:
        raise DataError("no oscillation stands out of the noise: the spectral peak at "
                        f"{f_fft:.6g} Hz is only "
                        f"{X[k] / floor:.3g}× the median of the spectrum",
                        hint="check the signal column and that the record holds a free vibration")
    if f_fft > 0.98 * rate / 2:
        raise DataError(f"the peak at {f_fft:.6g} Hz lies at the Nyquist frequency {rate / 2:g} "
                        "Hz: the mode is "
                        f"aliased or unresolved", hint="sample faster")
    return f_fft, f, X, k


def _hilbert_estimate(x: np.ndarray, t: np.ndarray, per: int, noise: float) -> dict | None:
    """σ from a straight line through log|analytic signal| and ω_d from its unwrapped phase, over
    the first run of samples where the envelope stands 5× above ``noise`` (two periods ``per`` cut
    at each end); None when fewer than 8 samples qualify."""
    z = hilbert(x)
    env = np.abs(z)
    use = np.flatnonzero(env > max(5.0 * noise, 1e-3 * env.max()))
    use = use[(use >= 2 * per) & (use < x.size - 2 * per)]
    if use.size < 8:
        return None
    lu = use[: np.argmax(np.diff(use) > 1) + 1] if np.any(np.diff(use) > 1) else use
    if lu.size < 8:
        return None
    sl, ic = np.polyfit(t[lu], np.log(env[lu]), 1)
    ph = np.unwrap(np.angle(z[lu]))
    wd = np.polyfit(t[lu], ph, 1)[0]
    sigma_h = -sl
    wn_h = math.hypot(wd, sigma_h)
    return ({"natural_frequency_hz": wn_h / (2 * math.pi), "damping_ratio": sigma_h / wn_h,
             "amplitude": math.exp(ic)})


def _log_decrement_estimate(x: np.ndarray, rate: float, f_d: float, per: int,
                            noise: float) -> dict | None:
    """δ = ln(a_i / a_{i+k})/k from a straight line through the log of the peaks of ``x``
    upsampled 16× (band-limited), those 5× above ``noise`` and three periods from the ends;
    ζ = δ/√(4π² + δ²). None with fewer than 3 such peaks."""
    up = 16
    xu = resample_poly(x, up, 1)
    pk, _ = find_peaks(xu, distance=int(0.6 * up * rate / f_d))
    edge = 3 * up * per
    pk = pk[(pk > edge) & (pk < xu.size - edge)]
    amp = xu[pk]
    good = pk[amp > max(5.0 * noise, 1e-3 * np.max(np.abs(x)))]
    if good.size < 3:
        return None
    cycles = (good - good[0]) / (up * rate / f_d)
    delta = -np.polyfit(cycles, np.log(xu[good]), 1)[0]
    return {"log_decrement": delta, "damping_ratio": delta / math.sqrt(4 * math.pi**2 + delta**2)}


@dataclass(frozen=True)
class _DampedSine:
    """x(t) = A e^{−σ t} cos(ω_d t + φ) + c fitted by least squares; ``covariance`` of
    (A, σ, ω_d, φ, c) = s² (JᵀJ)⁻¹ with s² the residual variance (unit of x)."""

    amplitude: float
    sigma: float
    omega_d: float
    phase: float
    offset: float
    covariance: np.ndarray
    residual_variance: float


def _fit_damped_sine(x: np.ndarray, t: np.ndarray, f_d: float, per: int,
                     zeta0: float) -> _DampedSine:
    """The five-parameter damped-sine least squares (module doc), started from f_d and ζ₀ with the
    amplitude and phase of the linear fit x ≈ e^{−σt}(p cos + q sin) at those (σ, ω_d)."""
    zeta0 = min(max(zeta0, 1e-4), 0.5)
    wd0 = 2 * math.pi * f_d
    sig0 = zeta0 * wd0
    A0 = float(np.max(np.abs(x[:max(per, 1) + 1])))
    E = np.exp(-sig0 * t)
    M = np.column_stack([E * np.cos(wd0 * t), E * np.sin(wd0 * t)])
    pq, *_ = np.linalg.lstsq(M, x, rcond=None)
    A0 = math.hypot(*pq) or A0
    phi0 = math.atan2(-pq[1], pq[0])
    scale = np.array([A0, wd0, wd0, 1.0, A0])

    def resid(p):
        A, s, w, ph, c = p * scale
        return (A * np.exp(-s * t) * np.cos(w * t + ph) + c - x) / A0

    sol = (least_squares(resid, np.array([1.0, sig0 / wd0, 1.0, phi0, 0.0]), method="lm",
                         x_scale="jac"))
    A, s, w, ph, c = sol.x * scale
    if not sol.success or not np.isfinite(sol.x).all():
        raise IdentificationError(f"the damped-sine fit did not converge: {sol.message}")
    if A < 0:
        A, ph = -A, ph + math.pi
    r = sol.fun * A0
    dof = max(r.size - 5, 1)
    s2 = float(r @ r) / dof
    J = sol.jac * A0 / scale[None, :]  # d r / d (A, σ, ω_d, φ, c), r in the unit of y
    try:
        cov = np.linalg.inv(J.T @ J) * s2
    except np.linalg.LinAlgError:
        raise IdentificationError("the damped-sine fit is singular (no decay or no "
                                  "oscillation in the record)") from None
    return _DampedSine(A, s, w, ph, c, cov, s2)


def _natural_frequency_and_damping(fit: _DampedSine) -> tuple[float, float, float, float]:
    """f_n = √(ω_d² + σ²)/2π and ζ = σ/ω_n with their σ by the delta method:
    (f_n, ζ, σ_fn, σ_ζ)."""
    s, w, cov = fit.sigma, fit.omega_d, fit.covariance
    wn = math.hypot(w, s)
    zeta = s / wn
    g_wn = np.array([0.0, s / wn, w / wn, 0.0, 0.0])
    g_z = np.array([0.0, 1.0 / wn - s * s / wn**3, -s * w / wn**3, 0.0, 0.0])
    f_std = math.sqrt(max(g_wn @ cov @ g_wn, 0.0)) / (2 * math.pi)
    z_std = math.sqrt(max(g_z @ cov @ g_z, 0.0))
    return wn / (2 * math.pi), zeta, f_std, z_std


#: The envelope of a free vibration should fall by at least this fraction over the record for ζ to
#: rest on a visible decay; less gets an AccuracyWarning.
_MIN_DECAY = 0.05


def _check_decay(zeta: float, z_std: float, sigma_t: float) -> None:
    """Refuse a record whose envelope does not decay (ζ within 2σ of 0) or grows (ζ below −2σ): a
    forced or self-sustained oscillation, whose damped-sine fit returns ζ ≈ 0 with a σ that looks
    precise, or a growing one (negative damping);
    warn when it decays by less than :data:`_MIN_DECAY` over the record. ``sigma_t``: σ·T, the
    fitted decay rate times the record's duration."""
    kept = math.exp(-sigma_t) if sigma_t > -700 else math.inf
    if zeta < -2 * z_std:  # significantly negative: the envelope grows
        raise IdentificationError(
            f"free vibration: the envelope grows (to {100 * kept:.4g} % of its start): the fitted "
            f"damping ratio ζ = {zeta:.3g} ± {z_std:.2g} is negative, as in a self-excited "
            f"oscillation or an unstable loop, not a free vibration; its damping cannot be "
            f"measured from it",
            hint="analyse the free response after a release or an impulse, with no excitation "
                 "during the record (CLI: --start at the release)")
    if not zeta > 2 * z_std:
        raise IdentificationError(
            f"free vibration: the fitted damping ratio ζ = {zeta:.3g} ± {z_std:.2g} does not "
            f"differ from 0 (the envelope ends at {100 * kept:.4g} % of its start): the record "
            f"does not decay, as a forced or self-sustained oscillation does not; its damping "
            f"cannot be measured from it",
            hint="analyse the free response after a release or an impulse, with no excitation "
                 "during the record (CLI: --start at the release)")
    if 1.0 - kept < _MIN_DECAY:
        emit_warning(f"free vibration: the envelope decays by only {100 * (1 - kept):.3g} % over "
                     f"the record (ζ = {zeta:.3g} ± {z_std:.2g}): check that it is a free "
                     f"vibration (no forcing during the record), or record longer",
                     AccuracyWarning)


def _warn_doubtful(methods: dict, f_fft: float, omega_d: float, fn: float, zeta: float,
                   f_std: float,
                   z_std: float) -> None:
    """AccuracyWarnings (attributed to the caller of :func:`free_vibration`): a
    method's ζ further from the fit's than its expected scatter, an FFT peak away from the fitted
    damped frequency."""
    for name, v in methods.items():
        if name in ("hilbert", "half_power", "log_decrement") and "damping_ratio" in v:
            if abs(v["damping_ratio"] - zeta) > max(0.3 * zeta, 10 * z_std):
                emit_warning(f"free vibration: the {name.replace('_', ' ')} damping ratio "
                             f"{v['damping_ratio']:.4g} "
                             "disagrees with the least-squares fit "
                             f"{zeta:.4g} ± {z_std:.2g}", AccuracyWarning)
    if abs(f_fft - omega_d / (2 * math.pi)) > max(0.01 * fn, 20 * f_std):
        emit_warning(f"free vibration: the FFT peak {f_fft:.6g} Hz disagrees with the fitted "
                     "damped frequency "
                     f"{omega_d / (2 * math.pi):.6g} Hz", AccuracyWarning)


@entry_point
def free_vibration(y, *, dt: float, start: int | None = None, end: int | None = None,
                   noise_std: float | None = None) -> ModalResult:
    """Estimate the natural frequency and damping ratio of a free vibration.

    Parameters
    ----------
    y
        The signal (any unit, e.g. the force sensor's reading), shape (N,), one sample every ``dt``
        s.
    start, end
        Sample range to analyse; ``start`` defaults to the release (the first large step, so a
        record may begin with the preload plateau), ``end`` to the end of the record.
    noise_std
        Measurement noise (same unit as ``y``); default: estimated from the fit residuals.

    Raises
    ------
    DataError
        NaN/inf, fewer than 64 samples after the release, no oscillation standing out of the noise,
        or a frequency at DC or at the Nyquist frequency.
    IdentificationError
        A record that does not decay (ζ within two standard deviations of 0): a forced response.
    """
    y = _checked_signal(y, dt)
    rate = 1.0 / dt
    # work at unit size (an exact power of two: any scale, 1e-300 … 1e300); amplitudes mapped back
    # below
    cy = unit_scale(y)
    y = y * cy
    noise_std = None if noise_std is None else float(noise_std) * cy
    i0, seg = _release_segment(y, start, end)
    t = np.arange(seg.size) / rate
    tail = seg[-max(seg.size // 5, 8):]
    c0 = float(np.median(tail))
    x = seg - c0
    f_fft, f, X, k = _spectral_peak(x, rate)
    methods: dict[str, dict] = {"fft_peak": {"damped_frequency_hz": f_fft}}
    bw = _half_power(f, X, k)
    if math.isfinite(bw):
        methods["half_power"] = {"bandwidth_hz": bw, "damping_ratio": bw / (2.0 * f_fft)}
    noise = float(np.std(tail - np.mean(tail))) if noise_std is None else float(noise_std)
    per = max(int(round(rate / f_fft)), 1)
    for name, estimate in (("hilbert", _hilbert_estimate(x, t, per, noise)),
                           ("log_decrement", _log_decrement_estimate(x, rate, f_fft, per, noise))):
        if estimate is not None:
            methods[name] = estimate
    # damped-sine least squares, started from the best of the above
    zeta0 = methods.get("hilbert",
                        methods.get("log_decrement", methods.get("half_power", {}))
                        ).get("damping_ratio", 0.01)
    sine = _fit_damped_sine(x, t, f_fft, per, zeta0)
    fn, zeta, f_std, z_std = _natural_frequency_and_damping(sine)
    _check_decay(zeta, z_std, sine.sigma * seg.size / rate)
    _warn_doubtful(methods, f_fft, sine.omega_d, fn, zeta, f_std, z_std)
    methods["damped_sine_fit"] = {"natural_frequency_hz": fn, "damping_ratio": zeta,
                                  "natural_frequency_std_hz": f_std, "damping_ratio_std": z_std}
    if "hilbert" in methods:
        methods["hilbert"]["amplitude"] /= cy
    return ModalResult(fn, zeta, f_std, z_std, float(sine.amplitude) / cy,
                       float(sine.offset + c0) / cy,
                       float(i0 / rate), int(seg.size), float(dt),
                       math.sqrt(sine.residual_variance) / cy, methods)
