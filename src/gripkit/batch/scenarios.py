"""Sweep scenarios: what one job computes, vectorised over the jobs of a chunk.

A scenario is ``fn(model, params, settings) -> metrics``: ``model`` is the built model (or None),
``params`` maps parameter names to arrays (one value per job), ``settings`` is the sweep's
``[scenario]`` table, and ``metrics`` maps metric names to arrays of the same length. Register new
scenarios in :data:`SCENARIOS`.

A scenario declares what it accepts with ``fn.interface = check(model, settings) -> Interface``:
its parameters with their SI units, its settings read and checked (:func:`read_settings`), its
metrics and its memory per job. :func:`prepare` calls it before any job runs, so a misspelt
parameter, a stiffness given in furlongs or ``fs = 0`` is refused up front.

Code named in a sweep file (``scenario = "package.module:function"``, ``model =
"package.module:factory"``) is imported and run only with an explicit opt-in (``allow_code=True``,
CLI ``--allow-code``): a sweep file is then code, to be trusted like a Python script.
"""

from __future__ import annotations

import importlib
import numbers
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

from .. import zoo
from ..errors import ConfigError, ConsistencyWarning, GripkitError, emit_warning
from ..sim.model import Model
from ..sysid.physical.step_response import step_metrics
from .spec import quantity

__all__ = ["SCENARIOS", "Setting", "Interface", "Prepared", "read_settings", "resolve",
           "build_model", "prepare", "step_response", "step_metrics_rows", "POSITIVE_TIME",
           "POSITIVE_RATE", "FRACTION", "summarise_warnings"]

SCENARIOS: dict[str, str] = {
    "step-response": "gripkit.batch.scenarios:step_response",
    "tsfm-grasp": "gripkit.systems.tsfm.grasp_batch:tsfm_grasp",
    "ftg100-grasp": "gripkit.systems.ftg100.scenario:ftg100_grasp",
}



# --- what a scenario accepts ------------------------------------------------------------------
@dataclass(frozen=True)
class Setting:
    """One ``[scenario]`` entry. ``kind``: an SI unit for a quantity (``"s"``, ``"Hz"``, ``"1"``),
    or ``"int"``, ``"bool"``, ``"str"``; numbers must lie in [``low``, ``high``] (the ends
    excluded when ``strict``); strings must be one of ``choices`` when given."""

    kind: str
    low: float | None = None
    high: float | None = None
    strict: bool = False
    choices: tuple[str, ...] = ()

    def read(self, value, where: str):
        if self.kind == "bool":
            if not isinstance(value, bool):
                raise ConfigError(f"{where}: expected true or false, found {value!r}")
            return value
        if self.kind == "str":
            if not isinstance(value, str) or (self.choices and value not in self.choices):
                raise ConfigError(f"{where}: expected one of {', '.join(map(repr, self.choices))}, "
                                  f"found {value!r}"
                                  if self.choices else f"{where}: expected a string, "
                                                       f"found {value!r}")
            return value
        if self.kind == "int":
            if isinstance(value, bool) or not isinstance(value, numbers.Integral):
                raise ConfigError(f"{where}: expected an integer, found {value!r}")
            v = int(value)
        else:
            v = quantity(value, where, self.kind)
        unit = "" if self.kind in ("int", "1") else f" {self.kind}"
        if self.low is not None and (v <= self.low if self.strict else v < self.low):
            raise ConfigError(f"{where}: expected a value {'>' if self.strict else '>='} "
                              f"{self.low:g}{unit}, "
                              f"found {value!r}")
        if self.high is not None and (v >= self.high if self.strict else v > self.high):
            raise ConfigError(f"{where}: expected a value {'<' if self.strict else '<='} "
                              f"{self.high:g}{unit}, "
                              f"found {value!r}")
        return v


POSITIVE_TIME = Setting("s", low=0.0, strict=True)
POSITIVE_RATE = Setting("Hz", low=0.0, strict=True)
FRACTION = Setting("1", low=0.0, high=1.0, strict=True)


def read_settings(table: Mapping, schema: Mapping[str, Setting], scenario: str) -> dict:
    """``table`` (a sweep's ``[scenario]``) read against ``schema``: unknown keys and bad values
    raise :class:`ConfigError`; quantities come back in SI."""
    unknown = sorted(set(table) - set(schema))
    if unknown:
        raise ConfigError(f"[scenario] ({scenario}): "
                          f"unknown keys {unknown}", hint=f"allowed: {', '.join(schema)}")
    return {k: schema[k].read(v, f"[scenario] {k}") for k, v in table.items()}


@dataclass(frozen=True)
class Interface:
    """What a scenario accepts and costs: ``parameters`` (name -> SI unit; None: any name, units
    not checked), ``settings`` (read and in SI), ``metrics`` it returns (None: not declared),
    working memory per job and per task (bytes, beyond the metrics)."""

    parameters: Mapping[str, str] | None = None
    settings: dict = field(default_factory=dict)
    metrics: tuple[str, ...] | None = None
    bytes_per_job: int = 0
    bytes_per_task: int = 0
    bounds: Mapping[str, tuple[float | None, float | None]] = field(default_factory=dict)

    def check_values(self, jobs: Mapping[str, np.ndarray]) -> None:
        """Refuse a job table with values outside the parameters' ``bounds`` (inclusive; None:
        unbounded): such jobs would all fail."""
        for name, (lo, hi) in self.bounds.items():
            if name not in jobs:
                continue
            v = jobs[name]
            bad = (v < (-np.inf if lo is None else lo)) | (v > (np.inf if hi is None else hi))
            if bad.any():
                i = int(np.argmax(bad))
                unit = (self.parameters or {}).get(name, "")
                raise ConfigError(
                    f"[parameters] {name}: {int(bad.sum()):,} of {len(v):,} jobs have values "
                    "outside its bounds "
                    f"[{-np.inf if lo is None else lo:g}, {np.inf if hi is None else hi:g}] {unit} "
                    f"(job {i}: {v[i]:g})",
                    hint="narrow the grid or range, or give a random draw clip = [low, high]")


# --- names to code -----------------------------------------------------------------------------
def _refuse_code(what: str, ref: str, registered) -> ConfigError:
    return ConfigError(
        f"{what} {ref!r} names Python code to import; without --allow-code a sweep may only name "
        f"registered {what}s ({', '.join(registered)})",
        hint="if you trust this sweep file as you would a script, pass --allow-code "
             "(Python: sweep(..., allow_code=True))")


def _import(target: str, what: str):
    module, func = target.split(":", 1)
    try:
        return getattr(importlib.import_module(module), func)
    except (ImportError, AttributeError, ValueError) as exc:
        raise ConfigError(f"{what}: cannot import {target!r} ({exc})") from None


def resolve(name, allow_code: bool = False):
    """The scenario function registered as ``name``; ``name`` itself when it is a callable (your
    own code, pickled by value for workers); ``"module:function"`` imported only when
    ``allow_code``."""
    if callable(name):
        return name
    if not isinstance(name, str):
        raise ConfigError(f"scenario: expected a registered name, found {name!r}")
    if name in SCENARIOS:
        return _import(SCENARIOS[name], f"scenario {name!r}")
    if ":" not in name:
        raise ConfigError(f"unknown scenario {name!r}", hint=f"registered: {', '.join(SCENARIOS)}")
    if not allow_code:
        raise _refuse_code("scenario", name, SCENARIOS)
    return _import(name, f"scenario {name!r}")


_MODELS: dict = {}


def build_model(ref: str | None, allow_code: bool = False):
    """Build (once per process) the model a sweep names: a zoo entry (:mod:`gripkit.zoo`, the one
    registry of buildable models), or (only when ``allow_code``) ``"module:factory"``."""
    if ref is None:
        return None
    key = (ref, allow_code)
    if key not in _MODELS:
        zoo_names = [e.name for e in zoo.entries()]
        if ref in zoo_names:
            factory = zoo.get(ref).build
        elif ":" in ref:
            if not allow_code:
                raise _refuse_code("model", ref, zoo_names)
            factory = _import(ref, f"model {ref!r}")
        else:
            raise ConfigError(f"unknown model {ref!r}",
                              hint=f"registered (the zoo): {', '.join(zoo_names)}")
        with warnings.catch_warnings():  # consistency findings are reported by `gripkit zoo check`
            warnings.simplefilter("ignore", ConsistencyWarning)
            try:
                _MODELS[key] = factory()
            except GripkitError:
                raise
            except Exception as exc:
                raise ConfigError(f"model {ref!r}: building it failed "
                                  f"({type(exc).__name__}: {exc})") from None
    return _MODELS[key]


@dataclass(frozen=True)
class Prepared:
    """A sweep's scenario and model resolved and its description checked against them."""

    fn: Callable
    model: object
    interface: Interface

    @property
    def settings(self) -> dict:
        return self.interface.settings


def prepare(spec, allow_code: bool = False) -> Prepared:
    """Resolve ``spec``'s scenario and model and check its parameter names, units, settings and
    metrics against the scenario's :class:`Interface`: every error a whole sweep would hit is
    raised here, before any job runs."""
    fn = resolve(spec.scenario, allow_code)
    model = build_model(spec.model, allow_code)
    declare = getattr(fn, "interface", None)
    iface = (declare(model, dict(spec.settings)) if declare
             else Interface(settings=dict(spec.settings)))
    scen = (spec.scenario if isinstance(spec.scenario,
                                        str) else getattr(spec.scenario, "__name__", "scenario"))
    if iface.parameters is not None:
        unknown = [n for n in spec.parameters if n not in iface.parameters]
        if unknown:
            on = f" on model {spec.model!r}" if spec.model else ""
            raise ConfigError(
                f"[parameters]: {unknown} are not parameters of scenario {scen!r}{on}",
                hint="its parameters: "
                     f"{', '.join(f'{n} [{u}]' for n, u in iface.parameters.items())}")
    spec._axes(dict(iface.parameters or {}))  # every value read with its parameter's unit
    if spec.metrics is not None and iface.metrics is not None:
        missing = [m for m in spec.metrics if m not in iface.metrics]
        if missing:
            raise ConfigError(f"[metrics] record: scenario {scen!r} does not compute {missing}",
                              hint=f"it computes: {', '.join(iface.metrics)}")
    return Prepared(fn, model, iface)


def summarise_warnings(records, text_of: Callable, total: int | None = None) -> None:
    """Issue one warning per category of ``records``, ``(category, text, count, of)`` tuples (a
    warning's text, how many warnings it stands for, out of how many items, None where unknown):
    the first text, the counts summed and the ``of`` summed (None once one is unknown), or
    ``total`` where given (the records are the single warnings of ``total`` items);
    ``text_of(first, count, of)`` is the message. The warning carries ``count``, ``total`` (the
    ``of``) and ``first``, so that they can be summed again: the rows of
    :func:`step_metrics_rows` in a chunk, the chunks of a sweep
    (:func:`gripkit.batch.sweep.run_chunk`)."""
    kinds: dict[type, tuple[str, int, int | None]] = {}
    for category, text, count, of in records:
        first, n, so_far = kinds.get(category, (text, 0, 0))
        kinds[category] = (first, n + count,
                           None if so_far is None or of is None else so_far + of)
    for category, (first, n, of) in kinds.items():
        of = of if total is None else total
        warning = category(text_of(first, n, of))
        warning.count, warning.total, warning.first = n, of, first
        emit_warning(warning, category)


def step_metrics_rows(t: np.ndarray, y: np.ndarray, band: float = 0.02) -> dict[str, np.ndarray]:
    """Step-response metrics of each row of ``y`` (P, N) from rest: final value (mean of the last
    10 %), peak, overshoot %, 10–90 % rise time and settling time into ±``band``
    (:func:`gripkit.sysid.physical.step_response.step_metrics` per row). The rows' warnings
    (an unsettled response) come as one per kind, with how many rows gave it: a sweep of
    thousands of jobs would otherwise print one per job."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rows = [step_metrics(t, yi, y_initial=0.0, band=band) for yi in np.atleast_2d(y)]
    summarise_warnings([(w.category, str(w.message), 1, None) for w in caught],
                       lambda first, count, of: first if count == 1 else
                       f"{count} of {of} responses gave this warning; the first: {first}",
                       total=len(rows))
    return {"final": np.array([r["y_final"] for r in rows]),
            "peak": np.array([r["peak"] for r in rows]),
            **{k: np.array([r[k] for r in rows]) for k in ("overshoot_percent", "rise_time",
                                                           "settling_time")}}


_STEP_DEFAULTS = {"fs": 20000.0, "duration": 0.05, "amplitude": 1.0, "band": 0.02}
_STEP_METRICS = ("final", "peak", "overshoot_percent", "rise_time", "settling_time")


def _step_interface(model, settings: dict) -> Interface:
    """step-response: the model's parameters; fs (Hz) and duration (s) > 0 giving >= 2 samples,
    amplitude in the input's unit, input/output among the model's, band in (0, 1]."""
    if not isinstance(model, Model):
        raise ConfigError("scenario 'step-response' needs a simulation model ([sweep] "
                          "model = ...), found "
                          f"{type(model).__name__ if model is not None else 'none'}",
                          hint="for instance model = \"mass-spring-damper\"")
    ins, outs = {s.name: s.unit for s in model.inputs}, [s.name for s in model.outputs]
    inp = settings.get("input", next(iter(ins)))
    schema = {"fs": POSITIVE_RATE, "duration": POSITIVE_TIME,
              "amplitude": Setting(ins.get(inp, "1")),
              "input": Setting("str", choices=tuple(ins)),
              "output": Setting("str", choices=tuple(outs)),
              "band": FRACTION}
    s = {**_STEP_DEFAULTS, **read_settings(settings, schema, "step-response")}
    n = round(s["duration"] * s["fs"])
    if n < 2:
        raise ConfigError(f"[scenario] duration × fs: {s['duration']:g} s × {s['fs']:g} Hz "
                          f"gives {n} samples, "
                          "expected at least 2", hint="lengthen duration or raise fs")
    p = model.parameters
    # per job its output record and room for two more; per task the input, the time axis and the
    # step-metric temporaries of one row. Measured: 193 MB peak for a task of 10 jobs of 10⁶
    # samples (mass-spring-damper), estimated 264 MB.
    return Interface(parameters={name: p[name].unit for name in p.names}, settings=s,
                     metrics=_STEP_METRICS,
                     bytes_per_job=8 * n * (len(outs) + 2), bytes_per_task=8 * n * (len(ins) + 2),
                     bounds={name: p[name].bounds for name in p.names})


def step_response(model, params: dict[str, np.ndarray], settings: dict) -> dict[str, np.ndarray]:
    """Step of ``amplitude`` on input ``input`` (default: the first) for ``duration`` s at ``fs``
    Hz;
    metrics of output ``output`` (default: the first), see :func:`step_metrics_rows`. ``settings``:
    as read by :func:`_step_interface`."""
    s = _step_interface(model, settings).settings
    in_names = [x.name for x in model.inputs]
    out_names = [x.name for x in model.outputs]
    inp = s.get("input", in_names[0])
    out = s.get("output", out_names[0])
    n_jobs = len(next(iter(params.values()))) if params else 1
    names = model.parameters.names
    unknown = [k for k in params if k not in names]
    if unknown:
        raise ConfigError(f"parameters {unknown} are not parameters of {model.name}",
                          hint=f"its parameters: {', '.join(names)}")
    thetas = np.repeat(model.parameters.vector()[None, :], n_jobs, axis=0)
    for k, v in params.items():
        thetas[:, names.index(k)] = v
    n = int(round(s["duration"] * s["fs"]))
    u = np.zeros((n, len(in_names)))
    u[:, in_names.index(inp)] = s["amplitude"]
    y = model.simulate_batch(thetas, u, 1.0 / s["fs"])[:, :, out_names.index(out)]
    return step_metrics_rows(np.arange(n) / s["fs"], y, s["band"])


step_response.interface = _step_interface
