"""What every nonlinear family answers to the names of the model protocol
(:mod:`gripkit.sysid.model_protocol`) that a linear model answers with its system.

:class:`NonlinearModel`, the base of every nonlinear model class (through
:class:`~.single_channel.SingleChannel` or directly): ``to_ss()``, ``to_tf()`` and
``to_control()`` raise a ModelError that names the family (``_family``) and says where a linear
view is (``_linear_hint``): a nonlinear model has no linear system to convert. Every family's
``simulate(data, x0=None)`` takes ``x0`` where it has an initial state (NARX: its first
``max_lag`` outputs; nonlinear state space: x(0); the Bouc-Wen oscillator: (x, ẋ, z)); the
others refuse a given one with an ArgumentError saying what their free run starts from
(``_refuse_x0``). Arrays given to a nonlinear model are the record's values (no offset is
removed; the nonlinear state space's ``u_offset``/``y_offset`` normalise inside the model).
A trajectory given to a rate-dependent family (every one but the Bouc-Wen actuator form and
Prandtl–Ishlinskii) must be sampled at the model's ``dt``: ``_check_rate`` refuses another
interval with the linear models' DataError
(:func:`~gripkit.sysid.model_protocol.check_sample_time`); arrays carry no time and are taken
as the model's samples.

:class:`OutputErrorPrediction`, the ``predict`` and ``residuals`` of the output-error families
(Hammerstein–Wiener, nonlinear state space, hysteresis): their noise enters at the output, so
the k-step predictor ``ŷ(t | t − k)`` is the free run for every horizon k ≥ 1 (Ljung,
System Identification, 1999, §4.2: the output-error predictor uses no past outputs), started as
``compare`` starts it (from the initial state it fits to the record, where it fits one), and
the residuals are ``y − ŷ`` over every sample.
"""

from __future__ import annotations

import numpy as np

from ...errors import ArgumentError, ModelError
from ...signals.trajectory import Trajectory
from ..linear.validation import validate
from ..model_protocol import ReportMixin, check_horizon, check_sample_time

__all__ = ["NonlinearModel", "OutputErrorPrediction"]

#: the identification methods that give a linear model, named in the hints
LINEAR_METHODS = "identify(data, 'arx', …) or identify(data, 'ss', …)"


class NonlinearModel(ReportMixin):
    """The protocol's conversions of a nonlinear model: each raises a ModelError headed by the
    family (``_family``: "a NARX model") with the class's ``_linear_hint``."""

    _family = "a nonlinear model"
    _linear_hint = f"identify a linear model ({LINEAR_METHODS}) for a linear approximation"

    #: False for a rate-independent family (Bouc-Wen actuator form, Prandtl–Ishlinskii): its
    #: output depends on the path of the input only, so data at any sample time fit it
    _rate_dependent = True

    def _check_dt(self, dt: float) -> None:
        """The linear models' check (:func:`~gripkit.sysid.model_protocol.check_sample_time`)
        of data sampled every ``dt`` s against the model's ``dt``: a DataError when they
        differ (none for a rate-independent family)."""
        mdt = getattr(self, "dt", None)
        if self._rate_dependent and mdt is not None:
            check_sample_time(float(dt), float(mdt))

    def _check_rate(self, data, why: str) -> None:
        """:meth:`_check_dt` of a :class:`~gripkit.signals.Trajectory` ``data`` (uniformly
        sampled, else a DataError naming ``why``); arrays carry no sample time and are taken as
        the model's samples."""
        if isinstance(data, Trajectory) and data.n > 1 and self._rate_dependent:
            self._check_dt(data.require_uniform(why=why))

    def _no_linear_system(self, name: str) -> ModelError:
        return ModelError(f"{name}: {self._family} has no linear system to convert (only "
                          "ARX, ARMAX, OE, state-space and transfer-function models have one)",
                          hint=self._linear_hint)

    def _refuse_x0(self, x0, starts: str, hint: str) -> None:
        """An ArgumentError for a given ``x0`` of a family without a settable initial state:
        ``starts`` says what its free run starts from."""
        if x0 is not None:
            raise ArgumentError(f"{self.structure}.simulate: x0: {self._family} has no settable "
                                f"initial state; its free run starts from {starts} (found x0 of "
                                f"shape {np.shape(x0)})", hint=hint)

    @property
    def fit_percent_definition(self) -> str:
        """What ``fit_percent`` is: the fit of :meth:`compare` (``fit_definition``, a free run)
        on the estimation data, as a state-space model's."""
        return f"{self.fit_definition}, on the estimation data"

    @property
    def simulation_fit_percent(self) -> list | None:
        """The free-run fit on the estimation data as a list per output, as every family has it
        (a linear model's: :attr:`IdentifiedLinearModel.simulation_fit_percent`): the figure to
        rank models of different families by. A nonlinear model's ``fit_percent`` is that fit."""
        fit = getattr(self, "fit_percent", None)
        if fit is None:
            return None
        return [None if f is None else float(f) for f in np.ravel(np.asarray(fit, dtype=object))]

    def validate(self, data, y=None, **kw):
        """Refused with a ModelError that names what to use: the residual-test report
        (:func:`gripkit.sysid.validate`) is a linear model's; a nonlinear model's fit on a
        separate record is :meth:`compare`, its prediction errors :meth:`residuals`."""
        return validate(self, data, y, **kw)

    def to_ss(self, dt: float | None = None):
        """Refused: a ModelError (module docstring)."""
        raise self._no_linear_system("to_ss")

    def to_tf(self):
        """Refused: a ModelError (module docstring)."""
        raise self._no_linear_system("to_tf")

    def to_control(self):
        """Refused: a ModelError (module docstring)."""
        raise self._no_linear_system("to_control")


class OutputErrorPrediction:
    """``predict`` and ``residuals`` of an output-error model (module docstring) from its
    ``compare(data, y)``; a family gives ``_measured(data, y)`` (the record's measured output,
    as its ``compare`` reads it). ``_signal_arrays``: arrays in, one signal (N,) out (the
    single-channel families; else (N, p), as the state-space models)."""

    _signal_arrays = True

    def _need_output(self, data, y, what: str) -> None:
        """An ArgumentError for one input signal without its measured output."""
        if y is None and not isinstance(data, (Trajectory, tuple, list)) and np.ndim(data) == 1:
            raise ArgumentError(f"{self.structure}.{what}: the record has no measured output "
                                f"(one signal of shape {np.shape(data)} given)",
                                hint=f"{what}(trajectory) or {what}(u, y); simulate(u) runs "
                                     "the model on an input alone")

    def _shaped(self, data, a: np.ndarray) -> np.ndarray:
        if self._signal_arrays and not isinstance(data, Trajectory):
            return a[:, 0]
        return a

    def predict(self, data, y=None, horizon: int = 1) -> np.ndarray:
        """``ŷ(t | t − horizon)`` on a trajectory with the model's columns ((N, p), its units)
        or on the arrays ``u``, ``y`` ((N,) for one output): the free run that ``compare``
        scores, for every horizon ≥ 1 (an output-error predictor uses no past outputs; module
        docstring). NaN from where the run diverges, after a StabilityWarning."""
        check_horizon(horizon)
        self._need_output(data, y, "predict")
        return self._shaped(data, self.compare(data, y).simulated)

    def residuals(self, data, y=None) -> np.ndarray:
        """Prediction errors ``y − ŷ`` (:meth:`predict`) over every sample: (N, p) for a
        trajectory, (N,) for the arrays of a single-channel model."""
        self._need_output(data, y, "residuals")
        measured = np.asarray(self._measured(data, y), dtype=np.float64)
        predicted = self.compare(data, y).simulated
        return self._shaped(data, measured.reshape(predicted.shape) - predicted)
