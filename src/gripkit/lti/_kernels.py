"""Numba kernel of the discrete state-space recursion (scalar, allocation-free)."""

from __future__ import annotations

import numba

__all__ = ["simulate_ss"]


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
    m = B.shape[1]
    p = C.shape[0]
    for k in range(u.shape[0]):
        for i in range(p):
            acc = 0.0
            for j in range(n):
                acc += C[i, j] * x[j]
            for j in range(m):
                acc += D[i, j] * u[k, j]
            y[k, i] = acc
        for i in range(n):
            acc = 0.0
            for j in range(n):
                acc += A[i, j] * x[j]
            for j in range(m):
                acc += B[i, j] * u[k, j]
            xn[i] = acc
        for i in range(n):
            x[i] = xn[i]
