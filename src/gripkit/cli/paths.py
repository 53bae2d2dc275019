"""Checks of the CLI's output paths, made before a command starts its work, so that a result is
never computed and then lost to a path that cannot be written (``--out``, ``--trajectory``)."""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import PathError

__all__ = ["output_file", "output_folder", "output_json"]

_WRITABLE_FORMATS = ("csv", "parquet", "hdf5")


def output_file(path: Path | None, option: str) -> Path | None:
    """``path`` if a data file can be written there (its folders may not exist yet) in a format
    :func:`gripkit.io.save` writes (.csv, .parquet, .h5), else :class:`PathError` naming
    ``option``."""
    if path is None:
        return None
    path = _writable_file(Path(path), option, "result.parquet")
    from ..io import FORMATS

    if FORMATS.get(path.suffix.lower()) not in _WRITABLE_FORMATS:
        raise PathError(f"{option} {str(path)!r}: cannot tell the format from the suffix "
                        f"{path.suffix!r}",
                        hint="use .csv, .parquet or .h5")
    return path


def output_json(path: Path | None, option: str) -> Path | None:
    """``path`` if a JSON file (a model file) can be written there (its folders may not exist
    yet), else :class:`PathError` naming ``option``."""
    if path is None:
        return None
    path = _writable_file(Path(path), option, "model.json")
    if path.suffix.lower() != ".json":
        raise PathError(f"{option} {str(path)!r}: expected a .json file, found the suffix "
                        f"{path.suffix!r}",
                        hint=f"use {str(path.with_suffix('.json'))!r}")
    return path


def output_folder(path: Path | None, option: str) -> Path | None:
    """``path`` if it is, or can be made, a folder that files can be written to, else
    :class:`PathError` naming ``option``."""
    if path is None:
        return None
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise PathError(f"{option} {str(path)!r} is a file, expected a folder",
                        hint="choose a folder (it is created if missing)")
    if path.is_dir():
        if not os.access(path, os.W_OK | os.X_OK):
            raise PathError(f"{option} {str(path)!r}: permission denied (cannot write "
                            "in this folder)",
                            hint="choose another folder")
        return path
    _check_folders(path, option)
    return path


def _writable_file(path: Path, option: str, example: str) -> Path:
    """``path`` if it is not a folder, its folders can be made and the file (if any) is writable."""
    if path.is_dir():
        raise PathError(f"{option} {str(path)!r} is a folder, expected a file",
                        hint=f"give a file path such as {str(path / example)!r}")
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
        if not os.access(parent, os.W_OK | os.X_OK):
            raise PathError(f"{option} {str(path)!r}: permission denied (cannot write in "
                            f"{str(parent)!r})",
                            hint="choose a path in a folder you may write to")
        return
