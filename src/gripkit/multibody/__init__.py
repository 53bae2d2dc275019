"""Rigid multibody dynamics for small chains: Craig DH and URDF descriptions, forward kinematics
and Jacobians, recursive Newton-Euler inverse dynamics, mass matrix, Coriolis and gravity terms,
forward dynamics, the inverse-dynamics regressor, and joint coupling (numba kernels, batched over
states)."""

from .coupling import CoupledChain as CoupledChain
from .coupling import Coupling as Coupling
from .coupling import differential_matrix as differential_matrix
from .coupling import finger_coupling as finger_coupling
from .dh import DHChain as DHChain
from .joints import JointChain as JointChain
from .joints import JointLimits as JointLimits
from .regressor import regressor as regressor
from .rnea import bias as bias
from .rnea import coriolis as coriolis
from .rnea import forward_dynamics as forward_dynamics
from .rnea import gravity as gravity
from .rnea import kinetic_energy as kinetic_energy
from .rnea import mass_matrix as mass_matrix
from .rnea import potential_energy as potential_energy
from .rnea import rnea as rnea
from .rnea import simulate_free as simulate_free
from .urdf import from_urdf as from_urdf
from .urdf import to_urdf as to_urdf

__all__ = ["bias", "coriolis", "CoupledChain", "Coupling", "DHChain", "differential_matrix",
           "finger_coupling", "forward_dynamics", "from_urdf", "gravity", "JointChain",
           "JointLimits",
           "kinetic_energy", "mass_matrix", "potential_energy", "regressor", "rnea",
           "simulate_free",
           "to_urdf"]
