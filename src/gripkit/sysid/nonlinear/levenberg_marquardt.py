"""Levenberg–Marquardt iteration for the nonlinear families' output-error fits: one
damping and acceptance loop shared by :mod:`.narx` and :mod:`.hammerstein_wiener`; each family
supplies its normal equations, its trial run and its convergence test.

The criterion is ``V(θ) = ‖r(θ)‖²``, ``r = y − ŷ(θ)``, with Jacobian ``J = ∂ŷ/∂θ``. At the
current θ, with ``A = JᵀJ`` (the Gauss–Newton Hessian), ``g = Jᵀr`` and Marquardt's scaling
``D = diag(√A_ii)`` (``D_ii = 1`` where ``A_ii = 0``), the step for the damping λ is::

    (D⁻¹ A D⁻¹ + λ I) z = D⁻¹ g,    δ = D⁻¹ z        i.e. (A + λ D²) δ = g

(K. Levenberg, *Q. Appl. Math.* 2(2), 1944; D. W. Marquardt, *J. SIAM* 11(2), 431–441, 1963;
J. Nocedal and S. J. Wright, *Numerical Optimization*, 2nd ed., Springer 2006, §10.3, the
Levenberg–Marquardt method with the scaling matrix D). ``θ + δ`` is taken when the family
admits it and its cost is lower; then ``λ ← max(λ / shrink, floor)`` and the normal equations
are formed again at the new θ. A refused step (a higher cost, a run that diverged, a candidate
the family refuses, such as an unstable denominator) gives ``λ ← grow · λ`` (a singular system
``λ ← 10 λ``) and the step is solved again, while ``λ ≤ ceiling``. The iteration ends after
``max_iter`` steps, when no damping up to the ceiling lowers the cost, or when the family's test
``converged(cost before, cost after)`` holds after a step. λ carries over from one iteration to
the next.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

__all__ = ["Damping", "levenberg_marquardt"]


@dataclass(frozen=True)
class Damping:
    """The damping schedule: first λ, its divisor after an accepted step and factor after a
    refused one, the largest λ tried and the smallest λ kept."""

    start: float = 1e-3
    shrink: float = 10.0
    grow: float = 10.0
    ceiling: float = 1e16
    floor: float = 1e-12


def _scaled_step(A: np.ndarray, g: np.ndarray, lam: float, d: np.ndarray) -> np.ndarray:
    """δ of ``(D⁻¹ A D⁻¹ + λ I) z = D⁻¹ g``, ``δ = D⁻¹ z`` (the module docstring)."""
    return np.linalg.solve(A / np.outer(d, d) + lam * np.eye(len(d)), g / d) / d


def levenberg_marquardt(theta: np.ndarray, cost: float, *,
                        normal_equations: Callable[[], tuple[np.ndarray, np.ndarray]],
                        trial: Callable[[np.ndarray], float | None],
                        accept: Callable[[np.ndarray], None],
                        converged: Callable[[float, float], bool],
                        max_iter: int, damping: Damping = Damping()):
    """Minimise ``‖r(θ)‖²`` from ``theta`` (whose cost is ``cost``) → (θ, cost, iterations).

    ``normal_equations()``: ``(JᵀJ, Jᵀr)`` at the θ last accepted (the start first).
    ``trial(θ)``: the cost at a candidate, or None when the family refuses it or its run
    diverges. ``accept(θ)``: that candidate, the last one tried, becomes the current point (the
    family keeps its residual and, for the next ``normal_equations``, its Jacobian).
    ``converged(old, new)``: stop after a step from cost ``old`` to ``new``."""
    lam, it = damping.start, 0
    for it in range(1, max_iter + 1):
        A, g = normal_equations()
        d = np.sqrt(np.maximum(np.diag(A), 0.0))
        d[d == 0] = 1.0
        new = None
        while lam <= damping.ceiling:
            try:
                cand = theta + _scaled_step(A, g, lam, d)
            except np.linalg.LinAlgError:
                lam *= 10.0
                continue
            new = trial(cand)
            if new is not None and new < cost:
                break
            new = None
            lam *= damping.grow
        if new is None:
            break
        theta = cand
        accept(theta)
        old, cost = cost, new
        lam = max(lam / damping.shrink, damping.floor)
        if converged(old, cost):
            break
    return theta, cost, it


def fit_residuals(run: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray] | None],
                  theta: np.ndarray, *, tol: float, max_iter: int,
                  damping: Damping = Damping()) -> tuple | None:
    """:func:`levenberg_marquardt` on a residual function: ``run(θ)`` gives ``(e, J)``, the
    residual ``e = y − ŷ(θ)`` and ``J = ∂ŷ/∂θ``, or None where θ is refused (a diverging run, a
    denominator through zero). From ``theta`` until a step lowers ``e·e`` by at most ``tol``
    of it → ``(θ, cov θ, e·e, iterations)`` with ``cov θ = σ² (JᵀJ)⁻¹`` at the optimum (the
    Gauss–Newton Hessian, a column-scaled pseudo-inverse), ``σ² = e·e/(N − k)``; None when
    ``run(theta)`` is None."""
    cur = run(theta)
    if cur is None:
        return None
    e, J = cur
    tried = []

    def trial(th):
        tried[:] = [run(th)]
        return None if tried[0] is None else float(tried[0][0] @ tried[0][0])

    def accept(th):
        nonlocal e, J
        e, J = tried[0]

    theta, cost, it = levenberg_marquardt(
        theta.copy(), float(e @ e), normal_equations=lambda: (J.T @ J, J.T @ e), trial=trial,
        accept=accept, converged=lambda old, new: old - new <= tol * old, max_iter=max_iter,
        damping=damping)
    n, k = J.shape
    A = J.T @ J
    d = np.sqrt(np.maximum(np.diag(A), 1e-300))
    cov = cost / max(n - k, 1) * np.linalg.pinv(A / np.outer(d, d)) / np.outer(d, d)
    return theta, cov, cost, it
