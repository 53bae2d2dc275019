"""MATLAB ``.mat`` files: version 4 and 5 (to 7.2) through :func:`scipy.io.loadmat`, version 7.3
(an HDF5 file with a 512-byte MATLAB header) through h5py.

What becomes a column:

* a numeric or logical variable with one dimension of length 1 (``N×1``, ``1×N``): a column
  named as the variable (``u``, ``y``);
* a numeric ``N×k`` matrix with ``k > 1``: k columns named ``name_1`` … ``name_k`` (MATLAB's
  1-based column index), the samples along the longer dimension (a ``2×N`` matrix of two rows
  is read as two columns too);
* scalars (``Ts``, a gain), text, cells, structs, objects (``iddata``, ``timeseries``) and
  arrays of three or more dimensions are not channels and are left out; naming one of them in
  ``columns=`` is a DataError that says what it is. Save struct fields as plain variables
  (``u = data.u;``) to read them.

Columns come in the file's order (version 7.3: by name). A variable named ``t``, ``time`` or
``timestamp`` is the time column, as in the other formats;
otherwise give ``fs``. ``.mat`` files carry no units: give them with ``units=`` (or the
command's unit options). Sizes are checked before anything is read (the shapes the file declares,
``scipy.io.whosmat`` or the HDF5 dataspace, against the load limit), and a version 7.3 dataset
that keeps its values in another file is refused as in :mod:`gripkit.io.formats`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import DataError
from .hdf5_links import check_dataset, hdf5_open, hdf5_text
from .table import check_size

__all__ = ["read_mat", "MAT73_SIGNATURE"]

#: the text at the start of a version 7.3 MAT-file's 512-byte user block
MAT73_SIGNATURE = b"MATLAB 7.3 MAT-file"
_NUMERIC = {"double", "single", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64",
            "uint64", "logical"}


def _layout(name: str, shape: tuple, kind: str) -> tuple[list[str], int] | str:
    """The column names and row count of a variable, or why it is not a channel."""
    if kind not in _NUMERIC:
        return f"a MATLAB {kind}"
    dims = [int(d) for d in shape]
    if len(dims) > 2 and any(d != 1 for d in dims[2:]):
        return f"a {'×'.join(map(str, dims))} array"
    dims = (dims + [1, 1])[:2]
    if min(dims) == 0:
        return "empty"
    if max(dims) == 1:
        return "a scalar"
    if min(dims) == 1:
        return [name], max(dims)
    k = min(dims)
    return [f"{name}_{j}" for j in range(1, k + 1)], max(dims)


def _plan(source: str, variables: dict, wanted, limit: float) -> dict[str, list[str]]:
    """{variable: its column names} for the variables to read, the declared size checked."""
    layouts = {v: _layout(v, shape, kind) for v, (shape, kind) in variables.items()}
    columns = {c: v for v, lay in layouts.items() if not isinstance(lay, str) for c in lay[0]}
    if wanted is not None and wanted.columns is not None:
        for c in wanted.columns:
            if c not in columns and c in layouts:
                raise DataError(f"{source}: variable {c!r} is {layouts[c]}, not a data channel",
                                hint="a channel is a numeric vector or the columns of a numeric "
                                     "matrix (name_1, name_2, ...)")
    keep = wanted.select(source, list(columns)) if wanted is not None else list(columns)
    if not keep:
        raise DataError(f"{source}: no numeric vector or matrix variables to read "
                        "(found "
                        f"{', '.join(f'{v} ({lay})' for v, lay in layouts.items()) or 'none'})",
                        hint="save the signals as numeric variables, one per channel")
    plan: dict[str, list[str]] = {}
    for c in keep:
        plan.setdefault(columns[c], []).append(c)
    rows = max(layouts[v][1] for v in plan)
    check_size(source, f"{len(plan)} variable(s)", rows, len(keep), limit)
    return plan


def _columns(name: str, x: np.ndarray, names: list[str]) -> dict[str, np.ndarray]:
    """The columns of one variable's values (samples along the longer dimension)."""
    x = np.asarray(x)
    if x.ndim > 2:
        x = x.reshape(x.shape[:2])  # trailing singleton dimensions (checked by _layout)
    if x.ndim == 1 or 1 in x.shape:
        return {name: x.reshape(-1)}
    if x.shape[0] < x.shape[1]:
        x = x.T
    return {c: x[:, int(c.rsplit("_", 1)[1]) - 1] for c in names}


def _read_v5(path: Path, wanted, limit: float):
    import scipy.io as sio

    try:
        found = sio.whosmat(path)
    except Exception as exc:  # scipy raises ValueError, TypeError, MatReadError for a bad file
        raise DataError(f"{path.name}: not a readable MAT-file (truncated or corrupt?): "
                        f"{str(exc).splitlines()[0] if str(exc) else type(exc).__name__}") from None
    plan = _plan(path.name, {v: (shape, kind) for v, shape, kind in found}, wanted, limit)
    try:
        data = sio.loadmat(path, variable_names=list(plan), squeeze_me=False, mat_dtype=False)
    except Exception as exc:
        raise DataError(f"{path.name}: MAT-file data cannot be read (truncated or corrupt?): "
                        f"{str(exc).splitlines()[0] if str(exc) else type(exc).__name__}") from None
    raw: dict[str, np.ndarray] = {}
    for v, names in plan.items():
        raw.update(_columns(v, data[v], names))
    return raw


def _read_v73(path: Path, wanted, limit: float, allow_external: bool):
    import h5py

    with hdf5_open(path, "MAT-file 7.3") as fh:
        variables = {}
        for name in fh.keys():
            link = fh.get(name, getlink=True)
            if not isinstance(link, h5py.HardLink):
                continue  # MATLAB writes no links; another file's data is never followed
            ds = fh[name]
            if not isinstance(ds, h5py.Dataset) or name.startswith("#"):
                continue  # structs are groups; '#refs#' holds cells' contents
            kind = hdf5_text(ds.attrs.get("MATLAB_class", b"double"))
            # MATLAB writes column-major: an N×k MATLAB matrix is a k×N dataset
            variables[name] = (tuple(reversed(ds.shape)), kind)
        plan = _plan(path.name, variables, wanted, limit)
        raw: dict[str, np.ndarray] = {}
        for v, names in plan.items():
            ds = fh[v]
            check_dataset(ds, path.name, allow_external)
            try:
                raw.update(_columns(v, np.asarray(ds[()]).T, names))
            except OSError as exc:
                raise DataError(f"{path.name}: MAT-file data cannot be read "
                                "(truncated or corrupt?): "
                                f"{exc}") from None
    return raw


def read_mat(path: Path, key=None, delimiter=None, *, wanted=None, limit=None,
             allow_external=False):
    """``(columns, units)`` of a MAT-file (module docstring); no units are stored in the format."""
    limit = float("inf") if limit is None else limit
    with open(path, "rb") as fh:
        head = fh.read(128)
    raw = (_read_v73(path, wanted, limit, allow_external) if head.startswith(MAT73_SIGNATURE)
           else _read_v5(path, wanted, limit))
    lengths = {k: len(v) for k, v in raw.items()}
    if len(set(lengths.values())) > 1:
        raise DataError(f"{path.name}: variables have different lengths {lengths}",
                        hint="read the channels of one length together (columns=)")
    return {k: np.asarray(v, dtype=np.float64) for k, v in raw.items()}, {}
