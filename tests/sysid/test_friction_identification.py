"""Friction identification from test-bed logs (gripkit.sysid.rigid_body.friction), on the generic
friction-loaded inertia (gripkit.models.FrictionDrive, Karnopp stiction, Stribeck kinetic
friction, the torque being the command): the breakaway test of §6.2 / Appendix C of
``002_ddea254371185ad3.txt`` brackets F_s between the last still and the first moving pulse, and
the constant-velocity runs of Appendix D give points on the Stribeck curve."""

import math

import numpy as np
import pytest

from gripkit.models import FrictionDrive, Stribeck
from gripkit.sysid.rigid_body.friction import (constant_velocity_friction, detect_breakaway,
                                               table_from_points)

DT = 1e-3
DRIVE = FrictionDrive(kind="karnopp")
P = DRIVE.parameters.value  # F_s = 0.36 N·m, F_c = 0.19 N·m, v_s = 0.3 rad/s, σ = 0.02


def _pulses(levels, on=200, off=800):
    return np.concatenate([np.r_[np.full(on, u), np.zeros(off)] for u in levels])


def test_breakaway_pulses_bracket_the_stiction_torque():
    """Pulses of 0.30…0.40 N·m in steps of 0.02, both directions: the joint first moves at 0.38
    (Karnopp holds every |τ| ≤ F_s = 0.36), so the estimate is the midpoint 0.37 N·m with the
    quantisation std 0.02/√12."""
    levels = np.round(np.arange(0.30, 0.401, 0.02), 2)
    tau = np.r_[_pulses(levels), _pulses(-levels)]
    tr = DRIVE.simulate(tau, dt=DT)
    res = detect_breakaway(tau, tr["velocity"], tr["position"], torque_at=lambda u, x: u)
    assert [r["pwm"] for r in res.breakaway] == [0.38, -0.38]
    assert [r["pwm_still"] for r in res.breakaway] == [0.36, -0.36]
    assert res.stiction == pytest.approx(0.37, rel=1e-12)
    assert res.stiction_std == pytest.approx(0.02 / math.sqrt(12), rel=1e-9)
    assert res.stiction - 0.01 <= P("fs") <= res.stiction + 0.01


def test_constant_velocity_runs_lie_on_the_stribeck_curve():
    """Held torques 0.4…0.6 N·m (above F_s) in both directions, 12 s each (J/σ = 1.1 s): each
    run's plateau speed v and torque τ (the inertial J·a subtracted) satisfy τ = F(v) of the
    drive's Stribeck curve to 0.1 %; the table of the points returns them at their velocities."""
    levels = np.array([0.4, 0.45, 0.5, 0.6])
    tau = np.concatenate([_pulses([s * u], on=12000, off=4000) for u in levels for s in (1, -1)])
    tr = DRIVE.simulate(tau, dt=DT)
    pts = constant_velocity_friction(tau, tr["velocity"], motor_torque=lambda u, v: u,
                                     inertia=P("J"), dt=DT, plateau=0.001)
    assert len(pts) == 8
    curve = Stribeck(P("fc"), P("fs"), P("vs"), P("delta"), P("sigma"))
    for p in pts:
        assert p.friction == pytest.approx(float(curve(p.velocity)), rel=1e-3)
    table = table_from_points(pts)
    v = np.array([p.velocity for p in pts])
    np.testing.assert_allclose(table(v), [p.friction for p in pts], rtol=1e-12)
