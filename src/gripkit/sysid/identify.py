"""One entry point for identifying a linear model from a :class:`~gripkit.signals.Trajectory`.

>>> import numpy as np
>>> from gripkit import Trajectory
>>> from gripkit.sysid import identify
>>> rng = np.random.default_rng(1)
>>> u = 0.85 + 0.1 * rng.standard_normal(2000)          # valve current around 850 mA (A)
>>> y = np.zeros(2000)
>>> for t in range(3, 2000):
...     y[t] = 1.8732*y[t-1] - 0.8996*y[t-2] + 195.0*(u[t-2]-0.85) - 227.6*(u[t-3]-0.85)
>>> tr = Trajectory.uniform(dt=0.005, current=u, force=y, units={"current": "A", "force": "N"})
>>> m = identify(tr, "arx", input="current", output="force", na=2, nb=2, nk=2)
>>> m.label, m.dt, m.parameters["b2"].unit
('ARX [2 2 2]', 0.005, 'N/A')

The array functions (:func:`~gripkit.sysid.linear.arx`, :func:`~gripkit.sysid.linear.armax`,
:func:`~gripkit.sysid.linear.oe`, :func:`~gripkit.sysid.linear.rls`,
:func:`~gripkit.sysid.structure_search`)
take the signals as they are; :func:`identify` adds what a data file needs: column selection,
the uniform-sampling check, the sampling rate, units, and removal of the operating point
(``detrend='mean'`` by default: an ARX model has no constant term, so an input centred on 850 mA
would otherwise bias every coefficient).
"""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import math
import warnings

import numpy as np

from ..arguments import check_keywords, entry_point, keyword_names
from ..errors import (AccuracyWarning, ArgumentError, DataError, GripkitError, GripkitWarning,
                      IdentificationError, emit_warning)
from ..signals.trajectory import Trajectory
from .checks import LINEAR_ORDERS, check_channels_vary, operating_point_remedy
from .io_data import (IOData, check_scale, io_data, parse_names, records_provenance,
                      validation_data)
from .linear import identify_mimo
from .linear.armax import armax, armax_records
from .linear.arx import arx, arx_records
from .linear.arx_mimo import arx_mimo_records
from .linear.frf import frf
from .linear.oe import oe, oe_records
from .linear.search import parse_range, structure_search

__all__ = ["IOData", "io_data", "identify", "identify_records", "method_options", "METHODS",
           "with_provenance"]

METHODS = ("arx", "armax", "oe", "rls", "search", "ss", "frf", "tf", "step", "narx", "hw",
           "hysteresis", "nlss")


def _polynomial_fit(method: str, io: IOData, orders: tuple, options: dict):
    """ARX, ARMAX or OE of ``io`` with ``orders`` = (na, nb, nc, nf, nk)."""
    na, nb, nc, nf, nk = orders
    if method == "arx":
        return arx(io.u1, io.y1, na, nb, nk, dt=io.dt, **io.keywords, **options)
    if method == "armax":
        return armax(io.u1, io.y1, na, nb, nc, nk, dt=io.dt, **io.keywords, **options)
    return oe(io.u1, io.y1, nb, nf, nk, dt=io.dt, **io.keywords, **options)


def _finite_fit(model):
    """``model`` (ARX, ARMAX, OE) when its θ and σ are finite, else the IdentificationError: such
    a fit comes from samples the estimator cannot square (a corrupt value of 1e300 among values
    of order one), not from the system."""
    theta = np.asarray(model.theta, dtype=np.float64)
    std = np.asarray(model.theta_std, dtype=np.float64)
    if np.isfinite(theta).all() and np.isfinite(std).all():
        return model
    raise IdentificationError(
        f"{model.label}: the fit gives parameters or σ that are not finite (θ up to "
        f"{np.nanmax(np.abs(theta)):.3g}, σ up to {np.nanmax(std):.3g}): the record holds values "
        "far beyond the rest of its channel, which no linear model fits",
        hint="drop or repair the samples that the corrupt-sample warning names (or that are far "
             "beyond the rest) and identify again")


def _free_run_fit(model, u: np.ndarray, y: np.ndarray) -> float:
    """100 (1 − ‖y − ŷ‖/‖y − ȳ‖) of the model simulated from rest on the deviations ``u``, ``y``
    from its offsets (−inf if its run overflows)."""
    with np.errstate(over="ignore", invalid="ignore"):
        yhat = model.system.simulate(u)[:, 0]
        if not np.isfinite(yhat).all():
            return -np.inf
        return float(100.0 * (1.0 - np.linalg.norm(y - yhat) / np.linalg.norm(y - y.mean())))


def warn_if_mean_detrending_hurt(model, io: IOData, raw, refit) -> None:
    """The SISO form of :func:`gripkit.sysid.linear.identify_mimo._warn_if_detrending_hurt`: when a
    pole of ``model`` (fitted on the mean-detrended ``io``) does not settle within the record
    (|z|^N > e⁻⁵), fit the same structure (``refit(raw())``) on the data as they are (``raw()``:
    their :class:`IOData` without detrending) and warn, naming ``--detrend none``, when its free
    run from rest fits better by more than 10 points than the detrended model's."""
    poles = np.abs(model.poles())
    n = io.n_samples
    if not poles.size or not 0.0 < -n * np.log(max(float(poles.max()), 1e-300)) < 5.0:
        return
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            rio = raw()
            other = refit(rio)
        except GripkitError:
            return
    mean_fit = _free_run_fit(model, io.u1, io.y1)
    none_fit = _free_run_fit(other, rio.u1, rio.y1)
    if none_fit > mean_fit + 10.0:
        tau = -io.dt / math.log(float(poles.max()))
        emit_warning(
           f"identify {model.structure}: removing the means (detrend 'mean', the default) hurt "
           f"this fit: the slowest pole (|z| = {poles.max():.6g}, time constant {tau:.4g} s) does "
           f"not settle within the {n * io.dt:.4g} s record, so the output drifts and its mean is "
           f"no operating point; free-run fit from rest {mean_fit:.4g} % with the means removed, "
           f"{none_fit:.4g} % without; use --detrend none (Python: detrend='none')",
           AccuracyWarning)


def _method_function(method: str):
    # numba kernels (and scipy.optimize for the step fit): a family's module is loaded by its
    # first fit, so that `gripkit identify arx` loads none of them
    if method == "rls":
        from .linear.rls import rls as fit
    elif method == "narx":
        from .nonlinear.narx_entry import narx as fit
    elif method == "hw":
        from .nonlinear.hammerstein_wiener import hammerstein_wiener as fit
    elif method == "hysteresis":
        from .nonlinear.hysteresis import hysteresis as fit
    elif method == "nlss":
        from .nonlinear.nlss import nlss as fit
    elif method == "step":
        from .physical.step_response import identify_step_model as fit
    else:
        fit = {"arx": arx, "armax": armax, "oe": oe, "ss": identify_mimo.identify_ss, "frf": frf,
               "tf": identify_mimo.identify_tf}.get(method, structure_search)
    return fit


#: what identify() itself passes to the method's function (not accepted as an option)
_SUPPLIED = ("u", "y", "na", "nb", "nc", "nf", "nk", "dt", *IOData.__dataclass_fields__, "input",
             "output", "input_name", "output_name", "input_unit", "output_unit")


def method_options(method: str) -> list[str]:
    """The ``**options`` that :func:`identify` accepts for ``method``. For 'ss' the subspace
    weighting (n4sid, moesp or cva) is the option ``weighting``, for one record and several
    (identify's own ``method`` being 'ss')."""
    names = keyword_names(_method_function(method), exclude=_SUPPLIED)
    if method == "ss":
        names = [n for n in names if n not in ("data", "method")] + ["weighting"]
    if method == "step":
        names = [n for n in names if n != "data"]
    return names


def _linear_orders(na, nb, nk, nc) -> tuple:
    """(na, nb, nk, nc) with each one not given (None) at its :data:`LINEAR_ORDERS` value."""
    return tuple(LINEAR_ORDERS[k] if v is None else v
                 for k, v in zip(("na", "nb", "nk", "nc"), (na, nb, nk, nc)))


def _column_argument(given: dict):
    """The one column argument in ``given`` ({'inputs': …, 'input': …}: the documented name and
    its alias, None where not given) for :func:`identify`."""
    (name, value), (alias, old) = given.items()
    if value is not None and old is not None:
        raise ArgumentError(f"identify(): {name}= and its alias {alias}= both given "
                            f"({name}={value!r:.40}, {alias}={old!r:.40})",
                            hint=f"give the column(s) once, as {name}=")
    if value is None and old is None:
        raise ArgumentError(f"identify(): missing a required argument: '{name}' (or its alias "
                            f"'{alias}')",
                            hint=f"identify accepts {', '.join(keyword_names(identify))}")
    return old if value is None else value


@entry_point
def identify(data: Trajectory, method: str = "arx", *, inputs: str | list[str] | None = None,
             outputs: str | list[str] | None = None, input: str | list[str] | None = None,
             output: str | list[str] | None = None,
             na: int | None = None, nb: int | None = None, nk: int | None = None,
             nc: int | None = None, nf: int | None = None, detrend: str = "mean", **options):
    """Identify a model of the ``outputs`` column(s) driven by the ``inputs`` column(s) from a
    trajectory.

    Parameters
    ----------
    data
        A uniformly sampled :class:`~gripkit.signals.Trajectory` (e.g. from
        :func:`gripkit.io.load`), or a list of them: several records of the same columns fitted
        by one model, each with its own initial conditions (methods of
        :data:`RECORD_METHODS`; see :func:`identify_records`).
    method
        ``'arx'`` (least squares), ``'armax'`` (orders na, nb, nc, nk), ``'oe'`` (orders nb, nf,
        nk; ``nf`` defaults to ``na``), ``'rls'`` (recursive least squares; options
        ``forgetting``, ``p0``, ``windup``), or ``'search'`` (``na``, ``nb``, ``nk`` may be ranges
        such as ``'1:4'``; option ``criterion``); ``'ss'`` (state space by subspace + PEM,
        options of :func:`gripkit.sysid.linear.identify_mimo.identify_ss`), ``'frf'`` (frequency
        response, options of :func:`gripkit.sysid.linear.frf`), ``'tf'`` (continuous-time transfer
        function, options ``poles``, ``zeros``); ``'step'`` (second-order step response
        K ω_n²/(s² + 2ζω_n s + ω_n²) of a record at rest at its start, a continuous transfer
        function with the record's offsets u₀, y₀ and its coefficients' covariance; options
        ``solver`` (``'lm'`` or ``'trf'``), ``multistart``, ``progress`` of
        :func:`gripkit.sysid.physical.step_response.identify_step_model`; ``detrend`` is not
        used: the model carries its operating point); ``'narx'`` (polynomial NARX on the data as
        they are, its constant term in place of detrending; options of
        :func:`gripkit.sysid.narx`: ``degree``, ``lags``, ``terms``, ``validate``, ``basis``
        (``'rational'``: y = N/D) …); ``'hw'``
        (Hammerstein–Wiener on the data as they are, with this function's ``nb``, ``nf``, ``nk``:
        each one not given is chosen by the array function, by the free-run fit on ``validate``
        (a trajectory or ``(u, y)``) or by BIC; options of
        :func:`gripkit.sysid.hammerstein_wiener`: ``input_nonlinearity``,
        ``output_nonlinearity``, ``linear`` (``'oe'`` B/F or ``'ss'`` state space, with its
        ``order``), ``periods`` (the linear start from the FRF of a periodic input),
        ``validate`` …); ``'hysteresis'`` (Bouc-Wen or Prandtl–Ishlinskii, options of
        :func:`gripkit.sysid.hysteresis`: ``model``, ``form``, ``initial_state``, ``exponent``,
        ``operators`` …); ``'nlss'``
        (polynomial nonlinear state space, options of :func:`gripkit.sysid.nlss`: ``order``,
        ``degree``, ``validate`` …). For ss, frf, tf, nlss (and arx, matrix-polynomial)
        ``inputs``/``outputs`` may name several columns (``'a,b'`` or a list).
    inputs, outputs
        Column names (required). ``input``/``output`` are equal aliases; giving a name and its
        alias together is an :class:`~gripkit.errors.ArgumentError`.
    na, nb, nk, nc, nf
        Orders. Not given (None): for arx, armax, oe, rls and search ``na = nb = 2``, ``nk = 1``,
        ``nc = 1`` (:data:`LINEAR_ORDERS`) and ``nf = na``; for hw chosen by the fit.
    detrend
        ``'mean'`` (default), ``'linear'`` or ``'none'``; see :func:`io_data`. A step input
        (:func:`~gripkit.sysid.linear.identify_mimo.step_like`) is never at its mean: with
        ``'mean'``, tf, arx (one or several columns), armax and oe of one record refit it
        without detrending and return the model of the higher free-run fit (an
        AccuracyWarning when that is the refit).
    **options
        Passed to the method's function: for 'armax' and 'oe' ``maxiter``, ``tol``; for 'rls'
        ``forgetting``, ``p0``, ``theta0``, ``windup``, ``max_trace``, ``store``; for 'search'
        ``criterion``, ``progress`` (:func:`method_options`).

    Returns
    -------
    PolynomialModel, LinearModel, RLSResult, SearchResult, FRF, NARXModel, HWModel,
    BoucWenModel, PrandtlIshlinskiiModel or NLSSModel. A model records where its data came from
    (:func:`~gripkit.sysid.io_data.records_provenance`): the file's name and SHA-256 that
    :func:`gripkit.io.load` put in the trajectory's meta (its ``data_file``, ``data_hash``); of
    several records the names joined, no hash.
    """
    input = _column_argument({"inputs": inputs, "input": input})
    output = _column_argument({"outputs": outputs, "output": output})
    if not isinstance(method, str) or method not in METHODS:
        raise DataError(f"method: expected one of {', '.join(METHODS)}, found {method!r}")
    opts = method_options(method)
    check_keywords(options, opts, f"identify(method={method!r})",
                   hint=f"identify accepts {', '.join(keyword_names(identify))} and, for "
                        f"method {method!r}, "
                        + (", ".join(opts) if opts else "no other options"))
    for name, col in (("input", input), ("output", output)):
        if not (isinstance(col, str) or (method in ("ss", "frf", "tf", "arx", "nlss")
                                         and isinstance(col, (list, tuple))
                                         and all(isinstance(c, str) for c in col))):
            raise ArgumentError(f"identify(): {name} must be a column name (str), found "
                                f"{type(col).__name__} "
                                f"{col!r:.40}", hint=f"columns: {', '.join(data.names)}"
                                if isinstance(data, Trajectory) else None)
    _check_single_channel(data, method, input, output)
    with operating_point_remedy(IDENTIFY_REMEDY):  # the warning names identify's own option
        model = _dispatch(data, method, input=input, output=output, na=na, nb=nb, nk=nk, nc=nc,
                          nf=nf, detrend=detrend, **options)
    return with_provenance(model, records_provenance(data))


#: the last remedy of the operating-point warning (:func:`~gripkit.sysid.checks.\
#: warn_if_operating_point`) for a fit inside :func:`identify` (``detrend='none'``)
IDENTIFY_REMEDY = "fit with detrend='mean' (CLI: --detrend mean), which removes the means"


#: the methods that take several input and output columns; the others take one of each
SEVERAL_CHANNELS = ("ss", "frf", "tf", "arx", "nlss")


def _check_single_channel(data, method: str, input, output) -> None:
    """An ArgumentError, in the user's terms, when a method of one input and one output is given
    several columns (``'a,b'``; a column whose own name holds the comma is left to the method)."""
    if method in SEVERAL_CHANNELS:
        return
    first = data[0] if isinstance(data, (list, tuple)) and data else data
    names = set(first.names) if isinstance(first, Trajectory) else set()
    ins, outs = ((parse_names(c, role) if c not in names else (c,))
                 for c, role in ((input, "input"), (output, "output")))
    if len(ins) > 1 or len(outs) > 1:
        raise ArgumentError(
            f"identify {method}: this family takes one input and one output column, found "
            f"{len(ins)} input(s) {', '.join(map(repr, ins))} and {len(outs)} output(s) "
            f"{', '.join(map(repr, outs))}",
            hint=f"give one column each to --input and --output; the families that take "
                 f"several: {', '.join(SEVERAL_CHANNELS)}")


def with_provenance(model, provenance: dict):
    """``model`` with ``data_file``/``data_hash`` set from ``provenance`` (the fields of a
    LinearModel and a PolynomialModel, through their ``replace``; of a nonlinear family's model,
    :class:`~gripkit.sysid.model_file.FamilyFile`, on a shallow copy), or in the ``info`` of a
    result that keeps it there; other results, and data built in memory, as they are."""
    if provenance.get("data_file") is None:
        return model
    if hasattr(model, "data_file") and hasattr(model, "replace"):
        return model.replace(**provenance)
    if hasattr(model, "data_file"):  # a copy keeps what the fit set besides the fields (records)
        out = copy.copy(model)
        out.data_file, out.data_hash = provenance["data_file"], provenance["data_hash"]
        return out
    if isinstance(getattr(model, "info", None), dict) and hasattr(model, "replace"):
        return model.replace(info={**model.info, **provenance})
    return model


def _dispatch(data, method: str, *, input, output, na: int | None, nb: int | None,
              nk: int | None, nc: int | None, nf: int | None, detrend: str, **options):
    """The fit of :func:`identify`, its arguments checked."""
    if isinstance(data, (list, tuple)):  # several records, one model
        return identify_records(data, method, input=input, output=output, na=na, nb=nb, nk=nk,
                                nc=nc, nf=nf, detrend=detrend, **options)
    if method in ("ss", "frf", "tf"):  # MIMO: input/output may name several columns
        fn = ({"ss": identify_mimo.identify_ss, "frf": identify_mimo.identify_frf,
               "tf": identify_mimo.identify_tf})
        if method == "ss" and "weighting" in options:  # identify_ss names it ``method``
            options = dict(options)
            options["method"] = options.pop("weighting")
        out = fn[method](data, input=input, output=output, detrend=detrend, **options)
        if method == "ss":  # the order search and the validation fit go into the model's info
            out = _with_extras(*out)
        # a model file saved from it shows its columns in the data file's units (force [mN])
        return out.with_display_units(data) if hasattr(out, "with_display_units") else out
    if method == "arx" and identify_mimo.several(input, output):  # matrix-polynomial ARX
        na, nb, nk, _ = _linear_orders(na, nb, nk, nc)
        return identify_mimo.identify_arx(data, input=input, output=output, na=na, nb=nb, nk=nk,
                                          detrend=detrend).with_display_units(data)
    if method == "nlss":  # the model carries the operating point (input and output means)
        return _method_function(method)(data, input=input, output=output, **options)
    if method == "narx":  # the model's constant term carries the operating point
        io = _in_scale(io_data(data, input=input, output=output, detrend="none",
                               why="NARX identification"), "NARX identification")
        check_channels_vary(io.u1, io.y1, io.keywords)  # a constant column named, in its unit
        model = _method_function(method)(io.u1, io.y1, dt=io.dt, **_validation_arrays(options, io))
        return _with_channels(model, io)
    if method == "hw":  # the offset y0 carries the operating point; orders not given: chosen
        io = _in_scale(io_data(data, input=input, output=output, detrend="none",
                               why="Hammerstein-Wiener identification"),
                       "Hammerstein-Wiener identification")
        check_channels_vary(io.u1, io.y1, io.keywords)
        model = _method_function(method)(io.u1, io.y1, nb=nb, nf=nf, nk=nk, dt=io.dt,
                                         **_validation_arrays(options, io))
        return _with_channels(model, io)
    if method == "hysteresis":  # rate independent, its offset a parameter: the data as they are
        return _method_function(method)(data, input=input, output=output, **options)
    if method == "step":  # the model's u₀ (the record's start) and y₀ (fitted): the operating point
        model = _method_function(method)(data, input=input, output=output, **options)
        return model.with_display_units(data)
    na, nb, nk, nc = _linear_orders(na, nb, nk, nc)
    io = (io_data(data, input=input, output=output, detrend=detrend,
                  why=f"{method.upper()} identification"))
    if method in ("arx", "armax", "oe"):
        orders = (na, nb, nc, na if nf is None else nf, nk)
        model = _finite_fit(_polynomial_fit(method, io, orders, options))
        if detrend == "mean":
            raw = lambda: io_data(data, input=input, output=output, detrend="none")  # noqa: E731
            quiet = {k: v for k, v in options.items() if k != "progress"}  # one bar: the fit's
            refit = lambda r: _polynomial_fit(method, r, orders, quiet)  # noqa: E731
            return identify_mimo.after_mean_detrending(
                model, io.u1, lambda: refit(raw()), f"identify {method}",
                lambda m: identify_mimo.compare_score(m, data),
                lambda _: warn_if_mean_detrending_hurt(model, io, raw, refit))
        return model
    if method == "rls":
        from .linear.rls import rls  # numba: loaded only for an RLS fit

        check_channels_vary(io.u1, io.y1, io.keywords)  # a constant column named, in its unit
        res = rls(io.u1, io.y1, na, nb, nk, dt=io.dt, **options)
        named = {k: v for k, v in io.keywords.items() if not k.endswith("_offset")}
        return dataclasses.replace(res, model=res.model.replace(**named))  # the units of θ
    if isinstance(options.get("validate"), Trajectory):  # around the estimation operating point
        vd = validation_data(options["validate"], io, detrend=detrend)
        options = {**options, "validate": (vd.u1, vd.y1)}
    return search_widened(io, na, nb, nk, options)


#: structures a search adds past each edge of its ranges where the best structure sits
SEARCH_WIDEN_STEPS = 3
#: the smallest value of each order in a search
_LOWEST = {"na": 1, "nb": 1, "nk": 0}


def search_widened(io: IOData, na, nb, nk, options: dict):
    """:func:`~gripkit.sysid.structure_search` of ``io`` that goes past the edge of its ranges:
    while the best structure sits on the edge of a range of three or more values (what
    structure_search warns about), that range gains the next value past the edge (at most
    :data:`SEARCH_WIDEN_STEPS` times; never for ``criterion='loss'``, which always prefers the
    largest structure) and the search runs again. Only the last search's warnings are emitted
    (its edge warning, when the best still sits on an edge, names the ranges searched)."""
    ranges = {"na": parse_range(na, "na"), "nb": parse_range(nb, "nb"), "nk": parse_range(nk, "nk")}
    asked = {k: (min(r), max(r)) for k, r in ranges.items()}
    for step in range(SEARCH_WIDEN_STEPS + 1):
        searched = {k: (min(r), max(r)) for k, r in ranges.items()}
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            res = structure_search(io.u1, io.y1, ranges["na"], ranges["nb"], ranges["nk"],
                                   dt=io.dt, **options)
        grown = _grow_ranges(res.best, ranges) if options.get("criterion") != "loss" else False
        if not grown or step == SEARCH_WIDEN_STEPS:
            break
    widened = [f"{k} to {lo}:{hi} (asked {asked[k][0]}:{asked[k][1]})"
               for k, (lo, hi) in searched.items() if (lo, hi) != asked[k]]
    if widened:
        emit_warning("structure search: the best structure sat on the edge of the asked ranges, "
                     f"so the search went past it: {', '.join(widened)}", GripkitWarning)
    for w in caught:
        emit_warning(str(w.message), w.category)
    _warn_delay_ties(res)
    return res


def _warn_delay_ties(res) -> None:
    """Warn when the best structure's loss is matched (to 1e-9) by the same na and nb with
    other delays: the data cannot tell those nk apart (too little excitation, e.g. one sine)."""
    best = res.best
    tied = sorted({c.nk for c in res.candidates if (c.na, c.nb) == (best.na, best.nb)
                   and abs(c.loss - best.loss) <= 1e-9 * abs(best.loss)})
    if len(tied) > 1:
        emit_warning(f"structure search: na = {best.na}, nb = {best.nb} gives the same loss for "
                     f"nk = {', '.join(map(str, tied))}: these data cannot tell the delay apart "
                     "(the input excites too few frequencies); the ranking among them is "
                     "arbitrary", AccuracyWarning)


def _grow_ranges(best, ranges: dict) -> bool:
    """Add the value past each edge of ``ranges`` (three values or more) where ``best`` sits;
    whether any grew."""
    grown = False
    for name, r in ranges.items():
        v = getattr(best, name)
        if len(set(r)) < 3:
            continue
        if v == max(r):
            r.append(v + 1)
            grown = True
        elif v == min(r) and v - 1 >= _LOWEST[name]:
            r.insert(0, v - 1)
            grown = True
    return grown


def _with_extras(model, extras: dict):
    """The state-space model with :func:`~.linear.identify_mimo.identify_ss`'s extras in its
    ``info``: ``search`` (the ranked orders) and ``search_criterion`` of an order range,
    ``validation_fit_percent`` with ``validate``."""
    info = dict(model.info)
    if "search" in extras:
        info.update(search=extras["search"], search_criterion=extras["criterion"])
    if "validation_fit_percent" in extras:
        info["validation_fit_percent"] = extras["validation_fit_percent"]
    return model.replace(info=info)


def _in_scale(io: IOData, why: str) -> IOData:
    """``io`` once its columns pass :func:`~gripkit.sysid.io_data.check_scale` (the nonlinear
    families form unscaled sums of squares, like state space), named as in the data file."""
    check_scale(io.inputs, io.u, "input", why)
    check_scale(io.outputs, io.y, "output", why)
    return io


#: the methods that fit one model to several records (``identify([tr1, tr2], ...)``)
RECORD_METHODS = ("arx", "armax", "oe", "ss", "tf", "narx", "hw", "hysteresis", "nlss")


def _per_record(i: int, fn, *args, **kw):
    """``fn(*args, **kw)`` for record ``i``, its errors prefixed with ``data[i]: ``."""
    try:
        return fn(*args, **kw)
    except GripkitError as exc:
        raise type(exc)(f"data[{i}]: {exc.message}", hint=exc.hint) from None


def identify_records(data, method: str = "arx", *, input, output, na: int | None = None,
                     nb: int | None = None, nk: int | None = None, nc: int | None = None,
                     nf: int | None = None, detrend: str = "mean", **options):
    """One model from several records (a list of :class:`~gripkit.signals.Trajectory` with the
    same columns, sample interval and units), each with its own initial conditions; σ from all
    of them: ARX (:func:`gripkit.sysid.arx_records`; with several columns
    :func:`gripkit.sysid.linear.arx_mimo.arx_mimo_records`), ARMAX
    (:func:`gripkit.sysid.linear.armax.armax_records`), OE
    (:func:`gripkit.sysid.linear.oe.oe_records`; ``nf``
    defaults to ``na``), ``options`` ``maxiter``, ``tol`` for the last two; state space
    (``options`` of :data:`gripkit.sysid.linear.identify_mimo.SS_RECORD_OPTIONS`: subspace, then
    PEM, see :func:`gripkit.sysid.linear.identify_mimo.identify_ss_records`),
    continuous-time transfer functions (``poles``, ``zeros``:
    :func:`gripkit.sysid.linear.tfest.tfest_records`) and polynomial NARX
    (:func:`gripkit.sysid.narx` on the records as they are, its constant term in place of
    ``detrend``; ``options`` of that function), Hammerstein–Wiener (each record from its own
    steady state: :func:`gripkit.sysid.hammerstein_wiener` on the records as they are, with
    this function's ``nb``, ``nf``, ``nk``, each one not given chosen), hysteresis (each record
    from its own relaxed state: :func:`gripkit.sysid.hysteresis`) and nonlinear state space (each
    record its own initial state: :func:`gripkit.sysid.nlss`; ``input``/``output`` may name several
    columns); these three ignore ``detrend`` (their models carry the operating point). This is what
    ``identify([tr1, tr2], method, ...)`` and ``gripkit identify METHOD DATA1 DATA2 ...`` do.

    The model has one operating point: ``detrend='mean'`` removes the mean of all the records
    together (each channel's samples pooled), stored as ``u_offset``/``y_offset``;
    ``detrend='none'`` keeps the data as they are. ``'linear'`` is refused: each record's own
    line would give each record its own operating point, which one model cannot have.
    ``fit_percent`` per record is in ``info['records']``. Orders not given: as
    :func:`identify`.
    """
    _check_records(data, method, detrend)
    _no_duplicate_records(data, input, output)
    why = f"{method.upper()} identification"
    hw_orders = dict(nb=nb, nf=nf, nk=nk)  # each one not given is chosen by the fit
    na, nb, nk, nc = _linear_orders(na, nb, nk, nc)
    if method == "nlss":  # the model carries the operating point; input/output may be several
        for i, d in enumerate(data):
            _per_record(i, identify_mimo.mimo_data, d, input, output, "none", why=why)
        return _method_function(method)(list(data), input=input, output=output, **options)
    if identify_mimo.several(input, output) or method in ("ss", "tf"):
        if method not in ("arx", "ss", "tf"):
            raise ArgumentError(f"identify(): several input or output columns with several records "
                                f"are fitted by method 'arx' or 'ss' only, found method {method!r}",
                                hint="name one input and one output, or use method 'arx' or 'ss'")
        ds = [_per_record(i, identify_mimo.mimo_data, d, input, output, "none", why=why)
              for i, d in enumerate(data)]
        _same_sampling([(d.dt, d.input_units + d.output_units) for d in ds],
                       ds[0].inputs + ds[0].outputs)
        u0, y0 = _pooled_mean([d.u for d in ds]), _pooled_mean([d.y for d in ds])
        if detrend == "none":
            u0, y0 = np.zeros_like(u0), np.zeros_like(y0)
        records = [(d.u - u0, d.y - y0) for d in ds]
        if method == "ss":
            return _as_data(identify_mimo.identify_ss_records, records, ds[0], u0, y0, options,
                            demean=detrend == "mean")
        if method == "tf":
            return _as_data(identify_mimo.identify_tf_records, records, ds[0], u0, y0,
                            options["poles"], options["zeros"])
        return _as_data(arx_mimo_records, [(d.u - u0, d.y - y0) for d in ds], na, nb, nk,
                        dt=ds[0].dt, u_offset=tuple(map(float, u0)),
                        y_offset=tuple(map(float, y0)), **ds[0].signals)
    (input,) = identify_mimo.parse_names(input, "input")
    (output,) = identify_mimo.parse_names(output, "output")
    ios = [_per_record(i, io_data, d, input=input, output=output, detrend="none", why=why)
           for i, d in enumerate(data)]
    _same_sampling([(io.dt, (io.input_unit, io.output_unit)) for io in ios],
                   (ios[0].input, ios[0].output))
    if method in ("narx", "hw"):  # the data as they are: NARX's constant, HW's y0 (shared; each
        # record from its own steady state) carry the operating point
        fit, orders = _method_function(method), ({} if method == "narx" else hw_orders)
        model = _as_data(fit, [(io.u1, io.y1) for io in ios], dt=ios[0].dt, **orders,
                         **_validation_arrays(options, ios[0]))
        return _with_channels(model, ios[0])
    if method == "hysteresis":  # each record from its own relaxed state, the data as they are
        return _method_function(method)(list(data), input=input, output=output, **options)
    u0 = float(_pooled_mean([io.u1 for io in ios])) if detrend == "mean" else 0.0
    y0 = float(_pooled_mean([io.y1 for io in ios])) if detrend == "mean" else 0.0
    meta = dict(ios[0].keywords, u_offset=u0, y_offset=y0, dt=ios[0].dt, **options)
    records = [(io.u1 - u0, io.y1 - y0) for io in ios]
    if method == "arx":
        return _as_data(arx_records, records, na, nb, nk, **meta)
    if method == "armax":
        return _as_data(armax_records, records, na, nb, nc, nk, **meta)
    return _as_data(oe_records, records, nb, na if nf is None else nf, nk, **meta)


def _check_records(data, method: str, detrend: str) -> None:
    """The arguments of :func:`identify_records` that need no record read, or an error."""
    if method not in RECORD_METHODS:
        raise ArgumentError(f"identify(): several records (a list of {len(data)} trajectories) are "
                            f"fitted by method {', '.join(map(repr, RECORD_METHODS))} only, found "
                            f"method {method!r}",
                            hint=f"pass one trajectory, or use method {', '.join(RECORD_METHODS)}")
    if not data:
        raise DataError("data: expected a trajectory or a non-empty list of them, found an empty "
                        "list")
    for i, d in enumerate(data):
        if not isinstance(d, Trajectory):
            raise DataError(f"data[{i}]: expected a gripkit Trajectory, found {type(d).__name__}",
                            hint="use gripkit.io.load(path) or "
                                 "Trajectory.uniform(dt=..., u=..., y=...)")
    if detrend not in ("mean", "none"):
        raise DataError(f"detrend: with several records expected 'mean' (one operating point: the "
                        f"mean of all records) or 'none', found {detrend!r}",
                        hint="detrend 'linear' would give every record its own operating point; "
                             "detrend the records before, or use 'mean'")


def _no_duplicate_records(data, input, output) -> None:
    """A DataError naming the two records when two of ``data`` hold the same samples (the same
    SHA-256 of their ``input`` and ``output`` columns, at the same sample interval and in the
    same units; a shifted time axis does not matter): a record given twice counts its evidence
    twice, so the fit's σ would come out too small (by √2 for two copies) with the same θ."""
    names = (*parse_names(input, "input"), *parse_names(output, "output"))
    seen: dict[bytes, int] = {}
    for i, d in enumerate(data):
        if d.n < 2 or not all(n in d for n in names):
            continue  # the per-record checks name the missing column or the short record
        # another interval or unit is another error, reported after this check
        digest = hashlib.sha256(f"{d.dt:.9g}".encode())
        for n in names:
            digest.update(f"{n} [{d.unit(n)}]".encode())
            digest.update(np.ascontiguousarray(d[n], dtype=np.float64).tobytes())
        key = digest.digest()
        if key in seen:
            j = seen[key]
            raise DataError(
                f"data[{j}] and data[{i}] hold the same samples of "
                f"{', '.join(map(repr, names))}: a record given twice counts as two independent "
                "records and would make the parameters' σ too small (by √2 for two copies)",
                hint="give each record once")
        seen[key] = i


def _with_channels(model, io: IOData):
    """The NARX or Hammerstein–Wiener ``model`` fitted on the arrays of ``io`` (its SISO view),
    given the record's column names and units."""
    model.input_name, model.output_name = io.input, io.output
    model.input_unit, model.output_unit = io.input_unit, io.output_unit
    return model


def _validation_arrays(options: dict, io: IOData) -> dict:
    """``options`` with a trajectory ``validate`` given as the arrays ``(u, y)`` of its columns,
    as they are (``io`` the estimation record, read without detrending): what narx and
    hammerstein_wiener take."""
    if not isinstance(options.get("validate"), Trajectory):
        return options
    vd = validation_data(options["validate"], io)
    return {**options, "validate": (vd.u1, vd.y1)}


def _as_data(fit, records, *args, **kw):
    """``fit(records, ...)``, its errors naming ``data[i]`` (the caller's list), not
    ``records[i]``."""
    try:
        return fit(records, *args, **kw)
    except GripkitError as exc:
        if not exc.message.startswith("records["):
            raise
        raise type(exc)("data[" + exc.message[len("records["):], hint=exc.hint) from None


def _pooled_mean(xs: list) -> np.ndarray:
    """The mean of every sample of every record (per column)."""
    return sum(np.sum(x, axis=0) for x in xs) / sum(x.shape[0] for x in xs)


def _same_sampling(props: list, columns: tuple) -> None:
    """Every record sampled at the first one's interval, in its units, or a DataError."""
    dt0, units0 = props[0]
    for i, (dt, units) in enumerate(props[1:], 1):
        if abs(dt - dt0) > 1e-9 * dt0:
            raise DataError(f"data[{i}] is sampled at {1 / dt:g} Hz, data[0] at {1 / dt0:g} Hz: "
                            "the records of one fit must share the sample interval",
                            hint="resample one of them")
        for col, a, b in zip(columns, units0, units):
            if a != b:
                raise DataError(f"data[{i}]: column {col!r} is in {b!r}, in data[0] in {a!r}: the "
                                "records of one fit must use the same units",
                                hint="convert one of them")
