"""The FT-G100 command-line interfaces, through gripkit.cli.main: `zoo discretize`, `identify step`,
`zoo check`, and bad input (one line on stderr, non-zero exit)."""

import json

import numpy as np
import pytest

from gripkit.cli import main
from gripkit.io import save
from gripkit.systems.ftg100.identification import step_experiment
from gripkit.systems.ftg100.model import SEED_EQ10


def run(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_zoo_discretize_actuated_json(capsys):
    """`gripkit zoo discretize ftg100-actuated --fs 20000 --json`: eq 10 reproduced (A within 0.2 %,
    B = [0.25, 0], C in metres = printed µm × 1e-6 within 0.5 %), DC gain 0.1878 µm/V ± 1.5 %."""
    code, out, err = run(capsys, "zoo", "discretize", "ftg100-actuated", "--fs", "20000", "--json")
    assert code == 0
    d = json.loads(out)
    for key in ("A", "B", "C", "D", "poles", "dc_gain"):
        assert key in d
    np.testing.assert_allclose(d["A"], SEED_EQ10["A"], rtol=2e-3, atol=1e-12)
    assert d["B"] == [[0.25], [0.0]]
    np.testing.assert_allclose(np.array(d["C"]) * 1e6, SEED_EQ10["C"], rtol=5e-3)
    assert d["D"] == [[0.0]]
    assert d["dc_gain"] == pytest.approx(0.1878e-6, rel=0.015)
    assert len(d["poles"]) == 2 and all(len(p) == 2 for p in d["poles"])
    z = np.array([complex(*p) for p in d["poles"]])
    np.testing.assert_allclose(np.sort_complex(z), np.sort_complex(np.linalg.eigvals(d["A"])),
                               rtol=1e-12)


def test_zoo_discretize_text_and_other_models(capsys):
    code, out, _ = run(capsys, "zoo", "discretize", "ftg100-coupled", "--fs", "20000")
    assert code == 0 and "eq 18 block form" in out and "DC gain" in out
    code, out, _ = (run(capsys, "zoo", "discretize", "ftg100-sensing", "--fs", "20000", "--form",
                        "physical", "--json"))
    assert code == 0 and json.loads(out)["dc_gain"] == pytest.approx(6.05 ** 2 / 235.36, rel=1e-9)


@pytest.mark.parametrize("args, pattern", [
    (("zoo", "discretize", "ftg100-actuated", "--fs", "-5"), "fs"),
    (("zoo", "discretize", "no-such-model", "--fs", "20000"), "no zoo model"),
    (("zoo", "discretize", "ftg100-actuated", "--fs", "20000", "--form", "modal"), "form"),
])
def test_zoo_discretize_bad_input(capsys, args, pattern):
    code, out, err = run(capsys, *args)
    assert code != 0 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:") and pattern in lines[0]


def test_identify_step_json(capsys, tmp_path):
    """`gripkit identify step DATA --input V_in --output x_a --json` on the simulated §III-B step:
    f_n = 1757 Hz and ζ = 0.043 of eq 9 at the seed's values, within 3σ."""
    path = tmp_path / "step.csv"
    save(step_experiment(duration=0.05, seed=4), path)
    code, out, err = (run(capsys, "identify", "step", str(path), "--input", "V_in", "--output",
                          "x_a", "--json"))
    assert code == 0
    d = json.loads(out)
    for key in ("gain", "natural_frequency_hz", "damping_ratio"):
        assert key in d and d[key + "_std"] > 0
    assert abs(d["natural_frequency_hz"] - 1757.2) < 3 * d["natural_frequency_hz_std"]
    assert abs(d["damping_ratio"] - 0.04299) < 3 * d["damping_ratio_std"]
    assert abs(d["gain"] - 0.18887e-6) < 3 * d["gain_std"]
    assert d["gain_unit"] == "m/V"


def test_identify_step_fs_option_and_text(capsys, tmp_path):
    d = step_experiment(duration=0.02, seed=1)
    path = tmp_path / "notime.csv"
    np.savetxt(path, np.column_stack([d["V_in"], d["x_a"]]), delimiter=",", header="u [V],y [um]",
               comments="")
    code, out, _ = (run(capsys, "identify", "step", str(path), "--input", "u", "--output", "y",
                        "--fs", "20000"))
    assert code == 0 and "natural frequency" in out and "Hz" in out


@pytest.mark.parametrize("make, args, pattern", [
    ("good", ("--input", "nope", "--output", "x_a"), "nope"),
    ("good", ("--input", "V_in", "--output", "V_in"), "second-order"),
    ("const", ("--input", "V_in", "--output", "x_a"), "constant"),
    ("nan", ("--input", "V_in", "--output", "x_a"), "NaN"),
    ("missing", ("--input", "V_in", "--output", "x_a"), "not found"),
])
def test_identify_step_bad_input(capsys, tmp_path, make, args, pattern):
    d = step_experiment(duration=0.02, seed=1)
    path = tmp_path / "data.csv"
    if make == "const":
        d = d.with_channels(V_in=np.full(d.n, 70.0))
    if make != "missing":
        save(d, path)
    if make == "nan":
        text = path.read_text().splitlines()
        text[10] = text[10].rsplit(",", 1)[0] + ",nan"
        path.write_text("\n".join(text) + "\n")
    code, out, err = run(capsys, "identify", "step", str(path), *args)
    assert code != 0 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:") and pattern in lines[0]


def test_zoo_check_reports_eq17(capsys):
    code, out, _ = run(capsys, "zoo", "check", "ftg100-sensing", "--json")
    assert code == 3
    d = json.loads(out)
    bad = {f["check"] for f in d["findings"] if not f["consistent"]}
    assert {"eq17-poles", "eq17-implied-M_b"} <= bad
    code, out, _ = run(capsys, "zoo", "check", "ftg100-actuated")
    assert code == 0 and "eq10-poles" in out
