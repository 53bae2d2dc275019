"""Linear regression for ARX models: regressor construction and QR least squares.

The ARX model of ``000_8f66dcc7ab06470c.txt`` eq (20)/(23), in MATLAB's ``[na nb nk]`` layout::

    y(t) + a_1 y(t-1) + ... + a_na y(t-na) = b_nk u(t-nk) + ... + b_{nk+nb-1} u(t-nk-nb+1) + e(t)

is the linear regression ``y(t) = φ(t)ᵀ θ + e(t)`` with (eq 21)::

    θ = [a_1 ... a_na, b_nk ... b_{nk+nb-1}]ᵀ
    φ(t) = [-y(t-1) ... -y(t-na), u(t-nk) ... u(t-nk-nb+1)]ᵀ

for ``t = t0 ... N-1``, ``t0 = max(na, nk+nb-1)`` (the first sample whose regressor is known).

The least-squares solution is computed from the QR factorisation of the augmented matrix
``[Φ | Y] = Q R`` (LAPACK ``dgeqrf``; Q is never formed): with ``R = [[R1, r], [0, ρ]]``,
``θ = R1⁻¹ r`` and the residual sum of squares is ``ρ²``. The normal equations ``ΦᵀΦ θ = ΦᵀY``
are never formed (they square the condition number). The parameter covariance is
``σ² (R1ᵀ R1)⁻¹ = σ² R1⁻¹ R1⁻ᵀ`` with ``σ² = ρ² / (M − p)``, M = N − t0 equations, p parameters.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import AccuracyWarning, UnidentifiableError, emit_warning

__all__ = ["arx_start", "arx_regression", "QRSolution", "qr_solve", "triangular_solve",
           "scaled_condition",
           "COND_LIMIT", "warn_threshold", "hac_covariance"]

#: Largest acceptable condition number of the column-scaled regressor. Beyond it the data do
#: not determine the parameters (1e10 keeps about 6 significant digits in float64).
COND_LIMIT = 1e10
#: Largest relative error tolerated, without a warning, in the least-determined combination of the
#: parameters: at 1/3 its 3σ interval reaches zero, i.e. the data no longer determine it at the 3σ
#: level (see :func:`warn_threshold`).
WARN_RELATIVE_ERROR = 1.0 / 3.0
#: The warning is about conditioning: below this κ the weakest parameter combination is known at
#: most 100 times worse than the best one, and large σ come from the noise (σ reports them).
COND_NOTABLE = 100.0


def warn_threshold(sigma_rel: float, tan_phi: float | None = None) -> float:
    """Condition number above which a least-squares fit warns that it barely determines its
    parameters.

    With the columns of Φ scaled to unit norm (parameters θ̃ = θ·‖φ_i‖), the least-determined
    combination of the parameters has σ = σ_e/s_min = κ·σ_e/s_max, so relative to ‖θ̃‖ it is
    ``κ·sigma_rel`` with ``sigma_rel = σ_e/(s_max·‖θ̃‖)`` (σ_e the noise standard deviation, s_max
    the largest singular value). Rounding adds at most ``u·(2κ + κ²·tan φ)``, u = 2⁻⁵³, the
    first-order error bound of a QR least-squares solution (Golub & Van Loan, *Matrix
    Computations*, 4th ed., Thm 5.3.1), ``tan φ = ‖r‖/‖Φθ‖`` the residual-to-fit ratio. The
    threshold is the κ at which either reaches δ = :data:`WARN_RELATIVE_ERROR`:
    ``min(δ/sigma_rel, √(δ/(u·tan φ)), δ/(2u))``, never below :data:`COND_NOTABLE` and never above
    :data:`COND_LIMIT`.
    Noise-free data warn only near the hard limit; 1 % noise over 2000 samples warns near κ ≈ 1e3.
    """
    u = 2.0**-53
    d = WARN_RELATIVE_ERROR
    stat = d / sigma_rel if sigma_rel > 0 else math.inf
    rounding = math.sqrt(d / (u * tan_phi)) if tan_phi else math.inf
    return max(COND_NOTABLE, min(stat, rounding, d / (2 * u), COND_LIMIT))


def arx_start(na: int, nb: int, nk: int) -> int:
    """First sample index whose ARX regressor is fully known: ``max(na, nk + nb - 1)``."""
    return max(na, nk + nb - 1)


def arx_regression(u: np.ndarray, y: np.ndarray, na: int, nb: int, nk: int,
                   t0: int | None = None) -> np.ndarray:
    """Augmented regression matrix ``[Φ | Y]``, shape (N − t0, na + nb + 1), Fortran order.

    Columns: ``-y(t-1) ... -y(t-na), u(t-nk) ... u(t-nk-nb+1), y(t)`` for ``t = t0 ... N-1``.
    ``t0`` defaults to :func:`arx_start`; a larger one (common to several structures, as in a
    structure search) compares models on the same samples.
    """
    n = y.shape[0]
    t0 = arx_start(na, nb, nk) if t0 is None else t0
    m = n - t0
    X = np.empty((m, na + nb + 1), dtype=np.float64, order="F")
    for i in range(na):
        np.negative(y[t0 - 1 - i:n - 1 - i], out=X[:, i])
    for j in range(nb):
        lag = nk + j
        X[:, na + j] = u[t0 - lag:n - lag]
    X[:, na + nb] = y[t0:]
    return X


def solve_upper(r1: np.ndarray, b: np.ndarray, trans: int = 0) -> np.ndarray:
    """``x`` with ``r1 x = b`` (``trans=1``: ``r1ᵀ x = b``) for a nonsingular upper-triangular
    ``r1`` (float64), by numpy's LAPACK ``gesv``: partial pivoting finds each column's largest
    entry on the diagonal (the entries below it are zero), so the LU factors are I and ``r1``
    itself and the solve is the back substitution (for ``r1ᵀ``, the same on the reversed
    system). numpy, not ``scipy.linalg.solve_triangular``: importing scipy.linalg is a
    noticeable part of a CLI start-up, and scipy's argument handling costs more than a small
    solve."""
    if trans:  # r1ᵀ x = b  ⇔  (J r1ᵀ J)(J x) = J b, J the reversal; J r1ᵀ J is upper triangular
        return np.linalg.solve(r1.T[::-1, ::-1], b[::-1])[::-1]
    return np.linalg.solve(r1, b)


#: Regressors up to this many elements are factored by numpy's LAPACK (``np.linalg.qr``), which
#: needs no scipy.linalg import (start-up a small CLI fit does without); larger ones by
#: scipy's ``geqrf`` in place (numpy copies the matrix twice). Both call OpenBLAS's ``dgeqrf``.
NUMPY_QR_MAX_ELEMENTS = 2**15


def qr_r(X: np.ndarray, overwrite: bool) -> np.ndarray:
    """The (q, q) triangular factor R of ``X = QR`` (LAPACK ``geqrf`` called directly: scipy's
    ``qr(mode='r')`` also applies ``triu`` to the whole m×q array, which costs more than the
    factorisation itself for tall matrices)."""
    q = X.shape[1]
    if X.size <= NUMPY_QR_MAX_ELEMENTS:
        return np.linalg.qr(X, mode="r")[:q, :q]  # numpy's triu is of the top q rows only
    import scipy.linalg as sla

    (geqrf,) = sla.get_lapack_funcs(("geqrf",), (X,))
    # workspace n·nb with a generous block size (a workspace query would copy X first)
    qr, _, _, info = geqrf(X, lwork=64 * q, overwrite_a=overwrite)
    if info != 0:  # pragma: no cover - LAPACK argument error
        raise RuntimeError(f"LAPACK geqrf failed (info={info})")
    return np.triu(qr[:q, :q])


@dataclass(frozen=True)
class QRSolution:
    """Least-squares solution of ``Y ≈ Φ θ`` from the QR factorisation of ``[Φ | Y]``.

    Attributes
    ----------
    theta
        Estimate, shape (p,).
    rss
        Residual sum of squares ``‖Y − Φθ‖²``.
    r1
        Upper-triangular factor of Φ, shape (p, p); ``ΦᵀΦ = R1ᵀR1``.
    cov_unscaled
        ``(ΦᵀΦ)⁻¹`` computed as ``R1⁻¹R1⁻ᵀ``; multiply by σ² for the covariance.
    cond
        Condition number of Φ with its columns scaled to unit norm.
    m
        Number of equations (rows of Φ).
    """

    theta: np.ndarray
    rss: float
    r1: np.ndarray
    cov_unscaled: np.ndarray
    cond: float
    m: int


def _weak_combination(vt: np.ndarray, names: tuple[str, ...]) -> list[int]:
    """Indices of the parameters in the near-null direction (last right singular vector ``vt[-1]``
    of the column-scaled regressor), largest first: those whose share exceeds 0.2 of the largest."""
    v = np.abs(vt[-1])
    return [i for i in np.argsort(-v) if v[i] > 0.2 * np.max(v)]


def qr_solve(X: np.ndarray, names: tuple[str, ...], overwrite: bool = False, warn: bool = True,
             values: np.ndarray | None = None) -> QRSolution:
    """Solve the least-squares problem held in the augmented matrix ``X = [Φ | Y]``.

    Raises :class:`UnidentifiableError` naming the parameters that the data do not determine when
    Φ is rank deficient or its column-scaled condition number exceeds :data:`COND_LIMIT`; warns
    (:class:`~gripkit.errors.AccuracyWarning`, unless ``warn=False``) naming the poorly determined
    parameters and their relative σ when it exceeds :func:`warn_threshold`.
    ``overwrite=True`` lets LAPACK factor ``X`` in place (it must then be Fortran-ordered);
    ``values``: the parameter values the warning compares σ with (default: the solution θ; a
    Gauss-Newton step solves for an increment, not for the parameters, and its own rounding does
    not limit the accuracy of the iteration's result, so only the noise term counts then).
    """
    m, q = X.shape
    p = q - 1
    if m <= p:
        raise UnidentifiableError(f"{m} equations cannot determine {p} parameters "
                                  f"({', '.join(names)})",
                                  hint="use a longer record or a smaller model")
    return triangular_solve(qr_r(X, overwrite), names, m, warn, values, stacklevel=4)


def scaled_condition(r1: np.ndarray) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    """Condition number of Φ with its columns scaled to unit norm, from a triangular factor
    ``R1`` (``ΦᵀΦ = R1ᵀR1``); returns ``(cond, sv, vt, col)``: the singular values and right
    singular vectors of the scaled factor and the column norms of Φ (inf and empty ``sv``, ``vt``
    when a column is zero)."""
    col = np.sqrt(np.sum(r1 * r1, axis=0))  # column norms of Φ (Q is orthogonal)
    if (col <= 1e-300).any():
        return np.inf, np.empty(0), np.empty((0, r1.shape[1])), col
    sv, vt = np.linalg.svd(r1 / col, compute_uv=True)[1:]
    return (float(sv[0] / sv[-1]) if sv[-1] > 0 else np.inf), sv, vt, col


def triangular_solve(R: np.ndarray, names: tuple[str, ...], m: int, warn: bool = True,
                     values: np.ndarray | None = None, stacklevel: int = 3,
                     condition: tuple | None = None) -> QRSolution:
    """:func:`qr_solve` from the (q, q) upper-triangular factor ``R`` of ``[Φ | Y]`` (m rows),
    however it was obtained (QR of the data, or Cholesky of its Gram matrix); ``condition``:
    :func:`scaled_condition` of ``R[:p, :p]`` when the caller has it already."""
    p = R.shape[0] - 1
    r1 = R[:p, :p]
    condition = scaled_condition(r1) if condition is None else condition
    check_determined(condition, names)
    r = R[:p, p]
    theta = solve_upper(r1, r)
    rinv = solve_upper(r1, np.eye(p))
    cov = rinv @ rinv.T
    if warn:
        warn_if_weakly_determined(condition, names, theta, r, float(R[p, p]), cov, m, values)
    return QRSolution(theta, float(R[p, p] ** 2), r1.copy(), 0.5 * (cov + cov.T), condition[0],
                      m)


def check_determined(condition: tuple, names: tuple[str, ...]) -> None:
    """An :class:`UnidentifiableError` naming the parameters when a column of Φ is zero or the
    column-scaled condition number (``condition``: :func:`scaled_condition`) exceeds
    :data:`COND_LIMIT`."""
    cond, _, vt, col = condition
    zero = col <= 1e-300
    if zero.any():
        bad = [names[i] for i in np.flatnonzero(zero)]
        raise UnidentifiableError(
            f"the regressor of {', '.join(bad)} is identically zero: the data carry no information "
            f"about {'it' if len(bad) == 1 else 'them'}", hint="check the input and output columns")
    if not cond <= COND_LIMIT:
        involved = [names[i] for i in _weak_combination(vt, names)]
        raise UnidentifiableError(
            f"the data do not determine the parameters (regressor condition number {cond:.3g} > "
            f"{COND_LIMIT:.0e}); the poorly determined combination involves {', '.join(involved)}",
            hint="excite the system more richly (more frequencies than parameters) or "
                 "lower the orders")


def warn_if_weakly_determined(condition: tuple, names: tuple[str, ...], theta: np.ndarray,
                              r: np.ndarray, rho: float, cov: np.ndarray, m: int,
                              values: np.ndarray | None = None) -> None:
    """The :class:`~gripkit.errors.AccuracyWarning` of :func:`qr_solve` when κ exceeds
    :func:`warn_threshold`: ``r``, ``rho`` the last column of R (``R1ᵀr = ΦᵀY``, ρ² the residual
    sum of squares), ``cov`` ``(ΦᵀΦ)⁻¹``."""
    cond, sv, vt, col = condition
    p = theta.size
    rss = rho**2
    val = np.abs(theta if values is None else np.asarray(values, dtype=np.float64))
    vc = val * col
    size = math.sqrt(vc.dot(vc))  # np.linalg.norm of a vector (the same dot), without its dispatch
    sigma_rel = math.sqrt(rss / (m - p)) / (float(sv[0]) * size) if size > 0 else math.inf
    rk = r.ravel(order="K")  # contiguous, as np.linalg.norm makes it
    fitted = math.sqrt(rk.dot(rk))
    tan_phi = (abs(rho) / fitted if fitted > 0 else math.inf) if values is None else None
    limit = warn_threshold(sigma_rel, tan_phi)
    if cond > limit:
        std = np.sqrt(rss / (m - p) * np.clip(np.diag(cov), 0.0, None))
        with np.errstate(divide="ignore"):
            rel = ", ".join(f"{names[i]} (σ/|{names[i]}| = {std[i] / val[i]:.2g})"
                            for i in _weak_combination(vt, names))
        emit_warning(
           f"the data barely determine the parameters (regressor condition number {cond:.3g} > "
           f"{limit:.3g}, the limit for this fit's noise and length; refused above "
           f"{COND_LIMIT:.0e}): "
           f"poorly determined are {rel}; they move together along a nearly "
           "unexcited direction, so "
           "their values may be far from the truth; excite the system more richly "
           "(more frequencies "
           f"than parameters) or lower the orders", AccuracyWarning)


def hac_covariance(X: np.ndarray, r: np.ndarray, lags: int | None = None) -> np.ndarray:
    """Newey-West (Bartlett-kernel) covariance of least-squares estimates θ̂ = (XᵀX)⁻¹Xᵀy whose
    residuals ``r`` are autocorrelated (filtered, differentiated or decimated signals):

        Cov(θ̂) = (XᵀX)⁻¹ S (XᵀX)⁻¹,  S = Γ₀ + Σ_{l=1..L} (1 − l/(L+1)) (Γ_l + Γ_lᵀ),
        Γ_l = Σ_t x_t r_t r_{t−l} x_{t−l}ᵀ,

    with the lag L chosen from the data by Andrews' (1991) AR(1) plug-in for the Bartlett kernel,
    ``L = ⌈1.1447 (α n)^{1/3}⌉``, ``α = 4ρ̂²/((1−ρ̂)²(1+ρ̂)²)``, ρ̂ the residuals' lag-1
    autocorrelation. For white residuals it tends to the usual σ̂²(XᵀX)⁻¹; for correlated ones it
    is the honest (larger) one. Systematic errors (a biased filter, a wrong model) are not in it."""
    X = np.asarray(X, dtype=np.float64)
    r = np.asarray(r, dtype=np.float64)
    n, p = X.shape
    if lags is None:
        rc = r - r.mean()
        rho = float(np.clip((rc[1:] @ rc[:-1]) / max(rc @ rc, 1e-300), -0.97, 0.97))
        alpha = 4 * rho**2 / ((1 - rho) ** 2 * (1 + rho) ** 2)
        L = int(np.ceil(1.1447 * (alpha * n) ** (1.0 / 3.0)))
    else:
        L = int(lags)
    L = max(0, min(L, n // 4))
    g = X * r[:, None]
    S = g.T @ g
    for lag in range(1, L + 1):
        G = g[lag:].T @ g[:-lag]
        S += (1.0 - lag / (L + 1.0)) * (G + G.T)
    Xi = np.linalg.inv(X.T @ X)
    return Xi @ S @ Xi * (n / max(n - p, 1))
