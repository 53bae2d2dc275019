"""Two numba steps shared by the kernels that accumulate normal equations without forming their
regressor (:func:`gripkit.sysid.subspace._bdx_normal_equations`,
:func:`gripkit.sysid.pem_ss._sensitivity_gram`): a row of a small matrix product over contiguous
columns, and a block of collected rows added to ΦᵀΦ and Φᵀy by BLAS."""

from __future__ import annotations

import numba
import numpy as np

__all__ = ["add_rows", "row_product"]


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
def add_rows(rows, rhs, fill, G, g):  # pragma: no cover - compiled
    """G += ΦᵀΦ and g += Φᵀy for the first ``fill`` collected rows Φ of ``rows`` and their
    right-hand sides y (one BLAS product each)."""
    blk = rows[:fill]
    G += np.dot(blk.T, blk)
    g += np.dot(blk.T, rhs[:fill])
