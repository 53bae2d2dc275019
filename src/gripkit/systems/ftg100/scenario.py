"""The FT-G100 grasp as a sweep scenario (``ftg100-grasp`` in :data:`gripkit.batch.scenarios.SCENARIOS`):
one approach-and-grasp under the hybrid force/position controller per job."""

from __future__ import annotations

import dataclasses

import numpy as np

from ...errors import ConfigError
from ...units import setting_si
from .hybrid_control import METRICS, HybridForcePosition, grasp_batch
from .model import FTG100Plant

__all__ = ["ftg100_grasp"]

_PARAMS = ("force", "k0", "gap", "noise_force", "noise_position")
_OPTS = ("duration", "damage_threshold", "band", "noise_seed")


def ftg100_grasp(model, params: dict[str, np.ndarray], settings: dict) -> dict[str, np.ndarray]:
    """FT-G100 approach-and-grasp under the hybrid force/position controller
    (:func:`gripkit.systems.ftg100.hybrid_control.grasp_batch`, already parallel): one grasp per job.

    Parameters (per job): ``force`` (N, commanded), ``k0`` (N/m), ``gap`` (m), ``noise_force``
    (N), ``noise_position`` (m). ``[scenario]``: ``duration`` (s, default 0.06),
    ``damage_threshold`` (N, default 1.5 × force), ``band`` (settling band, default 0.02),
    ``noise_seed``, and any :class:`~gripkit.systems.ftg100.hybrid_control.HybridForcePosition` field (gains,
    approach_speed, ...). ``model``: an :class:`~gripkit.systems.ftg100.model.FTG100Plant`
    (``model = "gripkit.systems.ftg100.model:FTG100Plant"``, a factory) or None (the nominal plant). Metrics: :data:`gripkit.systems.ftg100.hybrid_control.METRICS`."""
    if model is not None and not isinstance(model, FTG100Plant):
        raise ConfigError(f"scenario 'ftg100-grasp' needs an FT-G100 plant, found {type(model).__name__}",
                          hint='leave [sweep] model out, or model = "gripkit.systems.ftg100.model:FTG100Plant"')
    plant = model if model is not None else FTG100Plant(check=False)
    unknown = [k for k in params if k not in (*_PARAMS, "job_id")]
    if unknown:
        raise ConfigError(f"ftg100-grasp: unknown parameters {unknown}", hint=f"allowed: {', '.join(_PARAMS)}")
    fields = {f.name for f in dataclasses.fields(HybridForcePosition)}
    bad = sorted(set(settings) - fields - set(_OPTS))
    if bad:
        raise ConfigError(f"[scenario] (ftg100-grasp): unknown keys {bad}",
                          hint=f"allowed: {', '.join(_OPTS)} and HybridForcePosition fields")
    gains = {k: (v if isinstance(v, bool) else setting_si(v, f"[scenario] {k}")) for k, v in settings.items() if k in fields}
    ctrl = HybridForcePosition.for_plant(plant.parameters, **gains)
    n = len(params["job_id"])
    seed = np.asarray(params["job_id"], dtype=np.int64) + int(settings.get("noise_seed", 0)) * 1_000_003
    kw = {k: params[k] for k in _PARAMS if k in params}
    kw.setdefault("force", 20e-6)
    dmg = settings.get("damage_threshold")
    b = grasp_batch(ctrl, plant, seed=seed if n else 0, duration=setting_si(settings.get("duration", 0.06), "[scenario] duration"),
                    damage_threshold=None if dmg is None else setting_si(dmg, "[scenario] damage_threshold"),
                    band=float(settings.get("band", 0.02)), progress=False, **kw)
    if len(b) != n:
        raise ConfigError(f"ftg100-grasp: {len(b)} results for {n} jobs")
    return {m: b[m] for m in METRICS}


ftg100_grasp.uses_job_id = True
