"""Parameter covariance carried to poles and frequency responses by linearisation, checked
against Monte Carlo on independently rebuilt systems.

Tolerance: the sample variance of N Gaussian draws has relative standard error √(2/N); the
linearisation error is O(σ/scale) relative, made ≤ 1e-3 by the chosen σ. Variances must agree
within 5√(2/N) + 1e-2 (5 σ of the Monte Carlo noise), correlations within 5/√N + 1e-2.
"""

import numpy as np
import pytest
from scipy import signal

from gripkit.errors import ModelError
from gripkit.lti import StateSpace, TransferFunction, as_system, series

N_MC = 4000
REL = 5 * np.sqrt(2 / N_MC) + 1e-2
COR = 5 / np.sqrt(N_MC) + 1e-2


def _check_cov(lin, samples):
    """lin: (2, 2) linearised covariance; samples: (N, 2) draws of (Re, Im)."""
    emp = np.cov(samples.T)
    for i in range(2):
        if lin[i, i] > 1e-12 * max(lin[0, 0], lin[1, 1]):
            assert emp[i, i] == pytest.approx(lin[i, i], rel=REL)
    if min(lin[0, 0], lin[1, 1]) > 1e-6 * max(lin[0, 0], lin[1, 1]):
        r_lin = lin[0, 1] / np.sqrt(lin[0, 0] * lin[1, 1])
        r_emp = emp[0, 1] / np.sqrt(emp[0, 0] * emp[1, 1])
        assert abs(r_lin - r_emp) <= COR


def _upper(p):
    return p[np.argmax(p.imag)]


# k ωn² / (s² + 2ζωn s + ωn²) with ωn = 10, ζ = 0.2, k = 2, θ = (num[2], den[1], den[2])
THETA = np.array([200.0, 4.0, 100.0])
SIGMA = np.array([0.2, 0.004, 0.1])          # 1e-3 relative
CORR = np.array([[1.0, 0.3, -0.2], [0.3, 1.0, 0.5], [-0.2, 0.5, 1.0]])
COV = CORR * np.outer(SIGMA, SIGMA)


@pytest.fixture(scope="module")
def draws():
    return np.random.default_rng(2026).multivariate_normal(THETA, COV, size=N_MC)


@pytest.fixture(scope="module")
def g():
    return TransferFunction([0.0, 0.0, THETA[0]], [1.0, THETA[1], THETA[2]]).with_covariance(
        COV, ["num[2]", "den[1]", "den[2]"])


def test_pole_covariance_matches_monte_carlo(g, draws):
    p, cov = g.pole_covariance()
    k = np.argmax(p.imag)
    mc = np.array([_upper(np.roots([1.0, t[1], t[2]])) for t in draws])
    _check_cov(cov[k], np.c_[mc.real, mc.imag])
    # analytic check of the linearisation: p = −a1/2 + j √(a2 − a1²/4), ∂Re p/∂a1 = −1/2
    J = np.array([[0.0, -0.5, 0.0], [0.0, -THETA[1] / 4 / np.sqrt(THETA[2] - THETA[1] ** 2 / 4),
                                     0.5 / np.sqrt(THETA[2] - THETA[1] ** 2 / 4)]])
    np.testing.assert_allclose(cov[k], J @ COV @ J.T, rtol=1e-6)


def test_frequency_response_covariance_matches_monte_carlo(g, draws):
    w = np.array([2.0, 10.0, 30.0])
    cov = g.frequency_response_covariance(w)
    H = np.array([signal.freqs([t[0]], [1.0, t[1], t[2]], worN=w)[1] for t in draws])
    for f in range(w.size):
        _check_cov(cov[f, 0, 0], np.c_[H[:, f].real, H[:, f].imag])
    b = g.bode(w)
    np.testing.assert_allclose(np.std(np.abs(H), axis=0, ddof=1), b.magnitude_std[:, 0, 0],
                               rtol=REL)
    np.testing.assert_allclose(np.std(np.unwrap(np.angle(H), axis=1), axis=0, ddof=1),
                               b.phase_std[:, 0, 0],
                               rtol=REL)


def test_covariance_goes_through_c2d_and_to_ss(g, draws):
    """Discrete poles of c2d(G, zoh) against Monte Carlo of e^{p dt} (ZOH's pole map); the
    state-space
    view gives the same frequency-response covariance as the transfer function (central
    differences with h = ε^{1/3}: relative error ~ε^{2/3} ≈ 4e-11, checked at 1e-6)."""
    dt = 0.02
    gd = g.c2d(dt)
    p, cov = gd.pole_covariance()
    k = np.argmax(p.imag)
    # ZOH maps each continuous pole p to e^{p dt} exactly
    mc = np.exp(np.array([_upper(np.roots([1.0, t[1], t[2]])) for t in draws]) * dt)
    _check_cov(cov[k], np.c_[mc.real, mc.imag])
    w = np.array([1.0, 10.0])
    np.testing.assert_allclose(gd.to_ss().frequency_response_covariance(w),
                               gd.frequency_response_covariance(w), rtol=1e-6,
                               atol=1e-12 * np.abs(gd.frequency_response_covariance(w)).max())


def test_state_space_entry_covariance_matches_monte_carlo():
    A = np.array([[0.0, 1.0], [-100.0, -4.0]])
    s = StateSpace(A, [[0.0], [200.0]], [[1.0, 0.0]]).with_covariance(np.diag([0.1, 0.004]) ** 2,
                                                                       ["A[1,0]", "A[1,1]"])
    p, cov = s.pole_covariance()
    k = np.argmax(p.imag)
    rng = np.random.default_rng(5)
    mc = []
    for d in rng.standard_normal((N_MC, 2)) * [0.1, 0.004]:
        mc.append(_upper(np.linalg.eigvals(A + np.array([[0, 0], [d[0], d[1]]]))))
    mc = np.array(mc)
    _check_cov(cov[k], np.c_[mc.real, mc.imag])
    # sample() draws from the same linearised distribution
    sp = np.array([_upper(x.poles()) for x in s.sample(N_MC, seed=6)])
    _check_cov(cov[k], np.c_[sp.real, sp.imag])


def test_series_of_uncertain_systems_matches_monte_carlo():
    """Independent parameters of two systems in series: σ of G2 G1 at 3 rad/s."""
    g1 = TransferFunction([0.0, 2.0], [1.0, 1.0]).with_covariance([[1e-6]], ["num[1]"])
    g2 = TransferFunction([0.0, 5.0], [1.0, 5.0]).with_covariance([[1e-6]], ["den[1]"])
    gs = series(g1, g2)
    assert gs.uncertainty.names == ("num[1]", "den[1]")
    # colliding names get prefixes
    assert series(g1, g1).uncertainty.names == ("1.num[1]", "2.num[1]")
    w = np.array([3.0])
    cov = gs.frequency_response_covariance(w)[0, 0, 0]
    rng = np.random.default_rng(8)
    d = rng.standard_normal((N_MC, 2)) * 1e-3
    s = 3j
    H = (2 + d[:, 0]) / (s + 1) * 5 / (s + 5 + d[:, 1])
    _check_cov(cov, np.c_[H.real, H.imag])


def test_arx_covariance_reaches_the_frequency_response():
    """An ARX [2 2 2] identified by gripkit.sysid on Table II data (000_8f66dcc7ab06470c.txt):
    its covariance over (a1, a2, b2, b3), carried by as_system, gives the σ of G(e^{jω dt}) that
    Monte Carlo over θ ~ N(θ̂, cov θ) gives."""
    from gripkit.sysid import arx

    A, B = np.array([1.0, -1.8732, 0.8996]), np.array([0.0, 0.0, 0.1950, -0.2276])
    rng = np.random.default_rng(3)
    u = rng.standard_normal(3000)
    y = signal.lfilter(B, A, u) + signal.lfilter([1.0], A, 0.05 * rng.standard_normal(3000))
    m = arx(u, y, 2, 2, 2, dt=0.005)
    g = as_system(m)
    assert g.uncertainty.names == ("a1", "a2", "b2", "b3")
    w = np.array([5.0, 60.0, 300.0])
    cov = g.frequency_response_covariance(w)
    th = rng.multivariate_normal(m.theta, m.covariance, size=N_MC)
    z = np.exp(1j * w * 0.005)
    for f in range(w.size):
        H = (th[:, 2] * z[f] ** -2 + th[:, 3]
             * z[f] ** -3) / (1 + th[:, 0] / z[f] + th[:, 1] / z[f] ** 2)
        _check_cov(cov[f, 0, 0], np.c_[H.real, H.imag])


def test_covariance_errors():
    g = TransferFunction([1.0], [1.0, 2.0])
    with pytest.raises(ModelError, match="carries no covariance"):
        g.pole_covariance()
    with pytest.raises(ModelError, match=r"covariance: expected shape \(1, 1\)"):
        g.with_covariance(np.eye(2), ["den[1]"])
    with pytest.raises(ModelError, match="not a free coefficient"):
        g.with_covariance([[1.0]], ["den[0]"])
    with pytest.raises(ModelError, match="positive semi-definite"):
        g.with_covariance([[-1.0]], ["den[1]"])
    with pytest.raises(ModelError, match="names like 'A"):
        StateSpace([[1.0]], [[1.0]], [[1.0]]).with_covariance([[1.0]], ["Q[0,0]"])


def test_damping_and_its_sigma_match_monte_carlo(g, draws):
    """ω_n = √a2 and ζ = a1/(2√a2) of s² + a1 s + a2 (analytic), and their σ against Monte Carlo;
    for the ZOH-discretised system the same ω_n and ζ come back from ln(z)/dt."""
    d = g.damping()
    assert d.wn[0] == pytest.approx(10.0, rel=1e-12) and d.zeta[0] == pytest.approx(0.2, rel=1e-12)
    wn_mc = np.sqrt(draws[:, 2])
    zeta_mc = draws[:, 1] / (2 * wn_mc)
    assert np.std(wn_mc, ddof=1) == pytest.approx(d.wn_std[0], rel=REL)
    assert np.std(zeta_mc, ddof=1) == pytest.approx(d.zeta_std[0], rel=REL)
    dd = g.c2d(0.02).damping()
    np.testing.assert_allclose(dd.wn, d.wn, rtol=1e-9)
    np.testing.assert_allclose(dd.zeta, d.zeta, rtol=1e-9)
    np.testing.assert_allclose(dd.wn_std, d.wn_std, rtol=1e-5)
    np.testing.assert_allclose(dd.zeta_std, d.zeta_std, rtol=1e-5)


def test_delay_poles_have_zero_sigma_and_agree_with_the_realisation():
    """ARX [2 2 3]: two poles at z = 0 from the delay are exact (σ = 0), and the root-sensitivity
    σ of the others equals the eigenvector formula on the state-space realisation."""
    cov = np.diag([1e-3, 1e-3, 2e-3, 2e-3]) ** 2
    g = TransferFunction.from_polynomials([1.0, -1.8732, 0.8996], [0, 0, 0, 0.1950, -0.2276],
                                          dt=0.005,
                                          covariance=cov)
    p, c = g.pole_covariance()
    assert np.count_nonzero(p == 0) == 2 and np.all(c[p == 0] == 0)
    d = g.damping()
    assert np.all(np.isinf(d.wn[p == 0])) and np.all(d.zeta[p == 0] == 1.0)
    # the same σ from the eigenvalues of a realisation without the delay states
    g2 = (TransferFunction.from_polynomials([1.0, -1.8732, 0.8996], [0.1950, -0.2276], dt=0.005,
                                            covariance=cov))
    p2, c2 = g2.to_ss(minimal=False).pole_covariance()
    order = [int(np.argmin(np.abs(p2 - x))) for x in p[p != 0]]
    np.testing.assert_allclose(c[p != 0], c2[order], rtol=1e-6)


def test_frequency_response_at_a_pole_is_an_error():
    with pytest.raises(ModelError, match="is a pole of the system"):
        TransferFunction([1.0], [1.0, 0.0]).frequency_response([0.0])
    with pytest.raises(ModelError, match="is a pole of the system"):
        StateSpace([[0.0]], [[1.0]], [[1.0]]).frequency_response([0.0])
