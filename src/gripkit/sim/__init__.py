"""Simulation core: the Model base class, simulate(), step-resolution checks, linear systems,
fixed-step integrators, hybrid (contact) dynamics, TOML model descriptions. Linear systems are
:class:`gripkit.lti.StateSpace`; :mod:`.linear` keeps the kernels' array-level ZOH and recursion."""

from .linear import c2d_zoh as c2d_zoh
from .model import Model as Model
from .model import Signal as Signal
from .model import simulate as simulate
from .steps import check_step as check_step
from .steps import step_report as step_report
from .steps import substeps_for as substeps_for
from .hybrid import Guard as Guard
from .hybrid import HybridSystem as HybridSystem
from .hybrid import Mode as Mode
from .integrators import integrate_lti as integrate_lti
from .integrators import zoh_levels as zoh_levels

__all__ = ["c2d_zoh", "check_step", "Guard", "HybridSystem", "integrate_lti", "Mode", "Model",
           "Signal",
           "simulate", "step_report", "substeps_for", "zoh_levels"]
