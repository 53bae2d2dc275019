"""Hammerstein–Wiener models around a state-space linear block (issue 26, family 2,
``linear='ss'``): the numba free run and its exact Jacobian, recovery of a known Wiener system whose
linear block is given in state space (parameters, poles and frequency response within 3σ, the
validation fit at the noise limit), the same fit as the B/F block on a system both represent,
save/load, the CLI, and bad input."""

import dataclasses
import importlib
import json

import numpy as np
import pytest
from scipy.signal import lfilter, ss2tf

from gripkit.errors import ArgumentError, DataWarning, ModelError
from gripkit.sysid import HWModel, hammerstein_wiener, load_hw, load_model
from test_hammerstein_wiener import assert_jacobian_matches_central_differences

HW = importlib.import_module("gripkit.sysid.nonlinear.hammerstein_wiener")

#: the Wiener system's linear block, in modal (not canonical) form: poles 0.75 ± 0.35j and 0.3
A_TRUE = np.array([[0.75, 0.35, 0.0], [-0.35, 0.75, 0.0], [0.0, 0.0, 0.3]])
B_TRUE = np.array([0.4, 0.3, 0.6])
C_TRUE = np.array([0.8, 0.0, 0.5])
#: its output nonlinearity x + 0.2 x² − 0.1 x³ and the offset
C2, C3, Y0 = 0.2, -0.1, 0.1


def _true_canonical():
    """The observer canonical a (coefficients of det(zI − A)) and b of the true block (its
    transfer function: ss2tf)."""
    num, den = ss2tf(A_TRUE, B_TRUE[:, None], C_TRUE[None, :], [[0.0]])
    return den[1:], num[0][1:]


def wiener_ss(rng, n=800, noise=0.05):
    """u ~ U(−1.5, 1.5) through the state-space block (at rest at t = 0), then the cubic; white
    noise σ_e on the output. Returns u, y and the noise-free y."""
    u = rng.uniform(-1.5, 1.5, n)
    x, v = np.zeros(3), np.empty(n)
    for t in range(n):
        v[t] = C_TRUE @ x
        x = A_TRUE @ x + B_TRUE * u[t]
    y0 = v + C2 * v**2 + C3 * v**3 + Y0
    return u, y0 + noise * rng.normal(size=n), y0


def hammerstein_sat(rng, n=800, noise=0.05):
    """The saturation [−1, 0.8] then (0.5 q⁻¹ + 0.3 q⁻²)/(1 − 1.2 q⁻¹ + 0.5 q⁻²): a block both
    an order-2 state-space block (nk = 1) and B/F with nb = nf = 2, nk = 1 represent."""
    u = rng.uniform(-2.0, 2.0, n)
    y = lfilter([0.0, 0.5, 0.3], [1.0, -1.2, 0.5], np.clip(u, -1.0, 0.8)) + 0.3
    return u, y + noise * rng.normal(size=n)


@pytest.mark.parametrize("nk", [0, 1, 3])
def test_state_space_free_run_jacobian_is_exact_and_equals_bf(nk):
    """ss_run's forward sensitivities ∂ŷ/∂[θ, w₋] equal central differences of its free run, and
    the run equals the B/F kernel's on the same transfer function (model.B, model.F) from the same
    steady state."""
    rng = np.random.default_rng(4)
    u = rng.uniform(-2.0, 2.0, 300)
    fin = HW.parse_nonlinearity("saturation")
    fout = HW._with_consts(HW.parse_nonlinearity("sigmoid:2"), np.linspace(-1.5, 1.5, 50))
    lin = [-1.2, 0.6, -0.1, 0.4, 0.2, -0.1] + [0.3] * (nk == 0)
    the = np.r_[-1.1, 0.9, lin, 0.2, -0.1, 0.1, 0.7]
    prob = HW._SSProblem(u, fin, fout, 3, nk)
    assert_jacobian_matches_central_differences(prob, the)
    P = len(the) - 1
    m = HWModel(fin, fout, 3, 3, nk, the[:P], np.zeros(P), np.zeros((P, P)), linear="ss")
    B, F = m.B, m.F
    oe = HW._Problem(u, fin, fout, len(B) - nk, 3, nk)
    oe.run(np.r_[-1.1, 0.9, B[nk:], F[1:], 0.2, -0.1, 0.1, 0.7], False)
    prob.run(the, False)
    np.testing.assert_allclose(prob.yhat, oe.yhat, rtol=0, atol=1e-12)
    A, b, C, d = m.state_space                   # the realisation's transfer function is B/F
    num, den = ss2tf(A, b, C, d)
    np.testing.assert_allclose(den, F, atol=1e-12)
    np.testing.assert_allclose(num[0], B[:4] if nk == 0 else np.r_[0.0, B[nk:]], atol=1e-12)


def _frequency_response(a, b, w):
    """G(e^{jw}) = Σ b_k e^{−jwk} / (1 + Σ a_k e^{−jwk}) and its gradient to [a, b]."""
    e = np.exp(-1j * w * np.arange(1, len(a) + 1))
    F = 1.0 + a @ e
    G = (b @ e) / F
    return G, np.r_[-G * e / F, e / F]


def test_wiener_with_a_state_space_block_recovered_within_3_sigma():
    """The Wiener system above (order 3, given in modal form), 10 seeded noisy records (N = 800,
    σ_e = 0.05) fitted with linear='ss', order=3, nk=1: every true parameter (a, b of the
    observer canonical form from ss2tf, c2, c3, y0) within 3σ of its estimate in ≥ 90 % of the
    (run, parameter) pairs (measured: 89 of 90); on every run the three poles (Re and Im) and
    |G(e^{jw})| at w = 0.1, 0.5, 1, 2 rad/sample within 3σ (delta method from the covariance of
    a, b); the validation free-run fit within 0.3 points of the noise limit (the fit of the
    noise-free output itself)."""
    a_true, b_true = _true_canonical()
    true = np.r_[a_true, b_true, C2, C3, Y0]
    poles_true = np.sort_complex(np.linalg.eigvals(A_TRUE))
    uv, yv, yv_clean = wiener_ss(np.random.default_rng(99), n=500)
    limit = 100.0 * (1.0 - np.linalg.norm(yv - yv_clean) / np.linalg.norm(yv - yv.mean()))
    inside = total = 0
    for seed in range(10):
        u, y, _ = wiener_ss(np.random.default_rng(100 + seed))
        m = hammerstein_wiener(u, y, output_nonlinearity="poly:3", linear="ss", order=3, nk=1)
        assert m.names == ["a1", "a2", "a3", "b1", "b2", "b3", "out_c2", "out_c3", "y0"]
        assert m.linear == "ss" and m.order == 3
        inside += int(np.sum(np.abs(m.theta - true) < 3.0 * m.theta_std))
        total += len(true)
        a, b, cov = m.theta[:3], m.theta[3:6], m.covariance[:6, :6]
        z = np.sort_complex(m.poles)
        assert np.max(np.abs(z)) < 1.0
        for zi in z:   # ∂z/∂a_k = −z^(n−k) / p'(z), p(z) = z³ + a1 z² + a2 z + a3
            gz = np.r_[-zi ** np.arange(2, -1, -1) / np.polyval(np.polyder(np.r_[1.0, a]), zi),
                       np.zeros(3)]
            zt = poles_true[np.argmin(np.abs(poles_true - zi))]
            for part in (np.real, np.imag):
                sd = np.sqrt(part(gz) @ cov @ part(gz))
                assert abs(part(zi) - part(zt)) <= 3.0 * sd + 1e-12, (seed, zi, zt, sd)
        for w in (0.1, 0.5, 1.0, 2.0):
            G, dG = _frequency_response(a, b, w)
            Gt, _ = _frequency_response(a_true, b_true, w)
            g = np.real(np.conj(G) * dG) / abs(G)
            assert abs(abs(G) - abs(Gt)) < 3.0 * np.sqrt(g @ cov @ g), (seed, w)
        fit = m.compare(uv, yv).fit_percent[0]
        assert limit - 0.3 < fit < limit + 0.3, (seed, fit, limit)
    assert inside >= 0.9 * total, (inside, total)


def test_order_and_delay_of_the_state_space_block_chosen():
    """order and nk not given: the free-run fit on a validation record chooses order 3 and
    nk = 1, the true ones, and its fit is within 0.3 points of the noise limit."""
    u, y, _ = wiener_ss(np.random.default_rng(1))
    uv, yv, yv_clean = wiener_ss(np.random.default_rng(2), n=500)
    limit = 100.0 * (1.0 - np.linalg.norm(yv - yv_clean) / np.linalg.norm(yv - yv.mean()))
    m = hammerstein_wiener(u, y, output_nonlinearity="poly:3", linear="ss", validate=(uv, yv))
    assert (m.order, m.nk) == (3, 1)
    assert m.criterion.startswith("state-space order 3, nk = 1 by validation free-run fit")
    assert all(c["linear"] == "ss" and "nb" not in c for c in m.candidates)
    assert abs(m.validation_fit_percent - limit) < 0.3


@pytest.mark.parametrize("nk, nb", [(1, 2), (0, 3)])
def test_state_space_and_bf_blocks_give_the_same_fit(nk, nb):
    """A Hammerstein system (saturation, second-order block) fitted with linear='ss' order 2
    and with B/F of the same transfer functions (nf = 2, nb = 2 for nk = 1, nb = 3 with the
    feedthrough for nk = 0): the same estimation and validation fits (within 0.01 points, far
    inside the noise) and the same transfer function (B and F within 0.05σ of B/F's)."""
    u, y = hammerstein_sat(np.random.default_rng(7))
    uv, yv = hammerstein_sat(np.random.default_rng(8), n=400)
    ss = hammerstein_wiener(u, y, input_nonlinearity="saturation", linear="ss", order=2, nk=nk)
    oe = hammerstein_wiener(u, y, input_nonlinearity="saturation", nb=nb, nf=2, nk=nk)
    assert ss.fit_percent > 90.0
    assert abs(ss.fit_percent - oe.fit_percent) < 0.01
    assert abs(ss.compare(uv, yv).fit_percent[0] - oe.compare(uv, yv).fit_percent[0]) < 0.01
    tf = np.r_[ss.B[nk:], ss.F[1:]]
    np.testing.assert_array_less(np.abs(tf - np.r_[oe.B[nk:], oe.F[1:]]),
                                 0.05 * oe.theta_std[2:2 + nb + 2])
    np.testing.assert_allclose(ss.theta[:2], oe.theta[:2], atol=0.05 * oe.theta_std[:2].max())


def test_state_space_model_save_load_round_trip(tmp_path):
    """Save then load: the same type with every field equal (θ, σ, covariance, linear, order,
    candidates, initial state, fits), the same compare number; the file is schema_version 2
    (a reader of version 1 alone refuses it); a B/F model file as written before the
    state-space block (version 1, no linear, candidates or initial_input) still loads."""
    from gripkit import Trajectory

    u, y, _ = wiener_ss(np.random.default_rng(5), n=600)
    uv, yv, _ = wiener_ss(np.random.default_rng(6), n=300)
    m = hammerstein_wiener(u, y, output_nonlinearity="poly:2", linear="ss", order=2,
                           validate=(uv, yv), dt=0.01)
    m.input_name, m.output_name = "valve", "force"
    path = m.save(tmp_path / "hw.json")
    doc = json.loads(path.read_text())
    assert doc["schema_version"] == 2 and doc["linear"] == "ss" and doc["order"] == 2
    m2 = load_model(path)
    assert type(m2) is HWModel
    for f in dataclasses.fields(HWModel):
        a, b = getattr(m, f.name), getattr(m2, f.name)
        if isinstance(a, np.ndarray):
            np.testing.assert_array_equal(a, b)
        elif f.name == "y_range":
            assert tuple(a) == tuple(b)
        else:
            assert a == b, f.name
    tr = Trajectory.uniform(dt=0.01, valve=uv, force=yv)
    assert m2.compare(tr).fit_percent[0] == m.compare(tr).fit_percent[0]
    assert m2.compare(tr).fit_percent[0] == pytest.approx(m.validation_fit_percent, abs=1e-9)
    assert m2.parameters["a1"].std == m.theta_std[0]
    with pytest.raises(ModelError, match="of schema_version 2; this gripkit reads "
                                         "schema_version 1;"):   # a reader of the B/F files
        HW.read_family_document(path, HW.SCHEMA, 1, family="hw", writer="HWModel.save",
                                version_key="schema_version")
    (tmp_path / "v3.json").write_text(json.dumps({**doc, "schema_version": 3}))
    with pytest.raises(ModelError, match="this gripkit reads schema_version 1 or 2"):
        load_hw(tmp_path / "v3.json")
    doc.pop("linear")
    (tmp_path / "bad.json").write_text(json.dumps(doc))
    with (pytest.warns(DataWarning, match="content differs from what gripkit wrote"),
          pytest.raises(ModelError, match="a malformed gripkit.hw-model")):
        load_hw(tmp_path / "bad.json")
    old = hammerstein_wiener(u, y, output_nonlinearity="poly:2", nb=2, nf=2, nk=1)
    doc = json.loads(old.save(tmp_path / "oe.json").read_text())
    assert doc["schema_version"] == 1 and "linear" not in doc
    for key in ("candidates", "initial_input", "content_sha256"):  # none in an old file
        doc.pop(key)
    (tmp_path / "old.json").write_text(json.dumps(doc))
    m3 = load_hw(tmp_path / "old.json")
    assert m3.linear == "oe" and m3.names == old.names
    np.testing.assert_array_equal(m3.simulate(uv), old.simulate(uv))


def _cli(capsys, *args):
    from gripkit.cli import main

    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_identify_hw_linear_ss(tmp_path, capsys):
    """``gripkit identify hw … --linear ss --order 3 --nk 1 --json``: fit_percent,
    validation.fit_percent equal to the Python call's, every parameter with a finite σ and the
    truth within 4σ; ``compare`` and ``report`` on the saved model give the validation number
    again."""
    u, y, _ = wiener_ss(np.random.default_rng(30))
    uv, yv, _ = wiener_ss(np.random.default_rng(31), n=400)
    est, val, model = tmp_path / "est.csv", tmp_path / "val.csv", tmp_path / "hw.json"
    for path, (a, b) in ((est, (u, y)), (val, (uv, yv))):
        np.savetxt(path, np.column_stack([a, b]), delimiter=",", header="valve,force",
                   comments="", fmt="%.12g")
    code, out, err = _cli(capsys, "identify", "hw", est, "--input", "valve", "--output", "force",
                          "--fs", 100, "--output-nonlinearity", "poly:3", "--linear", "ss",
                          "--order", 3, "--nk", 1, "--validate", val, "--out", model, "--json")
    assert code == 0, err
    d = json.loads(out)
    assert d["structure"]["linear"] == "ss" and d["structure"]["order"] == 3
    a_true, b_true = _true_canonical()
    true = np.r_[a_true, b_true, C2, C3, Y0]
    assert [p["name"] for p in d["parameters"]] == ["a1", "a2", "a3", "b1", "b2", "b3", "out_c2",
                                                    "out_c3", "y0"]
    for p, t in zip(d["parameters"], true):
        assert 0.0 < p["std"] < np.inf and abs(p["value"] - t) < 4.0 * p["std"]
    py = hammerstein_wiener(u, y, output_nonlinearity="poly:3", linear="ss", order=3, nk=1,
                            validate=(uv, yv))
    assert d["fit_percent"] == pytest.approx(py.fit_percent, abs=1e-6)
    assert d["validation"]["fit_percent"] == pytest.approx(py.validation_fit_percent, abs=1e-6)
    for cmd in (("compare", model, val), ("report", model, val, "--out", tmp_path / "rep")):
        code, out, err = _cli(capsys, *cmd, "--fs", 100, "--json")
        assert code == 0, err
        assert json.loads(out)["fit_percent"][0] == pytest.approx(
            d["validation"]["fit_percent"], abs=1e-6)


@pytest.mark.parametrize("args, phrase", [
    (("--linear", "arx"), "--linear must be 'oe' (the output-error block B/F) or 'ss'"),
    (("--linear", "ss", "--order", 0), "--order must be an integer from 1 to 20, found 0"),
    (("--order", 2), "--order 2 is the state dimension of the state-space block"),
    (("--linear", "ss", "--nb", 2), "--nb/--nf (found 2/None) are the orders of the output-error"),
])
def test_cli_bad_linear_block_is_one_line(tmp_path, capsys, args, phrase):
    est = tmp_path / "est.csv"
    np.savetxt(est, np.column_stack([np.arange(50.0), np.arange(50.0) ** 0.5]), delimiter=",",
               header="valve,force", comments="", fmt="%.12g")
    code, out, err = _cli(capsys, "identify", "hw", est, "--input", "valve", "--output", "force",
                          *args)
    assert code != 0 and out == ""
    assert err.startswith("error: ArgumentError: hammerstein_wiener: " + phrase), err
    assert err.strip().count("\n") == 0


def test_python_bad_linear_block():
    u, y = hammerstein_sat(np.random.default_rng(1), n=300)
    with pytest.raises(ArgumentError, match="linear must be 'oe'"):
        hammerstein_wiener(u, y, linear="state-space")
    with pytest.raises(ArgumentError, match="order must be an integer from 1 to 20, found 0"):
        hammerstein_wiener(u, y, linear="ss", order=0)
    with pytest.raises(ArgumentError, match="order 3 is the state dimension"):
        hammerstein_wiener(u, y, order=3)
    with pytest.raises(ArgumentError, match="with linear ss give order"):
        hammerstein_wiener(u, y, linear="ss", nf=2)


@pytest.mark.parametrize("nk", [0, 2])
def test_state_functions_of_a_state_space_model_run_as_simulate(nk):
    """The estimation filters' state functions of an ss model (built from its transfer function
    B/F) give the model's own free run from rest (``simulate(initial_input=0)``)."""
    from gripkit.estimation.state_functions import state_functions

    lin = [-1.2, 0.6, -0.1, 0.4, 0.2, -0.1] + [0.3] * (nk == 0)
    theta = np.r_[-0.8, 0.8, lin, 0.1, -0.05, 0.3]
    P = len(theta)
    m = HWModel(HW.parse_nonlinearity("saturation"), HW.parse_nonlinearity("poly:3"), 3, 3, nk,
                theta, np.zeros(P), np.zeros((P, P)), linear="ss", y_range=(-10.0, 10.0))
    u = np.random.default_rng(2).uniform(-1.5, 1.5, 200)
    f, h, x, nx = state_functions(m)
    assert nx == 3 + max(nk - 1, 0)
    run = np.empty(len(u))
    for t, ut in enumerate(u):
        run[t] = h(x, np.array([ut]))[0]
        x = f(x, np.array([ut]))
    np.testing.assert_allclose(run, m.simulate(u, initial_input=0.0)[:, 0], rtol=0, atol=1e-12)
