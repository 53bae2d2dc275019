"""Shared helpers for gripkit's side-by-side benchmarks.

Each ``benchmarks/bench_*.py`` module defines ``run(quick: bool) -> list[dict]``; every dict is one
comparison row made by :func:`row`. ``benchmarks/run.py`` runs them all in one process, one after
another, and writes ``results/results.json`` and ``results/results.md`` with the machine noted.
"""

from __future__ import annotations

import gc
import statistics
import time
from collections.abc import Callable


def best_time(fn: Callable[[], object], repeat: int = 5, number: int = 1, warmup: int = 1) -> float:
    """Best wall time of ``number`` calls, over ``repeat`` runs, after ``warmup`` calls (s/call)."""
    for _ in range(warmup):
        fn()
    times = []
    gc.disable()
    try:
        for _ in range(repeat):
            t0 = time.perf_counter()
            for _ in range(number):
                fn()
            times.append((time.perf_counter() - t0) / number)
    finally:
        gc.enable()
    return min(times)


def median_time(fn: Callable[[], object], repeat: int = 5, number: int = 1, warmup: int = 1) -> float:
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(number):
            fn()
        times.append((time.perf_counter() - t0) / number)
    return statistics.median(times)


def row(benchmark: str, task: str, gripkit_s: float | None, peer: str, peer_s: float | None,
        *, target: str = "", unit: str = "s", notes: str = "", extra: dict | None = None) -> dict:
    """One comparison: times per call in seconds; ``ratio`` = peer / gripkit (> 1: gripkit faster)."""
    ratio = (peer_s / gripkit_s) if (gripkit_s and peer_s) else None
    return dict(benchmark=benchmark, task=task, gripkit_s=gripkit_s, peer=peer, peer_s=peer_s,
                ratio=ratio, target=target, unit=unit, notes=notes, extra=extra or {})
