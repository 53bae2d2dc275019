"""MCAP logs on the command line (issue 25, "Files as users have them"): ``--input /topic:field``
works exactly as ``io.load(columns=[...])`` does in Python, the model file names its channels so,
and ``gripkit compare`` reads the log again by those names, reporting the same fit."""

import json
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy import signal

from gripkit.cli import main

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "core"))
from test_io import write_mcap  # noqa: E402


@pytest.fixture(scope="module")
def log(tmp_path_factory):
    """A first-order plant y = 0.5 q⁻¹ u / (1 − 0.8 q⁻¹) logged at 100 Hz on two topics, the
    output with a little noise."""
    rng = np.random.default_rng(3)
    n = 1500
    t = np.arange(n) / 100.0
    u = rng.standard_normal(n)
    y = signal.lfilter([0.0, 0.5], [1.0, -0.8], u) + 0.01 * rng.standard_normal(n)
    p = tmp_path_factory.mktemp("mcap") / "log.mcap"
    write_mcap(p, [("/cmd", t, u[:, None]), ("/force", t, y[:, None])])
    return p


def _run(capsys, *args):
    code = main(list(args))
    out = capsys.readouterr()
    return code, out.out, out.err


def test_identify_and_compare_an_mcap_log_by_topic_field(log, capsys, tmp_path):
    model = tmp_path / "m.json"
    code, out, err = _run(capsys, "identify", "arx", str(log), "--input", "/cmd:data[0]",
                          "--output",
                          "/force:data[0]", "--na", "1", "--nb", "1", "--nk", "1", "--out",
                          str(model), "--json")
    assert code == 0, err
    res = json.loads(out)
    assert res["A"][1] == pytest.approx(-0.8, abs=0.01)   # the plant's pole, recovered
    assert res["B"][1] == pytest.approx(0.5, abs=0.01)
    doc = json.loads(model.read_text())
    assert [d["name"] for d in doc["inputs"]] == ["/cmd:data[0]"]
    code, out, err = _run(capsys, "compare", str(model), str(log), "--json")
    assert code == 0, err
    fit = json.loads(out)["fit_percent"][0]
    assert fit > 95.0


def test_aliases_name_the_channels_on_the_command_line_too(log, capsys):
    code, out, err = _run(capsys, "identify", "arx", str(log), "--input", "u=/cmd:data[0]",
                          "--output",
                          "force=/force:data[0]", "--na", "1", "--nb", "1", "--nk", "1", "--json")
    assert code == 0, err
    assert json.loads(out)["input"] == "u=/cmd:data[0]"
