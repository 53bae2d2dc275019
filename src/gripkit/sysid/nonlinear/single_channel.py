"""What the single-input single-output nonlinear families share about their records: the
protocol's channel names (:class:`SingleChannel`), the fields of a model fitted on its free run
and the limits beyond which that run counts as diverged (:class:`FreeRunModel`; the names and
units of the columns written and read by :meth:`SingleChannel.channel_document` and
:func:`channel_fields`), the checks of one signal (:func:`one_signal`, :func:`not_constant`)
and the free-run fit
``100 (1 − ‖y − ŷ‖/‖y − ȳ‖)`` (:func:`fit_percent`, the definition of
:mod:`gripkit.sysid.model_protocol`), each error message headed by the family's name."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...arguments import real_array
from ...errors import DataError
from ..model_protocol import column_in_unit
from .nonlinear_model import NonlinearModel

__all__ = ["DIVERGENCE_FACTOR", "FreeRunModel", "SingleChannel", "channel_fields", "fit_percent",
           "not_constant", "one_signal"]

#: a free run beyond this many times the estimation output's range (about its middle) counts as
#: diverged
DIVERGENCE_FACTOR = 1e3


class SingleChannel(NonlinearModel):
    """The protocol's ``inputs`` and ``outputs`` of a model of one input and one output column,
    named by its attributes ``input_name`` and ``output_name``, and their SI units
    ``input_units`` and ``output_units`` (one-element tuples, as every family has them) from its
    attributes ``input_unit`` and ``output_unit`` (and, as every
    :class:`~.nonlinear_model.NonlinearModel`, no linear system to convert)."""

    input_name: str
    output_name: str
    input_unit: str
    output_unit: str

    @property
    def inputs(self) -> tuple[str, ...]:
        return (self.input_name,)

    @property
    def outputs(self) -> tuple[str, ...]:
        return (self.output_name,)

    @property
    def input_units(self) -> tuple[str, ...]:
        return (self.input_unit or "1",)

    @property
    def output_units(self) -> tuple[str, ...]:
        return (self.output_unit or "1",)

    def _column(self, data, role: str) -> np.ndarray:
        """The model's ``role`` ('input' or 'output') column of the trajectory ``data`` in the
        model's unit, as a linear model reads it (:func:`~gripkit.sysid.model_protocol
        .column_in_unit`: converted from another unit of the same dimension, a DataError for
        another physical quantity)."""
        name, unit = ((self.input_name, self.input_unit) if role == "input"
                      else (self.output_name, self.output_unit))
        return column_in_unit(data, name, unit, role)

    def channel_document(self) -> dict:
        """The column names and units as the model files write them: ``input_name``,
        ``output_name``, ``input_unit``, ``output_unit`` (read back by :func:`channel_fields`)."""
        return dict(input_name=self.input_name, output_name=self.output_name,
                    input_unit=self.input_unit, output_unit=self.output_unit)


@dataclass(kw_only=True)
class FreeRunModel(SingleChannel):
    """The fields (keyword-only) of a single-channel model fitted on its free run: sample time
    ``dt`` (s), ``y_range`` (the estimation output's (min, max)), ``fit_percent`` (free run on
    the estimation record), ``validation_fit_percent`` (on ``validate=``; None when diverged or
    none given), ``criterion`` (how the structure was chosen), the column names and their units
    (those of the record fitted, '1' where it had none)."""

    dt: float = 1.0
    y_range: tuple = (-np.inf, np.inf)
    fit_percent: float | None = None
    validation_fit_percent: float | None = None
    criterion: str = ""
    input_name: str = "u"
    output_name: str = "y"
    input_unit: str = "1"
    output_unit: str = "1"

    def _limits(self) -> tuple[float, float]:
        """The band of a free run that has not diverged: :data:`DIVERGENCE_FACTOR` times the
        span of ``y_range`` either side of its middle."""
        lo, hi = self.y_range
        span = max(hi - lo, 1e-12)
        mid = 0.5 * (hi + lo)
        return mid - DIVERGENCE_FACTOR * span, mid + DIVERGENCE_FACTOR * span


def channel_fields(doc: dict) -> dict:
    """The column names and units of a model file document (:meth:`SingleChannel.channel_document`),
    each one missing at its default ('u', 'y', and '1' for the units of a file written before
    the units were)."""
    return dict(input_name=str(doc.get("input_name", "u")),
                output_name=str(doc.get("output_name", "y")),
                input_unit=str(doc.get("input_unit", "1")),
                output_unit=str(doc.get("output_unit", "1")))


def one_signal(x, name: str, family: str) -> np.ndarray:
    """``x`` as one finite float signal (N,) (a column (N, 1) or row (1, N) is flattened);
    a DataError headed ``family`` names ``name`` otherwise (complex numbers, no samples, NaN or
    ±inf)."""
    a = real_array(x, f"{family}: {name}")
    if a.ndim == 2 and 1 in a.shape:
        a = a.ravel()
    if a.ndim != 1:
        raise DataError(f"{family}: {name} must be one signal (shape (N,)), found shape "
                        f"{a.shape}; pass one column")
    if a.size == 0:
        raise DataError(f"{family}: {name} holds no samples (shape {np.shape(x)})")
    if not np.all(np.isfinite(a)):
        raise DataError(f"{family}: {name} has {int(np.sum(~np.isfinite(a)))} non-finite "
                        "samples; remove or interpolate them first")
    return a


def not_constant(x: np.ndarray, what: str, family: str, fix: str) -> None:
    """A DataError headed ``family`` when the signal ``x`` (``what``: "the output") is constant:
    its value, its length and ``fix`` (why it cannot be fitted, what to do)."""
    if np.ptp(x) == 0.0:
        raise DataError(f"{family}: {what} is constant ({x[0]:g} in all {len(x)} samples); {fix}")


def fit_percent(y: np.ndarray, yhat: np.ndarray, family: str) -> float:
    """``100 (1 − ‖y − ŷ‖/‖y − ȳ‖)``; a DataError headed ``family`` for a constant ``y``."""
    den = float(np.linalg.norm(y - y.mean()))
    if den == 0.0:
        raise DataError(f"{family}: the fit is undefined for a constant output (‖y − ȳ‖ = 0)")
    return 100.0 * (1.0 - float(np.linalg.norm(y - yhat)) / den)
