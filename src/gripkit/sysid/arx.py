"""ARX identification by least squares (QR), eq (20)–(23) and (29) of ``000_8f66dcc7ab06470c.txt``.

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

from ._scaling import in_user_units, unit_scale
from .checks import check_identifiable, checked_problem
from .polynomial import PolynomialModel, check_meta
from .regression import arx_regression, arx_start, qr_solve
from .validation import fit_percent, loss_vn

__all__ = ["arx"]


def arx(u, y, na: int, nb: int, nk: int = 1, *, dt: float | None = None, fs: float | None = None,
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
    dt, fs
        Sample interval (s) or rate (Hz); default: dt = 1 (time in samples).
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
        from .arx_mimo import arx_mimo

        return arx_mimo(u, y, na, nb, nk, dt=dt, fs=fs, **meta)
    u, y, step, na, nb, nk = checked_problem(u, y, dt, fs, na=na, nb=nb, nk=nk)
    cu, cy = unit_scale(u), unit_scale(y)
    return in_user_units(_arx(u * cu, y * cy, na, nb, nk, step, **meta), cu, cy)


def _arx(u: np.ndarray, y: np.ndarray, na: int, nb: int, nk: int, step: float, *, warn: bool = True,
         **meta) -> PolynomialModel:
    """:func:`arx` on checked signals, without scaling; ``warn=False`` for the internal fits of
    other estimators (their own diagnostics speak for the final model)."""
    p = na + nb
    t0 = arx_start(na, nb, nk)
    check_identifiable(u, y, t0 + p + 1, f"ARX [{na} {nb} {nk}] ({p} parameters, {t0} initial samples)")
    names = tuple(f"a{i}" for i in range(1, na + 1)) + tuple(f"b{nk + j}" for j in range(nb))
    sol = qr_solve(arx_regression(u, y, na, nb, nk), names, overwrite=True, warn=warn)
    A = np.concatenate([[1.0], sol.theta[:na]])
    B = np.concatenate([np.zeros(nk), sol.theta[na:]])
    model = PolynomialModel(A, B, nk, dt=step, structure="arx", n_samples=int(y.size), **meta)
    e = model.prediction_errors(u, y)
    m = e.size
    sigma2 = float(e @ e) / (m - p)
    return model.replace(covariance=sigma2 * sol.cov_unscaled, noise_variance=sigma2, loss=loss_vn(e),
                         fit_percent=fit_percent(y[t0:], y[t0:] - e), n_used=m, residuals=e,
                         info={"method": "least squares (QR of [Φ | Y])", "cond": sol.cond})
