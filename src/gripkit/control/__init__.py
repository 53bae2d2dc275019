"""Control: force control, hybrid force/position, impedance, compensation.

A flat list of explicit re-exports; each developer adds the names of their own modules.
"""

from .two_finger_grasp import GraspSettings as GraspSettings
from .two_finger_grasp import TwoFingerGrasp as TwoFingerGrasp
from .two_finger_grasp import TwoFingerGraspResult as TwoFingerGraspResult
from .two_finger_grasp import simulate_two_finger_grasp as simulate_two_finger_grasp
