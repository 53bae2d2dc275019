"""Identification from a :class:`~gripkit.signals.Trajectory` with several inputs and outputs:
state space (subspace, then PEM), frequency response and continuous-time transfer function.

Column selection by name (``input='a,b'`` or ``['a', 'b']``), the uniform-sampling check, units,
and removal of the operating point (``detrend='mean'``: each channel's mean, recorded as the
model's offsets) as in :func:`gripkit.sysid.identify`.

Order search (``order='2:8'``): every order of the range is fitted from one factorisation and
ranked by the free-run fit on ``validate`` data (mean over outputs, x0 estimated) when given,
the lowest order within 0.05 fit points of the best winning (higher orders that fit the noise tie),
otherwise by Akaike's criterion of the innovation predictor,
``AIC = N log det Λ̂ + 2 d``, d = n(m + 2p) (+ pm with D) free parameters. When the best order
of a range of three or more orders sits on its edge, the search goes on past that edge, one
order at a time, up to :data:`WIDEN_STEPS` orders (and the largest order the factorisation
holds); a best order still on an edge is warned about: the true order may lie outside it.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from ...errors import (AccuracyWarning, ArgumentError, DataError, GripkitError, GripkitWarning,
                      IdentificationError, emit_warning)
from ...progress import status, track
from ...signals.trajectory import Trajectory
from .arx_mimo import arx_mimo
from .frf import frf
from .linear_model import deviation_compare
from .ss_bootstrap import (BOOTSTRAP_SEED, bootstrap_covariance, bootstrap_covariance_records,
                           check_bootstrap)
from ..checks import STEP_CHANGES, step_like
from ..io_data import IOData, parse_names, validation_data

__all__ = ["mimo_data", "identify_ss", "identify_frf", "identify_tf", "identify_arx", "several",
           "parse_names", "parse_order"]


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
            raise DataError("order: expected N or LO:HI (positive integers), "
                            f"found {order!r}") from None
    if lo < 1 or hi < lo:
        raise DataError(f"order: expected 1 <= LO <= HI, found {order!r}")
    return lo, hi


def mimo_data(data: Trajectory, inputs, outputs, detrend: str = "mean",
              why: str = "identification") -> IOData:
    """The named columns as :class:`~gripkit.sysid.io_data.IOData` with the constant and scale
    checks (these estimators form unscaled sums of squares); ``detrend`` 'mean' or 'none' (a line
    per column would leave the model no operating point)."""
    if detrend not in ("mean", "none"):
        raise DataError(f"detrend: expected 'mean' or 'none', found {detrend!r}")
    return IOData.from_trajectory(data, inputs, outputs, detrend=detrend, why=why, checks=True)


def _validation_fit(model, vd: IOData) -> list[float] | None:
    if not model.stable:
        return None
    return deviation_compare(model, vd.u, vd.y, vd.dt).fit_percent


def _aic(model, d: IOData) -> float:
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


def identify_ss(data: Trajectory, *, input, output, order=None, method: str = "n4sid",
                form: str = "innovation",
                refine: bool = True, validate: Trajectory | None = None, detrend: str = "mean",
                horizon: int | None = None, feedthrough: bool = False, progress: bool = False,
                focus: str = "simulation", max_iterations: int = 50,
                bootstrap_replicates: int | None = None, bootstrap_seed: int = BOOTSTRAP_SEED):
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
    scores. PEM stopping after ``max_iterations`` without converging is warned about too.

    A subspace model returned in place of the refinement (it scored higher, or PEM failed), and
    the subspace model of ``refine=False``, carry the σ of a parametric bootstrap of the subspace
    estimate (:func:`~gripkit.sysid.linear.ss_bootstrap.bootstrap_covariance`:
    ``bootstrap_replicates`` records, the model's free run plus disturbances drawn like its
    residuals, refitted alike; default by the record's length, 100 up to 20 000 samples, 30 from
    66 667: order 4 took 0.5 s at N = 1e4 and 2 s at N = 1e5 on an AMD EPYC (2.5 s and 6.7 s
    with its 2 cores shared and loaded), growing with N beyond; ``0``: no bootstrap, the
    subspace model without σ; ``bootstrap_seed``, default
    :data:`~gripkit.sysid.linear.ss_bootstrap.BOOTSTRAP_SEED`, seeds the draws),
    with ``info['covariance']`` saying so, where a refined model carries PEM's covariance."""
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
    bootstrap_replicates = check_bootstrap(bootstrap_replicates, bootstrap_seed,
                                           "bootstrap_replicates")
    d = mimo_data(data, input, output, detrend, why="state-space identification")
    vd = None if validate is None else validation_data(validate, d)
    rng = parse_order(order)
    n_hi = rng[1] if rng else DEFAULT_MAX_ORDER
    k = default_horizon(n_hi, d.y.shape[1]) if horizon is None else int(horizon)
    report = status if progress else (lambda line: None)
    report(f"{method}: {d.u.shape[0]} samples, {len(d.inputs)} input(s), {len(d.outputs)} "
           f"output(s), horizon {k}")
    fac = subspace_factor(d.u, d.y, horizon=k, method=method)
    extras: dict = {}
    build = lambda n: from_factor(  # noqa: E731
        fac, n, dt=d.dt, feedthrough=feedthrough, signals=d.signals)
    if rng is None:
        n = select_order(fac.s, min(n_hi, fac.s.size - 1))
        model = build(n)
        model.info["order_selection"] = "singular values above the noise floor"
    elif rng[0] == rng[1]:
        model = build(rng[0])
        model.info["order_selection"] = "given"
    if focus not in FOCUS:
        raise DataError(f"focus: expected one of {', '.join(FOCUS)}, found {focus!r}")
    ranked = None
    if rng is not None and rng[0] != rng[1]:
        ranked, extras["criterion"] = _order_search(
            lambda n: _order_row(build, n, d, vd), "aic" if vd is None else "validation_fit",
            rng, min(fac.s.size - 1, (k - 1) * d.y.shape[1]), progress)
        model = ranked[0][1]
    model = model.replace(u_offset=d.u_offset, y_offset=d.y_offset)
    if refine and ranked is not None:  # the search ranks the refined models it returns
        ranked = [(r, c.replace(u_offset=d.u_offset, y_offset=d.y_offset)) for r, c in ranked]
        model, ranked = _refine_top(
            ranked, lambda c: _refine(c, d, vd, form, focus, max_iterations, progress)[0],
            lambda m: focus_score(m, focus, d if vd is None else vd),
            None if vd is not None else lambda m: _aic(m, d), progress,
            REFINE_TOP if vd is not None else 1)
    elif refine:
        report(f"PEM refinement ({form} form) of the order-{model.order} model")
        model = _refine(model, d, vd, form, focus, max_iterations, progress,
                        sigma=bootstrap_replicates != 0)[0]
    if ranked is not None:
        extras["search"] = [r for r, _ in ranked]
    if model.structure == method and bootstrap_replicates != 0:  # subspace: σ by bootstrap
        model = _bootstrap_sigma(model, d, k, method, feedthrough, detrend,
                                 (bootstrap_replicates, bootstrap_seed), progress, refine)
    warn_if_stabilised(model)
    if detrend == "mean":
        refit = lambda: identify_ss(  # noqa: E731
            data, input=input, output=output, order=model.order, method=method, form=form,
            refine=False, detrend="none", horizon=horizon, feedthrough=feedthrough,
            bootstrap_replicates=0)[0]
        model = after_mean_detrending(model, d.u, refit, "identify ss", drift=lambda step: (
            _warn_if_detrending_hurt(model, refit, d.u.shape[0], d.dt, "identify ss",
                                     without="without (subspace model, not refined)", step=step)))
    if vd is not None:
        extras["validation_fit_percent"] = _validation_fit(model, vd)
    return model, extras


def _bootstrap_sigma(model, d: IOData, k: int, method: str, feedthrough: bool, detrend: str,
                     options: tuple, progress: bool, refined: bool = True):
    """The subspace ``model`` (kept in place of PEM's, or ``refined`` False: PEM skipped, which
    ``info['refined']`` then records) with the σ of a parametric bootstrap of the same estimation
    (order, ``method``, horizon ``k``, ``feedthrough``, ``detrend``) on the deviation data ``d``;
    ``options``: (replicates or None, seed)."""
    from .subspace import from_factor, subspace_factor

    n = model.order
    replicates, seed = options
    refit = lambda u, y: from_factor(  # noqa: E731
        subspace_factor(u, y, horizon=k, method=method), n, dt=d.dt, feedthrough=feedthrough)
    if not refined:
        model = model.replace(info={**model.info, "refined": False})
    return bootstrap_covariance(model, d.u, d.y, refit, replicates=replicates, seed=seed,
                                estimator=f"{method} (order {n}, horizon {k})",
                                detrend=detrend, feedthrough=feedthrough,
                                progress=progress)


#: orders an order search adds past an edge of its range where the best order sits
WIDEN_STEPS = 3


def _order_row(build, n: int, d: IOData, vd: IOData | None):
    """(row of the search table, subspace model) of order ``n``; score: the mean validation
    fit with ``vd``, else −AIC."""
    cand = build(n)
    row = {"order": n, "fit_percent": cand.fit_percent, "aic": _aic(cand, d)}
    if vd is not None:
        vf = _validation_fit(cand, vd)
        row["validation_fit_percent"] = vf
        row["score"] = -math.inf if vf is None else float(np.mean(vf))
    else:
        row["score"] = -row["aic"]
    return row, cand


def _ranked(found: dict, parsimony: bool) -> list:
    """The (row, model) pairs best first; ``parsimony`` (validation fits): the lowest order
    within 0.05 fit points of the best first (higher orders that fit the noise tie)."""
    rows = sorted(found.values(), key=lambda rc: -rc[0]["score"])
    if parsimony:
        top = rows[0][0]["score"]
        band = [rc for rc in rows if rc[0]["score"] >= top - 0.05]
        pick = min(band, key=lambda rc: rc[0]["order"])
        for row, _ in rows:  # the higher orders that tie with the pick: not worth a PEM
            row["tie"] = any(row is r for r, _ in band) and row is not pick[0]
        rows.remove(pick)
        rows.insert(0, pick)
    return rows


def _order_search(row_of, criterion: str, rng: tuple, n_cap: int, progress: bool):
    """Every order of ``rng`` ranked (module doc; ``row_of(n)`` -> (row, model), by ``criterion``,
    'validation_fit' or 'aic'); while the best sits on an edge of the orders tried, up to
    :data:`WIDEN_STEPS` orders past it (at most ``n_cap``, at least 1) are added. A best order
    still on an edge is warned about. Returns (the (row, model) pairs best first, criterion)."""
    parsimony = criterion == "validation_fit"
    found = {n: row_of(n) for n in track(range(rng[0], rng[1] + 1), description="order search",
                                         enabled=progress)}
    rows = _ranked(found, parsimony)
    for _ in range(WIDEN_STEPS):
        best, lo, hi = rows[0][0]["order"], min(found), max(found)
        nxt = hi + 1 if best == hi and hi < n_cap else lo - 1 if best == lo and lo > 1 else None
        if nxt is None or hi - lo < 2:
            break
        try:
            found[nxt] = row_of(nxt)
        except GripkitError:  # the factorisation does not support that order
            break
        rows = _ranked(found, parsimony)
    best_row, model = rows[0]
    lo, hi = min(found), max(found)
    tried = f"{lo}:{hi}" if (lo, hi) == rng else f"{lo}:{hi} ({rng[0]}:{rng[1]} widened)"
    model.info["order_selection"] = f"best of {tried} by {criterion}"
    best = best_row["order"]
    if (best == hi or best == lo > 1) and hi - lo >= 2:  # below order 1 there is nothing
        emit_warning(f"order search: the best order {best} lies on the edge of the "
                     f"searched range {tried}; the true order may lie outside it, widen the range",
                     GripkitWarning)
    return rows, criterion


#: the best orders of a search with a validation record that PEM refines, ranked again by their
#: focus fit on it; without one only the best order is refined (on the estimation data the
#: refined models could only be ranked by Akaike's criterion again, and the PEM of the
#: overparametrised runners-up costs many times that of the best)
REFINE_TOP = 3


def _refine_top(ranked: list, refine_one, fit_of, aic_of, progress: bool, n_top: int):
    """``refine_one(model)`` (PEM that never loses by the focus) of the ``n_top`` best orders of
    a search (the higher orders that tie with the best on the validation fit, ``tie``
    in their rows, left out: they fit the noise, and their PEM costs most), ranked again: by
    ``fit_of(model)`` (the focus fit on validation data;
    the lowest order within :data:`FOCUS_TIE` of the best first) when ``aic_of`` is None, else
    by ``aic_of(model)`` (on the estimation data a higher order always fits better: Akaike's
    criterion weighs the fit against the parameters). Each row gets ``refined_percent`` (the
    focus fit), ``kept`` (the structure returned for that order) and ``refined_aic`` when ranked
    by it. Only the returned model's warnings are emitted. Returns (best model, the ranking:
    refined orders first, then the others as the search ranked them)."""
    chosen = [rc for rc in ranked if not rc[0].get("tie")][:n_top]
    rest = [rc for rc in ranked if not any(rc is c for c in chosen)]
    top = []
    for row, cand in chosen:
        if progress:
            status(f"PEM refinement of the order-{cand.order} model")
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            model = refine_one(cand)
        row = {**row, "refined_percent": fit_of(model), "kept": model.structure}
        if aic_of is not None:
            row["refined_aic"] = aic_of(model)
        top.append((row, model, caught))
    if aic_of is None:
        best = max(r["refined_percent"] for r, _, _ in top)
        top.sort(key=lambda rmc: (-rmc[0]["refined_percent"], rmc[0]["order"]))
        pick = min((rmc for rmc in top if rmc[0]["refined_percent"] >= best - FOCUS_TIE),
                   key=lambda rmc: rmc[0]["order"])
        top.remove(pick)
        top.insert(0, pick)
    else:
        top.sort(key=lambda rmc: (rmc[0]["refined_aic"], rmc[0]["order"]))
    pick = top[0]
    for w in pick[2]:
        emit_warning(str(w.message), w.category)
    model = pick[1]
    by = "Akaike's criterion" if aic_of is not None else "the validation fit"
    model.info["order_selection"] = (f"{ranked[0][1].info['order_selection']}; the best "
                                     f"{len(top)} refined by PEM and ranked by {by}")
    return model, [(r, m) for r, m, _ in top] + rest


#: the criteria by which identify_ss keeps the better of the subspace and the refined model
FOCUS = ("simulation", "prediction")


def focus_score(model, focus: str, d: IOData) -> float:
    """Mean over outputs of the fit (%) by which ``focus`` judges ``model`` on the deviation data
    ``d``: ``'simulation'``, the free-run fit with x0 estimated (:data:`VALIDATION_FIT`; −inf for
    an unstable model); ``'prediction'``, the one-step-ahead fit of the innovation predictor
    ``x̂⁺ = A x̂ + B u + K (y − C x̂ − D u)`` from its x0 estimated by least squares
    (:func:`~.pem_ss.predictor_x0`; −inf when A − K C is unstable)."""
    if focus == "simulation":
        if not model.stable:
            return -math.inf
        return float(np.mean(deviation_compare(model, d.u, d.y, d.dt).fit_percent))
    from .pem_ss import predictor_x0

    ss = model.system
    n, p = ss.n_states, ss.n_outputs
    K = np.zeros((n, p)) if model.K is None else model.K
    if n and np.max(np.abs(np.linalg.eigvals(ss.A - K @ ss.C))) >= 1.0:
        return -math.inf
    _, e = predictor_x0(ss.A, ss.B, ss.C, ss.D, K, d.u, d.y)
    den = np.linalg.norm(d.y - d.y.mean(axis=0), axis=0)
    return float(np.mean(100.0 * (1.0 - np.linalg.norm(e, axis=0) / den)))


def _refine(start, d: IOData, vd: IOData | None, form: str, focus: str, max_iterations: int,
            progress: bool = False, sigma: bool = False):
    """PEM in ``form`` from the subspace model ``start``, kept only when it does not lose by
    ``focus`` (:func:`_never_lose`; PEM in oe form as the second candidate for the simulation
    focus); ``(model, refined?)``. A PEM that the data cannot determine returns ``start`` with a
    warning; ``sigma``: a ``start`` kept is the model returned and gets the bootstrap's σ, which
    the warnings then name (:func:`_kept_note`)."""
    from .pem_ss import pem

    try:
        model = pem(start, u=d.u, y=d.y, form=form, max_iterations=max_iterations,
                    progress=progress)
    except IdentificationError as exc:  # an order the data do not support in full
        emit_warning(f"PEM refinement of the order-{start.order} {start.structure} model failed "
                     f"({exc.message}); {_kept_note(sigma)} (lower the order, or --no-refine "
                     f"to skip PEM)", AccuracyWarning)
        return start, False
    oe = None
    if form == "innovation" and focus == "simulation":  # PEM in oe form minimises the free-run
        def oe():                                       # error itself: the second candidate
            try:
                return pem(start, u=d.u, y=d.y, form="oe", max_iterations=max_iterations,
                           progress=progress)
            except IdentificationError:
                return None
    return (_never_lose(start, model, focus, d if vd is None else vd, vd is None, max_iterations,
                        oe, sigma), True)


#: fit points (%) within which a refined model counts as scoring as well as its start: the scores
#: are means of fits computed in floating point, and PEM's σ is worth more than a 1e-5 % tie
FOCUS_TIE = 0.01


def _warn_unconverged(model, max_iterations: int) -> None:
    info = model.info.get("pem", {})
    if not info.get("converged", True):
        emit_warning(f"PEM refinement ({model.structure}) stopped after {info.get('iterations')} "
                     "iterations without converging (loss "
                     f"{info.get('loss_start', math.nan):.4g} -> "
                     f"{info.get('loss', math.nan):.4g} per sample); raise max_iterations "
                     f"(--max-iterations, now {max_iterations}) or lower the order",
                     AccuracyWarning)


def _kept_note(sigma: bool) -> str:
    """What a warning that drops PEM's model says of the subspace model kept: its σ from the
    bootstrap only when it is the model returned and gets that σ (``sigma``; not with
    ``bootstrap_replicates=0``, nor for a candidate of an order search)."""
    return ("the subspace model is returned, with σ from a parametric bootstrap of the subspace "
            "estimate where its replicates allow, not PEM's covariance" if sigma else
            "the subspace model is kept (without PEM's covariance)")


def _never_lose(start, refined, focus: str, d: IOData, estimation: bool, max_iterations: int,
                second=None, sigma: bool = False):
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
                emit_warning(f"PEM refinement ({refined.structure}) lowered the mean "
                             f"{focus} fit on "
                             f"the {where} data from {before:.2f} % to {tried[0][1]:.2f} %; the "
                             f"{model.structure} refinement ({after:.2f} %) is returned",
                             AccuracyWarning)
            return model
    other = "prediction" if focus == "simulation" else "simulation"
    emit_warning(f"PEM refinement lowered the mean {focus} fit on the {where} data from "
                 f"{before:.2f} % to "
                 f"{', '.join(f'{name} {fit:.2f} %' for name, fit in tried)}: "
                 f"{_kept_note(sigma)} (--focus {other} judges "
                 f"by the other criterion; --no-refine skips PEM)", AccuracyWarning)
    start.info["focus"] = {**record, "refined_percent": tried[0][1], "kept": "subspace"}
    start.info["pem_rejected"] = refined.info.get("pem", {})
    return start


def _warn_if_detrending_hurt(model, refit, n: int, dt: float, command: str,
                             without: str = "without", step: bool = False) -> None:
    """Mean detrending assumes the record's means are an operating point (an equilibrium). A mode
    that does not settle within the record (its envelope falls by less than e⁻⁵ over the N
    samples: a near-integrator, a drift) breaks that assumption; then ``refit()`` fits the same
    structure without detrending, and a warning names ``--detrend none`` when that fits the data
    better by more than 10 points (free run). For ``identify ss`` the refit is the subspace model
    alone (no PEM): a lower bound on what the data without detrending give, at a fraction of the
    cost of a second refinement; ``without`` names what was refitted in the warning. ``step``
    (a step input, :func:`step_like`, whose mean is no operating point either): refit whatever
    the modes."""
    poles = model.system.poles()
    if not poles.size:
        return
    if model.system.is_discrete:
        rate = -np.log(np.maximum(np.abs(poles), 1e-300)) / dt  # decay rate per second
    else:
        rate = -poles.real
    slowest = float(np.min(rate))
    if not step and not 0.0 < slowest * n * dt < 5.0:
        return
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            other = refit()
        except GripkitError:
            return
    mean_fit, none_fit = float(np.mean(model.fit_percent)), float(np.mean(other.fit_percent))
    if none_fit > mean_fit + 10.0:
        why = (f"the input is a step (piecewise constant, at most {STEP_CHANGES} level "
               "changes), whose mean is no operating point" if step else
               f"the slowest mode (time constant {1 / slowest:.4g} s) does not settle within the "
               f"{n * dt:.4g} s record, so the output drifts and its mean is no operating point")
        emit_warning(
           f"{command}: removing the means (detrend 'mean', the default) hurt this fit: {why}; "
           f"free-run fit {mean_fit:.4g} % with the means removed, {none_fit:.4g} % {without}; "
           f"use --detrend none (Python: detrend='none')", AccuracyWarning)


def keep_better_without_detrending(model, refit, command: str, score):
    """``model`` was fitted on the mean-detrended data of a step input (:func:`step_like`):
    ``refit()`` fits the same structure on the data as they are, and the one with the higher
    free-run fit ``score(model)`` (the fit of :meth:`LinearModel.compare`, initial state by least
    squares) is returned; an :class:`AccuracyWarning` says so when that is the refit."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            other = refit()
        except GripkitError:
            return model
    mean_fit, none_fit = score(model), score(other)
    if not none_fit > mean_fit:
        return model
    emit_warning(
        f"{command}: the input is a step (piecewise constant, at most {STEP_CHANGES} level "
        f"changes): its mean is no operating point, and removing the means (detrend 'mean', the "
        f"default) biased this fit: free-run fit {mean_fit:.4g} % with the means removed, "
        f"{none_fit:.4g} % without; the model fitted without detrending is returned "
        f"(--detrend none, Python: detrend='none', fits it directly)", AccuracyWarning)
    return other


def after_mean_detrending(model, u, refit, command: str, score=None, drift=None):
    """The one rule for ``model`` fitted with the means removed (detrend 'mean') from the input
    ``u``: a step input (:func:`step_like`) is never at its mean, so ``refit()`` (the same
    structure on the data as they are) is ranked against ``model`` by ``score`` and the better is
    returned (:func:`keep_better_without_detrending`); any other input gets ``drift(False)``, the
    family's warning for a mode that does not settle, where it has one. A family without
    ``score`` (ss: its refit is the subspace model alone, no peer to rank) keeps ``model`` and
    hands a step to ``drift(True)``, which then warns whatever the modes."""
    step = step_like(u)
    if step and score is not None:
        return keep_better_without_detrending(model, refit, command, score)
    if drift is not None:
        drift(step)
    return model


def identify_frf(data: Trajectory, *, input, output, detrend: str = "mean", **options):
    """Frequency response of the named columns (:func:`gripkit.sysid.linear.frf` options)."""
    d = mimo_data(data, input, output, detrend, why="frequency-response estimation")
    return frf(d.u, d.y, dt=d.dt, inputs=d.inputs, outputs=d.outputs,
               input_units=d.input_units, output_units=d.output_units, **options)


def identify_tf(data: Trajectory, *, input, output, poles: int, zeros: int, detrend: str = "mean"):
    """Continuous-time transfer function of the named columns
    (:func:`gripkit.sysid.linear.tfest`)."""
    from .tfest import tfest

    d = mimo_data(data, input, output, detrend, why="transfer-function estimation")
    model = tfest(d.u, d.y, poles, zeros, dt=d.dt, u_offset=d.u_offset, y_offset=d.y_offset,
                  **d.signals)
    if detrend == "mean":
        refit = lambda: identify_tf(data, input=input, output=output, poles=poles,  # noqa: E731
                                    zeros=zeros, detrend="none")
        return after_mean_detrending(
            model, d.u, refit, "identify tf", lambda m: float(np.mean(m.fit_percent)),
            lambda _: _warn_if_detrending_hurt(model, refit, d.u.shape[0], d.dt, "identify tf"))
    return model


def several(*names) -> bool:
    """Whether any of the column specifications names more than one column."""
    return any(len(parse_names(n, "column")) > 1 for n in names)


def identify_arx(data: Trajectory, *, input, output, na: int, nb: int, nk: int = 1,
                 detrend: str = "mean"):
    """MIMO ARX of the named columns (:func:`gripkit.sysid.linear.arx_mimo.arx_mimo`): a
    :class:`~gripkit.sysid.PolynomialModel` of matrix polynomials."""
    d = mimo_data(data, input, output, detrend, why="ARX identification")
    model = arx_mimo(d.u, d.y, na, nb, nk, dt=d.dt, u_offset=d.u_offset, y_offset=d.y_offset,
                     **d.signals)
    if detrend == "mean":
        refit = lambda: identify_arx(data, input=input, output=output, na=na,  # noqa: E731
                                     nb=nb, nk=nk, detrend="none")
        return after_mean_detrending(model, d.u, refit, "identify arx",
                                     lambda m: compare_score(m, data))
    return model


def compare_score(model, data) -> float:
    """The mean over the outputs of the fit of ``gripkit compare`` (:meth:`compare`: the model's
    offsets, x0 by least squares) of ``model`` on the trajectory ``data``; −inf where it has
    none (an unstable model, a record whose ‖y − ȳ‖ underflows)."""
    try:
        fits = model.compare(data).fit_percent
    except DataError:
        return -math.inf
    return -math.inf if any(f is None for f in fits) else float(np.mean(fits))


#: the options of method 'ss' with several records (``weighting``: the subspace method, n4sid,
#: moesp or cva, identify()'s own ``method`` being 'ss')
SS_RECORD_OPTIONS = ("order", "horizon", "feedthrough", "refine", "form", "max_iterations",
                     "weighting", "focus", "progress", "bootstrap_replicates", "bootstrap_seed")


def identify_ss_records(records: list, d: IOData, u0, y0, options: dict, demean: bool = False):
    """The state-space model of several records: subspace
    (:func:`gripkit.sysid.linear.subspace.n4sid_records`), then, unless ``refine=False``, PEM with
    one initial state per record (:func:`gripkit.sysid.linear.pem_ss.pem_records`), kept only when
    it does not lose to its start by ``focus`` (:func:`records_score` over all records; else the
    subspace model with an AccuracyWarning giving both). ``order='LO:HI'`` searches the order as
    for one record: ranked by Akaike's criterion of the free run over all records,
    widened past an edge, the best order refined (``info['search']``). A subspace model returned
    (kept, or ``refine=False``) carries the σ of a parametric bootstrap of the estimation over
    all records (:func:`_records_sigma`; ``bootstrap_replicates``, ``bootstrap_seed`` as for
    one record, the count by all records' samples together); ``demean``: the records are
    deviations from the mean of all their samples (detrend 'mean'), as the replicates are."""
    from .subspace import n4sid_records

    other = sorted(set(options) - set(SS_RECORD_OPTIONS))
    if other:
        raise ArgumentError(f"identify(method='ss'): with several records the options are "
                            f"{', '.join(SS_RECORD_OPTIONS)}, found {', '.join(other)}",
                            hint="pass one trajectory for the other options")
    focus, progress = options.get("focus", "simulation"), options.get("progress", False)
    if focus not in FOCUS:
        raise DataError(f"focus: expected one of {', '.join(FOCUS)}, found {focus!r}")
    options = {**options, "bootstrap_replicates": check_bootstrap(
        options.get("bootstrap_replicates"), options.get("bootstrap_seed", BOOTSTRAP_SEED),
        "bootstrap_replicates")}
    rng = parse_order(options.get("order"))

    def fit(n):
        return n4sid_records(records, n, method=options.get("weighting", "n4sid"),
                             horizon=options.get("horizon"),
                             feedthrough=options.get("feedthrough", False), dt=d.dt,
                             u_offset=tuple(map(float, u0)), y_offset=tuple(map(float, y0)),
                             **d.signals)

    refine = lambda m: _refine_records(m, records, options, focus)  # noqa: E731
    score = lambda m: records_score(m, records, focus)  # noqa: E731
    sigma = lambda m: _records_sigma(m, records, options, d.dt, demean)  # noqa: E731
    if rng is None or rng[0] == rng[1]:
        start = fit(None if rng is None else rng[0])
        return sigma(refine(start) if options.get("refine", True) else start)
    # the subspace models are ranked by their free run: the innovation gain a subspace fit of
    # several records gives is too rough to rank orders by; PEM's gains rank the refined ones
    row_of = lambda n: _records_row(fit(n), records, "simulation")  # noqa: E731
    ranked, criterion = _order_search(row_of, "aic", rng, rng[1] + WIDEN_STEPS, progress)
    if options.get("refine", True):
        model, ranked = _refine_top(ranked, refine, score,
                                    lambda m: _records_row(m, records, focus)[0]["aic"],
                                    progress, 1)
    else:
        model = ranked[0][1]
    model = sigma(model)
    return model.replace(info={**model.info, "search": [r for r, _ in ranked],
                               "search_criterion": criterion})


def _records_sigma(model, records: list, options: dict, dt: float, demean: bool):
    """``model`` with the σ of a parametric bootstrap of the subspace estimation over all
    ``records`` (:func:`~.ss_bootstrap.bootstrap_covariance_records`: the same order, weighting,
    horizon and feedthrough) when it is the subspace model (kept in place of PEM's, or
    ``refine=False``, which ``info['refined']`` then records) and ``bootstrap_replicates`` is not
    0; else ``model`` as it is."""
    from .subspace import n4sid_records

    weighting, replicates = options.get("weighting", "n4sid"), options.get("bootstrap_replicates")
    if model.structure != weighting or replicates == 0:
        return model
    if not options.get("refine", True):
        model = model.replace(info={**model.info, "refined": False})
    n, k, feedthrough = model.order, model.info["horizon"], options.get("feedthrough", False)
    refit = lambda us, ys: n4sid_records(  # noqa: E731
        list(zip(us, ys)), n, method=weighting, horizon=k, feedthrough=feedthrough, dt=dt)
    return bootstrap_covariance_records(
        model, records, refit, estimator=f"{weighting} (order {n}, horizon {k})",
        replicates=replicates, seed=options.get("bootstrap_seed", BOOTSTRAP_SEED), demean=demean,
        feedthrough=feedthrough, progress=options.get("progress", False))


def records_score(model, records: list, focus: str) -> float:
    """Mean over outputs of the fit (%) of all records together by ``focus``
    (:func:`focus_score` for several records): each record's errors from its own initial state
    estimated by least squares (:func:`~.pem_ss.predictor_x0`; K = 0 for 'simulation', the
    free run), ``100 (1 − √Σ_i‖e_i‖² / √Σ_i‖y_i − ȳ_i‖²)``; −inf for an unstable run."""
    from .pem_ss import predictor_x0

    ss = model.system
    n, p = ss.n_states, ss.n_outputs
    K = np.zeros((n, p)) if focus == "simulation" or model.K is None else model.K
    if n and np.max(np.abs(np.linalg.eigvals(ss.A - K @ ss.C))) >= 1.0:
        return -math.inf
    num = den = 0.0
    for u, y in records:
        u, y = _columns(u), _columns(y)
        _, e = predictor_x0(ss.A, ss.B, ss.C, ss.D, K, u, y)
        num = num + np.sum(e * e, axis=0)
        den = den + np.sum((y - np.mean(y, axis=0)) ** 2, axis=0)
    return float(np.mean(100.0 * (1.0 - np.sqrt(num) / np.sqrt(den))))


def _columns(x) -> np.ndarray:
    """A record's signal as float64 columns (N, k) (a 1-D array is one column)."""
    x = np.asarray(x, dtype=np.float64)
    return np.ascontiguousarray(x.reshape(x.shape[0], -1))


def _records_row(model, records: list, focus: str):
    """(row, model) of a records order search: ``AIC = ΣN log det Λ̂ + 2 d`` over all records,
    each from its least-squares initial state, of the errors ``focus`` judges: the free run
    ('simulation'; d = n (m + p + R) for R records) or the innovation predictor ('prediction';
    d = n (m + 2p + R)), + pm with D."""
    from .pem_ss import predictor_x0

    ss = model.system
    n, p, m = ss.n_states, ss.n_outputs, ss.n_inputs
    innovation = focus == "prediction" and model.K is not None
    K = model.K if innovation else np.zeros((n, p))
    es = [predictor_x0(ss.A, ss.B, ss.C, ss.D, K, _columns(u), _columns(y))[1]
          for u, y in records]
    e = np.vstack(es)
    N = e.shape[0]
    sign, logdet = np.linalg.slogdet(e.T @ e / N)
    k = n * (m + p + (p if innovation else 0) + len(records)) + (p * m if np.any(ss.D) else 0)
    aic = float(N * logdet + 2 * k) if sign > 0 and np.isfinite(logdet) else math.inf
    return {"order": n, "fit_percent": model.fit_percent, "aic": aic, "score": -aic}, model


def _refine_records(start, records: list, options: dict, focus: str):
    """PEM over the records (:func:`~.pem_ss.pem_records`) from ``start``, returned only when it
    does not lose to ``start`` by ``focus`` (:func:`records_score`, within :data:`FOCUS_TIE`)."""
    from .pem_ss import pem_records

    iters = options.get("max_iterations", 50)
    rng = parse_order(options.get("order"))  # a candidate of an order search gets no σ here
    sigma = options.get("bootstrap_replicates") != 0 and (rng is None or rng[0] == rng[1])
    refined = pem_records(start, records, form=options.get("form", "innovation"),
                          max_iterations=iters, progress=options.get("progress", False))
    if not refined.info["pem"]["converged"]:
        emit_warning(f"identify ss: PEM over the records stopped after {iters} iterations without "
                     f"converging; raise max_iterations", AccuracyWarning)
    before = records_score(start, records, focus)
    after = records_score(refined, records, focus)
    record = {"criterion": focus, "data": "estimation", "subspace_percent": before,
              "refined_percent": after}
    if after < before - FOCUS_TIE:
        emit_warning(f"identify ss: PEM over the records lowered the mean {focus} fit of all "
                     f"records from {before:.4g} % (subspace) to {after:.4g} %; "
                     f"{_kept_note(sigma)}", AccuracyWarning)
        return start.replace(info={**start.info, "focus": {**record, "kept": "subspace"}})
    return refined.replace(info={**refined.info, "focus": {**record, "kept": refined.structure}})


def identify_tf_records(records: list, d: IOData, u0, y0, poles: int, zeros: int):
    """The continuous-time transfer function of several records
    (:func:`gripkit.sysid.linear.tfest.tfest_records`) around the operating point (u0, y0)."""
    from .tfest import tfest_records

    return tfest_records(records, poles, zeros, dt=d.dt, u_offset=tuple(map(float, u0)),
                         y_offset=tuple(map(float, y0)), **d.signals)
