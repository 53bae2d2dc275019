"""The ``gripkit`` command-line interface (typer + rich).

Errors print one line on stderr, ``error: <Type>: <what>; <how to fix it>``, and exit non-zero;
``--debug`` shows the traceback. "unexpected" is reserved for bugs: a command's own checks raise
gripkit errors, usage mistakes (unknown option, a value that is not a number, a missing option)
print ``error: UsageError: …`` (exit 2), and operating-system errors on paths that slipped past
the checks become ``error: PathError: …`` (:func:`user_error`).
"""

from __future__ import annotations

import errno
import os
import sys
import traceback

__all__ = ["main", "user_error"]


def _build():
    from . import demo, identify_linear, identify_step, sweep, zoo, zoo_discretize  # noqa: F401  (commands register themselves)
    from . import identify_tsfm, simulate  # noqa: F401
    from . import identify_friction  # noqa: F401
    from . import excitation_fourier, identify_dynamics  # noqa: F401
    from . import compare, identify_ss, report_model  # noqa: F401
    from . import export_c  # noqa: F401
    from . import identify_narx  # noqa: F401
    from . import identify_hw  # noqa: F401
    from . import identify_hysteresis  # noqa: F401
    from . import identify_nlss  # noqa: F401
    from .app import app

    return app


def _click_classes(name: str) -> tuple[type, ...]:
    """The exception class ``name`` of click and of the copy of click that recent typer vendors
    (``typer._click``; typer then no longer needs click installed)."""
    import importlib

    found = []
    for module in ("click.exceptions", "typer._click.exceptions", "typer"):
        try:
            cls = getattr(importlib.import_module(module), name, None)
        except ImportError:
            continue
        if isinstance(cls, type):
            found.append(cls)
    return tuple(dict.fromkeys(found))


def _one_line(text: str) -> str:
    return " ".join(ln.strip() for ln in str(text).splitlines() if ln.strip())


def user_error(exc: BaseException):
    """The gripkit error a user should see for ``exc`` (an error of the environment, not of
    gripkit), or ``None`` when ``exc`` is a bug. OS errors on a path become
    :class:`~gripkit.errors.PathError`
    saying what is wrong with the path; undecodable text a :class:`~gripkit.errors.DataError`."""
    from ..errors import DataError, GripkitError, PathError

    if isinstance(exc, GripkitError):
        return exc
    if isinstance(exc, OSError):
        name = exc.filename if exc.filename is not None else exc.filename2
        where = "a path" if name is None else repr(os.fsdecode(name))
        if isinstance(exc, FileNotFoundError):
            return PathError(f"{where} not found", hint="check the path and that its folders exist")
        if isinstance(exc, IsADirectoryError):
            return PathError(f"{where} is a folder, expected a file", hint="give a file path")
        if isinstance(exc, NotADirectoryError):
            return PathError(f"{where}: part of this path is a file, not a folder",
                             hint="choose a path whose parent folders are folders")
        if isinstance(exc, FileExistsError):
            kind = "a folder" if name is not None and os.path.isdir(name) else "a file"
            return (PathError(f"{where} already exists as {kind}",
                              hint="choose another path, or remove it"))
        if isinstance(exc, PermissionError):
            return PathError(f"permission denied on {where}",
                             hint="choose a path you may read or write, or change its permissions")
        reason = exc.strerror or _one_line(exc) or type(exc).__name__
        return PathError(f"{reason} ({where})" if name is not None else "operating-system "
                                                                        f"error: {reason}",
                         hint="free disk space, or "
                              "choose another path" if exc.errno == errno.ENOSPC else None)
    if isinstance(exc, UnicodeDecodeError):
        return DataError(f"a file is not UTF-8 text (byte 0x{exc.object[exc.start]:02x} at "
                         f"offset {exc.start} "
                         f"cannot be decoded)", hint="check that each path names the right file")
    return None


def _usage_error(exc) -> str:
    ctx = getattr(exc, "ctx", None)
    see = f"; see '{ctx.command_path} --help'" if ctx is not None else "; see 'gripkit --help'"
    return f"error: UsageError: {_one_line(exc.format_message()).rstrip('.')}{see}"


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``gripkit`` command; returns the exit code."""
    argv = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in argv
    if debug:  # accepted anywhere on the line (the error lines say "run with --debug")
        argv = ["--debug"] + [a for a in argv if a != "--debug"]
    try:
        app = _build()
        rv = app(args=argv, prog_name="gripkit", standalone_mode=False)
        return rv if isinstance(rv, int) else 0
    except _click_classes("Exit") as exc:
        return exc.exit_code
    except _click_classes("NoArgsIsHelpError") as exc:  # `gripkit identify`: the help is the answer
        exc.show()
        return 0
    # unknown option, a value of the wrong type, ...
    except _click_classes("ClickException") as exc:
        print(_usage_error(exc), file=sys.stderr)
        return exc.exit_code
    except _click_classes("Abort"):
        print("error: aborted", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("error: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:
        if isinstance(exc, OSError) and exc.errno == errno.EPIPE:  # `gripkit zoo list | head`
            return 1
        if debug:
            traceback.print_exc()
        err = user_error(exc)
        if isinstance(exc, MemoryError):
            print("error: MemoryError: not enough memory for this run; make the problem "
                  "smaller (fewer or "
                  "shorter records, fewer jobs)", file=sys.stderr)
        elif err is not None:
            print(f"error: {type(err).__name__}: {_one_line(err)}", file=sys.stderr)
        else:  # a bug in gripkit: still one line unless --debug
            print(f"error: unexpected {type(exc).__name__}: {_one_line(exc)[:500]} "
                  "(a bug in gripkit: run with --debug for the "
                  "traceback and report it)", file=sys.stderr)
        return 1
