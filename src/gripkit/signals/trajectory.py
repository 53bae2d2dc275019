"""Trajectory: time stamps and named channels with units, validated on construction.

A :class:`Trajectory` is what gripkit reads from data files, what simulations return, and what
identification and estimation consume. It checks itself when built: finite values, strictly
increasing time. Methods that need more (uniform sampling, a minimum number of samples) ask for
it explicitly with :meth:`Trajectory.require_uniform` and :meth:`Trajectory.require_samples`.

>>> import numpy as np
>>> tr = Trajectory.uniform(dt=0.005, u=np.zeros(400), y=np.ones(400), units={"u": "A", "y": "N"})
>>> tr.dt, tr.n, tr.unit("y")
(0.005, 400, 'N')
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

import numpy as np

from ..arguments import sample_interval
from ..errors import DataError

__all__ = ["Trajectory", "MAX_FILL_FRACTION"]

#: Largest fraction of a channel's samples that ``fill='interpolate'`` makes up when a record is
#: read (:mod:`gripkit.io.table`; a channel with more missing samples is refused: the record would
#: be more interpolation than measurement). Here, in a module every command loads, so that the
#: CLI's ``--fill`` help states it without loading the readers.
MAX_FILL_FRACTION = 0.2


def _median(d: np.ndarray) -> float:
    """``np.median`` of a 1-D float64 array, the same arithmetic (partition, the mean of the one
    or two middle values, NaN when there is one), without its NaN check's import of numpy.ma
    (a part of a CLI start-up worth saving)."""
    h = d.size // 2
    if d.size % 2:
        part = np.partition(d, [h, -1])  # the last: NaN sorts there
        mid = part[h]
    else:
        part = np.partition(d, [h - 1, h, -1])
        mid = (part[h - 1] + part[h]) / 2.0
    return float("nan") if np.isnan(part[-1]) else float(mid)


def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=np.float64, copy=True)
    a.flags.writeable = False
    return a


class Trajectory:
    """Time stamps ``t`` (s, shape (N,)) and channels (each shape (N,)) with SI units.

    Parameters
    ----------
    t
        Time stamps in seconds, strictly increasing.
    channels
        Mapping name → 1-D array of length N.
    units
        Mapping name → unit string (SI, e.g. ``'N'``, ``'m'``, ``'V'``, ``'A'``); missing names
        get ``'1'`` (dimensionless).
    meta
        Free-form provenance (source file, nominal sample interval ``dt`` in s, notes; the units
        the file wrote its columns in, ``display_units``: :meth:`display_unit`).
    """

    __slots__ = ("t", "_ch", "_units", "meta")

    def __init__(self, t, channels: Mapping[str, Iterable[float]],
                 units: Mapping[str, str] | None = None, meta: Mapping | None = None):
        t = np.asarray(t)
        if t.ndim != 1:
            raise DataError(f"time stamps: expected a 1-D array, found shape {t.shape}")
        if not np.issubdtype(t.dtype, np.number):
            raise DataError(f"time stamps: expected numbers, found dtype {t.dtype}")
        if t.size == 0:
            raise DataError("the data holds no samples", hint="check the file and "
                                                              "the selected rows")
        t = _readonly(t)
        bad = ~np.isfinite(t)
        if bad.any():
            i = int(np.argmax(bad))
            raise DataError(f"time stamps have {int(bad.sum())} non-finite values "
                            f"(first at row {i})",
                            hint="drop those rows or rebuild the time base from the "
                                 "sampling rate (--fs)")
        if t.size >= 2:
            d = np.diff(t)
            if (d <= 0).any():
                i = int(np.argmax(d <= 0)) + 1
                kind = "repeated" if d[i - 1] == 0 else "decreasing"
                raise DataError(
                    f"time stamps must increase strictly; found {kind} time t[{i}]={t[i]:.9g} s "
                    f"after t[{i - 1}]={t[i - 1]:.9g} s",
                    hint="sort the rows by time and drop duplicates",
                )
        units = dict(units or {})
        ch: dict[str, np.ndarray] = {}
        for name, arr in channels.items():
            if not isinstance(name, str) or not name:
                raise DataError(f"channel names must be non-empty strings, found {name!r}")
            a = np.asarray(arr)
            if a.ndim != 1 or a.shape[0] != t.shape[0]:
                raise DataError(
                    f"column {name!r}: expected {t.shape[0]} values (one per time stamp), "
                    f"found shape {a.shape}")
            if not (np.issubdtype(a.dtype, np.number) or a.dtype == bool):
                raise DataError(f"column {name!r}: expected numbers, found dtype {a.dtype}",
                                hint="remove text cells or select numeric columns only")
            a = _readonly(a)
            if not np.isfinite(a).all():
                for label, mask in (("NaN", np.isnan(a)), ("infinite", np.isinf(a))):
                    if mask.any():
                        i = int(np.argmax(mask))
                        raise DataError(
                            f"column {name!r} has {int(mask.sum())} {label} values (first at "
                            f"t={t[i]:.6g} s)",
                            hint="drop or interpolate them with "
                                 "fill='drop'|'interpolate' (CLI: --fill)",
                        )
            ch[name] = a
        unknown = set(units) - set(ch)
        if unknown:
            raise DataError(f"units given for unknown channels {sorted(unknown)}; "
                            f"channels: {list(ch)}")
        self.t = t
        self._ch = ch
        self._units = {n: units.get(n, "1") for n in ch}
        self.meta = dict(meta or {})

    # construction helpers
    @classmethod
    def _from_checked(cls, t: np.ndarray, channels: Mapping[str, np.ndarray],
                      units: Mapping[str, str],
                      meta: Mapping) -> "Trajectory":
        """A Trajectory around arrays gripkit has just made and checked (strictly increasing
        ``t``, finite float64 channels that nothing else references): no copies, no second check.
        The arrays are made read-only."""
        self = cls.__new__(cls)
        for a in (t, *channels.values()):
            a.flags.writeable = False
        self.t = t
        self._ch = dict(channels)
        self._units = {n: units.get(n, "1") for n in self._ch}
        self.meta = dict(meta)
        return self

    @classmethod
    def uniform(cls, *, dt: float, t0: float = 0.0, units: Mapping[str, str] | None = None,
                meta: Mapping | None = None, **channels) -> "Trajectory":
        """Build from channels sampled every ``dt`` s starting at ``t0`` s (``dt`` is kept as the
        nominal interval, exact, in ``meta['dt']``)."""
        dt = sample_interval(dt)
        if not channels:
            raise DataError("a trajectory needs at least one channel")
        n = len(next(iter(channels.values())))
        t = t0 + np.arange(n) * float(dt)
        m = {"dt": float(dt), **(meta or {})}
        return cls(t, channels, units, m)

    # basic properties
    @property
    def n(self) -> int:
        return int(self.t.shape[0])

    def __len__(self) -> int:
        return self.n

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self._ch)

    @property
    def units(self) -> dict[str, str]:
        return dict(self._units)

    def unit(self, name: str) -> str:
        self._require(name)
        return self._units[name]

    def display_unit(self, name: str) -> str:
        """The unit channel ``name`` was written in by its file (``'mN'`` for a column
        ``force [mN]``, from ``meta['display_units']``), else its SI unit. The values stay SI;
        :func:`gripkit.io.save` with ``units="display"`` writes them in these units."""
        self._require(name)
        return (self.meta.get("display_units") or {}).get(name, self._units[name])

    @property
    def duration(self) -> float:
        return float(self.t[-1] - self.t[0]) if self.n > 1 else 0.0

    @property
    def dt(self) -> float:
        """Sample interval (s): the nominal one in ``meta['dt']`` when the record is uniform, else
        the median interval of the time stamps."""
        if "dt" in self.meta and self.is_uniform():
            return float(self.meta["dt"])
        if self.n < 2:
            source = self.meta.get("source")
            raise DataError(f"{source + ': ' if source else ''}{self.n} sample(s) have no "
                            "sample interval",
                            hint="a record needs at least 2 samples; check that the "
                                 "file is complete")
        return _median(np.diff(self.t))

    def is_uniform(self, rtol: float = 1e-3) -> bool:
        if self.n < 3:
            return True
        d = np.diff(self.t)
        med = _median(d)
        return bool(np.max(np.abs(d - med)) <= rtol * med)

    def require_uniform(self, rtol: float = 1e-3,
                        why: str = "discrete-time identification") -> float:
        """Return the sample interval ``dt`` (s), or raise :class:`DataError` if sampling is not
        uniform."""
        if not self.is_uniform(rtol):
            d = np.diff(self.t)
            med = _median(d)
            i = int(np.argmax(np.abs(d - med)))
            raise DataError(
                f"{why} needs uniform sampling; the interval at t={self.t[i]:.6g} s "
                f"is {d[i]:.6g} s "
                f"against a median of {med:.6g} s ({100 * abs(d[i] - med) / med:.3g} % off, "
                f"tolerance {100 * rtol:.3g} %)",
                hint="resample the data first (gripkit.signals.resample(tr, dt); for the command "
                     "line, save the result with gripkit.io.save)",
            )
        return self.dt

    def require_samples(self, n_min: int, why: str) -> None:
        if self.n < n_min:
            raise DataError(f"{why} needs at least {n_min} samples, found {self.n}",
                            hint="use a longer record or a smaller model")

    # channel access
    def _require(self, name: str) -> None:
        if name not in self._ch:
            raise DataError(f"column {name!r} not found", hint="available columns: "
                                                               f"{', '.join(self._ch)}")

    def __getitem__(self, name: str) -> np.ndarray:
        self._require(name)
        return self._ch[name]

    def __contains__(self, name: str) -> bool:
        return name in self._ch

    def column(self, name: str) -> np.ndarray:
        return self[name]

    def select(self, *names: str) -> "Trajectory":
        for n in names:
            self._require(n)
        return Trajectory(self.t, {n: self._ch[n] for n in names},
                          {n: self._units[n] for n in names}, self.meta)

    def with_channels(self, units: Mapping[str, str] | None = None, **channels) -> "Trajectory":
        """New trajectory with channels added or replaced."""
        ch = dict(self._ch)
        ch.update(channels)
        u = dict(self._units)
        u.update(units or {})
        u = {k: v for k, v in u.items() if k in ch}
        return Trajectory(self.t, ch, u, self.meta)

    def rename(self, **mapping: str) -> "Trajectory":
        """``rename(old="new")``."""
        for old in mapping:
            self._require(old)
        ch = {mapping.get(k, k): v for k, v in self._ch.items()}
        u = {mapping.get(k, k): v for k, v in self._units.items()}
        meta = dict(self.meta)
        if meta.get("display_units"):
            meta["display_units"] = {mapping.get(k, k): v for k, v in meta["display_units"].items()}
        return Trajectory(self.t, ch, u, meta)

    def window(self, t_start: float | None = None, t_end: float | None = None) -> "Trajectory":
        """Samples with ``t_start <= t < t_end``."""
        lo = -np.inf if t_start is None else t_start
        hi = np.inf if t_end is None else t_end
        m = (self.t >= lo) & (self.t < hi)
        if not m.any():
            raise DataError(f"window [{lo}, {hi}) s holds no samples; data spans "
                            f"[{self.t[0]:.6g}, {self.t[-1]:.6g}] s")
        return self.take(np.flatnonzero(m))

    def take(self, index) -> "Trajectory":
        idx = np.asarray(index)
        return (Trajectory(self.t[idx], {k: v[idx] for k, v in self._ch.items()}, self._units,
                           self.meta))

    def as_array(self, *names: str) -> np.ndarray:
        """Columns stacked as an (N, len(names)) float64 array."""
        names = names or self.names
        return np.column_stack([self[n] for n in names])

    def __repr__(self) -> str:
        chans = ", ".join(f"{n} [{u}]" for n, u in self._units.items())
        rate = f", dt={self.dt:.6g} s" if self.n > 1 and self.is_uniform() else ""
        return f"Trajectory(n={self.n}, t=[{self.t[0]:.6g}, {self.t[-1]:.6g}] s{rate}; {chans})"

    def __eq__(self, other) -> bool:
        return (isinstance(other, Trajectory) and self._units == other._units
                and np.array_equal(self.t, other.t)
                and all(np.array_equal(self._ch[k], other._ch[k]) for k in self._ch))

    __hash__ = None  # type: ignore[assignment]
