"""Linear system identification (``000_8f66dcc7ab06470c.txt`` §V): ARX by least squares, ARMAX
and OE by prediction-error minimisation, recursive least squares (streaming and batch), ARX
structure search, and validation (free-run fit with estimated initial conditions, residual tests).

Arrays in, model out::

    m = gripkit.sysid.arx(u, y, na=2, nb=2, nk=2)      # MATLAB [na nb nk]
    m.A, m.B, m.A_std, m.B_std, m.loss, m.zeros()

A trajectory (from :func:`gripkit.io.load`) in, model out::

    m = gripkit.sysid.identify(traj, "arx", input="current", output="force", na=2, nb=2, nk=2)
"""

from .armax import armax as armax
from .arx import arx as arx
from .identify import IOData as IOData
from .identify import identify as identify
from .identify import io_data as io_data
from .oe import oe as oe
from .polynomial import PolynomialModel as PolynomialModel
from .rls import RLS as RLS
from .rls import RLSResult as RLSResult
from .rls import rls as rls
from .search import SearchResult as SearchResult
from .search import structure_search as structure_search
from .validation import Comparison as Comparison
from .validation import ResidualTests as ResidualTests
from .validation import Validation as Validation
from .validation import compare as compare
from .validation import fit_percent as fit_percent
from .validation import residual_tests as residual_tests
from .validation import validate as validate
from .greybox import GreyboxResult as GreyboxResult
from .greybox import fit as fit_greybox
from .bouc_wen import identify_bouc_wen as identify_bouc_wen
from .modal import free_vibration as free_vibration
from .friction import constant_velocity_friction as constant_velocity_friction
from .friction import detect_breakaway as detect_breakaway
from .friction import fit_stribeck as fit_stribeck
from .friction import idim_ls as idim_ls
from .dynamics import DynamicsResult as DynamicsResult
from .dynamics import identify_dynamics as identify_dynamics
from .motor import characterize_motor as characterize_motor
from .motor import fit_motor as fit_motor
from .linear_model import LinearModel as LinearModel
from .subspace import n4sid as n4sid
from .subspace import moesp as moesp
from .pem_ss import pem as pem
from .frf import FRF as FRF
from .frf import frf as frf
from .tfest import tfest as tfest
from .tfest import tfest_frf as tfest_frf
from .model_file import load_model as load_model
from .dynamics import load_dynamics_model as load_dynamics_model
