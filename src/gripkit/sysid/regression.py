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

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from ..errors import UnidentifiableError

__all__ = ["arx_start", "arx_regression", "QRSolution", "qr_solve", "triangular_solve", "scaled_condition",
           "COND_LIMIT", "hac_covariance"]

#: Largest acceptable condition number of the column-scaled regressor. Beyond it the data do
#: not determine the parameters (1e10 keeps about 6 significant digits in float64).
COND_LIMIT = 1e10


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


def _qr_r(X: np.ndarray, overwrite: bool) -> np.ndarray:
    """The (q, q) triangular factor R of ``X = QR`` (LAPACK ``geqrf`` called directly: scipy's
    ``qr(mode='r')`` also applies ``triu`` to the whole m×q array, which costs more than the
    factorisation itself for tall matrices)."""
    q = X.shape[1]
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


def qr_solve(X: np.ndarray, names: tuple[str, ...], overwrite: bool = False) -> QRSolution:
    """Solve the least-squares problem held in the augmented matrix ``X = [Φ | Y]``.

    Raises :class:`UnidentifiableError` naming the parameters that the data do not determine when
    Φ is rank deficient or its column-scaled condition number exceeds :data:`COND_LIMIT`.
    ``overwrite=True`` lets LAPACK factor ``X`` in place (it must then be Fortran-ordered).
    """
    m, q = X.shape
    p = q - 1
    if m <= p:
        raise UnidentifiableError(f"{m} equations cannot determine {p} parameters ({', '.join(names)})",
                                  hint="use a longer record or a smaller model")
    return triangular_solve(_qr_r(X, overwrite), names, m)


def scaled_condition(r1: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """Condition number of Φ with its columns scaled to unit norm, from a triangular factor
    ``R1`` (``ΦᵀΦ = R1ᵀR1``); returns ``(cond, vt, col)``: the right singular vectors of the
    scaled factor and the column norms of Φ (inf and an empty ``vt`` when a column is zero)."""
    col = np.sqrt(np.sum(r1 * r1, axis=0))  # column norms of Φ (Q is orthogonal)
    if np.any(col <= 1e-300):
        return np.inf, np.empty((0, r1.shape[1])), col
    sv, vt = np.linalg.svd(r1 / col, compute_uv=True)[1:]
    return (float(sv[0] / sv[-1]) if sv[-1] > 0 else np.inf), vt, col


def triangular_solve(R: np.ndarray, names: tuple[str, ...], m: int) -> QRSolution:
    """:func:`qr_solve` from the (q, q) upper-triangular factor ``R`` of ``[Φ | Y]`` (m rows),
    however it was obtained (QR of the data, or Cholesky of its Gram matrix)."""
    p = R.shape[0] - 1
    r1 = R[:p, :p]
    cond, vt, col = scaled_condition(r1)
    zero = col <= 1e-300
    if zero.any():
        bad = [names[i] for i in np.flatnonzero(zero)]
        raise UnidentifiableError(
            f"the regressor of {', '.join(bad)} is identically zero: the data carry no information "
            f"about {'it' if len(bad) == 1 else 'them'}", hint="check the input and output columns")
    if not cond <= COND_LIMIT:
        v = vt[-1]
        involved = [names[i] for i in np.argsort(-np.abs(v)) if abs(v[i]) > 0.2 * np.max(np.abs(v))]
        raise UnidentifiableError(
            f"the data do not determine the parameters (regressor condition number {cond:.3g} > "
            f"{COND_LIMIT:.0e}); the poorly determined combination involves {', '.join(involved)}",
            hint="excite the system more richly (more frequencies than parameters) or lower the orders")
    r = R[:p, p]
    theta = sla.solve_triangular(r1, r, check_finite=False)
    rinv = sla.solve_triangular(r1, np.eye(p), check_finite=False)
    cov = rinv @ rinv.T
    return QRSolution(theta, float(R[p, p] ** 2), r1.copy(), 0.5 * (cov + cov.T), cond, m)


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
