"""Linear state-space models, exact zero-order-hold discretisation and discrete simulation.

Continuous:  ẋ = A x + B u,  y = C x + D u.   Discrete (step h):  x[k+1] = A_d x[k] + B_d u[k].

Exact ZOH (input held constant over each step) gives

    A_d = e^{A h},   B_d = ∫_0^h e^{A s} ds · B,

computed together from one matrix exponential of the augmented matrix [[A, B], [0, 0]]·h
(Van Loan). This is exact for piecewise-constant inputs whatever h is, which is why gripkit
discretises the linear parts of lightly damped models (the TSFM force sensor rings at 8.52 kHz)
instead of integrating them with a fixed-step scheme.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numba
import numpy as np
from scipy.linalg import expm

from ..errors import ModelError, SimulationError
from .integrators import lti_rhs, lti_step

__all__ = ["StateSpace", "c2d_zoh", "simulate_discrete"]


def _as2d(x, name: str) -> np.ndarray:
    a = np.atleast_2d(np.asarray(x, dtype=np.float64))
    if a.ndim != 2:
        raise ModelError(f"{name}: expected a 2-D matrix, found shape {np.shape(x)}")
    if not np.isfinite(a).all():
        raise ModelError(f"{name} contains NaN or inf")
    return a


@dataclass(frozen=True)
class StateSpace:
    """A linear time-invariant system; ``dt=None`` is continuous time, else discrete (s).

    Shapes: A (n, n), B (n, m), C (p, n), D (p, m). ``inputs``/``outputs`` name the signals and
    ``input_units``/``output_units`` give their SI units.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    dt: float | None = None
    inputs: tuple[str, ...] = ()
    outputs: tuple[str, ...] = ()
    input_units: tuple[str, ...] = ()
    output_units: tuple[str, ...] = ()
    meta: dict = field(default_factory=dict)

    def __post_init__(self):
        A, B, C = _as2d(self.A, "A"), _as2d(self.B, "B"), _as2d(self.C, "C")
        n = A.shape[0]
        if A.shape != (n, n):
            raise ModelError(f"A must be square, found shape {A.shape}")
        if B.shape[0] != n:
            B = B.T if B.shape[1] == n else B
        if B.shape[0] != n:
            raise ModelError(f"B must have {n} rows (one per state), found shape {B.shape}")
        if C.shape[1] != n:
            raise ModelError(f"C must have {n} columns (one per state), found shape {C.shape}")
        D = np.zeros((C.shape[0], B.shape[1])) if self.D is None else _as2d(self.D, "D")
        if D.shape != (C.shape[0], B.shape[1]):
            raise ModelError(f"D must have shape {(C.shape[0], B.shape[1])}, found {D.shape}")
        if self.dt is not None and not (np.isfinite(self.dt) and self.dt > 0):
            raise ModelError(f"dt: expected a positive sample time or None, found {self.dt!r}")
        for k, v in (("A", A), ("B", B), ("C", C), ("D", D)):
            v.flags.writeable = False
            object.__setattr__(self, k, v)

    @property
    def n_states(self) -> int:
        return self.A.shape[0]

    @property
    def is_discrete(self) -> bool:
        return self.dt is not None

    def poles(self) -> np.ndarray:
        return np.linalg.eigvals(self.A)

    def is_stable(self) -> bool:
        p = self.poles()
        return bool(np.all(np.abs(p) < 1.0)) if self.is_discrete else bool(np.all(p.real < 0.0))

    def dc_gain(self) -> np.ndarray:
        """Static gain (p, m): -C A^{-1} B + D (continuous) or C (I - A)^{-1} B + D (discrete)."""
        n = self.n_states
        M = (np.eye(n) - self.A) if self.is_discrete else -self.A
        try:
            return self.C @ np.linalg.solve(M, self.B) + self.D
        except np.linalg.LinAlgError:
            raise ModelError("the system has a pole at " + ("z = 1" if self.is_discrete else "s = 0")
                             + ": its DC gain is infinite") from None

    def freqresp(self, f_hz: np.ndarray) -> np.ndarray:
        """Frequency response H(f), shape (len(f), p, m)."""
        f = np.atleast_1d(np.asarray(f_hz, dtype=np.float64))
        s = np.exp(1j * 2 * np.pi * f * self.dt) if self.is_discrete else 1j * 2 * np.pi * f
        n = self.n_states
        out = np.empty((f.size, self.C.shape[0], self.B.shape[1]), dtype=complex)
        for i, si in enumerate(s):
            out[i] = self.C @ np.linalg.solve(si * np.eye(n) - self.A, self.B) + self.D
        return out

    def discretize(self, dt: float) -> "StateSpace":
        """Exact zero-order-hold discretisation at step ``dt`` (s)."""
        if self.is_discrete:
            raise ModelError("the system is already discrete")
        Ad, Bd = c2d_zoh(self.A, self.B, dt)
        return StateSpace(Ad, Bd, self.C, self.D, dt, self.inputs, self.outputs,
                          self.input_units, self.output_units, dict(self.meta))

    def simulate(self, u: np.ndarray, x0: np.ndarray | None = None) -> np.ndarray:
        """Outputs (N, p) of the discrete system for inputs ``u`` (N, m) or (N,)."""
        if not self.is_discrete:
            raise SimulationError("simulate() needs a discrete system: call discretize(dt) first")
        u2 = np.asarray(u, dtype=np.float64).reshape(len(u), -1)
        if u2.shape[1] != self.B.shape[1]:
            raise SimulationError(f"u: expected {self.B.shape[1]} input columns, found {u2.shape[1]}")
        x = np.zeros(self.n_states) if x0 is None else np.asarray(x0, dtype=np.float64).copy()
        y = np.empty((u2.shape[0], self.C.shape[0]))
        simulate_discrete(self.A, self.B, self.C, self.D, np.ascontiguousarray(u2), x, y)
        return y

    def to_scipy(self):
        from scipy import signal

        if self.is_discrete:
            return signal.dlti(self.A, self.B, self.C, self.D, dt=self.dt)
        return signal.lti(self.A, self.B, self.C, self.D)

    def to_control(self):
        try:
            import control
        except ImportError:
            raise ModelError("python-control is not installed",
                             hint="pip install 'gripkit[interop]'") from None
        return control.ss(self.A, self.B, self.C, self.D, self.dt if self.is_discrete else 0)


def c2d_zoh(A: np.ndarray, B: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact ZOH discretisation: (A_d, B_d) from one expm of [[A, B], [0, 0]]·dt."""
    A = np.asarray(A, dtype=np.float64)
    B = np.asarray(B, dtype=np.float64).reshape(A.shape[0], -1)
    if not (np.isfinite(dt) and dt > 0):
        raise ModelError(f"dt: expected a positive sample time, found {dt!r}")
    n, m = B.shape
    M = np.zeros((n + m, n + m))
    M[:n, :n] = A * dt
    M[:n, n:] = B * dt
    E = expm(M)
    return E[:n, :n].copy(), E[:n, n:].copy()


@numba.njit(cache=True)
def simulate_discrete(Ad, Bd, C, D, u, x, y):  # pragma: no cover - compiled
    """x[k+1] = Ad x[k] + Bd u[k];  y[k] = C x[k] + D u[k].  ``x`` holds x[0] and ends as x[N]."""
    m = Bd.shape[1]
    p = C.shape[0]
    xn = np.empty(Ad.shape[0])
    uk = np.empty(m)
    yk = np.empty(p)
    for k in range(u.shape[0]):
        for j in range(m):
            uk[j] = u[k, j]
        lti_rhs(C, D, x, uk, yk)
        for i in range(p):
            y[k, i] = yk[i]
        lti_step(Ad, Bd, x, uk, xn)
