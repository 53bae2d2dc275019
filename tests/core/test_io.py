"""gripkit.io.load: CSV, Parquet, HDF5 round trips and clear errors for bad files."""

import numpy as np
import pytest

from gripkit import DataError, Trajectory
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
    assert tr.fs == 200.0
    with pytest.raises(DataError, match="no time column found.*--fs"):
        load(p)


def test_missing_column_lists_available(tmp_path, traj):
    p = tmp_path / "d.parquet"
    save(traj, p)
    with pytest.raises(DataError, match="column 'pressure' not found; available columns: t, u, force"):
        load(p, columns=["pressure"])


def test_mixed_types(tmp_path):
    p = tmp_path / "d.csv"
    p.write_text("t,y\n0,1\n1,abc\n2,3\n")
    with pytest.raises(DataError, match="column 'y' mixes numbers and text: row 1 holds 'abc'"):
        load(p)


def test_truncated_csv(tmp_path):
    p = tmp_path / "d.csv"
    p.write_text("t,u,y\n0,1,2\n1,2\n")
    with pytest.raises(DataError, match="not a readable CSV"):
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
    p.write_text("t,y\n0,1\n1,\n2,3\n")
    with pytest.raises(DataError, match="1 NaN values"):
        load(p)
    assert load(p, fill="interpolate")["y"][1] == 2.0
    assert load(p, fill="drop").n == 2


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
