"""General second-order step-response identification (gain, natural frequency, damping, σ)."""

import math
import warnings

import numpy as np
import pytest
from scipy import signal

from gripkit import Trajectory
from gripkit.errors import AccuracyWarning, DataError
from gripkit.lti import TransferFunction
from gripkit.models.second_order import second_order_step
from gripkit.sysid.physical.step_response import identify_step, second_order_metrics, step_metrics

FS = 20000.0
# the FT-G100 actuated arm grasping the ball (eq 9 at the seed's values): 1757 Hz, ζ = 0.043
K, F_N, ZETA = 0.1889e-6, 1757.2, 0.0430


def record(seed, n=2000, noise=0.01, k=K, f=F_N, z=ZETA, amp=10.0, t_step=0.005, y0=3e-6):
    t = np.arange(n) / FS
    u = np.where(t >= t_step, 70 + amp, 70.0)
    y = y0 + second_order_step(t - t_step, k * amp, 2 * math.pi * f, z)
    y = y + noise * abs(k * amp) * np.random.default_rng(seed).standard_normal(n)
    return Trajectory(t, {"V": u, "x": y}, {"V": "V", "x": "m"})


def test_closed_form_matches_scipy_step():
    """second_order_step against scipy.signal.step for ζ = 0.043, 1 and 2."""
    for z in (0.043, 1.0, 2.0):
        wn = 2 * math.pi * 300
        t = np.linspace(0, 0.02, 500)
        _, ys = signal.step(([2.5 * wn * wn], [1, 2 * z * wn, wn * wn]), T=t)
        np.testing.assert_allclose(second_order_step(t, 2.5, wn, z), ys, atol=1e-8)


def test_metrics_match_textbook_formulas():
    """Overshoot exp(-πζ/√(1-ζ²)), peak time π/ω_d, 2 % settling ≈ 4/(ζ ω_n) (within one period)."""
    wn, z = 2 * math.pi * 100, 0.2
    m = second_order_metrics(wn, z)
    assert m["overshoot_percent"] == pytest.approx(100
                                                   * math.exp(-math.pi * z
                                                                  / math.sqrt(1 - z * z)), rel=1e-3)
    assert m["peak_time"] == pytest.approx(math.pi / (wn * math.sqrt(1 - z * z)), rel=1e-3)
    assert abs(m["settling_time"] - 4 / (z * wn)) < 2 * math.pi / wn


def test_recovers_gain_frequency_damping_within_3_sigma():
    """1 % noise on the FT-G100-like response: all three within 3σ and within 0.5 %."""
    r = identify_step(record(1), input="V", output="x")
    for est, sd, true in ((r.gain, r.gain_std, K),
                          (r.natural_frequency_hz, r.natural_frequency_hz_std, F_N),
                          (r.damping_ratio, r.damping_ratio_std, ZETA)):
        assert abs(est - true) < 3 * sd
        assert abs(est - true) / true < 0.005
    assert r.gain_unit == "m/V" and r.input_offset == 70.0
    assert r.offset == pytest.approx(3e-6, abs=5 * r.offset_std)
    np.testing.assert_allclose(r.covariance, r.covariance.T)
    assert np.all(np.linalg.eigvalsh(r.covariance) > -1e-30)


def test_transfer_function_is_the_fitted_second_order_system():
    """transfer_function() is an lti.TransferFunction K ω_n²/(s² + 2ζω_n s + ω_n²): its DC gain is
    K and its poles have the fitted ω_n and ζ (analytic: s = −ζω_n ± jω_n√(1−ζ²))."""
    r = identify_step(record(1), input="V", output="x")
    g = r.transfer_function()
    assert type(g) is TransferFunction and not g.is_discrete and g.meta["gain_unit"] == "m/V"
    assert float(g.dc_gain()[0, 0]) == pytest.approx(r.gain, rel=1e-12)
    d = g.damping()
    np.testing.assert_allclose(d.wn, r.natural_frequency, rtol=1e-12)
    np.testing.assert_allclose(d.zeta, r.damping_ratio, rtol=1e-9)


def test_sigma_agrees_with_monte_carlo():
    """Reported σ vs the spread of 30 noisy repetitions (within 35 %: 30 draws give the sample std
    to
    about ±13 %)."""
    est, sds = [], []
    for seed in range(30):
        r = identify_step(record(100 + seed, n=800), input="V", output="x")
        est.append([r.gain, r.natural_frequency_hz, r.damping_ratio])
        sds.append([r.gain_std, r.natural_frequency_hz_std, r.damping_ratio_std])
    np.testing.assert_allclose(np.std(est, axis=0, ddof=1), np.mean(sds, axis=0), rtol=0.35)


def test_overdamped_and_negative_gain():
    r = identify_step(record(3, k=-2.0, f=80.0, z=1.8, amp=1.0, y0=0.0), input="V", output="x")
    assert r.gain == pytest.approx(-2.0, rel=0.01)
    assert r.damping_ratio == pytest.approx(1.8, rel=0.05)
    assert r.natural_frequency_hz == pytest.approx(80.0, rel=0.05)
    assert r.overshoot_percent == 0.0 and math.isinf(r.peak_time)


def test_step_metrics_on_data():
    t = np.linspace(0, 0.05, 5001)
    y = second_order_step(t, 1.0, 2 * math.pi * 200, 0.3)
    m = step_metrics(t, y, y_final=1.0, y_initial=0.0)
    assert m["overshoot_percent"] == pytest.approx(100
                                                   * math.exp(-math.pi * 0.3
                                                                  / math.sqrt(1 - 0.09)), rel=1e-3)
    assert math.isinf(step_metrics(t[:300], y[:300], y_final=1.0, y_initial=0.0)["settling_time"])


def test_bad_data():
    t = np.arange(200) / FS
    const = (Trajectory(t, {"V": np.full(200, 70.0),
                            "x": np.random.default_rng(0).standard_normal(200)}))
    with pytest.raises(DataError, match="input column 'V' is constant"):
        identify_step(const, input="V", output="x")
    flat = Trajectory(t, {"V": np.where(t > 0.001, 1.0, 0.0), "x": np.zeros(200)})
    with pytest.raises(DataError, match="does not change"):
        identify_step(flat, input="V", output="x")
    with pytest.raises(DataError, match="not found"):
        identify_step(const, input="V", output="y")
    with pytest.raises(DataError, match="at least 20 samples"):
        identify_step(Trajectory(t[:10], {"V": np.arange(10.0), "x": np.arange(10.0)}), input="V",
                      output="x")
    with pytest.raises(DataError, match="uniform sampling"):
        tt = np.cumsum(np.r_[0, np.full(99, 1e-3), 5e-3, np.full(99, 1e-3)])
        identify_step(Trajectory(tt, {"V": (tt > 0.05) * 1.0, "x": np.sin(tt)}), input="V",
                      output="x")


def test_record_too_short_warns():
    """A record that ends long before the response settles: the gain is extrapolated -> warning."""
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        identify_step(record(4, n=160, f=300.0, z=0.05, t_step=0.001), input="V", output="x")
    assert any(issubclass(x.category, AccuracyWarning) and "settles" in str(x.message) for x in w)
