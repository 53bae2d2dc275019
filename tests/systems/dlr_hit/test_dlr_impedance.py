"""Joint and Cartesian impedance control (``002_ddea254371185ad3.txt`` eq 3.1, §3.1) of the
simulated finger: analytic equilibria without friction, the effect of friction compensation, and
stability margins against python-control."""

import math

import numpy as np
import pytest

from gripkit.errors import ModelError, SimulationError
from gripkit.systems.dlr_hit.impedance import (ImpedanceController, Wall, impedance_margins,
                                               simulate_impedance)
from gripkit.systems.dlr_hit.impedance import stability_margins
from gripkit.systems.dlr_hit.parameters import finger

DEG = math.pi / 180
Q0 = (0.0, 30 * DEG, 45 * DEG)


def contact_setup(f, K, depth, kw, N=5000):
    """Fingertip 10 mm above a horizontal wall; the set point moves within 2 s to ``depth`` behind
    it. Cartesian damping ζ ≈ 0.7 for a 4.4 kg apparent mass, plus 0.3 N·m·s/rad actuator damping:
    the thesis's motor model cannot brake at speed (Appendix E's guard zeroes any torque the
    speed term outweighs), so damping must be generous."""
    ch = f.chain()
    p0 = np.linalg.solve(ch.coupling.matrix[:3], np.array(Q0))
    tip0 = ch.tip_position(p0)
    wall = Wall(normal=(0, 0, 1), point=(0, 0, tip0[2] - 0.01), stiffness=kw, damping=2.0)
    t = np.arange(N) * 1e-3
    xd = np.tile(tip0, (N, 1))
    xd[:, 2] = tip0[2] - (0.01 + depth) * np.clip(t / 2.0, 0, 1)
    c = ImpedanceController("cartesian", (K, K, K), (1.4 * math.sqrt(K * 4.4),) * 3,
                            actuator_damping=(0.3, 0.3, 0.3))
    return c, xd, wall


def test_frictionless_contact_force_is_the_series_spring():
    """No friction, gravity compensated: at rest against the wall the impedance spring K and the
    wall k_w are in series, F = K·k_w/(K + k_w)·δ for a set point δ behind the wall (eq 3.1 at
    equilibrium), within 0.5 %."""
    f = finger(check=False, friction="none")
    for K, kw in ((300.0, 2000.0), (1000.0, 3000.0)):
        c, xd, wall = contact_setup(f, K, 0.005, kw)
        tr = simulate_impedance(f, c, xd, x0=f.state(q=Q0), wall=wall)
        assert tr["force_z"][-1] == pytest.approx(K * kw / (K + kw) * 0.005, rel=0.005)
        assert abs(tr["force_x"][-1]) < 1e-12 and abs(tr["tip_x"][-1] - xd[-1, 0]) < 1e-5


def test_joint_impedance_gravity_compensation():
    """Frictionless joint impedance holding a set point: with gravity compensation the error
    vanishes; without it the joints sag until K·(q_d − q) = G_q, the joint-space gravity torque."""
    f = finger(check=False, friction="none")
    ref = np.tile([0.0, 30 * DEG, 30 * DEG], (3000, 1))
    K = np.array([4.0, 4.0, 4.0])
    on = simulate_impedance(f, ImpedanceController("joint", K, (0.5, 0.5, 0.5)), ref)
    off = (simulate_impedance(f, ImpedanceController("joint", K, (0.5, 0.5, 0.5),
                                                     gravity_compensation=False), ref))
    q_on = np.array([on[j][-1] for j in ("abd", "flex", "prox")])
    q_off = np.array([off[j][-1] for j in ("abd", "flex", "prox")])
    np.testing.assert_allclose(q_on, ref[0], atol=1e-6)
    ch = f.chain()
    G = ch.coupling.matrix[:3]
    g_p = ch.gravity(np.linalg.solve(G, q_off))
    g_q = np.linalg.solve(G.T, g_p)  # joint-space gravity (θ4's torque on θ3)
    np.testing.assert_allclose(ref[0] - q_off, g_q / K, rtol=0.01, atol=1e-7)


def test_friction_compensation_improves_tracking_and_contact_force():
    """With Appendix G's friction and stiction: compensation more than halves the tracking error
    of a 0.5 Hz flexion/proximal motion, and pressing on the wall (expected 3.75 N) it ends within
    10 % of the force, where without compensation stiction stops it before the wall."""
    f = finger(check=False)
    N = 4000
    t = np.arange(N) * 1e-3
    ref = np.column_stack([0 * t, (30 + 20 * np.sin(2 * np.pi * 0.5 * t)) * DEG,
                           (30 + 20 * np.sin(2 * np.pi * 0.5 * t + 1)) * DEG])
    err = {}
    for comp in (True, False):
        c = ImpedanceController("joint", (5, 5, 5), (0.5, 0.5, 0.5), friction_compensation=comp)
        tr = simulate_impedance(f, c, ref)
        e = np.column_stack([tr["flex"] - ref[:, 1], tr["prox"] - ref[:, 2]])[1000:]
        err[comp] = np.sqrt(np.mean(e ** 2))
    assert err[True] < 0.5 * err[False]
    ferr = {}
    for comp in (True, False):
        c, xd, wall = contact_setup(f, 1000.0, 0.005, 3000.0)
        c = ImpedanceController("cartesian", c.stiffness, c.damping, friction_compensation=comp,
                                actuator_damping=c.actuator_damping)
        tr = simulate_impedance(f, c, xd, x0=f.state(q=Q0), wall=wall)
        ferr[comp] = abs(tr["force_z"][-1] - 1000 * 3000 / 4000 * 0.005)
    assert ferr[True] < 0.1 * 3.75 and ferr[True] < 0.5 * ferr[False]


def test_stability_margins_match_python_control():
    import control  # a dev dependency: the cross-check fails, never skips, without it
    for J, K, D, visc, ke in ((0.0221, 5.0, 0.5, 0.0, 0.0), (0.028, 50.0, 0.2, 0.05, 20.0),
                              (0.0221, 400.0, 1.0, 0.0, 0.0)):
        dt = 1e-3
        m = stability_margins(J, K, D, dt, viscous=visc, k_env=ke)
        P = control.sample_system(control.tf([1.0], [J, visc, ke]), dt, method="zoh")
        C = control.tf([K + D / dt, -D / dt], [1.0, 0.0], dt)
        L = P * C * control.tf([1.0], [1.0, 0.0], dt)
        gm, pm, wg, wp = control.margin(L)
        assert m["phase_margin_deg"] == pytest.approx(pm, rel=0.01, abs=0.05)
        if np.isfinite(gm):
            assert m["gain_margin"] == pytest.approx(gm, rel=0.01)
        poles = control.poles(control.feedback(L, 1))
        assert m["stable"] == bool(np.all(np.abs(poles) < 1))


def test_margins_of_the_finger_and_an_unstable_gain():
    f = finger(check=False)
    c = ImpedanceController("joint", (5, 5, 5), (0.5, 0.5, 0.5))
    rows = impedance_margins(f, c)
    assert all(r["stable"] and r["phase_margin_deg"] > 45 and r["gain_margin"] > 10 for r in rows)
    hot = ImpedanceController("joint", (2e4, 2e4, 2e4), (30, 30, 30))
    assert not all(r["stable"] for r in impedance_margins(f, hot))


def test_bad_controller_input():
    with pytest.raises(ModelError, match="kind"):
        ImpedanceController("force")
    with pytest.raises(ModelError, match="stiffness"):
        ImpedanceController("joint", (1.0, -1.0, 1.0))
    with pytest.raises(ModelError, match="normal"):
        Wall((0, 0, 0), (0, 0, 0), 1000.0)
    f = finger(check=False)
    with pytest.raises(SimulationError, match="reference"):
        simulate_impedance(f, ImpedanceController(), np.zeros((10, 2)))
    with pytest.raises(SimulationError, match="semi-implicit"):
        simulate_impedance(finger(check=False, integrator="rk4"), ImpedanceController(),
                           np.zeros((10, 3)))
