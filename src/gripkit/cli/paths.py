"""Checks of the CLI's output paths, made before a command starts its work, so that a result is
never computed and then lost to a path that cannot be written (``--out``, ``--report``,
``--trajectory``), and never written over one of the command's own input files.

A folder counts as writable only when a file can be made in it: the check makes and removes an
empty temporary file there (``os.access`` alone says yes to root on a read-only mount or in
``/sys``, where the write fails later)."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from ..errors import PathError

__all__ = ["output_file", "output_folder", "output_json", "report_folder", "TRAJECTORY_SUFFIXES"]

#: the suffixes a trajectory is written to (:func:`gripkit.io.save`); .txt, .tsv, .mcap and .mat
#: are read but not written
TRAJECTORY_SUFFIXES = (".csv", ".parquet", ".pq", ".h5", ".hdf5", ".hdf")
_WRITTEN = ".csv, .parquet (.pq) or .h5 (.hdf5, .hdf)"


def output_file(path: Path | None, option: str, inputs=()) -> Path | None:
    """``path`` if a data file can be written there (its folders may not exist yet) in a format
    :func:`gripkit.io.save` writes (:data:`TRAJECTORY_SUFFIXES`) and it is none of ``inputs``
    (the command's input files), else :class:`PathError` naming ``option``."""
    if path is None:
        return None
    path = _writable_file(Path(path), option, "result.parquet", inputs)
    suffix = path.suffix.lower()
    if suffix not in TRAJECTORY_SUFFIXES:
        from ..io import FORMATS

        problem = (f"cannot tell the format from the suffix {suffix!r}" if suffix not in FORMATS
                   else f"gripkit reads {suffix} files but does not write them")
        raise PathError(f"{option} {str(path)!r}: {problem}" if suffix else
                        f"{option} {str(path)!r}: no suffix to tell the format from",
                        hint=f"a trajectory is written as {_WRITTEN}: use e.g. "
                             f"{str(path.with_suffix('.csv'))!r}")
    return path


def output_json(path: Path | None, option: str, inputs=()) -> Path | None:
    """``path`` if a JSON file (a model file) can be written there (its folders may not exist
    yet) and it is none of ``inputs``, else :class:`PathError` naming ``option``."""
    if path is None:
        return None
    path = _writable_file(Path(path), option, "model.json", inputs)
    if path.suffix.lower() != ".json":
        raise PathError(f"{option} {str(path)!r}: expected a .json file, found the suffix "
                        f"{path.suffix!r}",
                        hint=f"use {str(path.with_suffix('.json'))!r}")
    return path


def output_folder(path: Path | None, option: str, inputs=()) -> Path | None:
    """``path`` if it is, or can be made, a folder that files can be written to and it is none of
    ``inputs``, else :class:`PathError` naming ``option``."""
    if path is None:
        return None
    path = Path(path)
    _not_an_input(path, option, inputs)
    if path.exists() and not path.is_dir():
        raise PathError(f"{option} {str(path)!r} is a file, expected a folder",
                        hint="choose a folder (it is created if missing)")
    if path.is_dir():
        _probe(path, path, option)
        return path
    _check_folders(path, option)
    return path


def report_folder(path: Path | None, option: str, inputs=()) -> Path | None:
    """``path`` if an HTML report can be written there (:func:`output_folder`, and its own files
    ``index.html`` and ``figures/`` are not in the way: a folder named index.html, a file named
    figures), and ``index.html`` there is none of ``inputs``; else :class:`PathError`."""
    path = output_folder(path, option, inputs)
    if path is None:
        return None
    index, figures = path / "index.html", path / "figures"
    _not_an_input(index, option, inputs)
    if index.is_dir():
        raise PathError(f"{option} {str(path)!r}: {str(index)!r} is a folder, where the report "
                        "writes its page",
                        hint="remove that folder, or choose another report folder")
    if figures.exists() and not figures.is_dir():
        raise PathError(f"{option} {str(path)!r}: {str(figures)!r} is a file, where the report "
                        "writes its figures (a folder)",
                        hint="remove that file, or choose another report folder")
    return path


def _not_an_input(path: Path, option: str, inputs) -> None:
    """A :class:`PathError` when ``path`` is one of the command's input files (the same file by
    ``os.path.samefile`` where both exist, else the same absolute path)."""
    for given in inputs:
        if given is None:
            continue
        try:
            same = os.path.samefile(path, given)
        except OSError:
            same = os.path.abspath(path) == os.path.abspath(given)
        if same:
            raise PathError(f"{option} {str(path)!r} is the input file {str(given)!r}: "
                            "writing there would destroy the data the command reads",
                            hint="choose another path for the output")


def _writable_file(path: Path, option: str, example: str, inputs=()) -> Path:
    """``path`` if it is not a folder nor an input, its folders can be made and the file (if any)
    is writable."""
    if path.is_dir():
        raise PathError(f"{option} {str(path)!r} is a folder, expected a file",
                        hint=f"give a file path such as {str(path / example)!r}")
    _not_an_input(path, option, inputs)
    _check_folders(path, option)
    if path.exists() and not os.access(path, os.W_OK):
        raise PathError(f"{option} {str(path)!r}: permission denied (the file is read-only)",
                        hint="choose another path, or make it writable")
    return path


def _check_folders(path: Path, option: str) -> None:
    """The nearest existing ancestor of ``path`` must be a folder we may write in (the missing ones
    below it are created by the command)."""
    for parent in path.parents:
        if not parent.exists() and not parent.is_symlink():
            continue
        if not parent.is_dir():
            raise PathError(f"{option} {str(path)!r}: {str(parent)!r} is not a folder",
                            hint="choose a path whose parent folders are folders")
        _probe(parent, path, option)
        return


def _probe(folder: Path, path: Path, option: str) -> None:
    """Make and remove an empty temporary file in ``folder``: a :class:`PathError` about
    ``option`` ``path`` when that fails (no permission, a read-only file system, ``/sys``)."""
    try:
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=".gripkit-check-", suffix=".tmp")
    except OSError as exc:
        raise PathError(f"{option} {str(path)!r}: cannot write in {str(folder)!r} "
                        f"({exc.strerror or exc})",
                        hint="choose a path in a folder you may write to") from None
    os.close(fd)
    os.unlink(tmp)
