"""MIMO ARX by least squares: matrix polynomials with σ.

    y(t) + A_1 y(t−1) + … + A_na y(t−na) = B_nk u(t−nk) + … + B_{nk+nb−1} u(t−nk−nb+1) + e(t),

A_i (p × p), B_j (p × m), e white with covariance Λ. Every output row is a linear regression on
the same regressor φ(t) = [−y(t−1)ᵀ … −y(t−na)ᵀ, u(t−nk)ᵀ … u(t−nk−nb+1)ᵀ]ᵀ (length
q = p·na + m·nb), solved by the QR least squares of :mod:`gripkit.sysid.regression` (which also
refuses an ill-conditioned regressor). The covariance of vec(θ) (row i = output i) is
``Λ ⊗ (ΦᵀΦ)⁻¹`` with ``Λ = EᵀE/(M − q)``.

The model is a :class:`~gripkit.sysid.linear.polynomial.PolynomialModel` holding the matrix
polynomials ``A`` (na+1, p, p), ``B`` (nk+nb, p, m) and their σ, as :func:`gripkit.sysid.arx`
returns for one input and one output; its ``system`` is the state-space realisation of
:mod:`.matrix_polynomial` (state x(t) = [y(t−1); …; y(t−na); u(t−1); …; u(t−L)],
L = nk + nb − 1, innovation gain K = [I_p; 0]), affine in θ, so the covariance carries exact
tangents. ``fit_percent`` is the one-step fit per output (as for one output);
``info['free_run_fit_percent']`` the free run from the initial state estimated by least squares.
"""

from __future__ import annotations

import numpy as np

from ...errors import DataError
from ..checks import check_columns_vary, check_dt, check_order, io_records
from .linear_model import as_io_matrix, estimate_x0, fit_per_output, free_run
from .polynomial import PolynomialModel, channel_meta
from ..regression import qr_solve
from .validation import records_fit

__all__ = ["arx_mimo", "arx_mimo_records"]


def arx_mimo(u, y, na: int, nb: int, nk: int = 1, *, dt: float | None = None,
             **meta) -> PolynomialModel:
    """Least-squares MIMO ARX (see the module docstring); ``u`` (N, m), ``y`` (N, p).

    Examples
    --------
    >>> import numpy as np
    >>> from gripkit.sysid import arx
    >>> rng = np.random.default_rng(0)
    >>> u = rng.standard_normal((3000, 2))
    >>> y = np.zeros((3000, 2))
    >>> for t in range(1, 3000):
    ...     y[t] = [[0.5, 0.1], [0.0, 0.7]] @ y[t - 1] + u[t - 1] + 0.01 * rng.standard_normal(2)
    >>> m = arx(u, y, 1, 1, 1)
    >>> (np.round(-m.A[1], 2) + 0.0).tolist()
    [[0.5, 0.1], [0.0, 0.7]]
    """
    u = as_io_matrix(u, "input u")
    y = as_io_matrix(y, "output y", u.shape[0])
    meta = channel_meta(meta, arx_mimo, False)
    check_columns_vary(u, y, meta)  # a constant column named, as identify names it
    return _arx_mimo([(u, y)], na, nb, nk, dt, meta)


def arx_mimo_records(records, na: int, nb: int, nk: int = 1, *, dt: float | None = None,
                     **meta) -> PolynomialModel:
    """:func:`arx_mimo` fitted to several records at once: ``records`` a list of ``(u, y)``
    pairs, ``u`` (N_i, m), ``y`` (N_i, p), around one common operating point. Each record's first
    ``start = max(na, nk + nb − 1)`` samples are its own initial conditions (no regressor row
    crosses from one record into the next); the rows of all records form one least-squares
    problem, ``Λ = EᵀE/(Σ M_i − q)``. ``info['free_run_fit_percent']`` is the free-run fit of
    all records per output (each from its own estimated initial state, about its own mean:
    :func:`~gripkit.sysid.linear.validation.records_fit`); ``info['records']`` gives each record's
    samples, free-run and one-step fits and initial state.
    """
    recs = io_records(records)
    return _arx_mimo(recs, na, nb, nk, dt, channel_meta(meta, arx_mimo, False), several=True)


def _arx_mimo(recs, na, nb, nk, dt, meta, several: bool = False) -> PolynomialModel:
    """The fit of :func:`arx_mimo` (one record) and :func:`arx_mimo_records`; ``meta`` the
    model's channel fields (:func:`~.polynomial.channel_meta`)."""
    step = check_dt(dt)
    na, nb, nk = check_order(na, "na"), check_order(nb, "nb", 1), check_order(nk, "nk")
    m = recs[0][0].shape[1]
    p = recs[0][1].shape[1]
    t0 = max(na, nk + nb - 1)
    q = p * na + m * nb
    for i, (u, _) in enumerate(recs):
        if u.shape[0] <= t0:
            where = f"records[{i}]: " if several else ""
            every = " of every record" if several else ""
            raise DataError(f"{where}ARX [{na} {nb} {nk}] takes the first {t0} samples{every} as "
                            f"its initial conditions, so it needs more than {t0} samples, found "
                            f"{u.shape[0]}", hint="use a longer record or lower the orders")
    N = sum(u.shape[0] for u, _ in recs)
    M = N - t0 * len(recs)
    X = np.empty((M, q + 1), order="F")
    Y = np.empty((M, p))
    row = 0
    for u, y in recs:
        Ni = u.shape[0]
        rows = slice(row, row + Ni - t0)
        for i in range(na):
            X[rows, i * p:(i + 1) * p] = -y[t0 - 1 - i:Ni - 1 - i]
        for j in range(nb):
            lag = nk + j
            X[rows, p * na + j * m:p * na + (j + 1) * m] = u[t0 - lag:Ni - lag]
        Y[rows] = y[t0:]
        row += Ni - t0
    names = [f"A{i + 1}[:,{k}]" for i in range(na) for k in range(p)] + \
            [f"B{nk + j}[:,{k}]" for j in range(nb) for k in range(m)]
    theta = np.empty((p, q))
    cov_unscaled = None
    for r in range(p):
        X[:, q] = Y[:, r]
        sol = qr_solve(X, tuple(names))
        theta[r] = sol.theta
        cov_unscaled = sol.cov_unscaled
    E = Y - X[:, :q] @ theta.T
    Lam = E.T @ E / (M - q)
    # vec(θ) row-major: output i, then regressor
    cov = np.kron(Lam, cov_unscaled)
    A = np.concatenate([np.eye(p)[None], theta[:, :p * na].reshape(p, na, p).transpose(1, 0, 2)])
    B = np.concatenate([np.zeros((nk, p, m)),
                        theta[:, p * na:].reshape(p, nb, m).transpose(1, 0, 2)])
    E.flags.writeable = False
    model = PolynomialModel(A, B, nk, dt=step, structure="arx", covariance=0.5 * (cov + cov.T),
                            noise_variance=Lam, loss=0.5 * float(np.sum(E * E)) / M,
                            fit_percent=fit_per_output(Y, Y - E), n_samples=N, n_used=M,
                            estimation_residuals=E,
                            info={"method": "least squares (QR of [Φ | Y] per output)"}, **meta)
    s = model.system
    stable = model.stable
    x0s, runs = [], []
    for u, y in recs:
        x0s.append(estimate_x0(s.A, s.B, s.C, s.D, u, y))
        runs.append(free_run(s.A, s.B, s.C, s.D, u, x0s[-1]) if stable else None)
    if len(recs) == 1:
        free = fit_per_output(recs[0][1], runs[0]) if stable else None
    else:
        free = records_fit([y for _, y in recs], runs).tolist() if stable else None
    info = dict(model.info, free_run_fit_percent=free)
    if several:
        row, info["records"] = 0, []
        for (u, y), x0i, run in zip(recs, x0s, runs):
            rows = slice(row, row + u.shape[0] - t0)
            row = rows.stop
            info["records"].append({
                "n_samples": int(u.shape[0]), "n_used": int(u.shape[0] - t0),
                "fit_percent": None if run is None else fit_per_output(y, run),
                "one_step_fit_percent": fit_per_output(Y[rows], Y[rows] - E[rows]), "x0": x0i})
        info["n_records"] = len(recs)
    return model.replace(info=info)
