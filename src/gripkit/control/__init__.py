"""Control: force control of the AMADEUS finger (RST pole placement), discrete PID with
anti-windup and bumpless transfer, hybrid force/position control, impedance control.

A flat list of explicit re-exports.
"""

from .finger_force import DiscretePlant as DiscretePlant
from .finger_force import GraspResult as GraspResult
from .finger_force import GraspScenario as GraspScenario
from .finger_force import LoopResult as LoopResult
from .finger_force import RSTController as RSTController
from .finger_force import StepMetrics as StepMetrics
from .finger_force import design_rst as design_rst
from .finger_force import simulate_grasp as simulate_grasp
from .finger_force import simulate_loop as simulate_loop
from .finger_force import step_metrics as step_metrics
from .hybrid import HybridForcePosition as HybridForcePosition
from .pid import PID as PID
from .two_finger_grasp import GraspSettings as GraspSettings
from .two_finger_grasp import TwoFingerGrasp as TwoFingerGrasp
from .two_finger_grasp import TwoFingerGraspResult as TwoFingerGraspResult
from .two_finger_grasp import simulate_two_finger_grasp as simulate_two_finger_grasp
from .impedance import ImpedanceController as ImpedanceController
from .impedance import Wall as Wall
from .impedance import impedance_margins as impedance_margins
from .impedance import simulate_impedance as simulate_impedance
from .impedance import stability_margins as stability_margins
