"""Numba kernels of the discrete state-space recursion (scalar, allocation-free), and the row of
an affine map ``M x + N u`` they are made of, shared with the other state-space kernels (the PEM
predictor, the AMADEUS force-sensor Kalman filter).

Subnormal numbers: a carried state that decays freely (x ← A x with A stable, e.g. a free
response or the unforced tail of a record) sinks below 2.2e-308 within a few thousand steps and
then stays in the subnormal range through a rounding limit cycle; on Intel CPUs every multiply
with a subnormal operand takes a microcode assist (~100 cycles). :func:`flush_tiny` sets such
entries to zero as they are carried (see there for why the results do not change)."""

from __future__ import annotations

import numba

__all__ = ["FLUSH_BELOW", "affine_row", "flush_tiny", "simulate_ss"]

#: carried state entries smaller than this in magnitude are set to zero (:func:`flush_tiny`)
FLUSH_BELOW = 1e-280


@numba.njit(cache=True, inline="always")
def flush_tiny(v):  # pragma: no cover - compiled
    """``v``, or 0.0 when ``|v| < FLUSH_BELOW`` (NaN and ±inf pass unchanged).

    Applied to the entries of a state carried from one step to the next, so that a decaying free
    response never reaches the subnormal range (< 2.2e-308), whose arithmetic is slow on Intel
    CPUs. Why the results do not change: a carried entry below 1e-280 contributes less than
    1e-280·|M| to each later sum it enters (|M| the largest coefficient multiplying it, the data or
    the system matrices), i.e. nothing to any sum of magnitude above ~1e-264 (the half-ulp of
    such a sum is larger). Outputs of order one are bit-identical; an output that is itself below
    ~1e-264 may become exactly zero, an absolute change below 1e-280·Σ|M| per step carried
    (bounded by Σ_k ‖Aᵏ‖ times that for a stable A).

    Examples
    --------
    >>> flush_tiny(1e-300), flush_tiny(-2e-280), flush_tiny(0.5)
    (0.0, -2e-280, 0.5)
    """
    return 0.0 if abs(v) < FLUSH_BELOW else v


@numba.njit(cache=True, inline="always")
def affine_row(M, i, x, N, u, k):  # pragma: no cover - compiled
    """Row ``i`` of ``M x + N u[k]``: Σ_j M[i, j] x[j] + Σ_j N[i, j] u[k, j], summed in that order.

    Examples
    --------
    >>> import numpy as np
    >>> affine_row(np.array([[1.0, 2.0]]), 0, np.array([3.0, 4.0]), np.array([[10.0]]),
    ...            np.array([[0.5]]), 0)
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
    ``xn`` (n,) is work space. Scalar loops, no allocation: callable from other kernels. State
    entries below :data:`FLUSH_BELOW` are carried as zero (:func:`flush_tiny`).

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
            x[i] = flush_tiny(xn[i])
