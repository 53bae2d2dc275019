"""One linear-system type for gripkit: state space and transfer function, continuous or
discrete, MIMO, with signal names and units, and optional parameter covariance.

>>> from gripkit.lti import TransferFunction
>>> g = TransferFunction([4.0], [1.0, 0.8, 4.0], inputs="V", outputs="x", output_units="m")
>>> gd = g.c2d(0.05)                      # zero-order hold
>>> round(float(gd.dc_gain()[0, 0]), 12), gd.stable
(1.0, True)

Views: :class:`StateSpace` (A, B, C, D) and :class:`TransferFunction` (num/den per entry,
descending powers; ``from_polynomials``/``num_zinv``/``den_zinv`` for the q⁻¹ layout of ARX and
RST code), both :class:`LinearSystem`. Operations: :func:`c2d`/:func:`d2c` (ZOH, FOH, Tustin),
:func:`series`, :func:`parallel`, :func:`feedback`, poles, (transmission) zeros, DC gain,
frequency response and Bode data, natural frequencies and damping, step/impulse responses,
simulation (numba), stability, minimum phase; every one with σ where the system carries a
covariance.
Interop: ``to_control()``/:func:`from_control` (python-control, optional), ``to_scipy()``/
:func:`from_scipy`, :func:`as_system` (coerce older gripkit models). Array level, for kernels
and batch code: :func:`c2d_matrices`, :func:`d2c_matrices` and the numba kernel
:func:`simulate_ss`.
"""

from typing import TYPE_CHECKING

from ..exports import lazy_exports
from ._discretize import c2d_matrices as c2d_matrices
from ._discretize import d2c_matrices as d2c_matrices
from ._frequency import Bode as Bode
from ._interop import as_system as as_system
from ._interop import from_control as from_control
from ._interop import from_scipy as from_scipy
from ._system import Damping as Damping
from ._system import LinearSystem as LinearSystem
from ._system import StateSpace as StateSpace
from ._system import TransferFunction as TransferFunction
from ._system import c2d as c2d
from ._system import d2c as d2c
from ._system import feedback as feedback
from ._system import parallel as parallel
from ._system import series as series
from ._uncertainty import Uncertainty as Uncertainty

__all__ = ["Bode", "Damping", "LinearSystem", "StateSpace", "TransferFunction", "Uncertainty",
           "as_system",
           "c2d", "c2d_matrices", "d2c", "d2c_matrices", "feedback", "from_control", "from_scipy",
           "parallel",
           "series", "simulate_ss", "affine_row", "flush_tiny"]

if TYPE_CHECKING:
    from ._kernels import affine_row as affine_row
    from ._kernels import flush_tiny as flush_tiny
    from ._kernels import simulate_ss as simulate_ss

# the numba kernel loads on first use (numba's import is 0.2 s of a fresh process)
__getattr__, __dir__ = lazy_exports(__name__, {"simulate_ss": ("_kernels", "simulate_ss"),
                                                  "affine_row": ("_kernels", "affine_row"),
                                                  "flush_tiny": ("_kernels", "flush_tiny")})
