"""Atomic writes (issue 22, item 4): a write that fails midway (a full disk, Ctrl-C) leaves the
previous file byte for byte, leaves no temporary file, and says so. Each writer gripkit has is
driven into the failure: the one helper (gripkit.atomic), model files, reports, io.save and sweep
chunks, and ``excitation fourier --out`` writes the format its suffix names."""

from __future__ import annotations

import builtins
import errno
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from gripkit import atomic  # noqa: E402
from gripkit.errors import PathError  # noqa: E402

OLD = b"the previous good file\n"


class _HalfWriter:
    """A file object that writes half of what it is given, then fails as ``exc``."""

    def __init__(self, fh, exc):
        self._fh, self._exc = fh, exc

    def write(self, data):
        self._fh.write(data[: max(len(data) // 2, 1)])
        self._fh.flush()
        raise self._exc

    def __getattr__(self, name):
        return getattr(self._fh, name)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self._fh.close()


def _enospc():
    return OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


@pytest.fixture
def fail_open(monkeypatch):
    """Make the helper's ``open`` (gripkit.atomic.write_bytes) fail midway with ``exc``."""

    def arm(exc):
        def fake_open(path, mode="r", *a, **k):
            fh = builtins.open(path, mode, *a, **k)
            return _HalfWriter(fh, exc) if "w" in mode else fh
        monkeypatch.setattr(atomic, "open", fake_open, raising=False)
    return arm


def _half_then(exc, at=1):
    """A stand-in for a library writer whose argument ``at`` is the path (``write_table(table,
    path)``, ``savetxt(path, X)``): half a file there, then ``exc``."""
    def writer(*a, **k):
        with builtins.open(a[at], "wb") as fh:
            fh.write(b"PAR1 half a file")
        raise exc
    return writer


def _old_file(path):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(OLD)
    return sorted(os.listdir(path.parent))


def _assert_kept(path, listing, err=None):
    assert path.read_bytes() == OLD
    assert sorted(os.listdir(path.parent)) == listing  # no temporary file left
    if err is not None:
        msg = str(err.value)
        assert repr(str(path)) in msg and "No space left on device" in msg
        assert "the previous file was kept unchanged" in msg


# --- the helper --------------------------------------------------------------------------------
def test_helper_replaces_the_file_and_keeps_permissions(tmp_path):
    p = tmp_path / "a.txt"
    p.write_text("old")
    p.chmod(0o640)
    atomic.write_text(p, "new\n")
    assert p.read_text() == "new\n" and (p.stat().st_mode & 0o777) == 0o640
    q = tmp_path / "sub" / "b.bin"  # a new file in a new folder: the mode a plain open() gives
    atomic.write_bytes(q, b"\x00\x01")
    umask = os.umask(0)
    os.umask(umask)
    assert q.read_bytes() == b"\x00\x01" and (q.stat().st_mode & 0o777) == 0o666 & ~umask
    assert sorted(os.listdir(tmp_path)) == ["a.txt", "sub"]


def test_synced_before_the_rename(tmp_path, monkeypatch):
    """The file, then its folder, are fsynced before and after the rename; sweep chunks are not
    (checked when read back instead, see batch/store.py)."""
    import gripkit.batch.store as store

    calls = []
    real_fsync = os.fsync

    def fsync(fd):  # records whether the target exists yet
        calls.append(os.path.exists(tmp_path / "a.txt"))
        real_fsync(fd)
    monkeypatch.setattr(atomic.os, "fsync", fsync)
    atomic.write_text(tmp_path / "a.txt", "x")
    assert calls == [False, True]  # the temporary file before the rename, the folder after
    calls.clear()
    s = store.ResultStore(tmp_path / "sw")
    s.write_chunk(0, {"job_id": np.arange(2), "y": np.ones(2),
                      "error": np.full(2, None, dtype=object)})
    assert calls == [] and s.chunk_path(0).exists()


def test_helper_writes_through_a_link(tmp_path):
    """A model file reached through a symbolic link: the link stays, its target gets the text."""
    (tmp_path / "real").mkdir()
    target = tmp_path / "real" / "m.json"
    target.write_text("old")
    link = tmp_path / "m.json"
    link.symlink_to(target)
    assert atomic.write_text(link, "new") == link
    assert link.is_symlink() and target.read_text() == "new"
    assert os.listdir(tmp_path / "real") == ["m.json"]


def test_helper_full_disk_midway(tmp_path, fail_open):
    p = tmp_path / "x.json"
    listing = _old_file(p)
    fail_open(_enospc())
    with pytest.raises(PathError, match="could not be written") as err:
        atomic.write_text(p, "{}" * 1000, what="model file")
    _assert_kept(p, listing, err)
    assert str(err.value).startswith("model file ")


def test_helper_new_file_says_none_was_written(tmp_path, fail_open):
    fail_open(_enospc())
    with pytest.raises(PathError, match="no file was written"):
        atomic.write_text(tmp_path / "new.json", "{}")
    assert os.listdir(tmp_path) == []


def test_ctrl_c_midway_leaves_the_old_file(tmp_path, fail_open):
    p = tmp_path / "m.json"
    listing = _old_file(p)
    fail_open(KeyboardInterrupt())
    with pytest.raises(KeyboardInterrupt):
        atomic.write_text(p, "x" * 10_000)
    _assert_kept(p, listing)


def test_failed_rename_leaves_the_old_file(tmp_path, monkeypatch):
    p = tmp_path / "r.txt"
    listing = _old_file(p)

    def no_replace(src, dst):
        raise OSError(errno.EXDEV, os.strerror(errno.EXDEV))
    monkeypatch.setattr(atomic.os, "replace", no_replace)
    with pytest.raises(PathError, match="the previous file was kept unchanged"):
        atomic.write_text(p, "new")
    _assert_kept(p, listing)


# --- every writer ------------------------------------------------------------------------------
def test_model_file_full_disk(tmp_path, fail_open, monkeypatch):
    from gripkit.lti import StateSpace
    from gripkit.sysid import load_model
    from gripkit.sysid.linear.linear_model import LinearModel

    model = LinearModel(StateSpace([[0.5]], [[1.0]], [[1.0]], dt=0.1), "n4sid")
    p = tmp_path / "model.json"
    model.save(p)
    good = p.read_bytes()
    p.write_bytes(OLD)
    listing = sorted(os.listdir(tmp_path))
    fail_open(_enospc())
    with pytest.raises(PathError) as err:
        model.save(p)
    _assert_kept(p, listing, err)
    assert str(err.value).startswith("model file ")
    monkeypatch.delattr(atomic, "open")  # the same save without the fault is whole
    model.save(p)
    assert p.read_bytes() == good
    np.testing.assert_array_equal(load_model(p).system.A, [[0.5]])


def test_report_full_disk(tmp_path, fail_open):
    from gripkit.report import Report

    rep = Report("t")
    sec = rep.section("s")
    sec.table(["a"], [[1.0]])
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    sec.figure(fig, "a line", name="line")
    index = tmp_path / "index.html"
    listing = _old_file(index)
    fail_open(_enospc())
    with pytest.raises(PathError) as err:
        rep.write(tmp_path)
    # the figure is written first, named by where it was going
    assert str(err.value).startswith(f"report figure {str(tmp_path / 'figures' / 'line.png')!r}")
    assert "free disk space" in str(err.value)
    assert index.read_bytes() == OLD
    assert sorted(os.listdir(tmp_path)) == listing  # no figures folder, no temporary folder


@pytest.mark.parametrize("suffix, target", [(".csv", "savetxt"), (".parquet", "write_table")])
def test_io_save_full_disk(tmp_path, monkeypatch, suffix, target):
    import pyarrow.parquet as pq

    from gripkit.io import load, save
    from gripkit.signals import Trajectory

    tr = Trajectory.uniform(dt=0.1, u=np.arange(5.0), units={"u": "N"})
    p = tmp_path / f"out{suffix}"
    save(tr, p)
    np.testing.assert_array_equal(load(p)["u"], np.arange(5.0))
    p.write_bytes(OLD)
    listing = sorted(os.listdir(tmp_path))
    if target == "savetxt":
        monkeypatch.setattr(np, "savetxt", _half_then(_enospc(), at=0))
    else:
        monkeypatch.setattr(pq, "write_table", _half_then(_enospc()))
    with pytest.raises(PathError) as err:
        save(tr, p)
    _assert_kept(p, listing, err)
    assert str(err.value).startswith("trajectory file ")


def test_sweep_chunk_full_disk(tmp_path, monkeypatch):
    import pyarrow.parquet as pq

    from gripkit.batch.store import ResultStore

    store = ResultStore(tmp_path)
    cols = {"job_id": np.arange(3), "peak": np.array([1.0, 2.0, 3.0]),
            "error": np.full(3, None, dtype=object)}
    store.chunks_dir.mkdir(parents=True)
    chunk = store.chunk_path(0)
    listing = _old_file(chunk)
    monkeypatch.setattr(pq, "write_table", _half_then(_enospc()))
    with pytest.raises(PathError) as err:
        store.write_chunk(0, cols)
    _assert_kept(chunk, listing, err)
    assert str(err.value).startswith("sweep chunk ")


def test_cli_model_out_full_disk_one_line(tmp_path, fail_open, capsys):
    """``identify arx --out`` over an existing model: one error line, the old file kept."""
    from gripkit.cli import main
    from gripkit.io import save
    from gripkit.signals import Trajectory

    rng = np.random.default_rng(0)
    u = rng.standard_normal(400)
    y = np.zeros(400)
    for k in range(1, 400):
        y[k] = 0.8 * y[k - 1] + 0.5 * u[k - 1]
    data = tmp_path / "d.csv"
    save(Trajectory.uniform(dt=0.01, u=u, y=y + 1e-3 * rng.standard_normal(400)), data)
    out = tmp_path / "m.json"
    listing = _old_file(out)
    fail_open(_enospc())
    code = main(["identify", "arx", str(data), "--input", "u", "--output", "y",
                 "--na", "1", "--nb", "1", "--nk", "1", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code != 0 and err[-1].startswith("error: PathError: model file ")
    assert "the previous file was kept unchanged" in err[-1] and "Traceback" not in "\n".join(err)
    _assert_kept(out, listing)


# --- excitation fourier: the format the suffix names -------------------------------------------
_LINK = ('<link name="{}"><inertial><mass value="0.1"/>'
         '<inertia ixx="1e-4" iyy="1e-4" izz="1e-4"/></inertial></link>')
_JOINT = ('<joint name="j{}" type="{}"><parent link="l{}"/><child link="l{}"/><axis xyz="0 0 1"/>'
          '<limit lower="-1" upper="1" effort="1" velocity="2"/></joint>')


def test_excitation_parquet_is_parquet(tmp_path, capsys):
    """A revolute and a prismatic joint: ``--out e.parquet`` is Parquet (not CSV text) with the
    same numbers as ``--out e.csv`` and SI units per joint kind; an unknown suffix is refused
    before the design starts."""
    import pyarrow.parquet as pq

    from gripkit.cli import main
    from gripkit.io import load

    urdf = tmp_path / "arm.urdf"
    urdf.write_text('<robot name="arm"><link name="l0"/>' + _LINK.format("l1") + _LINK.format("l2")
                    + _JOINT.format(0, "revolute", 0, 1) + _JOINT.format(1, "prismatic", 1, 2)
                    + "</robot>")
    args = ["excitation", "fourier", str(urdf), "--harmonics", "1", "--f0", "0.5", "--fs", "20"]
    assert main([*args, "--out", str(tmp_path / "e.csv")]) == 0
    assert main([*args, "--out", str(tmp_path / "e.parquet")]) == 0
    assert (tmp_path / "e.parquet").read_bytes()[:4] == b"PAR1"
    assert pq.read_table(tmp_path / "e.parquet").num_rows == 40  # 2 s period at 20 Hz
    tr = load(tmp_path / "e.parquet")
    csv = np.genfromtxt(tmp_path / "e.csv", delimiter=",", names=True)
    assert tr.n == csv.size == 40
    for col in ("q_j0", "qd_j1", "qdd_j1"):
        np.testing.assert_allclose(tr[col], csv[col], rtol=1e-9, atol=1e-12)  # CSV keeps 10 digits
    assert (tr.unit("q_j0"), tr.unit("qd_j0"), tr.unit("qdd_j0")) == ("rad", "rad/s", "rad/s**2")
    assert (tr.unit("q_j1"), tr.unit("qdd_j1")) == ("m", "m/s**2")
    capsys.readouterr()
    assert main([*args, "--out", str(tmp_path / "e.xlsx")]) != 0
    err = capsys.readouterr().err
    assert "error: PathError: --out" in err and "suffix '.xlsx'" in err and "optimising" not in err
    assert not (tmp_path / "e.xlsx").exists()
