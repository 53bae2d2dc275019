"""``gripkit identify arx`` on 2000 rows with the README's unit headers (``time [s]``,
``current [A]``, ``force [N]``), whole process from start to exit (issue 24: target ≤ 0.6 s).

    python benchmarks/cli_identify_arx.py [RUNS]

Runs the CLI as ``python -c "from gripkit.cli import main; ..."`` (the installed ``gripkit``
script does the same import), 2 warm-up runs then RUNS (default 9); prints the median and minimum
of wall time and of the child's CPU time, with the CPU model, and the same for ``import gripkit``
alone. Set BLAS threads in the environment before (the device script sets them to 1)."""

from __future__ import annotations

import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

CLI = "import sys; from gripkit.cli import main; sys.exit(main(sys.argv[1:]))"


def _record(path: Path, n: int = 2000) -> None:
    """A second-order force response to a random current, 1 kHz, with noise (seeded)."""
    rng = np.random.default_rng(7)
    u = rng.standard_normal(n)
    y = np.zeros(n)
    for k in range(2, n):
        y[k] = 1.5 * y[k - 1] - 0.7 * y[k - 2] + 0.5 * u[k - 2]
    y += 0.01 * rng.standard_normal(n)
    rows = "\n".join(f"{k / 1000:.3f},{u[k]:.6f},{y[k]:.6f}" for k in range(n))
    path.write_text("time [s],current [A],force [N]\n" + rows + "\n")


def _timed(cmd: list[str]) -> tuple[float, float]:
    """Wall and CPU seconds (the child's user + system) of one run; exits on failure."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        sys.exit(f"{' '.join(cmd[:3])}: exit {done.returncode}: {done.stderr.strip()[-300:]}")
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def _line(label: str, cmd: list[str], runs: int) -> str:
    for _ in range(2):
        _timed(cmd)
    wall, cpu = zip(*(_timed(cmd) for _ in range(runs)))
    return (f"{label}: wall median {statistics.median(wall):.3f} s min {min(wall):.3f} s; "
            f"cpu median {statistics.median(cpu):.3f} s min {min(cpu):.3f} s "
            f"({runs} runs, 2 warm-up)")


def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def main(runs: int = 9) -> None:
    threads = os.environ.get("OPENBLAS_NUM_THREADS", "not set")
    print(f"# CPU: {_cpu_model()}; Python {platform.python_version()}; "
          f"OPENBLAS_NUM_THREADS={threads}; load {os.getloadavg()[0]:.1f}")
    with tempfile.TemporaryDirectory() as tmp:
        csv = Path(tmp) / "log.csv"
        _record(csv)
        cmd = [sys.executable, "-c", CLI, "identify", "arx", str(csv), "--input", "current",
               "--output", "force", "--na", "2", "--nb", "2", "--nk", "2", "--json"]
        print(_line("identify arx, 2000 rows, unit headers", cmd, runs))
        print(_line("import gripkit", [sys.executable, "-c", "import gripkit"], runs))


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 9)
