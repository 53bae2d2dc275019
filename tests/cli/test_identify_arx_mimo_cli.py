"""`gripkit identify arx DATA --input a,b --output c[,d]` (issue 13, MIMO data): a matrix-polynomial
ARX whose fit figures are lists per output in --output order, recovering a known 2×2 ARX system
from noisy data within 4σ; SISO calls keep their JSON (``validation.fit_percent`` a number)."""

import sys
from pathlib import Path

import numpy as np
import pytest

from gripkit import Trajectory
from gripkit.cli import main
from gripkit.io import save
from gripkit.sysid import load_model

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bad_inputs"))
from corpus import CliResult, assert_user_error, assert_warned  # noqa: E402

# y(t) = A y(t−1) + B u(t−1) + e(t), i.e. ARX [1 1 1] with A1 = −A, B1 = B (outputs c, d; inputs a,
# b)
A_TRUE = np.array([[0.5, 0.1], [-0.2, 0.7]])
B_TRUE = np.array([[1.0, 0.3], [0.0, 0.8]])
NOISE = 0.05


def _record(n, seed, unstable=False):
    rng = np.random.default_rng(seed)
    u = rng.standard_normal((n, 2))
    A = np.array([[1.02, 0.0], [0.0, 0.5]]) if unstable else A_TRUE
    y = np.zeros((n, 2))
    for t in range(1, n):
        y[t] = A @ y[t - 1] + B_TRUE @ u[t - 1] + NOISE * rng.standard_normal(2)
    return Trajectory.uniform(dt=0.02, a=u[:, 0] + 2.0, b=u[:, 1], c=y[:, 0] - 1.0, d=y[:, 1] + 5.0,
                              units={"a": "V", "b": "V", "c": "N", "d": "m"})


def _true_free_run_fit(tr):
    """Fit (%) per output (c, d) of the true system's noise-free free run on a record (from rest,
    as the record starts; the fit in gripkit's sense: 100 (1 − ‖y − ŷ‖/‖y − ȳ‖))."""
    u = np.column_stack([tr["a"], tr["b"]]) - [2.0, 0.0]
    y = np.column_stack([tr["c"], tr["d"]])
    ys = np.zeros_like(y)
    for t in range(1, y.shape[0]):
        ys[t] = A_TRUE @ ys[t - 1] + B_TRUE @ u[t - 1]
    y, ys = y - y.mean(axis=0), ys - ys.mean(axis=0)
    return 100 * (1 - np.linalg.norm(y - ys, axis=0) / np.linalg.norm(y, axis=0))


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("arx_mimo")
    out = {"dir": d}
    for name, seed in (("est", 1), ("val", 2)):
        out[name] = d / f"{name}.csv"
        save(_record(3000, seed), out[name])
    out["unstable"] = d / "unstable.csv"
    save(_record(300, 3, unstable=True), out["unstable"])
    return out


@pytest.fixture
def cli(capsys):
    def run(*args) -> CliResult:
        code = main([str(a) for a in args])
        o, e = capsys.readouterr()
        return CliResult(code, o, e)

    return run


def arx_args(path, inputs, outputs, *extra):
    return ["identify", "arx", path, "--input", inputs, "--output", outputs, "--na", 1, "--nb", 1,
            "--nk", 1,
            *extra]


def test_mimo_arx_json_per_output_in_output_order(cli, files):
    model_file = files["dir"] / "arx.json"
    r = (cli(*arx_args(files["est"], "a,b", "d,c", "--validate", files["val"], "--out", model_file,
                       "--json")))
    assert r.code == 0, r.err
    d = r.json()
    assert d["outputs"] == ["d", "c"] and d["inputs"] == ["a", "b"] and (d["na"], d["nb"],
                                                                         d["nk"]) == (1, 1, 1)
    # rows in --output order: d first, then c; A1 = −A, B1 = B (both permuted the same way)
    perm = [1, 0]
    A1, A1_std = np.array(d["A_poly"][0]), np.array(d["A_poly_std"][0])
    B1, B1_std = np.array(d["B_poly"][0]), np.array(d["B_poly_std"][0])
    assert np.all(np.abs(A1 - (-A_TRUE[np.ix_(perm, perm)])) <= 4 * A1_std)
    assert np.all(np.abs(B1 - B_TRUE[perm]) <= 4 * B1_std)
    assert np.all(A1_std < 0.01) and np.all(B1_std < 0.01)
    for key in ("fit_percent", "one_step_fit_percent"):
        assert isinstance(d[key], list) and len(d[key]) == 2
    assert isinstance(d["validation"]["fit_percent"],
                      list) and len(d["validation"]["fit_percent"]) == 2
    assert d["validation_fit_percent"] == d["validation"]["fit_percent"]
    # free run on fresh data: as good as the true system's own free run (the equation noise passes
    # through A(q)⁻¹ and no model can predict it), within half a fit point, on each output
    best = _true_free_run_fit(_record(3000, 2))[perm]
    assert np.all(np.array(d["validation"]["fit_percent"]) > best - 0.5) and min(best) > 90
    assert d["stable"] is True and d["warnings"] == []
    # the model file reloads and gives the same validation fit per output
    m = load_model(model_file)
    assert m.outputs == ("d", "c") and m.data_file == "est.csv"
    fit = m.compare(_record(3000, 2)).fit_percent
    assert np.allclose(fit, d["validation"]["fit_percent"], atol=0.5)


def test_miso_arx_has_lists_too(cli, files):
    d = cli(*arx_args(files["est"], "a,b", "c", "--json")).json()
    assert (d["outputs"] == ["c"] and len(d["fit_percent"]) == 1
            and np.shape(d["B_poly"][0]) == (1, 2))
    assert np.allclose(d["B_poly"][0][0], B_TRUE[0], atol=4 * np.max(d["B_poly_std"][0]))


def test_siso_arx_json_unchanged(cli, files):
    d = cli(*arx_args(files["est"], "a", "c", "--validate", files["val"], "--json")).json()
    assert isinstance(d["validation"]["fit_percent"], float) and isinstance(d["fit_percent"], float)
    assert (d["input"], d["output"]) == ("a", "c") and len(d["A"]) == 2 and d["A"][0] == 1.0


def test_mimo_arx_human_readable(cli, files):
    r = cli(*arx_args(files["est"], "a,b", "c,d", "--validate", files["val"]))
    assert r.code == 0, r.err
    assert "ARX [1 1 1]: 2 input(s)" in r.out and "A1 = [" in r.out and "B1 = [" in r.out
    assert ("  c: fit free run" in r.out and "  d: fit free run" in r.out
            and "validation free run" in r.out)


def test_mimo_arx_unstable_model_warns_and_reports_no_fit(cli, files):
    r = cli(*arx_args(files["unstable"], "a,b", "c,d", "--json"))
    assert r.code == 0, r.err
    assert_warned(r, "unstable")
    assert r.json()["fit_percent"] is None and r.json()["stable"] is False


@pytest.mark.parametrize("extra, inputs, outputs, cls, phrase", [
    (("--detrend", "linear"), "a,b", "c,d", "DataError", "--detrend"),
    ((), "a,b", "c,nope", "DataError", "'nope' not found"),
    ((), "a,b", "c,c", "DataError", "listed twice"),
    ((), "a,c", "c,d", "DataError", "'c' is both"),
])
def test_mimo_arx_bad_columns_one_line_error(cli, files, extra, inputs, outputs, cls, phrase):
    assert_user_error(cli(*arx_args(files["est"], inputs, outputs, *extra)), cls, phrase)
