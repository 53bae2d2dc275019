"""Controllers: discrete PID (numba scalar step), hybrid force/position control."""

from .hybrid import HybridForcePosition as HybridForcePosition
from .pid import PID as PID
