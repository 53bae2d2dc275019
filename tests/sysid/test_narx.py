"""Polynomial NARX (issue 26, family 1): FROLS structure selection, least squares with σ, pruning,
free-run simulation, save/load, and the measured DC-motor record."""

import json
from pathlib import Path

import numpy as np
import pytest

from gripkit.errors import ArgumentError, DataError, ModelError, StabilityWarning
from gripkit.sysid import arx, narx
from gripkit.sysid.linear.linear_model import from_polynomial
from gripkit.sysid.nonlinear.narx import NARXModel, candidate_terms, load_narx

FIXTURE = Path(__file__).resolve().parents[1] / "fixtures" / "dc_motor" / "dc_motor.csv"

#: the NARX example of Billings (2013) used by SysIdentPy's documentation:
#: y(t) = −0.605 y(t−1) − 0.163 y(t−2)² + 0.588 u(t−1) − 0.240 u(t−2) + e(t)
TRUE = {"y(t-1)": -0.605, "y(t-2)*y(t-2)": -0.163, "u(t-1)": 0.588, "u(t-2)": -0.240}


def _true_system(rng, n=1000, noise=0.05, amplitude=1.0):
    u = rng.uniform(-amplitude, amplitude, n)
    e = rng.normal(0.0, noise, n)
    y = np.zeros(n)
    for t in range(2, n):
        y[t] = (-0.605 * y[t - 1] - 0.163 * y[t - 2] ** 2 + 0.588 * u[t - 1] - 0.240 * u[t - 2]
                + e[t])
    return u, y


def test_candidate_terms_count_and_names():
    """ly = lu = 2, degree 2: 1 constant + 4 linear + C(5, 2) = 10 quadratic = 15 candidates."""
    bases, rows = candidate_terms(2, 2, 2)
    assert len(bases) == 4 and len(rows) == 15
    m = NARXModel(2, 2, 2, False, bases, rows, np.zeros(15), np.zeros(15), np.zeros((15, 15)))
    assert m.terms[0] == "1" and "y(t-1)*u(t-2)" in m.terms and "y(t-2)*y(t-2)" in m.terms
    assert len(candidate_terms(2, 2, 2, direct=True)[1]) == 21           # u(t) added: 1 + 5 + 15


def test_recovers_known_polynomial_narx_monte_carlo():
    """30 noisy records (σ_e = 0.05, N = 1000): the true four terms are the structure chosen by
    FROLS + BIC + pruning in ≥ 27 runs, and every true parameter lies within 3σ of its estimate in
    ≥ 90 % of the (run, parameter) pairs (σ from σ² (ΦᵀΦ)⁻¹, honest for equation-error noise)."""
    exact, inside, total = 0, 0, 0
    for i in range(30):
        u, y = _true_system(np.random.default_rng(100 + i))
        m = narx(u, y, degree=2, lags=2)
        exact += set(m.terms) == set(TRUE)
        for name, th, sd in zip(m.terms, m.theta, m.theta_std):
            if name in TRUE:
                total += 1
                inside += abs(th - TRUE[name]) < 3.0 * sd
    assert exact >= 27
    assert total >= 4 * 27 and inside >= 0.9 * total


def test_simulate_predict_and_save_load_round_trip(tmp_path):
    u, y = _true_system(np.random.default_rng(7), noise=0.0)
    m = narx(u, y, degree=2, lags=2, terms=4, prune=False)
    assert set(m.terms) == set(TRUE)
    np.testing.assert_allclose(m.theta, [TRUE[t] for t in m.terms], atol=1e-9)   # noise-free: exact
    np.testing.assert_allclose(m.simulate(u, y[:2], warn=True), y, atol=1e-8)
    np.testing.assert_allclose(m.predict(u, y), y, atol=1e-9)
    assert m.fit_percent == pytest.approx(100.0, abs=1e-6)
    path = m.save(tmp_path / "m.json")
    assert json.loads(path.read_text())["schema"] == "gripkit.narx-model"
    m2 = load_narx(path)
    assert m2.terms == m.terms
    np.testing.assert_array_equal(m2.simulate(u, y[:2]), m.simulate(u, y[:2]))


def test_load_refuses_another_schema(tmp_path):
    p = tmp_path / "other.json"
    p.write_text(json.dumps({"schema": "gripkit.linear-model", "version": 1}))
    with pytest.raises(ModelError, match="expected 'gripkit.narx-model'"):
        load_narx(p)


def test_divergent_free_run_is_reported_not_scored():
    """Identified on small inputs, y(t−2)² is harmless; on ±3 V inputs the quadratic feedback
    runs away: the fit is None with a StabilityWarning, never a huge negative percentage."""
    u, y = _true_system(np.random.default_rng(3), noise=0.01)
    m = narx(u, y, degree=2, lags=2)
    uv = np.full(500, -6.0)
    yv = -3.0 * (1.0 - 0.5 ** np.arange(500.0))            # a step response that settles
    with pytest.warns(StabilityWarning, match="diverges"):
        assert m.compare(uv, yv).fit_percent == [None]
    with pytest.warns(StabilityWarning, match="diverges"):
        m4 = narx(u, y, degree=2, lags=2, terms=4, validate=(uv, yv))
    assert m4.validation_fit_percent is None


def test_bad_input_is_named():
    u, y = _true_system(np.random.default_rng(1), n=200)
    with pytest.raises(DataError, match="equal"):
        narx(u, y[:-1])
    with pytest.raises(ArgumentError, match="only 15 candidates"):
        narx(u, y, terms=16)
    with pytest.raises(ArgumentError, match="degree must be an integer"):
        narx(u, y, degree=0)
    with pytest.raises(ArgumentError, match="terms must be 'auto' or an integer"):
        narx(u, y, terms="all")
    with pytest.raises(ArgumentError, match="dt must be a positive"):
        narx(u, y, dt=0.0)
    with pytest.raises(DataError, match="output is constant"):
        narx(u, np.full(200, 2.0))
    with pytest.raises(DataError, match="non-finite"):
        narx(np.where(np.arange(200) == 5, np.nan, u), y)


def test_load_refuses_folder_and_non_json(tmp_path):
    from gripkit.errors import PathError

    with pytest.raises(PathError, match="cannot be read"):
        load_narx(tmp_path)
    (tmp_path / "x.json").write_text("not json")
    with pytest.raises(ModelError, match="is not JSON"):
        load_narx(tmp_path / "x.json")


@pytest.fixture(scope="module")
def dc_motor():
    d = np.loadtxt(FIXTURE, delimiter=",", skiprows=1)
    return d[:500, 0], d[:500, 1], d[500:, 0], d[500:, 1]


def test_dc_motor_narx_beats_the_best_linear_arx(dc_motor):
    """SysIdentPy's split (first 500 samples estimate, last 500 validate). Best linear ARX [n n 1],
    n = 1…4, free run with estimated initial state: ≈ 48–51 % (test_measured_dc_motor.py). The
    cubic NARX (lags 2, 18 terms by validation fit) reaches 94.0 %, the quadratic 92.0 %
    (measured); asserted with a 4-point margin, and ≥ 35 points above the best ARX."""
    ue, ye, uv, yv = dc_motor
    um, ym = ue.mean(), ye.mean()
    best_arx = max(from_polynomial(arx(ue - um, ye - ym, n, n, 1, dt=1.0))
                   .compare(uv - um, yv - ym)[0][0] for n in (1, 2, 3, 4))
    cubic = narx(ue, ye, degree=3, lags=2, validate=(uv, yv))
    quadratic = narx(ue, ye, degree=2, lags=2, validate=(uv, yv))
    assert cubic.validation_fit_percent > 90.0 and quadratic.validation_fit_percent > 88.0
    assert cubic.validation_fit_percent > best_arx + 35.0
    assert best_arx < 55.0
    assert "validation free-run fit" in cubic.criterion


def _cli(capsys, *args):
    from gripkit.cli import main

    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_identify_narx_json_validate_and_model_file(dc_motor, tmp_path, capsys):
    """The CLI gives the same validation fit as the Python call and writes a loadable model."""
    ue, ye, uv, yv = dc_motor
    est, val, model = tmp_path / "est.csv", tmp_path / "val.csv", tmp_path / "narx.json"
    for path, (u, y) in ((est, (ue, ye)), (val, (uv, yv))):
        np.savetxt(path, np.column_stack([u, y]), delimiter=",", header="voltage,output",
                   comments="", fmt="%.10g")
    code, out, err = _cli(capsys, "identify", "narx", est, "--input", "voltage",
                          "--output", "output", "--fs", 1, "--degree", 3, "--validate", val,
                          "--out", model, "--json")
    assert code == 0, err
    d = json.loads(out)
    py = narx(ue, ye, degree=3, lags=2, validate=(uv, yv))
    assert d["validation"]["fit_percent"] == pytest.approx(py.validation_fit_percent, abs=1e-6)
    assert d["structure"]["terms"] == py.terms and d["warnings"] == []
    assert load_narx(model).compare(uv, yv).fit_percent[0] == pytest.approx(py.validation_fit_percent,
                                                                          abs=1e-6)
    code, out, err = _cli(capsys, "compare", model, val, "--fs", 1, "--json")     # the same number
    assert code == 0, err
    fit = json.loads(out)["fit_percent"][0]
    assert fit == pytest.approx(d["validation"]["fit_percent"], abs=1e-6)
    code, out, err = _cli(capsys, "simulate", model, "--data", val, "--fs", 1, "--json")
    assert code == 0, err                                      # from rest: the model's own free run
    sim = load_narx(model).simulate(uv)
    assert json.loads(out)["outputs"]["output"]["final"] == pytest.approx(sim[-1], rel=1e-9)
    code, out, err = _cli(capsys, "identify", "narx", est, "--input", "voltage",
                          "--output", "output", "--fs", 1, "--terms", "many")
    assert code != 0 and err.startswith("error: DataError: --terms: expected 'auto'")


def test_identify_method_narx_on_a_trajectory(dc_motor):
    """``identify(traj, "narx", ...)`` is the array call on the raw columns (no detrending: the
    constant term carries the operating point); an unknown option is named."""
    from gripkit import Trajectory
    from gripkit.sysid import identify

    ue, ye, uv, yv = dc_motor
    tr = Trajectory.uniform(dt=1.0, voltage=ue, output=ye)
    m = identify(tr, "narx", input="voltage", output="output", degree=3, lags=2)
    ref = narx(ue, ye, degree=3, lags=2)
    assert m.terms == ref.terms
    assert m.compare(uv, yv).fit_percent[0] == pytest.approx(ref.compare(uv, yv).fit_percent[0],
                                                             abs=1e-9)
    with pytest.raises(ArgumentError, match="banana"):
        identify(tr, "narx", input="voltage", output="output", banana=3)


def test_hostile_narx_model_files_are_named(tmp_path):
    """A NARX model file nested beyond the recursion limit, or with a 5000-digit integer, is a
    one-line ModelError naming the file (issue 22's model-file cases, for the new schema)."""
    from gripkit.errors import ModelError
    from gripkit.sysid import load_narx

    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(ModelError, match="deep.json' cannot be read: its JSON nests"):
        load_narx(deep)
    big = tmp_path / "big.json"
    big.write_text('{"schema": "gripkit.narx-model", "x": ' + "9" * 5000 + "}")
    with pytest.raises(ModelError, match="big.json' cannot be read"):
        load_narx(big)
