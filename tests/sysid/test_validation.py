"""Validation: fit %, free-run simulation with initial conditions (never silently zero),
unstable models, residual whiteness and independence tests."""

import numpy as np
import pytest
from arx_cases import A222, B222, simulate_arx
from scipy.signal import lfilter

from gripkit import DataError
from gripkit.errors import ArgumentError, StabilityWarning
from gripkit.sysid import PolynomialModel, arx, compare, fit_percent, residual_tests

TRUE = PolynomialModel.from_coefficients(A222, B222, dt=0.005)  # Table II [2 2 2]


def test_fit_percent_definition():
    y = np.array([1.0, 2.0, 3.0, 4.0])
    assert fit_percent(y, y) == 100.0
    assert fit_percent(y, np.full(4, 2.5)) == pytest.approx(0.0)
    assert fit_percent(y, y + 1.0) == pytest.approx(100 * (1 - 2 / np.sqrt(5)))
    with pytest.raises(DataError, match="constant output"):
        fit_percent(np.ones(4), np.ones(4))


def test_initial_conditions_estimated_not_zero():
    """A record that starts in the middle of a response: compare() is model.compare (initial
    state estimated by least squares) and fits exactly; a free run from rest misses the start,
    and compare() refuses to start from rest (initial='zero')."""
    u = 100 * np.random.default_rng(30).standard_normal(3000)
    y_all = lfilter(B222, A222, u)
    u2, y2 = u[1000:1400], y_all[1000:1400]
    est = compare(TRUE, u2, y2)
    assert est.fit_percent == TRUE.compare(u2, y2).fit_percent
    assert est.fit_percent[0] == pytest.approx(100.0, abs=1e-6)
    np.testing.assert_allclose(est.simulated[:, 0], y2, rtol=1e-6, atol=1e-6 * np.abs(y2).max())
    zero = fit_percent(y2, TRUE.simulate(u2))
    assert zero < 99.0  # the slow poles (|p| = 0.948) carry the start-up error for ~60 samples
    with pytest.raises(ArgumentError, match="initial: expected 'estimate'"):
        compare(TRUE, u2, y2, initial="zero")


def test_unstable_model_warns_and_reports_no_fit():
    """An unstable fitted model diverges in free run: StabilityWarning, fit None (not −10⁴⁰ %)."""
    unstable = PolynomialModel.from_coefficients([1.0, -2.1, 1.1], [0.0, 0.0, 0.2])
    u, y = simulate_arx(500, noise=1.0, seed=31)
    with pytest.warns(StabilityWarning, match="unstable.*no simulation fit"):
        c = compare(unstable, u, y)
    assert c.fit_percent == [None] and not unstable.stable
    with pytest.warns(StabilityWarning):
        v = unstable.validate(u, y)
    assert v.fit_percent is None and not v.stable
    assert np.isfinite(v.prediction_fit_percent)  # the ARX predictor is FIR
    unstable_oe = PolynomialModel.from_coefficients([1.0], [0.0, 0.0, 0.2], F=[1.0, -2.1, 1.1])
    with pytest.warns(StabilityWarning):
        v = unstable_oe.validate(u, y)  # its predictor is the diverging simulation itself
    assert v.fit_percent is None and v.prediction_fit_percent is None and v.tests is None


def test_residual_tests_accept_white_and_reject_coloured():
    """Whiteness: white noise passes at α = 0.01; an MA(1) sequence fails. Independence: errors
    that contain filtered past input fail. (Seeds fixed; the statistics are χ².)"""
    rng = np.random.default_rng(32)
    u = rng.standard_normal(2000)
    e = rng.standard_normal(2000)
    ok = residual_tests(e, u)
    assert ok.white and ok.independent
    assert abs(ok.bound - 2.5758 / np.sqrt(2000)) < 1e-4
    coloured = residual_tests(lfilter([1, 0.5], [1], e), u)
    assert not coloured.white
    leaky = residual_tests(e + 0.3 * lfilter([0, 0, 1], [1], u), u)
    assert not leaky.independent and leaky.crosscorr[2] > leaky.bound


def test_independence_test_is_calibrated_for_a_multisine_input():
    """Monte Carlo (200 runs): with white errors independent of the S1 multisine (§V-E), the test
    rejects at α = 0.05 in about 5 % of runs (a plain χ²(L+1) statistic would never reject)."""
    from gripkit.excitation import multisine

    s1 = multisine(range(1, 11), 2.0, dt=0.005, operating_point=0.85, limits=(0.6, 1.1)).u
    rng = np.random.default_rng(33)
    rej = np.mean([not residual_tests(rng.standard_normal(400), s1, alpha=0.05).independent
                   for _ in range(200)])
    assert 0.01 <= rej <= 0.10


def test_validate_true_model_on_fresh_data():
    """The true model's one-step errors on fresh ARX data are the white noise: tests pass and
    the one-step loss is σ²/2 (eq 29)."""
    u, y = simulate_arx(4000, noise=2.0, seed=34)
    v = TRUE.validate(u, y)
    assert v.tests.white and v.tests.independent
    assert v.loss == pytest.approx(2.0, rel=0.08)


def test_arx_prediction_equals_regression():
    u, y = simulate_arx(500, noise=1.0, seed=35)
    m = arx(u, y, 2, 2, 2)
    yp = m.predict(u, y)
    np.testing.assert_allclose(y[3:] - yp[3:], m.estimation_residuals, atol=1e-9)
    np.testing.assert_array_equal(yp[:3], y[:3])
