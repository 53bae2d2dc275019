"""Linear state space in simulation (gripkit.lti.StateSpace and the kernels' c2d_zoh): exact ZOH
against scipy, discrete simulation, DC gain."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy import signal

from gripkit.errors import ModelError
from gripkit.lti import StateSpace
from gripkit.sim import c2d_zoh


def test_zoh_matches_scipy_cont2discrete():
    A = np.array([[0.0, 1.0], [-128 / 1.8e-6, -7e-4 / 1.8e-6]])
    B = np.array([[0.0], [1 / 1.8e-6]])
    Ad, Bd = c2d_zoh(A, B, 5e-5)
    ref = signal.cont2discrete((A, B, np.eye(2), np.zeros((2, 1))), 5e-5, method="zoh")
    np.testing.assert_allclose(Ad, ref[0], rtol=1e-10, atol=1e-12 * np.abs(ref[0]).max())
    np.testing.assert_allclose(Bd, ref[1], rtol=1e-10)


@given(st.floats(0.1, 100.0), st.floats(0.01, 2.0), st.floats(1e-3, 0.5))
def test_discrete_step_settles_at_dc_gain(wn, zeta, dt):
    """Property: the discretised system's DC gain equals the continuous one (ZOH is exact at DC)."""
    A = np.array([[0.0, 1.0], [-wn**2, -2 * zeta * wn]])
    sys = StateSpace(A, [[0.0], [wn**2]], [[1.0, 0.0]], [[0.0]])
    d = sys.c2d(dt)
    np.testing.assert_allclose(d.dc_gain(), sys.dc_gain(), rtol=1e-8)
    assert d.stable and sys.stable


def test_simulate_matches_scipy_dlsim():
    sys = StateSpace([[0.0, 1.0], [-4.0, -0.4]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]]).c2d(0.05)
    u = np.sin(np.arange(300) * 0.1)
    _, yref, _ = signal.dlsim(sys.to_scipy(), u)
    # Both run the same recursion in another order; a rounding made at step k reaches y[n] through
    # C A^(n−k) B, so the difference is bounded by 4·ε·Σ_k ‖C A^k‖·(‖A‖ ‖x‖∞ + ‖B‖ ‖u‖∞).
    Ak, h1 = np.eye(2), 0.0
    for _ in range(u.size):
        h1 += np.abs(sys.C @ Ak).sum()
        Ak = sys.A @ Ak
    x_max = np.abs(signal.dlsim(sys.to_scipy(), u)[2]).max()
    tol = 4 * np.finfo(np.float64).eps * h1 * (np.abs(sys.A).sum() * x_max + np.abs(sys.B).sum())
    np.testing.assert_allclose(sys.simulate(u)[:, 0], yref[:, 0], rtol=0, atol=tol)


def test_frequency_response_matches_python_control():
    import control  # a dev dependency: the cross-check fails, never skips, without it
    sys = StateSpace([[0.0, 1.0], [-4.0, -0.4]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]])
    f = np.array([0.1, 0.3, 1.0])
    h = sys.frequency_response(2 * np.pi * f)[:, 0, 0]  # rad/s
    mag, phase, _ = control.frequency_response(sys.to_control(), 2 * np.pi * f)
    np.testing.assert_allclose(np.abs(h), np.squeeze(mag), rtol=1e-10)


def test_errors():
    with pytest.raises(ModelError, match="square"):
        StateSpace(np.ones((2, 3)), np.ones((2, 1)), np.ones((1, 2)), None)
    with pytest.raises(ModelError, match="sample time"):
        StateSpace([[-1.0]], [[1.0]], [[1.0]], [[0.0]]).simulate(np.ones(3))
    with pytest.raises(ModelError, match="infinite"):
        StateSpace([[0.0]], [[1.0]], [[1.0]], [[0.0]]).dc_gain()
