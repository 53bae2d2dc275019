"""Hybrid dynamics: free ↔ constrained motion through a gap, events located inside the step."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from gripkit.errors import ModelError, SimulationError
from gripkit.sim import Guard, HybridSystem, Mode

K_WALL = 100.0


def bouncing(k_wall=K_WALL, c_wall=0.0):
    """A unit mass on a unit spring that hits a wall (stiffness k_wall) at x = 1; output x and
    the wall force."""
    free = Mode("free", A=[[0, 1], [-1, 0]], B=[[0], [1]], C=[[1, 0], [0, 0]])
    wall = Mode("contact", A=[[0, 1], [-(1 + k_wall), -c_wall]], B=[[0], [1]],
                C=[[1, 0], [k_wall, c_wall]],
                e=[0, k_wall], f=[0, -k_wall])
    return HybridSystem([free, wall], [Guard("free", "contact", G=[-1, 0], c=1.0),
                                       Guard("contact", "free", G=[1, 0], c=-1.0)],
                                       outputs=("x", "F"))


def test_contact_instant_and_energy_against_analytic():
    """x = v0 sin t reaches the wall at t = asin(1/v0): the event is located within dt/2^12, and
    the undamped system keeps its energy ½v² + ½x² + ½k(x−1)₊² to 1e-9 through 4 impacts."""
    v0, dt = 1.5, 0.01
    res = bouncing().simulate(np.zeros(2000), dt, x0=[0.0, v0])
    t_hit = res.events[0][0]
    assert res.events[0][1:] == ("free", "contact")
    assert abs(t_hit - math.asin(1 / v0)) < dt / 4096
    x, v = res.states[:, 0], res.states[:, 1]
    E = 0.5 * v**2 + 0.5 * x**2 + 0.5 * K_WALL * np.clip(x - 1, 0, None) ** 2
    assert np.max(np.abs(E / E[0] - 1)) < 1e-9
    assert sum(1 for e in res.events if e[2] == "contact") >= 4


def test_exact_scheme_agrees_with_fine_rk4_reference():
    res = bouncing(c_wall=0.5).simulate(np.zeros(800), 0.01, x0=[0.0, 1.5])
    ref = bouncing(c_wall=0.5).simulate_reference(np.zeros(800), 0.01, x0=[0.0, 1.5], substeps=2000)
    np.testing.assert_allclose(res.trajectory["x"], ref.trajectory["x"], atol=2e-6)


@given(st.floats(1.05, 4.0), st.floats(10.0, 1e4))
def test_no_force_before_contact_and_no_jump_at_zero_velocity_contact(v0, k_wall):
    """Property: the wall force is exactly 0 while x < 1; an impact at zero velocity (the spring's
    turning point lands exactly on the wall, x0 = 0, v0 = 1) starts the force from 0."""
    sysm = bouncing(k_wall)
    r = sysm.simulate(np.zeros(400), 0.01, x0=[0.0, v0])
    x, F = r.trajectory["x"], r.trajectory["F"]
    assert np.all(F[x < 1.0] == 0.0)
    assert np.all(F >= -1e-9 * k_wall)
    # grazing: turning point exactly at the wall → no force at all (no spurious impulse)
    g = sysm.simulate(np.zeros(400), 0.01, x0=[0.0, 1.0])
    assert np.max(np.abs(g.trajectory["F"])) < 1e-6 * k_wall


def test_chattering_is_reported():
    """Guards that leave a mode straight back into it switch endlessly: SimulationError."""
    a = Mode("a", A=[[0.0]], B=[[1.0]], C=[[1.0]])
    b = Mode("b", A=[[0.0]], B=[[1.0]], C=[[1.0]])
    sysm = (HybridSystem([a, b], [Guard("a", "b", G=[1.0], c=-0.5),
                                  Guard("b", "a", G=[1.0], c=-0.5)]))
    with pytest.raises(SimulationError, match="chattering"):
        sysm.simulate(np.ones(10), 0.1, x0=[0.0])


def test_bad_definitions():
    m = Mode("m", A=[[0.0]], B=[[1.0]], C=[[1.0]])
    with pytest.raises(ModelError, match="no mode 'x'"):
        HybridSystem([m], [Guard("m", "x", G=[1.0])])
    with pytest.raises(ModelError, match="unique"):
        HybridSystem([m, m])
    with pytest.raises(SimulationError, match="inputs of shape"):
        HybridSystem([m]).simulate(np.ones((5, 2)), 0.1)
