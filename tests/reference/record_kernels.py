"""Write tests/reference/kernel_records.json: the results of the DLR/HIT finger and TSFM grasp
kernels in the scenarios of tests/systems/dlr_hit/test_dlr_kernel_records.py and
tests/systems/tsfm/test_grasp_kernel_records.py, a dozen rows each (exact, float.hex).

Run from the repository root, with the kernels whose results are the reference:
``PYTHONPATH=src python tests/reference/record_kernels.py``."""

import contextlib
import json
import platform
import subprocess
import sys
import warnings
from pathlib import Path

import numba

TESTS = Path(__file__).resolve().parents[1]
# tests/conftest.py first
for folder in (TESTS / "systems" / "dlr_hit", TESTS / "systems" / "tsfm", TESTS):
    sys.path.insert(0, str(folder))

from conftest import RECORD_RTOL, record_of  # noqa: E402
from test_dlr_kernel_records import _trajectories  # noqa: E402
from test_grasp_kernel_records import _results  # noqa: E402


def _cpu() -> str:
    """The CPU's model name (/proc/cpuinfo on Linux), else what platform knows."""
    with contextlib.suppress(OSError):
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    return platform.processor() or "cpu"


def main():
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                            cwd=TESTS).stdout.strip()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        dlr = _trajectories()
        tsfm = _results()
    records = {"source": f"recorded by tests/reference/record_kernels.py at commit {commit}, "
                         f"{platform.machine()} ({_cpu()}), numba {numba.__version__}; "
                         "each result's shape and a dozen of its rows (float.hex); "
                         "the tests ask for "
                         f"agreement to {RECORD_RTOL} relative",
               "dlr_hit": {k: record_of(v) for k, v in dlr.items()},
               "tsfm": {k: record_of(v) for k, v in tsfm.items()}}
    out = TESTS / "reference" / "kernel_records.json"
    out.write_text(json.dumps(records, indent=1) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
