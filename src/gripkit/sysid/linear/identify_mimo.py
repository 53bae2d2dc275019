"""Identification from a :class:`~gripkit.signals.Trajectory` with several inputs and outputs:
state space (subspace, then PEM), frequency response and continuous-time transfer function.

Column selection by name (``input='a,b'`` or ``['a', 'b']``), the uniform-sampling check, units,
and removal of the operating point (``detrend='mean'``: each channel's mean, recorded as the
model's offsets) as in :func:`gripkit.sysid.identify`.

Order search (``order='2:8'``): every order of the range is fitted from one factorisation and
ranked by the free-run fit on ``validate`` data (mean over outputs, x0 estimated) when given,
the lowest order within 0.05 fit points of the best winning (higher orders that fit the noise tie),
otherwise by Akaike's criterion of the innovation predictor,
``AIC = N log det Λ̂ + 2 d``, d = n(m + 2p) (+ pm with D) free parameters. A best order on the
edge of a range of three or more orders is warned about: the true order may lie outside it.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from dataclasses import dataclass

import numpy as np

from ...errors import (AccuracyWarning, ArgumentError, DataError, GripkitError, GripkitWarning,
                      IdentificationError, emit_warning)
from ...progress import status
from ...signals.trajectory import Trajectory
from .arx_mimo import arx_mimo
from .frf import frf
from .linear_model import VALIDATION_FIT  # the one definition, re-exported for the CLI

__all__ = ["MimoData", "mimo_data", "identify_ss", "identify_frf", "identify_tf", "identify_arx", "several",
           "parse_names", "parse_order"]


def parse_names(x, what: str) -> tuple[str, ...]:
    """Column names from ``'a,b'`` or a sequence."""
    names = [s.strip() for s in x.split(",")] if isinstance(x, str) else [str(s).strip() for s in x]
    if not names or any(not n for n in names):
        raise DataError(f"{what}: expected one or more column names separated by commas, found {x!r}")
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise DataError(f"{what}: column(s) {', '.join(map(repr, dup))} listed twice")
    return tuple(names)


def parse_order(order) -> tuple[int, int] | None:
    """None, N, 'N' or 'LO:HI' as an inclusive (lo, hi) range."""
    if order is None:
        return None
    if isinstance(order, (int, np.integer)) and not isinstance(order, bool):
        lo = hi = int(order)
    else:
        txt = str(order).strip()
        try:
            lo, hi = (int(v) for v in txt.split(":")) if ":" in txt else (int(txt),) * 2
        except ValueError:
            raise DataError(f"order: expected N or LO:HI (positive integers), found {order!r}") from None
    if lo < 1 or hi < lo:
        raise DataError(f"order: expected 1 <= LO <= HI, found {order!r}")
    return lo, hi


@dataclass(frozen=True)
class MimoData:
    """Inputs (N, m) and outputs (N, p) in deviation units, with names, units and offsets."""

    u: np.ndarray
    y: np.ndarray
    dt: float
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    input_units: tuple[str, ...]
    output_units: tuple[str, ...]
    u_offset: tuple[float, ...]
    y_offset: tuple[float, ...]

    @property
    def signals(self) -> dict:
        return dict(inputs=self.inputs, outputs=self.outputs, input_units=self.input_units,
                    output_units=self.output_units)


def mimo_data(data: Trajectory, inputs, outputs, detrend: str = "mean", why: str = "identification") -> MimoData:
    """Select and detrend the input and output columns of a uniformly sampled trajectory."""
    if not isinstance(data, Trajectory):
        raise DataError(f"data: expected a gripkit Trajectory, found {type(data).__name__}",
                        hint="use gripkit.io.load(path) or Trajectory.uniform(dt=..., u=..., y=...)")
    ins, outs = parse_names(inputs, "input"), parse_names(outputs, "output")
    both = sorted(set(ins) & set(outs))
    if both:
        raise DataError(f"input and output must be different columns, {', '.join(map(repr, both))} is both")
    missing = [n for n in ins + outs if n not in data.names]
    if missing:
        raise DataError(f"data: column(s) {', '.join(map(repr, missing))} not found; the data have "
                        f"{', '.join(map(repr, data.names))}")
    if detrend not in ("mean", "none"):
        raise DataError(f"detrend: expected 'mean' or 'none', found {detrend!r}")
    dt = float(f"{data.require_uniform(why=why):.9g}")  # time stamps in files carry rounding noise
    u = np.column_stack([np.asarray(data[n], dtype=np.float64) for n in ins])
    y = np.column_stack([np.asarray(data[n], dtype=np.float64) for n in outs])
    for names, x, what in ((ins, u, "input"), (outs, y, "output")):
        flat = np.ptp(x, axis=0) <= 1e-12 * np.maximum(np.max(np.abs(x), axis=0), 1e-300)
        if flat.any():
            name = names[int(np.argmax(flat))]
            raise DataError(f"{what} column {name!r} is constant ({x[0, int(np.argmax(flat))]:.6g} for all "
                            f"{x.shape[0]} samples): it carries no information",
                            hint="drop it from --input/--output or check the data")
    _check_scale(ins, u, "input", why)
    _check_scale(outs, y, "output", why)
    u0 = u.mean(axis=0) if detrend == "mean" else np.zeros(len(ins))
    y0 = y.mean(axis=0) if detrend == "mean" else np.zeros(len(outs))
    return MimoData(u - u0, y - y0, dt, ins, outs, tuple(data.unit(n) for n in ins),
                    tuple(data.unit(n) for n in outs), tuple(map(float, u0)), tuple(map(float, y0)))


#: Largest and smallest peak magnitude of a column that state-space, frequency-response and
#: transfer-function estimation accept: they form sums of squares and of products of the signals
#: (covariances, spectra, Gram matrices), which leave float64 (1e±308) for values beyond about
#: 1e±150; 1e±100 keeps the margin for record lengths and orders.
SCALE_LIMITS = (1e-100, 1e100)


def _check_scale(names, x: np.ndarray, what: str, why: str) -> None:
    """Refuse a column whose values are too large or too small for the estimators' sums of squares
    (the SISO polynomial estimators scale internally; these do not)."""
    peak = np.max(np.abs(x), axis=0)
    lo, hi = SCALE_LIMITS
    bad = (peak > hi) | (peak < lo)
    if bad.any():
        i = int(np.argmax(bad))
        raise DataError(
            f"{what} column {names[i]!r} has values up to {peak[i]:.3g}: {why} forms sums of "
            f"squares of the signals, which leave float64 beyond about 1e±150, so it accepts peak "
            f"values between {lo:.0e} and {hi:.0e}",
            hint="give the column in other units (multiply it by a power of ten); arx, armax and "
                 "oe (SISO) scale internally")


def _validation_data(validate: Trajectory, d: MimoData) -> MimoData:
    """The validation record's columns as deviations from the *estimation* operating point
    ``d.u_offset``/``d.y_offset`` (the model's offsets): the one validation fit of
    :data:`gripkit.sysid.linear.linear_model.VALIDATION_FIT`, the number ``gripkit compare`` gives."""
    vd = mimo_data(validate, d.inputs, d.outputs, "none", why="validation")
    if abs(vd.dt - d.dt) > 1e-9 * d.dt:
        raise DataError(f"validation data are sampled at {1 / vd.dt:g} Hz, the estimation data at "
                        f"{1 / d.dt:g} Hz", hint="resample one of them")
    return dataclasses.replace(vd, u=vd.u - np.asarray(d.u_offset), y=vd.y - np.asarray(d.y_offset),
                               u_offset=d.u_offset, y_offset=d.y_offset)


def _validation_fit(model, vd: MimoData) -> list[float] | None:
    if not model.stable:
        return None
    return model.compare(vd.u, vd.y, dt=vd.dt).fit_percent


def _aic(model, d: MimoData) -> float:
    from .pem_ss import predict_errors

    ss = model.system
    K = model.K if model.K is not None else np.zeros((ss.n_states, ss.n_outputs))
    x0 = model.x0 if model.x0 is not None else np.zeros(ss.n_states)
    e = np.empty_like(d.y)
    predict_errors(ss.A, ss.B, ss.C, ss.D, K, x0, d.u, d.y, e)
    N, p = d.y.shape
    m = d.u.shape[1]
    sign, logdet = np.linalg.slogdet(e.T @ e / N)
    k = ss.n_states * (m + 2 * p) + (p * m if np.any(ss.D) else 0)
    return float(N * logdet + 2 * k) if sign > 0 else -math.inf


def identify_ss(data: Trajectory, *, input, output, order=None, method: str = "n4sid", form: str = "innovation",
                refine: bool = True, validate: Trajectory | None = None, detrend: str = "mean",
                horizon: int | None = None, feedthrough: bool = False, progress: bool = False,
                focus: str = "simulation", max_iterations: int = 50):
    """State-space model of the named columns: subspace (``method``), then PEM in ``form``
    unless ``refine=False``. Returns ``(model, extras)``; ``extras`` holds ``search`` (the ranked
    orders of a range), ``validation_fit_percent`` (per output, with ``validate``) and
    ``criterion``. ``progress=True`` (the command line) reports each stage on stderr; a Python
    call is silent.

    The returned model never loses to the subspace model it started from by the criterion
    ``focus`` names (:func:`focus_score`, on ``validate`` when given, else on the estimation
    record): ``'simulation'`` (default: the free-run fit, the one validation fit of gripkit, which
    is what a model used for simulation and control design is judged by) or ``'prediction'`` (the
    one-step-ahead fit, PEM's own criterion, as MATLAB's default ``Focus``). When the refined model
    scores lower, the subspace model is returned with an :class:`AccuracyWarning` giving both
    scores. PEM stopping after ``max_iterations`` without converging is warned about too."""
    from .subspace import (
        DEFAULT_MAX_ORDER,
        SUBSPACE_METHODS,
        default_horizon,
        from_factor,
        select_order,
        subspace_factor,
        warn_if_stabilised,
    )

    if method not in SUBSPACE_METHODS:
        raise DataError(f"method: expected one of {', '.join(SUBSPACE_METHODS)}, found {method!r}")
    d = mimo_data(data, input, output, detrend, why="state-space identification")
    vd = None if validate is None else _validation_data(validate, d)
    rng = parse_order(order)
    n_hi = rng[1] if rng else DEFAULT_MAX_ORDER
    k = default_horizon(n_hi, d.y.shape[1]) if horizon is None else int(horizon)
    report = status if progress else (lambda line: None)
    report(f"{method}: {d.u.shape[0]} samples, {len(d.inputs)} input(s), {len(d.outputs)} output(s), horizon {k}")
    fac = subspace_factor(d.u, d.y, horizon=k, method=method)
    extras: dict = {}
    build = lambda n: from_factor(fac, n, dt=d.dt, feedthrough=feedthrough, signals=d.signals)  # noqa: E731
    if rng is None:
        n = select_order(fac.s, min(n_hi, fac.s.size - 1))
        model = build(n)
        model.info["order_selection"] = "singular values above the noise floor"
    elif rng[0] == rng[1]:
        model = build(rng[0])
        model.info["order_selection"] = "given"
    else:
        rows = []
        criterion = "validation_fit" if vd is not None else "aic"
        for n in range(rng[0], rng[1] + 1):
            cand = build(n)
            row = {"order": n, "fit_percent": cand.fit_percent, "aic": _aic(cand, d)}
            if vd is not None:
                vf = _validation_fit(cand, vd)
                row["validation_fit_percent"] = vf
                row["score"] = -math.inf if vf is None else float(np.mean(vf))
            else:
                row["score"] = -row["aic"]
            rows.append((row, cand))
        rows.sort(key=lambda rc: -rc[0]["score"])
        if vd is not None:  # parsimony: the lowest order within 0.05 fit points of the best
            top = rows[0][0]["score"]
            close = [rc for rc in rows if rc[0]["score"] >= top - 0.05]
            pick = min(close, key=lambda rc: rc[0]["order"])
            rows.remove(pick)
            rows.insert(0, pick)
        best_row, model = rows[0]
        model.info["order_selection"] = f"best of {rng[0]}:{rng[1]} by {criterion}"
        extras["search"] = [r for r, _ in rows]
        extras["criterion"] = criterion
        if best_row["order"] in rng and rng[1] - rng[0] >= 2:
            emit_warning(f"order search: the best order {best_row['order']} lies on the edge of the searched range "
                         f"{rng[0]}:{rng[1]}; the true order may lie outside it, widen the range",
                         GripkitWarning)
    model = model.replace(u_offset=d.u_offset, y_offset=d.y_offset)
    if focus not in FOCUS:
        raise DataError(f"focus: expected one of {', '.join(FOCUS)}, found {focus!r}")
    if refine:
        report(f"PEM refinement ({form} form) of the order-{model.order} model")
        model, refine = _refine(model, d, vd, form, focus, max_iterations)
    warn_if_stabilised(model)
    if detrend == "mean":
        refit = lambda: identify_ss(  # noqa: E731
            data, input=input, output=output, order=model.order, method=method, form=form,
            refine=refine, detrend="none", horizon=horizon, feedthrough=feedthrough)[0]
        _warn_if_detrending_hurt(model, refit, d.u.shape[0], d.dt, "identify ss")
    if vd is not None:
        extras["validation_fit_percent"] = _validation_fit(model, vd)
    return model, extras


#: the criteria by which identify_ss keeps the better of the subspace and the refined model
FOCUS = ("simulation", "prediction")


def focus_score(model, focus: str, d: MimoData) -> float:
    """Mean over outputs of the fit (%) by which ``focus`` judges ``model`` on the deviation data
    ``d``: ``'simulation'``, the free-run fit with x0 estimated (:data:`VALIDATION_FIT`; −inf for
    an unstable model); ``'prediction'``, the one-step-ahead fit of the innovation predictor
    ``x̂⁺ = A x̂ + B u + K (y − C x̂ − D u)`` from its x0 estimated by least squares
    (:func:`~.pem_ss.predictor_x0`; −inf when A − K C is unstable)."""
    if focus == "simulation":
        if not model.stable:
            return -math.inf
        return float(np.mean(model.compare(d.u, d.y, dt=d.dt).fit_percent))
    from .pem_ss import predictor_x0

    ss = model.system
    n, p = ss.n_states, ss.n_outputs
    K = np.zeros((n, p)) if model.K is None else model.K
    if n and np.max(np.abs(np.linalg.eigvals(ss.A - K @ ss.C))) >= 1.0:
        return -math.inf
    _, e = predictor_x0(ss.A, ss.B, ss.C, ss.D, K, d.u, d.y)
    den = np.linalg.norm(d.y - d.y.mean(axis=0), axis=0)
    return float(np.mean(100.0 * (1.0 - np.linalg.norm(e, axis=0) / den)))


def _refine(start, d: MimoData, vd: MimoData | None, form: str, focus: str, max_iterations: int):
    """PEM in ``form`` from the subspace model ``start``, kept only when it does not lose by
    ``focus`` (:func:`_never_lose`; PEM in oe form as the second candidate for the simulation
    focus); ``(model, refined?)``. A PEM that the data cannot determine returns ``start`` with a
    warning."""
    from .pem_ss import pem

    try:
        model = pem(start, u=d.u, y=d.y, form=form, max_iterations=max_iterations)
    except IdentificationError as exc:  # an order the data do not support in full
        emit_warning(f"PEM refinement of the order-{start.order} {start.structure} model failed "
                     f"({exc.message}); the subspace model is returned, without parameter "
                     f"covariance (lower the order, or --no-refine to skip PEM)",
                     AccuracyWarning)
        return start, False
    oe = None
    if form == "innovation" and focus == "simulation":  # PEM in oe form minimises the free-run
        def oe():                                       # error itself: the second candidate
            try:
                return pem(start, u=d.u, y=d.y, form="oe", max_iterations=max_iterations)
            except IdentificationError:
                return None
    return _never_lose(start, model, focus, d if vd is None else vd, vd is None, max_iterations, oe), True


#: fit points (%) within which a refined model counts as scoring as well as its start: the scores
#: are means of fits computed in floating point, and PEM's σ is worth more than a 1e-5 % tie
FOCUS_TIE = 0.01


def _warn_unconverged(model, max_iterations: int) -> None:
    info = model.info.get("pem", {})
    if not info.get("converged", True):
        emit_warning(f"PEM refinement ({model.structure}) stopped after {info.get('iterations')} "
                     f"iterations without converging (loss {info.get('loss_start', math.nan):.4g} -> "
                     f"{info.get('loss', math.nan):.4g} per sample); raise max_iterations "
                     f"(--max-iterations, now {max_iterations}) or lower the order",
                     AccuracyWarning)


def _never_lose(start, refined, focus: str, d: MimoData, estimation: bool, max_iterations: int,
                second=None):
    """The refined model, or, when it scores lower than its subspace start by ``focus`` on ``d``
    (by more than :data:`FOCUS_TIE`), the model of ``second()`` (PEM in output-error form, which
    minimises the simulation error itself) if that does not, else the subspace start; warns when
    PEM did not converge and when a refinement is dropped."""
    _warn_unconverged(refined, max_iterations)
    where = "estimation" if estimation else "validation"
    before = focus_score(start, focus, d)
    record = {"criterion": focus, "data": where, "subspace_percent": before}
    tried: list[tuple[str, float]] = []
    for candidate in (lambda: refined, second):
        model = None if candidate is None else candidate()
        if model is None:  # no second candidate, or the output-error refinement failed
            continue
        if model is not refined:
            _warn_unconverged(model, max_iterations)
        after = focus_score(model, focus, d)
        tried.append((model.structure, after))
        if after >= before - FOCUS_TIE:
            model.info["focus"] = {**record, "refined_percent": after, "kept": model.structure}
            if model is not refined:
                emit_warning(f"PEM refinement ({refined.structure}) lowered the mean {focus} fit on "
                             f"the {where} data from {before:.2f} % to {tried[0][1]:.2f} %; the "
                             f"{model.structure} refinement ({after:.2f} %) is returned",
                             AccuracyWarning)
            return model
    other = "prediction" if focus == "simulation" else "simulation"
    emit_warning(f"PEM refinement lowered the mean {focus} fit on the {where} data from "
                 f"{before:.2f} % to {', '.join(f'{name} {fit:.2f} %' for name, fit in tried)}: the "
                 f"subspace model is returned, without parameter covariance (--focus {other} judges "
                 f"by the other criterion; --no-refine skips PEM)", AccuracyWarning)
    start.info["focus"] = {**record, "refined_percent": tried[0][1], "kept": "subspace"}
    start.info["pem_rejected"] = refined.info.get("pem", {})
    return start


def _warn_if_detrending_hurt(model, refit, n: int, dt: float, command: str) -> None:
    """Mean detrending assumes the record's means are an operating point (an equilibrium). A mode
    that does not settle within the record (its envelope falls by less than e⁻⁵ over the N
    samples: a near-integrator, a drift) breaks that assumption; then ``refit()`` fits the same
    structure without detrending, and a warning names ``--detrend none`` when that fits the data
    better by more than 10 points (free run)."""
    poles = model.system.poles()
    if not poles.size:
        return
    if model.system.is_discrete:
        rate = -np.log(np.maximum(np.abs(poles), 1e-300)) / dt  # decay rate per second
    else:
        rate = -poles.real
    slowest = float(np.min(rate))
    if not 0.0 < slowest * n * dt < 5.0:
        return
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            other = refit()
        except GripkitError:
            return
    mean_fit, none_fit = float(np.mean(model.fit_percent)), float(np.mean(other.fit_percent))
    if none_fit > mean_fit + 10.0:
        emit_warning(
           f"{command}: removing the means (detrend 'mean', the default) hurt this fit: the "
           f"slowest mode (time constant {1 / slowest:.4g} s) does not settle within the "
           f"{n * dt:.4g} s record, so the output drifts and its mean is no operating point; "
           f"free-run fit {mean_fit:.4g} % with the means removed, {none_fit:.4g} % without; "
           f"use --detrend none (Python: detrend='none')", AccuracyWarning)


def identify_frf(data: Trajectory, *, input, output, detrend: str = "mean", **options):
    """Frequency response of the named columns (:func:`gripkit.sysid.linear.frf` options)."""
    d = mimo_data(data, input, output, detrend, why="frequency-response estimation")
    return frf(d.u, d.y, dt=d.dt, inputs=d.inputs, outputs=d.outputs, **options)


def identify_tf(data: Trajectory, *, input, output, poles: int, zeros: int, detrend: str = "mean"):
    """Continuous-time transfer function of the named columns (:func:`gripkit.sysid.linear.tfest`)."""
    from .tfest import tfest

    d = mimo_data(data, input, output, detrend, why="transfer-function estimation")
    model = tfest(d.u, d.y, poles, zeros, dt=d.dt, u_offset=d.u_offset, y_offset=d.y_offset,
                  **d.signals)
    if detrend == "mean":
        refit = lambda: identify_tf(data, input=input, output=output, poles=poles,  # noqa: E731
                                    zeros=zeros, detrend="none")
        _warn_if_detrending_hurt(model, refit, d.u.shape[0], d.dt, "identify tf")
    return model


def several(*names) -> bool:
    """Whether any of the column specifications names more than one column."""
    return any(len(parse_names(n, "column")) > 1 for n in names)


def identify_arx(data: Trajectory, *, input, output, na: int, nb: int, nk: int = 1, detrend: str = "mean"):
    """MIMO ARX of the named columns (:func:`gripkit.sysid.linear.arx_mimo.arx_mimo`): a
    :class:`~gripkit.sysid.PolynomialModel` of matrix polynomials."""
    d = mimo_data(data, input, output, detrend, why="ARX identification")
    return arx_mimo(d.u, d.y, na, nb, nk, dt=d.dt, u_offset=d.u_offset, y_offset=d.y_offset, **d.signals)


#: the options of method 'ss' with several records (``weighting``: the subspace method, n4sid,
#: moesp or cva, identify()'s own ``method`` being 'ss')
SS_RECORD_OPTIONS = ("order", "horizon", "feedthrough", "refine", "form", "max_iterations",
                     "weighting")


def identify_ss_records(records: list, d: MimoData, u0, y0, options: dict):
    """The state-space model of several records: subspace
    (:func:`gripkit.sysid.linear.subspace.n4sid_records`), then, unless ``refine=False``, PEM with one
    initial state per record (:func:`gripkit.sysid.linear.pem_ss.pem_records`); the refined model is
    returned only when its free-run fit of all records (mean over the outputs) is not below the
    subspace model's, else the subspace model with an AccuracyWarning giving both."""
    from .pem_ss import pem_records
    from .subspace import n4sid_records

    other = sorted(set(options) - set(SS_RECORD_OPTIONS))
    if other:
        raise ArgumentError(f"identify(method='ss'): with several records the options are "
                            f"{', '.join(SS_RECORD_OPTIONS)}, found {', '.join(other)}",
                            hint="pass one trajectory for the other options")
    rng = parse_order(options.get("order"))
    if rng is not None and rng[0] != rng[1]:
        raise ArgumentError(f"identify(method='ss'): with several records the order is one number "
                            f"or None, found the range {options['order']!r}",
                            hint="search the order on one record")
    start = n4sid_records(records, None if rng is None else rng[0],
                          method=options.get("weighting", "n4sid"), horizon=options.get("horizon"),
                          feedthrough=options.get("feedthrough", False), dt=d.dt,
                          u_offset=tuple(map(float, u0)), y_offset=tuple(map(float, y0)),
                          **d.signals)
    if not options.get("refine", True):
        return start
    iters = options.get("max_iterations", 50)
    refined = pem_records(start, records, form=options.get("form", "innovation"),
                          max_iterations=iters)
    if not refined.info["pem"]["converged"]:
        emit_warning(f"identify ss: PEM over the records stopped after {iters} iterations without "
                     f"converging; raise max_iterations", AccuracyWarning)
    before, after = float(np.mean(start.fit_percent)), float(np.mean(refined.fit_percent))
    if after < before:
        emit_warning(f"identify ss: PEM over the records lowered the free-run fit of all records "
                     f"from {before:.4g} % (subspace) to {after:.4g} %; the subspace model is "
                     f"returned", AccuracyWarning)
        return start
    return refined


def identify_tf_records(records: list, d: MimoData, u0, y0, poles: int, zeros: int):
    """The continuous-time transfer function of several records
    (:func:`gripkit.sysid.linear.tfest.tfest_records`) around the operating point (u0, y0)."""
    from .tfest import tfest_records

    return tfest_records(records, poles, zeros, dt=d.dt, u_offset=tuple(map(float, u0)),
                         y_offset=tuple(map(float, y0)), **d.signals)
