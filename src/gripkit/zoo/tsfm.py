"""The TSFM piezoelectric two-finger microgripper of ``001_0b92a7da96e7aa46.txt`` (Komati et al.),
with the identified parameters of Table II (p. 7 of the paper: §IV, "TABLE II: The values of the
identified parameters of each of the two fingers") and their provenance.

What the zoo models simulate, and why it differs from Table II as printed:

* **m_s and b_s.** Table II's k_s = 128 N/m and m_s = 1.8e-6 kg ring at √(k_s/m_s)/2π = 1.34 kHz,
  not at the 8.52 kHz measured in §IV-B (Fig. 8) and listed as the sensing bandwidth in Table I;
  √(k_s/m_s) = 8433 rad/s, so Table II's m_s is k_s/8520² with 8520 taken as rad/s. Table II's
  b_s = 7e-4 N·s/m gives ζ = 0.023 with Table II's m_s (0.146 with the corrected one), not the
  measured ζ = 0.006. gripkit keeps k_s (it agrees with Table I's 130 N/m) and the measurements
  (f0, ζ), and simulates m_s = k_s/(2π f0)² and b_s = 2ζ√(k_s m_s).
* **λ unit.** Table II prints λ without a unit; it is read in µm/V like d_p (see
  :mod:`gripkit.models.hysteresis`). β and γ are in 1/V.
* **b.** The row of D(s)'s b is printed under "Force sensor" by the table layout; it is the
  actuator's (eq 4, §IV-C2 identifies a and b together).
* **Lengths.** The seed gives no L_r, L_a. gripkit assumes L_a = 15 mm (a PZT bimorph with the
  1100 N/m tip stiffness of Table I: 15 × 2 × 0.5 mm gives E w t³/(4 L³) ≈ 1.1 kN/m with
  E ≈ 60 GPa), L_s = 1 mm (the sensor length, §II) and L_r = 7 mm, so L = 8 mm: with Table II's
  left finger the model then places the tip C at 62.4 µm at U = 44 V on the first rising branch,
  which is where Fig. 13 / §V-C locate the contact (62.42 µm at 44 V).

Sensitivity: §IV-B gives 200 µN/V for the sensors; Table II gives 6e-3 and 5.1e-3 V/µN
(167 and 196 µN/V): the left finger's disagrees (reported; each finger keeps its own).
"""

from __future__ import annotations

import dataclasses

from ..consistency import Finding, compare
from ..models.tsfm import (TSFMFinger, TSFMGripper, finger_parameters, micropart_parameters,
                           sensor_from_modal)
from ..params import ParameterSet

__all__ = ["TABLE_II", "REFERENCE", "ASSUMED_LENGTHS", "TABLE_III", "left_finger", "right_finger", "gripper",
           "table_ii", "finger"]

SEED = "001_0b92a7da96e7aa46.txt"
_T2 = f"{SEED}, Table II (p. 7)"

#: Table II as printed, in SI (λ read in µm/V; the b row belongs to the actuator)
TABLE_II = {
    "left": dict(d_p=0.77e-6, s_p=9.1e-4, lam=0.43e-6, beta=10.8e-2, gamma=7.5e-3, a=2.5e-8, b=8e-5,
                 m_s=1.8e-6, b_s=7e-4, k_s=128.0, sensitivity=6e-3 * 1e6),
    "right": dict(d_p=0.78e-6, s_p=8.5e-4, lam=0.39e-6, beta=11.1e-2, gamma=3.5e-3, a=2.5e-8, b=8e-5,
                  m_s=1.79e-6, b_s=6.98e-4, k_s=130.8, sensitivity=5.1e-3 * 1e6),
}

#: the measurements the seed states elsewhere, (value, source)
REFERENCE = {
    "sensor_f0_hz": (8520.0, f"{SEED} §IV-B (Fig. 8) and Table I"),
    "sensor_zeta": (0.006, f"{SEED} §IV-B"),
    "sensor_stiffness": (130.0, f"{SEED} Table I"),
    "actuator_stiffness": (1100.0, f"{SEED} Table I"),
    "sensitivity_uN_per_V": (200.0, f"{SEED} §IV-B"),
    "actuation_bandwidth_hz": (1000.0, f"{SEED} Table I (> 1 kHz)"),
}

ASSUMED_LENGTHS = dict(L_r=7e-3, L_s=1e-3, L_a=15e-3)
_LEN_SRC = {
    "L_a": "assumed: 15 mm PZT bimorph (1/s_p = 1100 N/m of Table I fits a 15 × 2 × 0.5 mm bimorph); the seed gives none",
    "L_s": f"{SEED} §II: force sensor 1 mm long",
    "L_r": "assumed: 7 mm socket, so that L = 8 mm puts tip C at 62.4 µm at 44 V (Fig. 13, §V-C: 62.42 µm)",
}

_PART_ASSUMED = {
    "c_e": "assumed: no damping in the part",
    "F_po": "assumed: no pull-off force",
    "F_stick": "assumed: 20 µN static friction/adhesion holding the part on the substrate",
    "X_p": "assumed: part centred unless given",
}

#: Table III: micropart stiffness measured (N/m), estimated by the TSFM (N/m), stated error
TABLE_III = [(12.1, 11.7, 0.03), (72.5, 71.05, 0.02), (469.0, 445.55, 0.05)]


def table_ii(side: str = "left") -> ParameterSet:
    """Table II as printed (plus the assumed lengths), one finger."""
    if side not in TABLE_II:
        raise ValueError(f"side: expected 'left' or 'right', found {side!r}")
    v = TABLE_II[side]
    sources = {n: f"{_T2}, {side} finger" for n in v}
    sources.update(_LEN_SRC)
    return finger_parameters(**v, **ASSUMED_LENGTHS, sources=sources, name=f"tsfm-{side} (Table II)")


def finger(side: str = "left", *, as_printed: bool = False, check: bool = True) -> TSFMFinger:
    """A TSFM finger with Table II's parameters; m_s and b_s from the measured f0 and ζ unless
    ``as_printed`` (see the module docstring)."""
    printed = table_ii(side)
    params = printed
    if not as_printed:
        k = printed.value("k_s")
        f0, z = REFERENCE["sensor_f0_hz"][0], REFERENCE["sensor_zeta"][0]
        m, b = sensor_from_modal(k, f0, z)
        params = ParameterSet([
            p if p.name not in ("m_s", "b_s") else p.with_value(
                m if p.name == "m_s" else b,
                source=f"derived: {'k_s/(2π f0)²' if p.name == 'm_s' else '2ζ√(k_s m_s)'} with f0 = 8520 Hz, "
                       f"ζ = 0.006 ({SEED} §IV-B); Table II prints {printed.value(p.name):g}")
            for p in printed.values()], f"tsfm-{side}")
    return TSFMFinger(params, reference=REFERENCE, printed=printed, name=f"tsfm-{side}", check=check)


def left_finger(**kw) -> TSFMFinger:
    """Left finger of Table II (zoo entry ``tsfm-left``)."""
    return finger("left", **kw)


def right_finger(**kw) -> TSFMFinger:
    """Right finger of Table II (zoo entry ``tsfm-right``)."""
    return finger("right", **kw)


class _Gripper(TSFMGripper):
    description = "TSFM: left and right fingers of Table II, 400 µm gap (§V-C), 300 µm part"

    def consistency_checks(self) -> list[Finding]:
        out = super().consistency_checks()
        for i, (meas, est, err) in enumerate(TABLE_III, 1):
            out.append(compare(f"table-iii-error-{i}", "Table III", computed=abs(est - meas) / meas, stated=err,
                               rtol=0.25, what=f"|{est:g} − {meas:g}|/{meas:g}", used="Table III's measured stiffness",
                               source=f"{SEED} Table III"))
        w = 400.0 - (62.42 + 39.4)
        out.append(compare("width-example", "§V-C", computed=w, stated=298.18, rtol=1e-6,
                           what="400 − (62.42 + 39.4)", unit="um", source=f"{SEED} §V-C"))
        return out


def gripper(stiffness: float = 72.5, width: float = 300e-6, centre: float | None = None, *,
            check: bool = True) -> TSFMGripper:
    """Both fingers (finger 1 = left, finger 2 = right) and a micropart (default: 300 µm wide,
    Table III's 72.5 N/m, centred in the 400 µm gap)."""
    part = micropart_parameters(width, stiffness, centre=centre,
                                source=f"{SEED} §V-C (400 µm gap, 300 µm part), Table III (stiffness)")
    part = ParameterSet([p if p.name not in _PART_ASSUMED else dataclasses.replace(p, source=_PART_ASSUMED[p.name])
                         for p in part.values()], part.name)
    g = _Gripper(finger("left", check=False), finger("right", check=False), part, check=check)
    g.name = "tsfm-gripper"
    return g

