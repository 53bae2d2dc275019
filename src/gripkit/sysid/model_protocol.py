"""The one protocol of an identified model, and the one door that reads any model file.

Every identified model (linear: ARX, ARMAX, OE, state space, transfer function; nonlinear: NARX,
Hammerstein–Wiener, nonlinear state space, hysteresis) is an object with these names, so that
``gripkit simulate``, ``compare``, ``report`` and ``export`` take any model file::

    m.structure                  # 'arx', 'n4sid', 'narx', 'hw', ...
    m.inputs, m.outputs          # column names, in the model's order
    m.dt                         # sample time [s] (None for a continuous-time model)
    m.parameters                 # ParameterSet: every free parameter with its unit and 1σ
    m.fit_definition             # how compare scores
    m.fit_percent_definition     # what m.fit_percent is (ARX/ARMAX: the one-step prediction fit)
    m.simulation_fit_percent     # compare's free-run fit on the estimation data, list per output
    m.simulate(data, x0=None)    # free run on data's input columns -> (N, ny), in the file's units
    m.predict(data, horizon=1)   # ŷ(t | t − horizon) on a record with the output columns
    m.compare(data)              # ModelFit: the fit (%) per output by m.fit_definition
    m.residuals(data)            # y − ŷ of predict
    m.save(path)                 # atomic JSON; load_model(path) gives the same type back
    m.report(data, out)          # out/index.html: the HTML report gripkit report writes
    m.to_ss(), m.to_tf(), m.to_control()   # the linear system (lti, python-control)

``predict`` is each family's own predictor: the innovation-form predictor of a linear model
(:class:`~gripkit.sysid.linear.linear_model.IdentifiedLinearModel`: state space, transfer
function, ARX/ARMAX/OE), the one-step predictor of NARX (horizon 1 only), and for the
output-error families (Hammerstein–Wiener, nonlinear state space, hysteresis) the free run that
``compare`` scores, whatever the horizon (:mod:`gripkit.sysid.nonlinear.nonlinear_model`).
``to_ss``, ``to_tf`` and ``to_control`` convert a linear model; a nonlinear one has no linear
system and raises a ModelError naming its family and where a linear view is. Optional:
``m.initial_state``, how ``compare`` starts the free run (``'estimated'`` for the linear
models, ``'measured'`` for NARX; ``gripkit compare --json`` states it when the model has it), and
``m.display_units`` for :func:`simulated_trajectory`. Every family has ``m.input_units`` and
``m.output_units``: the SI unit of each input and output column (tuples, one per channel).

``data`` is a Trajectory (columns by name, units converted) or arrays, for every family the
record's values in the units of the data the model was fitted on: a linear model removes its
offsets (``u_offset``, ``y_offset``, the operating point ``identify`` detrended; zero for a model
fitted on arrays) from either and adds them back to its outputs (NLSS's ``u_offset``/``y_offset``
normalise internally). So ``sysid.compare(m, u, y)`` is ``m.compare(u, y)`` for every family, and
equals ``m.compare(trajectory)`` on that trajectory's columns. ``x0`` where the family has an
initial state: a linear model's state, NARX's first ``max_lag`` outputs, NLSS's x(0), the Bouc-Wen
oscillator's (x, ẋ, z); Hammerstein–Wiener (the steady state of its initial input), Bouc-Wen
(h = 0) and Prandtl–Ishlinskii (relaxed plays) refuse a given ``x0`` with an ArgumentError
saying what their free run starts from.

``report`` is written once, on :class:`ReportMixin`, the base of every model class: it names
the page its family gets (``_report_page``: ``'linear'``, the poles, Bode with σ and innovation
residuals of :mod:`gripkit.sysid.model_report`; ``'protocol'``, the page of any family built on
these names alone, :mod:`gripkit.sysid.protocol_report`) and finds the writer through the table
:data:`MODEL_REPORTS` (page → module of this package and the writer's name), imported when a
report is written. So the report modules, which import the linear models, stay above every
model module, and no model module imports them: the table names them, as :data:`MODEL_FILES`
names the readers.

A model family registers its JSON schema in :data:`MODEL_FILES` (schema → module of this package
and the name of its reader); `load_model` reads the schema and hands the file to that reader.
A new family goes into ``sysid/nonlinear/`` (or ``sysid/linear/``), derives its model class from
:class:`ReportMixin` and adds one line here.
"""

from __future__ import annotations

import importlib
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol, runtime_checkable

import numpy as np

from ..errors import (ArgumentError, DataError, DataWarning, ModelError, ParameterError, PathError,
                      emit_warning)
from ..units import convert, dimension_of, same_dimension
from ..signals.trajectory import Trajectory

__all__ = ["IdentifiedModel", "ModelFit", "MODEL_FILES", "MODEL_REPORTS", "ReportMixin",
           "check_horizon", "check_sample_time", "column_in_unit", "file_schema", "load_model",
           "report_record", "simulated_trajectory"]


def column_in_unit(data, name: str, unit: str | None, what: str) -> np.ndarray:
    """Column ``name`` of ``data`` in the model's ``unit``: converted when the data give another
    unit of the same dimension, a :class:`DataError` when they give another dimension (a model of
    u [A] compared with u [V]). Either side without a unit ('1' or none) is taken as it is."""
    x = np.asarray(data[name], dtype=np.float64)
    have = data.unit(name)
    if unit in (None, "", "1") or have in (None, "", "1") or have == unit:
        return x
    try:
        same = same_dimension(have, unit)
    except ParameterError:  # a unit that is not one (a hand-edited or foreign model file)
        emit_warning(f"data: cannot compare the units of the {what} column {name!r}: {have!r} in "
                     f"the data, {unit!r} in the model, and one is not a unit gripkit can read; "
                     f"the values are taken as they are", DataWarning)
        return x
    if not same:
        raise DataError(f"data: {what} column {name!r} is in {have!r} (dimension "
                        f"{dimension_of(have)}), but the model's {what} {name!r} is in {unit!r} "
                        f"(dimension {dimension_of(unit)}): a different physical quantity",
                        hint="check that the record holds the signals the model was identified "
                             "from")
    return convert(x, have, unit)


def check_horizon(horizon) -> int:
    """``horizon`` of ``predict`` as a whole number of samples ≥ 1 (every family takes it so)."""
    if isinstance(horizon, bool) or not isinstance(horizon, (int, np.integer)) or horizon < 1:
        raise ArgumentError(f"horizon: expected a whole number of samples ≥ 1, found {horizon!r}",
                            hint="horizon=1 is the one-step-ahead prediction")
    return int(horizon)


def check_sample_time(dt: float, model_dt: float) -> None:
    """The check of every discrete model, linear and nonlinear, that runs on its own samples:
    data sampled every ``dt`` s fit a model sampled every ``model_dt`` s only at the same
    interval; a DataError naming both intervals otherwise. Same means within 10⁻⁶ relative: an
    identified model keeps its interval to 9 significant digits (file time stamps carry rounding
    noise), up to 5·10⁻⁹ from the record's own, and a rate that is really another differs by far
    more."""
    if abs(dt - model_dt) > 1e-6 * model_dt:
        raise DataError(f"data: sampled every {dt:g} s, the model every {model_dt:g} s",
                        hint="resample the data to the model's rate")


@dataclass(frozen=True)
class ModelFit:
    """The validation fit of a model on one record: ``fit_percent`` per output (None where the
    free run diverged), the free run ``simulated`` (N, ny) and the ``definition`` of the fit."""

    outputs: tuple[str, ...]
    fit_percent: list[float | None]
    simulated: np.ndarray
    definition: str


@runtime_checkable
class IdentifiedModel(Protocol):
    """What every identified model offers, linear and nonlinear (see the module docstring; a
    nonlinear model's ``to_*`` raise a ModelError). Arrays: the record's values, in the units of
    the data the model was fitted on (a linear model applies its offsets to them)."""

    structure: str
    fit_definition: str
    fit_percent_definition: str

    @property
    def simulation_fit_percent(self) -> list | None: ...

    @property
    def inputs(self) -> tuple[str, ...]: ...

    @property
    def outputs(self) -> tuple[str, ...]: ...

    @property
    def input_units(self) -> tuple[str, ...]: ...

    @property
    def output_units(self) -> tuple[str, ...]: ...

    @property
    def dt(self) -> float | None: ...

    @property
    def parameters(self): ...

    def simulate(self, data, *args, **kwargs) -> np.ndarray: ...

    def predict(self, data, *args, **kwargs) -> np.ndarray: ...

    def compare(self, data, *args, **kwargs) -> ModelFit: ...

    def residuals(self, data, *args, **kwargs) -> np.ndarray: ...

    def save(self, path) -> object: ...

    def report(self, data, out, *args, **kwargs) -> Path: ...

    def to_ss(self, *args, **kwargs): ...

    def to_tf(self): ...

    def to_control(self): ...


# schema -> (module of gripkit.sysid, reader function); one line per model family
MODEL_FILES: dict[str, tuple[str, str]] = {
    "gripkit.linear-model": ("linear.polynomial", "load_linear_model"),
    "gripkit.narx-model": ("nonlinear.narx", "load_narx"),
    "gripkit.rational-narx-model": ("nonlinear.narx_rational", "load_rational_narx"),
    "gripkit.hw-model": ("nonlinear.hammerstein_wiener", "load_hw"),
    "gripkit.hysteresis-model": ("nonlinear.hysteresis", "load_hysteresis"),
    "gripkit.nlss-model": ("nonlinear.nlss", "load_nlss"),
}

# report page -> (module of gripkit.sysid, writer function): the writer of a model's HTML report,
# ``writer(model, trajectory, out, data_name=..., warnings_list=...)`` -> the path of index.html
MODEL_REPORTS: dict[str, tuple[str, str]] = {
    "linear": ("model_report", "write_model_report"),
    "protocol": ("protocol_report", "write_protocol_page"),
}


class ReportMixin:
    """The one :meth:`report` of every identified model class (module docstring); a class names
    its page of :data:`MODEL_REPORTS` in ``_report_page``."""

    _report_page = "protocol"

    def report(self, data, out, y=None, *, dt: float | None = None, data_name: str = "data",
               warnings_list=()) -> Path:
        """Write the HTML report of this model on ``data`` to ``out/index.html`` (atomically,
        figures inline and in ``out/figures/``) and return that path: the page ``gripkit report
        MODEL DATA --out DIR`` writes, its fit ``self.compare(data)``. ``data``: a
        :class:`~gripkit.signals.Trajectory` with the model's columns, or the arrays ``compare``
        takes (``u`` and ``y``, a pair ``(u, y)``, or the columns side by side) sampled every
        ``dt`` (default the model's), in the units of the data the model was fitted on;
        ``data_name``: how the page names the record; ``warnings_list``: lines raised before,
        listed on the page. The warnings raised on the way are emitted as well."""
        record = report_record(self, data, y, dt)
        module, writer = MODEL_REPORTS[self._report_page]
        write = getattr(importlib.import_module(f"{__package__}.{module}"), writer)
        return write(self, record, out, data_name=data_name, warnings_list=warnings_list)


def _matrix(x, what: str, width: int, n: int | None = None) -> np.ndarray:
    a = np.asarray(x, dtype=np.float64)
    a = a.reshape(-1, 1) if a.ndim == 1 else a
    if a.ndim != 2 or a.shape[1] != width or (n is not None and a.shape[0] != n):
        expected = f"({n if n is not None else 'N'}, {width})"
        raise DataError(f"report: {what} must have shape {expected} (one column per model "
                        f"{what}), found {np.shape(x)}",
                        hint="give a trajectory with the model's columns, or arrays u, y")
    return a


def report_record(model, data, y=None, dt: float | None = None) -> Trajectory:
    """``data`` as the trajectory a report is written on: a Trajectory as it is; arrays (``u``
    and ``y``, a pair ``(u, y)``, or one array with the input then the output columns) as a
    trajectory of the model's columns sampled every ``dt`` (default ``model.dt``), their values
    as they are (the record's, as :meth:`compare` takes them)."""
    if isinstance(data, Trajectory):
        return data
    m, p = len(model.inputs), len(model.outputs)
    if y is None and isinstance(data, (tuple, list)) and len(data) == 2:
        data, y = data
    if y is None:
        both = np.asarray(data, dtype=np.float64)
        if both.ndim != 2 or both.shape[1] != m + p:
            raise ArgumentError(f"report: give a trajectory, or the arrays u and y (found one "
                                f"array of shape {both.shape})",
                                hint="model.report(data, out) or model.report(u, out, y=y)")
        data, y = both[:, :m], both[:, m:]
    u = _matrix(data, "input", m)
    yy = _matrix(y, "output", p, u.shape[0])
    step = dt if dt is not None else getattr(model, "dt", None)
    if step is None:
        raise ArgumentError("report: the model is continuous and the arrays carry no sample time",
                            hint="give dt=… (s), or a trajectory")
    cols = {n: u[:, i] for i, n in enumerate(model.inputs)}
    cols |= {n: yy[:, i] for i, n in enumerate(model.outputs)}
    return Trajectory(np.arange(u.shape[0]) * float(step), cols, None, {"dt": float(step)})


def file_schema(path) -> str | None:
    """The ``schema`` field of a JSON model file; None when it has none or cannot be read (the
    family's reader then names what is wrong)."""
    try:
        doc = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return None
    return doc.get("schema") if isinstance(doc, dict) else None


def load_model(path):
    """Read any gripkit model file with its family's reader (:data:`MODEL_FILES`); the same type
    that was saved comes back. Raises PathError for a missing file and ModelError for a schema no
    family knows."""
    p = Path(path)
    if not p.is_file():
        raise PathError(f"model file {str(p)!r} does not exist", hint="give the path written by "
                        "gripkit identify --out or model.save(path)")
    schema = file_schema(p)
    if schema is None:  # the linear reader names what is wrong with the file
        schema = "gripkit.linear-model"
    if schema not in MODEL_FILES:
        raise ModelError(f"model file {str(p)!r}: unknown schema {schema!r}; gripkit reads "
                         f"{', '.join(sorted(MODEL_FILES))}",
                         hint="regenerate the file with gripkit identify --out")
    module, reader = MODEL_FILES[schema]
    return getattr(importlib.import_module(f"{__package__}.{module}"), reader)(p)


def simulated_trajectory(model, data):
    """The free run of any identified model on the input columns of the trajectory ``data``
    (``model.simulate(data)``: by name, offsets applied, from rest) as a
    :class:`~gripkit.signals.Trajectory` on ``data``'s time base: one column per output, SI
    values in the model's ``output_units`` (every family has them), its display units (where
    the family keeps them: the linear models' ``display_units``) in ``meta['display_units']``
    (so ``gripkit.io.save(sim, path, units="display")`` writes ``force [mN]`` where the
    estimation file did). What ``gripkit simulate MODEL.json --data DATA`` writes."""
    ys = np.asarray(model.simulate(data), dtype=np.float64).reshape(data.t.size, -1)
    units = {n: u for n, u in zip(model.outputs, model.output_units) if u}
    display = getattr(model, "display_units", None) or {}
    shown = {n: display[n] for n in model.outputs if n in display}
    return Trajectory(data.t, {n: ys[:, i] for i, n in enumerate(model.outputs)}, units,
                      {"model": model.structure, "display_units": shown})
