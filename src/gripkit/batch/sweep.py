"""Parameter sweeps: chunked, checkpointed, resumable, on any executor.

>>> from gripkit.batch import SweepSpec, sweep
>>> spec = SweepSpec.from_dict({"sweep": {"scenario": "step-response", "model": "mass-spring-damper"},
...                             "parameters": {"k": {"grid": [1.0, 4.0]}}})
>>> res = sweep(spec, backend="in-process", progress=False)   # doctest: +SKIP
>>> res["overshoot_percent"]                                   # doctest: +SKIP

Jobs are grouped into chunks (default: as many jobs as take ≥ 0.1 s, measured on a warm-up run);
each chunk is one task for the executor and one Parquet file in the output folder
(:class:`~gripkit.batch.store.ResultStore`). A job that raises is recorded with its error in the
``error`` column and the sweep goes on; a chunk whose task fails as a whole (its worker died three
times) records the failure for each of its jobs.
"""

from __future__ import annotations

import json
import math
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..arguments import entry_point
from ..errors import ConfigError, ConsistencyWarning
from ..progress import status, track
from .executors import Executor, make_executor
from .scenarios import resolve
from .spec import SweepSpec
from .store import ResultStore

__all__ = ["sweep", "run_chunk", "SweepResult"]

_MODELS: dict = {}


def _model(ref: str | None):
    """Build (once per process) the model a sweep names: a zoo entry or 'module:factory'."""
    if ref is None:
        return None
    if ref not in _MODELS:
        import importlib

        with warnings.catch_warnings():  # consistency findings are reported by `gripkit zoo check`
            warnings.simplefilter("ignore", ConsistencyWarning)
            if ":" in ref:
                module, func = ref.split(":", 1)
                _MODELS[ref] = getattr(importlib.import_module(module), func)()
            elif ref == "mass-spring-damper":
                from ..models import MassSpringDamper

                _MODELS[ref] = MassSpringDamper()
            else:
                from .. import zoo

                _MODELS[ref] = zoo.build(ref)
    return _MODELS[ref]


def run_chunk(scenario: str, model_ref: str | None, settings: dict, job_ids: np.ndarray,
              params: dict[str, np.ndarray], metrics: tuple[str, ...] | None) -> dict[str, np.ndarray]:
    """Compute one chunk: the scenario on every job, failures recorded per job."""
    fn = resolve(scenario)
    model = _model(model_ref)
    n = len(job_ids)
    errors = np.full(n, None, dtype=object)
    try:
        # a scenario that draws random numbers per job (noise) seeds them by job id, so results do
        # not depend on the chunking: it declares ``fn.uses_job_id = True`` and gets params["job_id"]
        res = fn(model, {**params, "job_id": np.asarray(job_ids)} if getattr(fn, "uses_job_id", False) else params,
                 settings)
        res = {k: np.asarray(v, dtype=np.float64) for k, v in res.items()}
        for k, v in res.items():
            if v.shape != (n,):
                raise ConfigError(f"scenario {scenario!r} returned {v.shape} values for metric {k!r}, expected ({n},)")
    except Exception as exc:
        if n == 1:
            res, errors[0] = {}, f"{type(exc).__name__}: {exc}"
        else:  # find the failing jobs one by one
            rows = []
            for i in range(n):
                part = run_chunk(scenario, model_ref, settings, job_ids[i:i + 1],
                                 {k: v[i:i + 1] for k, v in params.items()}, metrics)
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
        return np.zeros(self.n_jobs, bool) if err is None else np.array([e is not None for e in err])

    @property
    def failures(self) -> list[tuple[int, str]]:
        return [(int(j), e) for j, e in zip(self.columns["job_id"], self.columns["error"]) if e is not None]

    def summary(self) -> str:
        return (f"{self.n_jobs} jobs ({int(self.failed.sum())} failed) in {self.seconds:.2f} s on "
                f"{self.backend}, chunks of {self.chunk_size}, {self.computed_chunks} computed"
                + (f"; results in {self.path}" if self.path else ""))


def _calibrate(spec: SweepSpec, jobs: dict[str, np.ndarray], target_s: float) -> int:
    """Jobs per chunk so a chunk takes >= target_s, timed on a warm (compiled) run of 2 jobs."""
    names = [k for k in jobs if k != "job_id"]
    k = min(2, len(jobs["job_id"]))
    args = (spec.scenario, spec.model, spec.settings, jobs["job_id"][:k],
            {n: jobs[n][:k] for n in names}, spec.metrics)
    run_chunk(*args)  # compile
    t0 = time.perf_counter()
    run_chunk(*args)
    per_job = max((time.perf_counter() - t0) / k, 1e-7)
    return max(1, math.ceil(target_s / per_job))


@entry_point
def sweep(spec: SweepSpec | dict | str | Path, *, backend: str = "process", workers: int | None = None,
          scheduler: str | None = None, out: str | Path | None = None, resume: bool = False,
          progress: bool = True, executor: Executor | None = None,
          target_task_s: float = 0.1) -> SweepResult:
    """Run a sweep. ``backend``: 'process' (default), 'in-process' or 'dask' (``scheduler`` address
    or a LocalCluster); ``out``: folder for checkpointed results (required for ``resume``)."""
    if not isinstance(spec, SweepSpec):
        spec = SweepSpec.from_dict(spec) if isinstance(spec, dict) else SweepSpec.from_toml(spec)
    if resume and out is None:
        raise ConfigError("resume needs the output folder of the interrupted sweep (out=...)")
    jobs = spec.jobs()
    n_jobs = len(jobs["job_id"])
    store = ResultStore(out) if out is not None else None
    chunk_size = spec.chunk_size
    manifest = Path(out) / "manifest.json" if out is not None else None
    if chunk_size is None and resume and manifest is not None and manifest.exists():
        chunk_size = json.loads(manifest.read_text())["spec"]["sweep"]["chunk_size"]
    if chunk_size is None:
        chunk_size = _calibrate(spec, jobs, target_task_s)
    chunk_size = int(min(chunk_size, n_jobs))
    record = spec.to_dict()
    record["sweep"]["chunk_size"] = chunk_size
    n_chunks = math.ceil(n_jobs / chunk_size)
    done: set[int] = set()
    mem: dict[int, dict] = {}
    if store is not None:
        store.initialise(record, jobs, resume)
        done = store.done_chunks()
    names = [k for k in jobs if k != "job_id"]
    tasks = []
    for c in range(n_chunks):
        if c in done:
            continue
        sl = slice(c * chunk_size, min((c + 1) * chunk_size, n_jobs))
        tasks.append((c, run_chunk, (spec.scenario, spec.model, spec.settings, jobs["job_id"][sl],
                                     {n: jobs[n][sl] for n in names}, spec.metrics)))
    own = executor is None
    ex = executor or make_executor(backend, workers, scheduler)
    t0 = time.perf_counter()
    if done:
        status(f"resuming {spec.name}: {len(done)} of {n_chunks} chunks already on disk")
    try:
        for c, ok, value in track(ex.map_unordered(tasks), total=len(tasks),
                                  description=f"{spec.name} ({ex.name}, {chunk_size} jobs/chunk)",
                                  enabled=progress):
            if not ok:
                sl = slice(c * chunk_size, min((c + 1) * chunk_size, n_jobs))
                value = {"job_id": jobs["job_id"][sl], "error": np.full(sl.stop - sl.start, value, dtype=object)}
            if store is not None:
                store.write_chunk(c, value)
            else:
                mem[c] = value
    finally:
        if own:
            ex.close()
    seconds = time.perf_counter() - t0
    if store is not None:
        cols = store.read()
    else:
        cols = dict(jobs)
        parts = [mem[c] for c in sorted(mem)]
        keys = [k for k in dict.fromkeys(k for p in parts for k in p) if k != "job_id"]
        for k in keys:
            arr = np.full(n_jobs, None if k == "error" else np.nan, dtype=object if k == "error" else np.float64)
            for p in parts:
                if k in p:
                    arr[np.asarray(p["job_id"])] = p[k]
            cols[k] = arr
    return SweepResult(cols, None if out is None else Path(out), ex.name, chunk_size, seconds, len(tasks))
