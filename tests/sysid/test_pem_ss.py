"""PEM refinement of state-space models: exact sensitivity Jacobians, recovery, stability kept,
and honest σ (Monte Carlo: the truth within 3σ in at least 90 % of the runs)."""

import numpy as np
import pytest

from gripkit.lti import StateSpace
from gripkit.sysid import n4sid, pem
from gripkit.sysid.linear.pem_ss import (_directions, _gauss_newton_terms, _predict_sensitivity,
                                         predict_errors)

from mimo_systems import TRUE_POLES, match_poles, oe_data, two_by_two


@pytest.mark.parametrize("feedthrough,innovation", [(False, False), (True, True)])
def test_sensitivity_jacobian_matches_finite_differences(feedthrough, innovation):
    """∂ŷ/∂θ from the sensitivity equations equals central differences of the predictor (relative
    error ≤ 1e-6; the differences themselves carry O(h²) ≈ 1e-12 and rounding ε/h ≈ 1e-10)."""
    rng = np.random.default_rng(0)
    n, m, p, N = 3, 2, 2, 200
    A = np.diag([0.9, 0.5, -0.3])
    B, C = rng.standard_normal((n, m)), rng.standard_normal((p, n))
    D = rng.standard_normal((p, m)) if feedthrough else np.zeros((p, m))
    K = 0.1 * rng.standard_normal((n, p)) if innovation else np.zeros((n, p))
    x0 = rng.standard_normal(n)
    u, y = rng.standard_normal((N, m)), rng.standard_normal((N, p))
    dA, dB, dC, dD, dK, entries = _directions(A, B, C, D, K, feedthrough, innovation)
    d = dA.shape[0]
    assert d == n * m + p * n + (p * m if feedthrough else 0) + (n * p if innovation else 0)
    e, J = _predict_sensitivity(A, B, C, D, K, dA, dB, dC, dD, dK, x0, u, y)
    # the Gauss-Newton terms of the unit-direction kernel (J never formed) are JᵀJ and Jᵀe
    e2, H, g = _gauss_newton_terms(A, B, C, D, K, x0, u, y, entries)
    np.testing.assert_array_equal(e2, e)
    np.testing.assert_allclose(H, J.T @ J, rtol=0, atol=1e-12 * np.abs(J.T @ J).max())
    np.testing.assert_allclose(g, J.T @ e.reshape(-1), rtol=0,
                               atol=1e-12 * np.abs(J).max() * np.abs(e).sum())
    h = 1e-6
    for q in range(d + n):
        th, dx = np.zeros(d), np.zeros(n)
        if q < d:
            th[q] = h
        else:
            dx[q - d] = h
        def errs(s):  # noqa: E306
            out = np.empty((N, p))
            predict_errors(A + s * np.tensordot(th, dA, 1), B + s * np.tensordot(th, dB, 1),
                           C + s * np.tensordot(th, dC, 1),
                     D + s * np.tensordot(th, dD, 1), K + s * np.tensordot(th, dK, 1), x0 + s * dx,
                     u, y, out)
            return out
        fd = -(errs(1) - errs(-1)).reshape(-1) / (2 * h)
        assert np.max(np.abs(fd - J[:, q])) <= 1e-6 * np.max(np.abs(fd))


def test_pem_recovers_poles_within_sigma_and_keeps_stability():
    g = two_by_two()
    u, y = oe_data(g, 3000, 0.1, seed=4)
    start = n4sid(u, y, 4, dt=0.01)
    for form in ("oe", "innovation"):
        r = pem(start, u=u, y=y, form=form)
        assert r.stable and r.structure == f"pem-{form}"
        assert r.info["pem"]["loss"] <= r.info["pem"]["loss_start"]
        if form == "innovation":
            assert np.max(np.abs(np.linalg.eigvals(r.system.A - r.K @ r.system.C))) < 1
        p, cov = r.system.pole_covariance()
        sd = np.sqrt(cov[:, 0, 0] + cov[:, 1, 1])
        i = match_poles(p, TRUE_POLES)
        assert np.all(np.abs(p[i] - TRUE_POLES) <= 4 * sd[i])


def test_frequency_response_sigma_from_pem():
    """σ of the frequency response (lti linearisation of the PEM covariance) covers the true
    response: |Ĝ − G| ≤ 4 σ on every entry at 20 frequencies."""
    g = two_by_two()
    u, y = oe_data(g, 3000, 0.1, seed=6)
    r = pem(n4sid(u, y, 4, dt=0.01), u=u, y=y, form="oe")
    w = np.linspace(1.0, 300.0, 20)
    b = r.system.bode(w)
    sd = np.sqrt(b.H_cov[..., 0, 0] + b.H_cov[..., 1, 1])
    assert np.all(np.abs(b.H - g.frequency_response(w)) <= 4 * sd)


def _mc_pem(runs, N, seed):
    """Second-order SISO output-error system, poles 0.85 ± 0.3j; fraction of runs whose true pole
    lies within 3σ (Re and Im each) of the PEM estimate."""
    A = np.array([[1.7, -0.8125], [1.0, 0.0]])        # z² − 1.7 z + 0.8125: poles 0.85 ± 0.3j
    g = StateSpace(A, [[1.0], [0.0]], [[0.5, 0.3]], dt=1.0)
    true = 0.85 + 0.3j
    hits = 0
    rng = np.random.default_rng(seed)
    for _ in range(runs):
        u = rng.standard_normal((N, 1))
        y = g.simulate(u) + 0.3 * rng.standard_normal((N, 1))
        r = pem(n4sid(u, y, 2), u=u, y=y, form="oe")
        p, cov = r.system.pole_covariance()
        k = int(np.argmin(np.abs(p - true)))
        d = p[k] - true
        hits += (abs(d.real) <= 3 * np.sqrt(cov[k, 0,
                                                0]) and abs(d.imag) <= 3 * np.sqrt(cov[k, 1, 1]))
    return hits / runs


def test_sigma_honest_monte_carlo_small():
    assert _mc_pem(30, 600, seed=11) >= 0.9


@pytest.mark.slow
def test_sigma_honest_monte_carlo_large():
    assert _mc_pem(300, 600, seed=12) >= 0.95


def test_sigma_honest_mimo_monte_carlo_small():
    """2×2 system of order 4, 12 records of 1500 samples with 10 % output noise: the true poles lie
    within 3σ (Re and Im each) of the PEM estimate in at least 90 % of the pole-runs."""
    g = two_by_two()
    hits = []
    for k in range(12):
        u, y = oe_data(g, 1500, 0.1, seed=200 + k)
        r = pem(n4sid(u, y, 4, dt=0.01), u=u, y=y, form="oe")
        p, cov = r.system.pole_covariance()
        i = match_poles(p, TRUE_POLES)
        d = p[i] - TRUE_POLES
        hits += list((np.abs(d.real) <= 3 * np.sqrt(cov[i, 0, 0])) & (np.abs(d.imag) <= 3
                                                                      * np.sqrt(cov[i, 1, 1])
                                                                      + 1e-12))
    assert np.mean(hits) >= 0.9


def test_identify_ss_from_python_prints_nothing(capsys):
    """Issue 25: ``identify(data, "ss")`` printed its stages to stderr from the library; only the
    command line (progress=True) reports them."""
    from gripkit import Trajectory
    from gripkit.sysid import identify

    rng = np.random.default_rng(0)
    u = rng.standard_normal(800)
    y = np.zeros(800)
    for t in range(1, 800):
        y[t] = 0.8 * y[t - 1] + 0.5 * u[t - 1]
    tr = Trajectory.uniform(dt=0.01, u=u, y=y + 0.01 * rng.standard_normal(800))
    capsys.readouterr()
    model = identify(tr, "ss", input="u", output="y", order=1)
    model = model[0] if isinstance(model, tuple) else model
    out = capsys.readouterr()
    assert out.err == "" and out.out == ""
    assert abs(model.system.poles()[0] - 0.8) < 0.02
