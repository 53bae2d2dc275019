"""BLDC motor model (``002_ddea254371185ad3.txt`` ch. 5, Appendix E) and its identification."""

import math

import numpy as np
import pytest

from gripkit.errors import DataError, ModelError, UnidentifiableError
from gripkit import zoo
from gripkit.models.bldc import NCM, RPM, SLOPES_5_4_2, BLDCMotor, MotorTestBed, motor_parameters
from gripkit.models.transmission import DLR_BASE, DLR_DISTAL, Transmission, harmonic_drive
from gripkit.sysid.rigid_body.motor import characterize_motor, fit_motor

MOTOR = BLDCMotor()


def test_stall_torque_follows_eq_5_7():
    """Eq 5.7: τ = 1.43e-4 Ncm × PWM at n = 0 (and T_ref); PWM 4000 → 0.572 Ncm; negative PWM
    reverses; |PWM| is clipped at 4096 (§5.2)."""
    pwm = np.arange(-4000, 4001, 250.0)
    np.testing.assert_allclose(MOTOR.torque(pwm, 0.0) / NCM, 1.43e-4 * pwm, rtol=1e-12, atol=1e-15)
    assert MOTOR.torque(5000, 0.0) / NCM == pytest.approx(1.43e-4 * 4096)


def test_slopes_of_section_5_4_2():
    """Eq 5.8 reproduces the printed torque-speed slopes within 5 % (§5.4.2; printed as magnitudes,
    the torque falls with speed)."""
    for pwm, stated in SLOPES_5_4_2.items():
        assert MOTOR.slope(pwm) * RPM / NCM == pytest.approx(stated, rel=0.05)
        # the torque actually falls with that slope
        w = 1500 * RPM
        assert (MOTOR.torque(pwm, w) - MOTOR.torque(pwm, 0.0)) / 1500 / NCM == pytest.approx(
            MOTOR.slope(pwm) * RPM / NCM)


#: eq 5.8 against the four slopes printed under Fig. 5.6 (§5.4.2, Ncm/rpm): (eq 5.8 value, relative
#: deviation). Eq 5.8 is b = 1.215e-8·PWM − 7.711e-5; two printed slopes are off by more than 3 %:
#: PWM 3000 by 4.9 % and PWM 3500 by 3.45 % (the ``eq5.8-slope-pwm*`` findings of ``zoo check``).
FIG_5_6_SLOPES = {2000: (-5.281e-5, 0.00956), 2500: (-4.6735e-5, 0.00309),
                  3000: (-4.066e-5, 0.0490), 3500: (-3.4585e-5, 0.0345)}


@pytest.mark.parametrize("pwm", sorted(FIG_5_6_SLOPES))
def test_fig_5_6_slopes_against_eq_5_8_and_the_consistency_finding(pwm):
    """Each Fig. 5.6 slope printed in §5.4.2 against eq 5.8, with the deviation ``zoo check``
    reports: PWM 2000 0.96 %, 2500 0.31 %, 3000 4.9 %, 3500 3.45 % (all within the 6 %
    tolerance)."""
    eq58, rel = FIG_5_6_SLOPES[pwm]
    stated = SLOPES_5_4_2[pwm]
    b = float(MOTOR.slope(pwm)) * RPM / NCM
    assert b == pytest.approx(1.215e-8 * pwm - 7.711e-5,
                              rel=1e-12) == pytest.approx(eq58, rel=1e-12)
    assert abs(b - stated) / abs(stated) == pytest.approx(rel, abs=5e-5)
    f = {x.check: x
         for x in zoo.build("dlr-hit-finger").consistency_checks()}[f"eq5.8-slope-pwm{pwm}"]
    assert f.consistent and f.tolerance == 0.06
    assert f.computed == pytest.approx(b, rel=1e-12) and f.stated == stated
    assert f.rel_error == pytest.approx(rel, abs=5e-5)


def test_eq_5_8_is_the_least_squares_line_through_the_fig_5_6_slopes():
    """Eq 5.8 (1.215e-8 Ncm/(rpm·PWM), −7.711e-5 Ncm/rpm) is the least-squares line of the four
    printed slopes within 0.3 % (the fit gives 1.2124e-8 and −7.7036e-5); the 4.9 % and 3.45 %
    deviations are its residuals."""
    pwm = np.array(sorted(SLOPES_5_4_2), dtype=float)
    slope, intercept = np.polyfit(pwm, [SLOPES_5_4_2[int(p)] for p in pwm], 1)
    assert slope == pytest.approx(1.215e-8, rel=3e-3)
    assert intercept == pytest.approx(-7.711e-5, rel=3e-3)


def test_appendix_e_guard():
    """Appendix E: if |speed term| exceeds |PWM term| the torque is zero; PWM 0 gives no torque."""
    # speed where the terms cancel (rad/s)
    w0 = 1.43e-4 * 2000 / -(1.215e-8 * 2000 - 7.711e-5) * RPM
    assert MOTOR.torque(2000, 0.99 * w0) > 0
    assert MOTOR.torque(2000, 1.01 * w0) == 0.0
    assert MOTOR.torque(0, 100.0) == 0.0
    assert MOTOR.torque(-2000, -1.01 * w0) == 0.0


def test_fig_5_7_temperature_drop():
    """Fig. 5.7: PWM 4000 held at stall gives ~1 Ncm at room temperature, falling below 0.6 Ncm
    as the motor reaches ~80 °C within the figure's 120 s."""
    tb = MotorTestBed(check=False)
    tr = tb.simulate(np.column_stack([np.full(1201, 4000.0), np.zeros(1201)]), dt=0.1)
    tau = tr["torque"] / NCM
    T = tr["temperature"] - 273.15
    assert tau[0] == pytest.approx(1.0, rel=0.03)
    assert tau[-1] < 0.6
    assert 75.0 < T[-1] < 90.0
    assert np.all(np.diff(tau) <= 1e-12)  # monotone decay while heating
    # eq 5.5: R(T) = R0(1 + α(T − T0))
    assert MOTOR.resistance(298.15 + 50) == pytest.approx(9.32 * (1 + 0.0136 * 50))


def test_consistency_reports_the_temperature_coefficient():
    f = {x.check: x for x in MOTOR.consistency_checks()}
    assert not f["fig5.7-temperature-coefficient"].consistent
    assert all(f[f"eq5.8-slope-pwm{p}"].consistent for p in SLOPES_5_4_2)


def test_transmissions_of_appendix_e():
    assert DLR_DISTAL.ratio == pytest.approx(208.3)
    assert DLR_BASE.ratio == pytest.approx(234.3375)
    assert DLR_DISTAL.reflected_inertia(5.1e-7) == pytest.approx(0.02213, rel=1e-3)
    hd = harmonic_drive(100, efficiency=0.8)
    assert hd.output_torque(0.01, 1.0) == pytest.approx(0.8)  # driving
    assert hd.output_torque(0.01, -1.0) == pytest.approx(1.25)  # back-driven
    with pytest.raises(ModelError, match="efficiency"):
        Transmission(10.0, 1.5)


def synthetic_test_bed(seed, noise_ncm=0.005):
    """Stall sweep PWM 0..4000 step 50 (§5.4.1) and torque-speed runs at PWM 2000..4000 with speeds
    0..2500 rpm (§5.4.2), generated with eqs 5.7/5.8 plus sensor noise (0.05 % of 5 Ncm, §5.3)."""
    rng = np.random.default_rng(seed)
    stall = np.arange(0, 4001, 50.0)
    t_stall = MOTOR.torque(stall, 0.0) + rng.normal(0, noise_ncm * NCM, stall.size)
    runs = []
    for pwm in (2000, 2500, 3000, 3500, 4000):
        w = np.repeat(np.arange(0, 2501, 500.0), 40) * RPM
        runs.append((pwm, w, MOTOR.torque(pwm, w) + rng.normal(0, noise_ncm * NCM, w.size)))
    return stall, t_stall, runs


def test_two_stage_characterisation_recovers_eqs_5_7_and_5_8():
    stall, t_stall, runs = synthetic_test_bed(1)
    ch = characterize_motor(stall, t_stall, runs)
    p = motor_parameters()
    assert abs(ch.c - p.value("c_pwm")) < 3 * ch.c_std and ch.c_std / ch.c < 0.005
    assert abs(ch.b1 - p.value("b_pwm")) < 3 * ch.b1_std
    assert abs(ch.b0 - p.value("b_0")) < 3 * ch.b0_std
    for pwm, slope, std in ch.table():
        assert slope == pytest.approx(MOTOR.slope(pwm) * RPM / NCM, abs=4 * std * RPM / NCM + 1e-9)


def test_one_shot_fit_with_std_matching_the_scatter():
    ests, stds = [], []
    for seed in range(20):
        stall, t_stall, runs = synthetic_test_bed(100 + seed, noise_ncm=0.02)
        u = np.concatenate([stall] + [np.full(r[1].size, r[0]) for r in runs])
        w = np.concatenate([np.zeros(stall.size)] + [r[1] for r in runs])
        t = np.concatenate([t_stall] + [r[2] for r in runs])
        fit = fit_motor(u, w, t)
        ests.append([fit.values[k] for k in ("c_pwm", "b_pwm", "b_0")])
        stds.append([fit.std[k] for k in ("c_pwm", "b_pwm", "b_0")])
    ests, stds = np.array(ests), np.array(stds)
    truth = motor_parameters().vector(["c_pwm", "b_pwm", "b_0"])
    np.testing.assert_allclose(ests.mean(0), truth, rtol=0.01)
    np.testing.assert_allclose(ests.std(0, ddof=1), stds.mean(0), rtol=0.4)
    c, _ = fit.thesis_units()["c_pwm"]
    assert c == pytest.approx(1.43e-4, rel=0.01)


def test_fit_with_temperature_recovers_alpha():
    """Heating runs (Fig. 5.2-like): torque at several PWM, speeds and temperatures, generated with
    eq 5.10 × R(T_ref)/R(T); the fit returns α of eq 5.5."""
    rng = np.random.default_rng(7)
    u = rng.choice([1500.0, 2500.0, 3500.0, 4000.0], 3000)
    w = rng.uniform(0, 2000, 3000) * RPM
    T = rng.uniform(298.15, 363.15, 3000)
    tau = MOTOR.torque(u, w, T) + rng.normal(0, 0.005 * NCM, 3000)
    fit = fit_motor(u, w, tau, T, T_ref=353.15, T_amb=298.15)
    assert abs(fit.values["alpha_R"] - 0.0136) < 3 * fit.std["alpha_R"]
    assert fit.values["c_pwm"] == pytest.approx(1.43e-6, rel=0.01)


def test_bad_motor_data():
    with pytest.raises(DataError, match="non-finite"):
        fit_motor([1000, 2000, np.nan], [0, 0, 0], [1, 2, 3])
    with pytest.raises(UnidentifiableError, match="collinear|excite"):
        fit_motor(np.full(20, 2000.0), np.zeros(20), np.ones(20))
    with pytest.raises(DataError, match="three or more"):
        characterize_motor([1000, 2000], [0.1, 0.2], [(2000, np.arange(5.0), np.arange(5.0))])
    assert math.isfinite(MOTOR.torque(10000, 0.0))


# --- power balance, eqs 5.1-5.6 (issue 28 item 3) -------------------------------------------------

def test_electrical_constants_reproduce_the_parameters():
    """k_t = V·|b(3000)|/(4096·c) and R(T_ref) = k_t²/|b(3000)| at the assumed 12 V: 7.955 mN·m/A
    and R₀ = 9.323 Ω, the parameters k_t = 7.95e-3 and R_0 = 9.32 to their printed digits;
    k_t ∝ V and R₀ ∝ V²."""
    kt, R0 = MOTOR.electrical_constants(12.0)
    b3000 = (1.215e-8 * 3000 - 7.711e-5) * NCM / RPM
    assert kt == pytest.approx(12.0 * abs(b3000) / (4096 * 1.43e-6), rel=1e-12)
    assert kt == pytest.approx(7.955e-3, abs=1e-6) and R0 == pytest.approx(9.323, abs=1e-3)
    assert kt == pytest.approx(MOTOR.parameters.value("k_t"), rel=1e-3)
    assert R0 == pytest.approx(MOTOR.parameters.value("R_0"), rel=1e-3)
    kt24, R24 = MOTOR.electrical_constants(24.0)
    assert kt24 == pytest.approx(2 * kt) and R24 == pytest.approx(4 * R0)


def test_power_balance_terms_at_pwm_4000():
    """Eqs 5.2-5.6 term by term at PWM 4000, 1000 rpm, T_ref, the parameters' k_t and R₀ (12 V):
    τ = 0.572 − 2.851e-5·1000 = 0.5435 Ncm, P_mech = π·τ[mN·m]·n/30000 = τ·ω = 0.5691 W,
    U = 12·4000/4096 = 11.72 V, I = τ/k_t = 0.6836 A, P_el = 8.011 W, P_J = R(T_ref)·I² = 7.614 W,
    P_F = P_el − P_mech − P_J = −0.1717 W (−30.2 % of P_mech)."""
    b = MOTOR.power_balance(4000.0, 1000.0)
    tau = (1.43e-4 * 4000 + (1.215e-8 * 4000 - 7.711e-5) * 1000) * NCM
    assert b.torque == pytest.approx(tau, rel=1e-12)
    assert tau / NCM == pytest.approx(0.54349, rel=1e-5)
    assert b.mechanical == pytest.approx(tau * 1000 * 2 * math.pi / 60, rel=1e-12)
    assert b.voltage == pytest.approx(12 * 4000 / 4096)
    assert b.current == pytest.approx(tau / 7.95e-3)
    assert b.electrical == pytest.approx(8.0114, abs=1e-4)
    R_ref = 9.32 * (1 + 0.0136 * 55)
    assert b.joule == pytest.approx(R_ref * (tau / 7.95e-3) ** 2, rel=1e-12)
    assert b.electrical == pytest.approx(b.mechanical + b.joule + b.friction, rel=1e-12)
    assert b.friction == pytest.approx(-0.1717, abs=1e-4)
    assert b.friction_fraction == pytest.approx(-0.3016, abs=1e-4)
    assert b.as_dict()["friction"][1] == "W" and b.as_dict()["speed"][1] == "rpm"


@pytest.mark.parametrize("volts", [6.0, 12.0, 24.0])
def test_friction_loss_is_negative_above_pwm_3000_at_any_voltage(volts):
    """With k_t and R derived for the supply voltage, P_F/P_mech = |b(u)|/|b(3000)| − 1 at every
    speed (derivation in BLDCMotor.power_balance): +29.9 %, +14.9 %, 0, −14.9 %, −29.9 % at PWM
    2000..4000."""
    pwm = np.array([2000.0, 2500.0, 3000.0, 3500.0, 4000.0])
    speed = np.array([[300.0], [1000.0], [2500.0]])
    frac = MOTOR.power_balance(pwm, speed, supply_voltage=volts).friction_fraction
    b = 1.215e-8 * pwm - 7.711e-5
    expected = np.abs(b) / abs(1.215e-8 * 3000 - 7.711e-5) - 1
    np.testing.assert_allclose(frac, np.broadcast_to(expected, frac.shape), atol=1e-12)
    np.testing.assert_allclose(expected, [0.2988, 0.1494, 0.0, -0.1494, -0.2988], atol=1e-4)


def test_zoo_check_reports_the_power_balance_and_the_speed_unit():
    f = {x.check: x for x in zoo.build("dlr-hit-finger", check=False).consistency_checks()}
    pb = f["eq5.6-power-balance"]
    assert not pb.consistent and pb.stated == 0.0
    assert pb.computed == pytest.approx(-0.2988, abs=1e-4)
    assert "-14.9% at PWM 3500" in pb.message and "-29.9% at PWM 4000" in pb.message
    su = f["fig5.6-speed-unit"]
    assert not su.consistent and su.computed == 180000.0 and su.stated == 6000.0
    assert "gripkit reads rpm" in su.used and "-3.7 Ncm" in su.message


def test_power_balance_bad_input():
    with pytest.raises(ModelError, match="speeds >= 0 rpm"):
        MOTOR.power_balance(3000.0, -10.0)
    with pytest.raises(ModelError, match="supply_voltage: expected a positive voltage"):
        MOTOR.electrical_constants(0.0)
