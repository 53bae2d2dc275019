"""Checkpointed sweep results: one Parquet file per chunk, written atomically.

Layout of an output folder::

    OUT/manifest.json          the sweep's specification and its fingerprint
    OUT/jobs.parquet           every job: job_id, chunk, and its parameters
    OUT/chunks/chunk-000012.parquet   results of chunk 12 (job_id, metrics..., error)

A chunk file is written to a temporary name and renamed, so it is either complete or absent: a
crash loses at most the chunks in flight, a resumed sweep skips every chunk already on disk, and a
chunk computed twice (a worker killed after finishing) replaces its file with identical content —
each job's result is present exactly once.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
from pathlib import Path

import numpy as np

from ..errors import ConfigError, DataError

__all__ = ["ResultStore"]

_CHUNK = re.compile(r"^chunk-(\d{6})\.parquet$")


def _atomic_write_table(table, path: Path) -> None:
    import pyarrow.parquet as pq

    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    pq.write_table(table, tmp)
    os.replace(tmp, path)


def fingerprint(obj) -> str:
    """A stable hash of a JSON-serialisable specification."""
    return hashlib.sha256(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()[:16]


class ResultStore:
    """The output folder of one sweep."""

    def __init__(self, root):
        self.root = Path(root)
        self.chunks_dir = self.root / "chunks"

    # --- setup -----------------------------------------------------------------------------
    def initialise(self, spec: dict, jobs: dict[str, np.ndarray], resume: bool) -> None:
        """Create the folder, or check that an existing one belongs to the same sweep."""
        import pyarrow as pa

        fp = fingerprint(spec)
        manifest = self.root / "manifest.json"
        if manifest.exists():
            old = json.loads(manifest.read_text())
            if old.get("fingerprint") != fp:
                raise ConfigError(
                    f"output folder {str(self.root)!r} holds a different sweep (fingerprint "
                    f"{old.get('fingerprint')} vs {fp})", hint="choose another --out folder or delete it")
            if not resume and self.done_chunks():
                raise ConfigError(f"output folder {str(self.root)!r} already holds results of this sweep",
                                  hint="pass --resume (resume=True) to continue it, or choose another folder")
        self.chunks_dir.mkdir(parents=True, exist_ok=True)
        tmp = manifest.with_name(".manifest.json.tmp")
        tmp.write_text(json.dumps({"fingerprint": fp, "spec": spec}, indent=2, default=str))
        os.replace(tmp, manifest)
        _atomic_write_table(pa.table({k: np.asarray(v) for k, v in jobs.items()}), self.root / "jobs.parquet")

    # --- chunks ----------------------------------------------------------------------------
    def chunk_path(self, chunk: int) -> Path:
        return self.chunks_dir / f"chunk-{chunk:06d}.parquet"

    def done_chunks(self) -> set[int]:
        if not self.chunks_dir.exists():
            return set()
        return {int(m.group(1)) for p in self.chunks_dir.iterdir() if (m := _CHUNK.match(p.name))}

    def write_chunk(self, chunk: int, columns: dict[str, np.ndarray]) -> None:
        import pyarrow as pa

        arrays = {}
        for k, v in columns.items():
            a = np.asarray(v)
            arrays[k] = pa.array(a.tolist(), type=pa.string()) if a.dtype == object else pa.array(a)
        _atomic_write_table(pa.table(arrays), self.chunk_path(chunk))

    # --- reading ---------------------------------------------------------------------------
    def read(self) -> dict[str, np.ndarray]:
        """Every job's parameters joined with its results, ordered by job_id."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        jobs_path = self.root / "jobs.parquet"
        if not jobs_path.exists():
            raise DataError(f"{str(self.root)!r} holds no sweep (jobs.parquet missing)")
        jobs = pq.read_table(jobs_path).to_pydict()
        out = {k: np.asarray(v) for k, v in jobs.items()}
        n = len(out["job_id"])
        position = {int(j): i for i, j in enumerate(out["job_id"])}
        for c in sorted(self.done_chunks()):
            part = pq.read_table(self.chunk_path(c))
            rows = np.array([position[int(j)] for j in part["job_id"].to_pylist()], dtype=np.int64)
            for name in part.column_names:
                if name == "job_id":
                    continue
                col = part[name]
                if name not in out:
                    is_text = pa.types.is_string(col.type) or pa.types.is_null(col.type)
                    out[name] = np.full(n, None, dtype=object) if is_text else np.full(n, np.nan)
                vals = col.to_pylist()
                if out[name].dtype == object:
                    out[name][rows] = np.array(vals, dtype=object)
                else:
                    out[name][rows] = np.array([np.nan if v is None else v for v in vals], dtype=np.float64)
        return out
