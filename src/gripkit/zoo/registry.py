"""The zoo: the seeds' reference systems, each a named factory with provenance.

A zoo model is any object with ``name``, ``description``, ``parameters`` (a
:class:`~gripkit.params.ParameterSet` whose parameters carry their ``source``) and
``consistency_checks()`` (see :mod:`gripkit.consistency`). ``gripkit zoo list|show|check``
works on every entry.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass

from ..errors import ModelError

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
        return getattr(importlib.import_module(module), func)(**kwargs)


_AMADEUS = "000_8f66dcc7ab06470c.txt"
_TSFM = "001_0b92a7da96e7aa46.txt"
_DLR = "002_ddea254371185ad3.txt"
_FTG = "003_abd62b560633beaf.txt"

_ENTRIES: tuple[ZooEntry, ...] = (
    ZooEntry("amadeus-finger-force", "AMADEUS subsea hand",
             "Finger force dynamics, ARX [2 2 2] LS model of Table II (9 Hz filtered data), valve "
             "current (A) to fingertip force (N) at 200 Hz, two-sample valve delay",
             _AMADEUS, "gripkit.zoo.amadeus:finger_force_model"),
    ZooEntry("amadeus-hand", "AMADEUS subsea hand",
             "Three-bellows finger (eqs 1-8), proportional valves, six-bridge force sensor with fusion "
             "(eqs 9-19, Table I), PVDF slip sensor, Table II force dynamics in SI units",
             _AMADEUS, "gripkit.zoo.amadeus_hand:amadeus_hand"),
)


def entries() -> tuple[ZooEntry, ...]:
    return _ENTRIES


def get(name: str) -> ZooEntry:
    for e in _ENTRIES:
        if e.name == name:
            return e
    raise ModelError(f"no zoo model {name!r}", hint=f"available: {', '.join(e.name for e in _ENTRIES)}")


def build(name: str, **kwargs):
    """Build the zoo model ``name``."""
    return get(name).build(**kwargs)
