"""Identification at any scale: the signals are scaled to unit size before fitting, the model is
returned in the user's units.

Signals whose values are all near 1e300 or 1e-300 are valid data, but squares and products of them
overflow or underflow (a regressor that reads as "identically zero", a condition number of inf).
Each signal is multiplied by a power of two ``c = 2^-e`` with ``max|x| = m·2^e``, ``0.5 <= m < 1``:
the scaled signal has ``0.5 <= max|x'| < 1``, and the multiplication is exact (only the exponent
changes), so data already of order 1 give bit-for-bit the same fit as without scaling.

With ``u' = c_u u`` and ``y' = c_y y``, ``A y = B u + C e`` becomes ``A y' = (c_y/c_u) B u' + C c_y
e``:
A, C and F are unchanged, ``B = B' c_u/c_y``, the errors are ``e = e'/c_y``, the noise variance and
the loss (squares of e) are divided by ``c_y²``, and the covariance of θ is ``D Cov' D`` with D =
c_u/c_y on the B entries and 1 elsewhere.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["unit_scale", "in_user_units"]


def unit_scale(x: np.ndarray, peaks: tuple[float, float] | None = None) -> float:
    """The power of two ``c`` that brings ``max|x|`` into [0.5, 1) (1 for an all-zero signal);
    ``peaks``: ``(min, max)`` of ``x`` when already known."""
    lo, hi = (float(np.min(x)), float(np.max(x))) if peaks is None else peaks
    peak = max(hi, -lo)  # max|x| without an N-sized temporary
    if peak == 0.0:
        return 1.0
    return math.ldexp(1.0, -math.frexp(peak)[1])  # exact, as np.ldexp/np.frexp


def in_user_units(model, cu: float, cy: float):
    """``model`` fitted to ``u' = cu·u``, ``y' = cy·y``, expressed for ``u`` and ``y``."""
    if cu == 1.0 and cy == 1.0:
        return model
    g = cu / cy
    changes = {"B": model.B * g}
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        # variances of B beyond ~1e308 overflow to inf: not representable
        if model.covariance is not None:
            d = np.ones(model.n_params)
            d[model.na:model.na + model.nb] = g
            changes["covariance"] = model.covariance * d[:, None] * d[None, :]
        if model.noise_variance is not None:
            changes["noise_variance"] = model.noise_variance / cy / cy
        if model.loss is not None:
            changes["loss"] = model.loss / cy / cy
    stored = model.stored_residuals  # not estimation_residuals: those not yet computed stay so
    if stored is not None:
        changes["estimation_residuals"] = stored / cy
    if "initial_outputs" in model.info:
        changes["info"] = {**model.info,
                           "initial_outputs": [v / cy for v in model.info["initial_outputs"]]}
    return model.replace(**changes)
