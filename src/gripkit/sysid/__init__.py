"""Linear system identification (``000_8f66dcc7ab06470c.txt`` §V): ARX by least squares, ARMAX
and OE by prediction-error minimisation, recursive least squares (streaming and batch), ARX
structure search, and validation (free-run fit with estimated initial conditions, residual tests).

Arrays in, model out::

    m = gripkit.sysid.arx(u, y, na=2, nb=2, nk=2)      # MATLAB [na nb nk]
    m.A, m.B, m.A_std, m.B_std, m.loss, m.zeros()

A trajectory (from :func:`gripkit.io.load`) in, model out::

    m = gripkit.sysid.identify(traj, "arx", input="current", output="force", na=2, nb=2, nk=2)

The public names are loaded on first use (the table ``_LAZY``, :mod:`gripkit.exports`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..exports import lazy_exports

# public name -> (module of this package, name in that module)
_LAZY = {
    "armax": ("armax", "armax"),
    "arx": ("arx", "arx"),
    "arx_records": ("arx", "arx_records"),
    "IOData": ("identify", "IOData"),
    "identify": ("identify", "identify"),
    "io_data": ("identify", "io_data"),
    "oe": ("oe", "oe"),
    "PolynomialModel": ("polynomial", "PolynomialModel"),
    "RLS": ("rls", "RLS"),
    "RLSResult": ("rls", "RLSResult"),
    "rls": ("rls", "rls"),
    "SearchResult": ("search", "SearchResult"),
    "structure_search": ("search", "structure_search"),
    "Comparison": ("validation", "Comparison"),
    "ResidualTests": ("validation", "ResidualTests"),
    "Validation": ("validation", "Validation"),
    "compare": ("validation", "compare"),
    "fit_percent": ("validation", "fit_percent"),
    "residual_tests": ("validation", "residual_tests"),
    "validate": ("validation", "validate"),
    "GreyboxResult": ("greybox", "GreyboxResult"),
    "fit_greybox": ("greybox", "fit"),
    "identify_bouc_wen": ("bouc_wen", "identify_bouc_wen"),
    "free_vibration": ("modal", "free_vibration"),
    "constant_velocity_friction": ("friction", "constant_velocity_friction"),
    "detect_breakaway": ("friction", "detect_breakaway"),
    "fit_stribeck": ("friction", "fit_stribeck"),
    "idim_ls": ("friction", "idim_ls"),
    "DynamicsResult": ("dynamics", "DynamicsResult"),
    "identify_dynamics": ("dynamics", "identify_dynamics"),
    "characterize_motor": ("motor", "characterize_motor"),
    "fit_motor": ("motor", "fit_motor"),
    "LinearModel": ("linear_model", "LinearModel"),
    "n4sid": ("subspace", "n4sid"),
    "moesp": ("subspace", "moesp"),
    "pem": ("pem_ss", "pem"),
    "FRF": ("frf", "FRF"),
    "frf": ("frf", "frf"),
    "tfest": ("tfest", "tfest"),
    "tfest_frf": ("tfest", "tfest_frf"),
    "load_model": ("model_protocol", "load_model"),
    "ModelFit": ("model_protocol", "ModelFit"),
    "IdentifiedModel": ("model_protocol", "IdentifiedModel"),
    "load_dynamics_model": ("dynamics", "load_dynamics_model"),
    "narx": ("nonlinear.narx", "narx"),
    "NARXModel": ("nonlinear.narx", "NARXModel"),
    "load_narx": ("nonlinear.narx", "load_narx"),
    "nlss": ("nonlinear.nlss", "nlss"),
    "NLSSModel": ("nonlinear.nlss", "NLSSModel"),
    "load_nlss": ("nonlinear.nlss", "load_nlss"),
}
__getattr__, __dir__ = lazy_exports(__name__, _LAZY)
__all__ = [*_LAZY]

if TYPE_CHECKING:  # static readers see the same names, imported eagerly
    from .armax import armax as armax
    from .arx import arx as arx
    from .arx import arx_records as arx_records
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
    from .model_protocol import IdentifiedModel as IdentifiedModel
    from .model_protocol import ModelFit as ModelFit
    from .model_protocol import load_model as load_model
    from .dynamics import load_dynamics_model as load_dynamics_model
    from .nonlinear.narx import NARXModel as NARXModel
    from .nonlinear.narx import load_narx as load_narx
    from .nonlinear.narx import narx as narx
    from .nonlinear.nlss import NLSSModel as NLSSModel
    from .nonlinear.nlss import load_nlss as load_nlss
    from .nonlinear.nlss import nlss as nlss
