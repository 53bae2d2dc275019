"""`gripkit identify step` as a thin shell over ``identify(data, "step")`` (issue 23): its JSON keys
and text are identify_step's on the file's record; ``--out`` writes a model file that
``gripkit compare``, ``simulate``, ``report`` and ``export c --dt`` take; ``--validate`` gives the
one validation fit. The records: the synthetic step of tests/sysid/test_step_model.py (K = 2.5
mm/V, f_n = 3 Hz, ζ = 0.3, noise σ = 0.01 mm), seeds 0 (estimation) and 1 (validation)."""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

from gripkit.cli import main
from gripkit.io import load, save
from gripkit.sysid import LinearModel, load_model
from gripkit.sysid.model_file import plain
from gripkit.sysid.physical.step_response import identify_step

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "sysid"))
from test_step_model import F_N, K, ZETA, step_record  # noqa: E402


def run(capsys, *args):
    code = main([str(a) for a in args])
    o, e = capsys.readouterr()
    return code, o, e


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("step")
    for name, seed in (("est", 0), ("val", 1)):
        save(step_record(seed=seed), d / f"{name}.csv")
    return d


def test_json_keys_are_identify_steps_and_the_model_file_compares_alike(capsys, files):
    model = files / "step.json"
    code, out, err = run(capsys, "identify", "step", files / "est.csv", "--input", "v",
                         "--output", "x", "--out", model, "--validate", files / "val.csv",
                         "--json")
    assert code == 0, err
    d = json.loads(out)
    res = identify_step(load(files / "est.csv"), input="v", output="x")
    ref = plain(res.to_dict())
    assert {k: d[k] for k in ref} == ref
    assert d["method"] == "lm" and d["input"] == "v" and d["output"] == "x"
    assert d["gain_unit"] == "m/V"  # the file's mm read in SI
    assert abs(d["gain"] - K * 1e-3) < 3 * d["gain_std"]
    assert abs(d["natural_frequency_hz"] - F_N) < 3 * d["natural_frequency_hz_std"]
    assert abs(d["damping_ratio"] - ZETA) < 3 * d["damping_ratio_std"]
    assert d["out"] == str(model) and d["warnings"] == []
    m = load_model(model)
    assert isinstance(m, LinearModel) and m.structure == "step"
    assert m.display_units == {"x": "mm"} and m.data_file == "est.csv"
    code, out, err = run(capsys, "compare", model, files / "est.csv", "--json")
    assert code == 0, err
    c = json.loads(out)
    assert c["structure"] == "step"
    assert c["fit_percent"][0] == pytest.approx(d["model_fit_percent"][0], abs=1e-9)
    assert c["fit_percent"] == m.compare(load(files / "est.csv")).fit_percent
    code, out, err = run(capsys, "compare", model, files / "val.csv", "--json")
    assert code == 0, err
    assert json.loads(out)["fit_percent"] == d["validation"]["fit_percent"]
    assert d["validation"]["fit_percent"][0] > 95.0


def test_text_is_identify_steps_summary(capsys, files):
    code, out, err = run(capsys, "identify", "step", files / "est.csv", "--input", "v",
                         "--output", "x", "--method", "trf")
    assert code == 0, err
    res = identify_step(load(files / "est.csv"), input="v", output="x", method="trf")
    assert out == res.summary() + "\n"


def test_model_file_simulates_reports_and_exports_to_c(capsys, files, tmp_path):
    model = tmp_path / "m.json"
    code, _, err = run(capsys, "identify", "step", files / "est.csv", "--input", "v", "--output",
                       "x", "--out", model, "--report", tmp_path / "rep")
    assert code == 0, err
    assert (tmp_path / "rep" / "index.html").is_file()
    code, _, err = run(capsys, "simulate", model, "--data", files / "est.csv", "--out",
                       tmp_path / "sim.csv")
    assert code == 0, err
    sim = load(tmp_path / "sim.csv")
    m, tr = load_model(model), load(files / "est.csv")
    np.testing.assert_allclose(sim["x"], m.simulate(tr)[:, 0], rtol=1e-12, atol=1e-15)
    code, out, err = run(capsys, "export", "c", model, "--out", tmp_path / "c", "--dt", 0.002,
                         "--json")
    assert code == 0, err
    assert all(Path(f).is_file() for f in json.loads(out)["files"])
