"""Issue 23 (one identification path): ``identify(data, "step")`` returns the second-order step fit
of :func:`~gripkit.sysid.physical.step_response.identify_step` as a protocol model, a
:class:`~gripkit.sysid.LinearModel` holding G(s) = K ω_n²/(s² + 2ζω_n s + ω_n²).

The record: a known system (K = 2.5 mm/V, f_n = 3 Hz, ζ = 0.3) at rest at y₀ = 5 mm, its input
stepping from 0.2 V to 1.2 V at t = 0.1 s, sampled every 2 ms (zero-order hold: simulated by
scipy.signal.lsim with ``interp=False``), 1500 samples, white output noise σ = 0.01 mm (seed 0).
No measured record in tests/fixtures is a step response (cascaded tanks, CD player arm, DC
motor, EMPS, evaporator, flexible arm, silverbox: broadband or PRBS excitation), so the
provenance is this synthetic truth and scipy."""

import math

import numpy as np
import pytest
from scipy import signal

from gripkit import Trajectory
from gripkit.errors import ArgumentError, DataError
from gripkit.sysid import LinearModel, identify, load_model
from gripkit.sysid.identify import method_options
from gripkit.sysid.model_file import plain
from gripkit.sysid.physical.step_response import identify_step, step_summary

K, F_N, ZETA = 2.5, 3.0, 0.3
W_N = 2 * math.pi * F_N
U0, U1, Y0, DT, N, NOISE = 0.2, 1.2, 5.0, 0.002, 1500, 0.01


def step_record(zeta=ZETA, seed=0):
    """The step record of the module docstring (damping ``zeta``)."""
    t = np.arange(N) * DT
    u = np.where(t >= 0.1, U1, U0)
    _, y, _ = signal.lsim(([K * W_N ** 2], [1.0, 2 * zeta * W_N, W_N ** 2]), u - U0, t,
                          interp=False)
    y = Y0 + y + NOISE * np.random.default_rng(seed).standard_normal(N)
    return Trajectory.uniform(dt=DT, v=u, x=y, units={"v": "V", "x": "mm"})


@pytest.fixture(scope="module")
def fitted():
    tr = step_record()
    return tr, identify(tr, "step", inputs="v", outputs="x"), identify_step(tr, input="v",
                                                                              output="x")


def test_identify_step_recovers_the_truth_with_identify_steps_numbers(fitted):
    """K, f_n, ζ within 3σ of the truth; the model's info['step'] is identify_step's result
    (the same fit, compared with ==); offsets u₀ = 0.2 V (the record's start) and y₀ fitted."""
    tr, m, res = fitted
    assert isinstance(m, LinearModel) and m.structure == "step" and m.dt is None
    step = m.info["step"]
    assert step == plain(res.to_dict())
    for key, truth in (("gain", K), ("natural_frequency_hz", F_N), ("damping_ratio", ZETA)):
        assert abs(step[key] - truth) < 3 * step[key + "_std"], key
    assert abs(step["offset"] - Y0) < 3 * step["offset_std"]
    assert step["gain_unit"] == "mm/V"
    assert m.u_offset == (U0,) and m.y_offset == (res.offset,)
    assert m.inputs == ("v",) and m.outputs == ("x",)
    assert m.system.input_units == ("V",) and m.system.output_units == ("mm",)
    assert m.info["natural_frequency_hz"] == [res.natural_frequency_hz]
    assert m.info["damping_ratio_std"] == [res.damping_ratio_std]


def test_solver_trf_is_identify_steps_trf():
    tr = step_record(seed=1)
    m = identify(tr, "step", inputs="v", outputs="x", solver="trf")
    assert m.info["step"] == plain(identify_step(tr, input="v", output="x",
                                                 method="trf").to_dict())


def test_transfer_function_gives_gain_natural_frequency_and_damping(fitted):
    """to_tf(): DC gain K; poles p with |p| = ω_n and −Re p/|p| = ζ (1e-12 relative)."""
    _, m, res = fitted
    g = m.to_tf()
    assert g.dc_gain()[0, 0] == pytest.approx(res.gain, rel=1e-12)
    p = g.poles()
    assert p.size == 2
    np.testing.assert_allclose(np.abs(p), res.natural_frequency, rtol=1e-12)
    np.testing.assert_allclose(-p.real / np.abs(p), res.damping_ratio, rtol=1e-12)


def test_coefficient_covariance_is_the_propagated_step_covariance(fitted):
    """Cov of (den[1], den[2], num[2]) = (2ζω_n, ω_n², Kω_n²) is J Σ Jᵀ, J taken here by central
    differences of that map (Σ: identify_step's covariance of K, f_n, ζ with f_n → ω_n = 2πf_n);
    the model's parameters carry the square roots of its diagonal."""
    _, m, res = fitted
    x = np.array([res.gain, res.natural_frequency_hz, res.damping_ratio])

    def theta(v):
        k, f, z = v
        w = 2 * math.pi * f
        return np.array([2 * z * w, w * w, k * w * w])

    J = np.empty((3, 3))
    for j in range(3):
        h = 1e-6 * x[j]
        e = np.zeros(3)
        e[j] = h
        J[:, j] = (theta(x + e) - theta(x - e)) / (2 * h)
    want = J @ res.covariance[:3, :3] @ J.T
    unc = m.system.uncertainty
    assert unc.names == ("den[1]", "den[2]", "num[2]")
    np.testing.assert_allclose(unc.covariance, want, rtol=1e-6)
    params = m.parameters
    std = {p.name: p.std for p in params.values()}
    np.testing.assert_allclose([std["den_0_0_1"], std["den_0_0_2"], std["num_0_0_2"]],
                               np.sqrt(np.diag(want)), rtol=1e-6)


def _fit(y, yhat):
    return 100.0 * (1.0 - np.linalg.norm(y - yhat) / np.linalg.norm(y - y.mean()))


def test_free_run_from_rest_and_the_validation_fit_against_scipy(fitted):
    """simulate(tr) is the fitted G's zero-order-hold free run from rest plus the offsets
    (scipy.signal.lsim), and its fit is the step fit's; compare(tr) is the one validation fit:
    that free run from the initial state estimated by least squares (the discrete realisation's
    responses to unit initial states by scipy.signal.dlsim), at least the fit from rest."""
    tr, m, res = fitted
    u, y, t = np.asarray(tr["v"]), np.asarray(tr["x"]), tr.t
    num, den = [res.gain * res.natural_frequency ** 2], [1.0, 2 * res.damping_ratio
                                                           * res.natural_frequency,
                                                           res.natural_frequency ** 2]
    _, ylsim, _ = signal.lsim((num, den), u - u[0], t, interp=False)
    free = ylsim + res.offset
    np.testing.assert_allclose(m.simulate(tr)[:, 0], free, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(res.y_model, free, rtol=1e-9, atol=1e-9)
    assert _fit(y, free) == pytest.approx(res.fit_percent, abs=1e-9)
    A, B, C, D, _ = signal.cont2discrete(signal.tf2ss(num, den), DT, method="zoh")
    r = (y - res.offset) - signal.dlsim((A, B, C, D, DT), u - u[0])[1][:, 0]
    O = np.column_stack([signal.dlsim((A, B, C, D, DT), np.zeros(N), x0=e)[1][:, 0]
                         for e in np.eye(2)])
    x0 = np.linalg.lstsq(O, r, rcond=None)[0]
    want = _fit(y, free + O @ x0)
    got = m.compare(tr).fit_percent[0]
    assert got == pytest.approx(want, abs=1e-8)
    assert m.fit_percent == [got]
    assert res.fit_percent <= got < res.fit_percent + 0.01


def test_save_and_load_model_round_trip(fitted, tmp_path):
    tr, m, _ = fitted
    m.save(tmp_path / "step.json")
    back = load_model(tmp_path / "step.json")
    assert type(back) is LinearModel and back.structure == "step"
    assert back.info == m.info and back.u_offset == m.u_offset and back.y_offset == m.y_offset
    assert back.system.to_dict() == m.system.to_dict()
    np.testing.assert_array_equal(back.simulate(tr), m.simulate(tr))
    assert back.compare(tr).fit_percent == m.compare(tr).fit_percent


def test_overdamped_step_keeps_its_summary_through_the_model_file(tmp_path):
    """ζ = 1.5 has no peak (peak time inf, written as null): the text of the step fit rebuilt from
    the loaded model's info is identify_step's summary."""
    tr = step_record(zeta=1.5)
    m = identify(tr, "step", inputs="v", outputs="x")
    res = identify_step(tr, input="v", output="x")
    assert math.isinf(res.peak_time) and m.info["step"]["peak_time"] is None
    assert abs(res.damping_ratio - 1.5) < 3 * res.damping_ratio_std
    m.save(tmp_path / "od.json")
    back = load_model(tmp_path / "od.json")
    assert back.info == m.info
    assert step_summary(back.info["step"]) == res.summary()
    assert "peak inf s" in res.summary()


def test_step_options_and_bad_solver(fitted):
    tr = fitted[0]
    assert method_options("step") == ["solver", "multistart", "progress"]
    with pytest.raises(DataError, match="solver: expected one of lm, trf, found 'dogbox'"):
        identify(tr, "step", inputs="v", outputs="x", solver="dogbox")
    with pytest.raises(ArgumentError, match="unknown keyword 'poles'"):
        identify(tr, "step", inputs="v", outputs="x", poles=2)
    with pytest.raises(ArgumentError, match="several records"):
        identify([tr, tr], "step", inputs="v", outputs="x")
