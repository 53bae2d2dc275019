"""Extended and unscented Kalman filters for grey-box and nonlinear models.

The model, with ``x`` (n,), ``u`` (m,), ``y`` (p,) in SI::

    x[t+1] = f(x[t], u[t]) + w[t],   y[t] = h(x[t], u[t]) + v[t],   w ~ N(0, Q),  v ~ N(0, R)

``f(x, u) -> (n,)`` and ``h(x, u) -> (p,)`` are Python callables or ``numba.njit`` functions.
As :class:`~gripkit.estimation.KalmanFilter`, each filter carries the one-step prediction
``x[t|t−1]``, ``P[t|t−1]`` (``x0``, ``P0`` at the start), and ``step(u, y)`` returns the
filtered ``x[t|t]``, ``P[t|t]`` and then predicts the next sample.

Extended (Jazwinski 1970; Simon, *Optimal State Estimation*, §13.2), with ``H = ∂h/∂x`` at
``x_p`` and ``F = ∂f/∂x`` at ``x_f``::

    e = y − h(x_p, u),   Σ = H P_p Hᵀ + R,   K = P_p Hᵀ Σ⁻¹,
    x_f = x_p + K e,     P_f = P_p − K (P_p Hᵀ)ᵀ,
    x_p ← f(x_f, u),     P_p ← F P_f Fᵀ + Q

The Jacobians are the functions ``F(x, u) -> (n, n)``, ``H(x, u) -> (p, n)`` when given, else
central differences (step ``ε^(1/3) max(1, |x_j|)``) or, with ``jacobian="complex"``, the complex
step ``Im f(x + i δ e_j) / δ`` (δ = 1e-30; exact to rounding, for an ``f`` that accepts complex
states).

Unscented (Julier & Uhlmann 2004; the scaled sigma points of Wan & van der Merwe 2000), for
``(x, P)`` with ``P = L Lᵀ`` (Cholesky), ``c = α² (n + κ)``, ``λ = c − n``::

    X_0 = x,  X_j = x + √c L[:, j],  X_{n+j} = x − √c L[:, j]                (j = 1 … n)
    W^m_0 = λ/c,  W^c_0 = λ/c + 1 − α² + β,  W^m_j = W^c_j = 1/(2c)

update from the sigma points of ``(x_p, P_p)`` through ``h``, ``ŷ = Σ W^m_i h(X_i)``,
``Σ = Σ W^c_i (h(X_i) − ŷ)(·)ᵀ + R``, ``P_xy = Σ W^c_i (X_i − x_p)(h(X_i) − ŷ)ᵀ``,
``K = P_xy Σ⁻¹``, ``x_f = x_p + K (y − ŷ)``, ``P_f = P_p − K Σ Kᵀ``; prediction from the sigma
points of ``(x_f, P_f)`` through ``f``: ``x_p = Σ W^m_i f(X_i)``,
``P_p = Σ W^c_i (f(X_i) − x_p)(·)ᵀ + Q``. Defaults α = 1, β = 2, κ = 0 (all weights but
``W^c_0`` positive). On a linear model both filters are the Kalman filter.

Missing measurements and bad data as :class:`~gripkit.estimation.KalmanFilter`: a NaN ``y_i`` is
left out of the update (h's row, R's row and column), a NaN or ±inf in ``u`` or a ±inf in ``y``
is a DataError. A NaN or ±inf from ``f`` or ``h`` (or a Jacobian) is a ModelError naming the
function and the sample, raised before the prediction ``x_pred``, ``P_pred`` changes.

The filters' own arithmetic is numba kernels in scalar loops on work arrays made once with the
filter. When ``f`` and ``h`` (and ``F``, ``H`` if given) are ``numba.njit`` functions, ``step``
and ``run`` call them from inside one kernel (``run``: the whole record in one call); Python
callables are called from Python between the kernels. What ``f`` and ``h`` allocate (their
returned arrays) is theirs.

**Caching.** The kernels that take ``f``, ``h`` (or their Jacobians) as arguments are compiled
once per process and per set of model functions and not written to numba's disk cache: numba
keys such an entry by the function objects' types, a model's functions are new objects in every
process (closures over its parameters), so the cache could never be hit, and its index grew by
one entry per process until loading it failed with ``ReferenceError: underlying object has
vanished`` (numba issues #2956 and #9348). The kernels without function arguments stay cached.
"""

from __future__ import annotations

from operator import attrgetter
from typing import NamedTuple

import numba
import numpy as np

from ..errors import ArgumentError, DataError, ModelError
from .kalman import (KalmanFilter, KalmanRun, _chol_solve_rows, _cholesky, _drop_missing,
                     _mark_missing, bad_channel, bad_sample, warn_missing)
from .state_functions import state_functions

__all__ = ["ExtendedKalmanFilter", "UnscentedKalmanFilter"]

_EPS3 = np.finfo(float).eps ** (1.0 / 3.0)


def _is_jit(fn) -> bool:
    return isinstance(fn, numba.core.registry.CPUDispatcher)


# ---------------------------------------------------------------- records


class FilterState(NamedTuple):
    """A filter's state and last results: prediction ``xp`` (n,), ``Pp`` (n, n); filtered
    ``xf``, ``Pf``; innovation ``e`` (p,) and its covariance ``Se`` (p, p)."""

    xp: np.ndarray
    Pp: np.ndarray
    xf: np.ndarray
    Pf: np.ndarray
    e: np.ndarray
    Se: np.ndarray


class Noise(NamedTuple):
    """Process (n, n) and measurement (p, p) noise covariances."""

    Q: np.ndarray
    R: np.ndarray


class EKFWork(NamedTuple):
    """EKF work arrays: P Hᵀ and the gain (n, p), the Jacobians F (n, n) and H (p, n), F P (n,
    n), a perturbed state (n,)."""

    PHt: np.ndarray
    K: np.ndarray
    F: np.ndarray
    H: np.ndarray
    T: np.ndarray
    xt: np.ndarray


class UKFWork(NamedTuple):
    """UKF weights (2n+1,) and work arrays: P_xy, K (n, p), ŷ (p,), the Cholesky factor (n, n),
    the sigma points (2n+1, n) and their images through h (2n+1, p) and f (2n+1, n)."""

    Wm: np.ndarray
    Wc: np.ndarray
    Pxy: np.ndarray
    K: np.ndarray
    yhat: np.ndarray
    L: np.ndarray
    X: np.ndarray
    Yp: np.ndarray
    Xn: np.ndarray


# ---------------------------------------------------------------- shared kernels


@numba.njit(cache=True)
def _gain_update(s, yhat, Pxy, K, y):  # pragma: no cover - compiled
    """``e = y − ŷ``; ``K = P_xy Σ⁻¹`` (``s.Se`` = Σ factored in place, rebuilt before return);
    ``x_f = x_p + K e``; ``P_f = P_p − K P_xyᵀ`` (= P_p − K Σ Kᵀ; P_xy = P_p Hᵀ for the EKF).
    False if Σ is not positive definite.

    A NaN y_i is a missing measurement: column i of P_xy is zero and Σ's row and column i those
    of the identity, so that K's column i is zero and the update is that of the measured outputs
    alone (h's rows and R's rows and columns struck out; none measured: x_f = x_p, P_f = P_p);
    its innovation and Σ's row and column are NaN after the update."""
    n, p = s.xp.shape[0], y.shape[0]
    missing = False
    for i in range(p):
        measured = y[i] == y[i]
        s.e[i] = y[i] - yhat[i] if measured else 0.0
        missing = missing or not measured
    if missing:  # the flat views share the arrays' memory (C-contiguous)
        _drop_missing(y, 0, p, Pxy.reshape(-1), 0, 0, n, s.Se.reshape(-1), 0)
    if not _cholesky(s.Se):
        return False
    _chol_solve_rows(s.Se, Pxy, K)
    for i in range(n):
        acc = s.xp[i]
        for j in range(p):
            acc += K[i, j] * s.e[j]
        s.xf[i] = acc
        for j in range(n):
            acc = s.Pp[i, j]
            for k in range(p):
                acc -= K[i, k] * Pxy[j, k]
            s.Pf[i, j] = acc
    _symmetrise(s.Pf)
    for i in range(p):
        for j in range(i + 1):
            acc = 0.0
            for k in range(j + 1):
                acc += s.Se[i, k] * s.Se[j, k]
            s.Se[i, j] = acc
            s.Se[j, i] = acc
    if missing:
        _mark_missing(y, 0, p, s.e, 0, s.Se.reshape(-1), 0)
    return True


@numba.njit(cache=True, inline="always")
def _finite(a):  # pragma: no cover - compiled
    """True when no entry of the 1-D array ``a`` is NaN or ±inf."""
    for i in range(a.shape[0]):
        if not np.isfinite(a[i]):
            return False
    return True


@numba.njit(cache=True, inline="always")
def _symmetrise(P):  # pragma: no cover - compiled
    for i in range(P.shape[0]):
        for j in range(i + 1, P.shape[0]):
            a = 0.5 * (P[i, j] + P[j, i])
            P[i, j] = a
            P[j, i] = a


@numba.njit(cache=True)
def _store(k, s, out):  # pragma: no cover - compiled
    """Row k of ``out`` (a KalmanRun of arrays) from the state's filtered results."""
    for i in range(s.xf.shape[0]):
        out.x[k, i] = s.xf[i]
        for j in range(s.xf.shape[0]):
            out.P[k, i, j] = s.Pf[i, j]
    for i in range(s.e.shape[0]):
        out.e[k, i] = s.e[i]
        for j in range(s.e.shape[0]):
            out.S[k, i, j] = s.Se[i, j]


@numba.njit(cache=True, inline="always")
def _mul_add(A, B, C, out):  # pragma: no cover - compiled
    """``out = C + A B`` (``C`` None: ``out = A B``), each sum from ``C[i, j]`` (or 0) over k in
    order; ``B`` may be a transposed view (``H.T``) for ``A Hᵀ``."""
    for i in range(out.shape[0]):
        for j in range(out.shape[1]):
            if C is None:
                acc = 0.0
            else:
                acc = C[i, j]
            for k in range(A.shape[1]):
                acc += A[i, k] * B[k, j]
            out[i, j] = acc


# ---------------------------------------------------------------- extended


@numba.njit(cache=True)
def _ekf_update(s, w, hx, R, y):  # pragma: no cover - compiled
    """The EKF measurement update (module docstring) with ``hx = h(x_p, u)``, ``w.H`` at x_p."""
    _mul_add(s.Pp, w.H.T, None, w.PHt)
    _mul_add(w.H, w.PHt, R, s.Se)
    return _gain_update(s, hx, w.PHt, w.K, y)


@numba.njit(cache=True)
def _ekf_predict(s, w, Q):  # pragma: no cover - compiled
    """``P_p = F P_f Fᵀ + Q`` (symmetric part)."""
    _mul_add(w.F, s.Pf, None, w.T)
    _mul_add(w.T, w.F.T, Q, s.Pp)
    _symmetrise(s.Pp)


@numba.njit(cache=False)  # takes model functions: see the module docstring, "Caching"
def _jac_central(fn, x, u, J, xt):  # pragma: no cover - compiled
    """J[:, j] = (fn(x + δ_j e_j, u) − fn(x − δ_j e_j, u)) / (2 δ_j),
    δ_j = ε^(1/3) max(1, |x_j|)."""
    for j in range(x.shape[0]):
        d = _EPS3 * max(1.0, abs(x[j]))
        for k in range(x.shape[0]):
            xt[k] = x[k]
        xt[j] = x[j] + d
        hi = fn(xt, u)
        for i in range(J.shape[0]):  # kept before fn runs again (fn may return its argument)
            J[i, j] = hi[i]
        xt[j] = x[j] - d
        lo = fn(xt, u)
        for i in range(J.shape[0]):
            J[i, j] = (J[i, j] - lo[i]) / (2.0 * d)


@numba.njit(cache=False)  # takes model functions: see the module docstring, "Caching"
def _jac_given(Jf, x, u, J):  # pragma: no cover - compiled
    """J = Jf(x, u); False if it has the wrong shape."""
    M = Jf(x, u)
    if M.shape[0] != J.shape[0] or M.shape[1] != J.shape[1]:
        return False
    for i in range(J.shape[0]):
        for j in range(J.shape[1]):
            J[i, j] = M[i, j]
    return True


@numba.njit(cache=False, inline="always")  # takes model functions (module docstring)
def _linearised(fn, Jfn, x, u, J, xt, size, code):  # pragma: no cover - compiled
    """``(fn(x, u), 0)`` with its Jacobian at x in ``J`` (``Jfn`` None: central differences;
    numba prunes the other branch); ``(v, code)`` when fn returns other than ``size`` values,
    ``(v, 6)`` when ``Jfn`` returns the wrong shape, ``(v, code + 3)`` when ``fn`` or the
    Jacobian has a NaN or ±inf."""
    v = fn(x, u)
    if v.shape[0] != size:
        return v, code
    if not _finite(v):
        return v, code + 3
    if Jfn is None:
        _jac_central(fn, x, u, J, xt)
    elif not _jac_given(Jfn, x, u, J):
        return v, 6
    for i in range(J.shape[0]):
        if not _finite(J[i]):
            return v, code + 3
    return v, 0


@numba.njit(cache=False)  # takes model functions: see the module docstring, "Caching"
def _ekf_step_jit(f, h, Fj, Hj, noise, u, y, s, w):  # pragma: no cover - compiled
    """One EKF step calling numba ``f``, ``h`` and ``Fj``, ``Hj`` (None: central differences).
    0 done, 1 Σ not positive definite (the prediction is then left as it was), 4 ``f`` or 5
    ``h`` returned the wrong length, 6 a Jacobian the wrong shape, 7 ``f`` or 8 ``h`` (or its
    Jacobian) a NaN or ±inf, 9 a NaN or ±inf in ``u``, 10 a ±inf in ``y`` (the prediction left
    as it was in each case)."""
    bad = bad_sample(u, y)
    if bad:
        return 8 + bad
    hx, code = _linearised(h, Hj, s.xp, u, w.H, w.xt, noise.R.shape[0], 5)
    if code:
        return code
    if not _ekf_update(s, w, hx, noise.R, y):
        return 1
    fx, code = _linearised(f, Fj, s.xf, u, w.F, w.xt, s.xp.shape[0], 4)
    if code:
        return code
    for i in range(s.xp.shape[0]):
        s.xp[i] = fx[i]
    _ekf_predict(s, w, noise.Q)
    return 0


@numba.njit(cache=False)  # takes model functions: see the module docstring, "Caching"
def _ekf_run_jit(f, h, Fj, Hj, noise, U, Y, s, w, out):  # pragma: no cover - compiled
    """:func:`_ekf_step_jit` over the rows of U, Y into ``out``: (code, k) of the first failure
    or (0, N)."""
    for k in range(U.shape[0]):
        code = _ekf_step_jit(f, h, Fj, Hj, noise, U[k], Y[k], s, w)
        if code:
            return code, k
        _store(k, s, out)
    return 0, U.shape[0]


# ---------------------------------------------------------------- unscented


@numba.njit(cache=True)
def _sigma_points(x, P, c, L, X):  # pragma: no cover - compiled
    """X (2n+1, n): x, x ± √c L[:, j] with P = L Lᵀ (lower triangle of ``L``). False if P is
    not positive definite."""
    n = x.shape[0]
    for i in range(n):
        for j in range(n):
            L[i, j] = P[i, j]
    if not _cholesky(L):
        return False
    r = np.sqrt(c)
    for i in range(n):
        X[0, i] = x[i]
    for j in range(n):
        for i in range(n):
            d = r * L[i, j] if i >= j else 0.0
            X[1 + j, i] = x[i] + d
            X[1 + n + j, i] = x[i] - d
    return True


@numba.njit(cache=True, inline="always")
def _weighted_mean(W, Z, out):  # pragma: no cover - compiled
    """``out[j] = Σ_i W[i] Z[i, j]`` (the sigma points' weighted mean), summed in order of i."""
    for j in range(out.shape[0]):
        acc = 0.0
        for i in range(Z.shape[0]):
            acc += W[i] * Z[i, j]
        out[j] = acc


@numba.njit(cache=True)
def _ukf_update(s, w, R, y):  # pragma: no cover - compiled
    """The UKF measurement update (module docstring) from the sigma points ``w.X`` and their
    images ``w.Yp[i] = h(X[i], u)``."""
    n, p, ns = s.xp.shape[0], R.shape[0], w.X.shape[0]
    _weighted_mean(w.Wm, w.Yp, w.yhat)
    for a in range(p):
        for b in range(p):
            acc = R[a, b]
            for i in range(ns):
                acc += w.Wc[i] * (w.Yp[i, a] - w.yhat[a]) * (w.Yp[i, b] - w.yhat[b])
            s.Se[a, b] = acc
    for a in range(n):
        for b in range(p):
            acc = 0.0
            for i in range(ns):
                acc += w.Wc[i] * (w.X[i, a] - s.xp[a]) * (w.Yp[i, b] - w.yhat[b])
            w.Pxy[a, b] = acc
    return _gain_update(s, w.yhat, w.Pxy, w.K, y)


@numba.njit(cache=True)
def _ukf_predict(s, w, Q):  # pragma: no cover - compiled
    """x_p = Σ W^m_i Xn_i, P_p = Σ W^c_i (Xn_i − x_p)(·)ᵀ + Q."""
    n, ns = s.xp.shape[0], w.Xn.shape[0]
    _weighted_mean(w.Wm, w.Xn, s.xp)
    for a in range(n):
        for b in range(a, n):
            acc = Q[a, b]
            for i in range(ns):
                acc += w.Wc[i] * (w.Xn[i, a] - s.xp[a]) * (w.Xn[i, b] - s.xp[b])
            s.Pp[a, b] = acc
            s.Pp[b, a] = acc


@numba.njit(cache=False)  # takes model functions: see the module docstring, "Caching"
def _through_jit(fn, X, u, out):  # pragma: no cover - compiled
    """``out[i] = fn(X[i], u)`` for each sigma point: 0, or 1 if ``fn`` returns other than
    ``out.shape[1]`` values, 2 if one is NaN or ±inf."""
    for i in range(X.shape[0]):
        v = fn(X[i], u)
        if v.shape[0] != out.shape[1]:
            return 1
        for j in range(out.shape[1]):
            if not np.isfinite(v[j]):
                return 2
            out[i, j] = v[j]
    return 0


@numba.njit(cache=False)  # takes model functions: see the module docstring, "Caching"
def _ukf_step_jit(f, h, c, noise, u, y, s, w):  # pragma: no cover - compiled
    """One UKF step with numba ``f``, ``h``: 0 done, 1 P_p or 2 Σ or 3 P_f not positive
    definite (the prediction is then left as it was), 4 ``f`` or 5 ``h`` returned the wrong
    length, 7 ``f`` or 8 ``h`` a NaN or ±inf, 9 a NaN or ±inf in ``u``, 10 a ±inf in ``y``
    (the prediction left as it was)."""
    bad = bad_sample(u, y)
    if bad:
        return 8 + bad
    if not _sigma_points(s.xp, s.Pp, c, w.L, w.X):
        return 1
    code = _through_jit(h, w.X, u, w.Yp)
    if code:
        return 5 if code == 1 else 8
    if not _ukf_update(s, w, noise.R, y):
        return 2
    if not _sigma_points(s.xf, s.Pf, c, w.L, w.X):
        return 3
    code = _through_jit(f, w.X, u, w.Xn)
    if code:
        return 4 if code == 1 else 7
    _ukf_predict(s, w, noise.Q)
    return 0


@numba.njit(cache=False)  # takes model functions: see the module docstring, "Caching"
def _ukf_run_jit(f, h, c, noise, U, Y, s, w, out):  # pragma: no cover - compiled
    """:func:`_ukf_step_jit` over the rows of U, Y into ``out``: (code, k) of the first failure
    or (0, N)."""
    for k in range(U.shape[0]):
        code = _ukf_step_jit(f, h, c, noise, U[k], Y[k], s, w)
        if code:
            return code, k
        _store(k, s, out)
    return 0, U.shape[0]


# ---------------------------------------------------------------- one buffer per filter
#
# A filter's numbers live in one flat float64 buffer; the records above are views of it, made
# in Python for the kernels called from Python, and inside the kernel for the numba path (a
# call with three arrays instead of fourteen: unboxing a record of arrays costs ~0.5 µs per
# array, making views inside the kernel a few ns).


def _layout(n: int, p: int, kind: str) -> list:
    """(name, shape) of the buffer's blocks, in order; the numba builders below follow it."""
    ns = 2 * n + 1
    blocks = [("xp", (n,)), ("Pp", (n, n)), ("xf", (n,)), ("Pf", (n, n)), ("e", (p,)),
              ("Se", (p, p)), ("Q", (n, n)), ("R", (p, p))]
    if kind == "ekf":
        return blocks + [("PHt", (n, p)), ("K", (n, p)), ("F", (n, n)), ("H", (p, n)),
                         ("T", (n, n)), ("xt", (n,))]
    return blocks + [("Wm", (ns,)), ("Wc", (ns,)), ("Pxy", (n, p)), ("K", (n, p)), ("yhat", (p,)),
                     ("L", (n, n)), ("X", (ns, n)), ("Yp", (ns, p)), ("Xn", (ns, n)), ("c", (1,))]


def _allocate(n: int, p: int, kind: str):
    """The buffer (zeros) and a dict of its blocks as numpy views."""
    blocks = _layout(n, p, kind)
    buf = np.zeros(sum(int(np.prod(shape)) for _, shape in blocks))
    views, o = {}, 0
    for name, shape in blocks:
        k = int(np.prod(shape))
        views[name] = buf[o:o + k].reshape(shape)
        o += k
    return buf, views


@numba.njit(cache=True, inline="always")
def _block(buf, o, rows, cols):  # pragma: no cover - compiled
    """The (rows, cols) view of ``buf`` at offset ``o``, and the offset after it."""
    return buf[o:o + rows * cols].reshape((rows, cols)), o + rows * cols


@numba.njit(cache=True)
def _common_records(buf, n, p):  # pragma: no cover - compiled
    """FilterState and Noise as views of ``buf`` (the first blocks of :func:`_layout`), and the
    offset after them."""
    xp, o = buf[0:n], n
    Pp, o = _block(buf, o, n, n)
    xf, o = buf[o:o + n], o + n
    Pf, o = _block(buf, o, n, n)
    e, o = buf[o:o + p], o + p
    Se, o = _block(buf, o, p, p)
    Q, o = _block(buf, o, n, n)
    R, o = _block(buf, o, p, p)
    return FilterState(xp, Pp, xf, Pf, e, Se), Noise(Q, R), o


@numba.njit(cache=True)
def _ekf_records(buf, n, p):  # pragma: no cover - compiled
    """(FilterState, Noise, EKFWork) as views of an EKF's buffer."""
    s, noise, o = _common_records(buf, n, p)
    PHt, o = _block(buf, o, n, p)
    K, o = _block(buf, o, n, p)
    F, o = _block(buf, o, n, n)
    H, o = _block(buf, o, p, n)
    T, o = _block(buf, o, n, n)
    return s, noise, EKFWork(PHt, K, F, H, T, buf[o:o + n])


@numba.njit(cache=True)
def _ukf_records(buf, n, p):  # pragma: no cover - compiled
    """(FilterState, Noise, UKFWork, c) as views of a UKF's buffer."""
    s, noise, o = _common_records(buf, n, p)
    ns = 2 * n + 1
    Wm, o = buf[o:o + ns], o + ns
    Wc, o = buf[o:o + ns], o + ns
    Pxy, o = _block(buf, o, n, p)
    K, o = _block(buf, o, n, p)
    yhat, o = buf[o:o + p], o + p
    L, o = _block(buf, o, n, n)
    X, o = _block(buf, o, ns, n)
    Yp, o = _block(buf, o, ns, p)
    Xn, o = _block(buf, o, ns, n)
    return s, noise, UKFWork(Wm, Wc, Pxy, K, yhat, L, X, Yp, Xn), buf[o]


#: the step and run kernels specialised to one set of numba model functions, made once per set
_SPECIALISED: dict = {}


def _ekf_kernels(f, h, Fj, Hj):
    """``(step(dims, buf, u, y), run(dims, buf, U, Y, out))`` calling ``f``, ``h``, ``Fj``,
    ``Hj`` as compile-time constants (a numba function passed as an argument is typed again at
    every call, which costs more than the filter step itself: docs/performance.md, "Issue 24
    follow-up", Kalman filter from Python)."""
    key = ("ekf", f, h, Fj, Hj)
    if key not in _SPECIALISED:
        @numba.njit
        def step(dims, buf, u, y):  # pragma: no cover - compiled
            s, noise, w = _ekf_records(buf, dims[0], dims[1])
            return _ekf_step_jit(f, h, Fj, Hj, noise, u, y, s, w)

        @numba.njit
        def run(dims, buf, U, Y, out):  # pragma: no cover - compiled
            s, noise, w = _ekf_records(buf, dims[0], dims[1])
            return _ekf_run_jit(f, h, Fj, Hj, noise, U, Y, s, w, out)

        _SPECIALISED[key] = (step, run)
    return _SPECIALISED[key]


def _ukf_kernels(f, h):
    """As :func:`_ekf_kernels`, for the UKF."""
    key = ("ukf", f, h)
    if key not in _SPECIALISED:
        @numba.njit
        def step(dims, buf, u, y):  # pragma: no cover - compiled
            s, noise, w, c = _ukf_records(buf, dims[0], dims[1])
            return _ukf_step_jit(f, h, c, noise, u, y, s, w)

        @numba.njit
        def run(dims, buf, U, Y, out):  # pragma: no cover - compiled
            s, noise, w, c = _ukf_records(buf, dims[0], dims[1])
            return _ukf_run_jit(f, h, c, noise, U, Y, s, w, out)

        _SPECIALISED[key] = (step, run)
    return _SPECIALISED[key]


# ---------------------------------------------------------------- the classes


def _covariance(M, name, size, cls) -> np.ndarray:
    M = np.atleast_2d(np.asarray(M, dtype=np.float64))
    if M.shape != (size, size) or not np.all(np.isfinite(M)):
        raise ModelError(f"{cls}: {name} must be a finite {size}×{size} matrix, found shape "
                         f"{M.shape}")
    if np.min(np.linalg.eigvalsh(0.5 * (M + M.T))) < (1e-300 if name in ("R", "P0") else 0.0):
        what = "positive definite" if name in ("R", "P0") else "positive semidefinite"
        raise ModelError(f"{cls}: {name} must be {what} (a covariance)")
    return np.ascontiguousarray(0.5 * (M + M.T))


def _vector(v) -> np.ndarray:
    return np.ascontiguousarray(np.atleast_1d(np.asarray(v, dtype=np.float64)).ravel())


def _is_linear(model) -> bool:
    """An identified linear model: its lti ``system`` (a nonlinear one, NLSS with its
    ``u_offset`` included, has ``to_ss`` that refuses and no ``system``)."""
    return hasattr(model, "to_ss") and hasattr(model, "u_offset") and hasattr(model, "system")


def _names(model, kind: str) -> list:
    """The model's input or output names (a gripkit Model's are Signals)."""
    names = getattr(model, kind, None)
    if names is None:  # NARXModel: one input, one output
        names = (getattr(model, "input_name" if kind == "inputs" else "output_name"),)
    return [getattr(s, "name", s) for s in names]


def _model_functions(filt, model, x0, dt):
    """``f``, ``h`` and the initial state of ``model`` (:mod:`.state_functions`); the filter
    keeps the model and its signal names for ``run``."""
    if callable(model) and not _is_linear(model):
        raise ArgumentError(f"{filt._name}: give both f(x, u) and h(x, u), or a model alone")
    f, h, x0_model, _ = state_functions(model, dt)
    filt.model = model
    filt._inputs, filt._outputs = _names(model, "inputs"), _names(model, "outputs")
    return f, h, x0_model if x0 is None else x0


class _NonlinearFilter:
    """What the EKF and UKF share: the state record, the checks, the ``step``/``run`` plumbing.
    ``x_pred``, ``P_pred``, ``x``, ``P`` are the arrays of the state record. A subclass defines
    ``_step_python(u, y)``, one sample with Python-called ``f`` and ``h``, returning 0 or a
    failure code of ``_FAIL``."""

    _name = "filter"
    _FAIL = {1: "the innovation covariance is not positive definite",
             4: "f(x, u) returned the wrong number of values (expected n, Q's size)",
             5: "h(x, u) returned the wrong number of values (expected p, R's size)",
             6: "a Jacobian returned the wrong shape (expected F: n×n, H: p×n)",
             7: "f(x, u) returned a NaN or ±inf at the filtered state (or in its Jacobian)",
             8: "h(x, u) returned a NaN or ±inf at the predicted state (or in its Jacobian)"}

    def _setup(self, Q, R, x0, P0, kind):
        """Checks, the buffer (:func:`_allocate`) and its records; returns the dict of views."""
        Q = _covariance(Q, "Q", np.atleast_2d(np.asarray(Q)).shape[0], self._name)
        R = _covariance(R, "R", np.atleast_2d(np.asarray(R)).shape[0], self._name)
        n, p = Q.shape[0], R.shape[0]
        xp = np.zeros(n) if x0 is None else _vector(x0)
        if xp.shape != (n,):
            raise ModelError(f"{self._name}: x0 must hold {n} values (Q is {n}×{n}), found "
                             f"{xp.size}")
        Pp = Q.copy() if P0 is None else _covariance(P0, "P0", n, self._name)
        self._buf, v = _allocate(n, p, kind)
        self._dims = np.array([n, p], dtype=np.int64)
        v["Q"][:], v["R"][:], v["xp"][:], v["Pp"][:] = Q, R, xp, Pp
        self.noise, self.n, self.p = Noise(v["Q"], v["R"]), n, p
        self._s = FilterState(v["xp"], v["Pp"], v["xf"], v["Pf"], v["e"], v["Se"])
        self.x_pred, self.P_pred, self.x, self.P = self._s[:4]
        return v

    # the noise covariances, views of the filter's buffer
    Q = property(attrgetter("noise.Q"))
    R = property(attrgetter("noise.R"))

    _AT = {7: "f at the filtered state x", 8: "h at the predicted state x_pred"}

    def _raise(self, code, where, u=None, y=None, k=None):
        if code in (9, 10):
            raise bad_channel(self._name, where, code - 8, u, y, k)
        if code in (7, 8):
            raise ModelError(f"{self._name}.{where}: {self._FAIL[code]}; the prediction x_pred, "
                             "P_pred is left as it was",
                             hint=f"check {self._AT[code]} for a division by zero, a root or log "
                                  "of a negative number, or an overflow")
        raise ModelError(f"{self._name}.{where}: {self._FAIL[code]}",
                         hint="check f, h, Q, R, P0 and the model's scaling")

    def _sample(self, u, y):
        """``u``, ``y`` as 1-D float64 arrays (float64 arrays pass as they are); y's length
        checked (the kernels trust it)."""
        if type(u) is not np.ndarray or u.dtype != np.float64 or u.ndim != 1:
            u = np.ascontiguousarray(np.atleast_1d(np.asarray(u, dtype=np.float64)))
        if type(y) is not np.ndarray or y.dtype != np.float64 or y.ndim != 1:
            y = np.ascontiguousarray(np.atleast_1d(np.asarray(y, dtype=np.float64)))
        if y.shape[0] != self.p:
            raise DataError(f"{self._name}.step: y must hold {self.p} value(s) per sample (R is "
                            f"{self.p}×{self.p}), found {y.size}")
        return u, y

    @property
    def innovation(self) -> np.ndarray:
        """The last step's innovation ``e`` (p,) (a copy)."""
        return self._s.e.copy()

    def step(self, u, y, *, copy: bool = True):
        """One sample: ``(x[t|t], P[t|t])`` (copies; ``copy=False``: the filter's own arrays,
        overwritten by the next step)."""
        u, y = self._sample(u, y)
        if self._jit:
            code = self._kernels[0](self._dims, self._buf, u, y)
        else:
            code = self._step_python(u, y)
        if code:
            self._raise(code, "step", u, y)
        if copy:
            return self.x.copy(), self.P.copy()
        return self.x, self.P

    def run(self, data, inputs=None, outputs=None) -> KalmanRun:
        """Filter a record: a :class:`~gripkit.signals.Trajectory` and the names of its input
        and output columns (a linear model's own names by default), from the current state."""
        inputs = list(getattr(self, "_inputs", ()) if inputs is None else inputs)
        outputs = list(getattr(self, "_outputs", ()) if outputs is None else outputs)
        if not outputs:
            raise ArgumentError(f"{self._name}.run: name the output columns: outputs=[...]")
        missing = [c for c in (*inputs, *outputs) if c not in data.names]
        if missing:
            raise DataError(f"data: the column(s) {', '.join(map(repr, missing))} are missing; "
                            f"the data have {', '.join(map(repr, data.names))}")
        N = len(data)
        u = (np.column_stack([data[c] for c in inputs]) if inputs else np.zeros((N, 0)))
        y = np.column_stack([data[c] for c in outputs])
        return self.run_arrays(u, y)

    def run_arrays(self, u, y) -> KalmanRun:
        """Filter inputs ``u`` (N, m) and outputs ``y`` (N, p): one numba call over the record
        when the model's functions are numba functions, else the Python step per row. A NaN in
        ``y`` is a missing measurement (:func:`_gain_update`; one DataWarning gives their count
        and the first, and ``missing`` marks them); a NaN or ±inf in ``u``, a ±inf in ``y``, or
        a NaN or ±inf from ``f`` or ``h`` is an error naming the sample."""
        y = np.ascontiguousarray(np.asarray(y, dtype=np.float64).reshape(len(y), -1))
        u = np.ascontiguousarray(np.asarray(u, dtype=np.float64).reshape(len(u), -1))
        if y.shape[1] != self.p or u.shape[0] != y.shape[0]:
            raise DataError(f"{self._name}.run_arrays: expected u (N, m) and y (N, {self.p}) "
                            f"with the same N, found {u.shape} and {y.shape}")
        N = y.shape[0]
        out = KalmanRun(np.empty((N, self.n)), np.empty((N, self.n, self.n)),
                        np.empty((N, self.p)), np.empty((N, self.p, self.p)), np.isnan(y))
        if self._jit:
            code, k = self._kernels[1](self._dims, self._buf, u, y, out)
            if code:
                self._raise(code, f"run (sample {k})", u[k], y[k], k)
        else:
            s = self._s
            for k in range(N):
                code = self._step_python(u[k], y[k])
                if code:
                    self._raise(code, f"run (sample {k})", u[k], y[k], k)
                out.x[k], out.P[k], out.e[k], out.S[k] = s.xf, s.Pf, s.e, s.Se
        warn_missing(f"{self._name}.run_arrays", out.missing)
        return out


class ExtendedKalmanFilter(_NonlinearFilter):
    """Extended Kalman filter of ``x[t+1] = f(x, u) + w``, ``y = h(x, u) + v`` (module
    docstring).

    Parameters
    ----------
    f, h
        ``f(x, u) -> (n,)``, ``h(x, u) -> (p,)``: Python callables or ``numba.njit`` functions;
        or a model alone in place of ``f`` (``h`` left out): a linear, grey-box or identified
        nonlinear model, whose state functions are those of
        :func:`~gripkit.estimation.state_functions.state_functions` (``x0`` default the model's
        initial state; ``run(data)`` takes the model's input and output columns by default).
    Q, R
        Process (n×n) and measurement (p×p) noise covariances; they fix n and p.
    F, H
        Jacobians ``F(x, u) -> (n, n)``, ``H(x, u) -> (p, n)``; not given: by ``jacobian``.
    jacobian
        ``"central"`` (central differences) or ``"complex"`` (complex step; ``f`` and ``h`` must
        accept complex ``x``; evaluated from Python).
    x0, P0
        Initial prediction (default 0) and its covariance (default Q).
    dt
        Sample time of a continuous linear model or of a grey-box model (given as a model).

    Examples
    --------
    >>> ekf = ExtendedKalmanFilter(lambda x, u: 0.9 * x + u, lambda x, u: x, Q=[[0.1]],
    ...                            R=[[1.0]], P0=[[1.0]])
    >>> x, P = ekf.step([0.0], [2.0]); x.round(6).tolist(), P.round(6).tolist()
    ([1.0], [[0.5]])
    """

    _name = "ExtendedKalmanFilter"

    def __init__(self, f, h=None, Q=None, R=None, *, F=None, H=None, jacobian: str = "central",
                 x0=None, P0=None, dt: float | None = None):
        if Q is None or R is None:
            raise ArgumentError("ExtendedKalmanFilter: give the noise covariances Q= and R=")
        if h is None:
            f, h, x0 = _model_functions(self, f, x0, dt)
        if not (callable(f) and callable(h)):
            raise ArgumentError("ExtendedKalmanFilter: f and h must be callables f(x, u) and "
                                "h(x, u)")
        if jacobian not in ("central", "complex"):
            raise ArgumentError(f"ExtendedKalmanFilter: jacobian must be 'central' or 'complex', "
                                f"found {jacobian!r}")
        if (F is None) != (H is None):
            raise ArgumentError("ExtendedKalmanFilter: give both Jacobians F and H, or neither")
        self.f, self.h, self.Fj, self.Hj, self.jacobian = f, h, F, H, jacobian
        v = self._setup(Q, R, x0, P0, "ekf")
        self._w = EKFWork(*(v[k] for k in EKFWork._fields))
        self._jit = (_is_jit(f) and _is_jit(h) and jacobian == "central"
                     and (F is None or (_is_jit(F) and _is_jit(H))))
        self._kernels = _ekf_kernels(f, h, F, H) if self._jit else None

    def _jacobian(self, fn, J, x, u, given, code) -> int:
        """J at x (given, complex step or central differences): 0, 6 the wrong shape, or
        ``code + 3`` a NaN or ±inf in it."""
        if given is not None:
            M = np.asarray(given(x, u), dtype=np.float64)
            if M.shape != J.shape:
                return 6
            J[:] = M
        elif self.jacobian == "complex":
            d = 1e-30
            xc = x.astype(complex)
            for j in range(x.size):
                xc[j] += 1j * d
                J[:, j] = np.imag(np.asarray(fn(xc, u))) / d
                xc[j] = x[j]
        else:
            for j in range(x.size):
                dj = _EPS3 * max(1.0, abs(x[j]))
                xt = x.copy()
                xt[j] = x[j] + dj
                hi = np.array(fn(xt, u), dtype=np.float64)  # a copy: fn may return xt
                xt[j] = x[j] - dj
                J[:, j] = (hi - np.asarray(fn(xt, u), dtype=np.float64)) / (2 * dj)
        return 0 if np.isfinite(J).all() else code + 3

    @staticmethod
    def _fn(fn, x, u, size, code):
        """``(fn(x, u), 0)``, or ``(…, code)`` for the wrong length, ``code + 3`` a NaN/±inf."""
        v = np.asarray(fn(x, u), dtype=np.float64).reshape(-1)
        if v.shape != (size,):
            return v, code
        return v, (0 if _finite(v) else code + 3)

    def _step_python(self, u, y) -> int:
        """One step calling ``f``, ``h`` from Python: 0 or a code of :func:`_ekf_step_jit`."""
        s, w = self._s, self._w
        bad = bad_sample(u, y)
        if bad:
            return 8 + bad
        hx, code = self._fn(self.h, s.xp, u, self.p, 5)
        code = code or self._jacobian(self.h, w.H, s.xp, u, self.Hj, 5)
        if code:
            return code
        if not _ekf_update(s, w, hx, self.noise.R, y):
            return 1
        fx, code = self._fn(self.f, s.xf, u, self.n, 4)
        code = code or self._jacobian(self.f, w.F, s.xf, u, self.Fj, 4)
        if code:
            return code
        s.xp[:] = fx
        _ekf_predict(s, w, self.noise.Q)
        return 0



class UnscentedKalmanFilter(_NonlinearFilter):
    """Unscented Kalman filter (module docstring) of a linear model or of ``f``, ``h``.

    ``UnscentedKalmanFilter(model, Q=, R=)`` with a :class:`~gripkit.sysid.LinearModel`: its
    discrete realisation with offsets (u, y in SI, offsets not removed, as
    :class:`~gripkit.estimation.KalmanFilter`), ``x0`` default rest and ``P0`` default the
    steady-state prediction covariance. With a grey-box gripkit ``Model``, an ``HWModel``,
    ``BoucWenModel``, ``BoucWenOscillatorModel``, ``NARXModel``, ``NLSSModel`` or
    ``PrandtlIshlinskiiModel``: the state functions of
    :func:`~gripkit.estimation.state_functions.state_functions` (``dt`` for a grey-box model),
    ``x0`` default the model's initial state, ``P0`` default Q; ``run(data)`` takes the model's
    input and output columns by default. ``UnscentedKalmanFilter(f, h, Q=, R=)``: ``f(x, u)``,
    ``h(x, u)`` Python or numba callables, ``x0`` default 0, ``P0`` default Q.
    ``alpha``, ``beta``, ``kappa``: the sigma-point scaling (module docstring).

    Examples
    --------
    A measurement y = x² of x ~ N(1, 0.1): the sigma points carry its mean E[x²] = 1 + 0.1
    exactly, so the innovation of y = 1.2 is 0.1 (a linearisation at x = 1 predicts 1, and 0.2).

    >>> ukf = UnscentedKalmanFilter(lambda x, u: x, lambda x, u: x ** 2, Q=[[0.01]], R=[[0.1]],
    ...                             x0=[1.0], P0=[[0.1]])
    >>> x, P = ukf.step([0.0], [1.2])
    >>> ukf.innovation.round(6).tolist(), x.round(6).tolist()
    ([0.1], [1.038462])
    """

    _name = "UnscentedKalmanFilter"
    _FAIL = {**_NonlinearFilter._FAIL,
             1: "the predicted covariance P is not positive definite",
             2: "the innovation covariance is not positive definite",
             3: "the filtered covariance P is not positive definite"}

    def __init__(self, f, h=None, Q=None, R=None, *, x0=None, P0=None, alpha: float = 1.0,
                 beta: float = 2.0, kappa: float = 0.0, dt: float | None = None):
        if Q is None or R is None:
            raise ArgumentError("UnscentedKalmanFilter: give the noise covariances Q= and R=")
        if h is None:
            model = f
            f, h, x0 = _model_functions(self, model, x0, dt)
            if P0 is None and _is_linear(model):
                P0 = KalmanFilter(model, Q=Q, R=R, dt=dt).P_steady_pred
        elif not (callable(f) and callable(h)):
            raise ArgumentError("UnscentedKalmanFilter: expected a LinearModel, or callables "
                                "f(x, u) and h(x, u)")
        self.f, self.h = f, h
        v = self._setup(Q, R, x0, P0, "ukf")
        n = self.n
        if not (alpha > 0 and np.isfinite(alpha) and n + kappa > 0):
            raise ArgumentError(f"UnscentedKalmanFilter: need alpha > 0 and n + kappa > 0, found "
                                f"alpha={alpha!r}, kappa={kappa!r} (n = {n})")
        self.c = float(alpha ** 2 * (n + kappa))
        v["c"][0] = self.c
        v["Wm"][:] = v["Wc"][:] = 0.5 / self.c
        v["Wm"][0] = (self.c - n) / self.c
        v["Wc"][0] = (self.c - n) / self.c + 1.0 - alpha ** 2 + beta
        self._w = UKFWork(*(v[k] for k in UKFWork._fields))
        self._jit = _is_jit(f) and _is_jit(h)
        self._kernels = _ukf_kernels(f, h) if self._jit else None

    @staticmethod
    def _through(fn, X, u, out, code) -> int:
        """``out[i] = fn(X[i], u)``: 0, ``code`` for the wrong length, ``code + 3`` a NaN/±inf."""
        for i in range(X.shape[0]):
            v = np.asarray(fn(X[i], u), dtype=np.float64).reshape(-1)
            if v.shape != (out.shape[1],):
                return code
            if not _finite(v):
                return code + 3
            out[i] = v
        return 0

    def _step_python(self, u, y) -> int:
        """One step calling ``f``, ``h`` from Python: 0 or a code of :func:`_ukf_step_jit`."""
        s, w = self._s, self._w
        bad = bad_sample(u, y)
        if bad:
            return 8 + bad
        if not _sigma_points(s.xp, s.Pp, self.c, w.L, w.X):
            return 1
        code = self._through(self.h, w.X, u, w.Yp, 5)
        if code:
            return code
        if not _ukf_update(s, w, self.noise.R, y):
            return 2
        if not _sigma_points(s.xf, s.Pf, self.c, w.L, w.X):
            return 3
        code = self._through(self.f, w.X, u, w.Xn, 4)
        if code:
            return code
        _ukf_predict(s, w, self.noise.Q)
        return 0
