"""The physical-consistency distance and the constrained fit of ``identify_dynamics``
(``gripkit.sysid.rigid_body.dynamics_projection``), Monte Carlo on the DLR/HIT Hand II finger of
the zoo
(``002_ddea254371185ad3.txt`` Appendix F: thin-rod phalanges, a pseudo-inertia on the boundary of
the consistent set, so noise puts the estimate outside it in most runs), exported by ``to_urdf``,
with exact joint states and white torque noise (σ honest:
``tests/sysid/test_identify_dynamics.py``).

What holds in every run, by the convexity of the consistent set S (module doc of
``dynamics_projection``): the true parameters lie in S, so the reported distance d, a minimum over
S, is at most the truth's Mahalanobis distance; the constrained estimate θ_c (the projection) is
nearer the truth than the unconstrained θ̂ by the obtuse-angle property
‖θ_c − θ*‖² ≤ ‖θ̂ − θ*‖² − d². What holds in distribution: the truth's squared distance is χ²
with dim θ degrees of freedom, so the check calls the data consistent in ≥ 95 % of runs (≥ 90 %
asserted over 40)."""

import warnings

import numpy as np
import pytest
from scipy.optimize import minimize
from scipy.stats import chi2

from gripkit.multibody import from_urdf, to_urdf
from gripkit.sysid import identify_dynamics
from gripkit.sysid.rigid_body.dynamics import pseudo_inertia
from test_identify_dynamics import FC, FV, NOISE, fourier_states


@pytest.fixture(scope="module")
def rod_finger(tmp_path_factory):
    """The zoo's DLR/HIT finger as it is (thin rods), through a URDF file."""
    from gripkit import zoo

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ch = zoo.build("dlr-hit-finger").chain()
        path = to_urdf(ch, tmp_path_factory.mktemp("u") / "finger.urdf")
    return from_urdf(path, gravity=ch.chain.gravity_vector)


def _truth(res, chain):
    return np.concatenate([res.structure.base(chain.standard_parameters()),
                           np.ravel(np.column_stack([FC, FV]))])


def _mahalanobis(a, b, W):
    v = a - b
    return float(np.sqrt(v @ W @ v))


def _monte_carlo(chain, runs, seed):
    rng = np.random.default_rng(seed)
    q, qd, qdd = fourier_states(3_000, 500.0, rng)
    clean = chain.rnea(q, qd, qdd) + FC * np.sign(qd) + FV * qd
    rows = []
    for _ in range(runs):
        tau = clean + rng.normal(size=clean.shape) * NOISE
        res = identify_dynamics(chain, q, qd, qdd, tau, constrained=True)
        W = np.linalg.inv(res.covariance)
        truth = _truth(res, chain)
        rows.append((res, W, truth))
    return rows


def _check_run(res, W, truth, chain):
    """Per-run assertions; returns (d_true, d, distance of θ_c to the truth)."""
    c = res.consistency
    th_u, th_c = res.unconstrained_theta, res.theta
    d_true = _mahalanobis(th_u, truth, W)
    # the distance is the Mahalanobis distance, in the identified parameters' covariance,
    # between the estimate and the constrained estimate, computed here from the result's arrays
    assert c.distance == pytest.approx(_mahalanobis(th_c, th_u, W), rel=1e-9, abs=1e-12)
    assert c.dof == th_u.size == 28
    assert c.bound == pytest.approx(np.sqrt(chi2.ppf(0.95, 28)), rel=1e-12)
    assert c.p_value == pytest.approx(chi2.sf(c.distance ** 2, 28), rel=1e-9)
    assert c.consistent == (c.distance <= c.bound)
    assert c.converged, c.solver
    # θ_c is consistent: reproduced by standard parameters with PSD pseudo-inertia, friction ≥ 0
    phi = c.standard_parameters
    nb = res.n_base
    np.testing.assert_allclose(res.structure.base(phi), th_c[:nb], rtol=1e-10, atol=1e-14)
    for k in range(4):
        J = pseudo_inertia(phi[10 * k:10 * k + 10])
        assert np.linalg.eigvalsh(J)[0] >= -1e-12 * np.linalg.eigvalsh(J)[-1]
    assert np.all(th_c[nb:] > 0)
    # the truth is consistent, so the minimum distance cannot exceed its distance
    assert c.distance <= d_true + 1e-6
    # the projection onto a convex set holding the truth is non-expansive towards it
    d_c = _mahalanobis(th_c, truth, W)
    assert d_c ** 2 <= d_true ** 2 - c.distance ** 2 + 1e-4, (d_c, d_true, c.distance)
    return d_true, c.distance, d_c


def test_consistency_monte_carlo(rod_finger):
    """40 noisy logs: the truth is judged consistent at the 95 % χ² level in ≥ 90 % of runs, the
    distance is the base-metric Mahalanobis distance, the constrained estimate is never further
    from the truth (in the same metric) and never worse on the largest per-parameter error in
    the mean."""
    rows = _monte_carlo(rod_finger, 40, seed=21)
    stats = np.array([_check_run(res, W, truth, rod_finger) for res, W, truth in rows])
    d_true, d, d_c = stats.T
    bound2 = chi2.ppf(0.95, 28)
    # the check judges the data consistent in ≥ 90 % of runs (here all 40: d is well below d_true),
    # and wherever the truth is inside the 95 % χ² region (d ≤ d_true)
    judged = np.array([res.consistency.consistent for res, _, _ in rows])
    assert np.mean(judged) >= 0.9
    assert judged[d_true ** 2 <= bound2].all()
    # σ honest: the truth inside the 95 % χ² region in 36 of these 40 runs (0.9; a binomial(40,
    # 0.95) count is ≥ 34 with probability 0.997; the slow study below: 283 of 300)
    assert np.mean(d_true ** 2 <= bound2) >= 0.85, np.mean(d_true ** 2 <= bound2)
    # the thin rods sit on the boundary: the estimate is outside S in most runs, so the
    # projection is exercised (d > 0) and it moves towards the truth
    assert np.mean(d > 0.1) >= 0.75
    assert np.all(d_c <= d_true + 1e-6) and np.mean(d_c) < np.mean(d_true)
    # per-parameter errors (σ units): the largest error does not grow on average
    max_u = [np.max(np.abs(res.unconstrained_theta - t) / res.std) for res, _, t in rows]
    max_c = [np.max(np.abs(res.theta - t) / res.std) for res, _, t in rows]
    assert np.mean(max_c) <= np.mean(max_u)


def _cholesky_search_distance(res, chain, start_phi, start_f):
    """An independent optimiser: BFGS over each link's Cholesky factor (J = L Lᵀ) and the square
    roots of the friction, from a consistent start; returns the Mahalanobis distance it reaches
    (an upper bound of the minimum)."""
    K = res.structure.matrix
    W = np.linalg.inv(res.covariance)
    th_u = res.unconstrained_theta
    tri = np.tril_indices(4)

    def unpack(z):
        phi = []
        for k in range(4):
            L = np.zeros((4, 4))
            L[tri] = z[10 * k:10 * k + 10]
            J = L @ L.T
            S = J[:3, :3]
            Io = np.trace(S) * np.eye(3) - S
            phi += [J[3, 3], J[0, 3], J[1, 3], J[2, 3],
                    Io[0, 0], Io[0, 1], Io[1, 1], Io[0, 2], Io[1, 2], Io[2, 2]]
        return np.concatenate([K @ np.array(phi), z[40:] ** 2])

    z0 = []
    for k in range(4):
        J = pseudo_inertia(start_phi[10 * k:10 * k + 10]) + 1e-9 * np.eye(4)
        z0 += list(np.linalg.cholesky(J)[tri])
    z0 = np.concatenate([z0, np.sqrt(start_f)])
    f = lambda z: float((unpack(z) - th_u) @ W @ (unpack(z) - th_u))  # noqa: E731
    sol = minimize(f, z0, method="BFGS", options=dict(maxiter=20_000, gtol=1e-10))
    return float(np.sqrt(min(sol.fun, f(z0))))


def test_distance_against_an_independent_optimiser(rod_finger):
    """The barrier method's distance is never above what BFGS over Cholesky factors reaches from
    the truth (a consistent start) or from gripkit's own answer."""
    for res, _, truth in _monte_carlo(rod_finger, 3, seed=5):
        c = res.consistency
        d_bfgs = _cholesky_search_distance(res, rod_finger, rod_finger.standard_parameters(),
                                           truth[22:])
        assert c.distance <= d_bfgs + 1e-3, (c.distance, d_bfgs)
        # and BFGS started at gripkit's answer finds nothing noticeably nearer
        d_again = _cholesky_search_distance(res, rod_finger, c.standard_parameters,
                                            np.maximum(res.theta[22:], 0))
        assert d_again >= c.distance - 1e-3 * max(1.0, c.distance)


def test_inconsistent_decision_is_the_chi2_test(rod_finger):
    """A negative distal Izz far outside the noise: d beyond the 95 % χ² bound, p-value below
    0.05, the link named; the estimate itself consistent gives d = 0 and p = 1."""
    names = rod_finger.parameter_names
    phi = rod_finger.standard_parameters().copy()
    phi[names.index("Izz_link4")] = -2e-4
    rng = np.random.default_rng(4)
    q, qd, qdd = fourier_states(3_000, 500.0, rng)
    tau = (rod_finger.regressor(q, qd, qdd) @ phi + FC * np.sign(qd) + FV * qd
           + rng.normal(size=q.shape) * NOISE)
    r = identify_dynamics(rod_finger, q, qd, qdd, tau)
    c = r.consistency
    assert not c.consistent and c.distance > c.bound and c.p_value < 0.05
    assert "link 'link4'" in c.failing_links
    assert "physically inconsistent" in c.message() and f"{c.bound:.3g} σ" in c.message()
    d = c.to_dict()
    assert d["dof"] == 28 and d["estimate_consistent"] is False and d["converged"] is True


def test_offsets_are_free_and_armature_is_signed(rod_finger):
    """With offsets and rotor inertias: the offsets do not count in the degrees of freedom (S
    leaves them free), the rotor inertias stay ≥ 0, and d stays below the truth's distance."""
    rng = np.random.default_rng(8)
    q, qd, qdd = fourier_states(3_000, 500.0, rng)
    arm = np.array([0.02, 0.03, 0.01])
    off = np.array([0.01, -0.02, 0.005])
    tau = (rod_finger.rnea(q, qd, qdd) + FC * np.sign(qd) + FV * qd + arm * qdd + off
           + rng.normal(size=q.shape) * NOISE)
    r = identify_dynamics(rod_finger, q, qd, qdd, tau, friction="coulomb-viscous-offset",
                          armature=True, constrained=True)
    c = r.consistency
    assert c.dof == r.theta.size - 3
    phi = np.concatenate([rod_finger.standard_parameters(), arm])
    truth = np.concatenate([r.structure.base(phi), np.ravel(np.column_stack([FC, FV, off]))])
    W = np.linalg.inv(r.covariance)
    assert c.converged, c.solver
    assert c.distance <= _mahalanobis(r.unconstrained_theta, truth, W) + 1e-6
    assert np.all(c.standard_parameters[40:] >= 0)
    assert _mahalanobis(r.theta, truth, W) <= _mahalanobis(r.unconstrained_theta, truth, W) + 1e-6


@pytest.mark.slow
def test_consistency_monte_carlo_long(rod_finger):
    """The same over 300 runs: the truth inside the 95 % χ² region in 92–98 % of them."""
    rows = _monte_carlo(rod_finger, 300, seed=99)
    stats = np.array([_check_run(res, W, truth, rod_finger) for res, W, truth in rows])
    inside = np.mean(stats[:, 0] ** 2 <= chi2.ppf(0.95, 28))
    assert 0.92 <= inside <= 0.98, inside


def test_consistency_fields_survive_the_model_file(rod_finger, tmp_path):
    """dof, bound, p-value, the solver's status and the constrained values round-trip through
    ``save`` / ``load_dynamics_model``."""
    from gripkit.sysid import load_dynamics_model

    (res, _, _), = _monte_carlo(rod_finger, 1, seed=3)
    res.save(tmp_path / "m.json")
    c, c2 = res.consistency, load_dynamics_model(tmp_path / "m.json").consistency
    assert (c2.dof, c2.consistent, c2.inside, c2.converged, c2.iterations, c2.solver) == \
        (c.dof, c.consistent, c.inside, c.converged, c.iterations, c.solver)
    assert (c2.distance, c2.bound, c2.p_value) == pytest.approx((c.distance, c.bound, c.p_value),
                                                                rel=1e-12)
    np.testing.assert_allclose(c2.theta, c.theta, rtol=1e-12)
    assert c2.message() == c.message()


def test_unconverged_projection_says_so(rod_finger, monkeypatch):
    """A projection stopped early (5 Newton steps) reports converged = False, says that its
    distance is an upper bound, and that bound is not below the converged distance."""
    import functools

    import gripkit.sysid.rigid_body.dynamics as dynamics
    import gripkit.sysid.rigid_body.dynamics_projection as dp

    rng = np.random.default_rng(12)
    q, qd, qdd = fourier_states(3_000, 500.0, rng)
    tau = (rod_finger.rnea(q, qd, qdd) + FC * np.sign(qd) + FV * qd
           + rng.normal(size=q.shape) * NOISE)
    full = identify_dynamics(rod_finger, q, qd, qdd, tau).consistency
    monkeypatch.setattr(dynamics, "project_consistent",
                        functools.partial(dp.project_consistent, max_newton=5))
    short = identify_dynamics(rod_finger, q, qd, qdd, tau).consistency
    assert full.converged and not short.converged and short.iterations == 5
    assert short.distance >= full.distance - 1e-9
    assert "stopped after 5 steps" in short.solver and "upper bound" in short.solver
    if not short.consistent:
        assert "did not converge" in short.message()
