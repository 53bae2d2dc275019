"""An identified linear model: a :mod:`gripkit.lti` system plus what identification knows about it
(innovation gain K, initial state, offsets, fit, singular values, data provenance).

Discrete innovation form (the subspace and PEM models)::

    x[t+1] = A x[t] + B u[t] + K e[t],   y[t] = C x[t] + D u[t] + e[t],   e white, cov Λ.

``K = 0`` is the output-error form. A :class:`~gripkit.signals.Trajectory` is read by column
name; arrays are in the units of the data the model was fitted on. Either way the model's
``u_offset`` and ``y_offset`` (one per input and output, the operating point removed before
fitting; zero for a model fitted on arrays) are removed from the data and added back to outputs,
so ``m.compare(u, y)`` on a record's columns is ``m.compare(record)``.

The identified linear models form one small hierarchy on the protocol of
:mod:`gripkit.sysid.model_protocol`: :class:`IdentifiedLinearModel` holds every protocol method
(``simulate``, ``predict``, ``compare``, ``residuals``, ``save``, ``to_ss``, ``to_tf``,
``to_control``, ``stable``, ``parameters``), written once on the model's ``system``, and
``report`` (:class:`~gripkit.sysid.model_protocol.ReportMixin`: the page of
:mod:`gripkit.sysid.model_report`, poles and Bode with σ);
:class:`LinearModel` (state space, transfer function) and
:class:`~gripkit.sysid.linear.polynomial.PolynomialModel` (ARX, ARMAX, OE, with the polynomial
views ``A``, ``B``, ``C``, ``F`` and their σ) derive from it. Frequencies are in rad/s everywhere
(:meth:`gripkit.lti.LinearSystem.frequency_response`).

Free-run fit per output, ``100 (1 − ‖y_i − ŷ_i‖/‖y_i − ȳ_i‖)``, uses an initial state estimated by
least squares (the output is affine in x0: ``y = O x0 + G u``, ``O`` the rows ``C A^t``).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from ... import __version__
from ...errors import ArgumentError, DataError, ModelError
from ...lti import LinearSystem, StateSpace, TransferFunction
from ...params import Parameter, ParameterSet
from ...signals.trajectory import Trajectory
from ...units import product_unit, same_dimension
from ..checks import as_io_matrix
from ..model_file import SCHEMA, SCHEMA_VERSION, read_document, write_document
from ..model_protocol import (ModelFit, ReportMixin, check_horizon, check_sample_time)
from .validation import checks_arrays, model_columns, validate

__all__ = ["VALIDATION_FIT", "IdentifiedLinearModel", "LinearModel", "as_io_matrix",
           "deviation_compare", "estimate_x0", "free_run", "fit_per_output", "k_step_prediction",
           "model_document", "polynomial_document", "read_linear_model", "x0_residual"]


def _sim(A, B, C, D, u, x0):
    from ...lti import simulate_ss  # numba, loaded on first simulation

    y = np.empty((u.shape[0], C.shape[0]))
    simulate_ss(A, B, C, D, u, np.array(x0, dtype=np.float64), np.empty(A.shape[0]), y)
    return y


def free_run(A, B, C, D, u, x0=None) -> np.ndarray:
    """Outputs (N, p) of ``x[t+1] = A x + B u, y = C x + D u`` from ``x0`` (numba kernel)."""
    A, B, C, D = (np.ascontiguousarray(M, dtype=np.float64) for M in (A, B, C, D))
    return (_sim(A, B, C, D, np.ascontiguousarray(u, dtype=np.float64),
                 np.zeros(A.shape[0]) if x0 is None else x0))


def observability_regressor(A, C, N: int) -> np.ndarray:
    """``O`` of shape (N, p, n): ``O[t] = C A^t`` (the response of each output to each unit x0)."""
    n, p = A.shape[0], C.shape[0]
    O = np.empty((N, p, n))
    Ac, Cc = np.ascontiguousarray(A), np.ascontiguousarray(C)
    z = np.zeros((N, 1))
    for i in range(n):
        e = np.zeros(n)
        e[i] = 1.0
        O[:, :, i] = _sim(Ac, np.zeros((n, 1)), Cc, np.zeros((p, 1)), z, e)
    return O


def _x0_least_squares(A, B, C, D, u, y):
    """(x0, the output error from rest ``y − G u`` flattened, ``O`` as an (N·p, n) matrix)."""
    r = (y - free_run(A, B, C, D, u)).reshape(-1)
    O = observability_regressor(A, C, y.shape[0]).reshape(-1, A.shape[0])
    return np.linalg.lstsq(O, r, rcond=None)[0], r, O


def estimate_x0(A, B, C, D, u, y) -> np.ndarray:
    """Least-squares initial state: ``argmin ‖y − G u − O x0‖`` (``O[t] = C A^t``)."""
    if A.shape[0] == 0:
        return np.zeros(0)
    return _x0_least_squares(A, B, C, D, u, y)[0]


def x0_residual(A, B, C, D, u, y) -> np.ndarray:
    """Output error (N, p) of the free run from the least-squares initial state
    (:func:`estimate_x0`), from the one simulation that state needs: the output is linear in x0,
    so ``y − ŷ(x0) = (y − G u) − O x0`` (what ``y − free_run(..., estimate_x0(...))`` gives, to
    round-off, without simulating again)."""
    if A.shape[0] == 0:
        return y - free_run(A, B, C, D, u)
    x0, r, O = _x0_least_squares(A, B, C, D, u, y)
    return (r - O @ x0).reshape(y.shape)


def fit_per_output(y, yhat) -> list[float]:
    """Fit (%) of each output column; DataError for a constant output."""
    out = []
    for i in range(y.shape[1]):
        den = float(np.linalg.norm(y[:, i] - y[:, i].mean()))
        if den == 0.0:
            raise DataError(f"output {i}: the fit is undefined for a constant output (‖y − ȳ‖ = 0)")
        out.append(100.0 * (1.0 - float(np.linalg.norm(y[:, i] - yhat[:, i])) / den))
    return out


def _checked_display_units(model, shown: dict) -> dict:
    """``shown`` ({name: unit}) checked against the model's inputs and outputs: each a unit of
    the same dimension as the SI unit it displays (else a :class:`ModelError`)."""
    if not shown:
        return shown
    s = model.system
    units = dict(zip(s.inputs, s.input_units)) | dict(zip(s.outputs, s.output_units))
    for name, unit in shown.items():
        si = units.get(name)
        if si in (None, "", "1") or not isinstance(unit, str):
            raise ModelError(f"display unit of {name!r}: the model has no input or output {name!r} "
                             f"with a physical unit (display units: {shown})",
                             hint="display units are taken from the estimation data's headers")
        try:
            ok = same_dimension(unit, si)
        except Exception:
            ok = False
        if not ok:
            raise ModelError(f"display unit of {name!r}: {unit!r} is not a unit of the same "
                             f"quantity as the model's {si!r}",
                             hint=f"give a unit of {name!r} in {si!r} or its multiples, or none")
    return shown


def _unit_of(units, k: int) -> str:
    """Unit ``k`` of a system's ``units`` (None, or '' for one not declared: '1')."""
    return (units[k] if units is not None and k < len(units) else "") or "1"


def _declared(units, n: int) -> tuple[str, ...]:
    """The ``n`` unit strings of a system's ``units`` (:func:`_unit_of`)."""
    return tuple(_unit_of(units, k) for k in range(n))


def _coefficient_unit(s: LinearSystem, name: str, idx: tuple) -> tuple[str, str]:
    """(unit, note for its description) of entry ``idx`` of array ``name`` of the system ``s``
    (``'1'`` for an undeclared signal unit; time in s).

    Transfer function ``num``/``den`` (p, m, L), entry (i, j) of denominator degree n: a
    coefficient of z^k is dimensionless in the denominator and in y_i/u_j in the numerator; one
    of s^k has s^(k−n) more (``a_1`` of ``s^n + a_1 s^(n−1) + …`` in 1/s, the numerator's constant
    in (y_i/u_j)/s^n, so that num/den at s = 0 is in y_i/u_j). State space: ``D`` in y_i/u_j;
    ``A``, ``B``, ``C`` in the declared state units (``x' = Ax + Bu``: A in x_i/x_j, B in
    x_i/u_j, times 1/s for a continuous system; C in y_i/x_j), or, when the identified state basis
    carries none, with the state taken dimensionless (and that said in the note)."""
    unit = _unit_of
    per_time = 0 if s.is_discrete else -1
    if isinstance(s, TransferFunction):
        i, j, k = idx
        den = np.asarray(s.den[i, j])
        power = (den.size - 1 - k) - (den.size - 1 - int(np.flatnonzero(den)[0]))
        time = ("s", 0 if s.is_discrete else power)
        if name == "den":
            return product_unit(time), ""
        return product_unit((unit(s.output_units, i), 1), (unit(s.input_units, j), -1),
                            time), ""
    i, j = idx
    declared = any(s.state_units or ())
    x_i, x_j = unit(s.state_units, i), unit(s.state_units, j)
    u_j, y_i = unit(s.input_units, j), unit(s.output_units, i)
    factors = {"A": ((x_i, 1), (x_j, -1), ("s", per_time)),
               "B": ((x_i, 1), (u_j, -1), ("s", per_time)),
               "C": ((y_i, 1), (x_j, -1)), "D": ((y_i, 1), (u_j, -1))}[name]
    note = ("" if declared or name == "D" else
            "; the identified state basis carries no unit (the state is taken dimensionless)")
    return product_unit(*factors), note


#: gripkit's one definition of a validation fit, used by ``identify --validate``, ``compare``,
#: ``report`` and the demo, and stated in their outputs (:meth:`IdentifiedLinearModel.compare`)
VALIDATION_FIT = ("free run from the model's operating point (its stored offsets), initial state "
                  "estimated by least squares, fit = 100 (1 − ‖y − ŷ‖/‖y − ȳ‖) over every sample")


def k_step_prediction(A, B, C, D, K, u, y, horizon: int) -> np.ndarray:
    """``ŷ(t | t − horizon)`` (N, p) of the innovation model ``x⁺ = A x + B u + K e``,
    ``y = C x + D u + e`` on deviation data ``u`` (N, m), ``y`` (N, p): the one-step predictor
    ``x̂⁺ = (A − KC) x̂ + (B − KD) u + K y``, ``ŷ = C x̂ + D u`` (a linear system of the inputs
    ``[u, y]``) from the initial state estimated by least squares (:func:`estimate_x0` on that
    system, as :func:`~gripkit.sysid.linear.pem_ss.predictor_x0` does), then ``horizon − 1``
    steps of the model with the known inputs and no measurement. Samples ``t < horizon − 1`` are
    the free run from that initial state. ``K = 0`` gives the free run for every horizon."""
    A, B, C, D, K = (np.ascontiguousarray(M, dtype=np.float64) for M in (A, B, C, D, K))
    u, y = np.ascontiguousarray(u, dtype=np.float64), np.ascontiguousarray(y, dtype=np.float64)
    n, N, p = A.shape[0], u.shape[0], C.shape[0]
    Ap, Bp, Dp = A - K @ C, np.hstack([B - K @ D, K]), np.hstack([D, np.zeros((p, p))])
    w = np.hstack([u, y])
    x0 = estimate_x0(Ap, Bp, C, Dp, w, y)
    if horizon == 1:
        return free_run(Ap, Bp, C, Dp, w, x0)
    out = free_run(A, B, C, D, u, x0)
    if N < horizon:
        return out
    X = free_run(Ap, Bp, np.eye(n), np.zeros((n, Bp.shape[1])), w, x0)
    rows = N - horizon + 1
    Z = X[:rows]
    for j in range(horizon - 1):
        Z = Z @ A.T + u[j:j + rows] @ B.T
    out[horizon - 1:] = Z @ C.T + u[horizon - 1:] @ D.T
    return out


def deviation_compare(model, u, y, dt, y_offset=0.0) -> ModelFit:
    """The validation fit (:data:`VALIDATION_FIT`) of the identified linear ``model`` on the
    deviations ``u`` (N, m), ``y`` (N, p) from its offsets (what the estimators and the order
    searches hold), its simulated output plus ``y_offset``; :meth:`IdentifiedLinearModel.compare`
    on the record's values removes the offsets and calls this."""
    ss = model.to_ss(dt)
    if not ss.stable:
        ys = free_run(ss.A, ss.B, ss.C, ss.D, u)
        fit = [None] * ss.n_outputs
    else:
        x0 = estimate_x0(ss.A, ss.B, ss.C, ss.D, u, y)
        ys = free_run(ss.A, ss.B, ss.C, ss.D, u, x0)
        fit = fit_per_output(y, ys)
    return ModelFit(tuple(model.outputs), fit, ys + y_offset, model.fit_definition)


class IdentifiedLinearModel(ReportMixin):
    """The protocol of every identified linear model (:mod:`gripkit.sysid.model_protocol`),
    written once on what a subclass holds: ``system`` (a :mod:`gripkit.lti` system with names,
    units, dt and parameter covariance), ``structure``, ``dt``, ``u_offset`` and ``y_offset``.

    ``data`` is a :class:`~gripkit.signals.Trajectory` (columns by name, converted to the
    model's units) or arrays in the units of the data the model was fitted on (``u`` (N, m)
    and, where needed, ``y`` (N, p)); either way the model's offsets are removed and added back:
    results in the data's units. Frequencies are in rad/s
    (:meth:`gripkit.lti.LinearSystem.frequency_response`)."""

    #: how :meth:`compare` scores a model, and how it starts the free run
    fit_definition = VALIDATION_FIT
    #: what the model's own ``fit_percent`` is: here the fit of :meth:`compare` on the
    #: estimation data (ARX and ARMAX: the one-step prediction fit, see PolynomialModel)
    fit_percent_definition = f"{VALIDATION_FIT}, on the estimation data"

    @property
    def simulation_fit_percent(self) -> list | None:
        """The free-run fit (:data:`VALIDATION_FIT`, what :meth:`compare` gives) on the
        estimation data, a list per output: the figure to rank models of every family by. A
        state-space or transfer-function model's ``fit_percent`` is it."""
        return self.fit_percent
    initial_state = "estimated"
    #: its HTML report: poles, Bode with σ, innovation residuals (gripkit.sysid.model_report)
    _report_page = "linear"

    @property
    def inputs(self) -> tuple[str, ...]:
        return self.system.inputs

    @property
    def outputs(self) -> tuple[str, ...]:
        return self.system.outputs

    @property
    def input_units(self) -> tuple[str, ...]:
        """The SI unit of each input, from ``system`` ('1' where it declares none)."""
        return _declared(self.system.input_units, len(self.inputs))

    @property
    def output_units(self) -> tuple[str, ...]:
        """The SI unit of each output, from ``system`` ('1' where it declares none)."""
        return _declared(self.system.output_units, len(self.outputs))

    @property
    def order(self) -> int:
        """States of the model's (non-minimal) state-space realisation."""
        return self.system.to_ss(minimal=False).n_states

    @property
    def stable(self) -> bool:
        """All poles strictly inside the unit circle (discrete) or left half-plane (continuous)."""
        return self.system.stable

    def _offsets(self) -> tuple[np.ndarray, np.ndarray]:
        return (np.atleast_1d(np.asarray(self.u_offset, dtype=np.float64)),
                np.atleast_1d(np.asarray(self.y_offset, dtype=np.float64)))

    def with_display_units(self, data) -> IdentifiedLinearModel:
        """This model with the display units of its inputs and outputs taken from the trajectory
        ``data`` (:meth:`~gripkit.signals.Trajectory.display_unit`: the units its file wrote
        them in, ``force [mN]`` → ``'mN'``), where they differ from the model's SI units."""
        s = self.system
        pairs = list(zip(s.inputs, s.input_units)) + list(zip(s.outputs, s.output_units))
        shown = {n: data.display_unit(n) for n, u in pairs
                 if n in data.names and u not in (None, "", "1") and data.unit(n) == u
                 and data.display_unit(n) != u}
        return self.replace(display_units=shown)

    def display_unit(self, name: str) -> str | None:
        """The unit input or output ``name`` is shown in: its display unit, else its SI unit."""
        s = self.system
        units = dict(zip(s.inputs, s.input_units)) | dict(zip(s.outputs, s.output_units))
        return self.display_units.get(name, units.get(name))

    # ------------------------------------------------------------------ systems and interop
    def to_ss(self, dt: float | None = None) -> StateSpace:
        """The model as a :class:`gripkit.lti.StateSpace` (its non-minimal realisation); with
        ``dt``, sampled at ``dt`` (zero-order hold for a continuous model; a discrete model must
        have that sample time, else a DataError)."""
        ss = self.system.to_ss(minimal=False)
        if dt is None:
            return ss
        if ss.is_discrete:
            check_sample_time(dt, ss.dt)
            return ss
        return ss.c2d(dt)

    def to_tf(self) -> TransferFunction:
        """The model as a :class:`gripkit.lti.TransferFunction`."""
        s = self.system
        return s if isinstance(s, TransferFunction) else s.to_tf()

    def to_control(self):
        """``control.StateSpace`` or ``control.TransferFunction`` with the channel names (needs
        python-control: ``pip install 'gripkit[interop]'``)."""
        return self.system.to_control()

    # ------------------------------------------------------------------ data in
    def _columns(self, data, names, offsets, what):
        """The trajectory's columns ``names`` (:func:`~.validation.model_columns`) less the
        model's ``offsets``."""
        units = self.system.input_units if what == "input" else self.system.output_units
        return model_columns(data, names, units, what) - offsets

    def _io(self, data, y, why: str, outputs: bool = True, dt: float | None = None):
        """``(u, y, dt, y_offset)``: the deviations from the model's offsets of a trajectory's
        columns or of the arrays given (in the units of the data the model was fitted on), and
        the y_offset to add back."""
        uo, yo = self._offsets()
        if isinstance(data, Trajectory):
            dt = data.require_uniform(why=why)
            u = self._columns(data, self.inputs, uo, "input")
            yy = self._columns(data, self.outputs, yo, "output") if outputs else None
            return u, yy, dt, yo
        u = as_io_matrix(data, "u")
        if u.shape[1] == uo.size:  # a wrong column count: the caller's DataError, not numpy's
            u = u - uo
        dt = dt or self.dt
        if dt is None:
            raise ArgumentError(f"{why}: the model is continuous and the arrays carry no sample "
                                f"time", hint="give dt=… (s), or a trajectory")
        if outputs:
            if y is None:
                raise ArgumentError(f"{why}: give a trajectory, or the arrays u and y",
                                    hint="model.compare(data) or model.compare(u, y)")
            y = as_io_matrix(y, "y", u.shape[0])
            y = y - yo if y.shape[1] == yo.size else y
        return u, y, dt, yo

    def _state_space(self, dt):
        """(A, B, C, D, K) of the model's innovation form at ``dt`` (K = 0: output error)."""
        ss = self.to_ss(dt)
        K = getattr(self, "K", None)
        K = np.zeros((ss.n_states, ss.n_outputs)) if K is None else K
        return ss.A, ss.B, ss.C, ss.D, K

    # ------------------------------------------------------------------ the protocol
    @checks_arrays("simulate", with_y=False)
    def simulate(self, data, x0=None, dt: float | None = None) -> np.ndarray:
        """Free run (N, p) from ``x0`` (default: rest) on the inputs of ``data``: a trajectory
        or the inputs ``u`` (N, m) sampled every ``dt`` (default the model's); offsets applied,
        the result in the data's units (from rest: from the model's operating point). Arrays
        are the record's own values, not deviations (:data:`~.validation.OFFSETS_RULE`;
        deviations with far-off offsets warn)."""
        u, _, step, yo = self._io(data, None, "simulation of an identified model", False, dt)
        ss = self.to_ss(step)
        if u.shape[1] != ss.n_inputs:
            raise DataError(f"u: expected {ss.n_inputs} input columns, found {u.shape[1]}")
        ys = free_run(ss.A, ss.B, ss.C, ss.D, u, x0)
        return ys + yo

    @checks_arrays("compare")
    def compare(self, data, y=None, dt: float | None = None) -> ModelFit:
        """The validation fit (:data:`VALIDATION_FIT`) per output on a trajectory, or on
        the arrays ``u``, ``y`` (offsets applied as to a trajectory): free run from the initial
        state estimated by least squares. ``fit_percent`` is None per output for an unstable
        model (its free run, from rest, is ``simulated``). Arrays are the record's own values,
        not deviations (:data:`~.validation.OFFSETS_RULE`; deviations with far-off offsets
        warn)."""
        u, yy, dt, yo = self._io(data, y, "comparison of an identified model", dt=dt)
        return deviation_compare(self, u, yy, dt, yo)

    @checks_arrays("predict")
    def predict(self, data, y=None, horizon: int = 1, dt: float | None = None) -> np.ndarray:
        """``ŷ(t | t − horizon)`` (N, p) on a trajectory or the arrays ``u``, ``y``: the
        model's predictor (innovation gain K; without K the prediction is the free run) from
        the initial state estimated by least squares (:func:`k_step_prediction`)."""
        h = check_horizon(horizon)
        u, yy, dt, yo = self._io(data, y, "prediction of an identified model", dt=dt)
        yh = self._prediction(u, yy, dt, h)
        return yh + yo

    def _prediction(self, u, y, dt, horizon: int) -> np.ndarray:
        return k_step_prediction(*self._state_space(dt), u, y, horizon)

    @checks_arrays("residuals")
    def residuals(self, data, y=None, dt: float | None = None) -> np.ndarray:
        """One-step prediction errors ``y − ŷ(t | t − 1)`` (N, p) on a trajectory or on
        the arrays ``u``, ``y`` (:meth:`predict`; the record's own values, not deviations:
        :data:`~.validation.OFFSETS_RULE`)."""
        u, yy, dt, _ = self._io(data, y, "residuals of an identified model", dt=dt)
        return yy - k_step_prediction(*self._state_space(dt), u, yy, 1)

    @checks_arrays("validate")
    def validate(self, data, y=None, **kw):
        """Free-run and one-step validation of a one-input, one-output model on a separate
        record, a trajectory or the arrays ``u``, ``y`` (the model's offsets applied to either:
        the record's own values, not deviations, :data:`~.validation.OFFSETS_RULE`):
        :func:`gripkit.sysid.validate` (several channels: :meth:`compare` and
        :meth:`residuals`)."""
        return validate(self, data, y, **kw)

    @property
    def parameters(self) -> ParameterSet:
        """The entries of the system's arrays (``A_0_1`` for A[0, 1]; ``num``/``den`` of a
        transfer function) that the identification estimated (a non-zero tangent in the
        parameter covariance; every entry when the model has none), with their 1σ propagated
        from that covariance, each in its unit (:func:`_coefficient_unit`)."""
        s = self.system
        named = ([("A", s.A), ("B", s.B), ("C", s.C), ("D", s.D)] if isinstance(s, StateSpace)
                 else [("num", s.num), ("den", s.den)])
        unc = s.uncertainty
        src = f"identified ({self.structure})"
        params = []
        for k, (name, arr) in enumerate(named):
            flat = np.asarray(arr, dtype=np.float64).reshape(-1)
            std, free = None, np.ones(flat.size, dtype=bool)
            if unc is not None:
                T = np.asarray(unc.tangents[k]).reshape(len(unc.names), -1)
                std = np.sqrt(np.clip(np.einsum("ij,ik,kj->j", T, unc.covariance, T), 0, None))
                free = np.any(T != 0.0, axis=0)
            for j in np.flatnonzero(free):
                idx = np.unravel_index(j, np.shape(arr))
                unit, note = _coefficient_unit(s, name, tuple(int(i) for i in idx))
                params.append(Parameter(f"{name}_{'_'.join(map(str, idx))}", float(flat[j]), unit,
                                        f"entry {tuple(int(i) for i in idx)} of {name}{note}",
                                        source=src, std=None if std is None else float(std[j])))
        return ParameterSet(params, name=self.structure)

    def save(self, path) -> None:
        """Write the model file (JSON, :func:`model_document`); :func:`gripkit.sysid.load_model`
        gives the same type back."""
        write_document(model_document(self), path)


def _operating_point(value, n: int, name: str) -> tuple[float, ...]:
    """An operating point as a tuple of ``n`` floats: None or empty (zeros), one number (for a
    single channel only: one level for several channels is not assumed), or a sequence."""
    if value is None or (isinstance(value, (tuple, list)) and not value):
        return (0.0,) * n
    if isinstance(value, (str, bytes)):
        raise ModelError(f"{name}: expected numbers, one per channel, found text {value!r:.60}")
    if isinstance(value, (int, float, np.number)) and not isinstance(value, bool):
        if n != 1:
            raise ModelError(f"{name}: one number given for {n} channels; give one per channel")
        return (float(value),)
    try:
        return tuple(float(v) for v in np.ravel(np.asarray(value, dtype=np.float64)))
    except (TypeError, ValueError):
        raise ModelError(f"{name}: expected numbers, one per channel, "
                         f"found {value!r:.60}") from None


@dataclass(frozen=True, eq=False)
class LinearModel(IdentifiedLinearModel):
    """An identified linear model in state-space or transfer-function form (subspace, PEM,
    tfest, second-order step response); the protocol is :class:`IdentifiedLinearModel`'s.

    Attributes
    ----------
    system
        The :mod:`gripkit.lti` system (``StateSpace`` for subspace/PEM models, continuous
        ``TransferFunction`` for tfest and step), with names, units, dt and parameter covariance.
    structure
        ``'n4sid'``, ``'moesp'``, ``'cva'``, ``'pem-oe'``, ``'pem-innovation'``, ``'tfest'``,
        ``'step'`` (:func:`gripkit.sysid.physical.step_response.step_model`).
    K
        Innovation gain (n, p) or None (output-error form).
    x0
        Initial state estimated on the estimation data (n,) or None.
    noise_covariance
        Λ, covariance of the innovations (p, p), or None.
    u_offset, y_offset
        Operating point removed from each input / output before fitting.
    fit_percent
        Free-run fit per output on the estimation data (estimated x0).
    singular_values
        Of the weighted subspace matrix (subspace models), else None.
    data_file, data_hash
        Provenance of the estimation data (file name, sha256 of its bytes).
    info
        Method details (horizon, weighting, iterations, stability notes, ...).
    display_units
        ``{name: unit}``: the units the estimation data's file wrote inputs and outputs in, where
        not SI (``{"force": "mN"}``; :meth:`with_display_units`). The model computes in SI; the
        model file keeps these as ``display_unit`` and ``gripkit simulate`` writes in them.
    """

    system: LinearSystem
    structure: str
    K: np.ndarray | None = None
    x0: np.ndarray | None = None
    noise_covariance: np.ndarray | None = None
    u_offset: tuple[float, ...] | None = None
    y_offset: tuple[float, ...] | None = None
    fit_percent: list[float] | None = None
    singular_values: np.ndarray | None = None
    n_samples: int | None = None
    data_file: str | None = None
    data_hash: str | None = None
    info: dict = field(default_factory=dict)
    display_units: dict = field(default_factory=dict)

    def __post_init__(self):
        s = self.system
        if not isinstance(s, LinearSystem):
            raise ModelError(f"system: expected a gripkit.lti system, found {type(s).__name__}")
        set_ = object.__setattr__
        for name, n in (("u_offset", s.n_inputs), ("y_offset", s.n_outputs)):
            set_(self, name, _operating_point(getattr(self, name), n, name))
        if len(self.u_offset) != s.n_inputs or len(self.y_offset) != s.n_outputs:
            raise ModelError(f"offsets: expected {s.n_inputs} input and {s.n_outputs} output "
                             "offsets, found "
                             f"{len(self.u_offset)} and {len(self.y_offset)}")
        if self.K is not None:
            K = np.array(self.K, dtype=np.float64).reshape(-1, s.n_outputs)
            if not isinstance(s, StateSpace) or K.shape != (s.n_states, s.n_outputs):
                raise ModelError(f"K: expected shape (n_states, {s.n_outputs}) on a StateSpace, "
                                 f"found {K.shape}")
            set_(self, "K", K)
        set_(self, "display_units", _checked_display_units(self, dict(self.display_units or {})))

    # ------------------------------------------------------------------ views
    @property
    def dt(self) -> float | None:
        return self.system.dt

    def replace(self, **changes) -> LinearModel:
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict:
        """JSON-ready summary (arrays as lists)."""
        ss = self.system.to_ss(minimal=False)
        out = {"structure": self.structure, "inputs": list(self.inputs),
               "outputs": list(self.outputs),
               "dt": self.dt, "order": ss.n_states, "stable": self.stable,
               "fit_percent": self.fit_percent}
        if isinstance(self.system, StateSpace):
            out.update(A=ss.A, B=ss.B, C=ss.C, D=ss.D,
                       K=np.zeros((ss.n_states, ss.n_outputs)) if self.K is None else self.K,
                       x0=self.x0, noise_covariance=self.noise_covariance)
        if isinstance(self.system, TransferFunction):
            out.update(num=self.system.num, den=self.system.den)
        if self.singular_values is not None:
            out["singular_values"] = self.singular_values
        p, cov = (self.system.pole_covariance() if self.system.uncertainty is not None
                  else (self.system.poles(), None))
        out["poles"] = [[float(z.real), float(z.imag)] for z in p]
        if cov is not None:
            out["poles_std"] = [[float(np.sqrt(c[0, 0])), float(np.sqrt(c[1, 1]))] for c in cov]
        out["info"] = self.info
        return out

    def __repr__(self) -> str:
        return (f"LinearModel({self.structure}, order={self.order}, inputs={list(self.inputs)}, "
                f"outputs={list(self.outputs)}, dt={self.dt})")


def model_document(model: IdentifiedLinearModel) -> dict:
    """The JSON document of ``model`` (schema ``gripkit.linear-model``, :mod:`.model_file`)::

        {"schema": "gripkit.linear-model", "schema_version": 2, "gripkit_version": "0.1.0",
         "structure": "pem-innovation", "kind": "ss" | "tf", "dt": 0.01 | null,
         "inputs":  [{"name": "current", "unit": "A", "offset": 0.85}, ...],
         "outputs": [{"name": "force", "unit": "N", "offset": 0.0, "display_unit": "mN"}, ...],
                              (display_unit: the unit the estimation data wrote the column in,
                              only where it is not SI; offsets and the system stay SI)
         "system": {…},       the lti system's own description (LinearSystem.to_dict: arrays,
                              names, units, dt, covariance with its tangents)
         "innovation": {"K": … | null, "x0": … | null, "noise_covariance": … | null},
         "fit_percent": […], "singular_values": […] | null, "n_samples": N, "info": {…},
         "data": {"file": "run1.csv", "sha256": "…"} | null,
         "polynomial": {…},   only for an ARX/ARMAX/OE model: its coefficients, covariance and
                              diagnostics (PolynomialModel.polynomial_section), from which
                              load_model builds the PolynomialModel again
         "content_sha256": "…"}

    A :class:`~gripkit.sysid.PolynomialModel` writes its system part as the discrete transfer
    function B/(A F) (:meth:`~gripkit.sysid.PolynomialModel.linear_record`), so that a reader of
    the schema that knows no polynomials still finds the system. Version 1 (no ``polynomial``
    section; an ARX/ARMAX/OE model kept its coefficients in ``info``) is read as well
    (:func:`~gripkit.sysid.linear.polynomial.load_linear_model`).
    """
    poly = None
    if not isinstance(model, LinearModel):
        poly, model = model.polynomial_section(), model.linear_record()
    s = model.system
    doc = {"schema": SCHEMA, "schema_version": SCHEMA_VERSION, "gripkit_version": __version__,
           "structure": model.structure, "kind": "ss" if isinstance(s, StateSpace) else "tf",
           "dt": s.dt,
           "inputs": [_entry(model, n, u, o)
                      for n, u, o in zip(s.inputs, s.input_units, model.u_offset)],
           "outputs": [_entry(model, n, u, o)
                       for n, u, o in zip(s.outputs, s.output_units, model.y_offset)]}
    doc["system"] = s.to_dict()
    doc["innovation"] = {"K": model.K, "x0": model.x0, "noise_covariance": model.noise_covariance}
    doc.update(fit_percent=model.fit_percent, singular_values=model.singular_values,
               n_samples=model.n_samples,
               info=model.info,
               data=None if model.data_file is None else {"file": model.data_file,
                                                          "sha256": model.data_hash})
    if poly is not None:
        doc["polynomial"] = poly
    return doc


def _entry(model: LinearModel, name: str, unit, offset: float) -> dict:
    """An input or output of the model document, with its ``display_unit`` when it has one."""
    entry = {"name": name, "unit": unit, "offset": offset}
    if name in model.display_units:
        entry["display_unit"] = model.display_units[name]
    return entry


def _arr(x, name, where):
    try:
        return np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise ModelError(f"model file {where}: field {name!r} is not an array of numbers") from None


def read_linear_model(path) -> tuple[dict, LinearModel, str]:
    """``(document, system part, where)`` of a model file written by ``model.save(path)``; the
    reader of the schema, which also builds a :class:`~gripkit.sysid.PolynomialModel` from the
    ``polynomial`` section, is :func:`gripkit.sysid.linear.polynomial.load_linear_model`.

    Raises ModelError for a file that is not a gripkit model (wrong ``schema``), of a newer
    ``schema_version``, or with missing fields; warns (DataWarning) when the content digest does
    not match (the file was edited after it was saved).

    Examples
    --------
    >>> import tempfile, os
    >>> from gripkit.lti import StateSpace
    >>> from gripkit.sysid import LinearModel, load_model  # reads any model file
    >>> m = LinearModel(StateSpace([[0.5]], [[1.0]], [[1.0]], dt=0.1, inputs="V", outputs="x"),
    ...                 "n4sid")
    >>> p = os.path.join(tempfile.mkdtemp(), "m.json"); m.save(p)
    >>> load_model(p).system.A.tolist(), load_model(p).inputs
    ([[0.5]], ('V',))
    """
    return _read(path)


def _read(path):
    doc = read_document(path)
    where = repr(str(path))
    try:
        ins, outs = doc["inputs"], doc["outputs"]
        system = LinearSystem.from_dict(doc["system"])
        if list(system.inputs) != [d["name"]
                                   for d in ins] or list(system.outputs) != [d["name"]
                                                                             for d in outs]:
            raise ModelError(f"model file {where}: the inputs/outputs lists disagree with "
                             "the system's names")
        _check_copies(doc, system, where)
        inn = doc.get("innovation") or {}
        K, x0, lam = (None if inn.get(k) is None else _arr(inn[k], k, where)
                      for k in ("K", "x0", "noise_covariance"))
        data = doc.get("data") or {}
        sv = doc.get("singular_values")
        lm = LinearModel(system, doc["structure"], K=K, x0=x0, noise_covariance=lam,
                           u_offset=_offsets(ins, "inputs", where),
                           y_offset=_offsets(outs, "outputs", where),
                           fit_percent=doc.get("fit_percent"),
                           singular_values=None if sv is None else np.asarray(sv),
                           n_samples=doc.get("n_samples"), data_file=data.get("file"),
                           data_hash=data.get("sha256"),
                           info=doc.get("info") or {},
                           display_units={d["name"]: d["display_unit"] for d in (*ins, *outs)
                                          if d.get("display_unit") is not None})
        return doc, lm, where
    except (KeyError, TypeError, AttributeError) as exc:
        raise ModelError(f"model file {where}: a required field is missing or malformed ({exc})",
                         hint="regenerate the file with gripkit identify --out") from None
    except ModelError as exc:
        if not exc.message.startswith("display unit"):
            raise
        raise ModelError(f"model file {where}: {exc.message}", hint=exc.hint) from None


def malformed(where: str, what: str) -> ModelError:
    """The ModelError of a model file (``where``: its quoted path) whose field is wrong or whose
    two copies of a value disagree (``what`` names the fields and what was found)."""
    return ModelError(f"model file {where}: malformed: {what}",
                      hint="regenerate the file with gripkit identify --out (a hand edit must "
                           "change every copy of a value alike)")


def _offsets(entries, kind: str, where: str) -> list[float]:
    """The ``offset`` of each entry of the document's ``inputs`` or ``outputs`` (``kind``): a
    finite number each, else a malformed-file ModelError naming the entry."""
    out = []
    for i, d in enumerate(entries):
        v = d["offset"]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v):
            raise malformed(where, f"'{kind}[{i}].offset' must be a finite number, found "
                                   f"{str(v)[:40]!r}")
        out.append(float(v))
    return out


def _same_dt(a, b) -> bool:
    """Two sample times (s) alike: both continuous (None or 0), or equal numbers to 10⁻¹²."""
    if a in (None, 0) or b in (None, 0):
        return a in (None, 0) and b in (None, 0) and not isinstance(a, bool)
    return (isinstance(a, (int, float)) and not isinstance(a, bool)
            and abs(a - b) <= 1e-12 * abs(b))


def _check_copies(doc: dict, system: LinearSystem, where: str) -> None:
    """The document's top-level ``dt`` and the ``unit`` of its ``inputs``/``outputs`` entries,
    copies of the system's own (the model runs on the system's), must agree with them: a
    malformed-file ModelError naming both fields otherwise."""
    top = doc.get("dt", system.dt)
    if not _same_dt(top, system.dt):
        raise malformed(where, f"'dt' is {str(top)[:40]} but 'system.dt' is {system.dt}; "
                               "they are two copies of the sample time and must agree")
    for kind, units in (("inputs", system.input_units), ("outputs", system.output_units)):
        for i, (d, u) in enumerate(zip(doc[kind], units)):
            if (d.get("unit") or "") != (u or ""):
                raise malformed(where, f"'{kind}[{i}].unit' is {str(d.get('unit'))[:40]!r} but "
                                       f"'system.{kind[:-1]}_units[{i}]' is {u!r}; they are two "
                                       "copies of the unit and must agree")


def polynomial_document(doc: dict) -> bool:
    """A version-1 file of an ARX/ARMAX/OE model (its coefficients in ``info``)."""
    info = doc.get("info") or {}
    return (doc.get("schema_version") == 1 and doc.get("structure") in ("arx", "armax", "oe")
            and all(k in info for k in ("A", "B", "C", "F", "nk")))
