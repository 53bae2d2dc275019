"""The zoo: the seeds' reference systems, each a named factory with provenance.

A zoo model is any object with ``name``, ``description``, ``parameters`` (a
:class:`~gripkit.params.ParameterSet` whose parameters carry their ``source``) and
``consistency_checks()`` (see :mod:`gripkit.consistency`). ``gripkit zoo list|show|check``
works on every entry.
"""

from __future__ import annotations

import importlib
import inspect
from dataclasses import dataclass

from ..arguments import check_keywords, keyword_names
from ..errors import ArgumentError, ModelError

__all__ = ["ZooEntry", "entries", "get", "build"]


@dataclass(frozen=True)
class ZooEntry:
    name: str
    system: str
    description: str
    seed: str
    factory: str  # "module:function", imported on build

    def build(self, **kwargs):
        module, func = self.factory.split(":")
        fn = getattr(importlib.import_module(module), func)
        if not any(p.kind is inspect.Parameter.VAR_KEYWORD for p in inspect.signature(fn).parameters.values()):
            check_keywords(kwargs, keyword_names(fn), f"zoo.build({self.name!r})")
        return fn(**kwargs)


_AMADEUS = "000_8f66dcc7ab06470c.txt"
_TSFM = "001_0b92a7da96e7aa46.txt"
_DLR = "002_ddea254371185ad3.txt"
_FTG = "003_abd62b560633beaf.txt"

_ENTRIES: tuple[ZooEntry, ...] = (
    ZooEntry("amadeus-finger-force", "AMADEUS subsea hand",
             "Finger force dynamics, ARX [2 2 2] LS model of Table II (9 Hz filtered data), valve "
             "current (A) to fingertip force (N) at 200 Hz, two-sample valve delay",
             _AMADEUS, "gripkit.systems.amadeus.force_dynamics:finger_force_model"),
    ZooEntry("amadeus-hand", "AMADEUS subsea hand",
             "Three-bellows finger (eqs 1-8), proportional valves, six-bridge force sensor with fusion "
             "(eqs 9-19, Table I), PVDF slip sensor, Table II force dynamics in SI units",
             _AMADEUS, "gripkit.systems.amadeus.parameters:amadeus_hand"),
    ZooEntry("ftg100-actuated", "FemtoTools FT-G100 microgripper",
             "Actuated subsystem linearised at 70 V with the 80 um glass ball grasped (eqs 8-10): "
             "voltage (V) to tip displacement (m), M_a, K_fa, k0 identified in §III-B",
             _FTG, "gripkit.systems.ftg100.parameters:actuated_model"),
    ZooEntry("ftg100-sensing", "FemtoTools FT-G100 microgripper",
             "Sensing subsystem (eqs 14-17): gripping force (N) to sensing-arm tip deflection (m), "
             "M_b, K_fb identified in §III-D; checks the printed eq 17",
             _FTG, "gripkit.systems.ftg100.parameters:sensing_model"),
    ZooEntry("ftg100-coupled", "FemtoTools FT-G100 microgripper",
             "Coupled gripper model (eq 18): voltage (V) to tip displacements, gripping force and "
             "readout voltage through the object stiffness k0",
             _FTG, "gripkit.systems.ftg100.parameters:coupled_model"),
    ZooEntry("ftg100-plant", "FemtoTools FT-G100 microgripper",
             "Nonlinear plant: eq 5 comb-drive force as printed (V², 0-200 V), the linear "
             "suspensions "
             "of eqs 4 and 8-10 (eq 10 at 70 V grasped), unilateral contact with the ball after "
             "the "
             "20 um gap (the stated 20 um at 70 V read as the travel to the ball; reported)",
             _FTG, "gripkit.systems.ftg100.parameters:plant_model"),
    ZooEntry("ftg100-plant-calibrated", "FemtoTools FT-G100 microgripper",
             "Nonlinear plant with the comb-drive force factor fitted to the stated 20 um at 70 V "
             "read as the free tip's travel (0.460 x eq 5); its departure from eqs 5 and 10 is "
             "reported",
             _FTG, "gripkit.systems.ftg100.parameters:calibrated_plant_model"),
    ZooEntry("tsfm-left", "TSFM piezo microgripper", "Left finger, Table II: Bouc-Wen + D(s) actuator, lever, force "
             "sensor (8.52 kHz, ζ = 0.006), eqs 3-13", _TSFM, "gripkit.systems.tsfm.parameters:left_finger"),
    ZooEntry("tsfm-right", "TSFM piezo microgripper", "Right finger, Table II (as tsfm-left)", _TSFM,
             "gripkit.systems.tsfm.parameters:right_finger"),
    ZooEntry("tsfm-gripper", "TSFM piezo microgripper", "Both fingers, 400 µm gap, a 300 µm micropart of Table III "
             "stiffness; hybrid contacts", _TSFM, "gripkit.systems.tsfm.parameters:gripper"),
    ZooEntry("dlr-hit-finger", "DLR/HIT Hand II",
             "Modular finger of ch. 7: PWM → BLDC motor (eq 5.10) → belts and harmonic drive → "
             "Appendix G friction with stick-slip → coupled Newton-Euler dynamics",
             _DLR, "gripkit.systems.dlr_hit.parameters:finger"),
    ZooEntry("dlr-hit-hand", "DLR/HIT Hand II",
             "Five identical fingers on a palm, thumb fixed, per-finger friction (§3.1, §6.3)",
             _DLR, "gripkit.systems.dlr_hit.hand:hand"),
)


def entries() -> tuple[ZooEntry, ...]:
    return _ENTRIES


def get(name: str) -> ZooEntry:
    if not isinstance(name, str):
        raise ArgumentError(f"zoo model name: expected a str, found {type(name).__name__} {name!r:.40}",
                            hint=f"available: {', '.join(e.name for e in _ENTRIES)}")
    for e in _ENTRIES:
        if e.name == name:
            return e
    raise ModelError(f"no zoo model {name!r}", hint=f"available: {', '.join(e.name for e in _ENTRIES)}")


def build(name: str, **kwargs):
    """Build the zoo model ``name``."""
    return get(name).build(**kwargs)
