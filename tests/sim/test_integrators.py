"""Fixed-step integrators (RK4, semi-implicit Euler) and the exact ZOH discretisation."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.linalg import expm
from scipy.signal import cont2discrete

from gripkit.errors import ModelError
from gripkit.sim import integrate_lti, zoh_levels
from gripkit.sim.integrators import expm_small, rk4_msd_step, semi_implicit_msd_step


def _msd_error(step, h, T=1.0, m=1.0, b=0.2, k=40.0):
    """Largest state error (x and v/ω_n) over [0, T] of the free response x(0)=1 against the
    analytic damped oscillation."""
    wn = math.sqrt(k / m)
    z = b / (2 * math.sqrt(k * m))
    wd = wn * math.sqrt(1 - z * z)
    x, v, err = 1.0, 0.0, 0.0
    for i in range(1, int(round(T / h)) + 1):
        x, v = step(x, v, 0.0, m, b, k, h)
        t = i * h
        e = math.exp(-z * wn * t)
        xe = e * (math.cos(wd * t) + z / math.sqrt(1 - z * z) * math.sin(wd * t))
        ve = -e * wn / math.sqrt(1 - z * z) * math.sin(wd * t)
        err = max(err, math.hypot(x - xe, (v - ve) / wn))
    return err


def test_rk4_is_fourth_order_and_semi_implicit_first_order():
    """Halving h divides the global error by 2^4 (RK4) and 2^1 (semi-implicit Euler)."""
    e1, e2 = _msd_error(rk4_msd_step, 1e-2), _msd_error(rk4_msd_step, 5e-3)
    assert 14.0 < e1 / e2 < 18.0
    s1, s2 = _msd_error(semi_implicit_msd_step, 1e-3), _msd_error(semi_implicit_msd_step, 5e-4)
    assert 1.7 < s1 / s2 < 2.3


def test_semi_implicit_keeps_modified_energy_of_undamped_oscillator():
    """Symplectic Euler (v⁺ = v − h ω² x, x⁺ = x + h v⁺) conserves ω²x² + v² − h ω² x v exactly
    (up to round-off) over 10^5 steps, where explicit Euler would grow without bound."""
    w2, h = 400.0, 0.02  # ω h = 0.4
    x, v = 1.0, 0.0
    q0 = w2 * x * x + v * v - h * w2 * x * v
    qs = []
    for _ in range(100000):
        x, v = semi_implicit_msd_step(x, v, 0.0, 1.0, 0.0, w2, h)
        qs.append(w2 * x * x + v * v - h * w2 * x * v)
    # 10^5 steps of 4 roundings each, added linearly in the worst case: 4·N·ε ≈ 8.9e-11
    assert np.max(np.abs(np.array(qs) / q0 - 1)) < 4 * 100000 * np.finfo(np.float64).eps


def test_zoh_levels_match_scipy():
    """Reference: scipy.signal.cont2discrete (ZOH) for a lightly damped 8.52 kHz sensor at 20 kHz
    (001_0b92a7da96e7aa46.txt §IV-B), every dyadic level."""
    w = 2 * math.pi * 8520.0
    A = np.array([[0.0, 1.0], [-w * w, -2 * 0.006 * w]])
    B = np.array([[0.0], [1.0]])
    Phi, Gam = zoh_levels(A, B, 5e-5, 6)
    for j in range(7):
        h = 5e-5 * 2.0 ** (j - 6)
        Ad, Bd, *_ = cont2discrete((A, B, np.eye(2), np.zeros((2, 1))), h, method="zoh")
        np.testing.assert_allclose(Phi[j], Ad, rtol=1e-11, atol=1e-11 * np.abs(Ad).max())
        np.testing.assert_allclose(Gam[j], Bd, rtol=1e-11, atol=1e-11 * np.abs(Bd).max())


@given(st.integers(2, 7), st.floats(-3.0, 3.0), st.integers(0, 10_000))
def test_expm_small_matches_scipy(n, log_scale, seed):
    """Property: the balanced Taylor exponential agrees with scipy.linalg.expm on random (badly
    scaled) matrices."""
    rng = np.random.default_rng(seed)
    D = np.diag(10.0 ** rng.uniform(-3, 3, n))
    M = D @ rng.standard_normal((n, n)) @ np.linalg.inv(D) * 10.0**log_scale / n
    out = np.empty_like(M)
    expm_small(M, out)
    ref = expm(M)
    scale = np.abs(ref).max(axis=1, keepdims=True) + np.abs(ref).max(axis=0, keepdims=True)
    assert np.max(np.abs(out - ref) / scale) < 1e-11


def test_integrate_lti_rk4_converges_to_zoh():
    A = np.array([[0.0, 1.0], [-100.0, -1.0]])
    B = np.array([[0.0], [1.0]])
    C = np.array([[1.0, 0.0]])
    u = np.sin(np.arange(400) * 0.05)[:, None]
    y0 = integrate_lti(A, B, C, [[0.0]], u, 0.01, method="zoh")
    y1 = integrate_lti(A, B, C, [[0.0]], u, 0.01, method="rk4", substeps=50)
    np.testing.assert_allclose(y1, y0, atol=1e-9 * np.abs(y0).max())


def test_bad_arguments():
    with pytest.raises(ModelError, match="positive sample time"):
        zoh_levels(np.eye(2), np.ones((2, 1)), 0.0)
    with pytest.raises(ModelError, match="A must be"):
        zoh_levels(np.eye(2), np.ones((3, 1)), 1.0)
    with pytest.raises(ModelError, match="method"):
        integrate_lti(np.eye(1), np.eye(1), np.eye(1), np.eye(1), np.ones(3), 0.1, method="euler")


def test_rk4_paths_check_the_step():
    """The TSFM sensor (8.52 kHz, ζ = 0.006, §IV-B) integrated by RK4 at 10 kHz is refused
    (ω h = 5.4 > 2.83); at 20 kHz without substeps it is computed but flagged as under-resolved."""
    from gripkit.errors import AccuracyWarning, SimulationError

    w = 2 * math.pi * 8520.0
    A = np.array([[0.0, 1.0], [-w * w, -2 * 0.006 * w]])
    B, C = np.array([[0.0], [1.0]]), np.array([[1.0, 0.0]])
    with pytest.raises(SimulationError, match="stability limit"):
        integrate_lti(A, B, C, [[0.0]], np.ones(10), 1e-4, method="rk4")
    with pytest.warns(AccuracyWarning, match="under-resolves"):
        integrate_lti(A, B, C, [[0.0]], np.ones(10), 5e-5, method="rk4")
    # resolved: silent
    integrate_lti(A, B, C, [[0.0]], np.ones(10), 5e-5, method="rk4", substeps=20)
