"""Prediction-error minimisation (PEM) engine shared by ARMAX and OE.

Minimises ``Σ e(t, θ)²`` with a Levenberg–Marquardt iteration (Marquardt's diagonal scaling): each
step solves the damped linearised problem ``min ‖J δ + e‖² + μ ‖D δ‖²`` by least squares on the
stacked matrix (no normal equations), rejects steps that make the noise or denominator
polynomial unstable (the predictor would diverge), and stops when the relative cost decrease and
the step are both below ``tol``. The covariance at the optimum is ``σ² (JᵀJ)⁻¹`` from the QR
factorisation of J (:func:`gripkit.sysid.regression.qr_solve`, which also refuses an
ill-conditioned Jacobian), ``σ² = Σe²/(M − p)``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ...errors import AccuracyWarning, emit_warning
from ...progress import track
from ..regression import qr_solve

__all__ = ["stabilize", "is_stable_poly", "PEMResult", "levenberg_marquardt", "covariance"]


def is_stable_poly(c: np.ndarray) -> bool:
    """All roots of the monic polynomial ``c`` (powers of q⁻¹) strictly inside the unit circle."""
    return c.size <= 1 or bool(np.all(np.abs(np.roots(c)) < 1.0))


def stabilize(c: np.ndarray) -> np.ndarray:
    """Reflect roots outside the unit circle to ``1/conj(z)`` (same spectrum shape), keep it
    monic."""
    c = np.asarray(c, dtype=np.float64)
    if c.size <= 1:
        return c
    r = np.roots(c)
    out = np.abs(r) >= 1.0
    if not out.any():
        return c
    r[out] = 1.0 / np.conj(r[out])
    r[np.abs(r) >= 0.999] *= 0.999 / np.abs(r[np.abs(r) >= 0.999])  # roots on the circle
    return np.real(np.poly(r))


@dataclass(frozen=True)
class PEMResult:
    theta: np.ndarray
    e: np.ndarray
    J: np.ndarray
    iterations: int
    converged: bool
    message: str


def levenberg_marquardt(fun: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
                        theta0: np.ndarray, admissible: Callable[[np.ndarray], bool], *,
                        maxiter: int = 100, tol: float = 1e-10, label: str = "model",
                        progress: bool = False) -> PEMResult:
    """Minimise ``‖e(θ)‖²`` where ``fun(θ) -> (e, J = ∂e/∂θ)``; ``admissible(θ)`` must stay True.
    ``progress``: a progress bar of the iterations on stderr (:func:`gripkit.progress.track`)."""
    theta = np.asarray(theta0, dtype=np.float64).copy()
    e, J = fun(theta)
    cost = float(e @ e)
    mu = 1e-3
    p = theta.size
    converged = False
    message = f"no convergence in {maxiter} iterations"
    it = 0
    for it in track(range(1, maxiter + 1), total=maxiter, description=f"PEM {label}",
                    enabled=progress):
        d = np.sqrt(np.sum(J * J, axis=0))
        d[d == 0] = 1.0
        while True:
            Jd = np.vstack([J, np.diag(np.sqrt(mu) * d)])
            rhs = np.concatenate([-e, np.zeros(p)])
            step = np.linalg.lstsq(Jd, rhs, rcond=None)[0]
            cand = theta + step
            if admissible(cand):
                e_new, J_new = fun(cand)
                cost_new = float(e_new @ e_new)
                if np.isfinite(cost_new) and cost_new < cost:
                    break
            mu *= 10.0
            if mu > 1e12:
                break
        if mu > 1e12:
            converged = True  # no descent direction left: a (local) minimum
            message = "converged (no further decrease)"
            break
        decrease = (cost - cost_new) / max(cost, 1e-300)
        small_step = (float(np.linalg.norm(step)) <= np.sqrt(tol)
                      * (float(np.linalg.norm(theta)) + np.sqrt(tol)))
        theta, e, J, cost = cand, e_new, J_new, cost_new
        mu = max(mu / 10.0, 1e-15)
        if decrease < tol or small_step:
            converged = True
            message = "converged"
            break
    if not converged:
        emit_warning(f"{label}: prediction-error minimisation stopped after {maxiter} iterations "
                     f"without converging; the estimate may not be the minimum", AccuracyWarning)
    return PEMResult(theta, e, J, it, converged, message)


def covariance(res: PEMResult, names: tuple[str, ...]) -> tuple[np.ndarray, float, float]:
    """(covariance, σ², condition number) at the optimum, from the QR factorisation of J (every
    column of J, initial conditions included, counts in the degrees of freedom)."""
    m, p = res.J.shape
    X = np.empty((m, p + 1), order="F")
    X[:, :p] = res.J
    X[:, p] = -res.e
    sol = qr_solve(X, names, overwrite=True, values=res.theta)
    sigma2 = float(res.e @ res.e) / (m - p)
    return sigma2 * sol.cov_unscaled, sigma2, sol.cond
