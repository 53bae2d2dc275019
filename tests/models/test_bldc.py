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


def test_test_bed_thermal_model_is_first_order():
    """With α = 0 (R fixed at R₀, ρ ≡ 1) the stall torque stays c·u and the winding temperature
    obeys C_th dT/dt = R₀ I² − (T − T_amb)/R_th: it rises by R_th R₀ I² with the time constant
    R_th C_th (1 − e⁻¹ of the rise at t = R_th C_th, to the explicit step's 1 %)."""
    from gripkit.models import MotorTestBed
    from gripkit.models.bldc import motor_parameters

    p = motor_parameters().replace(alpha_R=0.0)
    tb = MotorTestBed(p, check=False)
    tau_th = p.value("R_th") * p.value("C_th")
    dt = tau_th / 100
    n = 1001  # ten time constants
    tr = tb.simulate(np.column_stack([np.full(n, 3000.0), np.zeros(n)]), dt=dt)
    torque = p.value("c_pwm") * 3000.0
    np.testing.assert_allclose(tr["torque"], torque, rtol=1e-12)
    np.testing.assert_allclose(tr["current"], torque / p.value("k_t"), rtol=1e-12)
    rise = p.value("R_th") * p.value("R_0") * (torque / p.value("k_t")) ** 2
    T = tr["temperature"] - p.value("T_amb")
    assert T[0] == 0.0
    assert T[-1] == pytest.approx(rise * (1 - np.exp(-10.0)), rel=1e-3)
    assert T[100] == pytest.approx(rise * (1 - np.exp(-1.0)), rel=0.01)
    (rate, _), = tb.modes(tb.theta())
    assert rate == pytest.approx(1 / tau_th)
