"""Prediction-error refinement of discrete MIMO state-space models (ssest-like).

Predictor of the innovation form (``K = 0``: output error)::

    ŷ[t] = C x[t] + D u[t],   e[t] = y[t] − ŷ[t],   x[t+1] = A x[t] + B u[t] + K e[t],   x[0] = x0.

Criterion: ``V = Σ_t e[t]ᵀ Λ⁻¹ e[t]`` with Λ the innovation covariance of the starting model (fixed,
so that outputs in different units weigh alike). Parameters: a state-space model is defined up
to a similarity transformation, whose tangent at the current model, ``(T A T⁻¹, T B, C T⁻¹, T K)``
at T = I + X, is ``(XA − AX, XB, −CX, XK)``. As in the data-driven local coordinates of McKelvey,
Helmersson & Ribarits (2004) only d = nm + pn (+ pm) (+ np) directions complementing that orbit
are free; here they are d *entries* of (A, B, C[, D][, K]), the ones whose unit directions
complement the orbit best (QR with column pivoting of a basis of its orthogonal complement),
re-chosen at every iterate; the other entries stay where they are during the step. Unit
directions make the sensitivity equations sparse (cheap). x0 is estimated too.

Jacobians are exact, from the sensitivity equations (numba kernels, parallel over the
directions), for each direction θ_q with matrix tangents (dA, dB, dC, dD, dK)::

    ∂ŷ[t] = C s[t] + dC x[t] + dD u[t],
    s[t+1] = A s[t] + dA x[t] + dB u[t] + dK e[t] − K ∂ŷ[t]
           = (A − KC) s[t] + (dA − K dC) x[t] + (dB − K dD) u[t] + dK e[t],
    s[0] = 0 (e_i for x0_i).

Levenberg-Marquardt steps re-centre the coordinates after every accepted step and reject any step
that makes A (or the predictor A − KC) unstable, so stability is kept. The covariance of the
directions is ``σ² (JᵀJ)⁻¹`` (J of the whitened errors, σ² = V/(Np − d − n)); it is carried as the
:class:`gripkit.lti.Uncertainty` of the model's (A, B, C, D) with the directions as tangents, from
which poles and frequency responses get their σ by linearisation.
"""

from __future__ import annotations

import numba
import numpy as np
import scipy.linalg as sla

from ...errors import DataError, IdentificationError
from ...progress import status, track
from ...lti import StateSpace, Uncertainty, affine_row, flush_tiny
from .blocked_gram import add_rows, carried_states, carry, row_product, start_sums
from ..checks import io_records
from ..model_protocol import check_sample_time
from .linear_model import LinearModel, as_io_matrix, estimate_x0, fit_per_output, free_run
from .validation import records_fit

__all__ = ["pem", "pem_records", "PEM_FORMS", "predictor_x0"]

PEM_FORMS = ("oe", "innovation")
_WARM_START_SAMPLES = 20000
# A decrease of the whitened criterion below 0.01 means the last step moved the parameters by less
# than 0.1σ (jointly, ΔV ≈ δᵀ Σ⁻¹ δ): further iterations cannot change the answer.
_NEGLIGIBLE_DROP = 0.01


@numba.njit(cache=True)
def predict_errors(A, B, C, D, K, x0, u, y, e):  # pragma: no cover - compiled
    """Prediction errors e (N, p) of the predictor of the module docstring."""
    _predict_states(A, B, C, D, K, x0, u, y, e, np.empty((0, A.shape[0])))


@numba.njit(cache=True)
def _predict_states(A, B, C, D, K, x0, u, y, e, X):  # pragma: no cover - compiled
    """Prediction errors e (N, p) and, when X has N rows, predictor states X (N, n) (X[t] =
    x[t])."""
    n, p = A.shape[0], C.shape[0]
    store = X.shape[0] == u.shape[0]
    x = x0.copy()
    xn = np.empty(n)
    for t in range(u.shape[0]):
        if store:
            for r in range(n):
                X[t, r] = x[r]
        for i in range(p):
            e[t, i] = y[t, i] - affine_row(C, i, x, D, u, t)
        for r in range(n):
            acc = affine_row(A, r, x, B, u, t)
            for j in range(p):
                acc += K[r, j] * e[t, j]
            xn[r] = acc
        for r in range(n):
            x[r] = xn[r]


@numba.njit(cache=True, parallel=True)
def _sensitivities(Abar, C, F, G, S0, Z, J):  # pragma: no cover - compiled
    """Column q of J (N·p, nd), rows t·p + i: ∂ŷ_i[t]/∂θ_q from

        s[t+1] = Ā s[t] + F_q z[t],   ∂ŷ[t] = C s[t] + G_q z[t][:n+m],   s[0] = S0[q],

    z[t] = [x[t]; u[t]; e[t]] (Z, shape (N, n + m + p)), Ā = A − KC. Directions run in parallel."""
    n = Abar.shape[0]
    p = C.shape[0]
    for q in numba.prange(F.shape[0]):
        s = S0[q].copy()
        sn = np.empty(n)
        Gq, Fq = G[q], F[q]
        for t in range(Z.shape[0]):
            for i in range(p):
                J[t * p + i, q] = affine_row(C, i, s, Gq, Z, t)
            for r in range(n):
                sn[r] = affine_row(Abar, r, s, Fq, Z, t)
            for r in range(n):
                s[r] = flush_tiny(sn[r])  # x0 directions decay freely: no subnormals carried


#: samples per block of :func:`_sensitivity_gram` (its rows of J go to BLAS in one product)
_GRAM_BLOCK = 256


@numba.njit(cache=True)
def _sensitivity_gram(Abar, C, K, entries, n_x0, X, U, E, H, g):  # pragma: no cover - compiled
    """H = JᵀJ and g = Jᵀe for unit directions, without forming J: entry (kind, r, c) of A, B, C, D
    or K (kind 0 … 4) forces s with e_r x_c, e_r u_c, −K[:, r] x_c, −K[:, r] u_c or e_r e_c, and
    the C, D entries add x_c, u_c to output r; then ``n_x0`` directions of x0 (s[0] = e_i). The
    sensitivities of all d + n_x0 directions advance together as the columns of one n × Q state
    matrix S (the inner loops over its contiguous columns), and blocks of
    :data:`_GRAM_BLOCK` samples' rows of J are added to H and g by one BLAS product each.
    :func:`_predict_sensitivity` forms the same J for any tangents (the tests compare them).
    Returns the final S; its entries below 1e-280 are flushed to zero as it is carried
    (:func:`~gripkit.sysid.linear.blocked_gram.carry`: the x0 directions are free responses of Ā and
    decay into the subnormal range otherwise; H and g are unchanged by it)."""
    n = Abar.shape[0]
    p = C.shape[0]
    d = entries.shape[0]
    Q = d + n_x0
    S, Sn = carried_states(n, Q, d, n_x0)
    rows, eb = start_sums(_GRAM_BLOCK * p, Q, H, g)
    fill = 0
    for t in range(X.shape[0]):
        for i in range(p):
            row_product(C, i, S, rows[fill])
            eb[fill] = E[t, i]
            fill += 1
        for q in range(d):  # C and D entries add x_c, u_c to output r
            kind, r, c = entries[q, 0], entries[q, 1], entries[q, 2]
            if kind == 2:
                rows[fill - p + r, q] += X[t, c]
            elif kind == 3:
                rows[fill - p + r, q] += U[t, c]
        if fill == rows.shape[0] or t == X.shape[0] - 1:
            add_rows(rows, eb, fill, H, g)
            fill = 0
        for i in range(n):
            row_product(Abar, i, S, Sn[i])
        for q in range(d):
            kind, r, c = entries[q, 0], entries[q, 1], entries[q, 2]
            if kind == 0:
                Sn[r, q] += X[t, c]
            elif kind == 1:
                Sn[r, q] += U[t, c]
            elif kind == 4:
                Sn[r, q] += E[t, c]
            elif kind == 2:
                for i in range(n):
                    Sn[i, q] -= K[i, r] * X[t, c]
            elif kind == 3:
                for i in range(n):
                    Sn[i, q] -= K[i, r] * U[t, c]
        carry(Sn, S)
    return S


def _gauss_newton_terms(A, B, C, D, K, x0, u, y, entries):
    """Prediction errors e (N, p), H = JᵀJ and g = Jᵀe for the unit directions ``entries`` of
    :func:`_directions` and the n entries of x0 (J of :func:`_predict_sensitivity`)."""
    N, p = y.shape
    n = A.shape[0]
    e = np.empty((N, p))
    X = np.empty((N, n))
    _predict_states(A, B, C, D, K, x0, u, y, e, X)
    Q = entries.shape[0] + n
    H, g = np.empty((Q, Q)), np.empty(Q)
    _sensitivity_gram(np.ascontiguousarray(A - K @ C), np.ascontiguousarray(C),
                      np.ascontiguousarray(K),
                      entries, n, X, np.ascontiguousarray(u), e, H, g)
    return e, H, g


def _predict_sensitivity(A, B, C, D, K, dA, dB, dC, dD, dK, x0, u, y):
    """Prediction errors e (N, p) and J (N·p, d + n), Fortran order, = ∂ŷ/∂θ: d model directions
    with tangents dA (d, n, n), dB, dC, dD, dK, then the n entries of x0 (module docstring)."""
    N, p = y.shape
    n, m = A.shape[0], B.shape[1]
    d = dA.shape[0]
    e = np.empty((N, p))
    X = np.empty((N, n))
    _predict_states(A, B, C, D, K, x0, u, y, e, X)
    F = np.zeros((d + n, n, n + m + p))
    F[:d, :, :n] = dA - np.einsum("rj,qjk->qrk", K, dC)
    F[:d, :, n:n + m] = dB - np.einsum("rj,qjk->qrk", K, dD)
    F[:d, :, n + m:] = dK
    G = np.zeros((d + n, p, n + m))
    G[:d, :, :n] = dC
    G[:d, :, n:] = dD
    S0 = np.zeros((d + n, n))
    S0[d:] = np.eye(n)
    J = np.empty((N * p, d + n), order="F")
    _sensitivities(np.ascontiguousarray(A - K @ C), np.ascontiguousarray(C), F, G, S0,
                   np.hstack([X, u, e]), J)
    return e, J


def _directions(A, B, C, D, K, feedthrough: bool, innovation: bool):
    """The d free entries at the current model (d = the dimension of the orthogonal complement of
    the similarity orbit), chosen so that they complement the orbit best, as unit matrix tangents
    (dA, dB, dC, dD, dK), each with a leading axis of d, and their (kind, row, column), kind 0 … 4
    for A, B, C, D, K."""
    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    blocks = [n * n, n * m, p * n, p * m if feedthrough else 0, n * p if innovation else 0]
    T = np.empty((sum(blocks), n * n))
    for a in range(n):
        for b in range(n):
            X = np.zeros((n, n))
            X[a, b] = 1.0
            parts = [X @ A - A @ X, X @ B, -C @ X]
            if feedthrough:
                parts.append(np.zeros((p, m)))
            if innovation:
                parts.append(X @ K)
            T[:, a * n + b] = np.concatenate([q.ravel() for q in parts])
    U, sv, _ = np.linalg.svd(T, full_matrices=True)
    rank = int(np.sum(sv > 1e-10 * max(sv[0], 1e-300))) if sv.size else 0
    Qp = U[:, rank:]
    d = Qp.shape[1]
    # the d entries whose unit directions best complement the orbit (pivoted QR of Qpᵀ): moving
    # only them reaches every neighbouring system, with sparse tangents (cheap sensitivities)
    piv = sla.qr(Qp.T, pivoting=True, mode="r")[1][:d]
    shapes = [(n, n), (n, m), (p, n), (p, m), (n, p)]
    starts = np.cumsum([0] + blocks)
    out = [np.zeros((d,) + sh) for sh in shapes]
    entries = np.empty((d, 3), dtype=np.int64)
    for q, g in enumerate(np.sort(piv)):
        kind = int(np.searchsorted(starts, g, side="right") - 1)
        r, c = divmod(int(g - starts[kind]), shapes[kind][1])
        out[kind][q, r, c] = 1.0
        entries[q] = (kind, r, c)
    return (*out, entries)


def _proposal(H, hd, g, lam, directions, system, innovation: bool):
    """One damped Gauss-Newton proposal of the Levenberg-Marquardt loops (one record and several):
    δ from ``(H + λ diag H) δ = g``, the system moved by its first d entries along
    ``directions`` (dA, dB, dC, dD, dK); ``(None, δ)`` when the solve fails or the moved A (or,
    in innovation form, A − K C) leaves the stable set, else ``((A, B, C, D, K) moved, δ)``."""
    try:
        delta = np.linalg.solve(H + lam * np.diag(hd), g)
    except np.linalg.LinAlgError:
        return None, None
    dA, dB, dC, dD, dK = directions
    A, B, C, D, K = system
    th = delta[:dA.shape[0]]
    An, Cn, Kn = (A + np.tensordot(th, dA, 1), C + np.tensordot(th, dC, 1),
                  K + np.tensordot(th, dK, 1))
    if _radius(An) >= 1.0 or (innovation and _radius(An - Kn @ Cn) >= 1.0):
        return None, delta
    return (An, B + np.tensordot(th, dB, 1), Cn, D + np.tensordot(th, dD, 1), Kn), delta


def _radius(A):
    return float(np.max(np.abs(np.linalg.eigvals(A)))) if A.shape[0] else 0.0


def _lm_loop(system, x0, terms, loss, shifted, feedthrough, innovation, max_iterations, tol,
             progress):
    """The Levenberg-Marquardt loop of one record and of several: ``system`` (A, B, C, D, K)
    and the initial state(s) ``x0``; ``terms(system, x0, entries) -> (errors, H, g)``,
    ``loss(system, x0) -> V``, ``shifted(x0, δ_x0)`` the initial state(s) moved by the entries
    of δ after the system's d. Re-centres the local coordinates after every accepted step and
    rejects steps that leave the stable set. Returns ``(A, B, C, D, K, x0, V, iterations,
    converged, at_final)``."""
    A, B, C, D, K = system
    Vc = loss(system, x0)
    lam, it, converged = 1e-3, 0, False
    for it in track(range(1, max_iterations + 1), total=max_iterations,
                    description=progress or "", enabled=progress is not None):
        dA, dB, dC, dD, dK, ent = _directions(A, B, C, D, K, feedthrough, innovation)
        d = dA.shape[0]
        e, H, g = terms((A, B, C, D, K), x0, ent)
        hd = np.maximum(np.diag(H), 1e-300)
        improved, rel, drop = False, 0.0, 0.0
        for _ in range(30):
            moved, delta = _proposal(H, hd, g, lam, (dA, dB, dC, dD, dK), (A, B, C, D, K),
                                     innovation)
            if moved is None:
                lam *= 10
                continue
            x0n = shifted(x0, delta[d:])
            Vn = loss(moved, x0n)
            if np.isfinite(Vn) and Vn < Vc:
                improved, rel, drop = True, (Vc - Vn) / max(Vc, 1e-300), Vc - Vn
                (A, B, C, D, K), x0, Vc = moved, x0n, Vn
                lam = max(lam / 5, 1e-12)
                break
            lam *= 10
        if not improved or rel < tol:
            converged = True
            break
        if drop < _NEGLIGIBLE_DROP:  # the step moved θ by ≪ 1σ: J before it serves at the optimum
            converged, improved = True, False
            break
    # H at (or ≪ 1σ from) the end
    at_final = (H, (dA, dB, dC, dD, dK), e) if not improved else None
    return A, B, C, D, K, x0, Vc, it, converged, at_final


def _levenberg_marquardt(A, B, C, D, K, x0, u, yw, feedthrough, innovation, max_iterations, tol,
                         progress: str | None = None):
    """:func:`_lm_loop` on the whitened prediction errors of one record; ``progress``: the
    description of a progress bar of the iterations on stderr (:func:`gripkit.progress.track`),
    None for none."""

    def loss(system, x):
        e = np.empty(yw.shape)
        predict_errors(*system, x, u, yw, e)
        return float(np.sum(e * e))

    return _lm_loop((A, B, C, D, K), x0,
                    lambda system, x, ent: _gauss_newton_terms(*system, x, u, yw, ent), loss,
                    lambda x, dx: x + dx, feedthrough, innovation, max_iterations, tol, progress)


def _start_info(model) -> dict:
    """The start's ``info`` without what describes the start's σ alone (``covariance``: its
    bootstrap, ``sigma``: that it has none): the refined model carries PEM's covariance."""
    return {k: v for k, v in model.info.items() if k not in ("covariance", "sigma")}


def pem(model: LinearModel, data=None, *, u=None, y=None, form: str = "innovation",
        feedthrough: bool | None = None,
        max_iterations: int = 50, tol: float = 1e-7, progress: bool = False) -> LinearModel:
    """Refine a discrete state-space model by prediction-error minimisation.

    Parameters
    ----------
    model
        A :class:`LinearModel` with a discrete ``StateSpace`` (e.g. from
        :func:`gripkit.sysid.n4sid`).
    data
        A :class:`~gripkit.signals.Trajectory` with the model's input and output columns (offsets
        removed as recorded in the model), or give ``u`` (N, m) and ``y`` (N, p) in deviation units.
    form
        ``'innovation'`` (estimate K too; needs the model's K as a start) or ``'oe'`` (K = 0).
    feedthrough
        Estimate D (default: when the starting model has a non-zero D).
    max_iterations, tol
        Levenberg-Marquardt iterations and the relative decrease of V that stops them (they also
        stop when a step lowers the whitened V by less than 0.01, a move of less than 0.1σ). Records
        longer than 20 000 samples are first fitted on their first 20 000 samples, then polished
        on the whole record (the same optimum, a fraction of the full-length Jacobians).
    progress
        A progress bar of the iterations on stderr (:func:`gripkit.progress.track`: rich in a
        terminal, a line per 10 % of ``max_iterations`` otherwise) and a closing line saying
        whether PEM converged; a Python call is silent by default.

    Returns
    -------
    LinearModel
        Structure ``'pem-oe'`` or ``'pem-innovation'``; ``.system`` carries the covariance of the
        identifiable directions (σ of poles: ``system.pole_covariance()``; of the frequency
        response: ``system.bode(w)``).
    """
    if form not in PEM_FORMS:
        raise DataError(f"form: expected 'oe' or 'innovation', found {form!r}")
    if (not isinstance(model, LinearModel) or not isinstance(model.system, StateSpace)
            or not model.system.is_discrete):
        raise DataError("model: expected a discrete state-space LinearModel (e.g. from "
                        "gripkit.sysid.n4sid)")
    ss = model.system
    u, y = _pem_data(model, data, u, y)
    innovation = form == "innovation"
    feedthrough = bool(np.any(ss.D != 0)) if feedthrough is None else bool(feedthrough)
    A, B, C, D, K, x0 = _pem_start(model, u, y, feedthrough, innovation)
    N = u.shape[0]
    W, Winv = _output_whitening(A, B, C, D, K, x0, u, y)
    yw = np.ascontiguousarray(y @ W.T)
    C, D, K = W @ C, W @ D, K @ Winv
    e = np.empty((N, ss.n_outputs))
    predict_errors(A, B, C, D, K, x0, u, yw, e)
    V0 = float(np.sum(e * e))
    it_warm = 0
    label = f"PEM ({form} form)"
    if N > _WARM_START_SAMPLES:  # converge on the first samples, then polish on all of them
        A, B, C, D, K, x0, _, it_warm, _, _ = _levenberg_marquardt(
            A, B, C, D, K, x0, u[:_WARM_START_SAMPLES], yw[:_WARM_START_SAMPLES], feedthrough,
            innovation,
            max_iterations, tol,
            f"{label}, first {_WARM_START_SAMPLES} samples" if progress else None)
    A, B, C, D, K, x0, Vc, it, converged, at_final = _levenberg_marquardt(
        A, B, C, D, K, x0, u, yw, feedthrough, innovation, max_iterations, tol,
        label if progress else None)
    if progress:
        status(f"{label}: {'converged' if converged else 'NOT converged'} after {it} iteration(s) "
               f"of at most {max_iterations}, loss {V0 / N:.4g} -> {Vc / N:.4g} per sample")
    cov, (dA, dB, dC, dD), e = _pem_covariance(A, B, C, D, K, x0, u, yw, feedthrough, innovation,
                                               at_final)
    # back to physical output units
    C, D, K = Winv @ C, Winv @ D, K @ W
    dC, dD = np.einsum("ij,qjk->qik", Winv, dC), np.einsum("ij,qjk->qik", Winv, dD)
    e = e @ Winv.T
    unc = Uncertainty(tuple(f"theta{i}" for i in range(dA.shape[0])), cov, (dA, dB, dC, dD))
    sysn = StateSpace(A, B, C, D, **ss._signals(meta={**ss.meta, "refined_by": f"pem-{form}"}),
                      states=ss.states,
                      state_units=ss.state_units, uncertainty=unc)
    info = {**_start_info(model), "pem": {"form": form, "iterations": it_warm + it,
                                          "iterations_warm_start": it_warm,
                                          "converged": converged, "loss_start": V0 / N,
                                          "loss": Vc / N, "parameters": dA.shape[0],
                                          "feedthrough": feedthrough}}
    return model.replace(system=sysn, structure=f"pem-{form}", K=K if innovation else None, x0=x0,
                         noise_covariance=e.T @ e / N,
                         fit_percent=_free_run_fit(A, B, C, D, u, y),
                         n_samples=N, info=info)


def _free_run_fit(A, B, C, D, u, y) -> list[float]:
    """The fit of :meth:`LinearModel.compare` (issue 23): the free run from the initial state
    estimated by least squares for that free run, not the predictor's x0 (in innovation form the
    predictor's x0 fits the one-step error and can leave the free run far off)."""
    return fit_per_output(y, free_run(A, B, C, D, u, estimate_x0(A, B, C, D, u, y)))


def _pem_data(model: LinearModel, data, u, y) -> tuple[np.ndarray, np.ndarray]:
    """Input (N, m) and output (N, p) in deviation units, from a Trajectory (its columns by the
    model's names, offsets removed, sampled as the model) or from ``u`` and ``y``."""
    ss = model.system
    if data is not None:
        dt = data.require_uniform(why="PEM refinement")
        check_sample_time(dt, ss.dt)
        u = model._columns(data, model.inputs, model.u_offset, "input")
        y = model._columns(data, model.outputs, model.y_offset, "output")
    u = as_io_matrix(u, "input u")
    y = as_io_matrix(y, "output y", u.shape[0])
    m, p = ss.n_inputs, ss.n_outputs
    if u.shape[1] != m or y.shape[1] != p:
        raise DataError(f"data: the model has {m} input(s) and {p} output(s), the data "
                        f"{u.shape[1]} and {y.shape[1]}")
    return u, y


def _pem_start(model: LinearModel, u, y, feedthrough: bool, innovation: bool):
    """Starting (A, B, C, D, K, x0): the model's own, with D = 0 unless estimated and K = 0 in
    output-error form or when the starting predictor A − K C is unstable."""
    ss = model.system
    n, m, p = ss.n_states, ss.n_inputs, ss.n_outputs
    A, B, C = ss.A.copy(), ss.B.copy(), ss.C.copy()
    D = ss.D.copy() if feedthrough else np.zeros((p, m))
    K = (model.K.copy() if model.K is not None
         else np.zeros((n, p))) if innovation else np.zeros((n, p))
    if innovation and _radius(A - K @ C) >= 1.0:
        K = np.zeros((n, p))
    x0 = np.zeros(n) if model.x0 is None else np.array(model.x0, dtype=np.float64)
    return A, B, C, D, K, x0


def _output_whitening(A, B, C, D, K, x0, u, y) -> tuple[np.ndarray, np.ndarray]:
    """W = Λ^{-1/2} and W⁻¹ for the starting model's prediction-error covariance Λ: the outputs
    are whitened once (ỹ = W y, C̃ = W C, D̃ = W D, K̃ = K W⁻¹), so that V = Σ ẽᵀẽ."""
    e = np.empty(y.shape)
    predict_errors(A, B, C, D, K, x0, u, y, e)
    w, V = np.linalg.eigh(e.T @ e / u.shape[0])
    if w.min() <= 0:
        raise IdentificationError("pem: the starting model predicts an output exactly (zero "
                                  "error variance)")
    return (V / np.sqrt(w)) @ V.T, (V * np.sqrt(w)) @ V.T


def _pem_covariance(A, B, C, D, K, x0, u, yw, feedthrough: bool, innovation: bool, at_final):
    """Covariance of the identifiable parameter directions at the optimum, σ²·(JᵀJ)⁻¹ with σ²
    from the whitened errors over N·p − d − n degrees of freedom, the directions (dA, dB, dC,
    dD) and the whitened prediction errors."""
    if at_final is not None:
        H, (dA, dB, dC, dD, dK), e = at_final
    else:
        dA, dB, dC, dD, dK, ent = _directions(A, B, C, D, K, feedthrough, innovation)
        e, H, _ = _gauss_newton_terms(A, B, C, D, K, x0, u, yw, ent)
    N, p = yw.shape
    n, d = A.shape[0], dA.shape[0]
    dof = N * p - d - n
    if dof <= 0:
        raise DataError(f"pem: {N} samples of {p} output(s) cannot determine {d + n} parameters",
                        hint="use a longer record or a lower order")
    s2 = float(np.sum(e * e)) / dof
    singular = IdentificationError(
        "pem: the Jacobian is singular at the optimum: the data do not determine the model (a "
        "non-minimal order or a poorly exciting input)",
        hint="lower the order or excite the system more richly")
    try:
        cov_full = s2 * np.linalg.inv(H)
    except np.linalg.LinAlgError:
        raise singular from None
    cov = 0.5 * (cov_full[:d, :d] + cov_full[:d, :d].T)
    # JᵀJ is positive semi-definite; an inverse that is not (rounding in an ill-conditioned JᵀJ,
    # beyond 1/ε) means some directions are not determined, and no σ can be given for them
    w = np.linalg.eigvalsh(cov) if d else np.zeros(0)
    if w.size and w.min() < -1e-9 * max(w.max(), 0.0):
        raise singular
    return cov, (dA, dB, dC, dD), e


def predictor_x0(A, B, C, D, K, u, y) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares initial state of the predictor ``x̂⁺ = A x̂ + B u + K e``,
    ``e = y − C x̂ − D u`` (K = 0: the free run) over the whole record, and its prediction
    errors e (N, p).

    e is affine in x0: ``e(x0) = e(0) − O x0`` with ``O[t] = C (A − KC)^t``, whose column i is
    the negated error of the same predictor started from the unit state e_i with u = 0 and
    y = 0; so x0 = argmin ‖e(0) − O x0‖ (the free-run comparison's
    :func:`~.linear_model.estimate_x0` with A − KC in place of A). Every pass is
    :func:`predict_errors`."""
    A, B, C, D, K = (np.ascontiguousarray(M, dtype=np.float64) for M in (A, B, C, D, K))
    u = np.ascontiguousarray(u, dtype=np.float64)
    y = np.ascontiguousarray(y, dtype=np.float64)
    n, (N, p) = A.shape[0], y.shape
    e = np.empty((N, p))
    predict_errors(A, B, C, D, K, np.zeros(n), u, y, e)
    if n == 0 or N == 0:
        return np.zeros(n), e
    O = np.empty((N, p, n))
    zu, zy, ei = np.zeros_like(u), np.zeros((N, p)), np.empty((N, p))
    for i in range(n):
        x = np.zeros(n)
        x[i] = 1.0
        predict_errors(A, B, C, D, K, x, zu, zy, ei)
        O[:, :, i] = -ei
    x0 = np.linalg.lstsq(O.reshape(-1, n), e.reshape(-1), rcond=None)[0]
    predict_errors(A, B, C, D, K, x0, u, y, e)
    return x0, e


def _records_terms(A, B, C, D, K, x0s, us, ys, entries):
    """:func:`_gauss_newton_terms` of several records: the errors of each, and H, g over the
    shared directions and one x0 block per record (that record's rows only)."""
    n = A.shape[0]
    d = entries.shape[0]
    R = len(us)
    H, g = np.zeros((d + R * n, d + R * n)), np.zeros(d + R * n)
    es = []
    for r, (x0, u, y) in enumerate(zip(x0s, us, ys)):
        e, Hr, gr = _gauss_newton_terms(A, B, C, D, K, x0, u, y, entries)
        own = np.r_[np.arange(d), d + r * n + np.arange(n)]
        H[np.ix_(own, own)] += Hr
        g[own] += gr
        es.append(e)
    return es, H, g


def _records_loss(A, B, C, D, K, x0s, us, ys) -> float:
    """Σ over the records of the squared (whitened) prediction errors."""
    total = 0.0
    for x0, u, y in zip(x0s, us, ys):
        e = np.empty(y.shape)
        predict_errors(A, B, C, D, K, x0, u, y, e)
        total += float(np.sum(e * e))
    return total


def _lm_records(A, B, C, D, K, x0s, us, ys, feedthrough, innovation, max_iterations, tol,
                progress: str | None = None):
    """:func:`_lm_loop` over several records (shared A, B, C, D, K; one x0 each)."""
    n = A.shape[0]
    return _lm_loop((A, B, C, D, K), x0s,
                    lambda system, xs, ent: _records_terms(*system, xs, us, ys, ent),
                    lambda system, xs: _records_loss(*system, xs, us, ys),
                    lambda xs, dx: [x0 + dx[r * n:(r + 1) * n] for r, x0 in enumerate(xs)],
                    feedthrough, innovation, max_iterations, tol, progress)[:9]


def pem_records(model: LinearModel, records, *, form: str = "innovation",
                feedthrough: bool | None = None, max_iterations: int = 50,
                tol: float = 1e-7, progress: bool = False) -> LinearModel:
    """:func:`pem` on several records (``progress``: a progress bar of the iterations on stderr,
    as :func:`pem`): ``records`` a list of ``(u, y)`` pairs in deviation units
    (the model's operating point removed). A, B, C, D (and K in innovation form) are shared; every
    record has its own initial state, estimated with them (started from
    ``model.info['records'][i]['x0']`` where the model has them, as from
    :func:`gripkit.sysid.linear.subspace.n4sid_records`, else the starting model's least-squares x0
    of each record); the prediction errors of all records,
    each predictor started at its own first sample, are minimised together by Levenberg-Marquardt.
    The covariance of the identifiable directions is σ²(JᵀJ)⁻¹ with σ² over Σ N_i·p − d − R·n
    degrees of freedom. ``fit_percent``: the free run of all records (each from its own x0);
    ``info['records']``: each record's free-run fit and x0."""
    if form not in PEM_FORMS:
        raise DataError(f"form: expected 'oe' or 'innovation', found {form!r}")
    if not isinstance(model, LinearModel) or not isinstance(model.system, StateSpace) \
            or not model.system.is_discrete:
        raise DataError("model: expected a discrete state-space LinearModel (e.g. from "
                        "gripkit.sysid.linear.subspace.n4sid_records)")
    data = [_pem_data(model, None, u, y) for u, y in io_records(records)]
    ss = model.system
    innovation = form == "innovation"
    feedthrough = bool(np.any(ss.D != 0)) if feedthrough is None else bool(feedthrough)
    A, B, C, D, K, _ = _pem_start(model, data[0][0], data[0][1], feedthrough, innovation)
    given = model.info.get("records")
    n = ss.n_states
    if given and len(given) == len(data):
        x0s = [np.array(r["x0"], dtype=np.float64) for r in given]
    elif len(data) == 1 and model.x0 is not None:  # as pem() starts
        x0s = [np.array(model.x0, dtype=np.float64)]
    else:  # each record's least-squares initial state under the starting model
        x0s = [estimate_x0(A, B, C, D, u, y) for u, y in data]
    us = [np.ascontiguousarray(u) for u, _ in data]
    es = []
    for x0, u, y in zip(x0s, us, (y for _, y in data)):
        e = np.empty(y.shape)
        predict_errors(A, B, C, D, K, x0, u, y, e)
        es.append(e)
    E = np.vstack(es)
    w, V = np.linalg.eigh(E.T @ E / E.shape[0])
    if w.min() <= 0:
        raise IdentificationError("pem: the starting model predicts an output exactly (zero "
                                  "error variance)")
    W, Winv = (V / np.sqrt(w)) @ V.T, (V * np.sqrt(w)) @ V.T
    yws = [np.ascontiguousarray(y @ W.T) for _, y in data]
    C, D, K = W @ C, W @ D, K @ Winv
    V0 = _records_loss(A, B, C, D, K, x0s, us, yws)
    label = f"PEM over {len(us)} records ({form} form)"
    A, B, C, D, K, x0s, Vc, it, converged = _lm_records(A, B, C, D, K, x0s, us, yws, feedthrough,
                                                       innovation, max_iterations, tol,
                                                       label if progress else None)
    if progress:
        status(f"{label}: {'converged' if converged else 'NOT converged'} after {it} "
               f"iteration(s) of at most {max_iterations}")
    dA, dB, dC, dD, dK, ent = _directions(A, B, C, D, K, feedthrough, innovation)
    es, H, _ = _records_terms(A, B, C, D, K, x0s, us, yws, ent)
    N = sum(u.shape[0] for u in us)
    p, d, R = yws[0].shape[1], dA.shape[0], len(us)
    dof = N * p - d - R * n
    if dof <= 0:
        raise DataError(f"pem: {N} samples of {p} output(s) cannot determine {d + R * n} "
                        f"parameters", hint="use longer records or a lower order")
    try:
        cov = float(sum(np.sum(e * e) for e in es)) / dof * np.linalg.inv(H)[:d, :d]
    except np.linalg.LinAlgError:
        raise IdentificationError("pem: the Jacobian is singular at the optimum: the data do not "
                                  "determine the model", hint="lower the order") from None
    C, D, K = Winv @ C, Winv @ D, K @ W
    dC, dD = np.einsum("ij,qjk->qik", Winv, dC), np.einsum("ij,qjk->qik", Winv, dD)
    E = np.vstack(es) @ Winv.T
    unc = Uncertainty(tuple(f"theta{i}" for i in range(d)), 0.5 * (cov + cov.T), (dA, dB, dC, dD))
    sysn = StateSpace(A, B, C, D, **ss._signals(meta={**ss.meta, "refined_by": f"pem-{form}"}),
                      states=ss.states, state_units=ss.state_units, uncertainty=unc)
    ys = [y for _, y in data]
    # the free run from each record's least-squares x0 (the predictor's x0s serve the loss)
    yhats = [free_run(A, B, C, D, u, estimate_x0(A, B, C, D, u, y)) for u, y in data]
    recs = [{"n_samples": int(y.shape[0]), "fit_percent": fit_per_output(y, yh), "x0": x0}
            for y, yh, x0 in zip(ys, yhats, x0s)]
    info = {**_start_info(model), "records": recs, "n_records": R,
            "pem": {"form": form, "iterations": it, "converged": converged, "loss_start": V0 / N,
                    "loss": Vc / N, "parameters": d, "feedthrough": feedthrough}}
    return model.replace(system=sysn, structure=f"pem-{form}", K=K if innovation else None,
                         x0=x0s[0], noise_covariance=E.T @ E / N,
                         fit_percent=records_fit(ys, yhats).tolist(),
                         n_samples=N, info=info)
