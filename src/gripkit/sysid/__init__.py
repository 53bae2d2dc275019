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
    "armax": ("linear.armax", "armax"),
    "arx": ("linear.arx", "arx"),
    "arx_records": ("linear.arx", "arx_records"),
    "IOData": ("io_data", "IOData"),
    "identify": ("identify", "identify"),
    "io_data": ("io_data", "io_data"),
    "oe": ("linear.oe", "oe"),
    "PolynomialModel": ("linear.polynomial", "PolynomialModel"),
    "RLS": ("linear.rls", "RLS"),
    "RLSResult": ("linear.rls", "RLSResult"),
    "rls": ("linear.rls", "rls"),
    "SearchResult": ("linear.search", "SearchResult"),
    "structure_search": ("linear.search", "structure_search"),
    "ResidualTests": ("linear.validation", "ResidualTests"),
    "Validation": ("linear.validation", "Validation"),
    "compare": ("linear.validation", "compare"),
    "fit_percent": ("linear.validation", "fit_percent"),
    "residual_tests": ("linear.validation", "residual_tests"),
    "validate": ("linear.validation", "validate"),
    "GreyboxResult": ("physical.greybox", "GreyboxResult"),
    "fit_greybox": ("physical.greybox", "fit"),
    "identify_bouc_wen": ("physical.bouc_wen", "identify_bouc_wen"),
    "free_vibration": ("physical.modal", "free_vibration"),
    "constant_velocity_friction": ("rigid_body.friction", "constant_velocity_friction"),
    "detect_breakaway": ("rigid_body.friction", "detect_breakaway"),
    "fit_stribeck": ("rigid_body.friction", "fit_stribeck"),
    "idim_ls": ("rigid_body.friction", "idim_ls"),
    "DynamicsResult": ("rigid_body.dynamics", "DynamicsResult"),
    "identify_dynamics": ("rigid_body.dynamics", "identify_dynamics"),
    "characterize_motor": ("rigid_body.motor", "characterize_motor"),
    "fit_motor": ("rigid_body.motor", "fit_motor"),
    "LinearModel": ("linear.linear_model", "LinearModel"),
    "n4sid": ("linear.subspace", "n4sid"),
    "moesp": ("linear.subspace", "moesp"),
    "pem": ("linear.pem_ss", "pem"),
    "FRF": ("linear.frf", "FRF"),
    "frf": ("linear.frf", "frf"),
    "tfest": ("linear.tfest", "tfest"),
    "tfest_frf": ("linear.tfest", "tfest_frf"),
    "load_model": ("model_protocol", "load_model"),
    "ModelFit": ("model_protocol", "ModelFit"),
    "IdentifiedModel": ("model_protocol", "IdentifiedModel"),
    "simulated_trajectory": ("model_protocol", "simulated_trajectory"),
    "IdentifiedLinearModel": ("linear.linear_model", "IdentifiedLinearModel"),
    "load_dynamics_model": ("rigid_body.dynamics", "load_dynamics_model"),
    "fourier_trajectory": ("rigid_body.fourier_trajectory", "fourier_trajectory"),
    "FourierTrajectory": ("rigid_body.fourier_trajectory", "FourierTrajectory"),
    "narx": ("nonlinear.narx_entry", "narx"),
    "NARXModel": ("nonlinear.narx", "NARXModel"),
    "load_narx": ("nonlinear.narx", "load_narx"),
    "RationalNARXModel": ("nonlinear.narx_rational", "RationalNARXModel"),
    "load_rational_narx": ("nonlinear.narx_rational", "load_rational_narx"),
    "hammerstein_wiener": ("nonlinear.hammerstein_wiener", "hammerstein_wiener"),
    "HWModel": ("nonlinear.hammerstein_wiener", "HWModel"),
    "load_hw": ("nonlinear.hammerstein_wiener", "load_hw"),
    "hysteresis": ("nonlinear.hysteresis", "hysteresis"),
    "BoucWenModel": ("nonlinear.hysteresis", "BoucWenModel"),
    "BoucWenOscillatorModel": ("nonlinear.hysteresis", "BoucWenOscillatorModel"),
    "PrandtlIshlinskiiModel": ("nonlinear.hysteresis", "PrandtlIshlinskiiModel"),
    "load_hysteresis": ("nonlinear.hysteresis", "load_hysteresis"),
    "nlss": ("nonlinear.nlss", "nlss"),
    "NLSSModel": ("nonlinear.nlss", "NLSSModel"),
    "load_nlss": ("nonlinear.nlss", "load_nlss"),
}
__getattr__, __dir__ = lazy_exports(__name__, _LAZY)
__all__ = [*_LAZY]

if TYPE_CHECKING:  # static readers see the same names, imported eagerly
    from .linear.armax import armax as armax
    from .linear.arx import arx as arx
    from .linear.arx import arx_records as arx_records
    from .io_data import IOData as IOData
    from .identify import identify as identify
    from .io_data import io_data as io_data
    from .linear.oe import oe as oe
    from .linear.polynomial import PolynomialModel as PolynomialModel
    from .linear.rls import RLS as RLS
    from .linear.rls import RLSResult as RLSResult
    from .linear.rls import rls as rls
    from .linear.search import SearchResult as SearchResult
    from .linear.search import structure_search as structure_search
    from .linear.validation import ResidualTests as ResidualTests
    from .linear.validation import Validation as Validation
    from .linear.validation import compare as compare
    from .linear.validation import fit_percent as fit_percent
    from .linear.validation import residual_tests as residual_tests
    from .linear.validation import validate as validate
    from .physical.greybox import GreyboxResult as GreyboxResult
    from .physical.greybox import fit as fit_greybox  # noqa: F401  (a lazy export: _LAZY)
    from .physical.bouc_wen import identify_bouc_wen as identify_bouc_wen
    from .physical.modal import free_vibration as free_vibration
    from .rigid_body.friction import constant_velocity_friction as constant_velocity_friction
    from .rigid_body.friction import detect_breakaway as detect_breakaway
    from .rigid_body.friction import fit_stribeck as fit_stribeck
    from .rigid_body.friction import idim_ls as idim_ls
    from .rigid_body.dynamics import DynamicsResult as DynamicsResult
    from .rigid_body.dynamics import identify_dynamics as identify_dynamics
    from .rigid_body.motor import characterize_motor as characterize_motor
    from .rigid_body.motor import fit_motor as fit_motor
    from .linear.linear_model import LinearModel as LinearModel
    from .linear.subspace import n4sid as n4sid
    from .linear.subspace import moesp as moesp
    from .linear.pem_ss import pem as pem
    from .linear.frf import FRF as FRF
    from .linear.frf import frf as frf
    from .linear.tfest import tfest as tfest
    from .linear.tfest import tfest_frf as tfest_frf
    from .model_protocol import IdentifiedModel as IdentifiedModel
    from .model_protocol import ModelFit as ModelFit
    from .model_protocol import load_model as load_model
    from .model_protocol import simulated_trajectory as simulated_trajectory
    from .linear.linear_model import IdentifiedLinearModel as IdentifiedLinearModel
    from .rigid_body.dynamics import load_dynamics_model as load_dynamics_model
    from .rigid_body.fourier_trajectory import FourierTrajectory as FourierTrajectory
    from .rigid_body.fourier_trajectory import fourier_trajectory as fourier_trajectory
    from .nonlinear.hammerstein_wiener import HWModel as HWModel
    from .nonlinear.hammerstein_wiener import hammerstein_wiener as hammerstein_wiener
    from .nonlinear.hammerstein_wiener import load_hw as load_hw
    from .nonlinear.narx import NARXModel as NARXModel
    from .nonlinear.narx import load_narx as load_narx
    from .nonlinear.narx_entry import narx as narx
    from .nonlinear.narx_rational import RationalNARXModel as RationalNARXModel
    from .nonlinear.narx_rational import load_rational_narx as load_rational_narx
    from .nonlinear.hysteresis import BoucWenModel as BoucWenModel
    from .nonlinear.hysteresis import BoucWenOscillatorModel as BoucWenOscillatorModel
    from .nonlinear.hysteresis import PrandtlIshlinskiiModel as PrandtlIshlinskiiModel
    from .nonlinear.hysteresis import hysteresis as hysteresis
    from .nonlinear.hysteresis import load_hysteresis as load_hysteresis
    from .nonlinear.nlss import NLSSModel as NLSSModel
    from .nonlinear.nlss import load_nlss as load_nlss
    from .nonlinear.nlss import nlss as nlss
