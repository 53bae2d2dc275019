"""Streaming estimate of a TSFM end-effector's tip position from the voltage and the measured force
(``001_0b92a7da96e7aa46.txt`` eq 11, §V-B):

    Y_C = G_u(s) (d_p U − H_s(U)) − G_u(s) G_f(s) F_g,     dH/dt = λ U̇ − β|U̇| H − γ U̇ |H|.

The TSFM has no position sensor: the model itself, driven by the applied voltage and by the force
the integrated sensor measures, is the estimator. :class:`TipPositionEstimator` runs it one sample
at a time — exact Bouc-Wen update, then the minimal 4-state realisation of eq 11
(:func:`gripkit.systems.tsfm.gripper.finger_minimal_state_space`) discretised exactly (ZOH) at the
loop's sample time — in a numba step (:func:`estimator_step`) that a control loop can call at 20 kHz
(its cost per call, from Python and inside a numba loop: docs/performance.md).

Timing convention (the same as the simulators'): ``update(U, F)`` returns the estimate at the
current sample, computed from the inputs up to the previous one, then takes the voltage U applied
now and the force F measured now as held over the coming sample.
"""

from __future__ import annotations

import numba
import numpy as np

from ...errors import DataError, ModelError
from ...models.hysteresis import bouc_wen_advance
from ...params import ParameterSet
from ...sim.integrators import zoh_levels
from .gripper import FINGER_NAMES, TSFMFinger, finger_minimal_state_space

__all__ = ["TipPositionEstimator", "estimator_step", "estimator_arrays"]


@numba.njit(cache=True)
def estimator_step(st, bw, Phi, Gam, cy, U, F, xt):  # pragma: no cover - compiled
    """One step of eq 11. ``st`` = [H, U_last, x0..x3]; bw = [d_p, λ, β, γ]; Phi (4, 4),
    Gam (4, 2) for inputs [W, F]; cy (4,) the y_C row. Returns the estimate before the step."""
    n = Phi.shape[0]
    y = 0.0
    for j in range(n):
        y += cy[j] * st[2 + j]
    H = bouc_wen_advance(st[0], U - st[1], bw[1], bw[2], bw[3])
    st[0] = H
    st[1] = U
    W = bw[0] * U - H
    for i in range(n):
        acc = Gam[i, 0] * W + Gam[i, 1] * F
        for j in range(n):
            acc += Phi[i, j] * st[2 + j]
        xt[i] = acc
    for i in range(n):
        st[2 + i] = xt[i]
    return y


@numba.njit(cache=True)
def _estimator_run(st, bw, Phi, Gam, cy, U, F, out):  # pragma: no cover - compiled
    xt = np.empty(Phi.shape[0])
    for k in range(U.shape[0]):
        out[k] = estimator_step(st, bw, Phi, Gam, cy, U[k], F[k], xt)


def estimator_arrays(finger, dt: float) -> dict:
    """bw (4,), Phi (4, 4), Gam (4, 2), cy (4,) of eq 11 for a finger at the sample time ``dt``."""
    if isinstance(finger, TSFMFinger):
        values = finger.values()
    elif isinstance(finger, ParameterSet):
        values = {n: finger.value(n) for n in finger}
    else:
        values = dict(finger)
    missing = [n for n in FINGER_NAMES[:-1] if n not in values]
    if missing:
        raise ModelError(f"tip-position estimator: finger parameters {missing} missing")
    ss = finger_minimal_state_space(values)
    Phi, Gam = zoh_levels(ss.A, ss.B, dt, 0)
    return {"bw": np.array([values[k] for k in ("d_p", "lam", "beta", "gamma")]), "Phi": Phi[0],
            "Gam": Gam[0], "cy": np.ascontiguousarray(ss.C[0]), "dt": float(dt)}


class TipPositionEstimator:
    """The eq 11 tip-position estimator of one finger, sample by sample.

    Parameters
    ----------
    finger
        A :class:`~gripkit.systems.tsfm.gripper.TSFMFinger`, its ParameterSet or a mapping of values
        (d_p, s_p, lam, beta, gamma, a, b, m_s, b_s, k_s, L_r, L_s, L_a; SI).
    dt
        Sample time of the loop (s), e.g. 1/20000.

    >>> from gripkit.systems.tsfm.parameters import left_finger
    >>> est = TipPositionEstimator(left_finger(check=False), 5e-5)
    >>> for _ in range(2000):
    ...     y = est.update(44.0, 0.0)            # 44 V held, no force
    >>> round(est.position * 1e6, 1)             # µm: Fig. 13's contact voltage
    62.4
    """

    def __init__(self, finger, dt: float):
        if not (np.isfinite(dt) and dt > 0):
            raise DataError(f"dt: expected a positive sample time in s, found {dt!r}")
        self._a = estimator_arrays(finger, dt)
        self._xt = np.empty(4)
        self.state = np.zeros(6)

    def reset(self, H: float = 0.0, U: float = 0.0) -> None:
        """Back to rest: no motion, hysteresis ``H`` (m) at voltage ``U`` (V)."""
        self.state[:] = 0.0
        self.state[0], self.state[1] = H, U

    @property
    def position(self) -> float:
        """The current estimate of y_C (m)."""
        return float(self._a["cy"] @ self.state[2:])

    def update(self, U: float, F: float) -> float:
        """Estimate y_C (m) now; then take U (V) and the measured force F (N) for the next
        sample."""
        a = self._a
        return (estimator_step(self.state, a["bw"], a["Phi"], a["Gam"], a["cy"], float(U), float(F),
                               self._xt))

    def run(self, U, F) -> np.ndarray:
        """Estimates for whole records U (V) and F (N) (continuing from the current state)."""
        U = np.ascontiguousarray(U, dtype=np.float64)
        F = np.ascontiguousarray(F, dtype=np.float64)
        if U.shape != F.shape or U.ndim != 1:
            raise DataError("U and F: expected two 1-D records of the same length, found "
                            f"{U.shape} and {F.shape}")
        if not (np.isfinite(U).all() and np.isfinite(F).all()):
            raise DataError("U or F contains NaN or inf")
        out = np.empty(U.size)
        a = self._a
        _estimator_run(self.state, a["bw"], a["Phi"], a["Gam"], a["cy"], U, F, out)
        return out

    @property
    def arrays(self) -> dict:
        """The arrays of :func:`estimator_step` (for use inside other numba loops)."""
        return dict(self._a)
