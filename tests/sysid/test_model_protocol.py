"""Issue 23, item 1: every identified model family on one protocol (gripkit.sysid.model_protocol).

For each family (ARX SISO, MISO and MIMO, ARMAX, OE, N4SID, PEM, tfest, step response (a
continuous second-order transfer function from ``identify(data, "step")``), NARX, rational NARX,
Hammerstein–Wiener, nonlinear state space, Bouc-Wen actuator and oscillator, Prandtl–Ishlinskii):
the model is an IdentifiedModel, save → load_model gives back the same type with the same
public attributes (walked by :func:`assert_same_public`) and bit-identical simulate() and
compare(); a model file of
schema gripkit.linear-model version 1 (written by gripkit 0.1.0 before this change, kept in
tests/sysid/data/model_v1) loads, migrated; and the one validation fit, prediction and residuals
agree with their definitions; the output-error families predict by the free run that compare
scores, and no nonlinear family converts to a linear system."""

import inspect
import json
import re

import numpy as np
import pytest

from gripkit import Trajectory
from gripkit.errors import ArgumentError, DataError, ModelError
from gripkit.io import load
from gripkit.lti import LinearSystem, TransferFunction
from gripkit.params import ParameterSet
from gripkit.sysid import (BoucWenModel, BoucWenOscillatorModel, IdentifiedLinearModel,
                           IdentifiedModel, LinearModel, ModelFit, PolynomialModel,
                           PrandtlIshlinskiiModel, armax, arx, compare, hammerstein_wiener,
                           hysteresis, identify, load_model, n4sid, narx, nlss, oe, pem, tfest,
                           validate)

from mimo_systems import oe_data, two_by_two
from pathlib import Path

V1 = Path(__file__).parent / "data" / "model_v1"
#: record-bound attributes a model file does not hold (documented at PolynomialModel)
#: record-bound: the polynomial models compute these from the estimation record they keep
#: (simulation_fit_percent: the free run, numba's kernel, which a saving `identify arx` skips)
NOT_IN_FILE = {"estimation_residuals", "estimation_data", "stored_residuals",
               "simulation_fit_percent"}


def _same(a, b, where):
    if isinstance(a, ParameterSet):
        a, b = ([(p.name, p.value, p.unit, p.std) for p in x.values()] for x in (a, b))
    if isinstance(a, LinearSystem):
        a, b = a.to_dict(), b.to_dict()
    if isinstance(a, dict):
        assert isinstance(b, dict) and sorted(a) == sorted(b), where
        for k in a:
            _same(a[k], b[k], f"{where}[{k!r}]")
        return
    if isinstance(a, np.ndarray) and a.dtype != object:
        np.testing.assert_array_equal(a, np.asarray(b, dtype=a.dtype), err_msg=where)
        return
    if isinstance(a, (np.ndarray, list, tuple)):
        assert len(a) == len(b), where
        for i, (va, vb) in enumerate(zip(a, b)):
            _same(va, vb, f"{where}[{i}]")
        return
    if isinstance(a, float) and isinstance(b, float) and np.isnan(a):
        assert np.isnan(b), where
        return
    assert a == b, f"{where}: {a!r} != {b!r}"


def assert_same_public(m, back):
    """Every public non-callable attribute of ``m`` (fields and properties) equals ``back``'s."""
    names = [n for n in dir(m) if not n.startswith("_") and n not in NOT_IN_FILE]
    seen = 0
    for n in names:
        a = getattr(m, n)
        if callable(a) and not isinstance(a, (LinearSystem, ParameterSet)):
            continue
        _same(a, getattr(back, n), n)
        seen += 1
    assert seen >= 10  # the walk did look at the attributes


def _siso(n=1500, seed=0):
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = np.zeros(n)
    for t in range(2, n):
        y[t] = 1.2 * y[t - 1] - 0.5 * y[t - 2] + 0.8 * u[t - 1] + 0.3 * u[t - 2]
    return u, y + 0.02 * rng.standard_normal(n)


def _families():
    u, y = _siso()
    meta = dict(dt=0.01, input_name="current", output_name="force", input_unit="A",
                output_unit="N", u_offset=0.5, y_offset=1.0)
    g = two_by_two()
    U, Y = oe_data(g, 2000, 0.05, seed=1)
    names = dict(inputs=["a", "b"], outputs=["c", "d"], input_units=["V", "V"],
                 output_units=["N", "m"])
    ss = n4sid(U, Y, 4, dt=0.01, u_offset=[1.0, 0.0], y_offset=[3.0, -1.0], **names)
    return {
        "arx siso": (arx(u, y, 2, 2, 1, **meta), ["current"], u, y),
        "arx miso": (arx(U, Y[:, :1], 2, 2, 1, dt=0.01), ["a", "b"], U, Y[:, :1]),
        "arx mimo": (arx(U, Y, 2, 2, 1, dt=0.01), ["a", "b"], U, Y),
        "armax": (armax(u, y, 2, 2, 1, 1, **meta), ["current"], u, y),
        "oe": (oe(u, y, 2, 2, 1, **meta), ["current"], u, y),
        "n4sid": (ss, ["a", "b"], U, Y),
        "pem": (pem(ss, u=U, y=Y), ["a", "b"], U, Y),
        "tfest": (tfest(u, y, 2, 1, dt=0.01, inputs=["current"], outputs=["force"]),
                  ["current"], u, y),
        "narx": (narx(u, y, degree=2, lags=2, dt=0.01), ["u"], u, y),
        "step": _step_family(),
    }


def _step_family():
    """The step-response model of a second-order system (K = 1.5 N/A, ω_n = 12 rad/s, ζ = 0.4),
    its input stepping from 0.5 A to 1.5 A at sample 20 of 300 (every 0.01 s), output noise
    σ = 0.005 N; with the record's deviations from the model's offsets (what _record takes)."""
    u = np.where(np.arange(300) >= 20, 1.5, 0.5)
    w = 12.0
    y = TransferFunction([1.5 * w * w], [1.0, 2 * 0.4 * w, w * w]).c2d(0.01).simulate(u - 0.5)
    y = 1.0 + y[:, 0] + 0.005 * np.random.default_rng(3).standard_normal(300)
    tr = Trajectory.uniform(dt=0.01, current=u, force=y, units={"current": "A", "force": "N"})
    m = identify(tr, "step", inputs="current", outputs="force")
    return m, ["current"], u - m.u_offset[0], y - m.y_offset[0]


def _nonlinear_records(n=400, seed=0):
    """Small records (400 samples, noise σ in ``NOISE``) of known nonlinear systems: a saturated
    input into the ARX [2 2 1] of :func:`_siso` (Hammerstein), a rational first-order system, a
    second-order state space with a quadratic state term; the seed's piezo actuator for Bouc-Wen
    (tests/sysid/test_hysteresis.py SEED), 8 plays for Prandtl–Ishlinskii, a Bouc-Wen
    oscillator sampled every 1 ms."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    w = np.clip(u, -0.8, 0.8)
    yh, yr, yn, x = np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(2)
    for t in range(n):
        if t >= 2:
            yh[t] = 1.2 * yh[t - 1] - 0.5 * yh[t - 2] + 0.8 * w[t - 1] + 0.3 * w[t - 2]
        if t >= 1:
            yr[t] = (0.6 * yr[t - 1] + 0.8 * u[t - 1]) / (1 + 0.3 * yr[t - 1] ** 2)
        yn[t] = x[0]
        x = np.array([0.7 * x[0] + 0.5 * u[t] + 0.2 * x[1] ** 2, 0.5 * x[1] + 0.4 * u[t]])
    T = np.linspace(0.0, 1.0, n)
    up = 50.0 + 50.0 * np.sin(2 * np.pi * 4 * T - np.pi / 2) * (1 - 0.7 * T)
    seed_bw = dict(d=0.77e-6, alpha=0.43 / 0.77, beta=0.108, gamma=7.5e-3, offset=0.0)
    ui = 0.85 * np.sin(2 * np.pi * 5 * T) * (1 - 0.8 * T) + 0.05
    pi = PrandtlIshlinskiiModel(np.arange(8) * 0.1, np.array([0.5, 0.3, 0.2, 0.15, 0.1, 0.08,
                                                              0.05, 0.03]), offset=0.2)
    osc = BoucWenOscillatorModel(mass=1.0, damping=6.0, k_e=2000.0, k_h=2000.0, beta=300.0,
                                 gamma=100.0, offset=0.0, dt=1e-3)
    to = np.arange(600) * 1e-3
    uo = 15 * np.sin(2 * np.pi * 2 * to) * (1 - 0.6 * to / to[-1])
    uo += 5 * np.sin(2 * np.pi * 5.3 * to)
    clean = {"hw": (u, yh), "rational narx": (u, yr), "nlss": (u, yn),
             "bouc-wen": (up, BoucWenModel(**seed_bw).simulate(up)[:, 0]),
             "prandtl-ishlinskii": (ui, pi.simulate(ui)[:, 0]),
             "bouc-wen oscillator": (uo, osc.simulate(uo)[:, 0])}
    return {k: (ui_, y + NOISE[k] * rng.standard_normal(y.size))
            for k, (ui_, y) in clean.items()}


#: the noise σ of each nonlinear record (in the output's unit)
NOISE = {"hw": 0.01, "rational narx": 0.01, "nlss": 0.005, "bouc-wen": 0.2e-6,
         "prandtl-ishlinskii": 0.005, "bouc-wen oscillator": 1e-4}


def _nonlinear_families():
    r = _nonlinear_records()
    hw = hammerstein_wiener(*r["hw"], input_nonlinearity="saturation", nb=2, nf=2, nk=1, dt=0.01)
    models = {
        "rational narx": narx(*r["rational narx"], degree=2, lags=1, dt=0.01, basis="rational"),
        "hw": hw,
        "nlss": nlss(r["nlss"], order=2, degree=2, dt=0.01, progress=False),
        "bouc-wen": hysteresis(r["bouc-wen"], dt=0.01, progress=False),
        "prandtl-ishlinskii": hysteresis(r["prandtl-ishlinskii"], "prandtl-ishlinskii",
                                         operators=8, dt=0.01, progress=False),
        "bouc-wen oscillator": hysteresis(r["bouc-wen oscillator"], form="oscillator", dt=1e-3,
                                          progress=False)}
    return {k: (m, list(m.inputs), *r[k]) for k, m in models.items()}


FAMILIES = _families() | _nonlinear_families()
#: the nonlinear families; the output-error ones predict by their free run
NONLINEAR = ("narx", "rational narx", "hw", "nlss", "bouc-wen", "prandtl-ishlinskii",
             "bouc-wen oscillator")
OUTPUT_ERROR = NONLINEAR[2:]


def _record(m, u, y):
    """A trajectory with the model's columns sampled every ``m.dt`` (a linear model's offsets
    added back: its arrays are deviations)."""
    u, y = np.asarray(u).reshape(len(u), -1), np.asarray(y).reshape(len(y), -1)
    linear = isinstance(m, IdentifiedLinearModel)
    uo = np.atleast_1d(m.u_offset if linear else 0.0) * np.ones(u.shape[1])
    yo = np.atleast_1d(m.y_offset if linear else 0.0) * np.ones(y.shape[1])
    cols = {n: u[:, i] + uo[i] for i, n in enumerate(m.inputs)}
    cols |= {n: y[:, i] + yo[i] for i, n in enumerate(m.outputs)}
    return Trajectory.uniform(dt=m.dt or 0.01, **cols)


@pytest.mark.parametrize("family", list(FAMILIES))
def test_round_trip_same_type_attributes_simulation_and_fit(family, tmp_path):
    m, _, u, y = FAMILIES[family]
    assert isinstance(m, IdentifiedModel)
    path = tmp_path / "m.json"
    m.save(path)
    back = load_model(path)
    assert type(back) is type(m)
    assert_same_public(m, back)
    tr = _record(m, u, y)
    np.testing.assert_array_equal(back.simulate(tr), m.simulate(tr))
    fit, fit_back = m.compare(tr), back.compare(tr)
    assert isinstance(fit, ModelFit) and fit.definition == m.fit_definition
    assert fit_back.fit_percent == fit.fit_percent and fit.outputs == tuple(m.outputs)
    np.testing.assert_array_equal(fit_back.simulated, fit.simulated)
    assert None not in fit.fit_percent                                # a stable model
    if family not in ("arx miso", "arx mimo"):  # ARX [2 2 1] is not the order-4 2x2 system
        assert min(fit.fit_percent) > 90.0


def test_arx_returns_one_type_whatever_the_number_of_inputs():
    types = {type(FAMILIES[k][0]) for k in ("arx siso", "arx miso", "arx mimo")}
    assert types == {PolynomialModel}, types


def test_linear_families_share_one_hierarchy_and_one_validation_fit():
    """The linear models are IdentifiedLinearModels: compare() is VALIDATION_FIT (free run, x0 by
    least squares) whatever the family, so an ARX model and its state-space record score alike."""
    from gripkit.sysid.linear.linear_model import VALIDATION_FIT

    for k, (m, *_rest) in FAMILIES.items():
        if k not in NONLINEAR:
            assert isinstance(m, IdentifiedLinearModel) and m.fit_definition == VALIDATION_FIT
    m, _, u, y = FAMILIES["arx siso"]
    tr = _record(m, u, y)
    assert m.compare(tr).fit_percent == m.linear_record().compare(tr).fit_percent


def test_narx_states_its_free_run_from_measured_outputs():
    from gripkit.sysid.nonlinear.narx import NARX_FIT

    m, _, u, y = FAMILIES["narx"]
    assert m.structure == "narx" and m.fit_definition == NARX_FIT and "measured" in NARX_FIT
    assert m.initial_state == "measured" and m.inputs == ("u",) and m.outputs == ("y",)
    assert m.compare(u, y).fit_percent == [m.fit_percent]   # the estimation fit, same definition
    p = m.parameters
    assert len(p) == len(m.terms) and [q.std for q in p.values()] == m.theta_std.tolist()


def _free_run(m, tr):
    """The free run that ``compare`` scores, from each family's own names: Hammerstein–Wiener from
    the initial steady state fitted to the record, nonlinear state space from the estimated x0,
    hysteresis from its relaxed state."""
    u, y = tr[m.inputs[0]], tr[m.outputs[0]]
    if m.structure == "hw":
        return m.simulate(tr, initial_input=m.fit_initial_input(u, y))
    if m.structure == "nlss":
        return m.simulate(tr, x0=m.estimate_x0(tr))
    return m.simulate(tr)


@pytest.mark.parametrize("family", OUTPUT_ERROR)
def test_output_error_families_predict_by_their_free_run(family):
    """Hammerstein–Wiener, NLSS and the hysteresis models are output-error models: ŷ(t | t − k)
    is the free run for every k (predict(tr, 1) and predict(tr, 7) are bit for bit the free run
    compare scores), the residuals are y − ŷ over all N samples, their RMS is between 0.8 and 1.4
    times the record's noise σ (the models fit the known systems: 0.96–1.04 σ, Hammerstein–Wiener
    1.28 σ on its 400 samples), and the arrays of a single-channel model give one signal (N,),
    of the NLSS model (N, p), as the linear state-space models."""
    m, _, u, y = FAMILIES[family]
    tr = _record(m, u, y)
    free = _free_run(m, tr)
    np.testing.assert_array_equal(m.predict(tr, horizon=1), free)
    np.testing.assert_array_equal(m.predict(tr, horizon=7), free)
    np.testing.assert_array_equal(m.compare(tr).simulated, free)
    e = m.residuals(tr)
    assert e.shape == (len(u), 1)
    np.testing.assert_array_equal(e, y.reshape(-1, 1) - free)
    assert 0.8 * NOISE[family] < np.sqrt(np.mean(e ** 2)) < 1.4 * NOISE[family]
    arrays = (m.predict(u, y), m.residuals(u, y))
    want = (len(u), 1) if family == "nlss" else (len(u),)
    assert arrays[0].shape == arrays[1].shape == want
    np.testing.assert_array_equal(arrays[0].reshape(-1, 1), free)
    with pytest.raises(ArgumentError, match="horizon: expected a whole number of samples ≥ 1"):
        m.predict(tr, horizon=0)
    for name in ("predict", "residuals"):
        with pytest.raises(ArgumentError, match=f"{m.structure}.{name}: the record has no "
                                                "measured output"):
            getattr(m, name)(u)


NAMED = {"narx": "a NARX model", "rational narx": "a rational NARX model",
         "hw": "a Hammerstein–Wiener model", "nlss": "a nonlinear state-space model",
         "bouc-wen": "a Bouc-Wen hysteresis model", "prandtl-ishlinskii":
         "a Prandtl–Ishlinskii model", "bouc-wen oscillator": "a Bouc-Wen oscillator model"}


@pytest.mark.parametrize("family", NONLINEAR)
def test_nonlinear_families_have_no_linear_system_to_convert(family):
    """to_ss, to_tf and to_control of every nonlinear family raise a ModelError naming the
    method and the family, with a hint where a linear view is."""
    m = FAMILIES[family][0]
    for name in ("to_ss", "to_tf", "to_control"):
        with pytest.raises(ModelError, match=f"{name}: {NAMED[family]} has no linear system to "
                                             "convert") as err:
            getattr(m, name)()
        assert err.value.hint and ("identify(data, 'arx'" in err.value.hint or family == "hw")


def test_hw_hint_gives_its_linear_block():
    """The hint of a Hammerstein–Wiener model's to_tf is true: TransferFunction.from_polynomials
    of its B and F is its linear block, gain B(1)/F(1) at z = 1."""
    m = FAMILIES["hw"][0]
    with pytest.raises(ModelError) as err:
        m.to_tf()
    assert "TransferFunction.from_polynomials([1.0], model.B, F=model.F" in err.value.hint
    g = TransferFunction.from_polynomials([1.0], m.B, F=m.F, dt=m.dt)
    assert float(g.dc_gain()[0, 0]) == pytest.approx(np.sum(m.B) / np.sum(m.F), rel=1e-12)


def test_v1_files_load_migrated():
    """Files written before the polynomial section (schema_version 1, gripkit 0.1.0 at commit
    0622ce5): an ARX/OE file comes back as a PolynomialModel with its coefficients, their σ (the
    covariance of the file's transfer function) and the one-step fit; its validation fit on the
    record is the one the version-1 reader gave (71.42703155216157 % and 23.793626275994704 %,
    computed at 0622ce5 with validation_fit); a state-space file is a LinearModel as before."""
    tr = load(V1 / "record.csv")
    for name, fit in (("arx_221", 71.42703155216157), ("oe_221", 23.793626275994704)):
        doc = json.loads((V1 / f"{name}.json").read_text())
        assert doc["schema_version"] == 1 and "polynomial" not in doc
        m = load_model(V1 / f"{name}.json")
        assert type(m) is PolynomialModel and m.structure == doc["structure"]
        np.testing.assert_array_equal(m.B, doc["info"]["B"])
        np.testing.assert_array_equal(m.covariance, doc["system"]["uncertainty"]["covariance"])
        assert m.fit_percent == doc["info"]["one_step_fit_percent"] and m.loss is None
        assert (m.u_offset, m.y_offset) == (doc["inputs"][0]["offset"], doc["outputs"][0]["offset"])
        assert (m.input_name, m.output_unit, m.dt) == ("current", "N", 0.01)
        assert m.compare(tr).fit_percent == [fit]
    m = load_model(V1 / "arx_221.json")
    np.testing.assert_allclose(m.A_std[1:], np.sqrt(np.diag(m.covariance))[:2], rtol=0)
    s = load_model(V1 / "n4sid_2x2.json")
    assert type(s) is LinearModel and s.inputs == ("current", "voltage") and s.order == 2


def test_arx_prediction_horizons_against_the_difference_equation():
    """ARX [2 2 1] known coefficients, noise-free data: ŷ(t|t−1) is the measured output (the
    predictor is exact after na samples), and ŷ(t|t−2) equals the recursion that replaces y(t−1)
    by its own one-step prediction."""
    a1, a2, b1, b2 = -1.2, 0.5, 0.8, 0.3
    m = PolynomialModel.from_coefficients([1.0, a1, a2], [0.0, b1, b2], dt=0.01)
    rng = np.random.default_rng(4)
    u = rng.standard_normal(400)
    y = np.zeros(400)
    for t in range(2, 400):
        y[t] = -a1 * y[t - 1] - a2 * y[t - 2] + b1 * u[t - 1] + b2 * u[t - 2]
    np.testing.assert_allclose(m.predict(u, y)[2:], y[2:], atol=1e-12)
    y1 = -a1 * y[1:-2] - a2 * y[:-3] + b1 * u[1:-2] + b2 * u[:-3]            # ŷ(t−1|t−2), t ≥ 3
    ref = -a1 * y1 - a2 * y[1:-2] + b1 * u[2:-1] + b2 * u[1:-2]             # ŷ(t|t−2)
    np.testing.assert_allclose(m.predict(u, y, horizon=2)[3:], ref, atol=1e-9)
    assert np.max(np.abs(m.residuals(u, y))) < 1e-12
    with pytest.raises(ArgumentError, match="horizon: expected a whole number"):
        m.predict(u, y, horizon=0)


def test_state_space_prediction_with_k_zero_is_the_free_run():
    """An output-error model (K = None) predicts by its free run for every horizon: predict(h)
    equals compare's simulated output (the same least-squares x0)."""
    m, _, U, Y = FAMILIES["n4sid"]
    oe_model = m.replace(K=None)
    tr = _record(oe_model, U, Y)
    free = oe_model.compare(tr).simulated
    for h in (1, 5):
        np.testing.assert_allclose(oe_model.predict(tr, horizon=h), free, rtol=1e-9, atol=1e-9)


V2 = Path(__file__).parent / "data" / "model_v2"


def test_v2_mimo_arx_file_written_as_a_linear_model_loads_as_the_polynomial_model():
    """A MIMO ARX file written before arx returned one type (schema_version 2, gripkit at commit
    ebed4b9, `identify(record, "arx", input=["a", "b"], output=["c", "d"], na=2, nb=1, nk=1)`):
    a state-space LinearModel with the matrix polynomials in ``info``. It loads as the
    PolynomialModel: A, B and their σ are the file's A_poly, B_poly and their σ, the covariance of
    θ the system's, and its validation fit on the record is the one ebed4b9 computed
    ([6.293701151614794, 69.16946622509013] %, free run, x0 by least squares)."""
    doc = json.loads((V2 / "arx_mimo_212.json").read_text())
    assert doc["schema_version"] == 2 and "polynomial" not in doc and doc["kind"] == "ss"
    m = load_model(V2 / "arx_mimo_212.json")
    assert type(m) is PolynomialModel and m.structure == "arx" and m.orders == (2, 1, 1)
    assert m.inputs == ("a", "b") and m.outputs == ("c", "d") and m.dt == 0.01
    np.testing.assert_array_equal(m.A[0], np.eye(2))
    np.testing.assert_array_equal(m.A[1:], doc["info"]["A_poly"])
    np.testing.assert_array_equal(m.B[0], np.zeros((2, 2)))
    np.testing.assert_array_equal(m.B[1:], doc["info"]["B_poly"])
    np.testing.assert_allclose(m.A_std[1:], doc["info"]["A_poly_std"], rtol=1e-12, atol=0)
    np.testing.assert_allclose(m.B_std[1:], doc["info"]["B_poly_std"], rtol=1e-12, atol=0)
    np.testing.assert_array_equal(m.covariance, doc["system"]["uncertainty"]["covariance"])
    np.testing.assert_array_equal(m.noise_covariance, doc["innovation"]["noise_covariance"])
    assert m.fit_percent == doc["info"]["one_step_fit_percent"]
    assert m.info["free_run_fit_percent"] == doc["fit_percent"]
    assert m.u_offset == tuple(d["offset"] for d in doc["inputs"])
    tr = load(V2 / "record.csv")
    assert m.compare(tr).fit_percent == [6.293701151614794, 69.16946622509013]


def _mimo_arx_record(n=300, seed=5):
    """Noise-free data of a known 2-output, 2-input ARX [2 2 1]: y(t) = −A1 y(t−1) − A2 y(t−2)
    + B1 u(t−1) + B2 u(t−2)."""
    A1 = np.array([[-0.9, 0.2], [0.1, -0.5]])
    A2 = np.array([[0.2, 0.0], [-0.05, 0.1]])
    B1 = np.array([[1.0, 0.3], [0.0, -0.7]])
    B2 = np.array([[0.4, 0.0], [0.2, 0.1]])
    rng = np.random.default_rng(seed)
    u = rng.standard_normal((n, 2))
    y = np.zeros((n, 2))
    for t in range(2, n):
        y[t] = -A1 @ y[t - 1] - A2 @ y[t - 2] + B1 @ u[t - 1] + B2 @ u[t - 2]
    A = np.stack([np.eye(2), A1, A2])
    B = np.stack([np.zeros((2, 2)), B1, B2])
    return A, B, u, y


def test_mimo_arx_one_step_prediction_is_exact():
    """Known matrix polynomials on noise-free data: ŷ(t|t−1) is the measured output from sample
    start = 2 on (the exact ARX predictor, rounding only), the residuals vanish, the model fitted
    to the same data recovers A and B, and ŷ(t|t−2) is the recursion that replaces y(t−1) by its
    one-step prediction."""
    A, B, u, y = _mimo_arx_record()
    m = PolynomialModel(A, B, 1, dt=0.01)
    assert m.multivariable and (m.n_inputs, m.n_outputs, m.start) == (2, 2, 2)
    yh = m.predict(u, y)
    np.testing.assert_array_equal(yh[:2], y[:2])
    np.testing.assert_allclose(yh[2:], y[2:], rtol=0, atol=1e-12)
    assert np.max(np.abs(m.residuals(u, y))) < 1e-12 and m.residuals(u, y).shape == (298, 2)
    fit = arx(u, y, 2, 2, 1, dt=0.01)
    np.testing.assert_allclose(fit.A, A, atol=1e-10)
    np.testing.assert_allclose(fit.B, B, atol=1e-10)
    y1 = -y[1:-2] @ A[1].T - y[:-3] @ A[2].T + u[1:-2] @ B[1].T + u[:-3] @ B[2].T  # ŷ(t−1|t−2)
    ref = -y1 @ A[1].T - y[1:-2] @ A[2].T + u[2:-1] @ B[1].T + u[1:-2] @ B[2].T     # ŷ(t|t−2)
    np.testing.assert_allclose(m.predict(u, y, horizon=2)[3:], ref, atol=1e-9)


def test_mimo_arx_aic_and_names():
    """AIC of a MIMO ARX is M ln det(2π Λ̂) + M p + 2 d with Λ̂ = EᵀE/M of its residuals (the
    Gaussian likelihood; MATLAB's aic); arx keeps the channel names, units and offsets given in
    either spelling (input_name=… or inputs=…), refuses both at once, and a SISO arx takes
    inputs=["a"] as input_name="a"."""
    g = two_by_two()
    U, Y = oe_data(g, 1000, 0.05, seed=2)
    m = arx(U, Y, 2, 2, 1, dt=0.01, inputs=["a", "b"], output_name=("c", "d"),
            input_units=["V", "V"], output_units=["N", "m"], y_offset=(1.0, 2.0))
    E = m.estimation_residuals
    M, d = E.shape[0], m.n_params
    assert (M, d) == (998, 16) and m.n_used == M
    ref = M * np.log(np.linalg.det(2 * np.pi * E.T @ E / M)) + M * 2 + 2 * d
    assert m.aic == pytest.approx(ref, rel=1e-12)
    assert (m.inputs, m.outputs, m.y_offset) == (("a", "b"), ("c", "d"), (1.0, 2.0))
    assert m.parameters["b1_1_0"].unit == "m/V" and m.parameters["a2_0_1"].unit == "1"
    with pytest.raises(ArgumentError, match="inputs= and input_name= name the same channels"):
        arx(U, Y, 1, 1, 1, inputs=["a", "b"], input_name=("a", "b"))
    u, y = _siso(300)
    s = arx(u, y, 2, 2, 1, inputs=["current"], outputs=["force"], input_units=["A"])
    assert (s.input_name, s.output_name, s.input_unit) == ("current", "force", "A")
    np.testing.assert_array_equal(s.A, arx(u, y, 2, 2, 1).A)


#: the linear families of continuous time (tfest, step response): their arrays need dt=
CONTINUOUS = ("tfest", "step")


@pytest.mark.parametrize("family", list(FAMILIES))
def test_sysid_compare_on_arrays_is_model_compare_on_the_record(family):
    """The protocol's arrays are the record's values for every family: a linear model removes
    its offsets from them as from a trajectory (NLSS's u_offset/y_offset normalise inside it).
    On a record's columns sysid.compare(m, u, y) gives the fit and free run of
    m.compare(record), to the rounding of the offsets added and removed (bit for bit for the
    nonlinear families); the arrays of a continuous model need dt= (else an ArgumentError says
    so). The deviations from the offsets are not those values: the ARX model (u_offset 0.5,
    y_offset 1.0) fits 58.7 % on them against 99.0 % (the fit of issue 2 on its record)."""
    m, _, u, y = FAMILIES[family]
    record = _record(m, u, y)
    want = m.compare(record)
    if family not in NONLINEAR:  # the record's columns: the deviations plus the offsets
        u = np.column_stack([record[n] for n in m.inputs])
        y = np.column_stack([record[n] for n in m.outputs])
    timed = {}
    if family in CONTINUOUS:
        with pytest.raises(ArgumentError, match="the model is continuous and the arrays carry no "
                                                "sample time"):
            compare(m, u, y)
        timed = {"dt": m.dt or 0.01}
    got = compare(m, u, y, **timed)
    assert isinstance(got, ModelFit) and got.definition == want.definition
    if family in NONLINEAR:
        assert got.fit_percent == want.fit_percent
        np.testing.assert_array_equal(got.simulated, want.simulated)
        return
    np.testing.assert_allclose(got.fit_percent, want.fit_percent, rtol=1e-12)
    np.testing.assert_allclose(got.simulated, want.simulated, rtol=1e-12, atol=1e-12)
    if family == "arx siso":
        assert want.fit_percent[0] == pytest.approx(99.0, abs=0.05)
        yd = y[:, 0] - m.y_offset
        dev = compare(m, u - m.u_offset, yd)
        ref = 100 * (1 - np.linalg.norm(yd - dev.simulated[:, 0]) / np.linalg.norm(yd - yd.mean()))
        assert dev.fit_percent[0] == pytest.approx(ref, rel=1e-12)
        assert dev.fit_percent[0] < want.fit_percent[0] - 30.0


def test_every_family_simulates_with_x0_none():
    """simulate(data, x0=None) is every family's free run of simulate(data)."""
    for family, (m, _, u, y) in FAMILIES.items():
        assert inspect.signature(m.simulate).parameters["x0"].default is None, family
    m, _, u, y = FAMILIES["bouc-wen oscillator"]
    tr = _record(m, u, y)
    np.testing.assert_array_equal(m.simulate(tr, x0=None), m.simulate(tr))


#: what the free run of a family without a settable initial state starts from
STARTS = {"hw": "the steady state of its linear block under the constant input initial_input",
          "bouc-wen": "the relaxed state h = 0 at the first input sample",
          "prandtl-ishlinskii": "every play relaxed at the first input sample"}


@pytest.mark.parametrize("family", list(STARTS))
def test_families_without_an_initial_state_refuse_x0(family):
    """Hammerstein–Wiener and the rate-independent hysteresis models have no settable initial
    state: x0=None is their free run, a given x0 an ArgumentError naming the family and what the
    run starts from, with a hint."""
    m, _, u, y = FAMILIES[family]
    tr = _record(m, u, y)
    np.testing.assert_array_equal(m.simulate(tr, x0=None), m.simulate(tr))
    head = (f"{m.structure}.simulate: x0: {NAMED[family]} has no settable initial state; its "
            f"free run starts from {STARTS[family]}")
    with pytest.raises(ArgumentError, match=re.escape(head)) as err:
        m.simulate(tr, x0=np.zeros(2))
    assert err.value.hint


def test_narx_x0_is_its_first_outputs():
    """NARX's initial state is its first max_lag outputs: simulate(u, x0=y[:2]) is the free run
    compare scores (from the measured outputs), y0= (its older name) gives the same run, and
    both at once are refused."""
    m, _, u, y = FAMILIES["narx"]
    first = y[:m.max_lag]
    run = m.simulate(u, x0=first)
    np.testing.assert_array_equal(run, m.compare(u, y).simulated[:, 0])
    np.testing.assert_array_equal(m.simulate(u, y0=first), run)
    assert not np.array_equal(m.simulate(u), run)
    with pytest.raises(ArgumentError, match="narx.simulate: x0 and y0 both given"):
        m.simulate(u, x0=first, y0=first)


@pytest.mark.parametrize("family", ["narx", "hw", "nlss", "bouc-wen"])
def test_validate_refuses_a_nonlinear_model(family):
    """sysid.validate is the residual-test report of a linear model: a nonlinear one is refused
    with a ModelError naming the family and pointing to compare and residuals; sysid.compare
    takes its own sample time as dt (it runs on its samples) and refuses another with the
    linear models' DataError; the rate-independent Bouc-Wen actuator form takes any."""
    m, _, u, y = FAMILIES[family]
    with pytest.raises(ModelError, match=f"validate: {NAMED[family]} is not a linear model; "
                                         "validate is the residual-test report") as err:
        validate(m, u, y)
    assert "model.compare(data)" in err.value.hint and "model.residuals(data)" in err.value.hint
    assert m.dt is not None
    assert compare(m, u, y, dt=m.dt).fit_percent == compare(m, u, y).fit_percent
    if family == "bouc-wen":
        assert compare(m, u, y, dt=2 * m.dt).fit_percent == compare(m, u, y).fit_percent
        return
    with pytest.raises(DataError, match=f"data: sampled every {2 * m.dt:g} s, the model every "
                                        f"{m.dt:g} s"):
        compare(m, u, y, dt=2 * m.dt)


def test_state_space_model_validates_as_sysid_validate():
    """LinearModel.validate is sysid.validate: a SISO state-space model of the ARX [2 2 1] record
    reports the fit of compare and the residual tests of its one-step errors."""
    u, y = _siso(800)
    m = n4sid(u[:400], y[:400], 2, dt=0.01)
    assert type(m) is LinearModel
    v = m.validate(u[400:], y[400:])
    assert v.to_dict() == validate(m, u[400:], y[400:]).to_dict()
    assert v.fit_percent == m.compare(u[400:], y[400:]).fit_percent[0] > 95.0
    np.testing.assert_array_equal(v.residuals, m.residuals(u[400:], y[400:])[:, 0])
