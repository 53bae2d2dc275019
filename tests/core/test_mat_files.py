"""MATLAB .mat files (issue 25, "Data as users have it"; issue 22 item 2 for the 7.3 files):
version 5 through scipy.io, version 7.3 (HDF5 with MATLAB's 512-byte header) through h5py; vectors
are columns by name, an N×k matrix gives name_1 … name_k, samples along the longer dimension;
what is not a channel is named as such; sizes checked before reading; a 7.3 dataset whose values
live in another file is refused."""

import json

import h5py
import numpy as np
import pytest
import scipy.io as sio
from scipy import signal

from gripkit.cli import main
from gripkit.errors import DataError
from gripkit.io import load
from gripkit.io.mat_reader import MAT73_SIGNATURE

N = 400
T = np.arange(N) * 0.01


def _record(seed=0):
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(N)
    y = signal.lfilter([0.0, 0.5], [1.0, -0.8], u) + 0.01 * rng.standard_normal(N)
    return u, y


def write_v73(path, variables: dict, external: str | None = None):
    """A MAT-file 7.3 as MATLAB lays it out: an HDF5 file with a 512-byte user block that starts
    with MATLAB's text header, each variable a dataset of the transposed shape (column-major)
    with its MATLAB_class attribute."""
    with h5py.File(path, "w", userblock_size=512) as f:
        for name, x in variables.items():
            x = np.atleast_2d(np.asarray(x, dtype=np.float64))
            if x.shape[0] == 1:
                x = x.T  # MATLAB column vector N×1
            if external and name == "y":
                ds = (f.create_dataset(name, shape=x.T.shape, dtype="f8",
                                       external=[(external, 0, 8 * x.size)]))
            else:
                ds = f.create_dataset(name, data=x.T)
            ds.attrs["MATLAB_class"] = np.bytes_("double")
    with open(path, "r+b") as fh:
        fh.write(b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Thu Nov 26 12:00:00 2026 "
                 b"HDF5 schema 1.00 .")


def test_version_5_vectors_and_matrix_columns(tmp_path):
    u, y = _record()
    p = tmp_path / "run.mat"
    sio.savemat(p, {"t": T, "u": u, "y": y[:, None], "Y2": np.column_stack([y, 2 * y]).T,
                    "Ts": 0.01,
                    "note": "grasp 3"})
    tr = load(p)
    assert tr.names == ("u", "y", "Y2_1", "Y2_2")
    assert tr.dt == pytest.approx(0.01)
    np.testing.assert_array_equal(tr["u"], u)
    np.testing.assert_array_equal(tr["y"], y)
    np.testing.assert_array_equal(tr["Y2_2"], 2 * y)   # a 2×N matrix: its rows are the channels
    assert load(p, columns=["y"]).names == ("y",)
    with pytest.raises(DataError, match="variable 'Ts' is a scalar, not a data channel"):
        load(p, columns=["Ts"])
    with pytest.raises(DataError, match="variable 'note' is a MATLAB char"):
        load(p, columns=["note"])
    with pytest.raises(DataError, match="column 'force' not found"):
        load(p, columns=["force"])


def test_version_73_reads_the_same_values(tmp_path):
    u, y = _record(1)
    p = tmp_path / "run73.mat"
    write_v73(p, {"t": T, "u": u, "y": y, "Y2": np.column_stack([y, 2 * y])})
    tr = load(p)
    assert sorted(tr.names) == ["Y2_1", "Y2_2", "u", "y"]   # HDF5 lists variables by name
    np.testing.assert_array_equal(tr["u"], u)
    np.testing.assert_array_equal(tr["Y2_2"], 2 * y)


def test_version_73_dataset_in_another_file_is_refused(tmp_path):
    secret = tmp_path / "secret.bin"
    secret.write_bytes(np.full(N, 7391.25).tobytes())   # a value no temporary path contains
    p = tmp_path / "ext.mat"
    write_v73(p, {"t": T, "u": np.zeros(N) + 1.0, "y": np.zeros(N)}, external=str(secret))
    with pytest.raises(DataError, match="'/y' keeps its values in an external file") as err:
        load(p)
    assert "7391" not in str(err.value).replace(str(tmp_path), "")
    assert load(p, allow_external_links=True)["y"][0] == 7391.25


def test_sizes_are_checked_before_reading_and_bad_files_are_named(tmp_path):
    u, y = _record()
    p = tmp_path / "run.mat"
    sio.savemat(p, {"u": u, "y": y})
    with pytest.raises(DataError, match="800 values|400 rows × 2 columns.*beyond the load limit"):
        load(p, fs=100.0, max_bytes=1000)
    bad = tmp_path / "bad.mat"
    bad.write_bytes(b"MATLAB 5.0 MAT-file" + b"\0" * 40)
    with pytest.raises(DataError, match="bad.mat: not a readable MAT-file"):
        load(bad, fs=100.0)


def test_a_corrupt_v73_file_is_named_with_its_format(tmp_path):
    """A 7.3 signature in front of bytes HDF5 cannot read: the one-line error of io.hdf5_open,
    naming the file and the format it claims."""
    bad = tmp_path / "bad73.mat"
    bad.write_bytes(MAT73_SIGNATURE.ljust(512, b" ") + b"\0" * 512)
    with pytest.raises(DataError, match=r"bad73.mat: not a readable MAT-file 7.3 \(truncated or "
                                        r"corrupt\?\)"):
        load(bad, fs=100.0)


def test_identify_from_a_mat_file_on_the_command_line(tmp_path, capsys):
    u, y = _record(2)
    p = tmp_path / "log.mat"
    sio.savemat(p, {"u": u, "y": y})
    code = main(["identify", "arx", str(p), "--input", "u", "--output", "y", "--na", "1", "--nb",
                 "1",
                 "--nk", "1", "--fs", "100", "--json"])
    out = capsys.readouterr()
    assert code == 0, out.err
    res = json.loads(out.out)
    assert res["A"][1] == pytest.approx(-0.8,
                                        abs=0.01) and res["B"][1] == pytest.approx(0.5, abs=0.01)
