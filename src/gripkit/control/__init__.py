"""Control: a discrete SISO plant and RST pole placement with integral action and anti-windup,
and a discrete PID with setpoint weighting, a filtered derivative and bumpless transfer.

The reference systems' controllers (the AMADEUS force loop, the TSFM two-finger grasp, the FT-G100
hybrid force/position control, the DLR/HIT impedance control) live in :mod:`gripkit.systems`.
A flat list of explicit re-exports.
"""

from .linear_quadratic import LQR as LQR
from .lqg import LQG as LQG
from .linear_quadratic import lqr as lqr
from .pid import PID as PID
from .rst import DiscretePlant as DiscretePlant
from .rst import LoopResult as LoopResult
from .rst import as_plant as as_plant
from .rst import RSTController as RSTController
from .rst import design_rst as design_rst
from .rst import simulate_loop as simulate_loop

__all__ = ["as_plant", "design_rst", "DiscretePlant", "LoopResult", "LQG", "LQR", "lqr", "PID",
           "RSTController", "simulate_loop"]
