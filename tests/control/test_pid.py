"""Discrete PID: linear behaviour against its z-transfer function (scipy.signal.lfilter),
anti-windup,
bumpless transfer (hypothesis), derivative on the measurement, configuration errors."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy import signal

from gripkit.control.pid import PID, PID_PARAMETERS, PIDS, PIDX, pid_step
from gripkit.errors import ConfigError

TS = 1e-3


def test_linear_region_equals_transfer_function():
    """b = c = 1, no saturation, e[0] = 0: u = C(z) e with C(z) = kp + ki T/(z-1) +
    kd(z-1)/((Tf+T)z - Tf)."""
    pid = PID(2.0, 150.0, 0.01, dt=TS, tf=0.004, c=1.0)
    e = np.r_[0.0, np.random.default_rng(0).standard_normal(500)]
    u = pid.run(e, np.zeros_like(e))
    g = pid.transfer_function()
    assert g.dt == TS and g.inputs == ("e",) and g.outputs == ("u",)
    num, den = g.numerator(), g.denominator()
    # The integrator's pole at z = 1 keeps every rounding: after N samples each recursion is off by
    # at most about N·ε·Σ|num|·Σ|den|·max|e| (a first-order bound, each step adding one rounding
    # of each product), which is 100× the difference actually seen.
    tol = (e.size * np.finfo(np.float64).eps * np.abs(num).sum() * np.abs(den).sum()
           * np.abs(e).max())
    np.testing.assert_allclose(u, signal.lfilter(num, den, e), rtol=0, atol=tol)


def test_first_output_and_integrator():
    pid = PID(2.0, 100.0, dt=TS)
    assert pid.step(0.1, 0.0) == pytest.approx(0.2)        # P only at k = 0
    assert pid.step(0.1, 0.0) == pytest.approx(0.2 + 100 * TS * 0.1)


def _windup_recovery(tt):
    """Plant y' = (u - y)/10 ms with u in [-1, 1]; the setpoint 5 is unreachable for 2 s, then
    0.5."""
    pid = PID(0.5, 50.0, dt=TS, u_min=-1.0, u_max=1.0, tt=tt)
    y, out = 0.0, []
    for rk in np.r_[np.full(2000, 5.0), np.full(3000, 0.5)]:
        u = pid.step(rk, y)
        y += TS * (u - y) / 0.01
        out.append(y)
    after = np.abs(np.array(out[2000:]) - 0.5) > 0.02
    return (np.flatnonzero(after)[-1] + 1) * TS if after.any() else 0.0


def test_back_calculation_prevents_windup():
    """After a long saturation the back-calculated integrator recovers > 5× faster than without."""
    with_aw, without = _windup_recovery(None), _windup_recovery(math.inf)
    assert with_aw * 5 < without
    assert with_aw < 0.1


@given(kp=st.floats(0, 10), ki=st.floats(0, 1e3), kd=st.floats(0, 0.1), r=st.floats(-5, 5),
       y=st.floats(-5, 5),
       ff=st.floats(-1, 1), u=st.floats(-9, 9), b=st.floats(0, 1), c=st.floats(0, 1))
def test_bumpless_transfer_returns_the_given_output(kp, ki, kd, r, y, ff, u, b, c):
    pid = PID(kp, ki, kd, dt=TS, b=b, c=c, u_min=-10, u_max=10)
    pid.run(np.random.default_rng(1).standard_normal(5), np.zeros(5))  # arbitrary history
    pid.transfer(u, r, y, ff)
    assert pid.step(r, y, ff) == pytest.approx(u, abs=1e-9 * (1 + abs(u) + kp * 10))


def test_derivative_on_measurement_has_no_setpoint_kick():
    pid = PID(1.0, 0.0, 0.05, dt=TS, c=0.0)
    pid.step(0.0, 0.0)
    assert pid.step(1.0, 0.0) == pytest.approx(1.0)   # setpoint step: P only
    pid_e = PID(1.0, 0.0, 0.05, dt=TS, c=1.0)
    pid_e.step(0.0, 0.0)
    assert pid_e.step(1.0, 0.0) > 5.0                  # derivative on the error kicks


def test_configuration_errors():
    with pytest.raises(ConfigError, match="dt"):
        PID(1.0, dt=0.0)
    with pytest.raises(ConfigError, match="u_min < u_max"):
        PID(1.0, dt=TS, u_min=1.0, u_max=0.0)
    with pytest.raises(ConfigError, match="finite"):
        PID(float("nan"), dt=TS)
    with pytest.raises(ConfigError, match="NaN"):
        PID(1.0, dt=TS).run([0.0, 1.0], [0.0, float("nan")])
    assert PID(2.0, 4.0, dt=TS).tt == pytest.approx(0.5)   # T_t = T_i without derivative
    assert math.isinf(PID(2.0, 4.0, dt=TS, tt=math.inf).tt)


def test_parameter_and_state_vectors_are_read_by_name():
    """The kernel's vectors through their generated index tables: each constructor argument lands
    at PIDX.<name>; a first step from rest (no derivative history, integral 0) with r = 1, y = 0.2
    gives u = kp (b r − y) = 2 (0.8 − 0.2) = 1.2, clipped to u_max = 1; then the integral holds
    ki dt (r − y) + dt/tt (u − v) = 3e-3·0.8 + (1e-3/0.05)(1 − 1.2) = −1.6e-3 and the stored
    derivative error is c r − y = 0.2 − 0.2 = 0."""
    given = (dict(kp=2.0, ki=3.0, kd=0.5, tf=0.01, b=0.8, c=0.2, tt=0.05, u_min=-1.0, u_max=1.0,
                  dt=1e-3))
    pid = PID(**given)
    assert len(pid.params) == len(PID_PARAMETERS)
    for name, value in given.items():
        assert pid.params[getattr(PIDX, name)] == value, name
    s = np.zeros(len(PIDS))
    assert pid_step(pid.params, s, 1.0, 0.2, 0.0) == 1.0
    assert s[PIDS.integral] == pytest.approx(3.0 * 1e-3 * 0.8 + 1e-3 / 0.05 * (1.0 - 1.2),
                                             rel=1e-12)
    assert s[PIDS.error_prev] == pytest.approx(0.0, abs=1e-15) and s[PIDS.started] == 1.0
