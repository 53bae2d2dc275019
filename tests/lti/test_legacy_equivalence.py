"""gripkit.lti reproduces the three linear types it replaces (issue 12): sim.linear.StateSpace,
sysid.PolynomialModel and control.finger_force.DiscretePlant, method by method, on the seed's
models. These tests document the migration table; delete them with the old types.

Tolerances: both sides compute each quantity by backward-stable routes that differ only in
realisation or summation order, so they agree to ~n ε κ; for these second- and third-order models
κ < 1e3 (TSFM sensor after scaling, Table II's poles 0.94 ± 0.12j), hence 1e-12 relative (1e-14
where the arithmetic is identical: roots of the same polynomial, sums of the same coefficients)."""

import numpy as np
import pytest

from gripkit.control.rst import DiscretePlant
from gripkit.lti import StateSpace, as_system
from gripkit.sim.linear import StateSpace as OldStateSpace
from gripkit.sim.linear import c2d_zoh
from gripkit.sysid.polynomial import PolynomialModel

# 000_8f66dcc7ab06470c.txt, Table II: ARX [2 2 2], fs = 200 Hz
A222 = [1.0, -1.8732, 0.8996]
B222 = [0.0, 0.0, 0.1950, -0.2276]


def test_sim_statespace():
    """TSFM-like lightly damped sensor (001_0b92a7da96e7aa46.txt: k_s = 128 N/m, m_s = 1.8e-6 kg)."""
    A = [[0.0, 1.0], [-128 / 1.8e-6, -7e-4 / 1.8e-6]]
    B, C = [[0.0], [1 / 1.8e-6]], [[1.0, 0.0]]
    old = OldStateSpace(A, B, C, None, None, ("F",), ("y",), ("N",), ("m",))
    new = StateSpace(A, B, C, None, None, ("F",), ("y",), ("N",), ("m",))
    np.testing.assert_allclose(np.sort_complex(new.poles()), np.sort_complex(old.poles()), rtol=1e-14)
    np.testing.assert_allclose(new.dc_gain(), old.dc_gain(), rtol=1e-14)
    f = np.array([10.0, 1e3, 8.5e3])
    np.testing.assert_allclose(new.frequency_response(2 * np.pi * f), old.freqresp(f), rtol=1e-12)
    od, nd = old.discretize(5e-5), new.c2d(5e-5)
    Ad, Bd = c2d_zoh(np.array(A), np.array(B), 5e-5)
    np.testing.assert_allclose(nd.A, Ad, rtol=1e-12, atol=1e-12 * np.abs(Ad).max())
    np.testing.assert_allclose(nd.B, Bd, rtol=1e-12)
    u = np.sin(np.arange(500) * 0.01)
    np.testing.assert_allclose(nd.simulate(u), od.simulate(u), rtol=1e-12, atol=1e-20)
    assert nd.is_stable() == od.is_stable()


def test_polynomial_model():
    old = PolynomialModel.from_coefficients(A222, B222, dt=0.005)
    new = as_system(old)
    np.testing.assert_allclose(np.sort_complex(np.roots(new.den_zinv())), np.sort_complex(old.poles()), rtol=1e-14)
    np.testing.assert_allclose(new.zeros(), old.zeros(), rtol=1e-14)
    assert float(new.dc_gain()[0, 0]) == pytest.approx(old.dc_gain, rel=1e-14)
    np.testing.assert_allclose(new.step(50)[:, 0, 0], old.step(50), rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(new.impulse(50)[:, 0, 0], old.impulse(50), rtol=1e-12, atol=1e-15)
    f, H = old.frequency_response(n=64)
    np.testing.assert_allclose(new.frequency_response(2 * np.pi * f)[:, 0, 0], H, rtol=1e-11)
    u = np.cos(np.arange(300) * 0.07)
    np.testing.assert_allclose(new.simulate(u)[:, 0], old.simulate(u), rtol=1e-12, atol=1e-14)
    yp, up = np.array([0.3, -0.1, 0.2]), np.array([1.0, 0.5, -0.5])
    np.testing.assert_allclose(new.simulate(u, new.initial_state(up, yp))[:, 0],
                               old.simulate(u, initial="given", y_past=yp, u_past=up), rtol=1e-12, atol=1e-14)
    assert new.is_stable() == old.stable
    assert bool(np.all(np.abs(new.zeros()) < 1)) == old.minimum_phase
    sp, so = new.to_scipy(), old.to_scipy()
    np.testing.assert_allclose(sp.den, so.den)
    for X, Y in zip(new.to_ss(form="controllable")._arrays(), old.to_statespace()):
        np.testing.assert_array_equal(X, Y)
    # with σ: Table II's stds become a diagonal covariance over a1 a2 b2 b3
    olds = PolynomialModel.from_coefficients(A222, B222, dt=0.005, std={"A": [0, 0.01, 0.01], "B": [0, 0, 0.02, 0.02]})
    news = as_system(olds)
    np.testing.assert_allclose(news.uncertainty.covariance, olds.covariance)
    assert news.uncertainty.names == olds.parameter_names


def test_discrete_plant():
    old = DiscretePlant(A222, B222, 0.005, input_name="i", input_unit="A", output_name="F", output_unit="N")
    new = as_system((A222, B222, 0.005), inputs="i", input_units="A", outputs="F", output_units="N")
    assert new.relative_degree() == old.nk
    np.testing.assert_allclose(np.sort_complex(np.roots(new.den_zinv())), np.sort_complex(old.poles()))
    np.testing.assert_allclose(new.zeros(), old.zeros())
    assert float(new.dc_gain()[0, 0]) == pytest.approx(old.dc_gain(), rel=1e-14)
    u = np.ones(200)
    np.testing.assert_allclose(new.simulate(u)[:, 0] + 2.0, old.simulate(u, y_offset=2.0), rtol=1e-12)
    np.testing.assert_allclose((3.0 * new).num_zinv(), old.scaled(3.0).B)
    ss_old, ss_new = old.to_state_space(), new.to_ss(form="controllable")
    for X, Y in zip(ss_new._arrays(), (ss_old.A, ss_old.B, ss_old.C, ss_old.D)):
        np.testing.assert_array_equal(X, Y)          # the same realisation, bit for bit
    assert ss_new.inputs == ss_old.inputs and ss_new.output_units == ss_old.output_units
    # DiscretePlant.from_model(StateSpace) ≡ StateSpace.to_tf()
    back = DiscretePlant.from_model(ss_old)
    np.testing.assert_allclose(ss_new.to_tf().den_zinv(), back.A, atol=1e-12)
    np.testing.assert_allclose(ss_new.to_tf().num_zinv(), back.B, atol=1e-12)
    c_old, c_new = old.to_control(), new.to_control()
    np.testing.assert_allclose(c_new(np.exp(0.3j)), c_old(np.exp(0.3j)), rtol=1e-12)


def test_as_system_reads_old_state_space_and_armax_oe_covariances():
    old = OldStateSpace([[-1.0, 0.0], [1.0, -2.0]], [[1.0], [0.0]], [[0.0, 1.0]], None, 0.1, ("V",), ("x",),
                        ("V",), ("m",))
    new = as_system(old)
    assert isinstance(new, StateSpace) and new.inputs == ("V",) and new.output_units == ("m",) and new.dt == 0.1
    # ARMAX: the covariance over a1 b1 c1 keeps its order; c1 does not move B/A (zero tangent)
    armax = PolynomialModel.from_coefficients([1.0, -0.5], [0.0, 1.0], C=[1.0, 0.3], dt=0.1,
                                              std={"A": [0, 0.01], "B": [0, 0.02], "C": [0, 0.05]})
    g = as_system(armax)
    assert g.uncertainty.names == ("a1", "b1", "c1") == armax.parameter_names
    assert np.all(g.uncertainty.tangents[0][2] == 0) and np.all(g.uncertainty.tangents[1][2] == 0)
    # OE: B/F with f's as the denominator's parameters
    oe = PolynomialModel.from_coefficients([1.0], [0.0, 1.0], F=[1.0, -0.7], dt=0.1,
                                           std={"B": [0, 0.02], "F": [0, 0.01]})
    h = as_system(oe)
    assert h.uncertainty.names == ("b1", "f1") and h.den_zinv().tolist() == [1.0, -0.7]
    np.testing.assert_allclose(h.pole_covariance()[1][0, 0, 0], 0.01 ** 2, rtol=1e-12)  # ∂p/∂f1 = −1
