"""Text files that used to get a misleading diagnosis or a raw Python error (issue 22, "Unclear
messages"): UTF-16 CSV files, ';' separators with decimal commas, '#' comment lines, and JSON
model files or TOML descriptions nested 100 000 deep or holding a 100 000-digit integer."""

from __future__ import annotations

import numpy as np
import pytest
from corpus import assert_user_error

from gripkit import DataError
from gripkit.errors import ConfigError, ModelError
from gripkit.io import load
from gripkit.io.toml_file import read_toml
from gripkit.sysid import load_dynamics_model, load_model

ROWS = "t,force\n0,1.5\n0.1,2.5\n0.2,3.5\n"


@pytest.mark.parametrize("encoding, why", [
    ("utf-16", "byte-order mark"), ("utf-16-le", "every other byte is NUL"),
    ("utf-16-be", "every other byte is NUL"), ("utf-32", "byte-order mark")])
def test_utf16_csv_is_named(tmp_path, encoding, why):
    """Saved as 'Unicode text' by Excel or Notepad: said so, not 'line 4 has 1 fields'."""
    p = tmp_path / "log.csv"
    p.write_bytes(ROWS.encode(encoding))
    family = "UTF-32" if "32" in encoding else "UTF-16"
    with pytest.raises(DataError, match=f"the file is {family} text .*{why}.*save it as UTF-8"):
        load(p)


def test_utf16_csv_in_the_cli(cli, tmp_path):
    p = tmp_path / "log.csv"
    p.write_bytes("t,u,y\n0,1,2\n0.1,1,2\n".encode("utf-16"))
    res = cli("identify", "arx", p, "--input", "u", "--output", "y", "--na", 1, "--nb", 1,
              "--nk", 1)
    assert_user_error(res, "DataError", "the file is UTF-16 text")


def test_binary_file_named_csv(tmp_path):
    p = tmp_path / "log.csv"
    p.write_bytes(b"t,force\n0,1\n" + bytes(range(256)) * 4)
    with pytest.raises(DataError, match="not a readable CSV file: byte 12 is a NUL byte"):
        load(p)


@pytest.mark.parametrize("text", ["t;force [mN]\n0,0;1,5\n0,1;-2,25\n0,2;3e-1\n",
                                  "t;force [mN]\n0.0;1.5\n0.1;-2.25\n0.2;0.3\n"])
def test_semicolon_separator_with_and_without_decimal_commas(tmp_path, text):
    """A European spreadsheet's export: read as the numbers it shows."""
    p = tmp_path / "eu.csv"
    p.write_text(text)
    tr = load(p)
    np.testing.assert_array_equal(tr.t, [0.0, 0.1, 0.2])
    np.testing.assert_allclose(tr["force"], [1.5e-3, -2.25e-3, 0.3e-3], rtol=1e-15)
    assert tr.units["force"] == "N"


def test_comment_lines_are_skipped(tmp_path):
    """'#' lines before the header and between rows (a logger's notes) are comments."""
    p = tmp_path / "notes.csv"
    p.write_text("# rig 3, finger 2\n# operator: A\nt,force\n0,1.5\n  # paused here\n"
                 "0.1,2.5\n0.2,3.5\n")
    tr = load(p)
    np.testing.assert_array_equal(tr.t, [0.0, 0.1, 0.2])
    np.testing.assert_array_equal(tr["force"], [1.5, 2.5, 3.5])


def test_commented_out_header_is_named(tmp_path):
    """``numpy.savetxt`` writes its header as '# t,force': the first data row would become the
    column names."""
    p = tmp_path / "np.csv"
    p.write_text("# t,force\n0,1.5\n0.1,2.5\n")
    with pytest.raises(DataError, match=r"line 2, the first that is not a comment, holds numbers "
                                        r".*header looks commented out"):
        load(p)


def test_ragged_line_after_comments_is_numbered_in_the_file(tmp_path):
    p = tmp_path / "cut.csv"
    p.write_text("# note\nt,force\n0,1\n# note\n0.1\n0.2,3\n")
    with pytest.raises(DataError, match="line 5 has 1 fields, the header has 2"):
        load(p)


# ------------------------------------------------------------------------------------------------
# model files (JSON) and TOML descriptions

DEEP_JSON = "[" * 100_000 + "]" * 100_000
BIG_INT = "1" * 100_000


@pytest.mark.parametrize("reader, what", [(load_model, "model file"),
                                          (load_dynamics_model, "dynamics model file")])
@pytest.mark.parametrize("text, phrase", [
    (DEEP_JSON, "nests lists or objects deeper than Python's recursion limit"),
    ('{"schema": "gripkit.linear-model", "schema_version": 1, "x": ' + "[" * 900 + "]" * 900 + "}",
     "nests lists or objects more than 32 deep"),
    ('{"schema": "gripkit.linear-model", "schema_version": ' + BIG_INT + "}",
     "Exceeds the limit (4300 digits) for integer string conversion"),
])
def test_hostile_model_files(tmp_path, reader, what, text, phrase):
    """100 000 nested lists (RecursionError in json), 900 (under the recursion limit for parsing,
    over it for hashing), and a 100 000-digit integer (Python's limit on int from text): one-line
    ModelErrors naming the file."""
    p = tmp_path / "evil.json"
    p.write_text(text)
    with pytest.raises(ModelError) as exc:
        reader(p)
    msg = str(exc.value)
    assert f"{what} '{p}'" in msg and phrase in msg and "\n" not in msg


def test_hostile_model_file_in_the_cli(cli, tmp_path):
    p = tmp_path / "evil.json"
    p.write_text(DEEP_JSON)
    data = tmp_path / "io.csv"
    data.write_text("t,u,y\n0,1,2\n0.1,1,2\n0.2,1,2\n")
    assert_user_error(cli("compare", p, data), "ModelError", "deeper than Python's recursion limit")


@pytest.mark.parametrize("text, phrase", [
    ("a = " + "[" * 100_000 + "]" * 100_000 + "\n",
     "nests arrays or tables deeper than Python's recursion limit"),
    ("a = " + "{b = " * 5_000 + "1" + "}" * 5_000 + "\n", "nests arrays or tables deeper"),
    ("a = " + BIG_INT + "\n", "Exceeds the limit (4300 digits)"),
])
def test_hostile_toml_files(tmp_path, text, phrase):
    p = tmp_path / "evil.toml"
    p.write_text(text)
    with pytest.raises(ConfigError) as exc:
        read_toml(p, "model description")
    assert f"model description '{p}' cannot be read" in str(exc.value) and phrase in str(exc.value)


def test_hostile_toml_in_the_cli(cli, tmp_path):
    p = tmp_path / "evil.toml"
    p.write_text("a = " + BIG_INT + "\n")
    assert_user_error(cli("simulate", p), "ConfigError", "Exceeds the limit (4300 digits)")
