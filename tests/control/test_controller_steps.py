"""Every controller's allocation-free step (issue 27): a sequence of ``step`` calls equals the
batch ``run`` bit for bit and the analytic response — PID on a known error sequence against the
difference equations worked by hand, RST against ``scipy.signal.lfilter`` of R, S, T (the
unsaturated law R u = T r − S y from rest), LQR state feedback against u = N_r r − K x and a
closed loop whose output settles at the reference (the prefilter's defining property)."""

import math

import numpy as np
import pytest
from scipy import signal

from gripkit.control import PID, StateFeedback, design_rst, lqr, lqr_controller
from gripkit.errors import ConfigError, DataError
from gripkit.lti import StateSpace, TransferFunction


def test_pid_steps_on_a_known_error_sequence_equal_the_hand_computed_outputs():
    """kp = 2, ki = 10 /s, kd = 0.1 s, T_f = 0.01 s, Δt = 0.01 s, b = c = 1, y = 0, r = e:
    D_k = (0.01 D_{k−1} + 0.1 (e_k − e_{k−1}))/0.02 (D_0 = 0), I_{k+1} = I_k + 0.1 e_k,
    u_k = 2 e_k + I_k + D_k."""
    pid = PID(2.0, 10.0, 0.1, dt=0.01, tf=0.01, c=1.0)
    e = [1.0, 1.0, 0.5, -1.0]
    # k=0: D=0, I=0 → u=2;  k=1: D=0, I=0.1 → 2.1;  k=2: D=(0 + 0.1(−0.5))/0.02 = −2.5,
    # I=0.2 → 1 + 0.2 − 2.5 = −1.3;  k=3: D=(0.01(−2.5) + 0.1(−1.5))/0.02 = −8.75, I=0.25
    # → −2 + 0.25 − 8.75 = −10.5
    u = [pid.step(ek, 0.0) for ek in e]
    assert u == pytest.approx([2.0, 2.1, -1.3, -10.5], rel=1e-14)
    pid.reset()
    assert pid.run(np.array(e), np.zeros(4)).tolist() == u


def _rst():
    g = TransferFunction.from_polynomials([1.0, -1.5, 0.56], [0.0, 0.2, 0.1], dt=0.01)
    return design_rst(g, wn=12.0, zeta=0.8)


def test_rst_steps_equal_lfilter_of_R_S_T_and_the_batch_run():
    c = _rst()
    rng = np.random.default_rng(27)
    r = np.repeat(rng.uniform(-1, 1, 20), 10)
    y = 0.3 * rng.standard_normal(200)
    u = np.array([c.step(a, b) for a, b in zip(r, y)])
    ref = signal.lfilter(c.T, c.R, r) - signal.lfilter(c.S, c.R, y)
    np.testing.assert_allclose(u, ref, rtol=0, atol=1e-10 * np.abs(ref).max())
    c.reset()
    assert c.run(r, y).tolist() == u.tolist()
    assert c.R.size >= 3 and c.S.size >= 3  # the recursion reaches back several samples


def test_rst_step_saturates_and_tracks_with_the_anti_windup_polynomial():
    """Saturated: u = clamp(v) and the kernel's v obeys A_aw v = T r − S y + (A_aw − R) u."""
    c = _rst()
    c.u_min, c.u_max = -0.5, 0.5
    r, y = np.ones(60), np.zeros(60)
    u = c.run(r, y)
    assert u.max() == 0.5 and np.count_nonzero(u == 0.5) > 10
    c.reset()
    v = []
    for k in range(60):
        c.step(r[k], y[k])
        v.append(c._v[0])
    aw, R = c.A_aw, c.R
    lhs = signal.lfilter(aw, [1.0], np.array(v))
    rhs = signal.lfilter(c.T, [1.0], r) - signal.lfilter(c.S, [1.0], y) \
        + signal.lfilter(aw - R, [1.0], u)
    np.testing.assert_allclose(lhs, rhs, atol=1e-9 * np.abs(rhs).max())


def test_rst_run_refuses_nan():
    with pytest.raises(DataError, match="contains NaN"):
        _rst().run(1.0, [0.0, math.nan])


def _plant2x2():
    A = np.array([[0.9, 0.1, 0.0], [0.0, 0.8, 0.2], [0.05, 0.0, 0.7]])
    B = np.array([[1.0, 0.0], [0.2, 0.5], [0.0, 1.0]])
    C = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    return StateSpace(A, B, C, np.zeros((2, 2)), dt=0.01)


def test_lqr_state_feedback_steps_equal_the_gain_and_settle_at_the_reference():
    g = _plant2x2()
    Q, R = np.eye(3), 0.1 * np.eye(2)
    sf = lqr_controller(g, Q, R)
    K = lqr(g, Q, R).K
    np.testing.assert_array_equal(sf.K, K)
    rng = np.random.default_rng(3)
    x, r = rng.standard_normal((50, 3)), rng.standard_normal((50, 2))
    u = np.array([sf.step(xk, rk) for xk, rk in zip(x, r)])
    np.testing.assert_allclose(u, r @ sf.Nr.T - x @ K.T, rtol=1e-13, atol=1e-13)
    assert sf.run(x, r).tolist() == u.tolist()
    # closed loop x ← A x + B u: y → r (N_r is the inverse of the loop's DC gain)
    xk, ref, out = np.zeros(3), np.array([0.7, -0.2]), np.empty(2)
    for _ in range(2000):
        sf.step(xk, ref, out=out)
        xk = g.A @ xk + g.B @ out
    np.testing.assert_allclose(g.C @ xk, ref, rtol=1e-10)


def test_state_feedback_limits_and_shapes():
    sf = StateFeedback([[1.0, 2.0]], dt=0.1, u_min=-1.0, u_max=1.0)
    assert sf.step([3.0, 0.0]).tolist() == [-1.0]        # regulator u = −K x, clamped
    assert sf.step([-0.25, 0.0]).tolist() == [0.25]
    with pytest.raises(ConfigError, match="expected 2 values, found 3"):
        sf.step([1.0, 2.0, 3.0])
    with pytest.raises(ConfigError, match="u_min < u_max"):
        StateFeedback([[1.0]], dt=0.1, u_min=1.0, u_max=0.0)


def test_lqr_controller_of_a_non_square_model_needs_reference_false():
    g = StateSpace([[0.5]], [[1.0, 1.0]], [[1.0]], dt=0.1)
    from gripkit.errors import ModelError

    with pytest.raises(ModelError, match="as many outputs as inputs"):
        lqr_controller(g, [[1.0]], np.eye(2))
    assert not lqr_controller(g, [[1.0]], np.eye(2), reference=False).has_reference
