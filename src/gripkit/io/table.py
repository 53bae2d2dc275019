"""From named columns (as read from any file format) to a validated :class:`Trajectory`.

Rules shared by every reader:

* a column header may carry its unit, ``"force [mN]"`` or ``"force (mN)"``; values are converted
  to SI and the channel is named ``force``. Units may also come from file metadata or ``units=``.
  The units as written, where they are not SI, are kept in ``meta['display_units']``
  (``{"force": "mN"}``; :meth:`Trajectory.display_unit`), so that results can be written back
  in them (``gripkit.io.save(tr, path, units="display")``, ``gripkit simulate MODEL --out``);
* the time base is the column named by ``time=``, else a column named ``t``, ``time``,
  ``timestamp``, ``time_s``, ``stamp``, ``time_ns`` and the like (:func:`is_time_name`; its
  unit converted to seconds), else a uniform one built from ``fs=``. Given both a time column
  and ``fs``, they must agree (within half a sample at every sample), or a
  :class:`DataError` says by how much they differ;
* a sample far outside the rest of its channel (a corrupt value) gives a
  :class:`~gripkit.errors.DataWarning` naming its time (:mod:`gripkit.signals.outliers`);
* integer time stamps (ROS nanoseconds, 1.7e18) are read exactly: beyond 2**53 (where float64
  loses integers) the first stamp is subtracted in integer arithmetic and the time starts at 0
  (``meta['time_origin']`` keeps the first stamp). Without a unit, a time column named ``*_ns``
  or of integers from 1e17 up is in nanoseconds; other stamps from 1e12 up (milliseconds or
  microseconds since 1970?) are refused until their unit is given. Any other integer column beyond
  2**53 is refused;
* ``columns=`` selects channels by name; ``fill='drop'|'interpolate'`` handles missing values:
  ``'interpolate'`` fills them linearly (the ends with the nearest value) with a
  :class:`~gripkit.errors.DataWarning` giving their count and fraction per channel, and refuses a
  channel with more than :data:`MAX_FILL_FRACTION` (20 %) of its samples missing;
* a CSV file without a header (every field of its first line a number) has its columns named by
  their 1-based position, ``'1'``, ``'2'``, …: none is taken as the time column unless named
  with ``time='1'`` (or ``fs=`` is given), and ``meta['header']`` says so.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence

import numpy as np

from ..errors import DataError, DataWarning, emit_warning
from ..signals.outliers import corrupt_samples
from ..signals.trajectory import MAX_FILL_FRACTION, Trajectory
from ..units import si_factor

__all__ = ["columns_to_trajectory", "split_header", "by_position", "check_fill", "check_fs",
           "check_size", "is_time_name", "FILL_CHOICES"]

_TIME_NAMES = ("t", "time", "timestamp", "time_s", "times", "stamp", "t_ns", "time_ns",
               "timestamp_ns", "stamp_ns", "header_stamp", "header_stamp_ns")
#: integer time stamps from here up can only be nanoseconds (1e17 µs since 1970: 3000 years)
NS_STAMPS_FROM = 10**17
#: time values from here up are no record's seconds (31 700 years): a stamp in another unit
STAMPS_FROM = 10**12
_HEADER = re.compile(r"^\s*(.*?)\s*[\[(]\s*([^\])]+?)\s*[\])]\s*$")


def is_time_name(name: str) -> bool:
    """Whether a column of this name is taken as the time column when ``time=`` is not given."""
    return name.lower() in _TIME_NAMES


def by_position(names) -> bool:
    """Whether the columns ``names`` are ``'1'``, ``'2'``, … ``'n'``: those of a CSV file without
    a header, named by their 1-based position."""
    names = [str(n) for n in names]
    return bool(names) and names == [str(k) for k in range(1, len(names) + 1)]


def split_header(header: str) -> tuple[str, str | None]:
    """``'force [mN]'`` → ``('force', 'mN')``; ``'force'`` → ``('force', None)``."""
    m = _HEADER.match(header)
    if m and m.group(1):
        return m.group(1), m.group(2)
    return header.strip(), None


def _to_si(name: str, values: np.ndarray, unit: str | None) -> tuple[np.ndarray, str]:
    if unit is None:
        return values, "1"
    try:
        scale, offset, si = si_factor(unit)
    except Exception:
        raise DataError(f"column {name!r}: unit {unit!r} is not a unit gripkit can read",
                        hint="write units like [N], [mN], [um], [V], [mA], [bar], [s]") from None
    return values * scale + offset, si


def _numeric(name: str, values, row=None) -> np.ndarray:
    """Float64 array, or a DataError naming the first non-numeric cell (``row``: the cell's
    place from its 0-based data-row index, as the file counts it; default ``'row i'``)."""
    a = np.asarray(values)
    if a.dtype == bool:
        return a.astype(np.float64)
    if np.issubdtype(a.dtype, np.integer) and a.size:
        big = max(abs(int(a.min())), abs(int(a.max())))
        if big > 2**53:
            raise DataError(
                f"column {name!r} holds integers up to {big}, beyond 2**53 (float64 cannot hold "
                f"them exactly); gripkit reads such integers only as time stamps",
                hint=f"if it is the time column, name it with time={name!r} (CLI: --time {name}); "
                     f"else leave it out with columns=")
    if np.issubdtype(a.dtype, np.number):
        return a.astype(np.float64)
    out = np.empty(a.shape[0], dtype=np.float64)
    for i, v in enumerate(a):
        if v is None:
            out[i] = np.nan
            continue
        try:
            out[i] = float(v)
        except (TypeError, ValueError):
            raise DataError(
                f"column {name!r} mixes numbers and text: {_place(row, i)} holds "
                f"{str(v)[:40]!r}",
                hint="fix or remove that cell, or leave it empty to be treated as missing",
            ) from None
    return out


def _place(row, i: int) -> str:
    """Where data row ``i`` (0-based) is: ``row(i)`` (``'line 52 of f.csv'``) or ``'row i'``."""
    return f"row {i}" if row is None else row(i)


FILL_CHOICES = ("drop", "interpolate")


def check_fill(fill) -> None:
    """``fill`` must be None, 'drop' or 'interpolate' (checked before any data are read)."""
    if fill is not None and fill not in FILL_CHOICES:
        raise DataError(f"fill: expected None, 'drop' or 'interpolate', found {fill!r}",
                        hint="CLI: --fill drop or --fill interpolate, or leave it out to "
                             "refuse missing values")


def check_size(source: str, what: str, rows: int, ncols: int, limit: float,
               itemsize: int = 8) -> None:
    """Refuse to read ``rows`` × ``ncols`` values (as float64, or ``itemsize`` bytes each when
    larger) beyond the load limit, before anything is allocated: a small file may declare a huge
    dataset."""
    size = max(8, int(itemsize))
    need = float(rows) * float(ncols) * size
    if need <= limit:
        return
    each = "as float64" if size == 8 else f"at {size} bytes a value"
    raise DataError(
        f"{source}: {what} declares {rows} rows × {ncols} columns, about {need / 1e9:.3g} GB "
        f"{each}, beyond the load limit of {limit / 1e9:.3g} GB; nothing was read",
        hint="read fewer columns (columns=, CLI: the command's column options), or raise the "
             "limit with max_bytes= or the environment variable GRIPKIT_MAX_LOAD_BYTES (bytes) "
             "if the machine has the memory")


def check_fs(fs) -> None:
    """``fs`` must be None or a positive finite sampling rate in Hz."""
    if fs is None:
        return
    try:
        ok = math.isfinite(float(fs)) and float(fs) > 0
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise DataError(f"fs: expected a positive sampling rate in Hz, found {fs!r}")


def _check_fs_against_time(source: str, tname: str, t: np.ndarray, fs: float) -> None:
    """Refuse a sampling rate ``fs`` that contradicts the file's time column ``t`` (s).

    The two time bases agree when the stamps stay within half a sample interval of the uniform grid
    ``t[0] + k/fs`` at every sample k: each stamp is then nearest to its own grid point, so both
    label the same samples with the same times. Rounding of the stamps (a few digits written to the
    file) and clock jitter far below a sample pass; a different rate drifts by more than half a
    sample over a record of N samples as soon as the rates differ by more than 1/(2N), relative.
    """
    k = np.flatnonzero(np.isfinite(t))
    if k.size < 2:
        return
    drift = (t[k] - t[k[0]]) - (k - k[0]) / fs
    i = int(np.argmax(np.abs(drift)))
    if abs(drift[i]) <= 0.5 / fs:
        return
    rate = (k[-1] - k[0]) / (t[k[-1]] - t[k[0]]) if t[k[-1]] != t[k[0]] else float("inf")
    raise DataError(
        f"{source}: fs={fs:g} Hz disagrees with the time column {tname!r} (its stamps give "
        f"{rate:.6g} Hz): at t={t[k[i]]:.6g} s the two time bases are "
        f"{abs(drift[i]) * fs:.3g} samples "
        f"apart (tolerance: half a sample)",
        hint="leave out fs (CLI: --fs) to use the file's time stamps; if the stamps "
             "are wrong, fix or "
             "rename the time column")


def _time_seconds(source: str, tname: str, values,
                  unit: str | None) -> tuple[np.ndarray, str | None]:
    """The time column in seconds, and the subtracted first stamp (``'1700000000000000000 ns'``)
    when integers beyond 2**53 were read relative to it; refuses stamps whose unit is unclear."""
    a = np.asarray(values)
    integer = np.issubdtype(a.dtype, np.integer) and a.size > 0
    if unit is None and tname.lower().endswith("_ns"):
        unit = "ns"
    big = 0.0
    if integer:
        big = max(abs(int(a.min())), abs(int(a.max())))
    elif np.issubdtype(a.dtype, np.floating) and a.size and np.isfinite(a).any():
        big = float(np.nanmax(np.abs(a[np.isfinite(a)])))
    if unit is None and integer and big >= NS_STAMPS_FROM:
        unit = "ns"
    elif unit is None and big >= STAMPS_FROM:
        raise DataError(
            f"{source}: time column {tname!r} holds values up to {big:.4g}, too large for "
            f"seconds: they look like time stamps in another unit "
            f"({'integers' if integer else 'floating point'}; milliseconds, microseconds or "
            f"nanoseconds since 1970?)",
            hint=f"give the unit: in the header ('{tname} [ms]', '{tname} [us]', '{tname} [ns]'), "
                 f"with units={{'{tname}': 'ns'}}, or name the column {tname}_ns for nanoseconds")
    try:
        scale, offset, si = si_factor(unit or "s")
    except Exception:
        raise DataError(f"column {tname!r}: unit {unit!r} is not a unit gripkit can read",
                        hint="write time units like [s], [ms], [us], [ns]") from None
    if si != "s":
        raise DataError(f"{source}: time column {tname!r} has unit {unit!r}, which is not a time")
    if not integer or big <= 2**53:
        return _numeric(tname, a) * scale + offset, None
    first = int(a[0])
    if int(a.max()) - first >= 2**63 or int(a.min()) - first < -(2**63):
        raise DataError(f"{source}: time column {tname!r} spans more than 2**63 {unit}")
    wide = a.astype(np.uint64)
    relative = (wide - wide[0]).view(np.int64)  # exact: the differences fit int64 (checked above)
    return relative.astype(np.float64) * scale, f"{first} {unit}"


def _warn_corrupt(source: str, t: np.ndarray, data: dict[str, np.ndarray],
                  units: dict[str, str]) -> None:
    """One :class:`~gripkit.errors.DataWarning` per channel holding corrupt samples, naming their
    times."""
    for name, x in data.items():
        if not np.isfinite(x).all():
            continue  # missing values are refused (or filled) elsewhere
        idx = corrupt_samples(x)
        if idx.size == 0:
            continue
        u = units.get(name, "1")
        u = "" if u == "1" else f" {u}"
        shown = ", ".join(f"{x[i]:.6g}{u} at t={t[i]:.6g} s" for i in idx[:3])
        more = f" and {idx.size - 3} more" if idx.size > 3 else ""
        emit_warning(
           f"{source}: column {name!r} has {idx.size} sample{'s' if idx.size > 1 else ''} "
           "far outside the "
           f"rest of the channel, which look{'s' if idx.size == 1 else ''} corrupt: "
           f"{shown}{more}; check "
           f"the file (drop or repair those rows) unless the spike is real", DataWarning)


def _fill(t: np.ndarray, data: dict[str, np.ndarray], fill: str | None, source: str = "data"):
    check_fill(fill)
    if fill is None:
        return t, data
    missing = np.zeros(t.shape[0], dtype=bool)
    for v in data.values():
        missing |= ~np.isfinite(v)
    if not missing.any():
        return t, data
    if fill == "drop":
        keep = ~missing
        return t[keep], {k: v[keep] for k, v in data.items()}
    if fill == "interpolate":
        out = {}
        for k, v in data.items():
            bad = ~np.isfinite(v)
            if bad.all():
                raise DataError(f"column {k!r} has no finite values to interpolate from")
            if bad.any():
                _check_filled(source, k, bad)
                v = v.copy()
                v[bad] = np.interp(t[bad], t[~bad], v[~bad])
            out[k] = v
        return t, out


def _check_filled(source: str, name: str, bad: np.ndarray) -> None:
    """The record's ``fill='interpolate'`` of the missing samples ``bad`` of column ``name``: a
    DataError above :data:`MAX_FILL_FRACTION` of the channel, else a DataWarning with their
    count and fraction (and how many at the ends were copied from the nearest value)."""
    n, k = bad.size, int(bad.sum())
    share = f"{k} of {n} samples ({100.0 * k / n:.3g} %)"
    if k > MAX_FILL_FRACTION * n:
        raise DataError(
            f"{source}: column {name!r} has {share} missing; interpolation fills at most "
            f"{100 * MAX_FILL_FRACTION:g} % of a channel, beyond that the record is more made up "
            "than measured",
            hint="repair the record or cut it to the stretch that holds data; fill='drop' "
                 "(--fill drop) keeps only the complete rows")
    good = np.flatnonzero(~bad)
    ends = int(good[0] + (n - 1 - good[-1]))
    edge = (f", {ends} of them before the first or after the last measured value, copied "
            "from the nearest one" if ends else "")
    were = "was" if k == 1 else "were"
    emit_warning(f"{source}: column {name!r}: {share} {were} missing and {were} made up by "
                 f"linear interpolation{edge}; what is computed from the record treats them as "
                 "measured", DataWarning)


def columns_to_trajectory(raw: Mapping[str, object], *, source: str,
                          columns: Sequence[str] | None = None, time: str | None = None,
                          fs: float | None = None, units: Mapping[str, str] | None = None,
                          meta_units: Mapping[str, str] | None = None,
                          fill: str | None = None, headerless: bool = False,
                          row=None) -> Trajectory:
    """Build a Trajectory from raw columns ``{header: values}``; ``headerless``: the columns of a
    CSV file without a header, named ``'1'``, ``'2'``, … by position (the messages say so);
    ``row``: a data row's place in the file from its 0-based index (a text file's line), for
    the messages."""
    units = dict(units or {})
    meta_units = dict(meta_units or {})
    cols: dict[str, tuple[object, str | None]] = {}
    for header, values in raw.items():
        name, unit = split_header(str(header))
        if name in cols:
            raise DataError(f"{source}: column {name!r} appears twice")
        cols[name] = (values,
                      units.get(name) or unit or meta_units.get(header) or meta_units.get(name))
    if not cols:
        raise DataError(f"{source}: the file holds no columns")
    available = ", ".join(cols)
    if headerless:
        available += (f" (the file has no header, its first line holds numbers: its columns are "
                      f"named by their position, 1 to {len(cols)})")

    # time base: the time column (named, or found by name) and/or the sampling rate fs, which must
    # agree
    check_fill(fill)
    check_fs(fs)
    tname = time
    if tname is None:
        tname = next((c for c in cols if is_time_name(c)), None)
        if tname is None and fs is None and headerless:
            raise DataError(f"{source}: no time column: the file has no header (its first line "
                            f"holds numbers), so its columns are named by their position, 1 to "
                            f"{len(cols)}, and none is known to be the time",
                            hint="give the time column by position, time='1' (CLI: --time 1), or "
                                 "the sampling rate fs (CLI: --fs HZ)")
        if tname is None and fs is None:
            looked = ", ".join(_TIME_NAMES[:9])
            raise DataError(f"{source}: no time column found (looked for {looked}, ...)",
                            hint="name it with time=COL (CLI: --time COL) or give the sampling "
                                 "rate fs (CLI: --fs HZ)")
    if tname is not None and tname not in cols:
        raise DataError(f"{source}: time column "
                        f"{tname!r} not found", hint=f"available columns: {available}")

    names = (list(columns) if columns is not None
             else [c for c in cols if c != tname and not is_time_name(c)])
    for c in names:
        if c not in cols:
            raise DataError(f"{source}: column "
                            f"{c!r} not found", hint=f"available columns: {available}")
    if not names:
        raise DataError(f"{source}: no data columns besides the time column")

    n = None
    data: dict[str, np.ndarray] = {}
    su: dict[str, str] = {}
    for c in names:
        vals, unit = cols[c]
        arr = _numeric(c, vals, row)
        data[c], su[c] = _to_si(c, arr, unit)
        n = arr.shape[0]
    if n == 0:
        raise DataError(f"{source}: the file has column names but no data rows",
                        hint="check that the file is complete")
    if tname is not None:
        tvals, tunit = cols[tname]
        t, origin = _time_seconds(source, tname, tvals, tunit)
        meta = {"source": source, "time_column": tname}
        if origin is not None:
            meta["time_origin"] = origin
        if fs is not None:
            _check_fs_against_time(source, tname, t, float(fs))
            meta["dt"] = 1.0 / float(fs)  # the nominal interval: gripkit speaks dt inside
    else:
        t = np.arange(n) / float(fs)
        meta = {"source": source, "dt": 1.0 / float(fs)}
    if headerless:
        meta["header"] = "none: columns named by their 1-based position"
    shown = {c: cols[c][1] for c in names if cols[c][1] is not None and cols[c][1] != su[c]}
    if shown:  # the units the file wrote, for outputs in them (Trajectory.display_unit)
        meta["display_units"] = shown
    t, data = _fill(t, data, fill, source)
    _warn_corrupt(source, t, data, su)
    if tname is not None:
        bad = ~np.isfinite(t)
        if bad.any():
            i = int(np.argmax(bad))
            raise DataError(f"{source}: time column {tname!r} has {int(bad.sum())} "
                            "missing or non-finite "
                            f"values (first at {_place(row, i)})",
                            hint="drop those rows (fill='drop')")
    return Trajectory(t, data, su, meta)
