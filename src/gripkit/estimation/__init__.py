"""Estimation: sensor fusion, force estimation, filters, observers, slip and contact detection.

A flat list of explicit re-exports; each developer adds the names of their own modules.
"""

from .contact_detection import ContactDetector as ContactDetector
from .force_sensor import ForceDynamics as ForceDynamics
from .force_sensor import ForceEstimate as ForceEstimate
from .force_sensor import ForceKalmanFilter as ForceKalmanFilter
from .force_sensor import KalmanResult as KalmanResult
from .force_sensor import SensorCalibration as SensorCalibration
from .force_sensor import calibrate as calibrate_force_sensor
from .force_sensor import estimate_force as estimate_force
from .fusion import NormalisedVariances as NormalisedVariances
from .fusion import fuse as fuse
from .fusion import fuse_proportional as fuse_proportional
from .fusion import fuse_update as fuse_update
from .fusion import fused_variance as fused_variance
from .fusion import implied_correlation as implied_correlation
from .fusion import normalised_variances as normalised_variances
from .fusion import proportional_variance as proportional_variance
from .micropart import MicropartEstimate as MicropartEstimate
from .micropart import estimate_micropart as estimate_micropart
from .slip import SlipDetection as SlipDetection
from .slip import SlipDetector as SlipDetector
from .slip import SlipEvent as SlipEvent
from .slip import SlipReflex as SlipReflex
from .slip import SlipStream as SlipStream
from .slip import SpeedCalibration as SpeedCalibration
from .slip import calibrate_speed as calibrate_speed
from .slip import false_alarm_rate as false_alarm_rate
from .slip import spectral_features as spectral_features
from .slip import stick_slip_rate as stick_slip_rate
from .tip_position import TipPositionEstimator as TipPositionEstimator
from .friction_adaptation import FrictionAdapter as FrictionAdapter
from .friction_adaptation import adapt_finger_friction as adapt_finger_friction
