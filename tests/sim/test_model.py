"""The Model base class, on the exact mass-spring-damper."""

import math

import numpy as np
import pytest

from gripkit import ParameterError, SimulationError, Trajectory
from gripkit.models import MassSpringDamper


def analytic_step(t, m, b, k, F):
    wn = math.sqrt(k / m)
    z = b / (2 * math.sqrt(k * m))
    wd = wn * math.sqrt(1 - z**2)
    return (F / k * (1 - np.exp(-z * wn * t)
                     * (np.cos(wd * t) + z / math.sqrt(1 - z**2) * np.sin(wd * t))))


def test_step_response_is_exact_for_tsfm_sensor():
    """Table II (001_0b92a7da96e7aa46.txt): m_s = 1.8e-6 kg, b_s = 7e-4 N·s/m, k_s = 128 N/m,
    sampled at the seed's 20 kHz: the ZOH kernel reproduces the analytic step response."""
    m, b, k = 1.8e-6, 7e-4, 128.0
    model = MassSpringDamper(m=m, b=b, k=k)
    tr = model.simulate(np.full(400, 1e-4), dt=1 / 20000)
    np.testing.assert_allclose(tr["x"], analytic_step(tr.t, m, b, k, 1e-4), rtol=0,
                               atol=1e-12 * 1e-4 / k * 1e6)


def test_batch_equals_single_runs():
    model = MassSpringDamper(m=1.0, b=0.3, k=4.0)
    thetas = np.array([[1.0, 0.3, 4.0], [2.0, 0.1, 9.0], [0.5, 1.0, 1.0]])
    u = np.sin(np.arange(500) * 0.02)
    Y = model.simulate_batch(thetas, u, dt=0.01)
    for i, th in enumerate(thetas):
        y1 = model.simulate(u, dt=0.01, params=dict(zip(("m", "b", "k"), th)))["x"]
        np.testing.assert_array_equal(Y[i, :, 0], y1)


def test_simulate_accepts_trajectory_and_returns_units():
    model = MassSpringDamper()
    u = Trajectory.uniform(dt=0.01, F=np.ones(50), units={"F": "N"})
    out = model.simulate(u)
    assert out.unit("x") == "m" and out.dt == 0.01 and out.n == 50


def test_errors_name_the_problem():
    model = MassSpringDamper()
    with pytest.raises(ParameterError, match=r"m = -1 kg is outside its bounds"):
        model.simulate_batch(np.array([[-1.0, 0.1, 1.0]]), np.ones(10), dt=0.1)
    with pytest.raises(SimulationError, match="give the sample time"):
        model.simulate(np.ones(10))
    with pytest.raises(SimulationError, match="NaN"):
        model.simulate(np.array([1.0, np.nan]), dt=0.1)


def test_output_buffer_is_reused_and_checked():
    model = MassSpringDamper(m=1.0, b=0.3, k=4.0)
    u = np.sin(np.arange(200) * 0.05)
    buf = np.empty((1, 200, 1))
    y = model.simulate_batch(model.theta()[None, :], u, dt=0.01, out=buf)
    assert y is buf
    np.testing.assert_array_equal(buf[0, :, 0], model.simulate(u, dt=0.01)["x"])
    with pytest.raises(SimulationError, match="shape"):
        model.simulate_batch(model.theta()[None, :], u, dt=0.01, out=np.empty((1, 100, 1)))


def test_simulated_trajectory_owns_read_only_contiguous_channels():
    """simulate() hands its arrays to the Trajectory without a second copy: they must not alias
    the caller's input, must be read-only, and each channel must be contiguous."""
    model = MassSpringDamper(m=1.0, b=0.3, k=4.0)
    u = np.sin(np.arange(200) * 0.05)
    tr = model.simulate(u, dt=0.01)
    for name in ("F", "x"):
        a = tr[name]
        assert a.flags.c_contiguous and not a.flags.writeable
        with pytest.raises(ValueError):
            a[0] = 1.0
    u[0] = 99.0
    assert tr["F"][0] == 0.0
    np.testing.assert_array_equal(tr["x"], model.simulate_batch(model.theta()[None],
                                                                np.sin(np.arange(200) * 0.05),
                                                                dt=0.01)[0, :, 0])

