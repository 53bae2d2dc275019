"""Polynomial nonlinear state space (issue 26, family 3): monomial tables, the sensitivity
kernel against finite differences, recovery of a known discrete Duffing oscillator with noise,
σ of the simulated output, save/load, divergence, the CLI, bad input and the DC-motor record."""

import json
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy.signal import lfilter

from gripkit.errors import (AccuracyWarning, ArgumentError, DataError, ModelError,
                            StabilityWarning)
from gripkit.sysid import load_model, nlss
from gripkit.sysid.nonlinear import nlss_kernels as K
from gripkit.sysid.nonlinear.nlss import NLSSModel, load_nlss, monomial_exponents

FIXTURE = Path(__file__).resolve().parents[1] / "fixtures" / "dc_motor" / "dc_motor.csv"


def duffing(u):
    """A discrete Duffing oscillator (symplectic Euler, h = 0.2, ω = 1, 2ζω = 0.3, cubic
    stiffness 2): v⁺ = v + h(−x − 0.3 v − 2 x³ + u), x⁺ = x + h v⁺, y = x. A PNLSS of order 2
    and degree 3 (x⁺ holds x³ and u through v⁺)."""
    x = v = 0.0
    y = np.empty(len(u))
    for t in range(len(u)):
        y[t] = x
        v = v + 0.2 * (-x - 0.3 * v - 2.0 * x ** 3 + u[t])
        x = x + 0.2 * v
    return y


def _input(rng, n):
    return lfilter([0.3], [1.0, -0.7], rng.normal(0.0, 1.0, n))


@pytest.fixture(scope="module")
def duffing_fit():
    """N = 3000 estimation samples, output noise 1 % of its standard deviation; a fresh input
    for validation, compared with the noise-free output."""
    rng = np.random.default_rng(0)
    u = _input(rng, 3000)
    y0 = duffing(u)
    y = y0 + rng.normal(0.0, 0.01 * y0.std(), y0.size)
    uv = _input(rng, 3000)
    yv = duffing(uv)
    m = nlss((u, y), validate=(uv, yv), degree=3, progress=False)
    return m, (u, y, y0), (uv, yv)


def test_monomial_tables():
    """n = 2, m = 1, degree 3: C(4, 2) + C(5, 3) = 6 + 10 monomials of (x1, x2, u); of the states
    only 3 + 4 = 7; a two-level input drops u², u²x1, u²x2, u³ (12 left)."""
    assert monomial_exponents(2, 1, 3).shape == (16, 3)
    assert monomial_exponents(2, 1, 3, inputs=False).shape == (7, 3)
    assert monomial_exponents(2, 1, 3, input_levels=[2]).shape == (12, 3)
    assert monomial_exponents(2, 1, 3)[:, 2].max() == 3


def _random_model(rng, n=2, m=1, p=1, degree=3):
    exz, exe = monomial_exponents(n, m, degree), monomial_exponents(n, m, degree, inputs=False)
    return NLSSModel(A=np.array([[0.8, 0.2], [-0.2, 0.7]]), B=rng.normal(size=(n, m)),
                     C=rng.normal(size=(p, n)), D=np.zeros((p, m)),
                     E=0.05 * rng.normal(size=(n, len(exz))),
                     F=0.05 * rng.normal(size=(p, len(exe))), exz=exz, exe=exe,
                     u_offset=np.zeros(m), u_scale=np.ones(m), y_offset=np.zeros(p),
                     dirs=np.zeros((0, 3), dtype=np.int64), covariance=np.zeros((0, 0)),
                     x0=np.zeros(n), state_limit=1e6)


def _window_problem(seed, w, starts, dirs):
    """A random order-2 model, 300 samples of input and output, the initial states of the three
    windows ``starts`` cuts, and the kernel's sums for the directions ``dirs`` with weight ``w``:
    (model, u, y, Z, NLSSGram, V of window_gram, V of window_loss)."""
    rng = np.random.default_rng(seed)
    m = _random_model(rng)
    u = np.ascontiguousarray(0.5 * rng.normal(size=(300, 1)))
    y = np.ascontiguousarray(rng.normal(size=(300, 1)))
    Z = 0.1 * rng.normal(size=(3, 2))
    P = len(dirs)
    out = K.NLSSGram(np.empty((P, P)), np.empty(P), np.empty((3, P, 2)), np.empty((3, 2, 2)),
                     np.empty((3, 2)))
    arrays = K.NLSSArrays(m.A, m.B, m.C, m.D, m.E, m.F, m.y_offset, m.exz, m.exe)
    win = K.NLSSWindows(Z, starts, u, y, w)
    return (m, u, y, Z, out, K.window_gram(arrays, dirs, win, 1e6, out),
            K.window_loss(arrays, win, 1e6))


def test_sensitivity_gram_matches_finite_differences():
    """g = Σ Jᵀ(w e) of the kernel equals −½ ∂V/∂θ by central differences (V the windowed loss,
    three windows), for entries of A, B, C, E, F and each window's initial state."""
    w = np.array([1.3])
    starts = np.array([0, 100, 220, 300], dtype=np.int64)
    dirs = np.array([(0, 0, 1), (1, 1, 0), (2, 0, 0), (4, 1, 5), (5, 0, 3)], dtype=np.int64)
    m, u, y, Z, out, V, loss = _window_problem(4, w, starts, dirs)
    P, Htt, gt, gz = len(dirs), out.Htt, out.gt, out.gz
    assert V == pytest.approx(loss, rel=1e-12)
    h = 1e-6
    from gripkit.sysid.nonlinear.nlss import _apply, _loss

    for q in range(P):
        d = np.zeros(P)
        d[q] = h
        fd = (_loss(_apply(m, dirs, d), Z, starts, u, y, w)
              - _loss(_apply(m, dirs, -d), Z, starts, u, y, w)) / (2 * h)
        assert gt[q] == pytest.approx(-0.5 * fd, rel=1e-5, abs=1e-7)
    for j in range(3):
        for c in range(2):
            dZ = np.zeros_like(Z)
            dZ[j, c] = h
            fd = (_loss(m, Z + dZ, starts, u, y, w) - _loss(m, Z - dZ, starts, u, y, w)) / (2 * h)
            assert gz[j, c] == pytest.approx(-0.5 * fd, rel=1e-5, abs=1e-7)
    assert np.all(np.linalg.eigvalsh(Htt) > -1e-9 * np.abs(Htt).max())   # JᵀJ ⪰ 0


def _windowed_outputs(model, Z, starts, u):
    """The free run of every window j from Z[j] (simulate_kernel), stacked (N, p)."""
    from gripkit.sysid.nonlinear.nlss import _arrays

    Y = np.empty((u.shape[0], model.C.shape[0]))
    for j in range(len(starts) - 1):
        a, b = starts[j], starts[j + 1]
        K.simulate_kernel(_arrays(model), Z[j].copy(), np.ascontiguousarray(u[a:b]), Y[a:b],
                          np.empty((0, model.A.shape[0])), 1e6)
    return Y


def test_gram_matrix_equals_the_finite_difference_jacobian():
    """JᵀJ of the kernel (the blocked two-rows-of-G sums of _add_rows) equals DᵀD with D the
    weighted central-difference Jacobian of the windowed free run (step 1e-6), for a parameter
    count Q = 7 (odd: the last row of G on its own) and windows of 101, 121 and 78 samples (blocks
    of 16 rows with 5, 9 and 14 left over: the rows past the last group of four)."""
    from gripkit.sysid.nonlinear.nlss import _apply

    w = np.array([0.7])
    starts = np.array([0, 101, 222, 300], dtype=np.int64)
    dirs = np.array([(0, 1, 0), (1, 0, 0), (2, 0, 1), (4, 0, 2), (5, 0, 6)], dtype=np.int64)
    m, u, _, Z, out, _, _ = _window_problem(7, w, starts, dirs)
    P = len(dirs)
    h = 1e-6
    D = np.empty((300, P + 6))
    for q in range(P):
        d = np.zeros(P)
        d[q] = h
        D[:, q] = (_windowed_outputs(_apply(m, dirs, d), Z, starts, u)
                   - _windowed_outputs(_apply(m, dirs, -d), Z, starts, u))[:, 0] / (2 * h)
    for j in range(3):
        for c in range(2):
            dZ = np.zeros_like(Z)
            dZ[j, c] = h
            D[:, P + 2 * j + c] = (_windowed_outputs(m, Z + dZ, starts, u)
                                   - _windowed_outputs(m, Z - dZ, starts, u))[:, 0] / (2 * h)
    D *= w[0]
    H = D.T @ D
    scale = np.abs(H).max()
    np.testing.assert_allclose(out.Htt, H[:P, :P], rtol=1e-6, atol=1e-8 * scale)
    for j in range(3):
        zj = slice(P + 2 * j, P + 2 * j + 2)
        np.testing.assert_allclose(out.Htz[j], H[:P, zj], rtol=1e-6, atol=1e-8 * scale)
        np.testing.assert_allclose(out.Hzz[j], H[zj, zj], rtol=1e-6, atol=1e-8 * scale)
    # the windows' initial states do not couple: the cross blocks of D vanish
    assert np.abs(H[P:P + 2, P + 2:]).max() == 0.0


def test_a_first_part_model_that_runs_away_later_is_not_kept(monkeypatch):
    """Stage 3 of a long record (first part Ns = 300 of N = 600, input 20× larger after it): a
    stage-2 model whose cubic term runs away beyond the first part (at sample 305) is fitted on
    the first part from the linear start with steps that keep the free run over all samples in
    range; the polish (here 1 iteration) starts from whichever of that model and the linear one
    fits all samples better, so the result is finite and no worse than the linear restart's one
    iteration (equal here: the small first-part input does not determine x1² well)."""
    import importlib

    mod = importlib.import_module("gripkit.sysid.nonlinear.nlss")
    exz, exe = monomial_exponents(2, 1, 3), monomial_exponents(2, 1, 3, inputs=False)
    k2, k3 = (next(i for i, e in enumerate(exz) if tuple(e) == t) for t in ((2, 0, 0), (3, 0, 0)))
    base = NLSSModel(A=np.array([[0.8, 0.2], [-0.2, 0.7]]), B=np.array([[1.0], [0.5]]),
                     C=np.array([[1.0, 0.3]]), D=np.zeros((1, 1)), E=np.zeros((2, len(exz))),
                     F=np.zeros((1, len(exe))), exz=exz, exe=exe, u_offset=np.zeros(1),
                     u_scale=np.ones(1), y_offset=np.zeros(1),
                     dirs=np.zeros((0, 3), dtype=np.int64), covariance=np.zeros((0, 0)),
                     x0=np.zeros(2), state_limit=1e3)
    E = base.E.copy()
    E[1, k2] = 0.05
    truth = replace(base, E=E)
    rng = np.random.default_rng(0)
    u = rng.normal(size=(600, 1))
    u[:300] *= 0.05
    u = np.ascontiguousarray(u)
    y = truth.simulate(u) + 0.01 * rng.normal(size=(600, 1))
    E[0, k3] = 0.3
    runaway = replace(base, E=E.copy())
    with pytest.warns(StabilityWarning, match="diverges at sample 305"):
        runaway.simulate(u)
    dirs = np.array([(4, 0, k3), (4, 1, k2), (2, 0, 1)], dtype=np.int64)
    w, everything = np.ones(1), np.array([0, 600], dtype=np.int64)
    monkeypatch.setattr(mod, "_POLISH_ITERATIONS", 1)
    model, Z, its, _ = mod._whole_record(runaway, base, dirs, np.zeros((1, 2)), np.zeros(2), u,
                                         y, w, 300, 30, lambda: None)
    V = mod._loss(model, Z, everything, u, y, w)
    restart = mod._lm(base, dirs, np.zeros((1, 2)), everything, u, y, w, 1, None)[2]
    assert its[0] > 0 and np.isfinite(V)
    assert V <= restart * (1 + 1e-9)


def test_recovers_a_duffing_oscillator(duffing_fit):
    """The order (2) wins the validation fit among 1, 2, 3; the free run on a fresh
    input matches the noise-free truth to > 97 % while the linear start stays below 70 %; the
    estimation fit is near the noise limit (1 % noise: ≤ 99 %)."""
    m, (u, y, y0), (uv, yv) = duffing_fit
    assert m.order == 2 and "validation fit among [2, 1, 3]" in m.criterion
    assert m.validation_fit_percent[0] > 97.0
    assert m.linear_validation_fit_percent[0] < 70.0
    assert 97.0 < m.fit_percent[0] < 99.2
    # prediction of the nonlinear output from rest equals the truth (started at rest too)
    yhat = m.simulate(uv)[:, 0]
    assert 100 * (1 - np.linalg.norm(yv - yhat) / np.linalg.norm(yv - yv.mean())) > 97.0


def test_sigma_of_the_simulated_output_covers_the_truth(duffing_fit):
    """σ of the free run by linearised propagation of cov θ: on the estimation input, started
    from the estimated x0, the noise-free output lies within 3σ at ≥ 90 % of the samples after
    the first 50 (σ covers the parameter error; x0 is held)."""
    m, (u, y, y0), _ = duffing_fit
    yh, sd = m.simulate(u, m.x0, std=True)
    assert sd.shape == yh.shape and np.all(sd[50:] > 0)
    inside = np.abs(yh[50:, 0] - y0[50:]) < 3 * sd[50:, 0]
    assert inside.mean() >= 0.9


def test_progress_bar_reaches_its_end_when_the_stages_stop_early(monkeypatch):
    """Each Levenberg-Marquardt stage owns max_iterations steps of the bar (the polish over all
    samples of a long record its 10 iterations, weighted by their cost); one that stops early
    (here after far fewer) completes its share, so the bar ends at its total, not part-way."""
    import importlib

    mod = importlib.import_module("gripkit.sysid.nonlinear.nlss")
    seen = []

    def track(iterable, description="", enabled=True, **kw):
        items = list(iterable)
        seen.append([len(items), 0])
        for item in items:
            seen[-1][1] += 1
            yield item

    monkeypatch.setattr(mod, "track", track)
    monkeypatch.setattr(mod, "status", lambda msg: None)
    rng = np.random.default_rng(3)
    u = _input(rng, 1500)
    y = duffing(u) + rng.normal(0.0, 0.01, 1500)
    m = nlss((u, y), order=2, max_iterations=40, progress=True)
    assert m.info["iterations_windows"] + m.info["iterations_whole"] < 40
    assert seen == [[80, 80]]
    # a record longer than the 8000-sample first part: each polish iteration over all 9000
    # samples is ⌈9000/8000⌉ = 2 steps, at most 10 of them: 2·20 + 2·10 = 60
    u = _input(rng, 9000)
    y = duffing(u) + rng.normal(0.0, 0.01, 9000)
    nlss((u, y), order=2, max_iterations=20, progress=True)
    assert seen[1] == [60, 60]


def test_save_load_round_trip(duffing_fit, tmp_path):
    m, (u, y, _), (uv, yv) = duffing_fit
    path = m.save(tmp_path / "m.json")
    assert json.loads(path.read_text())["schema"] == "gripkit.nlss-model"
    m2 = load_model(path)
    assert type(m2) is NLSSModel and m2.structure == "nlss"
    np.testing.assert_array_equal(m2.simulate(uv), m.simulate(uv))
    assert m2.compare(uv, yv).fit_percent == m.compare(uv, yv).fit_percent
    ps, ps2 = m.parameters, m2.parameters
    assert ps.names == ps2.names and all(ps[k].std == ps2[k].std for k in ps.names)
    free = [p for p in ps.values() if not p.fixed]
    assert len(free) == m.dirs.shape[0] and all(p.std > 0 for p in free)
    assert sum(p.fixed for p in ps.values()) == m.order ** 2      # the n² entries fixing the basis


def test_diverging_free_run_is_reported_not_scored():
    """x⁺ = 0.5 x + u + x²: bounded for small inputs, runs away for u = 1 (x ≥ 1 grows): the fit
    is None with a StabilityWarning, never a huge negative percentage."""
    exz = monomial_exponents(1, 1, 2)
    E = np.zeros((1, len(exz)))
    E[0, 0] = 1.0                                                   # the x² monomial
    m = NLSSModel(A=np.array([[0.5]]), B=np.array([[1.0]]), C=np.array([[1.0]]),
                  D=np.zeros((1, 1)), E=E, F=np.zeros((1, 0)), exz=exz,
                  exe=np.zeros((0, 2), dtype=np.int64), u_offset=np.zeros(1),
                  u_scale=np.ones(1), y_offset=np.zeros(1),
                  dirs=np.zeros((0, 3), dtype=np.int64), covariance=np.zeros((0, 0)),
                  x0=np.zeros(1), state_limit=1e3)
    small = 0.05 * np.sin(np.arange(200) / 5.0)
    assert np.all(np.isfinite(m.simulate(small)))
    with pytest.warns(StabilityWarning, match="diverges"):
        fit = m.compare(np.ones(200), np.linspace(0, 1, 200))
    assert fit.fit_percent == [None]


def test_mimo_two_inputs_two_outputs():
    """Two coupled first-order states with a quadratic coupling, two inputs, two outputs: the
    order 2 and degree 2 model reaches > 97 % on fresh data per output, above the linear start,
    without a warning; an order-3 model of the noise-free data is flagged ill-conditioned."""
    def truth(u):
        x = np.zeros(2)
        y = np.empty((len(u), 2))
        for t in range(len(u)):
            y[t] = [x[0] + 0.2 * x[1], x[1]]
            x = np.array([0.7 * x[0] + 0.5 * u[t, 0] + 0.3 * x[1] ** 2,
                          0.6 * x[1] + 0.4 * u[t, 1] - 0.2 * x[0] * u[t, 1]])
        return y

    rng = np.random.default_rng(2)
    u, uv = rng.normal(size=(2000, 2)), rng.normal(size=(1000, 2))
    y = truth(u) + 0.005 * rng.normal(size=(2000, 2))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        m = nlss((u, y), order=2, degree=2, validate=(uv, truth(uv)), progress=False)
    assert m.inputs == ("u1", "u2") and m.outputs == ("y1", "y2")
    assert min(m.validation_fit_percent) > 97.0
    assert all(f > lf for f, lf in zip(m.validation_fit_percent,
                                       m.linear_validation_fit_percent))
    # noise-free data and an order above the true 2: the surplus state is not determined, and
    # the σ of such a model are flagged (the default fit above, of order 2, warns of nothing)
    with pytest.warns(AccuracyWarning, match="ill-conditioned"):
        nlss((u, truth(u)), order=3, degree=2, progress=False)


def test_bad_input_is_named():
    rng = np.random.default_rng(1)
    u = _input(rng, 600)
    y = duffing(u)
    with pytest.raises(DataError, match="equal length"):
        nlss((u, y[:-1]))
    with pytest.raises(DataError, match="non-finite"):
        nlss((np.where(np.arange(600) == 5, np.nan, u), y))
    with pytest.raises(DataError, match="output 'y' is constant"):
        nlss((u, np.full(600, 2.0)))
    with pytest.raises(DataError, match="input 'u' is constant"):
        nlss((np.ones(600), y))
    with pytest.raises(ArgumentError, match="degree must be an integer ≥ 2"):
        nlss((u, y), degree=1)
    with pytest.raises(ArgumentError, match="order must be an integer ≥ 1"):
        nlss((u, y), order=0)
    with pytest.raises(DataError, match="lower the order or degree"):
        nlss((u[:100], y[:100]), order=3)
    with pytest.raises(ArgumentError, match="Trajectory or a pair"):
        nlss(u)
    from gripkit import Trajectory

    tr = Trajectory.uniform(dt=0.01, force=y, current=u)
    with pytest.raises(ArgumentError, match="name its columns with input= and output="):
        nlss(tr)
    with pytest.raises(DataError, match="no column\\(s\\) 'voltage'"):
        nlss(tr, input="voltage", output="force")


def test_load_refuses_another_schema_and_malformed_files(tmp_path):
    p = tmp_path / "other.json"
    p.write_text(json.dumps({"schema": "gripkit.narx-model", "version": 1}))
    with pytest.raises(ModelError, match="expected 'gripkit.nlss-model'"):
        load_nlss(p)
    p.write_text(json.dumps({"schema": "gripkit.nlss-model", "version": 1, "order": 2}))
    with pytest.raises(ModelError, match="a malformed gripkit.nlss-model"):
        load_nlss(p)
    (tmp_path / "x.json").write_text("not json")
    with pytest.raises(ModelError, match="is not JSON"):
        load_nlss(tmp_path / "x.json")


@pytest.fixture(scope="module")
def dc_motor():
    d = np.loadtxt(FIXTURE, delimiter=",", skiprows=1)
    return d[:500, 0], d[:500, 1], d[500:, 0], d[500:, 1]


def test_dc_motor_record(dc_motor):
    """SysIdentPy's split (first 500 samples estimate, last 500 validate). The linear start
    (n4sid, free run from the estimated x0) reaches ≈ 48 %, the NLSS model 93.1 % (measured,
    default options; NARX 94 %); asserted with a 3-point margin and ≥ 35 points above the
    linear start. The voltage takes two values, so its powers ≥ 2 are left out (named)."""
    ue, ye, uv, yv = dc_motor
    m = nlss((ue, ye), validate=(uv, yv), progress=False)
    assert m.validation_fit_percent[0] > 90.0
    assert m.validation_fit_percent[0] > m.linear_validation_fit_percent[0] + 35.0
    assert "takes 2 values" in m.criterion
    # without the validation record the order comes from the singular values and BIC: the same
    # order 2 (93.3 % on the validation half, measured)
    m2 = nlss((ue, ye), progress=False)
    assert m2.order == 2 and "BIC" in m2.criterion
    assert m2.compare(uv, yv).fit_percent[0] > 90.0


def _cli(capsys, *args):
    from gripkit.cli import main

    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_identify_nlss_json_compare_simulate(dc_motor, tmp_path, capsys):
    """identify nlss --json: fit, validation fit, structure, parameters with σ, warnings; the
    model file gives the same validation fit through load_model and `gripkit compare`."""
    ue, ye, uv, yv = dc_motor
    est, val, model = tmp_path / "est.csv", tmp_path / "val.csv", tmp_path / "nlss.json"
    for path, (u, y) in ((est, (ue, ye)), (val, (uv, yv))):
        np.savetxt(path, np.column_stack([u, y]), delimiter=",", header="voltage,output",
                   comments="", fmt="%.10g")
    code, out, err = _cli(capsys, "identify", "nlss", est, "--input", "voltage", "--output",
                          "output", "--fs", 1, "--order", 2, "--degree", 2, "--validate", val,
                          "--out", model, "--json")
    assert code == 0, err
    d = json.loads(out)
    assert d["structure"]["order"] == 2 and d["structure"]["degree"] == 2
    assert d["validation"]["fit_percent"][0] > 90.0 and d["warnings"] == []
    free = [p for p in d["parameters"] if not p["fixed"]]
    assert free and all(p["std"] > 0 for p in free)
    m = load_model(model)
    from gripkit.io import load

    fit = m.compare(load(val, fs=1.0)).fit_percent[0]
    assert fit == pytest.approx(d["validation"]["fit_percent"][0], abs=1e-9)
    code, out, err = _cli(capsys, "compare", model, val, "--fs", 1, "--json")
    assert code == 0, err
    assert json.loads(out)["fit_percent"][0] == pytest.approx(fit, abs=1e-9)
    code, out, err = _cli(capsys, "simulate", model, "--data", val, "--fs", 1, "--json")
    assert code == 0, err
    assert json.loads(out)["outputs"]["output"]["final"] == pytest.approx(
        m.simulate(uv)[-1, 0], rel=1e-9)
    code, out, err = _cli(capsys, "identify", "nlss", est, "--input", "voltage", "--output",
                          "output", "--fs", 1, "--degree", 1)
    assert code != 0 and err.startswith("error: ArgumentError: nlss: degree must be an integer")
    code, out, err = _cli(capsys, "identify", "nlss", est, "--input", "volts", "--output",
                          "output", "--fs", 1)
    assert code != 0 and err.startswith("error:") and "volts" in err


def test_identify_method_nlss_on_a_trajectory(dc_motor):
    from gripkit import Trajectory
    from gripkit.sysid import identify

    ue, ye, uv, yv = dc_motor
    tr = Trajectory.uniform(dt=1.0, voltage=ue, output=ye)
    m = identify(tr, "nlss", input="voltage", output="output", order=2, degree=2,
                 progress=False)
    ref = nlss(tr, input="voltage", output="output", order=2, degree=2, progress=False)
    assert m.inputs == ("voltage",) and m.outputs == ("output",)
    np.testing.assert_array_equal(m.simulate(uv), ref.simulate(uv))
    with pytest.raises(ArgumentError, match="banana"):
        identify(tr, "nlss", input="voltage", output="output", banana=3)


@pytest.mark.slow
def test_monte_carlo_sigma_of_the_output_is_honest():
    """20 noisy records (N = 1500, noise 2 % of the output's standard deviation): on a fixed
    validation input, started from rest, the noise-free output lies within 3σ of the simulated
    one (σ by linearised propagation of cov θ) at ≥ 90 % of 20 (run, sample) pairs each, and
    within 1σ at 45–90 % (a normal error: 68 %). The parameters themselves are not compared: the
    state basis differs from run to run (module docstring); the output is the invariant."""
    rng = np.random.default_rng(50)
    uv = _input(rng, 600)
    yv = duffing(uv)
    at = np.arange(100, 600, 25)
    r1, r3, total = 0, 0, 0
    for i in range(20):
        g = np.random.default_rng(200 + i)
        u = _input(g, 1500)
        y0 = duffing(u)
        m = nlss((u, y0 + g.normal(0.0, 0.02 * y0.std(), u.size)), order=2, degree=3,
                 progress=False)
        yh, sd = m.simulate(uv, std=True)
        z = np.abs(yh[at, 0] - yv[at]) / sd[at, 0]
        r1 += int(np.sum(z < 1))
        r3 += int(np.sum(z < 3))
        total += at.size
    print(f"within 1σ: {r1}/{total}, within 3σ: {r3}/{total}")
    assert r3 >= 0.9 * total
    assert 0.45 * total <= r1 <= 0.9 * total


@pytest.mark.slow
def test_forty_thousand_samples_within_a_minute():
    """Issue 26's speed target: 40 000 samples of the Duffing oscillator (1 % noise), default
    options (orders 2 and 3 fitted, 2 kept by BIC; degree 3, 44 parameters) in under 60 s on the
    2-core machine; measured 13.7 s (4.2 s CPU) at load 6 (benchmarks/bench_nlss.py; 28.7 s,
    8.7 s CPU before the iterations stopped on a stalled criterion). The fit is at the
    noise limit (1 % noise: 99.0 %)."""
    import time

    rng = np.random.default_rng(1)
    u = _input(rng, 40000)
    y0 = duffing(u)
    y = y0 + rng.normal(0.0, 0.01 * y0.std(), u.size)
    t = time.perf_counter()
    m = nlss((u, y), progress=False)
    assert time.perf_counter() - t < 60.0
    assert m.order == 2 and m.fit_percent[0] > 98.8
