"""Newey-West covariance for least squares with autocorrelated residuals (IDIM-LS uses it)."""

import numpy as np
import pytest

from gripkit.sysid.regression import hac_covariance


def _draw(rng, n, rho):
    x = np.sin(2 * np.pi * np.arange(n) / 200.0) + 0.3 * rng.standard_normal(n)  # smooth regressor
    X = np.column_stack([x, np.ones(n)])
    e = np.empty(n)
    e[0] = rng.standard_normal()
    for t in range(1, n):  # AR(1) noise, like residuals of filtered signals
        e[t] = rho * e[t - 1] + np.sqrt(1 - rho**2) * rng.standard_normal()
    return X, X @ np.array([2.0, -1.0]) + 0.1 * e


@pytest.mark.parametrize("rho", [0.0, 0.9])
def test_hac_sigma_matches_the_monte_carlo_spread(rho):
    """Over 300 draws the spread of the slope matches the mean Newey-West σ (within 25 %); with
    AR(1) residuals (ρ = 0.9) the classical s²(XᵀX)⁻¹ understates it by ≈ √((1+ρ)/(1−ρ)) ≈ 4×."""
    rng = np.random.default_rng(1)
    est, hac, classic = [], [], []
    for _ in range(300):
        X, y = _draw(rng, 2000, rho)
        th, *_ = np.linalg.lstsq(X, y, rcond=None)
        r = y - X @ th
        est.append(th[0])
        hac.append(np.sqrt(hac_covariance(X, r)[0, 0]))
        classic.append(np.sqrt(r @ r / (len(y) - 2) * np.linalg.inv(X.T @ X)[0, 0]))
    spread = np.std(est, ddof=1)
    assert np.mean(hac) == pytest.approx(spread, rel=0.25)
    if rho > 0:
        assert spread / np.mean(classic) > 2.5
    else:
        assert np.mean(classic) == pytest.approx(spread, rel=0.15)
