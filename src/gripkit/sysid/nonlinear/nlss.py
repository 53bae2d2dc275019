"""Polynomial nonlinear state-space models, in the PNLSS form of Paduart et
al. (J. Paduart, L. Lauwers, J. Swevers, K. Smolders, J. Schoukens, R. Pintelon, "Identification
of nonlinear systems using Polynomial Nonlinear State Space models", Automatica 46(4), 647–656,
2010)::

    x(t+1) = A x + B ũ + E ζ(x, ũ),      y(t) = y₀ + C x + D ũ + F η(x, ũ)

ζ holds every monomial of degree 2 … ``degree`` of the states and inputs; η the same monomials of
the states only (with ``feedthrough=True`` also of the inputs, and D is estimated; otherwise
D = 0 and y(t) does not depend on u(t)). Inputs enter normalised, ũ = (u − ū)/s_u (mean and
standard deviation of the estimation record), and the states are scaled to unit standard
deviation on the estimation record, so that the monomials are of order one; y₀, the output at
the equilibrium x = 0 of the mean input, is estimated (it differs from the mean output of a
nonlinear system).

Estimation (:func:`nlss`):

1. The linear start: :func:`gripkit.sysid.n4sid` on the centred data (order n at the largest
   gap of the singular values, at most ``max_order``, and n + 1; the model of lower BIC is kept,
   or with a validation record the best validation fit among n − 1, n, n + 1), E = F = 0 — the
   model's best linear approximation, from which Paduart et al. start too.
2. Truncated simulation windows: the record is cut into windows of ``window`` samples (default
   10 time constants of the slowest linear pole, at least 50 samples and at most 200 windows);
   each window is simulated from its own initial state, estimated with the parameters, and the
   criterion is the sum of the windows' squared simulation errors (outputs weighted by the
   linear model's error RMS). Short windows keep the criterion smooth and bounded while the
   nonlinear terms grow from zero (A. H. Ribeiro, K. Tiels, J. Umenberger, T. B. Schön,
   L. A. Aguirre, "On the smoothness of nonlinear system identification", Automatica 121, 2020).
3. The whole record: the same criterion with one window (the free-run simulation error from one
   estimated initial state), started from stage 2's parameters.

A record longer than 8000 samples goes through stages 2 and 3 on its first 8000 samples, then
stage 3 again on all of them, at most 10 iterations (a polish: the optimum moves little, and each
pass over the record costs N·P² for P parameters). Stage 3 on the first part takes only steps
whose free run stays in range over all samples, and starts from the linear model where stage 2's
model runs away over them (an over-parameterised model fitted to the first part can be unstable
beyond it: Silverbox at order 4, 239 parameters, diverged on the rest of the record and on the
validation record before).

Both stages are Levenberg-Marquardt on the exact Gauss-Newton sums of the sensitivity equations
(numba kernels, :mod:`.nlss_kernels`; the initial states are eliminated by a Schur complement,
one n × n block per window). A step whose free run leaves the state range (1000 × the
estimation states' largest magnitude) is rejected like a step that raises the criterion. Each
iteration is a pass of the sensitivity kernel over the record (N·Q²/2 multiply-adds for JᵀJ,
Q = P + n), so a stage stops as soon as more iterations buy nothing that shows in the fit: a step
that lowers the criterion by less than 0.01 noise variances, or three steps that together lower
it by less than 0.1 % (the windows of stage 2, only a start: 1 %).

Parameters and the state basis: a similarity transform x → T x gives the same input-output
behaviour, so n² entries of (A, B, C) are held at their values of the linear start: the
d = nm + pn free ones are those whose unit directions complement the similarity orbit best
(pivoted QR, the choice of :mod:`gripkit.sysid.linear.pem_ss`), and the other n² entries fix the
state basis. The σ of the free parameters are those of σ²(JᵀJ)⁻¹ at the optimum (J of the weighted
simulation errors, the initial state a parameter too, σ² over N·p − P − n degrees of freedom).
They are σ *in that fixed basis*: y₀ and D do not depend on the basis, and the output equation
(C, F) says how the output depends on the states of this basis; A, B, E and C, F of another
run (another start) are not comparable entry by entry. The input-output behaviour is the
invariant, and its σ is :meth:`NLSSModel.simulate` with ``std=True`` (the parameter covariance
propagated through the sensitivity equations of the free run; a 20-run Monte Carlo in the tests
finds the noise-free output within 3σ at 399 of 400 checks).
"""

from __future__ import annotations

import itertools
import math
import time
import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import scipy.linalg as sla

from ...arguments import real_array
from ...errors import (AccuracyWarning, ArgumentError, DataError, IdentificationError,
                       ModelError, StabilityWarning, emit_warning)
from ..checks import check_not_transposed
from ..io_data import check_scale
from ..model_file import (SAMPLE_TIME, Domain, FamilyFile, check_family_fields, file_provenance,
                          read_family_document)
from ..model_protocol import ModelFit, column_in_unit
from . import nlss_kernels as K
from .nonlinear_model import NonlinearModel, OutputErrorPrediction
from ...params import Parameter, ParameterSet
from ...progress import status, track
from ...signals.trajectory import Trajectory
from ..linear.subspace import RecordsFactor, default_horizon, n4sid, n4sid_records, subspace_factor

__all__ = ["SCHEMA", "NLSS_FIT", "NLSSModel", "nlss", "load_nlss", "monomial_exponents"]

SCHEMA = "gripkit.nlss-model"
VERSION = 1
#: how an NLSS model's fit is taken (``gripkit compare`` prints it)
NLSS_FIT = ("free run from an initial state estimated by Gauss-Newton on the record's simulation "
            "error, fit = 100 (1 − ‖y − ŷ‖/‖y − ȳ‖) per output over all samples")
#: a free run whose state exceeds this many times the estimation states' largest magnitude is
#: reported as diverged
DIVERGENCE_FACTOR = 1e3
#: Levenberg-Marquardt stops when the last step lowered the criterion by less than this many
#: noise variances (a move of ≪ 1σ) or by a relative 1e-7
_NEGLIGIBLE_DROP = 0.01
#: … or when the last :data:`_STALL_SPAN` steps together lowered it by less than this fraction
#: (the whole record: the free-run error's RMS moves by < 0.05 %, 0.01 fit points at a 98 % fit),
#: the crawl along a poorly determined valley of an over-parameterised model (Silverbox at
#: order 4: 100 iterations for the last 7 % of the criterion, a 0.05-point fit)
_STALL = 1e-3
#: … and the windows of stage 2, only the start of stage 3, when they lowered it by < 1 %
_STALL_WINDOWS = 1e-2
_STALL_SPAN = 3
_KIND = "ABCDEF"
#: a longer record is first fitted on its first this many samples (windows, then whole), then
#: polished on all of them (the same optimum, a fraction of the full-length sensitivity passes)
_WARM_SAMPLES = 8000
#: at most this many Levenberg-Marquardt iterations of the polish on a longer whole record
_POLISH_ITERATIONS = 10
#: condition number of the scaled Hessian beyond which σ are not trusted (AccuracyWarning)
_ILL_CONDITIONED = 1e12


def monomial_exponents(n_states: int, n_inputs: int, degree: int, inputs: bool = True,
                       input_levels=None):
    """Exponent table (M, n + m) of every monomial of degree 2 … ``degree`` of the states (and of
    the inputs when ``inputs``), by degree, then in the order of ``combinations_with_replacement``.
    ``input_levels``: the number of distinct values each input takes; a power ≥ that number of an
    input that takes k values is a polynomial of degree < k in it (u² = (a + b) u − a b for a
    two-level input), so the monomials holding one are left out."""
    nv = n_states + (n_inputs if inputs else 0)
    rows = []
    for d in range(2, degree + 1):
        for combo in itertools.combinations_with_replacement(range(nv), d):
            e = [0] * (n_states + n_inputs)
            for i in combo:
                e[i] += 1
            if input_levels is not None and any(
                    e[n_states + j] >= input_levels[j] for j in range(n_inputs)):
                continue
            rows.append(e)
    return np.array(rows, dtype=np.int64).reshape(len(rows), n_states + n_inputs)


def _monomial_name(e, n: int) -> str:
    """``x1^2*u1`` for the exponents (x1, …, xn, u1, …) of :func:`monomial_exponents`."""
    parts = []
    for i, a in enumerate(e):
        if a:
            v = f"x{i + 1}" if i < n else f"u{i - n + 1}"
            parts.append(v if a == 1 else f"{v}^{a}")
    return "*".join(parts)


def _fits(y: np.ndarray, yhat: np.ndarray) -> list[float]:
    out = []
    for i in range(y.shape[1]):
        den = float(np.linalg.norm(y[:, i] - y[:, i].mean()))
        if den == 0.0:
            raise DataError(f"nlss: output {i + 1} is constant; the fit is undefined "
                            "(‖y − ȳ‖ = 0): check the output column")
        out.append(100.0 * (1.0 - float(np.linalg.norm(y[:, i] - yhat[:, i])) / den))
    return out


def _trajectory_columns(data: Trajectory, names, kind: str, what: str,
                        units=None) -> np.ndarray:
    """The columns ``names`` of ``data`` as an array (N, k); a missing one is named (``kind``:
    "input" or "output", ``what``: the method); with the model's ``units``, each in its unit
    (:func:`~gripkit.sysid.model_protocol.column_in_unit`)."""
    missing = [c for c in names if c not in data.names]
    if missing:
        raise DataError(f"nlss.{what}: the data lack the model's {kind} column(s) "
                        f"{', '.join(map(repr, missing))}; they have "
                        f"{', '.join(map(repr, data.names))}")
    if units is not None:
        return np.column_stack([column_in_unit(data, c, u, kind) for c, u in zip(names, units)])
    return np.column_stack([np.asarray(data[c], dtype=np.float64) for c in names])


@dataclass
class NLSSModel(OutputErrorPrediction, NonlinearModel, FamilyFile):
    """A polynomial nonlinear state-space model (module docstring).

    Matrices ``A`` (n, n), ``B`` (n, m), ``C`` (p, n), ``D`` (p, m), ``E`` (n, Mζ), ``F`` (p, Mη)
    on the normalised input ``(u − u_offset)/u_scale`` and the output offset ``y_offset`` (the
    output at the equilibrium x = 0 of the mean input, estimated): an internal normalisation,
    not a linear model's operating point, so arrays given to :meth:`simulate` and
    :meth:`compare` are the record's values, as a Trajectory's columns;
    ``exz``/``exe``: the exponent tables of ζ and η; ``dirs``: the free entries (kind 0 … 5 for
    A … F, row, column) in the order of ``covariance``; ``x0``: the initial state of the
    estimation record; fits in % per output (None where the free run diverged)."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    E: np.ndarray
    F: np.ndarray
    exz: np.ndarray
    exe: np.ndarray
    u_offset: np.ndarray
    u_scale: np.ndarray
    y_offset: np.ndarray
    dirs: np.ndarray
    covariance: np.ndarray
    x0: np.ndarray
    state_limit: float
    dt: float = 1.0
    degree: int = 2
    feedthrough: bool = False
    input_names: tuple = ("u",)
    output_names: tuple = ("y",)
    input_units: tuple = ("1",)
    output_units: tuple = ("1",)
    fit_percent: list | None = None
    validation_fit_percent: list | None = None
    linear_fit_percent: list | None = None
    linear_validation_fit_percent: list | None = None
    criterion: str = ""
    info: dict = field(default_factory=dict)

    structure = "nlss"
    fit_definition = NLSS_FIT
    _file_what = "NLSS model"
    _family = "a nonlinear state-space model"
    _signal_arrays = False  # arrays in, (N, p) out, as the linear state-space models

    # ----------------------------------------------------------------- protocol
    @property
    def inputs(self) -> tuple[str, ...]:
        return tuple(self.input_names)

    @property
    def outputs(self) -> tuple[str, ...]:
        return tuple(self.output_names)

    @property
    def order(self) -> int:
        return int(self.A.shape[0])

    @property
    def zeta_terms(self) -> list[str]:
        return [_monomial_name(e, self.order) for e in self.exz]

    @property
    def eta_terms(self) -> list[str]:
        return [_monomial_name(e, self.order) for e in self.exe]

    @property
    def theta_std(self) -> np.ndarray:
        return np.sqrt(np.maximum(np.diag(self.covariance), 0.0))

    def _entry_name(self, kind: int, r: int, c: int) -> str:
        return f"{_KIND[kind]}_{r + 1}_{c + 1}"

    @property
    def parameters(self):
        """Every entry of A, B, C, (D), E, F as a :class:`~gripkit.params.ParameterSet`: the free
        ones with their σ (in the model's state basis, see the module docstring), the n² entries
        that fix the basis marked ``fixed``. Units: the output's unit for C, D, F (per normalised
        state/input), 1 for A, B, E."""
        std = dict(zip(map(tuple, self.dirs.tolist()), self.theta_std.tolist()))
        n = self.order
        params = []
        mats = [self.A, self.B, self.C, self.D, self.E, self.F]
        for kind, M in enumerate(mats):
            if kind == 3 and not self.feedthrough:
                continue
            for r in range(M.shape[0]):
                unit = self.output_units[r] if kind in (2, 3, 5) else "1"
                for c in range(M.shape[1]):
                    if kind == 4:
                        what = f"coefficient of {_monomial_name(self.exz[c], n)} in state {r + 1}"
                    elif kind == 5:
                        what = f"coefficient of {_monomial_name(self.exe[c], n)} in output {r + 1}"
                    else:
                        what = (f"entry ({r + 1}, {c + 1}) of {_KIND[kind]} (normalised states "
                                "and inputs)")
                    key = (kind, r, c)
                    params.append(Parameter(self._entry_name(kind, r, c), float(M[r, c]),
                                            unit or "1", what, fixed=key not in std,
                                            std=std.get(key), source="identified (nlss)"))
        for r in range(len(self.output_names)):
            key = (6, r, 0)
            params.append(Parameter(f"y0_{r + 1}", float(self.y_offset[r]),
                                    self.output_units[r] or "1",
                                    f"output {r + 1} at the equilibrium x = 0, u = mean input",
                                    fixed=key not in std, std=std.get(key),
                                    source="identified (nlss)"))
        return ParameterSet(params, name=f"NLSS order {n} degree {self.degree}")

    def _inputs_of(self, data, what: str) -> np.ndarray:
        """Normalised input (N, m) from a Trajectory (columns by name) or an array."""
        m = len(self.input_names)
        if isinstance(data, Trajectory):
            self._check_rate(data, f"nlss.{what}")
            u = _trajectory_columns(data, self.input_names, "input", what, self.input_units)
        else:
            u = np.asarray(data, dtype=np.float64)
            if u.ndim == 1:
                u = u[:, None]
            if u.ndim != 2 or u.shape[1] != m:
                raise DataError(f"nlss.{what}: expected the input as shape (N, {m}), found shape "
                                f"{np.shape(data)}")
        if not np.all(np.isfinite(u)):
            raise DataError(f"nlss.{what}: the input has {int(np.sum(~np.isfinite(u)))} "
                            "non-finite samples; remove or interpolate them first")
        return np.ascontiguousarray((u - self.u_offset) / self.u_scale)

    def _outputs_of(self, data, y, n: int, what: str) -> np.ndarray:
        """Output (N, p) from a Trajectory (columns by name) or the array ``y``."""
        p = len(self.output_names)
        if y is None:
            if not isinstance(data, Trajectory):
                raise ArgumentError(f"nlss.{what}: give the measured output: {what}(trajectory) "
                                    f"or {what}(u, y)")
            y = _trajectory_columns(data, self.output_names, "output", what, self.output_units)
        y = np.asarray(y, dtype=np.float64)
        if y.ndim == 1:
            y = y[:, None]
        if y.ndim != 2 or y.shape != (n, p):
            raise DataError(f"nlss.{what}: expected the output as shape ({n}, {p}), found "
                            f"{np.shape(y)}")
        if not np.all(np.isfinite(y)):
            raise DataError(f"nlss.{what}: the output has {int(np.sum(~np.isfinite(y)))} "
                            "non-finite samples; remove or interpolate them first")
        return np.ascontiguousarray(y)

    def _run(self, ut, x0):
        N = ut.shape[0]
        Y = np.empty((N, len(self.output_names)))
        at = K.simulate_kernel(_arrays(self), np.asarray(x0, dtype=np.float64), ut, Y,
                               np.empty((0, self.order)), self.state_limit)
        return Y, at

    def simulate(self, data, x0=None, *, std: bool = False, warn: bool = True):
        """Free run on the input of ``data`` (a Trajectory with the input columns by name, or an
        array (N,) / (N, m) of the record's values: ``u_offset`` is removed inside) from ``x0``
        (default 0: rest at the mean estimation input) → (N, p), the record's values.
        ``std=True`` also returns σ of the simulated output (N, p): the parameter covariance
        propagated through the free run's sensitivities (linearised, x0 held). A run whose state
        leaves the range of the estimation states by 1000× ends in NaN after a
        StabilityWarning."""
        ut = self._inputs_of(data, "simulate")
        x0 = np.zeros(self.order) if x0 is None else np.asarray(x0, dtype=np.float64).ravel()
        if x0.shape != (self.order,):
            raise ArgumentError(f"nlss.simulate: x0 must have {self.order} entries, found "
                                f"shape {x0.shape}")
        Y, at = self._run(ut, x0)
        if at >= 0 and warn:
            emit_warning(f"nlss: the free run diverges at sample {at} (a state beyond "
                         f"{DIVERGENCE_FACTOR:g}× the estimation range); the model is unstable on "
                         "this input", StabilityWarning)
        if not std:
            return Y
        var = np.full(Y.shape, np.nan)
        if at < 0 and self.dirs.shape[0]:
            w, V = np.linalg.eigh(0.5 * (self.covariance + self.covariance.T))
            L = np.ascontiguousarray(V * np.sqrt(np.maximum(w, 0.0)))
            K.output_variance(_arrays(self), self.dirs, x0, ut, L, var)
        return Y, np.sqrt(var)

    def estimate_x0(self, data, y=None, *, max_iterations: int = 30) -> np.ndarray:
        """Initial state minimising the free run's squared error on the record (Gauss-Newton,
        started from the least-squares x0 of the linear part)."""
        ut = self._inputs_of(data, "estimate_x0")
        yy = self._outputs_of(data, y, ut.shape[0], "estimate_x0")
        return self._x0(ut, yy, max_iterations)

    def _x0(self, ut, y, max_iterations):
        p = y.shape[1]
        w = np.ones(p) / np.maximum(y.std(axis=0), 1e-300)
        starts = np.array([0, ut.shape[0]], dtype=np.int64)
        lin = replace(self, E=np.zeros_like(self.E), F=np.zeros_like(self.F))
        Z = np.zeros((1, self.order))
        Z, _ = _lm(lin, np.zeros((0, 3), dtype=np.int64), Z, starts, ut, y, w, 1, None)
        Z, _ = _lm(self, np.zeros((0, 3), dtype=np.int64), Z, starts, ut, y, w,
                   max_iterations, None)
        return Z[0].copy()

    def compare(self, data, y=None, *, warn: bool = True) -> ModelFit:
        """Fit (%) per output of the free run from the estimated initial state
        (:attr:`fit_definition`) on a Trajectory with the model's columns, or on arrays
        ``compare(u, y)`` of the record's values (the offsets normalise inside the model, as for
        a Trajectory); None for an output whose free run diverged (with a StabilityWarning)."""
        ut = self._inputs_of(data, "compare")
        yy = self._outputs_of(data, y, ut.shape[0], "compare")
        x0 = self._x0(ut, yy, 30)
        Y, at = self._run(ut, x0)
        if at >= 0:
            if warn:
                emit_warning(f"nlss: the free run diverges at sample {at} of {ut.shape[0]} (a "
                             f"state beyond {DIVERGENCE_FACTOR:g}× the estimation range); no fit "
                             "is reported", StabilityWarning)
            fit = [None] * yy.shape[1]
        else:
            fit = _fits(yy, Y)
        return ModelFit(self.outputs, fit, Y, NLSS_FIT)

    def _measured(self, data, y) -> np.ndarray:
        """The record's outputs (N, p), as :meth:`compare` reads them (for ``residuals``)."""
        n = self._inputs_of(data, "residuals").shape[0]
        return self._outputs_of(data, y, n, "residuals")

    # ----------------------------------------------------------------- file
    def to_dict(self) -> dict:
        arr = lambda M: np.asarray(M).tolist()  # noqa: E731
        return dict(schema=SCHEMA, version=VERSION, structure="nlss", order=self.order,
                    degree=self.degree, feedthrough=self.feedthrough, dt=self.dt,
                    inputs=list(self.input_names), outputs=list(self.output_names),
                    input_units=list(self.input_units), output_units=list(self.output_units),
                    A=arr(self.A), B=arr(self.B), C=arr(self.C), D=arr(self.D), E=arr(self.E),
                    F=arr(self.F), zeta_exponents=arr(self.exz), eta_exponents=arr(self.exe),
                    zeta_terms=self.zeta_terms, eta_terms=self.eta_terms,
                    u_offset=arr(self.u_offset), u_scale=arr(self.u_scale),
                    y_offset=arr(self.y_offset), free=arr(self.dirs),
                    covariance=arr(self.covariance), x0=arr(self.x0),
                    state_limit=self.state_limit, fit_percent=self.fit_percent,
                    validation_fit_percent=self.validation_fit_percent,
                    linear_fit_percent=self.linear_fit_percent,
                    linear_validation_fit_percent=self.linear_validation_fit_percent,
                    criterion=self.criterion, fit_definition=NLSS_FIT,
                    info={k: v for k, v in self.info.items()
                          if isinstance(v, (int, float, str, bool, type(None)))})


def load_nlss(path) -> NLSSModel:
    """Read a model written by :meth:`NLSSModel.save`; any other schema is refused."""
    p = Path(path)
    writer = "NLSSModel.save or `gripkit identify nlss --out`"
    doc = read_family_document(p, SCHEMA, VERSION, family="nlss", writer=writer)
    check_family_fields(doc, f"nlss model file {str(p)!r}", writer,
                        numbers={"dt": SAMPLE_TIME, "order": Domain(1, integer=True),
                                 "degree": Domain(1, integer=True),
                                 "state_limit": Domain(0.0, strict=True)},
                        finite=("A", "B", "C", "D", "E", "F", "u_offset", "u_scale", "y_offset",
                                "x0"),
                        units=("input_units", "output_units"))
    try:
        n, m, p_ = int(doc["order"]), len(doc["inputs"]), len(doc["outputs"])
        f64 = lambda k, *shape: np.array(doc[k], dtype=np.float64).reshape(shape)  # noqa: E731
        exz = np.array(doc["zeta_exponents"], dtype=np.int64).reshape(-1, n + m)
        exe = np.array(doc["eta_exponents"], dtype=np.int64).reshape(-1, n + m)
        dirs = np.array(doc["free"], dtype=np.int64).reshape(-1, 3)
        P = dirs.shape[0]
        model = NLSSModel(
            A=f64("A", n, n), B=f64("B", n, m), C=f64("C", p_, n), D=f64("D", p_, m),
            E=f64("E", n, exz.shape[0]), F=f64("F", p_, exe.shape[0]), exz=exz, exe=exe,
            u_offset=f64("u_offset", m), u_scale=f64("u_scale", m), y_offset=f64("y_offset", p_),
            dirs=dirs, covariance=f64("covariance", P, P), x0=f64("x0", n),
            state_limit=float(doc["state_limit"]), dt=float(doc["dt"]),
            degree=int(doc["degree"]), feedthrough=bool(doc["feedthrough"]),
            input_names=tuple(str(s) for s in doc["inputs"]),
            output_names=tuple(str(s) for s in doc["outputs"]),
            input_units=tuple(str(s) for s in doc["input_units"]),
            output_units=tuple(str(s) for s in doc["output_units"]),
            fit_percent=doc.get("fit_percent"),
            validation_fit_percent=doc.get("validation_fit_percent"),
            linear_fit_percent=doc.get("linear_fit_percent"),
            linear_validation_fit_percent=doc.get("linear_validation_fit_percent"),
            criterion=str(doc.get("criterion", "")), info=dict(doc.get("info") or {}),
            **file_provenance(doc))
    except (KeyError, TypeError, ValueError, AttributeError) as exc:
        raise ModelError(f"{str(p)!r}: a malformed {SCHEMA} ({type(exc).__name__}: {exc}); "
                         "write it again with NLSSModel.save") from None
    lims = np.array([n, m, n, m, exz.shape[0], exe.shape[0], 1])
    rows_ = np.array([n, n, p_, p_, n, p_, p_])
    if P and ((dirs[:, 0] < 0).any() or (dirs[:, 0] > 6).any() or (dirs[:, 1:] < 0).any()
              or (dirs[:, 2] >= lims[np.clip(dirs[:, 0], 0, 6)]).any()
              or (dirs[:, 1] >= rows_[np.clip(dirs[:, 0], 0, 6)]).any()
              or (exz < 0).any() or (exe < 0).any() or not np.all(model.u_scale > 0)):
        raise ModelError(f"{str(p)!r}: a free entry names a missing matrix entry, or an exponent "
                         "or input scale is out of range; write it again with NLSSModel.save")
    return model


# --------------------------------------------------------------------- estimation
def _apply(model: NLSSModel, dirs, delta) -> NLSSModel:
    mats = [model.A.copy(), model.B.copy(), model.C.copy(), model.D.copy(), model.E.copy(),
            model.F.copy(), model.y_offset.copy()[:, None]]
    for (kind, r, c), d in zip(dirs, delta):
        mats[kind][r, c] += d
    return replace(model, A=mats[0], B=mats[1], C=mats[2], D=mats[3], E=mats[4], F=mats[5],
                   y_offset=mats[6][:, 0].copy())


def _arrays(model) -> K.NLSSArrays:
    """The model's arrays as the kernels take them (a :data:`.nlss_kernels.NLSSArrays`)."""
    return K.NLSSArrays(model.A, model.B, model.C, model.D, model.E, model.F, model.y_offset,
                        model.exz, model.exe)


def _loss(model, Z, starts, u, y, w) -> float:
    return K.window_loss(_arrays(model), K.NLSSWindows(Z, starts, u, y, w), model.state_limit)


def _gram(model, dirs, Z, starts, u, y, w):
    P, n, W = dirs.shape[0], model.order, starts.shape[0] - 1
    Htt, gt = np.empty((P, P)), np.empty(P)
    Htz, Hzz, gz = np.empty((W, P, n)), np.empty((W, n, n)), np.empty((W, n))
    V = K.window_gram(_arrays(model), dirs, K.NLSSWindows(Z, starts, u, y, w),
                      model.state_limit, K.NLSSGram(Htt, gt, Htz, Hzz, gz))
    return V, Htt, gt, Htz, Hzz, gz


def _schur_step(Htt, gt, Htz, Hzz, gz, lam):
    """The damped Gauss-Newton step (H + λ diag H) δ = g with the initial-state blocks of the
    windows eliminated (block-arrow H: each window's x0 couples only with θ). Solved in the
    coordinates scaled by diag(H)^½ (the parameters' scales differ by orders of magnitude), where
    the damping is λ I."""
    n = Hzz.shape[1]
    st = np.sqrt(np.maximum(np.diag(Htt), 1e-300))
    sz = np.sqrt(np.maximum(np.einsum("wii->wi", Hzz), 1e-300))              # (W, n)
    Hts = Htt / np.outer(st, st)
    Htzs = Htz / st[None, :, None] / sz[:, None, :]
    Hzzs = Hzz / sz[:, :, None] / sz[:, None, :] + lam * np.eye(n)
    gts, gzs = gt / st, gz / sz
    Hzi_gz = np.linalg.solve(Hzzs, gzs[:, :, None])[:, :, 0]
    if st.size:
        Hzi_Hzt = np.linalg.solve(Hzzs, np.transpose(Htzs, (0, 2, 1)))        # (W, n, P)
        R = Hts + lam * np.eye(st.size) - np.einsum("wpn,wnq->pq", Htzs, Hzi_Hzt)
        r = gts - np.einsum("wpn,wn->p", Htzs, Hzi_gz)
        dth = sla.solve(0.5 * (R + R.T), r, assume_a="sym")
        dz = Hzi_gz - np.einsum("wnp,p->wn", Hzi_Hzt, dth)
    else:
        dth, dz = np.zeros(0), Hzi_gz
    return dth / st, dz / sz


def _lm(model, dirs, Z, starts, u, y, w, max_iterations, bar, tol=1e-7, stall=_STALL,
        bounded=None):
    """Levenberg-Marquardt on the windowed simulation error; returns (Z, model) when ``dirs`` is
    empty (initial states only), else (model, Z, loss, iterations, converged). It stops after a
    step that lowered the criterion by less than ``tol`` (relative) or than a negligible part of
    the noise variance, or when :data:`_STALL_SPAN` steps lowered it by less than ``stall``
    (relative): each iteration is a pass of the sensitivity kernel over the record.
    ``bounded(model, Z)``: a step is taken only where it is true as well."""
    V, Htt, gt, Htz, Hzz, gz = _gram(model, dirs, Z, starts, u, y, w)
    if not np.isfinite(V):
        if dirs.shape[0] == 0:
            return Z, model
        return model, Z, V, 0, False
    dof = max(y.size - dirs.shape[0] - Z.size, 1)
    lam, it, converged = 1e-3, 0, False
    history = [V]
    for it in range(1, max_iterations + 1):
        improved, drop = False, 0.0
        for _ in range(25):
            try:
                dth, dz = _schur_step(Htt, gt, Htz, Hzz, gz, lam)
            except (np.linalg.LinAlgError, ValueError):
                lam *= 10
                continue
            cand = _apply(model, dirs, dth) if dirs.shape[0] else model
            Zn = Z + dz
            Vn = _loss(cand, Zn, starts, u, y, w)
            if np.isfinite(Vn) and Vn < V and (bounded is None or bounded(cand, Zn)):
                improved, drop = True, V - Vn
                model, Z = cand, Zn
                lam = max(lam / 5, 1e-12)
                break
            lam *= 10
        if bar is not None:
            bar()
        if not improved:
            converged = True
            break
        rel = drop / max(V, 1e-300)
        V -= drop
        history.append(V)
        stalled = it >= _STALL_SPAN and V > (1.0 - stall) * history[-1 - _STALL_SPAN]
        if rel < tol or drop < _NEGLIGIBLE_DROP * V / dof or stalled:
            converged = True
            break
        if it < max_iterations:
            V, Htt, gt, Htz, Hzz, gz = _gram(model, dirs, Z, starts, u, y, w)
    for _ in range(max_iterations - it if bar is not None else 0):
        bar()  # a stage that stops early completes its share of the progress bar
    if dirs.shape[0] == 0:
        return Z, model
    return model, Z, V, it, converged


def _free_linear_entries(A, B, C, D, feedthrough: bool) -> np.ndarray:
    """(kind, row, column) of the entries of A, B, C (and D) left free: the d that complement the
    similarity orbit best at (A, B, C) (pivoted QR of a basis of its orthogonal complement, as
    :func:`gripkit.sysid.linear.pem_ss._directions`); the other n² entries fix the state basis."""
    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    blocks = [n * n, n * m, p * n, p * m if feedthrough else 0]
    T = np.empty((sum(blocks), n * n))
    for a in range(n):
        for b in range(n):
            X = np.zeros((n, n))
            X[a, b] = 1.0
            parts = [X @ A - A @ X, X @ B, -C @ X] + ([np.zeros((p, m))] if feedthrough else [])
            T[:, a * n + b] = np.concatenate([q.ravel() for q in parts])
    U, sv, _ = np.linalg.svd(T, full_matrices=True)
    rank = int(np.sum(sv > 1e-10 * max(sv[0], 1e-300))) if sv.size else 0
    Qp = U[:, rank:]
    d = Qp.shape[1]
    piv = np.sort(sla.qr(Qp.T, pivoting=True, mode="r")[1][:d])
    shapes = [(n, n), (n, m), (p, n), (p, m)]
    starts = np.cumsum([0] + blocks)
    out = np.empty((d, 3), dtype=np.int64)
    for q, g in enumerate(piv):
        kind = int(np.searchsorted(starts, g, side="right") - 1)
        r, c = divmod(int(g - starts[kind]), shapes[kind][1])
        out[q] = (kind, r, c)
    return out


def _columns(spec, what: str) -> list[str]:
    if isinstance(spec, str):
        cols = [c.strip() for c in spec.split(",")]
    elif isinstance(spec, (list, tuple)) and all(isinstance(c, str) for c in spec):
        cols = [c.strip() for c in spec]
    else:
        raise ArgumentError(f"nlss: {what} must name the column(s) (str 'a,b' or a list), found "
                            f"{spec!r:.60}")
    if not cols or any(not c for c in cols):
        raise ArgumentError(f"nlss: {what} {spec!r}: an empty column name; give 'a' or 'a,b'")
    return cols


def _io(data, input, output, what: str):
    """(u (N, m), y (N, p), dt, input names, output names, input units, output units)."""
    if isinstance(data, Trajectory):
        if input is None or output is None:
            raise ArgumentError(f"nlss: {what} is a Trajectory: name its columns with input= and "
                                f"output= (it has {', '.join(map(repr, data.names))})")
        ins, outs = _columns(input, "input"), _columns(output, "output")
        both = set(ins) & set(outs)
        if both:
            raise DataError(f"nlss: column(s) {', '.join(map(repr, sorted(both)))} named as both "
                            "input and output; a column is one or the other")
        missing = [c for c in ins + outs if c not in data.names]
        if missing:
            raise DataError(f"nlss: {what} has no column(s) {', '.join(map(repr, missing))}; it "
                            f"has {', '.join(map(repr, data.names))}")
        dt = float(f"{data.require_uniform(why='NLSS identification'):.9g}")
        u = np.column_stack([np.asarray(data[c], dtype=np.float64) for c in ins])
        y = np.column_stack([np.asarray(data[c], dtype=np.float64) for c in outs])
        return (u, y, dt, tuple(ins), tuple(outs), tuple(data.unit(c) or "1" for c in ins),
                tuple(data.unit(c) or "1" for c in outs))
    try:
        u, y = data
    except (TypeError, ValueError):
        raise ArgumentError(f"nlss: {what} must be a Trajectory or a pair (u, y) of arrays, "
                            f"found {type(data).__name__}") from None
    u, y = real_array(u, f"nlss: {what}: u"), real_array(y, f"nlss: {what}: y")
    u = u[:, None] if u.ndim == 1 else u
    y = y[:, None] if y.ndim == 1 else y
    check_not_transposed(u, f"nlss: {what}: u")
    check_not_transposed(y, f"nlss: {what}: y")
    if u.ndim != 2 or y.ndim != 2:
        raise DataError(f"nlss: {what}: u and y must be arrays (N,) or (N, k), found shapes "
                        f"{u.shape} and {y.shape}")
    if u.size == 0 or y.size == 0:
        raise DataError(f"nlss: {what}: the signals hold no samples (u {u.shape}, y {y.shape})")
    m, p = u.shape[1], y.shape[1]
    ins = tuple(_columns(input, "input")) if input is not None else \
        tuple(f"u{i + 1}" if m > 1 else "u" for i in range(m))
    outs = tuple(_columns(output, "output")) if output is not None else \
        tuple(f"y{i + 1}" if p > 1 else "y" for i in range(p))
    if len(ins) != m or len(outs) != p:
        raise ArgumentError(f"nlss: {len(ins)} input and {len(outs)} output name(s) for "
                            f"{m} input and {p} output column(s)")
    return u, y, None, ins, outs, ("1",) * m, ("1",) * p


def _check_signals(u, y, what: str):
    if u.shape[0] != y.shape[0]:
        raise DataError(f"nlss: {what}: u has {u.shape[0]} samples but y has {y.shape[0]}; pass "
                        "a pair of equal length")
    for name, a in (("input", u), ("output", y)):
        bad = int(np.sum(~np.isfinite(a)))
        if bad:
            raise DataError(f"nlss: {what}: the {name} has {bad} non-finite samples; remove or "
                            "interpolate them first")


def _positive_int(v, name: str, lo: int = 1) -> int:
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < lo:
        raise ArgumentError(f"nlss: {name} must be an integer ≥ {lo}, found {v!r}")
    return int(v)


def _is_records(data) -> bool:
    """``data`` is a list of records (Trajectories or pairs ``(u, y)``), not one pair."""
    if not isinstance(data, (list, tuple)) or not data:
        return False
    if any(isinstance(d, Trajectory) for d in data):
        return True
    return all(isinstance(d, (list, tuple)) and len(d) == 2 for d in data)


def _io_records(data, input, output):
    """Several records → (list of (u, y), dt, names and units of data[0]); each record read and
    checked as one is, named ``data[i]``; all with the same columns, sampling and units."""
    recs, first = [], None
    for i, d in enumerate(data):
        u, y, dt, ins, outs, iu, ou = _io(d, input, output, f"data[{i}]")
        _check_signals(u, y, f"data[{i}]")
        if first is None:
            first = (dt, ins, outs, iu, ou)
        else:
            dt0, ins0, outs0, iu0, ou0 = first
            if u.shape[1] != len(ins0) or y.shape[1] != len(outs0):
                raise DataError(f"nlss: data[{i}] has {u.shape[1]} input(s) and {y.shape[1]} "
                                f"output(s), data[0] {len(ins0)} and {len(outs0)}: the records "
                                "of one fit must have the same columns")
            if (dt is None) != (dt0 is None) or (dt is not None and abs(dt - dt0) > 1e-9 * dt0):
                rate = lambda h: "an unknown rate" if h is None else f"{1 / h:g} Hz"  # noqa: E731
                raise DataError(f"nlss: data[{i}] is sampled at {rate(dt)}, data[0] at "
                                f"{rate(dt0)}: the records of one fit must share the sample "
                                "interval", hint="resample one of them")
            for col, a, b in zip(ins0 + outs0, iu0 + ou0, iu + ou):
                if a != b:
                    raise DataError(f"nlss: data[{i}]: column {col!r} is in {b!r}, in data[0] in "
                                    f"{a!r}: the records of one fit must use the same units",
                                    hint="convert one of them")
        recs.append((u, y))
    return (recs, *first)


def _read_data(data, input, output):
    """The estimation records → (records [(u, y)], u and y stacked, dt of the data or None,
    names (inputs, outputs, input units, output units), the records' first rows and the end)."""
    if _is_records(data):
        recs, tr_dt, ins, outs, iunits, ounits = _io_records(data, input, output)
        u, y = np.vstack([r[0] for r in recs]), np.vstack([r[1] for r in recs])
    else:
        u, y, tr_dt, ins, outs, iunits, ounits = _io(data, input, output, "data")
        _check_signals(u, y, "data")
        recs = [(u, y)]
    bounds = np.cumsum([0] + [len(r[0]) for r in recs]).astype(np.int64)
    return recs, u, y, tr_dt, (ins, outs, iunits, ounits), bounds


def _sample_interval(dt, tr_dt) -> float:
    """``dt`` as given, else the data's, else 1; a given one must be positive and finite."""
    if dt is None:
        return 1.0 if tr_dt is None else tr_dt
    if not (isinstance(dt, (int, float, np.floating)) and not isinstance(dt, bool)
            and math.isfinite(dt) and dt > 0):
        raise ArgumentError(f"nlss: dt must be a positive sample interval in s, found {dt!r}")
    return dt


def _check_excited(u, y, ins, outs) -> np.ndarray:
    """σ of each input; raises for a constant input or output."""
    sd_u = u.std(axis=0)
    if np.any(sd_u == 0):
        raise DataError(f"nlss: input {ins[int(np.argmin(sd_u))]!r} is constant; it excites "
                        "nothing: check the input column")
    const = [outs[i] for i in range(y.shape[1]) if np.ptp(y[:, i]) == 0]
    if const:
        raise DataError(f"nlss: output {const[0]!r} is constant ({y[0, outs.index(const[0])]:g} "
                        "throughout); there is nothing to identify: check the output column")
    return sd_u


def _read_validation(validate, input, output, m: int, p: int):
    """The validation record (u, y), or None."""
    if validate is None:
        return None
    uv, yv, *_ = _io(validate, input, output, "validate")
    _check_signals(uv, yv, "validate")
    if uv.shape[1] != m or yv.shape[1] != p:
        raise DataError(f"nlss: validate has {uv.shape[1]} input(s) and {yv.shape[1]} "
                        f"output(s), the data {m} and {p}")
    return uv, yv


def _linear_start(ut, yr, n, dt, feedthrough):
    """The subspace model of order n of one record (normalised input, output less its mean),
    and the distinct warnings it raised → (model, notes), or None."""
    N = ut.shape[0]
    with warnings.catch_warnings(record=True) as caught:  # the start, not the result
        warnings.simplefilter("always")
        lm = None
        # n4sid's least squares for B and x0 overflows on a long record when the
        # shift-invariance A of an over-large order is unstable (LinAlgError): the start is
        # then taken from a shorter head of the record
        for cut in (N, *(c for c in (4000, 2000, 1000, 500, 250) if c < N)):
            try:
                lm = n4sid(ut[:cut], yr[:cut], n, dt=dt, feedthrough=feedthrough)
                break
            except np.linalg.LinAlgError:
                continue
    notes = list(dict.fromkeys(str(c.message) for c in caught))
    return None if lm is None else (lm, notes)


def _linear_start_records(ut, yr, bounds, n, dt, feedthrough):
    """One subspace model of order n of all records, one x0 each → (model, notes), or None."""
    with warnings.catch_warnings(record=True) as caught:  # the start, not the result
        warnings.simplefilter("always")
        try:
            lm = n4sid_records([(ut[a:b], yr[a:b]) for a, b in
                                zip(bounds[:-1], bounds[1:])], n, dt=dt,
                               feedthrough=feedthrough)
        except np.linalg.LinAlgError:
            return None
    notes = list(dict.fromkeys(str(c.message) for c in caught))
    return lm, notes


def _gap_order(ut, yr, bounds, max_order: int, n_par) -> int:
    """The order at the largest gap s_n/s_(n+1) among the first ``max_order`` subspace singular
    values (of the records' stacked Hankel matrices for several), lowered until the data hold
    4 samples per parameter (``n_par(n)`` parameters at order n)."""
    N, p = yr.shape
    if len(bounds) > 2:
        sv = RecordsFactor([(ut[a:b], yr[a:b]) for a, b in zip(bounds[:-1], bounds[1:])],
                           default_horizon(max_order, p), "n4sid").s
    else:
        sv = subspace_factor(ut, yr, horizon=default_horizon(max_order, p), method="n4sid").s
    k = min(max_order, sv.size - 1)
    n_sv = int(np.argmax(sv[:k] / np.maximum(sv[1:k + 1], 1e-300 * sv[0]))) + 1
    while n_sv > 1 and N * p < 4 * n_par(n_sv):  # no more parameters than data allow
        n_sv -= 1
    return n_sv


def _score(mdl, val, yc, ut, bounds, x0s) -> float:
    """How well the candidate ``mdl`` does (higher is better): its mean free-run validation fit
    with ``val``, else −BIC of the estimation free run (kept in ``info['bic']``)."""
    if val is not None:
        fit = mdl.compare(val[0], val[1], warn=False)
        mdl.validation_fit_percent = fit.fit_percent
        lf = mdl.info.pop("_linear")
        mdl.linear_validation_fit_percent = lf.compare(val[0], val[1], warn=False).fit_percent
        return -np.inf if None in fit.fit_percent else float(np.mean(fit.fit_percent))
    # Bayesian information criterion of the estimation free run
    mdl.info.pop("_linear")
    N = yc.shape[0]
    k = mdl.dirs.shape[0] + mdl.order
    if mdl.fit_percent is None:
        score = -np.inf
    else:
        e = yc - _run_records(mdl, ut, bounds, x0s)[0]
        score = -(N * float(np.sum(np.log(np.maximum(np.mean(e * e, axis=0), 1e-300))))
                  + k * math.log(N))
    mdl.info["bic"] = None if not np.isfinite(score) else -score
    return score


def _criterion(model, order, candidates, max_order, val, ins, levels, degree) -> str:
    """How the order was chosen, and the inputs whose high powers were left out."""
    how = (f"order {model.order} given" if order is not None else
           f"order {model.order} by the information criterion (BIC) among {candidates}, the "
           f"largest gap of the subspace singular values (at most {max_order}) and the next"
           if val is None else
           f"order {model.order} by the free-run validation fit among {candidates}")
    few = [f"{ins[j]!r} takes {levels[j]} values" for j in range(len(levels))
           if levels[j] <= degree]
    if few:
        how += (f"; {', '.join(few)}: its powers of that degree and above are no new functions "
                "of it and are left out")
    return how


def _warn_of_result(model, val) -> None:
    """Warnings about the model returned: an ill-conditioned Hessian, a diverging validation
    run."""
    cond = model.info["hessian_condition"]
    if not cond < _ILL_CONDITIONED:  # said of the model returned, not of the candidates
        emit_warning(f"nlss: the Gauss-Newton Hessian at the optimum is ill-conditioned (condition "
                     f"number {cond:.2g} after scaling): some combinations of parameters are not "
                     "determined by the data and their σ are not reliable; lower the degree or the "
                     "order, or excite the system more richly", AccuracyWarning)
    if val is not None and None in (model.validation_fit_percent or []):
        emit_warning("nlss: the free run of the identified model diverges on the validation "
                     "record; no validation fit is reported", StabilityWarning)


def nlss(data, *, input=None, output=None, order: int | None = None, degree: int = 3,
         validate=None, dt: float | None = None, window: int | None = None, max_order: int = 4,
         feedthrough: bool = False, max_iterations: int = 100, progress: bool = True) -> NLSSModel:
    """Polynomial nonlinear state-space model (PNLSS, module docstring) of a record.

    ``data``: a :class:`~gripkit.signals.Trajectory` with ``input``/``output`` naming its
    columns (``'a,b'`` or a list for several), or a pair ``(u, y)`` of arrays (N,) or (N, k);
    or a list of them: several records of one system fitted by one model, each record with its
    own initial state (estimated), one operating point (the means of all records), the linear
    start from :func:`gripkit.sysid.linear.subspace.n4sid_records`, the windows of stage 2 inside
    the records (never across a seam), stage 3 with one window per record, σ from all of them
    (the first-8000-samples warm start of one long record is not used);
    ``fit_percent`` over all records, each one's in ``info['records']``.
    ``order``: states (default: n at the largest gap s_n/s_(n+1) among the first ``max_order``
    subspace singular values and n + 1 are fitted, and the one of lower BIC = N Σᵢ ln σ̂ᵢ² +
    k ln N is kept (σ̂ᵢ² the mean squared free-run error of output i, k the free parameters and
    the initial state); with ``validate``, the best free-run validation fit among n and its two
    neighbours). ``degree``: highest degree of the monomials (≥ 2).
    ``validate``: a second record like ``data``. ``window``: samples per truncated simulation
    window of stage 2 (default 10 linear time constants, ≥ 50, ≤ 200 windows).
    ``feedthrough``: estimate D and the input monomials of the output equation.
    ``max_iterations``: Levenberg-Marquardt iterations per stage. ``progress``: a progress bar
    on stderr.
    """
    recs, u, y, tr_dt, names, bounds = _read_data(data, input, output)
    ins, outs, iunits, ounits = names
    check_scale(ins, u, "input", "NLSS identification")
    check_scale(outs, y, "output", "NLSS identification")
    several = len(recs) > 1
    N, m = u.shape
    p = y.shape[1]
    degree = _positive_int(degree, "degree", 2)
    max_order = _positive_int(max_order, "max_order")
    max_iterations = _positive_int(max_iterations, "max_iterations")
    if order is not None:
        order = _positive_int(order, "order")
    if window is not None:
        window = _positive_int(window, "window", 10)
    dt = _sample_interval(dt, tr_dt)
    sd_u = _check_excited(u, y, ins, outs)
    val = _read_validation(validate, input, output, m, p)
    levels = [min(len(np.unique(u[:, j])), degree + 1) for j in range(m)]
    n_par = lambda n: (n + p) * (n + m + len(monomial_exponents(  # noqa: E731
        n, m, degree, input_levels=levels)))
    if order is not None and N * p < 4 * n_par(order):
        raise DataError(f"nlss: {N} samples for about {n_par(order)} parameters (order {order}, "
                        f"degree {degree}); need at least {4 * n_par(order) // p}: lower the "
                        "order or degree, or give more data")
    t0 = time.perf_counter()
    u_off, y_off = u.mean(axis=0), y.mean(axis=0)
    ut = np.ascontiguousarray((u - u_off) / sd_u)
    yc = np.ascontiguousarray(y)
    yr = y - y_off
    n_sv = order if order is not None else _gap_order(ut, yr, bounds, max_order, n_par)
    around = (n_sv, n_sv + 1) if val is None else (n_sv, n_sv - 1, n_sv + 1)
    candidates = [n_sv] if order is not None else \
        [k for k in around if 1 <= k <= max_order and (k == n_sv or N * p >= 4 * n_par(k))]
    best = None
    for n in candidates:
        start = (_linear_start_records(ut, yr, bounds, n, dt, feedthrough) if several
                 else _linear_start(ut, yr, n, dt, feedthrough))
        if start is None:
            continue
        lin_n, notes = start
        x0s = [r["x0"] for r in lin_n.info["records"]] if several else None
        mdl = _fit_order(lin_n, ut, yc, u_off, sd_u, y_off, degree, feedthrough, window,
                         max_iterations, progress, dt, ins, outs, iunits, ounits, levels,
                         bounds, x0s)
        x0s = mdl.info.pop("_x0s", [mdl.x0])
        if notes:
            mdl.info["linear_start"] = " | ".join(notes)
        score = _score(mdl, val, yc, ut, bounds, x0s)
        if best is None or score > best[0]:
            best = (score, mdl)
    if best is None:
        raise IdentificationError(f"nlss: the subspace start (n4sid) failed for every order "
                                  f"tried ({candidates})", hint="give another order= or check "
                                  "the record")
    model = best[1]
    model.criterion = _criterion(model, order, candidates, max_order, val, ins, levels, degree)
    _warn_of_result(model, val)
    model.info["seconds"] = round(time.perf_counter() - t0, 3)
    return model


def _run_records(model: NLSSModel, ut, bounds, x0s):
    """The free run of every record (rows ``bounds[r]:bounds[r+1]`` of ``ut``) from its own
    initial state → (Y stacked, the first diverging sample or −1)."""
    Ys = []
    for r, x0 in enumerate(x0s):
        a, b = int(bounds[r]), int(bounds[r + 1])
        Y, at = model._run(np.ascontiguousarray(ut[a:b]), x0)
        if at >= 0:
            return None, a + at
        Ys.append(Y)
    return np.vstack(Ys), -1


def _record_windows(bounds, L: int) -> np.ndarray:
    """Window starts of ``L`` samples inside each record (a short tail joins the record's last
    window; no window crosses from one record into the next), and the end."""
    starts = []
    for a, b in zip(bounds[:-1], bounds[1:]):
        st = np.arange(a, b, L, dtype=np.int64)
        if b - st[-1] < L // 2 and len(st) > 1:
            st = st[:-1]
        starts.append(st)
    return np.append(np.concatenate(starts), bounds[-1]).astype(np.int64)


def _start_model(A, B, C, D, x0, u_off, sd_u, y_off, degree, feedthrough, levels, dt, names):
    """The linear start as an NLSSModel (E = F = 0, no free directions, no state limit) with the
    exponent tables of ζ and η; ``names``: (inputs, outputs, input units, output units)."""
    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    ins, outs, iunits, ounits = names
    exz = monomial_exponents(n, m, degree, inputs=True, input_levels=levels)
    exe = monomial_exponents(n, m, degree, inputs=feedthrough, input_levels=levels)
    return NLSSModel(A=A, B=B, C=C, D=D, E=np.zeros((n, len(exz))), F=np.zeros((p, len(exe))),
                     exz=exz, exe=exe, u_offset=u_off, u_scale=sd_u, y_offset=y_off,
                     dirs=np.zeros((0, 3), dtype=np.int64), covariance=np.zeros((0, 0)),
                     x0=x0, state_limit=np.inf, dt=float(dt), degree=degree,
                     feedthrough=feedthrough, input_names=ins, output_names=outs,
                     input_units=iunits, output_units=ounits)


def _state_scales(X) -> np.ndarray:
    """σ of each state of the linear start's free run X (1 for a state that does not move)."""
    s = X.std(axis=0)
    s[s <= 1e-12 * max(float(s.max()), 1e-300)] = 1.0
    return s


def _output_weights(y, Y):
    """The linear start's fits, its error y − Y and the output weights 1/RMS of that error."""
    err = y - Y
    w = 1.0 / np.maximum(np.sqrt(np.mean(err * err, axis=0)), 1e-12 * y.std(axis=0))
    return _fits(y, Y), err, w


def _directions(base: NLSSModel) -> np.ndarray:
    """The free parameters (kind, r, c): the free linear entries, every entry of E and F, y₀."""
    n, p = base.order, base.C.shape[0]
    return np.vstack([_free_linear_entries(base.A, base.B, base.C, base.D, base.feedthrough),
                      np.array([(4, r, c) for r in range(n) for c in range(len(base.exz))],
                               dtype=np.int64).reshape(-1, 3),
                      np.array([(5, r, c) for r in range(p) for c in range(len(base.exe))],
                               dtype=np.int64).reshape(-1, 3),
                      np.array([(6, r, 0) for r in range(p)], dtype=np.int64)])


def _window_length(A, window, cap: int, total: int) -> int:
    """Samples per window of stage 2: ``window`` or 10 linear time constants (≥ 50), at most
    ``cap`` and at least total/200 (no more than 200 windows)."""
    n = A.shape[0]
    rad = float(np.max(np.abs(np.linalg.eigvals(A)))) if n else 0.0
    tau = -1.0 / math.log(min(max(rad, 1e-6), 1 - 1e-9))
    L = window if window is not None else int(min(max(50, 10 * tau), cap))
    return min(max(L, -(-total // 200)), cap)


def _parameter_covariance(H, V, dof: int, P: int):
    """cov θ = s² (H⁻¹)_θθ with s² = V/dof, H inverted in the coordinates scaled by diag(H)^½
    → (cov, the scaled H)."""
    s2 = V / max(dof, 1)
    sc = np.sqrt(np.maximum(np.diag(H), 1e-300))
    Hs = H / np.outer(sc, sc)
    try:
        cov = s2 * np.linalg.inv(Hs)[:P, :P] / np.outer(sc[:P], sc[:P])
    except np.linalg.LinAlgError:
        raise IdentificationError("nlss: the Jacobian is singular at the optimum: the data do "
                                  "not determine every monomial (a poorly exciting input)",
                                  hint="lower the degree or the order, or excite more richly") \
            from None
    return cov, Hs


def _polish_steps(N: int, Ns: int) -> int:
    """Progress-bar steps of one iteration over all N samples, one step being an iteration over
    the first Ns: the bar advances with the work, and its ETA holds."""
    return -(-N // Ns)


def _whole_record(model, base, dirs, Z, x0, ut, y, w, Ns, max_iterations, tick):
    """Stage 3 of one record: Levenberg-Marquardt on the whole record from one initial state,
    first on its warm-start part (``Ns`` samples) when shorter, taking there only steps whose
    free run stays in range over the whole record (a pass of the simulation, ~1 % of one of the
    sensitivity kernel; from the linear start when stage 2's model runs away over the whole
    record: a model fitted to the first part only is otherwise thrown away at the polish); a
    model that runs away over the longer record all the same, or fits it worse than the linear
    one, restarts there from the linear one → (model, Z, iterations, converged)."""
    N = ut.shape[0]
    its = []
    everything = np.array([0, N], dtype=np.int64)
    stays = lambda m_, Z_: bool(np.isfinite(_loss(m_, Z_, everything, ut, y, w)))  # noqa: E731
    for M_ in ((Ns, N) if Ns < N else (N,)):
        whole = np.array([0, M_], dtype=np.int64)
        Z0 = np.ascontiguousarray(Z[:1])
        xl = np.ascontiguousarray(x0[None, :])
        Vm = _loss(model, Z0, whole, ut, y, w)
        if not np.isfinite(Vm) or (M_ > Ns and _loss(base, xl, whole, ut, y, w) < Vm):
            # the model runs away over the longer record, or fits it worse than the linear one
            # (a part's model extrapolating badly): restart there from the linear one
            model, Z0 = base, xl
        cap = max_iterations if M_ == Ns else min(max_iterations, _POLISH_ITERATIONS)
        guard, step = None, tick
        if M_ < N:
            if not stays(model, Z0):
                model, Z0 = base, xl
            guard = stays
        elif Ns < N:
            def step():
                for _ in range(_polish_steps(N, Ns)):
                    tick()
        model, Z, V2, it2, conv2 = _lm(model, dirs, Z0, whole, ut[:M_], y[:M_], w, cap, step,
                                       bounded=guard)
        its.append(it2)
        if not np.isfinite(V2):
            raise IdentificationError("nlss: the free run of the model diverges on the "
                                      "estimation record at every step tried; lower the "
                                      "degree or the order")
    return model, Z, its, conv2


def _fit_order(lin, ut, y, u_off, sd_u, y_off, degree, feedthrough, window, max_iterations,
               progress, dt, ins, outs, iunits, ounits, levels, bounds=None,
               x0s=None) -> NLSSModel:
    """Stages 1-3 of the module docstring for one order. Several records: ``bounds`` their
    first rows in ``ut``, ``y`` and the end, ``x0s`` their initial states of the linear start;
    each record runs from its own initial state and no window crosses a seam."""
    ss = lin.system
    N, m = ut.shape
    p = y.shape[1]
    n = ss.n_states
    A, B, C = (np.array(M, dtype=np.float64) for M in (ss.A, ss.B, ss.C))
    D = np.array(ss.D, dtype=np.float64) if feedthrough else np.zeros((p, m))
    x0 = np.zeros(n) if lin.x0 is None else np.array(lin.x0, dtype=np.float64).ravel()
    if bounds is not None and len(bounds) > 2:
        return _fit_order_records(ss, A, B, C, D, ut, y, u_off, sd_u, y_off, degree,
                                  feedthrough, window, max_iterations, progress, dt, ins, outs,
                                  iunits, ounits, levels, np.asarray(bounds, dtype=np.int64),
                                  [np.asarray(z, dtype=np.float64).ravel() for z in x0s])
    base = _start_model(A, B, C, D, x0, u_off, sd_u, y_off, degree, feedthrough, levels, dt,
                        (ins, outs, iunits, ounits))
    X = np.empty((N, n))
    Y = np.empty((N, p))
    K.simulate_kernel(_arrays(base), x0, ut, Y, X, np.inf)
    if not np.all(np.isfinite(X)):
        raise IdentificationError("nlss: the linear start (n4sid) does not give a finite free "
                                  "run on the data; check the record")
    s = _state_scales(X)
    T, Ti = np.diag(1.0 / s), np.diag(s)
    A, B, C, x0, X = T @ A @ Ti, T @ B, C @ Ti, x0 / s, X / s
    limit = DIVERGENCE_FACTOR * max(1.0, float(np.abs(X).max()))
    base = replace(base, A=A, B=B, C=C, x0=x0, state_limit=limit)
    lin_fit, err, w = _output_weights(y, Y)
    dirs = _directions(base)
    # stage 2: truncated simulation windows (on the first _WARM_SAMPLES samples of a long record)
    Ns = min(N, _WARM_SAMPLES)
    L = _window_length(A, window, Ns, Ns)
    starts = np.arange(0, Ns, L, dtype=np.int64)
    if Ns - starts[-1] < L // 2 and len(starts) > 1:  # a short tail joins the last window
        starts = starts[:-1]
    starts = np.append(starts, Ns)
    Z = np.ascontiguousarray(X[starts[:-1]])
    total = 2 * max_iterations + (0 if Ns == N else _polish_steps(N, Ns)
                                  * min(max_iterations, _POLISH_ITERATIONS))
    bar = track(range(total), description=f"nlss order {n}",
                enabled=progress)
    t_start = time.perf_counter()
    if progress:
        status(f"nlss order {n} degree {degree}: {dirs.shape[0]} parameters; Levenberg-Marquardt "
               f"on {len(starts) - 1} windows of {L} samples, then the whole "
               + ("record" if Ns == N else f"first {Ns} samples, then all {N}"))
    try:
        tick = lambda: next(bar, None)  # noqa: E731
        model, Z, _, it1, _ = _lm(base, dirs, Z, starts, ut[:Ns], y[:Ns], w, max_iterations,
                                  tick, stall=_STALL_WINDOWS)
        # stage 3: the whole record (first its warm-start part) from one initial state
        model, Z, its, conv2 = _whole_record(model, base, dirs, Z, x0, ut, y, w, Ns,
                                             max_iterations, tick)
        its = [it1, *its]
    finally:
        bar.close()
    Z0 = Z
    whole = np.array([0, N], dtype=np.int64)
    V, Htt, gt, Htz, Hzz, gz = _gram(model, dirs, Z0, whole, ut, y, w)
    P = dirs.shape[0]
    H = np.zeros((P + n, P + n))
    H[:P, :P], H[:P, P:], H[P:, :P], H[P:, P:] = Htt, Htz[0], Htz[0].T, Hzz[0]
    cov, Hs = _parameter_covariance(H, V, N * p - P - n, P)
    cond = float(np.linalg.cond(Hs))
    model = replace(model, dirs=dirs, covariance=0.5 * (cov + cov.T), x0=Z0[0].copy())
    Yf, at = model._run(ut, model.x0)
    model.fit_percent = None if at >= 0 else _fits(y, Yf)
    model.linear_fit_percent = lin_fit
    lin_model = replace(base, dirs=np.zeros((0, 3), dtype=np.int64), covariance=np.zeros((0, 0)))
    model.info = {"iterations_windows": its[0], "iterations_whole": sum(its[1:]),
                  "converged": bool(conv2), "windows": len(starts) - 1, "window": int(L),
                  "parameters": int(P), "loss_linear": float(np.sum((w * err) ** 2) / N),
                  "loss": float(V / N), "hessian_condition": cond, "_linear": lin_model}
    if progress:
        status(f"nlss order {n}: {' + '.join(map(str, its))} iterations, "
               f"{time.perf_counter() - t_start:.1f} s")
    return model


def _records_hessian(Htt, Htz, Hzz):
    """The Gauss-Newton Hessian over [θ; z₁ … z_R] (every record's initial state a parameter)
    from the blocks of :func:`_gram` with one window per record."""
    P, R, n = Htt.shape[0], Htz.shape[0], Hzz.shape[1]
    H = np.zeros((P + R * n, P + R * n))
    H[:P, :P] = Htt
    for r in range(R):
        sl = slice(P + r * n, P + (r + 1) * n)
        H[:P, sl], H[sl, :P], H[sl, sl] = Htz[r], Htz[r].T, Hzz[r]
    return H


def _fit_order_records(ss, A, B, C, D, ut, y, u_off, sd_u, y_off, degree, feedthrough, window,
                       max_iterations, progress, dt, ins, outs, iunits, ounits, levels, bounds,
                       x0s) -> NLSSModel:
    """:func:`_fit_order` for several records (rows ``bounds[r]:bounds[r+1]``): the linear
    start's states scaled over all records; stage 2 on windows inside each record; stage 3 with
    one window per record (each record's free run from its own estimated initial state); σ from
    the Gauss-Newton Hessian with every record's initial state a parameter."""
    N, m = ut.shape
    p = y.shape[1]
    n = A.shape[0]
    R = len(bounds) - 1
    base = _start_model(A, B, C, D, x0s[0], u_off, sd_u, y_off, degree, feedthrough, levels,
                        dt, (ins, outs, iunits, ounits))
    X, Y = np.empty((N, n)), np.empty((N, p))
    for r, x0 in enumerate(x0s):
        a, b = bounds[r], bounds[r + 1]
        K.simulate_kernel(_arrays(base), x0, np.ascontiguousarray(ut[a:b]), Y[a:b], X[a:b],
                          np.inf)
    if not np.all(np.isfinite(X)):
        raise IdentificationError("nlss: the linear start (n4sid) does not give a finite free "
                                  "run on the records; check them")
    s = _state_scales(X)
    T, Ti = np.diag(1.0 / s), np.diag(s)
    A, B, C, X = T @ A @ Ti, T @ B, C @ Ti, X / s
    x0s = [x0 / s for x0 in x0s]
    limit = DIVERGENCE_FACTOR * max(1.0, float(np.abs(X).max()))
    base = replace(base, A=A, B=B, C=C, x0=x0s[0], state_limit=limit)
    lin_fit, err, w = _output_weights(y, Y)
    dirs = _directions(base)
    L = _window_length(A, window, int(np.min(np.diff(bounds))), N)
    starts = _record_windows(bounds, L)
    Z = np.ascontiguousarray(X[starts[:-1]])
    first = np.searchsorted(starts, bounds[:-1])  # the window that opens each record
    bar = track(range(2 * max_iterations), description=f"nlss order {n}", enabled=progress)
    t_start = time.perf_counter()
    if progress:
        status(f"nlss order {n} degree {degree}: {dirs.shape[0]} parameters; Levenberg-Marquardt "
               f"on {len(starts) - 1} windows of {L} samples inside {R} records, then each "
               "whole record")
    try:
        tick = lambda: next(bar, None)  # noqa: E731
        model, Z, _, it1, _ = _lm(base, dirs, Z, starts, ut, y, w, max_iterations, tick,
                                  stall=_STALL_WINDOWS)
        Z0 = np.ascontiguousarray(Z[first])
        if not np.isfinite(_loss(model, Z0, bounds, ut, y, w)):
            model, Z0 = base, np.ascontiguousarray(np.array(x0s))
        model, Z0, V, it2, conv2 = _lm(model, dirs, Z0, bounds, ut, y, w, max_iterations, tick)
        if not np.isfinite(V):
            raise IdentificationError("nlss: the free run of the model diverges on the "
                                      "estimation records at every step tried; lower the "
                                      "degree or the order")
    finally:
        bar.close()
    V, Htt, gt, Htz, Hzz, gz = _gram(model, dirs, Z0, bounds, ut, y, w)
    P = dirs.shape[0]
    cov, Hs = _parameter_covariance(_records_hessian(Htt, Htz, Hzz), V, N * p - P - R * n, P)
    model = replace(model, dirs=dirs, covariance=0.5 * (cov + cov.T), x0=Z0[0].copy())
    Yf, at = _run_records(model, ut, bounds, list(Z0))
    model.fit_percent = None if at >= 0 else _fits(y, Yf)
    model.linear_fit_percent = lin_fit
    lin_model = replace(base, dirs=np.zeros((0, 3), dtype=np.int64), covariance=np.zeros((0, 0)))
    records = []
    for r in range(R):
        a, b = bounds[r], bounds[r + 1]
        records.append({"n_samples": int(b - a), "x0": [float(v) for v in Z0[r]],
                        "fit_percent": None if at >= 0 else _fits(y[a:b], Yf[a:b])})
    model.info = {"iterations_windows": it1, "iterations_whole": it2, "converged": bool(conv2),
                  "windows": len(starts) - 1, "window": int(L), "parameters": int(P),
                  "loss_linear": float(np.sum((w * err) ** 2) / N), "loss": float(V / N),
                  "hessian_condition": float(np.linalg.cond(Hs)), "records": records,
                  "_linear": lin_model, "_x0s": [z.copy() for z in Z0]}
    if progress:
        status(f"nlss order {n}: {it1} + {it2} iterations, "
               f"{time.perf_counter() - t_start:.1f} s")
    return model
