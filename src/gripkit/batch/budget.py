"""Memory budget of a sweep, estimated before anything is allocated.

A sweep holds its job table (``job_id`` and one float64 column per parameter) and, at the end,
every job's metrics (float64) and error text (one pointer) in the coordinating process; each task
in flight also needs its scenario's working memory (:class:`~gripkit.batch.scenarios.Interface`)::

    bytes ≈ 3 · 8 N (1 + P + M + 1) + W (C b_job + b_task)

with N jobs, P parameters, M metrics, W tasks in flight (workers), C jobs per task. The factor 3
covers the copies: the table as built and as written (pyarrow), the results as computed per chunk
and as assembled. Measured on sweeps of 4·10⁶ jobs of a trivial scenario (peak resident memory
above the imports): 281 MB in memory and 415 MB with an output folder for P = 2, M = 1 (estimate
480 MB); 500 MB and 653 MB for P = 1, M = 5 (estimate 768 MB). The limit is half the memory
available now (``MemAvailable`` of ``/proc/meminfo``, lowered to a cgroup's limit where one is
set), or what the caller gives (``memory_limit``, CLI ``--memory-limit``).
"""

from __future__ import annotations

import contextlib
import os
import re
from dataclasses import dataclass
from pathlib import Path

from ..errors import ConfigError

__all__ = ["available_memory", "usable_cores", "parse_bytes", "format_bytes", "MemoryEstimate",
           "memory_limit"]

#: metrics assumed for a scenario that declares none and a sweep that records none
UNDECLARED_METRICS = 8

_UNITS = {"": 1, "b": 1, "kb": 10**3, "mb": 10**6, "gb": 10**9, "tb": 10**12,
          "kib": 2**10, "mib": 2**20, "gib": 2**30, "tib": 2**40}


def _cgroup_room() -> int | None:
    for limit_file, used_file in (("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),
                                  ("/sys/fs/cgroup/memory/memory.limit_in_bytes",
                                   "/sys/fs/cgroup/memory/memory.usage_in_bytes")):
        try:
            limit = Path(limit_file).read_text().strip()
            used = int(Path(used_file).read_text().strip())
        except (OSError, ValueError):
            continue
        if limit.isdigit() and int(limit) < 2**60:
            return max(int(limit) - used, 0)
    return None


def _cgroup_cpus(root: Path) -> float | None:
    """CPUs a cgroup's quota allows (v2 ``cpu.max``, v1 ``cpu.cfs_quota_us``), None where unset."""
    for quota_file, period_file in (("cpu.max", None),
                                    ("cpu/cpu.cfs_quota_us", "cpu/cpu.cfs_period_us")):
        try:
            fields = (root / quota_file).read_text().split()
            if period_file is not None:
                fields.append((root / period_file).read_text().strip())
            quota, period = fields[0], float(fields[1])
        except (OSError, ValueError, IndexError):
            continue
        if quota.lstrip("-").isdigit() and int(quota) > 0 and period > 0:
            return int(quota) / period
        return None  # "max" or -1: no quota
    return None


def usable_cores(cgroup_root: str | Path = "/sys/fs/cgroup") -> int:
    """Cores this process may run on: those of its CPU affinity (``taskset``, a container's
    cpuset), fewer where a cgroup's CPU quota (a container's CPU limit) allows fewer, at least 1.
    ``os.cpu_count()`` counts the host's cores, which a pool of that many processes would share."""
    try:
        cores = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # no affinity on this platform
        cores = os.cpu_count() or 1
    quota = _cgroup_cpus(Path(cgroup_root))
    if quota is not None:
        cores = min(cores, max(int(quota), 1))
    return max(cores, 1)


def available_memory() -> int:
    """Bytes of memory available to new allocations now (without swapping)."""
    avail = None
    with contextlib.suppress(OSError, ValueError, IndexError):  # no /proc: ask sysconf below
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                avail = int(line.split()[1]) * 1024
                break
    if avail is None:
        try:
            avail = os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
        except (ValueError, OSError, AttributeError):  # not a POSIX system: no limit we can derive
            avail = 2**62
    room = _cgroup_room()
    return avail if room is None else min(avail, room)


def parse_bytes(value, where: str = "memory_limit") -> int:
    """``8e9``, ``"8 GB"`` or ``"512 MiB"`` as a number of bytes."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        n = float(value)
    else:
        m = re.fullmatch(r"\s*([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*([A-Za-z]*)\s*", str(value))
        if not m or m.group(2).lower() not in _UNITS:
            raise ConfigError(f"{where}: expected a size such as '8 GB' or '512 MiB', "
                              f"found {value!r}",
                              hint="units: B, kB, MB, GB, TB, KiB, MiB, GiB, TiB")
        n = float(m.group(1)) * _UNITS[m.group(2).lower()]
    if not n > 0 or n == float("inf"):
        raise ConfigError(f"{where}: expected a positive size, found {value!r}")
    return int(n)


def format_bytes(n: float) -> str:
    for unit, size in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{int(n)} B"


def _count(n: int, noun: str) -> str:
    return f"{n:,} {noun}" + ("" if n == 1 else "s")


def memory_limit(override=None) -> tuple[int, str]:
    """(limit in bytes, where it comes from) for a sweep in this process."""
    if override is not None:
        n = parse_bytes(override)
        return n, f"the limit of {format_bytes(n)} given"
    avail = available_memory()
    return (avail // 2, f"the limit of {format_bytes(avail // 2)} (half the "
                        f"{format_bytes(avail)} available)")


@dataclass(frozen=True)
class MemoryEstimate:
    """Bytes a sweep needs: its table and results, and its tasks in flight."""

    n_jobs: int
    n_parameters: int
    n_metrics: int
    bytes_per_job: int
    bytes_per_task: int

    @property
    def table_bytes(self) -> int:
        return 3 * 8 * self.n_jobs * (1 + self.n_parameters + self.n_metrics + 1)

    def task_bytes(self, chunk_size: int) -> int:
        return chunk_size * self.bytes_per_job + self.bytes_per_task

    def total(self, chunk_size: int, in_flight: int) -> int:
        return self.table_bytes + in_flight * self.task_bytes(chunk_size)

    def check(self, chunk_size: int, in_flight: int, limit: int, limit_text: str,
              what: str) -> None:
        """Raise :class:`ConfigError` with the estimate and the limit when it does not fit."""
        total = self.total(chunk_size, in_flight)
        if total <= limit:
            return
        tasks = (f"; {_count(in_flight, 'task')} of {_count(chunk_size, 'job')} in flight, "
                 f"{format_bytes(self.task_bytes(chunk_size))} each" if in_flight else "")
        raise ConfigError(
            f"{what}: {_count(self.n_jobs, 'job')} need{'s' if self.n_jobs == 1 else ''} an "
            f"estimated {format_bytes(total)} of memory (job table "
            f"and results {format_bytes(self.table_bytes)} for "
            f"{_count(self.n_parameters, 'parameter')} and "
            f"{_count(self.n_metrics, 'metric')}{tasks}), above {limit_text}",
            hint="use fewer grid points, samples or time samples, split the sweep, "
                 "lower chunk_size, "
                 "or raise the limit with --memory-limit (Python: memory_limit=)")

    def largest_chunk(self, in_flight: int, limit: int) -> int:
        """The most jobs per task that still fit (0: not even one)."""
        room = (limit - self.table_bytes) // max(in_flight, 1) - self.bytes_per_task
        return max(int(room // self.bytes_per_job), 0) if self.bytes_per_job else 2**62
