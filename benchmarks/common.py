"""Shared helpers for gripkit's side-by-side benchmarks.

Each ``benchmarks/bench_*.py`` module defines ``run(quick: bool) -> list[dict]``; every dict is one
comparison row made by :func:`row`. ``benchmarks/run.py`` runs them all in one process, one after
another, and writes ``results/results.json`` and ``results/results.md`` with the machine noted.

Symmetric timing: both sides of every row go through :func:`measure`, with the same warm-up
(:data:`WARMUP` calls, so numba compilation and caches are excluded on both sides) and the same
number of timed runs (:data:`REPEAT`), garbage collection off; the median and the minimum are
reported. A call so slow that :data:`REPEAT` runs would exceed ``budget_s`` gets fewer runs (at
least one after the warm-up); the row then says how many each side had. BLAS threads are fixed
for the whole process by ``run.py`` before numpy is imported.
"""

from __future__ import annotations

import gc
import statistics
import time
from collections.abc import Callable

#: Warm-up calls before timing, on both sides.
WARMUP = 1
#: Timed runs on both sides (fewer only when they would exceed the budget).
REPEAT = 7
#: Seconds one side may spend on its timed runs before the count is reduced.
BUDGET_S = 60.0


class Timing(float):
    """Seconds per call: the median over ``runs`` timed runs (the float value), with ``.min``.
    Dividing or multiplying by a number scales both (``t / n_samples`` for per-sample figures)."""

    def __new__(cls, median: float, minimum: float, runs: int):
        obj = super().__new__(cls, median)
        obj.min = minimum
        obj.runs = runs
        return obj

    @property
    def median(self) -> float:
        return float(self)

    def __truediv__(self, k):
        return Timing(float(self) / k, self.min / k, self.runs)

    def __mul__(self, k):
        return Timing(float(self) * k, self.min * k, self.runs)

    __rmul__ = __mul__


def measure(fn: Callable[[], object], number: int = 1, budget_s: float = BUDGET_S) -> Timing:
    """Time ``fn``: :data:`WARMUP` calls, then :data:`REPEAT` runs of ``number`` calls each
    (fewer runs if they would exceed ``budget_s``); seconds per call."""
    t_warm = 0.0
    for _ in range(WARMUP):
        t0 = time.perf_counter()
        fn()
        t_warm = time.perf_counter() - t0
    runs = (REPEAT if t_warm * number * REPEAT <= budget_s
            else max(1, int(budget_s / max(t_warm * number, 1e-12))))
    times = []
    gc.collect()
    gc.disable()
    try:
        for _ in range(runs):
            t0 = time.perf_counter()
            for _ in range(number):
                fn()
            times.append((time.perf_counter() - t0) / number)
    finally:
        gc.enable()
    return Timing(statistics.median(times), min(times), runs)


def _split(t) -> tuple[float | None, float | None, int | None]:
    if t is None:
        return None, None, None
    if isinstance(t, Timing):
        return t.median, t.min, t.runs
    return float(t), None, None  # a reference figure (real time), not a measurement


def row(benchmark: str, task: str, gripkit_s, peer: str, peer_s, *, target: str = "",
        unit: str = "s",
        notes: str = "", gripkit_accuracy: str = "", peer_accuracy: str = "",
        pure_python_peer: bool = False,
        extra: dict | None = None) -> dict:
    """One comparison. ``gripkit_s``/``peer_s``: :class:`Timing` from :func:`measure` (or a plain
    number for a reference such as real time). ``ratio`` = peer median / gripkit median (> 1:
    gripkit faster). ``*_accuracy``: how close each side's answer is to the truth or reference.
    ``pure_python_peer``: the peer runs interpreted Python per sample; the table labels it."""
    g_med, g_min, g_runs = _split(gripkit_s)
    p_med, p_min, p_runs = _split(peer_s)
    ratio = (p_med / g_med) if (g_med and p_med) else None
    if pure_python_peer:
        peer = f"{peer} [pure-Python peer]"
    return dict(benchmark=benchmark, task=task, gripkit_s=g_med, gripkit_min_s=g_min,
                gripkit_runs=g_runs,
                peer=peer, peer_s=p_med, peer_min_s=p_min, peer_runs=p_runs, ratio=ratio,
                target=target,
                unit=unit, gripkit_accuracy=gripkit_accuracy, peer_accuracy=peer_accuracy,
                pure_python_peer=pure_python_peer, notes=notes, extra=extra or {})


def measure_alternating(fns: list[Callable[[], object]], runs: int = REPEAT,
                        clock: Callable[[], float] = time.perf_counter) -> list[Timing]:
    """Time several callables in turn (f0 f1 … f0 f1 …, after one warm-up call each), so that a
    drift of the machine's speed touches all of them alike; seconds per call, median and min.
    ``clock=time.thread_time`` counts this thread's CPU time only (steadier on a loaded machine,
    blind to waiting and to other threads)."""
    for fn in fns:
        fn()
    times: list[list[float]] = [[] for _ in fns]
    gc.collect()
    gc.disable()
    try:
        for _ in range(runs):
            for k, fn in enumerate(fns):
                t0 = clock()
                fn()
                times[k].append(clock() - t0)
    finally:
        gc.enable()
    return [Timing(statistics.median(t), min(t), runs) for t in times]


def print_alternating(fns: dict[str, Callable[[], object]], runs: int = 9) -> None:
    """:func:`measure_alternating` of the named callables twice, by wall clock and by this
    thread's CPU time, printed as one table each: name, median (min) in ms."""
    for clock, label in ((time.perf_counter, "wall"), (time.thread_time, "thread cpu")):
        times = measure_alternating(list(fns.values()), runs=runs, clock=clock)
        print(f"--- {label}, median (min) ms")
        for name, t in zip(fns, times):
            print(f"{name:50s} {float(t) * 1e3:8.2f} ({t.min * 1e3:8.2f})")


def finger_crba_calls(ch, pin_model, ps, M) -> tuple[list, dict[str, Callable[[], object]]]:
    """The DLR/HIT finger's mass-matrix calls timed beside ``pin.crba``: the joint states
    ``G·p`` of the actuator states ``ps``, and ``{"pin_crba": …, "mass_matrix": …,
    "mass_matrix_out": …}``, each a loop over the states: ``pin.crba(model, data, q)``,
    ``ch.mass_matrix(p)`` (a new array per call) and ``ch.mass_matrix(p, out=M)``.
    ``pin_model``: ``(model, data)`` of :func:`gripkit.multibody.pinocchio.to_pinocchio`."""
    import numpy as np
    import pinocchio as pin

    model, data = pin_model
    qs = [np.ascontiguousarray(ch.coupling.matrix @ p) for p in ps]

    def pin_crba():
        for q in qs:
            pin.crba(model, data, q)

    def mass_matrix():
        for p in ps:
            ch.mass_matrix(p)

    def mass_matrix_out():
        for p in ps:
            ch.mass_matrix(p, out=M)

    return qs, {"pin_crba": pin_crba, "mass_matrix": mass_matrix,
                "mass_matrix_out": mass_matrix_out}
