"""A CSV file without a header (issue 25, "files as users have them"): every field of its first
line is a number, so that line is the first data row, and the columns are named by their 1-based
position ('1', '2', …); a first line with one field that is not a number stays the header."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.signal import lfilter

from gripkit import DataError, DataWarning
from gripkit.cli import main
from gripkit.io import load

#: a known ARX plant, y[k] = 1.5 y[k-1] − 0.7 y[k-2] + 1.0 u[k-1] + 0.5 u[k-2] (poles 0.75±0.37j)
A_TRUE, B_TRUE = [1.0, -1.5, 0.7], [0.0, 1.0, 0.5]


def _write_rows(path, rows, sep=",", fmt="{:.17g}"):
    path.write_text("".join(sep.join(fmt.format(v) for v in r) + "\n" for r in rows))


def test_first_row_is_kept_and_columns_are_named_by_position(tmp_path):
    p = tmp_path / "raw.csv"
    p.write_text("0,0.5,1.5\n0.01,0.25,2\n0.02,-0.5,3\n")
    tr = load(p, time="1")
    assert tr.names == ("2", "3") and tr.n == 3
    np.testing.assert_array_equal(tr.t, [0.0, 0.01, 0.02])
    np.testing.assert_array_equal(tr["2"], [0.5, 0.25, -0.5])  # the first row: 0.5, 1.5
    np.testing.assert_array_equal(tr["3"], [1.5, 2.0, 3.0])
    assert "no" in tr.meta["header"]
    by_rate = load(p, columns=["2", "3"], fs=100)
    np.testing.assert_array_equal(by_rate["3"], [1.5, 2.0, 3.0])
    np.testing.assert_allclose(by_rate.t, [0.0, 0.01, 0.02], rtol=0, atol=1e-15)


def test_headerless_semicolon_file_with_decimal_commas(tmp_path):
    p = tmp_path / "eu.csv"
    p.write_text("0,0;1,5\n0,1;-2,25\n0,2;3e-1\n")
    tr = load(p, time="1")
    np.testing.assert_array_equal(tr.t, [0.0, 0.1, 0.2])
    np.testing.assert_array_equal(tr["2"], [1.5, -2.25, 0.3])


def test_missing_value_in_the_first_row_keeps_the_row(tmp_path):
    p = tmp_path / "gap.csv"
    p.write_text("0,,1\n1,2,3\n2,4,5\n3,6,7\n4,8,9\n5,10,11\n")
    with pytest.warns(DataWarning, match="1 of them before the first .* copied from the nearest"):
        tr = load(p, time="1", fill="interpolate")
    np.testing.assert_array_equal(tr["2"], [2.0, 2.0, 4.0, 6.0, 8.0, 10.0])  # the end value held
    np.testing.assert_array_equal(tr["3"], [1.0, 3.0, 5.0, 7.0, 9.0, 11.0])


def test_one_word_in_the_first_line_makes_it_a_header(tmp_path):
    """As before: a first line with one field that is not a number names the columns."""
    p = tmp_path / "named.csv"
    p.write_text("0,force,1.5\n0,1,2\n1,3,4\n")
    tr = load(p, time="0")
    assert tr.names == ("force", "1.5")
    np.testing.assert_array_equal(tr["force"], [1.0, 3.0])


def test_without_time_or_rate_the_message_says_there_is_no_header(tmp_path):
    p = tmp_path / "raw.csv"
    p.write_text("0,0.5,1.5\n0.01,0.25,2\n")
    with pytest.raises(DataError, match=r"no time column: the file has no header .* named by "
                                        r"their position, 1 to 3") as exc:
        load(p)
    assert "--time 1" in exc.value.hint
    with pytest.raises(DataError, match=r"column 'force' not found") as exc:
        load(p, columns=["force"], fs=100)
    assert "named by their position, 1 to 3" in exc.value.hint


def test_cli_identify_arx_by_position_recovers_a_known_arx(tmp_path, capsys):
    """``identify arx raw.csv --input 2 --output 3 --fs 100`` on noise-free data of a known ARX:
    the least-squares estimate is the plant (to rounding), and every row is used (N = 400)."""
    rng = np.random.default_rng(25)
    u = rng.standard_normal(400)
    y = lfilter(B_TRUE, A_TRUE, u)
    p = tmp_path / "raw.csv"
    _write_rows(p, np.column_stack([np.arange(400) / 100, u, y]))
    code = main(["identify", "arx", str(p), "--input", "2", "--output", "3", "--na", "2",
                 "--nb", "2", "--nk", "1", "--fs", "100", "--detrend", "none", "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    d = json.loads(out)
    assert d["n_samples"] == 400
    np.testing.assert_allclose(d["A"], A_TRUE, atol=1e-9)
    np.testing.assert_allclose(d["B"], B_TRUE, atol=1e-9)
    code = main(["identify", "arx", str(p), "--input", "2", "--output", "3", "--na", "2",
                 "--nb", "2", "--nk", "1", "--time", "1", "--detrend", "none", "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    np.testing.assert_allclose(json.loads(out)["A"], A_TRUE, atol=1e-9)


def test_cli_without_time_says_how_to_name_it(tmp_path, capsys):
    p = tmp_path / "raw.csv"
    _write_rows(p, np.column_stack([np.arange(50) / 100, np.ones(50), np.arange(50.0)]))
    code = main(["identify", "arx", str(p), "--input", "2", "--output", "3", "--na", "1",
                 "--nb", "1", "--nk", "1"])
    out, err = capsys.readouterr()
    assert code != 0 and "Traceback" not in err
    assert err.startswith("error: DataError:") and "the file has no header" in err


def test_ragged_line_of_a_headerless_file_is_named(tmp_path):
    p = tmp_path / "cut.csv"
    p.write_text("0,1,2\n1,2,3\n2,3\n")
    with pytest.raises(DataError, match=r"line 3 has 2 fields, line 1, the first \(the file has "
                                        r"no header\), has 3"):
        load(p, time="1")
