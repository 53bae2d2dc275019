"""A discrete Kalman filter for an identified linear model.

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

The step is one call of a numba kernel (:func:`kf_step_packed`) in scalar loops that allocates
nothing: the filter's matrices and its state and work arrays are two flat float64 buffers made
once, with the filter. ``run`` filters a whole record in one kernel call (:func:`kf_run_packed`).

A NaN in ``y`` is a missing measurement (a dropout): the step updates with the measured outputs
only (C's rows, R's rows and columns of the finite ones; none: the time update alone), and
``run`` warns once and marks them (``KalmanRun.missing``). A NaN or ±inf in ``u``, or a ±inf in
``y``, is a DataError naming the sample and the channel, the filter left as it was."""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np
from scipy.linalg import solve_discrete_are

from ..errors import ArgumentError, DataError, DataWarning, ModelError, emit_warning
from ..lti import flush_tiny
from .packed import block_offsets, block_starts

__all__ = ["KalmanFilter", "KalmanRun"]


class _KalmanArrays(NamedTuple):
    x: np.ndarray
    P: np.ndarray
    e: np.ndarray
    S: np.ndarray


class KalmanRun(_KalmanArrays):
    """What :meth:`KalmanFilter.run` returns: filtered states ``x`` (N, n), their covariances
    ``P`` (N, n, n), innovations ``e`` (N, p) and their covariances ``S`` (N, p, p) — the
    tuple, so ``x, P, e, S = run`` unpacks it — and the attribute ``missing`` (N, p), outside
    the tuple: True where the measurement was NaN, a missing one (its innovation and the
    innovation covariance's row and column are then NaN; ``missing.any(axis=1)``: the samples
    updated with fewer outputs, or not at all). ``_replace`` keeps it; without it (a run built
    by hand, or by ``_make``) it is ``isnan(e)``."""

    def __new__(cls, x, P, e, S, missing=None):
        run = super().__new__(cls, x, P, e, S)
        run.__dict__["_missing"] = missing
        return run

    @property
    def missing(self) -> np.ndarray:
        m = self.__dict__.get("_missing")
        return np.isnan(self.e) if m is None else m

    def _replace(self, **fields) -> "KalmanRun":
        values = [fields.pop(f, getattr(self, f)) for f in self._fields]
        if fields:
            raise ValueError(f"Got unexpected field names: {list(fields)!r}")
        return KalmanRun(*values, missing=self.__dict__.get("_missing"))


def warn_missing(where: str, missing: np.ndarray) -> None:
    """One DataWarning for the samples of a record with missing (NaN) measurements, if any:
    their count and the first one's index (``missing``: (N, p) booleans)."""
    rows = missing.any(axis=1)
    if rows.any():
        k = int(np.argmax(rows))
        emit_warning(DataWarning(
            f"{where}: {int(rows.sum())} of {rows.size} samples have missing (NaN) measurements "
            f"({int(missing.sum())} values; first at sample {k}, output "
            f"{int(np.argmax(missing[k]))}); they were updated with their measured outputs only "
            "(none: the time update alone); run.missing marks them"))


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


# --- packed buffers (:mod:`gripkit.estimation.packed`): one parameter vector and one state
# vector per filter, so that a step is one numba call with five array arguments.
#
# par: A (n×n), B (n×m), C (p×n), D (p×m), Q (n×n), R (p×p), S (n×p), u0 (m), y0 (p),
#      K_f (n×p), K_p (n×p), P_f steady (n×n), Σ steady (p×p), P_p steady (n×n)
# st:  x_p (n), P_p (n×n), x_f (n), P_f (n×n), du (m), y − y0 (p), e (p), Σ (p×p),
#      work: P_p Cᵀ (n×p), M (n×p), K_f (n×p), K_p (n×p), A P_p (n×n), x_next (n)
PAR_BLOCKS = ("A", "B", "C", "D", "Q", "R", "S", "u0", "y0", "Kf", "Kp", "Pf", "Sig", "Pp")
ST_BLOCKS = ("xp", "Pp", "xf", "Pf", "du", "yy", "e", "Sig", "PCt", "M", "Kf", "Kp", "T", "xn")


@numba.njit(cache=True, inline="always")
def _par_sizes(n, m, p):  # pragma: no cover - compiled
    """Sizes of the parameter vector's blocks (:data:`PAR_BLOCKS`)."""
    return (n * n, n * m, p * n, p * m, n * n, p * p, n * p, m, p, n * p, n * p, n * n, p * p,
            n * n)


@numba.njit(cache=True, inline="always")
def _st_sizes(n, m, p):  # pragma: no cover - compiled
    """Sizes of the state vector's blocks (:data:`ST_BLOCKS`)."""
    return (n, n * n, n, n * n, m, p, p, p * p, n * p, n * p, n * p, n * p, n * n, n)


def _par_layout(n, m, p):
    """Offsets of the parameter vector's blocks, and its size."""
    return block_offsets(PAR_BLOCKS, _par_sizes(n, m, p))


def _st_layout(n, m, p):
    """Offsets of the state vector's blocks, and its size."""
    return block_offsets(ST_BLOCKS, _st_sizes(n, m, p))


@numba.njit(cache=True, inline="always")
def _flat_cholesky(a, o, p):  # pragma: no cover - compiled
    """In place on the p×p block of ``a`` at ``o``: its lower triangle becomes L (Σ = L Lᵀ);
    False if Σ is not positive definite."""
    for j in range(p):
        d = a[o + j * p + j]
        for k in range(j):
            d -= a[o + j * p + k] * a[o + j * p + k]
        if not d > 0.0:
            return False
        d = np.sqrt(d)
        a[o + j * p + j] = d
        for i in range(j + 1, p):
            acc = a[o + i * p + j]
            for k in range(j):
                acc -= a[o + i * p + k] * a[o + j * p + k]
            a[o + i * p + j] = acc / d
    return True


@numba.njit(cache=True, inline="always")
def _flat_solve_rows(a, oL, p, ob, ox, rows):  # pragma: no cover - compiled
    """Rows of X = B Σ⁻¹ (X, B: rows×p blocks of ``a`` at ``ox``, ``ob``; Σ = L Lᵀ, L at
    ``oL``): forward then back substitution, row by row."""
    for r in range(rows):
        for i in range(p):
            acc = a[ob + r * p + i]
            for k in range(i):
                acc -= a[oL + i * p + k] * a[ox + r * p + k]
            a[ox + r * p + i] = acc / a[oL + i * p + i]
        for i in range(p - 1, -1, -1):
            acc = a[ox + r * p + i]
            for k in range(i + 1, p):
                acc -= a[oL + k * p + i] * a[ox + r * p + k]
            a[ox + r * p + i] = acc / a[oL + i * p + i]


@numba.njit(cache=True, inline="always")
def _par_offsets(n, m, p):  # pragma: no cover - compiled
    """Offsets of A, B, C, D, Q, R, S, u0, y0, K_f, K_p, P_f, Σ, P_p in the parameter vector."""
    return block_starts(_par_sizes(n, m, p))[0]


@numba.njit(cache=True, inline="always")
def _st_offsets(n, m, p):  # pragma: no cover - compiled
    """Offsets of x_p, P_p, x_f, P_f, du, y − y0, e, Σ, P_p Cᵀ, M, K_f, K_p, T, x_next in the
    state vector."""
    return block_starts(_st_sizes(n, m, p))[0]


@numba.njit(cache=True)
def bad_sample(u, y):  # pragma: no cover - compiled
    """0 when every ``u`` is finite and no ``y`` is ±inf (a NaN in ``y`` is a missing
    measurement, which the filters update without); 1 for a NaN or ±inf in ``u``, 2 for a ±inf
    in ``y``. :func:`bad_channel` then names the channel."""
    for j in range(u.shape[0]):
        if not np.isfinite(u[j]):
            return 1
    for i in range(y.shape[0]):
        if np.isinf(y[i]):
            return 2
    return 0


def bad_channel(filt: str, where: str, which: int, u, y, k=None) -> DataError:
    """The DataError for a :func:`bad_sample` code ``which`` (1: ``u``, 2: ``y``) of the sample
    ``u``, ``y`` (row ``k`` of a record, or None for one step), naming the channel."""
    arr = np.asarray(u if which == 1 else y, dtype=np.float64).reshape(-1)
    ch = int(np.flatnonzero(~np.isfinite(arr) if which == 1 else np.isinf(arr))[0])
    name = ("u" if which == 1 else "y") + (f"[{k}, {ch}]" if k is not None else f"[{ch}]")
    want = ("the inputs must be finite" if which == 1 else
            "a measurement must be finite, or NaN for a missing one")
    return DataError(f"{filt}.{where}: {name} is {arr[ch]} ({'input' if which == 1 else 'output'}"
                     f" channel {ch}{'' if k is None else f', sample {k}'}); {want}",
                     hint="fill or interpolate the gap, or drop those samples")


@numba.njit(cache=True, inline="always")
def _kf_innovation(n, m, p, par, st, u, y):  # pragma: no cover - compiled
    """du = u − u0, y − y0, e = y − y0 − C x_p − D du; a missing (NaN) y_i keeps its NaN in
    y − y0 (the mark the gains read) and gets e_i = 0. Returns the number of missing y_i."""
    oA, oB, oC, oD, oQ, oR, oS, ou0, oy0, oKf, oKp, oPs, oSs, oPp = _par_offsets(n, m, p)
    sxp, sPp, sxf, sPf, sdu, syy, se, sSe, sPC, sM, sKf, sKp, sT, sxn = _st_offsets(n, m, p)
    for j in range(m):
        st[sdu + j] = u[j] - par[ou0 + j]
    for i in range(p):
        st[syy + i] = y[i] - par[oy0 + i]
        acc = st[syy + i]
        for j in range(n):
            acc -= par[oC + i * n + j] * st[sxp + j]
        for j in range(m):
            acc -= par[oD + i * m + j] * st[sdu + j]
        st[se + i] = acc
    missing = 0
    for i in range(p):
        if st[syy + i] != st[syy + i]:
            st[se + i] = 0.0
            missing += 1
    return missing


@numba.njit(cache=True, inline="always")
def _drop_missing(yy, oy, p, a, oa, ob, rows, sig, osig):  # pragma: no cover - compiled
    """The update with the measured outputs only, shared by every filter: for each missing y_i
    (NaN at ``yy[oy + i]``), column i of the rows×p blocks of ``a`` at ``oa`` and ``ob`` (the
    same block twice where there is one: P_xy) is zero and Σ's row and column i (the p×p block
    of ``sig`` at ``osig``) those of the identity, so that the gains' column i is zero and the
    other columns are those of the filter with C's (h's) row i and R's row and column i struck
    out (Σ block diagonal). All blocks row-major."""
    for i in range(p):
        if yy[oy + i] == yy[oy + i]:
            continue
        for r in range(rows):
            a[oa + r * p + i] = 0.0
            a[ob + r * p + i] = 0.0
        for j in range(p):
            sig[osig + i * p + j] = 0.0
            sig[osig + j * p + i] = 0.0
        sig[osig + i * p + i] = 1.0


@numba.njit(cache=True, inline="always")
def _mark_missing(yy, oy, p, e, oe, sig, osig):  # pragma: no cover - compiled
    """After the step, shared by every filter: a missing y_i's (NaN at ``yy[oy + i]``)
    innovation (``e[oe + i]``) and Σ's row and column i (the p×p block of ``sig`` at ``osig``)
    are NaN (none was measured)."""
    for i in range(p):
        if yy[oy + i] == yy[oy + i]:
            continue
        e[oe + i] = np.nan
        for j in range(p):
            sig[osig + i * p + j] = np.nan
            sig[osig + j * p + i] = np.nan


@numba.njit(cache=True, inline="always")
def _flat_mul_add(c, oc, a, oa, b, ob, out, oo, rows, cols, inner):  # pragma: no cover
    """``out = C + A B`` on row-major blocks of flat vectors: C and out (rows, cols) at ``oc``,
    ``oo``, A (rows, inner) at ``oa``, B (inner, cols) at ``ob``; each sum from C[i, j] over k
    in order."""
    for i in range(rows):
        for j in range(cols):
            acc = c[oc + i * cols + j]
            for k in range(inner):
                acc += a[oa + i * inner + k] * b[ob + k * cols + j]
            out[oo + i * cols + j] = acc


@numba.njit(cache=True, inline="always")
def _kf_gains(n, m, p, par, st, src, oP):  # pragma: no cover - compiled
    """The time-varying gains: P_p Cᵀ, Σ = R + C P_p Cᵀ (factored), M = S + A P_p Cᵀ,
    K_f = P_p Cᵀ Σ⁻¹, K_p = M Σ⁻¹, with P_p the block of ``src`` at ``oP``, and the missing
    outputs left out (:func:`_drop_missing`). False if Σ is not positive definite."""
    oA, oB, oC, oD, oQ, oR, oS, ou0, oy0, oKf, oKp, oPs, oSs, oPp = _par_offsets(n, m, p)
    sxp, sPp, sxf, sPf, sdu, syy, se, sSe, sPC, sM, sKf, sKp, sT, sxn = _st_offsets(n, m, p)
    for i in range(n):  # P_p Cᵀ
        for j in range(p):
            acc = 0.0
            for k in range(n):
                acc += src[oP + i * n + k] * par[oC + j * n + k]
            st[sPC + i * p + j] = acc
    _flat_mul_add(par, oR, par, oC, st, sPC, st, sSe, p, p, n)  # Σ = R + C (P_p Cᵀ)
    _flat_mul_add(par, oS, par, oA, st, sPC, st, sM, n, p, n)  # M = S + A (P_p Cᵀ)
    _drop_missing(st, syy, p, st, sPC, sM, n, st, sSe)
    if not _flat_cholesky(st, sSe, p):
        return False
    _flat_solve_rows(st, sSe, p, sPC, sKf, n)
    _flat_solve_rows(st, sSe, p, sM, sKp, n)
    return True


@numba.njit(cache=True, inline="always")
def _kf_states(n, m, p, par, st, g, ogf, ogp):  # pragma: no cover - compiled
    """x_f = x_p + K_f e, x_p ← A x_p + B du + K_p e (through x_next); the gains K_f, K_p are
    the blocks of ``g`` at ``ogf``, ``ogp``."""
    oA, oB, oC, oD, oQ, oR, oS, ou0, oy0, oKf, oKp, oPs, oSs, oPp = _par_offsets(n, m, p)
    sxp, sPp, sxf, sPf, sdu, syy, se, sSe, sPC, sM, sKf, sKp, sT, sxn = _st_offsets(n, m, p)
    for i in range(n):
        acc = st[sxp + i]
        for j in range(p):
            acc += g[ogf + i * p + j] * st[se + j]
        st[sxf + i] = acc
    predicted_state(n, m, p, par, oA, oB, g, ogp, st, (sxp, sdu, se, sxn))


@numba.njit(cache=True, inline="always")
def predicted_state(n, m, p, par, oA, oB, g, ogp, st, so):  # pragma: no cover - compiled
    """x_p ← A x_p + B du + K_p e (through x_next) on a packed state vector ``st`` whose x_p, du,
    e, x_next blocks start at ``so``; A, B are the blocks of ``par`` at ``oA``, ``oB``, K_p the
    block of ``g`` at ``ogp`` (row-major; each sum in ascending order). Entries below
    ``FLUSH_BELOW`` are carried as zero (:func:`gripkit.lti.flush_tiny`: a state that decays
    under zero input and zero innovations never reaches the subnormal range)."""
    sxp, sdu, se, sxn = so
    for i in range(n):
        acc = 0.0
        for j in range(n):
            acc += par[oA + i * n + j] * st[sxp + j]
        for j in range(m):
            acc += par[oB + i * m + j] * st[sdu + j]
        for j in range(p):
            acc += g[ogp + i * p + j] * st[se + j]
        st[sxn + i] = acc
    for i in range(n):
        st[sxp + i] = flush_tiny(st[sxn + i])


@numba.njit(cache=True, inline="always")
def _kf_covariances(n, m, p, par, st, src, oP, predict):  # pragma: no cover - compiled
    """P_f = P_p − K_f (P_p Cᵀ)ᵀ with P_p the block of ``src`` at ``oP``; with ``predict``,
    P_p ← Q + A P_p Aᵀ − K_p Mᵀ (symmetric parts; entries below ``FLUSH_BELOW`` carried as
    zero); Σ rebuilt from its Cholesky factor."""
    oA, oB, oC, oD, oQ, oR, oS, ou0, oy0, oKf, oKp, oPs, oSs, oPp = _par_offsets(n, m, p)
    sxp, sPp, sxf, sPf, sdu, syy, se, sSe, sPC, sM, sKf, sKp, sT, sxn = _st_offsets(n, m, p)
    for i in range(n):
        for j in range(n):
            acc = src[oP + i * n + j]
            for k in range(p):
                acc -= st[sKf + i * p + k] * st[sPC + j * p + k]
            st[sPf + i * n + j] = acc
    for i in range(n):
        for j in range(i + 1, n):
            b = 0.5 * (st[sPf + i * n + j] + st[sPf + j * n + i])
            st[sPf + i * n + j] = b
            st[sPf + j * n + i] = b
    if predict:
        _kf_predicted_covariance(n, m, p, par, st)
    for i in range(p):
        for j in range(i + 1):
            acc = 0.0
            for k in range(j + 1):
                acc += st[sSe + i * p + k] * st[sSe + j * p + k]
            st[sSe + i * p + j] = acc
            st[sSe + j * p + i] = acc


@numba.njit(cache=True, inline="always")
def _kf_predicted_covariance(n, m, p, par, st):  # pragma: no cover - compiled
    """P_p ← Q + A P_p Aᵀ − K_p Mᵀ (symmetric part; entries below ``FLUSH_BELOW`` carried as
    zero)."""
    oA, oB, oC, oD, oQ, oR, oS, ou0, oy0, oKf, oKp, oPs, oSs, oPp = _par_offsets(n, m, p)
    sxp, sPp, sxf, sPf, sdu, syy, se, sSe, sPC, sM, sKf, sKp, sT, sxn = _st_offsets(n, m, p)
    for i in range(n):  # T = A P_p
        for j in range(n):
            acc = 0.0
            for k in range(n):
                acc += par[oA + i * n + k] * st[sPp + k * n + j]
            st[sT + i * n + j] = acc
    for i in range(n):
        for j in range(n):
            acc = par[oQ + i * n + j]
            for k in range(n):
                acc += st[sT + i * n + k] * par[oA + j * n + k]
            for k in range(p):
                acc -= st[sKp + i * p + k] * st[sM + j * p + k]
            st[sPp + i * n + j] = flush_tiny(acc)   # P_p decays where Q = 0
    for i in range(n):
        for j in range(i + 1, n):
            a = 0.5 * (st[sPp + i * n + j] + st[sPp + j * n + i])
            st[sPp + i * n + j] = a
            st[sPp + j * n + i] = a


@numba.njit(cache=True)
def kf_step_packed(dims, par, st, u, y):  # pragma: no cover - compiled
    """One Kalman step (module docstring) on the packed buffers; ``dims`` = (n, m, p, steady).
    Returns 0 done, 1 Σ not positive definite (``x_p``, ``P_p`` unchanged), 2 ``u`` or 3 ``y``
    of the wrong length, 4 a NaN or ±inf in ``u``, 5 a ±inf in ``y`` (the filter unchanged).
    Every row sum runs over its index ascending, as :mod:`gripkit.export.c_kalman`'s C step
    does.

    A NaN y_i is a missing measurement: the update uses the other outputs only (C's rows and
    R's rows and columns of the measured ones; none: the time update alone), its innovation and
    Σ's row and column are NaN. The steady-state filter then takes that sample's gains from the
    steady prediction covariance with the measured outputs only (its P stays the steady one)."""
    n, m, p, steady = dims[0], dims[1], dims[2], dims[3]
    if u.shape[0] != m:
        return 2
    if y.shape[0] != p:
        return 3
    bad = bad_sample(u, y)
    if bad:
        return 3 + bad
    oA, oB, oC, oD, oQ, oR, oS, ou0, oy0, oKf, oKp, oPs, oSs, oPp = _par_offsets(n, m, p)
    sxp, sPp, sxf, sPf, sdu, syy, se, sSe, sPC, sM, sKf, sKp, sT, sxn = _st_offsets(n, m, p)
    missing = _kf_innovation(n, m, p, par, st, u, y)
    if missing:
        return _kf_update_missing(n, m, p, par, st, steady)
    if steady:  # fixed gains and covariances
        _kf_states(n, m, p, par, st, par, oKf, oKp)
        for i in range(n * n):
            st[sPf + i] = par[oPs + i]
        for i in range(p * p):
            st[sSe + i] = par[oSs + i]
        return 0
    if not _kf_gains(n, m, p, par, st, st, sPp):
        return 1
    _kf_covariances(n, m, p, par, st, st, sPp, True)  # reads P_p before the states step
    _kf_states(n, m, p, par, st, st, sKf, sKp)
    return 0


@numba.njit(cache=True)
def kf_gains_packed(dims, par, st):  # pragma: no cover - compiled
    """The gains K_f, K_p (blocks of ``st``) that :func:`kf_step_packed` uses at a sample whose
    missing outputs are the NaN of ``st``'s y − y0 block: from the steady P_p (``dims[3]``) or
    ``st``'s own. False if Σ is not positive definite."""
    n, m, p, steady = dims[0], dims[1], dims[2], dims[3]
    oPp = _par_offsets(n, m, p)[13]
    if steady:
        return _kf_gains(n, m, p, par, st, par, oPp)
    return _kf_gains(n, m, p, par, st, st, _st_offsets(n, m, p)[1])


@numba.njit(cache=True, inline="always")
def _kf_update_missing(n, m, p, par, st, steady):  # pragma: no cover - compiled
    """The step of a sample with missing outputs (:func:`kf_step_packed`): gains from P_p (the
    steady one of ``par`` when ``steady``, whose P_p then stays) with the measured outputs only;
    0, or 1 if Σ is not positive definite."""
    oA, oB, oC, oD, oQ, oR, oS, ou0, oy0, oKf, oKp, oPs, oSs, oPp = _par_offsets(n, m, p)
    sxp, sPp, sxf, sPf, sdu, syy, se, sSe, sPC, sM, sKf, sKp, sT, sxn = _st_offsets(n, m, p)
    src, oP = (par, oPp) if steady else (st, sPp)
    if not _kf_gains(n, m, p, par, st, src, oP):
        return 1
    _kf_covariances(n, m, p, par, st, src, oP, not steady)
    _kf_states(n, m, p, par, st, st, sKf, sKp)
    _mark_missing(st, syy, p, st, se, st, sSe)
    return 0


@numba.njit(cache=True)
def kf_run_packed(dims, par, st, U, Y, xs, Ps, es, Ss):  # pragma: no cover - compiled
    """:func:`kf_step_packed` over the rows of U (N, m), Y (N, p); the filtered states, their
    covariances, the innovations and their covariances into xs, Ps, es, Ss. Returns
    (code, k): the first failing sample's code and index, or (0, N)."""
    n, m, p = dims[0], dims[1], dims[2]
    sxp, sPp, sxf, sPf, sdu, syy, se, sSe, sPC, sM, sKf, sKp, sT, sxn = _st_offsets(n, m, p)
    for k in range(U.shape[0]):
        code = kf_step_packed(dims, par, st, U[k], Y[k])
        if code:
            return code, k
        for i in range(n):
            xs[k, i] = st[sxf + i]
            for j in range(n):
                Ps[k, i, j] = st[sPf + i * n + j]
        for i in range(p):
            es[k, i] = st[se + i]
            for j in range(p):
                Ss[k, i, j] = st[sSe + i * p + j]
    return 0, U.shape[0]


#: the families whose model has no noise model at all (y = G u + e)
_OUTPUT_ERROR = ("oe", "pem-oe", "tfest", "step")


def without_innovation_gain(model) -> str:
    """Why ``model`` (whose ``K`` is None) gives the filter no noise model, naming its family:
    an output-error family has none; another (ARX, ARMAX, a subspace model saved without K)
    keeps only its input-output part B/A in the state-space form that the filter uses."""
    family = str(getattr(model, "structure", None) or getattr(model, "method", "") or "linear")
    label = family.upper() if family in ("arx", "armax", "oe") else family
    if family in _OUTPUT_ERROR:
        return f"the {label} model has no noise model (an output-error model: no innovation gain K)"
    return (f"the {label} model carries no innovation gain K in the state-space form that the "
            f"filter uses (that form holds its input-output dynamics only)")


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

    The filter's numbers live in two flat float64 buffers (parameters and state); ``x_pred``,
    ``P_pred``, ``x``, ``P`` are views into the state buffer. :meth:`step` is one call of the
    numba kernel :func:`kf_step_packed`, :meth:`run_arrays` one call of :func:`kf_run_packed`.

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
        A, B, C, D = (np.ascontiguousarray(M, dtype=np.float64) for M in (ss.A, ss.B, ss.C, ss.D))
        n, m, p = A.shape[0], B.shape[1], C.shape[0]
        self.innovation_form = Q is None and R is None
        Q, R, S = self._noise(model, Q, R, S, n, p)
        Kf, Kp, Pp, Pf = self._steady_gains(A, C, Q, R, S, n, p)
        Sss = C @ Pp @ C.T + R
        u0 = np.asarray(model.u_offset, dtype=np.float64).reshape(m)
        y0 = np.asarray(model.y_offset, dtype=np.float64).reshape(p)
        self._dims = np.array([n, m, p, int(self.steady_state)], dtype=np.int64)
        lp, _ = _par_layout(n, m, p)
        self._par = np.concatenate([M.ravel() for M in (A, B, C, D, Q, R, S, u0, y0, Kf, Kp, Pf,
                                                        Sss, Pp)])
        ls, size = _st_layout(n, m, p)
        self._st = np.zeros(size)

        def block(buf, lay, key, *shape):
            return buf[lay[key]:lay[key] + int(np.prod(shape))].reshape(shape)

        (self.A, self.B, self.C, self.D, self.Q, self.R, self.S, self.filter_gain,
         self.predictor_gain, self.P_steady, self.innovation_cov_steady) = (
            block(self._par, lp, k, *sh) for k, sh in (
                ("A", (n, n)), ("B", (n, m)), ("C", (p, n)), ("D", (p, m)), ("Q", (n, n)),
                ("R", (p, p)), ("S", (n, p)), ("Kf", (n, p)), ("Kp", (n, p)), ("Pf", (n, n)),
                ("Sig", (p, p))))
        for M in (self.A, self.B, self.C, self.D, self.Q, self.R, self.S, self.filter_gain,
                  self.predictor_gain, self.P_steady, self.innovation_cov_steady):
            M.flags.writeable = False
        self.P_steady_pred = Pp
        self._u0, self._y0 = u0, y0
        self.x_pred, self.P_pred = block(self._st, ls, "xp", n), block(self._st, ls, "Pp", n, n)
        self.x, self.P = block(self._st, ls, "xf", n), block(self._st, ls, "Pf", n, n)
        self._e = block(self._st, ls, "e", p)
        self.x_pred[:] = 0.0 if x0 is None else np.asarray(x0, dtype=np.float64).reshape(n)
        self.P_pred[:] = Pp if P0 is None else np.asarray(P0, dtype=np.float64).reshape(n, n)
        self._x_out, self._P_out = self.x.view(), self.P.view()
        self._x_out.flags.writeable = False
        self._P_out.flags.writeable = False

    @staticmethod
    def _noise(model, Q, R, S, n, p):
        """(Q, R, S) as given, or the innovation form's ``K Λ Kᵀ, Λ, K Λ``."""
        if Q is None and R is None:
            if getattr(model, "K", None) is None:
                raise ModelError(f"KalmanFilter: {without_innovation_gain(model)}; give the "
                                 f"noise covariances Q and R",
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

    def _steady_gains(self, A, C, Q, R, S, n, p):
        """Fixed gains K_f, K_p, the predictor's Riccati solution and its filtered form."""
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
        Kf = np.linalg.solve(Se, C @ Pp).T
        Kp = np.linalg.solve(Se, (A @ Pp @ C.T + S).T).T
        return Kf, Kp, Pp, Pp - Kf @ C @ Pp

    def _fail(self, code, what, u=None, y=None, k=None):
        if code in (4, 5):
            raise bad_channel("KalmanFilter", what, code - 3, u, y, k)
        if code == 1:
            raise ModelError(f"KalmanFilter.{what}: the innovation covariance C P Cᵀ + R is not "
                             "positive definite", hint="check R and the filter's covariance P")
        n_u, n_y = int(self._dims[1]), int(self._dims[2])
        arg, want = ("u", n_u) if code == 2 else ("y", n_y)
        raise DataError(f"KalmanFilter.{what}: {arg} must hold {want} value(s) per sample (the "
                        f"model's {'inputs' if code == 2 else 'outputs'} in order)")

    def step(self, u, y, *, copy: bool = True):
        """One sample (SI, the model's order, offsets not removed): ``(x[t|t], P[t|t])``.

        ``u`` (m,) and ``y`` (p,) 1-D arrays go straight to the kernel (anything else is
        converted to float64 first). ``copy=False`` returns read-only views of the filter's own
        buffers
        instead of copies: nothing is allocated, and the next step overwrites them."""
        if type(u) is not np.ndarray or u.ndim != 1:
            u = np.ascontiguousarray(u, dtype=np.float64).reshape(-1)
        if type(y) is not np.ndarray or y.ndim != 1:
            y = np.ascontiguousarray(y, dtype=np.float64).reshape(-1)
        code = kf_step_packed(self._dims, self._par, self._st, u, y)
        if code:
            self._fail(code, "step", u, y)
        if copy:
            return self.x.copy(), self.P.copy()
        return self._x_out, self._P_out

    def gains_measuring(self, measured) -> tuple[np.ndarray, np.ndarray]:
        """``(K_f, K_p)`` (n×p each) that the next :meth:`step` uses when only the outputs
        ``measured`` (p booleans) are measured, the others missing (NaN): the gains of C's rows
        and R's rows and columns of the measured outputs, from the steady prediction covariance
        (a steady-state filter) or the current one, with zero columns for the missing outputs
        (:func:`kf_step_packed`'s own numbers). A ModelError if that Σ is not positive
        definite."""
        n, m, p = (int(v) for v in self._dims[:3])
        ok = np.asarray(measured, dtype=bool).reshape(-1)
        if ok.shape != (p,):
            raise ArgumentError(f"measured: expected {p} booleans (one per output), found "
                                f"shape {ok.shape}")
        lay, _ = _st_layout(n, m, p)
        st = self._st.copy()
        st[lay["yy"]:lay["yy"] + p] = np.where(ok, 0.0, np.nan)
        if not kf_gains_packed(self._dims, self._par, st):
            self._fail(1, "gains_measuring")
        Kf, Kp = (st[lay[k]:lay[k] + n * p].reshape(n, p).copy() for k in ("Kf", "Kp"))
        return Kf, Kp

    @property
    def innovation(self) -> np.ndarray:
        """The last step's innovation ``e`` (p,) (a copy)."""
        return self._e.copy()

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
        """Filter inputs ``u`` (N, m) and outputs ``y`` (N, p), SI, offsets not removed: one
        call of the numba kernel :func:`kf_run_packed`. A NaN in ``y`` is a missing measurement
        (:func:`kf_step_packed`; one DataWarning gives their count and the first, and
        ``missing`` marks them); a NaN or ±inf in ``u``, or a ±inf in ``y``, is a DataError
        naming the sample and the channel."""
        n, m, p = (int(v) for v in self._dims[:3])
        u = np.ascontiguousarray(np.asarray(u, dtype=np.float64).reshape(-1, m) if m == 1 else
                                 np.atleast_2d(np.asarray(u, dtype=np.float64)))
        y = np.ascontiguousarray(np.asarray(y, dtype=np.float64).reshape(-1, p) if p == 1 else
                                 np.atleast_2d(np.asarray(y, dtype=np.float64)))
        if u.ndim != 2 or u.shape[1] != m or y.ndim != 2 or y.shape[1] != p \
                or u.shape[0] != y.shape[0]:
            raise DataError(f"KalmanFilter.run_arrays: expected u (N, {m}) and y (N, {p}) with "
                            f"the same N, found {u.shape} and {y.shape}")
        N = u.shape[0]
        xs, Ps = np.empty((N, n)), np.empty((N, n, n))
        es, Ss = np.empty((N, p)), np.empty((N, p, p))
        code, k = kf_run_packed(self._dims, self._par, self._st, u, y, xs, Ps, es, Ss)
        if code:
            self._fail(code, f"run (sample {k})", *((u[k], y[k], k) if code > 3 else ()))
        missing = np.isnan(y)
        warn_missing("KalmanFilter.run_arrays", missing)
        return KalmanRun(xs, Ps, es, Ss, missing)
