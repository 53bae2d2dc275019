"""The ``gripkit`` command-line interface (typer + rich).

Errors print one line on stderr and exit non-zero; ``--debug`` shows the traceback.
"""

from __future__ import annotations

import sys
import traceback

__all__ = ["main"]


def _build():
    from . import demo, identify_linear, identify_step, sweep, zoo, zoo_discretize  # noqa: F401  (commands register themselves)
    from . import identify_tsfm, simulate  # noqa: F401
    from . import identify_friction  # noqa: F401
    from . import compare, identify_ss, report_model  # noqa: F401
    from .app import app

    return app


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``gripkit`` command; returns the exit code."""
    import click

    from ..errors import GripkitError

    argv = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in argv
    try:
        app = _build()
        rv = app(args=argv, prog_name="gripkit", standalone_mode=False)
        code = rv if isinstance(rv, int) else 0
    except click.exceptions.Exit as exc:
        code = exc.exit_code
    except click.ClickException as exc:
        exc.show()
        code = exc.exit_code
    except click.exceptions.Abort:
        print("error: aborted", file=sys.stderr)
        code = 1
    except KeyboardInterrupt:
        print("error: interrupted", file=sys.stderr)
        code = 130
    except GripkitError as exc:
        if debug:
            traceback.print_exc()
        print(f"error: {type(exc).__name__}: {exc}", file=sys.stderr)
        code = 1
    except Exception as exc:  # an unexpected failure: still one line unless --debug
        if debug:
            traceback.print_exc()
        msg = str(exc).splitlines()[0] if str(exc) else ""
        print(f"error: unexpected {type(exc).__name__}: {msg} (run with --debug for the traceback)",
              file=sys.stderr)
        code = 1
    return code
