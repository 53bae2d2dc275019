"""Output paths are checked before the work, in every command that writes (``--out``,
``--report``): a folder where no file can be made (``/sys``, a read-only mount: ``os.access``
says yes to root there), an output that is one of the command's input files, a report folder
whose ``index.html`` is a folder or whose ``figures`` is a file, a suffix ``simulate`` cannot
write. Each test makes the work itself fail the test if it starts (the fit, the model file's
loading, the simulation), so the error must come first; and nothing is left behind."""

from __future__ import annotations

import errno
import os
import tempfile

import numpy as np
import pytest
from corpus import assert_user_error
from scipy.signal import lfilter

import gripkit.cli.paths as paths
import gripkit.sysid
from gripkit import Trajectory
from gripkit.errors import PathError
from gripkit.io import save


def _work_started(*args, **kwargs):
    pytest.fail("the work started before the output paths were checked")


@pytest.fixture
def record(tmp_path):
    """A 300-sample ARX record (current → force) as CSV, and an ARX model of it saved as JSON."""
    rng = np.random.default_rng(0)
    u = rng.standard_normal(300)
    y = lfilter([0.0, 0.5, 0.3], [1.0, -1.5, 0.7], u) + 0.01 * rng.standard_normal(300)
    tr = Trajectory.uniform(dt=0.01, current=u, force=y, units={"current": "A", "force": "N"})
    data = tmp_path / "good.csv"
    save(tr, data)
    model = tmp_path / "m.json"
    gripkit.sysid.identify(tr, "arx", input="current", output="force", na=2, nb=2,
                           nk=1).save(model)
    return data, model


@pytest.fixture
def no_fit(monkeypatch):
    monkeypatch.setattr(gripkit.sysid, "identify", _work_started)


@pytest.fixture
def unwritable(tmp_path, monkeypatch):
    """A folder in which no file can be made although ``os.access`` allows it (as root on a
    read-only mount): the check's probe gets EROFS there."""
    folder = tmp_path / "readonly"
    folder.mkdir()
    real = tempfile.mkstemp

    def mkstemp(*args, dir=None, **kwargs):
        if dir is not None and os.path.abspath(dir) == str(folder):
            raise OSError(errno.EROFS, os.strerror(errno.EROFS), str(folder))
        return real(*args, dir=dir, **kwargs)

    monkeypatch.setattr(paths.tempfile, "mkstemp", mkstemp)
    assert os.access(folder, os.W_OK)
    return folder


ARX = ("--input", "current", "--output", "force", "--na", 2, "--nb", 2, "--nk", 1)


@pytest.mark.parametrize("command", [
    ("identify", "nlss", "{data}", "--input", "current", "--output", "force"),
    ("identify", "ss", "{data}", "--input", "current", "--output", "force"),
    ("identify", "arx", "{data}", *ARX),
    ("identify", "step", "{data}", "--input", "current", "--output", "force"),
])
@pytest.mark.parametrize("option, name", [("--out", "m.json"), ("--report", "rep")])
def test_identify_unwritable_folder_before_the_fit(cli, record, no_fit, unwritable, command,
                                                   option, name):
    args = [str(record[0]) if a == "{data}" else a for a in command]
    res = cli(*args, option, unwritable / name)
    assert_user_error(res, "PathError", f"{option} '{unwritable / name}': cannot write in "
                                        f"'{unwritable}'")
    assert os.listdir(unwritable) == []


def _can_make_a_file_in(folder: str) -> bool:
    try:
        fd, tmp = tempfile.mkstemp(dir=folder)
    except OSError:
        return False
    os.close(fd)
    os.unlink(tmp)
    return True


def test_sys_is_refused_before_the_fit(cli, record, no_fit):
    """The audit's case, on the real /sys (Linux): no file can be made there, even as root."""
    if not os.path.isdir("/sys/kernel"):
        pytest.skip("needs Linux's /sys (a folder where no file can be made, even as root); the "
                    "same refusal for any unwritable folder is tested above on every system")
    if _can_make_a_file_in("/sys"):  # pragma: no cover - a /sys that takes files
        pytest.skip("this machine lets a file be made in /sys, so there is no refusal to show; "
                    "the unwritable-folder tests above cover the check")
    res = cli("identify", "nlss", record[0], "--input", "current", "--output", "force", "--out",
              "/sys/m.json")
    assert_user_error(res, "PathError", "--out '/sys/m.json': cannot write in '/sys'")


def test_out_and_report_both_checked_before_the_model_is_written(cli, record, no_fit, tmp_path):
    """``--out M --report BAD``: refused before the fit; M is not written."""
    bad = tmp_path / "rep"
    (bad / "index.html").mkdir(parents=True)
    res = cli("identify", "arx", record[0], *ARX, "--out", tmp_path / "M.json", "--report", bad)
    assert_user_error(res, "PathError", f"--report '{bad}': '{bad / 'index.html'}' is a folder")
    assert not (tmp_path / "M.json").exists() and os.listdir(bad) == ["index.html"]
    (bad / "index.html").rmdir()
    (bad / "figures").write_text("x")
    res = cli("identify", "arx", record[0], *ARX, "--out", tmp_path / "M.json", "--report", bad)
    assert_user_error(res, "PathError", f"'{bad / 'figures'}' is a file")
    assert not (tmp_path / "M.json").exists()


def test_identify_output_that_is_an_input(cli, record, no_fit, tmp_path):
    data = record[0]
    before = data.read_bytes()
    res = cli("identify", "arx", data, *ARX, "--report", data)
    assert_user_error(res, "PathError", f"--report '{data}' is the input file '{data}'")
    valid = tmp_path / "valid.json"  # a --validate record is an input too (suffix aside)
    valid.write_text("{}")
    res = cli("identify", "arx", data, *ARX, "--validate", valid, "--out", valid)
    assert_user_error(res, "PathError", f"--out '{valid}' is the input file")
    assert data.read_bytes() == before and valid.read_text() == "{}"


@pytest.fixture
def no_model(monkeypatch):
    monkeypatch.setattr(gripkit.sysid, "load_model", _work_started)


def test_report_over_its_input(cli, record, no_model, tmp_path):
    data, model = record
    before = data.read_bytes()
    res = cli("report", model, data, "--out", data)
    assert_user_error(res, "PathError", f"--out '{data}' is the input file '{data}'")
    assert data.read_bytes() == before


def test_report_folder_checks(cli, record, no_model, tmp_path, unwritable):
    data, model = record
    bad = tmp_path / "rep"
    (bad / "index.html").mkdir(parents=True)
    res = cli("report", model, data, "--out", bad)
    assert_user_error(res, "PathError", "index.html' is a folder, where the report writes its page")
    res = cli("report", model, data, "--out", unwritable / "rep")
    assert_user_error(res, "PathError", f"--out '{unwritable / 'rep'}': cannot write in")
    assert os.listdir(unwritable) == [] and os.listdir(bad) == ["index.html"]


@pytest.mark.parametrize("out, phrase", [
    ("s.xyz", "cannot tell the format from the suffix '.xyz'"),
    ("s", "no suffix to tell the format from"),
    ("s.mcap", "gripkit reads .mcap files but does not write them"),
    ("s.txt", "gripkit reads .txt files but does not write them"),
    ("s.mat", "gripkit reads .mat files but does not write them"),
])
def test_simulate_model_file_suffix_before_simulating(cli, record, monkeypatch, tmp_path, out,
                                                      phrase):
    import gripkit.cli.compare

    monkeypatch.setattr(gripkit.cli.compare, "simulate_model_file", _work_started)
    data, model = record
    res = cli("simulate", model, "--data", data, "--out", tmp_path / out)
    assert_user_error(res, "PathError", phrase)
    assert "a trajectory is written as .csv, .parquet (.pq) or .h5 (.hdf5, .hdf)" in res.err
    assert "format=" not in res.err and not (tmp_path / out).exists()


def test_simulate_over_its_input(cli, record, monkeypatch):
    import gripkit.cli.compare

    monkeypatch.setattr(gripkit.cli.compare, "simulate_model_file", _work_started)
    data, model = record
    before = data.read_bytes()
    res = cli("simulate", model, "--data", data, "--out", data)
    assert_user_error(res, "PathError", f"--out '{data}' is the input file '{data}'")
    assert data.read_bytes() == before


def test_simulate_description_suffix_before_simulating(cli, tmp_path, monkeypatch):
    import gripkit.description as description

    (tmp_path / "msd.toml").write_text("")
    monkeypatch.setattr(description, "load_description", _work_started)
    res = cli("simulate", tmp_path / "msd.toml", "--out", tmp_path / "s.txt")
    assert_user_error(res, "PathError", "gripkit reads .txt files but does not write them")


def test_export_c_out_checked_before_the_model_is_read(cli, record, no_model, unwritable):
    res = cli("export", "c", record[1], "--out", record[0])
    assert_user_error(res, "PathError", "is a file, expected a folder")
    res = cli("export", "c", record[1], "--out", unwritable)
    assert_user_error(res, "PathError", f"--out '{unwritable}': cannot write in")


# --- the report itself: written whole or not at all --------------------------------------------

def _report():
    import matplotlib

    matplotlib.use("Agg")
    from gripkit.report import Report
    from gripkit.report.plots import pyplot

    rep = Report("t")
    fig, ax = pyplot().subplots()
    ax.plot([0, 1], [0, 1])
    rep.section("s").figure(fig, "a line", name="line")
    return rep


def test_report_page_that_is_a_folder_leaves_no_figures(tmp_path):
    (tmp_path / "index.html").mkdir()
    with pytest.raises(PathError, match="report page .*index.html' is a folder") as err:
        _report().write(tmp_path)
    assert "free disk space" not in str(err.value) and "remove that folder" in str(err.value)
    assert os.listdir(tmp_path) == ["index.html"]  # no figures, no temporary folder


def test_report_failing_midway_leaves_no_folder(tmp_path, monkeypatch):
    """The page's write fails after the figure was written: the new folder (and its missing
    parent) are gone again; into an existing folder, nothing of the new report arrives."""
    import gripkit.report.html as html

    real = html.write_bytes

    def failing(path, data, what="file"):
        if what == "report page":
            raise PathError(f"{what} {str(path)!r} could not be written (Is a directory)")
        return real(path, data, what=what)

    monkeypatch.setattr(html, "write_bytes", failing)
    with pytest.raises(PathError, match=f"report page '{tmp_path / 'a' / 'rep'}"):
        _report().write(tmp_path / "a" / "rep")
    assert os.listdir(tmp_path) == []
    (tmp_path / "old").mkdir()
    (tmp_path / "old" / "index.html").write_text("old page")
    with pytest.raises(PathError):
        _report().write(tmp_path / "old")
    assert os.listdir(tmp_path / "old") == ["index.html"]
    assert (tmp_path / "old" / "index.html").read_text() == "old page"
    monkeypatch.setattr(html, "write_bytes", real)  # the same report, written: page and figure
    index = _report().write(tmp_path / "old")
    assert sorted(os.listdir(tmp_path / "old")) == ["figures", "index.html"]
    assert os.listdir(tmp_path / "old" / "figures") == ["line.png"]
    assert index.read_text().startswith("<!DOCTYPE html>")


def test_new_report_folder_has_the_usual_permissions(tmp_path):
    umask = os.umask(0o022)
    try:
        _report().write(tmp_path / "rep")
    finally:
        os.umask(umask)
    assert (tmp_path / "rep").stat().st_mode & 0o777 == 0o755


@pytest.mark.parametrize("code, phrase", [
    (errno.EISDIR, "a folder is in the way"), (errno.ENOSPC, "free disk space"),
    (errno.EROFS, "a folder you may write to"), (errno.ENOTDIR, "a file is in the way"),
])
def test_atomic_write_hint_by_cause(code, phrase):
    from gripkit.atomic import write_hint

    assert phrase in write_hint(OSError(code, os.strerror(code)))


def test_save_unknown_suffix_names_what_save_writes(tmp_path):
    """gripkit.io.save: the hint names the written formats, not the read-only .mcap and .mat."""
    from gripkit.errors import DataError

    tr = Trajectory.uniform(dt=0.1, x=np.zeros(3))
    with pytest.raises(DataError, match=r"from its suffix '\.xyz'; use \.csv, \.parquet or \.h5, "
                                        r"or pass format='csv'") as err:
        save(tr, tmp_path / "s.xyz")
    assert ".mcap" not in str(err.value) and os.listdir(tmp_path) == []


def test_report_figure_that_is_a_folder_is_named_first(tmp_path):
    (tmp_path / "figures" / "line.png").mkdir(parents=True)
    (tmp_path / "index.html").write_text("old page")
    with pytest.raises(PathError, match="report figure .*line.png' is a folder"):
        _report().write(tmp_path)
    assert (tmp_path / "index.html").read_text() == "old page"
    assert sorted(os.listdir(tmp_path)) == ["figures", "index.html"]
