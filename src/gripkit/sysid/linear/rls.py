"""Recursive least squares (RLS) for ARX models, §V-F of ``000_8f66dcc7ab06470c.txt``.

Two front ends share one numba kernel and one state vector:

* :class:`RLS`, a streaming estimator for a control loop: ``e = est.update(u, y)`` per sample
  (a few hundred nanoseconds: one call into a kernel compiled for the model structure, working in
  place). A NaN/inf sample, a corrupt one (:data:`ABSURD_JUMP`), a divergence or an overflow
  raises and leaves θ and P as they were (the kernel updates in place only when a bound shows
  that no value can overflow, else from a backup);
* :func:`rls`, the batch form, which returns θ and σ at every step (:class:`RLSResult`).

At each sample t with regressor φ(t) = [−y(t−1) … −y(t−na), u(t−nk) … u(t−nk−nb+1)] (eq 21)::

    e(t)  = y(t) − φᵀ θ(t−1)                      a-priori prediction error
    r     = φᵀ P φ
    K     = P φ / (λ + r)
    θ(t)  = θ(t−1) + K e(t)

and the covariance update depends on ``windup``:

* ``'trace'`` (default) and ``'none'``: exponential forgetting ``P ← (P − PφφᵀP/(λ + r)) / λ``;
  with ``'trace'`` P is scaled down whenever its trace exceeds ``max_trace`` (default: the trace
  of P0), so that P cannot wind up (grow without bound) when the input stops exciting some
  directions.
* ``'directional'``: forgetting only along the incoming regressor (Kulhavý & Kárný 1984).
  The information matrix R = P⁻¹ loses ``(1 − λ)/r · φφᵀ`` before the data are added, i.e.
  ``R ← R − (1 − λ)φφᵀ/r + φφᵀ``. By Sherman–Morrison this gives the same gain ``K = Pφ/(λ + r)``
  and ``P ← P + (1 − λ − r)/(r (λ + r)) · PφφᵀP``: directions that the data do not reach are
  never forgotten, so P stays bounded without a trace limit. When r ≤ 1e-12·trace(P) (no new
  information) the update is the plain λ = 1 one.

P is updated as ``P ← (P + coef·q qᵀ)·scale`` with ``q = Pφ``, on the upper triangle, which is
mirrored: P stays exactly symmetric. It stays positive definite because each
update keeps its inverse positive (the information loses at most a fraction 1 − λ along φ and
gains φφᵀ), and the trace limit bounds it above.

Uncertainty: the noise variance is tracked as σ̂² = V/(w₁ − p) with the weighted residual sum
``V ← λV + λe²/(λ + r)`` and effective sample count ``w₁ ← λw₁ + 1``; the parameter covariance
is ``σ̂² P · w₂/w₁`` with ``w₂ ← λ²w₂ + 1`` (asymptotically exact for stationary regressors:
weighted least
squares with weights λᵏ has covariance σ² R⁻¹(Σλ²ᵏφφᵀ)R⁻¹; for λ = 1 it is σ̂²P, the least-squares
covariance). With λ = 1 and a large P0 the RLS estimate equals the least-squares one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit, types
from numba.core.errors import TypingError

from ...arguments import entry_point
from ...errors import DataError, IdentificationError
from ...signals.trajectory import Trajectory
from ..checks import (check_dt, check_excitation, check_io_arrays, check_order, require_samples,
                      signal_with_peaks)
from .polynomial import PolynomialModel

__all__ = ["RLS", "RLSResult", "rls"]

# state vector layout (float64): header, then buffers, θ, P and work vectors
_COUNT, _LAM, _MODE, _MAXTR, _V, _W1, _W2, _TRACE, _NUPD, _NA, _NB, _NK, _STATUS = range(13)
_PU, _PY = 13, 14  # running peaks of |u| and |y| (corrupt-sample test)
_HDR = 16
_MODES = {"none": 0, "trace": 1, "directional": 2}
#: Records at least this long run through a batch kernel compiled for their number of parameters.
SPECIALISE_ABOVE = 100_000
#: A sample whose magnitude exceeds this many times the largest magnitude of its signal before it
#: is refused as corrupt (a spike, a logger's sentinel such as 1e30, a parse error): more than the
#: range of any converter (32 bits: 4.3e9), so no measured change of a signal reaches it, while one
#: such sample throws θ orders of magnitude off for the rest of the record.
ABSURD_JUMP = 1e10


#: The streaming step updates θ and P in place only when every new value is provably below this
#: bound (then no entry, nor the trace, can overflow); otherwise it backs them up first.
_SAFE_BOUND = 1e300


@njit(cache=True, inline="always")
def _gain(wb, at, p, size, lam, mode, trace, y, guard):
    """The first half of one RLS update (``at`` = the offsets ``(oP, oth, oph, oq)`` of P, θ, φ and
    q in the one buffer ``wb``, a tuple: the kernel is inlined): the a-priori error e, q = Pφ,
    r = φᵀPφ and the coefficients of the update. With ``guard`` (a literal) also a bound on every
    value the second half (:func:`_apply`) will write: ``safe`` is True when e and r are finite
    and all new entries of θ and P stay below :data:`_SAFE_BOUND`/p, so that the update cannot
    overflow (|P_ij + c q_i q_j|·s <= (max|P| + |c| max|q|²)·s, |θ_i + q_i g| <= max|θ| +
    max|q|·|g|; r finite implies q finite). Returns (e, r, coef, scale, g, safe)."""
    oP, oth, oph, oq = at
    if len(size) > 0:
        p = len(size)
    yhat = 0.0
    tm = 0.0
    pm = 0.0
    for i in range(p):  # q = Pφ, row i of P (= its column: P is exactly symmetric), j ascending
        row = oP + i * p
        acc = 0.0
        for j in range(p):
            acc += wb[row + j] * wb[oph + j]
            if guard:
                pm = max(pm, abs(wb[row + j]))
        wb[oq + i] = acc
        yhat += wb[oph + i] * wb[oth + i]
        if guard:
            tm = max(tm, abs(wb[oth + i]))
    e = y - yhat
    r = 0.0
    for i in range(p):
        r += wb[oph + i] * wb[oq + i]
    if mode == 2 and r <= 1e-12 * trace:  # directional, no new direction: no forgetting
        inv = 1.0 / (1.0 + r)
        coef, scale = -inv, 1.0
    elif mode == 2:  # directional forgetting
        inv = 1.0 / (lam + r)
        coef, scale = (1.0 - lam - r) / r * inv, 1.0
    else:  # exponential forgetting
        inv = 1.0 / (lam + r)
        coef, scale = -inv, 1.0 / lam
    g = e * inv
    safe = False
    if guard and math.isfinite(e) and math.isfinite(r):
        qm = 0.0
        for i in range(p):
            qm = max(qm, abs(wb[oq + i]))
        # NaN or inf in a bound compares False: not safe
        safe = ((pm + abs(coef) * qm * qm) * scale * p < _SAFE_BOUND
                and tm + qm * abs(g) < _SAFE_BOUND)
    return e, r, coef, scale, g, safe


@njit(cache=True, inline="always")
def _apply(wb, at, p, size, mode, maxtr, coef, scale, g):
    """The second half of one RLS update: θ ← θ + q·g and P ← (P + coef·q qᵀ)·scale on the upper
    triangle, mirrored, then the trace bound; returns trace P."""
    oP, oth, oph, oq = at
    if len(size) > 0:
        p = len(size)
    for i in range(p):
        wb[oth + i] += wb[oq + i] * g
    tr = 0.0
    for i in range(p):  # P stays exactly symmetric: update the upper triangle, mirror it
        qi = coef * wb[oq + i]
        row = oP + i * p
        for j in range(i, p):
            v = (wb[row + j] + qi * wb[oq + j]) * scale
            wb[row + j] = v
            wb[oP + j * p + i] = v
        tr += wb[row + i]
    if mode == 1 and tr > maxtr:  # bounded trace
        f = maxtr / tr
        for k in range(p * p):
            wb[oP + k] *= f
        tr = maxtr
    return tr


@njit(cache=True, inline="always")
def _step_update(s, at, ob, p, size, y):
    """The guarded update of :func:`_rls_step` (θ and P in the state vector ``s`` at the offsets
    ``at``, a backup area at ``s[ob:ob + p + p·p]``); returns (e, r, trace, status): status 0 =
    done, 2 = P or θ would no longer be finite, 3 = φᵀPφ overflowed; on 2 and 3 θ and P are as
    they were."""
    oP, oth, oph, oq = at
    if len(size) > 0:
        p = len(size)
    lam = s[_LAM]
    mode = int(s[_MODE])
    e, r, coef, scale, g, safe = _gain(s, at, p, size, lam, mode, s[_TRACE], y, True)
    if safe:  # no value can overflow: update in place, nothing to back up
        tr = _apply(s, at, p, size, mode, s[_MAXTR], coef, scale, g)
        return e, r, tr, 0
    for i in range(p):  # rare (huge values or a non-finite e or r): back up, update, check
        s[ob + i] = s[oth + i]
    for i in range(p * p):
        s[ob + p + i] = s[oP + i]
    tr = _apply(s, at, p, size, mode, s[_MAXTR], coef, scale, g)
    ok = math.isfinite(tr) and math.isfinite(e)
    for i in range(p):
        ok = ok and math.isfinite(s[oth + i])
    if ok and math.isfinite(r):
        return e, r, tr, 0
    for i in range(p):
        s[oth + i] = s[ob + i]
    for i in range(p * p):
        s[oP + i] = s[ob + p + i]
    return e, r, tr, 2 if math.isfinite(r) else 3


@njit(cache=True)
def _rls_step(s, u, y, size):
    """One RLS update in place on the state vector ``s``; returns the a-priori error (0 while
    the regressor is not yet filled). Same arithmetic as :func:`_rls_run` (:func:`_gain` and
    :func:`_apply`, which its loop writes out).

    A failed update returns NaN and leaves ``s`` as it was, with the reason in ``s[_STATUS]``:
    1 = ``u`` or ``y`` not finite, 2 = P or θ no longer finite (divergence), 3 = φᵀPφ overflowed
    (signals too large for P), 4 = ``|u|`` or ``|y|`` above :data:`ABSURD_JUMP` times its running
    peak ``s[_PU]``, ``s[_PY]``. θ and P are updated in place when a bound shows that no new
    value can overflow (:func:`_gain`), else from a backup (``s[ob:]``) that is restored on
    failure.

    ``size``: as for :func:`_rls_run`. θ, P, φ and q are addressed in ``s`` itself (one base
    pointer); with the orders known to the compiler (tuple lengths) their offsets are constants.
    """
    if not (math.isfinite(u) and math.isfinite(y)):
        s[_STATUS] = 1.0
        return np.nan
    au = abs(u)
    ay = abs(y)
    if (au > s[_PU] and s[_PU] > 0.0 and au > ABSURD_JUMP * s[_PU]) or (
            ay > s[_PY] and s[_PY] > 0.0 and ay > ABSURD_JUMP * s[_PY]):
        s[_STATUS] = 4.0  # a corrupt sample
        return np.nan
    if len(size[0]) > 0:
        na, nb, nk = len(size[1]), len(size[2]), len(size[3])
    else:
        na, nb, nk = int(s[_NA]), int(s[_NB]), int(s[_NK])
    p = na + nb
    nu = nk + nb
    oy = _HDR
    ou = oy + na
    oth = ou + nu
    op = oth + p
    oph = op + p * p
    oq = oph + p
    ob = oq + p  # backup of θ and P
    e = 0.0
    t0 = na if na > nk + nb - 1 else nk + nb - 1
    if s[_COUNT] >= t0:
        for i in range(na):
            s[oph + i] = -s[oy + i]
        for j in range(nb):  # u(t-nk-j): the buffer is shifted only once the update succeeded
            s[oph + na + j] = u if nk + j == 0 else s[ou + nk + j - 1]
        e, r, tr, status = _step_update(s, (op, oth, oph, oq), ob, p, size[0], y)
        if status != 0:
            s[_STATUS] = float(status)
            return np.nan
        lam = s[_LAM]
        s[_TRACE] = tr
        s[_V] = lam * (s[_V] + e * e / (lam + r))
        s[_W1] = lam * s[_W1] + 1.0
        s[_W2] = lam * lam * s[_W2] + 1.0
        s[_NUPD] += 1.0
    if au > s[_PU]:
        s[_PU] = au
    if ay > s[_PY]:
        s[_PY] = ay
    for i in range(nu - 1, 0, -1):
        s[ou + i] = s[ou + i - 1]
    s[ou] = u
    for i in range(na - 1, 0, -1):
        s[oy + i] = s[oy + i - 1]
    if na > 0:
        s[oy] = y
    s[_COUNT] += 1.0
    return e


_GENERIC = ((), (), (), ())


@njit(cache=True)
def _rls_step_any(s, u, y):
    """:func:`_rls_step` with the orders read from ``s`` (one compiled step for all models)."""
    return _rls_step(s, u, y, _GENERIC)


_STEPS: dict = {}


def _step_entry(na: int, nb: int, nk: int):
    """The step :meth:`RLS.update` calls for an ARX [na nb nk] model: :func:`_rls_step` compiled
    for this structure (the orders as tuple lengths, like the batch kernel's ``size``: unrolled
    p-loops and constant offsets), once per structure and process (numba caches it on disk).

    Returned is the compiled function's ``entry_point`` for (C-contiguous float64 vector, float,
    float), which unboxes its arguments as those types without numba's dispatcher (and its type
    resolution per call); only :meth:`RLS.update` calls it, with the estimator's own
    state vector and two floats. Where numba has no ``entry_point`` the dispatcher is returned.
    """
    key = (na, nb, nk)
    fn = _STEPS.get(key)
    if fn is None:
        size = ((0.0,) * (na + nb), (0.0,) * na, (0.0,) * nb, (0.0,) * nk)

        @njit(cache=True)
        def step(s, u, y):  # pragma: no cover - compiled
            return _rls_step(s, u, y, size)
        sig = (types.float64[::1], types.float64, types.float64)
        step.compile(sig)
        fn = getattr(step.overloads.get(sig), "entry_point", step)
        _STEPS[key] = fn, step  # the dispatcher too: it owns the compiled code
    else:
        fn = fn[0]
    return fn


@njit(cache=True)
def _var_factor(s, p):
    """σ̂²·w₂/w₁ (NaN until more than p updates): σ_i² = factor · P_ii."""
    w1 = s[_W1]
    if s[_NUPD] <= p or w1 <= p:
        return np.nan
    return s[_V] / (w1 - p) * (s[_W2] / w1)


@njit(cache=True, inline="always")
def _batch_loop(w, size, io, run, state, mode):
    """The sample loop of :func:`_rls_run` from sample ``nstart`` on, for one windup ``mode`` (a
    literal: :func:`_rls_run` calls it once per mode, so each loop holds one update instead of
    three behind a branch per sample). ``io``: u, y and the four output arrays; ``run``: the
    buffer offsets, (p, na, nb, nk), λ, the trace bound, ``nstart`` and the store / predict flags;
    ``state``: (trace, V, w₁, w₂, updates, σ factor of the last step, Σe²), returned updated
    (Σe² over the a-priori errors as stored: the loss of :meth:`RLS.run`, summed here rather than
    in a second pass over e).

    The update is :func:`_gain` then :func:`_apply` (the streaming step's halves) written out in
    the loop, with the same arithmetic in the same order, so batch and streaming results stay
    bit-identical. Written out, not called: through the inlined halves the compiled loop ran
    slower on Intel cores (``benchmarks/ab_rls_strip.py``; the figures in docs/performance.md,
    "Third pass"). Between the halves σ of step t − 1
    goes into ``std_out``, from P before this update (the square roots overlap with it).
    """
    u, y, theta_out, std_out, yhat_out, err_out = io
    at, dims, lam, maxtr, nstart, store, pred = run
    trace, V, w1, w2, nupd, f, loss = state
    oP, oth, oph, oq = at
    if len(size[0]) > 0:  # the orders are known to the compiler: constant regressor indices
        p, na, nb, nk = len(size[0]), len(size[1]), len(size[2]), len(size[3])
    else:
        p, na, nb, nk = dims
    for t in range(nstart, u.shape[0]):
        for i in range(na):
            w[oph + i] = -y[t - 1 - i]
        for j in range(nb):
            w[oph + na + j] = u[t - nk - j]
        yh = 0.0
        for i in range(p):  # q = Pφ and ŷ = φᵀθ (:func:`_gain`)
            row = oP + i * p
            acc = 0.0
            for j in range(p):
                acc += w[row + j] * w[oph + j]
            w[oq + i] = acc
            yh += w[oph + i] * w[oth + i]
        e = y[t] - yh
        r = 0.0
        for i in range(p):
            r += w[oph + i] * w[oq + i]
        if mode == 2 and r <= 1e-12 * trace:
            inv = 1.0 / (1.0 + r)
            coef, scale = -inv, 1.0
        elif mode == 2:
            inv = 1.0 / (lam + r)
            coef, scale = (1.0 - lam - r) / r * inv, 1.0
        else:
            inv = 1.0 / (lam + r)
            coef, scale = -inv, 1.0 / lam
        g = e * inv
        if store and t > nstart:  # σ of step t − 1
            for i in range(p):
                std_out[t - 1, i] = math.sqrt(f * w[oP + i * p + i])
        for i in range(p):  # θ and P (:func:`_apply`)
            w[oth + i] += w[oq + i] * g
        trace = 0.0
        for i in range(p):
            qi = coef * w[oq + i]
            row = oP + i * p
            for j in range(i, p):
                v = (w[row + j] + qi * w[oq + j]) * scale
                w[row + j] = v
                w[oP + j * p + i] = v
            trace += w[row + i]
        if mode == 1 and trace > maxtr:
            c = maxtr / trace
            for k in range(p * p):
                w[oP + k] *= c
            trace = maxtr
        V = lam * (V + e * e / (lam + r))
        w1 = lam * w1 + 1.0
        w2 = lam * lam * w2 + 1.0
        nupd += 1.0
        yh = y[t] - e
        err = y[t] - yh  # y − ŷ as stored (bit-identical to the arrays' difference)
        loss += err * err
        if pred:
            yhat_out[t] = yh
            err_out[t] = err
        if store:
            f = V / (w1 - p) * (w2 / w1) if (nupd > p and w1 > p) else np.nan
            for i in range(p):
                theta_out[t, i] = w[oth + i]
    return trace, V, w1, w2, nupd, f, loss


@njit(cache=True)
def _rls_run(s, u, y, theta_out, std_out, yhat_out, err_out, size):
    """Batch RLS: updates ``s`` over the record; writes θ and σ at every step when their arrays
    have N rows (pass arrays with 0 rows to skip storing), and the a-priori prediction ŷ and error
    y − ŷ (``err_out``, computed from the stored ŷ) when ``yhat_out`` has N rows. Returns Σe² over
    the record (e = 0 where no update was made).

    ``size``: four empty tuples (generic kernel, orders read from ``s`` at run time) or tuples of
    p, na, nb and nk zeros (:meth:`RLS._kernel_size`), whose lengths numba knows at compile time: it
    compiles (and caches) one kernel per model structure, with unrolled p-loops and constant
    regressor indices (faster: docs/performance.md, "RLS"); :meth:`RLS.run` uses it for records of
    at least :data:`SPECIALISE_ABOVE` samples, where the extra compilation (once) pays off. The
    first ``t0`` samples go through :func:`_rls_step` (their regressors need the buffered past);
    the rest take the regressor straight from ``u`` and ``y`` with θ and P in local arrays
    (:func:`_batch_loop`: the same arithmetic, so streaming and batch results are bit-identical).
    """
    n = u.shape[0]
    if len(size[0]) > 0:  # the orders are known to the compiler: constant regressor indices
        na, nb, nk = len(size[1]), len(size[2]), len(size[3])
    else:
        na, nb, nk = int(s[_NA]), int(s[_NB]), int(s[_NK])
    p, nu = na + nb, nk + nb
    oth = _HDR + na + nu
    op = oth + p
    store = theta_out.shape[0] == n
    pred = yhat_out.shape[0] == n
    t0 = na if na > nk + nb - 1 else nk + nb - 1
    nstart = t0 if t0 < n else n
    loss = 0.0
    for t in range(nstart):
        e = _rls_step(s, u[t], y[t], size)
        yh = y[t] - e
        err = y[t] - yh  # y − ŷ as stored (bit-identical to the arrays' difference)
        loss += err * err
        if pred:
            yhat_out[t] = yh
            err_out[t] = err
        if store:
            f = _var_factor(s, p)
            for i in range(p):
                theta_out[t, i] = s[oth + i]
                std_out[t, i] = math.sqrt(f * s[op + i * p + i])
    if n <= nstart:
        return loss
    # P, θ, φ and q in one local buffer at constant offsets (for the compiler: no aliasing)
    bP, bth, bph, bq = 0, p * p, p * p + p, p * p + 2 * p
    w = np.empty(p * p + 3 * p)
    for i in range(p):  # explicit loops: slice assignment costs seconds of numba compile time
        w[bth + i] = s[oth + i]
    for i in range(p * p):
        w[bP + i] = s[op + i]
    lam, mode, maxtr, trace = s[_LAM], int(s[_MODE]), s[_MAXTR], s[_TRACE]
    V, w1, w2, nupd = s[_V], s[_W1], s[_W2], s[_NUPD]
    state = (trace, V, w1, w2, nupd, np.nan, loss)
    io = (u, y, theta_out, std_out, yhat_out, err_out)
    run = ((bP, bth, bph, bq), (p, na, nb, nk), lam, maxtr, nstart, store, pred)
    if mode == 0:  # the mode as a literal: one compact loop per mode (docs/performance.md)
        state = _batch_loop(w, size, io, run, state, 0)
    elif mode == 1:
        state = _batch_loop(w, size, io, run, state, 1)
    else:
        state = _batch_loop(w, size, io, run, state, 2)
    trace, V, w1, w2, nupd, f, loss = state
    if store:  # σ of the last step
        for i in range(p):
            std_out[n - 1, i] = math.sqrt(f * w[bP + i * p + i])
    for i in range(p):
        s[oth + i] = w[bth + i]
    for i in range(p * p):
        s[op + i] = w[bP + i]
    s[_TRACE] = trace
    s[_V] = V
    s[_W1] = w1
    s[_W2] = w2
    s[_NUPD] = nupd
    s[_COUNT] += n - nstart
    for i in range(na):
        s[_HDR + i] = y[n - 1 - i]
    for i in range(nu):
        s[_HDR + na + i] = u[n - 1 - i]
    return loss


class RLS:
    """Streaming recursive least-squares estimator of an ARX ``[na nb nk]`` model.

    Parameters
    ----------
    na, nb, nk
        ARX orders in MATLAB's layout (see :func:`gripkit.sysid.linear.arx`).
    forgetting
        λ in (0, 1]; 1 = no forgetting (converges to the least-squares estimate).
    p0
        Initial covariance P0 = p0·I (large = weak prior on ``theta0``).
    theta0
        Initial parameters [a_1..a_na, b_nk..]; default zeros.
    windup
        ``'trace'`` (bound trace(P) by ``max_trace``), ``'directional'`` (directional
        forgetting) or ``'none'``; see the module docstring.
    max_trace
        Trace bound for ``windup='trace'`` (default: trace(P0) = p·p0).
    dt
        Sample interval (s), for the models this estimator returns.

    Use ``e = est.update(u_t, y_t)`` once per sample (returns the a-priori prediction error,
    0 during the first ``max(na, nk+nb−1)`` samples), read ``est.theta``, ``est.theta_std``,
    ``est.P``, ``est.model()``. ``est.run(u, y)`` processes a whole record from the current state.

    ``update`` runs a step compiled for the model structure (:func:`_step_entry`): the first
    update of a structure on a machine compiles it (2–4 s; numba caches it on disk, later
    processes load it in milliseconds), so call ``update`` once before a timed loop starts.
    """

    __slots__ = ("na", "nb", "nk", "forgetting", "windup", "dt", "_s", "_p0", "_theta0", "_maxtr",
                 "_step")

    def __init__(self, na: int, nb: int, nk: int = 1, *, forgetting: float = 1.0, p0: float = 1e4,
                 theta0=None, windup: str = "trace", max_trace: float | None = None,
                 dt: float = 1.0):
        self.na = check_order(na, "na", 0)
        self.nb = check_order(nb, "nb", 1)
        self.nk = check_order(nk, "nk", 0)
        lam = float(forgetting)
        if not (0.0 < lam <= 1.0):
            raise DataError(f"forgetting factor: expected 0 < λ <= 1, found {forgetting!r}",
                            hint="typical values are 0.95 ... 1 (memory of about 1/(1-λ) samples)")
        if windup not in _MODES:
            raise DataError(f"windup: expected one of {', '.join(_MODES)}, found {windup!r}")
        if not (math.isfinite(p0) and p0 > 0):
            raise DataError(f"p0: expected a positive initial covariance scale, found {p0!r}")
        p = self.na + self.nb
        if theta0 is None:
            theta0 = np.zeros(p)
        theta0 = np.asarray(theta0, dtype=np.float64)
        if theta0.shape != (p,) or not np.isfinite(theta0).all():
            raise DataError(f"theta0: expected {p} finite values (a1..a{self.na}, then {self.nb} B "
                            f"coefficients), found shape {theta0.shape}")
        maxtr = p * float(p0) if max_trace is None else float(max_trace)
        if not (maxtr > 0):
            raise DataError(f"max_trace: expected a positive number, found {max_trace!r}")
        self.forgetting = lam
        self.windup = windup
        self.dt = float(dt)
        self._p0 = float(p0)
        self._theta0 = theta0.copy()
        self._maxtr = maxtr
        # header, y and u buffers, θ, P, φ, q, backup of θ and P: see _rls_step
        self._s = np.zeros(_HDR + self.na + self.nk + self.nb + 2 * (p + p * p) + 2 * p)
        self._step = self._first_step  # the compiled step, fetched at the first update
        self.reset()

    def reset(self) -> None:
        """Back to θ0, P0 and empty buffers."""
        s = self._s
        s[:] = 0.0
        p = self.n_params
        s[_LAM] = self.forgetting
        s[_MODE] = _MODES[self.windup]
        s[_MAXTR] = self._maxtr
        s[_TRACE] = p * self._p0
        s[_NA], s[_NB], s[_NK] = self.na, self.nb, self.nk
        oth = self._oth
        s[oth:oth + p] = self._theta0
        P = s[oth + p:oth + p + p * p].reshape(p, p)
        P[np.diag_indices(p)] = self._p0

    @property
    def _oth(self) -> int:
        return _HDR + self.na + self.nk + self.nb

    @property
    def n_params(self) -> int:
        return self.na + self.nb

    @property
    def names(self) -> tuple[str, ...]:
        return (tuple(f"a{i}" for i in range(1, self.na + 1))
                + tuple(f"b{self.nk + j}" for j in range(self.nb)))

    def update(self, u: float, y: float) -> float:
        """Process one sample (input u(t), output y(t)); returns the a-priori prediction error.

        Raises :class:`DataError` for a NaN/inf or non-numeric sample or a corrupt one (a
        magnitude above :data:`ABSURD_JUMP` times the largest of its signal so far), and
        :class:`IdentificationError` when the update would make P or θ non-finite (divergence, or
        signals too large for P); either way the estimator is left as it was before the call.
        """
        if type(u) is float and type(y) is float:  # the common case: straight to the kernel
            e = self._step(self._s, u, y)
        else:
            e = self._update_other(u, y)
        if e != e:  # NaN: the kernel refused the sample and left the state unchanged
            self._refuse(u, y)
        return e

    def _first_step(self, s, u, y):
        """``self._step`` until the first call: fetches the step compiled for this structure
        (:func:`_step_entry`)."""
        self._step = _step_entry(self.na, self.nb, self.nk)
        return self._step(s, u, y)

    def _update_other(self, u, y):
        """:meth:`update` for samples that are not both Python floats: float subclasses (numpy
        float64) go to the compiled step too; other types through numba's dispatcher, which
        compiles a step for numeric types and refuses the rest."""
        if isinstance(u, float) and isinstance(y, float):
            return self._step(self._s, u, y)
        try:
            return _rls_step_any(self._s, u, y)
        except TypingError:
            raise DataError(f"RLS.update(u, y): expected two numbers, found {type(u).__name__} "
                            f"{u!r:.40} and {type(y).__name__} {y!r:.40}") from None

    def _refuse(self, u, y):
        status = self._s[_STATUS]
        self._s[_STATUS] = 0.0
        if status == 1.0:
            raise DataError(f"RLS.update: sample {self.n_samples} is not finite "
                            f"(u={u:.6g}, y={y:.6g}); "
                            f"the estimator is unchanged",
                            hint="skip or interpolate missing samples before passing them")
        if status == 4.0:
            pu = self._s[_PU]
            name, v, peak = ("u", u, pu) if 0.0 < pu < abs(u) / ABSURD_JUMP else \
                ("y", y, self._s[_PY])
            raise _absurd_sample(f"RLS.update: sample {self.n_samples}", name, v, peak,
                                 "the estimator is unchanged",
                                 "drop or repair the sample and go on with update(); if the signal "
                                 "truly changed scale that much, reset() the estimator")
        if status == 3.0:
            raise IdentificationError(
                f"RLS [{self.na} {self.nb} {self.nk}]: φᵀPφ overflows at sample {self.n_samples} "
                f"(u={u:.6g}, y={y:.6g}, trace P = {self._s[_TRACE]:.3g}): the regressor's "
                "values are too "
                f"large for float64 with this P; the estimator is unchanged",
                hint="scale u and y to order 1 (other units) and reset() the estimator")
        raise self._diverged(f"at update {self.n_updates + 1}; the estimator is left at "
                             "its last finite "
                             f"state (reset() it)")

    def _diverged(self, when: str) -> IdentificationError:
        return IdentificationError(
            f"RLS [{self.na} {self.nb} {self.nk}] diverged {when}: P or θ is no longer finite "
            f"(forgetting λ = {self.forgetting:g}, windup={self.windup!r}); the "
            "covariance wound up on "
            f"data that do not excite every direction",
            hint="use windup='trace' or 'directional', or a forgetting factor closer to 1")

    @property
    def n_samples(self) -> int:
        """Samples processed so far."""
        return int(self._s[_COUNT])

    @property
    def ready(self) -> bool:
        """True once enough samples arrived to form a regressor."""
        return self._s[_NUPD] > 0

    @property
    def n_updates(self) -> int:
        return int(self._s[_NUPD])

    @property
    def theta(self) -> np.ndarray:
        """Current estimate [a_1..a_na, b_nk..b_{nk+nb−1}] (a copy)."""
        return self._s[self._oth:self._oth + self.n_params].copy()

    @property
    def P(self) -> np.ndarray:
        """Current P matrix (symmetric positive definite), shape (p, p) (a copy)."""
        p = self.n_params
        o = self._oth + p
        return self._s[o:o + p * p].reshape(p, p).copy()

    @property
    def noise_variance(self) -> float | None:
        w1 = self._s[_W1]
        if self._s[_NUPD] <= self.n_params or w1 <= self.n_params:
            return None
        return float(self._s[_V] / (w1 - self.n_params))

    @property
    def covariance(self) -> np.ndarray | None:
        """Parameter covariance σ̂² P w₂/w₁ (see the module docstring), or None before p+1
        updates."""
        s2 = self.noise_variance
        if s2 is None:
            return None
        return s2 * self._s[_W2] / self._s[_W1] * self.P

    @property
    def theta_std(self) -> np.ndarray | None:
        c = self.covariance
        return None if c is None else np.sqrt(np.clip(np.diag(c), 0.0, None))

    def model(self, **meta) -> PolynomialModel:
        """The current estimate as a :class:`PolynomialModel` (with its covariance)."""
        th = self.theta
        A = np.concatenate([[1.0], th[:self.na]])
        B = np.concatenate([np.zeros(self.nk), th[self.na:]])
        return PolynomialModel(A, B, self.nk, dt=self.dt, structure="arx",
                               covariance=self.covariance,
                               noise_variance=self.noise_variance,
                               info={"method": f"recursive least squares (λ={self.forgetting:g}, "
                                               f"windup={self.windup})"}, **meta)

    def run(self, u, y, *, store: bool = True) -> "RLSResult":
        """Process a whole record from the current state (batch kernel); returns θ and σ at every
        step when ``store`` (else only the final values)."""
        u, y, scans = self._scanned(u, y)
        return self._run(u, y, store, scans)

    def _check_scale(self, u: np.ndarray, y: np.ndarray, peaks: tuple | None = None) -> None:
        """Refuse signals whose scale the recursion cannot represent next to the current P:

        * φᵀPφ <= ‖φ‖²·trace P must stay finite: ``p·max(|u|,|y|)²·trace P`` below the float64
        limit;
        * the data must outweigh the prior: the RLS estimate minimises
          ``Σe² + (θ − θ0)ᵀP0⁻¹(θ − θ0)``, so a parameter whose regressor energy ``Σφ_j²`` is below
          ``1/P_jj`` stays (more than half-way) at its prior value: θ0 returned as if estimated.
        """
        p = self.n_params
        P = self.P
        tr = float(np.trace(P))
        minmax = {"input u": (None if peaks is None else peaks[0]),
                  "output y": (None if peaks is None else peaks[1])}
        stats = {label: _peak(x, minmax[label]) for label, x in (("input u", u), ("output y", y))}
        peak = max(stats.values())
        if peak > 0 and math.log10(p) + 2 * math.log10(peak) + math.log10(tr) > 307.0:
            raise DataError(
                f"RLS [{self.na} {self.nb} {self.nk}]: values up to {peak:.3g} in u "
                "and y make φᵀPφ "
                f"overflow float64 (trace P = {tr:.3g}), so the recursion cannot run on them",
                hint="scale u and y to order 1 (other units); arx(), armax() and oe() "
                     "scale internally")
        for label, x, idx in (("output y", y, range(self.na)), ("input u", u, range(self.na, p))):
            if not len(idx):
                continue
            mx = stats[label]
            if mx == 0.0:
                raise IdentificationError(
                    f"RLS [{self.na} {self.nb} {self.nk}]: the {label} is zero throughout, so "
                    f"{', '.join(self.names[i] for i in idx)} cannot be estimated",
                    hint="check that the columns are the measured input and output")
            prior = float(np.max(np.diag(P)[list(idx)]))
            if 2 * math.log10(mx) + math.log10(prior) >= 0.0:
                continue  # Σx² ≥ max x²: the energy test below passes without the norm's pass
            log_energy = 2 * math.log10(_peak_and_norm(x, minmax[label])[1])
            if log_energy + math.log10(prior) < 0.0:
                names = ", ".join(self.names[i] for i in idx)
                raise IdentificationError(
                    f"RLS [{self.na} {self.nb} {self.nk}]: the {label} (values up to "
                    f"{mx:.3g}) carries "
                    f"almost no information next to the prior P = {prior:.3g}·I: Σ{label[-1]}² = "
                    f"10^{log_energy:.0f} is below 1/P, so {names} would stay at "
                    "their initial values",
                    hint="scale u and y to order 1 (other units), or raise p0 above "
                         f"1/Σ{label[-1]}²")

    def _scanned(self, u, y) -> tuple:
        """:func:`_scan_record` from the estimator's running peaks on."""
        return _scan_record(u, y, self._s[_PU], self._s[_PY])

    def _check_corrupt(self, u: np.ndarray, y: np.ndarray, scans: tuple) -> tuple[float, float]:
        """Refuse a record with a corrupt sample by the rule of :meth:`update` (a magnitude above
        :data:`ABSURD_JUMP` times every earlier one of its signal, from the estimator's running
        peaks on: ``scans`` of :meth:`_scanned`), so that ``run`` and a loop of ``update`` refuse
        the same records; returns the peaks of |u| and |y| at the end of the record."""
        for name, x, (i, peak, _, _, _) in (("u", u, scans[0]), ("y", y, scans[1])):
            if i >= 0:
                where = f"RLS [{self.na} {self.nb} {self.nk}]: sample {self.n_samples + i}"
                raise _absurd_sample(where, name, float(x[i]), peak, "the record was not processed",
                                     "drop or repair the sample (gripkit.signals.outliers."
                                     "corrupt_samples finds such values) and run again")
        return scans[0][1], scans[1][1]

    def _kernel_size(self, n: int) -> tuple:
        """The ``size`` argument of :func:`_rls_run`: the orders as tuple lengths (one compiled
        kernel per structure) for records of at least :data:`SPECIALISE_ABOVE` samples, else
        empty tuples (the generic kernel)."""
        if n < SPECIALISE_ABOVE:
            return (), (), (), ()
        return (0.0,) * self.n_params, (0.0,) * self.na, (0.0,) * self.nb, (0.0,) * self.nk

    def _run(self, u: np.ndarray, y: np.ndarray, store: bool, scans: tuple) -> "RLSResult":
        """:meth:`run` on the arrays and ``scans`` of :meth:`_scanned` (their corrupt-sample
        index, peaks, min and max: no more passes over the data before the kernel's)."""
        peaks = self._check_corrupt(u, y, scans)
        self._check_scale(u, y, tuple((sc[2], sc[3]) for sc in scans))
        n = u.size
        p = self.n_params
        rows = n if store else 0
        theta = np.empty((rows, p))
        std = np.empty((rows, p))
        # ŷ and e as the two rows of one block: glibc keeps a freed block of up to 16 MB (N = 10⁶)
        # on its heap for the next call, where two 8 MB arrays were often handed back to the
        # system and faulted in again (docs/performance.md, "Issue 24: RLS with history")
        yhat, e = np.empty((2, n))
        n0 = self.n_updates
        sum_e2 = _rls_run(self._s, u, y, theta, std, yhat, e, self._kernel_size(n))
        self._s[_PU], self._s[_PY] = peaks
        if not (np.isfinite(self.P).all() and np.isfinite(self.theta).all()):
            raise self._diverged(f"after {self.n_updates} updates")
        nupd = self.n_updates - n0
        if nupd == 0:
            raise DataError(f"RLS [{self.na} {self.nb} {self.nk}] made no update on {n} samples",
                            hint="give a record longer than the model's initial samples")
        loss = 0.5 * sum_e2 / nupd
        return RLSResult(names=self.names, na=self.na, nb=self.nb, nk=self.nk, dt=self.dt,
                         forgetting=self.forgetting, windup=self.windup,
                         theta=theta if store else None, theta_std=std if store else None,
                         y_pred=yhat, errors=e, first_update=n - nupd, loss=loss,
                         theta_final=self.theta, theta_std_final=self.theta_std,
                         covariance_final=self.covariance, P_final=self.P, model=self.model())


def _absurd_sample(where: str, name: str, value: float, peak: float, state: str,
                   hint: str) -> DataError:
    """The error for a corrupt sample ``value`` of signal ``name`` after a running peak ``peak``."""
    return DataError(
        f"{where} has {name} = {value:.6g}, {abs(value) / peak:.2g} times the largest |{name}| "
        f"before it ({peak:.6g}): a corrupt sample (a spike, a logger's sentinel, a parse error), "
        f"which would throw θ far off for good; {state}", hint=hint)


#: samples per block of :func:`_scan_signal` (a multiple of 4)
_ABSURD_BLOCK = 256


@njit(cache=True)
def _scan_signal(x, peak, factor):
    """One pass over a non-empty signal for :meth:`RLS.run`: ``(bad, peak, lo, hi, finite)``: the
    index of the first sample above ``factor`` times the largest |x| before it (from the running
    peak ``peak`` on: the test of :func:`_rls_step`) or −1, the largest |x| up to there, min and
    max of x, and whether every sample is finite (min, max and ``finite`` cover the whole signal
    only when ``bad`` is −1: the scan stops at a corrupt sample).

    By blocks, in four lanes: min, max, the largest |x| and Σ x·0 (NaN where a sample is NaN or
    ±inf; the comparisons skip NaN, as the sample rule does). While ``peak > 0``, a block whose
    largest |x| is at most ``factor·peak`` holds no corrupt sample (every later running peak is at
    least ``peak``) and its largest |x| updates the peak; other blocks go sample by sample. The
    same index and peak as the plain sample loop, in one pass instead of three (numpy's min and
    max, then the corrupt-sample scan)."""
    n = x.shape[0]
    lo = x[0]
    hi = x[0]
    probe = 0.0
    for i in range(0, n, _ABSURD_BLOCK):
        stop = min(i + _ABSURD_BLOCK, n)
        if stop - i == _ABSURD_BLOCK:
            m0 = m1 = m2 = m3 = 0.0
            l0 = l1 = l2 = l3 = lo
            h0 = h1 = h2 = h3 = hi
            p0 = p1 = p2 = p3 = 0.0
            for k in range(i, stop, 4):
                v0, v1, v2, v3 = x[k], x[k + 1], x[k + 2], x[k + 3]
                a0, a1, a2, a3 = abs(v0), abs(v1), abs(v2), abs(v3)
                m0 = a0 if a0 > m0 else m0
                m1 = a1 if a1 > m1 else m1
                m2 = a2 if a2 > m2 else m2
                m3 = a3 if a3 > m3 else m3
                l0 = v0 if v0 < l0 else l0
                l1 = v1 if v1 < l1 else l1
                l2 = v2 if v2 < l2 else l2
                l3 = v3 if v3 < l3 else l3
                h0 = v0 if v0 > h0 else h0
                h1 = v1 if v1 > h1 else h1
                h2 = v2 if v2 > h2 else h2
                h3 = v3 if v3 > h3 else h3
                p0 += v0 * 0.0
                p1 += v1 * 0.0
                p2 += v2 * 0.0
                p3 += v3 * 0.0
            m = max(max(m0, m1), max(m2, m3))
            lo = min(min(l0, l1), min(l2, l3))
            hi = max(max(h0, h1), max(h2, h3))
            probe += (p0 + p1) + (p2 + p3)
        else:  # a short last block: its extremes, then sample by sample
            m = np.inf
            for k in range(i, stop):
                v = x[k]
                lo = v if v < lo else lo
                hi = v if v > hi else hi
                probe += v * 0.0
        if peak > 0.0 and m <= factor * peak:  # (NaN never reaches m)
            if m > peak:
                peak = m
            continue
        for k in range(i, stop):
            a = abs(x[k])
            if a > peak:
                if peak > 0.0 and a > factor * peak:
                    return k, peak, lo, hi, False
                peak = a
    return -1, peak, lo, hi, probe == 0.0


def _scan_record(u, y, pu: float, py: float) -> tuple:
    """``u`` and ``y`` as 1-D float64 arrays of one length, finite (else the
    :func:`~gripkit.sysid.checks.signal_with_peaks` error), with their :func:`_scan_signal` from
    the running peaks ``pu`` and ``py`` on: ``(u, y, (scan of u, scan of y))``."""
    u, y = check_io_arrays(u, y)
    scans = (_scan_signal(u, pu, ABSURD_JUMP), _scan_signal(y, py, ABSURD_JUMP))
    for x, name, scan in ((u, "input u", scans[0]), (y, "output y", scans[1])):
        if not scan[4]:  # not finite, or the scan stopped at a corrupt sample
            signal_with_peaks(x, name)  # raises for a NaN or an inf anywhere
    return u, y, scans


#: peaks within these bounds square and sum without overflow (N·peak² < 1e290 for N < 1e10)
#: and with the underflow of values below 1e-150 negligible next to peak² ≥ 1e-280
_PLAIN_NORM_RANGE = (1e-140, 1e140)


def _peak(x, minmax: tuple[float, float] | None = None) -> float:
    """max |x| (from ``minmax`` = (min, max) when known)."""
    if x.size == 0:
        return 0.0
    lo, hi = (float(x.min()), float(x.max())) if minmax is None else minmax
    return max(hi, -lo)


def _peak_and_norm(x, minmax: tuple[float, float] | None = None):
    """(max |x|, ‖x‖₂) without temporaries: max/min and a BLAS dot (fast) when the peak lies in
    :data:`_PLAIN_NORM_RANGE`, else :func:`_peak_and_norm_scaled` (one pass scaled by the running
    peak). The dot sums in another order than the scaled pass: the norms agree to a few ulps,
    which only feed the order-of-magnitude checks of :meth:`RLS._check_scale`."""
    peak = _peak(x, minmax)
    if peak == 0.0:
        return 0.0, 0.0
    if _PLAIN_NORM_RANGE[0] < peak < _PLAIN_NORM_RANGE[1]:
        return peak, math.sqrt(float(np.dot(x, x)))
    return _peak_and_norm_scaled(x)


@njit(cache=True)
def _peak_and_norm_scaled(x):
    """(max |x|, ‖x‖₂) in one pass without temporaries; the norm is scaled by the running peak
    (the LAPACK dnrm2 way), so it neither overflows nor underflows."""
    peak = 0.0
    ssq = 1.0
    for v in x:
        a = abs(v)
        if a > peak:
            ssq = 1.0 + ssq * (peak / a) ** 2
            peak = a
        elif a > 0.0:
            ssq += (a / peak) ** 2
    return peak, (peak * math.sqrt(ssq) if peak > 0.0 else 0.0)


@dataclass(frozen=True, eq=False)
class RLSResult:
    """Result of :func:`rls` / :meth:`RLS.run`.

    Attributes
    ----------
    names
        Parameter names a1..a_na, b_nk..b_{nk+nb−1} (order of ``theta`` columns).
    theta, theta_std
        θ(t) and σ(t) after each sample, shape (N, p) (σ is NaN until p+1 updates), or None.
    y_pred, errors
        A-priori one-step prediction ŷ(t|t−1) and error y − ŷ (ŷ = y, e = 0 before
        ``first_update``).
    loss
        Eq (29) over the a-priori errors from ``first_update`` on.
    theta_final, theta_std_final, covariance_final, P_final
        Final estimate, its σ and covariance, and the final P.
    model
        Final estimate as a :class:`PolynomialModel`.
    """

    names: tuple[str, ...]
    na: int
    nb: int
    nk: int
    dt: float
    forgetting: float
    windup: str
    theta: np.ndarray | None
    theta_std: np.ndarray | None
    y_pred: np.ndarray
    errors: np.ndarray
    first_update: int
    loss: float
    theta_final: np.ndarray
    theta_std_final: np.ndarray | None
    covariance_final: np.ndarray | None
    P_final: np.ndarray
    model: PolynomialModel

    @property
    def n_samples(self) -> int:
        return int(self.y_pred.size)

    def to_dict(self) -> dict:
        m = self.model
        return dict(structure="arx-rls", na=self.na, nb=self.nb, nk=self.nk,
                    forgetting=self.forgetting,
                    windup=self.windup, parameter_names=list(self.names),
                    theta_final=self.theta_final.tolist(),
                    theta_std_final=None if self.theta_std_final is None
                    else self.theta_std_final.tolist(),
                    A=m.A.tolist(), B=m.B.tolist(),
                    A_std=None if m.A_std is None else m.A_std.tolist(),
                    B_std=None if m.B_std is None else m.B_std.tolist(), loss=self.loss,
                    poles=[[float(z.real), float(z.imag)] for z in m.poles()],
                    zeros=[[float(z.real), float(z.imag)] for z in m.zeros()],
                    minimum_phase=m.minimum_phase, n_samples=self.n_samples, dt=self.dt)

    def to_trajectory(self, t0: float = 0.0):
        """θ(t), σ(t), ŷ(t) and e(t) as a :class:`~gripkit.signals.Trajectory` (to save as
        Parquet/CSV/HDF5)."""
        if self.theta is None:
            raise DataError("this RLS result kept no history (run with store=True)")
        t = t0 + np.arange(self.n_samples) * self.dt
        first_sigma = self.first_update + len(self.names) + 1
        ch = {}
        for i, n in enumerate(self.names):
            ch[n] = self.theta[:, i]
        for i, n in enumerate(self.names):  # σ undefined before p+1 updates: start the file there
            ch[f"{n}_std"] = self.theta_std[:, i]
        ch["y_pred"] = self.y_pred
        ch["error"] = self.errors
        keep = slice(min(first_sigma, self.n_samples - 1), None)
        return Trajectory(t[keep], {k: v[keep] for k, v in ch.items()},
                          meta={"dt": self.dt, "forgetting": self.forgetting,
                                "structure": f"ARX [{self.na} {self.nb} {self.nk}]"})


@entry_point
def rls(u, y, na: int, nb: int, nk: int = 1, *, forgetting: float = 1.0, p0: float = 1e4,
        theta0=None,
        windup: str = "trace", max_trace: float | None = None, dt: float | None = None,
        store: bool = True) -> RLSResult:
    """Recursive least squares over a record (numba batch kernel): θ and σ at every step.

    Parameters as :class:`RLS`; ``u``, ``y`` of shape (N,). Raises :class:`DataError` for bad
    data or too few samples and :class:`~gripkit.errors.UnidentifiableError` for a constant input.
    """
    u, y, scans = _scan_record(u, y, 0.0, 0.0)  # one pass per signal for all the checks
    est = RLS(na, nb, nk, forgetting=forgetting, p0=p0, theta0=theta0, windup=windup,
              max_trace=max_trace, dt=check_dt(dt))
    t0 = max(est.na, est.nk + est.nb - 1)
    p = est.n_params
    require_samples(u.size, t0 + p + 1, f"RLS ARX [{est.na} {est.nb} {est.nk}] ({p} parameters)")
    if scans[0][0] < 0:  # (else min and max stop at the corrupt sample: that error comes first)
        check_excitation(u, peaks=scans[0][2:4])
    return est._run(u, y, store, scans)
