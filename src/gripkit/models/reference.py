"""The generic components built with reference parameters, each value with its source: the
factories of the zoo's ``generic`` entries (``mass-spring-damper``, ``bouc-wen``,
``piezo-actuator``; see :mod:`gripkit.zoo.registry`).

The Bouc-Wen and piezo-actuator values are those the components default to: the left finger of
Table II of ``001_0b92a7da96e7aa46.txt`` (λ read in µm/V, the b row the actuator's, see
:mod:`gripkit.systems.tsfm.parameters`). The mass-spring-damper has no seed: unit mass and
stiffness with ζ = b/(2√(km)) = 0.05, a lightly damped 1/(2π) Hz oscillator to try a sweep on.
"""

from __future__ import annotations

from ..params import ParameterSet
from .hysteresis import BoucWen, bouc_wen_parameters
from .mass_spring_damper import MassSpringDamper, msd_parameters
from .piezo import PiezoActuator, actuator_parameters

__all__ = ["reference_mass_spring_damper", "reference_bouc_wen", "reference_piezo_actuator",
           "TABLE_II_LEFT", "SOURCES"]

_T2 = "001_0b92a7da96e7aa46.txt Table II, left finger"

#: Table II's left finger (SI), the values the Bouc-Wen and piezo components default to
TABLE_II_LEFT = dict(d_p=0.77e-6, s_p=9.1e-4, lam=0.43e-6, beta=0.108, gamma=7.5e-3, a=2.5e-8,
                     b=8e-5)

#: where each reference value comes from
SOURCES = {
    "msd": "illustrative (no seed): m = 1 kg, k = 1 N/m, b = 0.1 N·s/m, so ζ = 0.05",
    "table_ii": f"{_T2} (λ read in µm/V)",
    "L_a": "assumed: 15 mm PZT bimorph (1/s_p = 1100 N/m of 001_0b92a7da96e7aa46.txt Table I); the "
           "seed gives none",
}


def reference_mass_spring_damper(*, check: bool = True) -> MassSpringDamper:
    """m ẍ + b ẋ + k x = F with m = 1 kg, b = 0.1 N·s/m, k = 1 N/m (zoo
    ``mass-spring-damper``)."""
    return MassSpringDamper(msd_parameters(1.0, 0.1, 1.0, source=SOURCES["msd"]), check=check)


def reference_bouc_wen(*, check: bool = True) -> BoucWen:
    """Eq 3 hysteresis with Table II's left-finger d_p, λ, β, γ (zoo ``bouc-wen``)."""
    v = TABLE_II_LEFT
    return BoucWen(bouc_wen_parameters(v["d_p"], v["lam"], v["beta"], v["gamma"],
                                       source=SOURCES["table_ii"]), check=check)


def reference_piezo_actuator(*, loads: bool = True, check: bool = True) -> PiezoActuator:
    """Eq 4 actuator with Table II's left-finger values and the assumed L_a = 15 mm (zoo
    ``piezo-actuator``); ``loads=False``: voltage the only input (free motion)."""
    p = actuator_parameters(**TABLE_II_LEFT, L_a=15e-3, source=SOURCES["table_ii"])
    p = ParameterSet([q.with_value(q.value, source=SOURCES["L_a"]) if q.name == "L_a" else q
                      for q in p.values()], p.name)
    return PiezoActuator(p, loads=loads, check=check)
