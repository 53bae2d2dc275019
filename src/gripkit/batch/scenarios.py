"""Sweep scenarios: what one job computes, vectorised over the jobs of a chunk.

A scenario is ``fn(model, params, settings) -> metrics``: ``model`` is the built model (or None),
``params`` maps parameter names to arrays (one value per job), ``settings`` is the sweep's
``[scenario]`` table, and ``metrics`` maps metric names to arrays of the same length. Register new
scenarios in :data:`SCENARIOS` (or name them as ``"package.module:function"`` in the sweep file).
"""

from __future__ import annotations

import importlib

import numpy as np

from ..errors import ConfigError
from ..sim.model import Model
from ..sysid.step_response import step_metrics
from ..units import setting_si

__all__ = ["SCENARIOS", "resolve", "step_response", "step_metrics_rows"]

SCENARIOS: dict[str, str] = {
    "step-response": "gripkit.batch.scenarios:step_response",
    "tsfm-grasp": "gripkit.systems.tsfm.grasp_batch:tsfm_grasp",
    "ftg100-grasp": "gripkit.systems.ftg100.scenario:ftg100_grasp",
}


def resolve(name):
    """The scenario function registered as ``name``, importable as ``module:function``, or
    ``name`` itself when it is a callable (pickled by value for workers)."""
    if callable(name):
        return name
    target = SCENARIOS.get(name, name)
    if ":" not in target:
        raise ConfigError(f"unknown scenario {name!r}", hint=f"registered: {', '.join(SCENARIOS)}; "
                                                               "or give 'package.module:function'")
    module, func = target.split(":", 1)
    try:
        return getattr(importlib.import_module(module), func)
    except (ImportError, AttributeError) as exc:
        raise ConfigError(f"scenario {name!r}: cannot import {target!r} ({exc})") from None


def step_metrics_rows(t: np.ndarray, y: np.ndarray, band: float = 0.02) -> dict[str, np.ndarray]:
    """Step-response metrics of each row of ``y`` (P, N) from rest: final value (mean of the last
    10 %), peak, overshoot %, 10–90 % rise time and settling time into ±``band``
    (:func:`gripkit.sysid.step_response.step_metrics` per row)."""
    rows = [step_metrics(t, yi, y_initial=0.0, band=band) for yi in np.atleast_2d(y)]
    return {"final": np.array([r["y_final"] for r in rows]), "peak": np.array([r["peak"] for r in rows]),
            **{k: np.array([r[k] for r in rows]) for k in ("overshoot_percent", "rise_time", "settling_time")}}


def step_response(model, params: dict[str, np.ndarray], settings: dict) -> dict[str, np.ndarray]:
    """Step of ``amplitude`` on input ``input`` (default: the first) for ``duration`` s at ``fs`` Hz;
    metrics of output ``output`` (default: the first), see :func:`step_metrics_rows`."""
    if not isinstance(model, Model):
        raise ConfigError("scenario 'step-response' needs a simulation model ([sweep] model = ...)")

    fs = setting_si(settings.get("fs", 20000.0), "[scenario] fs")
    duration = setting_si(settings.get("duration", 0.05), "[scenario] duration")
    amplitude = setting_si(settings.get("amplitude", 1.0), "[scenario] amplitude")
    in_names = [s.name for s in model.inputs]
    out_names = [s.name for s in model.outputs]
    inp = settings.get("input", in_names[0])
    out = settings.get("output", out_names[0])
    if inp not in in_names or out not in out_names:
        raise ConfigError(f"[scenario] input/output: {model.name} has inputs {in_names}, outputs {out_names}")
    n_jobs = len(next(iter(params.values()))) if params else 1
    names = model.parameters.names
    unknown = [k for k in params if k not in names]
    if unknown:
        raise ConfigError(f"parameters {unknown} are not parameters of {model.name}",
                          hint=f"its parameters: {', '.join(names)}")
    thetas = np.repeat(model.parameters.vector()[None, :], n_jobs, axis=0)
    for k, v in params.items():
        thetas[:, names.index(k)] = v
    n = int(round(duration * fs))
    u = np.zeros((n, len(in_names)))
    u[:, in_names.index(inp)] = amplitude
    y = model.simulate_batch(thetas, u, 1.0 / fs)[:, :, out_names.index(out)]
    return step_metrics_rows(np.arange(n) / fs, y, float(settings.get("band", 0.02)))
