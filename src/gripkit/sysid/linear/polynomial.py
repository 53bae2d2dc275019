"""Discrete-time polynomial input-output models (ARX, ARMAX, OE) in MATLAB's layout.

The general form (``000_8f66dcc7ab06470c.txt`` eqs 20–27, with Ljung's F for output error)::

    A(q) y(t) = B(q)/F(q) u(t) + C(q) e(t)

    A(q) = 1 + a_1 q⁻¹ + ... + a_na q⁻ⁿᵃ          (eq 22)
    B(q) = b_nk q⁻ⁿᵏ + ... + b_{nk+nb-1} q⁻⁽ⁿᵏ⁺ⁿᵇ⁻¹⁾  (eq 22 has nk = 1)
    C(q) = 1 + c_1 q⁻¹ + ... + c_nc q⁻ⁿᶜ          (eq 25)
    F(q) = 1 + f_1 q⁻¹ + ... + f_nf q⁻ⁿᶠ

Arrays hold the coefficients in increasing powers of q⁻¹: ``A = [1, a_1, ..., a_na]`` and
``B = [0]*nk + [b_nk, ..., b_{nk+nb-1}]`` (``B`` carries ``nk`` leading zeros, as MATLAB's
``idpoly``). ARX: C = F = 1; ARMAX: F = 1; OE: A = C = 1.

Parameter names follow the powers of q⁻¹ (Table III of the seed: ``a1 a2 b2 b3`` for ``[2 2 2]``).

Several inputs or outputs (ARX only, ``arx`` returns this one type whatever the number of
channels): ``A`` (na+1, p, p) with ``A[0] = I`` and ``B`` (nk+nb, p, m) with ``nk`` leading zero
matrices are matrix polynomials, ``A(q) y(t) = B(q) u(t) + e(t)``; ``A_std``, ``B_std`` have
their shapes, ``covariance`` is over θ row by row (output 0 first: ``a1_0_0 … b_nk_0_0 …``,
:mod:`.matrix_polynomial`), ``noise_variance`` is Λ (p, p), ``fit_percent`` the one-step fit per
output, names, units and offsets one per channel. The ``system`` is then the state-space
realisation of :mod:`.matrix_polynomial` (the one the former MIMO ``LinearModel`` had), the
one-step predictor the exact matrix difference equation, ``horizon > 1`` the realisation's
innovation form (K = [I; 0]). With one input and one output every array stays 1-D, as below.

:class:`PolynomialModel` is an :class:`~gripkit.sysid.linear.linear_model.IdentifiedLinearModel`:
its ``system`` is the discrete transfer function B/(A F); simulation, comparison, prediction,
the report, the model file and the conversions are the protocol's (one set of names for every
identified model). Its predictor is that of the noise model: ``ŷ(t|t−1)`` from
``A y = B/F u + C e`` (:meth:`PolynomialModel.prediction_errors`), ``horizon > 1`` from the
innovation form of ``[B/(A F), C/A]`` (:meth:`PolynomialModel.innovation_form`).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass, field

import numpy as np

from ...arguments import check_keywords, keyword_names
from ...errors import ArgumentError, DataError, ModelError
from ...lti import StateSpace, TransferFunction
from ...params import Parameter, ParameterSet
from ...signals.trajectory import Trajectory
from ...units import ratio_unit
from . import matrix_polynomial as mp
from .linear_model import (IdentifiedLinearModel, LinearModel, _checked_display_units,
                           as_io_matrix, deviation_compare, k_step_prediction, malformed,
                           polynomial_document, read_linear_model)
from ..model_protocol import check_horizon, check_sample_time
from .validation import checks_arrays, validate

__all__ = ["PolynomialModel", "load_linear_model"]

_STRUCTURES = ("arx", "armax", "oe")


class _Residuals:
    """The ``estimation_residuals`` field: the array an estimator passed, or, when it passed its
    estimation record as ``estimation_data`` instead, the one-step prediction errors computed from
    that record on first access (a large ARX fit keeps no N-sample array a user may never read, so
    its memory stays O(p²) beyond the data). The computed errors must reproduce the fit's loss:
    a record changed in place after the fit raises instead of giving other residuals."""

    def __get__(self, model, owner=None):
        if model is None:
            return None  # the dataclass default
        r = model.stored_residuals
        if r is None and model.estimation_data is not None:
            r = model._residuals_from_record()
            model.__dict__["_residuals"] = r
        return r

    def __set__(self, model, value):
        model.__dict__["_residuals"] = value


@functools.lru_cache(maxsize=8)
def _field_defaults(cls) -> tuple[dict, tuple]:
    """``({name: default}, ((name, default_factory), …))`` of the fields of the dataclass ``cls``
    that have one, but ``estimation_residuals`` (a descriptor: set through ``_residuals``)."""
    fields = [f for f in dataclasses.fields(cls) if f.name != "estimation_residuals"]
    return ({f.name: f.default for f in fields if f.default is not dataclasses.MISSING},
            tuple((f.name, f.default_factory) for f in fields
                  if f.default_factory is not dataclasses.MISSING))


#: The default C and F: read-only, shared by every model without a C or F polynomial.
_ONE = np.ones(1)
_ONE.flags.writeable = False


def _coeffs(x, name: str, monic: bool) -> np.ndarray:
    if x is _ONE:
        return x
    a = np.array(x, dtype=np.float64, copy=True).ravel()
    if a.size == 0:
        raise ModelError(f"{name}: expected at least one coefficient")
    # a few coefficients: Python's isfinite over a list is ~5x cheaper than a ufunc and a reduction
    if not (all(map(math.isfinite, a.tolist())) if a.size <= 64 else np.isfinite(a).all()):
        raise ModelError(f"{name} has non-finite coefficients: {a.tolist()}")
    if monic and a[0] != 1.0:
        raise ModelError(f"{name} must start with 1 (monic polynomial), found {a[0]:g}")
    a.flags.writeable = False
    return a


def _std_property(which: str, fixed: str) -> property:
    """The read-only 1σ of each entry of the polynomial ``which`` (0 for ``fixed``)."""
    return property(lambda self: self._std_layout(which),
                    doc=f"One-sigma uncertainty of each entry of ``{which}`` (0 for {fixed}).")


@dataclass(frozen=True, eq=False)
class PolynomialModel(IdentifiedLinearModel):
    """A discrete-time polynomial model with its uncertainty and fit diagnostics, on the
    protocol of :class:`~gripkit.sysid.linear.linear_model.IdentifiedLinearModel`: SISO ARX,
    ARMAX, OE, or a MIMO ARX of matrix polynomials (see the module docstring).

    Build one with :func:`gripkit.sysid.linear.arx`, :func:`~gripkit.sysid.linear.armax`,
    :func:`~gripkit.sysid.linear.oe`, or from known coefficients with :meth:`from_coefficients`.

    Attributes
    ----------
    A, B, C, F
        Coefficients in increasing powers of q⁻¹ (see the module docstring); ``B`` has ``nk``
        leading zeros. Read-only float64 arrays.
    nk
        Input delay in samples.
    dt
        Sample interval (s).
    structure
        ``'arx'``, ``'armax'`` or ``'oe'``.
    parameter_names
        Free parameters in the order of ``theta`` and ``covariance``: ``a1..a_na``,
        ``b_nk..b_{nk+nb-1}``, ``c1..c_nc``, ``f1..f_nf``.
    covariance
        Covariance of the free parameters, shape (p, p), or None for a model with known
        coefficients.
    noise_variance
        Estimate of var e(t): ``Σe²/(M − p)``.
    loss
        V_N of eq (29): ``(1/M) Σ ½ e²(t)`` over the M one-step prediction errors.
    fit_percent
        One-step-ahead prediction fit on the estimation data, ``100 (1 − ‖y − ŷ‖/‖y − ȳ‖)``
        (``fit_percent_definition`` says so; also ``prediction_fit_percent``). Not the free-run
        fit of :meth:`compare` that a state-space, transfer-function or NARX model's
        ``fit_percent`` is: compare families by ``simulation_fit_percent``.
    n_samples
        Samples in the estimation record (N); ``n_used`` = M = N − start prediction errors.
    estimation_residuals
        One-step prediction errors e(t), t = start … N−1, on the estimation record (read-only).
        :func:`gripkit.sysid.linear.arx` computes them on first access from ``estimation_data``.
        (``residuals(data)`` computes them on any record.) Not written to the model file.
    estimation_data
        ``(u, y)``, references to the record the model was fitted on (no copy; ``arx``,
        ``armax`` and ``oe`` of one record keep it), or None: the source of
        ``estimation_residuals`` when the estimator did not keep them, and of
        ``simulation_fit_percent``. Changing those
        arrays in place after the fit makes ``estimation_residuals`` raise a DataError. Not
        written to the model file.
    input_name, output_name, input_unit, output_unit
        Channel names and SI units of the data.
    u_offset, y_offset
        Means removed from the data before estimation (0 when not detrended); the model relates
        the deviations ``u − u_offset`` and ``y − y_offset``.
    info
        Method details: solver, iterations, condition number, source.
    data_file, data_hash, display_units
        Provenance of the estimation data and the units its file showed the columns in, as
        :class:`~gripkit.sysid.LinearModel` has them (:meth:`with_display_units`).
    """

    A: np.ndarray
    B: np.ndarray
    nk: int
    C: np.ndarray = field(default_factory=lambda: _ONE)
    F: np.ndarray = field(default_factory=lambda: _ONE)
    dt: float = 1.0
    structure: str = "arx"
    covariance: np.ndarray | None = None
    noise_variance: float | None = None
    loss: float | None = None
    fit_percent: float | None = None
    n_samples: int | None = None
    n_used: int | None = None
    estimation_residuals: np.ndarray | None = _Residuals()
    estimation_data: tuple | None = field(default=None, repr=False)
    input_name: str = "u"
    output_name: str = "y"
    input_unit: str = "1"
    output_unit: str = "1"
    u_offset: float = 0.0
    y_offset: float = 0.0
    info: dict = field(default_factory=dict)
    data_file: str | None = None
    data_hash: str | None = None
    display_units: dict = field(default_factory=dict)

    def __post_init__(self):
        if np.ndim(self.A) == 3 or np.ndim(self.B) == 3:
            self._post_init_matrix()
            return
        set_ = object.__setattr__
        set_(self, "A", _coeffs(self.A, "A", True))
        set_(self, "B", _coeffs(self.B, "B", False))
        set_(self, "C", _coeffs(self.C, "C", True))
        set_(self, "F", _coeffs(self.F, "F", True))
        if self.structure not in _STRUCTURES:
            raise ModelError(f"structure: expected one of {', '.join(_STRUCTURES)}, found "
                             f"{self.structure!r}")
        nk = int(self.nk)
        if nk < 0 or nk >= self.B.size:
            raise ModelError(f"nk={self.nk} must lie in [0, len(B)-1 = {self.B.size - 1}]")
        if any(self.B[:nk].tolist()):  # a nonzero leading entry (NaN was refused above)
            raise ModelError(f"B must start with nk={nk} zeros (MATLAB layout), found "
                             f"{self.B[:nk].tolist()}")
        set_(self, "nk", nk)
        if not (math.isfinite(self.dt) and self.dt > 0):
            raise ModelError(f"dt: expected a positive sample interval in s, found {self.dt!r}")
        if self.structure == "oe" and self.A.size > 1:
            raise ModelError("an OE model has A = 1; use F for its denominator")
        if self.structure != "armax" and self.C.size > 1:
            raise ModelError(f"an {self.structure.upper()} model has C = 1")
        if self.structure != "oe" and self.F.size > 1:
            raise ModelError(f"an {self.structure.upper()} model has F = 1")
        if self.covariance is not None:
            cov = np.array(self.covariance, dtype=np.float64)
            p = self.n_params
            if cov.shape != (p, p):
                raise ModelError(f"covariance: expected shape ({p}, {p}), found {cov.shape}")
            cov.flags.writeable = False
            set_(self, "covariance", cov)
        r = self.stored_residuals  # not estimation_residuals: that would compute them now
        if r is not None:
            # a read-only float64 array is kept as it is (an estimator's fresh residuals, or a
            # replace()): copying N samples again would double the memory of a large fit
            if not (isinstance(r, np.ndarray) and r.dtype == np.float64 and not r.flags.writeable):
                r = np.array(r, dtype=np.float64)
                r.flags.writeable = False
            set_(self, "estimation_residuals", r)
        set_(self, "display_units", _checked_display_units(self, dict(self.display_units or {})))

    def _post_init_matrix(self):
        """The checks of a MIMO ARX model: ``A`` (na+1, p, p) with ``A[0] = I``, ``B``
        (nk+nb, p, m) with ``B[:nk] = 0``, one name, unit and offset per channel."""
        set_ = object.__setattr__
        A, B = (np.array(x, dtype=np.float64) for x in (self.A, self.B))
        if A.ndim != 3 or B.ndim != 3 or A.shape[1:] != (A.shape[1],) * 2 or A.shape[0] < 1 \
                or B.shape[0] < 1 or B.shape[1] != A.shape[1]:
            raise ModelError(f"A, B: expected matrix polynomials of shapes (na+1, p, p) and "
                             f"(nk+nb, p, m), found {A.shape} and {B.shape}")
        if not (np.isfinite(A).all() and np.isfinite(B).all()):
            raise ModelError("A, B: the matrix polynomials have non-finite coefficients")
        p, m = A.shape[1], B.shape[2]
        if not np.array_equal(A[0], np.eye(p)):
            raise ModelError(f"A[0] must be the identity (monic matrix polynomial), found "
                             f"{A[0].tolist()}")
        if self.structure != "arx" or np.size(self.C) > 1 or np.size(self.F) > 1:
            raise ModelError(f"a model with several inputs or outputs is an ARX model "
                             f"(C = F = 1), found structure {self.structure!r}")
        nk = int(self.nk)
        if nk < 0 or nk >= B.shape[0]:
            raise ModelError(f"nk={self.nk} must lie in [0, len(B)-1 = {B.shape[0] - 1}]")
        if B[:nk].any():
            raise ModelError(f"B must start with nk={nk} zero matrices (MATLAB layout)")
        if not (math.isfinite(self.dt) and self.dt > 0):
            raise ModelError(f"dt: expected a positive sample interval in s, found {self.dt!r}")
        for x in (A, B):
            x.flags.writeable = False
        set_(self, "A", A)
        set_(self, "B", B)
        set_(self, "nk", nk)
        for k in ("C", "F"):
            set_(self, k, _coeffs(getattr(self, k), k, True))
        for name, default, n in (("input_name", "u", m), ("output_name", "y", p),
                                 ("input_unit", "1", m), ("output_unit", "1", p),
                                 ("u_offset", 0.0, m), ("y_offset", 0.0, p)):
            set_(self, name, _per_channel(getattr(self, name), name, default, n))
        for name, x, shape in (("covariance", self.covariance, (self.n_params,) * 2),
                               ("noise_variance", self.noise_variance, (p, p))):
            if x is not None:
                x = np.array(x, dtype=np.float64)
                if x.shape != shape:
                    raise ModelError(f"{name}: expected shape {shape}, found {x.shape}")
                x.flags.writeable = False
                set_(self, name, x)
        r = self.stored_residuals
        if r is not None and not (isinstance(r, np.ndarray) and not r.flags.writeable):
            r = np.array(r, dtype=np.float64)
            r.flags.writeable = False
            set_(self, "estimation_residuals", r)
        set_(self, "display_units", _checked_display_units(self, dict(self.display_units or {})))

    # ------------------------------------------------------------------ construction
    @classmethod
    def _estimated(cls, A: np.ndarray, B: np.ndarray, nk: int, covariance: np.ndarray,
                   estimation_residuals: np.ndarray | None, **fields) -> "PolynomialModel":
        """The model ``cls(A, B, nk, covariance=…, estimation_residuals=…, **fields)`` of a SISO
        estimator that built every array itself: ``A``, ``B`` fresh finite float64 vectors with
        ``A[0] = 1`` and ``nk`` leading zeros in ``B``, ``covariance`` a fresh (p, p) float64
        array, the residuals read-only float64 (or None), ``dt`` checked, no ``display_units``.
        The same fields, without :meth:`__post_init__`'s checks and copies of those arrays (a
        fixed cost of every fit that counts in order searches and sliding windows at N ≈ 10⁴);
        the arrays are made read-only here, as ``__post_init__`` makes its copies."""
        obj = object.__new__(cls)
        d = obj.__dict__
        defaults, factories = _field_defaults(cls)
        d.update(defaults)
        for name, factory in factories:
            d[name] = factory()
        for x in (A, B, covariance):
            x.flags.writeable = False
        d.update(A=A, B=B, nk=int(nk), covariance=covariance, **fields)
        d["_residuals"] = estimation_residuals  # the estimation_residuals descriptor's slot
        return obj

    @classmethod
    def from_coefficients(cls, A, B, *, nk: int | None = None, C=(1.0,), F=(1.0,), dt: float = 1.0,
                          structure: str | None = None, std: dict | None = None,
                          **kw) -> "PolynomialModel":
        """A model with known coefficients (no estimation diagnostics).

        ``nk`` defaults to the number of leading zeros of ``B``. ``std`` may give one-sigma
        uncertainties per coefficient array (``{"A": [...], "B": [...]}``, MATLAB layout, 0 for
        fixed entries); they become a diagonal covariance.
        """
        B = np.asarray(B, dtype=np.float64)
        if nk is None:
            nz = np.flatnonzero(B.reshape(len(B), -1).any(axis=1) if B.ndim == 3 else B)
            if nz.size == 0:
                raise ModelError("B is all zeros: the model has no input path")
            nk = int(nz[0])
        if B.ndim == 3 and std is not None:
            raise ModelError("std: give a MIMO model's uncertainty as covariance=… (over θ, "
                             "output 0's row first)")
        if structure is None:
            structure = "oe" if np.size(F) > 1 else ("armax" if np.size(C) > 1 else "arx")
        m = cls(A=A, B=B, nk=nk, C=C, F=F, dt=dt, structure=structure, **kw)
        if std is None:
            return m
        var = []
        for k, arr, sl in m._blocks():
            s = np.asarray(std.get(k, np.zeros(arr.size)), dtype=np.float64)
            if s.shape != arr.shape:
                raise ModelError(f"std[{k!r}]: expected {arr.size} values (the layout of "
                                 f"{k}), found {s.size}")
            var.append(s[sl] ** 2)
        return m.replace(covariance=np.diag(np.concatenate(var)))

    def replace(self, **changes) -> "PolynomialModel":
        """A copy with some fields changed (residuals not yet computed stay so)."""
        changes.setdefault("estimation_residuals", self.stored_residuals)
        return dataclasses.replace(self, **changes)

    def __getstate__(self) -> dict:
        """Pickled (process pools, batch results) with its residuals instead of the record they
        come from: N numbers rather than the 2N of ``(u, y)``, and no tie to the caller's arrays."""
        state = dict(self.__dict__)
        if state.get("estimation_data") is not None:
            state["_residuals"] = self.estimation_residuals
            state["estimation_data"] = None
        return state

    @property
    def stored_residuals(self) -> np.ndarray | None:
        """The residual array the model holds, or None while ``estimation_residuals`` has not been
        computed from ``estimation_data`` (reading this never computes them)."""
        return self.__dict__.get("_residuals")

    def _residuals_from_record(self) -> np.ndarray:
        u, y = self.estimation_data
        e = self.prediction_errors(u, y)
        if self.loss is not None:
            loss = 0.5 * float(e @ e) / e.size
            floor = 1e-24 * float(np.mean(np.square(y[self.start:])))  # rounding of noise-free fits
            if abs(loss - self.loss) > 1e-8 * self.loss + floor:
                raise DataError("residuals: the estimation record (u, y) was changed in "
                                "place after the fit "
                                f"(its one-step loss is now {loss:.6g}, the fit's was "
                                f"{self.loss:.6g}); compute "
                                f"errors on the data you hold with model.prediction_errors(u, y)")
        e.flags.writeable = False
        return e

    # ------------------------------------------------------------------ orders and parameters
    @property
    def na(self) -> int:
        return len(self.A) - 1

    @property
    def nb(self) -> int:
        return len(self.B) - self.nk

    @property
    def multivariable(self) -> bool:
        """Several inputs or outputs: ``A``, ``B`` and their σ are matrix polynomials."""
        return self.A.ndim == 3

    @property
    def n_inputs(self) -> int:
        return self.B.shape[2] if self.multivariable else 1

    @property
    def n_outputs(self) -> int:
        return self.A.shape[1] if self.multivariable else 1

    @property
    def noise_covariance(self) -> np.ndarray | None:
        """Λ, the covariance of e(t), (p, p) (``[[noise_variance]]`` with one output)."""
        if self.noise_variance is None:
            return None
        return np.array(self.noise_variance, dtype=np.float64).reshape(self.n_outputs, -1)

    @property
    def nc(self) -> int:
        return self.C.size - 1

    @property
    def nf(self) -> int:
        return self.F.size - 1

    @property
    def orders(self) -> tuple[int, ...]:
        """``(na, nb, nk)`` for ARX, ``(na, nb, nc, nk)`` for ARMAX, ``(nb, nf, nk)`` for OE."""
        return {"arx": (self.na, self.nb, self.nk), "armax": (self.na, self.nb, self.nc, self.nk),
                "oe": (self.nb, self.nf, self.nk)}[self.structure]

    @property
    def label(self) -> str:
        """``'ARX [2 2 2]'``."""
        return f"{self.structure.upper()} [{' '.join(str(o) for o in self.orders)}]"

    def _blocks(self):
        """(array name, array, slice of its free entries) in parameter order."""
        return [("A", self.A, slice(1, None)), ("B", self.B, slice(self.nk, None)),
                ("C", self.C, slice(1, None)), ("F", self.F, slice(1, None))]

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """``a1 … b_nk …`` (one output); with several, ``a1_i_j`` the entry (i, j) of A_1,
        output 0's row first (:mod:`.matrix_polynomial`)."""
        if self.multivariable:
            p, m = self.n_outputs, self.n_inputs
            return tuple(n for i in range(p) for n in
                         [f"a{k}_{i}_{j}" for k in range(1, self.na + 1) for j in range(p)]
                         + [f"b{self.nk + k}_{i}_{j}" for k in range(self.nb) for j in range(m)])
        names = [f"a{i}" for i in range(1, self.na + 1)]
        names += [f"b{self.nk + j}" for j in range(self.nb)]
        names += [f"c{i}" for i in range(1, self.nc + 1)]
        names += [f"f{i}" for i in range(1, self.nf + 1)]
        return tuple(names)

    @property
    def n_params(self) -> int:
        if self.multivariable:
            return self.n_outputs * (self.n_outputs * self.na + self.n_inputs * self.nb)
        return self.na + self.nb + self.nc + self.nf

    @property
    def theta(self) -> np.ndarray:
        """Free parameters in ``parameter_names`` order (eq 21 / eq 27)."""
        if self.multivariable:
            return mp.theta_rows(self.A, self.B, self.nk).ravel()
        return np.concatenate([arr[sl] for _, arr, sl in self._blocks()])

    @property
    def theta_std(self) -> np.ndarray | None:
        if self.covariance is None:
            return None
        return np.sqrt(np.clip(np.diag(self.covariance), 0.0, None))

    def _std_layout(self, which: str) -> np.ndarray | None:
        s = self.theta_std
        if s is None:
            return None
        if self.multivariable:
            if which not in ("A", "B"):  # C = F = 1: fixed
                return np.zeros(1)
            p, m = self.n_outputs, self.n_inputs
            rows = s.reshape(p, -1)
            out = np.zeros(self.A.shape if which == "A" else self.B.shape)
            if which == "A":
                out[1:] = rows[:, :p * self.na].reshape(p, self.na, p).transpose(1, 0, 2)
            else:
                out[self.nk:] = rows[:, p * self.na:].reshape(p, self.nb, m).transpose(1, 0, 2)
            return out
        i = 0
        for name, arr, sl in self._blocks():
            n = arr[sl].size
            if name == which:
                out = np.zeros(arr.size)
                out[sl] = s[i:i + n]
                return out
            i += n
        raise KeyError(which)

    A_std = _std_property("A", "the fixed leading 1")
    B_std = _std_property("B", "the ``nk`` fixed leading zeros")
    C_std = _std_property("C", "the fixed leading 1")
    F_std = _std_property("F", "the fixed leading 1")

    @property
    def parameters(self):
        """The free coefficients as a :class:`~gripkit.params.ParameterSet` (SI units: ``b``
        in output unit per input unit, the others dimensionless), with their std."""
        std = self.theta_std
        src = self.info.get("source", f"identified ({self.label})")
        if self.multivariable:
            return self._matrix_parameters(std, src)
        bunit = ratio_unit(self.output_unit, self.input_unit)
        params = []
        for i, (n, v) in enumerate(zip(self.parameter_names, self.theta)):
            doc = {"a": f"coefficient of q^-{n[1:]} in A(q)",
                   "b": f"coefficient of q^-{n[1:]} in B(q)",
                   "c": f"coefficient of q^-{n[1:]} in C(q)",
                   "f": f"coefficient of q^-{n[1:]} in F(q)"}[n[0]]
            params.append(Parameter(n, float(v), bunit if n[0] == "b" else "1", doc, source=src,
                                    std=None if std is None else float(std[i])))
        return ParameterSet(params, name=self.label)

    def _matrix_parameters(self, std, src) -> ParameterSet:
        """:attr:`parameters` of a MIMO model: ``a1_i_j`` dimensionless, ``b2_i_j`` in
        output i's unit per input j's."""
        params = []
        for k, (n, v) in enumerate(zip(self.parameter_names, self.theta)):
            power, i, j = (int(x) for x in n[1:].split("_"))
            unit = "1" if n[0] == "a" else ratio_unit(self.output_unit[i], self.input_unit[j])
            doc = f"entry ({i}, {j}) of the coefficient of q^-{power} in {n[0].upper()}(q)"
            params.append(Parameter(n, float(v), unit, doc, source=src,
                                    std=None if std is None else float(std[k])))
        return ParameterSet(params, name=self.label)

    # ------------------------------------------------------------------ fits
    @property
    def fit_percent_definition(self) -> str:
        """What ``fit_percent`` is: ARX and ARMAX, the one-step-ahead prediction fit on the
        estimation data (not the free run of :meth:`compare`: that is
        ``simulation_fit_percent``); OE, whose noise model is white, the fit of its one-step
        predictor, the free run from the estimated initial conditions."""
        which = ("its one-step-ahead predictor, the free run B/F u from the estimated initial "
                 "conditions" if self.structure == "oe" else "one-step-ahead prediction ŷ(t|t−1)")
        return (f"{which} on the estimation data, fit = 100 (1 − ‖y − ŷ‖/‖y − ȳ‖) over samples "
                f"start … N−1 (the free run of compare: simulation_fit_percent)")

    @property
    def prediction_fit_percent(self):
        """The one-step-ahead prediction fit on the estimation data: ``fit_percent`` (a number,
        a list per output with several outputs)."""
        return self.fit_percent

    @functools.cached_property
    def simulation_fit_percent(self) -> list | None:
        """The free-run fit of :meth:`compare` (:data:`~.linear_model.VALIDATION_FIT`) on the
        estimation data, a list per output, as every linear family's (and the figure to rank
        ARX against OE, state space or NARX by); None where the model holds no estimation record
        (one read from a file with one output, or a fit of several records), [None] for an
        unstable model. Computed on first access (the free-run kernel is numba's)."""
        if self.multivariable:
            return self.info.get("free_run_fit_percent")
        rec = self.estimation_data
        if not isinstance(rec, tuple) or len(rec) != 2:
            return None
        u, y = (np.asarray(x, dtype=np.float64).reshape(-1, 1) for x in rec)
        return deviation_compare(self, u, y, self.dt).fit_percent

    # ------------------------------------------------------------------ criteria
    @property
    def start(self) -> int:
        """First sample index whose one-step prediction uses only measured past data."""
        return max(self.na, self.nf, len(self.B) - 1)

    @property
    def aic(self) -> float | None:
        """Akaike's information criterion for Gaussian errors: ``M ln(2π V) + M + 2p`` with
        ``V = Σe²/M`` (MATLAB's ``aic``, same constant)."""
        if self.loss is None or not self.n_used:
            return None
        if self.multivariable:  # M ln det(2π Λ̂) + M p + 2 d, Λ̂ = EᵀE/M
            sign, logdet = np.linalg.slogdet(2 * math.pi * self._ml_noise_covariance())
            if sign <= 0:
                return -math.inf
            return self.n_used * (logdet + self.n_outputs) + 2 * self.n_params
        v = 2.0 * self.loss
        if v <= 0:
            return -math.inf
        return self.n_used * math.log(2 * math.pi * v) + self.n_used + 2 * self.n_params

    def _ml_noise_covariance(self) -> np.ndarray:
        """``EᵀE/M`` from the unbiased Λ = EᵀE/(M − q) (q regressors per output)."""
        q = self.n_params // self.n_outputs
        return self.noise_covariance * (self.n_used - q) / self.n_used

    @property
    def fpe(self) -> float | None:
        """Akaike's final prediction error ``V (1 + p/M) / (1 − p/M)``, ``V = Σe²/M``."""
        if self.loss is None or not self.n_used or self.n_used <= self.n_params:
            return None
        r = self.n_params / self.n_used
        if self.multivariable:  # MATLAB's: det Λ̂ (1 + d/M)/(1 − d/M)
            return float(np.linalg.det(self._ml_noise_covariance())) * (1 + r) / (1 - r)
        return 2.0 * self.loss * (1 + r) / (1 - r)

    # ------------------------------------------------------------------ the linear system
    @functools.cached_property
    def system(self) -> TransferFunction:
        """The input-output part ``y = B(q)/(A(q) F(q)) u`` as a discrete
        :class:`gripkit.lti.TransferFunction`, with the channel names and units, ``dt`` and the
        parameter covariance over ``parameter_names`` (the c's of an ARMAX model with zero
        tangents). Poles, zeros, DC gain, responses and exports below are computed by it.
        With several inputs or outputs: the :class:`gripkit.lti.StateSpace` realisation of
        :mod:`.matrix_polynomial` (state: past outputs and inputs) with exact tangents."""
        if self.multivariable:
            return mp.state_space(self.A, self.B, self.nk, self.dt, self.covariance,
                                  inputs=self.input_name, outputs=self.output_name,
                                  input_units=self.input_unit, output_units=self.output_unit)
        return TransferFunction.from_polynomials(
            self.A, self.B, C=self.C if self.nc else None, F=self.F, dt=self.dt,
            covariance=self.covariance,
            inputs=self.input_name, outputs=self.output_name, input_units=self.input_unit,
            output_units=self.output_unit)

    # ------------------------------------------------------------------ analysis
    @property
    def denominator(self) -> np.ndarray:
        """A(q)·F(q): the denominator of the input-output transfer function B/(A F); with
        several outputs det A(q) = Π (1 − λ_i q⁻¹) over the :meth:`poles`."""
        if self.multivariable:
            return np.real(np.poly(self.poles()))
        return np.convolve(self.A, self.F)

    def poles(self) -> np.ndarray:
        """Roots of A(z)·F(z) (the delay's poles at the origin are not listed): the first
        ``na + nf`` poles of :attr:`system` (np.roots lists the origin roots last). With
        several outputs: the p·na roots of det A(z), the eigenvalues of the past-output block of
        the realisation (the input-delay states add only poles at the origin)."""
        if self.multivariable:
            k = self.n_outputs * self.na
            return np.linalg.eigvals(self.system.A[:k, :k])
        return self.system.poles()[:self.denominator.size - 1]

    def zeros(self) -> np.ndarray:
        """Roots of B(z) without its delay: the ``nb − 1`` roots of ``[b_nk, ..., b_last]`` (the
        first zeros of :attr:`system`; the origin zeros of the q⁻¹ padding come last). With
        several inputs or outputs: the transmission zeros of :attr:`system`."""
        if self.multivariable:
            return self.system.zeros()
        return self.system.zeros()[:np.trim_zeros(self.B).size - 1]

    @property
    def minimum_phase(self) -> bool:
        """All zeros strictly inside the unit circle (the [2 2 2] model of Table II is not: its
        zero lies at z ≈ 1.167, §V-F)."""
        return self.system.minimum_phase

    @property
    def phase_note(self) -> str:
        """``'minimum phase'``, ``'NON-minimum phase'``, or, when every zero outside the unit
        circle lies less than 2σ of its modulus beyond it (:meth:`zero_moduli`), that these data
        do not decide it: a zero pushed out by a coefficient that does not differ from 0."""
        if self.minimum_phase:
            return "minimum phase"
        found = self.zero_moduli()
        if found is None:
            return "NON-minimum phase"
        modulus, std = found
        out = modulus >= 1.0
        if np.any(modulus[out] - 1.0 > 2.0 * std[out]):
            return "NON-minimum phase"
        k = int(np.argmax(np.where(out, modulus, -np.inf)))
        return (f"a zero outside the unit circle, |z| = {modulus[k]:.4g} ± {std[k]:.2g}: less "
                "than 2σ beyond it, so these data do not decide minimum phase")

    def zero_moduli(self) -> tuple[np.ndarray, np.ndarray] | None:
        """|z| of the zeros of B (one input, one output) and its 1σ by the delta method from the
        covariance of ``b_nk …`` (∂z/∂b_j = −z^(m−j)/B'(z), B of degree m in z); None without a
        covariance, with several channels, or with fewer than two B coefficients."""
        if self.multivariable or self.covariance is None:
            return None
        b = np.asarray(self.B[self.nk:], dtype=np.float64)
        if b.size < 2 or b[0] == 0.0 or b[-1] == 0.0:
            return None
        z = np.roots(b)
        slope = np.polyval(np.polyder(b), z)
        dz = -(z[:, None] ** np.arange(b.size - 1, -1, -1)[None, :]) / slope[:, None]
        grad = np.real(np.conj(z)[:, None] / np.abs(z)[:, None] * dz)  # ∂|z_i|/∂b_j
        cov = np.asarray(self.covariance, dtype=np.float64)[self.na:self.na + b.size,
                                                            self.na:self.na + b.size]
        var = np.einsum("ij,jk,ik->i", grad, cov, grad)
        return np.abs(z), np.sqrt(np.clip(var, 0.0, None))

    @property
    def dc_gain(self) -> float | np.ndarray:
        """Static gain B(1)/(A(1)F(1)) (±inf with an integrator); with several inputs or
        outputs the (p, m) matrix A(1)⁻¹ B(1)."""
        if self.multivariable:
            return self.system.dc_gain()
        try:
            return float(self.system.dc_gain()[0, 0])
        except ModelError:  # a pole at z = 1
            num = float(np.sum(self.B))
            return math.copysign(math.inf, num) if num != 0 else math.nan

    def step(self, n: int) -> np.ndarray:
        """Response to a unit step applied at sample 0, from rest, ``n`` samples ((n, p, m)
        with several inputs or outputs)."""
        r = self.system.step(int(n))
        return r if self.multivariable else r[:, 0, 0]

    def impulse(self, n: int) -> np.ndarray:
        """Response to a unit pulse at sample 0, from rest, ``n`` samples ((n, p, m) with
        several inputs or outputs)."""
        r = self.system.impulse(int(n))
        return r if self.multivariable else r[:, 0, 0]

    def frequency_response(self, w=None, n: int = 512) -> tuple[np.ndarray, np.ndarray]:
        """``(w, H)``: the complex response of B/(A F) at the angular frequencies ``w`` (rad/s,
        as every gripkit frequency response; default ``n`` points from 0 up to, not including,
        the Nyquist frequency π/dt), ``H = B(e^{-jωdt}) / (A F)(e^{-jωdt})``."""
        w = np.linspace(0.0, np.pi / self.dt, int(n), endpoint=False) if w is None \
            else np.atleast_1d(np.asarray(w, dtype=np.float64))
        H = self.system.frequency_response(w)
        return w, H if self.multivariable else H[:, 0, 0]

    # ------------------------------------------------------------------ simulation and prediction
    @checks_arrays("simulate", with_y=False)
    def simulate(self, data, x0=None, *, initial: str = "rest", y_past=None,
                 u_past=None) -> np.ndarray:
        """Free-run output ``ŷ = B/(A F) u`` (no noise) plus ``y_offset``: of a trajectory,
        (N, 1) in its units (:meth:`IdentifiedLinearModel.simulate`); of the inputs ``u``,
        shape (N,) (:meth:`gripkit.lti.TransferFunction.simulate` of ``u − u_offset``).

        Parameters
        ----------
        data
            A trajectory, or the input samples u(0) … u(N−1) in the units of the data the
            model was fitted on (the model's ``u_offset`` is removed), shape (N,): the record's
            own values, not deviations (:data:`~.validation.OFFSETS_RULE`; deviations with a
            far-off ``u_offset`` warn).
        x0
            Initial state of :attr:`system` (default rest); or ``initial='given'``.
        initial
            ``'rest'``: zero past inputs and outputs (say so explicitly: gripkit never assumes
            it silently in validation). ``'given'``: use ``y_past`` and ``u_past``.
        y_past, u_past
            The samples before u(0), in time order (most recent last), in the units of ``u``
            and of the output; at least ``len(A F) − 1`` outputs and ``len(B) − 1`` inputs are
            used (missing ones count as the operating point).
        """
        if isinstance(data, Trajectory) or self.multivariable:
            if initial != "rest":
                raise DataError("initial='given' takes the arrays of one input and one "
                                "output, not a trajectory or several columns")
            return super().simulate(data, x0)
        if initial == "rest" and (y_past is not None or u_past is not None):
            raise DataError("initial='rest' takes no y_past/u_past; use initial='given'")
        if initial not in ("rest", "given"):
            raise DataError(f"initial: expected 'rest' or 'given', found {initial!r}")
        uo, yo = self.u_offset, self.y_offset
        u = as_io_matrix(data, "u") - uo
        if initial == "rest":
            return self.system.simulate(u, x0)[:, 0] + yo
        past = [np.zeros(0) if p is None else np.asarray(p, dtype=np.float64) - o
                for p, o in ((u_past, uo), (y_past, yo))]
        return self._run_from_past(u, *past) + yo

    def _run_from_past(self, u, u_past, y_past) -> np.ndarray:
        """The free run (N,) on the deviations ``u`` from the model's operating point, from the
        state that the deviation pasts ``u_past``, ``y_past`` give."""
        g = self.system
        return g.simulate(u, g.initial_state(u_past, y_past))[:, 0]

    def prediction_errors(self, u, y) -> np.ndarray:
        """One-step prediction errors e(t), t = ``start`` … N−1 (``u``, ``y`` the deviations from
        the model's offsets; :meth:`residuals` takes the record's values).

        ARX/ARMAX: ``C(q) e(t) = A(q) y(t) − B(q) u(t)`` with e(t) = 0 before ``start``.
        OE: ``e = y − B/F u`` with the filter's past outputs taken from the measured y.
        """
        u = np.asarray(u, dtype=np.float64)
        y = np.asarray(y, dtype=np.float64)
        t0 = self.start
        if self.multivariable:
            u = as_io_matrix(u, "u")
            y = as_io_matrix(y, "y", u.shape[0])
            if (u.shape[1], y.shape[1]) != (self.n_inputs, self.n_outputs):
                raise DataError(f"u, y: expected {self.n_inputs} input and {self.n_outputs} "
                                f"output columns, found {u.shape[1]} and {y.shape[1]}")
            if y.shape[0] <= t0:
                raise DataError(f"one-step prediction with {self.label} needs more than {t0} "
                                f"samples, found {y.shape[0]}")
            return mp.prediction_errors(self.A, self.B, u, y, t0)
        if y.size <= t0:
            raise DataError(f"one-step prediction with {self.label} needs more than {t0} "
                            f"samples, found {y.size}")
        if self.structure == "oe":
            return y[t0:] - self._run_from_past(u[t0:], u[:t0], y[:t0])
        # the FIR parts by np.convolve: scipy.signal's import is 0.9 s of a fresh ARX process
        v = np.convolve(y, self.A)[t0:y.size] - np.convolve(u, self.B)[t0:u.size]
        if not self.nc:
            return v
        from scipy import signal as _sig

        return _sig.lfilter([1.0], self.C, v)

    @checks_arrays("predict")
    def predict(self, data, y=None, horizon: int = 1) -> np.ndarray:
        """``ŷ(t | t − horizon)``: of a trajectory (N, 1) in its units, of the arrays ``u``,
        ``y`` (offsets applied, as to a trajectory: the record's values, not deviations) shape
        (N,). ``horizon = 1``: the exact
        one-step predictor of the polynomials, the first ``start`` samples being the record's
        own values (the predictor's initial conditions); ``horizon > 1``:
        :func:`~.linear_model.k_step_prediction` on :meth:`innovation_form`."""
        if isinstance(data, Trajectory) or self.multivariable:
            return super().predict(data, y, horizon=horizon)
        u = np.asarray(data, dtype=np.float64) - self.u_offset
        y = np.asarray(y, dtype=np.float64) - self.y_offset
        h = check_horizon(horizon)
        return self._prediction(u.reshape(-1, 1), y.reshape(-1, 1), self.dt, h)[:, 0] \
            + self.y_offset

    def _prediction(self, u, y, dt, horizon: int) -> np.ndarray:
        if horizon > 1:
            return k_step_prediction(*self._state_space(dt), u, y, horizon)
        out = y.copy()
        if self.multivariable:
            self._state_space(dt)  # the sample time checked
            out[self.start:] = y[self.start:] - self.prediction_errors(u, y)
            return out
        out[self.start:, 0] = y[self.start:, 0] - self.prediction_errors(u[:, 0], y[:, 0])
        return out

    @checks_arrays("residuals")
    def residuals(self, data, y=None) -> np.ndarray:
        """One-step prediction errors :meth:`prediction_errors` from sample ``start`` on: of a
        trajectory (N − start, 1), of the arrays ``u``, ``y`` (offsets applied, as to a
        trajectory) shape (N − start,), (N − start, p) with several outputs."""
        u, yy, _, _ = self._io(data, y, "residuals of an identified model")
        if self.multivariable:
            return self.prediction_errors(u, yy)
        e = self.prediction_errors(u[:, 0], yy[:, 0])
        return e.reshape(-1, 1) if isinstance(data, Trajectory) else e

    def innovation_form(self) -> tuple[np.ndarray, ...]:
        """``(A, B, C, D, K)`` of ``y = B/(A F) u + C/A e`` in innovation form,
        ``x⁺ = A x + B u + K e``, ``y = C x + D u + e``: the controllable realisation of the
        two-input transfer function ``[B, C F]/(A F)`` (both monic denominators), transposed.
        With several inputs or outputs: the realisation of :mod:`.matrix_polynomial` with
        K = [I; 0]."""
        if self.multivariable:
            s = self.system
            return s.A, s.B, s.C, s.D, mp.innovation_gain(self.n_outputs, s.n_states, self.na)
        from scipy import signal as _sig

        den = np.convolve(self.A, self.F)
        nums = [self.B, np.convolve(self.C, self.F)]
        L = max(den.size, *(v.size for v in nums))
        pad = lambda v: np.concatenate([v, np.zeros(L - v.size)])  # noqa: E731  (q⁻¹ → z layout)
        A, B, C, D = _sig.tf2ss(np.vstack([pad(v) for v in nums]), pad(den))
        A, Bt, Ct, Dt = A.T, C.T, B.T, D.T  # the transpose: one output, the inputs u and e
        return A, Bt[:, :1], Ct, Dt[:, :1], Bt[:, 1:]

    def _state_space(self, dt):
        if dt is not None:
            check_sample_time(dt, self.dt)
        return self.innovation_form()

    @checks_arrays("validate")
    def validate(self, data, y=None, **kw):
        """Free-run and one-step validation on a separate record, a trajectory or the arrays
        ``u``, ``y`` (the record's own values, not deviations: :data:`~.validation.OFFSETS_RULE`);
        see :func:`gripkit.sysid.validate` (one input and one output; a MIMO
        model: :meth:`compare` and :meth:`residuals`)."""
        if self.multivariable:
            raise ModelError(f"validate: {self.label} has {self.n_inputs} inputs and "
                             f"{self.n_outputs} outputs; validate takes one of each",
                             hint="use model.compare(data) and model.residuals(data)")
        return validate(self, data, y, **kw)

    # ------------------------------------------------------------------ exports
    def to_scipy(self):
        """``scipy.signal.dlti`` transfer function B/(A F) with ``dt`` (the delay appears as
        poles at the origin): ``lti.to_scipy()``."""
        return self.system.to_scipy()

    def to_ss(self, dt: float | None = None, form: str = "observable") -> StateSpace:
        """B/(A F) as a :class:`gripkit.lti.StateSpace` (delay included as states);
        ``form='controllable'`` is scipy's ``tf2ss`` realisation. With ``dt``, the model's own
        sample time is checked (:meth:`IdentifiedLinearModel.to_ss`)."""
        if form == "observable":
            return super().to_ss(dt)
        self._state_space(dt)
        return self.system.to_ss(minimal=False, form=form)

    # ------------------------------------------------------------------ the model file
    def linear_record(self) -> LinearModel:
        """The model's system part as a :class:`~gripkit.sysid.LinearModel` on B/(A F) (what
        the ``system`` of its model file holds): the parameter covariance (the noise polynomial
        C keeps its place, with zero tangents), names, units and offsets. With several inputs
        or outputs: the state-space realisation with its innovation gain K = [I; 0] and Λ."""
        if self.multivariable:
            s = self.system
            return LinearModel(s, "arx", K=mp.innovation_gain(self.n_outputs, s.n_states, self.na),
                               noise_covariance=self.noise_variance, u_offset=self.u_offset,
                               y_offset=self.y_offset, n_samples=self.n_samples,
                               data_file=self.data_file, data_hash=self.data_hash,
                               display_units=self.display_units,
                               info={"label": self.label, "nk": self.nk,
                                     "parameter_names": list(self.parameter_names)})
        info = {"label": self.label, "A": self.A, "B": self.B, "C": self.C, "F": self.F,
                "nk": self.nk, "one_step_fit_percent": self.fit_percent,
                "noise_variance": self.noise_variance,
                "parameter_names": list(self.parameter_names),
                **{k: v for k, v in self.info.items() if isinstance(v, (str, int, float))}}
        return LinearModel(self.system, self.structure, u_offset=(self.u_offset,),
                           y_offset=(self.y_offset,), n_samples=self.n_samples,
                           data_file=self.data_file, data_hash=self.data_hash,
                           display_units=self.display_units,
                           noise_covariance=None if self.noise_variance is None
                           else np.array([[self.noise_variance]]), info=info)

    def polynomial_section(self) -> dict:
        """The ``polynomial`` section of the model file: what :meth:`from_document` needs to
        build this model again (every field but the record-bound ``estimation_residuals`` and
        ``estimation_data``)."""
        return {"A": self.A, "B": self.B, "C": self.C, "F": self.F, "nk": self.nk,
                "covariance": self.covariance, "noise_variance": self.noise_variance,
                "loss": self.loss, "fit_percent": self.fit_percent, "n_used": self.n_used,
                "info": self.info}

    @classmethod
    def from_document(cls, doc: dict, lm: LinearModel, where: str) -> "PolynomialModel":
        """The model of a model file's document ``doc`` whose system part was read as ``lm``;
        a version-1 file (coefficients in ``info``, covariance in the system's) is migrated."""
        poly = doc.get("polynomial")
        if len(lm.inputs) > 1 or len(lm.outputs) > 1:
            return cls._from_matrix_document(poly, lm, where)
        if poly is None:  # schema_version 1: the coefficients in info, the covariance the system's
            info = dict(lm.info)
            unc = lm.system.uncertainty
            poly = {k: info.pop(k) for k in ("A", "B", "C", "F", "nk")}
            poly.update(covariance=None if unc is None else unc.covariance,
                        noise_variance=info.pop("noise_variance", None),
                        fit_percent=info.pop("one_step_fit_percent", None))
            for k in ("label", "parameter_names"):
                info.pop(k, None)
            poly["info"] = info
        try:
            model = cls(A=poly["A"], B=poly["B"], nk=int(poly["nk"]), C=poly["C"], F=poly["F"],
                        dt=lm.dt, structure=lm.structure, covariance=poly.get("covariance"),
                        noise_variance=poly.get("noise_variance"), loss=poly.get("loss"),
                        fit_percent=poly.get("fit_percent"), n_samples=lm.n_samples,
                        n_used=poly.get("n_used"), input_name=lm.inputs[0],
                        output_name=lm.outputs[0], input_unit=lm.system.input_units[0],
                        output_unit=lm.system.output_units[0], u_offset=lm.u_offset[0],
                        y_offset=lm.y_offset[0], info=dict(poly.get("info") or {}),
                        data_file=lm.data_file, data_hash=lm.data_hash,
                        display_units=lm.display_units)
        except (ModelError, ValueError, TypeError) as exc:
            msg = exc.message if isinstance(exc, ModelError) else str(exc)
            raise ModelError(f"model file {where}: its polynomial section is malformed ({msg})",
                             hint="regenerate the file with gripkit identify --out") from None
        section = "polynomial" if "polynomial" in doc else "info"
        if section == "polynomial":
            _check_info_copy(doc, where)
        check_system_copy(model.system, lm.system, section, where)
        return model

    @classmethod
    def _from_matrix_document(cls, poly: dict, lm: LinearModel, where: str) -> "PolynomialModel":
        """:meth:`from_document` of a MIMO ARX model: the ``polynomial`` section, or a file
        without one (gripkit before the matrix polynomials moved here wrote a MIMO ARX model as
        a state-space ``LinearModel`` with ``A_poly``, ``B_poly`` in ``info`` and the
        covariance of θ in its system's: :func:`_matrix_section` migrates it)."""
        section = "info" if poly is None else "polynomial"
        if poly is None:
            poly = _matrix_section(lm)
        s = lm.system
        try:
            model = cls(A=poly["A"], B=poly["B"], nk=int(poly["nk"]), dt=lm.dt, structure="arx",
                       covariance=poly.get("covariance"),
                       noise_variance=poly.get("noise_variance"), loss=poly.get("loss"),
                       fit_percent=poly.get("fit_percent"), n_samples=lm.n_samples,
                       n_used=poly.get("n_used"), input_name=s.inputs, output_name=s.outputs,
                       input_unit=s.input_units, output_unit=s.output_units,
                       u_offset=lm.u_offset, y_offset=lm.y_offset,
                       info=dict(poly.get("info") or {}), data_file=lm.data_file,
                       data_hash=lm.data_hash, display_units=lm.display_units)
        except (ModelError, ValueError, TypeError, KeyError) as exc:
            msg = exc.message if isinstance(exc, ModelError) else str(exc)
            raise ModelError(f"model file {where}: its polynomial section is malformed ({msg})",
                             hint="regenerate the file with gripkit identify --out") from None
        check_system_copy(model.system, s, section, where)
        return model

    def to_dict(self) -> dict:
        """JSON-ready summary (complex numbers as ``[re, im]`` pairs)."""
        if self.multivariable:
            return self._matrix_dict()
        def pairs(z):
            return [[float(np.real(v)), float(np.imag(v))] for v in z]

        def lst(a):
            return None if a is None else [float(v) for v in a]

        d = {"structure": self.structure, "na": self.na, "nb": self.nb, "nk": self.nk}
        if self.structure == "armax":
            d["nc"] = self.nc
        if self.structure == "oe":
            d["nf"] = self.nf
        d.update(A=lst(self.A), B=lst(self.B), A_std=lst(self.A_std), B_std=lst(self.B_std))
        if self.structure == "armax":
            d.update(C=lst(self.C), C_std=lst(self.C_std))
        if self.structure == "oe":
            d.update(F=lst(self.F), F_std=lst(self.F_std))
        d.update(parameter_names=list(self.parameter_names), theta=lst(self.theta),
                 theta_std=lst(self.theta_std), loss=self.loss, fit_percent=self.fit_percent,
                 fit_percent_definition=self.fit_percent_definition, aic=self.aic,
                 fpe=self.fpe, noise_variance=self.noise_variance,
                 poles=pairs(self.poles()), zeros=pairs(self.zeros()),
                 minimum_phase=self.minimum_phase, stable=self.stable, dc_gain=self.dc_gain,
                 n_samples=self.n_samples, dt=self.dt,
                 input=self.input_name, output=self.output_name, input_unit=self.input_unit,
                 output_unit=self.output_unit, u_offset=self.u_offset, y_offset=self.y_offset)
        return d

    def _matrix_dict(self) -> dict:
        """:meth:`to_dict` of a MIMO model: ``A``, ``B``, ``A_std``, ``B_std`` nested lists
        (na+1, p, p) and (nk+nb, p, m), ``fit_percent`` and Λ per output."""
        def lst(a):
            return None if a is None else np.asarray(a, dtype=np.float64).tolist()

        poles = self.poles()
        return {"structure": "arx", "na": self.na, "nb": self.nb, "nk": self.nk,
                "A": lst(self.A), "B": lst(self.B), "A_std": lst(self.A_std),
                "B_std": lst(self.B_std), "parameter_names": list(self.parameter_names),
                "theta": lst(self.theta), "theta_std": lst(self.theta_std), "loss": self.loss,
                "fit_percent": self.fit_percent, "aic": self.aic, "fpe": self.fpe,
                "noise_covariance": lst(self.noise_covariance),
                "poles": [[float(z.real), float(z.imag)] for z in poles], "stable": self.stable,
                "n_samples": self.n_samples, "dt": self.dt, "inputs": list(self.inputs),
                "outputs": list(self.outputs), "input_units": list(self.input_unit),
                "output_units": list(self.output_unit), "u_offset": list(self.u_offset),
                "y_offset": list(self.y_offset)}

    def summary(self) -> str:
        """Several lines: structure, coefficients ± σ, loss, fit, poles and zeros."""
        if self.multivariable:
            return self._matrix_summary()
        lines = [f"{self.label}  dt = {self.dt:g} s"]
        for name, arr, _ in self._blocks():
            if arr.size == 1 and name in ("C", "F"):
                continue
            if name == "A" and self.structure == "oe":
                continue
            std = self._std_layout(name)
            terms = [f"{v:.5g}" + (f"±{s:.2g}" if std is not None and s > 0 else "")
                     for v, s in zip(arr, std if std is not None else np.zeros(arr.size))]
            lines.append(f"  {name} = [{', '.join(terms)}]")
        if self.loss is not None:
            lines.append(f"  loss V_N = {self.loss:.5g}, one-step fit = {self.fit_percent:.2f} %, "
                         f"AIC = {self.aic:.5g}, N = {self.n_samples}")
        fmt = lambda z: ", ".join(f"{v.real:.4g}{v.imag:+.4g}j" for v in z) or "none"  # noqa: E731
        lines.append(f"  poles: {fmt(self.poles())}")
        lines.append(f"  zeros: {fmt(self.zeros())} ({self.phase_note})")
        return "\n".join(lines)

    def _matrix_summary(self) -> str:
        lines = [f"{self.label}  {self.n_inputs} input(s) {list(self.inputs)} → "
                 f"{self.n_outputs} output(s) {list(self.outputs)}, dt = {self.dt:g} s"]
        for what, arr, std, first in (("A", self.A, self.A_std, 1), ("B", self.B, self.B_std,
                                                                      self.nk)):
            sd = np.zeros(arr.shape) if std is None else std
            for k in range(first, len(arr)):
                rows = "; ".join(" ".join(f"{v:.4g}±{e:.2g}" for v, e in zip(r, rs))
                                 for r, rs in zip(arr[k], sd[k]))
                lines.append(f"  {what}{k} = [{rows}]")
        if self.fit_percent is not None:
            fits = ", ".join(f"{n} {f:.2f} %" for n, f in zip(self.outputs, self.fit_percent))
            lines.append(f"  one-step fit: {fits}; N = {self.n_samples}")
        fmt = lambda z: ", ".join(f"{v.real:.4g}{v.imag:+.4g}j" for v in z) or "none"  # noqa: E731
        lines.append(f"  poles: {fmt(self.poles())}")
        return "\n".join(lines)

    def __repr__(self) -> str:
        if self.multivariable:
            return (f"PolynomialModel({self.label}, inputs={list(self.inputs)}, "
                    f"outputs={list(self.outputs)}, dt={self.dt:g})")
        return (f"PolynomialModel({self.label}, A={self.A.tolist()}, B={self.B.tolist()}, "
                f"dt={self.dt:g})")


def _per_channel(value, name: str, default, n: int) -> tuple:
    """One name, unit or offset per channel of a MIMO model: a sequence of ``n``, or the
    scalar default (names ``u0``, ``u1``, …; units '1'; offsets 0)."""
    if not isinstance(value, (list, tuple, np.ndarray)):
        if value == default or value is None:
            if name.endswith("_name"):
                return tuple(f"{default}{i}" for i in range(n))
            return (default,) * n
        value = (value,)
    if len(value) != n:
        raise ModelError(f"{name}: expected {n} values (one per channel), found {len(value)}")
    if name.endswith("offset"):
        return tuple(float(v) for v in value)
    if name.endswith("unit"):
        return tuple("1" if v in (None, "") else str(v) for v in value)
    return tuple(str(v) for v in value)


def _matrix_section(lm: LinearModel) -> dict:
    """The ``polynomial`` section of a MIMO ARX file written without one: ``A``, ``B`` from
    ``info['A_poly']``, ``info['B_poly']`` (A_i, B_{nk+j}), the covariance of θ the system's
    (the same order: output 0's row first), Λ, the one-step fit; the free-run fit and the
    estimated initial state that file held move to ``info``."""
    info = dict(lm.info)
    orders = info.pop("orders")
    na, nb, nk = int(orders["na"]), int(orders["nb"]), int(orders["nk"])
    p, m = len(lm.outputs), len(lm.inputs)
    A = np.concatenate([np.eye(p)[None]] + [np.asarray(a, dtype=np.float64).reshape(1, p, p)
                                            for a in info.pop("A_poly")])
    B = np.concatenate([np.zeros((nk, p, m))] + [np.asarray(b, dtype=np.float64).reshape(1, p, m)
                                                 for b in info.pop("B_poly")])
    if A.shape[0] != na + 1 or B.shape[0] != nk + nb:
        raise ModelError(f"A_poly, B_poly: expected {na} and {nb} matrices (orders {orders}), "
                         f"found {A.shape[0] - 1} and {B.shape[0] - nk}")
    for k in ("A_poly_std", "B_poly_std"):
        info.pop(k, None)
    info["free_run_fit_percent"] = lm.fit_percent
    unc = lm.system.uncertainty
    return {"A": A, "B": B, "nk": nk, "covariance": None if unc is None else unc.covariance,
            "noise_variance": lm.noise_covariance,
            "fit_percent": info.pop("one_step_fit_percent", None), "info": info}


def load_linear_model(path) -> IdentifiedLinearModel:
    """Read a file of schema ``gripkit.linear-model`` (:func:`gripkit.sysid.load_model`'s reader
    of it): a :class:`PolynomialModel` for a file with a ``polynomial`` section, and for a
    version-1 ARX/ARMAX/OE file (migrated: its coefficients were in ``info``, its covariance in
    the system's; loss, ``n_used`` and the residuals were not written), else the
    :class:`~gripkit.sysid.LinearModel` (:func:`~.linear_model.read_linear_model`)."""
    doc, lm, where = read_linear_model(path)
    if "polynomial" in doc or polynomial_document(doc) or _matrix_document(doc):
        return PolynomialModel.from_document(doc, lm, where)
    return lm


def _first_difference(a: np.ndarray, b: np.ndarray):
    """The first index where the arrays ``a`` and ``b`` differ beyond rounding (10⁻⁹ of their
    largest magnitude; NaN equal to NaN), ``()`` when their shapes differ, None when alike."""
    if a.shape != b.shape:
        return ()
    scale = max(float(np.max(np.abs(np.nan_to_num(a)), initial=0.0)),
                float(np.max(np.abs(np.nan_to_num(b)), initial=0.0)))
    bad = ~((np.abs(a - b) <= 1e-9 * scale) | (np.isnan(a) & np.isnan(b)))
    if not bad.any():
        return None
    return tuple(int(i) for i in np.argwhere(bad)[0])


def _numbers(x) -> np.ndarray:
    try:
        return np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        return np.full(1, np.nan)


def _disagree(where: str, field_: str, idx: tuple, a, b, section: str) -> ModelError:
    if idx:
        at = f"[{', '.join(map(str, idx))}] is {a[idx]:.10g}, {b[idx]:.10g} by {section!r}"
    else:
        at = f" has shape {a.shape}, {b.shape} by {section!r}"
    return malformed(where, f"{field_!r} and the {section!r} section disagree ({field_}{at}); "
                            f"the model is built from {section!r}, and {field_!r} is its copy: "
                            "one was edited without the other")


def check_system_copy(built, read, section: str, where: str) -> None:
    """The model file's ``system`` (``read``: the copy for readers without polynomials) must be
    the system of the coefficients in its ``section`` ('polynomial', or 'info' of a version-1
    file), ``built``, which the model is built from: arrays and parameter covariance alike to
    rounding (:func:`_first_difference`), else a malformed-file ModelError naming both."""
    b, r = built.to_dict(), read.to_dict()
    if b["type"] != r["type"]:
        raise malformed(where, f"'system' is a {r['type']} but the {section!r} section gives "
                               f"a {b['type']}")
    keys = ("A", "B", "C", "D") if b["type"] == "StateSpace" else ("num", "den")
    pairs = [(f"system.{k}", r[k], b[k]) for k in keys]
    if r["uncertainty"] is not None and b["uncertainty"] is not None:
        pairs.append(("system.uncertainty.covariance", r["uncertainty"]["covariance"],
                      b["uncertainty"]["covariance"]))
    for name, x, y in pairs:
        x, y = _numbers(x), _numbers(y)
        idx = _first_difference(x, y)
        if idx is not None:
            raise _disagree(where, name, idx, x, y, section)


def _check_info_copy(doc: dict, where: str) -> None:
    """A version-2 file's ``info`` repeats the coefficients of its ``polynomial`` section (A, B,
    C, F, nk, for readers of version 1): where it holds them they must agree."""
    info, poly = doc.get("info") or {}, doc["polynomial"]
    for k in ("A", "B", "C", "F", "nk"):
        if k in info and k in poly:
            x, y = _numbers(info[k]), _numbers(poly[k])
            idx = _first_difference(x, y)
            if idx is not None:
                raise _disagree(where, f"info.{k}", idx, x, y, "polynomial")


def _matrix_document(doc: dict) -> bool:
    """A MIMO ARX file written as a state-space model (``A_poly`` in ``info``, no
    ``polynomial`` section)."""
    info = doc.get("info") or {}
    return doc.get("structure") == "arx" and "A_poly" in info and "B_poly" in info


# : the ``**meta`` keywords of :func:`~gripkit.sysid.linear.arx`,
# :func:`~gripkit.sysid.linear.armax` and :func:`~gripkit.sysid.linear.oe`
META_KEYS = ("input_name", "output_name", "input_unit", "output_unit", "u_offset", "y_offset")


def check_meta(meta: dict, fn) -> None:
    """Refuse an unknown ``**meta`` keyword of ``fn`` (arx, armax or oe) before any fitting: it
    would otherwise fail only when the model is built, after the work."""
    if all(k in META_KEYS for k in meta):  # the usual case: no signature to read (~30 µs)
        return
    name = fn.__name__
    check_keywords(meta, META_KEYS, f"{name}()",
                   hint=f"{name} accepts {', '.join(keyword_names(fn))} and the "
                                                      f"metadata {', '.join(META_KEYS)}")


#: the lti spelling of the channel keywords (``inputs=[...]``, as :class:`gripkit.lti.StateSpace`
#: and :func:`gripkit.sysid.n4sid` take them) and the model's field each one sets
CHANNEL_KEYS = {"inputs": "input_name", "outputs": "output_name", "input_units": "input_unit",
                "output_units": "output_unit"}


def channel_meta(meta: dict, fn, siso: bool) -> dict:
    """``meta`` with ``inputs``, ``outputs``, ``input_units``, ``output_units`` turned into the
    model's fields (:data:`CHANNEL_KEYS`; a list of one taken as its entry for a SISO model),
    then checked (:func:`check_meta`); an ArgumentError when both spellings are given."""
    if not meta:  # the common call: nothing to translate or check
        return {}
    out = dict(meta)
    for lti_key, field_ in CHANNEL_KEYS.items():
        if lti_key not in out:
            continue
        value = out.pop(lti_key)
        if field_ in out:
            raise ArgumentError(f"{fn.__name__}(): {lti_key}= and {field_}= name the same "
                                f"channels; give one of them", hint=f"use {field_}=…")
        if value is None:
            continue
        if siso and isinstance(value, (list, tuple)) and len(value) == 1:
            value = value[0]
        out[field_] = value
    check_meta(out, fn)
    return out
