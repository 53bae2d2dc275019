"""Checks shared by every linear identification: signals, orders, sample counts, excitation.

Each check raises a :class:`~gripkit.errors.GripkitError` whose message names the argument, what
was expected and what was found (DEVELOPING.md, "Errors").
"""

from __future__ import annotations

import contextlib
import contextvars
import math

import numpy as np

from ..arguments import real_array, sample_interval
from ..errors import DataError, DataWarning, UnidentifiableError, emit_warning
from ..units import dimension_of, same_dimension
from .regression import COND_LIMIT, arx_regression, qr_r, scaled_condition

__all__ = ["as_signal", "signal_array", "signal_with_peaks", "as_io_matrix", "check_not_transposed",
           "io_records",
           "check_io", "check_io_peaks", "check_io_arrays", "check_order", "check_dt",
           "require_samples", "check_excitation", "check_channels_vary", "check_columns_vary",
           "channel_of",
           "check_output_varies", "checked_problem", "checked_problem_peaks", "check_identifiable",
           "check_persistent_excitation", "check_dimension", "LENGTH_OR_ANGLE", "FORCE_OR_TORQUE",
           "LINEAR_ORDERS", "warn_if_operating_point", "constant_term", "operating_point_remedy"]

#: the orders of the linear methods (arx, armax, oe, rls, search) that are not given (OE's nf:
#: na's); :func:`gripkit.sysid.identify` and ``gripkit identify arx|armax|oe|rls`` use it, the
#: CLI from here as this module loads without the fitting code (``gripkit --help`` stays fast)
LINEAR_ORDERS = {"na": 2, "nb": 2, "nk": 1, "nc": 1}

#: Expected dimensions for :func:`check_dimension`: a description and a reference unit each.
LENGTH_OR_ANGLE = {"a length": "m", "an angle": "rad"}
FORCE_OR_TORQUE = {"a force": "N", "a torque": "N*m"}


def as_signal(x, name: str) -> np.ndarray:
    """``x`` as a finite 1-D float64 array, or a :class:`DataError` naming ``name``."""
    return signal_with_peaks(x, name)[0]


def signal_array(x, name: str) -> np.ndarray:
    """``x`` as a non-empty 1-D float64 array, or a :class:`DataError` naming ``name`` (its values
    are not looked at: :func:`signal_with_peaks` checks them)."""
    a = real_array(x, name, "a 1-D array of numbers")
    if a.ndim != 1:
        row = a.ndim == 2 and a.shape[0] == 1 and a.shape[1] > 1
        raise DataError(f"{name}: expected a 1-D array of samples, found shape {a.shape}"
                        + (" (one row: it looks transposed)" if row else ""),
                        hint="pass x.ravel()" if row else
                        "pass one channel at a time (single-input single-output models)")
    if a.size == 0:
        raise DataError(f"{name}: the signal holds no samples")
    return a


def signal_with_peaks(x, name: str) -> tuple[np.ndarray, float, float]:
    """:func:`as_signal` with the signal's minimum and maximum ``(a, lo, hi)``, which the
    finiteness check computes anyway: the excitation checks and the scaling take them from here
    instead of two more passes each (``peaks=(lo, hi)``)."""
    a = signal_array(x, name)
    # the ufuncs' reductions themselves (the same as a.min(), a.max(), without their wrappers)
    lo, hi = float(np.minimum.reduce(a)), float(np.maximum.reduce(a))
    if not (math.isfinite(lo) and math.isfinite(hi)):  # min and max carry a NaN or an inf through
        for label, mask in (("NaN", np.isnan(a)), ("infinite", np.isinf(a))):
            if mask.any():
                raise DataError(
                    f"{name} has {int(mask.sum())} {label} values (first at sample "
                    f"{int(np.argmax(mask))})",
                    hint="drop or interpolate them before identification (CLI: --fill)")
    return a, lo, hi


def as_io_matrix(x, name: str, n: int | None = None, channels: tuple[str, ...] | None = None,
                 kind: str = "channel") -> np.ndarray:
    """``x`` as a finite (N, k) float64 array (a 1-D signal is one column); ``n`` samples when
    given; with ``channels``, k = len(channels) and the errors name the channel (of ``kind``)."""
    a = real_array(x, name)
    if a.ndim == 1:
        a = a[:, None]
    check_not_transposed(a, name)
    if channels is not None and (a.ndim != 2 or a.shape[1] != len(channels)):
        raise DataError(f"{name}: expected shape (N, {len(channels)}) for the {kind}s "
                        f"{', '.join(channels)}, "
                        f"found {a.shape}")
    if a.ndim != 2 or a.shape[0] == 0 or a.shape[1] == 0:
        raise DataError(f"{name}: expected shape (N,) or (N, {kind}s), found {a.shape}")
    if n is not None and a.shape[0] != n:
        raise DataError(f"{name}: expected {n} samples (as many as the other signal), "
                        f"found {a.shape[0]}")
    if not _all_finite(a):
        bad = ~np.isfinite(a)
        r, c = np.argwhere(bad)[0]
        raise DataError(f"{name}: {int(bad.sum())} NaN or inf values (first at sample {r}, {kind} "
                        f"{channels[c] if channels is not None else c})",
                        hint="drop or interpolate them before identification (CLI: --fill)")
    return np.ascontiguousarray(a)


def check_not_transposed(a: np.ndarray, name: str) -> None:
    """A DataError when the 2-D ``a`` has far fewer rows (samples) than columns (channels): at
    least 10 columns and 10 per row, as a (1, N) record passed for an (N, 1) one is."""
    if a.ndim == 2 and a.shape[0] > 0 and a.shape[1] >= max(10, 10 * a.shape[0]):
        raise DataError(f"{name}: shape {a.shape} is {a.shape[0]} sample(s) of {a.shape[1]} "
                        "channels: it looks transposed",
                        hint="samples go in rows: pass x.T, or a 1-D array for one channel")


def io_records(records, *, siso: bool = False) -> list[tuple[np.ndarray, np.ndarray]]:
    """Several records as checked ``(u (N_i, m), y (N_i, p))`` pairs with the same numbers of
    columns (one input and one output with ``siso``); a DataError names the record."""
    if not isinstance(records, (list, tuple)) or not records:
        raise DataError("records: expected a non-empty list of (u, y) pairs, found "
                        f"{records!r:.60}")
    recs = []
    for i, r in enumerate(records):
        if not (isinstance(r, (tuple, list)) and len(r) == 2):
            raise DataError(f"records[{i}]: expected a (u, y) pair, found {type(r).__name__}")
        u = as_io_matrix(r[0], f"records[{i}] input u")
        y = as_io_matrix(r[1], f"records[{i}] output y", u.shape[0])
        if siso and (u.shape[1] != 1 or y.shape[1] != 1):
            raise DataError(f"records[{i}]: expected one input and one output, found {u.shape[1]} "
                            f"and {y.shape[1]}", hint="estimate one input-output pair at a time")
        first = (recs[0][0].shape[1], recs[0][1].shape[1]) if recs else None
        if first and (u.shape[1], y.shape[1]) != first:
            raise DataError(f"records[{i}]: expected {first[0]} input and {first[1]} output "
                            f"columns as records[0], found {u.shape[1]} and {y.shape[1]}")
        recs.append((u, y))
    return recs


def _all_finite(a: np.ndarray) -> bool:
    """True when no value is NaN or ±inf: min and max carry a NaN or an infinity through, so two
    passes without the N-element boolean temporary of ``np.isfinite(a).all()``."""
    return math.isfinite(float(a.min())) and math.isfinite(float(a.max()))


def check_io(u, y) -> tuple[np.ndarray, np.ndarray]:
    """Input and output as finite 1-D float64 arrays of equal length."""
    return check_io_peaks(u, y)[:2]


def check_io_peaks(u, y) -> tuple[np.ndarray, np.ndarray, tuple]:
    """:func:`check_io` with ``((min u, max u), (min y, max y))`` (:func:`signal_with_peaks`)."""
    u, ulo, uhi = signal_with_peaks(u, "input u")
    y, ylo, yhi = signal_with_peaks(y, "output y")
    _same_length(u, y)
    return u, y, ((ulo, uhi), (ylo, yhi))


def check_io_arrays(u, y) -> tuple[np.ndarray, np.ndarray]:
    """Input and output as non-empty 1-D float64 arrays of equal length (:func:`signal_array`:
    their values not yet checked, for a caller that scans them in its own pass)."""
    u, y = signal_array(u, "input u"), signal_array(y, "output y")
    _same_length(u, y)
    return u, y


def _same_length(u: np.ndarray, y: np.ndarray) -> None:
    if u.shape != y.shape:
        raise DataError("input u and output y must have the same length, found "
                        f"{u.size} and {y.size}")


def check_order(value, name: str, minimum: int = 0) -> int:
    """A model order or delay: an integer >= ``minimum``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        if isinstance(value, (float, np.floating)) and float(value).is_integer():
            value = int(value)
        else:
            raise DataError(f"{name}: expected an integer >= {minimum}, found {value!r}")
    if value < minimum:
        raise DataError(f"{name}: expected an integer >= {minimum}, found {value}")
    return int(value)


def check_dt(dt: float | None) -> float:
    """The sample interval in seconds (1.0 — 'one sample' — when None)."""
    if dt is None:
        return 1.0
    return sample_interval(dt)


def require_samples(n: int, n_min: int, what: str) -> None:
    """``n`` samples must be at least ``n_min`` for ``what`` (e.g. "ARX [2 2 2] (4 parameters)")."""
    if n < n_min:
        raise DataError(f"{what} needs at least {n_min} samples, found {n}",
                        hint="use a longer record or a smaller model")


def _level(x: np.ndarray, offset: float, unit: str | None) -> str:
    """The constant value of ``x`` in the user's terms: ``offset`` (the mean that detrending took
    off) added back, with ``unit`` when it has one (``'1 A'``)."""
    value = f"{float(x[0]) + offset:.6g}"
    return f"{value} {unit}" if unit not in (None, "", "1") else value


def check_excitation(u: np.ndarray, name: str = "input u",
                     peaks: tuple[float, float] | None = None, *, offset: float = 0.0,
                     unit: str | None = None) -> None:
    """Refuse a constant input: it cannot identify the numerator B (the input-output dynamics).
    ``peaks``: ``(min, max)`` of ``u`` when known (:func:`signal_with_peaks`); ``offset`` and
    ``unit``: what the message adds to the value and prints after it (:func:`check_channels_vary`).
    """
    lo, hi = (float(np.min(u)), float(np.max(u))) if peaks is None else peaks
    span = hi - lo
    scale = max(hi, -lo, 1e-300)  # max|u| without an N-sized temporary
    if span <= 1e-12 * scale or span == 0.0:
        raise UnidentifiableError(
            f"{name} is constant ({_level(u, offset, unit)} for all {u.size} samples): a constant "
            f"input cannot "
            f"identify B, the input-output dynamics; no estimate returned",
            hint="record data with a varying input (multisine, PRBS, noise: gripkit.excitation)")


def check_persistent_excitation(u: np.ndarray, order: int, what: str,
                                name: str = "input u") -> None:
    """Refuse an input that is not persistently exciting of ``order`` (Ljung 1999, §13.2): its
    ``order`` delayed copies must be linearly independent, or the data cannot determine ``order``
    parameters of the input-output dynamics (a single sine determines 2, a sum of m sines 2m).

    The copies are delayed by the lag τ at which the input's autocorrelation first falls below one
    half (at least one sample), so that an oversampled but rich input is not mistaken for a poor
    one; the test is the one of least squares (:func:`~gripkit.sysid.regression.triangular_solve`):
    the condition number of the column-scaled matrix above ``COND_LIMIT``."""
    n = u.size
    x = u - u.mean()
    f = np.fft.rfft(x, 2 * n)
    r = np.fft.irfft(f * f.conj())[:n]
    below = np.flatnonzero(r[1:n // (2 * order) + 1] < 0.5 * r[0]) if r[0] > 0 else np.empty(0)
    tau = int(below[0]) + 1 if below.size else max(1, n // (2 * order))
    U = np.column_stack([u[(order - 1 - k) * tau:n - k * tau] for k in range(order)])
    cond = scaled_condition(qr_r(np.asfortranarray(U), True))[0]
    if not cond <= COND_LIMIT:
        raise UnidentifiableError(
            f"{what}: {name} is not persistently exciting of order {order}: {order} copies of it "
            f"delayed by {tau} sample(s) are linearly dependent (condition number {cond:.3g} > "
            f"{COND_LIMIT:.0e}; a single sine determines only 2 parameters, m sines 2m); "
            f"the data cannot determine {order} coefficients of the input-output dynamics; "
            f"no estimate returned",
            hint="excite the system more richly (more frequencies than parameters: multisine, "
                 "PRBS, noise: gripkit.excitation) or use fewer poles/zeros")


def check_dimension(column: str, unit: str | None, expected: dict[str, str], role: str) -> None:
    """Refuse a column whose unit measures none of the ``expected`` dimensions (a description
    mapped to a reference unit, e.g. ``{"a voltage": "V"}``): a position in N, an effort in m, an
    input and output swapped. A column without a unit (``'1'``, as files without units load) is
    not checked: nothing says what it measures. Units of the right dimension were converted to SI
    when the file was read."""
    if unit in (None, "", "1"):
        return
    if any(same_dimension(unit, ref) for ref in expected.values()):
        return
    want = " or ".join(f"{d} (like {ref!r})" for d, ref in expected.items())
    raise DataError(f"{role} column {column!r} is in {unit!r} (dimension {dimension_of(unit)}), "
                    f"expected {want}",
                    hint=f"check that {column!r} is the {role} column (not swapped with another) "
                         f"and that its header gives the right unit")


def check_output_varies(y: np.ndarray, name: str = "output y",
                        peaks: tuple[float, float] | None = None, *, offset: float = 0.0,
                        unit: str | None = None) -> None:
    """Refuse a constant output: there is nothing to fit (and the fit % is undefined).
    ``peaks``: ``(min, max)`` of ``y`` when known (:func:`signal_with_peaks`); ``offset``, ``unit``
    as :func:`check_excitation`'s."""
    lo, hi = (float(np.min(y)), float(np.max(y))) if peaks is None else peaks
    if hi - lo <= 1e-12 * max(hi, -lo, 1e-300):
        raise UnidentifiableError(f"{name} is constant ({_level(y, offset, unit)} for all "
                                  f"{y.size} samples): "
                                  f"there are no dynamics to identify; no estimate returned",
                                  hint="check that the output column is the measured response")


def channel_of(meta: dict, role: str, symbol: str) -> tuple[str, float, str | None]:
    """The label, offset and unit of the ``role`` (``'input'``/``'output'``) channel in the model
    keywords ``meta`` (``input_name``, ``u_offset``, ``input_unit`` …, or the lti spelling
    ``inputs``, ``input_units``); ``'input u'`` and no offset or unit when ``meta`` has none."""
    def one(key: str, plural: str):
        value = meta.get(key, meta.get(plural))
        if isinstance(value, (list, tuple)):
            value = value[0] if len(value) == 1 else None
        return value
    name = one(f"{role}_name", f"{role}s")
    offset = one(f"{symbol}_offset", f"{symbol}_offsets")
    unit = one(f"{role}_unit", f"{role}_units")
    label = f"{role} column {name!r}" if isinstance(name, str) else f"{role} {symbol}"
    off = float(offset) if isinstance(offset, (int, float, np.number)) else 0.0
    return label, off if math.isfinite(off) else 0.0, unit if isinstance(unit, str) else None


def check_channels_vary(u: np.ndarray, y: np.ndarray, meta: dict,
                        peaks: tuple | None = None) -> None:
    """:func:`check_excitation` and :func:`check_output_varies` on a SISO estimator's checked,
    unscaled signals, the channels named by its model keywords ``meta``: a constant column is
    reported by its name, with its value (the detrending offset added back) in its unit.
    ``peaks``: ``((min u, max u), (min y, max y))`` when known."""
    label, offset, unit = channel_of(meta, "input", "u")
    check_excitation(u, label, None if peaks is None else peaks[0], offset=offset, unit=unit)
    label, offset, unit = channel_of(meta, "output", "y")
    check_output_varies(y, label, None if peaks is None else peaks[1], offset=offset, unit=unit)


def _nth(value, i: int, k: int):
    """The entry of channel ``i`` of ``k`` in a model keyword's ``value``: a sequence of ``k``
    entries, or one value for a single channel; None otherwise."""
    if isinstance(value, (list, tuple, np.ndarray)):
        return value[i] if len(value) == k else None
    return value if k == 1 else None


def check_columns_vary(u: np.ndarray, y: np.ndarray, meta: dict | None = None) -> None:
    """:func:`check_excitation` on every column of a MIMO estimator's checked (N, m) input ``u``
    and :func:`check_output_varies` on every column of its (N, p) output ``y`` (the data as the
    caller gives them, before any scaling), the columns named by the model keywords ``meta``
    (``inputs`` or ``input_name``, ``input_units`` or ``input_unit``, ``u_offset``; the same
    for the outputs): ``input column 'current'`` with its value, the offset added back, in its
    unit, or ``input channel 1`` without a name. One pass for the minima and one for the maxima
    of all columns. A record of one sample is left to the caller's length check (which says how
    many samples it needs)."""
    if u.shape[0] < 2:
        return
    meta = meta or {}
    for role, symbol, x, check in (("input", "u", u, check_excitation),
                                   ("output", "y", y, check_output_varies)):
        k = x.shape[1]
        lo, hi = np.min(x, axis=0), np.max(x, axis=0)
        for i in range(k):
            name, unit, offset = (_nth(meta.get(a, meta.get(b)), i, k) for a, b in (
                (f"{role}s", f"{role}_name"), (f"{role}_units", f"{role}_unit"),
                (f"{symbol}_offset", f"{symbol}_offsets")))
            label = f"{role} column {name!r}" if isinstance(name, str) else f"{role} channel {i}"
            number = isinstance(offset, (int, float, np.number)) and not isinstance(offset, bool)
            off = float(offset) if number and math.isfinite(float(offset)) else 0.0
            check(x[:, i], label, (float(lo[i]), float(hi[i])), offset=off,
                  unit=unit if isinstance(unit, str) else None)


def checked_problem(u, y, dt: float | None, **orders):
    """The common start of every estimator: signals checked (:func:`check_io`), orders checked
    (``nb`` >= 1, the others >= 0), sample interval resolved. Returns ``(u, y, dt, *orders)`` with
    the orders as ints in the order given."""
    return checked_problem_peaks(u, y, dt, **orders)[:-1]


def checked_problem_peaks(u, y, dt: float | None, **orders):
    """:func:`checked_problem` with the signals' ``((min u, max u), (min y, max y))`` last."""
    u, y, peaks = check_io_peaks(u, y)
    ints = [check_order(v, name, 1 if name == "nb" else 0) for name, v in orders.items()]
    return (u, y, check_dt(dt), *ints, peaks)


def check_identifiable(u: np.ndarray, y: np.ndarray, n_min: int, what: str,
                       peaks: tuple | None = None) -> None:
    """Enough samples, a varying input and a varying output, or a clear error; ``peaks``:
    ``((min u, max u), (min y, max y))`` when known."""
    require_samples(y.size, n_min, what)
    check_excitation(u, peaks=None if peaks is None else peaks[0])
    check_output_varies(y, peaks=None if peaks is None else peaks[1])


#: level changes an input column may make and still count as a step (a step, a few held steps)
STEP_CHANGES = 4


def step_like(u) -> bool:
    """Whether every column of the input ``u`` ((N,) or (N, m); as recorded or with its mean
    removed: a shift changes neither its span nor its steps) is piecewise
    constant with at most :data:`STEP_CHANGES` level changes, and one column at least changes: a
    step record. Its mean is no operating point: the record sits at one level, then at another,
    never at the mean, so with the means removed a record that starts at rest starts away from
    rest (a measured, noisy step is not detected)."""
    u = np.asarray(u, dtype=np.float64).reshape(len(u), -1)
    span = np.ptp(u, axis=0)
    if not u.shape[0] or not np.any(span > 0):
        return False
    changes = np.count_nonzero(np.abs(np.diff(u, axis=0)) > 1e-9 * span, axis=0)
    return bool(np.all(changes <= STEP_CHANGES))


#: |c|/σ_c above which :func:`warn_if_operating_point` finds the constant term significant
OPERATING_POINT_Z = 5.0
#: relative change of the static gain the constant term must make to matter
OPERATING_POINT_GAIN_CHANGE = 0.1
#: a signal's mean within this fraction of its span (max − min) of zero: centred, nothing to
#: check (about 0.1 σ of a Gaussian record of 10³–10⁶ samples)
CENTRED = 0.01


def warn_if_operating_point(u, y, na: int, nb: int, nk: int, what: str,
                            peaks: tuple | None = None) -> None:
    """Warn (:class:`~gripkit.errors.DataWarning`) when the one-input, one-output arrays ``u``,
    ``y`` that a linear estimator (``what``: "oe [2 2 1]") takes as deviations sit around an
    operating point: the model ``A y = B u`` has no constant, so a level ȳ ≠ G(1) ū biases every
    coefficient (σ that exclude the truth), silently. The check: the ARX least squares of the
    same orders ``na``, ``nb``, ``nk`` with and without a constant regressor c,
    ``y(t) + a₁ y(t−1) + … = b u(t−nk) + … + c``; it warns when c is significant
    (|c|/σ_c > :data:`OPERATING_POINT_Z`) and changes the static gain ``Σb/(1 + Σa)`` by more
    than :data:`OPERATING_POINT_GAIN_CHANGE`. Data centred on zero (both means within
    :data:`CENTRED` of their spans, ``peaks`` ``((min u, max u), (min y, max y))`` when the
    caller knows them: what ``identify`` fits after removing the means) are not checked; a
    step from rest fits without a constant (c ≈ 0) and passes; a step input with an offset is
    told to subtract its starting steady state, not its mean (:func:`step_like`). A constant
    that the regressors already span (:func:`constant_term` is ``None``) is not checked. The
    last remedy named is the caller's (:func:`operating_point_remedy`)."""
    u, y = np.ravel(u), np.ravel(y)
    ubar, ybar = (float(np.add.reduce(x)) / x.size for x in (u, y))  # x.mean() without its wrapper
    (ulo, uhi), (ylo, yhi) = peaks or ((u.min(), u.max()), (y.min(), y.max()))
    if abs(ubar) <= CENTRED * (uhi - ulo) and abs(ybar) <= CENTRED * (yhi - ylo):
        return
    X = arx_regression(u, y, na, nb, nk)
    m, p = X.shape[0], na + nb
    if m <= p + 2:
        return
    phi, target = X[:, :p], X[:, p]
    fit = constant_term(phi, target)
    if fit is None:
        return
    theta, sigma_c = fit
    plain = np.linalg.lstsq(phi, target, rcond=None)[0]
    c = float(theta[p])
    g0, g1 = (float(np.sum(t[na:p]) / (1.0 + np.sum(t[:na]))) for t in (plain, theta))
    if not (math.isfinite(g0) and math.isfinite(g1)) or abs(c) <= OPERATING_POINT_Z * sigma_c \
            or abs(g0 - g1) <= OPERATING_POINT_GAIN_CHANGE * max(abs(g1), 1e-300):
        return
    fix = (f"subtract the steady state before the step (u = {u[0]:.4g}, y = {y[0]:.4g}) from "
           "u and y" if step_like(u) else "subtract the means from u and y")
    emit_warning(
        f"{what}: the data sit around an operating point (mean u = {ubar:.4g}, mean y = "
        f"{ybar:.4g}) that the model has no term for: the ARX fit of the same orders with a "
        f"constant term finds c = {c:.4g} (|c|/σ_c = {abs(c) / sigma_c:.3g}) and a static gain "
        f"of {g1:.4g} against {g0:.4g} without it, so this model is biased and its σ do not "
        f"cover that; {fix} before fitting, pass them as u_offset=, y_offset= and validate the "
        f"model with the record's own values (m.compare(u, y), not the deviations), or "
        f"{_OPERATING_POINT_REMEDY.get()}", DataWarning)


def constant_term(phi: np.ndarray, target: np.ndarray):
    """The least squares ``target ≈ [phi, 1] θ`` with a constant regressor last: ``(θ, σ_c)``,
    σ_c the standard error of the constant, ``sqrt(s²·[(XᵀX)⁻¹]_pp)`` with
    ``s² = e·e/(m − p − 1)``; ``None`` when the constant column lies (nearly) in the span of
    ``phi`` (``|r_pp| ≤`` :data:`CONSTANT_APART` ``·√m``) or ``[phi, 1]``, its columns scaled to
    unit norm, has a condition number above ``COND_LIMIT``: the constant cannot be told apart."""
    m, p = phi.shape
    q, r = np.linalg.qr(np.column_stack([phi, np.ones(m)]))
    r_pp = abs(float(r[p, p]))
    norms = np.linalg.norm(r, axis=0)  # the columns' norms: the condition whatever the units
    if r_pp <= CONSTANT_APART * math.sqrt(m) or not np.all(norms > 0) \
            or np.linalg.cond(r / norms) > COND_LIMIT:
        return None
    qt = q.T @ target
    theta = np.linalg.solve(r, qt)
    e = target - q @ qt
    # Var(c) = s²·[(XᵀX)⁻¹]_pp = s²·‖row p of R⁻¹‖² = s²/r_pp² (that row of the upper-triangular
    # R⁻¹ holds 1/r_pp alone)
    return theta, math.sqrt(float(e @ e) / (m - p - 1)) / r_pp


#: |r_pp| at or below this fraction of the constant column's norm: the constant lies (nearly) in
#: the span of the regressors (an input held constant over the fitted samples)
CONSTANT_APART = 1e-8
#: the last remedy the operating-point warning names: a direct estimator call is told of
#: :func:`gripkit.sysid.identify`; a fit inside ``identify(..., detrend='none')`` (set by
#: :func:`operating_point_remedy`) of its ``detrend='mean'``
_OPERATING_POINT_REMEDY: contextvars.ContextVar[str] = contextvars.ContextVar(
    "operating_point_remedy", default="use gripkit.sysid.identify, which removes the means")


@contextlib.contextmanager
def operating_point_remedy(text: str):
    """Within the ``with`` block the operating-point warning (:func:`warn_if_operating_point`)
    ends with ``text`` as its last remedy (the caller's own option that removes the means)."""
    token = _OPERATING_POINT_REMEDY.set(text)
    try:
        yield
    finally:
        _OPERATING_POINT_REMEDY.reset(token)
