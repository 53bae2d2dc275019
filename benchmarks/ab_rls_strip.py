"""Which piece of gripkit's batch RLS kernel costs time on a given CPU: the plain RLS loop of
``ab_rls_kernel`` (P, θ, φ and q in one buffer at constant offsets, p = 6 known to the compiler)
built with gripkit's pieces switched on one at a time:

* ``yhat``: how the a-priori error is formed. ``"plain"``: ``e = y; e -= φᵢθᵢ`` inside the q
  loop (the plain loop); ``"separate"``: ``ŷ = Σ φᵢθᵢ`` in a loop of its own before q, then
  ``e = y − ŷ`` (gripkit's arithmetic and order); ``"fused"``: gripkit's arithmetic (ŷ summed in
  the same order, ``e = y − ŷ``) inside the q loop.
* ``stats``: the noise-variance sums V, w₁, w₂ and the update count (σ needs them).
* ``trace``: trace P summed during the P update (gripkit's trace bound and state need it).

Each variant is a closure whose flags numba compiles as constants; [3 3 1], N = 1e6, λ = 0.999,
9 alternating runs each (``measure_alternating``), wall and thread CPU time; beside them gripkit's
compiled batch kernel itself (specialised for p, no ŷ/e, no history). Prints the largest θ
difference of every variant against gripkit's kernel (0 where the arithmetic is the same).

    PYTHONPATH=src python benchmarks/ab_rls_strip.py
"""

from __future__ import annotations

import math
import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import bench_rls as B  # noqa: E402
import numpy as np  # noqa: E402
from common import print_alternating  # noqa: E402
from numba import njit  # noqa: E402

P6 = 6


def make_variant(yhat: str, stats: bool, trace: bool):
    """The plain one-buffer RLS with the chosen pieces of gripkit's kernel (module docstring)."""
    sep, fused = yhat == "separate", yhat == "fused"

    @njit
    def run(u, y, lam, p0):  # pragma: no cover - compiled
        n = u.shape[0]
        oP, oth, oph, oq = 0, 36, 42, 48
        w = np.zeros(54)
        for i in range(P6):
            w[oP + i * P6 + i] = p0
        V, w1, w2, nupd, tr = 0.0, 0.0, 0.0, 0.0, 0.0
        for t in range(3, n):
            for i in range(3):
                w[oph + i] = -y[t - 1 - i]
                w[oph + 3 + i] = u[t - 1 - i]
            yh = 0.0
            if sep:
                for i in range(P6):
                    yh += w[oph + i] * w[oth + i]
            e = y[t]
            for i in range(P6):
                acc = 0.0
                for j in range(P6):
                    acc += w[oP + i * P6 + j] * w[oph + j]
                w[oq + i] = acc
                if fused:
                    yh += w[oph + i] * w[oth + i]
                elif not sep:
                    e -= w[oph + i] * w[oth + i]
            if sep or fused:
                e = y[t] - yh
            r = 0.0
            for i in range(P6):
                r += w[oph + i] * w[oq + i]
            inv = 1.0 / (lam + r)
            coef, scale = -inv, 1.0 / lam
            g = e * inv
            for i in range(P6):
                w[oth + i] += w[oq + i] * g
            tr = 0.0
            for i in range(P6):
                qi = coef * w[oq + i]
                for j in range(i, P6):
                    v = (w[oP + i * P6 + j] + qi * w[oq + j]) * scale
                    w[oP + i * P6 + j] = v
                    w[oP + j * P6 + i] = v
                if trace:
                    tr += w[oP + i * P6 + i]
            if stats:
                V = lam * (V + e * e / (lam + r))
                w1 = lam * w1 + 1.0
                w2 = lam * lam * w2 + 1.0
                nupd += 1.0
        out = w[oth:oth + P6].copy()
        out[0] += 0.0 * (V + w1 + w2 + nupd + tr)  # keep the sums live
        return out

    return run


VARIANTS = {
    "plain": ("plain", False, False),
    "+ stats": ("plain", True, False),
    "+ trace": ("plain", False, True),
    "+ separate ŷ loop": ("separate", False, False),
    "+ fused ŷ (gripkit arithmetic)": ("fused", False, False),
    "+ stats + trace": ("plain", True, True),
    "all, separate ŷ loop (as gripkit)": ("separate", True, True),
    "all, fused ŷ": ("fused", True, True),
}


def make_framed(flags: str, mid_std: bool):
    """The full replica (fused ŷ, stats, trace) inside gripkit's framing: θ, σ, ŷ and e written
    to output arrays when they have N rows. ``flags``: ``"runtime"`` (store / predict read from
    the arrays' shapes, as gripkit's loop does) or ``"store"`` / ``"none"`` (compiled in as
    constants). ``mid_std``: σ of the previous step written between the two halves of the update
    (gripkit's order) instead of at the end of each step."""
    const = flags != "runtime"
    cstore = flags == "store"

    @njit
    def run(u, y, lam, p0, th_out, std_out, yh_out, e_out):  # pragma: no cover - compiled
        n = u.shape[0]
        store = cstore if const else th_out.shape[0] == n
        pred = False if const else yh_out.shape[0] == n
        oP, oth, oph, oq = 0, 36, 42, 48
        w = np.zeros(54)
        for i in range(P6):
            w[oP + i * P6 + i] = p0
        V, w1, w2, nupd, tr, f = 0.0, 0.0, 0.0, 0.0, 0.0, np.nan
        for t in range(3, n):
            for i in range(3):
                w[oph + i] = -y[t - 1 - i]
                w[oph + 3 + i] = u[t - 1 - i]
            yh = 0.0
            for i in range(P6):
                acc = 0.0
                for j in range(P6):
                    acc += w[oP + i * P6 + j] * w[oph + j]
                w[oq + i] = acc
                yh += w[oph + i] * w[oth + i]
            e = y[t] - yh
            r = 0.0
            for i in range(P6):
                r += w[oph + i] * w[oq + i]
            inv = 1.0 / (lam + r)
            coef, scale = -inv, 1.0 / lam
            g = e * inv
            if mid_std and store and t > 3:
                for i in range(P6):
                    std_out[t - 1, i] = math.sqrt(f * w[oP + i * P6 + i])
            for i in range(P6):
                w[oth + i] += w[oq + i] * g
            tr = 0.0
            for i in range(P6):
                qi = coef * w[oq + i]
                for j in range(i, P6):
                    v = (w[oP + i * P6 + j] + qi * w[oq + j]) * scale
                    w[oP + i * P6 + j] = v
                    w[oP + j * P6 + i] = v
                tr += w[oP + i * P6 + i]
            V = lam * (V + e * e / (lam + r))
            w1 = lam * w1 + 1.0
            w2 = lam * lam * w2 + 1.0
            nupd += 1.0
            if pred:
                yh_out[t] = yh
                e_out[t] = y[t] - yh
            if store:
                f = V / (w1 - P6) * (w2 / w1) if (nupd > P6 and w1 > P6) else np.nan
                for i in range(P6):
                    th_out[t, i] = w[oth + i]
                if not mid_std:
                    for i in range(P6):
                        std_out[t, i] = math.sqrt(f * w[oP + i * P6 + i])
        out = w[oth:oth + P6].copy()
        out[0] += 0.0 * (V + w1 + w2 + nupd + tr)
        return out

    return run


def make_halves_kernel():
    """gripkit's batch kernel as it was before the Intel measurements: the same framing, with the
    update made by calls to the streaming step's inlined halves ``_gain`` and ``_apply`` instead of
    written out in the loop (same arithmetic; bound into ``_rls_run``'s own source, no copy)."""
    import types

    from gripkit.sysid.linear import rls

    @njit(inline="always")
    def loop(w, size, io, run, state, mode):  # pragma: no cover - compiled
        u, y, theta_out, std_out, yhat_out, err_out = io
        at, dims, lam, maxtr, nstart, store, pred = run
        trace, V, w1, w2, nupd, f, loss = state
        p, na, nb, nk = len(size[0]), len(size[1]), len(size[2]), len(size[3])
        for t in range(nstart, u.shape[0]):
            for i in range(na):
                w[at[2] + i] = -y[t - 1 - i]
            for j in range(nb):
                w[at[2] + na + j] = u[t - nk - j]
            e, r, coef, scale, g, _ = rls._gain(w, at, p, size[0], lam, mode, trace, y[t], False)
            if store and t > nstart:
                for i in range(p):
                    std_out[t - 1, i] = math.sqrt(f * w[at[0] + i * p + i])
            trace = rls._apply(w, at, p, size[0], mode, maxtr, coef, scale, g)
            V = lam * (V + e * e / (lam + r))
            w1 = lam * w1 + 1.0
            w2 = lam * lam * w2 + 1.0
            nupd += 1.0
            yh = y[t] - e
            loss += (y[t] - yh) * (y[t] - yh)
            if pred:
                yhat_out[t] = yh
                err_out[t] = y[t] - yh
            if store:
                f = V / (w1 - p) * (w2 / w1) if (nupd > p and w1 > p) else np.nan
                for i in range(p):
                    theta_out[t, i] = w[at[1] + i]
        return trace, V, w1, w2, nupd, f, loss

    glb = dict(rls._rls_run.py_func.__globals__, _batch_loop=loop)
    return njit(types.FunctionType(rls._rls_run.py_func.__code__, glb, "_rls_run_halves"))


def main() -> None:
    from gripkit.sysid import RLS
    from gripkit.sysid.linear.rls import _rls_run

    n = 1_000_000
    u, y = B._data(n)
    est = RLS(3, 3, 1, forgetting=B.LAM, p0=B.P0, windup="none")
    s0 = est._s.copy()
    none, none1 = np.empty((0, 6)), np.empty(0)
    kernels = {name: make_variant(*flags) for name, flags in VARIANTS.items()}
    fns = {name: (lambda k=k: k(u, y, B.LAM, B.P0)) for name, k in kernels.items()}
    hist = np.empty((n, 6)), np.empty((n, 6))
    for flags, mid, store in (("runtime", True, False), ("none", True, False),
                              ("runtime", True, True), ("store", True, True),
                              ("runtime", False, True), ("store", False, True)):
        k = make_framed(flags, mid)
        outs = hist if store else (none, none)
        name = (f"framed, flags {flags}, σ {'mid-step' if mid else 'at end'}"
                f"{', history' if store else ''}")
        fns[name] = lambda k=k, outs=outs: k(u, y, B.LAM, B.P0, *outs, none1, none1)

    halves = make_halves_kernel()

    def gripkit_halves(store):
        s = s0.copy()
        outs = hist if store else (none, none)
        halves(s, u, y, *outs, none1, none1, est._kernel_size(n))
        return s[est._oth:est._oth + 6]

    fns["gripkit kernel through the halves (before)"] = lambda: gripkit_halves(False)
    fns["gripkit kernel through the halves, history"] = lambda: gripkit_halves(True)

    def gripkit_history():
        s = s0.copy()
        _rls_run(s, u, y, hist[0], hist[1], none1, none1, est._kernel_size(n))
        return s[est._oth:est._oth + 6]

    def gripkit_kernel(size):
        s = s0.copy()
        _rls_run(s, u, y, none, none, none1, none1, size)
        return s[est._oth:est._oth + 6]

    fns["gripkit kernel, specialised"] = lambda: gripkit_kernel(est._kernel_size(n))
    fns["gripkit kernel, generic (p at run time)"] = lambda: gripkit_kernel(((), (), (), ()))
    fns["gripkit kernel, specialised, history"] = gripkit_history
    s1, s2 = s0.copy(), s0.copy()
    h1, h2 = (np.empty((n, 6)), np.empty((n, 6))), (np.empty((n, 6)), np.empty((n, 6)))
    _rls_run(s1, u, y, *h1, none1, none1, est._kernel_size(n))
    halves(s2, u, y, *h2, none1, none1, est._kernel_size(n))
    print("update through the halves against gripkit's kernel: state, θ, σ history identical:",
          np.array_equal(s1, s2) and np.array_equal(h1[0], h2[0])
          and np.array_equal(h1[1], h2[1], equal_nan=True))
    ref = gripkit_kernel(est._kernel_size(n))
    for name, fn in fns.items():
        print(f"max |θ − gripkit| {name:42s} {np.max(np.abs(fn() - ref)):.3g}")
    print_alternating(fns)


if __name__ == "__main__":
    main()
