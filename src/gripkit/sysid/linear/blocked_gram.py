"""Numba steps shared by the kernels that accumulate normal equations without forming their
regressor (:func:`gripkit.sysid.linear.subspace._bdx_normal_equations`,
:func:`gripkit.sysid.linear.pem_ss._sensitivity_gram`): the state matrix their responses are
carried in, a row of a small matrix product over contiguous columns, the copy of the next state into
the carried one (entries below 1e-280 flushed to zero, :func:`gripkit.lti.flush_tiny`: the free
responses of the initial-state columns decay into the subnormal range otherwise), and a block of
collected rows added to ΦᵀΦ and Φᵀy by BLAS."""

from __future__ import annotations

import numba
import numpy as np

from ...lti import flush_tiny

__all__ = ["add_rows", "carry", "row_product", "carried_states", "start_sums"]


@numba.njit(cache=True, inline="always")
def row_product(M, i, S, out):  # pragma: no cover - compiled
    """out = Σ_j M[i, j]·S[j]: row i of M·S, the inner loop over S's contiguous columns."""
    for q in range(out.shape[0]):
        out[q] = 0.0
    for j in range(S.shape[0]):
        a = M[i, j]
        sj = S[j]
        for q in range(out.shape[0]):
            out[q] += a * sj[q]


@numba.njit(cache=True, inline="always")
def carry(Sn, S):  # pragma: no cover - compiled
    """S = Sn, entries below 1e-280 in magnitude set to zero (:func:`gripkit.lti.flush_tiny`):
    such an entry adds less than 1e-280·|data| to sums of order one, i.e. nothing, so ΦᵀΦ and Φᵀy
    stay bit-identical, while the subnormal arithmetic it would lead to is slow on Intel CPUs."""
    for i in range(S.shape[0]):
        for q in range(S.shape[1]):
            S[i, q] = flush_tiny(Sn[i, q])


@numba.njit(cache=True, inline="always")
def add_rows(rows, rhs, fill, G, g):  # pragma: no cover - compiled
    """G += ΦᵀΦ and g += Φᵀy for the first ``fill`` collected rows Φ of ``rows`` and their
    right-hand sides y (one BLAS product each)."""
    blk = rows[:fill]
    G += np.dot(blk.T, blk)
    g += np.dot(blk.T, rhs[:fill])


@numba.njit(cache=True)
def carried_states(n, cols, first_x0, n_x0):  # pragma: no cover - compiled
    """The n × cols matrix whose columns carry responses through the state recursion, zero but
    for the ``n_x0`` initial-state directions e_i in columns ``first_x0 …``, and its next-step
    buffer."""
    S = np.zeros((n, cols))
    for i in range(n_x0):
        S[i, first_x0 + i] = 1.0
    return S, np.empty((n, cols))


@numba.njit(cache=True)
def start_sums(n_rows, cols, G, g):  # pragma: no cover - compiled
    """Clear the sums ΦᵀΦ (G) and Φᵀy (g); return an empty block of ``n_rows`` collected rows of
    Φ and their right-hand sides, for :func:`add_rows`."""
    G[:, :] = 0.0
    g[:] = 0.0
    return np.zeros((n_rows, cols)), np.empty(n_rows)
