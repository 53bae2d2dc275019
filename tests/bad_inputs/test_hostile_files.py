"""Data files that name other files or declare sizes they do not hold (issue 22, items 2 and 11).

An HDF5 file can take a dataset's values from any file on the machine (external raw storage, a
virtual dataset, an external link): gripkit refuses each by default with a DataError naming the
dataset, and the other file's bytes never reach a channel or a message; ``allow_external_links``
(CLI: ``gripkit --allow-external-links``) follows them. A file that declares a huge dataset is
refused before anything is allocated, with the estimate and the limit."""

from __future__ import annotations

import os
import re

import h5py
import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from corpus import assert_user_error

from gripkit import DataError, DataWarning, Trajectory
from gripkit.io import load, save

SECRET = b"TOPSECRET-ssh-private-key-0123456789abcdef\n" * 8  # 344 bytes = 43 float64 values
N = len(SECRET) // 8


@pytest.fixture
def secret(tmp_path):
    """A private file outside the data folder."""
    p = tmp_path / "private" / "id_rsa"
    p.parent.mkdir()
    p.write_bytes(SECRET)
    return p


def _data_folder(tmp_path):
    d = tmp_path / "data"
    d.mkdir(exist_ok=True)
    return d


def _refused(path, phrase: str, **kw) -> str:
    with pytest.raises(DataError, match=phrase) as exc:
        load(path, **kw)
    msg = str(exc.value)
    assert "\n" not in msg
    assert "TOPSECRET" not in msg and "ssh-private" not in msg
    return msg


def test_external_raw_storage_is_refused(tmp_path, secret):
    """A dataset whose raw storage is the secret file: refused, naming the dataset."""
    p = _data_folder(tmp_path) / "run.h5"
    with h5py.File(p, "w") as f:
        f["t"] = np.arange(N) / 100.0
        f.create_dataset("force", shape=(N,), dtype="<f8",
                         external=[(str(secret), 0, h5py.h5f.UNLIMITED)])
    msg = _refused(p, "dataset '/force' keeps its values in an external file")
    assert "allow_external_links=True" in msg
    # with the option the values are the file's bytes, read as the dataset says (some look corrupt)
    with pytest.warns(DataWarning, match="look corrupt"):
        tr = load(p, allow_external_links=True)
    np.testing.assert_array_equal(tr["force"], np.frombuffer(SECRET, dtype="<f8"))


def test_external_storage_in_a_two_dimensional_dataset(tmp_path, secret):
    p = _data_folder(tmp_path) / "table.h5"
    with h5py.File(p, "w") as f:
        ds = f.create_dataset("log", shape=(N // 2, 2), dtype="<f8",
                              external=[(str(secret), 0, h5py.h5f.UNLIMITED)])
        ds.attrs["columns"] = ["t", "force"]
    _refused(p, "dataset '/log' keeps its values in an external file", key="log")


def test_virtual_dataset_is_refused(tmp_path, secret):
    """A virtual dataset mapping another HDF5 file's data."""
    other = secret.parent / "other.h5"
    with h5py.File(other, "w") as f:
        f["hidden"] = np.frombuffer(SECRET, dtype="<f8")
    layout = h5py.VirtualLayout(shape=(N,), dtype="<f8")
    layout[:] = h5py.VirtualSource(str(other), "hidden", shape=(N,))
    p = _data_folder(tmp_path) / "run.h5"
    with h5py.File(p, "w") as f:
        f["t"] = np.arange(N) / 100.0
        f.create_virtual_dataset("force", layout, fillvalue=0.0)
    _refused(p, "dataset '/force' is a virtual dataset")


@pytest.mark.parametrize("how", ["link", "soft link to a link", "key through a link"])
def test_external_links_are_refused_unless_allowed(tmp_path, secret, how):
    """An external link to another file's dataset, directly, behind a soft link, or on the
    ``key=`` path: refused by default; followed with ``allow_external_links=True``."""
    other = secret.parent / "other.h5"
    with h5py.File(other, "w") as f:
        f["g/force"] = np.arange(N) * 2.0
        f["g/t"] = np.arange(N) / 100.0
    p = _data_folder(tmp_path) / "run.h5"
    key = None
    with h5py.File(p, "w") as f:
        g = f.create_group("g")
        g["t"] = np.arange(N) / 100.0
        if how == "link":
            g["force"] = h5py.ExternalLink(str(other), "/g/force")
            key, where = "g", "/g/force"
        elif how == "soft link to a link":
            f["outside"] = h5py.ExternalLink(str(other), "/g/force")
            g["force"] = h5py.SoftLink("/outside")
            key, where = "g", "/outside"
        else:
            del f["g"]
            f["g"] = h5py.ExternalLink(str(other), "/g")
            key, where = "g", "/g"
    msg = _refused(p, "is an external link", key=key)
    assert f"{where!r} is an external link to" in msg and "other.h5" in msg
    tr = load(p, key=key, allow_external_links=True)
    np.testing.assert_array_equal(tr["force"], np.arange(N) * 2.0)


def test_environment_variable_allows_external_links(tmp_path, secret, monkeypatch):
    other = secret.parent / "other.h5"
    with h5py.File(other, "w") as f:
        f["force"] = np.arange(5) * 1.0
    p = _data_folder(tmp_path) / "run.h5"
    with h5py.File(p, "w") as f:
        f["t"] = np.arange(5) / 10.0
        f["force"] = h5py.ExternalLink(str(other), "/force")
    monkeypatch.delenv("GRIPKIT_ALLOW_EXTERNAL_LINKS", raising=False)
    _refused(p, "'/force' is an external link")
    monkeypatch.setenv("GRIPKIT_ALLOW_EXTERNAL_LINKS", "1")
    np.testing.assert_array_equal(load(p)["force"], np.arange(5) * 1.0)
    with pytest.raises(DataError, match="is an external link"):  # the keyword wins
        load(p, allow_external_links=False)


def test_cli_refuses_external_links_and_follows_them_when_asked(cli, tmp_path, monkeypatch):
    """``gripkit identify arx`` on a file whose output channel is an external link: a one-line
    DataError; with ``gripkit --allow-external-links`` the model is identified (the ARX
    coefficients of y = 0.5 y₋₁ + u₋₁, noise-free, recovered to 1e-4 after the default mean
    detrending)."""
    monkeypatch.delenv("GRIPKIT_ALLOW_EXTERNAL_LINKS", raising=False)
    rng = np.random.default_rng(5)
    u = rng.standard_normal(300)
    y = np.zeros(300)
    for k in range(1, 300):
        y[k] = 0.5 * y[k - 1] + u[k - 1]
    other = tmp_path / "elsewhere.h5"
    with h5py.File(other, "w") as f:
        f["y"] = y
    p = _data_folder(tmp_path) / "run.h5"
    with h5py.File(p, "w") as f:
        f["t"] = np.arange(300) / 100.0
        f["u"] = u
        f["y"] = h5py.ExternalLink(str(other), "/y")
    args = ("identify", "arx", p, "--input", "u", "--output", "y", "--na", 1, "--nb", 1, "--nk", 1,
            "--json")
    assert_user_error(cli(*args), "DataError", "'/y' is an external link")
    res = cli("--allow-external-links", *args)
    assert "GRIPKIT_ALLOW_EXTERNAL_LINKS" not in os.environ  # for that command only
    assert res.code == 0, res.err
    out = res.json()
    np.testing.assert_allclose(out["A"], [1.0, -0.5], atol=1e-4)
    np.testing.assert_allclose(out["B"], [0.0, 1.0], atol=1e-4)


def test_parquet_metadata_summary_is_refused(tmp_path):
    """A dataset's ``_metadata`` file names the data files holding the row groups: refused."""
    root = tmp_path / "ds"
    collector = []
    table = pa.table({"t": np.arange(10) / 10.0, "force": np.arange(10) * 1.0})
    pq.write_to_dataset(table, root, metadata_collector=collector)
    pq.write_metadata(table.schema, root / "_metadata", metadata_collector=collector)
    msg = _refused(root / "_metadata", "data live in other files", format="parquet")
    assert "_metadata" in msg
    _refused(root, "is a folder, expected a data file")


def test_symlink_to_a_private_file_is_not_echoed(tmp_path, secret):
    """A ``.parquet`` or ``.h5`` name that is a link to a private text file: 'not readable', and
    none of its bytes in the message."""
    for suffix, phrase in ((".parquet", "not a readable Parquet file"),
                           (".h5", "not a readable HDF5 file")):
        link = _data_folder(tmp_path) / f"run{suffix}"
        os.symlink(secret, link)
        _refused(link, phrase)


# ------------------------------------------------------------------------------------------------
# sizes a file only declares (item 11)

def test_declared_huge_hdf5_dataset_is_refused_before_reading(tmp_path, monkeypatch):
    """200 000 000 × 3 float64 declared in a chunked, compressed file of a few kB: 4.8 GB, refused
    by the default limit (at most 4 GiB) with the estimate, before any allocation."""
    monkeypatch.delenv("GRIPKIT_MAX_LOAD_BYTES", raising=False)
    p = tmp_path / "huge.h5"
    with h5py.File(p, "w") as f:
        ds = f.create_dataset("log", shape=(200_000_000, 3), dtype="f8", chunks=(65536, 3),
                              compression="gzip")
        ds.attrs["columns"] = ["t", "force", "current"]
    assert p.stat().st_size < 100_000
    msg = _refused(p, "declares 200000000 rows × 3 columns, about 4.8 GB as float64", key="log")
    assert "beyond the load limit of" in msg and "GRIPKIT_MAX_LOAD_BYTES" in msg
    # columns= reads only what it names (and the time column): 2 of 3 columns, 3.2 GB
    _refused(p, "200000000 rows × 2 columns, about 3.2 GB", key="log", columns=["force"],
             max_bytes=1e9)


def test_declared_huge_group_of_datasets_is_refused(tmp_path):
    p = tmp_path / "huge.h5"
    with h5py.File(p, "w") as f:
        for name in ("t", "force"):
            f.create_dataset(name, shape=(10**9,), dtype="f8", chunks=(2**16,), compression="gzip")
    _refused(p, "group '/' declares 1000000000 rows × 2 columns, about 16 GB")


def test_load_limit_from_keyword_and_environment(tmp_path, monkeypatch):
    """A real 1000-sample record: 2 columns × 1000 rows × 8 bytes = 16 kB. Refused under a 10 kB
    limit (keyword or environment variable), read under 20 kB; every format estimates from what
    the file declares before reading it (Parquet: its row count; HDF5: the dataset shapes)."""
    tr = Trajectory.uniform(dt=0.001, force=np.sin(np.arange(1000) / 50.0))
    for suffix in (".parquet", ".h5"):
        p = tmp_path / f"run{suffix}"
        save(tr, p)
        _refused(p, "1000 rows × 2 columns, about 1.6e-05 GB as float64, beyond the load limit "
                 "of 1e-05 GB", max_bytes=10_000)
        monkeypatch.setenv("GRIPKIT_MAX_LOAD_BYTES", "10000")
        _refused(p, "beyond the load limit of 1e-05 GB")
        monkeypatch.setenv("GRIPKIT_MAX_LOAD_BYTES", "20000")
        np.testing.assert_array_equal(load(p)["force"], tr["force"])
        monkeypatch.delenv("GRIPKIT_MAX_LOAD_BYTES")


def test_bad_load_limits_are_argument_errors(tmp_path, monkeypatch):
    from gripkit.errors import ArgumentError

    p = tmp_path / "run.csv"
    save(Trajectory.uniform(dt=0.1, force=np.ones(3)), p)
    with pytest.raises(ArgumentError, match="max_bytes must be a positive number of bytes"):
        load(p, max_bytes=-1)
    monkeypatch.setenv("GRIPKIT_MAX_LOAD_BYTES", "lots")
    with pytest.raises(ArgumentError, match="GRIPKIT_MAX_LOAD_BYTES must be a number of bytes"):
        load(p)
    with pytest.raises(ArgumentError, match="allow_external_links must be True or False"):
        load(p, allow_external_links="yes")


@pytest.mark.parametrize("chunk_size, limit, phrase", [
    (2**20, 70_000, r"a chunk of the MCAP file declares [0-9.e-]+ GB uncompressed, beyond the "
                    r"load limit of 7e-05 GB"),
    (1024, 20_000, "the MCAP file declares 2000 rows × 2 columns, about 3.2e-05 GB"),
])
def test_mcap_declared_sizes(tmp_path, chunk_size, limit, phrase):
    """An MCAP file's summary declares its chunks' uncompressed sizes and the message count per
    channel: both are checked before a message is decoded (2000 Float64 messages: one chunk of
    about 86 kB, or 1 kB chunks and 2000 × 2 values × 8 bytes = 32 kB)."""
    from mcap_ros2.writer import Writer

    p = tmp_path / "run.mcap"
    with open(p, "wb") as f:
        w = Writer(f, chunk_size=chunk_size)
        schema = w.register_msgdef("std_msgs/Float64", "float64 data\n")
        for k in range(2000):
            w.write_message("/force", schema, {"data": float(k)}, log_time=10**18 + k * 10**6,
                            publish_time=0)
        w.finish()
    _refused(p, phrase, columns=["force=/force:data"], max_bytes=limit)
    tr = load(p, columns=["force=/force:data"], max_bytes=100_000)
    np.testing.assert_array_equal(tr["force"], np.arange(2000.0))


def test_parquet_text_repeated_from_a_dictionary_is_not_multiplied(tmp_path, traced_peak):
    """A dictionary-encoded text column: one 1 MB string for 200 rows, 200 MB if every row got its
    own copy. Read as the one string (Python allocates under 8 MB), then refused as text, the
    message cut to 40 characters of it (measured in a process of its own: ``traced_peak``)."""
    p = tmp_path / "text.parquet"
    note = pa.array(["x" * 2**20] * 200).dictionary_encode()
    pq.write_table(pa.table({"t": np.arange(200) / 1e3, "note": note}), p, compression="zstd")
    small = tmp_path / "small.parquet"  # the reader's first use imports modules: not this test's
    pq.write_table(pa.table({"t": np.arange(3) / 1e3,
                             "note": pa.array(["x"] * 3).dictionary_encode()}),
                   small)
    setup = ("import sys\nfrom gripkit import DataError\nfrom gripkit.io import load\n"
             "def refused(path):\n"
             "    try:\n"
             "        load(path)\n"
             "    except DataError as exc:\n"
             "        return str(exc)\n"
             "first = refused(sys.argv[1])")
    (first, msg), peak = traced_peak(setup, "result = [first, refused(sys.argv[2])]", small, p)
    assert first is not None and "column 'note' mixes numbers and text" in first
    assert msg is not None and "\n" not in msg
    assert re.search(r"column 'note' mixes numbers and text: row 0 holds 'x{40}';", msg), msg
    assert peak < 8e6, peak
    assert len(msg) < 300


def test_parquet_pages_declaring_more_than_the_limit(tmp_path):
    """1000 distinct 1 kB strings: 16 kB as float64 rows, but about 1 MB of uncompressed pages."""
    p = tmp_path / "pages.parquet"
    words = [f"{k:04d}" * 256 for k in range(1000)]
    pq.write_table(pa.table({"t": np.arange(1000) / 1e3, "note": words}), p, use_dictionary=False)
    _refused(p, r"the file's columns declare 0.00\d+ GB uncompressed, beyond the load limit of "
                r"0.0001 GB", max_bytes=100_000)


def test_hdf5_wide_values_count_their_size(tmp_path):
    """Fixed-length strings of 100 000 bytes: 1000 rows declare 100 MB, not 8 kB as float64."""
    p = tmp_path / "text.h5"
    with h5py.File(p, "w") as f:
        f["t"] = np.arange(1000) / 1e3
        f.create_dataset("note", shape=(1000,), dtype="S100000", chunks=(10,), compression="gzip")
    _refused(p, "1000 rows × 2 columns, about 0.2 GB at 100000 bytes a value", max_bytes=50e6)
