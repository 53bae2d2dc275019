"""Readers and writers for CSV, Parquet and HDF5 behind :func:`load` and :func:`save`.

* CSV: one header row; units in headers (``force [N]``). Read with pyarrow.
* Parquet: one column per channel; units in the field metadata key ``unit`` (or in headers).
* HDF5: a group holding one 1-D dataset per channel (attribute ``unit``), or one 2-D dataset
  with a ``columns`` attribute (and optionally ``units``); ``key=`` names the group/dataset.
* MCAP (ROS 2 logs, optional extra): columns ``[alias=]/topic:field.path[i]``, see
  :mod:`gripkit.io.mcap_reader`.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from ..arguments import check_path, entry_point
from ..atomic import atomic_write
from ..errors import ArgumentError, DataError, DataWarning
from ..signals.trajectory import Trajectory
from .table import check_fill, check_fs, columns_to_trajectory

__all__ = ["load", "save", "FORMATS"]

FORMATS = {".csv": "csv", ".txt": "csv", ".tsv": "csv", ".parquet": "parquet", ".pq": "parquet",
           ".h5": "hdf5", ".hdf5": "hdf5", ".hdf": "hdf5", ".mcap": "mcap"}


def _format(path: Path, fmt: str | None) -> str:
    if fmt is not None:
        if fmt not in set(FORMATS.values()):
            raise DataError(f"format: expected one of csv, parquet, hdf5, mcap, found {fmt!r}")
        return fmt
    try:
        return FORMATS[path.suffix.lower()]
    except KeyError:
        raise DataError(f"cannot tell the format of {str(path)!r} from its suffix {path.suffix!r}",
                        hint="use .csv, .parquet or .h5, or pass format=") from None


@entry_point
def load(path, *, columns: Sequence[str] | None = None, time: str | None = None,
         fs: float | None = None, units: Mapping[str, str] | None = None,
         fill: str | None = None, format: str | None = None, key: str | None = None,
         delimiter: str | None = None, stamp: str = "log") -> Trajectory:
    """Read experiment data into a validated :class:`Trajectory` (SI units).

    Parameters
    ----------
    path
        A ``.csv``, ``.parquet`` or ``.h5`` file.
    columns
        Channels to keep (default: all but the time column).
    time
        Name of the time column; else one named t/time/timestamp, else ``fs`` must be given.
    fs
        Sampling rate in Hz when the file has no time column. With a time column it must agree
        with the stamps (within half a sample at every sample), else :class:`DataError`.
    units
        Units per channel, overriding those in headers or metadata (``{"force": "mN"}``).
    fill
        Missing values: ``None`` (error), ``'drop'`` rows, or ``'interpolate'`` linearly in time.
    format
        Force a format ('csv', 'parquet', 'hdf5') instead of the suffix.
    key
        HDF5 group or dataset path.
    stamp
        MCAP time stamps: 'log' (log time) or 'header' (``header.stamp`` of each message).

    Raises
    ------
    DataError
        Missing file or column, truncated or corrupt file (a CSV line with missing fields names
        the line), mixed types, NaN/inf, bad time stamps, ``fs`` contradicting the time column,
        an invalid ``fill`` or ``fs`` (checked before the file is read).
    ArgumentError
        An unknown keyword, or an argument of the wrong type (``path`` not a path, ``units`` not a
        mapping, ``fs`` not a number).

    Warns
    -----
    DataWarning
        A CSV whose last line has no line ending (the file looks truncated); a sample far outside
        the rest of its channel (a corrupt value), naming its time.
    """
    check_path(path, "path", "load()")
    if units is not None and not isinstance(units, Mapping):
        raise ArgumentError(f"load(): units must be a mapping {{column: unit}}, found {type(units).__name__}",
                            hint='e.g. units={"force": "mN"}')
    if fs is not None and (isinstance(fs, bool) or not isinstance(fs, (int, float, np.integer, np.floating))):
        raise ArgumentError(f"load(): fs must be a sampling rate in Hz (a number), found {type(fs).__name__} "
                            f"{fs!r:.40}")
    path = Path(path)
    if not path.exists():
        raise DataError(f"data file {str(path)!r} not found")
    if path.is_dir():
        raise DataError(f"{str(path)!r} is a folder, expected a data file")
    if path.stat().st_size == 0:
        raise DataError(f"data file {str(path)!r} is empty")
    check_fill(fill)
    check_fs(fs)
    fmt = _format(path, format)
    if fmt == "mcap":
        from .mcap_reader import read_mcap

        raw, meta_units = read_mcap(path, columns, stamp)
        return columns_to_trajectory(raw, source=path.name, time="t", fs=fs, units=units,
                                     meta_units=meta_units, fill=fill)
    reader = {"csv": _read_csv, "parquet": _read_parquet, "hdf5": _read_hdf5}[fmt]
    raw, meta_units = reader(path, key=key, delimiter=delimiter)
    return columns_to_trajectory(raw, source=path.name, columns=columns, time=time, fs=fs,
                                 units=units, meta_units=meta_units, fill=fill)


def _read_csv(path: Path, key=None, delimiter=None):
    import pyarrow as pa
    from pyarrow import csv as pacsv

    if delimiter is None:
        delimiter = "\t" if path.suffix.lower() == ".tsv" else ","
    try:
        table = pacsv.read_csv(
            path, parse_options=pacsv.ParseOptions(delimiter=delimiter),
            convert_options=pacsv.ConvertOptions(strings_can_be_null=True,
                                                 null_values=["", "NaN", "nan", "NA", "null"]))
    except (pa.ArrowInvalid, pa.ArrowTypeError, UnicodeDecodeError) as exc:
        _refuse_ragged_line(path, delimiter)
        raise DataError(f"{path.name}: not a readable CSV file (truncated or corrupt?): "
                        f"{str(exc).splitlines()[0]}") from None
    _warn_unterminated(path)
    return _arrow_columns(table, path.name), {}


def _refuse_ragged_line(path: Path, delimiter: str) -> None:
    """Raise a DataError naming the first line whose number of fields differs from the header's
    (pyarrow's own message does not say which line)."""
    text = path.read_bytes().decode("utf-8", errors="replace")
    lines = text.splitlines()
    if not lines:
        return
    sep = delimiter
    expected = lines[0].count(sep) + 1
    for k, line in enumerate(lines[1:], start=2):
        if not line.strip() or '"' in line:
            continue
        got = line.count(sep) + 1
        if got != expected:
            last = k == len(lines)
            cut = " and is the last line, without a line ending" if last and not text.endswith(("\n", "\r")) else ""
            raise DataError(
                f"{path.name}: line {k} has {got} fields, the header has {expected}{cut}: the file looks "
                f"{'truncated' if last else 'truncated or corrupt'}",
                hint=f"repair or remove line {k}")


def _warn_unterminated(path: Path) -> None:
    """Warn when the file's last line has no line ending: a file cut short while being written or
    copied ends that way, and its last values may be cut (1.529 read as 1)."""
    with open(path, "rb") as fh:
        fh.seek(-1, os.SEEK_END)
        if fh.read(1) in (b"\n", b"\r"):
            return
    data = path.read_bytes()
    k = data.count(b"\n") + 1 if b"\n" in data else data.count(b"\r") + 1
    last = data.splitlines()[-1].decode("utf-8", errors="replace")
    warnings.warn(f"{path.name}: line {k}, the last, has no line ending: the file looks truncated and "
                  f"that line's values may be cut short ({last[:60]!r}); check the end of the file, and end "
                  f"it with a newline if it is complete", DataWarning, stacklevel=4)


def _arrow_columns(table, source: str) -> dict[str, object]:
    import pyarrow as pa

    names = table.column_names
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise DataError(f"{source}: column name {repeated[0]!r} appears {names.count(repeated[0])} times in "
                        f"the header; each column needs its own name", hint="rename the repeated columns")
    out = {}
    for name, col in zip(table.column_names, table.columns):
        if pa.types.is_integer(col.type) or pa.types.is_floating(col.type) or pa.types.is_boolean(col.type):
            out[name] = _float64_column(col)
        elif pa.types.is_null(col.type):
            out[name] = np.full(len(col), np.nan)
        else:
            out[name] = np.asarray(col.to_pylist(), dtype=object)
    return out


def _float64_column(col) -> np.ndarray:
    """A numeric or boolean Arrow column as float64 with NaN for nulls, read from its buffers:
    pyarrow's ``to_numpy`` imports pandas (0.3 s of a CLI call) to check for it."""
    import pyarrow as pa
    import pyarrow.compute as pc

    parts = []
    for chunk in pc.cast(col, pa.float64()).chunks:
        n = len(chunk)
        validity, values = chunk.buffers()
        x = np.frombuffer(values, dtype=np.float64, count=n, offset=chunk.offset * 8).copy()
        if chunk.null_count:
            bits = np.unpackbits(np.frombuffer(validity, dtype=np.uint8), bitorder="little")
            x[bits[chunk.offset:chunk.offset + n] == 0] = np.nan
        parts.append(x)
    return np.concatenate(parts) if parts else np.empty(0)


def _read_parquet(path: Path, key=None, delimiter=None):
    import pyarrow as pa
    import pyarrow.parquet as pq

    try:
        table = pq.read_table(path)
    except (pa.ArrowInvalid, OSError) as exc:
        raise DataError(f"{path.name}: not a readable Parquet file (truncated or corrupt?): "
                        f"{str(exc).splitlines()[0]}") from None
    units = {}
    for f in table.schema:
        md = f.metadata or {}
        if b"unit" in md:
            units[f.name] = md[b"unit"].decode()
    return _arrow_columns(table, path.name), units


def _read_hdf5(path: Path, key=None, delimiter=None):
    import h5py

    try:
        fh = h5py.File(path, "r")
    except OSError as exc:
        raise DataError(f"{path.name}: not a readable HDF5 file (truncated or corrupt?): {exc}") from None
    with fh:
        node = fh if key is None else fh.get(key)
        if node is None:
            raise DataError(f"{path.name}: no group or dataset {key!r}",
                            hint=f"top-level entries: {', '.join(fh.keys())}")
        raw, units = {}, {}
        try:
            if isinstance(node, h5py.Dataset):
                arr = node[()]
                cols = node.attrs.get("columns")
                if arr.ndim != 2 or cols is None:
                    raise DataError(f"{path.name}: dataset {node.name!r} must be 2-D with a 'columns' attribute")
                cols = [c.decode() if isinstance(c, bytes) else str(c) for c in cols]
                if len(cols) != arr.shape[1]:
                    raise DataError(f"{path.name}: 'columns' names {len(cols)} columns, data has {arr.shape[1]}")
                ulist = node.attrs.get("units")
                for j, c in enumerate(cols):
                    raw[c] = arr[:, j]
                    if ulist is not None:
                        u = ulist[j]
                        units[c] = u.decode() if isinstance(u, bytes) else str(u)
            else:
                order = [c.decode() if isinstance(c, bytes) else str(c) for c in node.attrs.get("columns", [])]
                items = sorted(node.items(), key=lambda kv: order.index(kv[0]) if kv[0] in order else len(order))
                for name, ds in items:
                    if isinstance(ds, h5py.Dataset) and ds.ndim == 1:
                        raw[name] = ds[()]
                        if "unit" in ds.attrs:
                            u = ds.attrs["unit"]
                            units[name] = u.decode() if isinstance(u, bytes) else str(u)
                if not raw:
                    raise DataError(f"{path.name}: group {node.name!r} holds no 1-D datasets",
                                    hint="pass key= to point at the group holding the channels")
        except OSError as exc:
            raise DataError(f"{path.name}: HDF5 data cannot be read (truncated or corrupt?): {exc}") from None
    lengths = {k: len(v) for k, v in raw.items()}
    if len(set(lengths.values())) > 1:
        raise DataError(f"{path.name}: datasets have different lengths {lengths}")
    return raw, units


@entry_point
def save(tr: Trajectory, path, *, format: str | None = None, key: str = "/") -> None:
    """Write a trajectory: time as ``t`` (s) then each channel with its SI unit. Written with
    :func:`gripkit.atomic.atomic_write`: a save that fails midway leaves the old file as it was and
    raises :class:`PathError`."""
    if not isinstance(tr, Trajectory):
        raise ArgumentError(f"save(): tr must be a gripkit Trajectory, found {type(tr).__name__}")
    check_path(path, "path", "save()")
    path = Path(path)
    fmt = _format(path, format)
    if fmt == "mcap":
        raise DataError("gripkit reads MCAP logs but writes CSV, Parquet or HDF5", hint="save as .parquet")
    cols = {"t": tr.t, **{n: tr[n] for n in tr.names}}
    units = {"t": "s", **tr.units}
    if fmt == "csv":
        header = ",".join(f"{n} [{u}]" if u != "1" else n for n, u in units.items())

        def write(tmp):
            np.savetxt(tmp, np.column_stack(list(cols.values())), delimiter=",", header=header,
                       comments="", fmt="%.17g")
    elif fmt == "parquet":
        import pyarrow as pa
        import pyarrow.parquet as pq

        fields = [pa.field(n, pa.float64(), metadata={"unit": units[n]}) for n in cols]
        table = pa.Table.from_arrays([pa.array(v) for v in cols.values()], schema=pa.schema(fields))

        def write(tmp):
            pq.write_table(table, tmp)
    else:
        import h5py

        def write(tmp):
            with h5py.File(tmp, "w", track_order=True) as fh:
                g = fh.require_group(key)
                g.attrs["columns"] = list(cols)
                for n, v in cols.items():
                    ds = g.create_dataset(n, data=v)
                    ds.attrs["unit"] = units[n]
    atomic_write(path, write, what="trajectory file")
