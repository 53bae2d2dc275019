"""Bad output paths of ``gripkit identify dynamics --out MODEL.json --report DIR``: one ``error:``
line naming the option, given before any work (the URDF and the log are not read yet)."""

import pytest
from corpus import assert_user_error
from test_bad_urdf_dynamics import OK, _arm, _log


@pytest.fixture
def inputs(tmp_path):
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(_arm())
    return urdf, _log(tmp_path)


def test_out_is_a_folder(cli, inputs, tmp_path):
    (tmp_path / "models").mkdir()
    res = cli("identify", "dynamics", *inputs, *OK, "--out", tmp_path / "models")
    assert_user_error(res, "PathError", "--out")
    assert "is a folder, expected a file" in res.err


def test_out_not_json(cli, inputs, tmp_path):
    res = cli("identify", "dynamics", *inputs, *OK, "--out", tmp_path / "model.csv")
    assert_user_error(res, "PathError", "expected a .json file, found the suffix '.csv'")


def test_out_under_a_file(cli, inputs, tmp_path):
    res = cli("identify", "dynamics", *inputs, *OK, "--out", inputs[1] / "model.json")
    assert_user_error(res, "PathError", "is not a folder")


def test_report_under_a_file(cli, inputs, tmp_path):
    res = cli("identify", "dynamics", *inputs, *OK, "--report", inputs[1] / "report")
    assert_user_error(res, "PathError", "--report")
    assert "is not a folder" in res.err


def test_report_is_a_file(cli, inputs, tmp_path):
    (tmp_path / "notes.txt").write_text("x")
    res = cli("identify", "dynamics", *inputs, *OK, "--report", tmp_path / "notes.txt")
    assert_user_error(res, "PathError", "is a file, expected a folder")


def test_report_or_out_is_an_input(cli, inputs, tmp_path):
    """The log given as the report folder: named as the input it is; the URDF as --out likewise
    (before its suffix is looked at)."""
    res = cli("identify", "dynamics", *inputs, *OK, "--report", inputs[1])
    assert_user_error(res, "PathError", f"--report {str(inputs[1])!r} is the input file")
    res = cli("identify", "dynamics", *inputs, *OK, "--out", inputs[0])
    assert_user_error(res, "PathError", f"--out {str(inputs[0])!r} is the input file")
    assert inputs[0].read_text().startswith("<robot")


def test_paths_checked_before_the_work(cli, tmp_path):
    """A bad --out is reported even though the URDF and the log do not exist: nothing was read."""
    (tmp_path / "models").mkdir()
    res = cli("identify", "dynamics", tmp_path / "missing.urdf", tmp_path / "missing.csv", *OK,
              "--out", tmp_path / "models")
    assert_user_error(res, "PathError", "--out")
    assert not list((tmp_path / "models").iterdir())
