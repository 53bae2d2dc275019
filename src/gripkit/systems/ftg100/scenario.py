"""The FT-G100 grasp as a sweep scenario (``ftg100-grasp`` in
:data:`gripkit.batch.scenarios.SCENARIOS`):
one approach-and-grasp under the hybrid force/position controller per job, its parameters and
settings declared and checked up front (:class:`gripkit.batch.scenarios.Interface`)."""

from __future__ import annotations

import numpy as np

from ...batch.scenarios import FRACTION, POSITIVE_TIME, Interface, Setting, read_settings
from ...errors import ConfigError
from .hybrid_control import METRICS, HybridForcePosition, grasp_batch
from .model import FTG100Plant

__all__ = ["ftg100_grasp"]

#: ftg100-grasp: per-job parameters and the units of the HybridForcePosition fields (its docstring)
_PARAMS = {"force": "N", "k0": "N/m", "gap": "m", "noise_force": "N", "noise_position": "m"}
_HYBRID_UNITS = {"dt": "s", "kp_x": "N/m", "ki_x": "N/(m*s)", "kd_x": "N*s/m", "tf_x": "s",
                 "kp_f": "1",
                 "ki_f": "1/s", "kd_f": "s", "kv": "N*s/m", "tf_v": "s", "approach_speed": "m/s",
                 "x_limit": "m",
                 "contact_threshold": "N", "confirm": "int", "force_ramp": "s", "force_tau": "s",
                 "k_contact": "N/m", "anti_windup": "bool", "bumpless": "bool", "lever": "1",
                 "k1": "N/m",
                 "k3": "N/m**3", "c_e": "N/V**2", "v_max": "V", "v_min": "V"}
_OPTS = {"duration": POSITIVE_TIME, "damage_threshold": Setting("N", low=0.0, strict=True),
                "band": FRACTION, "noise_seed": Setting("int", low=0)}


def _interface(model, settings: dict) -> Interface:
    if model is not None and not isinstance(model, FTG100Plant):
        raise ConfigError("scenario 'ftg100-grasp' needs an FT-G100 plant, found "
                          f"{type(model).__name__}",
                          hint="leave [sweep] model out (the nominal plant)")
    schema = {**_OPTS, **{k: Setting(u) for k, u in _HYBRID_UNITS.items()}}
    s = read_settings(settings, schema, "ftg100-grasp")
    _controller(model, s)  # the controller's own checks (positive dt, v_min < v_max, ...)
    return (Interface(parameters=_PARAMS, settings=s, metrics=METRICS,
                      bytes_per_job=8 * (len(METRICS) + 64)))


def _controller(model, settings: dict):
    plant = model if model is not None else FTG100Plant(check=False)
    gains = {k: v for k, v in settings.items() if k in _HYBRID_UNITS}
    return plant, HybridForcePosition.for_plant(plant.parameters, **gains)


def ftg100_grasp(model, params: dict[str, np.ndarray], settings: dict) -> dict[str, np.ndarray]:
    """FT-G100 approach-and-grasp under the hybrid force/position controller
    (:func:`gripkit.systems.ftg100.hybrid_control.grasp_batch`, already parallel): one grasp per
    job.

    Parameters (per job): ``force`` (N, commanded), ``k0`` (N/m), ``gap`` (m), ``noise_force``
    (N), ``noise_position`` (m). ``[scenario]``: ``duration`` (s, default 0.06),
    ``damage_threshold`` (N, default 1.5 × force), ``band`` (settling band, default 0.02),
    ``noise_seed``, and any :class:`~gripkit.systems.ftg100.hybrid_control.HybridForcePosition`
    field (gains, approach_speed, ...). ``model``: None (the nominal plant) or an
    :class:`~gripkit.systems.ftg100.model.FTG100Plant` factory (``"module:factory"``, with
    ``allow_code``). Metrics: :data:`gripkit.systems.ftg100.hybrid_control.METRICS`."""
    s = _interface(model, settings).settings
    plant, ctrl = _controller(model, s)
    unknown = [k for k in params if k not in (*_PARAMS, "job_id")]
    if unknown:
        raise ConfigError("ftg100-grasp: unknown "
                          f"parameters {unknown}", hint=f"allowed: {', '.join(_PARAMS)}")
    n = len(params["job_id"])
    seed = np.asarray(params["job_id"], dtype=np.int64) + s.get("noise_seed", 0) * 1_000_003
    kw = {k: params[k] for k in _PARAMS if k in params}
    kw.setdefault("force", 20e-6)
    b = grasp_batch(ctrl, plant, seed=seed if n else 0, duration=s.get("duration", 0.06),
                    damage_threshold=s.get("damage_threshold"), band=s.get("band", 0.02),
                    progress=False, **kw)
    if len(b) != n:
        raise ConfigError(f"ftg100-grasp: {len(b)} results for {n} jobs")
    return {m: b[m] for m in METRICS}


ftg100_grasp.uses_job_id = True
ftg100_grasp.interface = _interface
