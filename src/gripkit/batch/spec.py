"""Sweep specifications (TOML or dict) and the job table they expand to.

```toml
[sweep]
name = "msd-robustness"
scenario = "step-response"         # a registered scenario or "package.module:function"
model = "mass-spring-damper"       # a zoo name, "package.module:factory", or left out
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
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ConfigError
from ..io.toml_file import read_toml
from ..units import setting_si as _si

__all__ = ["SweepSpec"]

_GRID_KINDS = ("grid", "values", "linspace", "logspace")
_RANDOM_KINDS = ("uniform", "normal", "loguniform")


@dataclass(frozen=True)
class SweepSpec:
    """A parameter sweep: a scenario run for every job of a parameter table."""

    scenario: object  # a registered name, "module:function", or a callable
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
        sw = d.get("sweep")
        if not isinstance(sw, dict) or "scenario" not in sw:
            raise ConfigError("sweep specification: a [sweep] table with a 'scenario' is required")
        unknown = set(sw) - {"name", "scenario", "model", "samples", "seed", "chunk_size"}
        if unknown:
            raise ConfigError(f"[sweep]: unknown keys {sorted(unknown)}",
                              hint="allowed: name, scenario, model, samples, seed, chunk_size")
        params = d.get("parameters", {})
        if not isinstance(params, dict):
            raise ConfigError("[parameters] must be a table of name = { kind = ... }")
        metrics = d.get("metrics", {}).get("record")
        samples = int(sw.get("samples", 1))
        if samples < 1:
            raise ConfigError(f"[sweep] samples: expected a positive integer, found {samples}")
        cs = sw.get("chunk_size")
        if cs is not None and int(cs) < 1:
            raise ConfigError(f"[sweep] chunk_size: expected a positive integer, found {cs}")
        scen = sw["scenario"]
        spec = cls(scenario=scen if callable(scen) else str(scen), parameters=dict(params), model=sw.get("model"),
                   name=str(sw.get("name", "sweep")), settings=dict(d.get("scenario", {})),
                   metrics=tuple(metrics) if metrics else None, samples=samples,
                   seed=int(sw.get("seed", 0)), chunk_size=None if cs is None else int(cs),
                   base_dir=base_dir)
        spec.jobs()  # validate now: errors surface before any work starts
        return spec

    def to_dict(self) -> dict:
        scen = self.scenario if isinstance(self.scenario, str) else \
            f"{getattr(self.scenario, '__module__', '?')}:{getattr(self.scenario, '__qualname__', '?')}"
        return {"sweep": {"name": self.name, "scenario": scen, "model": self.model,
                          "samples": self.samples, "seed": self.seed, "chunk_size": self.chunk_size},
                "parameters": self.parameters, "scenario": self.settings,
                "metrics": {"record": list(self.metrics) if self.metrics else None}}

    def jobs(self) -> dict[str, np.ndarray]:
        """The job table: ``job_id`` and one float column per parameter."""
        grids: dict[str, np.ndarray] = {}
        randoms: dict[str, tuple[str, list, list | None]] = {}
        tables: dict[str, list[str]] = {}
        for name, desc in self.parameters.items():
            where = f"[parameters] {name}"
            if not isinstance(desc, dict) or not desc:
                raise ConfigError(f"{where}: expected {{ grid = [...] }}, {{ uniform = [lo, hi] }}, ...")
            kinds = [k for k in desc if k in (*_GRID_KINDS, *_RANDOM_KINDS, "table")]
            if len(kinds) != 1:
                raise ConfigError(f"{where}: give exactly one of {', '.join((*_GRID_KINDS, *_RANDOM_KINDS, 'table'))}")
            kind = kinds[0]
            arg = desc[kind]
            if kind in ("grid", "values"):
                vals = np.array([_si(v, where) for v in (arg if isinstance(arg, list) else [arg])])
                if vals.size == 0:
                    raise ConfigError(f"{where}: empty grid")
                grids[name] = vals
            elif kind in ("linspace", "logspace"):
                if not (isinstance(arg, list) and len(arg) == 3):
                    raise ConfigError(f"{where}: {kind} = [start, stop, count]")
                a, b, n = _si(arg[0], where), _si(arg[1], where), int(arg[2])
                if kind == "logspace" and (a <= 0 or b <= 0):
                    raise ConfigError(f"{where}: logspace needs positive ends")
                grids[name] = np.linspace(a, b, n) if kind == "linspace" else np.geomspace(a, b, n)
            elif kind == "table":
                tables.setdefault(str(arg), []).append(name)
            else:
                if not (isinstance(arg, list) and len(arg) == 2):
                    raise ConfigError(f"{where}: {kind} = [a, b]")
                lo, hi = _si(arg[0], where), _si(arg[1], where)
                if kind in ("uniform", "loguniform") and not lo < hi:
                    raise ConfigError(f"{where}: {kind} needs a < b, found {lo} >= {hi}")
                if kind == "loguniform" and lo <= 0:
                    raise ConfigError(f"{where}: loguniform needs positive bounds")
                if kind == "normal" and hi < 0:
                    raise ConfigError(f"{where}: normal = [mean, std] needs std >= 0")
                clip = desc.get("clip")
                randoms[name] = (kind, [lo, hi], None if clip is None else [_si(c, where) for c in clip])
        # table rows (each file zips its columns)
        table_rows: list[dict[str, float]] = [{}]
        for file, names in tables.items():
            from ..io import load

            path = Path(file) if Path(file).is_absolute() else Path(self.base_dir) / file
            cols = [self.parameters[n].get("column", n) for n in names]
            tr = load(path, columns=cols, fs=1.0)
            rows = [{n: float(tr[c][i]) for n, c in zip(names, cols)} for i in range(tr.n)]
            table_rows = [{**a, **b} for a in table_rows for b in rows]
        grid_names = list(grids)
        points = list(itertools.product(*(grids[n] for n in grid_names))) or [()]
        n_jobs = len(points) * len(table_rows) * self.samples
        out: dict[str, np.ndarray] = {"job_id": np.arange(n_jobs, dtype=np.int64)}
        base = [(dict(zip(grid_names, p)), r) for p in points for r in table_rows]
        for n in grid_names:
            out[n] = np.repeat([b[0][n] for b in base], self.samples).astype(np.float64)
        for n in (n for names in tables.values() for n in names):
            out[n] = np.repeat([b[1][n] for b in base], self.samples).astype(np.float64)
        rng = np.random.default_rng(self.seed)
        for n, (kind, (a, b), clip) in randoms.items():
            if kind == "uniform":
                v = rng.uniform(a, b, n_jobs)
            elif kind == "loguniform":
                v = np.exp(rng.uniform(np.log(a), np.log(b), n_jobs))
            else:
                v = rng.normal(a, b, n_jobs)
            out[n] = np.clip(v, *clip) if clip else v
        return out
