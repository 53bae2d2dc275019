"""Hysteresis from the user's data (issue 26, family 4): generic Bouc-Wen (actuator form) and
Prandtl–Ishlinskii with its analytic inverse; recovery with σ, save/load, CLI, bad input."""

import json
import warnings

import numpy as np
import pytest

from gripkit import Trajectory
from gripkit.errors import ArgumentError, DataError, ModelError, PathError, StabilityWarning
from gripkit.models.hysteresis import bouc_wen_advance, bouc_wen_response
from gripkit.sysid import (BoucWenModel, BoucWenOscillatorModel, PrandtlIshlinskiiModel,
                           hysteresis, identify, load_hysteresis, load_model)
from gripkit.sysid.nonlinear.hysteresis_kernels import bw_advance_rk4
from gripkit.sysid.nonlinear.hysteresis import pi_inverse

N = 1500
T = np.linspace(0.0, 1.0, N)
#: a piezo voltage sweep, 0-100 V, four loops of shrinking amplitude (outer and inner loops)
U_PIEZO = 50.0 + 50.0 * np.sin(2 * np.pi * 4 * T - np.pi / 2) * (1 - 0.7 * T)
#: the seed's actuator (001_0b92a7da96e7aa46.txt Table II as read by gripkit.models.hysteresis:
#: d_p = 0.77 µm/V, λ = 0.43 µm/V so α = λ/d_p, β = 0.108 1/V, γ = 7.5e-3 1/V), n = 1 (eq 3)
SEED = dict(d=0.77e-6, alpha=0.43 / 0.77, beta=0.108, gamma=7.5e-3, offset=0.0)
#: a Prandtl–Ishlinskii operator: 8 plays, thresholds 0 … 0.7, positive weights, offset 0.2
PI_R = np.arange(8) * 0.1
PI_W = np.array([0.5, 0.3, 0.2, 0.15, 0.1, 0.08, 0.05, 0.03])
U_PI = 0.85 * np.sin(2 * np.pi * 5 * T) * (1 - 0.8 * T) + 0.05


def test_n1_is_the_seed_eq3_kernel_and_rk4_agrees():
    """For n = 1 the free run is the piezo reference system's eq 3 (BoucWen of gripkit.models)
    bit for bit; the Runge-Kutta step of n ≠ 1, run at n = 1, agrees with its exact step to
    1e-7 (the kink of |h| where a move crosses h = 0 limits RK4 there to a few 1e-9)."""
    m = BoucWenModel(**SEED)
    ref = bouc_wen_response(U_PIEZO, 0.77e-6, 0.43e-6, 0.108, 7.5e-3, 0.0, U_PIEZO[0])[0]
    np.testing.assert_array_equal(m.simulate(U_PIEZO)[:, 0], ref)
    lam = 0.43e-6
    for h, du in ((0.0, 30.0), (2e-6, -45.0), (-3e-6, 60.0), (1e-6, 0.5)):
        exact = bouc_wen_advance(h, du, lam, 0.108, 7.5e-3)
        assert bw_advance_rk4(h, du, lam, 0.108, 7.5e-3, 1.0) == pytest.approx(exact, rel=1e-7,
                                                                               abs=1e-15)


def test_rk4_exponent_2_matches_scipy_ode():
    """n = 2: the per-sample step equals scipy's solve_ivp (rtol 1e-11) on dh/du = α d −
    β s h|h| − γ |h|² along each monotone move."""
    from scipy.integrate import solve_ivp

    lam, beta, gamma, n = 0.4, 3.0, 1.0, 2.0
    for h0, du in ((0.0, 1.2), (0.3, -0.9), (-0.35, 0.7)):
        s = np.sign(du)
        ref = solve_ivp(lambda v, h: [lam - beta * s * h[0] * abs(h[0]) - gamma * h[0] ** 2],
                        (0.0, du), [h0], rtol=1e-11, atol=1e-13).y[0, -1]
        assert bw_advance_rk4(h0, du, lam, beta, gamma, n) == pytest.approx(ref, abs=1e-8)


def test_bouc_wen_recovery_monte_carlo_within_3_sigma():
    """20 noisy records of the seed's actuator (σ = 0.2 µm on a 77 µm stroke): d, α, β, γ and
    the offset within 3σ of the truth in ≥ 90 % of the 100 (run, parameter) pairs, σ from
    s² (JᵀJ)⁻¹ of the free run; σ of ŷ (std=True) matches the runs' spread within 40 %."""
    y0 = BoucWenModel(**SEED).simulate(U_PIEZO)[:, 0]
    inside = total = 0
    runs, sds = [], []
    for i in range(20):
        y = y0 + np.random.default_rng(10 + i).normal(0.0, 0.2e-6, N)
        m = hysteresis((U_PIEZO, y), progress=False)
        assert m.free == ("d", "alpha", "beta", "gamma", "offset") and m.n == 1.0
        for k, v in SEED.items():
            total += 1
            inside += abs(getattr(m, k) - v) < 3 * m.std[k]
        yh, sd = m.simulate(U_PIEZO, std=True)
        runs.append(yh[:, 0])
        sds.append(sd[:, 0])
    assert total == 100 and inside >= 90
    # σ of the simulated output (linearised propagation) against the spread of the 20 runs
    ratio = np.mean(np.array(sds), axis=0) / np.std(np.array(runs), axis=0, ddof=1)
    assert 0.6 < np.median(ratio) < 1.4
    assert m.fit_percent == pytest.approx(_noise_floor(y0, 0.2e-6), abs=0.1)


def _noise_floor(y0, sigma):
    """The fit of the true model on data with white noise σ: 100 (1 − σ √N / ‖y − ȳ‖)."""
    return 100.0 * (1.0 - sigma * np.sqrt(len(y0)) / np.linalg.norm(y0 - y0.mean()))


def test_generic_bouc_wen_agrees_with_the_piezo_identification():
    """On one record of the seed's actuator, the generic family (n = 1, no offset) and the
    piezo system's identify_bouc_wen (greybox fit of models.hysteresis.BoucWen, eq 3) find the
    same minimum: λ = α d, β, γ and d_p to 1e-5, and the same σ to 1e-3."""
    from gripkit.sysid import identify_bouc_wen

    y = BoucWenModel(**SEED).simulate(U_PIEZO)[:, 0] + np.random.default_rng(2).normal(
        0.0, 0.2e-6, N)
    tr = Trajectory(T, {"U": U_PIEZO, "y": y}, {"U": "V", "y": "m"})
    old = identify_bouc_wen(tr, progress=False)
    new = hysteresis(tr, input="U", output="y", offset=False, progress=False)
    assert new.free == ("d", "alpha", "beta", "gamma")
    for k_old, v_new in (("d_p", new.d), ("lambda", new.lam), ("beta", new.beta),
                         ("gamma", new.gamma)):
        assert v_new == pytest.approx(old.params[k_old], rel=1e-5)
    for k_old, k_new in (("d_p", "d"), ("beta", "beta"), ("gamma", "gamma")):
        assert new.std[k_new] == pytest.approx(old.std[k_old], rel=1e-3)


def _n2_case():
    true = dict(d=1.0, alpha=0.4, beta=3.0, gamma=1.0, offset=0.1)
    u = np.sin(2 * np.pi * 4 * T) * (1 - 0.6 * T)
    return true, u, BoucWenModel(**true, n=2.0).simulate(u)[:, 0]


def test_bouc_wen_free_exponent_recovered():
    """exponent='free' on a Bouc-Wen of n = 2 (noise 0.005 on a ±0.6 output): n and the other
    five parameters within 3σ in ≥ 16 of the 18 pairs of 3 runs."""
    true, u, y0 = _n2_case()
    true["n"] = 2.0
    inside = 0
    for i in range(3):
        y = y0 + np.random.default_rng(50 + i).normal(0.0, 0.005, N)
        m = hysteresis((u, y), exponent="free", progress=False)
        assert "n" in m.free
        inside += sum(abs(getattr(m, k) - v) < 3 * m.std[k] for k, v in true.items())
    assert inside >= 16


@pytest.mark.slow
def test_bouc_wen_free_exponent_monte_carlo():
    """The same with 20 runs: ≥ 90 % of the 120 pairs within 3σ."""
    true, u, y0 = _n2_case()
    true["n"] = 2.0
    inside = 0
    for i in range(20):
        y = y0 + np.random.default_rng(500 + i).normal(0.0, 0.005, N)
        m = hysteresis((u, y), exponent="free", progress=False)
        inside += sum(abs(getattr(m, k) - v) < 3 * m.std[k] for k, v in true.items())
    assert inside >= 0.9 * 120


#: a 1 kg mass on a spring of 4 kN/m, half of it hysteretic (z saturates at 1/(β+γ) = 2.5 mm),
#: driven by a force of two tones, sampled at 1 kHz
OSC = dict(mass=1.0, damping=6.0, k_e=2000.0, k_h=2000.0, beta=300.0, gamma=100.0, offset=0.0)
OSC_DT, OSC_N = 1e-3, 3000
OSC_T = np.arange(OSC_N) * OSC_DT
OSC_F = (15 * np.sin(2 * np.pi * 2 * OSC_T) * (1 - 0.6 * OSC_T / OSC_T[-1])
         + 5 * np.sin(2 * np.pi * 5.3 * OSC_T))


def _oscillator_runs(seeds):
    y0 = BoucWenOscillatorModel(**OSC, dt=OSC_DT).simulate(OSC_F)[:, 0]
    inside, models = 0, []
    for i in seeds:
        y = y0 + np.random.default_rng(i).normal(0.0, 1e-4, OSC_N)     # 0.1 mm on ±10 mm
        tr = Trajectory(OSC_T, {"F": OSC_F, "x": y}, {"F": "N", "x": "m"})
        m = hysteresis(tr, input="F", output="x", form="oscillator", progress=False)
        inside += sum(abs(getattr(m, k) - v) < 3 * m.std[k] for k, v in OSC.items())
        models.append((m, tr))
    return inside, models


def test_bouc_wen_oscillator_recovery_and_round_trip(tmp_path):
    """The oscillator form (force on a mass with a Bouc-Wen spring) from one noisy record: its
    seven parameters within 3σ (≥ 6 of 7), the fit at the noise floor; saved and read back it is
    the same type with the same free run; a record at another sample time is refused."""
    inside, [(m, tr)] = _oscillator_runs([0])
    assert inside >= 6 and m.dt == pytest.approx(OSC_DT, rel=1e-12) and m.substeps == 4
    y0 = BoucWenOscillatorModel(**OSC, dt=OSC_DT).simulate(OSC_F)[:, 0]
    assert m.fit_percent == pytest.approx(_noise_floor(y0, 1e-4), abs=0.1)
    m2 = load_model(m.save(tmp_path / "osc.json"))
    assert type(m2) is BoucWenOscillatorModel and m2.parameters == m.parameters
    np.testing.assert_array_equal(m2.simulate(tr), m.simulate(tr))
    assert m.parameters["k_e"].unit == "N/m"
    with pytest.raises(DataError, match="sampled every 0.002 s, the model every 0.001 s"):
        m.simulate(Trajectory(OSC_T * 2, {"F": OSC_F}))
    with pytest.raises(DataError, match="sampled every 0.002 s"):
        m.compare(Trajectory(OSC_T * 2, {"F": OSC_F, "x": y0}))
    with pytest.raises(ArgumentError, match="give the sample time dt="):
        hysteresis((OSC_F, y0), form="oscillator")


def test_cli_bouc_wen_oscillator(tmp_path, capsys):
    """--form oscillator: the structure says so, and gripkit compare on the validation record
    gives the --validate number."""
    truth = BoucWenOscillatorModel(**OSC, dt=OSC_DT)
    est, val, model = tmp_path / "est.csv", tmp_path / "val.csv", tmp_path / "osc.json"
    rng = np.random.default_rng(9)
    for path, f in ((est, OSC_F), (val, 12 * np.sin(2 * np.pi * 3 * OSC_T))):
        y = truth.simulate(f)[:, 0] + rng.normal(0.0, 1e-4, OSC_N)
        np.savetxt(path, np.column_stack([OSC_T, f, y]), delimiter=",", header="t,F,x",
                   comments="", fmt="%.12g")
    code, out, err = _cli(capsys, "identify", "hysteresis", est, "--input", "F", "--output", "x",
                          "--form", "oscillator", "--validate", val, "--out", model, "--json")
    assert code == 0, err
    d = json.loads(out)
    assert d["structure"]["form"] == "oscillator" and d["warnings"] == []
    p = {q["name"]: q for q in d["parameters"]}
    assert p["k_h"]["value"] == pytest.approx(2000.0, abs=3 * p["k_h"]["std"])
    code, out, err = _cli(capsys, "compare", model, val, "--json")
    assert code == 0, err
    assert json.loads(out)["fit_percent"][0] == pytest.approx(d["validation"]["fit_percent"],
                                                              abs=1e-9)
    assert d["validation"]["fit_percent"] > 95.0


@pytest.mark.slow
def test_bouc_wen_oscillator_monte_carlo():
    """20 noisy records: ≥ 90 % of the 140 (run, parameter) pairs within 3σ."""
    inside, _ = _oscillator_runs(range(100, 120))
    assert inside >= 0.9 * 140


def test_prandtl_ishlinskii_recovery_monte_carlo_and_output_sigma():
    """30 noisy records (σ = 0.01): the 8 weights within 3σ in ≥ 90 % of the 240 pairs; the
    σ of the simulated output (std=True, exact for a model linear in the weights) matches the
    spread of the 30 free runs within 35 %."""
    y0 = PrandtlIshlinskiiModel(PI_R, PI_W, offset=0.2).simulate(U_PI)[:, 0]
    inside, runs, sds = 0, [], []
    for i in range(30):
        y = y0 + np.random.default_rng(80 + i).normal(0.0, 0.01, N)
        m = hysteresis((U_PI, y), "prandtl-ishlinskii", thresholds=PI_R)
        inside += int(np.sum(np.abs(m.weights - PI_W) < 3 * m.weights_std))
        yh, sd = m.simulate(U_PI, std=True)
        runs.append(yh[:, 0])
        sds.append(sd[:, 0])
    assert inside >= 0.9 * 240
    spread = np.std(np.array(runs), axis=0, ddof=1)
    ratio = np.mean(np.array(sds), axis=0) / spread
    assert 0.65 < np.median(ratio) < 1.35


def test_pi_inverse_formula_and_round_trip():
    """Kuhnen's inverse: for r = [0, 1], w = [1, 1] it is r̂ = [0, 1], ŵ = [1, −1/2]; for the
    8-play operator inverse ∘ model and model ∘ inverse are the identity on a trajectory, and
    inverting twice gives the model back."""
    rh, wh = pi_inverse([0.0, 1.0], [1.0, 1.0])
    np.testing.assert_allclose(rh, [0.0, 1.0])
    np.testing.assert_allclose(wh, [1.0, -0.5])
    m = PrandtlIshlinskiiModel(PI_R, PI_W, offset=0.2, input_name="U", output_name="x")
    inv = m.invert()
    assert inv.inputs == ("x",) and inv.outputs == ("U",)
    np.testing.assert_allclose(inv.simulate(m.simulate(U_PI)[:, 0])[:, 0], U_PI, atol=1e-12)
    desired = 0.2 + 0.6 * np.sin(2 * np.pi * 3 * T) * np.exp(-T)       # feed-forward target
    voltage = inv.simulate(desired)[:, 0]
    np.testing.assert_allclose(m.simulate(voltage)[:, 0], desired, atol=1e-12)
    back = inv.invert()
    np.testing.assert_allclose(back.thresholds, PI_R, atol=1e-14)
    np.testing.assert_allclose(back.weights, PI_W, rtol=1e-12)
    assert back.offset == pytest.approx(0.2) and back.input_offset == 0.0


def test_identified_pi_inverts_and_compensates():
    """An identified model's inverse linearises the true hysteresis: fed through the inverse,
    the true operator follows a desired trajectory to within 2 % of its range (the residual is
    the identification error)."""
    truth = PrandtlIshlinskiiModel(PI_R, PI_W, offset=0.2)
    y = truth.simulate(U_PI)[:, 0] + np.random.default_rng(3).normal(0.0, 0.005, N)
    m = hysteresis((U_PI, y), "prandtl-ishlinskii", operators=8)
    desired = 0.2 + 0.6 * np.sin(2 * np.pi * 3 * T) * np.exp(-T)
    achieved = truth.simulate(m.invert().simulate(desired)[:, 0])[:, 0]
    assert np.max(np.abs(achieved - desired)) < 0.02 * np.ptp(desired)


def test_invert_refuses_a_zero_initial_weight():
    m = PrandtlIshlinskiiModel(np.array([0.0, 0.5]), np.array([0.0, 1.0]))
    with pytest.raises(ModelError, match="not invertible"):
        m.invert()


@pytest.mark.parametrize("kind", ["bouc-wen", "prandtl-ishlinskii"])
def test_save_load_same_type_and_identical_simulate(kind, tmp_path):
    u = U_PIEZO if kind == "bouc-wen" else U_PI
    truth = (BoucWenModel(**SEED) if kind == "bouc-wen"
             else PrandtlIshlinskiiModel(PI_R, PI_W, offset=0.2))
    y = truth.simulate(u)[:, 0] * (1 + 0.0) + np.random.default_rng(1).normal(
        0.0, 1e-3 * np.ptp(truth.simulate(u)), N)
    tr = Trajectory(T, {"U": u, "x": y}, {"U": "V", "x": "m"})
    m = hysteresis(tr, kind, input="U", output="x", progress=False)
    path = m.save(tmp_path / "h.json")
    assert json.loads(path.read_text())["schema"] == "gripkit.hysteresis-model"
    for m2 in (load_model(path), load_hysteresis(path)):
        assert type(m2) is type(m) and m2.structure == kind
        assert m2.inputs == ("U",) and m2.outputs == ("x",)
        np.testing.assert_array_equal(m2.simulate(tr), m.simulate(tr))
        np.testing.assert_array_equal(m2.simulate(tr, std=True)[1], m.simulate(tr, std=True)[1])
        assert m2.parameters == m.parameters
        assert m2.compare(tr).fit_percent == m.compare(tr).fit_percent
    assert m.parameters["w_0" if kind != "bouc-wen" else "d"].unit == "m/V"


def test_identify_method_hysteresis_on_a_trajectory():
    tr = Trajectory(T, {"U": U_PI, "x": PrandtlIshlinskiiModel(PI_R, PI_W).simulate(U_PI)[:, 0]})
    m = identify(tr, "hysteresis", input="U", output="x", model="prandtl-ishlinskii",
                 thresholds=PI_R)
    assert isinstance(m, PrandtlIshlinskiiModel) and m.inputs == ("U",)
    np.testing.assert_allclose(m.weights, PI_W, atol=1e-9)                # noise-free: exact
    with pytest.raises(ArgumentError, match="unknown keyword 'degree'"):
        identify(tr, "hysteresis", input="U", output="x", degree=3)


def test_bad_input_is_named():
    y = np.linspace(0.0, 1.0, N)
    with pytest.raises(DataError, match="hysteresis not excited: the input 'u' never reverses"):
        hysteresis((np.linspace(0.0, 100.0, N), y), progress=False)
    with pytest.raises(DataError, match="hysteresis not excited"):               # noise is no loop
        hysteresis((np.linspace(0.0, 1.0, N) + np.random.default_rng(0).normal(0, 1e-3, N), y),
                   "prandtl-ishlinskii")
    with pytest.raises(DataError, match="input 'u' is constant"):
        hysteresis((np.ones(N), y))
    with pytest.raises(DataError, match="play of threshold 0.9 is not excited"):
        hysteresis((U_PI, y), "prandtl-ishlinskii", thresholds=[0.0, 0.5, 0.9])
    with pytest.raises(ArgumentError, match="model must be one of bouc-wen, prandtl-ishlinskii"):
        hysteresis((U_PI, y), "preisach")
    with pytest.raises(ArgumentError, match="exponent must be a number in"):
        hysteresis((U_PI, y), exponent=0.5)
    with pytest.raises(DataError, match="u has 1500 samples but y has 3"):
        hysteresis((U_PI, y[:3]))


def test_divergent_free_run_is_reported_not_scored():
    """β + γ < 0: h grows without bound; compare gives None with a StabilityWarning."""
    m = BoucWenModel(d=1.0, alpha=1.0, beta=0.0, gamma=-20.0)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fit = m.compare((U_PIEZO, U_PIEZO))
    assert fit.fit_percent == [None]
    assert any(issubclass(w.category, StabilityWarning) for w in caught)


def _cli(capsys, *args):
    from gripkit.cli import main

    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_identify_hysteresis_json_compare_simulate(tmp_path, capsys):
    """--json has fit_percent, validation.fit_percent (= gripkit compare's number), the structure,
    the parameters with σ and warnings; simulate reproduces the model's free run; a record that
    never reverses is one error line."""
    truth = BoucWenModel(**SEED)
    est, val, mono, model = (tmp_path / n for n in ("est.csv", "val.csv", "mono.csv", "bw.json"))
    rng = np.random.default_rng(5)
    for path, u in ((est, U_PIEZO), (val, 50.0 + 30.0 * np.sin(2 * np.pi * 3 * T)),
                    (mono, np.linspace(0.0, 100.0, N))):
        y = truth.simulate(u)[:, 0] + rng.normal(0.0, 0.2e-6, N)
        np.savetxt(path, np.column_stack([T, u, y]), delimiter=",", header="t,U,x",
                   comments="", fmt="%.12g")
    code, out, err = _cli(capsys, "identify", "hysteresis", est, "--input", "U", "--output", "x",
                          "--validate", val, "--out", model, "--json")
    assert code == 0, err
    d = json.loads(out)
    assert d["structure"]["model"] == "bouc-wen" and d["structure"]["exponent"] == 1.0
    y0 = truth.simulate(U_PIEZO)[:, 0]
    assert d["warnings"] == [] and d["fit_percent"] == pytest.approx(_noise_floor(y0, 0.2e-6),
                                                                     abs=0.1)
    p = {q["name"]: q for q in d["parameters"]}
    assert p["beta"]["value"] == pytest.approx(0.108, abs=3 * p["beta"]["std"])
    assert p["n"]["fixed"] and p["n"]["std"] is None and p["d"]["std"] > 0
    code, out, err = _cli(capsys, "compare", model, val, "--json")
    assert code == 0, err
    validation_fit = d["validation"]["fit_percent"]
    assert json.loads(out)["fit_percent"][0] == pytest.approx(validation_fit, abs=1e-9)
    code, out, err = _cli(capsys, "simulate", model, "--data", val, "--json")
    assert code == 0, err
    final = json.loads(out)["outputs"]["x"]["final"]
    tv = np.loadtxt(val, delimiter=",", skiprows=1)
    assert final == pytest.approx(load_model(model).simulate(tv[:, 1])[-1, 0], rel=1e-12)
    code, out, err = _cli(capsys, "identify", "hysteresis", est, "--input", "U", "--output", "x",
                          "--model", "prandtl-ishlinskii", "--operators", 6, "--json")
    assert code == 0, err
    d = json.loads(out)
    assert d["structure"]["operators"] == 6 and d["validation"] is None
    code, out, err = _cli(capsys, "identify", "hysteresis", mono, "--input", "U", "--output", "x")
    assert code == 1 and err.startswith("error: DataError: hysteresis not excited")
    assert len(err.strip().splitlines()) == 1
    code, out, err = _cli(capsys, "report", model, val, "--out", tmp_path / "rep", "--json")
    assert code == 0, err                                              # the same number again
    assert json.loads(out)["fit_percent"][0] == pytest.approx(validation_fit, abs=1e-9)
    code, out, err = _cli(capsys, "identify", "hysteresis", est, "--input", "U", "--output", "x",
                          "--model", "preisach")
    assert code == 1 and "--model: expected one of bouc-wen, prandtl-ishlinskii" in err


def test_hostile_model_files_are_named(tmp_path):
    m = PrandtlIshlinskiiModel(PI_R, PI_W, offset=0.2)
    doc = m.to_dict()
    cases = {"not JSON": ("{", "is not JSON"),
             "version": (json.dumps({**doc, "version": 9}), "of version 9"),
             "kind": (json.dumps({**doc, "model": "preisach"}), "unknown hysteresis model"),
             "lengths": (json.dumps({**doc, "weights": [1.0]}), "a malformed"),
             "schema": (json.dumps({**doc, "schema": "gripkit.narx-model"}),
                        "expected 'gripkit.hys")}
    for name, (text, phrase) in cases.items():
        p = tmp_path / f"{name}.json"
        p.write_text(text)
        with pytest.raises(ModelError, match=phrase):
            load_hysteresis(p)
    with pytest.raises(PathError, match="does not exist"):
        load_hysteresis(tmp_path / "missing.json")


def test_prandtl_ishlinskii_weights_the_record_does_not_determine_have_no_sigma():
    """A binary input (±1 A, held for a few samples: a PRBS) moves every play of threshold
    below 1 between the same two levels, so the ten play operators are collinear: the weights'
    Gram matrix is singular to working precision, and the pseudo-inverse left some variances at
    0 or below by rounding, printed as "± 0" beside σ of 10⁵–10⁶. Those weights now have no σ
    (NaN; null in JSON; "not determined" in the summary), the others keep theirs, and a
    well-excited record (the recovery test's) has every σ finite and positive."""
    rng = np.random.default_rng(0)
    u = np.repeat(np.sign(rng.standard_normal(100)), 4)
    y = np.convolve(u, [0.0, 0.5, 0.3])[:400] + 0.01 * rng.standard_normal(400)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = hysteresis((u, y), "prandtl-ishlinskii", operators=10)
    var = np.diag(m.covariance)[:10]
    sd = m.weights_std
    assert np.array_equal(np.isnan(sd), var <= 0.0) and np.isnan(sd).any()
    np.testing.assert_allclose(sd[var > 0], np.sqrt(var[var > 0]))
    assert "not determined by this record" in m.summary()
    assert all(s is None for s, v in zip(m.to_dict()["weights_std"], var) if v <= 0.0)
    good = hysteresis((U_PI, np.asarray(PrandtlIshlinskiiModel(PI_R, PI_W).simulate(U_PI))[:, 0]
                       + 1e-3 * np.random.default_rng(1).standard_normal(len(U_PI))),
                      "prandtl-ishlinskii", thresholds=PI_R)
    assert np.all(np.isfinite(good.weights_std)) and np.all(good.weights_std > 0)
