"""Discrete linear-quadratic regulator on an identified model.

For the model's discrete state-space realisation ``x[t+1] = A x + B u`` (``LinearModel.to_ss(dt)``,
or an :class:`~gripkit.lti.StateSpace`), ``u = −K x`` minimises
``Σ_t xᵀ Q x + uᵀ R u + 2 xᵀ N u``; ``K = (Bᵀ S B + R)⁻¹ (Bᵀ S A + Nᵀ)`` with ``S`` the stabilising
solution of the discrete algebraic Riccati equation (``scipy.linalg.solve_discrete_are``). The
same three results, in the same order, as python-control's ``control.dlqr(A, B, Q, R, N)``:
gain, Riccati solution, closed-loop eigenvalues. The state is the model's own (its realisation's
coordinates); u is in deviation from the model's input offsets."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.linalg import solve_discrete_are

from ..errors import ModelError
from ..lti import StateSpace

__all__ = ["LQR", "lqr"]


class LQR(NamedTuple):
    """``K`` (m, n) for ``u = −K x``, ``S`` (n, n) the Riccati solution, ``E`` (n,) the
    eigenvalues of ``A − B K``."""

    K: np.ndarray
    S: np.ndarray
    E: np.ndarray


def _discrete(model, dt) -> StateSpace:
    if isinstance(model, StateSpace):
        ss = model
    elif hasattr(model, "to_ss") and hasattr(model, "u_offset"):  # an identified model
        if model.dt is None and dt is None:
            raise ModelError("lqr: the model is continuous; give the sample time: dt=…")
        return model.to_ss(model.dt if dt is None else dt)
    else:
        raise ModelError(f"lqr: expected a gripkit.sysid.LinearModel or gripkit.lti.StateSpace, "
                         f"found {type(model).__name__}")
    if not ss.is_discrete:
        if dt is None:
            raise ModelError("lqr: the system is continuous; give the sample time: dt=…")
        ss = ss.c2d(dt)
    return ss


def _weight(M, name, shape) -> np.ndarray:
    M = np.atleast_2d(np.asarray(M, dtype=np.float64))
    if M.shape != shape or not np.all(np.isfinite(M)):
        raise ModelError(f"lqr: {name} must be a finite {shape[0]}×{shape[1]} matrix for this "
                         f"model, found shape {M.shape}")
    return M


def lqr(model, Q, R, N=None, *, dt: float | None = None) -> LQR:
    """Discrete LQR gain of ``model`` (module docstring): ``LQR(K, S, E)``.

    Examples
    --------
    >>> from gripkit.lti import StateSpace
    >>> K, S, E = lqr(StateSpace([[1.0]], [[1.0]], [[1.0]], dt=0.1), [[1.0]], [[1.0]])
    >>> round(float(S[0, 0]), 12), round(float(K[0, 0]), 12)   # S = (1 + √5)/2, K = S/(S + 1)
    (1.61803398875, 0.61803398875)
    """
    ss = _discrete(model, dt)
    A, B = np.asarray(ss.A, dtype=np.float64), np.asarray(ss.B, dtype=np.float64)
    n, m = B.shape
    Q, R = _weight(Q, "Q", (n, n)), _weight(R, "R", (m, m))
    N = np.zeros((n, m)) if N is None else _weight(N, "N", (n, m))
    if np.min(np.linalg.eigvalsh(0.5 * (R + R.T))) <= 0:
        raise ModelError("lqr: R must be positive definite (every input costs something)")
    try:
        S = solve_discrete_are(A, B, Q, R, s=N)
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise ModelError(f"lqr: the Riccati equation has no stabilising solution ({exc})",
                         hint="check that (A, B) is stabilisable and Q is positive semidefinite"
                         ) from None
    K = np.linalg.solve(B.T @ S @ B + R, B.T @ S @ A + N.T)
    return LQR(K, S, np.linalg.eigvals(A - B @ K))
