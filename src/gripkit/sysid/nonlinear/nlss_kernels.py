"""Numba kernels of the polynomial nonlinear state-space model (:mod:`.nlss`): the free run, and
the Gauss-Newton sums of its simulation error (sensitivity equations), scalar and allocation-free
in the time loop.

Model (normalised input ũ, states of the model's basis)::

    x[t+1] = A x + B ũ + E ζ(x, ũ),    ŷ[t] = y₀ + C x + D ũ + F η(x, ũ)

ζ and η are monomials given by exponent tables (M, n + m) over the variables v = [x; ũ]. A
parameter direction is a row (kind, r, c) of ``dirs``: kind 0 … 5 for the entry (r, c) of A, B,
C, D, E, F, kind 6 for the output offset y₀ᵣ (c = 0). Its sensitivity s = ∂x/∂θ obeys::

    s[t+1] = (A + E ∂ζ/∂x) s[t] + f_θ[t],     ∂ŷ[t] = (C + F ∂η/∂x) s[t] + g_θ[t]

with f_θ = e_r x_c, e_r ũ_c, e_r ζ_c for A, B, E and g_θ = e_r x_c, e_r ũ_c, e_r η_c for C, D, F
and g_θ = e_r for y₀ᵣ: the form of the linear PEM sensitivities of
:mod:`gripkit.sysid.linear.pem_ss`,
with the Jacobian of the state map in place of A. The initial state of each window gives n more
directions (s = I at the window's first sample). The columns of S advance together (rows contiguous,
:func:`~gripkit.sysid.linear.blocked_gram.row_product`), and blocks of 16 rows of J are added to the
upper triangle of JᵀJ in the kernel itself (:func:`_add_rows`): no BLAS call, so no BLAS
threads, which on a loaded 2-core machine made the Gram sums several times slower than one thread
(docs/performance.md, "Nonlinear state space").
"""

from __future__ import annotations

from collections import namedtuple

import numba
import numpy as np

from ..linear.blocked_gram import row_product

# Named records the kernels take (namedtuples: numba resolves each field at compile time).
#: the model's arrays: A (n, n), B (n, m), C (p, n), D (p, m), E (n, Mζ), F (p, Mη), the output
#: offset y0 (p,) and the exponent tables exz (Mζ, n + m), exe (Mη, n + m)
NLSSArrays = namedtuple("NLSSArrays", "A B C D E F y0 exz exe")
#: the estimation windows: initial states Z (W, n), first samples ``starts`` (W + 1,), the
#: normalised input u (N, m), the output y (N, p) and the per-output weights w (p,)
NLSSWindows = namedtuple("NLSSWindows", "Z starts u y w")
#: the Gauss-Newton sums :func:`window_gram` writes: Htt (P, P), gt (P,), Htz (W, P, n),
#: Hzz (W, n, n), gz (W, n)
NLSSGram = namedtuple("NLSSGram", "Htt gt Htz Hzz gz")

#: a carried sensitivity below this magnitude is set to zero: the initial-state directions decay
#: freely, and once below 1e-154 their products in JᵀJ would be subnormal numbers, whose
#: arithmetic is slow on Intel CPUs; such an entry adds less than 1e-300 to sums of order one,
#: i.e. nothing
_FLUSH = 1e-150
#: rows of J gathered before they are added to JᵀJ together
_ROWS = 16


@numba.njit(cache=True, fastmath={"contract"})
def _add_rows(R, eb, fill, G, g):  # pragma: no cover - compiled
    """G += Σ_k r_k r_kᵀ (upper triangle only) and g += Σ_k r_k e_k for the first ``fill`` rows
    r_k of R (_ROWS, Q): two rows a, a + 1 of G at a time, four rows of R per pass over them, so
    that each r_k[b] loaded serves both (contiguous inner loops, fused multiply-adds; not inlined,
    so that its fastmath flag holds). This is where :func:`window_gram` spends its time (Q²/2
    multiply-adds per row of J against n·Q for the sensitivities)."""
    Q = R.shape[1]
    for k in range(fill):
        rk = R[k]
        ek = eb[k]
        for a in range(Q):
            g[a] += rk[a] * ek
    k4 = fill - fill % 4
    for a in range(0, Q - 1, 2):
        Ga, Gb = G[a], G[a + 1]
        for k in range(0, k4, 4):
            r0, r1, r2, r3 = R[k], R[k + 1], R[k + 2], R[k + 3]
            c0, c1, c2, c3 = r0[a], r1[a], r2[a], r3[a]
            d0, d1, d2, d3 = r0[a + 1], r1[a + 1], r2[a + 1], r3[a + 1]
            Ga[a] += c0 * c0 + c1 * c1 + c2 * c2 + c3 * c3
            for b in range(a + 1, Q):
                x0, x1, x2, x3 = r0[b], r1[b], r2[b], r3[b]
                Ga[b] += c0 * x0 + c1 * x1 + c2 * x2 + c3 * x3
                Gb[b] += d0 * x0 + d1 * x1 + d2 * x2 + d3 * x3
        for k in range(k4, fill):
            rk = R[k]
            ca, cb = rk[a], rk[a + 1]
            Ga[a] += ca * ca
            for b in range(a + 1, Q):
                Ga[b] += ca * rk[b]
                Gb[b] += cb * rk[b]
    if Q % 2:  # the last row of G when Q is odd
        for k in range(fill):
            G[Q - 1, Q - 1] += R[k, Q - 1] * R[k, Q - 1]


@numba.njit(cache=True, inline="always")
def _carry(Sn, S):  # pragma: no cover - compiled
    """S = Sn, entries below :data:`_FLUSH` in magnitude set to zero."""
    for i in range(S.shape[0]):
        for q in range(S.shape[1]):
            v = Sn[i, q]
            S[i, q] = v if abs(v) >= _FLUSH or v != v else 0.0


@numba.njit(cache=True, inline="always")
def monomials(ex, x, u, t, out):  # pragma: no cover - compiled
    """out[k] = Π_i v_i^ex[k, i] with v = [x; u[t]]."""
    n = x.shape[0]
    for k in range(ex.shape[0]):
        v = 1.0
        for i in range(ex.shape[1]):
            base = x[i] if i < n else u[t, i - n]
            for _ in range(ex[k, i]):
                v *= base
        out[k] = v


@numba.njit(cache=True, inline="always")
def _monomial_jacobian(ex, x, u, t, out):  # pragma: no cover - compiled
    """out[k, j] = ∂(Π_i v_i^ex[k, i])/∂x_j for the n states."""
    n = x.shape[0]
    for k in range(ex.shape[0]):
        for j in range(n):
            a = ex[k, j]
            if a == 0:
                out[k, j] = 0.0
                continue
            v = float(a)
            for i in range(ex.shape[1]):
                base = x[i] if i < n else u[t, i - n]
                p = ex[k, i] - 1 if i == j else ex[k, i]
                for _ in range(p):
                    v *= base
            out[k, j] = v


@numba.njit(cache=True, inline="always")
def _equation_row(M0, M1, M2, x, u, t, v, i):  # pragma: no cover - compiled
    """(M0 x + M1 u[t] + M2 v)_i: row i of the state or the output equation."""
    acc = 0.0
    for j in range(M0.shape[1]):
        acc += M0[i, j] * x[j]
    for j in range(M1.shape[1]):
        acc += M1[i, j] * u[t, j]
    for k in range(M2.shape[1]):
        acc += M2[i, k] * v[k]
    return acc


@numba.njit(cache=True, inline="always")
def state_update(A, B, E, x, u, t, zeta, xn):  # pragma: no cover - compiled
    """xn = A x + B u[t] + E ζ."""
    for r in range(A.shape[0]):
        xn[r] = _equation_row(A, B, E, x, u, t, zeta, r)


@numba.njit(cache=True, inline="always")
def output_row(C, D, F, y0, x, u, t, eta, i):  # pragma: no cover - compiled
    """ŷ_i = y₀_i + (C x + D u[t] + F η)_i."""
    return y0[i] + _equation_row(C, D, F, x, u, t, eta, i)


#: the direction kinds (kind, r, c) that enter the output equation directly: C (∂ŷ_r/∂θ = x_c),
#: D (ũ_c), F (η_c) and y₀ (1); and the state equation: A (x_c), B (ũ_c), E (ζ_c), none constant
_OUTPUT_KINDS = (2, 3, 5, 6)
_STATE_KINDS = (0, 1, 4, -1)


@numba.njit(cache=True, inline="always")
def _sensitivity_rows(M0, M1, ex, kinds, dirs, x, u, t, S, work,
                      rows):  # pragma: no cover - compiled
    """The sensitivity of one equation of the model, v = M0 x + M1 μ(x, ũ) + (direct terms),
    at sample t: into ``work`` = (vals, Jac, Mx) the monomials μ, their Jacobian and
    Mx = M0 + M1 ∂μ/∂x, and rows = Mx S plus the direct terms of the directions ``dirs`` whose
    kind is one of ``kinds`` (for the entry (r, c): x_c, ũ_c, μ_c, 1). The output equation:
    (C, F, exe, _OUTPUT_KINDS), rows ∂ŷ/∂θ; the state equation: (A, E, exz, _STATE_KINDS), the
    next sensitivity."""
    vals, Jac, Mx = work
    n = x.shape[0]
    monomials(ex, x, u, t, vals)
    _monomial_jacobian(ex, x, u, t, Jac)
    for i in range(M0.shape[0]):
        for c in range(n):
            acc = M0[i, c]
            for k in range(M1.shape[1]):
                acc += M1[i, k] * Jac[k, c]
            Mx[i, c] = acc
        row_product(Mx, i, S, rows[i])
    k_x, k_u, k_v, k_1 = kinds
    for q in range(dirs.shape[0]):
        kind, r, c = dirs[q, 0], dirs[q, 1], dirs[q, 2]
        if kind == k_x:
            rows[r, q] += x[c]
        elif kind == k_u:
            rows[r, q] += u[t, c]
        elif kind == k_v:
            rows[r, q] += vals[c]
        elif kind == k_1:
            rows[r, q] += 1.0


@numba.njit(cache=True, inline="always")
def _window_sums(G, g, P, j, out):  # pragma: no cover - compiled
    """Adds window j's sums (G: the upper triangle of JᵀJ over [θ; z_j], g = Jᵀe) to
    ``out.Htt``, ``out.gt`` and writes its blocks ``out.Htz[j]``, ``out.Hzz[j]``, ``out.gz[j]``."""
    Htt, Htz, Hzz = out.Htt, out.Htz, out.Hzz
    n = G.shape[0] - P
    for a in range(P):  # G holds its upper triangle
        out.gt[a] += g[a]
        for b in range(P):
            Htt[a, b] += G[a, b] if a <= b else G[b, a]
        for c in range(n):
            Htz[j, a, c] = G[a, P + c]
    for c in range(n):
        out.gz[j, c] = g[P + c]
        for d in range(n):
            Hzz[j, c, d] = G[P + c, P + d] if c <= d else G[P + d, P + c]


@numba.njit(cache=True)
def simulate_kernel(m, x0, u, Y, X, limit):  # pragma: no cover - compiled
    """Free run of the model ``m`` (:data:`NLSSArrays`) from x0: outputs into Y (N, p), states
    into X (N, n) when X has N rows. Returns the first sample whose state leaves [−limit, limit]
    (or is not finite), −1 if none; the outputs from there on are NaN."""
    A, B, C, D, E, F, y0, exz, exe = m
    n = A.shape[0]
    N = u.shape[0]
    store = X.shape[0] == N
    x = x0.copy()
    xn = np.empty(n)
    zeta = np.empty(exz.shape[0])
    eta = np.empty(exe.shape[0])
    for t in range(N):
        bad = False
        for r in range(n):
            if not (abs(x[r]) <= limit):
                bad = True
        if bad:
            for s in range(t, N):
                for i in range(Y.shape[1]):
                    Y[s, i] = np.nan
            return t
        if store:
            for r in range(n):
                X[t, r] = x[r]
        monomials(exe, x, u, t, eta)
        for i in range(Y.shape[1]):
            Y[t, i] = output_row(C, D, F, y0, x, u, t, eta, i)
        monomials(exz, x, u, t, zeta)
        state_update(A, B, E, x, u, t, zeta, xn)
        for r in range(n):
            x[r] = xn[r]
    return -1


@numba.njit(cache=True)
def window_loss(m, win, limit):  # pragma: no cover - compiled
    """Σ over the windows ``win`` (:data:`NLSSWindows`; window j: samples starts[j] …
    starts[j+1] − 1, free run of ``m`` from Z[j]) of the weighted squared simulation errors
    Σ (w_i e_i)²; inf when a state leaves [−limit, limit]."""
    A, B, C, D, E, F, y0, exz, exe = m
    Z, starts, u, y, w = win
    n = A.shape[0]
    p = C.shape[0]
    x = np.empty(n)
    xn = np.empty(n)
    zeta = np.empty(exz.shape[0])
    eta = np.empty(exe.shape[0])
    V = 0.0
    for j in range(starts.shape[0] - 1):
        for r in range(n):
            x[r] = Z[j, r]
        for t in range(starts[j], starts[j + 1]):
            for r in range(n):
                if not (abs(x[r]) <= limit):
                    return np.inf
            monomials(exe, x, u, t, eta)
            for i in range(p):
                e = w[i] * (y[t, i] - output_row(C, D, F, y0, x, u, t, eta, i))
                V += e * e
            monomials(exz, x, u, t, zeta)
            state_update(A, B, E, x, u, t, zeta, xn)
            for r in range(n):
                x[r] = xn[r]
    return V


@numba.njit(cache=True)
def _sensitivity_buffers(m, Q):  # pragma: no cover - compiled
    """The buffers of a sensitivity pass of ``m`` over Q directions: S (n, Q) = 0 and its next
    value Sn, the output rows (p, Q), the state x and its next value xn, ζ, η, their Jacobians
    (Mζ, n), (Mη, n) and the linearised state and output matrices Fx (n, n), Gx (p, n)."""
    n, p = m.A.shape[0], m.C.shape[0]
    nz, ne = m.exz.shape[0], m.exe.shape[0]
    return (np.zeros((n, Q)), np.empty((n, Q)), np.zeros((p, Q)), np.empty(n), np.empty(n),
            np.empty(nz), np.empty(ne), np.empty((nz, n)), np.empty((ne, n)), np.empty((n, n)),
            np.empty((p, n)))


@numba.njit(cache=True, inline="always")
def _advance(m, dirs, x, u, t, S, Sn, zeta, Jz, Fx, xn):  # pragma: no cover - compiled
    """One step of the state and of its sensitivity S (carried, tiny entries flushed)."""
    _sensitivity_rows(m.A, m.E, m.exz, _STATE_KINDS, dirs, x, u, t, S, (zeta, Jz, Fx), Sn)
    _carry(Sn, S)
    state_update(m.A, m.B, m.E, x, u, t, zeta, xn)
    for r in range(x.shape[0]):
        x[r] = xn[r]


@numba.njit(cache=True)
def window_gram(m, dirs, win, limit, out):  # pragma: no cover - compiled
    """Gauss-Newton sums of the windowed simulation error (module docstring) of the model ``m``
    (:data:`NLSSArrays`) over the windows ``win`` (:data:`NLSSWindows`): for the P parameter
    directions ``dirs`` and the n initial-state directions of each window j, into ``out``
    (:data:`NLSSGram`): Htt = Σ JθᵀJθ (P, P), gt = Σ Jθᵀe, Htz[j] = Σ Jθᵀ Jz_j (P, n), Hzz[j] =
    Σ Jz_jᵀJz_j, gz[j] = Σ Jz_jᵀ e, rows weighted by w (per output). Returns the loss Σ (w e)²,
    inf when a state leaves [−limit, limit] (the sums are then incomplete)."""
    C, D, F, y0, exe = m.C, m.D, m.F, m.y0, m.exe
    Z, starts, u, y, w = win
    n = m.A.shape[0]
    p = C.shape[0]
    P = dirs.shape[0]
    Q = P + n
    S, Sn, rows, x, xn, zeta, eta, Jz, Je, Fx, Gx = _sensitivity_buffers(m, Q)
    G = np.zeros((Q, Q))
    g = np.zeros(Q)
    RT = np.zeros((_ROWS, Q))
    eb = np.zeros(_ROWS)
    out.Htt[:, :] = 0.0
    out.gt[:] = 0.0
    V = 0.0
    for j in range(starts.shape[0] - 1):
        for r in range(n):
            x[r] = Z[j, r]
            for q in range(Q):
                S[r, q] = 0.0
            S[r, P + r] = 1.0
        G[:, :] = 0.0
        g[:] = 0.0
        fill = 0
        for t in range(starts[j], starts[j + 1]):
            for r in range(n):
                if not (abs(x[r]) <= limit):
                    return np.inf
            _sensitivity_rows(C, F, exe, _OUTPUT_KINDS, dirs, x, u, t, S, (eta, Je, Gx), rows)
            for i in range(p):
                wi = w[i]
                e = wi * (y[t, i] - output_row(C, D, F, y0, x, u, t, eta, i))
                V += e * e
                ri = rows[i]
                for q in range(Q):
                    RT[fill, q] = wi * ri[q]
                eb[fill] = e
                fill += 1
                if fill == _ROWS:
                    _add_rows(RT, eb, fill, G, g)
                    fill = 0
            _advance(m, dirs, x, u, t, S, Sn, zeta, Jz, Fx, xn)
        if fill:
            _add_rows(RT, eb, fill, G, g)
        _window_sums(G, g, P, j, out)
    return V


@numba.njit(cache=True)
def output_variance(m, dirs, x0, u, L, out):  # pragma: no cover - compiled
    """out[t, i] = ‖Lᵀ ∂ŷ_i[t]/∂θ‖² for the free run of ``m`` (:data:`NLSSArrays`) from x0 (x0
    held): the variance of the simulated output by linearised propagation of cov θ = L Lᵀ
    (directions ``dirs``)."""
    C, F, exe = m.C, m.F, m.exe
    P = dirs.shape[0]
    S, Sn, rows, x, xn, zeta, eta, Jz, Je, Fx, Gx = _sensitivity_buffers(m, P)
    x[:] = x0
    tmp = np.empty(L.shape[1])
    N = u.shape[0]
    for t in range(N):
        _sensitivity_rows(C, F, exe, _OUTPUT_KINDS, dirs, x, u, t, S, (eta, Je, Gx), rows)
        for i in range(C.shape[0]):  # ‖Lᵀ r‖²
            ri = rows[i]
            for b in range(L.shape[1]):
                tmp[b] = 0.0
            for a in range(P):
                ra = ri[a]
                if ra == 0.0:
                    continue
                La = L[a]
                for b in range(L.shape[1]):
                    tmp[b] += ra * La[b]
            acc = 0.0
            for b in range(L.shape[1]):
                acc += tmp[b] * tmp[b]
            out[t, i] = acc
        _advance(m, dirs, x, u, t, S, Sn, zeta, Jz, Fx, xn)
