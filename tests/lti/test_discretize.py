"""c2d and d2c (ZOH, FOH, Tustin with prewarp) against scipy.signal.cont2discrete and
python-control's sample_system, and d2c(c2d(G)) = G as a hypothesis property."""

import control  # a dev dependency: the cross-checks fail, not skip, without it
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy import signal

from gripkit.errors import ModelError
from gripkit.lti import StateSpace, TransferFunction, c2d, d2c
from lti_systems import EPS, random_ss


def _tol(A, dt):
    """expm by scaling and squaring is backward stable: relative error ≲ 10 n ε e^{‖A‖dt}, and at
    most κ(V)² more through non-normality; the tests use κ(V) ≤ 3."""
    n = A.shape[0]
    return 10 * n * EPS * np.exp(np.linalg.norm(A, 2) * dt) * 9


@pytest.mark.parametrize("method", ["zoh", "foh", "bilinear"])
def test_c2d_matches_scipy_mimo(method):
    rng = np.random.default_rng(3)
    A, B, C, D, _ = random_ss(rng, 4, 2, 3)
    dt = 0.1
    ours = StateSpace(A, B, C, D).c2d(dt, method)
    ref = signal.cont2discrete((A, B, C, D), dt, method=method)
    tol = _tol(A, dt)
    for X, R in zip((ours.A, ours.B, ours.C, ours.D), ref[:4]):
        assert np.abs(X - R).max() <= tol * max(np.abs(R).max(), 1.0)
    assert ours.dt == dt and ours.meta["c2d"] == {"bilinear": "tustin"}.get(method, method)


@pytest.mark.parametrize("method", ["zoh", "foh", "tustin"])
def test_c2d_transfer_function_matches_python_control(method):
    """The discrete TF of a lightly damped resonance (the TSFM sensor's 8.52 kHz mode sampled at
    40 kHz) against control.sample_system: same coefficients to the conditioning of np.poly."""
    wn, zeta, dt = 2 * np.pi * 8.52e3, 0.01, 1 / 40e3
    g = TransferFunction([wn**2], [1.0, 2 * zeta * wn, wn**2])
    ref = control.sample_system(control.tf([wn**2], [1.0, 2 * zeta * wn, wn**2]), dt, method=method)
    gd = g.c2d(dt, method)
    num_ref = np.trim_zeros(np.squeeze(ref.num_array[0, 0]), "f")
    den_ref = np.squeeze(ref.den_array[0, 0])
    den_ref, num_ref = den_ref / den_ref[0], num_ref / den_ref[0]
    np.testing.assert_allclose(gd.denominator(), den_ref, atol=1e3 * EPS * np.abs(den_ref).sum())
    np.testing.assert_allclose(gd.numerator(), num_ref, atol=1e3 * EPS * np.abs(den_ref).sum())


def test_tustin_prewarp_matches_python_control_and_is_exact_at_the_prewarp_frequency():
    wn, zeta, dt = 30.0, 0.05, 0.05
    g = TransferFunction([wn**2], [1.0, 2 * zeta * wn, wn**2])
    wp = 30.0
    gd = g.c2d(dt, "tustin", prewarp=wp)
    ref = control.sample_system(control.tf([wn**2], [1.0, 2 * zeta * wn, wn**2]), dt,
                                method="tustin",
                                prewarp_frequency=wp)
    w = np.array([1.0, 10.0, wp])
    # the bilinear map solves with E = I − (T/2)A, κ(E) ≈ 1 + ‖A‖T/2 ≈ 25: both sides agree to
    # ~10 n ε κ ≈ 1e-13; 1e-10 leaves room for the different realisations python-control builds
    np.testing.assert_allclose(gd.frequency_response(w)[:, 0, 0], ref(np.exp(1j * w * dt)),
                               rtol=1e-10)
    # prewarp makes the response exact at ω_p (the bilinear map sends jω_p to e^{jω_p dt})
    assert gd.frequency_response([wp])[0, 0, 0] == pytest.approx(
        g.frequency_response([wp])[0, 0, 0], rel=1e-10)
    with pytest.raises(ModelError, match="prewarp applies to the Tustin method only"):
        g.c2d(dt, "zoh", prewarp=wp)
    with pytest.raises(ModelError, match=r"prewarp: expected a frequency in \(0, π/dt"):
        g.c2d(dt, "tustin", prewarp=100.0)


def _stable_ss(seed, n, m, p, dt):
    rng = np.random.default_rng(seed)
    # |Im p| dt < 0.8 π: every pole stays left of the Nyquist limit, so log Φ is the principal one
    return random_ss(rng, n, m, p, max_angle=0.8 * np.pi / dt)


@given(st.integers(0, 10_000), st.integers(1, 5), st.integers(1, 2), st.integers(1, 2),
       st.sampled_from([1e-3, 0.05, 0.3]), st.sampled_from(["zoh", "foh", "tustin"]))
def test_d2c_inverts_c2d(seed, n, m, p, dt, method):
    """Property: d2c(c2d(G, dt, method), method) = G for poles below Nyquist. logm and expm each
    lose ~κ(V)² n ε relative, amplified by 1/dt when dividing log Φ by dt: tolerance
    100 n κ(V)² ε (1 + ‖A‖) / (‖A‖ dt)."""
    A, B, C, D, V = _stable_ss(seed, n, m, p, dt)
    g = StateSpace(A, B, C, D)
    back = d2c(c2d(g, dt, method), method)
    kV = np.linalg.cond(V)
    normA = np.linalg.norm(A, 2)
    tol = 100 * n * kV**2 * EPS * (1 + normA) / min(normA * dt, 1.0)
    for X, R in zip(back._arrays(), g._arrays()):
        assert np.abs(X - R).max() <= tol * max(np.abs(R).max(), 1.0)
    assert back.dt is None


def test_d2c_refuses_a_pole_on_the_negative_real_axis():
    """z = −0.5 has no continuous ZOH/FOH preimage (it would need a pole at the Nyquist
    frequency); Tustin refuses z = −1."""
    d = StateSpace([[-0.5]], [[1.0]], [[1.0]], dt=0.1)
    with pytest.raises(ModelError, match="negative real axis"):
        d.d2c("zoh")
    with pytest.raises(ModelError, match="negative real axis"):
        d.d2c("foh")
    assert d.d2c("tustin").poles()[0].real == pytest.approx(2 / 0.1 * (-1.5) / 0.5)
    with pytest.raises(ModelError, match=r"z = −1"):
        StateSpace([[-1.0]], [[1.0]], [[1.0]], dt=0.1).d2c("tustin")
    with pytest.raises(ModelError, match="already discrete"):
        d.c2d(0.1)
    with pytest.raises(ModelError, match="already continuous"):
        StateSpace([[-1.0]], [[1.0]], [[1.0]]).d2c()
    with pytest.raises(ModelError, match="c2d: expected a positive sample time"):
        StateSpace([[-1.0]], [[1.0]], [[1.0]]).c2d(0.0)
    with pytest.raises(ModelError, match="method: expected one of zoh, foh, tustin"):
        StateSpace([[-1.0]], [[1.0]], [[1.0]]).c2d(0.1, "euler")


def test_zoh_keeps_the_dc_gain_and_maps_poles_to_exp():
    """ZOH maps each pole p to e^{p dt} and keeps the DC gain (analytic)."""
    g = TransferFunction([4.0], [1.0, 0.8, 4.0])
    gd = g.c2d(0.05)
    np.testing.assert_allclose(np.sort_complex(gd.poles()),
                               np.sort_complex(np.exp(g.poles() * 0.05)), rtol=1e-13)
    assert gd.dc_gain()[0, 0] == pytest.approx(1.0, rel=1e-12)
