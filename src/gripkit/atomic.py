"""Atomic file writes: the one way gripkit writes a file.

A file is written to a temporary file in the target's folder, flushed and synced to disk, and
renamed over the target (``os.replace``, atomic on POSIX and Windows). A write that fails midway
(a full disk, a file-size limit, Ctrl-C) leaves the previous file byte for byte as it was and no
temporary file behind; an ``OSError`` becomes a :class:`~gripkit.errors.PathError` that names
the file and says whether an old file was kept:

>>> import pathlib, tempfile
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> write_text(folder / "model.json", "{}\\n", what="model file").read_text()
'{}\\n'
>>> atomic_write(folder / "x.csv", lambda tmp: pathlib.Path(tmp).write_text("t\\n0\\n")).name
'x.csv'
>>> sorted(p.name for p in folder.iterdir())  # no temporary file left
['model.json', 'x.csv']
>>> import shutil; shutil.rmtree(folder)

Model files, simulated and excitation trajectories, reports and their figures, sweep manifests,
job tables and chunks all go through :func:`atomic_write`.
"""

from __future__ import annotations

import contextlib
import errno
import os
import tempfile
from collections.abc import Callable
from pathlib import Path

from .errors import GripkitError, PathError

__all__ = ["atomic_write", "write_bytes", "write_text", "write_hint", "TEMP_SUFFIX"]

#: the suffix of the temporary files (``.<name>.<random>.tmp`` next to the target)
TEMP_SUFFIX = ".tmp"


def _sync_file(path: str) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _sync_folder(folder: Path) -> None:
    """Make the rename durable (POSIX); folders cannot be opened on Windows, so it is skipped."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass  # some file systems do not sync folders; the rename itself is still atomic
    finally:
        os.close(fd)


def write_hint(exc: OSError) -> str:
    """The hint of a write that failed with ``exc``, by its cause: disk space only for a full
    disk (or quota, or file-size limit); a folder or file in the way; no permission."""
    code = getattr(exc, "errno", None)
    if code in (errno.ENOSPC, getattr(errno, "EDQUOT", errno.ENOSPC), errno.EFBIG):
        return "free disk space or choose another path, then write it again"
    if code in (errno.EISDIR, errno.ENOTEMPTY, errno.EEXIST):
        return "a folder is in the way of the file: remove it or choose another path"
    if code == errno.ENOTDIR:
        return "a file is in the way of a folder: remove it or choose another path"
    if code in (errno.EACCES, errno.EPERM, errno.EROFS):
        return "choose a path in a folder you may write to"
    return "choose another path, then write it again"


def atomic_write(path, write: Callable[[str], object], *, what: str = "file",
                 sync: bool = True) -> Path:
    """Write ``path`` atomically: ``write(tmp)`` writes the whole content to the temporary file
    ``tmp`` (a path string in the same folder), which is then synced and renamed over ``path``.

    On any failure (an exception in ``write``, the sync or the rename, KeyboardInterrupt included)
    the temporary file is removed and ``path`` is left untouched. An ``OSError`` is raised as
    :class:`PathError` naming ``what`` and ``path`` and saying that the old file was kept (or that
    none was written); other exceptions propagate unchanged. Missing parent folders are created;
    a ``path`` that is a symbolic link is followed (its target is replaced, the link stays), as a
    plain write would. ``sync=False`` skips the two ``fsync`` calls (file and folder): the write
    stays atomic (the old file or the whole new one), but a power cut may lose it; only for files
    that are checked when read back (sweep chunks, :mod:`gripkit.batch.store`). Returns ``path``
    as a :class:`~pathlib.Path`."""
    given = path = Path(path)
    if path.is_symlink():
        path = Path(os.path.realpath(path))
    existed = path.exists()
    kept = "the previous file was kept unchanged" if existed else "no file was written"
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=TEMP_SUFFIX)
        os.close(fd)
    except OSError as exc:
        raise PathError(f"{what} {str(path)!r} cannot be written ({exc.strerror or exc}); {kept}",
                        hint="check that the folder exists and is writable") from None
    try:
        write(tmp)
        if sync:
            _sync_file(tmp)
        if existed:  # keep the target's permission bits, as an in-place write would; a target
            # we may replace but not stat (a vanished link) keeps mkstemp's private 0600
            with contextlib.suppress(OSError):
                os.chmod(tmp, path.stat().st_mode & 0o7777)
        else:
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; a plain open() gives 0666 & ~umask
        os.replace(tmp, path)
    except BaseException as exc:
        with contextlib.suppress(OSError):  # the temporary file may be gone already; the target is
            os.unlink(tmp)                  # untouched either way, which the error below says
        if isinstance(exc, OSError) and not isinstance(exc, GripkitError):
            reason = exc.strerror or str(exc) or type(exc).__name__
            raise PathError(f"{what} {str(path)!r} could not be written ({reason}); {kept}",
                            hint=write_hint(exc)) from exc
        raise
    if sync:
        _sync_folder(path.parent)
    return given


def write_bytes(path, data: bytes, *, what: str = "file") -> Path:
    """Write ``data`` to ``path`` atomically (see :func:`atomic_write`)."""
    def _write(tmp: str) -> None:
        with open(tmp, "wb") as fh:
            fh.write(data)
            fh.flush()
    return atomic_write(path, _write, what=what)


def write_text(path, text: str, *, what: str = "file", encoding: str = "utf-8") -> Path:
    """Write ``text`` to ``path`` atomically (see :func:`atomic_write`)."""
    return write_bytes(path, text.encode(encoding), what=what)
