"""Many TSFM two-finger grasps at once, metrics only: the batch form of
:func:`gripkit.systems.tsfm.grasp.simulate_two_finger_grasp` (``001_0b92a7da96e7aa46.txt``
§I, §V), registered as the sweep scenario ``tsfm-grasp``.

Each job is one closed-loop grasp of a micropart drawn from a population: stiffness ``k_e``
(N/m), width ``w`` (m), position (``X_p``, m from finger 1's rest tip, or ``offset`` from the
centre of the gap), damping ``c_e``, pull-off ``F_po``, substrate friction ``F_stick``, the
approach speed (contact timing: with the part's faces ``(gap − w)/2 ± offset`` away, the fingers
touch after gap/speed) and the force-sensor noise ``noise_std`` (N). The loop is the same numba
code as the single grasp (:func:`~gripkit.systems.tsfm.grasp.grasp_step` and
:func:`~gripkit.systems.tsfm.gripper.gripper_advance`, called in the same order), but instead of a
(N, 15) record each job reduces its samples on the fly to the :data:`METRICS` — 10 000 grasps of
2000 samples would otherwise be 2.4 GB.

Per-job setup. Only the contact mode of each finger depends on the part (k_side = 2 k_e,
c_side = 2 c_e per side, pull-off F_po/k_side, see
:class:`~gripkit.systems.tsfm.gripper.TSFMGripper`):
its ZOH matrices (13 dyadic levels) are recomputed per job in numba (:func:`_job_setup`: two
9×9 matrix exponentials per finger, a small part of a grasp's cost: docs/performance.md); the free
mode, the estimators and the fingers' hysteresis come from one template per gripper. The contact
mode is built exactly as
:func:`~gripkit.systems.tsfm.gripper.finger_hybrid` builds it (A + b_F kᵀ, [B_W, −k b_F]), so a job
reproduces the single-grasp simulation bit for bit (tested).

Metrics (times in s from the start; forces are the true contact forces at the samples):

* ``t_contact1``, ``t_contact2``: first sample in contact (NaN if never);
* ``t_squeeze``: both fingers detected, force control starts (NaN if never);
* ``peak_force``: largest contact force of either finger; ``damage`` = peak > ``damage_force``;
* ``max_displacement``: largest |X_p − X_p(0)| of the part (it slides on the substrate when the
  finger forces differ by more than F_stick);
* ``grasped``: at the last sample both fingers touch the part and squeeze it;
  ``lost`` = not grasped, or displaced by more than ``lost_displacement``;
* ``settling_time``: from ``t_squeeze`` until the grip force (F₁ + F₂)/2 stays within
  ± ``band`` × ``grip_force`` (inf if it never does within the record);
* ``final_error``: mean grip-force error over the last 10 % of the record, relative to the command;
  ``final_force`` the mean grip force there (N);
* ``width_error``: the seed's threshold width gap − (ŷ₁c + ŷ₂c) minus the true width (m, §V-C);
* ``stiffness_error``: eq 16's k̂ = F̄/δ (measured force and estimated deformation, both averaged
  over the last 10 %) relative to k_e, minus 1.
"""

from __future__ import annotations

import collections
import contextlib
import math
from concurrent.futures import ThreadPoolExecutor
from dataclasses import replace

import numba
import numpy as np

from ...batch.scenarios import (FRACTION, POSITIVE_RATE, POSITIVE_TIME, Interface, Setting,
                                read_settings)
from ...errors import ConfigError
from ...estimation.contact_detection import ContactDetector
from ...progress import track
from .grasp import GraspSettings
from .grasp_kernels import (_NM, _SQUEEZE, METRICS, GraspTemplate, _default_gripper, _grasp_jobs,
                            _template)
from .gripper import TSFMGripper

__all__ = ["METRICS", "FAST_GRASP", "tsfm_grasp_batch", "record_metrics", "tsfm_grasp",
           "GraspTemplate",
           "POPULATION_NAMES"]

#: per-job parameters a population may vary (with ``offset`` as an alternative to ``X_p``)
POPULATION_NAMES = ("k_e", "w", "X_p", "offset", "c_e", "F_po", "F_stick", "approach_speed",
                    "noise_std")
# : their SI units (those of the part parameters of
# :class:`~gripkit.systems.tsfm.gripper.TSFMGripper`); ``gap`` too
POPULATION_UNITS = {"k_e": "N/m", "w": "m", "X_p": "m", "offset": "m", "c_e": "N*s/m", "F_po": "N",
                    "F_stick": "N",
                    "approach_speed": "m/s", "noise_std": "N", "gap": "m"}

#: a grasp that finishes in ~0.1 s (1 mm/s approach, 10 ms force ramp, 40 Hz force loop), used by
#: the batch scenario unless told otherwise; the single-grasp defaults (40 µm/s, 0.3 s) take seconds
FAST_GRASP = GraspSettings(approach_speed=1e-3, force_ramp_time=0.01, force_bandwidth_hz=40.0)

def _jobs(tpl: GraspTemplate, settings: GraspSettings, n_jobs: int, arrays: dict, noise_seed: int,
          job_ids):
    """Per-job part vectors, controller vectors, noise std and seeds; ConfigError on a bad job."""
    P = n_jobs

    def col(name, default):
        v = arrays.get(name)
        out = (np.full(P, float(default)) if v is None
               else np.asarray(v, dtype=np.float64).reshape(-1))
        if out.shape != (P,):
            raise ConfigError(f"{name}: expected one value or {P}, found shape {np.shape(v)}")
        if not np.isfinite(out).all():
            raise ConfigError(f"{name}: expected finite values, found {out[~np.isfinite(out)][:3]}")
        return out

    gap = col("gap", tpl.value("gap"))
    w = col("w", tpl.value("w"))
    k_e = col("k_e", tpl.value("k_e"))
    c_e = col("c_e", tpl.value("c_e"))
    F_po = col("F_po", tpl.value("F_po"))
    F_stick = col("F_stick", tpl.value("F_stick"))
    if arrays.get("X_p") is not None and arrays.get("offset") is not None:
        raise ConfigError("give the part's position as X_p or as offset (from the "
                          "centre), not both")
    X_p = col("X_p", 0.0) if arrays.get("X_p") is not None else gap / 2 + col("offset", 0.0)
    speed = col("approach_speed", settings.approach_speed)
    nstd = col("noise_std", arrays.get("_noise_default", 2e-6))
    for name, v, lo in (("k_e", k_e, 0.0), ("w", w, 0.0), ("approach_speed", speed, 0.0)):
        if (v <= lo).any():
            raise ConfigError(f"{name}: expected positive values, found {v[v <= lo][:3]}")
    for name, v in (("c_e", c_e), ("F_po", F_po), ("F_stick", F_stick), ("noise_std", nstd)):
        if (v < 0).any():
            raise ConfigError(f"{name}: expected values >= 0, found {v[v < 0][:3]}")
    bad = (w >= gap) | (X_p < w / 2) | (X_p > gap - w / 2)
    if bad.any():
        i = int(np.argmax(bad))
        raise ConfigError(f"part {i}: width {w[i] * 1e6:.4g} µm at X_p = {X_p[i] * 1e6:.4g} µm "
                          "does not fit between "
                          "the fingers (gap "
                          f"{gap[i] * 1e6:.4g} µm)", hint="keep w/2 <= X_p <= gap - w/2")
    parts = np.ascontiguousarray(np.column_stack([w, gap, 2 * k_e, 2 * c_e, F_po, F_stick, X_p]))
    cp0 = settings.vector(tpl.gains, tpl.dt)
    cps = np.repeat(cp0[None, :], P, axis=0)
    cps[:, 0] = speed
    ids = (np.arange(P, dtype=np.int64) if job_ids is None
           else np.asarray(job_ids, dtype=np.int64).reshape(-1))
    seeds = (ids + np.int64(noise_seed) * np.int64(1_000_003)).astype(np.int64)
    cols = dict(k_e=k_e, w=w, X_p=X_p, c_e=c_e, F_po=F_po, F_stick=F_stick, gap=gap,
                approach_speed=speed,
                noise_std=nstd)
    return parts, np.ascontiguousarray(cps), np.ascontiguousarray(nstd), seeds, cols


def tsfm_grasp_batch(gripper=None, *, settings: GraspSettings = FAST_GRASP, duration: float = 0.1,
                     dt: float = 5e-05, k_e=None, w=None, X_p=None, offset=None, c_e=None,
                     F_po=None,
                     F_stick=None, gap=None, approach_speed=None, noise_std=2e-6,
                     noise_seed: int = 0,
                     job_ids=None, noise=None, damage_force: float | None = None,
                     lost_displacement: float = 10e-6,
                     band: float = 0.05, estimator_fingers=None, backend: str = "cpu",
                     serial: bool = False,
                     progress: bool = False) -> dict[str, np.ndarray]:
    """Simulate many grasps of the two-finger loop on ``gripper`` (default: the zoo's
    ``tsfm-gripper``) and return their :data:`METRICS` and the per-job parameters as columns.

    Per-job arrays (broadcast against each other; unset ones take the gripper's values): ``k_e``
    (N/m), ``w`` (m), ``X_p`` (m from finger 1's rest tip) or ``offset`` (m from mid-gap),
    ``c_e`` (N·s/m), ``F_po``, ``F_stick`` (N), ``gap`` (m), ``approach_speed`` (m/s, default the
    settings'), ``noise_std`` (N). The noise of job j comes from its own splitmix64 stream seeded
    by ``job_ids[j]`` (default j) and ``noise_seed``: results do not depend on chunking or thread
    scheduling. ``noise`` (P, N, 2), if given, is used instead (N = duration/dt samples).
    ``damage_force`` defaults to 1.25 × ``settings.grip_force``. ``backend``: 'cpu' (the
    nogil numba kernel on ``numba.get_num_threads()`` threads, one with ``serial=True``) or 'cuda'
    (:mod:`gripkit.systems.tsfm.grasp_gpu`, needs a CUDA device).
    """
    if not (math.isfinite(duration) and duration > 0 and math.isfinite(dt) and dt > 0):
        raise ConfigError(f"duration and dt must be positive, found {duration!r} s, {dt!r} s")
    if not (math.isfinite(band) and 0 < band < 1):
        raise ConfigError(f"band: expected a fraction in (0, 1), found {band!r}")
    if not isinstance(settings, GraspSettings):
        raise ConfigError(f"settings: expected a GraspSettings, found {type(settings).__name__}")
    gripper = gripper if gripper is not None else _default_gripper()
    n_steps = int(round(duration / dt))
    tpl = _template(gripper, dt, estimator_fingers)
    given = dict(k_e=k_e, w=w, X_p=X_p, offset=offset, c_e=c_e, F_po=F_po, F_stick=F_stick, gap=gap,
                 approach_speed=approach_speed, noise_std=noise_std)
    present = {k: np.asarray(v, dtype=np.float64) for k, v in given.items() if v is not None}
    shape = (np.broadcast_shapes(*(v.shape for v in present.values()),
                                 () if job_ids is None else np.shape(job_ids)))
    P = int(np.prod(shape)) if shape else 1
    arrays = ({k: np.broadcast_to(v, shape).reshape(-1) if shape else v.reshape(1)
               for k, v in present.items()})
    parts, cps, nstd, seeds, cols = _jobs(tpl, settings, P, arrays, noise_seed, job_ids)
    dmg = 1.25 * settings.grip_force if damage_force is None else float(damage_force)
    if not (dmg > 0 and lost_displacement > 0):
        raise ConfigError("damage_force and lost_displacement must be positive")
    mset = np.array([dmg, float(lost_displacement), float(band)])
    if noise is None:
        nz = np.zeros((1, 0, 2))
    else:
        nz = np.ascontiguousarray(np.asarray(noise, dtype=np.float64))
        if nz.shape != (P, n_steps, 2) or not np.isfinite(nz).all():
            raise ConfigError(f"noise: expected finite values of shape ({P}, {n_steps}, 2), "
                              f"found {nz.shape}")
    met = np.empty((P, _NM))
    if backend == "cuda":
        from .grasp_gpu import run_cuda

        run_cuda(tpl, parts, nz, nstd, seeds, n_steps, settings.window, cps, mset, met)
    elif backend == "cpu":
        _run_cpu(tpl, parts, nz, nstd, seeds, n_steps, settings.window, cps, mset, met,
                 1 if serial else None,
                 progress)
    else:
        raise ConfigError(f"backend: expected 'cpu' or 'cuda', found {backend!r}")
    return {**cols, **{m: met[:, i] for i, m in enumerate(METRICS)}}


def _run_cpu(tpl, parts, nz, nstd, seeds, n_steps, window, cps, mset, met, threads=None,
             progress=False):
    """Slices of the jobs on ``threads`` threads (default numba's thread count, 1 in a pinned
    worker process) running the nogil kernel :func:`_grasp_jobs`; the results land in ``met``."""
    P = parts.shape[0]
    threads = max(1, min(numba.get_num_threads() if threads is None else int(threads), P))
    size = max(1, min(64, -(-P // (4 * threads))))   # small slices: even load, a live progress bar

    def run(a):
        b = min(P, a + size)
        _grasp_jobs(tpl.kernel_args(), parts[a:b], nz if nz.shape[0] == 1 else nz[a:b], nstd[a:b],
                    seeds[a:b],
                    n_steps, window, cps[a:b], mset, met[a:b])
        return b - a

    starts = range(0, P, size)
    with ThreadPoolExecutor(threads) if threads > 1 else contextlib.nullcontext() as pool:
        slices = pool.map(run, starts) if pool else map(run, starts)
        # drain the slices (each writes its rows of met in place) while the bar advances
        collections.deque(track(slices, total=len(starts), description="TSFM grasps",
                                enabled=progress and P > 256), maxlen=0)


def record_metrics(result, *, gap: float | None = None, width: float | None = None,
                   stiffness: float | None = None,
                   damage_force: float | None = None, lost_displacement: float = 10e-6,
                   band: float = 0.05) -> dict[str, float]:
    """The :data:`METRICS` of one recorded grasp (a
    :class:`~gripkit.systems.tsfm.grasp.TwoFingerGraspResult`), computed from its record with
    numpy: the reference the batch kernel is tested against. ``gap``, ``width`` (m) and
    ``stiffness`` (N/m) are the truth for the estimate errors (NaN without them)."""
    tr = result.trajectory
    s = result.settings
    dt = tr.meta["dt"]
    n = tr.t.size
    fcmd = s.grip_force
    dmg = 1.25 * fcmd if damage_force is None else damage_force
    F1, F2 = tr["F_g1"], tr["F_g2"]

    def first(mask):
        idx = np.flatnonzero(mask)
        return int(idx[0]) if idx.size else -1

    c1, c2 = first(tr["contact1"] > 0.5), first(tr["contact2"] > 0.5)
    sq = first(tr["phase1"] == _SQUEEZE)
    peak = float(max(F1.max(), F2.max(), 0.0))
    maxd = float(np.abs(tr["X_p"] - tr["X_p"][0]).max())
    grasped = bool(tr["contact1"][-1] == 1 and tr["contact2"][-1] == 1
                   and tr["phase1"][-1] == _SQUEEZE
                   and tr["phase2"][-1] == _SQUEEZE)
    fbar = 0.5 * (F1 + F2)
    settle = math.inf
    if sq >= 0:
        out = np.flatnonzero(np.abs(fbar[sq:] - fcmd) > band * fcmd)
        last = sq + int(out[-1]) if out.size else -1
        settle = math.inf if last == n - 1 else max(0.0, (last + 1) * dt - sq * dt)
    tail = slice(n - max(1, n // 10), n)
    nan = math.nan
    m = dict(t_contact1=c1 * dt if c1 >= 0 else nan, t_contact2=c2 * dt if c2 >= 0 else nan,
             t_squeeze=sq * dt if sq >= 0 else nan, peak_force=peak, damage=float(peak > dmg),
             max_displacement=maxd, grasped=float(grasped),
             lost=float((not grasped) or maxd > lost_displacement),
             settling_time=settle, final_error=float((fbar[tail].mean() - fcmd) / fcmd),
             final_force=float(fbar[tail].mean()), width_error=nan, stiffness_error=nan)
    i1, i2 = (first(ContactDetector(s.threshold, window=s.window,
                                    release=s.release).run(tr[f"F_meas{i}"])[0])
              for i in (1, 2))
    if i1 >= 0 and i2 >= 0 and gap is not None and width is not None:
        ysum = float(tr["y_hat1"][i1] + tr["y_hat2"][i2])
        m["width_error"] = gap - ysum - width
        delta = float((tr["y_hat1"] + tr["y_hat2"])[tail].mean()) - ysum
        if grasped and delta > 0 and stiffness is not None:
            m["stiffness_error"] = (float((0.5 * (tr["F_meas1"] + tr["F_meas2"]))[tail].mean())
                                    / delta / stiffness - 1)
    return m


# ------------------------------------------------------------------------------------------------
# the sweep scenario
# ------------------------------------------------------------------------------------------------

_SETTING_KEYS = {"grip_force": "N", "approach_speed": "m/s", "position_bandwidth_hz": "Hz",
                 "force_bandwidth_hz": "Hz", "force_ramp_time": "s", "threshold": "N",
                 "release": "N",
                 "window": "1", "u_min": "V", "u_max": "V", "max_closing": "m", "k_min": "N/m",
                 "k_max": "N/m",
                 "wait_for_other": "bool"}
_OTHER_KEYS = ("duration", "fs", "damage_force", "lost_displacement", "band", "noise_std",
               "noise_seed", "backend")


def _settings_schema() -> dict:
    kinds = {"bool": Setting("bool"), "1": Setting("int", low=1)}
    return {**{k: kinds.get(u, Setting(u)) for k, u in _SETTING_KEYS.items()},
            "duration": POSITIVE_TIME, "fs": POSITIVE_RATE,
            "damage_force": Setting("N", low=0.0, strict=True),
            "lost_displacement": Setting("m", low=0.0, strict=True), "band": FRACTION,
            "noise_std": Setting("N", low=0.0), "noise_seed": Setting("int", low=0),
            "backend": Setting("str", choices=("cpu", "cuda"))}


def settings_from_table(table: dict) -> tuple[GraspSettings, dict]:
    """(GraspSettings, other options) from a sweep's ``[scenario]`` table; numbers in SI or
    strings with units ("200 uN"), checked (:func:`gripkit.batch.scenarios.read_settings`).
    Starts from :data:`FAST_GRASP`."""
    s = read_settings(table, _settings_schema(), "tsfm-grasp")
    return replace(FAST_GRASP, **{k: v for k, v in s.items() if k in _SETTING_KEYS}), \
        {k: v for k, v in s.items() if k in _OTHER_KEYS}


def _interface(model, settings: dict):
    if model is not None and not isinstance(model, TSFMGripper):
        raise ConfigError("scenario 'tsfm-grasp' needs a TSFM gripper model, found "
                          f"{type(model).__name__}",
                          hint='model = "tsfm-gripper"')
    positive, non_negative = (np.finfo(float).tiny, None), (0.0, None)  # as _jobs checks them
    bounds = {**{k: positive for k in ("k_e", "w", "approach_speed", "gap")},
              **{k: non_negative for k in ("c_e", "F_po", "F_stick", "noise_std")}}
    return Interface(parameters=POPULATION_UNITS,
                     settings=read_settings(settings, _settings_schema(), "tsfm-grasp"),
                     metrics=METRICS, bytes_per_job=8 * (_NM + 64), bounds=bounds)


def tsfm_grasp(model, params: dict[str, np.ndarray], settings: dict) -> dict[str, np.ndarray]:
    """Sweep scenario ``tsfm-grasp``: one TSFM grasp per job (see the module docstring).
    ``model``: a :class:`~gripkit.systems.tsfm.gripper.TSFMGripper` (``model = "tsfm-gripper"``) or
    None
    (the zoo's). Parameters: any of :data:`POPULATION_NAMES`; ``[scenario]``: the
    :class:`GraspSettings` fields and duration, fs, damage_force, lost_displacement, band,
    noise_std (when not a parameter), noise_seed, backend ('cpu' | 'cuda')."""
    if model is not None and not isinstance(model, TSFMGripper):
        raise ConfigError("scenario 'tsfm-grasp' needs a TSFM gripper model, found "
                          f"{type(model).__name__}",
                          hint='model = "tsfm-gripper"')
    unknown = [k for k in params if k not in POPULATION_NAMES and k not in ("job_id", "gap")]
    if unknown:
        raise ConfigError("tsfm-grasp: unknown "
                          f"parameters {unknown}", hint=f"allowed: {', '.join(POPULATION_NAMES)}")
    gs, opts = settings_from_table(settings)
    kw = {k: v for k, v in params.items() if k != "job_id"}
    if "noise_std" not in kw:
        kw["noise_std"] = opts.get("noise_std", 2e-6)
    res = tsfm_grasp_batch(model, settings=gs, duration=opts.get("duration", 0.1),
                           dt=1.0 / opts.get("fs", 20000.0),  # the sweep file gives a rate in Hz
                           job_ids=params.get("job_id"), noise_seed=int(opts.get("noise_seed", 0)),
                           damage_force=opts.get("damage_force"),
                           lost_displacement=opts.get("lost_displacement", 10e-6),
                           band=float(opts.get("band", 0.05)),
                           backend=str(opts.get("backend", "cpu")), **kw)
    return {m: res[m] for m in METRICS}


tsfm_grasp.uses_job_id = True
tsfm_grasp.interface = _interface
