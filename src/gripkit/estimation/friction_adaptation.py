"""Online adaptation of a friction model while the drive runs: recursive least squares with
exponential forgetting on a scale and an offset of the friction table.

Friction "differs from finger to finger and the parameters may change over time"
(``002_ddea254371185ad3.txt``, abstract, §6.3, §8). The thesis motivates adaptation but gives no
estimator (its adjustment is a hand-set factor on the lookup tables, §6.3): the recursive least
squares below is gripkit's addition. gripkit adapts, per actuator k, the friction
model

    F_k(v) = s_k · F_table,k(v) + o_k · sign(v)

(a scale of the identified lookup table and a Coulomb-like offset) from the running drive's
signals: the motor torque τ_m, the actuator velocity v and the bias torque h (gravity, Coriolis)
of the multibody model. The actuator's equation J v̇ = τ_m − h − F(v) is low-pass filtered with
H(s) = a/(s + a) on both sides, which removes the need for an acceleration signal
(H[s·v] = a(v − H[v])):

    y = H[τ_m − h] − J·a·(v − H[v]) = s·H[F_table(v)] + o·H[sign(v)] = φᵀθ,
    φ = (H[F_table], H[sign]).

H is discretised exactly for a held input: H[x]ₙ = H[x]ₙ₋₁ + α(xₙ − H[x]ₙ₋₁), α = 1 − e^(−a·T_s);
H[v̇] is the difference of the filtered velocity over one sample.

RLS with forgetting factor λ (per sample of period T_s):

    e = y − φᵀθ,   g = Pφ,   k = g / (λ + φᵀg),   θ ← Π(θ + k·e),   P ← (P − k·gᵀ)/λ,

with Π the projection onto the bounds of s and o in the metric of P⁻¹ (a coordinate clipped to
its bound moves the other by P₀₁/P_cc times the clipping: the most probable value given the
clipped one; plain clipping makes the nearly collinear pair bang between its bounds), and σ̂² ←
λσ̂² + (1 − λ)e²/(1 + φᵀg/λ)
the exponentially weighted variance of the a-priori residuals; the standard deviations are
σ̂·sqrt(diag P).

Guards against the estimator's own failure modes (:func:`friction_rls_step`):

* *No excitation.* The update runs only on samples where the actuator has slid in one direction
  (|v| > ``v_min``) for three filter time constants: at rest friction is a reaction, not a function
  of v. Otherwise θ, P and σ̂² are frozen (status 0), so a finger at rest neither drifts nor
  winds its covariance up.
* *Covariance windup while sliding without excitation.* At a constant speed φ keeps one direction,
  and the division by λ inflates P along the other one without bound. The division is skipped
  when it would lift trace P above ``trace_max`` (default 2·p0, the trace at the start), so
  trace P ≤ max(trace_max, its value before).
* *Velocity reversals.* Coulomb friction and the table jump at v = 0, and the filtered signals
  carry that step for a few time constants; every sign change (and every sample with
  |v| ≤ ``v_min``) restarts the sliding count, so those samples are left out.
* *Bad values.* A non-finite torque, bias or velocity leaves the filters and estimates as they
  are and restarts the sliding count (status −1). :meth:`FrictionAdapter.update` refuses such
  data with a one-line :class:`~gripkit.errors.DataError` unless asked to skip them
  (``nonfinite='skip'``, with a :class:`~gripkit.errors.DataWarning`).

Convergence time. After a change of friction, the weight of data older than k sliding samples is
λᵏ, and the error of the estimate decays like λᵏ; it falls to 5 % after
k = ln 20 / (−ln λ) samples, i.e. t₉₅ = T_s · ln 20 / (−ln λ) ≈ 3·T_s/(1 − λ) of *sliding* time
(:meth:`FrictionAdapter.convergence_time`): 3.0 s for λ = 0.999 at 1 kHz.

The per-sample step :func:`friction_rls_step` is a scalar, allocation-free numba function, so a
simulation kernel can run the estimator inside its control loop (see
:mod:`gripkit.systems.dlr_hit.impedance`); :class:`FrictionAdapter` runs it over logged data.
"""

from __future__ import annotations

import math
import numbers
from collections import namedtuple
from dataclasses import dataclass

import numpy as np

from ..errors import DataError, DataWarning, ModelError, emit_warning
from ..models.friction import FrictionTable, TableArrays, table_arrays, table_friction
from ..multibody.kernels import hot

__all__ = ["FrictionAdapter", "AdaptationResult", "AdaptationSettings", "friction_rls_step",
           "UPDATED", "FROZEN", "SKIPPED"]

#: status of one sample (:func:`friction_rls_step`)
UPDATED = 1.0
FROZEN = 0.0
SKIPPED = -1.0

# layout of the settings vector (AdaptationSettings.vector); module constants are compile-time
# constants for numba
S_LAMBDA = 0
S_ALPHA = 1
S_HOLD = 2
S_DT = 3
S_VMIN = 4
S_TRACE = 5
S_SLO = 6
S_SHI = 7
S_OLO = 8
S_OHI = 9
N_SETTINGS = 10


@dataclass(frozen=True)
class AdaptationSettings:
    """Settings of the friction RLS (see the module docstring).

    Parameters
    ----------
    forgetting
        λ ∈ (0, 1] per sample; memory ≈ T_s/(1 − λ).
    filter_hz
        Corner frequency a/2π of H (Hz); must lie below the Nyquist frequency.
    v_min
        Sliding threshold (rad/s, or m/s for a linear drive): slower samples never update.
    p0
        Initial covariance p0·I (> 0).
    scale_bounds, offset_bounds
        Bounds of s (dimensionless) and o (the table's unit) that the estimates are projected on
        (default s ≥ 0: friction opposes motion; o free).
    trace_max
        Bound of trace P (default 2·p0, the initial trace).
    """

    forgetting: float = 0.999
    filter_hz: float = 10.0
    v_min: float = 0.05
    p0: float = 100.0
    scale_bounds: tuple = (0.0, math.inf)
    offset_bounds: tuple = (-math.inf, math.inf)
    trace_max: float | None = None

    def __post_init__(self):
        for name in ("forgetting", "filter_hz", "v_min", "p0"):
            x = getattr(self, name)
            if not isinstance(x, numbers.Real) or isinstance(x, bool) or not math.isfinite(x):
                raise ModelError(f"{name}: expected a finite number, found {getattr(self, name)!r}")
        if not (0 < self.forgetting <= 1):
            raise ModelError(f"forgetting factor must lie in (0, 1], found {self.forgetting!r}",
                             hint="0.999 remembers about 1000 samples")
        if not (self.filter_hz > 0 and self.v_min >= 0 and self.p0 > 0):
            raise ModelError("filter_hz and p0 must be > 0 and v_min >= 0, found "
                             f"filter_hz={self.filter_hz!r}, "
                             f"p0={self.p0!r}, v_min={self.v_min!r}")
        for name in ("scale_bounds", "offset_bounds"):
            b = getattr(self, name)
            try:
                lo, hi = (float(x) for x in b)
            except (TypeError, ValueError):
                raise ModelError(f"{name}: expected (low, high), found {b!r}") from None
            if math.isnan(lo) or math.isnan(hi) or not lo < hi:
                raise ModelError(f"{name}: expected low < high, found {b!r}")
            object.__setattr__(self, name, (lo, hi))
        lo, hi = self.scale_bounds
        if not lo <= 1.0 <= hi:
            raise ModelError("scale_bounds: must contain the nominal scale 1, found "
                             f"{self.scale_bounds!r}")
        if not self.offset_bounds[0] <= 0.0 <= self.offset_bounds[1]:
            raise ModelError("offset_bounds: must contain the nominal offset 0, found "
                             f"{self.offset_bounds!r}")
        if self.trace_max is not None and not (math.isfinite(self.trace_max)
                                               and self.trace_max > 0):
            raise ModelError(f"trace_max: expected a positive number, found {self.trace_max!r}")

    def vector(self, dt: float) -> np.ndarray:
        """The settings as the kernel reads them, for sample period ``dt`` (s)."""
        if not (isinstance(dt, numbers.Real) and math.isfinite(dt) and dt > 0):
            raise ModelError(f"dt: expected a sample period > 0 s, found {dt!r}")
        if self.filter_hz >= 0.5 / dt:
            raise ModelError(f"filter_hz = {self.filter_hz:g} Hz must lie below the "
                             "Nyquist frequency "
                             f"{0.5 / dt:g} Hz")
        a = 2 * math.pi * self.filter_hz
        c = np.empty(N_SETTINGS)
        c[S_LAMBDA] = self.forgetting
        c[S_ALPHA] = 1.0 - math.exp(-a * dt)  # exact discretisation of a/(s + a)
        c[S_HOLD] = math.ceil(3.0 / (a * dt))  # three filter time constants
        c[S_DT] = dt
        c[S_VMIN] = self.v_min
        c[S_TRACE] = 2.0 * self.p0 if self.trace_max is None else self.trace_max
        c[S_SLO], c[S_SHI] = self.scale_bounds
        c[S_OLO], c[S_OHI] = self.offset_bounds
        return c

    def initial_state(self, m: int, scale: float = 1.0, offset: float = 0.0):
        """Estimator state for m actuators: θ (m, 2), P (m, 2, 2), filters (m, 5), σ̂² (m,)."""
        theta = np.tile([scale, offset], (m, 1)).astype(np.float64)
        P = np.tile(np.eye(2) * self.p0, (m, 1, 1))
        return theta, P, np.zeros((m, 5)), np.zeros(m)


#: the estimator as the kernels take it: ``cfg`` the settings vector
#: (:meth:`AdaptationSettings.vector`), ``inertia`` (m,) apparent inertias, and the state, updated
#: in place: ``theta`` (m, 2) = (s, o), ``P`` (m, 2, 2), ``filt`` (m, 5) = H[τ−h], H[v],
#: H[F_table], H[sign], signed count of samples sliding in the current direction; ``sig2`` (m,)
FrictionEstimator = namedtuple("FrictionEstimator", "cfg inertia theta P filt sig2")


@hot
def friction_rls_step(k, tau, bias, v, tab, est):  # pragma: no cover - compiled
    """One sample of actuator k (see the module docstring): motor torque ``tau``, bias torque
    ``bias``, velocity ``v``; ``tab`` the tables (:data:`~gripkit.models.friction.TableArrays`),
    ``est`` the estimator (:data:`FrictionEstimator`, its state updated in place). Returns
    :data:`UPDATED` (1), :data:`FROZEN` (0: not sliding long enough) or :data:`SKIPPED` (−1:
    non-finite input)."""
    cfg, inertia, theta, P, filt, sig2 = est.cfg, est.inertia, est.theta, est.P, est.filt, est.sig2
    if not (math.isfinite(tau) and math.isfinite(bias) and math.isfinite(v)):
        filt[k, 4] = 0.0  # the filters missed a sample: wait three time constants again
        return -1.0
    al = cfg[S_ALPHA]
    dt = cfg[S_DT]
    vmin = cfg[S_VMIN]
    sg = 1.0 if v > 0.0 else (-1.0 if v < 0.0 else 0.0)
    fr = (table_friction(v, tab.velocity[k], tab.values[k], tab.length[k], tab.ipos[k]) if v != 0.0
          else 0.0)
    filt[k, 0] += al * (tau - bias - filt[k, 0])
    vf_old = filt[k, 1]
    filt[k, 1] += al * (v - filt[k, 1])
    filt[k, 2] += al * (fr - filt[k, 2])
    filt[k, 3] += al * (sg - filt[k, 3])
    # sliding in one direction for `hold` samples: the filtered signals no longer carry the holding
    # torque of a stick phase or the friction step of a reversal
    if abs(v) > vmin and sg * filt[k, 4] >= 0.0:
        filt[k, 4] += sg
    else:
        filt[k, 4] = sg if abs(v) > vmin else 0.0
    if abs(filt[k, 4]) <= cfg[S_HOLD]:
        return 0.0
    lam = cfg[S_LAMBDA]
    # y = H[τ − h] − J·H[v̇], with H[v̇] = d/dt H[v] as a difference of the filter state
    y = filt[k, 0] - inertia[k] * (filt[k, 1] - vf_old) / dt
    f1 = filt[k, 2]
    f2 = filt[k, 3]
    e = y - f1 * theta[k, 0] - f2 * theta[k, 1]
    p00 = P[k, 0, 0]
    p01 = P[k, 0, 1]
    p11 = P[k, 1, 1]
    g0 = p00 * f1 + p01 * f2
    g1 = p01 * f1 + p11 * f2
    fg = f1 * g0 + f2 * g1
    den = lam + fg
    k0 = g0 / den
    k1 = g1 / den
    s = theta[k, 0] + k0 * e
    o = theta[k, 1] + k1 * e
    q00 = p00 - k0 * g0
    q01 = p01 - k0 * g1
    q11 = p11 - k1 * g1
    # projection on the bounds in the metric of P⁻¹: a clipped coordinate moves the other one
    # along the estimate's correlation (s and o are nearly collinear on a flat table)
    sc = min(max(s, cfg[S_SLO]), cfg[S_SHI])
    if sc != s and q00 > 0.0:
        o += q01 / q00 * (sc - s)
        s = sc
    oc = min(max(o, cfg[S_OLO]), cfg[S_OHI])
    if oc != o and q11 > 0.0:
        s = min(max(s + q01 / q11 * (oc - o), cfg[S_SLO]), cfg[S_SHI])
        o = oc
    theta[k, 0] = s
    theta[k, 1] = o
    # forget only while the trace stays bounded (no windup along an unexcited direction)
    div = lam if (q00 + q11) <= lam * cfg[S_TRACE] else 1.0
    P[k, 0, 0] = q00 / div
    P[k, 0, 1] = q01 / div
    P[k, 1, 0] = q01 / div
    P[k, 1, 1] = q11 / div
    sig2[k] = lam * sig2[k] + (1.0 - lam) * e * e / (1.0 + fg / lam)
    return 1.0


@hot
def _rls_run(tau, bias, vel, tab, est, out_theta, out_std, out_status):  # pragma: no cover
    """:func:`friction_rls_step` over N samples of m actuators; the state of ``est``
    (:data:`FrictionEstimator`) continues from a previous call."""
    theta, P, sig2 = est.theta, est.P, est.sig2
    for n in range(tau.shape[0]):
        for k in range(tau.shape[1]):
            out_status[n, k] = friction_rls_step(k, tau[n, k], bias[n, k], vel[n, k], tab, est)
            out_theta[n, k, 0] = theta[k, 0]
            out_theta[n, k, 1] = theta[k, 1]
            s = math.sqrt(max(sig2[k], 0.0))
            out_std[n, k, 0] = s * math.sqrt(max(P[k, 0, 0], 0.0))
            out_std[n, k, 1] = s * math.sqrt(max(P[k, 1, 1], 0.0))


@dataclass(frozen=True)
class AdaptationResult:
    """Estimates over time: ``scale`` and ``offset`` (N, m), their ``std`` (N, m, 2), ``active``
    (N, m) marking the samples that updated (sliding) and ``skipped`` (N, m) those left out for a
    non-finite input."""

    t: np.ndarray
    scale: np.ndarray
    offset: np.ndarray
    std: np.ndarray
    active: np.ndarray
    names: tuple
    skipped: np.ndarray | None = None

    def settling_time(self, k: int, true_scale: float, t_change: float, tol: float = 0.05) -> float:
        """Time after ``t_change`` until the scale of actuator k stays within ``tol`` (relative) of
        ``true_scale`` (inf if it never does)."""
        err = np.abs(self.scale[:, k] - true_scale) / abs(true_scale)
        after = self.t >= t_change
        bad = after & (err > tol)
        if not after.any():
            return math.inf
        if not bad.any():
            return 0.0
        last_bad = np.flatnonzero(bad)[-1]
        if last_bad == self.t.size - 1:
            return math.inf
        return float(self.t[last_bad + 1] - t_change)


class FrictionAdapter:
    """Recursive friction correction for m actuators (see the module docstring).

    Parameters
    ----------
    tables
        The friction tables being corrected (one :class:`FrictionTable` per actuator).
    inertia
        Apparent inertia of each actuator (kg·m²), e.g. the diagonal of M_p.
    dt
        Sample period (s).
    forgetting, filter_hz, v_min, p0
        As :class:`AdaptationSettings` (ignored when ``settings`` is given).
    settings
        An :class:`AdaptationSettings` (bounds, trace bound).
    """

    def __init__(self, tables, inertia, dt: float, *, forgetting: float = 0.999,
                 filter_hz: float = 10.0, v_min: float = 0.05, p0: float = 100.0,
                 names=None, settings: AdaptationSettings | None = None):
        self.tables = tuple(tables)
        if not self.tables or not all(isinstance(t, FrictionTable) for t in self.tables):
            raise ModelError("tables: expected one FrictionTable per actuator")
        m = len(self.tables)
        J = np.asarray(inertia, dtype=np.float64)
        if J.shape != (m,) or not np.isfinite(J).all() or not (J > 0).all():
            raise ModelError(f"inertia: expected {m} positive values, found {inertia!r}")
        self.settings = settings if settings is not None else AdaptationSettings(
            forgetting=forgetting, filter_hz=filter_hz, v_min=v_min, p0=p0)
        if not isinstance(self.settings, AdaptationSettings):
            raise ModelError("settings: expected AdaptationSettings, found "
                             f"{type(settings).__name__}")
        self.cfg = self.settings.vector(dt)
        self.J = J
        self.dt = float(dt)
        self.lam = self.settings.forgetting
        self.v_min = self.settings.v_min
        self.names = tuple(names) if names is not None else tuple(f"a{k}" for k in range(m))
        self._tv, self._tf, self._tn, self._tip = table_arrays(self.tables)
        self.reset()

    @property
    def m(self) -> int:
        return len(self.tables)

    def reset(self, scale: float = 1.0, offset: float = 0.0) -> None:
        """Start again from ``scale``, ``offset`` with covariance p0·I."""
        self.theta, self.P, self.filt, self.sig2 = self.settings.initial_state(
            self.m, scale, offset)
        self.t = 0.0

    def convergence_time(self, tol: float = 0.05) -> float:
        """Sliding time (s) for the estimate error to fall to ``tol`` of a step change:
        dt·ln(1/tol)/(−ln λ)."""
        if self.lam == 1.0:
            return math.inf
        return self.dt * math.log(1.0 / tol) / (-math.log(self.lam))

    def update(self, tau_motor, bias, velocity, *, nonfinite: str = "raise") -> AdaptationResult:
        """Feed samples (N, m) (or one sample (m,)) of motor torque, bias torque and velocity;
        the adapter keeps its state between calls. ``nonfinite='raise'`` (default) refuses NaN/inf
        with a DataError; ``'skip'`` leaves those samples out (estimates held) with a
        DataWarning."""
        if nonfinite not in ("raise", "skip"):
            raise ModelError(f"nonfinite: expected 'raise' or 'skip', found {nonfinite!r}")
        tau = np.atleast_2d(np.asarray(tau_motor, dtype=np.float64))
        h = np.atleast_2d(np.asarray(bias, dtype=np.float64))
        v = np.atleast_2d(np.asarray(velocity, dtype=np.float64))
        m = self.m
        for name, a in (("tau_motor", tau), ("bias", h), ("velocity", v)):
            if a.ndim != 2 or a.shape[1] != m or a.shape[0] != tau.shape[0]:
                raise DataError(f"{name}: expected shape (N, {m}) like tau_motor, found {a.shape}")
            bad = ~np.isfinite(a)
            if bad.any():
                n0, k0 = np.argwhere(bad)[0]
                what = (f"{name}: {int(bad.sum())} non-finite value(s), the first at sample {n0} "
                        f"(t = {self.t + n0 * self.dt:.6g} s) of actuator {self.names[k0]}")
                if nonfinite == "raise":
                    raise DataError(what, hint="drop or interpolate them, or pass "
                                               "nonfinite='skip' to "
                                               "leave those samples out (the estimates hold)")
                emit_warning(DataWarning(f"{what}: left out, the estimates hold over them"))
        N = tau.shape[0]
        th = np.empty((N, m, 2))
        sd = np.empty((N, m, 2))
        status = np.empty((N, m))
        _rls_run(np.ascontiguousarray(tau), np.ascontiguousarray(h), np.ascontiguousarray(v),
                 TableArrays(self._tv, self._tf, self._tn, self._tip),
                 FrictionEstimator(self.cfg, self.J, self.theta, self.P, self.filt, self.sig2),
                 th, sd, status)
        t = self.t + np.arange(N) * self.dt
        self.t = float(t[-1] + self.dt)
        return AdaptationResult(t, th[:, :, 0], th[:, :, 1], sd, status == UPDATED, self.names,
                                status == SKIPPED)

    def corrected_tables(self) -> tuple[FrictionTable, ...]:
        """The tables with the current scale applied (offsets are reported, not tabulated)."""
        return tuple(t.scaled(float(s)) for t, s in zip(self.tables, self.theta[:, 0]))
