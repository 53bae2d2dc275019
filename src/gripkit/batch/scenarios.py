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

__all__ = ["SCENARIOS", "resolve", "step_response", "step_metrics", "ftg100_grasp"]

SCENARIOS: dict[str, str] = {
    "step-response": "gripkit.batch.scenarios:step_response",
    "tsfm-grasp": "gripkit.systems.tsfm.grasp_batch:tsfm_grasp",
    "ftg100-grasp": "gripkit.batch.scenarios:ftg100_grasp",
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


def step_metrics(t: np.ndarray, y: np.ndarray, band: float = 0.02) -> dict[str, np.ndarray]:
    """Step-response metrics of each row of ``y`` (P, N) from rest: final value (mean of the last
    10 %), peak, overshoot %, 10–90 % rise time and settling time into ±``band``
    (:func:`gripkit.sysid.step_response.step_metrics` per row)."""
    from ..sysid.step_response import step_metrics as one

    rows = [one(t, yi, y_initial=0.0, band=band) for yi in np.atleast_2d(y)]
    return {"final": np.array([r["y_final"] for r in rows]), "peak": np.array([r["peak"] for r in rows]),
            **{k: np.array([r[k] for r in rows]) for k in ("overshoot_percent", "rise_time", "settling_time")}}


def step_response(model, params: dict[str, np.ndarray], settings: dict) -> dict[str, np.ndarray]:
    """Step of ``amplitude`` on input ``input`` (default: the first) for ``duration`` s at ``fs`` Hz;
    metrics of output ``output`` (default: the first), see :func:`step_metrics`."""
    from ..sim.model import Model

    if not isinstance(model, Model):
        raise ConfigError("scenario 'step-response' needs a simulation model ([sweep] model = ...)")
    from .spec import _si

    fs = _si(settings.get("fs", 20000.0), "[scenario] fs")
    duration = _si(settings.get("duration", 0.05), "[scenario] duration")
    amplitude = _si(settings.get("amplitude", 1.0), "[scenario] amplitude")
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
    return step_metrics(np.arange(n) / fs, y, float(settings.get("band", 0.02)))


_FTG100_PARAMS = ("force", "k0", "gap", "noise_force", "noise_position")
_FTG100_OPTS = ("duration", "damage_threshold", "band", "noise_seed")


def ftg100_grasp(model, params: dict[str, np.ndarray], settings: dict) -> dict[str, np.ndarray]:
    """FT-G100 approach-and-grasp under the hybrid force/position controller
    (:func:`gripkit.control.hybrid.grasp_batch`, already parallel): one grasp per job.

    Parameters (per job): ``force`` (N, commanded), ``k0`` (N/m), ``gap`` (m), ``noise_force``
    (N), ``noise_position`` (m). ``[scenario]``: ``duration`` (s, default 0.06),
    ``damage_threshold`` (N, default 1.5 × force), ``band`` (settling band, default 0.02),
    ``noise_seed``, and any :class:`~gripkit.control.hybrid.HybridForcePosition` field (gains,
    approach_speed, ...). ``model``: an :class:`~gripkit.models.ftg100.FTG100Plant`
    (``model = "gripkit.models.ftg100:FTG100Plant"``, a factory) or None (the nominal plant). Metrics: :data:`gripkit.control.hybrid.METRICS`."""
    import dataclasses

    from ..control.hybrid import METRICS, HybridForcePosition, grasp_batch
    from ..models.ftg100 import FTG100Plant
    from .spec import _si

    if model is not None and not isinstance(model, FTG100Plant):
        raise ConfigError(f"scenario 'ftg100-grasp' needs an FT-G100 plant, found {type(model).__name__}",
                          hint='leave [sweep] model out, or model = "gripkit.models.ftg100:FTG100Plant"')
    plant = model if model is not None else FTG100Plant(check=False)
    unknown = [k for k in params if k not in (*_FTG100_PARAMS, "job_id")]
    if unknown:
        raise ConfigError(f"ftg100-grasp: unknown parameters {unknown}", hint=f"allowed: {', '.join(_FTG100_PARAMS)}")
    fields = {f.name for f in dataclasses.fields(HybridForcePosition)}
    bad = sorted(set(settings) - fields - set(_FTG100_OPTS))
    if bad:
        raise ConfigError(f"[scenario] (ftg100-grasp): unknown keys {bad}",
                          hint=f"allowed: {', '.join(_FTG100_OPTS)} and HybridForcePosition fields")
    gains = {k: (v if isinstance(v, bool) else _si(v, f"[scenario] {k}")) for k, v in settings.items() if k in fields}
    ctrl = HybridForcePosition.for_plant(plant.parameters, **gains)
    n = len(params["job_id"])
    seed = np.asarray(params["job_id"], dtype=np.int64) + int(settings.get("noise_seed", 0)) * 1_000_003
    kw = {k: params[k] for k in _FTG100_PARAMS if k in params}
    kw.setdefault("force", 20e-6)
    dmg = settings.get("damage_threshold")
    b = grasp_batch(ctrl, plant, seed=seed if n else 0, duration=_si(settings.get("duration", 0.06), "[scenario] duration"),
                    damage_threshold=None if dmg is None else _si(dmg, "[scenario] damage_threshold"),
                    band=float(settings.get("band", 0.02)), progress=False, **kw)
    if len(b) != n:
        raise ConfigError(f"ftg100-grasp: {len(b)} results for {n} jobs")
    return {m: b[m] for m in METRICS}


ftg100_grasp.uses_job_id = True
