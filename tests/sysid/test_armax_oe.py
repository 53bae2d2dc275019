"""ARMAX and OE by prediction-error minimisation: recovery of known parameters (truth: Table II
[2 2 2] of 000_8f66dcc7ab06470c.txt with a known noise model)."""

import numpy as np
import pytest
from arx_cases import A222, B222, THETA222, simulate_arx

from gripkit.sysid import armax, arx, oe


def test_armax_recovers_known_parameters_within_3_sigma():
    """A y = B u + C e with C = 1 − 0.5q⁻¹ + 0.2q⁻² (eq 26): θ = [a, b, c] within 3σ."""
    C = np.array([1.0, -0.5, 0.2])
    u, y = simulate_arx(4000, noise=2.0, seed=11, C=C)
    m = armax(u, y, 2, 2, 2, 2)
    truth = np.r_[THETA222, C[1:]]
    assert m.structure == "armax" and m.parameter_names == ("a1", "a2", "b2", "b3", "c1", "c2")
    assert np.all(np.abs(m.theta - truth) < 3 * m.theta_std), (m.theta, m.theta_std)
    assert m.C_std[0] == 0 and m.C_std.size == 3
    assert m.info["converged"]


def test_armax_beats_arx_on_coloured_noise():
    """With C ≠ 1, ARX is biased while ARMAX is consistent (§V-A: ARMAX models coloured noise)."""
    C = np.array([1.0, 0.8])
    u, y = simulate_arx(4000, noise=3.0, seed=12, C=C)
    ma = armax(u, y, 2, 2, 1, 2)
    mx = arx(u, y, 2, 2, 2)
    err_armax = np.abs(ma.theta[:4] - THETA222) / ma.theta_std[:4]
    err_arx = np.abs(mx.theta - THETA222) / mx.theta_std
    assert np.all(err_armax < 3) and np.max(err_arx) > 5
    assert ma.loss < mx.loss


def test_armax_with_nc_zero_is_arx():
    u, y = simulate_arx(500, noise=1.0, seed=13)
    np.testing.assert_allclose(armax(u, y, 2, 2, 0, 2).theta, arx(u, y, 2, 2, 2).theta)


def test_oe_recovers_known_parameters_within_3_sigma():
    """y = B/F u + e (white output noise): OE is consistent, θ = [b, f] within 3σ."""
    u, y = simulate_arx(3000, noise=2.0, seed=14, F=A222, kind="oe")
    m = oe(u, y, 2, 2, 2)
    truth = np.r_[B222[2:], A222[1:]]
    assert m.structure == "oe" and m.parameter_names == ("b2", "b3", "f1", "f2")
    assert np.all(np.abs(m.theta - truth) < 3 * m.theta_std), (m.theta, m.theta_std)
    # roots of F
    np.testing.assert_allclose(np.sort_complex(m.poles()), np.sort_complex(np.roots(m.F)))
    np.testing.assert_allclose(np.sort_complex(m.poles()), np.sort_complex(np.roots(A222)),
                               atol=1e-3)
    assert m.A.tolist() == [1.0] and m.F_std[0] == 0
    assert m.noise_variance == pytest.approx(4.0, rel=0.1)


@pytest.mark.slow
def test_oe_std_agrees_with_monte_carlo_spread():
    """Monte Carlo (100 repetitions, N = 1000): OE σ within 25 % of the spread."""
    est, sig = [], []
    for rep in range(100):
        u, y = simulate_arx(1000, noise=2.0, seed=500 + rep, F=A222, kind="oe")
        m = oe(u, y, 2, 2, 2)
        est.append(m.theta)
        sig.append(m.theta_std)
    np.testing.assert_allclose(np.mean(sig, axis=0) / np.std(est, axis=0, ddof=1), 1.0, atol=0.25)


def test_oe_validation_on_fresh_record_is_near_noise_floor():
    """Free-run fit of the OE model on a new record equals the fit of the true model."""
    u, y = simulate_arx(3000, noise=2.0, seed=15, F=A222, kind="oe")
    m = oe(u, y, 2, 2, 2)
    u2, y2 = simulate_arx(2000, noise=2.0, seed=16, F=A222, kind="oe")
    from gripkit.sysid import PolynomialModel, compare

    true = PolynomialModel.from_coefficients([1.0], B222, F=A222)
    assert compare(m, u2, y2).fit_percent == pytest.approx(compare(true, u2, y2).fit_percent,
                                                           abs=0.5)
