"""An identified linear model: a :mod:`gripkit.lti` system plus what identification knows about it
(innovation gain K, initial state, offsets, fit, singular values, data provenance).

Discrete innovation form (the subspace and PEM models)::

    x[t+1] = A x[t] + B u[t] + K e[t],   y[t] = C x[t] + D u[t] + e[t],   e white, cov Λ.

``K = 0`` is the output-error form. Signals are in deviation units: the model's ``u_offset`` and
``y_offset`` (one per input and output, the operating point removed before fitting) are applied by
:meth:`LinearModel.simulate_data` and :meth:`LinearModel.compare_data`, which take a
:class:`~gripkit.signals.Trajectory` and pick its columns by name.

Free-run fit per output, ``100 (1 − ‖y_i − ŷ_i‖/‖y_i − ȳ_i‖)``, uses an initial state estimated by
least squares (the output is affine in x0: ``y = O x0 + G u``, ``O`` the rows ``C A^t``).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from ... import __version__
from ...errors import DataError, DataWarning, ModelError, ParameterError, emit_warning
from ...lti import LinearSystem, StateSpace, TransferFunction
from ...signals.trajectory import Trajectory
from ...units import convert, dimension_of, same_dimension
from ..checks import as_io_matrix
from ..model_file import SCHEMA, SCHEMA_VERSION, read_document, write_document

__all__ = ["VALIDATION_FIT", "validation_fit", "LinearModel", "as_io_matrix", "estimate_x0", "free_run", "fit_per_output", "from_polynomial",
           "model_document", "save_model", "load_linear_model"]


def _sim(A, B, C, D, u, x0):
    from ...lti import simulate_ss  # numba, loaded on first simulation

    y = np.empty((u.shape[0], C.shape[0]))
    simulate_ss(A, B, C, D, u, np.array(x0, dtype=np.float64), np.empty(A.shape[0]), y)
    return y


def free_run(A, B, C, D, u, x0=None) -> np.ndarray:
    """Outputs (N, p) of ``x[t+1] = A x + B u, y = C x + D u`` from ``x0`` (numba kernel)."""
    A, B, C, D = (np.ascontiguousarray(M, dtype=np.float64) for M in (A, B, C, D))
    return _sim(A, B, C, D, np.ascontiguousarray(u, dtype=np.float64), np.zeros(A.shape[0]) if x0 is None else x0)


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


def estimate_x0(A, B, C, D, u, y) -> np.ndarray:
    """Least-squares initial state: ``argmin ‖y − G u − O x0‖`` (``O[t] = C A^t``)."""
    n = A.shape[0]
    if n == 0:
        return np.zeros(0)
    r = y - free_run(A, B, C, D, u)
    O = observability_regressor(A, C, y.shape[0]).reshape(-1, n)
    return np.linalg.lstsq(O, r.reshape(-1), rcond=None)[0]


def fit_per_output(y, yhat) -> list[float]:
    """Fit (%) of each output column; DataError for a constant output."""
    out = []
    for i in range(y.shape[1]):
        den = float(np.linalg.norm(y[:, i] - y[:, i].mean()))
        if den == 0.0:
            raise DataError(f"output {i}: the fit is undefined for a constant output (‖y − ȳ‖ = 0)")
        out.append(100.0 * (1.0 - float(np.linalg.norm(y[:, i] - yhat[:, i])) / den))
    return out


def _in_unit(data, name: str, unit: str | None, what: str) -> np.ndarray:
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


@dataclass(frozen=True, eq=False)
class LinearModel:
    """An identified linear model.

    Attributes
    ----------
    system
        The :mod:`gripkit.lti` system (``StateSpace`` for subspace/PEM models, continuous
        ``TransferFunction`` for tfest), with names, units, dt and parameter covariance.
    structure
        ``'n4sid'``, ``'moesp'``, ``'cva'``, ``'pem-oe'``, ``'pem-innovation'``, ``'tfest'``.
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
        set_(self, "u_offset", tuple(float(v) for v in (self.u_offset or (0.0,) * s.n_inputs)))
        set_(self, "y_offset", tuple(float(v) for v in (self.y_offset or (0.0,) * s.n_outputs)))
        if len(self.u_offset) != s.n_inputs or len(self.y_offset) != s.n_outputs:
            raise ModelError(f"offsets: expected {s.n_inputs} input and {s.n_outputs} output offsets, found "
                             f"{len(self.u_offset)} and {len(self.y_offset)}")
        if self.K is not None:
            K = np.array(self.K, dtype=np.float64).reshape(-1, s.n_outputs)
            if not isinstance(s, StateSpace) or K.shape != (s.n_states, s.n_outputs):
                raise ModelError(f"K: expected shape (n_states, {s.n_outputs}) on a StateSpace, found {K.shape}")
            set_(self, "K", K)
        set_(self, "display_units", _checked_display_units(self, dict(self.display_units or {})))

    # ------------------------------------------------------------------ views
    @property
    def inputs(self) -> tuple[str, ...]:
        return self.system.inputs

    @property
    def outputs(self) -> tuple[str, ...]:
        return self.system.outputs

    @property
    def dt(self) -> float | None:
        return self.system.dt

    @property
    def order(self) -> int:
        return self.system.to_ss(minimal=False).n_states

    @property
    def stable(self) -> bool:
        return self.system.is_stable()

    def replace(self, **changes) -> LinearModel:
        return dataclasses.replace(self, **changes)

    def with_display_units(self, data) -> LinearModel:
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

    def discrete(self, dt: float) -> StateSpace:
        """The state-space system sampled at ``dt`` (ZOH for a continuous model)."""
        ss = self.system.to_ss(minimal=False)
        if ss.is_discrete:
            if abs(ss.dt - dt) > 1e-9 * dt:
                raise DataError(f"data: sampled every {dt:g} s, the model every {ss.dt:g} s",
                                hint="resample the data to the model's rate")
            return ss
        return ss.c2d(dt)

    # ------------------------------------------------------------------ arrays in
    def simulate(self, u, x0=None, dt: float | None = None) -> np.ndarray:
        """Free-run outputs (N, p) in deviation units for deviation inputs ``u`` (N, m)."""
        ss = self.discrete(dt or self.dt)
        u = as_io_matrix(u, "u")
        if u.shape[1] != ss.n_inputs:
            raise DataError(f"u: expected {ss.n_inputs} input columns, found {u.shape[1]}")
        return free_run(ss.A, ss.B, ss.C, ss.D, u, x0)

    def compare(self, u, y, dt: float | None = None) -> tuple[list[float], np.ndarray, np.ndarray]:
        """Free-run fit (%) per output with the initial state estimated by least squares;
        returns ``(fit_percent, y_sim, x0)``."""
        ss = self.discrete(dt or self.dt)
        u = as_io_matrix(u, "u")
        y = as_io_matrix(y, "y", u.shape[0])
        if not ss.is_stable():
            raise ModelError("compare: the model is unstable (a pole outside the unit circle): its free run "
                             "diverges, so no fit is reported")
        x0 = estimate_x0(ss.A, ss.B, ss.C, ss.D, u, y)
        ys = free_run(ss.A, ss.B, ss.C, ss.D, u, x0)
        return fit_per_output(y, ys), ys, x0

    # ------------------------------------------------------------------ trajectories in
    def _columns(self, data, names, offsets, what):
        missing = [n for n in names if n not in data.names]
        if missing:
            raise DataError(f"data: the model's {what} column(s) {', '.join(map(repr, missing))} are missing; "
                            f"the data have {', '.join(map(repr, data.names))}",
                            hint="rename the columns or identify the model from matching data")
        units = self.system.input_units if what == "input" else self.system.output_units
        return np.column_stack([_in_unit(data, n, u, what) - o
                                for n, u, o in zip(names, units, offsets)])

    def simulate_data(self, data) -> np.ndarray:
        """Simulated outputs (N, p), offsets added back, for the input columns of a trajectory
        (picked by name; the model's input offsets removed first), from x0 = 0."""
        dt = data.require_uniform(why="simulation of an identified model")
        u = self._columns(data, self.inputs, self.u_offset, "input")
        return self.simulate(u, dt=dt) + np.asarray(self.y_offset)

    def simulate_trajectory(self, data) -> Trajectory:
        """The model's outputs for the input columns of the trajectory ``data`` (by name, offsets
        applied, from rest) as a :class:`~gripkit.signals.Trajectory` on ``data``'s time base:
        SI values and units, the model's display units in ``meta['display_units']`` (so
        ``gripkit.io.save(sim, path, units="display")`` writes ``force [mN]`` where the estimation
        file did). What ``gripkit simulate MODEL.json --data DATA`` writes."""
        ys = self.simulate_data(data)
        units = {n: u for n, u in zip(self.outputs, self.system.output_units) if u}
        shown = {n: self.display_units[n] for n in self.outputs if n in self.display_units}
        return Trajectory(data.t, {n: ys[:, i] for i, n in enumerate(self.outputs)}, units,
                          {"model": self.structure, "display_units": shown})

    def compare_data(self, data) -> tuple[list[float], np.ndarray]:
        """Free-run fit per output on a trajectory (columns by name, offsets applied, x0
        estimated); returns ``(fit_percent, y_sim with offsets)``."""
        dt = data.require_uniform(why="comparison of an identified model")
        u = self._columns(data, self.inputs, self.u_offset, "input")
        y = self._columns(data, self.outputs, self.y_offset, "output")
        fit, ys, _ = self.compare(u, y, dt=dt)
        return fit, ys + np.asarray(self.y_offset)

    # ------------------------------------------------------------------ interop and files
    def to_control(self):
        """``control.StateSpace`` or ``control.TransferFunction``, with names."""
        return self.system.to_control()

    def save(self, path) -> None:
        """Write the model to a JSON file (:func:`model_document`; reload with :func:`load_linear_model`)."""
        write_document(model_document(self), path)

    def to_dict(self) -> dict:
        """JSON-ready summary (arrays as lists)."""
        ss = self.system.to_ss(minimal=False)
        out = {"structure": self.structure, "inputs": list(self.inputs), "outputs": list(self.outputs),
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


#: gripkit's one definition of a validation fit, used by ``identify --validate``, ``compare``,
#: ``report`` and the demo, and stated in their outputs
VALIDATION_FIT = ("free run from the model's operating point (its stored offsets), initial state "
                  "estimated by least squares, fit = 100 (1 − ‖y − ŷ‖/‖y − ȳ‖) over every sample")


def validation_fit(model, data) -> list[float] | None:
    """Free-run fit (%) per output of ``model`` on the trajectory ``data``, by
    :data:`VALIDATION_FIT`: the model's columns by name, its input and output offsets removed (the
    estimation record's operating point, not the validation record's means), the initial state
    estimated by least squares (:meth:`LinearModel.compare`). ``model`` is a
    :class:`LinearModel` or a :class:`~gripkit.sysid.PolynomialModel`; None for an unstable
    model, whose free run diverges."""
    lm = model if isinstance(model, LinearModel) else from_polynomial(model)
    if not lm.stable:
        return None
    return lm.compare_data(data)[0]


def from_polynomial(pm) -> LinearModel:
    """A :class:`~gripkit.sysid.PolynomialModel` (ARX/ARMAX/OE) as a :class:`LinearModel` on the
    discrete transfer function B/(A F) (its :attr:`~gripkit.sysid.PolynomialModel.lti`),
    with the parameter covariance (the noise polynomial C keeps its place in it, with zero
    tangents, and is recorded in ``info``), names, units and offsets."""
    g = pm.lti
    info = {"label": pm.label, "A": pm.A, "B": pm.B, "C": pm.C, "F": pm.F, "nk": pm.nk,
            "one_step_fit_percent": pm.fit_percent, "noise_variance": pm.noise_variance,
            "parameter_names": list(pm.parameter_names), **{k: v for k, v in pm.info.items()
                                                            if isinstance(v, (str, int, float))}}
    return LinearModel(g, pm.structure, u_offset=(pm.u_offset,), y_offset=(pm.y_offset,), n_samples=pm.n_samples,
                       noise_covariance=None if pm.noise_variance is None else np.array([[pm.noise_variance]]),
                       info=info)


def model_document(model: LinearModel) -> dict:
    """The JSON document of ``model`` (schema ``gripkit.linear-model``, :mod:`.model_file`)::

        {"schema": "gripkit.linear-model", "schema_version": 1, "gripkit_version": "0.1.0",
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
         "content_sha256": "…"}
    """
    s = model.system
    doc = {"schema": SCHEMA, "schema_version": SCHEMA_VERSION, "gripkit_version": __version__,
           "structure": model.structure, "kind": "ss" if isinstance(s, StateSpace) else "tf", "dt": s.dt,
           "inputs": [_entry(model, n, u, o)
                      for n, u, o in zip(s.inputs, s.input_units, model.u_offset)],
           "outputs": [_entry(model, n, u, o)
                       for n, u, o in zip(s.outputs, s.output_units, model.y_offset)]}
    doc["system"] = s.to_dict()
    doc["innovation"] = {"K": model.K, "x0": model.x0, "noise_covariance": model.noise_covariance}
    doc.update(fit_percent=model.fit_percent, singular_values=model.singular_values, n_samples=model.n_samples,
               info=model.info,
               data=None if model.data_file is None else {"file": model.data_file, "sha256": model.data_hash})
    return doc


def _entry(model: LinearModel, name: str, unit, offset: float) -> dict:
    """An input or output of the model document, with its ``display_unit`` when it has one."""
    entry = {"name": name, "unit": unit, "offset": offset}
    if name in model.display_units:
        entry["display_unit"] = model.display_units[name]
    return entry


def save_model(model, path) -> None:
    """Write ``model`` (a :class:`LinearModel`, or a :class:`~gripkit.sysid.PolynomialModel`,
    converted by :func:`from_polynomial`) to ``path`` as JSON."""
    write_document(model_document(model if isinstance(model, LinearModel) else from_polynomial(model)), path)


def _arr(x, name, where):
    try:
        return np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise ModelError(f"model file {where}: field {name!r} is not an array of numbers") from None


def load_linear_model(path) -> LinearModel:
    """Read a model written by ``model.save(path)``.

    Raises ModelError for a file that is not a gripkit model (wrong ``schema``), of a newer
    ``schema_version``, or with missing fields; warns (AccuracyWarning) when the content hash does
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
    doc = read_document(path)
    where = repr(str(path))
    try:
        ins, outs = doc["inputs"], doc["outputs"]
        system = LinearSystem.from_dict(doc["system"])
        if list(system.inputs) != [d["name"] for d in ins] or list(system.outputs) != [d["name"] for d in outs]:
            raise ModelError(f"model file {where}: the inputs/outputs lists disagree with the system's names")
        inn = doc.get("innovation") or {}
        K, x0, lam = (None if inn.get(k) is None else _arr(inn[k], k, where) for k in ("K", "x0", "noise_covariance"))
        data = doc.get("data") or {}
        sv = doc.get("singular_values")
        return LinearModel(system, doc["structure"], K=K, x0=x0, noise_covariance=lam,
                           u_offset=[d["offset"] for d in ins], y_offset=[d["offset"] for d in outs],
                           fit_percent=doc.get("fit_percent"), singular_values=None if sv is None else np.asarray(sv),
                           n_samples=doc.get("n_samples"), data_file=data.get("file"), data_hash=data.get("sha256"),
                           info=doc.get("info") or {},
                           display_units={d["name"]: d["display_unit"] for d in (*ins, *outs)
                                          if d.get("display_unit") is not None})
    except (KeyError, TypeError, AttributeError) as exc:
        raise ModelError(f"model file {where}: a required field is missing or malformed ({exc})",
                         hint="regenerate the file with gripkit identify --out") from None
    except ModelError as exc:
        if not exc.message.startswith("display unit"):
            raise
        raise ModelError(f"model file {where}: {exc.message}", hint=exc.hint) from None
