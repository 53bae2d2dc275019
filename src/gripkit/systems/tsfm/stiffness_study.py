"""Table III of ``001_0b92a7da96e7aa46.txt`` reproduced: the seed's whole estimation protocol run on
simulated experiments, gripkit's micropart stiffness estimates with standard deviations beside the
seed's "Estimated" column.

The protocol (the seed's, step by step; the truth is Table II for the fingers, with gripkit's
m_s, b_s from the measured f0 and ζ, see :mod:`.parameters`, and Table III's "Measured" column for
the parts):

1. **§IV: identify both fingers** from simulated records with the noise the seed states
   (:data:`MEASUREMENT_NOISE`): the force sensor's k_s from a calibration against the FemtoTools
   reference (§IV-A/B, :func:`.parameters.sensor_calibration_experiment`), then
   :func:`.identification.identify_finger` — Bouc-Wen from the 100 V loop at 0.1 Hz (Fig. 9), D(s)
   from a 50 V step (Fig. 10), s_p from a force ramp at B (eq 15, Fig. 11), f0 and ζ from the free
   vibration (Fig. 8).
2. **§V-D: grasp each part** of Table III (k_e = the "Measured" stiffness; 300 µm wide like the part
   of §V-C, 30 µm off-centre, squeezed to 200 µN — the seed gives neither width nor force for these
   parts) in closed loop on the true gripper, the controller's tip estimates coming from the
   *identified* fingers (:func:`.grasp.simulate_two_finger_grasp`), 2 µN force noise per sensor
   (§V-C).
3. **Eq 16** from the record: the tips re-estimated offline by eq 11 with the identified fingers
   (:class:`.tip_position.TipPositionEstimator`), then k̂ = F_g/δ as the slope of the loading line
   (:func:`.micropart.estimate_micropart`).

Two details of step 3, both measured on this model:

* **The force fed to eq 11 offline is low-passed** (4th-order Butterworth at
  :data:`FORCE_CUTOFF_HZ`, zero phase). Eq 11 passes the measured force through the sensor's own
  mode (8.52 kHz, ζ = 0.006, Q ≈ 83), so white force noise makes the estimated tips ring by
  ±0.5 µm, in step with the force noise itself; on the loading line of a stiff part (δ ≈ 0.4 µm at
  469 N/m) that errors-in-variables coupling biased k̂ by −1 % (−3σ). The squeeze is quasi-static
  (a 0.3 s force ramp), so nothing is lost below 100 Hz.
* **Blocks of** :data:`BLOCK` **samples** (10 ms) on the loading line: longer than the filter's
  memory, so the block residuals are close to independent and the regression's σ matches the
  spread of repeated runs.
* **Instrumental variables** (:data:`INSTRUMENT_LAG` blocks back): the squeeze runs under force
  control, so the fingers move in response to the measured force's noise and the position sum of a
  block is correlated with the force noise of the same block; least squares then read k̂ low by
  3e-4 on the 12.1 N/m part (−1σ on average). The position sum two blocks earlier is free of that
  noise (causality, and 20 ms clears the filter's memory) and nearly collinear with the current one.

With the truth as estimator model, over 40 noise draws per part, the mean of (k̂ − k)/σ_noise is
−0.07, 0.05 and 0.23 and its RMS 1.01, 1.05 and 1.02 (12.1, 72.5, 469 N/m).

Standard deviation of k̂: σ² = σ²_noise + J Σ Jᵀ, σ_noise from the loading-line regression, Σ the
covariance of the identified parameters of both fingers (block-diagonal: the Bouc-Wen fit's, the
(a, b) fit's, and the variances of s_p, m_s, b_s, k_s) and J = ∂k̂/∂θ by central differences,
re-running step 3 on the same record. The sensitivity of k̂ to the sensors' stiffness k_s is
reported too (:attr:`StiffnessComparison.k_s_sensitivity`): for a stiff part δ is a small
difference of the tips' motion and the sensors' deflection F/k_s, so a small calibration error in
k_s becomes a large error in k̂ — the plausible source of the seed's 5 % on its stiffest part.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...consistency import Finding
from ...errors import DataError
from ...progress import track
from ...signals.filters import lowpass
from .end_effector import lever_coefficients
from .grasp import GraspSettings, TwoFingerGraspResult, simulate_two_finger_grasp
from .identification import FingerIdentification, identify_compliance, identify_finger
from .micropart import MicropartEstimate, estimate_micropart
from .parameters import (ASSUMED_LENGTHS, SEED, TABLE_III, compliance_experiment, finger,
                         free_vibration_experiment,
                         gripper, hysteresis_experiment, sensor_calibration_experiment,
                         step_experiment,
                         table_iii_findings)
from .tip_position import TipPositionEstimator

__all__ = ["MEASUREMENT_NOISE", "FORCE_CUTOFF_HZ", "BLOCK", "INSTRUMENT_LAG", "StiffnessComparison",
           "TableIIIStudy",
           "identify_fingers", "table_iii_study"]

#: white measurement noise of the simulated experiments (standard deviations, SI), with sources
MEASUREMENT_NOISE = {
    "laser_m": (20e-9, f"{SEED} §IV-A: Keyence laser sensors, 20 nm resolution (tips B, "
                       "Figs 9, 10, 11)"),
    "reference_force_N": (0.4e-6, f"{SEED} §IV-A: FemtoTools FT-S270 reference sensor, "
                                  "0.4 µN resolution"),
    "stage_m": (1e-9, f"{SEED} §IV-A: P-611.3 NanoCube stage, 1 nm resolution"),
    "vibration_relative": (0.01, "assumed: 1 % of the 150 µN preload on the free-vibration "
                                 "record (Fig. 8)"),
    "sensor_force_N": (2e-6, f"{SEED} §V-C: integrated force sensors, noise below 2 µN"),
}
# : low-pass (Hz) of the force fed to eq 11 when the tips are re-estimated offline (see the module
# docstring)
FORCE_CUTOFF_HZ = 100.0
#: samples per point of the loading line (10 ms at 20 kHz)
BLOCK = 200
#: blocks between a force block and the position block that serves as its instrument
INSTRUMENT_LAG = 2
_DT = 5e-05  # s (20 kHz)
_PART_WIDTH, _PART_CENTRE = 300e-6, 170e-6
# the parameters of a finger whose uncertainty is propagated into k̂
_PROPAGATED = ("d_p", "lam", "beta", "gamma", "a", "b", "s_p", "m_s", "b_s", "k_s")


@dataclass(frozen=True)
class StiffnessComparison:
    """One row of Table III: the seed's numbers and gripkit's (N/m unless said).

    ``true``: the "Measured" column, the simulated part's stiffness; ``seed_estimate`` and
    ``seed_error_printed``: the seed's "Estimated" and "Error" columns; ``estimate`` ± ``std``:
    gripkit's k̂, with ``std_noise`` (loading-line regression) and ``std_model`` (identified
    parameters) the two parts of ``std``; ``k_s_sensitivity``: ∂ln k̂/∂ln k_s with both sensors'
    k_s scaled together; ``estimate_detail``: the eq-16 estimate itself (width, contacts, ...).
    """

    part: int
    true: float
    seed_estimate: float
    seed_error_printed: float
    estimate: float
    std: float
    std_noise: float
    std_model: float
    k_s_sensitivity: float
    estimate_detail: MicropartEstimate

    @property
    def seed_error(self) -> float:
        """The seed's error recomputed from its columns, (k̂ − k)/k (signed)."""
        return self.seed_estimate / self.true - 1.0

    @property
    def error(self) -> float:
        """gripkit's relative error (k̂ − k)/k."""
        return self.estimate / self.true - 1.0

    @property
    def z(self) -> float:
        """(k̂ − k)/σ."""
        return (self.estimate - self.true) / self.std

    @property
    def k_s_error_for_seed_error(self) -> float:
        """The relative error of both sensors' k_s that alone would move gripkit's k̂ by the seed's
        error (first order)."""
        return self.seed_error / self.k_s_sensitivity if self.k_s_sensitivity else math.nan

    def to_dict(self) -> dict:
        return {"part": self.part, "true": self.true, "seed_estimate": self.seed_estimate,
                "seed_error_printed": self.seed_error_printed, "seed_error": self.seed_error,
                "estimate": self.estimate, "std": self.std, "std_noise": self.std_noise,
                "std_model": self.std_model,
                "error": self.error, "z": self.z, "k_s_sensitivity": self.k_s_sensitivity,
                "k_s_error_for_seed_error": self.k_s_error_for_seed_error,
                "width": self.estimate_detail.width, "width_std": self.estimate_detail.width_std}


@dataclass(frozen=True)
class TableIIIStudy:
    """The result of :func:`table_iii_study`: one :class:`StiffnessComparison` per part, the
    identified fingers (``identified['left'|'right']``, parameters with std), the grasp records,
    the seed's own Table III arithmetic checked (``findings``) and the noise levels used."""

    rows: tuple[StiffnessComparison, ...]
    identified: dict
    grasps: dict = field(repr=False)
    findings: tuple[Finding, ...]
    noise: dict
    seed: int

    def table(self) -> list[dict]:
        """One dict per part (:meth:`StiffnessComparison.to_dict`)."""
        return [r.to_dict() for r in self.rows]

    def to_dict(self) -> dict:
        return {"rows": self.table(), "findings": [f.to_dict() for f in self.findings],
                "noise": {k: v[0] for k, v in self.noise.items()}, "seed": self.seed,
                "identified": {side: ident.table() for side, ident in self.identified.items()}}


def identify_fingers(*, seed: int = 0, noise: dict = MEASUREMENT_NOISE,
                     progress: bool = False) -> dict:
    """Step 1: both fingers of Table II identified as in §IV from simulated records (module
    docstring); returns ``{'left': FingerIdentification, 'right': ...}``. ``seed`` draws the
    noise."""
    out = {}
    for i, side in enumerate(("left", "right")):
        f = finger(side, check=False)
        s = 100 * seed + 10 * i
        cal = sensor_calibration_experiment(f, stage_noise=noise["stage_m"][0],
                                            force_noise=noise["reference_force_N"][0], seed=s)
        c = identify_compliance(cal["F"], -cal["x"])
        k_s, k_s_std = 1.0 / c.compliance, c.compliance_std / c.compliance**2
        loops = hysteresis_experiment(f, (100.0,), noise=noise["laser_m"][0], seed=s + 1)
        step = step_experiment(f, noise=noise["laser_m"][0], seed=s + 2)
        comp = compliance_experiment(f, noise=noise["laser_m"][0],
                                     force_noise=noise["reference_force_N"][0],
                                     seed=s + 3)
        vib = free_vibration_experiment(f, noise=noise["vibration_relative"][0], seed=s + 4)
        out[side] = identify_finger(loops, step, comp, vib, k_s=k_s, k_s_std=k_s_std,
                                    **ASSUMED_LENGTHS,
                                    progress=progress)
    return out


def parameter_covariance(ident: FingerIdentification) -> np.ndarray:
    """Covariance (SI) of the identified parameters ``_PROPAGATED`` of one finger: the Bouc-Wen
    fit's block (d_p, λ converted from B to A by 1 + 2L_r/L_a, eq 14), the last (a, b) fit's block,
    and the variances of s_p, m_s, b_s and k_s."""
    p = ident.finger.parameters
    n = len(_PROPAGATED)
    cov = np.zeros((n, n))
    for name in _PROPAGATED:
        i = _PROPAGATED.index(name)
        cov[i, i] = (p[name].std or 0.0) ** 2
    bw = ident.bouc_wen.fit
    g = lever_coefficients(p.value("L_r"), p.value("L_a")).alpha_u
    scale = {"d_p": 1.0 / g, "lam": 1.0 / g}
    names = {"lambda": "lam"}
    idx = [_PROPAGATED.index(names.get(k, k)) for k in bw.free]
    sc = np.array([scale.get(names.get(k, k), 1.0) for k in bw.free])
    cov[np.ix_(idx, idx)] = bw.covariance * np.outer(sc, sc)
    ab = ident.dynamics.fit
    idx = [_PROPAGATED.index(k) for k in ab.free]
    cov[np.ix_(idx, idx)] = ab.covariance
    return cov


def _estimate(record, values: tuple[dict, dict], gap: float) -> MicropartEstimate:
    """Step 3 on a grasp record: eq 11 offline with the given finger values, then eq 16."""
    y = []
    for i, v in enumerate(values, 1):
        F = lowpass(record[f"F_meas{i}"], FORCE_CUTOFF_HZ, dt=_DT, order=4, zero_phase=True)
        y.append(TipPositionEstimator(v, _DT).run(record[f"U{i}"], F))
    return estimate_micropart(y[0], record["F_meas1"], y[1], record["F_meas2"], gap, block=BLOCK,
                              instrument_lag=INSTRUMENT_LAG)


def _compare(part: int, row: tuple, grasp: TwoFingerGraspResult, ident: dict,
             gap: float) -> StiffnessComparison:
    true, seed_est, seed_err = row
    base = (ident["left"].finger.values(), ident["right"].finger.values())
    est = _estimate(grasp.trajectory, base, gap)
    var_model = 0.0
    grads = []
    for j, side in enumerate(("left", "right")):
        cov = parameter_covariance(ident[side])
        grad = np.zeros(len(_PROPAGATED))
        for i, name in enumerate(_PROPAGATED):
            h = math.sqrt(cov[i, i]) or 1e-6 * abs(base[j][name])
            ks = []
            for sgn in (1.0, -1.0):
                vals = [dict(base[0]), dict(base[1])]
                vals[j][name] += sgn * h
                ks.append(_estimate(grasp.trajectory, tuple(vals), gap).stiffness)
            grad[i] = (ks[0] - ks[1]) / (2.0 * h)
        var_model += float(grad @ cov @ grad)
        grads.append(grad[_PROPAGATED.index("k_s")] * base[j]["k_s"])
    sens = sum(grads) / est.stiffness
    std = math.hypot(est.stiffness_std, math.sqrt(var_model))
    return StiffnessComparison(part, true, seed_est, seed_err, est.stiffness, std,
                               est.stiffness_std,
                               math.sqrt(var_model), sens, est)


def table_iii_study(*, seed: int = 0, identified: dict | None = None, duration: float = 3.0,
                    grip_force: float = 200e-6, noise: dict = MEASUREMENT_NOISE,
                    progress: bool = False) -> TableIIIStudy:
    """Reproduce Table III of ``001_0b92a7da96e7aa46.txt`` by the seed's protocol on simulated
    experiments (module docstring): identify both fingers (§IV), grasp each of the three parts
    (k_e = 12.1, 72.5, 469 N/m, the "Measured" column), estimate k̂ by eq 16 with σ.

    Parameters
    ----------
    seed
        Draws every noise record (identification and grasps); one seed, one repetition.
    identified
        ``{'left': FingerIdentification, 'right': ...}`` to reuse (default:
        :func:`identify_fingers`).
    duration
        Seconds of each grasp at 20 kHz (approach, hold, squeeze; 3 s covers all three parts).
    grip_force
        N, the force both fingers squeeze to (200 µN: the seed does not state it).
    noise
        Standard deviations of :data:`MEASUREMENT_NOISE` (same keys, ``(value, source)`` pairs).

    Returns
    -------
    TableIIIStudy
        ``rows[i].estimate ± rows[i].std`` beside ``rows[i].seed_estimate`` and ``rows[i].true``.
    """
    missing = sorted(set(MEASUREMENT_NOISE) - set(noise))
    if missing:
        raise DataError(f"noise: entries {missing} missing",
                        hint=f"give all of {sorted(MEASUREMENT_NOISE)}")
    if not (np.isfinite(duration) and duration > 0 and np.isfinite(grip_force) and grip_force > 0):
        raise DataError(f"duration and grip_force: expected positive numbers, found {duration!r} "
                        f"s, {grip_force!r} N")
    ident = (identify_fingers(seed=seed, noise=noise,
                              progress=progress) if identified is None else identified)
    if set(ident) != {"left", "right"}:
        raise DataError(f"identified: expected the keys 'left' and 'right', found {sorted(ident)}")
    fingers = (ident["left"].finger, ident["right"].finger)
    settings = GraspSettings(grip_force=grip_force, approach_speed=60e-6)
    rows, grasps = [], {}
    for part, row in track(list(enumerate(TABLE_III, 1)), description="Table III parts",
                           enabled=progress):
        g = gripper(stiffness=row[0], width=_PART_WIDTH, centre=_PART_CENTRE, check=False)
        gr = simulate_two_finger_grasp(g, estimator_fingers=fingers, settings=settings,
                                       duration=duration,
                                       noise_std=noise["sensor_force_N"][0],
                                       seed=1000 * seed + part)
        if gr.estimate is None:
            raise DataError(f"part {part} ({row[0]:g} N/m) was not grasped within {duration:g} s",
                            hint="give a longer duration")
        grasps[part] = gr
        rows.append(_compare(part, row, gr, ident, g.parameters.value("gap")))
    return TableIIIStudy(tuple(rows), ident, grasps, tuple(table_iii_findings()), dict(noise), seed)
