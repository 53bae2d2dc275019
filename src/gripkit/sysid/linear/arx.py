"""ARX identification by least squares, eq (20)–(23) and (29) of ``000_8f66dcc7ab06470c.txt``.

>>> import numpy as np
>>> from gripkit.sysid import arx
>>> rng = np.random.default_rng(0)
>>> u = rng.standard_normal(2000)
>>> y = np.zeros(2000)
>>> for t in range(3, 2000):  # Table II, [2 2 2], S1, filtered data
...     y[t] = (1.8732*y[t-1] - 0.8996*y[t-2] + 0.1950*u[t-2] - 0.2276*u[t-3]
...             + 0.001*rng.standard_normal())
>>> m = arx(u, y, 2, 2, 2)
>>> np.round(m.A, 3).tolist(), np.round(m.B, 3).tolist()
([1.0, -1.873, 0.9], [0.0, 0.0, 0.195, -0.228])
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ...errors import DataError
from ..scaling import in_user_units, unit_scale
from .arx_mimo import arx_mimo
from ..checks import (check_channels_vary, check_dt, check_excitation, check_identifiable, check_io,
                      check_order, check_output_varies, checked_problem_peaks, require_samples,
                      warn_if_operating_point)
from .polynomial import PolynomialModel, channel_meta
from ..regression import (COND_NOTABLE, NUMPY_QR_MAX_ELEMENTS, QRSolution, arx_regression,
                          arx_start, qr_solve, solve_upper, triangular_solve,
                          warn_if_weakly_determined)
from .validation import fit_percent, records_fit

__all__ = ["arx", "arx_records"]

#: Regressors up to this many elements (``m·(p+1)``, 2 MiB of float64) are materialised: a few
#: milliseconds at most, and no numba import or kernel load (the start-up it would add to a small
#: CLI fit: docs/performance.md, "Start-up"). Up to
#: ``regression.NUMPY_QR_MAX_ELEMENTS`` they are solved by QR (no scipy.linalg import), above it
#: by the normal equations of their BLAS Gram matrix where κ allows (:func:`blas_gram_cond_limit`,
#: else QR). Larger ones take the one-pass compensated lagged sums (O(p²) memory).
QR_MAX_ELEMENTS = 2**18


def arx(u, y, na: int, nb: int, nk: int = 1, *, dt: float | None = None,
        **meta) -> PolynomialModel:
    """Least-squares ARX model ``A(q) y(t) = B(q) u(t) + e(t)`` in MATLAB's ``[na nb nk]`` layout.

    Parameters
    ----------
    u, y
        Input and output samples, shape (N,), uniformly sampled, in deviation units (remove an
        operating point first: :func:`gripkit.sysid.identify` does it with ``detrend='mean'``).
        Deviations here, the operating point passed as ``u_offset=``, ``y_offset=``; the
        model's simulate/predict/compare/residuals/validate then take the record's own values
        (``m.compare(u + u_offset, y + y_offset)``), never these deviations.
    na, nb, nk
        Number of A coefficients (after the leading 1), number of B coefficients, input delay in
        samples (``B`` gets ``nk`` leading zeros). Table II's ``[2 2 2]`` is ``na=2, nb=2, nk=2``.
    dt
        Sample interval (s); default 1 (time in samples).
    **meta
        Model metadata: ``input_name``, ``output_name``, ``input_unit``, ``output_unit``,
        ``u_offset``, ``y_offset`` (or, in the lti spelling, ``inputs``, ``outputs``,
        ``input_units``, ``output_units``); one per channel with several columns.

    With several input or output columns (``u`` (N, m), ``y`` (N, p)) the model is the same
    :class:`PolynomialModel` holding matrix polynomials ``A`` (na+1, p, p) and ``B``
    (nk+nb, p, m): see :func:`gripkit.sysid.linear.arx_mimo.arx_mimo`.

    Returns
    -------
    PolynomialModel
        ``.A``, ``.B``, ``.A_std``, ``.B_std`` (MATLAB layout), ``.covariance``, ``.loss`` (eq 29),
        ``.fit_percent`` (one-step prediction), ``.aic``, ``.fpe``, ``.estimation_residuals``.

    Raises
    ------
    DataError
        NaN/inf, unequal lengths, fewer than ``t0 + na + nb + 1`` samples.
    UnidentifiableError
        Constant input (it cannot identify B), constant output, or a regressor whose
        column-scaled condition number exceeds 1e10 (the message names the parameters involved).

    Warns
    -----
    AccuracyWarning
        A column-scaled condition number above :func:`~gripkit.sysid.regression.warn_threshold`
        (the κ at which the least-determined parameter combination may be off by a third of the
        parameters' size, from the noise or from rounding): the message names those parameters
        and their relative σ.

    The signals are scaled to unit size internally (exact powers of two, :mod:`.scaling`), so data
    at any scale (1e-300 … 1e300) are identified; the model is in the units of ``u`` and ``y``.
    """
    several = (np.ndim(u) == 2 and np.shape(u)[1] > 1) or (np.ndim(y) == 2 and np.shape(y)[1] > 1)
    meta = channel_meta(meta, arx, not several)
    if several:  # several inputs or outputs: matrix polynomials
        return arx_mimo(u, y, na, nb, nk, dt=dt, **meta)
    # one min and max per signal (the finiteness check's) serve the excitation checks and scaling
    u, y, step, na, nb, nk, (pu, py) = checked_problem_peaks(u, y, dt, na=na, nb=nb, nk=nk)
    check_channels_vary(u, y, meta, (pu, py))  # named in the user's units, before any scaling
    warn_if_operating_point(u, y, na, nb, nk, f"arx [{na} {nb} {nk}]", (pu, py))
    cu, cy = unit_scale(u, pu), unit_scale(y, py)
    if max(abs(math.log2(cu)), abs(math.log2(cy))) <= _NO_SCALING_WITHIN:
        # scaling by powers of two is exact: skip the two copies where it changes nothing
        cu = cy = 1.0
    # a positive power of two maps min to min and max to max exactly (rounding is monotone)
    peaks = ((pu[0] * cu, pu[1] * cu), (py[0] * cy, py[1] * cy))
    model = _arx(u * cu if cu != 1.0 else u, y * cy if cy != 1.0 else y, na, nb, nk, step,
                 record=(u, y), peaks=peaks, **meta)
    return in_user_units(model, cu, cy)


#: Signals whose peak lies within 2^±this are fitted unscaled: their squares summed over up to 2^60
#: samples stay far inside float64's normal range (2^±1022), and a power-of-two scaling would give
#: bit-identical estimates (every operation commutes with it exactly), at the cost of two copies.
_NO_SCALING_WITHIN = 100


def _arx(u: np.ndarray, y: np.ndarray, na: int, nb: int, nk: int, step: float, *, warn: bool = True,
         keep_residuals: bool = True, record: tuple | None = None, peaks: tuple | None = None,
         **meta) -> PolynomialModel:
    """:func:`arx` on checked signals, without scaling; ``warn=False`` for the internal fits of
    other estimators (their own diagnostics speak for the final model). With ``record`` (the
    caller's ``(u, y)`` in its own units) or ``keep_residuals=False`` a large fit keeps no residual
    array; with ``record`` its model computes them from the record on first access. ``peaks``:
    ``((min u, max u), (min y, max y))`` when the caller knows them.

    The model object is built once, with every field (a fixed cost that counts in order searches
    and sliding windows at N ≈ 10⁴)."""
    keep_residuals = keep_residuals and record is None
    p = na + nb
    t0 = arx_start(na, nb, nk)
    check_identifiable(u, y, t0 + p + 1,
                       f"ARX [{na} {nb} {nk}] ({p} parameters, {t0} initial samples)", peaks)
    names = parameter_names(na, nb, nk)
    m = y.size - t0
    small = m * (p + 1) <= QR_MAX_ELEMENTS
    X = gram = None
    if not small:
        gram = _normal_equations(u, y, na, nb, nk, t0, names, warn, keep_residuals)
    elif m * (p + 1) > NUMPY_QR_MAX_ELEMENTS:  # scipy.linalg's range: BLAS normal equations
        X = arx_regression(u, y, na, nb, nk)
        gram = _blas_normal_equations(X, names, warn)
    if gram is None:  # small, or ill-conditioned: QR of the materialised [Φ | Y]
        X = arx_regression(u, y, na, nb, nk) if X is None else X
        sol = qr_solve(X, names, overwrite=True, warn=warn)
        method = "least squares (QR of [Φ | Y])"
        A, B = _polynomials(sol.theta, na, nk)
        # PolynomialModel.prediction_errors of an ARX model, on the same arrays
        e = np.convolve(y, A)[t0:y.size] - np.convolve(u, B)[t0:u.size]
        see, fit = float(e @ e), fit_percent(y[t0:], y[t0:] - e)
    elif X is not None:
        method = "least squares (normal equations of the BLAS Gram matrix, Cholesky)"
        sol, e, see, syy = gram
        A, B = _polynomials(sol.theta, na, nk)
        fit = 100.0 * (1.0 - math.sqrt(see / syy))
    else:
        method = "least squares (normal equations from compensated lagged sums, Cholesky)"
        sol, e, see, syy = gram
        A, B = _polynomials(sol.theta, na, nk)
        fit = 100.0 * (1.0 - np.sqrt(see / syy))
    sigma2 = see / (m - p)
    if e is not None:
        e.flags.writeable = False  # handed to the model without a copy
    # every array is fresh and checked here (θ finite: Σe² is): no copies nor checks again
    build = PolynomialModel._estimated if math.isfinite(see) else PolynomialModel
    return build(A, B, nk, dt=step, structure="arx", n_samples=int(y.size),
                 covariance=sigma2 * sol.cov_unscaled, noise_variance=sigma2, loss=0.5 * see / m,
                 fit_percent=fit, n_used=m, estimation_residuals=e,
                 estimation_data=record,  # also the source of simulation_fit_percent
                 info={"method": method, "cond": sol.cond}, **meta)


def _polynomials(theta, na, nk) -> tuple[np.ndarray, np.ndarray]:
    """``A = [1, a…]`` and ``B = [0]*nk + [b…]`` (MATLAB layout) from θ."""
    A = np.empty(na + 1)
    A[0] = 1.0
    A[1:] = theta[:na]
    B = np.zeros(nk + theta.size - na)
    B[nk:] = theta[na:]
    return A, B


@functools.lru_cache(maxsize=256)
def parameter_names(na: int, nb: int, nk: int) -> tuple[str, ...]:
    """``('a1', …, 'a<na>', 'b<nk>', …, 'b<nk+nb−1>')``, θ's order (one tuple per structure)."""
    return tuple(f"a{i}" for i in range(1, na + 1)) + tuple(f"b{nk + j}" for j in range(nb))


def _model(theta, na, nk, step, n, meta) -> PolynomialModel:
    A, B = _polynomials(theta, na, nk)
    return PolynomialModel(A, B, nk, dt=step, structure="arx", n_samples=int(n), **meta)


def _normal_equations(u, y, na, nb, nk, t0, names, warn, keep_residuals):
    """The solution from the Gram matrix of ``[Φ | Y]`` (:mod:`.lagged_sums`: one pass, O(q²)
    memory) with the residuals and their sums ``(sol, e, Σe², Σ(y − ȳ)²)``, or None when Φ is too
    ill-conditioned for it (then QR is used). ρ² is the residuals' compensated Σe², not
    ``YᵀY − rᵀr`` (which cancels when the fit is good)."""
    from .lagged_sums import (  # numba: only for large problems
        arx_gram,
        arx_residuals,
        gram_triangle,
    )

    G = arx_gram(u, y, na, nb, nk, t0)
    r1, condition = gram_triangle(G, with_condition=True)
    if r1 is None:
        return None
    p = na + nb
    R = np.zeros((p + 1, p + 1))
    R[:p, :p] = r1
    R[:p, p] = solve_upper(r1, G[:p, p], trans=1)  # R1ᵀ r = ΦᵀY
    theta = solve_upper(r1, R[:p, p])
    e, see, syy = arx_residuals(u, y, theta, na, nb, nk, t0, keep_residuals)
    R[p, p] = np.sqrt(see)
    return (triangular_solve(R, names, y.size - t0, warn, stacklevel=5, condition=condition),
            e, see, syy)


def blas_gram_cond_limit(m: int) -> float:
    """Largest column-scaled κ of Φ (m rows) for which :func:`_blas_normal_equations` is used:
    an uncompensated BLAS sum of m products errs by at most ``m·u`` relative to ``Σ|x z|``, and
    the normal equations turn a relative error ε of the Gram matrix into up to ``κ²ε`` in θ; the
    limit keeps ``κ²·m·u`` at 1e-8 (the lagged sums' bound, with m for their ``BLOCK``)."""
    return math.sqrt(1e-8 / (m * 2.0**-53))


@functools.cache
def _lapack():
    """scipy's LAPACK wrappers, imported on first use (scipy.linalg is a noticeable part of a
    fresh process's start-up; the regressors that take this route are large enough to load it
    anyway for QR)."""
    from scipy.linalg import lapack

    return lapack


def _blas_normal_equations(X: np.ndarray, names: tuple, warn: bool):
    """``(sol, e, Σe², Σ(y − ȳ)²)`` from the normal equations of the materialised ``X = [Φ | Y]``
    (one BLAS product ``Xᵀ Φ``, Cholesky), the residuals ``e = X·[−θ; 1] = Y − Φθ`` in one more
    pass over X; or None when Φ is not positive definite or its column-scaled κ exceeds
    :func:`blas_gram_cond_limit` (then QR is used). At N ≈ 10⁴ ``geqrf`` alone costs more than
    this whole route. ``(ΦᵀΦ)⁻¹`` for the covariance comes from the Cholesky factor
    (``dpotri``), not from another solve; the LAPACK routines are called directly (numpy's and
    scipy's wrappers cost more than these p×p problems)."""
    lapack = _lapack()
    m, q = X.shape
    p = q - 1
    G = X.T @ X[:, :p]  # (q, p): ΦᵀΦ over YᵀΦ; a gemm (numpy's X.T @ X, a syrk, is slower here)
    r1, info = lapack.dpotrf(G[:p], lower=0, clean=1)
    if info != 0:
        return None
    col = np.sqrt(G.diagonal())  # column norms of Φ
    sv = lapack.dgesdd(r1 / col, compute_uv=0)[1]  # singular vectors only for a warning
    # κ ≤ the limit (< COND_LIMIT) also means no column is zero: check_determined passes
    cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else math.inf
    if not cond <= blas_gram_cond_limit(m):  # NaN too
        return None
    theta = lapack.dpotrs(r1, G[p], lower=0)[0]  # R1ᵀ r = ΦᵀY, then R1 θ = r
    w = np.empty(q)
    np.negative(theta, out=w[:p])
    w[p] = 1.0
    e = X @ w
    see = float(e.dot(e))
    syy = _centred_sum_of_squares(X[:, p])
    if syy == 0.0:
        raise DataError("the fit is undefined for a constant output (‖y − ȳ‖ = 0)")
    # (R1ᵀR1)⁻¹ = R1⁻¹R1⁻ᵀ from the factor (dpotri: its upper triangle), mirrored
    c = lapack.dpotri(r1, lower=0)[0]
    cov = np.where(_upper(p), c, c.T)
    if warn and cond > COND_NOTABLE:  # warn_threshold is never below COND_NOTABLE
        sv, vt = lapack.dgesdd(r1 / col)[1:3]
        r = lapack.dtrtrs(r1, G[p], lower=0, trans=1)[0]  # R1ᵀ r = ΦᵀY
        warn_if_weakly_determined((cond, sv, vt, col), names, theta, r, math.sqrt(see), cov, m)
    return QRSolution(theta, see, r1, cov, cond, m), e, see, syy


@functools.lru_cache(maxsize=64)
def _upper(p: int) -> np.ndarray:
    """(p, p) mask, True on and above the diagonal (the mirror is its transpose)."""
    return np.triu(np.ones((p, p), dtype=bool))


def _centred_sum_of_squares(y: np.ndarray) -> float:
    """``Σ(y − ȳ)²``: as ``Σy² − (Σy)²/m`` (no N-sample temporary) when the mean is at most the
    spread (``(Σy)²/m ≤ Σy²/2``), where the rounding of both sums (≤ m·u each, relative to Σy²)
    costs at most ``3·m·u·Σy² ≤ 6·m·u`` of the result (2e-11 relative at m = 3·10⁴); otherwise
    from the centred samples."""
    s = float(np.add.reduce(y))
    yy = float(y.dot(y))
    mean_sq = s * (s / y.size)
    if mean_sq <= 0.5 * yy:
        return yy - mean_sq
    d = y - s / y.size
    return float(d.dot(d))


def checked_records(records, what: str) -> list:
    """``records`` as a list of at least one ``(u, y)`` pair, each checked (:func:`check_io`),
    or a DataError naming the record."""
    pair = isinstance(records, tuple) and len(records) == 2
    if pair and not isinstance(records[0], (tuple, list)):
        records = [records]  # one (u, y) pair
    try:
        records = list(records)
    except TypeError:
        raise DataError(f"records: expected a list of (u, y) pairs, found "
                        f"{type(records).__name__}") from None
    if not records:
        raise DataError(f"records: {what} needs at least one (u, y) record, found an empty list")
    out = []
    for i, r in enumerate(records):
        if not (isinstance(r, (tuple, list)) and len(r) == 2):
            raise DataError(f"records[{i}]: expected a (u, y) pair, found {type(r).__name__}",
                            hint="pass records=[(u1, y1), (u2, y2), ...]")
        try:
            out.append(check_io(*r))
        except DataError as exc:
            raise DataError(f"records[{i}]: {exc.message}", hint=exc.hint) from None
    return out


def check_record_lengths(recs: list, t0: int, label: str) -> None:
    """Every record longer than its ``t0`` initial samples, or a DataError naming the record."""
    for i, (_, y) in enumerate(recs):
        if y.size <= t0:
            raise DataError(f"records[{i}]: {label} takes the first {t0} samples of every record "
                            f"as its initial conditions, so a record needs more than {t0} samples, "
                            f"found {y.size}", hint="drop the short record or lower the orders")


def scaled_records(recs: list, skip_within: float = 0.0) -> tuple[list, float, float]:
    """The records with their input and output scaled to unit size (one power of two for all
    records, :func:`~gripkit.sysid.scaling.unit_scale`) and the factors ``(scaled, cu, cy)``,
    after the checks that need all the records: a varying input and a varying output. Peaks
    within 2^±``skip_within`` stay unscaled."""
    u_all = np.concatenate([u for u, _ in recs])
    y_all = np.concatenate([y for _, y in recs])
    check_excitation(u_all)
    check_output_varies(y_all)
    cu, cy = unit_scale(u_all), unit_scale(y_all)
    if max(abs(np.log2(cu)), abs(np.log2(cy))) <= skip_within:
        cu = cy = 1.0
    return [(u * cu, y * cy) if (cu, cy) != (1.0, 1.0) else (u, y) for u, y in recs], cu, cy


def records_summary(ys: list, errs: list, t0: int) -> tuple[float, list, list, np.ndarray]:
    """(fit of all records, per-record dicts, start of each record's errors, all errors read-only)
    from each record's predicted outputs ``ys`` (samples t0 … N_i − 1) and prediction errors."""
    yhats = [yi - ei for yi, ei in zip(ys, errs)]
    per_record = [{"n_samples": int(yi.size + t0), "n_used": int(yi.size),
                   "fit_percent": fit_percent(yi, hi)} for yi, hi in zip(ys, yhats)]
    e = np.concatenate(errs)
    e.flags.writeable = False
    starts = np.cumsum([0] + [yi.size for yi in ys[:-1]]).tolist()
    return float(records_fit(ys, yhats)), per_record, starts, e


def arx_records(records, na: int, nb: int, nk: int = 1, *, dt: float | None = None,
                **meta) -> PolynomialModel:
    """Least-squares ARX fitted to several records at once (one model, one θ, one σ).

    ``records``: a list of ``(u, y)`` pairs (1-D arrays, each record its own length, in deviation
    units around one common operating point). Every record supplies its own initial conditions:
    its first ``start = max(na, nk + nb − 1)`` samples only fill the regressor, so no regressor
    row reaches across from one record into the next (joining the records into one array would
    make the rows at each seam mix the end of one record with the start of the next, a false
    transient that biases θ). The rows of all records are stacked into one least-squares problem:

        θ = argmin Σ_i Σ_{t=start}^{N_i−1} (y_i(t) − φ_i(t)ᵀθ)²,   σ² = Σ e² / (Σ_i M_i − p),

    M_i = N_i − start. The covariance is σ²(ΦᵀΦ)⁻¹ of the stacked Φ. With one record the result
    is that of :func:`arx` (same rows). ``fit_percent`` is the one-step fit of all the records,
    each about its own mean (:func:`~gripkit.sysid.linear.validation.records_fit`);
    ``info['records']`` gives each record's samples and one-step fit; ``estimation_residuals`` are
    the records' one-step errors one after another (``info['record_starts']``: where each begins).

    Examples
    --------
    >>> import numpy as np
    >>> from gripkit.sysid import arx_records
    >>> rng = np.random.default_rng(0)
    >>> recs = []
    >>> for n in (800, 1200):
    ...     u = rng.standard_normal(n); y = np.zeros(n); y[0] = 3.0
    ...     for t in range(1, n):
    ...         y[t] = 0.9 * y[t - 1] + 0.5 * u[t - 1] + 0.01 * rng.standard_normal()
    ...     recs.append((u, y))
    >>> m = arx_records(recs, 1, 1, 1)
    >>> np.round(m.theta, 2).tolist(), m.n_used
    ([-0.9, 0.5], 1998)
    """
    meta = channel_meta(meta, arx, True)
    recs = checked_records(records, "arx_records")
    step = check_dt(dt)
    na, nb, nk = check_order(na, "na"), check_order(nb, "nb", 1), check_order(nk, "nk")
    p = na + nb
    t0 = arx_start(na, nb, nk)
    what = f"ARX [{na} {nb} {nk}] ({p} parameters, {t0} initial samples in every record)"
    check_record_lengths(recs, t0, f"ARX [{na} {nb} {nk}]")
    m = sum(y.size - t0 for _, y in recs)
    require_samples(m + t0, t0 + p + 1, what)
    scaled, cu, cy = scaled_records(recs, skip_within=_NO_SCALING_WITHIN)
    names = parameter_names(na, nb, nk)
    sol = theta = R = None
    if m * (p + 1) > QR_MAX_ELEMENTS:  # the records' Gram matrices summed (O(p²) memory)
        import scipy.linalg as sla

        from .lagged_sums import arx_gram, gram_triangle

        G = sum(arx_gram(u, y, na, nb, nk, t0) for u, y in scaled)
        r1 = gram_triangle(G)
        if r1 is not None:
            R = np.zeros((p + 1, p + 1))
            R[:p, :p] = r1
            R[:p, p] = sla.solve_triangular(r1, G[:p, p], trans="T", check_finite=False)
            theta = sla.solve_triangular(r1, R[:p, p], check_finite=False)
            method = "least squares over the records (summed normal equations, Cholesky)"
    if theta is None:
        X = np.asfortranarray(np.vstack([arx_regression(u, y, na, nb, nk, t0)
                                         for u, y in scaled]))
        sol = qr_solve(X, names, overwrite=True)
        theta = sol.theta
        method = "least squares over the records (QR of the stacked [Φ | Y])"
    model = _model(theta, na, nk, step, sum(y.size for _, y in recs), meta)
    errs = [model.prediction_errors(u, y) for u, y in scaled]
    e = np.concatenate(errs)
    see = float(e @ e)
    if sol is None:  # ρ² from the residuals, as in :func:`_normal_equations`
        R[p, p] = np.sqrt(see)
        sol = triangular_solve(R, names, m, True, stacklevel=3)
    sigma2 = see / (m - p)
    fit, per_record, starts, e = records_summary([y[t0:] for _, y in scaled], errs, t0)
    model = model.replace(covariance=sigma2 * sol.cov_unscaled, noise_variance=sigma2,
                          loss=0.5 * see / m, fit_percent=fit, n_used=m, estimation_residuals=e,
                          info={"method": method, "cond": sol.cond, "n_records": len(recs),
                                "records": per_record, "record_starts": starts})
    return in_user_units(model, cu, cy)

