"""Shared test configuration: headless plotting, deterministic hypothesis runs, and the check of
kernel results against their recording (tests/reference/kernel_records.json)."""

import os
from types import SimpleNamespace

os.environ.setdefault("MPLBACKEND", "Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from hypothesis import settings  # noqa: E402

settings.register_profile("gripkit", deadline=None, max_examples=60, derandomize=True)
settings.load_profile("gripkit")

#: agreement asked of a kernel result with its recording, relative to each entry and its column's
#: largest value. The same code differs by ~1e-16 between CPUs (BLAS kernels and compiled code
#: chosen per CPU); a wrong index or a swapped argument differs by far more.
RECORD_RTOL = 1e-9


def recorded_rows(n: int) -> np.ndarray:
    """The rows of an n-row result that a recording keeps: about a dozen, evenly spread, and the
    last."""
    return np.unique(np.r_[np.arange(0, n, max(1, n // 12)), n - 1])


def record_of(result: np.ndarray) -> dict:
    """A result as a recording: its shape, the kept rows and their values (float.hex, exact)."""
    result = np.asarray(result, dtype=np.float64)
    rows = recorded_rows(result.shape[0])
    return {"shape": list(result.shape), "rows": rows.tolist(),
            "values": [[float(v).hex() for v in result[r]] for r in rows]}


def _check_record(name, result, record):
    """The result has the recorded shape and agrees with the recorded rows to RECORD_RTOL."""
    result = np.asarray(result, dtype=np.float64)
    assert list(result.shape) == record["shape"], \
        f"{name}: shape {result.shape}, recorded {record['shape']}"
    ref = np.array([[float.fromhex(v) for v in row] for row in record["values"]])
    got = result[record["rows"]]
    finite = np.where(np.isfinite(ref), ref, 0.0)
    scale = np.abs(finite).max(axis=0, initial=0.0)
    with np.errstate(invalid="ignore"):
        close = np.abs(got - finite) <= RECORD_RTOL * (np.abs(finite) + scale)
    bad = ~np.where(np.isfinite(ref), close, (got == ref) | (np.isnan(got) & np.isnan(ref)))
    if bad.any():
        r, c = np.argwhere(bad)[0]
        raise AssertionError(f"{name}: row {record['rows'][r]}, column {c}: {got[r, c]!r}, "
                             f"recorded {ref[r, c]!r} ({int(bad.sum())} entries beyond "
                             f"rtol {RECORD_RTOL})")


@pytest.fixture(scope="session")
def assert_matches_record():
    """``check(name, result, record)``: the result has the recorded shape and agrees with the
    recorded rows to RECORD_RTOL."""
    return _check_record


@pytest.fixture(scope="session")
def record_tools():
    """RECORD_RTOL and record_of, for tests of the check (a test module cannot import this file by
    name: several test folders have a conftest.py)."""
    return SimpleNamespace(rtol=RECORD_RTOL, record_of=record_of)


@pytest.fixture
def traced_peak():
    """``run(setup, measured, *args) → (result, peak bytes)``: Python code in a process of its own
    (``sys.argv[1:]`` = ``args``), ``setup`` first, then ``measured`` (which sets ``result``, a
    JSON value) under tracemalloc, then the peak of the traced memory. The process exits without
    ``tracemalloc.stop()``: a CI run crashed once (a segfault in a thread without a Python frame)
    while a test worker stopped it, most likely a race between stopping tracemalloc and another
    thread (Arrow's, numba's) freeing a tracked block."""
    import json
    import subprocess
    import sys

    def run(setup: str, measured: str, *args):
        code = "\n".join([setup, "import json, os, sys, tracemalloc", "tracemalloc.start()",
                          measured, "peak = tracemalloc.get_traced_memory()[1]",
                          "sys.stdout.write(json.dumps([result, peak]))", "sys.stdout.flush()",
                          "os._exit(0)"])
        proc = subprocess.run([sys.executable, "-c", code, *map(str, args)], capture_output=True,
                              text=True, timeout=300)
        assert proc.returncode == 0, proc.stderr[-2000:]
        return json.loads(proc.stdout)

    return run
