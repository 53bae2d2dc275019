"""The four seed systems with parameters and provenance (see :mod:`gripkit.zoo.registry`)."""

from .registry import ZooEntry as ZooEntry
from .registry import build as build
from .registry import entries as entries
from .registry import get as get
