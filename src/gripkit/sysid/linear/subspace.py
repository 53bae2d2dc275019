"""Subspace identification of MIMO state-space models: N4SID, MOESP and CVA in one implementation
(Van Overschee & De Moor, *Subspace Identification for Linear Systems*, 1996, Theorem 12, the
"unifying theorem"; Verhaegen's PO-MOESP).

With horizon k, block-Hankel matrices of future inputs ``U_f``, past inputs and outputs
``W_p = [U_p; Y_p]`` and future outputs ``Y_f`` (each column one time t, j = N − 2k + 1 columns),
the LQ factorisation

    [U_f; W_p; Y_f] = [[L11, 0, 0], [L21, L22, 0], [L31, L32, L33]] [Q1; Q2; Q3]

gives the oblique projection of Y_f along U_f onto W_p, ``O = L32 L22⁻¹ W_p``, whose column space
is that of the extended observability matrix Γ_k = [C; CA; …; CA^{k−1}]. The weighted SVD
``W1 O W2 = U S Vᵀ`` fixes the method:

* N4SID: W1 = I, W2 = I              → SVD of ``[L32 L22⁻¹ L21, L32]``;
* MOESP: W1 = I, W2 = Π_{U_f⊥}       → SVD of ``L32``;
* CVA:   W1 = (Y_f Π_{U_f⊥} Y_fᵀ)^{−½} → SVD of ``W1 L32``, W1 = (L32 L32ᵀ + L33 L33ᵀ)^{−½}.

The order n is the number of singular values that stand above the noise floor (five times the
median of those beyond the largest order considered; :func:`select_order`), unless given.
Then Γ = W1⁻¹ U_n S_n^{½}, ``C = Γ[0:p]`` and ``A = Γ_↑⁺ Γ_↓`` (shift invariance). When that A is
unstable, ``A = Γ⁺ [Γ_↓; 0]`` is used instead, which is stable by construction (Chui &
Maciejowski, 1996) and the reason is recorded. B, D and x0 follow by linear least squares on the
whole record (the output is linear in them for fixed A, C). The state sequence ``X̂ = Γ⁺ O`` gives
the process and measurement residuals w = x̂[t+1] − A x̂ − B u, v = y − C x̂ − D u, their
covariances (Q, S, R) and the Kalman gain of the innovation form from the Riccati equation
``P = A P Aᵀ + Q − (A P Cᵀ + S)(C P Cᵀ + R)⁻¹(A P Cᵀ + S)ᵀ``, ``K = (A P Cᵀ + S)(C P Cᵀ + R)⁻¹``.

Inputs and outputs are scaled to unit RMS before the factorisation (the weighting would otherwise
depend on the units) and the model is scaled back.
"""

from __future__ import annotations

import contextlib
import math

import numba
import numpy as np
import scipy.linalg as sla

from ...errors import DataError, IdentificationError, StabilityWarning, emit_warning
from ...lti import StateSpace
from .blocked_gram import add_rows, carried_states, carry, row_product, start_sums
from ..checks import (check_columns_vary, check_dt, check_excitation, check_output_varies,
                      io_records, warn_if_operating_point)
from .linear_model import (LinearModel, as_io_matrix, fit_per_output, free_run,
                           observability_regressor)
from ..regression import qr_r
from .ss_bootstrap import BOOTSTRAP_SEED, bootstrap_covariance, check_bootstrap
from .validation import records_fit

__all__ = ["n4sid", "n4sid_records", "moesp", "SUBSPACE_METHODS", "default_horizon",
           "subspace_factor", "SubspaceFactor", "RecordsFactor"]

SUBSPACE_METHODS = ("n4sid", "moesp", "cva")
DEFAULT_MAX_ORDER = 10


def default_horizon(n_max: int, p: int) -> int:
    """Block rows k: Γ_k must have more rows than states (k p > n) with room for the shift;
    ``k = max(⌈2 (n_max + 1) / p⌉, 5)``."""
    return max(int(math.ceil(2 * (n_max + 1) / p)), 5)


def _gram(Z: np.ndarray) -> np.ndarray:
    """ZᵀZ by BLAS ``dsyrk`` (half the flops of a product, and free of numpy's matmul dispatch)."""
    from scipy.linalg.blas import dsyrk

    G = dsyrk(1.0, np.asfortranarray(Z), trans=1)
    return np.triu(G) + np.triu(G, 1).T


def _lower_factor(Z: np.ndarray) -> np.ndarray:
    """L with ``L Lᵀ = ZᵀZ / j`` (the LQ factor of Zᵀ/√j): Cholesky of the Gram matrix (a few times
    faster than Householder QR for j ≫ q), falling back to QR when the Gram matrix is numerically
    singular (noise-free or rank-deficient data), where squaring the condition number would lose
    the small singular values that decide the order."""
    j = Z.shape[0]
    G = _gram(Z) / j
    with contextlib.suppress(np.linalg.LinAlgError):  # not positive definite: QR below
        L = np.linalg.cholesky(G)
        if np.min(np.abs(np.diag(L))) > 1e-6 * np.sqrt(np.max(np.diag(G))):
            return L
    return qr_r(np.asfortranarray(Z), overwrite=True).T / math.sqrt(j)


class SubspaceFactor:
    """The LQ factor of the scaled data and what every order shares (computed once, so that an
    order search does not repeat the factorisation)."""

    def __init__(self, u, y, k, method):
        self.u, self.y, self.k, self.method = u, y, k, method
        N, m = u.shape
        p = y.shape[1]
        self.m, self.p = m, p
        j = N - 2 * k + 1
        q = 2 * k * (m + p)
        self.su = np.sqrt(np.mean(u * u, axis=0))
        self.sy = np.sqrt(np.mean(y * y, axis=0))
        us, ys = u / self.su, y / self.sy
        self.us, self.ys = us, ys
        Z = np.empty((j, q), order="F")
        a, b = k * m, k * (m + p)
        for i in range(k):
            Z[:, i * m:(i + 1) * m] = us[k + i:k + i + j]                 # U_f
            Z[:, a + i * m:a + (i + 1) * m] = us[i:i + j]                 # U_p
            Z[:, a + k * m + i * p:a + k * m + (i + 1) * p] = ys[i:i + j]  # Y_p
            Z[:, a + b + i * p:a + b + (i + 1) * p] = ys[k + i:k + i + j]  # Y_f
        L = _lower_factor(Z)
        del Z
        self._weighted_svd(L)
        self.j = j

    def _weighted_svd(self, L: np.ndarray) -> None:
        """From the LQ factor ``L``: L32 L22⁻¹, the method's weighted matrix and its SVD."""
        k, m, p, method = self.k, self.m, self.p, self.method
        a, b = k * m, k * (m + p)
        L21, L22 = L[a:a + b, :a], L[a:a + b, a:a + b]
        L32, L33 = L[a + b:, a:a + b], L[a + b:, a + b:]
        self.L32_L22inv = np.linalg.lstsq(L22.T, L32.T, rcond=1e-12)[0].T  # L32 L22⁻¹
        self.W1inv = None
        if method == "n4sid":
            M = np.hstack([self.L32_L22inv @ L21, L32])
        elif method == "moesp":
            M = L32
        else:  # cva
            Syy = L32 @ L32.T + L33 @ L33.T
            w, V = np.linalg.eigh(Syy)
            w = np.maximum(w, 1e-12 * w.max())
            W1 = (V / np.sqrt(w)) @ V.T
            self.W1inv = (V * np.sqrt(w)) @ V.T
            M = W1 @ L32
        self.U, self.s, _ = np.linalg.svd(M, full_matrices=False)

    def gamma(self, n: int) -> np.ndarray:
        G = self.U[:, :n] * np.sqrt(self.s[:n])
        return G if self.W1inv is None else self.W1inv @ G

    def times_past_windows(self, M: np.ndarray) -> np.ndarray:
        """W_p Mᵀ for the past windows W_p (j, k(m + p)), one row per time k … k + j − 1, without
        forming W_p: the sum over its k block columns of the shifted signals times M's blocks."""
        k, m, p, j = self.k, self.m, self.p, self.j
        out = np.zeros((j, M.shape[0]))
        tmp = np.empty_like(out)  # one product buffer for the 2k terms (not 2k j × n temporaries)
        for i in range(k):
            np.add(out, np.matmul(self.us[i:i + j], M[:, i * m:(i + 1) * m].T, out=tmp), out=out)
            My = M[:, k * m + i * p:k * m + (i + 1) * p]
            np.add(out, np.matmul(self.ys[i:i + j], My.T, out=tmp), out=out)
        return out


def subspace_factor(u, y, *, horizon: int, method: str) -> SubspaceFactor:
    """Check sizes and factor the data (see :class:`SubspaceFactor`)."""
    N, m = u.shape
    p = y.shape[1]
    j = N - 2 * horizon + 1
    q = 2 * horizon * (m + p)
    if j < 2 * q:
        raise DataError(f"data: {N} samples of {m} input(s) and {p} output(s) with horizon k = "
                        f"{horizon} give "
                        f"{max(j, 0)} Hankel columns, fewer than the {2 * q} needed "
                        "(2 × 2k(m + p)); "
                        f"at least {2 * q + 2 * horizon - 1} samples are required",
                        hint="use a longer record, fewer outputs or a smaller --order/horizon")
    for name, x, check in (("input", u, check_excitation), ("output", y, check_output_varies)):
        for i in np.flatnonzero(~np.any(x, axis=0)):  # identically zero: refused as a constant
            check(x[:, i], f"{name} channel {i}")
    return SubspaceFactor(u, y, horizon, method)


NOISE_FACTOR = 5.0


def select_order(s: np.ndarray, n_max: int) -> int:
    """The number of singular values among the first ``n_max`` that stand above the noise floor:
    ``n = max{i ≤ n_max : s_i > 5 s_noise}``, s_noise the median of the singular values beyond
    n_max (the horizon gives k·p ≥ 2(n_max + 1) of them, so at least half are noise). Noise-free
    data (a floor below 1e-10 s_1) take the same rule with the floor at 1e-10 s_1."""
    tail = s[n_max:] if s.size > n_max else s[-1:]
    floor = max(float(np.median(tail)), 1e-10 * float(s[0]))
    above = np.flatnonzero(s[:n_max] > NOISE_FACTOR * floor)
    return int(above[-1]) + 1 if above.size else 1


def _check_supported(fac: SubspaceFactor, n: int) -> None:
    kp = fac.s.size
    if n >= kp:
        raise IdentificationError(f"order: {n} states need a horizon k with k·p > {n}; the "
                                  f"horizon k = {fac.k} "
                                  f"with p = {fac.p} output(s) supports at most {kp - 1}",
                                  hint="lower --order or pass a larger horizon")
    if fac.s[n - 1] <= 1e-10 * fac.s[0]:
        r = int(np.sum(fac.s > 1e-10 * fac.s[0]))
        raise IdentificationError(f"order: the data support at most {r} state(s) "
                                  f"(singular value {n} is "
                                  f"{fac.s[n - 1] / fac.s[0]:.2g} of the first), found order = {n}",
                                  hint=f"use --order {r} or less, or excite the system more richly")


def _bdx_regressor(A, C, u, feedthrough: bool):
    """Columns of the output's linear dependence on vec(B) (row-major), vec(D) and x0."""
    N, m = u.shape
    n, p = A.shape[0], C.shape[0]
    cols = n * m + (p * m if feedthrough else 0) + n
    Phi = np.empty((N, p, cols))
    Ac, Cc = np.ascontiguousarray(A), np.ascontiguousarray(C)
    for i in range(n):
        Bi = np.zeros((n, 1))
        Bi[i, 0] = 1.0
        for jj in range(m):
            Phi[:, :, i * m + jj] = free_run(Ac, Bi, Cc, np.zeros((p, 1)), u[:, jj:jj + 1])
    c = n * m
    if feedthrough:
        for r in range(p):
            for jj in range(m):
                Phi[:, :, c] = 0.0
                Phi[:, r, c] = u[:, jj]
                c += 1
    Phi[:, :, c:] = observability_regressor(A, C, N)
    return Phi.reshape(N * p, cols)


#: samples per block of :func:`_bdx_normal_equations` (its rows go to BLAS in one product)
_BDX_BLOCK = 256


@numba.njit(cache=True)
def _bdx_normal_equations(A, C, u, y, feedthrough, G, r):  # pragma: no cover - compiled
    """ΦᵀΦ into G and Φᵀy into r for the regressor of :func:`_bdx_regressor`, without forming Φ:
    one pass that carries the n·m unit-input responses and the n free responses of the state
    together (X[t+1] = A X[t] + [e_i u_j(t)]; the x0 columns start at the identity). Rows of
    :data:`_BDX_BLOCK` samples are collected and added to the sums by one BLAS product each.
    O(N·n²(m+1)) flops, O(cols²) memory beyond the block. Returns the final carried state X[N]
    (n × (n·m + n)), whose entries below 1e-280 are flushed to zero as it is carried
    (:func:`~gripkit.sysid.linear.blocked_gram.carry`: the x0 columns decay into the subnormal range
    otherwise; G and r are unchanged by it)."""
    N, m = u.shape
    n, p = A.shape[0], C.shape[0]
    nb = n * m
    nd = p * m if feedthrough else 0
    ns = nb + n  # state-carried columns: B's, then x0's
    cols = nb + nd + n
    X, Xn = carried_states(n, ns, nb, n)
    rows, yb = start_sums(_BDX_BLOCK * p, cols, G, r)
    fill = 0
    CX = np.empty(ns)
    for t in range(N):
        for row in range(p):
            row_product(C, row, X, CX)
            phi = rows[fill]
            for c in range(nb):
                phi[c] = CX[c]
            for c in range(nd):
                phi[nb + c] = u[t, c % m] if c // m == row else 0.0
            for c in range(n):
                phi[nb + nd + c] = CX[nb + c]
            yb[fill] = y[t, row]
            fill += 1
        if fill == rows.shape[0] or t == N - 1:
            add_rows(rows, yb, fill, G, r)
            fill = 0
        for i in range(n):  # X ← A X + [e_i u(t)ᵀ, 0]
            row_product(A, i, X, Xn[i])
            for j in range(m):
                Xn[i, i * m + j] += u[t, j]
        carry(Xn, X)
    return X


def _bdx_least_squares(A, C, u, y, feedthrough: bool) -> np.ndarray:
    """θ = (vec(B) row-major, vec(D), x0) minimising ‖y − Φθ‖ (Φ of :func:`_bdx_regressor`):
    normal equations from :func:`_bdx_normal_equations` on column-scaled Φ when their condition
    number stays below 1e8 (no N·p × cols regressor in memory), else LAPACK ``gelsy`` on Φ itself
    (formed only then)."""
    n, m, p = A.shape[0], u.shape[1], C.shape[0]
    cols = n * m + (p * m if feedthrough else 0) + n
    G, rhs = np.empty((cols, cols)), np.empty(cols)
    _bdx_normal_equations(np.ascontiguousarray(A), np.ascontiguousarray(C), u, y, feedthrough, G,
                          rhs)
    col = np.sqrt(np.diag(G)).copy()
    col[col == 0] = 1.0
    Gs = G / np.outer(col, col)
    w = np.linalg.eigvalsh(Gs)
    if w[0] > 1e-8 * w[-1]:
        return sla.cho_solve(sla.cho_factor(Gs), rhs / col) / col
    return sla.lstsq(_bdx_regressor(A, C, u, feedthrough), y.reshape(-1), lapack_driver="gelsy",
                     check_finite=False)[0]


def _kalman_gain(A, C, Q, S, R):
    """Innovation gain and innovation covariance from the Riccati equation (None on failure)."""
    try:
        P = sla.solve_discrete_are(A.T, C.T, Q, R, s=S)
        Lam = C @ P @ C.T + R
        K = np.linalg.solve(Lam.T, (A @ P @ C.T + S).T).T
    except (np.linalg.LinAlgError, ValueError):
        return None, None
    if not np.isfinite(K).all() or np.max(np.abs(np.linalg.eigvals(A - K @ C))) >= 1.0:
        return None, None
    return K, 0.5 * (Lam + Lam.T)


def from_factor(fac: SubspaceFactor, n: int, *, dt: float, feedthrough: bool = False,
                stable: bool = True,
                signals: dict | None = None, meta: dict | None = None) -> LinearModel:
    """The order-n model from a factored data set (see the module docstring)."""
    p, m = fac.p, fac.m
    G, A, C, info = _shift_invariance(fac, n, stable,
                                      lambda A, C: _unstable_fit(fac, A, C, feedthrough))
    us, ys = fac.us, fac.ys
    N = us.shape[0]
    theta = _bdx_least_squares(A, C, us, ys, feedthrough)
    Bs = theta[:n * m].reshape(n, m)
    c = n * m
    Ds = np.zeros((p, m))
    if feedthrough:
        Ds = theta[c:c + p * m].reshape(p, m)
        c += p * m
    x0s = theta[c:]
    yhat = free_run(A, Bs, C, Ds, us, x0s)
    # innovation gain from the state sequence X̂ = Γ⁺ L32 L22⁻¹ W_p
    Mx = np.linalg.pinv(G) @ fac.L32_L22inv
    X = fac.times_past_windows(Mx)                       # x̂ at t = k … k + j − 1
    k0 = fac.k
    t = np.arange(k0, k0 + X.shape[0] - 1)
    w = X[1:] - X[:-1] @ A.T - us[t] @ Bs.T
    v = ys[t] - X[:-1] @ C.T - us[t] @ Ds.T
    nw = w.shape[0]
    Q, S, R = w.T @ w / nw, w.T @ v / nw, v.T @ v / nw
    Ks, Lam = _kalman_gain(A, C, Q, S, R)
    if Ks is None:
        info["noise_model"] = ("Riccati equation without a stabilising solution: K = 0 "
                               "(output-error form)")
        Ks, Lam = np.zeros((n, p)), R
    # back to physical units
    su, sy = fac.su, fac.sy
    B = Bs / su
    Cp = C * sy[:, None]
    D = Ds * sy[:, None] / su
    K = Ks / sy
    Lam = Lam * np.outer(sy, sy)
    yhat = yhat * sy
    sig = dict(signals or {})
    sys = StateSpace(A, B, Cp, D, dt=dt, meta={"identified_by": fac.method, **(meta or {})}, **sig)
    fit = fit_per_output(fac.y, yhat)
    return LinearModel(sys, fac.method, K=K, x0=x0s, noise_covariance=Lam, fit_percent=fit,
                       singular_values=fac.s.copy(), n_samples=N, info=info)


def _shift_invariance(fac, n: int, stable: bool, unstable_fit):
    """(Γ, A, C, info) of the order-n model: C = Γ[0:p], A = Γ_↑⁺ Γ_↓, or, when that A is
    unstable and ``stable``, the stable A = Γ⁺[Γ_↓; 0] (``unstable_fit(A, C)``: the free-run fit
    of the unstable estimate, recorded)."""
    _check_supported(fac, n)
    p = fac.p
    G = fac.gamma(n)
    C = G[:p].copy()
    A = np.linalg.lstsq(G[:-p], G[p:], rcond=None)[0]
    info = {"method": fac.method, "horizon": fac.k, "hankel_columns": fac.j}
    rho = float(np.max(np.abs(np.linalg.eigvals(A))))
    if rho >= 1.0:
        if stable:
            info["stabilised"] = {"largest_pole_before": rho,
                                  "fit_percent_before": unstable_fit(A, C)}
            A = np.linalg.lstsq(G, np.vstack([G[p:], np.zeros((p, n))]), rcond=None)[0]
            info["stability"] = (f"shift-invariance estimate unstable (largest |pole| {rho:.4g}); "
                                 "replaced by A = Γ⁺[Γ↓; 0], stable by construction (Chui & "
                                 "Maciejowski 1996)")
        else:
            info["stability"] = f"unstable model kept as asked (largest |pole| {rho:.4g})"
            emit_warning(f"subspace: the order-{n} model is unstable (largest |pole| {rho:.4g})",
                         StabilityWarning)
    else:
        info["stability"] = "stable (shift-invariance estimate)"
    return G, A, C, info


def _unstable_fit(fac: SubspaceFactor, A, C, feedthrough: bool) -> list[float]:
    """Free-run fit (% per output) of the unstable shift-invariance estimate, for the warning of
    :func:`warn_if_stabilised` (−inf where its free run overflows)."""
    n, m = A.shape[0], fac.m
    try:
        with np.errstate(over="ignore", invalid="ignore"):
            theta = _bdx_least_squares(A, C, fac.us, fac.ys, feedthrough)
    except (np.linalg.LinAlgError, ValueError):  # the unstable regressor overflowed first
        return [-math.inf] * fac.p
    D = theta[n * m:n * m + fac.p * m].reshape(fac.p, m) if feedthrough else np.zeros((fac.p, m))
    with np.errstate(over="ignore", invalid="ignore"):
        yhat = free_run(A, theta[:n * m].reshape(n, m), C, D, fac.us, theta[-n:]) * fac.sy
        if not np.isfinite(yhat).all():
            return [-math.inf] * fac.p
        return [float(f) for f in fit_per_output(fac.y, yhat)]


def warn_if_stabilised(model: LinearModel, stacklevel: int = 3) -> None:
    """A :class:`StabilityWarning` when the subspace step replaced an unstable estimate of A by a
    stable one: the data may come from an unstable plant, and the stable model then misfits them.
    Names the largest |pole| and the free-run fit before and after (of ``model`` as returned)."""
    s = model.info.get("stabilised")
    if not s:
        return
    after = float(np.max(np.abs(model.system.poles())))
    fits = lambda f: ", ".join(f"{v:.3g} %" for v in f)  # noqa: E731
    emit_warning(
       f"{model.structure}: the data point to an unstable system (the subspace estimate has "
       f"largest |pole| {s['largest_pole_before']:.4g}, free-run fit "
       f"{fits(s['fit_percent_before'])}); it was stabilised to largest |pole| {after:.6g} with "
       f"free-run fit {fits(model.fit_percent)}: if the plant is unstable this model is not it; "
       f"identify it from closed-loop data, or keep the "
       f"unstable estimate with gripkit.sysid.n4sid(u, y, stable=False)", StabilityWarning)


def _orders(order, max_order) -> tuple:
    """``(order, n_max)``: ``order`` None or checked a positive integer (as int), and the
    largest order to consider (``order`` when given, else ``max_order``)."""
    if order is not None:
        if isinstance(order, bool) or not float(order).is_integer() or int(order) < 1:
            raise DataError(f"order: expected a positive integer, found {order!r}")
        order = int(order)
    return order, order if order is not None else int(max_order)


def n4sid(u, y, order: int | None = None, *, method: str = "n4sid", horizon: int | None = None,
          dt: float | None = None, feedthrough: bool = False, stable: bool = True,
          max_order: int = DEFAULT_MAX_ORDER, inputs=None, outputs=None, input_units=None,
          output_units=None,
          u_offset=None, y_offset=None, bootstrap: bool | int = False,
          bootstrap_seed: int = BOOTSTRAP_SEED) -> LinearModel:
    """Subspace identification of a discrete MIMO state-space model in innovation form.

    Parameters
    ----------
    u, y
        Inputs (N, m) and outputs (N, p) (1-D: one channel), deviation units (operating point
        removed; it goes in ``u_offset``, ``y_offset``, and the model's methods then take the
        record's own values, ``m.compare(u + u_offset, y + y_offset)``), uniformly sampled.
    order
        Number of states n; None: the number of singular values above the noise floor
        (1 … ``max_order``, :func:`select_order`).
    method
        ``'n4sid'``, ``'moesp'`` or ``'cva'`` (weightings, see the module docstring).
    horizon
        Block rows k of the Hankel matrices (default :func:`default_horizon`).
    dt
        Sample interval (s).
    feedthrough
        Estimate D (default False: D = 0, a sampled physical system with a zero-order hold).
    stable
        Replace an unstable shift-invariance estimate of A by a stable one (default True).
    inputs, outputs, input_units, output_units, u_offset, y_offset
        Names, SI units and removed operating points (carried by the model).
    bootstrap
        σ of the estimate by a parametric bootstrap
        (:func:`~gripkit.sysid.linear.ss_bootstrap.bootstrap_covariance`, the same estimation
        refitted): ``True`` (replicates by the record's length), an integer >= 10 (that many
        replicates), or ``False`` (default) or 0: no σ, the subspace estimate alone, which
        ``info['sigma']`` says. This function is a building block (the start of PEM, the
        nonlinear families' initialisation, loops over orders or data), where the
        bootstrap's cost (100 refits up to N = 20 000: 0.5 s at N = 1e4, order 4, against
        0.01 s for the estimate) would be paid for nothing;
        ``gripkit.sysid.identify(data, 'ss', refine=False)`` (``gripkit identify ss
        --no-refine``) gives the subspace model with this σ by default.
    bootstrap_seed
        Seed of the bootstrap's draws (numpy's default_rng).

    Returns
    -------
    LinearModel
        ``.system`` (:class:`gripkit.lti.StateSpace`), ``.K``, ``.x0``, ``.noise_covariance``,
        ``.singular_values``, ``.fit_percent`` (free run per output), ``.info`` (horizon,
        stability note; ``covariance`` with ``bootstrap``, else ``sigma``).

    Raises
    ------
    UnidentifiableError
        For a constant input or output column (:func:`~gripkit.sysid.checks.check_columns_vary`,
        the check of :func:`~gripkit.sysid.identify`), named by ``inputs``/``outputs`` or its
        index, with its value: the data are deviation units, so a constant input is no offset
        input of the model but a channel that carries nothing about B (drop it, or record it
        varying), and a constant output has no dynamics to identify.

    Examples
    --------
    >>> import numpy as np
    >>> from gripkit.sysid import n4sid
    >>> from gripkit.lti import StateSpace
    >>> g = StateSpace([[0.9, 0.2], [0.0, 0.7]], [[0.0], [1.0]], [[1.0, 0.0]], dt=1.0)
    >>> u = np.random.default_rng(0).standard_normal(2000)
    >>> m = n4sid(u, g.simulate(u), None)
    >>> m.order, np.sort(m.system.poles().real).round(3).tolist()
    (2, [0.7, 0.9])
    """
    if method not in SUBSPACE_METHODS:
        raise DataError(f"method: expected one of {', '.join(SUBSPACE_METHODS)}, found {method!r}")
    replicates = check_bootstrap(bootstrap, bootstrap_seed, "bootstrap")
    u = as_io_matrix(u, "input u")
    y = as_io_matrix(y, "output y", u.shape[0])
    signals = (dict(inputs=inputs, outputs=outputs, input_units=input_units,
                    output_units=output_units))
    check_columns_vary(u, y, {**signals, "u_offset": u_offset, "y_offset": y_offset})
    step = check_dt(dt)
    order, n_max = _orders(order, max_order)
    p = y.shape[1]
    k = default_horizon(n_max, p) if horizon is None else int(horizon)
    fac = subspace_factor(u, y, horizon=k, method=method)
    n = order if order is not None else select_order(fac.s, min(n_max, fac.s.size - 1))
    if u.shape[1] == y.shape[1] == 1 and n > 0:  # as ARX [n n nk] with a constant term
        warn_if_operating_point(u[:, 0], y[:, 0], n, n, 0 if feedthrough else 1,
                                f"{method} (order {n})")
    model = from_factor(fac, n, dt=step, feedthrough=feedthrough, stable=stable, signals=signals)
    model.info["order_selection"] = ("given" if order is not None
                                     else "singular values above the noise floor")
    warn_if_stabilised(model)
    model = model.replace(u_offset=u_offset, y_offset=y_offset)
    if replicates == 0:
        model.info["sigma"] = NO_SIGMA
        return model
    refit = lambda uu, yy: from_factor(  # noqa: E731
        subspace_factor(uu, yy, horizon=k, method=method), n, dt=step, feedthrough=feedthrough,
        stable=stable)
    return bootstrap_covariance(model, u, y, refit, estimator=f"{method} (order {n}, horizon {k})",
                                replicates=replicates, seed=bootstrap_seed, feedthrough=feedthrough)


#: what a subspace model from :func:`n4sid` without ``bootstrap`` says of its σ (``info['sigma']``)
NO_SIGMA = ("no σ: the subspace estimate alone (PEM skipped); n4sid(..., bootstrap=True) gives σ "
            "(a parametric bootstrap), as identify(data, 'ss', refine=False) does by default")


def moesp(u, y, order: int | None = None, **options) -> LinearModel:
    """PO-MOESP: :func:`n4sid` with ``method='moesp'``."""
    return n4sid(u, y, order, method="moesp", **options)


class RecordsFactor(SubspaceFactor):
    """:class:`SubspaceFactor` of several records: the block-Hankel rows (one per time with a
    full past and future window) of every record stacked, none reaching across from one record
    into the next; one scaling (the RMS of all records) for all. ``us``, ``ys`` are then lists
    (one array per record) and ``records`` the records as given."""

    def __init__(self, records, k, method):
        self.records, self.k, self.method = records, k, method
        m, p = records[0][0].shape[1], records[0][1].shape[1]
        self.m, self.p = m, p
        N = sum(u.shape[0] for u, _ in records)
        self.su = np.sqrt(sum(np.sum(u * u, axis=0) for u, _ in records) / N)
        self.sy = np.sqrt(sum(np.sum(y * y, axis=0) for _, y in records) / N)
        self.us = [u / self.su for u, _ in records]
        self.ys = [y / self.sy for _, y in records]
        self.js = [u.shape[0] - 2 * k + 1 for u, _ in records]
        j = sum(self.js)
        Z = np.empty((j, 2 * k * (m + p)), order="F")
        a, b = k * m, k * (m + p)
        row = 0
        for us, ys, ji in zip(self.us, self.ys, self.js):
            r = slice(row, row + ji)
            for i in range(k):
                Z[r, i * m:(i + 1) * m] = us[k + i:k + i + ji]
                Z[r, a + i * m:a + (i + 1) * m] = us[i:i + ji]
                Z[r, a + k * m + i * p:a + k * m + (i + 1) * p] = ys[i:i + ji]
                Z[r, a + b + i * p:a + b + (i + 1) * p] = ys[k + i:k + i + ji]
            row += ji
        L = _lower_factor(Z)
        del Z
        self._weighted_svd(L)
        self.j = j

    def past_windows_of(self, r: int, M: np.ndarray) -> np.ndarray:
        """W_p Mᵀ of record ``r`` (rows: its times k … k + j_r − 1)."""
        k, m, p, j = self.k, self.m, self.p, self.js[r]
        us, ys = self.us[r], self.ys[r]
        out = np.zeros((j, M.shape[0]))
        for i in range(k):
            out += us[i:i + j] @ M[:, i * m:(i + 1) * m].T
            out += ys[i:i + j] @ M[:, k * m + i * p:k * m + (i + 1) * p].T
        return out


def _bdx_records(A, C, us, ys, feedthrough: bool) -> tuple[np.ndarray, list[np.ndarray]]:
    """θ = (vec(B) row-major, vec(D)) shared by all records and one x0 per record, minimising
    Σ_r ‖y_r − Φ_r θ‖: the normal equations of every record (:func:`_bdx_normal_equations`)
    assembled, the x0 columns of each record its own block; on column-scaled equations when their
    condition number stays below 1e8, else ``gelsy`` on the stacked regressors."""
    n, m, p = A.shape[0], us[0].shape[1], C.shape[0]
    s = n * m + (p * m if feedthrough else 0)  # shared columns
    R = len(us)
    cols = s + R * n
    G, rhs = np.zeros((cols, cols)), np.zeros(cols)
    Gi, ri = np.empty((s + n, s + n)), np.empty(s + n)
    for r, (u, y) in enumerate(zip(us, ys)):
        _bdx_normal_equations(np.ascontiguousarray(A), np.ascontiguousarray(C), u, y, feedthrough,
                              Gi, ri)
        own = np.r_[np.arange(s), s + r * n + np.arange(n)]
        G[np.ix_(own, own)] += Gi
        rhs[own] += ri
    col = np.sqrt(np.diag(G)).copy()
    col[col == 0] = 1.0
    Gs = G / np.outer(col, col)
    w = np.linalg.eigvalsh(Gs)
    if w[0] > 1e-8 * w[-1]:
        theta = sla.cho_solve(sla.cho_factor(Gs), rhs / col) / col
    else:
        blocks = []
        for r, (u, y) in enumerate(zip(us, ys)):
            Phi = _bdx_regressor(A, C, u, feedthrough)
            full = np.zeros((Phi.shape[0], cols))
            full[:, :s] = Phi[:, :s]
            full[:, s + r * n:s + (r + 1) * n] = Phi[:, s:]
            blocks.append(full)
        theta = sla.lstsq(np.vstack(blocks), np.concatenate([y.reshape(-1) for y in ys]),
                          lapack_driver="gelsy", check_finite=False)[0]
    return theta[:s], [theta[s + r * n:s + (r + 1) * n] for r in range(R)]


def from_records_factor(fac: RecordsFactor, n: int, *, dt: float, feedthrough: bool = False,
                        stable: bool = True, signals: dict | None = None) -> LinearModel:
    """:func:`from_factor` for several records: A, C from the pooled factor; B, D shared and one
    x0 per record by least squares over all records; the noise model from the state sequences of
    every record. ``fit_percent``: the free run of all records per output, each from its own x0
    (:func:`~gripkit.sysid.linear.validation.records_fit`); ``info['records']``: each record's
    samples, free-run fit and x0 (the model's ``x0`` is the first record's)."""
    p, m = fac.p, fac.m

    def unstable_fit(A, C):
        return [-math.inf] * p  # not simulated: an unstable free run over several records

    G, A, C, info = _shift_invariance(fac, n, stable, unstable_fit)
    shared, x0s = _bdx_records(A, C, fac.us, fac.ys, feedthrough)
    Bs = shared[:n * m].reshape(n, m)
    Ds = shared[n * m:].reshape(p, m) if feedthrough else np.zeros((p, m))
    Mx = np.linalg.pinv(G) @ fac.L32_L22inv
    ws, vs = [], []
    for r, (us, ys) in enumerate(zip(fac.us, fac.ys)):
        X = fac.past_windows_of(r, Mx)
        t = np.arange(fac.k, fac.k + X.shape[0] - 1)
        ws.append(X[1:] - X[:-1] @ A.T - us[t] @ Bs.T)
        vs.append(ys[t] - X[:-1] @ C.T - us[t] @ Ds.T)
    w, v = np.vstack(ws), np.vstack(vs)
    nw = w.shape[0]
    Ks, Lam = _kalman_gain(A, C, w.T @ w / nw, w.T @ v / nw, v.T @ v / nw)
    if Ks is None:
        info["noise_model"] = ("Riccati equation without a stabilising solution: K = 0 "
                               "(output-error form)")
        Ks, Lam = np.zeros((n, p)), v.T @ v / nw
    su, sy = fac.su, fac.sy
    yhats = [free_run(A, Bs, C, Ds, us, x0) * sy for us, x0 in zip(fac.us, x0s)]
    ys = [y for _, y in fac.records]
    info["n_records"] = len(ys)
    info["records"] = [{"n_samples": int(y.shape[0]), "fit_percent": fit_per_output(y, yh),
                        "x0": x0} for y, yh, x0 in zip(ys, yhats, x0s)]
    sys = StateSpace(A, Bs / su, C * sy[:, None], Ds * sy[:, None] / su, dt=dt,
                     meta={"identified_by": fac.method}, **dict(signals or {}))
    return LinearModel(sys, fac.method, K=Ks / sy, x0=x0s[0],
                       noise_covariance=Lam * np.outer(sy, sy),
                       fit_percent=records_fit(ys, yhats).tolist(), singular_values=fac.s.copy(),
                       n_samples=int(sum(y.shape[0] for y in ys)), info=info)


def n4sid_records(records, order: int | None = None, *, method: str = "n4sid",
                  horizon: int | None = None, dt: float | None = None, feedthrough: bool = False,
                  stable: bool = True, max_order: int = DEFAULT_MAX_ORDER, inputs=None,
                  outputs=None, input_units=None, output_units=None, u_offset=None,
                  y_offset=None) -> LinearModel:
    """:func:`n4sid` of several records at once: ``records`` a list of ``(u, y)`` pairs (u (N_i, m),
    y (N_i, p)) around one common operating point. The block-Hankel data matrices of every record
    are stacked (:class:`RecordsFactor`: no Hankel column reaches across from one record into the
    next, each record has its own initial state), A and C come from their one factorisation, B and
    D from all records with one x0 per record (estimated); see :func:`from_records_factor` for
    the fits. Each record needs at least 2k samples (k the horizon)."""
    if method not in SUBSPACE_METHODS:
        raise DataError(f"method: expected one of {', '.join(SUBSPACE_METHODS)}, found {method!r}")
    recs = io_records(records)
    m, p = recs[0][0].shape[1], recs[0][1].shape[1]
    step = check_dt(dt)
    order, n_max = _orders(order, max_order)
    k = default_horizon(n_max, p) if horizon is None else int(horizon)
    for i, (u, _) in enumerate(recs):
        if u.shape[0] < 2 * k:
            raise DataError(f"records[{i}]: {u.shape[0]} samples, fewer than the 2k = {2 * k} of "
                            f"one past and future window (horizon k = {k})",
                            hint="drop the short record or pass a smaller horizon/order")
    j, q = sum(u.shape[0] - 2 * k + 1 for u, _ in recs), 2 * k * (m + p)
    if j < 2 * q:
        raise DataError(f"records: {j} Hankel columns in all with horizon k = {k}, fewer than the "
                        f"{2 * q} needed (2 × 2k(m + p))",
                        hint="use longer records or a smaller order")
    fac = RecordsFactor(recs, k, method)
    n = order if order is not None else select_order(fac.s, min(n_max, fac.s.size - 1))
    signals = dict(inputs=inputs, outputs=outputs, input_units=input_units,
                   output_units=output_units)
    model = from_records_factor(fac, n, dt=step, feedthrough=feedthrough, stable=stable,
                                signals=signals)
    model.info["order_selection"] = ("given" if order is not None
                                     else "singular values above the noise floor")
    return model.replace(u_offset=u_offset, y_offset=y_offset)
