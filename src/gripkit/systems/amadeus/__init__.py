"""The AMADEUS hydraulic three-finger subsea hand (``000_8f66dcc7ab06470c.txt``).

- :mod:`.force_dynamics` — the identified finger-force ARX models of Tables II and III
  (:class:`FingerForcePlant`) and reference data;
- :mod:`.parameters` — the hand as a zoo system: Table I and Table II in SI units with provenance;
- :mod:`.bellows_finger`, :mod:`.hand`, :mod:`.valve` — the three-bellows finger (eqs 1–8), the
  three-finger hand (palm, knuckles, force closure), the proportional pressure valves;
- :mod:`.position_control`, :mod:`.knuckle` — fingertip position control from the tube pressures
  (no tip sensor, §II-C), and the knuckle's cylinder, linkage, three-position valve and bang-bang
  angle control (§II-B, §II-D);
- :mod:`.strain_gauge_sensor`, :mod:`.force_sensor` — the six-bridge fingertip force sensor and its
  calibration, weighted least squares and Kalman filter (eqs 9–19);
- :mod:`.pvdf`, :mod:`.slip` — the PVDF slip film on a stick-slip contact, and slip detection;
- :mod:`.force_control` — the finger force loop (RST of :mod:`gripkit.control.rst`) and a grasp;
- :mod:`.demo_identification`, :mod:`.demo_hand` — the demo-report sections.

A flat list of explicit re-exports.
"""

from .bellows_finger import BellowsFinger as BellowsFinger
from .force_control import FingerGraspResult as FingerGraspResult
from .force_control import GraspScenario as GraspScenario
from .force_control import simulate_finger_grasp as simulate_finger_grasp
from .force_dynamics import FingerForcePlant as FingerForcePlant
from .force_dynamics import ReferenceModel as ReferenceModel
from .force_dynamics import finger_force_model as finger_force_model
from .force_sensor import ForceDynamics as ForceDynamics
from .force_sensor import ForceEstimate as ForceEstimate
from .force_sensor import ForceKalmanFilter as ForceKalmanFilter
from .force_sensor import KalmanResult as KalmanResult
from .force_sensor import SensorCalibration as SensorCalibration
from .force_sensor import calibrate as calibrate_force_sensor
from .force_sensor import estimate_force as estimate_force
from .hand import AmadeusHand as AmadeusHand
from .parameters import AmadeusHandSystem as AmadeusHandSystem
from .parameters import amadeus_hand as amadeus_hand
from .pvdf import SlipTestbed as SlipTestbed
from .pvdf import StickSlipContact as StickSlipContact
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
from .strain_gauge_sensor import StrainGaugeSensor as StrainGaugeSensor
from .valve import ProportionalValve as ProportionalValve

__all__ = ["amadeus_hand", "AmadeusHand", "AmadeusHandSystem", "BellowsFinger",
           "calibrate_force_sensor",
           "calibrate_speed", "estimate_force", "false_alarm_rate", "finger_force_model",
           "FingerForcePlant",
           "FingerGraspResult", "ForceDynamics", "ForceEstimate", "ForceKalmanFilter",
           "GraspScenario",
           "KalmanResult", "ProportionalValve", "ReferenceModel", "SensorCalibration",
           "simulate_finger_grasp", "SlipDetection", "SlipDetector", "SlipEvent", "SlipReflex",
           "SlipStream",
           "SlipTestbed", "spectral_features", "SpeedCalibration", "stick_slip_rate",
           "StickSlipContact",
           "StrainGaugeSensor"]
