"""Readers and writers for CSV, Parquet and HDF5 behind :func:`load` and :func:`save`.

* CSV: one header row; units in headers (``force [N]``). Read with pyarrow. A file without a
  header (every field of its first line a number) is read whole, its columns named ``'1'``,
  ``'2'``, … by position (:mod:`gripkit.io.table`).
* Parquet: one column per channel; units in the field metadata key ``unit`` (or in headers).
* HDF5: a group holding one 1-D dataset per channel (attribute ``unit``), or one 2-D dataset
  with a ``columns`` attribute (and optionally ``units``); ``key=`` names the group/dataset.
* MCAP (ROS 2 logs, optional extra): columns ``[alias=]/topic:field.path[i]``, see
  :mod:`gripkit.io.mcap_reader`.
* MATLAB ``.mat`` (versions 4 to 7.3): numeric vectors are columns by variable name, the columns
  of an N×k matrix are ``name_1`` … ``name_k``; see :mod:`gripkit.io.mat_reader`.

A file names only its own data. HDF5 external links, external raw storage and virtual datasets
(which read other files on the machine) are refused unless ``allow_external_links=True`` (CLI:
``gripkit --allow-external-links``, or the environment variable ``GRIPKIT_ALLOW_EXTERNAL_LINKS=1``).
A Parquet file whose column chunks live in other files (a ``_metadata`` summary) is refused.

Sizes a file declares are checked before anything is allocated: when the requested columns would
take more than the load limit as float64 (rows × columns × 8 bytes), :func:`load` refuses with the
estimate. The limit is ``max_bytes=``, else ``GRIPKIT_MAX_LOAD_BYTES``, else the smaller of 4 GiB
and a quarter of the machine's memory.
"""

from __future__ import annotations

import hashlib
import os
import re
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from ..arguments import check_path, entry_point
from ..atomic import atomic_write
from ..errors import ArgumentError, DataError, DataWarning, emit_warning
from ..signals.trajectory import Trajectory
from ..units import convert, same_dimension
from .hdf5_links import check_dataset, hdf5_get, hdf5_open, hdf5_text
from .mat_reader import read_mat
from .table import (by_position, check_fill, check_fs, check_size, columns_to_trajectory,
                    is_time_name, split_header)

__all__ = ["load", "save", "file_sha256", "FORMATS"]

#: the load limit when neither max_bytes= nor GRIPKIT_MAX_LOAD_BYTES sets one: at most 4 GiB of
#: float64 values, and at most a quarter of the machine's memory (the data are copied a few times on
#: their way to a Trajectory: conversion to float64, to SI units, missing-value handling)
DEFAULT_MAX_BYTES = 4 * 2**30
_ENV_LIMIT = "GRIPKIT_MAX_LOAD_BYTES"
_ENV_EXTERNAL = "GRIPKIT_ALLOW_EXTERNAL_LINKS"

FORMATS = {".csv": "csv", ".txt": "csv", ".tsv": "csv", ".parquet": "parquet", ".pq": "parquet",
           ".h5": "hdf5", ".hdf5": "hdf5", ".hdf": "hdf5", ".mcap": "mcap", ".mat": "mat"}


def _format(path: Path, fmt: str | None, writing: bool = False) -> str:
    """The format of ``path`` (``fmt`` when given); ``writing``: the hint names the suffixes
    :func:`save` writes, not the read-only .mcap and .mat."""
    if fmt is not None:
        if fmt not in set(FORMATS.values()):
            raise DataError(f"format: expected one of csv, parquet, hdf5, mcap, mat, found {fmt!r}")
        return fmt
    try:
        return FORMATS[path.suffix.lower()]
    except KeyError:
        raise DataError(f"cannot tell the format of {str(path)!r} from its suffix {path.suffix!r}",
                        hint=("use .csv, .parquet or .h5, or pass format='csv', 'parquet' or "
                              "'hdf5'") if writing else
                        "use .csv, .parquet, .h5, .mcap or .mat, or pass format=") from None


@entry_point
def load(path, *, columns: Sequence[str] | None = None, time: str | None = None,
         fs: float | None = None, units: Mapping[str, str] | None = None,
         fill: str | None = None, format: str | None = None, key: str | None = None,
         delimiter: str | None = None, stamp: str = "log", allow_external_links: bool | None = None,
         max_bytes: float | None = None) -> Trajectory:
    """Read experiment data into a validated :class:`Trajectory` (SI units).

    Parameters
    ----------
    path
        A ``.csv``, ``.parquet``, ``.h5``, ``.mcap`` or ``.mat`` file.
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
        Force a format ('csv', 'parquet', 'hdf5', 'mcap', 'mat') instead of the suffix.
    key
        HDF5 group or dataset path.
    stamp
        MCAP time stamps: 'log' (log time) or 'header' (``header.stamp`` of each message).
    allow_external_links
        HDF5: follow external links and read external raw storage and virtual datasets, which take
        their data from other files. Default: refused (``GRIPKIT_ALLOW_EXTERNAL_LINKS=1`` allows).
    max_bytes
        Refuse a file whose requested columns would take more than this many bytes as float64,
        before reading them (default: ``GRIPKIT_MAX_LOAD_BYTES``, else the smaller of 4 GiB and
        a quarter of the machine's memory).

    Provenance: ``meta['source']`` is the file's name and ``meta['sha256']`` the SHA-256 of its
    bytes (hex), which :func:`gripkit.sysid.identify` stores in the model it returns
    (``data_file``, ``data_hash``) and ``gripkit compare`` checks.

    Raises
    ------
    DataError
        Missing file or column, truncated or corrupt file (a CSV line with missing fields names
        the line), mixed types, NaN/inf, bad time stamps, ``fs`` contradicting the time column,
        an invalid ``fill`` or ``fs`` (checked before the file is read); an HDF5 dataset that takes
        its data from another file; declared sizes beyond ``max_bytes``; a CSV file in UTF-16.
    ArgumentError
        An unknown keyword, or an argument of the wrong type (``path`` not a path, ``units`` not a
        mapping, ``fs`` not a number).

    Warns
    -----
    DataWarning
        A CSV whose last line has no line ending (the file looks truncated); a sample far outside
        the rest of its channel (a corrupt value), naming its time.

    Notes
    -----
    CSV files: lines that start with ``#`` are comments and are skipped; a file whose header is
    separated by ``;`` is read with ``;`` as separator, and with ``,`` as decimal point when its
    numbers are written so (``0,25``); one whose header holds tabs and neither ``,`` nor ``;``
    is read as tab-separated (as a ``.tsv`` file is). Integer time stamps in nanoseconds (a
    column named ``stamp``, ``time_ns`` and the like or ``*_ns`` given as ``time=``, with the
    unit ``[ns]``, or integers of 1e17 and more) are read exactly, relative to the first stamp
    (``meta['time_origin']``). A file without a header (every field of its first line a
    number) is read from its first line, its columns named by 1-based position (``'1'``, ``'2'``,
    …; ``columns=["2", "3"]``, ``time="1"``), and ``meta['header']`` says so.
    """
    check_path(path, "path", "load()")
    if units is not None and not isinstance(units, Mapping):
        raise ArgumentError(f"load(): units must be a mapping {{column: unit}}, found "
                            f"{type(units).__name__}",
                            hint='e.g. units={"force": "mN"}')
    if fs is not None and (isinstance(fs, bool) or not isinstance(fs,
                                                                  (int, float, np.integer,
                                                                       np.floating))):
        raise ArgumentError("load(): fs must be a sampling rate in Hz (a number), found "
                            f"{type(fs).__name__} "
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
    allow_external_links = _allow_external(allow_external_links)
    limit = _load_limit(max_bytes)
    tr = _read(path, _format(path, format), columns=columns, time=time, fs=fs, units=units,
               fill=fill, key=key, delimiter=delimiter, stamp=stamp,
               allow_external=allow_external_links, limit=limit)
    tr.meta["sha256"] = file_sha256(path)
    return tr


def _read(path: Path, fmt: str, *, columns, time, fs, units, fill, key, delimiter, stamp,
          allow_external: bool, limit: float) -> Trajectory:
    """The file read by its format's reader, as a validated trajectory (:func:`load`)."""
    if fmt == "mcap":
        from .mcap_reader import read_mcap

        raw, meta_units = read_mcap(path, columns, stamp, limit)
        return columns_to_trajectory(raw, source=path.name, time="t", fs=fs, units=units,
                                     meta_units=meta_units, fill=fill)
    reader = {"csv": _read_csv, "parquet": _read_parquet, "hdf5": _read_hdf5, "mat": read_mat}[fmt]
    raw, meta_units = reader(path, key=key, delimiter=delimiter, wanted=_Wanted(columns, time),
                             limit=limit, allow_external=allow_external)
    headerless = fmt == "csv" and by_position(raw)
    row = (lambda i: f"line {_data_line(path, i, headerless)} of {path.name}") if fmt == "csv" \
        else None
    try:
        return columns_to_trajectory(raw, source=path.name, columns=columns, time=time, fs=fs,
                                     units=units, meta_units=meta_units, fill=fill,
                                     headerless=headerless, row=row)
    except DataError as exc:  # a message about a column's values names the file too
        if exc.message.startswith(f"{path.name}:") or path.name in exc.message:
            raise
        raise type(exc)(f"{path.name}: {exc.message}", hint=exc.hint) from None


def _data_line(path: Path, i: int, headerless: bool) -> int | str:
    """The 1-based line of ``path`` (a CSV file) that holds data row ``i`` (0-based): blank and
    comment lines skipped, as the reader skips them, and the header counted ('?' past the end)."""
    k = -1 if headerless else -2  # the header is the first counted line
    with path.open("rb") as f:
        for line_no, line in enumerate(f, start=1):
            if not line.strip() or _is_comment(line):
                continue
            k += 1
            if k == i:
                return line_no
    return "?"


def file_sha256(path) -> str:
    """SHA-256 of a file's bytes (hex), read in 1 MiB blocks."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def _allow_external(allow) -> bool:
    """``allow_external_links``, or the environment's ``GRIPKIT_ALLOW_EXTERNAL_LINKS`` when None."""
    if allow is None:
        return os.environ.get(_ENV_EXTERNAL, "").strip().lower() in ("1", "true", "yes")
    if not isinstance(allow, (bool, np.bool_)):
        raise ArgumentError(f"load(): allow_external_links must be True or False, "
                            f"found {allow!r:.40}")
    return bool(allow)


def _load_limit(max_bytes) -> float:
    """The load limit in bytes: ``max_bytes``, else ``GRIPKIT_MAX_LOAD_BYTES``, else the smaller of
    :data:`DEFAULT_MAX_BYTES` and a quarter of the machine's memory."""
    where = "load(): max_bytes"
    if max_bytes is None and os.environ.get(_ENV_LIMIT, "").strip():
        max_bytes, where = os.environ[_ENV_LIMIT].strip(), f"environment variable {_ENV_LIMIT}"
        try:
            max_bytes = float(max_bytes)
        except ValueError:
            raise ArgumentError(f"{where} must be a number of bytes, "
                                f"found {max_bytes!r:.40}") from None
    if max_bytes is None:
        try:
            memory = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
        except (AttributeError, ValueError, OSError):
            memory = 4 * DEFAULT_MAX_BYTES
        return float(min(DEFAULT_MAX_BYTES, memory / 4))
    ok = (isinstance(max_bytes, (int, float, np.integer, np.floating))
          and not isinstance(max_bytes, bool))
    if not ok or not float(max_bytes) > 0:
        raise ArgumentError(f"{where} must be a positive number of bytes, found {max_bytes!r:.40}")
    return float(max_bytes)


class _Wanted:
    """Which of a file's columns :func:`load` needs: those named by ``columns`` (as headers, less
    their unit) and every possible time column; all of them when ``columns`` is None."""

    def __init__(self, columns, time):
        self.columns = None if columns is None else [str(c) for c in columns]
        self.time = time

    def select(self, source: str, headers) -> list[str]:
        """The ``headers`` to read; a DataError naming a requested column the file lacks."""
        headers = [str(h) for h in headers]
        if self.columns is None:
            return headers
        names = [split_header(h)[0] for h in headers]
        for c in self.columns:
            if c not in names:
                raise DataError(f"{source}: column {c!r} not found",
                                hint=f"available columns: {', '.join(dict.fromkeys(names))}")
        return [h for h, n in zip(headers, names) if n in self.columns or n == self.time
                or is_time_name(n)]


def _read_csv(path: Path, key=None, delimiter=None, *, wanted=None, limit=None,
              allow_external=False):
    import pyarrow as pa
    from pyarrow import csv as pacsv

    data = path.read_bytes()
    _refuse_utf16(path, data)
    data = _strip_comments(path, data)
    decimal = "."
    if delimiter is None:
        tsv = path.suffix.lower() == ".tsv"
        delimiter, decimal = ("\t", ".") if tsv else _sniff_separator(data)
    names = _headerless_names(data, delimiter)
    try:
        table = pacsv.read_csv(
            pa.BufferReader(data), read_options=pacsv.ReadOptions(column_names=names),
            parse_options=pacsv.ParseOptions(delimiter=delimiter),
            convert_options=pacsv.ConvertOptions(strings_can_be_null=True, decimal_point=decimal,
                                                 null_values=["", "NaN", "nan", "NA", "null"]))
        columns = _arrow_columns(table, path.name)
    except UnicodeDecodeError:  # its offset is within a field, not the file: find the byte
        raise _not_utf8(path) from None
    except (pa.ArrowInvalid, pa.ArrowTypeError) as exc:
        _refuse_ragged_line(path, delimiter)
        raise DataError(f"{path.name}: not a readable CSV file (truncated or corrupt?): "
                        f"{str(exc).splitlines()[0]}") from None
    _warn_unterminated(path)
    return columns, {}


def _not_utf8(path: Path) -> DataError:
    """The DataError of a CSV file that is not UTF-8 text, naming the file, the first byte that
    does not decode, its offset in the file and its line (the decoding error's own offset counts
    from the start of the field that holds it)."""
    data = path.read_bytes()
    try:
        data.decode("utf-8")
        where = "somewhere"
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        where = f"byte 0x{data[exc.start]:02x} at offset {exc.start} (line {line})"
    return DataError(f"{path.name}: not UTF-8 text: {where} cannot be decoded as UTF-8",
                     hint="save the file as UTF-8 (e.g. a 'µ' written in Latin-1 is the single "
                          "byte 0xb5), or check that the path names the right file")


def _refuse_utf16(path: Path, data: bytes) -> None:
    """A CSV file must be UTF-8 (or ASCII) text: UTF-16 and UTF-32 (a byte-order mark, or NUL
    bytes between the characters) would otherwise be misread as one garbled column."""
    boms = ((b"\xff\xfe\x00\x00", "UTF-32"), (b"\x00\x00\xfe\xff", "UTF-32"),
            (b"\xff\xfe", "UTF-16"), (b"\xfe\xff", "UTF-16"))
    found = next((name for bom, name in boms if data.startswith(bom)), None)
    why = f"it starts with a {found} byte-order mark"
    head = data[:65536]
    if found is None and b"\x00" in head:
        if head.count(b"\x00") * 3 < len(head):
            k = head.index(b"\x00")
            raise DataError(f"{path.name}: not a readable CSV file: byte {k} is a NUL byte, found "
                            f"in binary files, not in text",
                            hint="check that the path names the CSV file, or pass format= for "
                                 "another format")
        found, why = "UTF-16", "every other byte is NUL"
    if found is not None:
        raise DataError(f"{path.name}: not a readable CSV file: the file is {found} text ({why}), "
                        f"and gripkit reads CSV files as UTF-8",
                        hint=f"save it as UTF-8 (in Excel: 'CSV UTF-8'; or iconv -f {found} "
                             f"-t UTF-8)")


def _is_comment(line: bytes) -> bool:
    return line.lstrip().startswith(b"#")


def _strip_comments(path: Path, data: bytes) -> bytes:
    """``data`` without its comment lines (lines whose first character other than a blank is
    ``#``, before the header or between data rows). Refuses a file whose header is itself
    commented out (``# t,force`` as ``numpy.savetxt`` writes it): its first row would be read as
    column names."""
    if b"#" not in data:
        return data
    lines = data.splitlines(keepends=True)
    if not any(_is_comment(line) for line in lines):
        return data
    first = next((k for k, line in enumerate(lines) if line.strip() and not _is_comment(line)),
                 None)
    if first is not None and first > 0:
        fields = [f.strip() for f in re.split(rb"[,;\t]", lines[first])]
        if all(_NUMBER.match(f) for f in fields):
            shown = lines[first].decode("utf-8", errors="replace").strip()[:60]
            raise DataError(
                f"{path.name}: line {first + 1}, the first that is not a comment, holds numbers "
                f"({shown!r}), not column names: the header looks commented out",
                hint="lines starting with '#' are comments; remove the '#' before the column names")
    return b"".join(line for line in lines if not _is_comment(line))


_NUMBER = re.compile(rb"^[-+]?(\d+([.,]\d*)?|[.,]\d+)([eE][-+]?\d+)?$")
_DECIMAL_COMMA = re.compile(r"^\s*[-+]?\d*,\d+([eE][-+]?\d+)?\s*$")


#: cells of a first line that a headerless file's first data row may hold besides numbers
_MISSING = (b"", b"NaN", b"nan", b"NA", b"null")


def _headerless_names(data: bytes, delimiter: str) -> list[str] | None:
    """Column names ``'1'``, ``'2'``, … when the file has no header (every field of its first
    line is a number, or a missing value beside at least one number): the first line is then the
    first data row, and the columns are named by their 1-based index. None for a header."""
    line = next((x for x in data[:65536].splitlines() if x.strip()), b"")
    fields = [f.strip().strip(b'"') for f in line.split(delimiter.encode())]
    if not any(_NUMBER.match(f) for f in fields):
        return None
    if not all(_NUMBER.match(f) or f in _MISSING for f in fields):
        return None
    return [str(k) for k in range(1, len(fields) + 1)]


def _sniff_separator(data: bytes) -> tuple[str, str]:
    """The separator and decimal point of a CSV file read without ``delimiter=``: ``,`` and
    ``.``, unless the header holds ``;`` and no ``,`` (a European spreadsheet's export), or the
    file has no header and its first line is numbers separated by ``;`` (``0,25;1,5``): then
    ``;``, with ``,`` as decimal point when the data rows write their numbers so (``0,25``); a
    tab when the first line holds tabs and neither ``,`` nor ``;`` (a TSV file named ``.csv``)."""
    lines = data[:65536].decode("utf-8", errors="replace").splitlines()
    if len(data) > 65536:
        lines = lines[:-1]  # cut short
    header = next((line for line in lines if line.strip()), "")
    if "\t" in header and "," not in header and ";" not in header:  # tab-separated (.csv named)
        return "\t", "."
    numbers = all(_NUMBER.match(f.strip().encode()) for f in header.split(";"))
    if ";" not in header or ("," in header and not numbers):
        return ",", "."
    rows = [line for line in lines[:200] if line.strip()]  # the header: a data row or no comma
    comma = any(_DECIMAL_COMMA.match(f) for line in rows for f in line.split(";"))
    return ";", "," if comma else "."


def _refuse_ragged_line(path: Path, delimiter: str) -> None:
    """Raise a DataError naming the first line whose number of fields differs from the header's
    (pyarrow's own message does not say which line); comment lines are skipped."""
    text = path.read_bytes().decode("utf-8", errors="replace")
    lines = text.splitlines()
    numbered = [(k, line) for k, line in enumerate(lines, start=1)
                if not line.lstrip().startswith("#")]
    if not numbered:
        return
    sep = delimiter
    expected = numbered[0][1].count(sep) + 1
    first = "the header" if _headerless_names(numbered[0][1].encode(), sep) is None else \
        f"line {numbered[0][0]}, the first (the file has no header),"
    for k, line in numbered[1:]:
        if not line.strip() or '"' in line:
            continue
        got = line.count(sep) + 1
        if got != expected:
            last = k == len(lines)
            cut = (" and is the last line, without a line ending" if last
                   and not text.endswith(("\n", "\r")) else "")
            raise DataError(
                f"{path.name}: line {k} has {got} fields, {first} has {expected}{cut}: "
                f"the file looks "
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
    emit_warning(f"{path.name}: line {k}, the last, has no line ending: the file "
                 "looks truncated and "
                 f"that line's values may be cut short ({last[:60]!r}); check the end of "
                 "the file, and end "
                 f"it with a newline if it is complete", DataWarning)


def _arrow_columns(table, source: str) -> dict[str, object]:
    import pyarrow as pa

    names = table.column_names
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise DataError(f"{source}: column name {repeated[0]!r} appears "
                        f"{names.count(repeated[0])} times in "
                        "the header; each column "
                        "needs its own name", hint="rename the repeated columns")
    out = {}
    for name, col in zip(table.column_names, table.columns):
        if pa.types.is_integer(col.type):
            out[name] = _integer_column(col, name, source)
        elif pa.types.is_floating(col.type) or pa.types.is_boolean(col.type):
            out[name] = _float64_column(col)
        elif pa.types.is_null(col.type):
            out[name] = np.full(len(col), np.nan)
        elif pa.types.is_dictionary(col.type):
            out[name] = _dictionary_column(col)
        else:
            out[name] = np.asarray(col.to_pylist(), dtype=object)
    return out


def _integer_column(col, name: str, source: str) -> np.ndarray:
    """An integer Arrow column as a numpy integer array (exact: time stamps in nanoseconds exceed
    float64's 2**53), or as float64 with NaN for nulls when every value fits float64 exactly."""
    import pyarrow.compute as pc

    if col.null_count == 0:
        parts = []
        for chunk in col.chunks:
            dtype = np.dtype(str(chunk.type))
            parts.append(np.frombuffer(chunk.buffers()[1], dtype=dtype, count=len(chunk),
                                       offset=chunk.offset * dtype.itemsize).copy())
        return np.concatenate(parts) if parts else np.empty(0, dtype=np.int64)
    lo, hi = pc.min_max(col).values()
    big = max(abs(lo.as_py() or 0), abs(hi.as_py() or 0))
    if big > 2**53:
        raise DataError(f"{source}: column {name!r} holds integers up to {big} (beyond 2**53, "
                        f"which float64 cannot hold exactly) and {col.null_count} missing values",
                        hint="fill the missing values, or leave the column out")
    return _float64_column(col)


def _dictionary_column(col) -> np.ndarray:
    """A dictionary-encoded Arrow column as an object array whose repeated values are one Python
    object each (``to_pylist`` would make one per row)."""
    import pyarrow as pa
    import pyarrow.compute as pc

    parts = []
    for chunk in col.chunks:
        words = chunk.dictionary.to_pylist()
        values = np.empty(len(words) + 1, dtype=object)  # the last one for nulls
        values[:-1] = words
        idx = pc.fill_null(chunk.indices, len(words))
        parts.append(values[_integer_column(pa.chunked_array([idx]), "", "")])
    return np.concatenate(parts) if parts else np.empty(0, dtype=object)


def _float64_column(col) -> np.ndarray:
    """A numeric or boolean Arrow column as float64 with NaN for nulls, read from its buffers:
    pyarrow's ``to_numpy`` imports pandas (0.3 s of a CLI call) to check for it."""
    import pyarrow as pa

    if not pa.types.is_float64(col.type):  # a float64 column needs no cast: no pyarrow.compute
        import pyarrow.compute as pc  # import (a part of a CLI start-up worth saving)

        col = pc.cast(col, pa.float64())
    parts = []
    for chunk in col.chunks:
        n = len(chunk)
        validity, values = chunk.buffers()
        x = np.frombuffer(values, dtype=np.float64, count=n, offset=chunk.offset * 8).copy()
        if chunk.null_count:
            bits = np.unpackbits(np.frombuffer(validity, dtype=np.uint8), bitorder="little")
            x[bits[chunk.offset:chunk.offset + n] == 0] = np.nan
        parts.append(x)
    return np.concatenate(parts) if parts else np.empty(0)


def _read_parquet(path: Path, key=None, delimiter=None, *, wanted=None, limit=None,
                  allow_external=False):
    """Read the columns ``wanted`` of a Parquet file, from pyarrow's own file object (a path
    string would be read by pyarrow as a URI or a dataset folder; a Python file object leaves
    pyarrow's reader threads to interpreter shutdown, which aborted 1 run in 10 under load:
    "terminate called without an active exception", apache/arrow#34314 and #50482)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    wanted = wanted or _Wanted(None, None)
    with _native_file(path) as fh:
        try:
            pf = pq.ParquetFile(fh)
            meta = pf.metadata
            elsewhere = {meta.row_group(i).column(j).file_path for i in range(meta.num_row_groups)
                         for j in range(meta.num_columns)} - {"", None}
            if elsewhere:
                raise DataError(f"{path.name}: the Parquet file's data live in other files "
                                f"({sorted(elsewhere)[0]!r}; a dataset's _metadata summary)",
                                hint="give one of the data files of the dataset, not its _metadata")
            schema = pf.schema_arrow
            names = wanted.select(path.name, schema.names)
            limit = limit or float("inf")
            check_size(path.name, "the file", meta.num_rows, len(names), limit)
            _check_parquet_stored(path.name, meta, names, limit)
            # text as dictionaries: one string repeated a million times stays one string
            text = [f.name for f in schema if f.name in names
                    and (pa.types.is_string(f.type) or pa.types.is_large_string(f.type)
                         or pa.types.is_binary(f.type) or pa.types.is_large_binary(f.type))]
            if text:
                pf = pq.ParquetFile(fh, read_dictionary=text)
            table = pf.read(columns=names)
        except DataError:
            raise
        except (pa.ArrowException, OSError) as exc:
            raise DataError(f"{path.name}: not a readable Parquet file (truncated or corrupt?): "
                            f"{str(exc).splitlines()[0]}") from None
    units = {}
    for f in table.schema:
        md = f.metadata or {}
        if b"unit" in md:
            units[f.name] = md[b"unit"].decode()
    return _arrow_columns(table, path.name), units


def _native_file(path: Path):
    """``path`` opened for reading as a pyarrow ``OSFile`` (a local file, never a URI), with the
    OS's error as the open's OSError."""
    import pyarrow as pa

    try:
        return pa.OSFile(str(path), "rb")
    except pa.ArrowException as exc:  # (pyarrow raises its IOError subclasses of OSError too)
        raise OSError(str(exc).splitlines()[0]) from None


def _check_parquet_stored(source: str, meta, names, limit: float) -> None:
    """Refuse columns whose pages declare more bytes uncompressed than the load limit (a few kB
    of compressed pages may declare gigabytes)."""
    chosen = set(names)
    stored = sum(meta.row_group(i).column(j).total_uncompressed_size
                 for i in range(meta.num_row_groups) for j in range(meta.num_columns)
                 if meta.row_group(i).column(j).path_in_schema.split(".")[0] in chosen)
    if stored > limit:
        raise DataError(f"{source}: the file's columns declare {stored / 1e9:.3g} GB uncompressed, "
                        f"beyond the load limit of {limit / 1e9:.3g} GB; nothing was read",
                        hint="read fewer columns (columns=), or raise the limit with max_bytes= or "
                             "the environment variable GRIPKIT_MAX_LOAD_BYTES (bytes)")


def _read_hdf5(path: Path, key=None, delimiter=None, *, wanted=None, limit=None,
               allow_external=False):
    import h5py

    wanted = wanted or _Wanted(None, None)
    limit = float("inf") if limit is None else limit
    with hdf5_open(path, "HDF5 file") as fh:
        node = fh if key is None else hdf5_get(fh, key, path.name, allow_external)
        if node is None:
            raise DataError(f"{path.name}: no group or dataset {key!r}",
                            hint=f"top-level entries: {', '.join(fh.keys())}")
        try:
            if isinstance(node, h5py.Dataset):
                raw, units = _hdf5_table(node, path.name, wanted, limit, allow_external)
            else:
                raw, units = _hdf5_group(node, path.name, wanted, limit, allow_external)
        except OSError as exc:
            raise DataError(f"{path.name}: HDF5 data cannot be read (truncated or "
                            f"corrupt?): {exc}") from None
    lengths = {k: len(v) for k, v in raw.items()}
    if len(set(lengths.values())) > 1:
        raise DataError(f"{path.name}: datasets have different lengths {lengths}")
    return raw, units


def _hdf5_table(node, source: str, wanted, limit: float, allow_external: bool):
    """The wanted columns of one 2-D dataset with a ``columns`` attribute."""
    cols = node.attrs.get("columns")
    if node.ndim != 2 or cols is None:
        raise DataError(f"{source}: dataset {node.name!r} must be 2-D with a 'columns' attribute")
    cols = [hdf5_text(c) for c in cols]
    if len(cols) != node.shape[1]:
        raise DataError(f"{source}: 'columns' names {len(cols)} columns, data has {node.shape[1]}")
    check_dataset(node, source, allow_external)
    chosen = set(wanted.select(source, cols))
    keep = [j for j, c in enumerate(cols) if c in chosen]
    check_size(source, f"dataset {node.name!r}", node.shape[0], len(keep), limit,
               node.dtype.itemsize)
    arr = node[()] if len(keep) == len(cols) else None
    ulist = node.attrs.get("units")
    raw, units = {}, {}
    for j in keep:
        raw[cols[j]] = arr[:, j] if arr is not None else node[:, j]
        if ulist is not None:
            units[cols[j]] = hdf5_text(ulist[j])
    return raw, units


def _hdf5_group(node, source: str, wanted, limit: float, allow_external: bool):
    """The wanted 1-D datasets of a group, in the order of its ``columns`` attribute."""
    import h5py

    order = [hdf5_text(c) for c in node.attrs.get("columns", [])]
    names = sorted(node.keys(), key=lambda k: order.index(k) if k in order else len(order))
    datasets = {}
    for name in wanted.select(source, names):
        ds = hdf5_get(node, name, source, allow_external)
        if isinstance(ds, h5py.Dataset) and ds.ndim == 1:
            check_dataset(ds, source, allow_external)
            datasets[name] = ds
    if not datasets:
        raise DataError(f"{source}: group {node.name!r} holds no 1-D datasets",
                        hint="pass key= to point at the group holding the channels")
    rows = max(ds.shape[0] for ds in datasets.values())
    itemsize = max(ds.dtype.itemsize for ds in datasets.values())
    check_size(source, f"group {node.name!r}", rows, len(datasets), limit, itemsize)
    raw, units = {}, {}
    for name, ds in datasets.items():
        raw[name] = ds[()]
        if "unit" in ds.attrs:
            units[name] = hdf5_text(ds.attrs["unit"])
    return raw, units


@entry_point
def save(tr: Trajectory, path, *, format: str | None = None, key: str = "/",
         units: str = "si") -> None:
    """Write a trajectory: time as ``t`` (s) then each channel with its unit, SI by default;
    ``units="display"`` writes each channel in the unit its file was written in
    (:meth:`Trajectory.display_unit`: ``force [mN]`` read, ``force [mN]`` written, values in mN),
    which :func:`load` reads back to the same SI values. Written with
    :func:`gripkit.atomic.atomic_write`: a save that fails midway leaves the old file as it was and
    raises :class:`PathError`."""
    if not isinstance(tr, Trajectory):
        raise ArgumentError(f"save(): tr must be a gripkit Trajectory, found {type(tr).__name__}")
    if units not in ("si", "display"):
        raise ArgumentError(f"save(): units must be 'si' or 'display', found {units!r:.40}",
                            hint="'display' writes each channel in the unit its file used")
    check_path(path, "path", "save()")
    path = Path(path)
    fmt = _format(path, format, writing=True)
    if fmt == "mcap":
        raise DataError("gripkit reads MCAP logs but writes CSV, "
                        "Parquet or HDF5", hint="save as .parquet")
    cols = {"t": tr.t, **{n: tr[n] for n in tr.names}}
    units = {"t": "s", **(tr.units if units == "si" else _display(tr, cols))}
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


def _display(tr: Trajectory, cols: dict) -> dict[str, str]:
    """Each channel's display unit; the values in ``cols`` converted to it (in place)."""
    out = {}
    for n in tr.names:
        si, shown = tr.unit(n), tr.display_unit(n)
        if shown != si:
            if not same_dimension(si, shown):
                raise DataError(f"save(): channel {n!r} is in {si!r}, its display unit {shown!r} "
                                f"measures another quantity",
                                hint="correct or remove tr.meta['display_units']")
            cols[n] = convert(cols[n], si, shown)
        out[n] = shown
    return out
