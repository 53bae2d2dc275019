"""Progress on stderr for long work: a rich bar (rate, ETA) in a terminal, plain lines otherwise.

>>> for item in track(range(3), description="fitting", enabled=False):
...     pass
"""

from __future__ import annotations

import sys
import time
from collections.abc import Iterable, Iterator
from typing import TypeVar

__all__ = ["track", "status", "console"]

T = TypeVar("T")
_QUIET = False


def set_quiet(quiet: bool) -> None:
    """Silence progress output (the CLI's ``--quiet``; ``--json`` keeps stdout clean anyway)."""
    global _QUIET
    _QUIET = bool(quiet)


def console():
    from rich.console import Console

    return Console(stderr=True)


def status(message: str) -> None:
    """One line of progress on stderr."""
    if not _QUIET:
        print(message, file=sys.stderr, flush=True)


def track(iterable: Iterable[T], total: int | None = None, description: str = "working",
          enabled: bool = True) -> Iterator[T]:
    """Iterate with a progress bar on stderr (rich in a terminal; a line per ~10 % otherwise)."""
    if total is None:
        try:
            total = len(iterable)  # type: ignore[arg-type]
        except TypeError:
            total = None
    if not enabled or _QUIET:
        yield from iterable
        return
    if sys.stderr.isatty():
        from rich.progress import (BarColumn, MofNCompleteColumn, Progress, TextColumn,
                                   TimeElapsedColumn, TimeRemainingColumn)

        with Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                      TextColumn("{task.fields[rate]}"), TimeElapsedColumn(), TimeRemainingColumn(),
                      console=console(), transient=False) as bar:
            task = bar.add_task(description, total=total, rate="")
            t0 = time.perf_counter()
            for i, item in enumerate(iterable, 1):
                yield item
                dt = time.perf_counter() - t0
                bar.update(task, advance=1, rate=f"{i / dt:.3g}/s" if dt > 0 else "")
        return
    t0 = time.perf_counter()
    tenth = 1  # the next line at tenth/10 of the total, counted in integers (no drift)
    for i, item in enumerate(iterable, 1):
        yield item
        if total:
            frac = i / total
            if 10 * i >= tenth * total or i == total:
                dt = time.perf_counter() - t0
                eta = dt / frac - dt
                status(f"  {description}: {i}/{total} ({100 * frac:.0f} %, {dt:.1f} s, "
                       f"ETA {eta:.1f} s)")
                while tenth * total <= 10 * i:
                    tenth += 1
