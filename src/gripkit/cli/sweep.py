"""``gripkit sweep SPEC.toml``: a parameter sweep or Monte Carlo study, checkpointed per chunk.

Exit codes: 0 every job ran; 1 the sweep was refused or stopped (one ``error:`` line); 3 the sweep
ran but some jobs failed (their errors are in the ``error`` column of the results).
"""

from __future__ import annotations

from pathlib import Path

import typer

from .app import app
from .common import JsonOpt, emit_json, report_warnings

#: exit code of a sweep that ran to the end with failed jobs
EXIT_JOBS_FAILED = 3


@app.command()
def sweep(spec: Path = typer.Argument(..., help="Sweep specification (TOML)."),
          scheduler: str = typer.Option(None, "--scheduler", help="Dask scheduler address "
                                                                  "(tcp://host:8786)."),
          workers: int = typer.Option(None, "--workers", help="Local worker processes "
                                                              "(default: one per core)."),
          backend: str = typer.Option("auto", "--backend", help="auto | process | in-process | "
                                                                "dask (auto: in-process when the "
                                                                "work is below the pool start-up)"),
          out: Path = typer.Option(None, "--out", help="Folder for checkpointed results "
                                                       "(default: sweep-<name>)."),
          resume: bool = typer.Option(False, "--resume", help="Continue an interrupted "
                                                              "sweep in --out."),
          allow_code: bool = typer.Option(
              False, "--allow-code",
              help="Let the file name Python code to import (scenario/model = "
                   "'module:function'): the sweep "
                   "file is then code; use only with files you trust."),
          memory_limit: str = typer.Option(
              None, "--memory-limit", help="Memory the sweep may use, e.g. '8 GB' (default: half "
                                           "the available)."),
          json_out: bool = JsonOpt):
    """Run the sweep SPEC (jobs chunked, results streamed to OUT/chunks/*.parquet)."""
    import warnings

    from ..batch import SweepSpec
    from ..batch import sweep as run
    from .paths import output_folder

    output_folder(out, "--out", [spec])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        s = SweepSpec.from_toml(spec)
        out = out or Path(f"sweep-{s.name}")
        res = run(s, backend=backend, workers=workers, scheduler=scheduler, out=out, resume=resume,
                  allow_code=allow_code, memory_limit=memory_limit)
    lines = report_warnings(caught)
    if json_out:
        emit_json({"name": s.name, "n_jobs": res.n_jobs, "n_failed": res.n_failed,
                   "seconds": res.seconds, "backend": res.backend, "backend_choice": res.choice,
                   "chunk_size": res.chunk_size,
                   "out": str(out), "failures": res.failures[:20], "warnings": lines})
    else:
        typer.echo(res.summary())
    if res.n_failed:
        job, err = res.failures[0]
        typer.echo(f"error: {res.n_failed} of {res.n_jobs} jobs failed (first: job {job}: {err}); "
                   f"their errors are in the error column of {out}", err=True)
        for job, err in res.failures[1:5]:
            typer.echo(f"  job {job} failed: {err}", err=True)
        raise typer.Exit(EXIT_JOBS_FAILED)
