"""Poles, zeros, DC gain, frequency response, time responses and stability: analytic cases and
agreement with scipy.signal and python-control."""

import control  # a dev dependency: the cross-checks fail, not skip, without it
import numpy as np
import pytest
from scipy import signal

from gripkit.errors import DataError, ModelError
from gripkit.lti import StateSpace, TransferFunction

from lti_systems import EPS, random_ss, recursion_bound




def second_order(wn, zeta, k=1.0):
    """k wn² / (s² + 2 ζ wn s + wn²) as a state space in (position, velocity)."""
    return StateSpace([[0.0, 1.0], [-wn**2, -2 * zeta * wn]], [[0.0], [k * wn**2]], [[1.0, 0.0]],
                      inputs="F", outputs="x", input_units="N", output_units="m")


@pytest.mark.parametrize("wn, zeta", [(2.0, 0.1), (50.0, 0.7), (8.52e3 * 2 * np.pi, 0.01)])
def test_second_order_poles_and_dc_gain_analytic(wn, zeta):
    """Poles −ζ ωn ± j ωn √(1 − ζ²) and DC gain k (analytic). The eigenvalues of a 2×2 companion
    matrix are accurate to ~ε‖A‖ = ε ωn²/ωn relative to ωn, so 10 ε ωn is the tolerance."""
    s = second_order(wn, zeta, k=3.0)
    p = s.poles()
    expect = -zeta * wn + 1j * wn * np.sqrt(1 - zeta**2)
    upper = p[np.argmax(p.imag)]
    assert abs(upper - expect) <= 10 * EPS * wn**2 / wn * max(1.0, wn)
    assert s.dc_gain()[0, 0] == pytest.approx(3.0, rel=10 * EPS * np.linalg.cond(s.A))
    assert s.stable
    assert not StateSpace([[0.0, 1.0], [-wn**2, +0.1]], [[0.0], [1.0]], [[1.0, 0.0]]).stable


def test_frequency_response_matches_python_control_mimo():
    rng = np.random.default_rng(12)
    """G(jω) of a random 4-state, 2×3 system against control.frequency_response. Both solve
    (sI − A) X = B; their difference is bounded by ~n ε κ(sI − A) |G|: tolerance 10 n ε κ."""
    A, B, C, D, _ = random_ss(rng, 4, 2, 3)
    s = StateSpace(A, B, C, D)
    w = np.logspace(-2, 2, 25)
    H = s.frequency_response(w)
    Href = np.moveaxis(control.ss(A, B, C, D)(1j * w), -1, 0)  # (N, p, m)
    kappa = max(np.linalg.cond(1j * wk * np.eye(4) - A) for wk in w)
    assert np.abs(H - Href).max() <= 10 * 4 * EPS * kappa * np.abs(Href).max()


def test_discrete_frequency_response_matches_freqz():
    """A discrete TF at z = e^{jω dt} against scipy.signal.freqz (Horner on both sides: error
    ~ L ε Σ|a_k| / |den(z)| relative)."""
    b, a = [0.0, 0.0, 0.1950, -0.2276], [1.0, -1.8732, 0.8996, 0.0]
    g = TransferFunction(b, a, dt=0.005)
    w = np.linspace(0, np.pi / 0.005, 64, endpoint=False)
    _, href = signal.freqz(b, a, worN=w * 0.005)
    H = g.frequency_response(w)[:, 0, 0]
    den_min = np.abs(np.polyval(a, np.exp(1j * w * 0.005))).min()
    assert (np.abs(H - href).max()
            <= 10 * len(a) * EPS * np.abs(a).sum() / den_min * np.abs(href).max())


def test_siso_zeros_match_python_control():
    rng = np.random.default_rng(12)
    """Zeros of a random SISO state space (relative degree 1 and 2) against control.zeros of
    the same system; zeros are roots of the numerator, conditioned by their separation."""
    for n, rel in ((4, 1), (5, 2)):
        z_true = -rng.uniform(0.5, 3.0, n - rel)
        p_true = -rng.uniform(0.5, 3.0, n)
        g = TransferFunction(np.poly(z_true) * 2.5, np.poly(p_true))
        s = g.to_ss()
        z = np.sort(s.zeros().real)
        ref = np.sort(control.tf(np.poly(z_true) * 2.5, np.poly(p_true)).zeros().real)
        sep = np.diff(np.sort(z_true)).min()
        tol = 1e3 * n * EPS * np.abs(np.poly(-np.abs(z_true))).sum() / sep
        np.testing.assert_allclose(z, np.sort(z_true), atol=tol)
        np.testing.assert_allclose(z, ref, atol=tol)


def test_mimo_transmission_zeros_known():
    """G(s) = [[1/(s+1), 1/(s+2)], [1/(s+3), 1/(s+4)]]: det G = ((s+2)(s+3) − (s+1)(s+4)) / Π =
    2 / Π(s+i), so no finite transmission zero; and G₂ = [[(s+5)/(s+1), 0], [0, 1/(s+2)]] has
    the zero −5 (analytic)."""
    g = (TransferFunction([[[1.0], [1.0]], [[1.0], [1.0]]],
                          [[[1, 1.0], [1, 2.0]], [[1, 3.0], [1, 4.0]]]))
    assert g.zeros().size == 0
    g2 = (TransferFunction([[[1.0, 5.0], [0.0]], [[0.0], [1.0]]],
                           [[[1, 1.0], [1.0]], [[1.0], [1, 2.0]]]))
    z = g2.zeros()
    # rank decisions are taken at √ε relative: a zero is located to ~√ε |z| at worst
    tol = np.sqrt(EPS) * 5.0
    assert z.size == 1 and abs(z[0] + 5.0) < tol
    # non-square (3 outputs, 2 inputs): stacking a row that shares the zero keeps it
    g3 = TransferFunction([[[1.0, 5.0], [0.0]], [[0.0], [1.0]], [[0.0], [0.0]]],
                          [[[1, 1.0], [1.0]], [[1.0], [1, 2.0]], [[1.0], [1.0]]])
    z3 = g3.zeros()
    assert z3.size == 1 and abs(z3[0] + 5.0) < tol
    assert np.sort(g.poles().real).tolist() == pytest.approx([-4, -3, -2, -1], abs=np.sqrt(EPS) * 4)


def test_step_and_impulse_match_scipy():
    """Continuous step via ZOH sampling equals scipy.signal.step's (exact for a step input), and
    the discrete impulse equals scipy.signal.dimpulse.

    Tolerances: both sides build e^{A h} (‖A h‖ ≈ 0.2, error ~10 n ε) and accumulate it over 200
    steps of a decaying recursion: ≲ 200 · 10 · 2 ε ≈ 1e-12 relative, so 1e-10 (step) and 1e-9
    (impulse, whose scipy path integrates x' = A x from x0 = B with its own ODE tolerance of
    lsim's expm-based stepping) hold with margin. dimpulse uses the very matrices: only the
    summation order differs, N n ε |y| ≈ 50 · 2 · 2e-16 → 1e-13."""
    s = StateSpace([[0.0, 1.0], [-4.0, -0.4]], [[0.0], [4.0]], [[1.0, 0.0]])
    t = np.linspace(0, 10, 201)
    y = s.step(t)[:, 0, 0]
    _, yref = signal.step((s.A, s.B, s.C, s.D), T=t)
    np.testing.assert_allclose(y, yref, atol=1e-10 * np.abs(yref).max())
    _, yimp = signal.impulse((s.A, s.B, s.C, s.D), T=t)
    np.testing.assert_allclose(s.impulse(t)[:, 0, 0], yimp, atol=1e-9 * np.abs(yimp).max())
    d = s.c2d(0.05)
    _, (ydi,) = signal.dimpulse((d.A, d.B, d.C, d.D, 0.05), n=50)
    np.testing.assert_allclose(d.impulse(50)[:, 0, 0], ydi[:, 0], rtol=0, atol=1e-13)
    # the step response settles at the DC gain (after 200 s the transient e^{-0.2 t} is 4e-18)
    assert d.step(4000)[-1, 0, 0] == pytest.approx(float(s.dc_gain()[0, 0]), rel=1e-9)


def test_simulate_matches_dlsim_mimo():
    rng = np.random.default_rng(12)
    """The numba recursion against scipy.signal.dlsim on a 2-input 3-output system: the same
    recursion rounded in another order, within :func:`lti_systems.recursion_bound`."""
    A, B, C, D, _ = random_ss(rng, 4, 2, 3, dt=0.1)
    s = StateSpace(A, B, C, D, dt=0.1)
    u = rng.standard_normal((300, 2))
    x0 = rng.standard_normal(4)
    _, yref, xref = signal.dlsim((A, B, C, D, 0.1), u, x0=x0)
    y = s.simulate(u, x0)
    assert np.abs(y - yref).max() <= recursion_bound(A, B, C, u, np.abs(xref).max())


def test_bode_default_grids_and_db():
    """Discrete default grid = freqz's (k π / (n dt)); −3.01 dB at the corner of 1/(τs + 1)."""
    d = TransferFunction([1.0], [1.0, -0.5], dt=0.01)
    b = d.bode(n=8)
    np.testing.assert_allclose(b.w, np.pi / 0.01 * np.arange(8) / 8)
    c = TransferFunction([1.0], [0.1, 1.0]).bode([10.0])
    assert c.magnitude_db[0, 0, 0] == pytest.approx(20 * np.log10(1 / np.sqrt(2)), abs=1e-12)
    assert c.phase[0, 0, 0] == pytest.approx(-np.pi / 4, abs=1e-12)
    assert c.magnitude_std is None


def test_validation_errors():
    with pytest.raises(ModelError, match=r"A: expected a square matrix, found shape \(2, 3\)"):
        StateSpace(np.ones((2, 3)), np.ones((2, 1)), np.ones((1, 2)))
    with pytest.raises(ModelError, match=r"B: expected shape \(2, m\).*found \(3, 1\)"):
        StateSpace(np.eye(2), np.ones((3, 1)), np.ones((1, 2)))
    with pytest.raises(ModelError, match=r"D: expected shape \(1, 1\), found \(2, 2\)"):
        StateSpace(np.eye(2), np.ones((2, 1)), np.ones((1, 2)), np.eye(2))
    with pytest.raises(ModelError, match="non-finite"):
        StateSpace([[np.nan]], [[1.0]], [[1.0]])
    with pytest.raises(ModelError, match="dt: expected None or 0"):
        StateSpace([[1.0]], [[1.0]], [[1.0]], dt=-0.1)
    with pytest.raises(ModelError, match="inputs: expected 1 names, found 2"):
        StateSpace([[1.0]], [[1.0]], [[1.0]], inputs=("a", "b"))
    with pytest.raises(ModelError, match="distinct"):
        StateSpace(np.eye(2), np.eye(2), np.eye(2), inputs=("a", "a"))
    with pytest.raises(ModelError, match="continuous"):
        StateSpace([[-1.0]], [[1.0]], [[1.0]]).simulate(np.ones(3))
    with pytest.raises(DataError, match=r"u: expected shape \(N, 2\)"):
        StateSpace(np.eye(2) * 0.5, np.eye(2), np.eye(2), dt=1.0).simulate(np.ones(3))
    with pytest.raises(DataError, match="x0: expected 1 initial states"):
        StateSpace([[0.5]], [[1.0]], [[1.0]], dt=1.0).simulate(np.ones(3), x0=[0.0, 1.0])
    with pytest.raises(ModelError, match="DC gain is infinite"):
        StateSpace([[0.0]], [[1.0]], [[1.0]]).dc_gain()
    with pytest.raises(ModelError, match="DC gain is infinite"):
        TransferFunction([1.0], [1.0, -1.0], dt=0.1).dc_gain()
    with pytest.raises(ModelError, match="improper"):
        TransferFunction([1.0, 0.0, 1.0], [1.0, 1.0])
    with pytest.raises(ModelError, match="denominator is zero"):
        TransferFunction([1.0], [0.0])
    with pytest.raises(ModelError, match="powers of z"):
        TransferFunction([1.0], [1.0, 1.0]).den_zinv()
    with pytest.raises(DataError, match="samples spaced by dt"):
        TransferFunction([1.0], [1.0, -0.5], dt=0.1).step(np.linspace(0, 1, 7))


def test_names_and_units_survive_conversions():
    s = second_order(10.0, 0.3).replace(states=("x", "v"), state_units=("m", "m/s"))
    for t in (s.c2d(0.01), s.c2d(0.01).d2c(), s.to_tf(), s.to_tf().to_ss(), s.c2d(0.01, "tustin"),
              2.0 * s, -s):
        assert (t.inputs, t.outputs, t.input_units,
                t.output_units) == (("F",), ("x",), ("N",), ("m",))
    d = s.c2d(0.01)
    assert d.states == ("x", "v") and d.state_units == ("m", "m/s") and d.dt == 0.01


def test_minimum_phase():
    """(s − 1)/(s + 2)² is not minimum phase, (s + 1)/(s + 2)² is (analytic)."""
    assert not TransferFunction([1.0, -1.0], [1.0, 4.0, 4.0]).minimum_phase
    assert TransferFunction([1.0, 1.0], [1.0, 4.0, 4.0]).minimum_phase
    assert TransferFunction([1.0, 1.0], [1.0, 4.0, 4.0]).to_ss().minimum_phase
