"""The zoo: a registry of the reference models of :mod:`gripkit.systems`, each a named factory with
provenance (see :mod:`gripkit.zoo.registry`); building one imports its system on demand."""

from .registry import ZooEntry as ZooEntry
from .registry import build as build
from .registry import entries as entries
from .registry import get as get

__all__ = ["build", "entries", "get", "ZooEntry"]
