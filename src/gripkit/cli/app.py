"""The ``gripkit`` command: typer apps and the error boundary.

Command groups live in their own modules (``identify_*.py``, ``zoo.py``, ``demo.py``, ...), each
adding commands to the apps defined here. Heavy imports happen inside commands so that
``gripkit --help`` stays fast.
"""

from __future__ import annotations

import os

import typer

from .. import progress

app = typer.Typer(name="gripkit", no_args_is_help=True, add_completion=False,
                  pretty_exceptions_enable=False,
                  help="Model, simulate, identify, estimate and control robotic "
                       "grippers and fingers.")
identify_app = typer.Typer(no_args_is_help=True, pretty_exceptions_enable=False,
                           help="Identify models from logged data (prints a summary, or "
                                "JSON with --json).")
zoo_app = typer.Typer(no_args_is_help=True, pretty_exceptions_enable=False,
                      help="The reference systems of the seeds, with parameters and provenance.")
app.add_typer(identify_app, name="identify")
app.add_typer(zoo_app, name="zoo")


def version() -> str:
    """gripkit's version: the installed package's metadata, else ``gripkit.__version__`` (a source
    tree on the path without an install)."""
    from importlib import metadata

    try:
        return metadata.version("gripkit")
    except metadata.PackageNotFoundError:
        from .. import __version__

        return __version__


def _print_version(value: bool) -> None:
    if value:
        typer.echo(f"gripkit {version()}")
        raise typer.Exit(0)


@app.callback()
def _root(ctx: typer.Context,
          debug: bool = typer.Option(False, "--debug", help="Show tracebacks on errors."),
          quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress output."),
          show_version: bool = typer.Option(False, "--version", is_eager=True,
                                            callback=_print_version,
                                            help="Print gripkit's version and exit."),
          allow_external_links: bool = typer.Option(
              False, "--allow-external-links",
              help="Read HDF5 data kept in other files (external links, external storage, virtual "
                   "datasets); refused by default, as a file could name any file on the machine.")):
    progress.set_quiet(quiet)
    if allow_external_links:  # read by gripkit.io.load, for this command only
        before = os.environ.get(_EXTERNAL)
        os.environ[_EXTERNAL] = "1"
        ctx.call_on_close(lambda: _restore(_EXTERNAL, before))


_EXTERNAL = "GRIPKIT_ALLOW_EXTERNAL_LINKS"


def _restore(name: str, value: str | None) -> None:
    if value is None:
        os.environ.pop(name, None)
    else:
        os.environ[name] = value
