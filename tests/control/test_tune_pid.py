"""PID tuning by Skogestad's SIMC rules (issue 27; S. Skogestad, J. Process Control 13 (2003)
291–309): Table 1's settings exactly on known first- and second-order models with delay, the half
rule (eqs 8–10) recovering known time constants and delay from ZOH-sampled models, and the
loop's margins on a first-order process with delay against the analytic L = e^{−θs}/(2θ s)
(τ_c = θ, τ_I = τ₁): gain margin π, phase margin 90° − (1/2 rad)."""

import math
import warnings

import numpy as np
import pytest

from gripkit.control import LowOrderModel, reduce_model, robustness, tune_pid
from gripkit.control.pid import PIDX
from gripkit.errors import ArgumentError, ModelError
from gripkit.lti import TransferFunction


def test_simc_first_order_settings_are_table_1():
    """k = 2, τ₁ = 10 s, θ = 1 s: τ_c = θ gives K_c = 10/(2·2) = 2.5, τ_I = min(10, 8) = 8 s;
    τ_c = 3 s gives K_c = 10/(2·4) = 1.25, τ_I = min(10, 16) = 10 s (a PI: k_d = 0). hold=True:
    θ is the design's delay as given (tune_pid adds no h/2)."""
    m = LowOrderModel(2.0, 10.0, 1.0, dt=0.1, hold=True)
    pid = tune_pid(m)
    assert (pid.kp, pid.ki, pid.kd, pid.dt) == (2.5, 2.5 / 8.0, 0.0, 0.1)
    assert pid.design["Kc"] == 2.5 and pid.design["tau_I"] == 8.0
    pid = tune_pid(m, tau_c=3.0)
    assert (pid.kp, pid.ki, pid.kd) == (1.25, 1.25 / 10.0, 0.0)


def test_simc_second_order_and_integrating_settings_are_table_1():
    """SOPTD k = 1, τ₁ = 5, τ₂ = 0.5, θ = 0.2, τ_c = 0.2: series K_c = 12.5, τ_I = 1.6,
    τ_D = 0.5, parallel k_p = K_c(1 + τ_D/τ_I), k_i = K_c/τ_I, k_d = K_c τ_D. Integrating with lag
    k′ = 0.5, τ₂ = 0.1, θ = 0.3, τ_c = 0.3: K_c = 1/(0.5·0.6), τ_I = 2.4, τ_D = 0.1 (hold=True:
    θ as given)."""
    pid = tune_pid(LowOrderModel(1.0, 5.0, 0.2, 0.5, dt=0.01, hold=True), tau_c=0.2)
    assert pid.kp == pytest.approx(12.5 * (1 + 0.5 / 1.6), rel=1e-15)
    assert pid.ki == pytest.approx(12.5 / 1.6, rel=1e-15)
    assert pid.kd == pytest.approx(6.25, rel=1e-15)
    pid = tune_pid(LowOrderModel(0.5, 0.0, 0.3, 0.1, dt=0.01, integrating=True, hold=True))
    Kc = 1 / (0.5 * 0.6)
    assert pid.kp == pytest.approx(Kc * (1 + 0.1 / 2.4), rel=1e-15)
    assert pid.ki == pytest.approx(Kc / 2.4, rel=1e-15)
    assert pid.kd == pytest.approx(Kc * 0.1, rel=1e-15)


def _foptd(k=2.0, tau=0.5, delay=10, h=0.01):
    """ZOH sample of k e^{−θ₀s}/(τs + 1), θ₀ = delay·h: b q^{−(delay+1)}/(1 − a q⁻¹)."""
    a = math.exp(-h / tau)
    return TransferFunction.from_polynomials([1.0, -a], np.r_[np.zeros(delay + 1), k * (1 - a)],
                                             dt=h)


def test_half_rule_recovers_a_sampled_first_order_process_with_delay():
    m = reduce_model(_foptd(), 1)
    assert m.k == pytest.approx(2.0, rel=1e-12) and m.tau1 == pytest.approx(0.5, rel=1e-12)
    assert m.theta == pytest.approx(10 * 0.01 + 0.005, rel=1e-12)  # θ₀ + h/2
    assert m.tau2 == 0.0 and not m.integrating


def test_half_rule_on_three_lags():
    """1/((s + 1)(0.2 s + 1)(0.05 s + 1)) sampled at h = 0.05 s: first order τ₁ = 1 + 0.1,
    θ = 0.1 + 0.05 + h/2; second order τ₁ = 1, τ₂ = 0.2 + 0.025, θ = 0.025 + h/2 (eqs 9, 10)."""
    h = 0.05
    den = np.polymul(np.polymul([1.0, 1.0], [0.2, 1.0]), [0.05, 1.0])
    g = TransferFunction([1.0], den).c2d(h)
    m1, m2 = reduce_model(g, 1), reduce_model(g, 2)
    np.testing.assert_allclose([m1.k, m1.tau1, m1.theta], [1.0, 1.1, 0.175], rtol=1e-9)
    np.testing.assert_allclose([m2.tau1, m2.tau2, m2.theta], [1.0, 0.225, 0.05], rtol=1e-9)
    from gripkit.errors import AccuracyWarning

    with pytest.warns(AccuracyWarning, match="gain margin 1.61 and phase margin 22.8°"):
        assert tune_pid(g).kd > 0  # τ_c = θ = 0.05 s is tight for this loop (h = 0.05 s)
    assert tune_pid(g, order=1).kd == 0.0


def test_simc_loop_margins_on_a_first_order_process_with_delay():
    """τ₁ = 0.5 s ≤ 8θ: τ_I = τ₁ cancels the lag and L(s) = e^{−θs}/(2θ s): gain margin π
    (phase −180° at ωθ = π/2) and phase margin 90° − 28.65° (gain crossover at ω = 1/(2θ)).
    The discrete loop (θ = 10.5 samples) is within 1.5 % and 0.5° of that."""
    g = _foptd()
    pid = tune_pid(g)
    assert pid.dt == 0.01 and pid.kd == 0.0
    r = robustness(g, pid, n=0)
    assert r.stable
    assert r.nominal["gain_margin"] == pytest.approx(math.pi, rel=0.015)
    assert r.nominal["phase_margin_deg"] == pytest.approx(90 - math.degrees(0.5), abs=0.5)


def test_models_the_rules_do_not_cover_are_refused():
    osc = TransferFunction.from_polynomials(np.poly([0.9 + 0.2j, 0.9 - 0.2j]).real, [0, 1.0, 0.5],
                                            dt=0.01)
    with pytest.raises(ModelError, match="complex poles"):
        tune_pid(osc)
    with pytest.raises(ModelError, match="outside"):
        tune_pid(TransferFunction.from_polynomials([1.0, -1.2], [0.0, 1.0], dt=0.01))
    with pytest.raises(ArgumentError, match="tau_c: expected a closed-loop time constant"):
        tune_pid(LowOrderModel(1.0, 1.0, 0.1, dt=0.01), tau_c=-1.0)
    with pytest.raises(ArgumentError, match="method: expected 'simc'"):
        tune_pid(_foptd(), method="ziegler")


def test_half_rule_with_zeros_is_skogestads_example():
    """Skogestad 2003, §3's example g₀ = (−0.3s + 1)(0.08s + 1)/((2s + 1)(s + 1)(0.4s + 1)
    (0.2s + 1)(0.05s + 1)³): the inverse-response zero adds 0.3 to θ, the zero 0.08 cancels
    against 0.2 by rule R3 (leaving a lag 0.12); first order τ₁ = 2.5, θ = 1.47; second order
    τ₁ = 2, τ₂ = 1.2, θ = 0.77 (the paper's figures), here sampled at h = 0.05 s, + h/2."""
    num = np.polymul([-0.3, 1.0], [0.08, 1.0])
    den = np.polymul(np.polymul([2.0, 1.0], [1.0, 1.0]), np.polymul([0.4, 1.0], [0.2, 1.0]))
    den = np.polymul(den, np.polymul(np.polymul([0.05, 1.0], [0.05, 1.0]), [0.05, 1.0]))
    g = TransferFunction(num, den).to_ss(minimal=False).c2d(0.05)
    m1, m2 = reduce_model(g, 1), reduce_model(g, 2)
    np.testing.assert_allclose([m1.k, m1.tau1, m1.theta], [1.0, 2.5, 1.47 + 0.025], rtol=1e-6)
    np.testing.assert_allclose([m2.tau1, m2.tau2, m2.theta], [2.0, 1.2, 0.77 + 0.025], rtol=1e-6)
    assert "zero T0=0.08 s cancelled (rule R3)" in m1.notes


def test_an_integrating_model_keeps_its_integrator():
    """0.5 q⁻²/((1 − q⁻¹)(1 − 0.8 q⁻¹)) at h = 0.01 s: k′ = B(1)/(A′(1) h) = 0.5/(0.2·0.01) =
    250 /s, the lag τ₂ = −h/ln 0.8, θ = h + h/2; SIMC: K_c = 1/(k′(τ_c + θ)), τ_I = 4(τ_c + θ)."""
    h = 0.01
    g = TransferFunction.from_polynomials(np.polymul([1.0, -1.0], [1.0, -0.8]), [0.0, 0.0, 0.5],
                                          dt=h)
    m = reduce_model(g, 2)
    assert m.integrating and m.k == pytest.approx(250.0, rel=1e-9)
    assert m.tau2 == pytest.approx(-h / math.log(0.8), rel=1e-9)
    assert m.theta == pytest.approx(1.5 * h, rel=1e-9)
    pid = tune_pid(g)
    Kc, ti = 1 / (250.0 * 2 * m.theta), 8 * m.theta
    assert pid.ki == pytest.approx(Kc / ti, rel=1e-9) and pid.kd == pytest.approx(Kc * m.tau2,
                                                                                 rel=1e-9)


def _closed_loop_step(A, B, pid, n=1500):
    """The sampled loop y = B/A u, u = pid(r = 1, y): the output at every sample."""
    y, u = np.zeros(n), np.zeros(n)
    for t in range(n):
        y[t] = (-sum(A[i] * y[t - i] for i in range(1, len(A)) if t >= i)
                + sum(B[j] * u[t - j] for j in range(1, len(B)) if t >= j))
        u[t] = pid.step(1.0, y[t])
    return y


def test_an_exact_integrator_with_delay_tunes_to_simc_margins():
    """0.05 q⁻³/(1 − q⁻¹) at h = 0.01 s (audit: d2c refused the pole at z = 0 of the realisation
    of 0.05 q⁻¹ left after the integrator): k′ = 0.05/h = 5 /s, θ = 2h + h/2 (the delay, not a
    lag). τ_c = θ on k′e^{−θs}/s gives L = e^{−θs}(1 + 1/(8θs))/(2θs): gain margin 2.963 and
    phase margin 46.86° (solved from L; Skogestad's §4.3 'about 3 and 47°', the promise of the
    module docstring); the discrete loop is within 2 % and 0.5° of that, and its simulated step
    response settles at the setpoint."""
    h = 0.01
    g = TransferFunction.from_polynomials([1.0, -1.0], [0.0, 0.0, 0.0, 0.05], dt=h)
    m = reduce_model(g, 2)
    assert m.integrating and m.k == pytest.approx(5.0, rel=1e-12)
    assert (m.tau1, m.tau2) == (0.0, 0.0) and m.theta == pytest.approx(2.5 * h, rel=1e-12)
    pid = tune_pid(g)
    assert pid.kp == pytest.approx(1 / (5.0 * 2 * 0.025), rel=1e-12) and pid.kd == 0.0
    r = robustness(g, pid, n=0)
    assert r.stable
    assert r.nominal["gain_margin"] == pytest.approx(2.963, rel=0.02)
    assert r.nominal["phase_margin_deg"] == pytest.approx(46.86, abs=0.5)
    y = _closed_loop_step([1.0, -1.0], [0.0, 0.0, 0.0, 0.05], pid)
    assert np.all(np.abs(y) < 2.0) and np.max(np.abs(y[-200:] - 1.0)) < 1e-6


def test_an_estimated_integrator_within_its_sigma_is_one():
    """ARX on 0.05 q⁻²/(1 − q⁻¹) with noise 1e-3: the pole is estimated at 1 + 8.7e-8, σ 1.05e-5
    (beyond the 1e-9 rule, so it was refused as unstable): within 3σ of 1 it is the integrator,
    and the result's notes say so; k′ = b/h within 0.1 %."""
    from scipy.signal import lfilter

    from gripkit import sysid

    rng = np.random.default_rng(0)
    u = rng.standard_normal(3000)
    y = lfilter([0.0, 0.0, 0.05], [1.0, -1.0], u) + 1e-3 * rng.standard_normal(3000)
    est = sysid.arx(u, y, 1, 1, 2, dt=0.01)
    assert 1.0 + 1e-9 < -est.A[1] < 1.0 + est.A_std[1]
    pid = tune_pid(est)
    notes = pid.design["model"]["notes"]
    assert pid.design["model"]["integrating"] and pid.design["model"]["k"] == pytest.approx(
        5.0, rel=1e-3)
    assert any("within 3σ of 1: taken as an integrator" in n for n in notes)


def test_a_truly_unstable_estimated_pole_is_still_refused():
    """A pole at 1.05 estimated with σ ≈ 6e-7 lies ~1e5 σ beyond 1: refused, the σ shown."""
    from scipy.signal import lfilter

    from gripkit import sysid

    rng = np.random.default_rng(0)
    u = rng.standard_normal(200)
    y = lfilter([0.0, 0.05], [1.0, -1.05], u) + 1e-3 * rng.standard_normal(200)
    with pytest.raises(ModelError, match=r"poles \[1\.05 ± .*\] outside \(0, 1\) \(unstable"):
        tune_pid(sysid.arx(u, y, 1, 1, 1, dt=0.01))


def test_numerator_taps_beyond_the_lag_order_are_a_delay():
    """0.05 (q⁻² + q⁻³)/(1 − 0.9 q⁻¹) (nb > na: the realisation's pole at z = 0 has no
    continuous equivalent): τ₁ = −h/ln 0.9 exact, k = B(1)/A(1) = 1, and the taps' first moment
    (half a sample; the ZOH lag's own single tap has moment 0) adds h/2 to θ = (nk − 1) h + h/2.
    A pure delay (no lag at all) is SIMC's integral controller, not d2c (its own tests below)."""
    h = 0.01
    tau = -h / math.log(0.9)
    m = reduce_model(TransferFunction.from_polynomials([1.0, -0.9], [0, 0, 0.05, 0.05], dt=h), 1)
    assert m.k == pytest.approx(1.0, rel=1e-12) and m.tau1 == pytest.approx(tau, rel=1e-9)
    assert m.theta == pytest.approx(h + 0.5 * h + h / 2, rel=1e-9)
    assert "taken as a delay of 0.005 s (first moment)" in m.notes[0]
    pid = tune_pid(TransferFunction.from_polynomials([1.0], [0.0, 0.0, 0.3], dt=h))
    assert pid.design["structure"] == "I" and "no lag left" in pid.design["model"]["notes"][-1]


def test_unknown_pid_options_name_the_valid_ones():
    """The docstring said '(limits, tf, b, c)'; limits= raised a bare TypeError from PID."""
    with pytest.raises(ArgumentError, match=r"unknown option\(s\) limits; the PID options are "
                                            r"u_min, u_max, tf, b, c, tt"):
        tune_pid(_foptd(), limits=(-1.0, 1.0))
    pid = tune_pid(_foptd(), u_min=-1.0, u_max=1.0, b=0.5)
    assert pid.limits == (-1.0, 1.0) and float(pid._p[PIDX.b]) == 0.5


def test_taps_beyond_a_second_order_lag_are_their_extra_mean_delay():
    """1/((s + 1)(0.5 s + 1)) ZOH-sampled at h = 0.1 s, its numerator convolved with
    (1 + q⁻¹)/2 (a two-tap average: half a sample of mean delay, and a tap more than A's order):
    the time constants 1 and 0.5 s come back exact, k = 1, and θ = h/2 (the taps' first moment
    beyond the lag's own ZOH taps) + h/2 (the controller's hold); second order: τ₂ = 0.5 s."""
    h = 0.1
    g = TransferFunction([1.0], np.polymul([1.0, 1.0], [0.5, 1.0])).c2d(h)
    A, B = g.den_zinv(), np.convolve(g.num_zinv(), [0.5, 0.5])
    m = reduce_model(TransferFunction.from_polynomials(A, B, dt=h), 2)
    np.testing.assert_allclose([m.k, m.tau1, m.tau2, m.theta], [1.0, 1.0, 0.5, h], rtol=1e-9)


def _delay(d: int, k: float = 0.3, h: float = 0.01):
    """The static gain with delay k q⁻ᵈ (an FIR model with one tap)."""
    return TransferFunction.from_polynomials([1.0], np.r_[np.zeros(d), k], dt=h)


def _python_control_margins(g, pid):
    """Gain and phase margin of the discrete loop C G by python-control (the reference)."""
    import control  # python-control: a dependency of the project (pyproject.toml)

    from gripkit.control.robustness import controller_transfer_function

    num, den, dt = controller_transfer_function(pid)
    with warnings.catch_warnings():  # its evaluation at the PID's pole z = 0 divides by zero
        warnings.simplefilter("ignore", RuntimeWarning)
        loop = control.tf(num, den, dt) * control.tf(g.num[0, 0], g.den[0, 0], dt)
        return control.stability_margins(loop, method="poly")[:2]


def test_a_pure_delay_gets_simcs_integral_controller():
    """0.3 q⁻²¹ at h = 0.01 s (no lag: it was refused with 'use PID(0, ki) by hand'): SIMC's
    I-controller k_i = 1/(k (τ_c + θ)), τ_c = θ, θ = 20h (the delay) + h/2 (the hold) + h (the
    integral's own sample, k_i h/(z − 1)); k_p = k_d = 0. Its loop is L ≈ e^{−θs}/(2θs): gain
    margin π (phase −180° at ωθ = π/2), phase margin 90° − (1/2 rad) = 61.35°; the discrete
    loop's margins, recorded in pid.design, are python-control's to 1e-8 and within 0.1 % and
    0.01° of those; the simulated step settles at the setpoint, and no warning."""
    g = _delay(21)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        pid = tune_pid(g)
    theta = 20 * 0.01 + 0.005 + 0.01
    assert pid.design["model"]["theta"] == pytest.approx(theta, rel=1e-12)
    assert pid.ki == pytest.approx(1.0 / (0.3 * 2 * theta), rel=1e-12)
    assert (pid.kp, pid.kd, pid.design["structure"]) == (0.0, 0.0, "I")
    margins = pid.design["margins"]
    gm, pm = _python_control_margins(g, pid)
    assert margins["gain_margin"] == pytest.approx(gm, rel=1e-8)
    assert margins["phase_margin_deg"] == pytest.approx(pm, rel=1e-8)
    assert margins["gain_margin"] == pytest.approx(math.pi, rel=1e-3)
    assert margins["phase_margin_deg"] == pytest.approx(90 - math.degrees(0.5), abs=0.01)
    assert margins["stable"] is True
    y = _closed_loop_step([1.0], np.r_[np.zeros(21), 0.3], pid, n=1500)
    assert np.max(y) < 1.05 and np.max(np.abs(y[-300:] - 1.0)) < 1e-6  # overshoot 4.05 %


def test_a_one_sample_delay_gets_a_stable_integral_loop():
    """0.3 q⁻¹: θ = h/2 + h. Without the integral's sample in θ the rule gives k_i h k = 1 and
    the closed-loop poles z² − z + 1 = 0 on the unit circle; with it k_i h k = 1/3:
    L = (1/3)/(z(z − 1)), poles |z| = 1/√3, gain margin 3 exactly (L = −1/3 at ωh = π/3) and
    phase margin 90° − 3 asin(1/6) = 61.22° (|z − 1| = 1/3); the step settles."""
    g = _delay(1)
    pid = tune_pid(g)
    assert pid.ki * 0.01 * 0.3 == pytest.approx(1.0 / 3.0, rel=1e-12)
    margins = pid.design["margins"]
    assert margins["gain_margin"] == pytest.approx(3.0, rel=1e-9)
    assert margins["w_gain_margin"] == pytest.approx(math.pi / 3 / 0.01, rel=1e-9)
    assert margins["phase_margin_deg"] == pytest.approx(90 - 3 * math.degrees(math.asin(1 / 6)),
                                                        abs=1e-6)
    r = robustness(g, pid, n=0)
    np.testing.assert_allclose(np.sort(np.abs(r.poles)), [0.0, 3 ** -0.5, 3 ** -0.5],
                               rtol=1e-9, atol=1e-12)  # the PID's pole at z = 0 besides
    y = _closed_loop_step([1.0], [0.0, 0.3], pid, n=200)
    assert np.max(np.abs(y[-50:] - 1.0)) < 1e-9


def test_a_pure_delay_low_order_model_and_its_bad_forms():
    """LowOrderModel(k = 2, τ₁ = 0, θ = 0.5 s) at h = 0.01 s: θ = 0.5 + h/2 (hold) + h (the
    integral's sample) = 0.515 s in the design, k_i = 1/(2 (2 · 0.515)); the loop on the exact
    ZOH sample 2 z⁻⁵⁰ is L = (1/103)/(z⁵⁰ (z − 1)) (k_i h k = 1/103): phase −180° at
    50.5 ωh = π/2, gain margin 206 sin(π/202) = 3.204 (SIMC's π on e^{−θs}/(2θs); the sample
    2 z⁻⁵⁰ reads as 49.5 h + h/2 to the half rule, half a sample less than designed for), phase
    margin 90° − 101 asin(1/206) = 61.91°, python-control's to 1e-8, and stable. τ₁ = 0 with
    θ = 0 or with τ₂ > 0 is no model the rules know: an ArgumentError."""
    pid = tune_pid(LowOrderModel(2.0, 0.0, 0.5, dt=0.01))
    assert pid.design["model"]["theta"] == pytest.approx(0.515, rel=1e-12)
    assert (pid.kp, pid.kd) == (0.0, 0.0)
    assert pid.ki == pytest.approx(1.0 / (2.0 * 2 * 0.515), rel=1e-12)
    margins = pid.design["margins"]
    gm, pm = _python_control_margins(_delay(50, k=2.0), pid)
    assert margins["gain_margin"] == pytest.approx(gm, rel=1e-8)
    assert margins["phase_margin_deg"] == pytest.approx(pm, rel=1e-8)
    assert margins["gain_margin"] == pytest.approx(206 * math.sin(math.pi / 202), rel=1e-9)
    assert margins["phase_margin_deg"] == pytest.approx(
        90 - 101 * math.degrees(math.asin(1 / 206)), abs=1e-7)
    assert margins["stable"] is True
    for args in ((1.0, 0.0, 0.0), (1.0, 0.0, 0.1, 0.2)):
        with pytest.raises(ArgumentError, match=r"tau1 = tau2 = 0 with theta > 0: a pure delay"):
            LowOrderModel(*args, dt=0.01)


def test_the_margins_are_recorded_and_simcs_promise_holds_on_a_first_order_process():
    """The first-order process with delay of test_simc_loop_margins…: pid.design['margins']
    holds the loop's margins (those of robustness, python-control's to 1e-8) and no warning
    is given (π and 61°, the case SIMC is exact for)."""
    g = _foptd()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        pid = tune_pid(g)
    gm, pm = _python_control_margins(g, pid)
    assert pid.design["margins"]["gain_margin"] == pytest.approx(gm, rel=1e-8)
    assert pid.design["margins"]["phase_margin_deg"] == pytest.approx(pm, rel=1e-8)
    assert pid.design["structure"] == "PI"


def test_low_margins_on_a_second_order_arx_warn_with_a_tau_c_that_restores_them():
    """(0.2 q⁻¹ + 0.15 q⁻²)/(1 − 1.5 q⁻¹ + 0.56 q⁻²) at h = 0.01 s (poles 0.8, 0.7; a zero that
    rule R3 cancels): the SIMC PID has gain margin 1.833 and phase margin 29.1° on it
    (python-control's to 1e-8), well below SIMC's 3 and 47°: one AccuracyWarning with the
    numbers and the first τ_c of 2θ, 3θ … that clears 2 and 30° (τ_c = 2θ = 0.01 s: 2.8 and
    49.6°, which tune_pid then gives without a warning)."""
    from gripkit.errors import AccuracyWarning

    g = TransferFunction.from_polynomials([1.0, -1.5, 0.56], [0.0, 0.2, 0.15], dt=0.01)
    with pytest.warns(AccuracyWarning) as caught:
        pid = tune_pid(g)
    assert len(caught) == 1
    message = str(caught[0].message)
    gm, pm = _python_control_margins(g, pid)
    assert pid.design["margins"]["gain_margin"] == pytest.approx(gm, rel=1e-8)
    assert pid.design["margins"]["phase_margin_deg"] == pytest.approx(pm, rel=1e-8)
    assert gm == pytest.approx(1.833, abs=5e-4) and pm == pytest.approx(29.14, abs=0.01)
    assert "gain margin 1.83 and phase margin 29.1°" in message and "\n" not in message
    assert "tau_c=0.01 s gives 2.8 and 49.6°" in message
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        again = tune_pid(g, tau_c=0.01)
    assert again.design["margins"]["gain_margin"] == pytest.approx(2.8, abs=0.005)
    assert again.design["margins"]["phase_margin_deg"] == pytest.approx(49.6, abs=0.05)


def test_a_phase_crossover_at_the_nyquist_frequency_counts():
    """0.05 q⁻¹/(1 − 0.98 q⁻¹) at h = 0.01 s with SIMC's PI: L(z) = C(z) G(z) is real at z = −1
    and negative there, the phase −180° exactly at ω = π/h (no interior crossover). The gain
    margin is 1/|L(−1)| (C and G evaluated at z = −1 by hand: 1.704 for τ_c = 0.002 s, 1.333
    for τ_c = 0), equal to python-control's 1/|L(e^{jπ})| from its frequency response (phase
    −180° there); it was inf (the grid stopped short of π/h). The phase margin stays
    python-control's stability_margins' to 1e-8; both τ_c warn (gain margin below 2), the
    message giving the finite gain margin."""
    import control  # python-control: a dependency of the project (pyproject.toml)

    from gripkit.control.robustness import controller_transfer_function
    from gripkit.errors import AccuracyWarning

    h = 0.01
    g = TransferFunction.from_polynomials([1.0, -0.98], [0.0, 0.05], dt=h)
    for tau_c, expected, shown in ((0.002, 1.7044, "1.7"), (0.0, 1.33338, "1.33")):
        with pytest.warns(AccuracyWarning) as caught:
            pid = tune_pid(g, tau_c=tau_c)
        num, den, _ = controller_transfer_function(pid)
        by_hand = 1.0 / abs(np.polyval(num, -1.0) / np.polyval(den, -1.0) * 0.05 / (-1.0 - 0.98))
        with warnings.catch_warnings():  # python-control evaluates the PID's pole z = 0
            warnings.simplefilter("ignore", RuntimeWarning)
            loop = control.tf(num, den, h) * control.tf([0.05], [1.0, -0.98], h)
            mag, phase, _ = control.frequency_response(loop, [math.pi / h])
            pm = control.stability_margins(loop, method="poly")[1]
        margins = pid.design["margins"]
        assert margins["gain_margin"] == pytest.approx(by_hand, rel=1e-12)
        assert margins["gain_margin"] == pytest.approx(1.0 / float(mag[0]), rel=1e-12)
        assert abs(abs(math.degrees(float(phase[0]))) - 180.0) < 1e-9
        assert margins["gain_margin"] == pytest.approx(expected, abs=1e-4)
        assert margins["w_gain_margin"] == pytest.approx(math.pi / h, rel=1e-15)
        assert margins["phase_margin_deg"] == pytest.approx(pm, rel=1e-8)
        assert len(caught) == 1 and f"gain margin {shown} and" in str(caught[0].message)


def test_a_hand_made_model_is_tuned_as_its_zoh_sample_is():
    """k e^{−θ₀s}/(τs + 1) (k = 2, τ = 0.5 s, θ₀ = 0.1 s, h = 0.01 s) given as a LowOrderModel
    gets the PI of its ZOH sample b q⁻¹¹/(1 − a q⁻¹) (identified path: θ = θ₀ + h/2): the same
    gains (1e-9) and θ = 0.105 s; its margins are those of that discrete loop, python-control's
    (c2d of the lag, zoh, times z⁻¹⁰) to 1e-8. The same for the pure delay 0.3 e^{−0.2s} and
    0.3 q⁻²¹ (θ = 0.2 + h/2 + h). A fractional delay θ₀ = 0.105 s samples to
    (b₀ z + b₁) z⁻¹¹/(z − a) with b₀ = k(1 − e^{−(h − ε)/τ}), b₀ + b₁ = k(1 − a), ε = 0.005 s."""
    import control  # python-control: a dependency of the project (pyproject.toml)

    h, a = 0.01, math.exp(-0.01 / 0.5)
    hand = tune_pid(LowOrderModel(2.0, 0.5, 0.1, dt=h))
    ident = tune_pid(_foptd())
    assert hand.design["model"]["theta"] == pytest.approx(0.105, rel=1e-12)
    np.testing.assert_allclose([hand.kp, hand.ki, hand.kd], [ident.kp, ident.ki, ident.kd],
                               rtol=1e-9)
    lag = control.c2d(control.tf([2.0], [0.5, 1.0]), h, "zoh")
    gd = TransferFunction(np.asarray(lag.num[0][0], float),
                          np.r_[np.asarray(lag.den[0][0], float), np.zeros(10)], dt=h)
    gm, pm = _python_control_margins(gd, hand)
    assert hand.design["margins"]["gain_margin"] == pytest.approx(gm, rel=1e-8)
    assert hand.design["margins"]["phase_margin_deg"] == pytest.approx(pm, rel=1e-8)
    assert hand.design["margins"]["stable"] is True
    delay = tune_pid(LowOrderModel(0.3, 0.0, 0.2, dt=h))
    assert delay.ki == pytest.approx(tune_pid(_delay(21)).ki, rel=1e-12)
    gm, pm = _python_control_margins(_delay(20), delay)
    assert delay.design["margins"]["gain_margin"] == pytest.approx(gm, rel=1e-8)
    frac = LowOrderModel(2.0, 0.5, 0.105, dt=h).sampled_plant()
    b0 = 2.0 * (1.0 - math.exp(-0.005 / 0.5))
    np.testing.assert_allclose(frac.num[0, 0][-2:], [b0, 2.0 * (1.0 - a) - b0], rtol=1e-12)
    np.testing.assert_allclose(frac.den[0, 0][:2], [1.0, -a], rtol=1e-12)
    assert frac.relative_degree() == 11
