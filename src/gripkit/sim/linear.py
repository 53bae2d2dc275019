"""Linear state space in the simulation layer: :class:`gripkit.lti.StateSpace` under the name the
simulators use, and the array-level ZOH discretisation and discrete recursion of their kernels.

Continuous:  ẋ = A x + B u,  y = C x + D u.   Discrete (step h):  x[k+1] = A_d x[k] + B_d u[k].

Exact ZOH (input held constant over each step) gives

    A_d = e^{A h},   B_d = ∫_0^h e^{A s} ds · B,

computed together from one matrix exponential of the augmented matrix [[A, B], [0, 0]]·h
(Van Loan; :func:`gripkit.lti.c2d_matrices`). This is exact for piecewise-constant inputs whatever
h is, which is why gripkit discretises the linear parts of lightly damped models (the TSFM force
sensor rings at 8.52 kHz) instead of integrating them with a fixed-step scheme.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .. import lti
from ..lti import simulate_ss
from ..errors import ModelError, SimulationError

__all__ = ["StateSpace", "c2d_zoh", "simulate_discrete"]


class StateSpace(lti.StateSpace):
    """A :class:`gripkit.lti.StateSpace` (every method, names, units, covariance), with the
    simulation layer's two older spellings: :meth:`freqresp` in Hz and :meth:`discretize` (ZOH).

    ``StateSpace(A, B, C, D, dt, inputs, outputs, input_units, output_units, meta)``: shapes
    A (n, n), B (n, m), C (p, n), D (p, m); ``dt=None`` is continuous time, else discrete (s).
    Discretising keeps the class.

    Examples
    --------
    >>> from gripkit.sim import StateSpace
    >>> s = StateSpace([[-2.0]], [[1.0]], [[2.0]], None)
    >>> d = s.discretize(0.1)
    >>> (type(d).__name__, round(float(d.dc_gain()[0, 0]), 12),
    ...  float(abs(s.freqresp([0.0])[0, 0, 0])))
    ('StateSpace', 1.0, 1.0)
    """

    def freqresp(self, f_hz) -> np.ndarray:
        """Frequency response H at ``f_hz`` (Hz), shape (len(f), p, m):
        ``frequency_response(2π f_hz)``."""
        return self.frequency_response(2.0 * np.pi * np.atleast_1d(np.asarray(f_hz, dtype=np.float64)))

    def discretize(self, dt: float) -> StateSpace:
        """Exact zero-order-hold discretisation at step ``dt`` (s): ``c2d(dt)``."""
        return self.c2d(dt)

    def simulate(self, u, x0=None) -> np.ndarray:
        """Outputs (N, p) of the discrete system for inputs ``u`` (N, m) or (N,), from ``x0``
        (default rest); see :meth:`gripkit.lti.StateSpace.simulate`. A continuous system raises
        SimulationError."""
        if not self.is_discrete:
            raise SimulationError("simulate() needs a discrete system: call discretize(dt) first")
        return super().simulate(u, x0)


def c2d_zoh(A: np.ndarray, B: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact ZOH discretisation (A_d, B_d), C-contiguous for the kernels:
    :func:`gripkit.lti.c2d_matrices` (one expm of [[A, B], [0, 0]]·dt)."""
    A = np.asarray(A, dtype=np.float64)
    B = np.asarray(B, dtype=np.float64).reshape(A.shape[0], -1)
    if not (math.isfinite(dt) and dt > 0):
        raise ModelError(f"dt: expected a positive sample time, found {dt!r}")
    no_outputs = np.zeros((0, A.shape[0])), np.zeros((0, B.shape[1]))
    Ad, Bd, _, _ = lti.c2d_matrices(A, B, *no_outputs, dt)
    return np.ascontiguousarray(Ad), np.ascontiguousarray(Bd)


@numba.njit(cache=True)
def simulate_discrete(Ad, Bd, C, D, u, x, y):  # pragma: no cover - compiled
    """x[k+1] = Ad x[k] + Bd u[k];  y[k] = C x[k] + D u[k] (:func:`gripkit.lti.simulate_ss`).
    ``x`` holds x[0] and ends as x[N]."""
    simulate_ss(Ad, Bd, C, D, u, x, np.empty(Ad.shape[0]), y)
