"""Batch identification: the same identification on many logged experiments, one table out.

>>> table = identify_many("logs/finger3/*.parquet", "friction",
...                       dict(position="q", effort="pwm", effort_scale=3e-4))   # doctest: +SKIP
>>> table["coulomb"], table["coulomb_std"]                                        # doctest: +SKIP

Each file is loaded with :func:`gripkit.io.load` and passed to an *identifier*: a function
``identifier(trajectory, **options) -> dict`` returning ``{"params": {name: value},
"std": {name: std}, ...}`` (the same shape as the CLI's ``--json`` output). Identifiers are
registered in :data:`IDENTIFIERS` or given as ``"package.module:function"`` or as a callable.
Files are independent tasks on any executor; a file that fails (bad data, a fit that does not
converge) gets its error in the ``error`` column and the others go on.
"""

from __future__ import annotations

import glob
import importlib
from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np

from ..arguments import entry_point
from ..errors import ConfigError, DataError
from ..io import load
from ..progress import track
from .executors import Executor, make_executor

__all__ = ["IDENTIFIERS", "identify_many", "identify_file"]

#: name -> "module:function" of identifiers taking (Trajectory, **options) -> {"params", "std", ...}
IDENTIFIERS: dict[str, str] = {}


def _resolve(identifier) -> Callable:
    if callable(identifier):
        return identifier
    target = IDENTIFIERS.get(identifier, identifier)
    if ":" not in str(target):
        raise ConfigError(f"unknown identifier {identifier!r}",
                          hint=f"registered: {', '.join(IDENTIFIERS) or 'none'}; or "
                               "'package.module:function'")
    module, func = target.split(":", 1)
    try:
        return getattr(importlib.import_module(module), func)
    except (ImportError, AttributeError) as exc:
        raise ConfigError(f"identifier {identifier!r}: cannot import {target!r} ({exc})") from None


def identify_file(path: str, identifier, options: dict, load_options: dict) -> dict:
    """Load one file and identify (runs inside a worker)."""
    tr = load(path, **load_options)
    res = _resolve(identifier)(tr, **options)
    if not isinstance(res, dict) or "params" not in res:
        raise ConfigError("an identifier must return a dict with 'params' (and 'std')")
    return res


def _files(paths) -> list[str]:
    if isinstance(paths, (str, Path)):
        p = Path(paths)
        if p.is_dir():
            files = sorted(str(f) for f in p.iterdir() if f.suffix.lower() in
                           (".csv", ".parquet", ".pq", ".h5", ".hdf5", ".tsv", ".txt"))
        else:
            files = sorted(glob.glob(str(paths)))
    else:
        files = [str(f) for f in paths]
    if not files:
        raise DataError(f"no data files found at {paths!r}")
    return files


@entry_point
def identify_many(paths: str | Path | Iterable, identifier, options: dict | None = None, *,
                  load_options: dict | None = None, backend: str = "process",
                  workers: int | None = None,
                  scheduler: str | None = None, executor: Executor | None = None,
                  progress: bool = True) -> dict[str, np.ndarray]:
    """Identify every file; returns columns ``file``, each parameter, ``<param>_std``, any scalar
    diagnostics the identifier returns, and ``error`` (None when the file succeeded)."""
    files = _files(paths)
    options = dict(options or {})
    load_options = dict(load_options or {})
    _resolve(identifier)  # fail early on an unknown identifier
    tasks = ([(i, identify_file, (f, identifier, options,
                                  load_options)) for i, f in enumerate(files)])
    own = executor is None
    ex = executor or make_executor(backend, workers, scheduler)
    results: dict[int, tuple[bool, object]] = {}
    try:
        for key, ok, value in track(ex.map_unordered(tasks), total=len(tasks),
                                    description=f"identifying {len(files)} files",
                                    enabled=progress):
            results[key] = (ok, value)
    finally:
        if own:
            ex.close()
    names: list[str] = []
    extras: list[str] = []
    for ok, v in results.values():
        if ok:
            names += [n for n in v["params"] if n not in names]
            extras += [k for k, x in v.items() if k not in ("params", "std") and np.isscalar(x)
                       and not isinstance(x, str) and k not in extras]
    n = len(files)
    table: dict[str, np.ndarray] = {"file": np.array(files, dtype=object)}
    for name in names:
        table[name] = np.full(n, np.nan)
        table[f"{name}_std"] = np.full(n, np.nan)
    for k in extras:
        table[k] = np.full(n, np.nan)
    table["error"] = np.full(n, None, dtype=object)
    for i, (ok, v) in results.items():
        if not ok:
            table["error"][i] = v
            continue
        for name, val in v["params"].items():
            table[name][i] = val
            table[f"{name}_std"][i] = v.get("std", {}).get(name, np.nan)
        for k in extras:
            if k in v:
                table[k][i] = float(v[k])
    return table
