"""MIMO ARX by least squares: matrix polynomials with σ.

    y(t) + A_1 y(t−1) + … + A_na y(t−na) = B_nk u(t−nk) + … + B_{nk+nb−1} u(t−nk−nb+1) + e(t),

A_i (p × p), B_j (p × m), e white with covariance Λ. Every output row is a linear regression on
the same regressor φ(t) = [−y(t−1)ᵀ … −y(t−na)ᵀ, u(t−nk)ᵀ … u(t−nk−nb+1)ᵀ]ᵀ (length
q = p·na + m·nb), solved by the QR least squares of :mod:`gripkit.sysid.regression` (which also
refuses an ill-conditioned regressor). The covariance of vec(θ) (row i = output i) is
``Λ ⊗ (ΦᵀΦ)⁻¹`` with ``Λ = EᵀE/(M − q)``.

The model is returned as a :class:`~gripkit.sysid.linear.linear_model.LinearModel` on a (non-minimal)
state-space realisation with state x(t) = [y(t−1); …; y(t−na); u(t−1); …; u(t−L)],
L = nk + nb − 1, whose innovation gain K = [I_p; 0] makes its one-step predictor the ARX
predictor. A, B, C, D are affine in θ, so the covariance carries exact tangents; the matrix
polynomials and their σ are in ``info`` (``A_poly``, ``B_poly``, ``A_poly_std``, ``B_poly_std``).
"""

from __future__ import annotations

import numpy as np

from ...errors import DataError
from ...lti import StateSpace, Uncertainty
from ..checks import check_dt, check_order, io_records
from .linear_model import LinearModel, as_io_matrix, estimate_x0, fit_per_output, free_run
from ..regression import qr_solve
from .validation import records_fit

__all__ = ["arx_mimo", "arx_mimo_records"]


def _realisation(theta, p, m, na, nb, nk):
    """(A, B, C, D) of the ARX with coefficient rows ``theta`` (p, q)."""
    L = nk + nb - 1
    n = p * na + m * L
    Ay = theta[:, :p * na]                   # multiplies −y(t−1) … −y(t−na)
    Bu = theta[:, p * na:]                   # multiplies u(t−nk) … u(t−nk−nb+1)
    C = np.zeros((p, n))
    D = np.zeros((p, m))
    C[:, :p * na] = -Ay
    for j in range(nb):
        lag = nk + j
        blk = Bu[:, j * m:(j + 1) * m]
        if lag == 0:
            D += blk
        else:
            C[:, p * na + (lag - 1) * m:p * na + lag * m] += blk
    A = np.zeros((n, n))
    B = np.zeros((n, m))
    if na:
        A[:p] = C
        B[:p] = D
        A[p:p * na, :p * (na - 1)] = np.eye(p * (na - 1))
    if L:
        B[p * na:p * na + m] = np.eye(m)
        A[p * na + m:, p * na:p * na + m * (L - 1)] = np.eye(m * (L - 1))
    return A, B, C, D


def arx_mimo(u, y, na: int, nb: int, nk: int = 1, *, dt: float | None = None,
             inputs=None, outputs=None, input_units=None, output_units=None, u_offset=None, y_offset=None,
             **_meta) -> LinearModel:
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
    >>> (np.round(-np.asarray(m.info["A_poly"][0]), 2) + 0.0).tolist()
    [[0.5, 0.1], [0.0, 0.7]]
    """
    u = as_io_matrix(u, "input u")
    y = as_io_matrix(y, "output y", u.shape[0])
    meta = dict(inputs=inputs, outputs=outputs, input_units=input_units, output_units=output_units,
                u_offset=u_offset, y_offset=y_offset)
    return _arx_mimo([(u, y)], na, nb, nk, dt, meta)


def arx_mimo_records(records, na: int, nb: int, nk: int = 1, *, dt: float | None = None,
                     inputs=None, outputs=None, input_units=None, output_units=None, u_offset=None,
                     y_offset=None) -> LinearModel:
    """:func:`arx_mimo` fitted to several records at once: ``records`` a list of ``(u, y)``
    pairs, ``u`` (N_i, m), ``y`` (N_i, p), around one common operating point. Each record's first
    ``start = max(na, nk + nb − 1)`` samples are its own initial conditions (no regressor row
    crosses from one record into the next); the rows of all records form one least-squares
    problem, ``Λ = EᵀE/(Σ M_i − q)``. ``fit_percent`` is the free-run fit of all records per
    output (each from its own estimated initial state, about its own mean:
    :func:`~gripkit.sysid.linear.validation.records_fit`); ``info['records']`` gives each record's
    samples, free-run and one-step fits and initial state (``x0`` of the model: the first
    record's).
    """
    recs = io_records(records)
    meta = dict(inputs=inputs, outputs=outputs, input_units=input_units, output_units=output_units,
                u_offset=u_offset, y_offset=y_offset)
    return _arx_mimo(recs, na, nb, nk, dt, meta, several=True)


def _arx_mimo(recs, na, nb, nk, dt, meta, several: bool = False) -> LinearModel:
    """The fit of :func:`arx_mimo` (one record) and :func:`arx_mimo_records`."""
    inputs, outputs = meta["inputs"], meta["outputs"]
    input_units, output_units = meta["input_units"], meta["output_units"]
    u_offset, y_offset = meta["u_offset"], meta["y_offset"]
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
    cov = np.kron(Lam, cov_unscaled)                     # vec(θ) row-major: output i, then regressor
    A, B, C, D = _realisation(theta, p, m, na, nb, nk)
    k = p * q
    tangents = [np.empty((k,) + X_.shape) for X_ in (A, B, C, D)]
    zero = _realisation(np.zeros((p, q)), p, m, na, nb, nk)
    for i in range(k):
        e = np.zeros(k)
        e[i] = 1.0
        for t, a, z in zip(tangents, _realisation(e.reshape(p, q), p, m, na, nb, nk), zero):
            t[i] = a - z
    pnames = tuple(f"y{i}:{nm}" for i in range(p) for nm in [f"θ{j}" for j in range(q)])
    unc = Uncertainty(pnames, 0.5 * (cov + cov.T), tuple(tangents))
    sys = StateSpace(A, B, C, D, dt=step, inputs=inputs, outputs=outputs, input_units=input_units,
                     output_units=output_units, uncertainty=unc, meta={"identified_by": "arx (least squares)"})
    n = A.shape[0]
    Kg = np.zeros((n, p))
    if na:
        Kg[:p] = np.eye(p)
    stable = sys.is_stable()
    x0s, runs = [], []
    for u, y in recs:
        x0s.append(estimate_x0(A, B, C, D, u, y))
        runs.append(free_run(A, B, C, D, u, x0s[-1]) if stable else None)
    x0 = x0s[0]
    if len(recs) == 1:
        u, y = recs[0]
        fit = fit_per_output(y, runs[0]) if stable else None
    else:
        fit = records_fit([y for _, y in recs], runs).tolist() if stable else None
    std = np.sqrt(np.diag(cov)).reshape(p, q)
    info = {"orders": {"na": na, "nb": nb, "nk": nk},
            "A_poly": [theta[:, i * p:(i + 1) * p] for i in range(na)],
            "A_poly_std": [std[:, i * p:(i + 1) * p] for i in range(na)],
            "B_poly": [theta[:, p * na + j * m:p * na + (j + 1) * m] for j in range(nb)],
            "B_poly_std": [std[:, p * na + j * m:p * na + (j + 1) * m] for j in range(nb)],
            "one_step_fit_percent": fit_per_output(Y, Y - E)}
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
    return LinearModel(sys, "arx", K=Kg, x0=x0, noise_covariance=Lam, fit_percent=fit, u_offset=u_offset,
                       y_offset=y_offset, n_samples=N, info=info)
