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
