"""ARX identification by least squares, eq (20)–(23) and (29) of ``000_8f66dcc7ab06470c.txt``.

>>> import numpy as np
>>> from gripkit.sysid import arx
>>> rng = np.random.default_rng(0)
>>> u = rng.standard_normal(2000)
>>> y = np.zeros(2000)
>>> for t in range(3, 2000):  # Table II, [2 2 2], S1, filtered data
...     y[t] = 1.8732*y[t-1] - 0.8996*y[t-2] + 0.1950*u[t-2] - 0.2276*u[t-3] + 0.001*rng.standard_normal()
>>> m = arx(u, y, 2, 2, 2)
>>> np.round(m.A, 3).tolist(), np.round(m.B, 3).tolist()
([1.0, -1.873, 0.9], [0.0, 0.0, 0.195, -0.228])
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from ._scaling import in_user_units, unit_scale
from .arx_mimo import arx_mimo
from .checks import check_identifiable, checked_problem
from .polynomial import PolynomialModel, check_meta
from .regression import arx_regression, arx_start, qr_solve, triangular_solve
from .validation import fit_percent

__all__ = ["arx"]

#: Regressors up to this many elements (``m·(p+1)``, 2 MiB of float64) are materialised and
#: solved by QR: a few milliseconds at most, and no numba import or kernel load (0.45 s of a
#: fresh process). Larger ones take the one-pass compensated lagged sums (O(p²) memory).
QR_MAX_ELEMENTS = 2**18


def arx(u, y, na: int, nb: int, nk: int = 1, *, dt: float | None = None,
        **meta) -> PolynomialModel:
    """Least-squares ARX model ``A(q) y(t) = B(q) u(t) + e(t)`` in MATLAB's ``[na nb nk]`` layout.

    Parameters
    ----------
    u, y
        Input and output samples, shape (N,), uniformly sampled, in deviation units (remove an
        operating point first: :func:`gripkit.sysid.identify` does it with ``detrend='mean'``).
    na, nb, nk
        Number of A coefficients (after the leading 1), number of B coefficients, input delay in
        samples (``B`` gets ``nk`` leading zeros). Table II's ``[2 2 2]`` is ``na=2, nb=2, nk=2``.
    dt
        Sample interval (s); default 1 (time in samples).
    **meta
        Model metadata: ``input_name``, ``output_name``, ``input_unit``, ``output_unit``,
        ``u_offset``, ``y_offset``.

    With several input or output columns (``u`` (N, m), ``y`` (N, p)) the model is a MIMO ARX
    of matrix polynomials: see :func:`gripkit.sysid.arx_mimo.arx_mimo`.

    Returns
    -------
    PolynomialModel
        ``.A``, ``.B``, ``.A_std``, ``.B_std`` (MATLAB layout), ``.covariance``, ``.loss`` (eq 29),
        ``.fit_percent`` (one-step prediction), ``.aic``, ``.fpe``, ``.residuals``.

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

    The signals are scaled to unit size internally (exact powers of two, :mod:`._scaling`), so data
    at any scale (1e-300 … 1e300) are identified; the model is in the units of ``u`` and ``y``.
    """
    check_meta(meta, arx)
    if any(np.ndim(x) == 2 and np.shape(x)[1] > 1 for x in (u, y)):  # several inputs or outputs
        return arx_mimo(u, y, na, nb, nk, dt=dt, **meta)
    u, y, step, na, nb, nk = checked_problem(u, y, dt, na=na, nb=nb, nk=nk)
    cu, cy = unit_scale(u), unit_scale(y)
    if max(abs(np.log2(cu)), abs(np.log2(cy))) <= _NO_SCALING_WITHIN:
        cu = cy = 1.0  # scaling by powers of two is exact: skip the two copies where it changes nothing
    model = _arx(u * cu if cu != 1.0 else u, y * cy if cy != 1.0 else y, na, nb, nk, step, record=(u, y), **meta)
    return in_user_units(model, cu, cy)


#: Signals whose peak lies within 2^±this are fitted unscaled: their squares summed over up to 2^60
#: samples stay far inside float64's normal range (2^±1022), and a power-of-two scaling would give
#: bit-identical estimates (every operation commutes with it exactly), at the cost of two copies.
_NO_SCALING_WITHIN = 100


def _arx(u: np.ndarray, y: np.ndarray, na: int, nb: int, nk: int, step: float, *, warn: bool = True,
         keep_residuals: bool = True, record: tuple | None = None, **meta) -> PolynomialModel:
    """:func:`arx` on checked signals, without scaling; ``warn=False`` for the internal fits of
    other estimators (their own diagnostics speak for the final model). With ``record`` (the
    caller's ``(u, y)`` in its own units) or ``keep_residuals=False`` a large fit keeps no residual
    array; with ``record`` its model computes them from the record on first access."""
    keep_residuals = keep_residuals and record is None
    p = na + nb
    t0 = arx_start(na, nb, nk)
    check_identifiable(u, y, t0 + p + 1, f"ARX [{na} {nb} {nk}] ({p} parameters, {t0} initial samples)")
    names = tuple(f"a{i}" for i in range(1, na + 1)) + tuple(f"b{nk + j}" for j in range(nb))
    m = y.size - t0
    small = m * (p + 1) <= QR_MAX_ELEMENTS
    gram = None if small else _normal_equations(u, y, na, nb, nk, t0, names, warn, keep_residuals)
    if gram is None:  # small, or ill-conditioned: QR of the materialised [Φ | Y]
        sol = qr_solve(arx_regression(u, y, na, nb, nk), names, overwrite=True, warn=warn)
        method = "least squares (QR of [Φ | Y])"
        model = _model(sol.theta, na, nk, step, y.size, meta)
        e = model.prediction_errors(u, y)
        see, fit = float(e @ e), fit_percent(y[t0:], y[t0:] - e)
    else:
        method = "least squares (normal equations from compensated lagged sums, Cholesky)"
        sol, e, see, syy = gram
        model = _model(sol.theta, na, nk, step, y.size, meta)
        fit = 100.0 * (1.0 - np.sqrt(see / syy))
    sigma2 = see / (m - p)
    if e is not None:
        e.flags.writeable = False  # handed to the model without a copy
    return model.replace(covariance=sigma2 * sol.cov_unscaled, noise_variance=sigma2, loss=0.5 * see / m,
                         fit_percent=fit, n_used=m, residuals=e, estimation_data=record if e is None else None,
                         info={"method": method, "cond": sol.cond})


def _model(theta, na, nk, step, n, meta) -> PolynomialModel:
    A = np.concatenate([[1.0], theta[:na]])
    B = np.concatenate([np.zeros(nk), theta[na:]])
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
    r1 = gram_triangle(G)
    if r1 is None:
        return None
    p = na + nb
    R = np.zeros((p + 1, p + 1))
    R[:p, :p] = r1
    R[:p, p] = sla.solve_triangular(r1, G[:p, p], trans="T", check_finite=False)  # R1ᵀ r = ΦᵀY
    theta = sla.solve_triangular(r1, R[:p, p], check_finite=False)
    e, see, syy = arx_residuals(u, y, theta, na, nb, nk, t0, keep_residuals)
    R[p, p] = np.sqrt(see)
    return triangular_solve(R, names, y.size - t0, warn, stacklevel=5), e, see, syy
