"""``gripkit demo``: run the seeds' studies on simulated data and write the HTML report."""

from __future__ import annotations

from pathlib import Path

import typer

from .app import app
from .common import emit_json


@app.command()
def demo(out: Path = typer.Option(Path("report"), "--out",
                                  help="Folder for index.html and figures."),
         section: list[str] = typer.Option(None, "--section",
                                           help="Run only these sections (repeatable)."),
         quick: bool = typer.Option(False, "--quick", help="Shorter records and "
                                                           "fewer repetitions."),
         json_out: bool = typer.Option(False, "--json", help="Print the summary as JSON.")):
    """Run the demo study and write OUT/index.html."""
    from ..demos import run_demo
    from .paths import report_folder

    report_folder(out, "--out")
    path, summary = run_demo(out, section or None, quick)
    if json_out:
        emit_json({"report": str(path), "sections": summary})
    else:
        typer.echo(f"report written to {path}")
