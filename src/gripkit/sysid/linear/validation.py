"""Model validation: fit, free-run simulation with initial conditions, residual tests.

* Loss (eq 29 of ``000_8f66dcc7ab06470c.txt``): ``V_N = (1/N) Σ ½ e²(t)``.
* Fit: ``100 (1 − ‖y − ŷ‖ / ‖y − ȳ‖)`` (100 % is perfect, 0 % is as good as the mean).
* The validation fit of a model on a record is one number, ``model.compare(u, y)``
  (:data:`~gripkit.sysid.linear.linear_model.VALIDATION_FIT`: free run from the initial state
  estimated by least squares, every sample scored); :func:`compare` returns exactly it (a
  :class:`~gripkit.sysid.ModelFit`) for every identified model, linear or nonlinear (each by
  its own ``fit_definition``), and :func:`validate`, for a linear model only, reports it as its
  ``fit_percent``. gripkit never starts a validation free run silently from rest.
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

import contextvars
import functools
import inspect
import math
from dataclasses import dataclass

import numpy as np

from ...errors import (ArgumentError, DataError, DataWarning, ModelError, StabilityWarning,
                       emit_warning)
from ...lti import LinearSystem
from ...signals.trajectory import Trajectory
from ..checks import check_io
from ..model_protocol import ModelFit, check_sample_time, column_in_unit

__all__ = ["fit_percent", "records_fit", "loss_vn", "compare", "ResidualTests", "residual_tests",
           "Validation", "validate", "model_columns", "OFFSETS_RULE", "warn_if_deviations",
           "checks_arrays"]


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


def _check_initial(initial: str) -> None:
    if initial != "estimate":
        raise ArgumentError(f"initial: expected 'estimate' (the initial state estimated by least "
                            f"squares, as model.compare), found {initial!r}",
                            hint="a free run from rest: fit_percent(y, model.simulate(u))")


def compare(model, u, y=None, *, initial: str = "estimate",
            dt: float | None = None) -> ModelFit:
    """The validation fit of any identified ``model`` on a :class:`~gripkit.signals.Trajectory`
    ``u`` with its columns (``y`` and ``dt`` not given: the trajectory carries them), or on the
    arrays ``u``, ``y`` (``(N,)`` or ``(N, m)``, ``(N, p)``, the record's values in the units
    of the data the model was fitted on): exactly ``model.compare(u, y)``, the fit by the
    model's ``fit_definition`` (a linear model: ARX, ARMAX, OE, state space, transfer function,
    its free run from the initial state estimated by least squares, every sample scored, its
    offsets removed from the arrays as from a trajectory; a nonlinear model: NARX,
    Hammerstein–Wiener, nonlinear state space, hysteresis). Warns :class:`StabilityWarning` for
    an unstable linear model, whose ``fit_percent`` is None per output. ``initial`` takes only
    ``'estimate'`` (a free run from rest is ``model.simulate(u)``, never a validation fit).
    ``dt``: the arrays' sample time, which a continuous linear model needs (else an
    ArgumentError); a discrete model is checked against it."""
    _check_initial(initial)
    if isinstance(u, Trajectory) and (y is not None or dt is not None):
        raise ArgumentError("compare(): a trajectory carries its outputs and sample time; give "
                            "no y or dt with it", hint="gripkit.sysid.compare(model, data)")
    if not isinstance(u, Trajectory) and y is None:
        raise ArgumentError("compare(): give a trajectory with the model's columns, or the "
                            "arrays u and y", hint="gripkit.sysid.compare(model, data) or "
                                                   "gripkit.sysid.compare(model, u, y)")
    if not callable(getattr(model, "compare", None)):
        raise ArgumentError(f"compare(): model: expected an identified model, found "
                            f"{type(model).__name__}", hint="gripkit.sysid.identify(...)")
    if not getattr(model, "stable", True):
        pmax = float(np.max(np.abs(model.system.poles())))
        name = getattr(model, "label", model.structure)
        emit_warning(f"{name} is unstable (largest pole magnitude {pmax:.4g} > 1): its free-run "
                     f"simulation diverges, so no simulation fit is reported", StabilityWarning)
    timed = {}
    if dt is not None:
        if not isinstance(getattr(model, "system", None), LinearSystem):
            _check_sample_time(model, dt)  # a nonlinear model runs on its own samples
        else:
            timed = {"dt": dt}
    with np.errstate(over="ignore", invalid="ignore"):
        return model.compare(u) if y is None else model.compare(u, y, **timed)


def _check_sample_time(model, dt) -> None:
    """A nonlinear model's arrays are its samples: ``dt`` may only confirm its sample time (the
    linear models' check, :func:`~gripkit.sysid.model_protocol.check_sample_time`: a
    DataError; any ``dt`` for a rate-independent family), and a model of unknown sample time
    takes none."""
    mdt = getattr(model, "dt", None)
    family = getattr(model, "_family", "this model")
    if mdt is None:
        raise ArgumentError(f"compare(): dt: {family} has no sample time to check the arrays' "
                            f"dt={dt!r} s against", hint="leave dt out")
    check = getattr(model, "_check_dt", None)
    if check is not None:
        check(float(dt))
    else:
        check_sample_time(float(dt), float(mdt))


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
    """Validation of a SISO model on a separate record (:func:`validate`).

    Attributes
    ----------
    simulation
        The :class:`~gripkit.sysid.ModelFit` of ``model.compare(u, y)`` (free run; its
        ``fit_percent`` None for an unstable model).
    prediction_fit_percent
        One-step-ahead prediction fit (None when the predictor diverges: 1/(C F) unstable, e.g.
        an unstable OE model, whose predictor is its diverging simulation).
    y_pred
        One-step prediction, shape (N,).
    residuals
        One-step prediction errors from ``model.start`` on (0 for a state-space model).
    loss
        V_N (eq 29) of those errors (None when they diverge).
    tests
        :class:`ResidualTests` of the errors against the input (None when they diverge).
    stable
        Whether the model's poles lie inside the unit circle.
    """

    simulation: ModelFit
    prediction_fit_percent: float | None
    y_pred: np.ndarray
    residuals: np.ndarray
    loss: float | None
    tests: ResidualTests | None
    stable: bool

    @property
    def fit_percent(self) -> float | None:
        """Free-run simulation fit, ``model.compare(u, y).fit_percent[0]`` (None for an unstable
        model)."""
        return self.simulation.fit_percent[0]

    def to_dict(self) -> dict:
        tests = None if self.tests is None else {k: v for k, v in self.tests.to_dict().items()
                                                 if k not in ("lags", "autocorr", "crosscorr")}
        return dict(fit_percent=self.fit_percent,
                    prediction_fit_percent=self.prediction_fit_percent,
                    loss=self.loss, initial="estimate", stable=self.stable,
                    residual_tests=tests)


#: the offsets convention, one sentence (the estimators', the models' docstrings and the warning)
OFFSETS_RULE = ("the estimators (arx, armax, oe, n4sid, tfest) take u, y as deviations from the "
                "operating point, with u_offset=/y_offset= as metadata, while a model's "
                "simulate/predict/compare/residuals/validate take the record's own values and "
                "subtract the offsets themselves")
#: a column's mean within this fraction of its span (max − min) of zero: it looks like deviations
DEVIATION_CENTRED = 0.05
#: an offset farther than this fraction of its span outside a column's range lies "far outside"
#: it: the model's operating point is none the arrays visit
OFFSET_FAR = 0.1
#: set while a checked entry (:func:`checks_arrays`) runs: the calls it makes do not warn again
_ARRAYS_CHECKED: contextvars.ContextVar[bool] = contextvars.ContextVar("arrays_checked",
                                                                      default=False)


def _looks_like_deviations(x, offsets) -> bool | None:
    """For the columns of ``x`` (N, k) and the model's ``offsets`` (k,): None when some column
    is not centred on zero (:data:`DEVIATION_CENTRED`) or the shapes differ (the method's own
    error follows), else whether some offset lies more than :data:`OFFSET_FAR` of its column's
    span outside that column's range."""
    try:
        x = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):  # not numbers: the method's own DataError follows
        return None
    if not x.size:  # empty: the method's own DataError follows
        return None
    x = x.reshape(x.shape[0], -1) if x.ndim else x.reshape(1, 1)
    if x.shape[1] != offsets.size or not np.all(np.isfinite(x)):
        return None
    lo, hi = x.min(axis=0), x.max(axis=0)
    span = hi - lo
    if np.any(np.abs(x.mean(axis=0)) > DEVIATION_CENTRED * span):
        return None
    return bool(np.any((offsets != 0) & ((offsets > hi + OFFSET_FAR * span)
                                         | (offsets < lo - OFFSET_FAR * span))))


def warn_if_deviations(model, u, y, what: str) -> None:
    """Warn (:class:`DataWarning`) when the arrays ``u`` (and ``y``, None for a simulation) given
    to ``what`` ("compare", …) of a linear ``model`` with non-zero offsets look like deviations
    (every column's mean within :data:`DEVIATION_CENTRED` of its span of zero) while an offset
    lies far outside its column's range (:data:`OFFSET_FAR`): the model would subtract its
    offsets a second time (:data:`OFFSETS_RULE`)."""
    uo, yo = (np.atleast_1d(np.asarray(getattr(model, k, 0.0) or 0.0, dtype=np.float64))
              for k in ("u_offset", "y_offset"))
    if not (np.any(uo) or np.any(yo)):
        return
    checks = [_looks_like_deviations(u, uo)] + ([] if y is None else
                                                [_looks_like_deviations(y, yo)])
    if None in checks or not any(checks):
        return
    name = getattr(model, "label", None) or getattr(model, "structure", "the model")
    emit_warning(f"{name}.{what}: the arrays look like deviations from the operating point "
                 f"(their means within {DEVIATION_CENTRED:.0%} of their spans of 0) while the "
                 f"model's offsets (u_offset = {_numbers(uo)}, y_offset = {_numbers(yo)}) lie far "
                 f"outside their range; {OFFSETS_RULE}"
                 f": pass the record's values (u + u_offset, y + y_offset), else the offsets are "
                 f"subtracted twice", DataWarning)


def _numbers(v: np.ndarray) -> str:
    return ", ".join(f"{x:.4g}" for x in v)


def checks_arrays(what: str, with_y: bool = True):
    """Decorator of a model method or function whose first two parameters are the model and the
    data (``(self, data, y=None, …)``, ``(model, u, y=None, …)``; ``with_y`` False: no ``y``, a
    simulation) that runs :func:`warn_if_deviations` on arrays (not a trajectory) once: the
    methods it calls in turn do not check again. Arguments bind as the wrapped signature says
    (by position or by keyword)."""
    def wrap(fn):
        sig = inspect.signature(fn)
        model_name, data_name = list(sig.parameters)[:2]

        @functools.wraps(fn)
        def run(*args, **kw):
            if _ARRAYS_CHECKED.get():
                return fn(*args, **kw)
            try:
                bound = sig.bind(*args, **kw).arguments
            except TypeError:  # the call itself is wrong: the function says so
                return fn(*args, **kw)
            data = bound.get(data_name)
            if data is not None and not isinstance(data, Trajectory):
                y = bound.get("y") if with_y else None
                warn_if_deviations(bound[model_name], data, y, what)
            token = _ARRAYS_CHECKED.set(True)
            try:
                return fn(*args, **kw)
            finally:
                _ARRAYS_CHECKED.reset(token)
        return run
    return wrap


@checks_arrays("validate")
def validate(model, u, y=None, *, initial: str = "estimate", lags: int = 25,
             alpha: float = 0.01, dt: float | None = None) -> Validation:
    """Validate the one-input, one-output linear ``model`` (ARX, ARMAX, OE, state space or
    transfer function) on a separate record: a :class:`~gripkit.signals.Trajectory` with the
    model's columns (as ``model.compare(data)`` reads it), or the arrays ``u``, ``y`` in the
    units of the data the model was fitted on (the model's offsets applied, as to a trajectory;
    same sampling as the estimation data): the free-run fit of :func:`compare`
    (``model.compare(u, y)``), the one-step prediction fit, residual whiteness and independence.
    ``dt``: the arrays' sample time, which a continuous model (tfest, step response) needs, as
    in :func:`compare`. A nonlinear model (no linear ``system``) is refused with a ModelError:
    its fit is ``model.compare``, its prediction errors ``model.residuals``."""
    _check_initial(initial)
    if not isinstance(getattr(model, "system", None), LinearSystem):
        what = getattr(model, "_family", None) or f"a {type(model).__name__}"
        raise ModelError(f"validate: {what} is not a linear model; validate is the residual-test "
                         "report of a linear one (ARX, ARMAX, OE, state space, transfer "
                         "function)", hint="use model.compare(data) for its fit and "
                                           "model.residuals(data) for its prediction errors")
    if len(model.inputs) != 1 or len(model.outputs) != 1:
        raise ModelError(f"validate: the model has {len(model.inputs)} inputs and "
                         f"{len(model.outputs)} outputs; validate takes one of each",
                         hint="use model.compare(data) and model.residuals(data)")
    u, y, dt = _record_arrays(model, u, y, dt)
    sim = compare(model, u, y, dt=dt)
    with np.errstate(over="ignore", invalid="ignore"):
        e, t0, predictor_poles = _one_step(model, u, y, dt)
    yp = y.copy()
    yp[t0:] = y[t0:] - e
    if np.any(np.abs(predictor_poles) >= 1.0) or not np.isfinite(e).all():
        return Validation(sim, None, yp, e, None, None, model.stable)  # no numbers
    return Validation(sim, fit_percent(y[t0:], yp[t0:]), yp, e, loss_vn(e),
                      residual_tests(e, u[t0:], lags=lags, alpha=alpha), model.stable)


def _record_arrays(model, data, y, dt) -> tuple[np.ndarray, np.ndarray, float | None]:
    """``(u, y, dt)`` of what :func:`validate` was given: a trajectory's input and output columns
    in the model's units (and its sample time), or the arrays ``u``, ``y`` checked."""
    if not isinstance(data, Trajectory):
        if y is None:
            raise ArgumentError("validate: give a trajectory with the model's columns, or the "
                                "arrays u and y", hint="model.validate(data) or "
                                                       "model.validate(u, y)")
        u, y = check_io(data, y)
        return u, y, dt
    if y is not None or dt is not None:
        raise ArgumentError("validate: a trajectory carries its outputs and sample time; give "
                            "no y or dt with it", hint="model.validate(data)")
    step = data.require_uniform(why="validation of an identified model")
    u, y = (model_columns(data, names, units, what)[:, 0] for names, units, what in
            ((model.inputs, model.input_units, "input"),
             (model.outputs, model.output_units, "output")))
    return *check_io(u, y), step


def model_columns(data, names, units, what: str) -> np.ndarray:
    """The columns ``names`` (N, k) of the trajectory ``data`` in the model's ``units`` (``what``:
    "input" or "output"), or a DataError naming the missing ones; a model's own arrays
    (:meth:`IdentifiedLinearModel._columns <gripkit.sysid.linear.linear_model>`) and
    :func:`validate` read a trajectory by it."""
    missing = [n for n in names if n not in data.names]
    if missing:
        raise DataError(f"data: the model's {what} column(s) {', '.join(map(repr, missing))} "
                        f"are missing; the data have {', '.join(map(repr, data.names))}",
                        hint="rename the columns or use a record with the model's columns")
    return np.column_stack([column_in_unit(data, n, u, what) for n, u in zip(names, units)])


def _one_step(model, u, y, dt) -> tuple[np.ndarray, int, np.ndarray]:
    """(one-step errors, first sample they start at, poles of the predictor) on the arrays
    ``u``, ``y`` (the model's offsets applied)."""
    if hasattr(model, "prediction_errors"):  # a polynomial model: its exact predictor
        cf = np.convolve(model.C, model.F)  # the predictor filters by 1/(C F)
        return (model.residuals(u, y), model.start,
                np.roots(cf) if cf.size > 1 else np.zeros(0))
    ss = model.to_ss(dt)  # innovation form: the predictor's poles are those of A − K C
    K = getattr(model, "K", None)
    a = ss.A if K is None else ss.A - K @ ss.C
    return model.residuals(u, y, dt=dt)[:, 0], 0, np.linalg.eigvals(a)
