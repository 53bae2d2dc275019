"""PWM-driven BLDC motor (gripkit.models.bldc, eqs 5.5, 5.7, 5.8, 5.10 of
``002_ddea254371185ad3.txt``): at ρ = 1 (the winding at T_ref) the torque is c·u + (b₁|u| + b₀)·ω
with Appendix E's guard; every torque scales with ρ(T) = R(T_ref)/R(T) (eq 5.5)."""

import numpy as np
import pytest

from gripkit.models import BLDCMotor
from gripkit.models.bldc import bldc_torque, temperature_factor


MOTOR = BLDCMotor()
P = MOTOR.parameters.value


def test_torque_formula_at_rho_1():
    """T = None and T = T_ref both give ρ = 1 and τ = c u + (b₁|u| + b₀) ω, the compiled kernel
    the same (on a grid of PWM and speeds where the guard does not act)."""
    u = np.array([[-3000.0], [-500.0], [1200.0], [4000.0]])
    w = np.array([-40.0, 0.0, 25.0])
    c, b1, b0 = P("c_pwm"), P("b_pwm"), P("b_0")
    expected = c * u + (b1 * np.abs(u) + b0) * w
    assert np.all(np.abs(c * u) >= np.abs((b1 * np.abs(u) + b0) * w))  # guard inactive here
    np.testing.assert_allclose(MOTOR.torque(u, w), expected, rtol=1e-12)
    np.testing.assert_allclose(MOTOR.torque(u, w, T=P("T_ref")), expected, rtol=1e-12)
    for i, j in ((0, 0), (2, 2), (3, 1)):
        k = bldc_torque(u[i, 0], w[j], c, b1, b0, P("pwm_max"), 1.0)
        assert k == pytest.approx(expected[i, j], rel=1e-12)


def test_temperature_scales_torque_by_the_resistance_ratio():
    """ρ(T) = R(T_ref)/R(T) with R(T) = R₀(1 + α(T − T_amb)) (eq 5.5): ρ(T_ref) = 1, and the
    torque at T is ρ(T) times the torque at T_ref."""
    T = np.array([P("T_amb"), 320.0, P("T_ref"), 390.0])
    rho = MOTOR.resistance(P("T_ref")) / MOTOR.resistance(T)
    np.testing.assert_allclose(MOTOR.rho(T), rho, rtol=1e-12)
    assert temperature_factor(P("T_ref"), P("T_ref"), P("T_amb"), P("alpha_R")) == 1.0
    assert temperature_factor(320.0, P("T_ref"), P("T_amb"), P("alpha_R")) == pytest.approx(rho[1])
    np.testing.assert_allclose(MOTOR.torque(2500.0, 30.0, T), rho * MOTOR.torque(2500.0, 30.0))


def test_inverse_model_round_trip():
    pwm = np.array([-3500.0, -1200.0, 800.0, 2500.0, 3900.0])
    w = np.array([-200.0, 50.0, 100.0, 300.0, -150.0])
    np.testing.assert_allclose(MOTOR.pwm_for_torque(MOTOR.torque(pwm, w), w), pwm, rtol=1e-9)
    np.testing.assert_allclose(MOTOR.pwm_for_torque(MOTOR.torque(pwm, w, 330.0), w, 330.0), pwm,
                               rtol=1e-9)


def test_current_is_torque_over_k_t():
    assert MOTOR.current(0.01) == pytest.approx(0.01 / P("k_t"), rel=1e-12)
