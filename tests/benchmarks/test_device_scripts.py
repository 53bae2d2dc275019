"""The scripts that carry issue 24's remaining rows to the lent machines' Intel Xeon
(benchmarks/intel_pending.sh, benchmarks/pinocchio_bundle.sh) parse as bash, and every benchmark
the device script runs exists (a renamed benchmark would otherwise be found out only there)."""

import re
import shutil
import subprocess
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[2] / "benchmarks"


@pytest.mark.parametrize("name", ["intel_pending.sh", "pinocchio_bundle.sh"])
def test_script_parses(name):
    bash = shutil.which("bash")
    run = subprocess.run([bash, "-n", str(BENCH / name)], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr


def test_device_script_runs_existing_benchmarks():
    text = (BENCH / "intel_pending.sh").read_text(encoding="utf-8")
    called = set(re.findall(r"benchmarks/([a-z_]+\.(?:py|sh))", text))
    assert {"run.py", "ab_rls_wrapper.py", "ab_one_state.py", "pinocchio_bundle.sh",
            "cli_identify_arx.py", "bench_sweep_auto.py"} <= called
    assert all((BENCH / f).is_file() for f in called)
    assert "--only rls" in text and (BENCH / "bench_rls.py").is_file()
