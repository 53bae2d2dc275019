"""Control: a discrete SISO plant and RST pole placement with integral action and anti-windup,
a discrete PID with setpoint weighting, a filtered derivative and bumpless transfer, LQR and its
state feedback (:class:`StateFeedback`), each with an allocation-free numba ``.step``; PID tuning
on an identified model by the SIMC rules (:func:`tune_pid`); margins and closed-loop poles with
their Monte Carlo distribution over the model's covariance (:func:`robustness`); the controller
file (:func:`save_controller`, :func:`load_controller`) that ``gripkit export c --kind`` reads.

The reference systems' controllers (the AMADEUS force loop, the TSFM two-finger grasp, the FT-G100
hybrid force/position control, the DLR/HIT impedance control) live in :mod:`gripkit.systems`.
A flat list of explicit re-exports.
"""

from .controller_file import load_controller as load_controller
from .controller_file import save_controller as save_controller
from .linear_quadratic import LQR as LQR

from .linear_quadratic import lqr as lqr
from .lqg import LQG as LQG
from .pid import PID as PID
from .rst import DiscretePlant as DiscretePlant
from .rst import LoopResult as LoopResult
from .rst import as_plant as as_plant
from .rst import RSTController as RSTController
from .rst import design_rst as design_rst
from .rst import simulate_loop as simulate_loop
from .robustness import Robustness as Robustness
from .robustness import loop_margins as loop_margins
from .robustness import robustness as robustness
from .state_feedback import StateFeedback as StateFeedback
from .state_feedback import lqr_controller as lqr_controller
from .tuning import LowOrderModel as LowOrderModel
from .tuning import reduce_model as reduce_model
from .tuning import tune_pid as tune_pid

__all__ = ["as_plant", "design_rst", "DiscretePlant", "LoopResult", "LQG", "LQR", "lqr", "PID",
           "RSTController", "simulate_loop",
           "StateFeedback", "lqr_controller", "LowOrderModel", "reduce_model", "tune_pid",
           "Robustness", "loop_margins", "robustness", "load_controller", "save_controller"]
