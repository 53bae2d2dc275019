"""Piezo-actuator identification helpers (gripkit.sysid.physical.bouc_wen) on the generic
actuator (gripkit.models.PiezoActuator, eq 4 of ``001_0b92a7da96e7aa46.txt``) with values of no
seed: D(s) = 1/(a s² + b s + 1) is recovered from a simulated voltage step with the static
Bouc-Wen part held at its true values; the loop error is max |y − ŷ| over the loop's range."""

import numpy as np
import pytest

from gripkit import Trajectory
from gripkit.errors import DataError
from gripkit.models import PiezoActuator
from gripkit.sysid.physical.bouc_wen import (ActuatorDynamicsResult, identify_actuator_dynamics,
                                             loop_error)

STATIC = dict(d_p=1.2e-6, lam=0.2e-6, beta=0.05, gamma=0.01)
A, B = 4e-8, 1.2e-4  # ω_n = 5000 rad/s, ζ = 0.3


def test_d_s_recovered_from_a_noise_free_step():
    dt = 2e-5
    act = PiezoActuator(loads=False, a=A, b=B, L_a=10e-3, s_p=1e-3, **STATIC)
    U = np.r_[np.zeros(50), np.full(950, 40.0)]
    y = act.simulate(U, dt=dt)["y_A"]
    data = Trajectory(np.arange(U.size) * dt, {"U": U, "y": y}, {"U": "V", "y": "m"})
    static = {"d_p": STATIC["d_p"], "lambda": STATIC["lam"], "beta": STATIC["beta"],
              "gamma": STATIC["gamma"]}  # the keys of a BoucWenResult's params
    res = identify_actuator_dynamics(data, static, "U", "y", progress=False)
    assert type(res) is ActuatorDynamicsResult
    assert res.a == pytest.approx(A, rel=1e-5)
    assert res.b == pytest.approx(B, rel=1e-5)
    # D(s) = 1/(a s² + b s + 1): ω_n = 1/√a = 5000 rad/s, ζ = b/(2√a) = 0.3
    assert res.natural_frequency_hz == pytest.approx(5000 / (2 * np.pi), rel=1e-5)
    assert res.damping_ratio == pytest.approx(0.3, rel=1e-5)


def test_loop_error_is_the_largest_gap_over_the_range():
    y = np.array([0.0, 1.0, 4.0, 2.0])
    assert loop_error(y, y + np.array([0.0, 0.2, -0.1, 0.0])) == pytest.approx(0.05)
    with pytest.raises(DataError, match="does not vary"):
        loop_error(np.ones(4), np.zeros(4))
