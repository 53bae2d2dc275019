"""The identification procedure of ``001_0b92a7da96e7aa46.txt`` §IV for one TSFM finger.

Steps 1 and 2 (static Bouc-Wen parameters, Fig. 9, and D(s), Fig. 10) are the generic piezo
procedures of :mod:`gripkit.sysid.physical.bouc_wen`; this module adds the TSFM's own:

3. **s_p** from a force–displacement test at the tip B (§IV-C3, eq 15, Fig. 11):
   y_B = −(1 + 3L_r/L_a + 3L_r²/L_a²) s_p F_g, a straight line: :func:`identify_compliance`.
4. **Force sensor m_s, b_s, k_s** (§IV-B) from the free-vibration f_0 and ζ
   (:func:`gripkit.sysid.physical.modal.free_vibration`) and one of them known:
   :func:`gripkit.systems.tsfm.end_effector.sensor_parameters` (k_s = m_s ω₀², b_s = 2ζ √(k_s m_s)).

and the whole procedure, :func:`identify_finger`.

Lengths. The seed measures the actuator at the tip B (the laser does not reach A), so steps 1–3
identify the parameters *of the point measured*: with the lever of eq 14, a free point at
distance ℓ moves by (1 + 2ℓ/L_a)(d_p U − H) D(s); Bouc-Wen is homogeneous in (H, λ), so the
identified d_p and λ are (1 + 2L_r/L_a) times those at A, while β, γ, a, b do not depend on the
lengths at all. Likewise step 3 gives the compliance at B. gripkit reports the point-B values,
which need no length, and converts to the tip A only when L_r and L_a are given
(:func:`to_tip_a`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import DataError, IdentificationError
from ...params import ParameterSet
from ...signals.trajectory import Trajectory
from ...sysid.physical.bouc_wen import (ActuatorDynamicsResult, BoucWenResult,
                                        identify_actuator_dynamics, identify_bouc_wen)
from ...sysid.physical.greybox import fit
from ...sysid.physical.modal import free_vibration
from .end_effector import lever_coefficients, sensor_parameters
from .gripper import TSFMFinger, finger_parameter_set

__all__ = (["ComplianceResult", "identify_compliance", "to_tip_a", "FingerIdentification",
            "identify_finger"])


@dataclass(frozen=True)
class ComplianceResult:
    """Compliance at the loaded point (m/N) from y = y₀ − c F, with std; s_p (m/N, at A, eq 15)
    when the lengths were given."""

    compliance: float
    compliance_std: float
    offset: float
    s_p: float | None
    s_p_std: float | None
    n_samples: int
    residual_std: float

    def to_dict(self) -> dict:
        return dict(self.__dict__)


def identify_compliance(F, y, *, L_r: float | None = None, L_a: float | None = None,
                        min_force: float | None = None) -> ComplianceResult:
    """Eq 15: fit y_B = y₀ − c F_g by least squares (c = (1 + 3L_r/L_a + 3L_r²/L_a²) s_p).

    ``F`` (N): force applied at B; ``y`` (m): displacement of B; samples with |F| below
    ``min_force`` are left out (the approach before contact, where the pull-in effect of Fig. 11b
    spoils the force). With ``L_r`` and ``L_a``, s_p at the tip A is returned too.
    """
    F = np.asarray(F, dtype=np.float64).ravel()
    y = np.asarray(y, dtype=np.float64).ravel()
    if F.shape != y.shape:
        raise DataError("force and displacement must have the same length, found "
                        f"{F.size} and {y.size}")
    if not (np.isfinite(F).all() and np.isfinite(y).all()):
        raise DataError("force or displacement contains NaN or inf")
    keep = np.abs(F) >= (min_force or 0.0)
    F, y = F[keep], y[keep]
    if F.size < 3 or np.ptp(F) <= 0:
        raise DataError(f"eq 15 needs at least 3 samples at different forces, found {F.size} "
                        f"(spread {np.ptp(F) if F.size else 0:g} N)", hint="load the tip over a "
                                                                           "range of forces")
    M = np.column_stack([np.ones_like(F), -F])
    coef, *_ = np.linalg.lstsq(M, y, rcond=None)
    r = y - M @ coef
    s2 = float(r @ r) / max(F.size - 2, 1)
    cov = s2 * np.linalg.inv(M.T @ M)
    c, c_std = float(coef[1]), math.sqrt(cov[1, 1])
    if c <= 0:
        raise IdentificationError("the tip moves with the force, not against it "
                                  f"(compliance {c:g} m/N)",
                                  hint="check the sign convention: F is the force "
                                       "pressing on the tip")
    s_p = s_p_std = None
    if L_r is not None and L_a is not None:
        af = lever_coefficients(L_r, L_a).alpha_f
        s_p, s_p_std = c / af, c_std / af
    return ComplianceResult(c, c_std, float(coef[0]), s_p, s_p_std, int(F.size), math.sqrt(s2))


def to_tip_a(values: dict, L_r: float, L_a: float, stds: dict | None = None) -> tuple[dict, dict]:
    """Convert point-B parameters (d_p, lambda, compliance) to the tip A with the lever of eq 14/15:
    d_p and λ divide by 1 + 2L_r/L_a, the compliance by 1 + 3L_r/L_a + 3L_r²/L_a² (→ s_p)."""
    lc = lever_coefficients(L_r, L_a)
    out, sd = {}, {}
    for k, v in values.items():
        f = (lc.alpha_u if k in ("d_p", "lambda",
                                 "lam") else (lc.alpha_f if k in ("compliance", "s_p") else 1.0))
        out["s_p" if k == "compliance" else k] = v / f
        if stds and k in stds:
            sd["s_p" if k == "compliance" else k] = stds[k] / f
    return out, sd


@dataclass(frozen=True)
class FingerIdentification:
    """A finger identified by the procedure of §IV (:func:`identify_finger`): the model
    (``finger``, a TSFMFinger whose parameters carry std and provenance) and each step's result."""

    finger: object
    bouc_wen: BoucWenResult
    dynamics: ActuatorDynamicsResult
    compliance: ComplianceResult
    modal: object
    sensor: ParameterSet

    def table(self) -> list[dict]:
        return self.finger.parameters.table()


def identify_finger(loops: Trajectory, step: Trajectory, compliance: Trajectory,
                    vibration: Trajectory, *,
                    k_s: float, k_s_std: float = 0.0, L_r: float, L_s: float, L_a: float,
                    dac_dt: float = 5e-5, sensitivity: float = 5e3, voltage: str = "U",
                    displacement: str = "y_B",
                    force: str = "F", progress: bool = False):
    """The identification procedure of §IV for one finger, from four records:

    ``loops``: quasi-static voltage sweep at B (columns ``voltage``, ``displacement``) — the seed
    uses the 100 V external loop; ``step``: a voltage step at B; ``compliance``: force on B and its
    displacement, no voltage (eq 15); ``vibration``: the sensor's free vibration (column ``force``).
    ``k_s``: the sensor stiffness known from its calibration (§IV-B needs one of m_s, b_s, k_s).
    Order: Bouc-Wen → D(s) → Bouc-Wen again with the lag b + dac_dt/2 → D(s) again; s_p (eq 15);
    f0, ζ → m_s, b_s. Point-B values are converted to the tip A with the lengths (eq 14).
    """
    bw = identify_bouc_wen(loops, voltage, displacement, progress=progress)
    dyn = identify_actuator_dynamics(step, bw, voltage, displacement, progress=progress)
    bw = identify_bouc_wen(loops, voltage, displacement, delay=dyn.b + 0.5 * dac_dt,
                           progress=progress,
                           initial=bw.params)
    dyn = (identify_actuator_dynamics(step, bw, voltage, displacement, progress=progress,
                                      initial=(dyn.a, dyn.b)))
    comp = (identify_compliance(compliance[force], compliance[displacement], L_r=L_r, L_a=L_a,
                                min_force=5e-6))
    vib = free_vibration(vibration[force], dt=vibration.dt)
    sensor = sensor_parameters(vib.natural_frequency_hz, vib.damping_ratio, k_s=k_s,
                               f0_std=vib.natural_frequency_std_hz,
                               zeta_std=vib.damping_ratio_std, known_std=k_s_std)
    at_a, sd_a = to_tip_a({"d_p": bw.params["d_p"], "lambda": bw.params["lambda"]}, L_r, L_a,
                          {"d_p": bw.std["d_p"], "lambda": bw.std["lambda"]})
    src = {"d_p": "identified: hysteresis loops (Fig. 9), converted to A with eq 14",
           "lam": "identified: hysteresis loops (Fig. 9), converted to A with eq 14",
           "beta": "identified: hysteresis loops (Fig. 9)",
           "gamma": "identified: hysteresis loops (Fig. 9)",
           "a": "identified: step response (Fig. 10), whole-finger model",
           "b": "identified: step response (Fig. 10), whole-finger model",
           "s_p": "identified: force-displacement at B (eq 15, Fig. 11)",
           "m_s": "identified: free vibration "
                  "(Fig. 8) and k_s", "b_s": "identified: free vibration (Fig. 8) and k_s",
           "k_s": "given (sensor calibration)", "L_r": "given", "L_s": "given", "L_a": "given",
           "sensitivity": "given (nominal 200 µN/V, 001_0b92a7da96e7aa46.txt §IV-B)"}
    params = finger_parameter_set(d_p=at_a["d_p"], s_p=comp.s_p, lam=at_a["lambda"],
                                  beta=bw.params["beta"],
                                  gamma=bw.params["gamma"], a=dyn.a, b=dyn.b,
                                  m_s=sensor.value("m_s"),
                                  b_s=sensor.value("b_s"), k_s=k_s, L_r=L_r, L_s=L_s, L_a=L_a,
                                  sensitivity=sensitivity, sources=src, name="identified finger")
    stds = {"d_p": sd_a["d_p"], "lam": sd_a["lambda"], "beta": bw.std["beta"],
            "gamma": bw.std["gamma"],
            "a": dyn.a_std, "b": dyn.b_std, "s_p": comp.s_p_std, "m_s": sensor["m_s"].std,
            "b_s": sensor["b_s"].std, "k_s": k_s_std}
    # last: a, b again, now through the whole finger — the step at B also carries the sensor's
    # inertia on the actuator (0.3 % on a with Table II), which the bare actuator model absorbs
    # into a
    whole = TSFMFinger(params, name="identified finger", check=False)
    st = Trajectory(step.t, {"U": step[voltage], "F_g": np.zeros(step.n),
                             "y_B": step[displacement]},
                    {"U": "V", "F_g": "N", "y_B": "m"}, {**step.meta, "dt": step.dt})
    ab = fit(whole, st, outputs=["y_B"], free=["a", "b"], progress=progress)
    dyn = ActuatorDynamicsResult(ab.value("a"), ab.value("b"), ab.stdev("a"), ab.stdev("b"), ab)
    params = params.replace(a=dyn.a, b=dyn.b)
    stds.update(a=dyn.a_std, b=dyn.b_std)
    params = ParameterSet([p if p.name not in stds else p.with_value(p.value, std=stds[p.name],
                                                                     source=p.source)
                           for p in params.values()], params.name)
    return (FingerIdentification(TSFMFinger(params, name="identified finger", check=False), bw, dyn,
                                 comp, vib, sensor))
