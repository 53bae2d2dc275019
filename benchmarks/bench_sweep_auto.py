"""``sweep(backend="auto")`` on 4000 and 8000 small jobs (mass-spring-damper step responses)
beside the same sweep in-process, alternating, end to end (issue 24: on a loaded 2-core machine
the old estimate chose the pool in 8 of 16 trials, 4–20× slower). Target: never slower than
in-process (ratio ≥ 1 within the noise); each row records the load average and the choice."""

from __future__ import annotations

import os

from common import measure_alternating, row


def run(quick: bool) -> list[dict]:
    """Rows for 4000 and 8000 jobs (``quick``: 4000 only); 9 alternating runs each."""
    from gripkit.batch import SweepSpec, sweep
    from gripkit.batch.budget import usable_cores

    rows = []
    for n in (4000,) if quick else (4000, 8000):
        spec = SweepSpec.from_dict({
            "sweep": {"scenario": "step-response", "model": "mass-spring-damper", "samples": n},
            "parameters": {"k": {"uniform": [1.0, 8.0]}, "b": {"uniform": [0.5, 1.0]}},
            "scenario": {"duration": 6.0, "fs": 20.0, "amplitude": 2.0}})
        choices = []

        def auto():
            choices.append(sweep(spec, backend="auto", progress=False).choice)
        load = os.getloadavg()[0]
        t_auto, t_in = measure_alternating(
            [auto, lambda: sweep(spec, backend="in-process", progress=False)], runs=9)
        pooled = sum("process pool" in c for c in choices)
        rows.append(row("batch: sweep auto", f"sweep of {n} short jobs, backend auto, end to end",
                        t_auto, "in-process", t_in,
                        target="ratio ≥ 1 (never slower than in-process)",
                        notes=f"load average {load:.1f}; {usable_cores()} usable of "
                              f"{os.cpu_count()} cores; the pool chosen in {pooled} "
                              f"of {len(choices)} runs; last choice: {choices[-1]}"))
    return rows


if __name__ == "__main__":
    import json
    import sys

    for r in run(quick="--quick" in sys.argv):
        print(json.dumps(r, default=str))
