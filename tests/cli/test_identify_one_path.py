"""One identification path (issue 23 item 2): every ``gripkit identify`` command that yields a
model is a shell over ``gripkit.sysid.identify`` and ``identify_results.validate_model``, so the
CLI's JSON numbers are the Python call's, bit for bit, on the file read by ``gripkit.io.load``;
``--out``, ``--report`` and ``--validate`` are on every such command; the model file carries the
data file's name and SHA-256."""

import hashlib
import json

import numpy as np
import pytest
from scipy import signal

from gripkit import Trajectory
from gripkit.cli import main
from gripkit.io import load, save
from gripkit.sysid import identify, load_model
from gripkit.sysid.identify_results import validate_model
from gripkit.sysid.linear.linear_model import VALIDATION_FIT


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """y = 0.4 q⁻¹/(1 − 0.7 q⁻¹) u + noise around u = 1 V; the validation record at u = 1.3 V."""
    d = tmp_path_factory.mktemp("one")
    out = {"dir": d}
    for name, seed, shift in (("est", 1, 0.0), ("val", 2, 0.3)):
        rng = np.random.default_rng(seed)
        u = 1.0 + shift + rng.standard_normal(2000)
        y = signal.lfilter([0, 0.4], [1, -0.7], u) + 0.02 * rng.standard_normal(2000)
        out[name] = d / f"{name}.csv"
        save(Trajectory.uniform(dt=0.01, u=u, y=y, units={"u": "V", "y": "N"}), out[name])
    return out


def _json(capsys, *args):
    code = main([*map(str, args), "--json"])
    cap = capsys.readouterr()
    assert code == 0, cap.err
    return json.loads(cap.out)


@pytest.mark.parametrize("method, orders, options", [
    ("arx", ["--na", "1", "--nb", "1", "--nk", "1"], dict(na=1, nb=1, nk=1)),
    ("armax", ["--na", "1", "--nb", "1", "--nc", "1", "--nk", "1"], dict(na=1, nb=1, nc=1, nk=1)),
    ("oe", ["--nb", "1", "--nf", "1", "--nk", "1"], dict(nb=1, nf=1, nk=1)),
])
def test_polynomial_cli_is_the_python_fit(files, capsys, method, orders, options):
    model_file = files["dir"] / f"{method}.json"
    res = _json(capsys, "identify", method, files["est"], "--input", "u", "--output", "y", *orders,
                "--validate", files["val"], "--out", model_file, "--report",
                files["dir"] / f"rep-{method}")
    py = identify(load(files["est"]), method, input="u", output="y", **options)
    assert res["theta"] == py.theta.tolist()  # bit for bit
    val = validate_model(py, load(files["val"]))
    assert res["validation"]["fit_percent"] == val.fit_percent == res["validation_fit_percent"]
    assert res["validation"]["definition"] == VALIDATION_FIT
    assert res["validation"]["prediction_fit_percent"] == val.one_step.prediction_fit_percent
    # the noise-free system: pole 0.7 (ARX is biased by the noise, within 0.01 here)
    assert abs(py.poles()[0] - 0.7) < 0.01
    m = load_model(model_file)
    assert (m.data_file, m.data_hash) == ("est.csv",
                                          hashlib.sha256(files["est"].read_bytes()).hexdigest())
    assert (files["dir"] / f"rep-{method}" / "index.html").is_file()


def test_ss_and_tf_cli_are_the_python_fit(files, capsys):
    res = _json(capsys, "identify", "ss", files["est"], "--input", "u", "--output", "y",
                "--order", "1", "--validate", files["val"])
    py = identify(load(files["est"]), "ss", input="u", output="y", order=1,
                  validate=load(files["val"]))
    assert res["A"] == py.system.A.tolist() and res["C"] == py.system.C.tolist()
    assert res["validation"]["fit_percent"] == validate_model(py, load(files["val"])).fit_percent
    res = _json(capsys, "identify", "tf", files["est"], "--input", "u", "--output", "y",
                "--poles", "1", "--zeros", "0", "--validate", files["val"])
    py = identify(load(files["est"]), "tf", input="u", output="y", poles=1, zeros=0)
    assert res["den"] == list(py.system.denominator())
    # continuous pole of the discrete 0.7 at 100 Hz: ln(0.7)/0.01 = −35.67 rad/s
    assert res["poles"][0][0] == pytest.approx(np.log(0.7) / 0.01, rel=0.02)
    assert res["validation"]["fit_percent"] == validate_model(py, load(files["val"])).fit_percent


def test_search_out_writes_the_best_structure(files, capsys):
    model_file = files["dir"] / "best.json"
    rows = _json(capsys, "identify", "search", files["est"], "--input", "u", "--output", "y",
                 "--na", "1:2", "--nb", "1:2", "--nk", "1:2", "--out", model_file)
    best = rows[0]
    py = identify(load(files["est"]), "arx", input="u", output="y", na=best["na"], nb=best["nb"],
                  nk=best["nk"])
    m = load_model(model_file)
    assert m.label == py.label and best["nk"] == 1  # the true delay of one sample
    np.testing.assert_array_equal(m.A, py.A)


def test_narx_validation_is_the_library_one(files, capsys):
    res = _json(capsys, "identify", "narx", files["est"], "--input", "u", "--output", "y",
                "--degree", "1", "--lags", "1", "--terms", "2", "--validate", files["val"])
    py = identify(load(files["est"]), "narx", input="u", output="y", degree=1, lags=1, terms=2,
                  validate=load(files["val"]))
    assert res["validation"]["fit_percent"] == py.validation_fit_percent
    assert res["validation"]["initial_state"] == "measured"
    fitted = py.compare(load(files["val"]))   # the one fit, with its one definition
    assert res["validation"]["definition"] == fitted.definition
    assert res["validation"]["fit_percent"] == fitted.fit_percent[0]


def test_rls_help_says_why_it_has_no_out(capsys):
    code = main(["identify", "rls", "--help"])
    assert code == 0
    assert "No --out, --report or --validate: the result is a parameter trajectory" in \
        " ".join(capsys.readouterr().out.split())


@pytest.mark.parametrize("method, args, options", [
    # --nb and --nk given, nf not: the fit chooses it (the true system has nb = nf = nk = 1)
    ("hw", ["--output-nonlinearity", "poly:2", "--nb", "1", "--nk", "1"],
     dict(output_nonlinearity="poly:2", nb=1, nk=1)),
    ("nlss", ["--order", "1", "--degree", "2"], dict(order=1, degree=2)),
    ("hysteresis", ["--model", "prandtl-ishlinskii", "--operators", "4"],
     dict(model="prandtl-ishlinskii", operators=4)),
])
def test_nonlinear_cli_is_the_python_fit(files, capsys, method, args, options):
    """``identify hw|nlss|hysteresis`` on one file with --validate: the parameters, the fits and
    the structure are those of ``identify(load(est), method, validate=load(val))``, bit for
    bit, and the page of --report is ``model.report`` on the validation record."""
    report = ["--report", files["dir"] / f"rep-{method}"]
    res = _json(capsys, "identify", method, files["est"], "--input", "u", "--output", "y", *args,
                "--validate", files["val"], *report)
    py = identify(load(files["est"]), method, input="u", output="y",
                  validate=load(files["val"]), **options)
    assert [p["value"] for p in res["parameters"]] == [p.value for p in py.parameters.values()] \
        if method != "hw" else [p["value"] for p in res["parameters"]] == py.theta.tolist()
    assert res["fit_percent"] == py.fit_percent
    assert res["validation"]["fit_percent"] == py.validation_fit_percent
    assert res["structure"]["criterion"] == py.criterion
    if report:
        page = (files["dir"] / f"rep-{method}" / "index.html").read_text(encoding="utf-8")
        fit = py.compare(load(files["val"])).fit_percent[0]
        assert "data val.csv" in page and f"<td>{fit:.2f} %</td>" in page
    if method == "hw":  # nf chosen, as in Python: the true order
        assert (res["structure"]["nb"], res["structure"]["nf"], res["structure"]["nk"]) == (1, 1, 1)


@pytest.mark.parametrize("method", ["hw", "hysteresis", "narx", "nlss"])
@pytest.mark.parametrize("option, value, message", [
    ("--out", "a-file/model.json", "a-file' is not a folder"),
    ("--out", "model.txt", "expected a .json file"),
    ("--report", "a-file", "is a file, expected a folder"),
])
def test_nonlinear_cli_refuses_outputs_before_reading(tmp_path, capsys, method, option, value,
                                                      message):
    """Every nonlinear command checks --out and --report (the shared options of
    ``record_command``) before it reads a file: DATA does not exist here, and the error is the
    output's, in one line."""
    (tmp_path / "a-file").write_text("x", encoding="utf-8")
    code = main(["identify", method, str(tmp_path / "missing.csv"), "--input", "u", "--output",
                 "y", option, str(tmp_path / value)])
    err = capsys.readouterr().err.strip()
    assert code != 0 and message in err and option in err and len(err.splitlines()) == 1
    assert not (tmp_path / "model.txt").exists()


def test_identify_hw_chooses_the_orders_not_given(files):
    """``identify(tr, 'hw')`` without orders chooses nb, nf, nk (by BIC without ``validate``):
    the true [1 1 1] of y = 0.4 q⁻¹/(1 − 0.7 q⁻¹) u, where the linear defaults [2 2 1] were
    taken before; with ``nb=2`` given, nb stays 2."""
    tr = load(files["est"])
    m = identify(tr, "hw", input="u", output="y", output_nonlinearity="poly:2")
    assert (m.nb, m.nf, m.nk) == (1, 1, 1) and "by BIC" in m.criterion
    m = identify(tr, "hw", input="u", output="y", output_nonlinearity="poly:2", nb=2)
    assert m.nb == 2


@pytest.mark.parametrize("method, args", [
    ("narx", ["--degree", "1", "--lags", "1", "--terms", "2"]),
    ("hw", ["--output-nonlinearity", "poly:2", "--nb", "1", "--nf", "1", "--nk", "1"]),
    ("hysteresis", ["--model", "prandtl-ishlinskii", "--operators", "4"]),
    ("nlss", ["--order", "1", "--degree", "2"]),
])
def test_nonlinear_cli_shows_the_units_and_its_file_the_provenance(files, capsys, method, args):
    """``identify narx|hw|hysteresis|nlss --json`` shows the columns' units under the keys of
    ``identify arx`` (``input_unit``/``output_unit``; nlss, of several columns, the lists
    ``input_units``/``output_units`` of the MIMO commands): 'V' and 'N'; the model file of
    ``--out`` carries the data file's name and SHA-256, as the ARX model file does, so
    ``gripkit compare`` knows its estimation data (and not the validation record)."""
    d = files["dir"]
    lin = _json(capsys, "identify", "arx", files["est"], "--input", "u", "--output", "y",
                "--na", "1", "--nb", "1", "--nk", "1", "--out", d / "units-arx.json")
    assert (lin["input_unit"], lin["output_unit"]) == ("V", "N")
    res = _json(capsys, "identify", method, files["est"], "--input", "u", "--output", "y", *args,
                "--out", d / f"units-{method}.json")
    if method == "nlss":
        assert (res["input_units"], res["output_units"]) == ([lin["input_unit"]],
                                                            [lin["output_unit"]])
    else:
        assert (res["input_unit"], res["output_unit"]) == (lin["input_unit"], lin["output_unit"])
    arx_file, m = load_model(d / "units-arx.json"), load_model(d / f"units-{method}.json")
    assert (m.data_file, m.data_hash) == (arx_file.data_file, arx_file.data_hash) == (
        "est.csv", hashlib.sha256(files["est"].read_bytes()).hexdigest())
    for data, same in ((files["est"], True), (files["val"], False)):
        assert _json(capsys, "compare", d / f"units-{method}.json", data)["estimation_data"] is same
