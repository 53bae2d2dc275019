"""Issue 24's two remaining rows, each side by side with its peer in one process:

* batch RLS [3 3 1], N = 10⁶, with θ and σ history (``rls()``) and without
  (``RLS.run(store=False)``), and the streaming ``RLS.update``, beside the plain numba RLS of
  ``bench_rls.py`` (target: peer time / gripkit time ≥ 0.9);
* the one-state mass matrix of the DLR/HIT finger without ``out=`` (``chain.mass_matrix(p)``, a
  new array per call) and with it, beside ``pin.crba`` (fills ``data.M`` and returns a new array
  copied from it; target: gripkit / pin ≤ 1.1), and the kernel through numba's dispatcher into
  an ``np.empty`` per call (the wrapper before issue 24's follow-up).

``python benchmarks/ab_rls_crba.py [rounds]``: every round runs each callable once in turn (after
one warm-up call each, garbage collection off, BLAS on one thread), timed by the wall clock and
by this thread's CPU time; printed are median and min per callable and, per row, the median over
rounds of the per-round ratio (both sides of a ratio ran in the same round, seconds apart) and
the ratio of the minima. The CPU model is ``lscpu``'s.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import datetime as dt  # noqa: E402
import gc  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).parents[1] / "src"))

from bench_rls import LAM, P0, _data, _plain_rls, streaming_calls  # noqa: E402

CLOCKS = {"wall": time.perf_counter, "cpu": time.thread_time}


def cpu_model() -> str:
    """``Model name`` from ``lscpu`` (/proc/cpuinfo where lscpu is missing)."""
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        out = Path("/proc/cpuinfo").read_text()
    for line in out.splitlines():
        if line.lower().startswith("model name"):
            return line.split(":", 1)[1].strip()
    return "?"


def rounds(fns: dict, n_rounds: int, per_call: int = 1) -> dict:
    """{name: {clock: [seconds per call, one per round]}}, the callables in turn each round."""
    for fn in fns.values():
        fn()
    out = {k: {c: [] for c in CLOCKS} for k in fns}
    gc.collect()
    gc.disable()
    try:
        for _ in range(n_rounds):
            for k, fn in fns.items():
                w0, c0 = time.perf_counter(), time.thread_time()
                fn()
                c1, w1 = time.thread_time(), time.perf_counter()
                out[k]["wall"].append((w1 - w0) / per_call)
                out[k]["cpu"].append((c1 - c0) / per_call)
    finally:
        gc.enable()
    return out


def _fmt(s: float) -> str:
    return f"{s * 1e3:7.2f} ms" if s >= 1e-4 else f"{s * 1e9:6.0f} ns"


def report(t: dict, pairs: list, peer_over_gripkit: bool) -> list[str]:
    lines = [f"{'':34s}" + "".join(f"{c + ' median':>13s}{c + ' min':>11s}" for c in CLOCKS)]
    for k, v in t.items():
        lines.append(f"{k:34s}" + "".join(f"{_fmt(statistics.median(v[c])):>13s}"
                                          f"{_fmt(min(v[c])):>11s}" for c in CLOCKS))
    for a, b, what in pairs:
        parts = []
        for c in CLOCKS:
            num, den = (t[b][c], t[a][c]) if peer_over_gripkit else (t[a][c], t[b][c])
            r = statistics.median(x / y for x, y in zip(num, den))
            parts.append(f"{c}: median of ratios {r:.3f}, "
                         f"ratio of minima {min(num) / min(den):.3f}")
        lines.append(f"{what}: " + "; ".join(parts))
    return lines


def rls_rows(n_rounds: int) -> list[str]:
    from gripkit.sysid import RLS, rls

    n = 1_000_000
    u, y = _data(n)
    res = rls(u, y, 3, 3, 1, forgetting=LAM, p0=P0, windup="none")
    hist = (np.empty((n, 6)), np.empty((n, 6)))
    th, _ = _plain_rls(u, y, LAM, P0, *hist)
    none = np.empty((0, 6))
    k = 200_000
    stream, plain_stream = streaming_calls(u, y, k)

    batch = {"rls() with θ, σ history": lambda: rls(u, y, 3, 3, 1, forgetting=LAM, p0=P0,
                                                      windup="none"),
             "plain numba RLS, history": lambda: _plain_rls(u, y, LAM, P0, np.empty((n, 6)),
                                                            np.empty((n, 6))),
             "RLS.run(store=False)": lambda: RLS(3, 3, 1, forgetting=LAM, p0=P0,
                                                 windup="none").run(u, y, store=False),
             "plain numba RLS, no history": lambda: _plain_rls(u, y, LAM, P0, none, none)}
    lines = [f"## batch RLS [3 3 1], N = {n:.0e}, windup='none', λ = {LAM} ({n_rounds} rounds)",
             f"accuracy: max |θ_N − θ_plain| = {np.max(np.abs(res.theta_final - th)):.1e}, "
             f"max |σ − σ_plain| over the history = "
             f"{np.nanmax(np.abs(res.theta_std[10:] - hist[1][10:])):.1e}"]
    lines += report(rounds(batch, n_rounds), [
        ("rls() with θ, σ history", "plain numba RLS, history", "with history, peer / gripkit"),
        ("RLS.run(store=False)", "plain numba RLS, no history", "no history, peer / gripkit")],
        peer_over_gripkit=True)
    lines.append(f"## streaming update, {k} calls from a Python loop per run, per call")
    lines += report(rounds({"RLS.update": stream, "plain numba step": plain_stream}, n_rounds,
                           per_call=k),
                    [("RLS.update", "plain numba step", "streaming, peer / gripkit")],
                    peer_over_gripkit=True)
    return lines


def crba_rows(n_rounds: int) -> list[str]:
    import pinocchio as pin

    from gripkit.errors import ConsistencyWarning
    from gripkit.multibody.onestate import mass_matrix_one
    from gripkit.multibody.pinocchio import to_pinocchio
    from gripkit.systems.dlr_hit.parameters import finger

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConsistencyWarning)
        ch = finger().chain()
    model, data = to_pinocchio(ch.chain)
    G, arm = ch.coupling.matrix, ch.coupling.armature
    n = 20_000
    rng = np.random.default_rng(0)
    ps = [np.ascontiguousarray(x) for x in rng.normal(size=(n, 3))]
    qs = [np.ascontiguousarray(G @ x) for x in ps]
    err = 0.0
    for p, q in zip(ps[:200], qs[:200]):
        Mp = G.T @ pin.crba(model, data, q) @ G
        Mp = np.triu(Mp) + np.triu(Mp, 1).T + np.diag(arm)
        err = max(err, float(np.max(np.abs(ch.mass_matrix(p) - Mp)) / np.max(np.abs(Mp))))
    M = np.empty((3, 3))
    one = ch._one or ch._one_state()

    def before(p):
        """Dynamics.mass_matrix's one-state path before issue 24's follow-up (dispatcher)."""
        buf, _, shape, _ = one
        res = np.empty(shape)
        try:
            done = mass_matrix_one(buf, p, res)
        except TypeError:
            done = False
        return res if done else None

    def loop(fn, xs):
        def run():
            for x in xs:
                fn(x)
        return run

    fns = {"pin.crba": loop(lambda q: pin.crba(model, data, q), qs),
           "mass_matrix(p)": loop(ch.mass_matrix, ps),
           "mass_matrix(p, out=M)": loop(lambda p: ch.mass_matrix(p, out=M), ps),
           "before: dispatcher + np.empty": loop(before, ps)}
    lines = [f"## one-state mass matrix, DLR/HIT finger (4 joints, 3 actuators), {n} states "
             f"per run, per call ({n_rounds} rounds)",
             f"accuracy: max |M − (Γᵀ M_pin Γ + diag(arm))| / max |M| = {err:.1e}"]
    lines += report(rounds(fns, n_rounds, per_call=n), [
        ("mass_matrix(p)", "pin.crba", "no out=, gripkit / pin (target ≤ 1.1)"),
        ("mass_matrix(p, out=M)", "pin.crba", "out=, gripkit / pin"),
        ("before: dispatcher + np.empty", "pin.crba", "before, gripkit / pin"),
        ("mass_matrix(p)", "before: dispatcher + np.empty", "no out=, after / before")],
        peer_over_gripkit=False)
    return lines


def main(n_rounds: int = 9) -> None:
    print("# benchmarks/ab_rls_crba.py (issue 24: batch RLS with history, CRBA without out=)")
    print(f"{dt.datetime.now().isoformat(timespec='seconds')}; CPU {cpu_model()}, "
          f"{os.cpu_count()} cores; load average at start "
          + ", ".join(f"{x:.2f}" for x in os.getloadavg()) + "; BLAS 1 thread")
    for line in rls_rows(n_rounds) + crba_rows(max(n_rounds, 15)):
        print(line)
    print("load average at end " + ", ".join(f"{x:.2f}" for x in os.getloadavg()))


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 9)
