"""Parameter sweeps: chunked, checkpointed, resumable, on any executor.

>>> from gripkit.batch import SweepSpec, sweep
>>> spec = SweepSpec.from_dict({"sweep": {"scenario": "step-response",
...                                        "model": "mass-spring-damper"},
...                             "parameters": {"k": {"grid": [1.0, 4.0]}}})
>>> res = sweep(spec, backend="in-process", progress=False)
>>> res["overshoot_percent"].round(2).tolist()
[10.59, 10.58]

Jobs are grouped into chunks (default: as many jobs as take ≥ 0.1 s, measured on a warm-up run);
each chunk is one task for the executor and one Parquet file in the output folder
(:class:`~gripkit.batch.store.ResultStore`). A job that raises is recorded with its error in the
``error`` column and the sweep goes on; a chunk whose task fails as a whole (its worker died three
times) records the failure for each of its jobs.

Before any job runs, :func:`sweep` checks the description against its scenario
(:func:`~gripkit.batch.scenarios.prepare`: parameter names and units, settings, metrics), counts the
jobs and estimates the memory they need (:mod:`gripkit.batch.budget`), and on resume checks every
chunk on disk (:meth:`~gripkit.batch.store.ResultStore.check_chunks`). The returned table holds
each job exactly once (:func:`~gripkit.batch.store.collect` raises otherwise).
"""

from __future__ import annotations

import math
import os
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..arguments import entry_point
from ..errors import ConfigError
from ..progress import status, track
from .budget import UNDECLARED_METRICS, MemoryEstimate, memory_limit as _memory_limit, usable_cores
from .executors import Executor, make_executor
from .scenarios import build_model, prepare, resolve, summarise_warnings
from .spec import SweepSpec
from .store import ResultStore, chunk_range, collect

__all__ = ["sweep", "run_chunk", "SweepResult"]


def run_chunk(scenario, model_ref: str | None, settings: dict, job_ids: np.ndarray,
              params: dict[str, np.ndarray], metrics: tuple[str, ...] | None,
              allow_code: bool = False) -> dict:
    """Compute one chunk: the scenario on every job, failures recorded per job, and the
    warnings its jobs gave under ``"warnings"`` (category, first text, count, jobs counted or
    None; :func:`sweep` sums them over the chunks and reports each kind once)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = _chunk_results(scenario, model_ref, settings, job_ids, params, metrics, allow_code)
    res["warnings"] = [(w.category, getattr(w.message, "first", str(w.message)),
                        getattr(w.message, "count", 1), getattr(w.message, "total", None))
                       for w in caught]
    return res


def _chunk_results(scenario, model_ref: str | None, settings: dict, job_ids: np.ndarray,
                   params: dict[str, np.ndarray], metrics: tuple[str, ...] | None,
                   allow_code: bool) -> dict[str, np.ndarray]:
    """:func:`run_chunk` without its warnings: a chunk that fails as a whole is run again job by
    job to find the failing ones."""
    fn = resolve(scenario, allow_code)
    model = build_model(model_ref, allow_code)
    n = len(job_ids)
    errors = np.full(n, None, dtype=object)
    try:
        # a scenario that draws random numbers per job (noise) seeds them by job id, so results do
        # not depend on the chunking: it declares ``fn.uses_job_id = True`` and gets
        # params["job_id"]
        res = fn(model, {**params, "job_id": np.asarray(job_ids)} if getattr(fn, "uses_job_id",
                                                                             False) else params,
                 settings)
        res = {k: np.asarray(v, dtype=np.float64) for k, v in res.items()}
        for k, v in res.items():
            if v.shape != (n,):
                raise ConfigError(f"scenario {scenario!r} returned {v.shape} values for metric "
                                  f"{k!r}, expected ({n},)")
    except Exception as exc:
        if n == 1:
            res, errors[0] = {}, f"{type(exc).__name__}: {exc}"
        else:  # find the failing jobs one by one
            rows = []
            for i in range(n):
                part = _chunk_results(scenario, model_ref, settings, job_ids[i:i + 1],
                                      {k: v[i:i + 1] for k, v in params.items()}, metrics,
                                      allow_code)
                rows.append(part)
                errors[i] = part["error"][0]
            keys = sorted({k for r in rows for k in r if k not in ("job_id", "error")})
            res = {k: np.array([r[k][0] if k in r else np.nan for r in rows]) for k in keys}
    if metrics is not None:
        missing = [m for m in metrics if m not in res]
        if missing and not any(e is not None for e in errors):
            raise ConfigError(f"scenario {scenario!r} does not compute {missing}",
                              hint=f"it computes: {', '.join(res)}")
        res = {m: res.get(m, np.full(n, np.nan)) for m in metrics}
    return {"job_id": np.asarray(job_ids, dtype=np.int64), **res, "error": errors}


@dataclass
class SweepResult:
    """Every job's parameters and metrics (``columns``), with the failures listed."""

    columns: dict[str, np.ndarray]
    path: Path | None
    backend: str
    chunk_size: int
    seconds: float
    computed_chunks: int
    #: why the backend was chosen (``backend='auto'``), else empty
    choice: str = ""

    def __getitem__(self, name: str) -> np.ndarray:
        if name not in self.columns:
            raise KeyError(f"no column {name!r}; columns: {', '.join(self.columns)}")
        return self.columns[name]

    @property
    def n_jobs(self) -> int:
        return len(self.columns["job_id"])

    @property
    def failed(self) -> np.ndarray:
        err = self.columns.get("error")
        return (np.zeros(self.n_jobs, bool) if err is None
                else np.array([e is not None for e in err], dtype=bool))

    @property
    def n_failed(self) -> int:
        return int(self.failed.sum())

    @property
    def failures(self) -> list[tuple[int, str]]:
        if "error" not in self.columns:
            return []
        return ([(int(j), e) for j, e in zip(self.columns["job_id"],
                                             self.columns["error"]) if e is not None])

    def summary(self) -> str:
        failed = (f"{self.n_failed} of them FAILED (see the error column)" if self.n_failed
                  else "none failed")
        return (f"{self.n_jobs} job{'s' if self.n_jobs != 1 else ''}, {failed}, in "
                f"{self.seconds:.2f} s on "
                f"{self.backend}, chunks of {self.chunk_size}, {self.computed_chunks} computed"
                + (f"; results in {self.path}" if self.path else "")
                + (f" ({self.choice})" if self.choice else ""))


#: Seconds a process pool needs before its first result: starting the workers, importing gripkit
#: and compiling (or loading from cache) the kernels in each. Measured 2.6 s for the TSFM grasp
#: sweep on 2 cores (benchmarks/results, "pool start + warm-up"); 1.5 s is the lower end with a
#: warm numba cache, so the automatic choice errs towards the pool only when it clearly pays.
POOL_STARTUP_S = 1.5


#: Jobs slower than this are timed on one chunk: a chunk's fixed cost (a few ms) is then small
#: beside its jobs' own time.
_EXACT_PER_JOB_S = 0.01


def _warm_seconds(args: tuple) -> float:
    """Wall time of one (already compiled) :func:`run_chunk` call."""
    t0 = time.perf_counter()
    run_chunk(*args)
    return time.perf_counter() - t0


def _per_job_seconds(t_one: float, t_k: float, k: int) -> float:
    """Seconds per job from the warm times of a 1-job chunk (``t_one``) and a k-job chunk
    (``t_k``): the slope (t_k − t_one)/(k − 1). It leaves out what every chunk pays once — the
    model's set-up, the launch of numba's parallel threads (several ms on a loaded machine:
    docs/performance.md, ``sweep(backend="auto")``) — which t_k/k counts k times over. Clamped to
    [1e-7, t_k/k]: timing noise may make the slope negative, and t_k/k includes the fixed cost."""
    if k <= 1:
        return max(t_k, 1e-7)
    return min(max((t_k - t_one) / (k - 1), 1e-7), max(t_k / k, 1e-7))


def _seconds_per_job(chunk_args, n_jobs: int) -> float:
    """Seconds per job, without the fixed cost of a chunk: the first ``k = min(8, n_jobs)`` jobs
    are run once to compile, timed, and — when they take less than :data:`_EXACT_PER_JOB_S` each
    — timed again beside the first job alone (the best of three), for :func:`_per_job_seconds`.
    ``chunk_args(range)`` gives :func:`run_chunk`'s arguments."""
    k = min(8, n_jobs)
    first = chunk_args(range(k))
    run_chunk(*first)  # compile
    t_k = _warm_seconds(first)
    if k <= 1 or t_k / k >= _EXACT_PER_JOB_S:
        return max(t_k / k, 1e-7)
    one = chunk_args(range(1))
    t_one = min(_warm_seconds(one) for _ in range(3))
    return _per_job_seconds(t_one, min(t_k, _warm_seconds(first)), k)


def _busy_cores() -> float:
    """Cores kept busy by other processes: the 1-minute load average less this process's own
    (at most 1), 0 where the load is unknown."""
    try:
        return max(os.getloadavg()[0] - 1.0, 0.0)
    except (AttributeError, OSError):  # not on this platform
        return 0.0


def _auto_backend(work_s: float, workers: int, busy: float = 0.0,
                  cores: int | None = None) -> tuple[str, str]:
    """'in-process' when the estimated work cannot win back the pool's start-up
    (``work ≤ startup + work / w``), else 'process'; with the reason for the summary. ``w``, the
    pool's speed-up, is the number of workers, but at most the cores (default :func:`usable_cores`)
    that other processes leave free (``busy``: their load, :func:`_busy_cores`), and at least 1:
    on a loaded machine a pool runs no faster than one process."""
    cores = int(cores or usable_cores())
    w = max(1.0, min(float(workers), cores - busy))
    load = f", {busy:.1f} of {cores} cores busy" if busy > 0 else ""
    if workers <= 1 or work_s <= POOL_STARTUP_S + work_s / w:
        return "in-process", (f"backend auto: in-process, the estimated work ({work_s:.2g} s) is "
                              f"too small for a pool of {workers} to win back its start-up "
                              f"(~{POOL_STARTUP_S:g} s{load})")
    return "process", (f"backend auto: process pool of {workers}, the estimated work "
                       f"({work_s:.2g} s) "
                       f"outweighs its start-up (~{POOL_STARTUP_S:g} s{load})")


def _in_flight(executor: Executor | None, backend: str, workers: int | None,
               scheduler: str | None) -> int:
    """Tasks that run at once on this machine (a remote scheduler's workers use their own)."""
    if executor is not None:
        return 0 if executor.name == "dask" and scheduler else max(int(executor.workers), 1)
    if scheduler:
        return 0
    return 1 if backend == "in-process" else int(workers or usable_cores())


def _checked_spec(spec: SweepSpec | dict | str | Path, *, backend: str, workers: int | None,
                  scheduler: str | None, out: str | Path | None, resume: bool,
                  executor: Executor | None) -> SweepSpec:
    """The first step of :func:`sweep`: the description as a :class:`SweepSpec` (read from a
    dict or a TOML file), after checking the arguments that need no scenario: ``resume`` needs
    ``out``, ``backend`` is one of the four names, ``workers`` a positive integer (ConfigError)."""
    if not isinstance(spec, SweepSpec):
        spec = SweepSpec.from_dict(spec) if isinstance(spec, dict) else SweepSpec.from_toml(spec)
    if resume and out is None:
        raise ConfigError("resume needs the output folder of the interrupted sweep (out=...)")
    if executor is None and not scheduler and backend not in ("auto", "in-process", "process",
                                                              "dask"):
        raise ConfigError("backend: expected 'auto', 'in-process', 'process' or 'dask', "
                          f"found {backend!r}")
    if workers is not None and (isinstance(workers,
                                           bool) or not isinstance(workers, int) or workers < 1):
        raise ConfigError(f"workers: expected a positive number, found {workers!r}")
    return spec


def _run_tasks(ex: Executor, own: bool, tasks: list, jobs: dict, store: ResultStore | None,
               mem: dict[int, dict], chunk_size: int, n_jobs: int, name: str,
               progress: bool) -> list:
    """The running step of :func:`sweep`: run the chunks' ``tasks`` on ``ex`` and put each
    chunk's results in ``store`` (or, without one, in ``mem`` by chunk number); a chunk whose task
    failed as a whole records its error for each of its jobs. Closes ``ex`` at the end if
    ``own``. Returns the chunks' warning records (:func:`run_chunk`)."""
    found: list = []
    try:
        for c, ok, value in track(ex.map_unordered(tasks), total=len(tasks),
                                  description=f"{name} ({ex.name}, {chunk_size} jobs/chunk)",
                                  enabled=progress):
            if ok:
                found.extend(value.pop("warnings", ()))
            else:
                r = chunk_range(c, chunk_size, n_jobs)
                value = ({"job_id": jobs["job_id"][r.start:r.stop],
                          "error": np.full(len(r), value, dtype=object)})
            if store is not None:
                store.write_chunk(c, value)
            else:
                mem[c] = value
    finally:
        if own:
            ex.close()
    return found


def _report_job_warnings(name: str, found: list) -> None:
    """One warning per kind for the whole sweep (its jobs' warnings, summed over the chunks, in
    every backend: a process pool's workers would otherwise print them nowhere), not one per job
    or per chunk."""
    summarise_warnings(found, lambda first, n, of: (
        f"sweep {name!r}: {n} of {of} jobs gave" if of is not None else
        f"sweep {name!r}: its jobs gave {n} warnings like") + f" this; the first: {first}")


@entry_point
def sweep(spec: SweepSpec | dict | str | Path, *, backend: str = "auto", workers: int | None = None,
          scheduler: str | None = None, out: str | Path | None = None, resume: bool = False,
          progress: bool = True, executor: Executor | None = None, target_task_s: float = 0.1,
          allow_code: bool = False, memory_limit: int | float | str | None = None) -> SweepResult:
    """Run a sweep. ``backend``: 'auto' (default: 'in-process' when the work, estimated from the
    first jobs timed without a chunk's fixed cost, is too small to win back a process pool's
    start-up :data:`POOL_STARTUP_S` with the cores the machine's load leaves free, else
    'process'; the summary says which and why), 'process', 'in-process' or 'dask' (``scheduler``
    address or a LocalCluster); ``out``: folder for checkpointed results (required for ``resume``).

    ``allow_code``: let the description name code to import (``scenario``/``model`` =
    ``"module:function"``); only registered names otherwise. Such a sweep file is code: run only
    files you trust as you would a script. ``memory_limit``: bytes (or ``"8 GB"``) the sweep may
    use; default half the memory available. A sweep that would not fit is refused up front with
    the estimate. Jobs that fail are recorded (``result.failures``), not raised."""
    spec = _checked_spec(spec, backend=backend, workers=workers, scheduler=scheduler, out=out,
                         resume=resume, executor=executor)
    prep = prepare(spec, allow_code)
    n_jobs = spec.n_jobs()
    limit, limit_text = _memory_limit(memory_limit)
    iface = prep.interface
    n_metrics = len(spec.metrics or iface.metrics or ()) or UNDECLARED_METRICS
    estimate = (MemoryEstimate(n_jobs, len(spec.parameters), n_metrics, iface.bytes_per_job,
                               iface.bytes_per_task))
    in_flight = _in_flight(executor, backend, workers, scheduler)
    store = ResultStore(out) if out is not None else None
    chunk_size = spec.chunk_size
    if chunk_size is None and resume and store is not None and (m := store.manifest()) is not None:
        chunk_size = m["spec"]["sweep"].get("chunk_size")
    # the table, the results and a first small task must fit before anything is built
    estimate.check(min(chunk_size or 2, n_jobs), max(in_flight, 1), limit, limit_text,
                   f"sweep {spec.name!r}")
    jobs = spec.jobs(dict(iface.parameters or {}), memory_limit=limit)
    iface.check_values(jobs)
    names = [k for k in jobs if k != "job_id"]

    def chunk_args(r: range) -> tuple:
        sl = slice(r.start, r.stop)
        return (spec.scenario, spec.model, prep.settings, jobs["job_id"][sl],
                {n: jobs[n][sl] for n in names},
                spec.metrics, allow_code)

    choice = ""
    auto = backend == "auto" and executor is None and not scheduler
    # per job without a chunk's fixed cost (model set-up, parallel thread launch)
    per_job = _seconds_per_job(chunk_args, n_jobs) if (chunk_size is None or auto) else None
    if auto:
        backend, choice = _auto_backend(per_job * n_jobs, int(workers or usable_cores()),
                                        _busy_cores())
        in_flight = _in_flight(None, backend, workers, None)
    if chunk_size is None:
        chunk_size = (min(max(1, math.ceil(target_task_s / per_job)),
                          max(estimate.largest_chunk(in_flight, limit), 1)))
    chunk_size = int(min(chunk_size, n_jobs))
    estimate.check(chunk_size, in_flight, limit, limit_text, f"sweep {spec.name!r}")
    record = spec.to_dict()
    record["sweep"]["chunk_size"] = chunk_size
    n_chunks = math.ceil(n_jobs / chunk_size)
    done: set[int] = set()
    mem: dict[int, dict] = {}  # the chunks' results when there is no store
    own = executor is None
    # the executor first: a scheduler that cannot be reached leaves the output folder untouched
    ex = executor or make_executor(backend, workers, scheduler)
    try:
        if store is not None:
            store.initialise(record, jobs, resume)
            done = store.check_chunks(chunk_size, n_jobs, spec.metrics)
    except BaseException:
        if own:
            ex.close()
        raise
    tasks = []
    for c in range(n_chunks):
        if c in done:
            continue
        tasks.append((c, run_chunk, chunk_args(chunk_range(c, chunk_size, n_jobs))))
    t0 = time.perf_counter()
    if done:
        status(f"resuming {spec.name}: {len(done)} of {n_chunks} chunks already on disk")
    found = _run_tasks(ex, own, tasks, jobs, store, mem, chunk_size, n_jobs, spec.name, progress)
    seconds = time.perf_counter() - t0
    _report_job_warnings(spec.name, found)
    parts = (store.read_parts(chunk_size, n_jobs,
                              spec.metrics) if store is not None else mem.values())
    cols = collect(jobs, parts)  # raises unless each job is there exactly once
    return (SweepResult(cols, None if out is None else Path(out), ex.name, chunk_size, seconds,
                        len(tasks), choice))
