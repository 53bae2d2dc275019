"""Simulation core: the Model base class, simulate(), step-resolution checks, linear systems."""

from .linear import StateSpace as StateSpace
from .linear import c2d_zoh as c2d_zoh
from .model import Model as Model
from .model import Signal as Signal
from .model import simulate as simulate
from .steps import check_step as check_step
from .steps import step_report as step_report
from .steps import substeps_for as substeps_for
