"""Checkpointed sweep results: one Parquet file per chunk, written atomically
(:func:`gripkit.atomic.atomic_write`; the manifest and job table also synced to disk).

Layout of an output folder::

    OUT/manifest.json          the sweep's specification and its fingerprint
    OUT/jobs.parquet           every job: job_id, chunk, and its parameters
    OUT/chunks/chunk-000012.parquet   results of chunk 12 (job_id, metrics..., error)

A chunk file is written to a temporary name and renamed, so it is either complete or absent: a
crash loses at most the chunks in flight, a resumed sweep skips every chunk already on disk, and a
chunk computed twice (a worker killed after finishing) replaces its file with identical content.

Files can still be damaged after the fact (a full disk, a copy gone wrong, a hand edit), so a
resumed sweep trusts no chunk unread: :meth:`ResultStore.check_chunks` reads every one and checks
that it belongs to this sweep (each chunk carries the sweep's fingerprint, a hash of its
specification, in its Parquet metadata, with the columns and types it was written with), its
schema (``job_id`` integers, ``error`` text, float metrics: no column dropped, added or retyped)
and that its job ids are exactly its range; a bad file is set aside as
``chunk-NNNNNN.parquet.bad`` with a warning and its jobs are computed again. :func:`collect`
refuses a result that does not hold each job exactly once.

A sweep never adopts or overwrites what is not its own: :meth:`ResultStore.initialise` refuses a
non-empty folder without a manifest (another sweep's results copied in, unrelated files), naming
what is there, and a folder whose manifest is another sweep's once it holds results.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
from pathlib import Path

import numpy as np

from ..atomic import TEMP_SUFFIX, atomic_write, write_text
from ..errors import ConfigError, DataError, GripkitWarning, emit_warning

__all__ = ["ResultStore", "chunk_range", "collect"]

_CHUNK = re.compile(r"^chunk-(\d{6})\.parquet$")
#: the keys of a chunk's Parquet metadata: the sweep's fingerprint, and the columns as written
_META_SWEEP, _META_COLUMNS = b"gripkit.sweep", b"gripkit.columns"


def chunk_range(chunk: int, chunk_size: int, n_jobs: int) -> range:
    """The job ids of chunk ``chunk``."""
    return range(chunk * chunk_size, min((chunk + 1) * chunk_size, n_jobs))


def collect(jobs: dict[str, np.ndarray], parts) -> dict[str, np.ndarray]:
    """Every job's parameters joined with its results from ``parts`` (dicts with ``job_id``,
    metrics and ``error``), ordered by job id. Raises :class:`DataError` unless the parts hold
    each job exactly once."""
    parts = list(parts)
    n = len(jobs["job_id"])
    ids = (np.concatenate([np.asarray(p["job_id"], dtype=np.int64) for p in parts]) if parts
           else np.zeros(0, np.int64))
    if ids.size and (ids.min() < 0 or ids.max() >= n):
        raise DataError(f"sweep results: job ids outside 0..{n - 1} (found "
                        f"{ids.min()}..{ids.max()})")
    count = np.bincount(ids, minlength=n)
    if (count != 1).any():
        missing, twice = np.flatnonzero(count == 0), np.flatnonzero(count > 1)
        raise DataError(f"sweep results: {len(missing)} jobs missing (first "
                        f"{missing[:5].tolist()}) and "
                        f"{len(twice)} held more than once (first {twice[:5].tolist()}); each "
                        "job must appear "
                        "exactly once", hint="resume the sweep to recompute the missing chunks")
    out = dict(jobs)
    for p in parts:
        rows = np.asarray(p["job_id"], dtype=np.int64)
        for k, v in p.items():
            if k == "job_id":
                continue
            if k not in out:
                out[k] = np.full(n, None, dtype=object) if k == "error" else np.full(n, np.nan)
            out[k][rows] = v
    return out


def _write_table(table, path: Path, what: str, sync: bool = True) -> None:
    import pyarrow.parquet as pq

    atomic_write(path, lambda tmp: pq.write_table(table, tmp), what=what, sync=sync)


def _schema(table) -> list[list[str]]:
    """[[column, type], ...] of a pyarrow table, in order."""
    return [[n, str(t)] for n, t in zip(table.column_names, table.schema.types)]


def fingerprint(obj) -> str:
    """A stable hash of a JSON-serialisable specification."""
    return hashlib.sha256(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()[:16]


def _foreign(table, fp: str | None) -> str:
    """What says that the chunk ``table`` is not this sweep's (fingerprint ``fp``), or ""."""
    meta = table.schema.metadata or {}
    theirs = meta.get(_META_SWEEP, b"").decode(errors="replace")
    if fp is None or theirs == fp:
        return ""
    if not theirs:
        return "carries no sweep fingerprint (it was not written by this sweep)"
    return f"was written by another sweep (fingerprint {theirs[:16]!r}, this sweep's is {fp!r})"


def _bad_schema(table, metrics) -> str:
    """What is wrong with the columns of the chunk ``table`` (as written, and as a chunk must
    be: integer job_id, text error, float metrics, those of ``metrics`` where given), or ""."""
    import pyarrow as pa

    meta = table.schema.metadata or {}
    try:
        written = [tuple(x) for x in json.loads(meta.get(_META_COLUMNS, b"null"))]
    except (ValueError, TypeError, RecursionError):
        written = None
    now = [tuple(x) for x in _schema(table)]
    if written is not None and written != now:
        was, has = dict(written), dict(now)
        parts = [f"column {k!r} dropped" for k in was if k not in has]
        parts += [f"column {k!r} added" for k in has if k not in was]
        parts += [f"column {k!r} changed from {was[k]} to {has[k]}"
                  for k in has if k in was and was[k] != has[k]]
        what = ", ".join(parts or ["columns reordered"])
        return f"differs from the columns it was written with: {what}"
    types = dict(zip(table.column_names, table.schema.types))
    if "job_id" not in types or not pa.types.is_integer(types["job_id"]):
        return "has no integer job_id column"
    error = types.get("error")
    if error is None or not (pa.types.is_string(error) or pa.types.is_null(error)):
        return "has no text error column"
    values = [k for k in types if k not in ("job_id", "error")]
    bad = [k for k in values if not pa.types.is_floating(types[k])]
    if bad:
        return f"has non-float metric columns {bad}"
    if metrics is not None and values and sorted(values) != sorted(metrics):
        return f"holds the metrics {values}, expected {list(metrics)}"
    return ""


class ResultStore:
    """The output folder of one sweep."""

    def __init__(self, root):
        self.root = Path(root)
        self.chunks_dir = self.root / "chunks"
        #: the sweep's fingerprint, set by :meth:`initialise` and written into every chunk
        self.fingerprint: str | None = None

    # --- setup -----------------------------------------------------------------------------
    def manifest(self) -> dict | None:
        """The recorded manifest, or None where there is none."""
        path = self.root / "manifest.json"
        if not path.exists():
            return None
        try:
            m = json.loads(path.read_text())
            m["spec"]["sweep"]
            return m
        except (OSError, ValueError, KeyError, TypeError, RecursionError) as exc:
            raise ConfigError(f"output folder {str(self.root)!r}: manifest.json is unreadable "
                              f"({type(exc).__name__})",
                              hint="choose another --out folder, or delete this one and run "
                                   "the sweep again") from None

    def initialise(self, spec: dict, jobs: dict[str, np.ndarray], resume: bool) -> None:
        """Create the folder, or check that an existing one belongs to the same sweep."""
        import pyarrow as pa

        fp = fingerprint(spec)
        if self.root.exists() and not self.root.is_dir():
            raise ConfigError(f"output folder {str(self.root)!r} is a file",
                              hint="choose another --out folder")
        old = self.manifest()
        if old is None:
            self._refuse_foreign()
        if old is not None and self.done_chunks():  # a folder without results may be reused
            if old.get("fingerprint") != fp:
                raise ConfigError(
                    f"output folder {str(self.root)!r} holds a different sweep (fingerprint "
                    f"{old.get('fingerprint')} vs {fp})", hint="choose another --out "
                                                               "folder or delete it")
            if not resume:
                raise ConfigError(f"output folder {str(self.root)!r} already holds "
                                  "results of this sweep",
                                  hint="pass --resume (resume=True) to continue it, or "
                                       "choose another folder")
        self.chunks_dir.mkdir(parents=True, exist_ok=True)
        self.fingerprint = fp
        manifest = json.dumps({"fingerprint": fp, "spec": spec}, indent=2, default=str)
        write_text(self.root / "manifest.json", manifest, what="sweep manifest")
        table = pa.table({k: np.asarray(v) for k, v in jobs.items()})
        _write_table(table, self.root / "jobs.parquet", "sweep job table")

    def _refuse_foreign(self) -> None:
        """A folder without a manifest must be empty (an empty ``chunks`` folder aside, left by a
        run stopped before it wrote its manifest): results or files found there are another's."""
        if not self.root.is_dir():
            return
        found = []
        for p in sorted(self.root.iterdir()):
            own_temp = p.name.startswith((".manifest.json.", ".jobs.parquet."))
            if own_temp and p.name.endswith(TEMP_SUFFIX):
                p.unlink(missing_ok=True)  # this store's own write, cut short by a crash
            elif not (p == self.chunks_dir and p.is_dir() and not any(p.iterdir())):
                found.append(p)
        if not found:
            return
        names = [p.name + ("/" if p.is_dir() else "") for p in found]
        chunks = len(self.done_chunks())
        held = f", {chunks} result chunk{'s' if chunks != 1 else ''} among them" if chunks else ""
        listed = ", ".join(names[:5]) + (", ..." if len(found) > 5 else "")
        entries = f"{len(found)} entr{'ies' if len(found) != 1 else 'y'}"
        raise ConfigError(
            f"output folder {str(self.root)!r} is not empty and holds no manifest.json of a sweep: "
            f"{entries} ({listed}){held}; a sweep writes only into an empty folder or its own",
            hint="choose a new or empty --out folder (it is created if missing)")

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
        table = pa.table(arrays)
        meta = {_META_SWEEP: (self.fingerprint or "").encode(),
                _META_COLUMNS: json.dumps(_schema(table)).encode()}
        # atomic but not fsynced: a chunk lost or torn by a power cut is found unreadable on resume
        # and computed again, while an fsync per chunk made a sweep of 300 one-job chunks 1.3-1.5x
        # slower (14.0-14.5 s against 9.4-11.2 s on a shared ext4 disk, 2026-11-26)
        _write_table(table.replace_schema_metadata(meta), self.chunk_path(chunk), "sweep chunk",
                     sync=False)

    def _load(self, chunk: int, chunk_size: int, n_jobs: int, metrics,
              fp: str | None) -> tuple[dict | None, str]:
        """(the chunk's columns, "") when its file is sound and this sweep's (fingerprint ``fp``),
        else (None, what is wrong)."""
        import pyarrow.parquet as pq

        expected = chunk_range(chunk, chunk_size, n_jobs)
        if not expected:
            return None, f"lies beyond the last chunk ({-(-n_jobs // chunk_size) - 1})"
        try:
            table = pq.read_table(self.chunk_path(chunk))
        except Exception as exc:  # pyarrow raises several types for damaged files
            return (None, f"is unreadable ({type(exc).__name__}: "
                          f"{str(exc).splitlines()[0][:120] if str(exc) else ''})")
        problem = _foreign(table, fp) or _bad_schema(table, metrics)
        if problem:
            return None, problem
        ids = table["job_id"].to_numpy()
        if not np.array_equal(ids, np.arange(expected.start, expected.stop)):
            found = f"{ids.min()}..{ids.max()}" if len(ids) else "none"
            found += ("" if not len(ids) or len(ids) == ids.max() - ids.min() + 1
                      else f" ({len(ids)} jobs)")
            return None, f"holds job ids {found}, expected {expected.start}..{expected.stop - 1}"
        values = [k for k in table.column_names if k not in ("job_id", "error")]
        cols = {"job_id": ids, "error": np.array(table["error"].to_pylist(), dtype=object)}
        cols.update({k: table[k].to_numpy().astype(np.float64) for k in values})
        return cols, ""

    def _load_all(self, chunk_size: int, n_jobs: int, metrics) -> dict[int, tuple]:
        """Every chunk on disk loaded as in :meth:`_load`; where the sweep records no fixed metrics,
        a chunk whose metric columns differ from those most chunks hold is bad too (a column
        dropped or added by hand)."""
        m = self.manifest()
        fp = None if m is None else str(m.get("fingerprint"))
        loaded = {c: self._load(c, chunk_size, n_jobs, metrics, fp)
                  for c in sorted(self.done_chunks())}
        if metrics is None:
            sets = [tuple(sorted(k for k in cols if k not in ("job_id", "error")))
                    for cols, _ in loaded.values() if cols is not None]
            sets = [x for x in sets if x]  # a chunk whose jobs all failed holds no metric
            if sets:
                usual = max(set(sets), key=sets.count)
                for c, (cols, _) in loaded.items():
                    have = tuple(sorted(k for k in cols or () if k not in ("job_id", "error")))
                    if cols is not None and have and have != usual:
                        loaded[c] = (None, f"holds the metrics {list(have)}, "
                                           f"the other chunks {list(usual)}")
        return loaded

    def check_chunks(self, chunk_size: int, n_jobs: int, metrics=None) -> set[int]:
        """The chunks on disk that are sound; each bad one is set aside (``.bad``) with a warning,
        so that it is computed again."""
        pattern = f".chunk-*{TEMP_SUFFIX}"
        for stale in self.chunks_dir.glob(pattern) if self.chunks_dir.exists() else ():
            stale.unlink(missing_ok=True)  # a write cut short by a crash
        good = set()
        for c, (cols, problem) in self._load_all(chunk_size, n_jobs, metrics).items():
            if cols is not None:
                good.add(c)
                continue
            path = self.chunk_path(c)
            os.replace(path, path.with_name(path.name + ".bad"))
            r = chunk_range(c, chunk_size, n_jobs)
            again = (f"its jobs {r.start}..{r.stop - 1} are computed again" if r
                     else "it is not used")
            emit_warning(f"sweep output {str(self.root)!r}: chunk {c} ({path.name}) "
                         f"{problem}; {again} "
                         f"(the file is kept as {path.name}.bad)", GripkitWarning)
        return good

    # --- reading ---------------------------------------------------------------------------
    def read_parts(self, chunk_size: int, n_jobs: int, metrics=None) -> list[dict]:
        """The columns of every chunk on disk, each checked as in :meth:`check_chunks`; a bad
        one raises :class:`DataError` (a sweep's output must not change under it)."""
        parts = []
        for c, (cols, problem) in self._load_all(chunk_size, n_jobs, metrics).items():
            if cols is None:
                raise DataError(f"sweep output {str(self.root)!r}: chunk {c} {problem}",
                                hint="resume the sweep (--resume) to compute it again")
            parts.append(cols)
        return parts

    def read(self) -> dict[str, np.ndarray]:
        """Every job's parameters joined with its results, ordered by job_id (each job exactly
        once, else :class:`DataError`)."""
        import pyarrow.parquet as pq

        jobs_path = self.root / "jobs.parquet"
        manifest = self.manifest()
        if manifest is None or not jobs_path.exists():
            raise DataError(f"{str(self.root)!r} holds no sweep (manifest.json or "
                            "jobs.parquet missing)")
        try:
            table = pq.read_table(jobs_path)
            jobs = {k: table[k].to_numpy() for k in table.column_names}
        except Exception as exc:
            raise DataError(f"{str(jobs_path)!r} is unreadable ({type(exc).__name__})") from None
        sw = manifest["spec"]["sweep"]
        metrics = (manifest["spec"].get("metrics") or {}).get("record")
        n = len(jobs["job_id"])
        return collect(jobs, self.read_parts(int(sw["chunk_size"]), n, metrics))
