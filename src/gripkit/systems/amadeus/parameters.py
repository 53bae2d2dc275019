"""The AMADEUS hand and finger with provenance: bellows geometry, valves, fingertip force sensor,
force dynamics (``000_8f66dcc7ab06470c.txt``).

:func:`amadeus_hand` builds :class:`AmadeusHandSystem`, which holds

* ``finger`` — :class:`~gripkit.systems.amadeus.bellows_finger.BellowsFinger` (§II-A, §III, eqs
1–8),
* ``valve`` — :class:`~gripkit.systems.amadeus.valve.ProportionalValve` (§II-D, Fig. 5, Fig. 15),
* ``sensor`` — :class:`~gripkit.systems.amadeus.strain_gauge_sensor.StrainGaugeSensor` (§IV-A, eqs
9–19,
  with Table I's measured normalised variances),
* ``hand`` — :class:`~gripkit.systems.amadeus.hand.AmadeusHand` (§II-B, §II-C),
* ``contact`` — :class:`~gripkit.systems.amadeus.pvdf.StickSlipContact` with the PVDF film (§IV-B),
* ``plant`` — the Table II ``[2 2 2]`` force model in SI units (valve current deviation, A → N) and
  ``plant_raw`` in the seed's units,

and the seed's consistency checks (Table I, Fig. 2(c) against the models).

Force model units: see :mod:`gripkit.systems.amadeus.force_dynamics` — the Table II coefficients
are in force-sensor
units per mA; gripkit's SI plant (A → N) scales them with ``FORCE_SCALE`` = 0.0250 N per unit
(assumed: the 500 mA valve span moves the fingertip force over its 15.45 N peak, Fig. 2(c)).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ...consistency import Finding, compare, warn_inconsistent
from ...control.rst import DiscretePlant
from ...estimation.fusion import fused_variance, implied_correlation
from ...params import Parameter, ParameterSet
from .bellows_finger import BellowsFinger
from .force_dynamics import FORCE_SCALE, PEAK_FORCE, finger_force_model, force_scale_parameter
from .hand import AmadeusHand
from .knuckle import KnuckleDrive
from .pvdf import StickSlipContact
from .strain_gauge_sensor import StrainGaugeSensor
from .valve import ProportionalValve

__all__ = (["AmadeusHandSystem", "amadeus_hand", "force_plant", "table2_plant", "TABLE_I",
            "table1_findings"])

_SEED = "000_8f66dcc7ab06470c.txt"

#: Table I: normalised variances σ²_N of single and combined strain-gauge estimates (y direction)
TABLE_I = {
    "actual": {"e1": 0.01309, "e2": 0.00459, "e3": 0.00301, "e12": 0.00440, "e23": 0.00265,
               "e123": 0.00241},
    "theoretical": {"e12": 0.00340, "e23": 0.00181, "e123": 0.00160},
}
#: Table II, [2 2 2] LS model on S_1 with the 9 Hz filter (also Table III, RLS)
TABLE2_A = (1.0, -1.8732, 0.8996)
TABLE2_B = (0.0, 0.0, 0.1950, -0.2276)
TABLE2_STD = {"A": (0.0, 0.0117, 0.0117), "B": (0.0, 0.0, 0.0221, 0.0225)}  # Table III σ
DT = 0.005  # s: sampled at 200 Hz (§V-C)


def table2_plant():
    """The ``[2 2 2]`` model in the seed's units (mA → force-sensor units), as a
    :class:`~gripkit.control.DiscretePlant`."""
    return DiscretePlant(TABLE2_A, TABLE2_B, DT, input_name="i", input_unit="mA", output_name="F",
                         output_unit="force units", source=f"{_SEED} Table II [2 2 2] "
                                                           "(S_1, 9 Hz filter)")


def force_plant(force_scale: float = FORCE_SCALE) -> tuple:
    """(plant in SI (A → N), force_scale N/unit): the zoo model ``amadeus-finger-force``
    (:func:`gripkit.systems.amadeus.force_dynamics.finger_force_model`) as a DiscretePlant, and its
    force scale (N per sensor unit, assumed by default)."""
    m = finger_force_model(force_scale).model
    plant = DiscretePlant(m.A, m.B, m.dt, input_name="i", input_unit="A", output_name="F",
                          output_unit="N",
                          source="gripkit.systems.amadeus.force_dynamics.finger_force_model (Table "
                                 "II [2 2 2] x force_scale)")
    return plant, float(force_scale)


def _sig3(x: float) -> str:
    return format(x, "#.3g")


def table1_findings() -> list[Finding]:
    """Table I checked: the theoretical column from eq 18 (generalised) of the measured single
    variances, and the measured fused variances against that theory (with the correlation between
    combinations that would explain the excess)."""
    a, th = TABLE_I["actual"], TABLE_I["theoretical"]
    combos = {"e12": ("e1", "e2"), "e23": ("e2", "e3"), "e123": ("e1", "e2", "e3")}
    out = []
    for key, parts in combos.items():
        v = [a[p] for p in parts]
        theory = fused_variance(v)
        # rounding: printed inputs carry ±0.000005; propagate to an interval of the theory
        lo = fused_variance([x - 5e-6 for x in v])
        hi = fused_variance([x + 5e-6 for x in v])
        # consistent when the interval the printed inputs allow meets the printed value's rounding
        # interval
        ok = bool(lo <= th[key] + 5e-6 and hi >= th[key] - 5e-6)
        rel = abs(theory - th[key]) / th[key]
        f = Finding(f"tableI-theory-{key}", "amadeus-hand", ok,
                    f"eq 18 of the measured σ²_N of {', '.join(parts)} = {theory:.6g} "
                    f"({_sig3(theory)} to three "
                    f"digits; [{lo:.5g}, {hi:.5g}] within the rounding of the printed "
                    "inputs), printed "
                    f"{_sig3(th[key])} ± 5e-06 ({100 * rel:.2g} % apart)",
                    f"{theory:.5g} from eq 18" + ("" if ok else ": the printed value is one "
                                                                "unit off in its "
                                                  "last digit, not reproducible from "
                                                  "the printed inputs"),
                    theory, th[key], rel, 5e-6 / th[key], f"{_SEED} Table I, theoretical column")
        out.append(f)
        rho = implied_correlation(v, a[key])
        out.append(compare(f"tableI-actual-vs-theory-{key}", "amadeus-hand", computed=a[key],
                           stated=theory,
                           rtol=0.05, what=f"measured σ²_N of the fused {key} (Table I 'actual')",
                           used=("theory; the excess matches a common correlation ρ = "
                                 f"{rho:.2f} between the "
                                 "combinations (eq 16-18 assume independent noise; §IV-A "
                                 "blames violated "
                                 "assumptions)"),
                           source=f"{_SEED} Table I, actual column"))
    return out


class AmadeusHandSystem:
    """The AMADEUS finger and hand with all their parts (see the module docstring)."""

    name = "amadeus-hand"
    description = ("AMADEUS hydraulic three-finger hand: bellows finger (eqs 1-8), "
                   "valves, six-bridge "
                   "force sensor (eqs 9-19), PVDF slip sensor, Table II force dynamics")

    def __init__(self, *, check: bool = True, force_scale: float = FORCE_SCALE):
        self.finger = BellowsFinger(check=False)
        self.valve = ProportionalValve(check=False)
        self.sensor = StrainGaugeSensor()
        self.hand = AmadeusHand(self.finger, check=False)
        self.knuckle = KnuckleDrive(check=False)
        self.contact = StickSlipContact(check=False)
        self.plant_raw = table2_plant()
        self.plant, self.force_scale = force_plant(force_scale)
        if check:
            warn_inconsistent(self.consistency_checks())

    @property
    def parameters(self) -> ParameterSet:
        """Every part's parameters, prefixed by part (``finger_``, ``valve_``, ``sensor_``,
        ``hand_``, ``contact_``, ``knuckle_``, ``force_``)."""
        params = []
        for prefix, ps in (("finger", self.finger.parameters), ("valve", self.valve.parameters),
                           ("sensor", self.sensor.parameters), ("hand", self.hand.hand_parameters),
                           ("contact", self.contact.parameters),
                           ("knuckle", self.knuckle.parameters)):
            params += [dataclasses.replace(p, name=f"{prefix}_{p.name}") for p in ps.values()]
        A, B = self.plant_raw.A, self.plant_raw.B
        src = self.plant_raw.source
        sd = dict(zip(("a1", "a2"), TABLE2_STD["A"][1:]))
        sd.update(zip(("b2", "b3"), TABLE2_STD["B"][2:]))
        for n, v in (("a1", A[1]), ("a2", A[2])):
            params.append(Parameter(f"force_{n}", float(v), "1", "Table II [2 2 2] "
                                                                 f"denominator {n}",
                                    source=src, std=sd[n]))
        for n, v in (("b2", B[2]), ("b3", B[3])):
            params.append(Parameter(f"force_{n}", float(v), "1", "Table II [2 2 2] "
                                                                 f"numerator {n} (per mA, "
                                    "force-sensor units)", source=src, std=sd[n]))
        params.append(force_scale_parameter(self.force_scale))
        params.append(Parameter("force_dt", self.plant.dt, "s", "sample time of the force model",
                                bounds=(0.0, None), source=f"{_SEED} §V-C (200 Hz)",
                                display_unit="ms"))
        return ParameterSet(params, "amadeus-hand")

    def consistency_checks(self) -> list[Finding]:
        out = []
        for part in (self.finger, self.valve, self.hand, self.knuckle):
            out += part.consistency_checks()
        out += table1_findings()
        # Fig. 2(c) maximum frequency response vs the identified poles
        p = self.plant.poles()
        wn = float(np.abs(np.log(p[0])) / self.plant.dt)
        out.append(compare("fig2c-frequency-response", self.name, computed=wn / (2 * math.pi),
                           stated=5.5,
                           rtol=0.1, what="natural frequency of the Table "
                                          "II [2 2 2] poles", unit="Hz",
                           used="the identified model", source=f"{_SEED} Fig. 2(c): maximum "
                                                               "frequency response 5.5 Hz"))
        # Fig. 2(c) peak tip force vs the bending model (blocked straight finger, 12-30 bar)
        f = self.finger
        pr = f.parameters
        m0 = f.max_moment(0.0, pr.value("p_operating"), pr.value("p_max"))
        s = (f.bending(np.array([pr.value("p_operating"), pr.value("p_max"),
                                 pr.value("p_max")])).arc_length)
        lever = float(s) + pr.value("tip_length")
        out.append(compare("fig2c-peak-force", self.name, computed=m0 / lever, stated=PEAK_FORCE,
                           rtol=0.15,
                           what="blocked lateral tip force M₀/(s + l_tip) at 18 "
                                "bar differential", unit="N",
                           used="the assumed bellows area (ID 9.0 mm) and tip length",
                           source=f"{_SEED} Fig. 2(c): peak finger tip force (straight) 15.45 N"))
        z = self.plant.zeros()
        out.append(Finding("tableII-nmp-zero", self.name, True,
                           f"Table II [2 2 2] zero at z = {float(np.real(z[0])):.4f} (outside "
                           "the unit circle: "
                           "non-minimum phase, as §V-F states); force controllers "
                           "must not cancel it",
                           "RST design keeping B in the loop (gripkit.control.design_rst)",
                           float(np.real(z[0])), math.nan, math.nan, math.nan,
                           f"{_SEED} §V-F, Table II"))
        return out


def amadeus_hand(check: bool = True, force_scale: float = FORCE_SCALE) -> AmadeusHandSystem:
    """The zoo entry ``amadeus-hand``; ``force_scale`` is the force sensor's calibration (N per
    unit of Table II, assumed by default: see
    :data:`~gripkit.systems.amadeus.force_dynamics.FORCE_SCALE_DERIVATION`)."""
    return AmadeusHandSystem(check=check, force_scale=force_scale)
