"""Estimation: fusion of independent estimates, contact detection, online friction adaptation,
Kalman filters (linear, extended, unscented).

The reference systems' estimators (AMADEUS fingertip force and slip, TSFM tip position and
micropart) live in :mod:`gripkit.systems`.

A flat list of explicit re-exports; each developer adds the names of their own modules.
"""

from .contact_detection import ContactDetector as ContactDetector
from .fusion import NormalisedVariances as NormalisedVariances
from .fusion import fuse as fuse
from .fusion import fuse_proportional as fuse_proportional
from .fusion import fuse_update as fuse_update
from .fusion import fused_variance as fused_variance
from .fusion import implied_correlation as implied_correlation
from .fusion import normalised_variances as normalised_variances
from .fusion import proportional_variance as proportional_variance
from .friction_adaptation import AdaptationSettings as AdaptationSettings
from .friction_adaptation import FrictionAdapter as FrictionAdapter
from .kalman import KalmanFilter as KalmanFilter
from .kalman import KalmanRun as KalmanRun
from .nonlinear_kalman import ExtendedKalmanFilter as ExtendedKalmanFilter
from .nonlinear_kalman import UnscentedKalmanFilter as UnscentedKalmanFilter

__all__ = ["AdaptationSettings", "ContactDetector", "ExtendedKalmanFilter", "FrictionAdapter",
           "fuse", "fuse_proportional",
           "fuse_update", "fused_variance", "implied_correlation", "KalmanFilter", "KalmanRun",
           "normalised_variances",
           "NormalisedVariances", "proportional_variance", "UnscentedKalmanFilter"]
