"""Numba kernels of the Hammerstein–Wiener family (:mod:`.hammerstein_wiener`): the static
nonlinearities with their derivatives, and the free run of ``y = g(B/F f(u)) + y0`` (output-error
linear block, :func:`hw_run`) or of ``y = g(G f(u)) + y0`` with ``G`` a state-space block in
observer canonical form (:func:`ss_run`), each with the forward sensitivities of ŷ to every
parameter (scalar, allocation-free loops; the caller owns every work array)."""

from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import njit

#: kind codes shared with the Python side
NONE, SATURATION, DEADZONE, POLY, PWL, SIGMOID = 0, 1, 2, 3, 4, 5

# Named records the free-run kernel takes (namedtuples: numba resolves each field at compile time).
#: a static nonlinearity: its kind code, parameters ``p``, fixed constants ``c`` (breakpoints, or
#: centres then the width; one unused element where none) and ``grad`` (≥ 2), which receives ∂f/∂p
HWBlock = namedtuple("HWBlock", "kind p c grad")
#: the linear block ``B(q)/F(q)``: ``b1…b_nb``, ``f1…f_nf`` and the delay ``nk``
HWLinear = namedtuple("HWLinear", "b f nk")
#: scratch of the free run: ``w``, ``x`` (N + M) and their sensitivities ``dw`` (N + M, ni + 1),
#: ``dx`` (N + M, ni + nb + nf + 1), ``M = nk + nb + nf`` the rows before the record
HWWork = namedtuple("HWWork", "w x dw dx")
#: the state-space linear block in observer canonical form (:func:`ss_run`): ``a1…a_n``, ``b1…b_n``,
#: ``d`` (one element: the feedthrough, when ``nk = 0``; else empty) and the delay ``nk``
SSLinear = namedtuple("SSLinear", "a b d nk")
#: scratch of the state-space free run: ``w`` (N + M) and ``dw`` (N + M, ni + 1) as in
#: :data:`HWWork` (``M = max(nk − 1, 0)`` rows before the record), ``x`` (N) the block's output,
#: the state ``xi`` (n) and its sensitivities ``dxi`` (n, ni + 2n + nd + 1)
SSWork = namedtuple("SSWork", "w x dw xi dxi")
#: what the free run writes: ``yhat`` (N) and, when asked, ``jac`` (N, P + 1)
HWOut = namedtuple("HWOut", "yhat jac")


@njit(cache=True)
def nl_eval(kind, p, c, v, grad):
    """``(f(v), f'(v))`` of the nonlinearity ``kind`` with parameters ``p`` and constants ``c``;
    ``grad[:len(p)]`` receives ∂f/∂p. Every kind has unit slope in its linear part (the gain
    normalisation, see the module docstring of :mod:`.hammerstein_wiener`)."""
    if kind == SATURATION:
        lo, hi = p[0], p[1]
        grad[0] = 0.0
        grad[1] = 0.0
        if v < lo:
            grad[0] = 1.0
            return lo, 0.0
        if v > hi:
            grad[1] = 1.0
            return hi, 0.0
        return v, 1.0
    if kind == DEADZONE:
        lo, hi = p[0], p[1]
        grad[0] = 0.0
        grad[1] = 0.0
        if v < lo:
            grad[0] = -1.0
            return v - lo, 1.0
        if v > hi:
            grad[1] = -1.0
            return v - hi, 1.0
        return 0.0, 0.0
    if kind == POLY:  # v + c2 v² + … + cN v^N
        f = v
        d = 1.0
        vk = v  # v^(k-1)
        for k in range(p.shape[0]):
            deg = k + 2
            d += deg * p[k] * vk
            vk *= v
            grad[k] = vk
            f += p[k] * vk
        return f, d
    if kind == PWL:  # v + Σ_{k<N/2} d_k min(0, v − β_k) + Σ_{k≥N/2} d_k max(0, v − β_k)
        f = v
        d = 1.0
        half = p.shape[0] // 2
        for k in range(p.shape[0]):
            r = v - c[k]
            if (k >= half and r > 0.0) or (k < half and r < 0.0):
                grad[k] = r
                f += p[k] * r
                d += p[k]
            else:
                grad[k] = 0.0
        return f, d
    if kind == SIGMOID:  # v + Σ a_k tanh((v − c_k)/h), h = c[-1]
        h = c[c.shape[0] - 1]
        f = v
        d = 1.0
        for k in range(p.shape[0]):
            th = np.tanh((v - c[k]) / h)
            grad[k] = th
            f += p[k] * th
            d += p[k] * (1.0 - th * th) / h
        return f, d
    return v, 1.0


@njit(cache=True, _nrt=False)
def hw_run(u, fin, lin, fout, y0, wpre, want_j, work, out):
    """Free run of ``w = f(u)``, ``F(q) x = B(q) q^-nk w``, ``ŷ = g(x) + y0`` from the linear
    block's steady state under the constant input ``wpre`` (``w(t<0) = wpre``,
    ``x(t<0) = B(1)/F(1) wpre``).

    ``fin``, ``fout``: the nonlinearities (:data:`HWBlock`), ``lin``: the linear block
    (:data:`HWLinear`), ``work``: :data:`HWWork`, ``out``: :data:`HWOut`. With ``want_j`` the rows
    of ``out.jac`` (N, P + 1) receive ∂ŷ(t)/∂θ for ``θ = [fin.p, b, f, fout.p, y0, wpre]``.
    Returns the first sample where ŷ is not finite, −1 if none."""
    b, f, nk = lin.b, lin.f, lin.nk
    w, x, dw, dx = work.w, work.x, work.dw, work.dx
    gin, gout, yhat, jac = fin.grad, fout.grad, out.yhat, out.jac
    n = u.shape[0]
    ni = fin.p.shape[0]
    nb = b.shape[0]
    nf = f.shape[0]
    no = fout.p.shape[0]
    nl = ni + nb + nf
    m = nk + nb + nf
    sb = 0.0
    for i in range(nb):
        sb += b[i]
    f1 = 1.0
    for j in range(nf):
        f1 += f[j]
    s = sb / f1
    for t in range(m):
        w[t] = wpre
        x[t] = s * wpre
        if want_j:
            for k in range(ni):
                dw[t, k] = 0.0
                dx[t, k] = 0.0
            dw[t, ni] = 1.0
            for i in range(nb):
                dx[t, ni + i] = wpre / f1
            for j in range(nf):
                dx[t, ni + nb + j] = -s * wpre / f1
            dx[t, nl] = s
    bad = -1
    for t in range(m, n + m):
        wt, _ = nl_eval(fin.kind, fin.p, fin.c, u[t - m], gin)
        w[t] = wt
        acc = 0.0
        for i in range(nb):
            acc += b[i] * w[t - nk - i]
        for j in range(nf):
            acc -= f[j] * x[t - 1 - j]
        x[t] = acc
        g, gd = nl_eval(fout.kind, fout.p, fout.c, acc, gout)
        yt = g + y0
        yhat[t - m] = yt
        if bad < 0 and not np.isfinite(yt):
            bad = t - m
        if want_j:
            for k in range(ni):
                dw[t, k] = gin[k]
            dw[t, ni] = 0.0
            for k in range(nl + 1):
                a = 0.0
                for j in range(nf):
                    a -= f[j] * dx[t - 1 - j, k]
                dx[t, k] = a
            for k in range(ni):
                a = 0.0
                for i in range(nb):
                    a += b[i] * dw[t - nk - i, k]
                dx[t, k] += a
            a = 0.0
            for i in range(nb):
                a += b[i] * dw[t - nk - i, ni]
                dx[t, ni + i] += w[t - nk - i]
            dx[t, nl] += a
            for j in range(nf):
                dx[t, ni + nb + j] -= x[t - 1 - j]
            r = t - m
            for k in range(nl):
                jac[r, k] = gd * dx[t, k]
            for k in range(no):
                jac[r, nl + k] = gout[k]
            jac[r, nl + no] = 1.0
            jac[r, nl + no + 1] = gd * dx[t, nl]
    return bad


@njit(cache=True, _nrt=False)
def _ss_start(lin, wpre, want_j, work, ni, m):
    """The start of :func:`ss_run`: the block's steady state under the constant input ``wpre``
    (``ξ_1 = Σb/(1 + Σa)·wpre``, ``ξ_i = Σ_{k≥i} (b_k wpre − a_k ξ_1)``) into ``work.xi``, the
    ``m`` delayed inputs ``w(t<0) = wpre`` and, with ``want_j``, their derivatives by θ (``ni``
    columns of the input nonlinearity first, as in :func:`ss_run`)."""
    a, b, d = lin.a, lin.b, lin.d
    w, dw, xi, dxi = work.w, work.dw, work.xi, work.dxi
    ns = a.shape[0]
    ca = ni
    cb = ni + ns
    cd = ni + 2 * ns
    nl = cd + d.shape[0]
    cw = nl
    sa = 1.0
    sb = 0.0
    for i in range(ns):
        sa += a[i]
        sb += b[i]
    x1 = sb / sa * wpre
    acc = 0.0
    for i in range(ns - 1, -1, -1):
        acc += b[i] * wpre - a[i] * x1
        xi[i] = acc
    for t in range(m):
        w[t] = wpre
    if want_j:
        for t in range(m):
            for k in range(ni):
                dw[t, k] = 0.0
            dw[t, ni] = 1.0
        for k in range(nl + 1):
            d1 = 0.0          # ∂ξ_1(0)/∂θ_k
            if ca <= k < cb:
                d1 = -x1 / sa
            elif cb <= k < cd:
                d1 = wpre / sa
            elif k == cw:
                d1 = sb / sa
            acc = 0.0
            for i in range(ns - 1, -1, -1):
                acc -= a[i] * d1
                if k == cb + i:
                    acc += wpre
                if k == ca + i:
                    acc -= x1
                if k == cw:
                    acc += b[i]
                dxi[i, k] = acc


@njit(cache=True, _nrt=False)
def ss_run(u, fin, lin, fout, y0, wpre, want_j, work, out):
    """Free run of ``w = f(u)``, the observer canonical state-space block ::

        ξ(t+1) = A ξ(t) + b w(t − m),   x(t) = ξ_1(t) + d w(t),   m = max(nk − 1, 0)
        A = [[−a1, 1, 0, …], [−a2, 0, 1, …], …, [−a_n, 0, …, 0]]

    (``d`` only when ``nk = 0``), and ``ŷ = g(x) + y0``, from the block's steady state under the
    constant input ``wpre`` (``w(t<0) = wpre``, ``ξ(0) = (I − A)⁻¹ b wpre``: ``ξ_1 = Σb/(1 + Σa)
    wpre``, ``ξ_i = Σ_{k≥i} (b_k wpre − a_k ξ_1)``).

    ``fin``, ``fout``: :data:`HWBlock`, ``lin``: :data:`SSLinear`, ``work``: :data:`SSWork`,
    ``out``: :data:`HWOut`. With ``want_j`` the rows of ``out.jac`` (N, P + 1) receive
    ∂ŷ(t)/∂θ for ``θ = [fin.p, a, b, d, fout.p, y0, wpre]``, from the sensitivities
    ``∂ξ(t+1)/∂θ = A ∂ξ(t)/∂θ + b ∂w/∂θ + (∂A/∂θ) ξ(t) + (∂b/∂θ) w``. Returns the first sample
    where ŷ is not finite, −1 if none."""
    a, b, d, nk = lin.a, lin.b, lin.d, lin.nk
    w, x, dw, xi, dxi = work.w, work.x, work.dw, work.xi, work.dxi
    gin, gout, yhat, jac = fin.grad, fout.grad, out.yhat, out.jac
    n = u.shape[0]
    ni = fin.p.shape[0]
    ns = a.shape[0]
    nd = d.shape[0]
    no = fout.p.shape[0]
    ca = ni                   # columns of a, b, d and wpre in dxi (and in jac, but wpre)
    cb = ni + ns
    cd = ni + 2 * ns
    nl = cd + nd
    cw = nl
    m = nk - 1 if nk > 0 else 0
    dd = d[0] if nd > 0 else 0.0
    _ss_start(lin, wpre, want_j, work, ni, m)
    bad = -1
    for r in range(n):
        t = r + m
        wt, _ = nl_eval(fin.kind, fin.p, fin.c, u[r], gin)
        w[t] = wt
        wi = w[t - m]
        v = xi[0] + dd * wi
        x[r] = v
        g, gd = nl_eval(fout.kind, fout.p, fout.c, v, gout)
        yt = g + y0
        yhat[r] = yt
        if bad < 0 and not np.isfinite(yt):
            bad = r
        if want_j:
            for k in range(ni):
                dw[t, k] = gin[k]
            dw[t, ni] = 0.0
            for k in range(nl + 1):
                dwi = 0.0     # ∂w(t − m)/∂θ_k
                if k < ni:
                    dwi = dw[t - m, k]
                elif k == cw:
                    dwi = dw[t - m, ni]
                dv = dxi[0, k] + dd * dwi
                if nd > 0 and k == cd:
                    dv += wi
                if k < nl:
                    jac[r, k] = gd * dv
                else:
                    jac[r, nl + no + 1] = gd * dv
                d1 = dxi[0, k]
                for i in range(ns):
                    s = -a[i] * d1 + b[i] * dwi
                    if i + 1 < ns:
                        s += dxi[i + 1, k]
                    if k == ca + i:
                        s -= xi[0]
                    if k == cb + i:
                        s += wi
                    dxi[i, k] = s
            for k in range(no):
                jac[r, nl + k] = gout[k]
            jac[r, nl + no] = 1.0
        x1 = xi[0]
        for i in range(ns):
            s = -a[i] * x1 + b[i] * wi
            if i + 1 < ns:
                s += xi[i + 1]
            xi[i] = s
    return bad


@njit(cache=True)
def gram(jac, r, H, g):
    """``H = JᵀJ`` and ``g = Jᵀr`` in one pass, single-threaded: BLAS's threads on these thin
    (N × P) products cost more than they give on a shared machine."""
    n, p = jac.shape
    for a in range(p):
        g[a] = 0.0
        for b in range(p):
            H[a, b] = 0.0
    for t in range(n):
        rt = r[t]
        for a in range(p):
            ja = jac[t, a]
            g[a] += ja * rt
            for b in range(a, p):
                H[a, b] += ja * jac[t, b]
    for a in range(p):
        for b in range(a):
            H[a, b] = H[b, a]


@njit(cache=True)
def residual(y, yhat, r):
    """``r = y − ŷ`` and its sum of squares (single-threaded, as :func:`gram`)."""
    s = 0.0
    for t in range(y.shape[0]):
        e = y[t] - yhat[t]
        r[t] = e
        s += e * e
    return s
