"""Second-order step-response identification: static gain, natural frequency and damping ratio,
each with its standard deviation, from a recorded step (or any piecewise-constant input).

Model (``gripkit.models.second_order.SecondOrderSystem``):

    y(t) = y₀ + G(s)·(u − u₀),   G(s) = K ω_n² / (s² + 2ζω_n s + ω_n²),

with u₀ the input at the start of the record (the system is assumed at rest there) and y₀ the
output there. Simulated exactly (zero-order hold at the data's sampling rate), so any lightly
damped mode below the Nyquist frequency is resolved.

Procedure (:func:`identify_step`):

1. Starting values from a least-squares ARX(2, 2) fit with a constant,
   y_k = −a₁y_{k−1} − a₂y_{k−2} + b₁u_{k−1} + b₂u_{k−2} + c: its poles z = e^{sT} give ω_n = |s|
   and ζ = −Re s/|s|, its static gain (b₁ + b₂)/(1 + a₁ + a₂) gives K. When the ARX poles are not
   a stable pair (heavy noise), the step's levels and its 63 % time are used instead.
2. Output-error least squares on (K, ω_n, ζ, y₀) with the grey-box engine
   (:func:`gripkit.sysid.physical.greybox.fit`): Levenberg-Marquardt by default (``method='lm'``:
   ω_n and ζ
   in log space, so they stay positive), or the bounded trust-region reflective method
   (``method='trf'``, CLI ``--method trf``), which keeps every parameter within its bounds.
3. Uncertainty: the asymptotic covariance σ̂²(JᵀJ)⁻¹ of the grey-box engine; σ(f_n) = σ(ω_n)/2π.

As an identified model of the one protocol (:func:`identify_step_model`, what
``identify(data, "step")`` and ``gripkit identify step`` return): a
:class:`~gripkit.sysid.LinearModel` of structure ``'step'`` holding G(s) as a continuous
:class:`gripkit.lti.TransferFunction` with the record's names and units, ``u_offset`` = u₀ and
``y_offset`` = y₀, and the covariance of G's coefficients propagated from that of (K, ω_n, ζ)
(:func:`step_model`).

The result also carries the step metrics the fitted model predicts (overshoot, peak, rise and 2 %
settling times) and :func:`step_metrics` measures them on any response (used for controllers).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from ...arguments import entry_point
from ...errors import AccuracyWarning, DataError, IdentificationError, SimulationError, emit_warning
from ...lti import TransferFunction
from ...models.second_order import SecondOrderSystem, second_order_step
from ...signals.trajectory import Trajectory
from ...units import ratio_unit
from ..linear.linear_model import LinearModel
from ..model_file import plain
from .greybox import GreyboxResult, fit

__all__ = (["StepResponseResult", "identify_step", "identify_step_model", "step_model",
            "step_summary", "step_metrics", "second_order_metrics", "STEP_METHODS"])


@dataclass(frozen=True)
class StepResponseResult:
    """Result of :func:`identify_step`. Frequencies in Hz and rad/s, times in s, ``gain`` in output
    unit per input unit (``gain_unit``). ``covariance``/``correlation`` are over
    (gain, natural_frequency_hz, damping_ratio, offset)."""

    gain: float
    gain_std: float
    natural_frequency_hz: float
    natural_frequency_hz_std: float
    damping_ratio: float
    damping_ratio_std: float
    offset: float
    offset_std: float
    input_offset: float
    gain_unit: str
    covariance: np.ndarray
    correlation: np.ndarray
    fit_percent: float
    residual_std: float
    n_samples: int
    dt: float
    overshoot_percent: float
    peak_time: float
    rise_time: float
    settling_time: float
    y_model: np.ndarray = field(repr=False)
    greybox: GreyboxResult = field(repr=False)

    @property
    def natural_frequency(self) -> float:
        """ω_n in rad/s."""
        return 2 * math.pi * self.natural_frequency_hz

    def transfer_function(self) -> TransferFunction:
        """G(s) = K ω_n²/(s² + 2ζω_n s + ω_n²), a continuous :class:`gripkit.lti.TransferFunction`
        (the result keeps only the gain's unit, not the channels' names and units)."""
        w = self.natural_frequency
        return TransferFunction([self.gain * w * w], [1.0, 2 * self.damping_ratio * w, w * w],
                                meta={"gain_unit": self.gain_unit})

    def to_dict(self) -> dict:
        keys = ("gain", "gain_std", "natural_frequency_hz", "natural_frequency_hz_std",
                "damping_ratio",
                "damping_ratio_std", "offset", "offset_std", "input_offset", "gain_unit",
                "fit_percent",
                "residual_std", "n_samples", "dt", "overshoot_percent", "peak_time", "rise_time",
                "settling_time")
        d = {k: getattr(self, k) for k in keys}
        d["covariance"] = self.covariance.tolist()
        d["correlation"] = self.correlation.tolist()
        d["covariance_order"] = ["gain", "natural_frequency_hz", "damping_ratio", "offset"]
        d["identifiability"] = str(self.greybox.identifiability)
        return d

    def summary(self) -> str:
        return step_summary(self.to_dict())


def step_summary(d: dict) -> str:
    """The text of a step fit from its :meth:`StepResponseResult.to_dict` ``d`` (as a model's
    ``info["step"]`` keeps it: a number that is None is infinite, as the model file writes it)."""
    d = {k: math.inf if v is None else v for k, v in d.items()}
    return (f"second-order step fit ({d['n_samples']} samples every {d['dt']:g} s, fit "
            f"{d['fit_percent']:.2f} %):\n"
            f"  gain K = {d['gain']:.6g} ± {d['gain_std']:.2g} {d['gain_unit']}\n"
            f"  natural frequency f_n = {d['natural_frequency_hz']:.6g} ± "
            f"{d['natural_frequency_hz_std']:.2g} Hz\n"
            f"  damping ratio ζ = {d['damping_ratio']:.5g} ± {d['damping_ratio_std']:.2g}\n"
            f"  predicted step: overshoot {d['overshoot_percent']:.3g} %, peak "
            f"{d['peak_time']:.4g} s, "
            f"rise (10-90 %) {d['rise_time']:.4g} s, settling (2 %) {d['settling_time']:.4g} s")


def _arx_start(u: np.ndarray, y: np.ndarray, dt: float):
    """(K, ω_n, ζ) from an ARX(2, 2) least-squares fit, or None if it gives no stable pair."""
    n = len(y)
    if n < 8:
        return None
    Phi = np.column_stack([-y[1:-1], -y[:-2], u[1:-1], u[:-2], np.ones(n - 2)])
    try:
        th, *_ = np.linalg.lstsq(Phi, y[2:], rcond=None)
    except np.linalg.LinAlgError:
        return None
    a1, a2, b1, b2, _ = th
    z = np.roots([1.0, a1, a2])
    if np.any(np.abs(z) >= 1.0) or np.any(np.abs(z) < 1e-9):
        return None
    s = np.log(z.astype(complex)) / dt
    if np.any(np.abs(s.imag) >= math.pi / dt * 0.999) or np.any(s.real >= 0):
        return None
    wn = float(math.sqrt(abs(s[0] * s[1])))
    zeta = float(-(s[0] + s[1]).real / (2 * wn))
    den = 1.0 + a1 + a2
    if not (wn > 0 and zeta > 0 and abs(den) > 1e-12):
        return None
    return float((b1 + b2) / den), wn, zeta


def _level_start(t: np.ndarray, u: np.ndarray, y: np.ndarray):
    """(K, ω_n, ζ) from the levels of the largest input change and the 63 % time after it."""
    du = np.diff(u)
    k = int(np.argmax(np.abs(du))) + 1
    stop = k + 1 + int(np.argmax(np.abs(du[k:]) > 0)) if np.any(np.abs(du[k:]) > 0) else len(u)
    stop = min(max(stop, k + 2), len(u))
    y_before = y[max(0, k - 10):k].mean() if k > 0 else y[0]
    tail = y[k + max(1, (stop - k) * 3 // 4):stop]
    y_after = tail.mean() if tail.size else y[stop - 1]
    K = (y_after - y_before) / du[k - 1]
    seg = ((y[k:stop] - y_before) / (y_after - y_before) if y_after != y_before
           else np.zeros(stop - k))
    i63 = int(np.argmax(seg >= 0.63)) if np.any(seg >= 0.63) else max(1, (stop - k) // 4)
    t63 = max(t[min(k + i63, len(t) - 1)] - t[k], t[1] - t[0])
    return float(K), 1.5 / t63, 0.7


def second_order_metrics(wn: float, zeta: float, band: float = 0.02) -> dict:
    """Overshoot (%), peak time, 10-90 % rise time and settling time (±``band``) of the unit step
    of ω_n²/(s² + 2ζω_n s + ω_n²), evaluated on the closed form."""
    T = (12.0 + 4.0 / max(zeta, 1e-3)) / wn if zeta < 1 else 12.0 * (zeta + 1.0) ** 2 / wn
    t = np.linspace(0.0, T, 20001)
    r = second_order_step(t, 1.0, wn, zeta)
    m = step_metrics(t, r, t_step=0.0, y_initial=0.0, y_final=1.0, band=band)
    if zeta >= 1.0:
        m["peak_time"] = math.inf  # monotonic: no peak
    return m


def step_metrics(t, y, *, t_step: float | None = None, y_initial: float | None = None,
                 y_final: float | None = None, band: float = 0.02) -> dict:
    """Step-response metrics of a measured or simulated response.

    ``y_initial`` defaults to the mean before ``t_step`` (or y[0]); ``y_final`` to the mean of the
    last 10 % of the record (pass the command for tracking metrics); an :class:`AccuracyWarning`
    says when that estimate cannot be trusted because the response has not settled by the end of
    the record (:func:`_unsettled`). Returns ``overshoot_percent``
    (beyond ``y_final``, relative to the step amplitude), ``undershoot_percent`` (the largest
    excursion against the step's direction, as a non-minimum-phase zero causes), ``peak`` and
    ``peak_time``, ``rise_time`` (10 → 90 %), ``settling_time`` (last time outside
    ±``band``·|amplitude| around ``y_final``; inf when the record ends outside),
    ``steady_state_error_percent`` (|y(end) − y_final| relative to the amplitude), ``y_initial`` and
    ``y_final``; all times measured from ``t_step`` (default t[0]).
    """
    t = np.asarray(t, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    if t.shape != y.shape or t.ndim != 1 or t.size < 3:
        raise DataError("step_metrics: expected two 1-D arrays of equal length ≥ 3, found shapes "
                        f"{t.shape}, {y.shape}")
    if not (np.isfinite(t).all() and np.isfinite(y).all()):
        raise DataError("step_metrics: t or y contains NaN or inf")
    t0 = float(t[0]) if t_step is None else float(t_step)
    after = t >= t0
    if after.sum() < 2:
        raise DataError(f"step_metrics: no samples after t_step = {t0:g} s (record ends "
                        f"at {t[-1]:g} s)")
    if y_initial is None:
        before = ~after
        y_initial = float(y[before].mean()) if before.any() else float(y[0])
    estimated = y_final is None
    if estimated:
        y_final = float(y[-max(2, y.size // 10):].mean())
    amp = y_final - y_initial
    if amp == 0 or not math.isfinite(amp):
        raise DataError("step_metrics: the response has no step (final level equals initial level)")
    if estimated:
        _unsettled(t, y[after], amp, band)
    ta, ya = t[after], y[after]
    norm = (ya - y_initial) / amp
    ip = int(np.argmax(norm))
    overshoot = max(0.0, (norm[ip] - 1.0) * 100.0)
    i10 = np.flatnonzero(norm >= 0.1)
    i90 = np.flatnonzero(norm >= 0.9)
    rise = float(ta[i90[0]] - ta[i10[0]]) if i10.size and i90.size else math.inf
    outside = np.flatnonzero(np.abs(ya - y_final) > band * abs(amp))
    if outside.size == 0:
        settling = 0.0
    elif outside[-1] == ya.size - 1:
        settling = math.inf
    else:
        settling = float(ta[outside[-1] + 1] - t0)
    return dict(overshoot_percent=float(overshoot),
                undershoot_percent=max(0.0, float(-norm.min()) * 100.0),
                peak=float(ya[ip]), peak_time=float(ta[ip] - t0), rise_time=rise,
                settling_time=settling,
                steady_state_error_percent=float(abs(ya[-1] - y_final) / abs(amp) * 100.0),
                y_initial=float(y_initial), y_final=float(y_final))


def _unsettled(t: np.ndarray, ya: np.ndarray, amp: float, band: float) -> None:
    """Warn when the final level (mean of the last 10 %) is not a final level: the means of the
    four 5 % pieces of the last 20 % of the response differ by more than ``band``·|step| (a drift
    or an oscillation going on; measurement noise averages out within each piece)."""
    w = ya.size // 20
    if w < 2:
        return
    means = ya[-4 * w:].reshape(4, w).mean(axis=1)
    drift = float(np.ptp(means)) / abs(amp)
    if drift > band:
        emit_warning(
           f"step_metrics: the response has not settled by the end of the record (t = "
           f"{t[-1]:.4g} s): over its last 20 % its level still moves by {100 * drift:.3g} % of "
           f"the step (more than the {100 * band:g} % band); the final level taken from it, and "
           f"the overshoot, settling time and error measured against that level, are not "
           f"reliable: the record is too short; record until the response settles, or pass "
           f"y_final",
           AccuracyWarning)


#: Fewest samples after the first input change that :func:`identify_step` fits (half its minimum
#: record): fewer cannot show a response, let alone four parameters of one.
_MIN_AFTER_STEP = 10

#: least-squares methods of :func:`identify_step`
STEP_METHODS = ("lm", "trf")


def _step_signals(data: Trajectory, input: str, output: str):
    """The input and output of :func:`identify_step`, checked: the input steps (with at least
    :data:`_MIN_AFTER_STEP` samples after its first change) and the output responds. Returns
    ``(u, y, ptp(u), ptp(y))``."""
    u = np.asarray(data[input], dtype=np.float64)
    y = np.asarray(data[output], dtype=np.float64)
    if np.ptp(u) == 0:
        raise DataError(f"input column {input!r} is constant ({u[0]:g}): a step response needs a "
                        f"step in the input",
                        hint="choose the column that holds the commanded step")
    first = int(np.argmax(u != u[0]))  # the first sample after the input left its first value
    if u.size - first < _MIN_AFTER_STEP:
        raise DataError(
            f"input column {input!r} changes only at t = {data.t[first]:.6g} s, {u.size - first} "
            f"sample(s) before the end of the record: the response to the step is not recorded "
            f"(at least {_MIN_AFTER_STEP} samples after the step are needed)",
            hint="record longer after the step, or check that the column holds the commanded step")
    u_scale = np.ptp(u)
    y_scale = np.ptp(y)
    if y_scale == 0 or y_scale <= 1e-12 * np.max(np.abs(y)):  # relative: data at any scale
        raise DataError(f"output column {output!r} does not change: nothing to identify",
                        hint="check the column, or whether the system was powered")
    return u, y, u_scale, y_scale


@entry_point
def identify_step(data: Trajectory, *, input: str, output: str, multistart: int = 0,
                  method: str = "lm",
                  progress: bool = False) -> StepResponseResult:
    """Identify K, ω_n, ζ (and the output offset) of a second-order response (module docstring).

    Parameters
    ----------
    data
        Uniformly sampled record holding ``input`` and ``output``; the system must be at rest at
        the start (the input's first value is the operating point u₀).
    input, output
        Column names.
    multistart
        Extra random starts of the least-squares search.
    method
        ``'lm'`` (Levenberg-Marquardt, default) or ``'trf'`` (trust-region reflective, bounded).

    Raises
    ------
    DataError
        Missing columns, non-uniform sampling, fewer than 20 samples, a constant input (no step) or
        an output that does not respond.
    IdentificationError
        A fitted natural frequency above the Nyquist frequency, or a fit that fails.
    """
    if not isinstance(data, Trajectory):
        raise DataError(f"data: expected a Trajectory, found {type(data).__name__}")
    if method not in STEP_METHODS:
        raise DataError(f"method: expected one of {', '.join(STEP_METHODS)}, found {method!r}",
                        hint="'lm' (Levenberg-Marquardt) or 'trf' (bounded trust-region; "
                             "CLI: --method trf)")
    dt = data.require_uniform(why="step-response identification")
    nyquist_w = math.pi / dt  # rad/s
    data.require_samples(20, "step-response identification")
    u, y, u_scale, y_scale = _step_signals(data, input, output)
    # fit in normalised units, u_n = (u − u₀)/Δu and y_n = (y − y₀,ref)/Δy, so that every
    # parameter is of order one whatever the physical units; mapped back below
    u0, y_ref = float(u[0]), float(y[0])
    un, yn = (u - u0) / u_scale, (y - y_ref) / y_scale
    start = _arx_start(un, yn, dt)
    if start is None or not (0 < start[1] < nyquist_w):
        start = _level_start(data.t, un, yn)
    K0, wn0, z0 = start
    wn0 = min(wn0, 0.9 * nyquist_w)
    z0 = min(max(z0, 1e-3), 5.0)
    model = (SecondOrderSystem(gain=K0, wn=wn0, zeta=z0, y0=0.0, u0=0.0, input_name="u",
                               output_name="y"))
    sub = Trajectory(data.t, {"u": un, "y": yn}, meta=data.meta)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AccuracyWarning)  # re-issued below with the step's names
        try:
            res = fit(model, sub, outputs=["y"], free=["gain", "wn", "zeta", "y0"], method=method,
                      multistart=multistart, progress=progress, output_scale=[1.0])
        except IdentificationError as exc:
            if method == "lm" and "method='trf'" in str(exc):
                raise IdentificationError(exc.message,
                                          hint="use method='trf' (CLI: --method trf) to keep the "
                                               "parameters within their bounds") from None
            raise
        except SimulationError:
            raise IdentificationError(
                f"the response of {output!r} to {input!r} is not a second-order "
                "response resolved at "
                f"dt = {dt:g} s: the fit diverged", hint="check the columns, or record at a "
                                                         "higher sampling rate") from None
    Kn, wn, zeta, y0n = (res.value(n) for n in ("gain", "wn", "zeta", "y0"))
    if wn >= nyquist_w:
        raise IdentificationError(
            f"the fitted natural frequency {wn / (2 * math.pi):.4g} Hz is above the "
            "Nyquist frequency "
            f"{0.5 / dt:.4g} Hz of the data", hint="record at a higher sampling rate")
    if not res.identifiability.ok:
        emit_warning(f"step-response fit of {output!r}: {res.identifiability}", AccuracyWarning)
    K = Kn * y_scale / u_scale
    y0 = y_ref + y0n * y_scale
    jd = np.array([y_scale / u_scale, 1.0 / (2 * math.pi), 1.0, y_scale])
    # variances of data at 1e300 do not fit in float64
    with np.errstate(over="ignore", under="ignore"):
        cov = res.covariance * jd[:, None] * jd[None, :]
    std_n = np.sqrt(np.clip(np.diag(res.covariance), 0, None))  # σ and correlation without squaring
    std = np.where(np.isfinite(res.std), std_n * jd, np.inf)  # the scales: finite at any data scale
    d = np.where(std_n > 0, std_n, 1.0)
    corr = res.covariance / np.outer(d, d)
    m = second_order_metrics(wn, zeta)
    if m["settling_time"] > data.duration:
        emit_warning(f"step-response fit of {output!r}: the fitted response settles in "
                     f"{m['settling_time']:.3g} s, longer than the {data.duration:.3g} s "
                     "record; the gain "
                     f"is extrapolated", AccuracyWarning)

    gunit = ratio_unit(data.unit(output), data.unit(input))
    return StepResponseResult(
        gain=K, gain_std=float(std[0]), natural_frequency_hz=wn / (2 * math.pi),
        natural_frequency_hz_std=float(std[1]), damping_ratio=zeta, damping_ratio_std=float(std[2]),
        offset=y0, offset_std=float(std[3]), input_offset=float(u[0]), gain_unit=gunit,
        covariance=cov, correlation=corr, fit_percent=float(res.fit_percent[0]),
        residual_std=float(res.residual_std[0]), n_samples=int(data.n), dt=float(dt),
        overshoot_percent=m["overshoot_percent"], peak_time=m["peak_time"],
        rise_time=m["rise_time"],
        settling_time=m["settling_time"], y_model=y_ref + res.y_model[:, 0] * y_scale, greybox=res)


#: the names of G's coefficients in the model's covariance, as tfest names them (den[0] = 1 fixed)
STEP_COEFFICIENTS = ("den[1]", "den[2]", "num[2]")


def step_model(res: StepResponseResult, *, input: str, output: str, input_unit: str | None,
               output_unit: str | None) -> LinearModel:
    """The :class:`~gripkit.sysid.LinearModel` (structure ``'step'``) of the step fit ``res`` of
    column ``output`` driven by column ``input`` (in ``input_unit``, ``output_unit``):

    * ``system``: G(s) = K ω_n² / (s² + 2ζω_n s + ω_n²), a continuous
      :class:`~gripkit.lti.TransferFunction` carrying the names and units;
    * ``u_offset`` = u₀ (the input at the record's start), ``y_offset`` = y₀ (the fitted output
      offset): the model's free run from rest on the record is the step fit's ``y_model``;
    * the covariance of G's free coefficients θ = (2ζω_n, ω_n², K ω_n²), named ``den[1]``,
      ``den[2]``, ``num[2]`` as :func:`gripkit.sysid.linear.tfest` names them, is J Σ Jᵀ with Σ
      the covariance of (K, ω_n, ζ) (``res.covariance`` over (K, f_n, ζ, y₀), f_n scaled by 2π)
      and J = ∂θ/∂(K, ω_n, ζ) = [[0, 2ζ, 2ω_n], [0, 2ω_n, 0], [ω_n², 2Kω_n, 0]] (first-order
      propagation);
    * ``info["step"]``: ``res.to_dict()`` (K, f_n, ζ, y₀ with σ, the step metrics, the fit from
      rest; non-finite numbers as None, as the model file writes them), and, as tfest's info,
      ``natural_frequency_hz``, ``damping_ratio`` with their ``_std`` (one mode) and
      ``num_std``/``den_std``;
    * ``fit_percent``: left to the caller (:func:`identify_step_model` sets the validation fit on
      the record, ``model.compare(data)``).
    """
    K, w, z = res.gain, res.natural_frequency, res.damping_ratio
    to_w = np.diag([1.0, 2 * math.pi, 1.0])  # (K, f_n, ζ) → (K, ω_n, ζ)
    sigma = to_w @ np.asarray(res.covariance)[:3, :3] @ to_w
    J = np.array([[0.0, 2 * z, 2 * w], [0.0, 2 * w, 0.0], [w * w, 2 * K * w, 0.0]])
    cov = J @ sigma @ J.T
    cov = 0.5 * (cov + cov.T)
    g = TransferFunction([0.0, 0.0, K * w * w], [1.0, 2 * z * w, w * w], inputs=[input],
                         outputs=[output], input_units=[input_unit], output_units=[output_unit])
    g = g.with_covariance(cov, list(STEP_COEFFICIENTS))
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    info = {"step": plain(res.to_dict()),
            "natural_frequency_hz": [res.natural_frequency_hz],
            "natural_frequency_hz_std": [res.natural_frequency_hz_std],
            "damping_ratio": [z], "damping_ratio_std": [res.damping_ratio_std],
            "num_std": [0.0, 0.0, float(sd[2])], "den_std": [0.0, float(sd[0]), float(sd[1])]}
    return LinearModel(g, "step", u_offset=(res.input_offset,), y_offset=(res.offset,),
                       n_samples=res.n_samples, info=info)


def identify_step_model(data: Trajectory, *, input: str, output: str, solver: str = "lm",
                        multistart: int = 0, progress: bool = False) -> LinearModel:
    """:func:`identify_step` as an identified model of the one protocol (:func:`step_model`),
    what ``identify(data, "step", inputs=…, outputs=…, solver=…)`` returns: ``solver`` is
    identify_step's ``method`` (``'lm'`` or ``'trf'``; identify's own ``method`` is ``'step'``).
    The model's ``fit_percent`` is the validation fit on ``data`` (``model.compare(data)``: the
    free run from the initial state estimated by least squares, which for a record at rest is
    close to, and never below, the fit from rest in ``info["step"]["fit_percent"]``)."""
    if solver not in STEP_METHODS:
        raise DataError(f"solver: expected one of {', '.join(STEP_METHODS)}, found {solver!r}",
                        hint="'lm' (Levenberg-Marquardt) or 'trf' (bounded trust-region; "
                             "CLI: --method trf)")
    res = identify_step(data, input=input, output=output, multistart=multistart, method=solver,
                        progress=progress)
    model = step_model(res, input=input, output=output, input_unit=data.unit(input),
                       output_unit=data.unit(output))
    return model.replace(fit_percent=model.compare(data).fit_percent)
