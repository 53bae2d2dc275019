"""gripkit.io.load: CSV, Parquet, HDF5 round trips and clear errors for bad files."""

import numpy as np
import pytest

from gripkit import DataError, DataWarning, Trajectory
from gripkit.io import load, save


@pytest.fixture
def traj():
    t = np.arange(50) / 200.0
    return Trajectory(t, {"u": np.sin(t), "force": np.cos(t)}, {"u": "A", "force": "N"})


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".h5"])
def test_roundtrip(tmp_path, traj, suffix):
    p = tmp_path / f"data{suffix}"
    save(traj, p)
    back = load(p)
    assert back.names == ("u", "force")
    assert back.units == {"u": "A", "force": "N"}
    np.testing.assert_array_equal(back.t, traj.t)
    np.testing.assert_array_equal(back["force"], traj["force"])


def test_header_units_converted_to_si(tmp_path):
    p = tmp_path / "d.csv"
    p.write_text("time [ms],force [mN],current [mA]\n0,1,850\n5,2,860\n10,3,870\n")
    tr = load(p)
    np.testing.assert_allclose(tr.t, [0, 0.005, 0.01])
    np.testing.assert_allclose(tr["force"], [1e-3, 2e-3, 3e-3])
    assert tr.unit("current") == "A" and tr["current"][0] == pytest.approx(0.85)


def test_fs_instead_of_time(tmp_path):
    p = tmp_path / "d.csv"
    p.write_text("u,y\n1,2\n3,4\n5,6\n")
    tr = load(p, fs=200.0)
    assert tr.dt == 0.005
    with pytest.raises(DataError, match="no time column found.*--fs"):
        load(p)


def test_missing_column_lists_available(tmp_path, traj):
    p = tmp_path / "d.parquet"
    save(traj, p)
    with pytest.raises(DataError, match="column 'pressure' not found; available "
                                        "columns: t, u, force"):
        load(p, columns=["pressure"])


def test_mixed_types(tmp_path):
    p = tmp_path / "d.csv"
    p.write_text("t,y\n0,1\n1,abc\n2,3\n")
    # the cell's line in the file, the header counted (line 3, not data row 1)
    with pytest.raises(DataError, match="column 'y' mixes numbers and text: line 3 of d.csv "
                                        "holds 'abc'"):
        load(p)


def test_truncated_csv(tmp_path):
    p = tmp_path / "d.csv"
    p.write_text("t,u,y\n0,1,2\n1,2\n")
    with pytest.raises(DataError, match="line 3 has 2 fields, the header has 3: the file "
                                        "looks truncated"):
        load(p)


@pytest.mark.parametrize("suffix", [".parquet", ".h5"])
def test_corrupt_binary(tmp_path, traj, suffix):
    p = tmp_path / f"d{suffix}"
    save(traj, p)
    data = p.read_bytes()
    p.write_bytes(data[: len(data) // 2])
    with pytest.raises(DataError, match="truncated or corrupt"):
        load(p)


def test_nan_and_fill(tmp_path):
    p = tmp_path / "d.csv"
    p.write_text("t,y\n0,1\n1,\n2,3\n3,4\n4,5\n5,6\n")
    with pytest.raises(DataError, match="1 NaN values"):
        load(p)
    with pytest.warns(DataWarning, match=r"column 'y': 1 of 6 samples \(16.7 %\) was missing"):
        assert load(p, fill="interpolate")["y"][1] == 2.0
    assert load(p, fill="drop").n == 5


def test_missing_file_and_unknown_suffix(tmp_path):
    with pytest.raises(DataError, match="not found"):
        load(tmp_path / "nope.csv")
    q = tmp_path / "d.xyz"
    q.write_text("x")
    with pytest.raises(DataError, match="cannot tell the format"):
        load(q)


def test_hdf5_2d_dataset(tmp_path):
    import h5py

    p = tmp_path / "d.h5"
    with h5py.File(p, "w") as fh:
        ds = fh.create_dataset("run1", data=np.column_stack([np.arange(5) / 10, np.ones(5)]))
        ds.attrs["columns"] = ["t", "force"]
        ds.attrs["units"] = ["s", "mN"]
    tr = load(p, key="run1")
    assert tr["force"][0] == pytest.approx(1e-3) and tr.unit("force") == "N"


FLOAT64_ARRAY = ("std_msgs/MultiArrayLayout "
                 "layout\nfloat64[] data\n" + "=" * 80 + "\nMSG: std_msgs/MultiArrayLayout\n"
                 "MultiArrayDimension[] "
                 "dim\nuint32 data_offset\n" + "=" * 80 + "\nMSG: std_msgs/MultiArrayDimension\n"
                 "string label\nuint32 size\nuint32 stride\n")


def write_mcap(path, topics):
    from mcap_ros2.writer import Writer

    with open(path, "wb") as f:
        w = Writer(f)
        schema = w.register_msgdef("std_msgs/Float64MultiArray", FLOAT64_ARRAY)
        for topic, times, values in topics:
            for t, v in zip(times, values):
                w.write_message(topic, schema,
                                {"layout": {"dim": [], "data_offset": 0}, "data": list(v)},
                                log_time=int(round(t * 1e9)), publish_time=int(round(t * 1e9)))
        w.finish()


def test_mcap_topics_aligned_on_first_column(tmp_path):
    """Force at 200 Hz, pressure at 100 Hz: pressure is interpolated onto the force time stamps."""
    import mcap_ros2  # noqa: F401  (a dev dependency: fail, never skip, without it)
    p = tmp_path / "run.mcap"
    tf = 0.02 + np.arange(40) / 200.0
    tp = np.arange(24) / 100.0
    write_mcap(p, [("/finger/force", tf, np.column_stack([np.sin(tf), 2 * tf])),
                   ("/finger/pressure", tp, np.column_stack([3.0 * tp]))])
    tr = load(p, columns=["force=/finger/force:data[1]", "p=/finger/pressure:data[0]"],
              units={"p": "bar"})
    np.testing.assert_allclose(tr.t, tf - tf[0], atol=1e-9)
    np.testing.assert_allclose(tr["force"], 2 * tf, atol=1e-12)
    # linear, so interpolation is exact
    np.testing.assert_allclose(tr["p"], 3.0 * tf * 1e5, rtol=1e-9)
    with pytest.raises(DataError, match="no field 'wrench'"):
        load(p, columns=["/finger/force:wrench.force.z"])
    with pytest.raises(DataError, match="no messages on topics"):
        load(p, columns=["/nope:data[0]"])
    with pytest.raises(DataError, match="alias=.*topic:field"):
        load(p, columns=["force"])
