"""PWM-motor identification (gripkit.sysid.rigid_body.motor) on a generic motor (no seed values):
torque = c·u + (b₁|u| + b₀)·ω (eq 5.10 of ``002_ddea254371185ad3.txt``) with c = 2e-6 N·m per
count, b₁ = 5e-10 N·m·s/rad per count, b₀ = −4e-6 N·m·s/rad. The one-shot least squares and the
two-stage characterisation (§5.4) recover them within three standard deviations, and
noise-free data exactly."""

import numpy as np
import pytest

from gripkit.models import BLDCMotor
from gripkit.models.bldc import motor_parameters
from gripkit.sysid.rigid_body.motor import characterize_motor, fit_motor

TRUE = dict(c_pwm=2e-6, b_pwm=5e-10, b_0=-4e-6)
MOTOR = BLDCMotor(motor_parameters().replace(**TRUE))


def _runs(rng, noise):
    u = rng.choice([800.0, 1600.0, 2400.0, 3200.0, -2000.0], 600)
    w = rng.uniform(-100.0, 300.0, 600)
    tau = MOTOR.torque(u, w)
    keep = tau != 0  # outside Appendix E's guard
    return u[keep], w[keep], tau[keep] + rng.normal(0, noise, keep.sum())


def test_fit_motor_recovers_the_parameters():
    rng = np.random.default_rng(11)
    u, w, tau = _runs(rng, 0.0)
    exact = fit_motor(u, w, tau)
    for k, v in TRUE.items():
        assert exact.values[k] == pytest.approx(v, rel=1e-9)
    u, w, tau = _runs(rng, 2e-5)
    fit = fit_motor(u, w, tau)
    for k, v in TRUE.items():
        assert abs(fit.values[k] - v) < 3 * fit.std[k], k


def test_two_stage_characterisation_recovers_c_and_the_slope_line():
    """Stage 1: c from a stall sweep; stage 2: the slope b(u) = b₁ u + b₀ of each run at
    constant PWM, then the line through them."""
    rng = np.random.default_rng(12)
    stall = np.arange(0.0, 4001.0, 100.0)
    t_stall = MOTOR.torque(stall, 0.0) + rng.normal(0, 2e-5, stall.size)
    runs = []
    for pwm in (1500.0, 2500.0, 3500.0, 4000.0):
        w = np.repeat(np.arange(0.0, 201.0, 40.0), 20)
        runs.append((pwm, w, MOTOR.torque(pwm, w) + rng.normal(0, 2e-5, w.size)))
    ch = characterize_motor(stall, t_stall, runs)
    assert abs(ch.c - TRUE["c_pwm"]) < 3 * ch.c_std
    assert abs(ch.b1 - TRUE["b_pwm"]) < 3 * ch.b1_std
    assert abs(ch.b0 - TRUE["b_0"]) < 3 * ch.b0_std
