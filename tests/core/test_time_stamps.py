"""Integer time stamps (issue 22, item 9): ROS nanoseconds since 1970 (1.7e18, beyond float64's
2**53) are read exactly in every format, relative to the first stamp; stamps whose unit is unclear
are refused with the way to give it; other integer columns beyond 2**53 are refused.

The stamps below are 1 ms apart with an odd nanosecond every other sample: a conversion through
float64 before subtracting the first stamp rounds 1.7e18 to multiples of 256 ns and loses it."""

from __future__ import annotations

import h5py
import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from gripkit import DataError
from gripkit.io import load

T0 = 1_700_000_000_123_456_789  # 2023-11-14, in ns since 1970
K = np.arange(50)
STAMPS = T0 + K * 1_000_000 + K % 2  # 1 ms apart, odd samples 1 ns late
EXPECTED = (K * 1_000_000 + K % 2) * 1e-9  # seconds after the first stamp, exact to 1 ulp
FORCE = np.cos(K / 7.0)


def _write(path, stamps, name="stamp", extra=None):
    cols = {name: np.asarray(stamps), "force": FORCE, **(extra or {})}
    if path.suffix == ".csv":
        rows = [",".join(str(v[k]) for v in cols.values()) for k in range(len(K))]
        lines = [",".join(cols)] + rows
        path.write_text("\n".join(lines) + "\n")
    elif path.suffix == ".parquet":
        pq.write_table(pa.table(cols), path)
    else:
        with h5py.File(path, "w") as f:
            for n, v in cols.items():
                f[n] = v


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".h5"])
@pytest.mark.parametrize("name", ["stamp", "t", "timestamp_ns"])
def test_nanosecond_stamps_are_read_exactly(tmp_path, suffix, name):
    """By name (``stamp``, ``*_ns``) or by magnitude (integers from 1e17 under ``t``)."""
    p = tmp_path / f"ros{suffix}"
    _write(p, STAMPS, name)
    tr = load(p)
    np.testing.assert_allclose(tr.t, EXPECTED, rtol=1e-15, atol=0)
    assert tr.t[1] - tr.t[0] == pytest.approx(1.000001e-3, rel=1e-12)  # the 1 ns is kept
    assert tr.meta["time_origin"] == f"{T0} ns"
    np.testing.assert_array_equal(tr["force"], FORCE)
    assert tr.dt == pytest.approx(1e-3, rel=1e-5)


def test_unsigned_stamps_and_a_header_unit(tmp_path):
    """uint64 stamps, and the unit from the header ``stamp [ns]``."""
    p = tmp_path / "u.parquet"
    pq.write_table(pa.table({"stamp [ns]": pa.array(STAMPS.astype(np.uint64)), "force": FORCE}), p)
    np.testing.assert_allclose(load(p).t, EXPECTED, rtol=1e-15, atol=0)


def test_relative_nanoseconds_named_ns(tmp_path):
    """A ``time_ns`` column of small integers (below 2**53): nanoseconds, absolute."""
    p = tmp_path / "rel.csv"
    _write(p, 5_000 + K * 1_000_000, "time_ns")
    tr = load(p)
    np.testing.assert_allclose(tr.t, (5_000 + K * 1_000_000) * 1e-9, rtol=1e-15)
    assert "time_origin" not in tr.meta


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".h5"])
def test_microsecond_stamps_need_their_unit(tmp_path, suffix):
    """Integers of 1.7e15 (microseconds since 1970, or nanoseconds since boot): refused, saying how
    to give the unit; with ``units=`` they are read (1 ms apart)."""
    p = tmp_path / f"us{suffix}"
    _write(p, 1_700_000_000_000_000 + K * 1_000, "stamp")
    with pytest.raises(DataError, match=r"time column 'stamp' holds values up to 1\.7e\+15, too "
                                        r"large for seconds.*give the unit.*'stamp \[us\]'"):
        load(p)
    t = load(p, units={"stamp": "us"}).t  # below 2**53: exact as float64, read as absolute
    assert t[0] == 1.7e9
    np.testing.assert_allclose(t - t[0], K * 1e-3, rtol=0, atol=2.5e-7)  # spacing at 1.7e9 s


def test_floating_point_stamps_beyond_seconds_are_refused(tmp_path):
    """Milliseconds since 1970 written as floats (1.7e12): refused, not read as 5e8-year records."""
    p = tmp_path / "ms.csv"
    p.write_text("t,force\n" + "".join(f"{1.7e12 + k:.1f},{k}\n" for k in range(5)))
    with pytest.raises(DataError, match="too large for seconds.*floating point"):
        load(p)
    np.testing.assert_allclose(load(p, units={"t": "ms"}).t - 1.7e9, np.arange(5) * 1e-3, atol=1e-6)


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".h5"])
def test_other_integer_columns_beyond_2_53_are_refused(tmp_path, suffix):
    """A data column of 64-bit counts beyond 2**53: refused, naming it (float64 would round it)."""
    p = tmp_path / f"count{suffix}"
    _write(p, K * 1_000_000, "time_ns", extra={"ticks": 2**60 + K})
    with pytest.raises(DataError, match=r"column 'ticks' holds integers up to "
                                        r"1152921504606847025, beyond 2\*\*53"):
        load(p)
    tr = load(p, columns=["force"])  # left out, the rest reads
    np.testing.assert_array_equal(tr["force"], FORCE)


def test_mcap_stamps_keep_nanoseconds(tmp_path):
    """MCAP log times of 1.7e18 ns, 1 ms apart with an odd nanosecond: exact after the first."""
    from mcap_ros2.writer import Writer

    p = tmp_path / "run.mcap"
    with open(p, "wb") as f:
        w = Writer(f)
        schema = w.register_msgdef("std_msgs/Float64", "float64 data\n")
        for k, s in zip(K, STAMPS):
            w.write_message("/force", schema, {"data": FORCE[k]}, log_time=int(s),
                            publish_time=int(s))
        w.finish()
    tr = load(p, columns=["force=/force:data"])
    np.testing.assert_allclose(tr.t, EXPECTED, rtol=1e-15, atol=0)
    np.testing.assert_array_equal(tr["force"], FORCE)
