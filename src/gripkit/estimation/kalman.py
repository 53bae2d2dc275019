"""A discrete Kalman filter for an identified linear model (issue 27).

The model (a :class:`~gripkit.sysid.LinearModel`, its discrete state-space realisation)::

    x[t+1] = A x[t] + B du[t] + w[t],   y[t] − y_offset = C x[t] + D du[t] + v[t],
    du = u − u_offset,   cov [w; v] = [[Q, S], [S', R]]

``step(u, y)`` takes one sample and returns the filtered estimate ``x[t|t]`` and its covariance
``P[t|t]``; inside, the filter carries the one-step prediction ``x[t+1|t]``, ``P[t+1|t]``::

    e = y − y_offset − C x_p − D du,   Σ = C P_p Cᵀ + R,
    x_f = x_p + P_p Cᵀ Σ⁻¹ e,          P_f = P_p − P_p Cᵀ Σ⁻¹ C P_p,
    K_p = (A P_p Cᵀ + S) Σ⁻¹,          x_p ← A x_p + B du + K_p e,
    P_p ← A P_p Aᵀ + Q − K_p Σ K_pᵀ

(time-varying; ``steady_state=True`` uses the stabilising solution of the filter's discrete
algebraic Riccati equation, ``scipy.linalg.solve_discrete_are(Aᵀ, Cᵀ, Q, R, s=S)``, and its fixed
gains). With ``Q`` and ``R`` not given, an innovation-form model (``K``, ``Λ`` from subspace or
PEM identification) is its own filter: ``Q = K Λ Kᵀ``, ``R = Λ``, ``S = K Λ``, whose Riccati
solution is ``P_p = 0`` and predictor gain ``K``: the model's own steady-state predictor.

The step is a numba kernel in scalar loops that allocates nothing (the work arrays are made once,
with the filter)."""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np
from scipy.linalg import solve_discrete_are

from ..errors import DataError, ModelError

__all__ = ["KalmanFilter", "KalmanRun"]


class KalmanRun(NamedTuple):
    """What :meth:`KalmanFilter.run` returns: filtered states ``x`` (N, n), their covariances
    ``P`` (N, n, n), innovations ``e`` (N, p) and their covariances ``S`` (N, p, p)."""

    x: np.ndarray
    P: np.ndarray
    e: np.ndarray
    S: np.ndarray


class _Noisy(NamedTuple):
    """The model's matrices and its noise covariances, as the step kernel takes them."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    S: np.ndarray


class _Work(NamedTuple):
    e: np.ndarray
    PCt: np.ndarray
    Se: np.ndarray
    M: np.ndarray
    Kf: np.ndarray
    Kp: np.ndarray
    T: np.ndarray
    xn: np.ndarray


@numba.njit(cache=True)
def _chol_solve_rows(L, B, X):  # pragma: no cover - compiled
    """Rows of X = B Σ⁻¹ with Σ = L Lᵀ (L lower, in place in ``L``'s lower triangle)."""
    p = L.shape[0]
    for r in range(B.shape[0]):
        for i in range(p):  # L z = b
            acc = B[r, i]
            for k in range(i):
                acc -= L[i, k] * X[r, k]
            X[r, i] = acc / L[i, i]
        for i in range(p - 1, -1, -1):  # Lᵀ x = z
            acc = X[r, i]
            for k in range(i + 1, p):
                acc -= L[k, i] * X[r, k]
            X[r, i] = acc / L[i, i]


@numba.njit(cache=True)
def _cholesky(S):  # pragma: no cover - compiled
    """In place: S's lower triangle becomes L (S = L Lᵀ); False if S is not positive definite."""
    p = S.shape[0]
    for j in range(p):
        d = S[j, j]
        for k in range(j):
            d -= S[j, k] * S[j, k]
        if not d > 0.0:
            return False
        S[j, j] = np.sqrt(d)
        for i in range(j + 1, p):
            acc = S[i, j]
            for k in range(j):
                acc -= S[i, k] * S[j, k]
            S[i, j] = acc / S[j, j]
    return True


@numba.njit(cache=True)
def _plus_product(base, X, Y, out):  # pragma: no cover - compiled
    """``out = base + X Y`` (row by row, k ascending), without temporaries."""
    for i in range(out.shape[0]):
        for j in range(out.shape[1]):
            acc = base[i, j]
            for k in range(X.shape[1]):
                acc += X[i, k] * Y[k, j]
            out[i, j] = acc


@numba.njit(cache=True)
def _innovation(C, D, xp, du, y, e):  # pragma: no cover - compiled
    for i in range(C.shape[0]):
        acc = y[i]
        for j in range(C.shape[1]):
            acc -= C[i, j] * xp[j]
        for j in range(D.shape[1]):
            acc -= D[i, j] * du[j]
        e[i] = acc


@numba.njit(cache=True)
def _advance(A, B, Kp, xp, du, e, xn):  # pragma: no cover - compiled
    """x_p ← A x_p + B du + K_p e (through ``xn``)."""
    n = A.shape[0]
    for i in range(n):
        acc = 0.0
        for j in range(n):
            acc += A[i, j] * xp[j]
        for j in range(B.shape[1]):
            acc += B[i, j] * du[j]
        for j in range(Kp.shape[1]):
            acc += Kp[i, j] * e[j]
        xn[i] = acc
    for i in range(n):
        xp[i] = xn[i]


@numba.njit(cache=True)
def kf_step(m, xp, Pp, du, y, xf, Pf, w):  # pragma: no cover - compiled
    """One time-varying Kalman step (module docstring), in place: ``xp``, ``Pp`` advance to
    the next prediction, ``xf``, ``Pf`` receive the filtered estimate, ``w`` (:class:`_Work`)
    the innovation ``w.e`` and its covariance ``w.Se`` (its lower triangle overwritten by the
    Cholesky factor: the full matrix is rebuilt before return). False if Σ is not positive
    definite (the state is then left as it was). ``m`` holds A, B, C, D, Q, R, S."""
    A, B, C, D, Q, R, S = m.A, m.B, m.C, m.D, m.Q, m.R, m.S
    n, p = A.shape[0], C.shape[0]
    _innovation(C, D, xp, du, y, w.e)
    for i in range(n):  # P_p Cᵀ
        for j in range(p):
            acc = 0.0
            for k in range(n):
                acc += Pp[i, k] * C[j, k]
            w.PCt[i, j] = acc
    _plus_product(R, C, w.PCt, w.Se)  # Σ = C P_p Cᵀ + R
    _plus_product(S, A, w.PCt, w.M)   # M = A P_p Cᵀ + S
    if not _cholesky(w.Se):
        return False
    _chol_solve_rows(w.Se, w.PCt, w.Kf)
    _chol_solve_rows(w.Se, w.M, w.Kp)
    for i in range(n):  # x_f, P_f = P_p − K_f (P_p Cᵀ)ᵀ
        acc = xp[i]
        for j in range(p):
            acc += w.Kf[i, j] * w.e[j]
        xf[i] = acc
        for j in range(n):
            acc = Pp[i, j]
            for k in range(p):
                acc -= w.Kf[i, k] * w.PCt[j, k]
            Pf[i, j] = acc
    for i in range(n):  # T = A P_p
        for j in range(n):
            acc = 0.0
            for k in range(n):
                acc += A[i, k] * Pp[k, j]
            w.T[i, j] = acc
    for i in range(n):  # P_p ← T Aᵀ + Q − K_p Mᵀ
        for j in range(n):
            acc = Q[i, j]
            for k in range(n):
                acc += w.T[i, k] * A[j, k]
            for k in range(p):
                acc -= w.Kp[i, k] * w.M[j, k]
            Pp[i, j] = acc
    for i in range(n):  # symmetric parts
        for j in range(i + 1, n):
            a = 0.5 * (Pp[i, j] + Pp[j, i])
            Pp[i, j] = a
            Pp[j, i] = a
            b = 0.5 * (Pf[i, j] + Pf[j, i])
            Pf[i, j] = b
            Pf[j, i] = b
    _advance(A, B, w.Kp, xp, du, w.e, w.xn)
    for i in range(p):  # Σ back from its factor
        for j in range(i + 1):
            acc = 0.0
            for k in range(j + 1):
                acc += w.Se[i, k] * w.Se[j, k]
            w.Se[i, j] = acc
            w.Se[j, i] = acc
    return True


@numba.njit(cache=True)
def kf_step_steady(A, B, C, D, Kf, Kp, xp, du, y, xf, e, xn):  # pragma: no cover - compiled
    """One steady-state step with fixed gains: x_f = x_p + K_f e, x_p ← A x_p + B du + K_p e."""
    _innovation(C, D, xp, du, y, e)
    for i in range(A.shape[0]):
        acc = xp[i]
        for j in range(e.shape[0]):
            acc += Kf[i, j] * e[j]
        xf[i] = acc
    _advance(A, B, Kp, xp, du, e, xn)


class KalmanFilter:
    """The Kalman filter of an identified linear model (module docstring).

    Parameters
    ----------
    model
        A :class:`~gripkit.sysid.LinearModel` (discrete, or continuous with ``dt``).
    Q, R, S
        Process, measurement and cross covariance (n×n, p×p, n×p; S default 0). Not given: the
        model's innovation form (``K`` and ``noise_covariance`` Λ; Λ = I where the file has none,
        which leaves the gains as they are and scales P).
    steady_state
        Fixed gains from the Riccati equation's stabilising solution; ``P`` is then that
        solution's filtered covariance at every step.
    x0, P0
        Initial prediction ``x[0|−1]`` (default 0: rest, as ``gripkit simulate``) and its
        covariance (default: the steady-state one).
    dt
        Sample time for a continuous model.

    Examples
    --------
    >>> from gripkit.lti import StateSpace
    >>> from gripkit.sysid import LinearModel
    >>> m = LinearModel(StateSpace([[0.9]], [[1.0]], [[1.0]], dt=0.01), "n4sid", K=[[0.5]],
    ...                 noise_covariance=[[0.01]])
    >>> kf = KalmanFilter(m)
    >>> kf.predictor_gain.tolist()          # the model's own K
    [[0.5]]
    >>> x, P = kf.step([1.0], [0.2]); x.tolist(), kf.x_pred.tolist()
    ([0.0], [1.1])
    """

    def __init__(self, model, Q=None, R=None, S=None, *, steady_state: bool = False, x0=None,
                 P0=None, dt: float | None = None):
        ss = model.to_ss(model.dt if dt is None else dt) if (model.dt or dt) else None
        if ss is None:
            raise ModelError("KalmanFilter: the model is continuous; give the sample time: dt=…")
        self.model, self.steady_state = model, bool(steady_state)
        self.A, self.B, self.C, self.D = (np.ascontiguousarray(M, dtype=np.float64)
                                          for M in (ss.A, ss.B, ss.C, ss.D))
        n, p = self.A.shape[0], self.C.shape[0]
        self.innovation_form = Q is None and R is None
        self.Q, self.R, self.S = self._noise(model, Q, R, S, n, p)
        self._u0, self._y0 = np.atleast_1d(model.u_offset), np.atleast_1d(model.y_offset)
        self._steady_gains(n, p)
        self.x_pred = np.zeros(n) if x0 is None else np.array(x0, dtype=np.float64).reshape(n)
        self.P_pred = (self.P_steady_pred.copy() if P0 is None
                       else np.array(P0, dtype=np.float64).reshape(n, n))
        self.x, self.P = np.zeros(n), np.zeros((n, n))
        self._w = _Work(np.zeros(p), np.zeros((n, p)), np.zeros((p, p)), np.zeros((n, p)),
                        np.zeros((n, p)), np.zeros((n, p)), np.zeros((n, n)), np.zeros(n))
        self._m = _Noisy(self.A, self.B, self.C, self.D, self.Q, self.R, self.S)
        self._du = np.zeros(self.B.shape[1])
        self._y = np.zeros(p)

    @staticmethod
    def _noise(model, Q, R, S, n, p):
        """(Q, R, S) as given, or the innovation form's ``K Λ Kᵀ, Λ, K Λ``."""
        if Q is None and R is None:
            if getattr(model, "K", None) is None:
                raise ModelError("KalmanFilter: the model has no innovation gain K (an "
                                 "output-error model); give the noise covariances Q and R",
                                 hint="KalmanFilter(model, Q=Q, R=R)")
            lam = (np.eye(p) if getattr(model, "noise_covariance", None) is None
                   else np.asarray(model.noise_covariance, float))
            K = np.asarray(model.K, float)
            return K @ lam @ K.T, lam.copy(), K @ lam
        if Q is None or R is None:
            raise ModelError("KalmanFilter: give both Q and R, or neither (the model's "
                             "innovation form)")
        Q, R = np.asarray(Q, dtype=np.float64), np.asarray(R, dtype=np.float64)
        S = np.zeros((n, p)) if S is None else np.asarray(S, dtype=np.float64)
        for name, M, shape in (("Q", Q, (n, n)), ("R", R, (p, p)), ("S", S, (n, p))):
            if M.shape != shape or not np.all(np.isfinite(M)):
                raise ModelError(f"KalmanFilter: {name} must be a finite {shape[0]}×{shape[1]}"
                                 f" matrix for this model, found shape {M.shape}")
        if np.min(np.linalg.eigvalsh(0.5 * (R + R.T))) <= 0:
            raise ModelError("KalmanFilter: R must be positive definite (every output measured "
                             "with some noise)")
        return Q, R, S

    def _steady_gains(self, n, p):
        """P_steady (filtered), the predictor's Riccati solution and the fixed gains."""
        A, C, Q, R, S = self.A, self.C, self.Q, self.R, self.S
        if self.innovation_form:
            Pp = np.zeros((n, n))  # the innovation form: the model's own predictor
        else:
            try:
                Pp = solve_discrete_are(A.T, C.T, Q, R, s=S)
            except (np.linalg.LinAlgError, ValueError) as exc:
                raise ModelError("KalmanFilter: the Riccati equation has no stabilising "
                                 f"solution ({exc})",
                                 hint="check that (A, C) is detectable and Q, R are covariances"
                                 ) from None
        Se = C @ Pp @ C.T + R
        self.filter_gain = np.linalg.solve(Se, C @ Pp).T
        self.predictor_gain = np.linalg.solve(Se, (A @ Pp @ C.T + S).T).T
        self.P_steady_pred = Pp
        self.P_steady = Pp - self.filter_gain @ C @ Pp

    def step(self, u, y):
        """One sample (SI, the model's order, offsets not removed): ``(x[t|t], P[t|t])``
        (copies)."""
        np.subtract(np.asarray(u, dtype=np.float64), self._u0, out=self._du)
        np.subtract(np.asarray(y, dtype=np.float64), self._y0, out=self._y)
        if self.steady_state:
            kf_step_steady(self.A, self.B, self.C, self.D, self.filter_gain, self.predictor_gain,
                           self.x_pred, self._du, self._y, self.x, self._w.e, self._w.xn)
            return self.x.copy(), self.P_steady.copy()
        if not kf_step(self._m, self.x_pred, self.P_pred, self._du, self._y, self.x, self.P,
                       self._w):
            raise ModelError("KalmanFilter.step: the innovation covariance C P Cᵀ + R is not "
                             "positive definite", hint="check R and the filter's covariance P")
        return self.x.copy(), self.P.copy()

    def run(self, data) -> KalmanRun:
        """Filter a whole record: a :class:`~gripkit.signals.Trajectory` with the model's input
        and output columns (by name, SI or with units converted), from the current state."""
        missing = [n for n in (*self.model.inputs, *self.model.outputs) if n not in data.names]
        if missing:
            raise DataError(f"data: the model's column(s) {', '.join(map(repr, missing))} are "
                            f"missing; the data have {', '.join(map(repr, data.names))}")
        u = np.column_stack([data[n] for n in self.model.inputs])
        y = np.column_stack([data[n] for n in self.model.outputs])
        return self.run_arrays(u, y)

    def run_arrays(self, u, y) -> KalmanRun:
        """Filter inputs ``u`` (N, m) and outputs ``y`` (N, p), SI, offsets not removed."""
        u, y = np.atleast_2d(np.asarray(u, float)), np.atleast_2d(np.asarray(y, float))
        N, n, p = u.shape[0], self.A.shape[0], self.C.shape[0]
        xs, Ps = np.empty((N, n)), np.empty((N, n, n))
        es, Ss = np.empty((N, p)), np.empty((N, p, p))
        for k in range(N):
            xs[k], Ps[k] = self.step(u[k], y[k])
            es[k] = self._w.e
            Ss[k] = (self.C @ self.P_steady_pred @ self.C.T + self.R if self.steady_state
                     else self._w.Se)
        return KalmanRun(xs, Ps, es, Ss)
