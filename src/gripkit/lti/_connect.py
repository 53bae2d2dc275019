"""Array-level interconnections: series, parallel and feedback of state-space matrices, and of
SISO polynomial pairs (descending powers)."""

from __future__ import annotations

import numpy as np

from ..errors import ModelError

__all__ = ["ss_series", "ss_parallel", "ss_feedback", "tf_series", "tf_parallel", "tf_feedback"]


def ss_series(A1, B1, C1, D1, A2, B2, C2, D2):
    """u → G1 → G2 → y, state [x1; x2]:
    ``A = [[A1, 0], [B2 C1, A2]]``, ``B = [[B1], [B2 D1]]``, ``C = [D2 C1, C2]``, ``D = D2 D1``."""
    n1, n2 = A1.shape[0], A2.shape[0]
    A = np.block([[A1, np.zeros((n1, n2))], [B2 @ C1, A2]])
    return A, np.vstack([B1, B2 @ D1]), np.hstack([D2 @ C1, C2]), D2 @ D1


def ss_parallel(A1, B1, C1, D1, A2, B2, C2, D2):
    """y = G1 u + G2 u: ``A = diag(A1, A2)``, ``B = [B1; B2]``, ``C = [C1, C2]``, ``D = D1 +
    D2``."""
    n1, n2 = A1.shape[0], A2.shape[0]
    A = np.block([[A1, np.zeros((n1, n2))], [np.zeros((n2, n1)), A2]])
    return A, np.vstack([B1, B2]), np.hstack([C1, C2]), D1 + D2


def ss_feedback(A1, B1, C1, D1, A2, B2, C2, D2, *, sign: float):
    """y = G e, e = r + sign·K y. With E = (I − sign D1 D2)⁻¹:
    ``y = E (C1 x1 + sign D1 C2 x2 + D1 r)``, ``e = r + sign (C2 x2 + D2 y)``,
    ``ẋ1 = A1 x1 + B1 e``, ``ẋ2 = A2 x2 + B2 y``."""
    p = D1.shape[0]
    n1, n2 = A1.shape[0], A2.shape[0]
    F = np.eye(p) - sign * D1 @ D2
    s = np.linalg.svd(F, compute_uv=False)
    if s[-1] <= p * np.finfo(float).eps * max(s[0], 1.0):
        raise ModelError("feedback: I − sign·D_G·D_K is singular (an algebraic loop "
                         "with no solution)",
                         hint="make the plant or the feedback path strictly proper")
    E = np.linalg.inv(F)
    Cy = E @ np.hstack([C1, sign * D1 @ C2])
    Dy = E @ D1
    Ce = np.hstack([np.zeros((D2.shape[0], n1)), sign * C2]) + sign * D2 @ Cy
    De = np.eye(D1.shape[1]) + sign * D2 @ Dy
    A = (np.block([[A1, np.zeros((n1, n2))], [np.zeros((n2, n1)),
                                              A2]]) + np.vstack([B1 @ Ce, B2 @ Cy]))
    return A, np.vstack([B1 @ De, B2 @ Dy]), Cy, Dy


def _padd(a, b):
    n = max(a.size, b.size)
    return np.pad(a, (n - a.size, 0)) + np.pad(b, (n - b.size, 0))


def tf_series(n1, d1, n2, d2):
    """G2 G1 = (n1 n2)/(d1 d2)."""
    return np.convolve(n1, n2), np.convolve(d1, d2)


def tf_parallel(n1, d1, n2, d2):
    """G1 + G2 = (n1 d2 + n2 d1)/(d1 d2)."""
    return _padd(np.convolve(n1, d2), np.convolve(n2, d1)), np.convolve(d1, d2)


def tf_feedback(n, d, nk, dk, sign: float):
    """G/(1 − sign G K) = (n dk)/(d dk − sign n nk)."""
    den = _padd(np.convolve(d, dk), -sign * np.convolve(n, nk))
    if not np.any(den):
        raise ModelError("feedback: an algebraic loop with no solution (the closed "
                         "loop's denominator "
                         "d_G d_K − sign n_G n_K is identically zero)")
    return np.convolve(n, dk), den
