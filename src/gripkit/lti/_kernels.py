"""Numba kernels of the discrete state-space recursion (scalar, allocation-free), and the row of
an affine map ``M x + N u`` they are made of, shared with the other state-space kernels (the PEM
predictor, the AMADEUS force-sensor Kalman filter)."""

from __future__ import annotations

import numba

__all__ = ["affine_row", "simulate_ss"]


@numba.njit(cache=True, inline="always")
def affine_row(M, i, x, N, u, k):  # pragma: no cover - compiled
    """Row ``i`` of ``M x + N u[k]``: Σ_j M[i, j] x[j] + Σ_j N[i, j] u[k, j], summed in that order.

    Examples
    --------
    >>> import numpy as np
    >>> affine_row(np.array([[1.0, 2.0]]), 0, np.array([3.0, 4.0]), np.array([[10.0]]), np.array([[0.5]]), 0)
    16.0
    """
    acc = 0.0
    for j in range(M.shape[1]):
        acc += M[i, j] * x[j]
    for j in range(N.shape[1]):
        acc += N[i, j] * u[k, j]
    return acc


@numba.njit(cache=True)
def simulate_ss(A, B, C, D, u, x, xn, y):  # pragma: no cover - compiled
    """x[k+1] = A x[k] + B u[k],  y[k] = C x[k] + D u[k],  k = 0 … N−1.

    ``u`` (N, m), ``y`` (N, p) written in place; ``x`` (n,) holds x[0] and ends as x[N];
    ``xn`` (n,) is work space. Scalar loops, no allocation: callable from other kernels.

    Examples
    --------
    >>> import numpy as np
    >>> y, x = np.empty((3, 1)), np.zeros(1)
    >>> simulate_ss(np.array([[0.5]]), np.array([[1.0]]), np.array([[1.0]]), np.zeros((1, 1)),
    ...             np.array([[1.0], [0.0], [0.0]]), x, np.empty(1), y)
    >>> y[:, 0].tolist(), x.tolist()
    ([0.0, 1.0, 0.5], [0.25])
    """
    n = A.shape[0]
    p = C.shape[0]
    for k in range(u.shape[0]):
        for i in range(p):
            y[k, i] = affine_row(C, i, x, D, u, k)
        for i in range(n):
            xn[i] = affine_row(A, i, x, B, u, k)
        for i in range(n):
            x[i] = xn[i]
