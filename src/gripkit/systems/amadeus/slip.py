"""Slip detection from the PVDF fingertip film (``000_8f66dcc7ab06470c.txt`` §IV-B, Figs 12–13).

"The additional energy present in the signal during slipping is clearly shown" (Fig. 13) and "the
slip sensors are being used simply to detect the onset of slippage and thus initiate a reflex
reaction through the finger force control loops" (§IV-B). gripkit's detector:

1. **Band-limited energy.** A causal Butterworth band-pass (default 4th order, 100–800 Hz) keeps the
   stick-slip vibration and rejects what a non-slipping grasp puts on the film: the slow shear and
   compression changes of grip and load (below ~30 Hz after the film's own decay). The short-time
   energy E[n] = mean of the band-passed signal squared over a window W (default 5 ms).
2. **Threshold from a non-slip record.** :meth:`SlipDetector.calibrate` sets θ = ``margin`` × the
   ``quantile`` of E over a record of grasping without slip (pump ripple, electronics noise,
   handling taps), so the false-alarm rate is set by data, not guessed.
3. **Onset with persistence.** Slip is declared when E > θ for ``min_duration`` (default 3 ms,
   which rejects isolated impulses); the *onset* is the first sample of that run and the *alarm*
   the sample where it is declared (the reflex can act only then). Slip ends when E stays below
   ``release`` × θ for ``hold`` seconds.
4. **Spectral features and slip speed** (Figs 12(b), 13(b)). :func:`spectral_features` gives the
   short-time band energy, spectral centroid and dominant frequency. In stick-slip each cycle
   releases the shear stored up to the static friction limit, Δx ≈ 2(μ_s − μ_k) F_n / k_t, so the
   slip speed is v ≈ f_ss · Δx ∝ f_ss · F_n, with f_ss the stick-slip rate (the dominant frequency
   of the film signal, :func:`stick_slip_rate`). :func:`calibrate_speed` fits v against
   f_ss·F_n (or f_ss alone when the normal force is not known) from test-rig runs at known speeds
   (Fig. 12(b)) and returns the map with its uncertainty; :meth:`SlipDetector.detect` reports the
   rate and, when calibrated, a speed indication for every event. It is an *indication*: the
   relation bends at high speeds, where the slip phase takes a growing share of each cycle and the
   contact tends to steady sliding; the calibration's residual std says how good it is.
5. **Reflex.** :class:`SlipReflex` raises the grip-force demand on every slip onset (a ratchet,
   capped at a force limit), for use inside a force-control loop; :class:`SlipStream` runs the
   same detector causally, chunk by chunk, with results identical to the batch :meth:`detect`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba
import numpy as np

from ...arguments import sample_interval
from ...errors import DataError, IdentificationError
from ...signals.filters import butter_sos

__all__ = [
    "SlipDetector",
    "SlipDetection",
    "SlipEvent",
    "SlipStream",
    "SlipReflex",
    "SpeedCalibration",
    "calibrate_speed",
    "stick_slip_rate",
    "spectral_features",
    "SpectralFeatures",
    "false_alarm_rate",
]


@numba.njit(cache=True)
def _band_energy(x, sos, zi, ring, rstate, E):  # pragma: no cover - compiled
    """Causal band energy: cascade of second-order sections (transposed direct form II, as
    scipy.signal.sosfilt; ``zi`` (n_sections, 2) carried), squared, averaged over the ring buffer
    of the last W squares. ``rstate`` = [write position, absolute sample count, running sum]; the
    running sum is recomputed exactly every 1024 absolute samples, so the result does not depend on
    how the record is chunked. Writes E (len(x),)."""
    ns = sos.shape[0]
    W = ring.shape[0]
    pos = int(rstate[0])
    count = int(rstate[1])
    acc = rstate[2]
    for n in range(x.shape[0]):
        v = x[n]
        for j in range(ns):
            y = sos[j, 0] * v + zi[j, 0]
            zi[j, 0] = sos[j, 1] * v - sos[j, 4] * y + zi[j, 1]
            zi[j, 1] = sos[j, 2] * v - sos[j, 5] * y
            v = y
        e2 = v * v
        acc += e2 - ring[pos]
        ring[pos] = e2
        pos += 1
        if pos == W:
            pos = 0
        count += 1
        if count % 1024 == 0:
            acc = 0.0
            for i in range(W):
                acc += ring[i]
        E[n] = acc / W
    rstate[0] = pos
    rstate[1] = count
    rstate[2] = acc


@numba.njit(cache=True)
def _slip_state(E, theta, release, n_on, n_off, st, state, events, max_events):  # pragma: no cover
    """Hysteresis state machine over energies E. ``st`` = [slipping, run_on, run_off, run_start,
    n_offset] carries state between calls (n_offset = absolute index of E[0]). Writes ``state``
    (0/1 per sample) and appends events [onset, alarm, end] (absolute indices, end = -1 while
    open) into ``events``; returns the number of events written."""
    slipping = st[0]
    run_on = st[1]
    run_off = st[2]
    run_start = st[3]
    off = st[4]
    ne = 0
    for i in range(E.shape[0]):
        e = E[i]
        if slipping < 0.5:
            if e > theta:
                if run_on == 0.0:
                    run_start = off + i
                run_on += 1.0
                if run_on >= n_on:
                    slipping = 1.0
                    run_off = 0.0
                    if ne < max_events:
                        events[ne, 0] = run_start
                        events[ne, 1] = off + i
                        events[ne, 2] = -1.0
                    ne += 1
            else:
                run_on = 0.0
        else:
            if e < release * theta:
                run_off += 1.0
                if run_off >= n_off:
                    slipping = 0.0
                    run_on = 0.0
                    if ne < max_events and ne > 0:
                        events[ne - 1, 2] = off + i
                    elif ne == 0 and max_events > 0:
                        events[0, 0] = -2.0  # end of an event opened in an earlier call
                        events[0, 1] = -2.0
                        events[0, 2] = off + i
                        ne = 1
            else:
                run_off = 0.0
        state[i] = slipping
    st[0] = slipping
    st[1] = run_on
    st[2] = run_off
    st[3] = run_start
    st[4] = off + E.shape[0]
    return ne


@dataclass(frozen=True)
class SlipEvent:
    """One detected slip: ``onset`` (s, first sample of the above-threshold run), ``alarm`` (s,
    when the detector declared it), ``end`` (s, or None when still slipping at the end), the
    stick-slip ``rate`` (Hz, dominant frequency over the first ``feature_window`` after onset) and
    a ``speed`` indication (m/s) with its ``speed_std`` when the detector has a speed
    calibration."""

    onset: float
    alarm: float
    end: float | None
    rate: float
    speed: float | None = None
    speed_std: float | None = None


@dataclass(frozen=True)
class SlipDetection:
    """Output of :meth:`SlipDetector.detect`: per-sample ``t`` (s), band ``energy`` (V²),
    ``slipping`` state (bool), the ``threshold`` θ, and the list of ``events``."""

    t: np.ndarray
    energy: np.ndarray
    slipping: np.ndarray
    threshold: float
    events: list[SlipEvent]
    dt: float

    @property
    def onsets(self) -> np.ndarray:
        return np.array([e.onset for e in self.events])

    @property
    def alarms(self) -> np.ndarray:
        return np.array([e.alarm for e in self.events])


@dataclass(frozen=True)
class SpectralFeatures:
    """Short-time features (one row per frame): ``t`` frame centres (s), ``band_energy`` and
    ``total_energy`` (V²), ``centroid`` (Hz, within the band), ``dominant`` (Hz, peak in the band),
    ``band_ratio`` (band / total energy)."""

    t: np.ndarray
    band_energy: np.ndarray
    total_energy: np.ndarray
    centroid: np.ndarray
    dominant: np.ndarray
    band_ratio: np.ndarray
    freqs: np.ndarray
    power: np.ndarray


def _signal(x, what="signal") -> np.ndarray:
    a = np.asarray(x, dtype=np.float64)
    if a.ndim != 1:
        raise DataError(f"{what}: expected a 1-D PVDF record, found shape {a.shape}")
    if a.size == 0:
        raise DataError(f"{what} is empty")
    if not np.isfinite(a).all():
        i = int(np.argmax(~np.isfinite(a)))
        raise DataError(f"{what} has {int((~np.isfinite(a)).sum())} NaN/inf samples "
                        f"(first at sample {i})",
                        hint="interpolate or cut out the bad stretch before slip detection")
    return a


def spectral_features(signal, *, dt: float, frame: float = 0.016, hop: float | None = None,
                      band=(100.0, 800.0)) -> SpectralFeatures:
    """Short-time spectra of a PVDF record (Fig. 13(b)): Hann-windowed frames of ``frame`` s every
    ``hop`` s (default frame/2), vectorised with one rfft."""
    x = _signal(signal)
    rate = 1.0 / sample_interval(dt)
    nf = int(round(frame * rate))
    nh = int(round((hop if hop is not None else frame / 2) * rate))
    if nf < 8 or nh < 1:
        raise DataError(f"frame {frame} s at {rate} Hz gives {nf} samples: need at least 8")
    if x.size < nf:
        raise DataError(f"the record ({x.size} samples) is shorter than one frame ({nf})")
    nfr = 1 + (x.size - nf) // nh
    idx = np.arange(nf)[None, :] + nh * np.arange(nfr)[:, None]
    w = np.hanning(nf)
    X = np.fft.rfft((x[idx] - x[idx].mean(1, keepdims=True)) * w, axis=1)
    P = (X.real ** 2 + X.imag ** 2) / (w @ w) / rate
    f = np.fft.rfftfreq(nf, 1.0 / rate)
    inb = (f >= band[0]) & (f <= band[1])
    df = f[1] - f[0]
    be = P[:, inb].sum(1) * df * 2
    te = P.sum(1) * df * 2
    cen = (P[:, inb] * f[inb]).sum(1) / np.maximum(P[:, inb].sum(1), 1e-300)
    dom = f[inb][np.argmax(P[:, inb], axis=1)]
    t = (nh * np.arange(nfr) + nf / 2) / rate
    return SpectralFeatures(t, be, te, cen, dom, be / np.maximum(te, 1e-300), f, P)


@dataclass(frozen=True)
class SpeedCalibration:
    """Slip speed from the stick-slip rate, ``v = a + b · x`` with x = f_ss · F_n (Hz·N) when
    ``uses_force`` else x = f_ss (Hz), fitted by least squares on test-rig runs at known speeds
    (Fig. 12(b)). ``predict(rate, normal_force)`` returns (speed, std) with the parameter
    uncertainty and the residual scatter; ``valid`` is the calibrated speed range."""

    a: float
    b: float
    covariance: np.ndarray
    residual_std: float
    uses_force: bool
    valid: tuple[float, float]
    speeds: np.ndarray
    features: np.ndarray

    def feature(self, rate, normal_force=None):
        r = np.asarray(rate, dtype=np.float64)
        if self.uses_force:
            if normal_force is None:
                raise DataError("this speed calibration uses the normal force: pass normal_force=")
            return r * np.asarray(normal_force, dtype=np.float64)
        return r

    def predict(self, rate, normal_force=None):
        x = self.feature(rate, normal_force)
        v = self.a + self.b * x
        var = (self.covariance[0, 0] + 2 * self.covariance[0, 1] * x + self.covariance[1, 1] * x * x
               + self.residual_std ** 2)
        if v.ndim == 0:
            return float(v), float(np.sqrt(var))
        return v, np.sqrt(var)


def stick_slip_rate(signal, *, dt: float, band=(20.0, 400.0), frame: float | None = None) -> float:
    """Dominant frequency (Hz) of a PVDF record in ``band``: the peak of the averaged Hann
    spectrum, refined by parabolic interpolation of the log power (resolution ≪ 1/frame)."""
    x = _signal(signal)
    fr = frame if frame is not None else min(0.128, x.size * dt)
    ftr = spectral_features(x, dt=dt, frame=fr, band=band)
    P = ftr.power.mean(0)
    f = ftr.freqs
    inb = np.flatnonzero((f >= band[0]) & (f <= band[1]))
    if inb.size < 3:
        raise DataError(f"the band {band} Hz holds fewer than 3 frequency bins at "
                        "this frame length",
                        hint="use a longer record or a wider band")
    i = inb[np.argmax(P[inb])]
    if i <= 0 or i >= f.size - 1:
        return float(f[i])
    a, b, c = np.log(np.maximum(P[i - 1:i + 2], 1e-300))
    den = a - 2 * b + c
    d = 0.5 * (a - c) / den if den < 0 else 0.0
    return float(f[i] + max(-0.5, min(0.5, d)) * (f[1] - f[0]))


class SlipDetector:
    """Band-limited-energy slip detector with persistence and hysteresis (see the module docstring).

    Parameters
    ----------
    dt
        Sample interval of the PVDF record (s).
    band
        Pass band (Hz) of the detection filter.
    window
        Energy averaging window (s).
    min_duration
        How long the energy must stay above θ to declare slip (s).
    release, hold
        Slip ends when E < release·θ for ``hold`` s.
    threshold
        θ (V²) if known; otherwise call :meth:`calibrate` on a non-slip record.
    feature_window
        Span after onset over which the speed feature is computed (s).
    speed_calibration
        A :class:`SpeedCalibration` for speed indications.
    """

    def __init__(self, *, dt: float, band=(60.0, 800.0), order: int = 4, window: float = 0.005,
                 min_duration: float = 0.002, release: float = 0.5, hold: float = 0.05,
                 threshold: float | None = None, feature_window: float = 0.1,
                 speed_calibration: SpeedCalibration | None = None):
        self.dt = sample_interval(dt)
        rate = 1.0 / self.dt
        self.band = (float(band[0]), float(band[1]))
        self.sos = np.ascontiguousarray(butter_sos(order, self.band, dt=self.dt, btype="bandpass"))
        self.window = int(max(1, round(window * rate)))
        self.n_on = int(max(1, round(min_duration * rate)))
        self.n_off = int(max(1, round(hold * rate)))
        if not 0 < release <= 1:
            raise DataError(f"release: expected a fraction in (0, 1], found {release!r}")
        self.release = float(release)
        self.threshold = None if threshold is None else float(threshold)
        self.feature_window = float(feature_window)
        self.speed_calibration = speed_calibration
        self.calibration_info: dict = {}

    # -- energy ----------------------------------------------------------------------------
    def band_signal(self, signal) -> np.ndarray:
        from scipy import signal as sg

        x = _signal(signal)
        zi = sg.sosfilt_zi(self.sos) * x[0]
        return sg.sosfilt(self.sos, x, zi=zi)[0]

    def energy(self, signal) -> np.ndarray:
        """Causal short-time band energy E[n] (V²): mean of b² over the last ``window`` samples
        (fewer at the very start, as if the record were preceded by silence)."""
        x = _signal(signal)
        zi, ring, rpos = self._initial_filter_state(x[0])
        E = np.empty(x.size)
        _band_energy(x, self.sos, zi, ring, rpos, E)
        return E

    def _initial_filter_state(self, x0: float):
        from scipy import signal as sg

        zi = np.ascontiguousarray(sg.sosfilt_zi(self.sos) * x0)
        return zi, np.zeros(self.window), np.zeros(3)

    def calibrate(self, nonslip_signal, *, quantile: float = 0.9999,
                  margin: float = 2.0) -> "SlipDetector":
        """Set θ = ``margin`` × the ``quantile`` of the band energy of a record without slip."""
        E = self.energy(nonslip_signal)
        skip = min(E.size - 1, 4 * self.window)
        q = float(np.quantile(E[skip:], quantile))
        if not q > 0:
            raise IdentificationError("the non-slip record has no energy in the detection band",
                                      hint="check the band and the sampling rate")
        self.threshold = margin * q
        self.calibration_info = dict(quantile=quantile, margin=margin, energy_quantile=q,
                                     n=int(E.size), duration_s=E.size * self.dt)
        return self

    def _need_threshold(self):
        if self.threshold is None:
            raise DataError("the slip detector has no threshold",
                            hint="call calibrate(nonslip_record) or pass threshold=")

    # -- detection --------------------------------------------------------------------------
    def detect(self, signal, t0: float = 0.0, normal_force=None) -> SlipDetection:
        """Detect slip events in a PVDF record (V) sampled every ``dt`` s; times start at ``t0``.
        ``normal_force`` (N, scalar or per sample) feeds the speed indication when the speed
        calibration uses it."""
        self._need_threshold()
        x = _signal(signal)
        E = self.energy(x)
        state = np.zeros(E.size)
        # an event needs n_on samples up and n_off down
        max_ev = E.size // (self.n_on + self.n_off) + 2
        ev = np.zeros((max_ev, 3))
        st = np.zeros(5)
        ne = (_slip_state(E, self.threshold, self.release, float(self.n_on), float(self.n_off), st,
                          state, ev, max_ev))
        if ne > max_ev:  # cannot happen (see max_ev); kept as a guard against silent truncation
            raise DataError(f"more than {max_ev} slip events in {E.size} samples")
        t = t0 + np.arange(E.size) * self.dt
        fn = (None if normal_force is None else np.broadcast_to(np.asarray(normal_force,
                                                                           dtype=np.float64),
                                                                           x.shape))
        events = [self._event(x, ev[i], t0, fn) for i in range(ne)]
        return SlipDetection(t, E, state > 0.5, self.threshold, events, self.dt)

    def _event(self, x, row, t0, fn) -> SlipEvent:
        on, al, en = int(row[0]), int(row[1]), int(row[2])
        nfw = int(round(self.feature_window / self.dt))
        seg = x[on:on + nfw]
        rate = math.nan
        if seg.size >= 32:
            rate = stick_slip_rate(seg, dt=self.dt, frame=seg.size * self.dt)
        sp = ss = None
        cal = self.speed_calibration
        if cal is not None and np.isfinite(rate) and (fn is not None or not cal.uses_force):
            sp, ss = cal.predict(rate, None if fn is None else float(np.mean(fn[on:on + nfw])))
        return (SlipEvent(t0 + on * self.dt, t0 + al * self.dt,
                          None if en < 0 else t0 + en * self.dt, rate, sp, ss))

    def stream(self) -> "SlipStream":
        """A causal, chunk-by-chunk detector with the same settings (for control loops)."""
        self._need_threshold()
        return SlipStream(self)


class SlipStream:
    """Causal slip detection over successive chunks of a PVDF signal; results equal the batch
    :meth:`SlipDetector.detect` on the concatenated record (tested).

    ``update(chunk)`` returns ``(slipping_now, onsets)``: the state after the chunk and the list of
    alarm times (s) declared inside it."""

    def __init__(self, detector: SlipDetector):
        self.det = detector
        self._zi = None
        self._st = np.zeros(5)
        self.events: list[tuple[float, float, float | None]] = []
        self.slipping = False

    def update(self, chunk) -> tuple[bool, list[float]]:
        x = _signal(chunk, "chunk")
        if self._zi is None:
            self._zi, self._ring, self._rpos = self.det._initial_filter_state(x[0])
        E = np.empty(x.size)
        _band_energy(x, self.det.sos, self._zi, self._ring, self._rpos, E)
        state = np.zeros(E.size)
        ev = np.zeros((max(8, E.size), 3))
        ne = _slip_state(E, self.det.threshold, self.det.release, float(self.det.n_on),
                         float(self.det.n_off),
                         self._st, state, ev, ev.shape[0])
        alarms = []
        dt = self.det.dt
        for i in range(ne):
            on, al, en = ev[i]
            if on == -2.0:  # closes an event from an earlier chunk
                o, a, _ = self.events[-1]
                self.events[-1] = (o, a, en * dt)
                continue
            self.events.append((on * dt, al * dt, None if en < 0 else en * dt))
            alarms.append(al * dt)
        self.slipping = bool(self._st[0] > 0.5)
        return self.slipping, alarms


@dataclass
class SlipReflex:
    """Grip-force reflex: every slip alarm raises the force demand by ``step`` (N) plus
    ``speed_gain`` × the speed indication (N per m/s), and while the slip persists the demand keeps
    rising at ``rate`` (N/s) — a ratchet, never above ``max_force``.

    ``demand(base)`` returns the raised demand; ``on_slip(speed=None)`` registers an alarm and
    ``while_slipping(dt)`` is called every control period during which slip is still detected."""

    step: float = 0.5
    speed_gain: float = 0.0
    rate: float = 0.0
    max_force: float = math.inf
    boost: float = field(default=0.0)
    n_events: int = field(default=0)

    def __post_init__(self):
        if not (self.step >= 0 and self.speed_gain >= 0 and self.rate >= 0 and self.max_force > 0):
            raise DataError("SlipReflex: need step, speed_gain, rate >= 0 and max_force > 0")

    def while_slipping(self, dt: float) -> float:
        self.boost += self.rate * dt
        return self.boost

    def on_slip(self, speed: float | None = None) -> float:
        inc = (self.step + (self.speed_gain * speed if (speed is not None and np.isfinite(speed))
                            else 0.0))
        self.boost += max(inc, 0.0)
        self.n_events += 1
        return self.boost

    def demand(self, base: float) -> float:
        return min(base + self.boost, self.max_force)

    def reset(self):
        self.boost = 0.0
        self.n_events = 0


def calibrate_speed(records, speeds, *, dt: float, normal_forces=None, skip: float = 0.05,
                    band=(20.0, 400.0)) -> SpeedCalibration:
    """Fit slip speed against the stick-slip rate from test-rig records at known speeds
    (Fig. 12(b)).

    ``records``: PVDF signals recorded while sliding (the first ``skip`` s are dropped);
    ``speeds``: the rig speeds (m/s); ``normal_forces``: the rig's normal force per record (N) —
    when given the regressor is f_ss·F_n (stick-slip physics, see the module docstring), otherwise
    f_ss. Needs three or more distinct speeds."""
    sp = np.asarray(speeds, dtype=np.float64).reshape(-1)
    if len(records) != sp.size:
        raise DataError(f"calibrate_speed: {len(records)} records but {sp.size} speeds")
    if np.unique(sp).size < 3:
        raise DataError("calibrate_speed needs records at three or more distinct speeds")
    if normal_forces is not None:
        fn = np.broadcast_to(np.asarray(normal_forces, dtype=np.float64), sp.shape)
        if (fn <= 0).any():
            raise DataError("normal_forces must be positive (N)")
    rates = np.array([stick_slip_rate(_signal(r,
                                              "speed-calibration record")[int(round(skip / dt)):],
                                              dt=dt, band=band)
                      for r in records])
    x = rates * fn if normal_forces is not None else rates
    X = np.column_stack([np.ones_like(x), x])
    if np.linalg.matrix_rank(X) < 2:
        raise IdentificationError("the records all give the same stick-slip rate: speed is "
                                  "not identifiable")
    coef, *_ = np.linalg.lstsq(X, sp, rcond=None)
    res = sp - X @ coef
    dof = max(sp.size - 2, 1)
    s2 = float(res @ res) / dof
    cov = np.linalg.inv(X.T @ X) * s2
    return SpeedCalibration(float(coef[0]), float(coef[1]), cov, math.sqrt(s2),
                            normal_forces is not None,
                            (float(sp.min()), float(sp.max())), sp, x)


def false_alarm_rate(slipping, truth, *, dt: float, frame: float = 0.01) -> dict:
    """False alarms of a detector against ground truth, per frame of ``frame`` s.

    A frame is a false alarm when the detector says "slipping" in any of its samples while the
    truth shows no slip in it. Returns ``rate`` (false-alarm frames / non-slip frames),
    ``n_frames``, ``n_false`` and ``per_minute`` (distinct false alarm runs per minute)."""
    d = np.asarray(slipping, dtype=bool).reshape(-1)
    g = np.asarray(truth, dtype=np.float64).reshape(-1) > 0
    if d.size != g.size:
        raise DataError(f"slipping ({d.size}) and truth ({g.size}) have different lengths")
    nf = int(round(frame / dt))
    m = d.size // nf
    if m == 0:
        raise DataError("the record is shorter than one frame")
    df = d[: m * nf].reshape(m, nf).any(1)
    gf = g[: m * nf].reshape(m, nf).any(1)
    neg = ~gf
    fa = df & neg
    runs = int(np.count_nonzero(np.diff(np.concatenate([[0], fa.astype(np.int8)])) == 1))
    minutes = d.size * dt / 60.0
    return dict(rate=float(fa.sum() / max(neg.sum(), 1)), n_frames=int(neg.sum()),
                n_false=int(fa.sum()),
                per_minute=runs / minutes if minutes > 0 else math.nan)
