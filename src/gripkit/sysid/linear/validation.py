"""Model validation: fit, free-run simulation with initial conditions, residual tests.

* Loss (eq 29 of ``000_8f66dcc7ab06470c.txt``): ``V_N = (1/N) Σ ½ e²(t)``.
* Fit: ``100 (1 − ‖y − ŷ‖ / ‖y − ȳ‖)`` (100 % is perfect, 0 % is as good as the mean).
* Free-run simulation ``ŷ = B/(A F) u`` on a separate record needs the model's state at the start
  of the record. gripkit never sets it silently to zero: ``initial='estimate'`` (default) takes the
  past inputs from the record and estimates the ``n = len(A F) − 1`` past outputs by least squares
  (the output is affine in them); ``initial='past'`` takes the first samples of the record as the
  past; ``initial='zero'`` must be asked for. The fit is computed from sample ``t0`` on, where
  ``t0 = max(len(A F), len(B)) − 1`` samples serve as the past.
* An unstable model diverges in free run: :func:`compare` warns (:class:`StabilityWarning`) and
  reports no simulation fit instead of a meaningless number.
* Residual tests (Ljung, *System Identification*, 2nd ed., §16.6): the normalised
  autocorrelation ``r_e(τ)`` of the prediction errors, τ = 1 … L, and the cross-correlation
  ``r_eu(τ)`` between the errors and past inputs, τ = 0 … L, each with the band ``±z_{1−α/2}/√M``;
  the portmanteau statistic ``M Σ r_e(τ)²`` (χ² with L degrees of freedom) tests whiteness and
  ``M r̂_euᵀ R_u⁻¹ r̂_eu`` (χ², ``R_u`` the normalised input autocorrelation matrix, restricted to
  the directions the input excites) tests independence of the errors from past inputs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import DataError, StabilityWarning, emit_warning
from ..checks import check_io

__all__ = ["fit_percent", "records_fit", "loss_vn", "Comparison", "compare", "ResidualTests",
           "residual_tests", "Validation", "validate"]


def loss_vn(e: np.ndarray) -> float:
    """Eq (29): ``V_N = (1/N) Σ ½ e²``."""
    e = np.asarray(e, dtype=np.float64)
    return 0.5 * float(e @ e) / e.size


def fit_percent(y, yhat) -> float:
    """``100 (1 − ‖y − ŷ‖ / ‖y − ȳ‖)`` in percent."""
    y = np.asarray(y, dtype=np.float64)
    yhat = np.asarray(yhat, dtype=np.float64)
    if y.ndim == 1 and y.shape == yhat.shape:  # np.linalg.norm's arithmetic (√(d·d)), one buffer
        d = np.subtract(y, y.mean())
        den = math.sqrt(d.dot(d))
        if den == 0.0:
            raise DataError("the fit is undefined for a constant output (‖y − ȳ‖ = 0)")
        np.subtract(y, yhat, out=d)
        return 100.0 * (1.0 - math.sqrt(d.dot(d)) / den)
    den = float(np.linalg.norm(y - y.mean()))
    if den == 0.0:
        raise DataError("the fit is undefined for a constant output (‖y − ȳ‖ = 0)")
    return 100.0 * (1.0 - float(np.linalg.norm(y - yhat)) / den)


def records_fit(ys: list, yhats: list) -> np.ndarray:
    """Fit (%) of several records together, per column: ``100 (1 − √(Σ_i ‖y_i − ŷ_i‖²) /
    √(Σ_i ‖y_i − ȳ_i‖²))``, every record about its own mean ȳ_i (records at different operating
    levels do not inflate it); with one record it is :func:`fit_percent`."""
    num = sum(np.sum((np.asarray(y) - np.asarray(h)) ** 2, axis=0) for y, h in zip(ys, yhats))
    den = sum(np.sum((np.asarray(y) - np.mean(y, axis=0)) ** 2, axis=0) for y in ys)
    if np.any(den == 0.0):
        raise DataError("the fit is undefined for an output constant in every record "
                        "(Σ‖y − ȳ‖² = 0)")
    return 100.0 * (1.0 - np.sqrt(num) / np.sqrt(den))


@dataclass(frozen=True)
class Comparison:
    """Free-run simulation of a model against measured data.

    Attributes
    ----------
    y_sim
        Simulated output, shape (N,); the first ``t0`` samples are the record's own (the past).
    t0
        First compared sample.
    fit_percent
        Simulation fit on samples ``t0`` … N−1, or None when the model is unstable.
    initial
        How the initial conditions were obtained ('estimate', 'past' or 'zero').
    y_past
        The past outputs used (estimated or measured), most recent last.
    stable
        Whether the model's poles lie inside the unit circle.
    """

    y_sim: np.ndarray
    t0: int
    fit_percent: float | None
    initial: str
    y_past: np.ndarray
    stable: bool


def compare(model, u, y, *, initial: str = "estimate") -> Comparison:
    """Simulate ``model`` in free run on the record (u, y) (deviation units) and compute the fit.

    See the module docstring for ``initial``. Warns :class:`StabilityWarning` and returns
    ``fit_percent=None`` when the model is unstable.
    """
    u, y = check_io(u, y)
    if initial not in ("estimate", "past", "zero"):
        raise DataError(f"initial: expected 'estimate', 'past' or 'zero', found {initial!r}")
    a = model.denominator
    n_y = a.size - 1
    t0 = max(n_y, model.B.size - 1)
    if y.size < t0 + max(n_y, 1) + 2:
        raise DataError(f"validation of {model.label} needs at least "
                        f"{t0 + max(n_y, 1) + 2} samples, "
                        f"found {y.size}")
    stable = model.stable
    if not stable:
        pmax = float(np.max(np.abs(model.poles())))
        emit_warning(f"{model.label} is unstable (largest pole magnitude {pmax:.4g} > "
                     "1): its free-run "
                     f"simulation diverges, so no simulation fit is reported", StabilityWarning)
    u_past = u[:t0]
    if initial == "past":
        y_past = y[t0 - n_y:t0].copy() if n_y else np.zeros(0)
    elif initial == "zero":
        y_past = np.zeros(n_y)
        u_past = np.zeros(t0)
    else:
        y_past = (_estimate_past(model, u[t0:], y[t0:], u_past,
                                 n_y) if stable else y[t0 - n_y:t0].copy())
    with np.errstate(over="ignore", invalid="ignore"):
        ys = model.simulate(u[t0:], initial="given", y_past=y_past, u_past=u_past)
    y_sim = np.concatenate([y[:t0], ys])
    fit = None
    if stable and np.isfinite(ys).all():
        fit = fit_percent(y[t0:], ys)
    return Comparison(y_sim, t0, fit, initial, np.asarray(y_past), stable)


def _estimate_past(model, u, y, u_past, n_y: int) -> np.ndarray:
    """Least-squares estimate of the ``n_y`` past outputs (the output is affine in them)."""
    forced = model.simulate(u, initial="given", y_past=np.zeros(n_y), u_past=u_past)
    if n_y == 0:
        return np.zeros(0)
    zero_u = np.zeros_like(u)
    basis = np.empty((y.size, n_y))
    for k in range(n_y):
        e = np.zeros(n_y)
        e[k] = 1.0
        basis[:, k] = (model.simulate(zero_u, initial="given", y_past=e,
                                      u_past=np.zeros(model.B.size)))
    z = np.linalg.lstsq(basis, y - forced, rcond=None)[0]
    return z


@dataclass(frozen=True)
class ResidualTests:
    """Whiteness and independence tests of prediction errors.

    Attributes
    ----------
    lags
        τ = 0 … L (autocorrelation is tested for τ ≥ 1).
    autocorr
        Normalised autocorrelation r_e(τ), shape (L+1,), r_e(0) = 1.
    crosscorr
        Normalised cross-correlation r_eu(τ) = corr(e(t), u(t−τ)), shape (L+1,).
    bound
        Confidence band ±bound for both (``z_{1−α/2}/√M``).
    alpha
        Significance level.
    whiteness_stat, whiteness_p, white
        Portmanteau statistic, its χ²(L) p-value, and ``p >= alpha``.
    independence_stat, independence_p, independent, independence_dof
        Cross-correlation statistic, its χ² p-value, ``p >= alpha``, and the degrees of freedom
        (the number of eigen-directions of R_u above 10⁻³ of the largest: a band-limited or
        multisine input excites fewer than L+1 of them; a Monte Carlo check with white residuals
        gives 5 % rejections at α = 5 % for white, band-limited and multisine inputs).
    n
        Number of residuals M.
    """

    lags: np.ndarray
    autocorr: np.ndarray
    crosscorr: np.ndarray
    bound: float
    alpha: float
    whiteness_stat: float
    whiteness_p: float
    white: bool
    independence_stat: float
    independence_p: float
    independent: bool
    independence_dof: int
    n: int

    def to_dict(self) -> dict:
        return dict(lags=self.lags.tolist(), autocorr=self.autocorr.tolist(),
                    crosscorr=self.crosscorr.tolist(), bound=self.bound, alpha=self.alpha,
                    whiteness_stat=self.whiteness_stat, whiteness_p=self.whiteness_p,
                    white=self.white,
                    independence_stat=self.independence_stat, independence_p=self.independence_p,
                    independent=self.independent, independence_dof=self.independence_dof, n=self.n)


def _xcorr(a: np.ndarray, b: np.ndarray, lags: int) -> np.ndarray:
    """Biased cross-covariance c(τ) = (1/M) Σ_t a(t) b(t−τ), τ = 0 … lags (FFT)."""
    m = a.size
    nfft = 1 << int(math.ceil(math.log2(2 * m)))
    c = np.fft.irfft(np.fft.rfft(a, nfft) * np.conj(np.fft.rfft(b, nfft)), nfft)[:lags + 1]
    return c / m


def residual_tests(e, u, *, lags: int = 25, alpha: float = 0.01) -> ResidualTests:
    """Whiteness of ``e`` and independence of ``e`` from past ``u`` (same length, aligned)."""
    from scipy import stats

    e = np.asarray(e, dtype=np.float64)
    u = np.asarray(u, dtype=np.float64)
    if e.shape != u.shape:
        raise DataError(f"residuals and input must be aligned, found {e.size} and {u.size} samples")
    if not 0 < alpha < 1:
        raise DataError(f"alpha: expected a significance level in (0, 1), found {alpha!r}")
    m = e.size
    lags = int(min(lags, m // 4))
    if lags < 1:
        raise DataError(f"residual tests need at least 8 residuals, found {m}")
    e0 = e - e.mean()
    u0 = u - u.mean()
    ce = _xcorr(e0, e0, lags)
    cu = _xcorr(u0, u0, lags)
    ceu = _xcorr(e0, u0, lags)
    if ce[0] <= 0 or cu[0] <= 0:
        raise DataError("residual tests need non-constant residuals and input")
    re = ce / ce[0]
    ru = cu / cu[0]
    reu = ceu / math.sqrt(ce[0] * cu[0])
    bound = float(stats.norm.ppf(1 - alpha / 2) / math.sqrt(m))
    q = float(m * np.sum(re[1:] ** 2))
    p_white = float(stats.chi2.sf(q, lags))
    Ru = ru[np.abs(np.subtract.outer(np.arange(lags + 1), np.arange(lags + 1)))]
    w, V = np.linalg.eigh(Ru)
    keep = w > 1e-3 * w.max()  # directions the input excites (a multisine spans few of them)
    proj = V[:, keep].T @ reu
    s = float(m * np.sum(proj ** 2 / w[keep]))
    dof = int(keep.sum())
    p_ind = float(stats.chi2.sf(s, dof))
    return ResidualTests(np.arange(lags + 1), re, reu, bound, float(alpha), q, p_white,
                         p_white >= alpha,
                         s, p_ind, p_ind >= alpha, dof, m)


@dataclass(frozen=True)
class Validation:
    """Validation of a model on a separate record (:func:`validate`).

    Attributes
    ----------
    simulation
        :class:`Comparison` (free run; ``fit_percent`` None for an unstable model).
    prediction_fit_percent
        One-step-ahead prediction fit (None when the predictor 1/(C F) is unstable, e.g. an
        unstable OE model, whose predictor is its diverging simulation).
    y_pred
        One-step prediction, shape (N,).
    residuals
        One-step prediction errors from ``model.start`` on.
    loss
        V_N (eq 29) of those errors (None when they diverge).
    tests
        :class:`ResidualTests` of the errors against the input (None when they diverge).
    """

    simulation: Comparison
    prediction_fit_percent: float | None
    y_pred: np.ndarray
    residuals: np.ndarray
    loss: float | None
    tests: ResidualTests | None

    @property
    def fit_percent(self) -> float | None:
        """Free-run simulation fit (None for an unstable model)."""
        return self.simulation.fit_percent

    def to_dict(self) -> dict:
        tests = None if self.tests is None else {k: v for k, v in self.tests.to_dict().items()
                                                 if k not in ("lags", "autocorr", "crosscorr")}
        return dict(fit_percent=self.fit_percent,
                    prediction_fit_percent=self.prediction_fit_percent,
                    loss=self.loss, initial=self.simulation.initial, stable=self.simulation.stable,
                    residual_tests=tests)


def validate(model, u, y, *, initial: str = "estimate", lags: int = 25,
             alpha: float = 0.01) -> Validation:
    """Validate ``model`` on (u, y) (deviation units, same sampling as the estimation data):
    free-run simulation fit, one-step prediction fit, residual whiteness and independence."""
    u, y = check_io(u, y)
    sim = compare(model, u, y, initial=initial)
    with np.errstate(over="ignore", invalid="ignore"):
        e = model.prediction_errors(u, y)
    t0 = model.start
    yp = y.copy()
    yp[t0:] = y[t0:] - e
    cf = np.convolve(model.C, model.F)  # the predictor filters by 1/(C F)
    if cf.size > 1 and np.any(np.abs(np.roots(cf)) >= 1.0) or not np.isfinite(e).all():
        return Validation(sim, None, yp, e, None, None)  # diverging predictor: no numbers
    return Validation(sim, fit_percent(y[t0:], yp[t0:]), yp, e, loss_vn(e),
                      residual_tests(e, u[t0:], lags=lags, alpha=alpha))
