"""The zoo: the one registry of buildable models (the reference models of :mod:`gripkit.systems`
and the generic components of :mod:`gripkit.models.reference`), each a named factory with
provenance (see :mod:`gripkit.zoo.registry`); building one imports its module on demand."""

from .registry import ZooEntry as ZooEntry
from .registry import build as build
from .registry import entries as entries
from .registry import get as get
from .registry import register as register

__all__ = ["build", "entries", "get", "register", "ZooEntry"]
