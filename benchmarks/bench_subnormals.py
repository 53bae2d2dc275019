"""Subnormal numbers in carried-state kernels: each kernel timed with the CPU's flush-to-zero
(FTZ) and denormals-are-zero (DAZ) bits cleared (the default) and set, alternating, in one
process (benchmarks/mxcsr.py sets them through a small C helper compiled at run time).

A free response x ← A x of a stable A sinks below 2.2e-308 and stays there; on Intel CPUs every
multiply with a subnormal operand then takes a microcode assist (issue 24: 662 ms against 46 ms
for the B/D/x0 normal equations at N = 1e5). The kernels now flush carried entries below 1e-280
(gripkit.lti.flush_tiny), so their time must not depend on FTZ/DAZ: ratio ≈ 1.00 on any CPU.
The row "without flushing" runs a copy of the B/D/x0 kernel as it was before the fix: on AMD
(subnormals cost little) its ratio stays near 1, on Intel it shows the assist cost. Results name
the CPU model (results file header) because the effect is vendor-specific. Serial kernels only:
MXCSR is per thread, and numba's worker threads do not inherit it.
"""

from __future__ import annotations

import numba
import numpy as np
from common import measure_alternating, row

from gripkit.sysid.linear.blocked_gram import add_rows, carried_states, row_product, start_sums

N = 100_000
TARGET = "FTZ/DAZ set ≈ cleared (ratio 0.9–1.1)"


@numba.njit(cache=True)
def _bdx_unflushed(A, C, u, y, G, r):  # pragma: no cover - compiled
    """The B/x0 normal equations of gripkit.sysid.linear.subspace._bdx_normal_equations (no D) as
    they
    were before the flush: the carried state copied as is."""
    N, m = u.shape
    n, p = A.shape[0], C.shape[0]
    nb = n * m
    ns = nb + n
    X, Xn = carried_states(n, ns, nb, n)
    rows, yb = start_sums(256 * p, ns, G, r)
    fill = 0
    CX = np.empty(ns)
    for t in range(N):
        for row_ in range(p):
            row_product(C, row_, X, CX)
            phi = rows[fill]
            for c in range(ns):
                phi[c] = CX[c]
            yb[fill] = y[t, row_]
            fill += 1
        if fill == rows.shape[0] or t == N - 1:
            add_rows(rows, yb, fill, G, r)
            fill = 0
        for i in range(n):
            row_product(A, i, X, Xn[i])
            for j in range(m):
                Xn[i, i * m + j] += u[t, j]
        for i in range(n):
            for c in range(ns):
                X[i, c] = Xn[i, c]
    return X


def _pair(fn):
    """fn run with FTZ/DAZ cleared and set: two callables for measure_alternating."""
    from mxcsr import flush_denormals

    def cleared():
        with flush_denormals(False):
            return fn()

    def set_():
        with flush_denormals(True):
            return fn()
    return cleared, set_


def _subnormals(a) -> int:
    a = np.asarray(a)
    return int(np.count_nonzero((a != 0) & (np.abs(a) < np.finfo(np.float64).tiny)))


def run(quick: bool) -> list[dict]:
    """Rows for the B/D/x0 normal equations (flushed and, as before, unflushed), the PEM
    sensitivity Gram and a free-response simulation, FTZ/DAZ cleared (gripkit column) against
    set (peer column); ``quick`` changes nothing."""
    from bench_subspace import HORIZON, ORDER, _record, _system
    from mxcsr import available, cpu_model

    ok, why = available()
    if not ok:  # pragma: no cover - x86-64 Linux with a C compiler here
        return [row("subnormals", "FTZ/DAZ set vs cleared", None, "", None,
                    notes=f"not run: {why}")]
    from gripkit.lti import simulate_ss
    from gripkit.sysid import n4sid
    from gripkit.sysid.linear.pem_ss import _directions, _predict_states, _sensitivity_gram
    from gripkit.sysid.linear.subspace import _bdx_normal_equations

    g = _system()
    u, y = _record(g, N, 1)
    model = n4sid(u, y, ORDER, horizon=HORIZON)
    s = model.system
    A, C = np.ascontiguousarray(s.A), np.ascontiguousarray(s.C)
    n, m, p = A.shape[0], u.shape[1], C.shape[0]
    cpu = cpu_model()
    rows = []

    def add(task, fn, final, notes):
        t_clear, t_set = measure_alternating(list(_pair(fn)))
        rows.append(row("subnormals", f"{task}, N=1e5", t_clear, "same kernel with FTZ/DAZ set",
                        t_set, target=TARGET, notes=f"{notes}; CPU: {cpu}",
                        extra={"subnormal_entries_in_final_state": _subnormals(final), "cpu": cpu}))

    cols = n * m + n
    G, r = np.empty((cols, cols)), np.empty(cols)
    bdx = lambda: _bdx_normal_equations(A, C, u, y, False, G, r)  # noqa: E731
    add("B/x0 normal equations (subspace._bdx_normal_equations), order 8, 2×2", bdx, bdx(),
        "flushes carried entries below 1e-280")
    G2, r2 = np.empty((cols, cols)), np.empty(cols)
    old = lambda: _bdx_unflushed(A, C, u, y, G2, r2)  # noqa: E731
    add("the same B/x0 kernel without flushing (before issue 24)", old, old(),
        f"reference copy in this file; sums equal to the flushed kernel's: {np.array_equal(G, G2)}")
    for form, K in (("oe", np.zeros((n, p))), ("innovation", model.K / 1.0)):
        Kw = np.ascontiguousarray(K)
        B, D, x0 = s.B, np.zeros((p, m)), np.zeros(n) if model.x0 is None else model.x0
        *_, ent = _directions(A, B, C, D, Kw, False, form == "innovation")
        e, X = np.empty((N, p)), np.empty((N, n))
        _predict_states(A, B, C, D, Kw, x0, u, y, e, X)
        Q = ent.shape[0] + n
        H, gv = np.empty((Q, Q)), np.empty(Q)
        Abar = np.ascontiguousarray(A - Kw @ C)
        gram = lambda: _sensitivity_gram(Abar, C, Kw, ent, n, X, u, e, H, gv)  # noqa: E731
        add(f"PEM sensitivity Gram ({form}, pem_ss._sensitivity_gram), {Q} directions", gram,
            gram(), "flushes carried entries below 1e-280")
    x = np.empty(n)
    yo = np.empty((N, p))
    z = np.zeros((N, 1))

    def free():
        x[:] = 1.0
        simulate_ss(A, np.zeros((n, 1)), C, np.zeros((p, 1)), z, x, np.empty(n), yo)
        return x
    add("free response (lti.simulate_ss, as in estimate_x0's O[t] = C Aᵗ)", free, free().copy(),
        "flushes carried entries below 1e-280")
    return rows


if __name__ == "__main__":
    import json

    for r in run(quick=True):
        print(json.dumps(r, default=str))
