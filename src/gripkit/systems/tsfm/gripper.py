"""The two-smart-fingers microgripper (TSFM), ``001_0b92a7da96e7aa46.txt`` §III: one finger =
piezoelectric actuator (eq 4) + rigid socket + piezoresistive force sensor (eqs 5–10); two fingers
with a micropart between them (initial gap 400 µm, §V-C).

Three equivalent forms of the linear part of a finger, cross-checked in the tests:

* **component-wise** (:func:`finger_state_space`): the actuator of eq 4 (two D(s) filters,
  states y_A, ẏ_A, α_A, α̇_A), the lever y_D = y_A + L α_A (eq 6) and the sensor of eq 8
  (states y_C, ẏ_C), connected through the reactions of eq 1. Six states; outputs y_C, y_B
  (= y_A + L_r α_A), y_D, y_A and the measured force F_m = k_s (y_D − y_C).
* **minimal** (:func:`finger_minimal_state_space`): eq 7 for y_D and eq 9 for y_C, states
  y_D, ẏ_D, y_C, ẏ_C:

      a ÿ_D + b ẏ_D + y_D = α_u W − α_f s_p F_g − α_m s_p m_s ÿ_C,
      m_s ÿ_C = −F_g − b_s (ẏ_C − ẏ_D) − k_s (y_C − y_D),

  with W = d_p U − H. Its transfer functions are eq 11.
* **transfer functions** (:func:`finger_transfer_functions`): eqs 11–13, as
  :class:`gripkit.lti.TransferFunction` objects.

Derivation of eqs 11–13 and what the seed prints. Multiplying eq 10 by (m_s s² + b_s s + k_s),
inserting eq 7 and multiplying by (a s² + b s + 1):

    den(s) Y_C = α_u (b_s s + k_s) W − [ (a s² + b s + 1) + α_f s_p (b_s s + k_s) ] F_g,
    den(s) = (m_s s² + b_s s + k_s)(a s² + b s + 1) + α_m s_p m_s s² (b_s s + k_s),

so a4 = a m_s, a3 = b m_s + a b_s + α_m b_s m_s s_p, **a2 = a k_s + b b_s + m_s + α_m k_s m_s s_p**,
a1 = b k_s + b_s, a0 = k_s; b1 = α_u b_s, b0 = α_u k_s; c2 = a, c1 = b + α_f s_p b_s,
c0 = 1 + α_f s_p k_s — all as printed in eq 13 except a2, where the seed prints b_s m_s s_p
in place of k_s m_s s_p. That term has the unit kg·s where a2 needs kg (a copy of a3's term):
gripkit uses the derived a2 and reports the printed one (``eq13-a2`` finding). The force path is
Y_C/F_g = −c(s)/den(s) = −G_u(s) G_f(s) with G_f = c(s)/(b1 s + b0) as printed in eq 12, i.e.
eq 11 reads Y_C = G_u(s) [(d_p U − H) − G_f(s) F_g]; G_f alone is improper, G_u G_f is not.

Contacts (Fig. 5 b→d, :class:`TSFMFingerContact`, :class:`TSFMGripper`). The micropart is a
spring k_e with optional damping c_e and a pull-off force F_po: in contact, F_g = k_e δ + c_e δ̇
with δ the penetration; contact starts where the gap closes (δ = 0) and ends where δ falls to
−F_po/k_e (adhesion holds it until then). The switching instant is located inside the sample step
(:mod:`gripkit.sim.hybrid`), with the linear dynamics discretised exactly in both modes.
In the two-finger gripper the part rests on the substrate: its body holds by static friction
F_stick and each finger presses one half of it (stiffness 2 k_e per side, so a squeeze from both
sides sees k_e as in eq 16); when the two finger forces differ by more than F_stick the part slides
(quasi-statically, each sample) until they differ by F_stick.
"""

from __future__ import annotations

import dataclasses
import math
from collections import namedtuple
from collections.abc import Mapping

import numba
import numpy as np
from numba import prange

from ...consistency import Finding, compare
from ...errors import AccuracyWarning, DataWarning, ModelError, ParameterError, emit_warning
from ...models.hysteresis import bouc_wen_advance
from ...models.piezo import actuator_parameters, actuator_state_space, lti_modes, run_bw_lti
from ...params import Parameter, ParameterSet
from ...sim.hybrid import (DEFAULT_LEVELS, MAX_EVENTS_PER_STEP, EventWork, Guard, HybridSystem,
                           Mode, PWAGuards, pwa_output, pwa_step)
from ...sim.integrators import zoh_levels
from ...lti import StateSpace, TransferFunction
from ...sim.model import Model, Signal
from .end_effector import (end_effector_parameters, lever_coefficients, sensor_parameters,
                           sensor_state_space)

__all__ = ["FINGER_NAMES", "finger_parameter_set", "finger_state_space",
           "finger_minimal_state_space",
           "finger_coefficients", "finger_transfer_functions", "finger_hybrid",
           "micropart_parameters", "finger_checks", "TSFMFinger", "TSFMFingerContact",
           "TSFMGripper",
           "gripper_measure", "gripper_advance", "gripper_work", "gripper_model", "GripperModel",
           "GripperState", "GripperWork", "RANGES", "check_ranges"]

_SEED = "001_0b92a7da96e7aa46.txt"
#: The ranges the seed states for each finger (Table I; §V-A: "a displacement range of 100 µm for
#: each finger and force sensing range going from 60 nN to 2 mN for each force sensor"). The
#: simulations check their outputs against them (:func:`check_ranges`): beyond the stroke the model
#: extrapolates (AccuracyWarning); beyond the sensing range the sensor's reading is clipped
#: (DataWarning), the true contact force is not.
RANGES = ParameterSet([
    Parameter("stroke", 100e-6, "m", "displacement range of each finger (tip C)", (0, None),
              source=f"{_SEED} Table I, §V-A", display_unit="um"),
    Parameter("force_range", 2e-3, "N", "sensing range of each integrated force sensor", (0, None),
              source=f"{_SEED} Table I, §V-A", display_unit="mN"),
], "tsfm-ranges")


def check_ranges(trajectory, positions: tuple[str, ...], forces: tuple[str, ...], subject: str):
    """Warn where the tip ``positions`` (m) leave the finger's stroke, and clip the sensor
    readings ``forces`` (N) to the sensing range with a warning (:data:`RANGES`); returns the
    trajectory (a new one if a reading was clipped)."""
    stroke, limit = RANGES.value("stroke"), RANGES.value("force_range")
    for name in positions:
        peak = float(np.max(np.abs(trajectory[name]))) if trajectory.n else 0.0
        if peak > stroke:
            emit_warning(f"{subject}: {name} reaches {peak * 1e6:.4g} µm, beyond the finger's "
                         f"{stroke * 1e6:.3g} µm displacement range ({_SEED} Table I): the model "
                         "extrapolates there (lower the voltage amplitude)", AccuracyWarning)
    clipped = {}
    for name in forces:
        x = trajectory[name]
        peak = float(np.max(np.abs(x))) if x.size else 0.0
        if peak > limit:
            emit_warning(f"{subject}: {name} reaches {peak * 1e3:.4g} mN, beyond the sensor's "
                         f"{limit * 1e3:.3g} mN sensing range ({_SEED} Table I): the reading is "
                         "clipped "
                         f"to ±{limit * 1e3:.3g} mN", DataWarning)
            clipped[name] = np.clip(x, -limit, limit)
    return trajectory.with_channels(**clipped) if clipped else trajectory


FINGER_NAMES = ("d_p", "s_p", "lam", "beta", "gamma", "a", "b", "m_s", "b_s", "k_s", "L_r", "L_s",
                "L_a",
                "sensitivity")
CONTACT_NAMES = ("x_w", "k_e", "c_e", "F_po")
PART_NAMES = ("w", "k_e", "c_e", "F_po", "F_stick", "X_p", "gap")


def finger_parameter_set(*, d_p: float, s_p: float, lam: float, beta: float, gamma: float, a: float,
                         b: float,
                         m_s: float, b_s: float, k_s: float, L_r: float, L_s: float, L_a: float,
                         sensitivity: float = 5e3, source: str = "",
                         sources: Mapping[str, str] | None = None,
                         name: str = "tsfm-finger") -> ParameterSet:
    """ParameterSet of one finger (SI). ``sources`` overrides ``source`` per parameter.

    d_p, lam (m/V); s_p (m/N); beta, gamma (1/V); a (s²), b (s); m_s (kg), b_s (N·s/m), k_s (N/m);
    L_r, L_s, L_a (m); sensitivity (V/N) of the force-sensor read-out.
    """
    act = actuator_parameters(d_p, s_p, lam, beta, gamma, a, b, L_a, source=source)
    ee = end_effector_parameters(m_s, b_s, k_s, L_r, L_s, source=source)
    sens = Parameter("sensitivity", sensitivity, "V/N", "force-sensor read-out sensitivity "
                                                        "(volts per newton)",
                     bounds=(0.0, None), fixed=True, source=source, display_unit="mV/uN")
    by_name = {p.name: p for p in [*act.values(), *ee, sens]}
    for n, src in (sources or {}).items():
        if n not in by_name:
            raise ParameterError("sources: no finger "
                                 f"parameter {n!r}", hint=f"parameters: {', '.join(FINGER_NAMES)}")
        by_name[n] = dataclasses.replace(by_name[n], source=src)
    return ParameterSet([by_name[n] for n in FINGER_NAMES], name)


def _v(p) -> dict[str, float]:
    """Parameter values as a dict from a ParameterSet, a mapping or a vector in FINGER_NAMES
    order."""
    if isinstance(p, ParameterSet):
        return {n: p.value(n) for n in p}
    if isinstance(p, Mapping):
        return {k: float(v) for k, v in p.items()}
    arr = np.asarray(p, dtype=np.float64)
    return dict(zip(FINGER_NAMES, arr))


def finger_state_space(p) -> StateSpace:
    """The component-wise finger (eqs 1, 4, 6, 8): inputs [W = d_p U − H (m), F_g (N)],
    states [y_A, ẏ_A, α_A, α̇_A, y_C, ẏ_C], outputs [y_C, y_B, y_D, y_A, F_m]."""
    v = _v(p)
    L = v["L_r"] + v["L_s"]
    act = actuator_state_space(v["s_p"], v["a"], v["b"], v["L_a"])   # inputs W, F_A, M_A
    sen = sensor_state_space(v["m_s"], v["b_s"], v["k_s"])           # inputs y_D, v_D, F_g
    # [y_D, v_D] = lever x_a (eq 6)
    lever = np.array([[1.0, 0.0, L, 0.0], [0.0, 1.0, 0.0, L]])
    # eq 1: F_A = reaction of the sensor on the lever (sensor output 1), M_A = L F_g
    FA_xs, FA_in = sen.C[1], sen.D[1]
    A = np.zeros((6, 6))
    B = np.zeros((6, 2))
    A[:4, :4] = act.A + np.outer(act.B[:, 1], FA_in[:2] @ lever)
    A[:4, 4:] = np.outer(act.B[:, 1], FA_xs)
    A[4:, :4] = sen.B[:, :2] @ lever
    A[4:, 4:] = sen.A
    B[:4, 0] = act.B[:, 0]
    B[:4, 1] = act.B[:, 2] * L + act.B[:, 1] * FA_in[2]
    B[4:, 1] = sen.B[:, 2]
    C = np.zeros((5, 6))
    C[0, 4] = 1.0                                   # y_C
    C[1, 0], C[1, 2] = 1.0, v["L_r"]                # y_B
    C[2, 0], C[2, 2] = 1.0, L                       # y_D
    C[3, 0] = 1.0                                   # y_A
    C[4, 0], C[4, 2], C[4, 4] = v["k_s"], v["k_s"] * L, -v["k_s"]   # F_m = k_s (y_D − y_C)
    return StateSpace(A, B, C, np.zeros((5, 2)), inputs=("W", "F_g"),
                      outputs=("y_C", "y_B", "y_D", "y_A", "F_m"),
                      input_units=("m", "N"), output_units=("m", "m", "m", "m", "N"))


def finger_minimal_state_space(p) -> StateSpace:
    """Eqs 7 and 9 as a state space (the minimal realisation of eq 11): inputs [W, F_g], states
    [y_D, ẏ_D, y_C, ẏ_C], outputs [y_C, y_D, F_m]."""
    v = _v(p)
    L = v["L_r"] + v["L_s"]
    lc = lever_coefficients(L, v["L_a"])
    a, b, s_p, m, bs, ks = v["a"], v["b"], v["s_p"], v["m_s"], v["b_s"], v["k_s"]
    A = np.zeros((4, 4))
    B = np.zeros((4, 2))
    A[0, 1] = A[2, 3] = 1.0
    # sensor, eq 9: m ÿ_C = −F_g − bs (ẏ_C − ẏ_D) − ks (y_C − y_D)
    A[3] = [ks / m, bs / m, -ks / m, -bs / m]
    B[3, 1] = -1.0 / m
    # eq 7: a ÿ_D + b ẏ_D + y_D = α_u W − α_f s_p F_g − α_m s_p (m ÿ_C)
    A[1] = (np.array([-1.0, -b, 0.0, 0.0]) - lc.alpha_m * s_p * m * A[3]) / a
    B[1] = np.array([lc.alpha_u, -lc.alpha_f * s_p - lc.alpha_m * s_p * m * B[3, 1]]) / a
    C = np.array([[0.0, 0.0, 1.0, 0.0], [1.0, 0.0, 0.0, 0.0], [ks, 0.0, -ks, 0.0]])
    return StateSpace(A, B, C, np.zeros((3, 2)), inputs=("W", "F_g"), outputs=("y_C", "y_D", "F_m"),
                      input_units=("m", "N"), output_units=("m", "m", "N"))


def finger_coefficients(p, a2: str = "derived") -> dict[str, float]:
    """The coefficients of eq 13 (and α_u, α_f, α_m). ``a2='printed'`` gives the seed's a2
    (with b_s m_s s_p), ``'derived'`` the corrected one (k_s m_s s_p); see the module docstring."""
    if a2 not in ("derived", "printed"):
        raise ModelError(f"a2: expected 'derived' or 'printed', found {a2!r}")
    v = _v(p)
    L = v["L_r"] + v["L_s"]
    lc = lever_coefficients(L, v["L_a"])
    a, b, s_p, m, bs, ks = v["a"], v["b"], v["s_p"], v["m_s"], v["b_s"], v["k_s"]
    am, af, au = lc.alpha_m, lc.alpha_f, lc.alpha_u
    return dict(
        a0=ks, a1=b * ks + bs, a4=a * m,
        a2=a * ks + b * bs + m + am * (ks if a2 == "derived" else bs) * m * s_p,
        a3=b * m + a * bs + am * bs * m * s_p,
        b0=au * ks, b1=au * bs,
        c0=1.0 + af * s_p * ks, c1=b + af * s_p * bs, c2=a,
        alpha_u=au, alpha_f=af, alpha_m=am)


def finger_transfer_functions(p, a2: str = "derived",
                              meta: dict | None = None) -> dict[str, TransferFunction]:
    """Eqs 11–13 as continuous :class:`gripkit.lti.TransferFunction` objects (SI units, stored
    monic): ``G_u`` = (b1 s + b0)/den(s) from the stroke W = d_p U − H (m) to y_C (m), and
    ``force`` = G_u G_f = c(s)/den(s) from the grip force F_g (N) to y_C (m), with the seed's
    sign: Y_C = G_u W − force · F_g (eq 11 with its bracket). The printed G_f = c(s)/(b1 s + b0)
    alone is improper (no TransferFunction): its coefficients are :func:`finger_coefficients`'
    c2, c1, c0, b1, b0. ``meta`` is added to each one's ``meta``."""
    c = finger_coefficients(p, a2)
    den = np.array([c["a4"], c["a3"], c["a2"], c["a1"], c["a0"]])
    num_u = np.array([c["b1"], c["b0"]])
    num_c = np.array([c["c2"], c["c1"], c["c0"]])
    info = {"a2": a2, **(meta or {})}
    return {"G_u": TransferFunction(num_u, den, None, ("W",), ("y_C",), ("m",), ("m",),
                                    {"equation": "eq 12 G_u", **info}),
            "force": TransferFunction(num_c, den, None, ("F_g",), ("y_C",), ("N",), ("m",),
                                      {"equation": "eq 12 G_u G_f, entering eq 11 with −",
                                       **info})}


def d_bandwidth_hz(a: float, b: float) -> float:
    """−3 dB bandwidth of D(s) = 1/(a s² + b s + 1) (Hz)."""
    # |D(jω)|² = 1/((1 − a ω²)² + b² ω²) = 1/2  →  a² x² + (b² − 2a) x − 1 = 0, x = ω²
    A2, B2 = a * a, b * b - 2.0 * a
    x = (-B2 + math.sqrt(B2 * B2 + 4.0 * A2)) / (2.0 * A2)
    return math.sqrt(x) / (2.0 * math.pi)


# ---- consistency ---------------------------------------------------------------------------------

def finger_checks(values: Mapping[str, float], reference: Mapping[str, tuple[float, str]],
                  subject: str,
                  *, printed: bool = False) -> list[Finding]:
    """Compare a finger's parameter values with stated measurements.

    ``reference`` maps keys to (value, source): ``sensor_f0_hz``, ``sensor_zeta``,
    ``sensor_stiffness`` (N/m), ``actuator_stiffness`` (N/m), ``sensitivity_uN_per_V``,
    ``actuation_bandwidth_hz`` (a lower bound). ``printed=True`` words the ``used`` texts for a
    printed table that gripkit corrects (as in the zoo); otherwise for a model simulated as given.
    """
    v = values
    out: list[Finding] = []
    k, m, bs = v["k_s"], v["m_s"], v["b_s"]
    if "sensor_f0_hz" in reference:
        f0, src = reference["sensor_f0_hz"]
        f = math.sqrt(k / m) / (2 * math.pi)
        rad = abs(math.sqrt(k / m) - f0) / f0 < 0.03
        what = "√(k_s/m_s)/2π"
        if rad:
            what += (f" (√(k_s/m_s) = {math.sqrt(k / m):.5g} rad/s matches {f0:g} taken as "
                     "rad/s: 2π dropped)")
        m_fix = sensor_parameters(f0, 0.0, k_s=k).value("m_s")
        used = (f"gripkit keeps k_s = {k:g} N/m and the measured f0 = {f0:g} Hz: m_s = k_s/(2π "
                f"f0)² = {m_fix:.4g} kg"
                if printed else f"simulated with the model's own m_s, k_s ({f:.4g} Hz); m_s = "
                                f"{m_fix:.4g} kg "
                                f"would give {f0:g} Hz")
        out.append(compare("sensor-natural-frequency", subject, computed=f, stated=f0, rtol=0.02,
                           what=what,
                           unit="Hz", used=used, source=src))
    if "sensor_zeta" in reference:
        z0, src = reference["sensor_zeta"]
        z = bs / (2.0 * math.sqrt(k * m))
        if printed and "sensor_f0_hz" in reference:
            fix = sensor_parameters(reference["sensor_f0_hz"][0], z0, k_s=k)
            m_fix, b_fix = fix.value("m_s"), fix.value("b_s")
            used = f"gripkit uses the measured ζ = {z0:g}: b_s = 2ζ√(k_s m_s) = {b_fix:.4g} N·s/m"
        else:
            used = f"simulated with the model's own b_s (ζ = {z:.4g})"
        out.append(compare("sensor-damping-ratio", subject, computed=z, stated=z0, rtol=0.10,
                           what="b_s/(2√(k_s m_s))", used=used, source=src))
    if "sensor_stiffness" in reference:
        s0, src = reference["sensor_stiffness"]
        out.append(compare("sensor-stiffness", subject, computed=k, stated=s0, rtol=0.10,
                           what="k_s",
                           unit="N/m", used="k_s of the finger's parameter set", source=src))
    if "actuator_stiffness" in reference:
        s0, src = reference["actuator_stiffness"]
        out.append(compare("actuator-stiffness", subject, computed=1.0 / v["s_p"], stated=s0,
                           rtol=0.10,
                           what="1/s_p (stiffness at tip A)", unit="N/m",
                           used="s_p of the finger's parameter set",
                           source=src))
    if "sensitivity_uN_per_V" in reference and v.get("sensitivity", 0) > 0:
        s0, src = reference["sensitivity_uN_per_V"]
        out.append(compare("sensor-sensitivity", subject, computed=1e6 / v["sensitivity"],
                           stated=s0, rtol=0.10,
                           what="1/sensitivity", unit="uN/V",
                           used="the finger's own sensitivity (per-finger calibration); the stated "
                                "value is nominal",
                           source=src))
    if "actuation_bandwidth_hz" in reference:
        s0, src = reference["actuation_bandwidth_hz"]
        bw = d_bandwidth_hz(v["a"], v["b"])
        ok = bw >= s0
        out.append(Finding("actuation-bandwidth", subject, ok,
                           f"−3 dB bandwidth of D(s) = {bw:.5g} Hz, stated > {s0:g} Hz",
                           used="" if ok else "a and b of the parameter set", computed=bw,
                           stated=s0,
                           rel_error=abs(bw - s0) / s0, tolerance=0.0, source=src))
    return out


def eq13_a2_finding(values: Mapping[str, float], subject: str) -> Finding:
    """The seed's printed a2 (eq 13) against the derived one, for these parameter values."""
    d = finger_coefficients(values, "derived")["a2"]
    pr = finger_coefficients(values, "printed")["a2"]
    rel = abs(pr - d) / abs(d)
    return Finding("eq13-a2", subject, False,
                   "eq 13 prints a2 with (1 + 3L/2L_a) b_s m_s s_p (unit kg·s; a2 needs kg); "
                   "the derivation "
                   f"from eqs 7 and 10 gives (1 + 3L/2L_a) k_s m_s s_p: a2 = {d:.6g} kg, "
                   f"printed {pr:.6g} "
                   f"({100 * rel:.3g} % apart)",
                   used="gripkit uses the derived a2 (it agrees with the component-wise model)",
                   computed=d, stated=pr, rel_error=rel, tolerance=0.0,
                   source="001_0b92a7da96e7aa46.txt eq 13")


# ---- free finger -------------------------------------------------------------------------------

class TSFMFinger(Model):
    """One TSFM finger in free or externally loaded motion (eqs 1–13), exact per sample.

    Inputs ``U`` (V) and ``F_g`` (N, the gripping force the tip C applies; 0 in free motion);
    outputs ``y_C``, ``y_B`` (m) and ``F_m`` (N, the force the sensor reports). States: H, the
    voltage last applied, and the six states of :func:`finger_state_space`.

    ``reference`` (stated measurements, see :func:`finger_checks`) and ``printed`` (a printed
    parameter table the model corrects) feed :meth:`consistency_checks`; both are optional.
    """

    name = "tsfm-finger"
    description = "TSFM finger: Bouc-Wen + D(s) actuator, lever and force sensor (eqs 1–13)"
    inputs = (Signal("U", "V", "actuator voltage"), Signal("F_g", "N", "gripping force at tip C"))
    outputs = (Signal("y_C", "m", "sensor tip C"), Signal("y_B", "m", "socket tip B"),
               Signal("F_m", "N", "force reported by the sensor, k_s (y_D − y_C)"))
    states = (Signal("H", "m", "hysteresis"), Signal("U", "V", "voltage last applied"),
              Signal("y_A", "m", ""), Signal("v_A", "m/s", ""), Signal("alpha_A", "rad", ""),
              Signal("w_A", "rad/s", ""), Signal("y_C", "m", ""), Signal("v_C", "m/s", ""))
    integrator = "zoh"
    _out_rows = (0, 1, 4)

    def __init__(self, parameters: ParameterSet, *,
                 reference: Mapping[str, tuple[float, str]] | None = None,
                 printed: ParameterSet | None = None, name: str | None = None, check: bool = True):
        missing = [n for n in FINGER_NAMES if n not in parameters]
        if missing:
            raise ParameterError("TSFM finger parameters: "
                                 f"missing {missing}",
                                 hint="build them with finger_parameter_set(...)")
        parameters = ParameterSet([parameters[n] for n in FINGER_NAMES]
                                  + [parameters[n] for n in parameters if n not in FINGER_NAMES],
                                  parameters.name)
        self.reference = dict(reference or {})
        self.printed = printed
        if name:
            self.name = name
        super().__init__(parameters, check=check)

    # --- forms of the linear part
    def values(self) -> dict[str, float]:
        return {n: self.parameters.value(n) for n in self.parameters}

    def state_space(self) -> StateSpace:
        return finger_state_space(self.values())

    def minimal_state_space(self) -> StateSpace:
        return finger_minimal_state_space(self.values())

    def transfer_functions(self, a2: str = "derived") -> dict[str, TransferFunction]:
        """:func:`finger_transfer_functions` of this finger (``G_u``, ``force``), each one's
        ``meta`` naming the model."""
        return finger_transfer_functions(self.values(), a2, {"model": self.name})

    def modes(self, theta):
        return lti_modes(finger_state_space(theta[:len(FINGER_NAMES)]).A)

    def _matrices(self, thetas):
        A, B, C, bw = [], [], [], []
        for th in thetas:
            ss = finger_state_space(th[:len(FINGER_NAMES)])
            A.append(ss.A)
            B.append(ss.B)
            C.append(ss.C[list(self._out_rows)])
            bw.append(th[[0, 2, 3, 4]])
        return np.array(A), np.array(B), np.array(C), np.array(bw)

    def _simulate_batch(self, thetas, u, dt, substeps, x0, y):
        A, B, C, bw = self._matrices(thetas)
        Phi, Gam = zoh_levels(A, B, dt, 0)
        run_bw_lti(bw, Phi[:, 0], Gam[:, 0], C, np.zeros((len(thetas), C.shape[1], 2)), u, x0, y)

    def simulate(self, u, **kwargs):
        """:meth:`Model.simulate`, then the outputs checked against the stated ranges
        (:func:`check_ranges`: a warning beyond the 100 µm stroke, F_m clipped at 2 mN)."""
        return check_ranges(super().simulate(u, **kwargs), ("y_C",), ("F_m",), self.name)

    def consistency_checks(self) -> list[Finding]:
        v = self.values()
        out = []
        c = v["beta"] + v["gamma"]
        out.append(Finding("bounded-hysteresis", self.name, c > 0,
                           f"β + γ = {c:.4g} 1/V (> 0 bounds the hysteresis at λ/(β+γ))",
                           used="" if c > 0 else "simulated as given; the loop is unbounded",
                           computed=c, stated=0.0, source="eq 3"))
        seen = {}
        if self.printed is not None and self.reference:
            pv = {n: self.printed.value(n) for n in self.printed}
            for f in finger_checks(pv, self.reference, f"{self.name} (Table II as printed)",
                                   printed=True):
                seen[f.check] = f.computed
                out.append(f)
            out.append(eq13_a2_finding(pv, f"{self.name} (Table II as printed)"))
        if self.reference:
            # the model's own values; a check whose numbers equal the printed ones is not repeated
            out += ([f for f in finger_checks(v, self.reference,
                                              self.name) if seen.get(f.check) != f.computed])
        return out

    def contact(self, *, x_w: float, k_e: float, c_e: float = 0.0, F_po: float = 0.0,
                source: str = "", realisation: str = "component") -> "TSFMFingerContact":
        """This finger pressing on a part whose face is ``x_w`` (m) from the tip's rest position
        (``realisation='minimal'``: eq 11's four states, output y_D instead of y_B)."""
        return TSFMFingerContact(self.parameters.merged(contact_parameters(x_w, k_e, c_e, F_po,
                                                                           source=source)),
                                 reference=self.reference, printed=self.printed, check=False,
                                 finger_name=self.name, realisation=realisation)


def contact_parameters(x_w: float, k_e: float, c_e: float = 0.0, F_po: float = 0.0, *,
                       source: str = "") -> ParameterSet:
    """The contact of one finger with a part face (SI)."""
    return ParameterSet([
        Parameter("x_w", x_w, "m", "position of the part face from the "
                                   "tip's rest position", source=source,
                  display_unit="um"),
        Parameter("k_e", k_e, "N/m", "contact stiffness (part stiffness seen "
                                     "by this finger)", bounds=(1e-12, None),
                  source=source),
        Parameter("c_e", c_e, "N*s/m", "contact damping", bounds=(0.0, None), source=source),
        Parameter("F_po", F_po, "N", "pull-off (adhesion) force: contact ends at "
                                     "penetration −F_po/k_e",
                  bounds=(0.0, None), source=source, display_unit="uN"),
    ], "contact")


def micropart_parameters(width: float, stiffness: float, *, damping: float = 0.0,
                         pull_off: float = 0.0,
                         friction: float = 20e-6, centre: float | None = None, gap: float = 400e-6,
                         source: str = "") -> ParameterSet:
    """A micropart between the two fingers (SI): ``width`` (m), ``stiffness`` k_e (N/m, eq 16),
    ``damping`` (N·s/m), ``pull_off`` (N), substrate static ``friction`` (N), ``centre`` (m from
    finger 1's rest tip; default mid-gap) and the initial ``gap`` between the fingers (m, §V-C)."""
    centre = gap / 2.0 if centre is None else centre
    if not 0.0 < width < gap:
        raise ParameterError(f"micropart width {width:g} m must lie between 0 and "
                             f"the gap {gap:g} m")
    if not (width / 2 <= centre <= gap - width / 2):
        raise ParameterError(f"micropart centre {centre:g} m puts the part inside a finger "
                             f"(faces at {centre - width / 2:g} and {centre + width / 2:g} "
                             f"m, gap {gap:g} m)")
    return ParameterSet([
        Parameter("w", width, "m", "micropart width", bounds=(0.0, None), source=source,
                  display_unit="um"),
        Parameter("k_e", stiffness, "N/m", "micropart stiffness (eq 16)", bounds=(1e-12, None),
                  source=source),
        Parameter("c_e", damping, "N*s/m", "micropart damping", bounds=(0.0, None), source=source),
        Parameter("F_po", pull_off, "N", "pull-off (adhesion) "
                                         "force of a contact", bounds=(0.0, None),
                  source=source, display_unit="uN"),
        Parameter("F_stick", friction, "N", "static friction holding the part on the substrate",
                  bounds=(0.0, None), source=source, display_unit="uN"),
        Parameter("X_p", centre, "m", "part centre, from finger 1's rest tip "
                                      "towards finger 2", source=source,
                  display_unit="um"),
        Parameter("gap", gap, "m", "initial gap between "
                                   "the finger tips", bounds=(0.0, None), source=source,
                  display_unit="um"),
    ], "micropart")


# ---- hybrid finger (contact) -------------------------------------------------------------------

def finger_hybrid(values, k_e: float, c_e: float = 0.0, F_po: float = 0.0,
                  realisation: str = "component") -> HybridSystem:
    """The finger against a part face as a :class:`HybridSystem`: inputs [W (m), x_face (m)],
    modes 'free' and 'contact'. ``realisation='component'``: the six states of
    :func:`finger_state_space`, outputs [y_C, y_B, F_g, F_m]; ``'minimal'``: the four states of
    :func:`finger_minimal_state_space` (eq 11), outputs [y_C, y_D, F_g, F_m]."""
    if not k_e > 0:
        raise ParameterError(f"contact stiffness k_e must be > 0, found {k_e!r}")
    if realisation == "component":
        ss = finger_state_space(values)
        C = ss.C[[0, 1, 4]]
        iy = 4
    elif realisation == "minimal":
        ss = finger_minimal_state_space(values)
        C = ss.C[[0, 1, 2]]
        iy = 2
    else:
        raise ModelError(f"realisation: expected 'component' or 'minimal', found {realisation!r}")
    A, B = ss.A, ss.B
    n = A.shape[0]
    bF = B[:, 1]
    kvec = np.zeros(n)
    kvec[iy], kvec[iy + 1] = k_e, c_e   # F_g = k_e (y_C − x_face) + c_e ẏ_C
    C = np.vstack([C[0], C[1], np.zeros(n), C[2]])
    Cc = C.copy()
    Cc[2] = kvec
    free = Mode("free", A, np.column_stack([B[:, 0], np.zeros(n)]), C)
    # F_g enters through B[:, 1] (which already carries the sign of the reaction on the finger)
    contact = Mode("contact", A + np.outer(bF, kvec), np.column_stack([B[:, 0], -k_e * bF]), Cc,
                   D=np.array([[0.0, 0.0], [0.0, 0.0], [0.0, -k_e], [0.0, 0.0]]))
    e_y = np.zeros(n)
    e_y[iy] = 1.0
    guards = [Guard("free", "contact", G=-e_y, H=[0.0, 1.0], name="gap closes"),
              Guard("contact", "free", G=e_y, H=[0.0, -1.0], c=F_po / k_e, name="pull-off")]
    second = "y_B" if realisation == "component" else "y_D"
    return HybridSystem([free, contact], guards, inputs=("W", "x_face"),
                        outputs=("y_C", second, "F_g", "F_m"),
                        units={"W": "m", "x_face": "m", "y_C": "m", second: "m", "F_g": "N",
                               "F_m": "N"},
                        name="tsfm-finger-contact")


def _hybrid_arrays(rows, dt, levels, realisation="component"):
    """Stack the discretised hybrid finger for rows of (finger values, k_e, c_e, F_po)."""
    systems = [finger_hybrid(v, k, c, f, realisation) for v, k, c, f in rows]
    A = np.array([s.A for s in systems])
    B = np.array([s.B for s in systems])
    Phi, Gam = zoh_levels(A, B, dt, levels)
    s0 = systems[0]
    return dict(Phi=Phi, Gam=Gam, C=np.array([s.C for s in systems]),
                D=np.array([s.D for s in systems]),
                G=np.array([s.G for s in systems]), H=np.array([s.H for s in systems]),
                target=s0.target, ng=s0.n_guards)


@numba.njit(cache=True)
def _bw_pwa_row(bw, Phi, Gam, C, D, guards, K, xw, u, x0, y):  # pragma: no cover - compiled
    """One parameter row of :func:`_bw_pwa_batch` (a plain function: the prange body of a
    parallel kernel optimises worse, docs/performance.md); ``guards``:
    :data:`~gripkit.sim.hybrid.PWAGuards`."""
    G, Hg, target, ng = guards
    N = u.shape[0]
    n = Phi.shape[2]
    p_out = C.shape[1]
    x = np.empty(n)
    xt = np.empty(n)
    ua = np.empty(3)
    ev_frac = np.empty(MAX_EVENTS_PER_STEP)
    ev_to = np.empty(MAX_EVENTS_PER_STEP, dtype=np.int64)
    work = EventWork(xt, ev_frac, ev_to)
    yk = np.empty(p_out)
    for i in range(n):
        x[i] = x0[2 + i]
    H = x0[0]
    Uh = x0[1]
    mode = int(x0[2 + n])
    d_p, lam, beta, gamma = bw[0], bw[1], bw[2], bw[3]
    ua[1] = xw
    ua[2] = 1.0
    # the part face is fixed here: the outputs' input terms D[:, :, 1:] u are constants per mode
    dc = np.empty((C.shape[0], p_out))
    for q in range(C.shape[0]):
        for i in range(p_out):
            dc[q, i] = D[q, i, 1] * xw + D[q, i, 2]
    for k in range(N):
        U = u[k, 0]
        H = bouc_wen_advance(H, U - Uh, lam, beta, gamma)
        Uh = U
        ua[0] = d_p * U - H
        # outputs y = C x + D u; the sizes of the finger (4 outputs, 4 or 6 states) get loops with
        # constant trip counts (unrolled by LLVM), as in pwa_step
        if (n == 4 or n == 6) and p_out == 4:
            for i in range(4):
                acc = D[mode, i, 0] * ua[0] + dc[mode, i]
                if n == 4:
                    for j in range(4):
                        acc += C[mode, i, j] * x[j]
                else:
                    for j in range(6):
                        acc += C[mode, i, j] * x[j]
                y[k, i] = acc
        else:
            pwa_output(C, D, mode, x, ua, yk)
            for i in range(p_out):
                y[k, i] = yk[i]
        y[k, p_out] = mode
        mode, _nev = pwa_step(x, mode, ua, Phi, Gam, G, Hg, target, ng, K, work)


@numba.njit(cache=True, parallel=True)
def _bw_pwa_batch(bw, Phi, Gam, C, D, guards, K, xw, u, x0, y):  # pragma: no cover
    """:func:`_bw_pwa_row` for every parameter row (``guards``: PWAGuards with a leading row
    index on G and H). A prange body takes arrays, not records: each row builds its own."""
    G, Hg, target, ng = guards
    for p in prange(bw.shape[0]):
        _bw_pwa_row(bw[p], Phi[p], Gam[p], C[p], D[p], PWAGuards(G[p], Hg[p], target, ng), K, xw[p],
                    u, x0[p], y[p])


class TSFMFingerContact(Model):
    """One finger pressing on a part (Fig. 5, Fig. 13): free ↔ constrained motion through the gap
    x_w − y_C, with the switching located inside the sample step.

    Parameters: the finger's (see :func:`finger_parameter_set`) plus ``x_w`` (m, part face from the
    tip's rest position), ``k_e`` (N/m), ``c_e`` (N·s/m), ``F_po`` (N). Input ``U`` (V); outputs
    ``y_C``, ``y_B`` (m), ``F_g`` (N, the contact force), ``F_m`` (N, the sensor's reading) and
    ``contact`` (0 free, 1 in contact).
    """

    name = "tsfm-finger-contact"
    description = "TSFM finger with a contact (hybrid, exact ZOH with in-step event location)"
    inputs = (Signal("U", "V", "actuator voltage"),)
    outputs = (Signal("y_C", "m", "sensor tip C"), Signal("y_B", "m", "socket tip B"),
               Signal("F_g", "N", "contact force"),
               Signal("F_m", "N", "force reported by the sensor"),
               Signal("contact", "1", "0 free, 1 in contact"))
    states = TSFMFinger.states + (Signal("mode", "1", "0 free, 1 contact"),)
    integrator = "zoh"
    levels = DEFAULT_LEVELS

    def __init__(self, parameters: ParameterSet, *, reference=None, printed=None,
                 check: bool = True,
                 finger_name: str | None = None, realisation: str = "component"):
        if realisation not in ("component", "minimal"):
            raise ModelError("realisation: expected 'component' or 'minimal', found "
                             f"{realisation!r}")
        self.realisation = realisation
        # eq 11's four states: y_D replaces y_B, states y_D, v_D, y_C, v_C
        if realisation == "minimal":
            self.outputs = (self.outputs[0], Signal("y_D", "m", "lever tip D"), *self.outputs[2:])
            self.states = TSFMFinger.states[:2] + (Signal("y_D", "m", ""), Signal("v_D", "m/s", ""),
                                                   Signal("y_C", "m", ""), Signal("v_C", "m/s", ""),
                                                   Signal("mode", "1", "0 free, 1 contact"))
        missing = [n for n in FINGER_NAMES + CONTACT_NAMES if n not in parameters]
        if missing:
            raise ParameterError(f"{self.name}: missing parameters {missing}",
                                 hint="use TSFMFinger(...).contact(x_w=..., k_e=...)")
        self.finger = TSFMFinger(ParameterSet([parameters[n] for n in FINGER_NAMES],
                                              parameters.name),
                                 reference=reference, printed=printed, check=False,
                                 name=finger_name)
        super().__init__(ParameterSet([parameters[n] for n in FINGER_NAMES + CONTACT_NAMES],
                                      parameters.name),
                         check=check)

    def consistency_checks(self):
        return self.finger.consistency_checks()

    def modes(self, theta):
        return self.finger.modes(theta[:len(FINGER_NAMES)])

    def hybrid_system(self, theta=None) -> HybridSystem:
        th = self.theta() if theta is None else np.asarray(theta)
        v = dict(zip(self.parameters.names, th))
        return finger_hybrid(v, v["k_e"], v["c_e"], v["F_po"], self.realisation)

    def simulate(self, u, **kwargs):
        """:meth:`Model.simulate`, then the ranges checked (:func:`check_ranges`)."""
        return check_ranges(super().simulate(u, **kwargs), ("y_C",), ("F_m",), self.name)

    def _simulate_batch(self, thetas, u, dt, substeps, x0, y):
        nf = len(FINGER_NAMES)
        rows = [(th[:nf], th[nf + 1], th[nf + 2], th[nf + 3]) for th in thetas]
        d = _hybrid_arrays(rows, dt, self.levels, self.realisation)
        bw = np.ascontiguousarray(thetas[:, [0, 2, 3, 4]])
        xw = np.ascontiguousarray(thetas[:, nf])
        # one row: skip the parallel region (its thread wake-up costs more than it gives)
        if len(thetas) == 1:
            guards = PWAGuards(d["G"][0], d["H"][0], d["target"], d["ng"])
            _bw_pwa_row(bw[0], d["Phi"][0], d["Gam"][0], d["C"][0], d["D"][0], guards, self.levels,
                        xw[0], u, x0[0], y[0])
        else:
            guards = PWAGuards(d["G"], d["H"], d["target"], d["ng"])
            _bw_pwa_batch(bw, d["Phi"], d["Gam"], d["C"], d["D"], guards, self.levels, xw, u, x0, y)


# ---- two fingers and a part --------------------------------------------------------------------

@numba.njit(cache=True, _nrt=False)
def _face(i, Xp, part):  # pragma: no cover - compiled
    """Part face position in finger i's coordinates (closing direction); part = [w, gap, ...]."""
    if i == 0:
        return Xp - 0.5 * part[0]
    return part[1] - Xp - 0.5 * part[0]


#: one gripper's discretised model for the step kernels (:func:`gripper_model`): Bouc-Wen
# : parameters ``bw`` (2, 4) [d_p, A, β, γ]; each finger's mode stacks ``Phi``, ``Gam``, ``C``,
# ``D``,
#: ``G``, ``Hg`` (leading index: finger, see :meth:`TSFMGripper.arrays`); the hybrid step's
#: ``target``, ``ng`` and ``K`` levels; ``part`` = [w, gap, k_side, c_side, F_po, F_stick] (the
#: batch's jobs append the part's initial X_p)
GripperModel = namedtuple("GripperModel", "bw Phi Gam C D G Hg target ng K part")
#: the state of both fingers and the part: ``X`` (2, n) finger states, ``modes`` (2,),
#: ``hyst`` [H1, H2, U1_last, U2_last], ``ps`` [X_p]
GripperState = namedtuple("GripperState", "X modes hyst ps")
#: scratch of :func:`gripper_advance` (:func:`gripper_work`); ``yout`` (2, p) receives the outputs
GripperWork = namedtuple("GripperWork", "ua xt ev_frac ev_to yout")


def gripper_model(d: dict, row: int) -> GripperModel:
    """Row ``row`` of :meth:`TSFMGripper.arrays` as the record the kernels take."""
    return GripperModel(d["bw"][row], d["Phi"][row], d["Gam"][row], d["C"][row], d["D"][row],
                        d["G"][row],
                        d["H"][row], d["target"], d["ng"], d["K"], d["part"][row])


@numba.njit(cache=True, _nrt=False)
def gripper_measure(state, model, work):  # pragma: no cover - compiled
    """Outputs of both fingers: work.yout[i] = [y_C, y_B, F_g, F_m] for the states state.X (2, n)
    and the part at state.ps[0]; model.C (2, Q, p, n), model.D (2, Q, p, 3): each finger's output
    matrices (see :meth:`TSFMGripper.arrays`)."""
    X, modes, C, D, yout = state.X, state.modes, model.C, model.D, work.yout
    Xp = state.ps[0]
    n = X.shape[1]
    for i in range(2):
        face = _face(i, Xp, model.part)
        q = modes[i]
        for r in range(C.shape[2]):
            acc = D[i, q, r, 1] * face + D[i, q, r, 2]
            for j in range(n):
                acc += C[i, q, r, j] * X[i, j]
            yout[i, r] = acc


@numba.njit(cache=True, _nrt=False)
def gripper_advance(U1, U2, state, model, work):  # pragma: no cover - compiled
    """Advance both fingers and the part (``state``, :class:`GripperState`) by one sample with the
    voltages U1, U2 held, on the gripper ``model`` (:class:`GripperModel`). The fingers see the
    part faces fixed over the step; after it the part slides if the finger forces differ by more
    than F_stick, until they differ by F_stick. ``work.yout`` receives the outputs at the end of
    the step."""
    X, modes, hyst, ps = state.X, state.modes, state.hyst, state.ps
    bw, part, ua, yout = model.bw, model.part, work.ua, work.yout
    Xp = ps[0]
    ua[2] = 1.0
    for i in range(2):
        U = U1 if i == 0 else U2
        hyst[i] = bouc_wen_advance(hyst[i], U - hyst[2 + i], bw[i, 1], bw[i, 2], bw[i, 3])
        hyst[2 + i] = U
        ua[0] = bw[i, 0] * U - hyst[i]
        ua[1] = _face(i, Xp, part)
        q, _nev = pwa_step(X[i], modes[i], ua, model.Phi[i], model.Gam[i], model.G[i], model.Hg[i],
                           model.target,
                           model.ng, model.K, work)
        modes[i] = q
    gripper_measure(state, model, work)
    net = yout[0, 2] - yout[1, 2]  # finger 1 pushes towards +X, finger 2 towards −X
    if abs(net) > part[5]:
        kc = 0.0
        for i in range(2):
            if modes[i] == 1:
                kc += part[2]
        if kc > 0.0:
            shift = (abs(net) - part[5]) / kc
            ps[0] = Xp + shift if net > 0 else Xp - shift
            gripper_measure(state, model, work)


def gripper_work(n: int, p: int = 4) -> GripperWork:
    """Work arrays for :func:`gripper_advance`."""
    return GripperWork(np.empty(3), np.empty(n), np.empty(MAX_EVENTS_PER_STEP),
                       np.empty(MAX_EVENTS_PER_STEP, dtype=np.int64), np.empty((2, p)))


@numba.njit(cache=True)
def _gripper_row(model, u, x0, y, work):  # pragma: no cover - compiled
    N = u.shape[0]
    n = model.Phi.shape[4]
    state = GripperState(np.empty((2, n)), np.empty(2, dtype=np.int64), np.empty(4), np.empty(1))
    X, modes, hyst, ps = state.X, state.modes, state.hyst, state.ps
    yout = work.yout
    for i in range(2):
        off = i * (3 + n)
        hyst[i] = x0[off]
        hyst[2 + i] = x0[off + 1]
        for j in range(n):
            X[i, j] = x0[off + 2 + j]
        modes[i] = int(x0[off + 2 + n])
    ps[0] = x0[2 * (3 + n)]
    gripper_measure(state, model, work)
    for k in range(N):
        y[k, 0] = yout[0, 0]
        y[k, 1] = yout[1, 0]
        y[k, 2] = yout[0, 2]
        y[k, 3] = yout[1, 2]
        y[k, 4] = yout[0, 3]
        y[k, 5] = yout[1, 3]
        y[k, 6] = ps[0]
        y[k, 7] = modes[0]
        y[k, 8] = modes[1]
        gripper_advance(u[k, 0], u[k, 1], state, model, work)


class TSFMGripper(Model):
    """Two TSFM fingers facing each other with a micropart between them (§I, §V-C/D).

    Parameters: finger 1's with prefix ``f1_``, finger 2's with ``f2_``, and the micropart's
    (:func:`micropart_parameters`: w, k_e, c_e, F_po, F_stick, X_p, gap). Inputs ``U1``, ``U2``
    (V); outputs the tips ``y_C1``, ``y_C2`` (m, each in its own closing direction), contact forces
    ``F_g1``, ``F_g2`` and sensor readings ``F_m1``, ``F_m2`` (N), the part centre ``X_p`` (m, from
    finger 1's rest tip) and the contact flags ``contact1``, ``contact2``.
    """

    name = "tsfm-gripper"
    description = "two TSFM fingers and a micropart (hybrid contacts, substrate friction)"
    inputs = (Signal("U1", "V", "finger 1 voltage"), Signal("U2", "V", "finger 2 voltage"))
    outputs = (Signal("y_C1", "m", ""), Signal("y_C2", "m", ""), Signal("F_g1", "N", ""),
               Signal("F_g2", "N", ""),
               Signal("F_m1", "N", ""), Signal("F_m2", "N", ""), Signal("X_p", "m", "part centre"),
               Signal("contact1", "1", ""), Signal("contact2", "1", ""))
    integrator = "zoh"
    levels = DEFAULT_LEVELS

    def __init__(self, finger1: ParameterSet | TSFMFinger, finger2: ParameterSet | TSFMFinger,
                 part: ParameterSet, *, check: bool = True):
        self.fingers = (tuple(f if isinstance(f, TSFMFinger) else TSFMFinger(f, check=False)
                              for f in (finger1, finger2)))
        params = []
        for i, f in enumerate(self.fingers, 1):
            for n in FINGER_NAMES:
                p = f.parameters[n]
                params.append(Parameter(f"f{i}_{n}", p.value, p.unit, f"finger {i}: {p.doc}",
                                        p.bounds, True,
                                        p.source, None, p.display_unit))
        missing = [n for n in PART_NAMES if n not in part]
        if missing:
            raise ParameterError("micropart parameters: "
                                 f"missing {missing}", hint="use micropart_parameters(...)")
        params += [part[n] for n in PART_NAMES]
        sts = []
        for i in (1, 2):
            sts += ([Signal(f"{s.name}{i}", s.unit,
                            s.doc) for s in TSFMFinger.states] + [Signal(f"mode{i}", "1", "")])
        self.states = tuple(sts) + (Signal("X_p", "m", "part centre"),)
        super().__init__(ParameterSet(params, "tsfm-gripper"), check=check)

    def consistency_checks(self):
        out = []
        for f in self.fingers:
            out += f.consistency_checks()
        return out

    def initial_state(self, theta):
        x = np.zeros(len(self.states))
        x[-1] = theta[self.parameters.names.index("X_p")]
        return x

    def modes(self, theta):
        nf = len(FINGER_NAMES)
        return (lti_modes(finger_state_space(theta[:nf]).A)
                + lti_modes(finger_state_space(theta[nf:2 * nf]).A))

    def arrays(self, thetas: np.ndarray, dt: float) -> dict:
        """Discretised fingers and part vectors for :func:`gripper_advance` (leading index: row)."""
        nf = len(FINGER_NAMES)
        names = self.parameters.names
        ix = {n: names.index(n) for n in PART_NAMES}
        rows, part, bw = [], [], []
        for th in thetas:
            k_side = 2.0 * th[ix["k_e"]]
            c_side = 2.0 * th[ix["c_e"]]
            for i in range(2):
                rows.append((th[i * nf:(i + 1) * nf], k_side, c_side, th[ix["F_po"]]))
            part.append([th[ix["w"]], th[ix["gap"]], k_side, c_side, th[ix["F_po"]],
                         th[ix["F_stick"]]])
            bw.append([th[[i * nf + j for j in (0, 2, 3, 4)]] for i in range(2)])
        d = _hybrid_arrays(rows, dt, self.levels)
        P = len(thetas)
        out = ({k: np.ascontiguousarray(v.reshape((P, 2) + v.shape[1:])) for k, v in d.items()
                if k not in ("target", "ng")})
        out.update(target=d["target"], ng=d["ng"], part=np.array(part), bw=np.array(bw),
                   K=self.levels)
        return out

    def simulate(self, u, **kwargs):
        """:meth:`Model.simulate`, then the ranges checked (:func:`check_ranges`)."""
        return check_ranges(super().simulate(u, **kwargs), ("y_C1", "y_C2"), ("F_m1", "F_m2"),
                            self.name)

    def _simulate_batch(self, thetas, u, dt, substeps, x0, y):
        # rows one after another: a gripper is simulated for one or a few parameter sets (a prange
        # wrapper would double the compile time of this large step for no use)
        d = self.arrays(thetas, dt)
        work = gripper_work(d["Phi"].shape[-1], d["C"].shape[-2])
        for p in range(len(thetas)):
            _gripper_row(gripper_model(d, p), u, x0[p], y[p], work)
