"""PID tuning on an identified model by Skogestad's SIMC rules.

Reference: S. Skogestad, "Simple analytic rules for model reduction and PID controller tuning",
*Journal of Process Control* 13 (2003) 291–309: the half rule (§3, eqs 8–10) reduces a model to
first or second order plus time delay, and Table 1 gives the settings of the series PID
``c(s) = K_c (τ_I s + 1)/(τ_I s) · (τ_D s + 1)`` with the closed-loop time constant τ_c as the
one tuning knob (default τ_c = θ, "tight control"):

    g = k e^{−θs}/(τ₁s + 1)                 K_c = τ₁/(k (τ_c + θ)),  τ_I = min(τ₁, 4(τ_c + θ))
    g = k e^{−θs}/((τ₁s + 1)(τ₂s + 1))       the same, and τ_D = τ₂
    g = k′ e^{−θs}/s                        K_c = 1/(k′ (τ_c + θ)),  τ_I = 4(τ_c + θ)
    g = k′ e^{−θs}/(s (τ₂s + 1))             the same, and τ_D = τ₂
    g = k e^{−θs}                           k_i = 1/(k (τ_c + θ)): an integral (I) controller

The series settings become :class:`~gripkit.control.PID`'s parallel gains exactly:
``k_p = K_c (1 + τ_D/τ_I)``, ``k_i = K_c/τ_I``, ``k_d = K_c τ_D``. The last line is the first
with τ₁ → 0 (K_c → 0, τ_I = τ₁ → 0, K_c/τ_I = 1/(k (τ_c + θ)) kept): SIMC's integral controller
for a pure time-delay process (stated so by C. Grimholt and S. Skogestad, "Optimal PI-control
and verification of the SIMC tuning rule", IFAC Conference on Advances in PID Control, PID'12,
Brescia, 2012: the SIMC PI rule gives a pure integral controller there); a model with no lag
left after the reduction (a static gain with delay, an FIR model) is tuned so. The PID's
integral ``k_i h/(z − 1)`` acts a sample late, which for an I-controller delays the whole loop:
:func:`reduce_model` adds that sample h to θ besides the hold's h/2 (on b q⁻¹ the rule without
it gives k_i h k = 1, the closed-loop poles z² − z + 1 = 0 on the unit circle; with it
z² − z + 1/3: gain margin 3, phase margin 61.2°, SIMC's π and 61.4°).

**Margins.** SIMC's "gain margin ≈ 3, phase margin ≈ 47°" (τ_c = θ, the paper's §4.3) holds on
the models the rules are exact for: the first-order process with delay (τ₁ ≤ 8θ: L =
e^{−θs}/(2θs), gain margin π and phase margin 61.4°; τ₁ → ∞: 2.96 and 46.9°), the pure delay
(L = e^{−θs}/(2θs): π and 61.4°) and the integrating process with delay (2.96, 46.9°). On any other
model the PID acts on the model itself, not on its reduction, and its margins are whatever that
loop has ((0.2 q⁻¹ + 0.15 q⁻²)/(1 − 1.5 q⁻¹ + 0.56 q⁻²) at h = 0.01 s, whose zero the
reduction cancels by rule R3: 1.83 and 29.1°).
:func:`tune_pid` therefore computes the achieved margins on the model it was given
(:func:`~gripkit.control.robustness` of the discrete model; for a :class:`LowOrderModel`, of
the exact ZOH sample of its continuous plant, :meth:`LowOrderModel.sampled_plant`), records
them in ``pid.design["margins"]`` and warns (AccuracyWarning) when the gain
margin is below :data:`MIN_GAIN_MARGIN` or the phase margin below :data:`MIN_PHASE_MARGIN`
(well below SIMC's): a larger ``tau_c`` is more robust.

Model reduction (:func:`reduce_model`) of a discrete SISO model with sample time h and n_k samples
of input delay: the ZOH model without its delay beyond the first sample is taken to continuous
time (:meth:`gripkit.lti.LinearSystem.d2c`, exact for a ZOH-sampled system), leaving
``k Π_j(T_j s + 1) / Π_i(τ_i s + 1) · e^{−θ₀ s}`` with θ₀ = (n_k − 1) h. Then

* each zero in the right half plane (inverse response, time constant T_inv) adds T_inv to θ
  (the paper's eq 8, rule for negative numerator time constants);
* each zero in the left half plane (T₀ > 0) is cancelled against the closest larger denominator
  time constant τ₀ (the largest when none is larger) by the paper's rules of eq 7 (T1, T1a,
  T1b, R2, R3), with θ the effective delay before the cancellation: T₀/τ₀ (T₀ ≥ τ₀ ≥ θ),
  T₀/θ (T₀ ≥ θ ≥ τ₀), 1 (θ ≥ T₀ ≥ τ₀), T₀/τ₀ (τ₀ ≥ T₀ ≥ 5θ), else
  (τ̃₀/τ₀)/((τ̃₀ − T₀)s + 1) with τ̃₀ = min(τ₀, 5θ);
* the half rule: with the remaining time constants τ₁₀ ≥ τ₂₀ ≥ …, first order:
  τ₁ = τ₁₀ + τ₂₀/2, θ = θ₀ + τ₂₀/2 + Σ_{i≥3} τ_i0 + Σ T_inv; second order: τ₁ = τ₁₀,
  τ₂ = τ₂₀ + τ₃₀/2, θ = θ₀ + τ₃₀/2 + Σ_{i≥4} τ_i0 + Σ T_inv (eqs 9, 10); an integrator (pole at
  z = 1) is kept as 1/s with k′ = lim s g(s) and the half rule applied to the lags after it
  (their time constants exact, their zeros those of the lag part sampled alone: approximate);
* h/2 is added to θ for the sample-and-hold of the digital controller (the paper's §3.1 remark
  on digital implementation).

A pole is the integrator when it lies within 3σ of z = 1 for a model that carries its
covariance (an identified one: its estimate 1 ± σ cannot be told from 1, and the notes say it
was so taken), or within 1e-9 of 1 otherwise. Numerator taps beyond A's order (a pure delay
q⁻ᵏ, or no lag at all once the integrator is taken out) would put poles at z = 0 in the ZOH
realisation, which no continuous pole samples to: they become a delay instead, matching the
taps' first moment (exact for a single tap ``b q⁻ᵏ``: θ₀ = (k − 1) h), the lags' time constants
kept exact.

Oscillatory (complex) or unstable poles, and complex zeros, have no place in these rules: a
ModelError says so, and :class:`LowOrderModel` can be given directly instead (roots within
:data:`REAL_TOL` of the real axis count as real: a repeated real root splits so by rounding).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from scipy.linalg import expm
from scipy.signal import ss2tf, tf2ss

from ..errors import AccuracyWarning, ArgumentError, ModelError, emit_warning
from ..lti import TransferFunction
from .pid import PID
from .robustness import robustness
from .rst import as_plant

__all__ = ["LowOrderModel", "reduce_model", "simc_settings", "tune_pid"]

#: a pole or zero this close to the real axis (relative to max(1, |z|)) counts as real: rounding
#: splits a repeated real root of multiplicity m by about ε^(1/m) (a triple pole of a sampled
#: model by ~1e-4), and the rules take the real part
REAL_TOL = 1e-3
#: a pole of a model that carries a covariance is an integrator when it lies within this many
#: one-sigma of z = 1 (the data do not tell it from one); any pole within INTEGRATOR_TOL of 1 is
INTEGRATOR_SIGMAS = 3.0
INTEGRATOR_TOL = 1e-9
#: the keyword options of tune_pid that go on to PID (the gains and dt come from the design)
PID_OPTIONS = ("u_min", "u_max", "tf", "b", "c", "tt")
#: :func:`tune_pid` warns when the achieved loop has a gain margin below this (SIMC: about 3) …
MIN_GAIN_MARGIN = 2.0
#: … or a phase margin below this many degrees (SIMC: about 47°)
MIN_PHASE_MARGIN = 30.0


class LowOrderModel:
    """``k e^{−θs}/((τ₁s + 1)(τ₂s + 1))`` (τ₂ = 0: first order; τ₁ = τ₂ = 0: the pure delay
    ``k e^{−θs}``, θ > 0), or with ``integrating`` ``k e^{−θs}/(s (τ₂s + 1))`` (k is then k′,
    τ₁ unused), and the sample time ``dt`` (s) the PID will run at.

    ``hold``: whether θ already includes what sampling adds to the loop's delay — the hold's h/2
    and, for the pure delay, the sample the I-controller's integral acts late (:func:`reduce_model`
    returns such a model). By default (False) θ is the continuous plant's own delay and
    :func:`tune_pid` adds them, as for an identified model, so that a hand-made model and the
    reduction of its ZOH sample get the same design."""

    __slots__ = ("k", "tau1", "tau2", "theta", "integrating", "dt", "notes", "hold")

    def __init__(self, k: float, tau1: float, theta: float, tau2: float = 0.0, *, dt: float,
                 integrating: bool = False, notes: tuple = (), hold: bool = False):
        vals = dict(k=k, tau1=tau1, theta=theta, tau2=tau2, dt=dt)
        for name, v in vals.items():
            if not isinstance(v, (int, float, np.floating, np.integer)) or not math.isfinite(v):
                raise ArgumentError(f"LowOrderModel {name}: expected a finite number, found {v!r}")
        if k == 0:
            raise ArgumentError("LowOrderModel k: the gain is zero: the input does not move the "
                                "output")
        pure_delay = tau1 == 0 and tau2 == 0 and theta > 0
        if theta < 0 or tau2 < 0 or (tau1 <= 0 and not integrating and not pure_delay) or dt <= 0:
            raise ArgumentError(f"LowOrderModel: expected tau1 > 0 (or tau1 = tau2 = 0 with "
                                f"theta > 0: a pure delay), tau2 >= 0, theta >= 0 and "
                                f"dt > 0 (s), found tau1={tau1!r}, tau2={tau2!r}, "
                                f"theta={theta!r}, dt={dt!r}")
        self.k, self.tau1, self.tau2, self.theta = float(k), float(tau1), float(tau2), float(theta)
        self.dt, self.integrating, self.notes = float(dt), bool(integrating), tuple(notes)
        self.hold = bool(hold)

    def __repr__(self) -> str:
        kind = "integrating, " if self.integrating else ""
        return (f"LowOrderModel({kind}k={self.k:.6g}, tau1={self.tau1:.6g}, "
                f"tau2={self.tau2:.6g}, theta={self.theta:.6g}, dt={self.dt:g})")

    def to_dict(self) -> dict:
        return dict(k=self.k, tau1=self.tau1, tau2=self.tau2, theta=self.theta,
                    integrating=self.integrating, dt=self.dt, notes=list(self.notes),
                    hold=self.hold)

    @property
    def pure_delay(self) -> bool:
        """``k e^{−θs}``: no lag (SIMC's I-controller)."""
        return self.tau1 == 0 and self.tau2 == 0 and not self.integrating

    def sampling_delay(self) -> float:
        """What sampling adds to θ (s): the hold's h/2, and h for the pure delay's integral."""
        return self.dt / 2.0 + (self.dt if self.pure_delay else 0.0)

    def with_hold(self) -> LowOrderModel:
        """This model with θ including :meth:`sampling_delay` (itself where it already does)."""
        if self.hold:
            return self
        note = (f"θ includes the hold's h/2 = {self.dt / 2:.4g} s"
                + (f" and the integral's sample h = {self.dt:.4g} s (it acts a sample late)"
                   if self.pure_delay else "") + ", added by tune_pid")
        return LowOrderModel(self.k, self.tau1, self.theta + self.sampling_delay(), self.tau2,
                             dt=self.dt, integrating=self.integrating,
                             notes=(*self.notes, note), hold=True)

    def sampled_plant(self) -> TransferFunction:
        """The exact ZOH sample at ``dt`` of the continuous plant (θ less
        :meth:`sampling_delay` where ``hold``): with θ_p = d h + ε (0 ≤ ε < h) and the lags'
        realisation (A, B, C, D), Φ = e^{Ah}, Γ₀ = ∫₀^{h−ε} e^{As} ds B, Γ₁ = e^{A(h−ε)}
        ∫₀^ε e^{As} ds B: x⁺ = Φ x + Γ₀ u[k−d] + Γ₁ u[k−d−1] (Åström & Wittenmark, Computer-
        Controlled Systems, §2.3, a delay that is not a multiple of h)."""
        return _zoh_with_delay(self)


def _cancel_lhp_zero(T0: float, taus: list, theta: float) -> tuple[float, list, str]:
    """Skogestad's eq 7 for (T₀s + 1)/(τ₀s + 1): (gain factor, new time constants, rule)."""
    larger = [t for t in taus if t >= T0]
    tau0 = min(larger) if larger else max(taus)
    rest = list(taus)
    rest.remove(tau0)
    if T0 >= tau0:
        if tau0 >= theta:
            return T0 / tau0, rest, "T1"
        if T0 >= theta:
            return T0 / theta, rest, "T1a"
        return 1.0, rest, "T1b"
    if T0 >= 5 * theta:
        return T0 / tau0, rest, "R2"
    tt = min(tau0, 5 * theta)
    return tt / tau0, rest + [tt - T0], "R3"


def _pole_sigmas(g, zp: np.ndarray) -> np.ndarray:
    """One-sigma of each real pole in ``zp`` from the covariance ``g`` carries (an identified
    model's), NaN where it carries none or the first-order σ is undefined (a repeated pole)."""
    sig = np.full(zp.size, np.nan)
    if getattr(g, "uncertainty", None) is None or zp.size == 0:
        return sig
    with warnings.catch_warnings():  # a repeated pole's σ is inf: unknown here, no warning
        warnings.simplefilter("ignore", AccuracyWarning)
        lam, cov = g.pole_covariance()
    for i, p in enumerate(zp):
        v = cov[int(np.argmin(np.abs(lam - p))), 0, 0]
        sig[i] = math.sqrt(v) if math.isfinite(v) and v >= 0 else np.nan
    return sig


def _integrators(g, zp: np.ndarray) -> tuple[np.ndarray, list]:
    """Which poles are an integrator: within :data:`INTEGRATOR_SIGMAS` σ of z = 1 where the model
    carries σ, within :data:`INTEGRATOR_TOL` of it otherwise (or as well); the notes say which
    were taken so on their σ. A ModelError for any other pole outside (0, 1)."""
    sig = _pole_sigmas(g, zp)
    dist = np.abs(zp - 1.0)
    exact = dist < INTEGRATOR_TOL
    by_sigma = ~exact & np.isfinite(sig) & (dist <= INTEGRATOR_SIGMAS * np.nan_to_num(sig))
    integ = exact | by_sigma
    notes = [f"pole at z = {p:.9g} ± {s:.2g} is within {INTEGRATOR_SIGMAS:g}σ of 1: taken as "
             f"an integrator" for p, s in zip(zp[by_sigma], sig[by_sigma])]
    if int(integ.sum()) > 1:
        raise ModelError("tune_pid: the model has more than one integrator (a pole at z = 1)")
    bad = ~integ & ((zp >= 1.0) | (zp <= 0.0))
    if np.any(bad):
        shown = [f"{p:.6g}" + (f" ± {s:.2g}" if math.isfinite(s) else "")
                 for p, s in zip(zp[bad], sig[bad])]
        raise ModelError(f"tune_pid: the model has poles [{', '.join(shown)}] outside "
                         f"(0, 1) (unstable, or with no continuous-time equivalent)",
                         hint="SIMC needs a stable (or integrating) model with real poles")
    return integ, notes


def _lag_part(A: np.ndarray, taps: np.ndarray, h: float) -> tuple[float, list, np.ndarray,
                                                                   float, list]:
    """The lag part ``q⁻¹ (b₀ + b₁ q⁻¹ + …)/A(q⁻¹)`` (``taps`` = b₀, b₁, …; A's roots real in
    (0, 1)) in continuous time: (DC gain, time constants, zeros in s, extra delay θ₁ in s, notes).

    Taps within A's order: the ZOH realisation has A's poles only and d2c is exact. More taps
    (a pure delay beyond nk, or no lag at all: A = 1) would put poles at z = 0 in the realisation,
    which no continuous pole samples to: the time constants are then A's own (τ = −h/ln p), the
    DC gain B(1)/A(1) is kept, and the taps become a delay matching the first moment: θ₁ = h
    (μ_B − μ₀), μ_B = Σ j b_j/Σ b_j and μ₀ the same of the ZOH sample of the lags alone (0 when
    there are none), so ``b q^{−k}`` is exactly a delay of (k − 1) h."""
    n = A.size - 1
    if taps.size <= n:
        gc = TransferFunction.from_polynomials(A, np.r_[0.0, taps], dt=h).to_ss(
            minimal=False).d2c()  # the state-space route keeps high orders accurate
        return float(gc.dc_gain()[0, 0]), [-1.0 / p.real for p in gc.poles()], gc.zeros(), \
            0.0, []
    if taps.sum() == 0.0:
        raise ModelError("tune_pid: the model's DC gain is zero (its B coefficients sum to 0): "
                         "a step of the input does not move the output")
    taus = [-h / math.log(p) for p in np.roots(A).real] if n else []
    mu = lambda b: float(np.arange(b.size) @ b / b.sum())  # noqa: E731
    mu0 = 0.0
    if taus:
        den = np.array([1.0])
        for t in taus:
            den = np.polymul(den, [t, 1.0])
        mu0 = mu(TransferFunction([1.0], den).c2d(h).num_zinv()[1:])
    theta1 = h * (mu(taps) - mu0)
    notes = [f"{taps.size - 1} numerator tap(s) beyond the first taken as a delay of "
             f"{max(theta1, 0.0):.4g} s (first moment)"] if taps.size > 1 else []
    if theta1 < 0:
        notes.append("a lead of the taps ignored (the delay kept at its lower bound)")
    return float(taps.sum() / A.sum()), taus, np.zeros(0), max(theta1, 0.0), notes


def reduce_model(model, order: int = 1) -> LowOrderModel:
    """First- (``order=1``) or second-order-plus-delay approximation of a discrete SISO model
    (anything :func:`gripkit.control.as_plant` reads) by the half rule (module docstring)."""
    if order not in (1, 2):
        raise ArgumentError(f"order: expected 1 (FOPTD) or 2 (SOPTD), found {order!r}")
    g = as_plant(model)
    h = float(g.dt)
    A, B = g.den_zinv(), g.num_zinv()
    nk = g.relative_degree()
    if nk < 1:
        raise ModelError("tune_pid: the model has direct feedthrough (nk = 0); a sampled plant "
                         "has at least one sample of delay", hint="check the model's nk")
    zp = np.roots(A) if A.size > 1 else np.zeros(0)
    if np.any(np.abs(zp.imag) > REAL_TOL * np.maximum(1.0, np.abs(zp))):
        raise ModelError(f"tune_pid: the model has complex poles {np.round(zp, 6).tolist()} "
                         f"(an oscillatory mode), which the half rule does not reduce",
                         hint="give a LowOrderModel(k, tau1, theta, tau2, dt=...) fitted by hand")
    zp = zp.real
    integ, notes = _integrators(g, zp)
    theta = (nk - 1) * h
    if integ.any():  # 1/s kept apart: k' from the rest, the half rule on the remaining lags
        A = np.atleast_1d(np.real(np.poly(zp[~integ])))
        h_int = h
    else:
        h_int = None
    k, taus, zc, theta1, lag_notes = _lag_part(A, np.trim_zeros(B[nk:], "b"), h)
    theta += theta1
    notes += lag_notes
    taus = sorted(taus, reverse=True)
    if np.any(np.abs(zc.imag) > REAL_TOL * np.maximum(1.0, np.abs(zc))):
        raise ModelError(f"tune_pid: the model has complex zeros {np.round(zc, 6).tolist()}, "
                         f"which the half rule does not reduce",
                         hint="identify a model with fewer B coefficients, or give a "
                              "LowOrderModel directly")
    if h_int is not None:
        k /= h_int  # ZOH of k'/s is k' h/(z − 1): the lags' DC gain B(1)/A(1) is k' h
        notes.append("integrator kept as 1/s")
    t_inv = [1.0 / z.real for z in zc if z.real > 0]
    t_lhp = sorted((-1.0 / z.real for z in zc if z.real < 0), reverse=True)
    if t_inv:
        notes.append(f"{len(t_inv)} inverse-response zero(s) added to the delay")
    theta_eff = theta + sum(t_inv) + h / 2.0
    for T0 in t_lhp:
        if not taus:
            raise ModelError("tune_pid: the model has more zeros than lags to cancel them")
        f, taus, rule = _cancel_lhp_zero(T0, taus, theta_eff)
        k *= f
        taus = sorted(taus, reverse=True)
        notes.append(f"zero T0={T0:.4g} s cancelled (rule {rule})")
    theta += sum(t_inv) + h / 2.0
    if h_int is not None:  # the integrator plays τ1 = ∞: the lags fill τ2 and θ
        first, lags = [], taus
    elif not taus:  # a static gain with delay: τ1 = 0, SIMC's I-controller
        first, lags = [], []
        theta += h  # the I-controller's own sample: its integral k_i h/(z − 1) acts a sample late
        notes.append("no lag left: a pure delay k e^{-θs} (SIMC: an integral controller); θ "
                     "includes one sample for the integral, which acts a sample late")
    else:
        first, lags = [taus[0]], taus[1:]
    n_keep = order - 1  # lags kept beyond the first (or beyond the integrator)
    kept = lags[:n_keep]
    nxt = lags[n_keep:]
    if nxt:
        half = nxt[0] / 2.0
        theta += half + sum(nxt[1:])
        if kept:
            kept[-1] += half
        elif first:
            first[0] += half
    tau1 = first[0] if first else 0.0
    tau2 = kept[0] if kept else 0.0
    return LowOrderModel(k, tau1, theta, tau2, dt=h, integrating=h_int is not None,
                         notes=tuple(notes), hold=True)


def simc_settings(m: LowOrderModel, tau_c: float | None = None) -> dict:
    """Skogestad's Table 1 for ``m``: series K_c, τ_I, τ_D and the parallel k_p, k_i, k_d (a pure
    delay: the I-controller k_i = 1/(k (τ_c + θ)), K_c = τ_I = τ_D = 0, module docstring)."""
    tc = m.theta if tau_c is None else float(tau_c)
    if not (math.isfinite(tc) and tc >= 0 and tc + m.theta > 0):
        raise ArgumentError(f"tau_c: expected a closed-loop time constant >= 0 s (with tau_c + "
                            f"theta > 0), found {tau_c!r}",
                            hint="tau_c = theta is SIMC's 'tight control'; larger is slower "
                                 "and more robust")
    if m.integrating:
        Kc = 1.0 / (m.k * (tc + m.theta))
        ti = 4.0 * (tc + m.theta)
    elif m.tau1 == 0.0:  # the pure delay: τ1 → 0 in the first-order rule, K_c/τ_I kept
        return dict(Kc=0.0, tau_I=0.0, tau_D=0.0, tau_c=tc, kp=0.0,
                    ki=1.0 / (m.k * (tc + m.theta)), kd=0.0)
    else:
        Kc = m.tau1 / (m.k * (tc + m.theta))
        ti = min(m.tau1, 4.0 * (tc + m.theta))
    td = m.tau2
    return dict(Kc=Kc, tau_I=ti, tau_D=td, tau_c=tc, kp=Kc * (1.0 + td / ti), ki=Kc / ti,
                kd=Kc * td)


def tune_pid(model, method: str = "simc", *, tau_c: float | None = None, order: int | None = None,
             **pid_options) -> PID:
    """A :class:`~gripkit.control.PID` for ``model`` by the SIMC rules (module docstring).

    ``model``: an identified discrete SISO model (anything :func:`as_plant` reads) or a
    :class:`LowOrderModel`. ``order``: 1 (PI on the first-order approximation) or 2 (PID on the
    second-order one, the default; a PI where the model has one lag only). ``tau_c``:
    closed-loop time constant in s (default θ). ``pid_options`` go to :class:`PID`: ``u_min``,
    ``u_max`` (output limits), ``tf`` (derivative filter time constant, s), ``b``, ``c``
    (setpoint weights of P and D), ``tt`` (anti-windup tracking time constant, s); any other name
    is an ArgumentError. The PID runs at the model's dt; ``pid.design`` records the reduction and
    settings (its ``model["notes"]`` say, e.g., that a pole within 3σ of 1 was taken as an
    integrator), the ``structure`` ('PID', 'PI', or 'I' on a pure delay) and the achieved
    ``margins`` of the loop on ``model`` itself (``gain_margin``, ``gain_margin_db``,
    ``phase_margin_deg``, their frequencies in rad/s, and ``stable``: the discrete loop's poles
    inside the unit circle; for a :class:`LowOrderModel` the loop with its exact ZOH sample).
    A hand-made :class:`LowOrderModel` (``hold=False``) is the continuous plant: its θ gets the
    hold's h/2 (and a pure delay the integral's sample h) as an identified model's does.
    SIMC's gain margin ≈ 3 and phase margin ≈ 47° hold for the first-order process with delay
    (and the pure delay, the integrating process) it is exact for; on another model, whose
    reduction is approximate, the margins may be lower (module docstring): an AccuracyWarning
    says so when the gain margin is below 2 or the phase margin below 30° (or the loop is
    unstable), with a larger ``tau_c`` as the remedy.
    """
    if method != "simc":
        raise ArgumentError(f"method: expected 'simc' (Skogestad's rules), found {method!r}")
    unknown = sorted(set(pid_options) - set(PID_OPTIONS))
    if unknown:
        raise ArgumentError(f"tune_pid: unknown option(s) {', '.join(unknown)}; the PID options "
                            f"are {', '.join(PID_OPTIONS)}",
                            hint="output limits are u_min=..., u_max=... (not limits=(lo, hi))")
    if isinstance(model, LowOrderModel):
        m = model.with_hold()
    else:
        m = reduce_model(model, 2 if order is None else order)
    s = simc_settings(m, tau_c)
    design = dict(method="SIMC (Skogestad 2003, Table 1), half-rule reduction",
                  model=m.to_dict(), **{k: s[k] for k in ("Kc", "tau_I", "tau_D", "tau_c")},
                  structure="PID" if s["kd"] else ("PI" if s["kp"] else "I"))
    pid = PID(s["kp"], s["ki"], s["kd"], dt=m.dt, design=design, **pid_options)
    pid.design["margins"] = _achieved_margins(model, m, pid)
    _warn_if_margins_low(model, m, pid, s["tau_c"])
    return pid


def _achieved_margins(model, m: LowOrderModel, pid: PID) -> dict:
    """The margins of ``pid`` in the loop with ``model`` (:func:`robustness`, nominal); for a
    :class:`LowOrderModel`, with the exact ZOH sample of its continuous plant
    (:meth:`LowOrderModel.sampled_plant`), so that the hold and the integral's sample are the
    loop's own, as on an identified model."""
    plant = model.sampled_plant() if isinstance(model, LowOrderModel) else model
    r = robustness(plant, pid, n=0)
    return {**r.nominal, "stable": r.stable}


def _zoh_with_delay(m: LowOrderModel) -> TransferFunction:
    """:meth:`LowOrderModel.sampled_plant`."""
    h = m.dt
    theta = max(m.theta - (m.sampling_delay() if m.hold else 0.0), 0.0)
    d = int(math.floor(theta / h + 1e-9))
    eps = theta - d * h
    eps = 0.0 if eps < 1e-9 * h else eps
    den = np.polymul([m.tau2, 1.0], [1.0, 0.0] if m.integrating else [m.tau1, 1.0])
    den = np.trim_zeros(den, "f")
    if den.size == 1:  # no lag: y[k] = k u(kh − θ), the held input d (or d + 1) samples back
        num_z, den_z = np.array([m.k / den[0]]), np.r_[1.0, np.zeros(d + (eps > 0))]
        return TransferFunction(num_z, den_z, dt=h)
    A, B, C, D = tf2ss([m.k], den)

    def integral(t):  # ∫₀ᵗ e^{As} ds B and e^{At}, from one matrix exponential
        n = A.shape[0]
        E = expm(np.block([[A, B], [np.zeros((1, n + 1))]]) * t)
        return E[:n, n:], E[:n, :n]

    G0, Phi0 = integral(h - eps)
    G1, _ = integral(eps)
    Phi = expm(A * h)
    a = np.poly(Phi)
    num0 = ss2tf(Phi, G0, C, np.zeros((1, 1)))[0][0]
    if eps == 0.0:  # (C (zI − Φ)⁻¹ Γ + D) z^{−d}
        num_z, den_z = np.polyadd(num0, D[0, 0] * a), np.r_[a, np.zeros(d)]
    else:  # (z C (zI − Φ)⁻¹ Γ₀ + C (zI − Φ)⁻¹ Γ₁ + D) z^{−d−1}
        num1 = ss2tf(Phi, Phi0 @ G1, C, np.zeros((1, 1)))[0][0]
        num_z = np.polyadd(np.polyadd(np.r_[num0, 0.0], num1), D[0, 0] * a)
        den_z = np.r_[a, np.zeros(d + 1)]
    return TransferFunction(np.trim_zeros(num_z, "f") if np.any(num_z) else num_z, den_z,
                            dt=h)


def _warn_if_margins_low(model, m: LowOrderModel, pid: PID, tau_c: float) -> None:
    """An AccuracyWarning when the achieved loop (``pid.design["margins"]``) is unstable or its
    margins lie well below SIMC's (gain margin < :data:`MIN_GAIN_MARGIN`, phase margin <
    :data:`MIN_PHASE_MARGIN`), naming the first of τ_c = 2, 3, 4, 6, 8 × max(τ_c, θ) whose loop
    clears both, where one does."""
    def low(margins):
        return (margins["stable"] is False or margins["gain_margin"] < MIN_GAIN_MARGIN
                or margins["phase_margin_deg"] < MIN_PHASE_MARGIN)

    margins = pid.design["margins"]
    if not low(margins):
        return
    remedy = "a larger tau_c is more robust"
    for factor in (2.0, 3.0, 4.0, 6.0, 8.0):
        tc = factor * max(tau_c, m.theta)
        s = simc_settings(m, tc)
        better = _achieved_margins(model, m, PID(s["kp"], s["ki"], s["kd"], dt=m.dt))
        if not low(better):
            remedy = (f"tau_c={tc:.3g} s gives {better['gain_margin']:.3g} and "
                      f"{better['phase_margin_deg']:.3g}°")
            break
    gm, pm = margins["gain_margin"], margins["phase_margin_deg"]
    state = "is unstable on the model: its " if margins["stable"] is False else "has "
    emit_warning(f"tune_pid: the loop {state}gain margin {gm:.3g} and phase margin {pm:.3g}° "
                 f"on the model with tau_c = {tau_c:.3g} s (SIMC gives about 3 and 47° on the "
                 f"first-order process with delay it is exact for; this model's reduction is "
                 f"approximate), so expect overshoot and oscillation on the plant; {remedy}",
                 AccuracyWarning)
