"""Model analysis against reference implementations (scipy.signal, python-control)."""

import sys

import control
import numpy as np
import pytest
from scipy import signal

from gripkit import ModelError
from gripkit.sysid import PolynomialModel
from gripkit.systems.amadeus.force_dynamics import reference

M222 = reference("II", 2, 2, 2).model()  # Table II [2 2 2], 000_8f66dcc7ab06470c.txt
M442 = reference("II", 4, 4, 2).model()


@pytest.mark.parametrize("m", [M222, M442], ids=["222", "442"])
def test_poles_zeros_dcgain_match_python_control(m):
    """python-control's poles and zeros of the exported transfer function equal ours plus the
    delay's poles at the origin; DC gains agree."""
    g = m.to_control()
    pc = np.sort_complex(control.poles(g))
    ours = np.sort_complex(np.r_[m.poles(), np.zeros(g.den[0][0].size - 1 - m.na)])
    np.testing.assert_allclose(pc, ours, atol=1e-6)
    np.testing.assert_allclose(np.sort_complex(control.zeros(g)), np.sort_complex(m.zeros()),
                               atol=1e-6)
    assert float(np.real(control.dcgain(g))) == pytest.approx(m.dc_gain, rel=1e-9)
    assert g.dt == pytest.approx(0.005)


@pytest.mark.parametrize("m", [M222, M442], ids=["222", "442"])
def test_step_and_frequency_response_match_scipy(m):
    n = 200
    _, (ys,) = signal.dstep(m.to_scipy(), n=n)
    np.testing.assert_allclose(m.step(n), ys.ravel(), rtol=1e-9, atol=1e-12)
    f = np.array([0.5, 1.0, 5.0, 10.0, 50.0])
    _, h_ref = signal.freqz(m.B, m.A, worN=f, fs=200.0)
    w, h = m.frequency_response(2 * np.pi * f)                   # rad/s
    np.testing.assert_array_equal(w, 2 * np.pi * f)
    np.testing.assert_allclose(h, h_ref)
    # and with python-control's evaluation of the transfer function on the unit circle
    g = m.to_control()
    z = np.exp(1j * 2 * np.pi * f / 200.0)
    np.testing.assert_allclose(h, [complex(g(zz)) for zz in z], rtol=1e-9)


def test_step_settles_at_dc_gain_and_delay_is_two_samples():
    y = M222.step(2000)
    assert y[0] == y[1] == 0.0 and y[2] != 0.0  # nk = 2 (§V-C: two-sample valve delay)
    assert y[-1] == pytest.approx(M222.dc_gain, rel=1e-9)


def test_statespace_simulates_the_same_output():
    ss = M222.to_ss()
    Ad, Bd, Cd, Dd = ss.A, ss.B, ss.C, ss.D
    u = np.random.default_rng(0).standard_normal(300)
    x = np.zeros(Ad.shape[0])
    y = np.empty_like(u)
    for k, uk in enumerate(u):
        y[k] = (Cd @ x + Dd.ravel() * uk)[0]
        x = Ad @ x + Bd.ravel() * uk
    np.testing.assert_allclose(y, M222.simulate(u), atol=1e-9)


def test_simulate_with_given_past_continues_a_record():
    """Splitting a record and restarting from its past gives the uninterrupted output."""
    u = np.random.default_rng(1).standard_normal(400)
    full = M442.simulate(u)
    second = M442.simulate(u[150:], initial="given", y_past=full[:150], u_past=u[:150])
    np.testing.assert_allclose(second, full[150:], atol=1e-9)


def test_to_control_without_python_control(monkeypatch):
    monkeypatch.setitem(sys.modules, "control", None)
    with pytest.raises(ModelError, match="python-control.*not installed.*gripkit\\[interop\\]"):
        M222.to_control()


def test_bad_coefficients_are_refused():
    with pytest.raises(ModelError, match="A must start with 1"):
        PolynomialModel.from_coefficients([2.0, 1.0], [0.0, 1.0])
    with pytest.raises(ModelError, match="B must start with nk=2 zeros"):
        PolynomialModel([1.0], [1.0, 0.0, 1.0], 2)
    with pytest.raises(ModelError, match="non-finite"):
        PolynomialModel.from_coefficients([1.0, np.nan], [0.0, 1.0])
    with pytest.raises(ModelError, match="std\\['B'\\]"):
        PolynomialModel.from_coefficients([1.0, 0.5], [0.0, 1.0], std={"A": [0, 0.1], "B": [0.1]})


def test_parameters_carry_units_and_std():
    m = PolynomialModel.from_coefficients([1.0, -0.5], [0.0, 2.0], dt=0.01, input_unit="A",
                                          output_unit="N",
                                          std={"A": [0, 0.01], "B": [0, 0.2]})
    ps = m.parameters
    assert ps["a1"].unit == "1" and ps["b1"].unit == "N/A"
    assert ps["b1"].std == pytest.approx(0.2)
    d = m.to_dict()
    assert d["poles"] == [[0.5, 0.0]] and d["A_std"] == [0.0, 0.01]


def _arx_with_zero(b, noise, seed=0, n=4000):
    """ARX [1 2 1] fit of y = B/A u + e with A = 1 − 0.8 q⁻¹ and B = b (two coefficients)."""
    from gripkit.sysid import arx

    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = signal.lfilter([0.0, *b], [1.0, -0.8], u) + noise * rng.standard_normal(n)
    return arx(u, y, 1, 2, 1)


def test_zero_moduli_sigma_is_the_delta_method_of_the_b_covariance():
    """B = b1 z + b2 has the zero −b2/b1: |z| = |b2/b1|, σ² = (b2/b1²)² σ₁² + (1/b1)² σ₂²
    − 2 (b2/b1³) σ₁₂ (the gradient of |b2/b1| through the B block of the θ covariance), and a
    Monte Carlo draw of b from that covariance gives the same σ (small σ: the linear regime)."""
    m = _arx_with_zero([0.2, 0.5], noise=0.05)
    modulus, std = m.zero_moduli()
    b1, b2 = m.B[1], m.B[2]
    C = m.covariance[1:3, 1:3]
    g = np.array([-b2 / b1**2, 1.0 / b1]) * np.sign(b2 / b1)
    np.testing.assert_allclose(modulus, [abs(b2 / b1)], rtol=1e-12)
    np.testing.assert_allclose(std, [np.sqrt(g @ C @ g)], rtol=1e-9)
    draws = np.random.default_rng(1).multivariate_normal([b1, b2], C, size=20000)
    np.testing.assert_allclose(np.std(np.abs(draws[:, 1] / draws[:, 0])), std[0], rtol=0.05)


def test_phase_note_says_when_the_data_do_not_decide_minimum_phase():
    """A zero at −2.5 from B = [0.2, 0.5] with little noise lies many σ beyond the unit circle:
    NON-minimum phase. A leading coefficient of 0.002 buried in noise puts the zero at ≈ 250
    but with a σ of the same size: the note says the data do not decide (OE on the cascaded
    tanks printed 'NON-minimum phase' from b1 = −0.0012 ± 0.0046)."""
    assert _arx_with_zero([0.2, 0.5], noise=0.01).phase_note == "NON-minimum phase"
    m = _arx_with_zero([0.002, 0.5], noise=1.0, n=600)
    assert not m.minimum_phase
    assert m.phase_note.startswith("a zero outside the unit circle, |z| = ")
    assert "these data do not decide minimum phase" in m.phase_note
    assert "these data do not decide" in m.summary()
    assert _arx_with_zero([0.5, 0.2], noise=0.01).phase_note == "minimum phase"
