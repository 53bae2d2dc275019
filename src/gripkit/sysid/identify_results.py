"""What follows an identification: the one validation of a model on a second record
(:func:`validate_model` → :class:`ValidationResult`). The ``gripkit identify`` commands call these
after
:func:`gripkit.sysid.identify`; a Python session calls the same.

The validation fit is the one of :data:`gripkit.sysid.linear.linear_model.VALIDATION_FIT` (free
run from the model's operating point, its stored offsets; initial state estimated), the number
``gripkit compare`` and the model report give; a SISO polynomial model (ARX, ARMAX, OE) adds its
one-step prediction fit and the residual tests (:func:`gripkit.sysid.validate`) on the same
deviations; a NARX model is judged by its own free run (its ``compare``, with its definition).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ArgumentError, DataError
from ..signals.trajectory import Trajectory
from .io_data import IOData, provenance_of
from .linear.linear_model import LinearModel
from .linear.polynomial import PolynomialModel

__all__ = ["ValidationResult", "validate_model"]


@dataclass(frozen=True)
class ValidationResult:
    """The validation of one model on one record, built from the
    :class:`~gripkit.sysid.ModelFit` of ``model.compare(data)``.

    ``fit_percent``: that free-run fit (%), a number for a SISO polynomial or NARX model, else a
    list per output; None for a model whose free run diverges. ``definition``: how it is
    computed (the ModelFit's). ``data_file``: the record's file name (None for data built in
    memory).
    ``initial_state``: 'estimated' (least squares) or 'measured' (NARX: its first outputs).
    ``one_step``: the :class:`~gripkit.sysid.Validation` of a SISO polynomial model (one-step
    fit, residual tests; its free-run fit is ``model.compare`` of the same deviations), else
    None."""

    fit_percent: float | list[float] | None
    definition: str
    data_file: str | None = None
    one_step: object = None
    initial_state: str = "estimated"

    def to_dict(self) -> dict:
        """The JSON ``validation`` object of ``gripkit identify``."""
        d = {} if self.one_step is None else {**self.one_step.to_dict(), "initial": "estimated"}
        d.update(fit_percent=self.fit_percent, data=self.data_file,
                 initial_state=self.initial_state, definition=self.definition)
        return d


def validate_model(model, data: Trajectory, *, detrend: str = "mean") -> ValidationResult:
    """Validate ``model`` (a :class:`~gripkit.sysid.LinearModel`,
    :class:`~gripkit.sysid.PolynomialModel` or :class:`~gripkit.sysid.NARXModel`) on the
    trajectory ``data``, its columns found by the model's names. ``detrend='linear'`` (a SISO
    polynomial model fitted on linearly detrended data): the one-step fit and residual tests take
    the record's own line off, as the estimation did."""
    if not isinstance(data, Trajectory):
        raise ArgumentError(f"validate_model(): data: expected a gripkit Trajectory, found "
                            f"{type(data).__name__}", hint="use gripkit.io.load(path)")
    name = provenance_of(data)[0]
    dt, mdt = data.require_uniform(why="validation"), getattr(model, "dt", None)
    if mdt and abs(dt - mdt) > 1e-6 * mdt:  # a discrete model (a continuous one has dt None)
        where = "" if name is None else f" {name!r}"
        raise DataError(f"validation data{where} are sampled at {1 / dt:g} Hz, the model at "
                        f"{1 / mdt:g} Hz",
                        hint="resample the validation record to the model's interval")
    if hasattr(model, "max_lag"):  # NARX: the data as they are, its constant term the offset
        fitted = model.compare(np.asarray(data[model.input_name]),
                               np.asarray(data[model.output_name]))
        return ValidationResult(fitted.fit_percent[0], fitted.definition, name,
                                initial_state="measured")
    if isinstance(model, LinearModel) or getattr(model, "multivariable", False):
        return ValidationResult(*_free_run_fit(model, data), name)
    if not isinstance(model, PolynomialModel):
        raise ArgumentError(f"validate_model(): expected a LinearModel, PolynomialModel or "
                            f"NARXModel, found {type(model).__name__}")
    vfit, definition = _free_run_fit(model, data)
    vd = IOData.from_trajectory(data, model.input_name, model.output_name,
                                detrend="linear" if detrend == "linear" else "none",
                                why="validation", checks=False)
    if detrend == "linear":  # the record's own line off: no operating point left to remove
        model = model.replace(u_offset=0.0, y_offset=0.0)
    return ValidationResult(None if vfit is None else vfit[0], definition, name,
                            model.validate(vd.u1, vd.y1))


def _free_run_fit(model, data) -> tuple[list[float] | None, str]:
    """The one validation fit per output and its definition, those of the
    :class:`~gripkit.sysid.ModelFit` of ``model.compare(data)``; the fit None for an unstable
    model, whose free run diverges."""
    fitted = model.compare(data)
    return (fitted.fit_percent if model.stable else None), fitted.definition
