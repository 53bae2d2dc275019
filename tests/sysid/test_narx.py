"""Polynomial NARX (issue 26, family 1): FROLS structure selection, least squares with σ, pruning,
free-run simulation, save/load, and the measured DC-motor record."""

import json
from pathlib import Path

import numpy as np
import pytest

from gripkit.errors import ArgumentError, DataError, ModelError, StabilityWarning
from gripkit.sysid import arx, narx
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
    best_arx = max(arx(ue - um, ye - ym, n, n, 1, dt=1.0).compare(uv - um, yv - ym).fit_percent[0]
                   for n in (1, 2, 3, 4))
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
    fit = load_narx(model).compare(uv, yv).fit_percent[0]
    assert fit == pytest.approx(py.validation_fit_percent, abs=1e-6)
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


# ------------------------------------------------- refinement on the simulation error, σ of ŷ
TRUE_TERMS = set(TRUE)


def _output_error_system(rng, n=1000, noise=0.1, amplitude=1.0):
    """Billings' example with the noise on the measured output, not in the equation:
    x(t) = −0.605 x(t−1) − 0.163 x(t−2)² + 0.588 u(t−1) − 0.240 u(t−2), y = x + v."""
    u = rng.uniform(-amplitude, amplitude, n)
    x = np.zeros(n)
    for t in range(2, n):
        x[t] = -0.605 * x[t - 1] - 0.163 * x[t - 2] ** 2 + 0.588 * u[t - 1] - 0.240 * u[t - 2]
    return u, x, x + rng.normal(0.0, noise, n)


def test_sensitivities_match_finite_differences():
    """∂ŷ/∂θ of the sensitivity kernel (free run and derivative in one pass) against central
    differences of the free run, and the run itself equal to the plain simulation kernel."""
    u, _, y = _output_error_system(np.random.default_rng(4), n=300)
    m = narx(u, y, degree=2, lags=2, terms=6, prune=False)
    ys = np.zeros(300)
    ys[:2] = y[:2]
    at, J = m._sensitivities(u, ys, m.theta)
    assert at == -1
    np.testing.assert_allclose(ys, m.simulate(u, y[:2]), rtol=0, atol=1e-14)
    h = 1e-6
    for j in range(len(m.theta)):
        d = np.zeros(len(m.theta))
        d[j] = h
        runs = []
        for sgn in (1.0, -1.0):
            yy = np.zeros(300)
            yy[:2] = y[:2]
            m._sensitivities(u, yy, m.theta + sgn * d)
            runs.append(yy)
        np.testing.assert_allclose(J[:, j], (runs[0] - runs[1]) / (2 * h), rtol=1e-5, atol=1e-8)


def test_simulation_refinement_beats_one_step_on_output_error_noise():
    """20 records (N = 1000, measurement noise σ_v = 0.1 on the output): the one-step least
    squares is biased (the noisy y(t−1) in the regressors), the free-run refinement is not.
    Measured: the refined model's free-run fit on noise-free validation data is higher in 20 of
    20 runs (mean 99.0 % against 95.4 %; lowest refined 98.3 %, highest one-step 96.5 %); after
    refinement and pruning on its σ the structure is exactly the true one in 20 of 20 runs and
    80 of 80 true parameters lie within 3σ (σ from the Gauss–Newton Hessian of the simulation
    error); mean |error| of the y(t−1) coefficient 0.207 one-step against 0.0045 refined.
    Asserted: better in ≥ 18 runs, the exact structure in ≥ 18, ≥ 90 % within 3σ, the one-step
    error of the y(t−1) coefficient at least 10× the refined one (mean over the runs)."""
    uv, xv, _ = _output_error_system(np.random.default_rng(999), n=2000, noise=0.0)
    better = present = inside = total = 0
    err_ls, err_sim = [], []
    for i in range(20):
        u, _, y = _output_error_system(np.random.default_rng(200 + i))
        one = narx(u, y, degree=2, lags=2)
        ref = narx(u, y, degree=2, lags=2, refine="simulation")
        assert "refined on the free-run error" in ref.criterion
        better += ref.compare(uv, xv).fit_percent[0] > one.compare(uv, xv).fit_percent[0]
        present += TRUE_TERMS == set(ref.terms)
        for name, th, sd in zip(ref.terms, ref.theta, ref.theta_std):
            if name in TRUE:
                total += 1
                inside += abs(th - TRUE[name]) < 3.0 * sd
        err_ls.append(abs(one.theta[one.terms.index("y(t-1)")] - TRUE["y(t-1)"]))
        err_sim.append(abs(ref.theta[ref.terms.index("y(t-1)")] - TRUE["y(t-1)"]))
    assert better >= 18 and present >= 18
    assert total >= 4 * 18 and inside >= 0.9 * total
    assert np.mean(err_ls) > 10.0 * np.mean(err_sim)


def test_simulate_std_matches_monte_carlo_spread():
    """σ of the simulated output (linearised propagation of cov θ through the free run) against
    the spread of the free runs of independently identified models on one input (from rest).
    Equation-error noise, least squares (40 runs): measured ratio 0.96. Output-error noise,
    refined (60 runs, those whose structure is the true one, 48): 1.11. Asserted 0.6–1.6 (RMS
    over time of the mean predicted σ over the RMS of the empirical σ)."""
    uv = np.random.default_rng(5).uniform(-1.0, 1.0, 300)

    def ratio(sims, stds):
        emp = np.std(sims, axis=0, ddof=1)[2:]
        pred = np.mean(stds, axis=0)[2:]
        return np.sqrt(np.mean(pred ** 2)) / np.sqrt(np.mean(emp ** 2))

    sims, stds = [], []
    for i in range(40):
        u, y = _true_system(np.random.default_rng(300 + i))
        ys, sd = narx(u, y, degree=2, lags=2).simulate(uv, std=True)
        assert sd[0] == sd[1] == 0.0 and np.all(sd[2:] > 0)
        sims.append(ys)
        stds.append(sd)
    assert 0.6 < ratio(sims, stds) < 1.6
    sims, stds = [], []
    for i in range(60):
        u, _, y = _output_error_system(np.random.default_rng(300 + i))
        m = narx(u, y, degree=2, lags=2, refine="simulation")
        if set(m.terms) == TRUE_TERMS:
            ys, sd = m.simulate(uv, std=True)
            np.testing.assert_array_equal(ys, m.simulate(uv))
            sims.append(ys)
            stds.append(sd)
    assert len(sims) >= 20
    assert 0.6 < ratio(sims, stds) < 1.6


def test_refine_argument_is_checked():
    u, y = _true_system(np.random.default_rng(1), n=200)
    with pytest.raises(ArgumentError, match="refine must be None or 'simulation'"):
        narx(u, y, refine="prediction")
    with pytest.raises(ArgumentError, match="max_iter must be an integer"):
        narx(u, y, refine="simulation", max_iter=0)


# ------------------------------------------------------------------------ several records
def test_several_records_one_regression_sigma_from_all():
    """Two records: θ is the least squares on both records' regressors stacked (each record's
    first max_lag samples its own past, no junction row), computed here with numpy's lstsq; σ
    about 1/√2 of one record's (twice the data); identify([tr1, tr2], "narx") is the same fit."""
    from gripkit import Trajectory
    from gripkit.sysid import identify
    from gripkit.sysid.nonlinear.narx import _regressors

    u1, y1 = _true_system(np.random.default_rng(11), n=2000)
    u2, y2 = _true_system(np.random.default_rng(12), n=2000, amplitude=0.8)
    both = narx([(u1, y1), (u2, y2)], degree=2, lags=2)
    assert set(both.terms) == TRUE_TERMS
    bases, rows = candidate_terms(2, 2, 2)
    cols = [int(np.flatnonzero((rows == r).all(axis=1))[0]) for r in both.rows]
    P = np.vstack([_regressors(bases, rows, u, y, 2)[:, cols] for u, y in ((u1, y1), (u2, y2))])
    ref = np.linalg.lstsq(P, np.concatenate([y1[2:], y2[2:]]), rcond=None)[0]
    np.testing.assert_allclose(both.theta, ref, rtol=1e-10, atol=1e-12)
    one = narx(u1, y1, degree=2, lags=2)
    assert set(one.terms) == TRUE_TERMS
    s1 = dict(zip(one.terms, one.theta_std))
    for name, sd in zip(both.terms, both.theta_std):
        assert 0.55 < sd / s1[name] < 0.85
    tr = [Trajectory.uniform(dt=0.01, voltage=u, output=y) for u, y in ((u1, y1), (u2, y2))]
    m = identify(tr, "narx", input="voltage", output="output", degree=2, lags=2)
    np.testing.assert_allclose(m.theta, both.theta, rtol=1e-12)
    assert m.dt == 0.01 and m.output_name == "output"
    with pytest.raises(DataError, match=r"records\[1\]: u has 2000 samples but y has 1999"):
        narx([(u1, y1), (u2, y2[:-1])])


def test_cli_refine_simulation(tmp_path, capsys):
    """``--refine simulation`` gives the Python call's refined model; a bad value is one line."""
    u, _, y = _output_error_system(np.random.default_rng(200))
    est = tmp_path / "est.csv"
    np.savetxt(est, np.column_stack([u, y]), delimiter=",", header="u,y", comments="", fmt="%.17g")
    code, out, err = _cli(capsys, "identify", "narx", est, "--input", "u", "--output", "y",
                          "--fs", 1, "--refine", "simulation", "--json")
    assert code == 0, err
    d = json.loads(out)
    py = narx(u, y, degree=2, lags=2, refine="simulation")
    assert d["structure"]["refine"] == "simulation" and set(d["structure"]["terms"]) == TRUE_TERMS
    assert [p["value"] for p in d["parameters"]] == pytest.approx(list(py.theta), rel=1e-9)
    assert [p["std"] for p in d["parameters"]] == pytest.approx(list(py.theta_std), rel=1e-6)
    code, out, err = _cli(capsys, "identify", "narx", est, "--input", "u", "--output", "y",
                          "--fs", 1, "--refine", "pem")
    assert code != 0 and err.startswith("error: DataError: --refine: expected 'none' or")


def test_simulate_std_of_a_diverging_run_is_nan_after_the_divergence():
    """The σ of a free run that diverges stops where the run does: NaN there and after, with
    the same StabilityWarning as the plain simulation."""
    u, y = _true_system(np.random.default_rng(3), noise=0.01)
    m = narx(u, y, degree=2, lags=2)
    with pytest.warns(StabilityWarning, match="diverges"):
        ys, sd = m.simulate(np.full(500, -6.0), std=True)
    at = int(np.argmax(~np.isfinite(sd)))
    assert at > 2 and np.all(np.isnan(sd[at:])) and np.all(np.isfinite(sd[:at]))
    assert np.all(np.isnan(ys[at + 1:]))
