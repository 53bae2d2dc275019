"""``gripkit sweep SPEC.toml``: a parameter sweep or Monte Carlo study, checkpointed per chunk."""

from __future__ import annotations

from pathlib import Path

import typer

from .app import app
from .common import JsonOpt, emit_json


@app.command()
def sweep(spec: Path = typer.Argument(..., help="Sweep specification (TOML)."),
          scheduler: str = typer.Option(None, "--scheduler", help="Dask scheduler address (tcp://host:8786)."),
          workers: int = typer.Option(None, "--workers", help="Local worker processes (default: one per core)."),
          backend: str = typer.Option("process", "--backend", help="process | in-process | dask"),
          out: Path = typer.Option(None, "--out", help="Folder for checkpointed results (default: sweep-<name>)."),
          resume: bool = typer.Option(False, "--resume", help="Continue an interrupted sweep in --out."),
          json_out: bool = JsonOpt):
    """Run the sweep SPEC (jobs chunked, results streamed to OUT/chunks/*.parquet)."""
    from ..batch import SweepSpec
    from ..batch import sweep as run
    from .paths import output_folder

    output_folder(out, "--out")
    s = SweepSpec.from_toml(spec)
    out = out or Path(f"sweep-{s.name}")
    res = run(s, backend=backend, workers=workers, scheduler=scheduler, out=out, resume=resume)
    if json_out:
        emit_json({"name": s.name, "n_jobs": res.n_jobs, "n_failed": int(res.failed.sum()),
                   "seconds": res.seconds, "backend": res.backend, "chunk_size": res.chunk_size,
                   "out": str(out), "failures": res.failures[:20]})
    else:
        typer.echo(res.summary())
        for job, err in res.failures[:5]:
            typer.echo(f"  job {job} failed: {err}", err=True)
