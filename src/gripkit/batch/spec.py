"""Sweep specifications (TOML or dict) and the job table they expand to.

```toml
[sweep]
name = "msd-robustness"
scenario = "step-response"         # a registered scenario ("pkg.module:function": allow_code only)
model = "mass-spring-damper"       # optional registered model ("pkg.module:factory": allow_code)
samples = 200                      # random draws per grid point (default 1)
seed = 1
chunk_size = 50                    # jobs per task (default: chosen from a timing run, >= 0.1 s)

[parameters]
k = { grid = [50.0, 100.0, 200.0] }            # crossed with every other grid
m = { loguniform = ["1 mg", "3 mg"] }          # values may carry units (converted to SI)
b = { normal = [7e-4, 1e-4], clip = [0, 1] }
c = { uniform = [0.0, 1.0] }
d = { linspace = [0.0, 1.0, 5] }               # also logspace = [lo, hi, n]
e = { table = "objects.csv", column = "e" }    # rows of a CSV file (parameters from one file zip)

[scenario]                                     # passed to the scenario function
duration = 0.05
amplitude = "1e-4 N"

[metrics]
record = ["peak", "overshoot_percent", "settling_time"]   # default: everything the scenario returns
```

Jobs = (grid points × table rows) × samples; ``job_id`` numbers them 0..N-1.

Everything is checked before any job runs: the file's structure and types here
(:meth:`SweepSpec.from_dict`), the job count without building the table (:meth:`SweepSpec.n_jobs`),
and the parameter names, their units' dimensions and the ``[scenario]`` settings against what the
scenario declares (:func:`gripkit.batch.scenarios.prepare`).
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ConfigError, GripkitError
from ..io import load
from ..io.toml_file import read_toml
from ..units import same_dimension, si_unit, to_si
from .budget import MemoryEstimate, memory_limit as budget_limit

__all__ = ["SweepSpec", "quantity"]

_GRID_KINDS = ("grid", "values", "linspace", "logspace")
_RANDOM_KINDS = ("uniform", "normal", "loguniform")
_KINDS = (*_GRID_KINDS, *_RANDOM_KINDS, "table")
_OPTIONS = {"clip": _RANDOM_KINDS, "column": ("table",)}  # extra keys and the kinds they go with
_SWEEP_KEYS = ("name", "scenario", "model", "samples", "seed", "chunk_size")
_TOP_KEYS = ("sweep", "parameters", "scenario", "metrics")


def quantity(v, where: str, unit: str | None = None) -> float:
    """``v`` (a number in SI, or a string such as ``"3 mg"``) as an SI float.

    ``unit``: the SI unit the value must measure (``"N/m"``); a string with a unit of another
    dimension (``"3 furlong"`` for a stiffness) is refused. Non-finite values are refused."""
    expected = f" in {unit}" if unit else ""
    if isinstance(v, bool) or not isinstance(v, (numbers.Real, str)):
        raise ConfigError(f"{where}: expected a number{expected} or a quantity like '3 "
                          f"mg', found {v!r}")
    if isinstance(v, str):
        try:
            value = float(v)  # a bare number in a string: SI
        except ValueError:
            try:
                value, si = to_si(v)
            except GripkitError as exc:
                raise ConfigError(f"{where}: cannot read {v!r} as a quantity ({exc.message})",
                                  hint="write a number followed by a unit, like '3 "
                                       "mg' or '25 N/m'") from None
            if unit is not None and not same_dimension(si, unit):
                raise ConfigError(f"{where}: {v!r} is a quantity in {si}, expected one in "
                                  f"{si_unit(unit)}",
                                  hint=f"give it in {unit} (or a unit of the same "
                                       "dimension), or as a "
                                       f"plain number in {si_unit(unit)}")
    else:
        value = float(v)
    if not math.isfinite(value):
        raise ConfigError(f"{where}: expected a finite number{expected}, found {v!r}")
    return value


_si = quantity  # the name scenarios import


def _integer(v, where: str, low: int) -> int:
    if isinstance(v, bool) or not isinstance(v, numbers.Integral) or v < low:
        raise ConfigError(f"{where}: expected an integer >= {low}, found {v!r}")
    return int(v)


@dataclass(frozen=True)
class SweepSpec:
    """A parameter sweep: a scenario run for every job of a parameter table.

    ``scenario``: a registered name, ``"module:function"`` (imported only with ``allow_code``, see
    :func:`gripkit.batch.sweep`), or a callable; ``model`` likewise a registered name,
    ``"module:factory"`` or None."""

    scenario: object
    parameters: dict
    model: str | None = None
    name: str = "sweep"
    settings: dict = field(default_factory=dict)
    metrics: tuple[str, ...] | None = None
    samples: int = 1
    seed: int = 0
    chunk_size: int | None = None
    base_dir: str = "."

    @classmethod
    def from_toml(cls, path) -> "SweepSpec":
        return cls.from_dict(read_toml(path, "sweep file"), base_dir=str(Path(path).parent))

    @classmethod
    def from_dict(cls, d: dict, base_dir: str = ".") -> "SweepSpec":
        """Read and check a sweep description (the tables of a sweep file)."""
        if not isinstance(d, dict):
            raise ConfigError(f"sweep specification: expected a table, found {type(d).__name__}")
        unknown = sorted(set(d) - set(_TOP_KEYS))
        if unknown:
            raise ConfigError(f"sweep specification: unknown tables {unknown}",
                              hint=f"allowed: {', '.join(_TOP_KEYS)}")
        sw = d.get("sweep")
        if not isinstance(sw, dict) or "scenario" not in sw:
            raise ConfigError("sweep specification: a [sweep] table with a 'scenario' is required")
        unknown = sorted(set(sw) - set(_SWEEP_KEYS))
        if unknown:
            hint = f"allowed: {', '.join(_SWEEP_KEYS)}"
            if any("allow" in k or "code" in k for k in unknown):
                hint += ("; importing code cannot be allowed from inside a sweep file: "
                         "pass --allow-code "
                         "on the command line (Python: sweep(..., allow_code=True))")
            raise ConfigError(f"[sweep]: unknown keys {unknown}", hint=hint)
        params, settings, metrics = (d.get("parameters", {}), d.get("scenario", {}),
                                     d.get("metrics", {}))
        if not isinstance(metrics, dict):
            raise ConfigError(f"[metrics]: expected a table, found {metrics!r}")
        if set(metrics) - {"record"}:
            raise ConfigError("[metrics]: unknown keys "
                              f"{sorted(set(metrics) - {'record'})}", hint="allowed: record")
        record = metrics.get("record")
        return cls(scenario=sw["scenario"], parameters=params, model=sw.get("model"),
                   name=sw.get("name", "sweep"),
                   settings=settings, metrics=record, samples=sw.get("samples", 1),
                   seed=sw.get("seed", 0),
                   chunk_size=sw.get("chunk_size"), base_dir=base_dir)

    def __post_init__(self):
        """Check the types and ranges of every field, and count the jobs (reading every
        parameter), so that an error surfaces before any work starts."""
        for table, value in (("parameters", self.parameters), ("scenario", self.settings)):
            if not isinstance(value, dict):
                raise ConfigError(f"[{table}]: expected a table, found {value!r}")
        record = self.metrics
        if record is not None and (isinstance(record, str) or not isinstance(record, (list, tuple))
                                   or not record
                                   or not all(isinstance(m, str) for m in record)):
            raise ConfigError("[metrics] record: expected a non-empty list of metric names, "
                              f"found {record!r}")
        if not (callable(self.scenario) or isinstance(self.scenario, str)):
            raise ConfigError("[sweep] scenario: expected a scenario name, found "
                              f"{self.scenario!r}")
        if self.model is not None and not isinstance(self.model, str):
            raise ConfigError(f"[sweep] model: expected a model name, found {self.model!r}")
        name = self.name
        if not isinstance(name, str) or not name or any(c in name for c in "/\\\0"):
            raise ConfigError("[sweep] name: expected a short name without "
                              f"slashes, found {name!r}")
        cs = self.chunk_size
        fix = object.__setattr__  # frozen: normalise once, here
        fix(self, "parameters", dict(self.parameters))
        fix(self, "settings", dict(self.settings))
        fix(self, "metrics", tuple(record) if record else None)
        fix(self, "samples", _integer(self.samples, "[sweep] samples", 1))
        fix(self, "seed", _integer(self.seed, "[sweep] seed", 0))
        fix(self, "chunk_size", None if cs is None else _integer(cs, "[sweep] chunk_size", 1))
        if self.n_jobs() == 0:
            raise ConfigError("sweep specification: the parameter table has no rows, so "
                              "there are no jobs",
                              hint="check the table files named in [parameters]")

    def to_dict(self) -> dict:
        scen = self.scenario if isinstance(self.scenario, str) else \
            (f"{getattr(self.scenario, '__module__', '?')}:"
             f"{getattr(self.scenario, '__qualname__', '?')}")
        return {"sweep": {"name": self.name, "scenario": scen, "model": self.model,
                          "samples": self.samples, "seed": self.seed,
                          "chunk_size": self.chunk_size},
                "parameters": self.parameters, "scenario": self.settings,
                "metrics": {"record": list(self.metrics) if self.metrics else None}}

    # --- the parameter table ------------------------------------------------------------------
    def _axes(self, units: dict[str, str] | None = None):
        """Each parameter read (values in SI, checked against ``units`` where given) without
        building any array longer than the file states: (grids, linspaces, randoms, tables)."""
        grids: dict[str, np.ndarray] = {}
        spaces: dict[str, tuple[str, float, float, int]] = {}
        randoms: dict[str, tuple[str, list, list | None]] = {}
        tables: dict[str, list[str]] = {}
        for name, desc in self.parameters.items():
            where = f"[parameters] {name}"
            unit = (units or {}).get(name)
            if not isinstance(desc, dict) or not desc:
                raise ConfigError(f"{where}: expected {{ grid = [...] }}, "
                                  f"{{ uniform = [lo, hi] }}, ...")
            kinds = [k for k in desc if k in _KINDS]
            if len(kinds) != 1:
                raise ConfigError(f"{where}: give exactly one of {', '.join(_KINDS)}, "
                                  f"found {sorted(desc)}")
            kind = kinds[0]
            extra = sorted(k for k in desc if k != kind and kind not in _OPTIONS.get(k, ()))
            if extra:
                raise ConfigError(f"{where}: unknown keys {extra} for a {kind}",
                                  hint="'clip' goes with uniform/normal/loguniform, "
                                       "'column' with table")
            arg = desc[kind]
            if kind in ("grid", "values"):
                vals = (np.array([quantity(v, where, unit)
                                  for v in (arg if isinstance(arg, list) else [arg])]))
                if vals.size == 0:
                    raise ConfigError(f"{where}: empty grid")
                grids[name] = vals
            elif kind in ("linspace", "logspace"):
                if not (isinstance(arg, list) and len(arg) == 3):
                    raise ConfigError(f"{where}: {kind} = [start, stop, count], found {arg!r}")
                a, b = quantity(arg[0], where, unit), quantity(arg[1], where, unit)
                n = _integer(arg[2], f"{where} ({kind} count)", 1)
                if kind == "logspace" and (a <= 0 or b <= 0):
                    raise ConfigError(f"{where}: logspace needs positive ends, found {a}, {b}")
                spaces[name] = (kind, a, b, n)
            elif kind == "table":
                if not isinstance(arg, str) or not isinstance(desc.get("column", name), str):
                    raise ConfigError(f"{where}: table = \"file.csv\" (and column = "
                                      f"\"name\"), found {arg!r}")
                tables.setdefault(arg, []).append(name)
            else:
                if not (isinstance(arg, list) and len(arg) == 2):
                    raise ConfigError(f"{where}: {kind} = [a, b], found {arg!r}")
                lo = quantity(arg[0], where, unit)
                hi = quantity(arg[1], where, unit)
                if kind in ("uniform", "loguniform") and not lo < hi:
                    raise ConfigError(f"{where}: {kind} needs a < b, found {lo} >= {hi}")
                if kind == "loguniform" and lo <= 0:
                    raise ConfigError(f"{where}: loguniform needs positive bounds, found {lo}")
                if kind == "normal" and hi < 0:
                    raise ConfigError(f"{where}: normal = [mean, std] needs std >= 0, found {hi}")
                clip = desc.get("clip")
                if clip is not None:
                    if not (isinstance(clip, list) and len(clip) == 2):
                        raise ConfigError(f"{where}: clip = [low, high], found {clip!r}")
                    clip = [quantity(c, f"{where} clip", unit) for c in clip]
                    if not clip[0] <= clip[1]:
                        raise ConfigError(f"{where}: clip needs low <= high, found {clip}")
                randoms[name] = (kind, [lo, hi], clip)
        return grids, spaces, randoms, tables

    def _table_path(self, file: str, names: list[str]) -> Path:
        """The parameter file ``file``, which must lie in the sweep file's folder (``base_dir``)
        or below it: an absolute path, a ``..`` or a link that leads out of it is refused before
        anything is read (a sweep file someone sends must not read, nor echo, other files)."""
        base = Path(self.base_dir).resolve()
        given = Path(file)
        where = f"[parameters] {', '.join(names)}: table {file!r}"
        rule = f"tables are read only from the sweep file's folder {str(base)!r} or below it"
        fix = "copy the table into that folder and name it relative to it ('tables/objects.csv')"
        if given.is_absolute() or given.drive or given.root:
            raise ConfigError(f"{where} is an absolute path; {rule}", hint=fix)
        target = (base / given).resolve()  # follows every link on the way
        if target != base and base not in target.parents:
            how = ("leaves that folder through '..'" if ".." in given.parts
                   else "is a link that leads out of that folder")
            raise ConfigError(f"{where} {how}; {rule}", hint=fix)
        return target

    def _read_tables(self, tables: dict[str, list[str]]) -> list[tuple[list[str], list]]:
        """(parameter names, their columns) of each parameter file, read once, not yet crossed."""
        out = []
        for file, names in tables.items():
            cols = [self.parameters[n].get("column", n) for n in names]
            tr = load(self._table_path(file, names), columns=cols, fs=1.0)
            out.append((names, [np.asarray(tr[c], dtype=np.float64) for c in cols]))
        return out

    @staticmethod
    def _table_rows(read: list[tuple[list[str], list[np.ndarray]]]) -> dict[str, np.ndarray]:
        """Rows of the parameter files as read by :meth:`_read_tables` (each file zips its
        columns; files are crossed)."""
        cols_out: dict[str, np.ndarray] = {}
        n_rows = 1
        for names, columns in read:
            n = len(columns[0])
            idx = np.arange(n_rows * n)
            cols_out = {k: v[idx // n] for k, v in cols_out.items()}
            for name, col in zip(names, columns):
                cols_out[name] = col[idx % n]
            n_rows *= n
        return cols_out

    def n_jobs(self) -> int:
        """The number of jobs, counted without building the table (a Python int: no overflow):
        parameter files are read, but their rows are not crossed (1e5 × 1e5 rows are counted as
        1e10 jobs, then refused by the memory estimate, not allocated)."""
        grids, spaces, _, tables = self._axes()
        rows = math.prod(len(columns[0]) for _, columns in self._read_tables(tables))
        n = math.prod([g.size for g in grids.values()] + [s[3] for s in spaces.values()])
        return n * rows * self.samples

    def jobs(self, units: dict[str, str] | None = None, memory_limit=None) -> dict[str, np.ndarray]:
        """The job table: ``job_id`` and one float column per parameter (values checked against
        ``units``, name -> SI unit, where given). A table that would not fit in ``memory_limit``
        (bytes or ``"8 GB"``; default half the memory available) is refused with the estimate
        (:class:`~gripkit.batch.budget.MemoryEstimate`) before it is built."""
        grids, spaces, randoms, tables = self._axes(units)
        for name, (kind, a, b, n) in spaces.items():
            grids[name] = np.linspace(a, b, n) if kind == "linspace" else np.geomspace(a, b, n)
        # file order: first varies slowest
        grids = {n: grids[n] for n in self.parameters if n in grids}
        read = self._read_tables(tables)
        n_rows = math.prod(len(columns[0]) for _, columns in read)
        n_points = math.prod(g.size for g in grids.values())
        n_jobs = n_points * n_rows * self.samples
        limit, limit_text = budget_limit(memory_limit)
        table = MemoryEstimate(n_jobs, len(self.parameters), 0, 0, 0)
        table.check(0, 0, limit, limit_text, f"sweep {self.name!r}: the job table")
        rows = self._table_rows(read)
        out: dict[str, np.ndarray] = {"job_id": np.arange(n_jobs, dtype=np.int64)}
        base = out["job_id"] // self.samples  # job = ((point * n_rows) + row) * samples + draw
        point, row = base // n_rows, base % n_rows
        stride = n_points
        for n, g in grids.items():
            stride //= g.size
            out[n] = g[(point // stride) % g.size].astype(np.float64)
        for n, col in rows.items():
            out[n] = col[row]
        rng = np.random.default_rng(self.seed)
        for n, (kind, (a, b), clip) in randoms.items():
            if kind == "uniform":
                v = rng.uniform(a, b, n_jobs)
            elif kind == "loguniform":
                v = np.exp(rng.uniform(np.log(a), np.log(b), n_jobs))
            else:
                v = rng.normal(a, b, n_jobs)
            out[n] = np.clip(v, *clip) if clip else v
        return {"job_id": out["job_id"], **{n: out[n] for n in self.parameters}}
