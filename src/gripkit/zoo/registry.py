"""The zoo: the one registry of buildable models, each a named factory with provenance.

It holds the seeds' reference systems and the generic components with reference parameters
(system ``generic``: :mod:`gripkit.models.reference`). Every name a TOML description
(``[model] type`` or ``zoo``), a sweep (``[sweep] model``) or ``gripkit zoo`` takes resolves
here; :func:`register` adds one.

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

__all__ = ["ZooEntry", "entries", "get", "build", "register"]


@dataclass(frozen=True)
class ZooEntry:
    name: str
    system: str
    description: str
    seed: str
    factory: str  # "module:function", imported on build

    def factory_function(self):
        """The factory, imported."""
        module, func = self.factory.split(":")
        return getattr(importlib.import_module(module), func)

    def keywords(self) -> tuple[str, ...] | None:
        """The keywords the factory takes (None: any, it has ``**kwargs``); imports its module."""
        fn = self.factory_function()
        kinds = [p.kind for p in inspect.signature(fn).parameters.values()]
        if inspect.Parameter.VAR_KEYWORD in kinds:
            return None
        return tuple(keyword_names(fn))

    def build(self, **kwargs):
        names = self.keywords()
        if names is not None:
            check_keywords(kwargs, names, f"zoo.build({self.name!r})")
        return self.factory_function()(**kwargs)


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
             "Three-bellows finger (eqs 1-8), proportional valves, six-bridge force "
             "sensor with fusion "
             "(eqs 9-19, Table I), PVDF slip sensor, Table II force dynamics in SI units",
             _AMADEUS, "gripkit.systems.amadeus.parameters:amadeus_hand"),
    ZooEntry("ftg100-actuated", "FemtoTools FT-G100 microgripper",
             "Actuated subsystem linearised at 70 V with the 80 um glass ball grasped (eqs 8-10): "
             "voltage (V) to tip displacement (m), M_a, K_fa, k0 identified in §III-B",
             _FTG, "gripkit.systems.ftg100.model:actuated_model"),
    ZooEntry("ftg100-sensing", "FemtoTools FT-G100 microgripper",
             "Sensing subsystem (eqs 14-17): gripping force (N) to sensing-arm tip deflection (m), "
             "M_b, K_fb identified in §III-D; checks the printed eq 17",
             _FTG, "gripkit.systems.ftg100.model:sensing_model"),
    ZooEntry("ftg100-coupled", "FemtoTools FT-G100 microgripper",
             "Coupled gripper model (eq 18): voltage (V) to tip displacements, gripping force and "
             "readout voltage through the object stiffness k0",
             _FTG, "gripkit.systems.ftg100.model:coupled_model"),
    ZooEntry("ftg100-plant", "FemtoTools FT-G100 microgripper",
             "Nonlinear plant: eq 5 comb-drive force as printed (V², 0-200 V), the linear "
             "suspensions "
             "of eqs 4 and 8-10 (eq 10 at 70 V grasped), unilateral contact with the ball after "
             "the "
             "20 um gap (the stated 20 um at 70 V read as the travel to the ball; reported)",
             _FTG, "gripkit.systems.ftg100.model:plant_model"),
    ZooEntry("ftg100-plant-calibrated", "FemtoTools FT-G100 microgripper",
             "Nonlinear plant with the comb-drive force factor fitted to the stated 20 um at 70 V "
             "read as the free tip's travel (0.460 x eq 5); its departure from eqs 5 and 10 is "
             "reported",
             _FTG, "gripkit.systems.ftg100.model:calibrated_plant_model"),
    ZooEntry("tsfm-left", "TSFM piezo microgripper", "Left finger, Table II: Bouc-Wen + D(s) "
                                                     "actuator, lever, force "
             "sensor (8.52 kHz, ζ = "
             "0.006), eqs 3-13", _TSFM, "gripkit.systems.tsfm.parameters:left_finger"),
    ZooEntry("tsfm-right", "TSFM piezo microgripper", "Right finger, Table "
                                                      "II (as tsfm-left)", _TSFM,
             "gripkit.systems.tsfm.parameters:right_finger"),
    ZooEntry("tsfm-finger", "TSFM piezo microgripper", "One finger of Table II, side='left' "
             "(default) or 'right'", _TSFM, "gripkit.systems.tsfm.parameters:finger"),
    ZooEntry("tsfm-finger-contact", "TSFM piezo microgripper",
             "One finger pressing on a part (Fig. 13): face at 62.42 µm (§V-C), Table III's "
             "72.5 N/m; hybrid contact", _TSFM, "gripkit.systems.tsfm.parameters:finger_contact"),
    ZooEntry("tsfm-gripper", "TSFM piezo microgripper", "Both fingers, 400 µm gap, a 300 µm "
                                                        "micropart of Table III "
             "stiffness; hybrid contacts", _TSFM, "gripkit.systems.tsfm.parameters:gripper"),
    ZooEntry("dlr-hit-finger", "DLR/HIT Hand II",
             "Modular finger of ch. 7: PWM → BLDC motor (eq 5.10) → belts and harmonic drive → "
             "Appendix G friction with stick-slip → coupled Newton-Euler dynamics",
             _DLR, "gripkit.systems.dlr_hit.parameters:finger"),
    ZooEntry("dlr-hit-hand", "DLR/HIT Hand II",
             "Five identical fingers on a palm, thumb fixed, per-finger friction (§3.1, §6.3)",
             _DLR, "gripkit.systems.dlr_hit.hand:hand"),
    ZooEntry("mass-spring-damper", "generic",
             "m x'' + b x' + k x = F: force (N) to position (m), exact ZOH; m = 1 kg, k = 1 N/m, "
             "ζ = 0.05 (illustrative values)", "",
             "gripkit.models.reference:reference_mass_spring_damper"),
    ZooEntry("bouc-wen", "generic",
             "Rate-independent Bouc-Wen hysteresis (eq 3): voltage (V) to displacement (m), "
             "Table II left-finger values", _TSFM, "gripkit.models.reference:reference_bouc_wen"),
    ZooEntry("piezo-actuator", "generic",
             "Piezo actuator (eq 4): Bouc-Wen then D(s), voltage and tip loads to tip deflection "
             "and angle, Table II left-finger values (loads=False: voltage only)",
             _TSFM, "gripkit.models.reference:reference_piezo_actuator"),
)


def entries() -> tuple[ZooEntry, ...]:
    return _ENTRIES


def register(entry: ZooEntry) -> None:
    """Add ``entry`` to the zoo of this process (a name already taken is refused)."""
    global _ENTRIES
    if not isinstance(entry, ZooEntry):
        raise ArgumentError("zoo.register(entry): expected a ZooEntry, found "
                            f"{type(entry).__name__}",
                            hint="ZooEntry(name, system, description, seed, 'module:function')")
    if not isinstance(entry.factory, str) or entry.factory.count(":") != 1:
        raise ArgumentError(f"zoo.register({entry.name!r}): factory must be 'module:function', "
                            f"found {entry.factory!r:.60}",
                            hint="for instance 'mypackage.models:my_model'")
    if any(e.name == entry.name for e in _ENTRIES):
        raise ArgumentError(f"zoo.register: the name {entry.name!r} is taken",
                            hint="choose another name; `gripkit zoo list` shows those in use")
    _ENTRIES = (*_ENTRIES, entry)


def get(name: str) -> ZooEntry:
    if not isinstance(name, str):
        raise ArgumentError("zoo model name: expected a str, found "
                            f"{type(name).__name__} {name!r:.40}",
                            hint=f"available: {', '.join(e.name for e in _ENTRIES)}")
    for e in _ENTRIES:
        if e.name == name:
            return e
    raise ModelError(f"no zoo model {name!r}",
                     hint=f"available: {', '.join(e.name for e in _ENTRIES)}")


def build(name: str, **kwargs):
    """Build the zoo model ``name``."""
    return get(name).build(**kwargs)
