"""Rate-independent Bouc-Wen hysteresis (gripkit.models.hysteresis, eq 3 of
``001_0b92a7da96e7aa46.txt``): the exact per-sample update against a tight ODE solution, rate
independence, and the bound |H| → λ/(β+γ) on a monotone input."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from gripkit.models import BoucWen
from gripkit.models.hysteresis import bouc_wen_advance, bouc_wen_response

#: Table II, left finger (λ read in µm/V, here in m/V)
BW = dict(d_p=0.77e-6, lam=0.43e-6, beta=0.108, gamma=7.5e-3)


def test_bouc_wen_is_exact_against_a_tight_ode_solution():
    """Eq 3 integrated in time by solve_ivp (rtol 1e-11) under a 100 V, 0.1 Hz sine: the per-sample
    exact update agrees to 1e-8 of the hysteresis amplitude (the reference's own accuracy)."""
    t = np.linspace(0, 10, 4001)
    U = 100 * np.sin(2 * np.pi * 0.1 * t)
    _, H = bouc_wen_response(U, **BW)
    w = 2 * np.pi * 0.1

    def rhs(tt, h):
        du = 100 * w * math.cos(w * tt)
        return [BW["lam"] * du - BW["beta"] * abs(du) * h[0] - BW["gamma"] * du * abs(h[0])]

    ref = solve_ivp(rhs, (0, 10), [0.0], t_eval=t, rtol=1e-11, atol=1e-18, max_step=1e-3).y[0]
    assert np.max(np.abs(ref - H)) < 1e-8 * np.max(np.abs(H))


@given(st.lists(st.floats(-100, 100), min_size=2, max_size=30))
def test_bouc_wen_is_rate_independent(levels):
    """Property: H depends on the voltage path only. Visiting the same turning points with 1 or
    with 50 samples per monotone segment gives the same H at the turning points."""
    coarse = np.array(levels)
    fine = np.concatenate([np.linspace(a, b, 50, endpoint=False)
                           for a, b in zip(levels[:-1], levels[1:])] + [[levels[-1]]])
    _, Hc = bouc_wen_response(coarse, **BW)
    _, Hf = bouc_wen_response(fine, **BW)
    np.testing.assert_allclose(Hc, Hf[::50], rtol=1e-9, atol=1e-20)


def test_bouc_wen_saturates_at_lambda_over_beta_plus_gamma():
    """A long monotone sweep drives H to λ/(β+γ) = 3.72 µm (Table II)."""
    bw = BoucWen(**BW)
    _, H = bouc_wen_response(np.linspace(0, 200, 50), **BW)
    assert H[-1] == pytest.approx(bw.saturation(), rel=1e-8)
    assert bw.saturation() == pytest.approx(0.43e-6 / 0.1155)
    # zero crossing inside one step: from +H_sat down by 20 V lands where the two formulas meet
    Hs = bw.saturation()
    h1 = bouc_wen_advance(Hs, -20.0, BW["lam"], BW["beta"], BW["gamma"])
    h2 = Hs
    for _ in range(2000):
        h2 = bouc_wen_advance(h2, -0.01, BW["lam"], BW["beta"], BW["gamma"])
    assert h1 < 0 and h1 == pytest.approx(h2, rel=1e-10)


@pytest.mark.parametrize("lam,beta,gamma", [(1.0, 0.5, 0.2), (2e-3, 0.05, -0.02), (0.3, 0.0, 0.1)])
def test_monotone_input_bounds_h_by_lambda_over_beta_plus_gamma(lam, beta, gamma):
    """On a monotone input from the virgin state, dH/dU = λ − (β+γ)H: H = λ/c·(1 − e^{−cU})
    (c = β+γ), rising monotonically to λ/c and never beyond it; a decreasing sweep gives −λ/c."""
    c = beta + gamma
    U = np.linspace(0.0, 30.0 / c, 301)
    _, H = bouc_wen_response(U, 1.0, lam, beta, gamma)
    np.testing.assert_allclose(H, lam / c * -np.expm1(-c * U), rtol=1e-12, atol=1e-300)
    assert np.all(np.diff(H) > 0) and np.all(np.abs(H) <= lam / c)
    _, Hn = bouc_wen_response(-U, 1.0, lam, beta, gamma)
    assert Hn[-1] == pytest.approx(-lam / c, rel=1e-12)
    assert BoucWen(d_p=1.0, lam=lam, beta=beta, gamma=gamma).saturation() == pytest.approx(lam / c)


def test_unbounded_parameters_are_reported():
    """β + γ ≤ 0: no bound on a monotone sweep; the consistency finding says so."""
    f, = BoucWen(d_p=1e-6, lam=1e-7, beta=0.01, gamma=-0.02, check=False).consistency_checks()
    assert f.check == "bounded-hysteresis" and not f.consistent
    assert "grows without bound" in f.message
