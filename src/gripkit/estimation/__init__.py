"""Estimation: sensor fusion, force estimation, filters, observers, slip and contact detection.

A flat list of explicit re-exports; each developer adds the names of their own modules.
"""

from .contact_detection import ContactDetector as ContactDetector
from .micropart import MicropartEstimate as MicropartEstimate
from .micropart import estimate_micropart as estimate_micropart
from .tip_position import TipPositionEstimator as TipPositionEstimator
