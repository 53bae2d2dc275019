"""State feedback ``u = N_r r − K x`` with output limits: the controller an LQR gain becomes,
with an allocation-free numba step.

``K`` (m, n) is the gain of :func:`gripkit.control.lqr` (u = −K x on the model's own state, in
deviation from its input offsets); ``N_r`` (m, p) is the reference prefilter that makes the
steady-state output equal the reference r (p outputs) for a square loop (p = m):

    N_r = (C (I − A + B K)⁻¹ B + D)⁻¹      (discrete: x = A x + B u at rest, y = C x + D u)

the classical static precompensator (Franklin, Powell & Emami-Naeini, *Feedback Control of
Dynamic Systems*, §7.9 "reference input", in its discrete form). Without ``N_r`` (``None``) the
controller is the regulator ``u = −K x``. Each input is then limited to ``[u_min, u_max]``.

Kernel layout (:func:`state_feedback_step`): ``K`` (m, n), ``Nr`` (m, p), ``x`` (n,), ``r`` (p,),
limits (m,) each, ``u`` (m,) written in place; ``u_i = Σ_j Nr[i, j] r_j − Σ_j K[i, j] x_j`` in
that order of summation, then clamped.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ..errors import ConfigError, ModelError
from .linear_quadratic import _discrete, lqr

__all__ = ["StateFeedback", "state_feedback_step", "state_feedback_run", "lqr_controller",
           "reference_gain"]


@numba.njit(cache=True)
def state_feedback_step(K, Nr, x, r, u_min, u_max, u):  # pragma: no cover - compiled
    """u = clamp(Nr r − K x) into ``u`` (m,), allocation-free (module docstring)."""
    m = K.shape[0]
    for i in range(m):
        ff = 0.0
        for j in range(Nr.shape[1]):
            ff += Nr[i, j] * r[j]
        fb = 0.0
        for j in range(K.shape[1]):
            fb += K[i, j] * x[j]
        v = ff - fb
        if v < u_min[i]:
            v = u_min[i]
        elif v > u_max[i]:
            v = u_max[i]
        u[i] = v


@numba.njit(cache=True)
def state_feedback_run(K, Nr, x, r, u_min, u_max, u):  # pragma: no cover - compiled
    """:func:`state_feedback_step` for each row of ``x`` (N, n) and ``r`` (N, p) into ``u``
    (N, m)."""
    for k in range(x.shape[0]):
        state_feedback_step(K, Nr, x[k], r[k], u_min, u_max, u[k])


def _matrix(M, name: str, shape=None) -> np.ndarray:
    try:
        a = np.array(M, dtype=np.float64, copy=True)
    except (TypeError, ValueError):
        raise ConfigError(f"StateFeedback {name}: expected a matrix of numbers, found {M!r:.60}") \
            from None
    a = np.atleast_2d(a)
    if a.ndim != 2 or not np.isfinite(a).all():
        raise ConfigError(f"StateFeedback {name}: expected a finite 2-D matrix, found shape "
                          f"{a.shape}")
    if shape is not None and a.shape != shape:
        raise ConfigError(f"StateFeedback {name}: expected shape {shape}, found {a.shape}")
    a.flags.writeable = False
    return a


def _limits(v, m: int, name: str, default: float) -> np.ndarray:
    a = np.array(np.broadcast_to(np.asarray(default if v is None else v, dtype=np.float64), (m,)))
    if np.isnan(a).any():
        raise ConfigError(f"StateFeedback {name}: expected numbers (inf allowed), found NaN")
    a.flags.writeable = False
    return a


class StateFeedback:
    """``u = clamp(N_r r − K x)`` (module docstring): ``step(x, r)`` per sample, ``run(x, r)``
    for whole sequences. ``dt`` is the sample interval the gain was designed for (s).

    >>> sf = StateFeedback([[0.5, 0.25]], Nr=[[2.0]], dt=0.01, u_max=1.0)
    >>> sf.step([1.0, 2.0], [1.0]).tolist()   # 2·1 − (0.5 + 0.5) = 1, at the limit
    [1.0]
    >>> sf.step([1.0, 2.0], [0.5]).tolist()
    [0.0]
    """

    def __init__(self, K, *, Nr=None, dt: float, u_min=None, u_max=None):
        self.K = _matrix(K, "K")
        m = self.K.shape[0]
        self.Nr = _matrix(np.zeros((m, 1)) if Nr is None else Nr, "Nr")
        if self.Nr.shape[0] != m:
            raise ConfigError(f"StateFeedback Nr: expected {m} rows (one per input, as K), found "
                              f"{self.Nr.shape[0]}")
        self.has_reference = Nr is not None
        try:
            dt = float(dt)
        except (TypeError, ValueError):
            raise ConfigError(f"StateFeedback dt: expected a number of seconds, found {dt!r}") \
                from None
        if not (math.isfinite(dt) and dt > 0):
            raise ConfigError(f"StateFeedback dt: expected a positive sample interval, found "
                              f"{dt!r}")
        self.dt = dt
        self.u_min = _limits(u_min, m, "u_min", -math.inf)
        self.u_max = _limits(u_max, m, "u_max", math.inf)
        if not np.all(self.u_min < self.u_max):
            raise ConfigError(f"StateFeedback limits: expected u_min < u_max for every input, "
                              f"found {self.u_min.tolist()} and {self.u_max.tolist()}")
        self._u = np.zeros(m)
        self._r0 = np.zeros(self.Nr.shape[1])

    n_inputs = property(lambda self: self.K.shape[0])
    n_states = property(lambda self: self.K.shape[1])
    n_references = property(lambda self: self.Nr.shape[1])

    def __repr__(self) -> str:
        return (f"StateFeedback(m={self.n_inputs}, n={self.n_states}, p={self.n_references}, "
                f"dt={self.dt:g})")

    def reset(self) -> None:
        """No memory: nothing to forget (present for the common controller interface)."""


    def _vec(self, v, size: int, name: str) -> np.ndarray:
        if type(v) is np.ndarray and v.dtype == np.float64 and v.shape == (size,) \
                and v.flags.c_contiguous:
            return v  # the loop's own buffer: no conversion
        a = np.ascontiguousarray(np.asarray(v, dtype=np.float64).reshape(-1))
        if a.shape != (size,):
            raise ConfigError(f"StateFeedback.step {name}: expected {size} values, found {a.size}")
        return a

    def step(self, x, r=None, out=None) -> np.ndarray:
        """Inputs u (m,) for state ``x`` (n,) and reference ``r`` (p,; default 0), written into
        ``out`` when given (then nothing is allocated beyond the argument conversion)."""
        x = self._vec(x, self.n_states, "x")
        r = self._r0 if r is None else self._vec(r, self.n_references, "r")
        u = np.empty(self.n_inputs) if out is None else out
        state_feedback_step(self.K, self.Nr, x, r, self.u_min, self.u_max, u)
        return u

    def run(self, x, r=None) -> np.ndarray:
        """Inputs (N, m) for states ``x`` (N, n) and references ``r`` (N, p) or (p,)."""
        x = np.ascontiguousarray(np.atleast_2d(np.asarray(x, dtype=np.float64)))
        if x.ndim != 2 or x.shape[1] != self.n_states:
            raise ConfigError(f"StateFeedback.run x: expected shape (N, {self.n_states}), found "
                              f"{x.shape}")
        r = np.zeros(self.n_references) if r is None else np.asarray(r, dtype=np.float64)
        r = np.ascontiguousarray(np.broadcast_to(r, (x.shape[0], self.n_references)))
        if not (np.isfinite(x).all() and np.isfinite(r).all()):
            raise ConfigError("StateFeedback.run: x or r contains NaN or inf")
        u = np.empty((x.shape[0], self.n_inputs))
        state_feedback_run(self.K, self.Nr, x, r, self.u_min, self.u_max, u)
        return u


def reference_gain(A, B, C, D, K) -> np.ndarray:
    """``N_r = (C (I − A + B K)⁻¹ B + D)⁻¹`` (module docstring); ModelError when the closed loop
    has no invertible DC gain (not square, or a zero at z = 1)."""
    A, B, C, D, K = (np.atleast_2d(np.asarray(M, dtype=np.float64)) for M in (A, B, C, D, K))
    n = A.shape[0]
    if C.shape[0] != B.shape[1]:
        raise ModelError(f"reference gain: needs as many outputs as inputs, found {C.shape[0]} "
                         f"outputs and {B.shape[1]} inputs",
                         hint="select outputs (or give Nr yourself), or use reference=False")
    G0 = C @ np.linalg.solve(np.eye(n) - A + B @ K, B) + D
    if np.linalg.cond(G0) > 1e12:
        raise ModelError("reference gain: the closed loop's DC gain is singular (a zero at z = 1)",
                         hint="use reference=False (a regulator) or add integral action")
    return np.linalg.inv(G0)


def lqr_controller(model, Q, R, N=None, *, dt: float | None = None, reference: bool = True,
                   u_min=None, u_max=None) -> StateFeedback:
    """The LQR gain of :func:`gripkit.control.lqr` as a :class:`StateFeedback` on ``model``'s
    discrete realisation, with the reference prefilter ``N_r`` when ``reference`` (square
    models) or the regulator u = −K x without."""
    ss = _discrete(model, dt)
    K = lqr(ss, Q, R, N).K
    Nr = reference_gain(ss.A, ss.B, ss.C, ss.D, K) if reference else None
    return StateFeedback(K, Nr=Nr, dt=ss.dt, u_min=u_min, u_max=u_max)
