"""The demo study behind ``gripkit demo``: one module per section, each adding to one report.

A section module defines ``run(report, *, quick=False) -> dict`` (a summary of numbers printed at
the end). Sections run in the order listed here.
"""

from __future__ import annotations

import importlib
import time
from pathlib import Path

from ..errors import ConfigError
from ..progress import status
from ..report import Report

__all__ = ["SECTIONS", "run_demo"]

SECTIONS: dict[str, str] = {
    "amadeus-identification": "gripkit.systems.amadeus.demo_identification",
    "amadeus-hand": "gripkit.systems.amadeus.demo_hand",
    "ftg100": "gripkit.systems.ftg100.demo",
    "tsfm": "gripkit.systems.tsfm.demo",
    "dlr-hit": "gripkit.systems.dlr_hit.demo",
    "batch-robustness": "gripkit.demos.batch_robustness",
}


def run_demo(out_dir="report", sections: list[str] | None = None,
             quick: bool = False) -> tuple[Path, dict]:
    """Run the selected sections (default: all) and write ``out_dir/index.html``."""
    names = list(SECTIONS) if not sections else sections
    for n in names:
        if n not in SECTIONS:
            raise ConfigError(f"no demo section {n!r}", hint=f"available: {', '.join(SECTIONS)}")
    rep = Report("gripkit demo", "The seeds' studies reproduced on simulated data.")
    summary = {}
    t_all = time.perf_counter()
    for i, n in enumerate(names, 1):
        status(f"[{i}/{len(names)}] {n} ...")
        t0 = time.perf_counter()
        mod = importlib.import_module(SECTIONS[n])
        summary[n] = mod.run(rep, quick=quick)
        status(f"[{i}/{len(names)}] {n} done in {time.perf_counter() - t0:.1f} s")
        path = rep.write(out_dir)  # after every section: nothing lost if a later one fails
    status(f"demo finished in {time.perf_counter() - t_all:.1f} s; report: {path}")
    return path, summary
