"""LQG: the LQR state feedback on the Kalman filter's estimate, as one controller.

For an identified model's discrete realisation (``LinearModel.discrete``; strictly proper,
``D = 0``) with offsets ``u0``, ``y0``, the controller takes the measurement ``y[t]`` (and a
reference ``r``) and returns ``u[t]``::

    e   = y − y0 − C x_p                        (innovation)
    x_f = x_p + K_f e                           (filtered estimate x[t|t])
    u   = u0 + u_r − K (x̂ − x_r)                (x̂ = x_f, or x_p with estimate="predicted")
    x_p ← A x_p + B (u − u0) + K_p e            (prediction x[t+1|t])

``K`` is :func:`~gripkit.control.lqr`'s gain for the weights ``Q``, ``R`` (and ``N``); ``K_f``,
``K_p`` the steady-state gains of :class:`~gripkit.estimation.KalmanFilter` for the noise
covariances ``Qn``, ``Rn`` (not given: the model's innovation form, its own predictor gain K).
Without ``r`` the loop regulates to the model's operating point (``y0``, ``u0``). With ``r``
(p,; SI, offsets not removed; square models, m = p) the steady state of the model at output
``r`` is the target::

    [A − I  B] [x_r]   [   0   ]
    [  C    0] [u_r] = [r − y0 ]

(Franklin, Powell & Workman, *Digital Control of Dynamic Systems*, §8.4). By the separation
principle the closed loop's eigenvalues are those of ``A − B K`` and of the estimator,
``A − K_p C``. ``estimate="predicted"`` uses ``x[t|t−1]`` (no direct feedthrough from ``y[t]`` to
``u[t]``; one sample for the computation), the observer-based controller that python-control's
``dlqr`` and ``dlqe`` compose to.

:meth:`LQG.step` is one call of the numba kernel :func:`lqg_step`, which allocates nothing (its
numbers live in two flat float64 buffers made with the controller).
"""

from __future__ import annotations

import numba
import numpy as np

from ..errors import ArgumentError, DataError, ModelError
from ..estimation import KalmanFilter
from ..estimation.kalman import predicted_state, without_innovation_gain
from ..estimation.packed import block_offsets, block_starts
from .linear_quadratic import lqr

__all__ = ["LQG", "lqg_step"]


#: blocks of the controller's parameter vector and of its state vector (:mod:`.packed
#: <gripkit.estimation.packed>`), with their sizes below
PAR_BLOCKS = ("A", "B", "C", "Kf", "Kp", "K", "Mx", "Mu", "u0", "y0")
ST_BLOCKS = ("xp", "xf", "e", "dr", "xr", "du", "xn", "u")


@numba.njit(cache=True, inline="always")
def _par_sizes(n, m, p):  # pragma: no cover - compiled
    """Sizes of A, B, C, K_f, K_p, K, M_x, M_u, u0, y0 in the parameter vector."""
    return (n * n, n * m, p * n, n * p, n * p, m * n, n * p, m * p, m, p)


@numba.njit(cache=True, inline="always")
def _st_sizes(n, m, p):  # pragma: no cover - compiled
    """Sizes of x_p, x_f, e, r − y0, x_r, du, x_next, u in the state vector."""
    return (n, n, p, p, n, m, n, m)


@numba.njit(cache=True, inline="always")
def _estimate(n, m, p, par, st, y, r):  # pragma: no cover - compiled
    """e, x_f = x_p + K_f e, r − y0 and x_r = M_x (r − y0)."""
    oA, oB, oC, oKf, oKp, oK, oMx, oMu, ou0, oy0 = block_starts(_par_sizes(n, m, p))[0]
    sxp, sxf, se, sdr, sxr, sdu, sxn, su = block_starts(_st_sizes(n, m, p))[0]
    for i in range(p):
        acc = y[i] - par[oy0 + i]
        for j in range(n):
            acc -= par[oC + i * n + j] * st[sxp + j]
        st[se + i] = acc
        st[sdr + i] = r[i] - par[oy0 + i]
    for i in range(n):
        acc = st[sxp + i]
        for j in range(p):
            acc += par[oKf + i * p + j] * st[se + j]
        st[sxf + i] = acc
        acc = 0.0
        for j in range(p):
            acc += par[oMx + i * p + j] * st[sdr + j]
        st[sxr + i] = acc


@numba.njit(cache=True)
def lqg_step(dims, par, st, y, r):  # pragma: no cover - compiled
    """One LQG sample (module docstring) on the packed buffers; ``dims`` = (n, m, p,
    filtered). The input ``u`` lands in the state vector's last block. Returns 0, or 3 for a
    ``y`` or ``r`` of the wrong length."""
    n, m, p, filtered = dims[0], dims[1], dims[2], dims[3]
    if y.shape[0] != p or r.shape[0] != p:
        return 3
    oA, oB, oC, oKf, oKp, oK, oMx, oMu, ou0, oy0 = block_starts(_par_sizes(n, m, p))[0]
    sxp, sxf, se, sdr, sxr, sdu, sxn, su = block_starts(_st_sizes(n, m, p))[0]
    _estimate(n, m, p, par, st, y, r)
    sx = sxf if filtered else sxp
    for i in range(m):  # du = u_r − K (x̂ − x_r)
        acc = 0.0
        for j in range(p):
            acc += par[oMu + i * p + j] * st[sdr + j]
        for j in range(n):
            acc -= par[oK + i * n + j] * (st[sx + j] - st[sxr + j])
        st[sdu + i] = acc
        st[su + i] = acc + par[ou0 + i]
    predicted_state(n, m, p, par, oA, oB, par, oKp, st, (sxp, sdu, se, sxn))
    return 0


class LQG:
    """LQR on the steady-state Kalman filter's estimate, one controller (module docstring).

    Parameters
    ----------
    model
        A :class:`~gripkit.sysid.LinearModel` (discrete, or continuous with ``dt``), D = 0.
    Q, R, N
        LQR weights on the state (n×n), the input (m×m) and their cross term (n×m), as
        :func:`~gripkit.control.lqr`.
    Qn, Rn
        Process (n×n) and measurement (p×p) noise covariances of the Kalman filter; not given:
        the model's innovation form.
    estimate
        ``"filtered"`` (x[t|t], default) or ``"predicted"`` (x[t|t−1]).

    Attributes: ``K`` (m, n), ``filter_gain`` K_f (n, p), ``predictor_gain`` K_p (n, p),
    ``x_pred`` (the filter's prediction, a view), ``poles`` (the closed loop's eigenvalues).

    Examples
    --------
    >>> from gripkit.lti import StateSpace
    >>> from gripkit.sysid import LinearModel
    >>> m = LinearModel(StateSpace([[1.0]], [[1.0]], [[1.0]], dt=0.1), "n4sid")
    >>> c = LQG(m, Q=[[1.0]], R=[[1.0]], Qn=[[1.0]], Rn=[[1.0]])
    >>> round(float(c.K[0, 0]), 12), round(float(c.filter_gain[0, 0]), 12)  # both S/(S+1)
    (0.61803398875, 0.61803398875)
    >>> c.step([1.0]).round(12).tolist()     # u = −K K_f y
    [-0.38196601125]
    """

    def __init__(self, model, Q, R, Qn=None, Rn=None, *, N=None, estimate: str = "filtered",
                 dt: float | None = None):
        if estimate not in ("filtered", "predicted"):
            raise ArgumentError(f"LQG: estimate must be 'filtered' or 'predicted', found "
                                f"{estimate!r}")
        if Qn is None and Rn is None and getattr(model, "K", None) is None:
            raise ModelError(f"LQG: {without_innovation_gain(model)}; give the noise "
                             f"covariances Qn and Rn",
                             hint="LQG(model, Q, R, Qn=Qn, Rn=Rn)")
        kf = KalmanFilter(model, Q=Qn, R=Rn, steady_state=True, dt=dt)
        A, B, C, D = (np.array(M) for M in (kf.A, kf.B, kf.C, kf.D))
        if np.any(D != 0.0):
            raise ModelError("LQG: the model has a direct feedthrough (D ≠ 0): y[t] would depend "
                             "on the u[t] it sets", hint="identify the model with a delay nk ≥ 1")
        n, m, p = A.shape[0], B.shape[1], C.shape[0]
        self.K = lqr(model, Q, R, N, dt=dt).K
        self.filter_gain = np.array(kf.filter_gain)
        self.predictor_gain = np.array(kf.predictor_gain)
        self.estimate, self.model = estimate, model
        Mx, Mu, self.can_track = self._targets(A, B, C, n, m, p)
        self._u0 = np.asarray(model.u_offset, dtype=np.float64).reshape(m)
        self._y0 = np.asarray(model.y_offset, dtype=np.float64).reshape(p)
        self._dims = np.array([n, m, p, int(estimate == "filtered")], dtype=np.int64)
        blocks = dict(A=A, B=B, C=C, Kf=self.filter_gain, Kp=self.predictor_gain, K=self.K,
                      Mx=Mx, Mu=Mu, u0=self._u0, y0=self._y0)
        self._par = np.concatenate([blocks[k].ravel() for k in PAR_BLOCKS])
        lay, size = block_offsets(ST_BLOCKS, _st_sizes(n, m, p))
        self._st = np.zeros(size)
        self.x_pred = self._st[lay["xp"]:lay["xp"] + n]
        self._u = self._st[lay["u"]:lay["u"] + m]
        self._u_out = self._u.view()
        self._u_out.flags.writeable = False
        self.poles = np.concatenate([np.linalg.eigvals(A - B @ self.K),
                                     np.linalg.eigvals(A - self.predictor_gain @ C)])

    @staticmethod
    def _targets(A, B, C, n, m, p):
        """M_x, M_u with [x_r; u_r] = [M_x; M_u] (r − y0), or zeros and False where the model
        is not square or has a zero at z = 1 (no steady state for every r)."""
        if m != p:
            return np.zeros((n, p)), np.zeros((m, p)), False
        big = np.block([[A - np.eye(n), B], [C, np.zeros((p, m))]])
        if np.linalg.cond(big) > 1e12:
            return np.zeros((n, p)), np.zeros((m, p)), False
        M = np.linalg.solve(big, np.vstack([np.zeros((n, p)), np.eye(p)]))
        return M[:n], M[n:], True

    def reset(self) -> None:
        """Back to rest: the filter's prediction at the operating point."""
        self._st[:] = 0.0

    def step(self, y, r=None, *, copy: bool = True) -> np.ndarray:
        """``u[t]`` (m,; SI, offsets applied) for the measurement ``y[t]`` (p,) and the reference
        ``r`` (p,; default: the operating point y0). ``copy=False`` returns a read-only view of
        the controller's buffer (nothing allocated; the next step overwrites it)."""
        if type(y) is not np.ndarray or y.ndim != 1:
            y = np.ascontiguousarray(y, dtype=np.float64).reshape(-1)
        if r is None:
            r = self._y0
        else:
            if not self.can_track:
                raise ArgumentError("LQG.step: r needs a square model (as many inputs as "
                                    "outputs) with no zero at z = 1",
                                    hint="regulate without r, or add integral states")
            if type(r) is not np.ndarray or r.ndim != 1:
                r = np.ascontiguousarray(r, dtype=np.float64).reshape(-1)
        if lqg_step(self._dims, self._par, self._st, y, r):
            p = int(self._dims[2])
            raise DataError(f"LQG.step: y and r must hold {p} value(s) (the model's outputs), "
                            f"found {np.size(y)} and {np.size(r)}")
        return self._u.copy() if copy else self._u_out
