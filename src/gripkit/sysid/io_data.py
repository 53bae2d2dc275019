"""The one identification data class: inputs ``u`` (N, m) and outputs ``y`` (N, p) of a uniformly
sampled :class:`~gripkit.signals.Trajectory`, as deviations from an operating point, with the
columns' names and units, the offsets removed, the sample interval and the record's provenance.

Every identify method (:func:`gripkit.sysid.identify`) and every ``gripkit identify`` command
builds its data with :meth:`IOData.from_trajectory`; one input and one output is the case
m = p = 1 of the same class, read through its SISO view (:attr:`IOData.u1`, :attr:`IOData.y1`,
:attr:`IOData.input`, :attr:`IOData.output`, :attr:`IOData.keywords`).

>>> import numpy as np
>>> from gripkit import Trajectory
>>> tr = Trajectory.uniform(dt=0.01, a=[1.0, 2.0, 3.0, 6.0], b=[0.0, 1.0, 0.0, 3.0],
...                         units={"a": "A", "b": "N"})
>>> d = IOData.from_trajectory(tr, "a", "b")
>>> d.u.shape, d.u_offset, d.y_offset, d.u1.tolist(), d.input_unit
((4, 1), (3.0,), (1.0,), [-2.0, -1.0, 0.0, 3.0], 'A')

Provenance: :func:`gripkit.io.load` records the file's name (``meta['source']``) and the SHA-256
of its bytes (``meta['sha256']``); :attr:`IOData.provenance` hands them to the model
(``data_file``, ``data_hash``).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..errors import ArgumentError, DataError
from ..signals.processing import detrend as detrend_signals
from ..signals.trajectory import Trajectory
from .checks import check_excitation, check_output_varies

__all__ = ["IOData", "io_data", "parse_names", "validation_data", "provenance_of",
           "records_provenance", "SCALE_LIMITS", "DETRENDS", "check_scale"]

#: the operating-point removals: each column's mean, a least-squares line, nothing
DETRENDS = ("mean", "linear", "none")

#: Largest and smallest peak magnitude of a column that state-space, frequency-response and
#: transfer-function estimation accept: they form sums of squares and of products of the signals
#: (covariances, spectra, Gram matrices), which leave float64 (1e±308) for values beyond about
#: 1e±150; 1e±100 keeps the margin for record lengths and orders.
SCALE_LIMITS = (1e-100, 1e100)


def parse_names(x, what: str) -> tuple[str, ...]:
    """Column names from ``'a,b'`` or a sequence."""
    names = [s.strip() for s in x.split(",")] if isinstance(x, str) else [str(s).strip() for s in x]
    if not names or any(not n for n in names):
        raise DataError(f"{what}: expected one or more column names separated by commas, "
                        f"found {x!r}")
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise DataError(f"{what}: column(s) {', '.join(map(repr, dup))} listed twice")
    return tuple(names)


class _SisoView:
    """An attribute of :class:`IOData`'s SISO view: the one entry of the field ``source`` (the
    column of ``u`` or ``y`` as a 1-D array, the name or unit of the one input or output); an
    ArgumentError naming the attribute when the data have several inputs or outputs."""

    def __init__(self, source: str):
        self.source = source
        self.__doc__ = (f"The one column of ``{source}`` as a 1-D array (SISO view)."
                        if source in ("u", "y") else f"The one entry of ``{source}`` (SISO view).")

    def __set_name__(self, owner, name: str) -> None:
        self.name = name

    def __get__(self, obj, owner=None):
        if obj is None:
            return self
        obj._siso(self.name)
        value = getattr(obj, self.source)
        return value[:, 0] if isinstance(value, np.ndarray) else value[0]


@dataclass(frozen=True)
class IOData:
    """Inputs ``u`` (N, m) and outputs ``y`` (N, p) in deviation units (the offsets removed), with
    names, units, offsets (one per column), the sample interval ``dt`` (s) and ``source``, the
    record's provenance (``data_file``, ``data_hash``: from :func:`gripkit.io.load`'s meta, None
    for data built in memory).

    SISO view (one input, one output; an :class:`~gripkit.errors.ArgumentError` otherwise):
    :attr:`u1`, :attr:`y1` (1-D arrays), :attr:`input`, :attr:`output`, :attr:`input_unit`,
    :attr:`output_unit`, and :attr:`keywords` (the model keywords of the SISO estimators).
    """

    u: np.ndarray
    y: np.ndarray
    dt: float
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    input_units: tuple[str, ...]
    output_units: tuple[str, ...]
    u_offset: tuple[float, ...]
    y_offset: tuple[float, ...]
    source: tuple[str | None, str | None] = (None, None)

    @classmethod
    def from_trajectory(cls, data: Trajectory, input, output, *, detrend: str = "mean",
                        why: str = "identification", checks: bool = True) -> "IOData":
        """The ``input`` and ``output`` columns (a name, ``'a,b'`` or a list) of the uniformly
        sampled trajectory ``data``. ``detrend``: ``'mean'`` removes each column's mean (stored as
        the offsets), ``'linear'`` a least-squares line against time (the offsets are then the
        means), ``'none'`` keeps the data as they are. ``checks``: refuse a constant column (an
        :class:`~gripkit.errors.UnidentifiableError`, the estimators' own message) and one
        outside :data:`SCALE_LIMITS` (state space, FRF and transfer functions form unscaled
        sums of squares; the SISO polynomial estimators scale internally and name a constant
        input themselves, so they pass ``checks=False``). ``why`` names the work in the
        uniform-sampling error."""
        if not isinstance(data, Trajectory):
            raise DataError(f"data: expected a gripkit Trajectory, found {type(data).__name__}",
                            hint="use gripkit.io.load(path) or "
                                 "Trajectory.uniform(dt=..., u=..., y=...)")
        if detrend not in DETRENDS:
            raise DataError(f"detrend: expected 'mean', 'linear' or 'none', found {detrend!r}")
        ins, outs = parse_names(input, "input"), parse_names(output, "output")
        _check_columns(data, ins, outs)
        dt = float(f"{data.require_uniform(why=why):.9g}")  # file time stamps carry rounding noise
        u = np.column_stack([np.array(data[n], dtype=np.float64) for n in ins])
        y = np.column_stack([np.array(data[n], dtype=np.float64) for n in outs])
        if checks:
            _check_constant(data, ins, u, "input")
            _check_constant(data, outs, y, "output")
            check_scale(ins, u, "input", why)
            check_scale(outs, y, "output", why)
        # each column's own mean (pairwise summation of the contiguous column): one column has
        # the same offset whatever other columns are named with it
        u0 = np.array([u[:, j].mean() for j in range(u.shape[1])])
        y0 = np.array([y[:, j].mean() for j in range(y.shape[1])])
        if detrend == "none":
            u0, y0 = np.zeros_like(u0), np.zeros_like(y0)
        if detrend == "linear":
            d = detrend_signals(data.select(*ins, *outs), kind="linear")
            u = np.column_stack([np.array(d[n], dtype=np.float64) for n in ins])
            y = np.column_stack([np.array(d[n], dtype=np.float64) for n in outs])
        else:
            u, y = u - u0, y - y0
        return cls(u, y, dt, ins, outs, tuple(data.unit(n) for n in ins),
                   tuple(data.unit(n) for n in outs), tuple(map(float, u0)),
                   tuple(map(float, y0)), provenance_of(data))

    @property
    def n_samples(self) -> int:
        return int(self.u.shape[0])

    @property
    def signals(self) -> dict:
        """The names and units as the MIMO model constructors take them."""
        return dict(inputs=self.inputs, outputs=self.outputs, input_units=self.input_units,
                    output_units=self.output_units)

    @property
    def provenance(self) -> dict:
        """``data_file`` and ``data_hash`` for the model (:func:`gripkit.io.load` meta)."""
        return dict(data_file=self.source[0], data_hash=self.source[1])

    @property
    def is_siso(self) -> bool:
        return len(self.inputs) == 1 and len(self.outputs) == 1

    def _siso(self, what: str) -> None:
        if not self.is_siso:
            raise ArgumentError(f"IOData.{what}: the SISO view needs one input and one output, "
                                f"found {len(self.inputs)} input(s) {list(self.inputs)} and "
                                f"{len(self.outputs)} output(s) {list(self.outputs)}",
                                hint="read u (N, m) and y (N, p) instead")

    #: the SISO view: the one input and output as 1-D arrays, their names and units
    u1, y1, input, output, input_unit, output_unit = (
        _SisoView(f) for f in ("u", "y", "inputs", "outputs", "input_units", "output_units"))

    @property
    def keywords(self) -> dict:
        """The model keywords of the SISO estimators (:func:`~gripkit.sysid.arx`, ``armax``,
        ``oe``): names, units and the offsets as numbers (SISO view)."""
        self._siso("keywords")
        return dict(input_name=self.inputs[0], output_name=self.outputs[0],
                    input_unit=self.input_units[0], output_unit=self.output_units[0],
                    u_offset=self.u_offset[0], y_offset=self.y_offset[0])


def io_data(data: Trajectory, *, input, output, detrend: str = "mean",
            why: str = "discrete-time identification", checks: bool = False) -> IOData:
    """:meth:`IOData.from_trajectory` with keyword columns (the form of
    :func:`gripkit.sysid.identify`); ``checks`` off by default, as the SISO estimators take it."""
    return IOData.from_trajectory(data, input, output, detrend=detrend, why=why, checks=checks)


def provenance_of(data: Trajectory) -> tuple[str | None, str | None]:
    """(file name, SHA-256) of the file ``data`` was read from, (None, None) for data built in
    memory (:func:`gripkit.io.load` writes ``meta['source']`` and ``meta['sha256']``)."""
    meta = data.meta
    return meta.get("source"), meta.get("sha256")


def records_provenance(data) -> dict:
    """``data_file`` and ``data_hash`` for a model of ``data``: a trajectory's file name and
    SHA-256 (:func:`provenance_of`); of a list of records the file names joined by ``', '`` and
    no hash (no one file holds them); None for data built in memory."""
    if isinstance(data, Trajectory):
        name, digest = provenance_of(data)
        return dict(data_file=name, data_hash=digest)
    names = [provenance_of(d)[0] if isinstance(d, Trajectory) else None for d in data]
    if not names or None in names:
        return dict(data_file=None, data_hash=None)
    return dict(data_file=", ".join(names), data_hash=None)


def validation_data(validate: Trajectory, d: IOData, *, detrend: str = "none") -> IOData:
    """The validation record's columns of ``d`` as deviations from the *estimation* operating
    point ``d.u_offset``/``d.y_offset`` (the model's offsets): the one validation fit of
    :data:`gripkit.sysid.linear.linear_model.VALIDATION_FIT`, the number ``gripkit compare``
    gives. ``detrend='linear'`` takes the record's own line off instead (a trend is the record's
    own, no operating point)."""
    vd = IOData.from_trajectory(validate, d.inputs, d.outputs,
                                detrend="linear" if detrend == "linear" else "none",
                                why="validation", checks=False)
    if abs(vd.dt - d.dt) > 1e-9 * d.dt:
        raise DataError(f"validation data are sampled at {1 / vd.dt:g} Hz, the estimation data at "
                        f"{1 / d.dt:g} Hz", hint="resample one of them")
    if detrend == "linear":
        return vd
    return dataclasses.replace(vd, u=vd.u - np.asarray(d.u_offset),
                               y=vd.y - np.asarray(d.y_offset), u_offset=d.u_offset,
                               y_offset=d.y_offset)


def _check_columns(data: Trajectory, ins: tuple, outs: tuple) -> None:
    both = sorted(set(ins) & set(outs))
    if both:
        if len(ins) == len(outs) == 1:
            raise DataError(f"input and output must be different columns, both are {ins[0]!r}")
        raise DataError(f"input and output must be different columns, "
                        f"{', '.join(map(repr, both))} is both")
    for n in ins + outs:
        data.column(n)  # a missing column: "column 'x' not found", with the columns there


def _check_constant(data: Trajectory, names, x: np.ndarray, what: str) -> None:
    """Refuse a constant column of ``x`` (one per name of ``names``, ``what`` 'input' or
    'output', the data as recorded): the estimators' own check (:func:`check_excitation`,
    :func:`check_output_varies`), so that ``identify`` and a direct call say the same, the column
    named with its value in its unit."""
    check = check_excitation if what == "input" else check_output_varies
    for i, name in enumerate(names):
        check(x[:, i], f"{what} column {name!r}", unit=data.unit(name))


def check_scale(names, x: np.ndarray, what: str, why: str) -> None:
    """Refuse a column (of ``x``, one per name of ``names``; a 1-D ``x`` is one column) whose
    values are too large or too small for the estimators' sums of squares (the SISO polynomial
    estimators scale internally; state space, FRF, transfer functions and the nonlinear families
    do not). ``what``: 'input' or 'output'; ``why``: the work, 'NARX identification'."""
    x = np.asarray(x, dtype=np.float64)
    if x.size == 0:
        raise DataError(f"{what} column(s) {', '.join(map(repr, names))}: no samples; {why} "
                        "needs a record")
    peak = np.max(np.abs(x.reshape(x.shape[0], -1)), axis=0)
    lo, hi = SCALE_LIMITS
    bad = (peak > hi) | (peak < lo)
    if bad.any():
        i = int(np.argmax(bad))
        raise DataError(
            f"{what} column {names[i]!r} has values up to {peak[i]:.3g}: {why} forms sums of "
            f"squares of the signals, which leave float64 beyond about 1e±150, so it accepts peak "
            f"values between {lo:.0e} and {hi:.0e}",
            hint="give the column in other units (multiply it by a power of ten); arx, armax and "
                 "oe (SISO) scale internally")
