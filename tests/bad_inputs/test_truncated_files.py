"""Property (issue 11, §3): a valid CSV, Parquet or HDF5 file cut at any byte offset loads as the
same
data, or with a warning, or fails with a gripkit error — never as different data in silence and
never with a raw pyarrow/h5py exception.

For CSV, a cut exactly at a line ending leaves a shorter but valid file: its rows must then be the
first rows of the original, value for value. Parquet and HDF5 keep their metadata at the end or
record the file size, so every cut must be an error."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gripkit import DataWarning, GripkitError, Trajectory
from gripkit.io import load, save


@pytest.fixture(scope="module")
def originals(tmp_path_factory):
    """One 200-sample record saved in each format, and its bytes."""
    rng = np.random.default_rng(11)
    t = np.arange(200) / 500.0
    tr = Trajectory(t, {"current": 0.85 + 0.1 * rng.standard_normal(200),
                        "force": 1.529 * np.sin(40 * t) + 0.01 * rng.standard_normal(200)},
                    {"current": "A", "force": "N"})
    folder = tmp_path_factory.mktemp("truncation")
    out = {}
    for suffix in (".csv", ".parquet", ".h5"):
        path = folder / f"record{suffix}"
        save(tr, path)
        out[suffix] = (tr, path.read_bytes())
    return folder, out


def check_cut(folder, original: Trajectory, data: bytes, suffix: str, offset: int) -> str:
    """Load ``data[:offset]``; return the outcome ('error', 'warning' or 'prefix') or fail."""
    path = folder / f"cut-{offset}{suffix}"
    path.write_bytes(data[:offset])
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                tr = load(path)
            except GripkitError:
                return "error"
            except Exception as exc:  # a raw pyarrow/h5py/numpy exception is a failure
                pytest.fail(f"{suffix} cut at byte {offset}/{len(data)}: {type(exc).__module__}."
                            f"{type(exc).__name__}: {exc}")
        if any(issubclass(w.category, DataWarning) for w in caught):
            return "warning"
        # silent: the data must be the original's first rows, exactly
        n = tr.n
        assert suffix == ".csv", f"{suffix} cut at byte {offset}/{len(data)} loaded silently"
        assert tr.names == original.names and tr.units == original.units
        assert 0 < n <= original.n
        np.testing.assert_array_equal(tr.t, original.t[:n])
        for name in original.names:
            np.testing.assert_array_equal(tr[name], original[name][:n])
        return "prefix"
    finally:
        path.unlink()


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".h5"])
@settings(max_examples=200, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture], derandomize=True)
@given(data=st.data())
def test_a_cut_file_never_loads_as_different_data_in_silence(originals, suffix, data):
    folder, files = originals
    original, raw = files[suffix]
    offset = data.draw(st.integers(min_value=0, max_value=len(raw) - 1), label="offset")
    check_cut(folder, original, raw, suffix, offset)


def test_every_outcome_occurs_for_csv(originals):
    """The property above is not vacuous: cuts at a line ending give a silent prefix, cuts inside
    a line a warning or an error."""
    folder, files = originals
    original, raw = files[".csv"]
    line_end = raw.index(b"\n", len(raw) // 2) + 1
    assert check_cut(folder, original, raw, ".csv", line_end) == "prefix"
    # last value cut short
    assert check_cut(folder, original, raw, ".csv", line_end - 3) == "warning"
    # fields missing
    assert check_cut(folder, original, raw, ".csv", raw.index(b",", line_end) + 1) == "error"
    assert check_cut(folder, original, raw, ".csv", 0) == "error"  # empty file
