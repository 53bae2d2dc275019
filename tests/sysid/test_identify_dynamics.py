"""Multi-joint inverse-dynamics identification (``gripkit.sysid.identify_dynamics``) recovers the
truth from simulated noisy torques of the DLR/HIT Hand II finger read from a URDF (the zoo model,
``002_ddea254371185ad3.txt`` Appendix F masses and centres of mass, exported by ``to_urdf``):
base parameters and friction within their σ, predicted torque on a new trajectory at the noise
level, σ honest over Monte Carlo runs, and the physical-consistency check names the failing link.
The base-parameter structure is checked against an independent count (the rank of the regressor
on random states)."""

import warnings

import numpy as np
import pytest

from gripkit.errors import DataError, UnidentifiableError
from gripkit.multibody import from_urdf, to_urdf
from gripkit.sysid import identify_dynamics

FC = np.array([0.02, 0.015, 0.01])      # Coulomb friction, N·m
FV = np.array([0.005, 0.004, 0.003])    # viscous friction, N·m·s/rad
NOISE = np.array([1e-3, 2e-3, 5e-4])    # torque noise σ per joint, N·m


@pytest.fixture(scope="module")
def finger(tmp_path_factory):
    """The DLR/HIT finger through the zoo registry (one place to update), as a URDF chain."""
    from gripkit import zoo

    from gripkit.multibody import CoupledChain

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ch = zoo.build("dlr-hit-finger").chain()
        # the zoo's thin-rod tensors (Appendix F) put each phalanx's mass on a line: a
        # pseudo-inertia
        # on the boundary of the consistent set. A solid body (I_xx = 0.2·m·lc², I_yy = I_zz =
        # m·lc²)
        # keeps the truth strictly inside, so "consistent" is decidable at any noise level.
        I = ch.chain.inertia.copy()  # noqa: E741
        for k in range(1, 4):
            I[k, 0, 0] = 0.2 * I[k, 1, 1]
        ch = CoupledChain(ch.chain.replace(inertia=I), ch.coupling, ch.name)
        path = to_urdf(ch, tmp_path_factory.mktemp("u") / "finger.urdf")
    return from_urdf(path, gravity=ch.chain.gravity_vector)


def fourier_states(n, fs, rng, m=3, harmonics=5, f0=0.1, amp=0.3):
    t = np.arange(n) / fs
    q = np.zeros((n, m))
    qd = np.zeros_like(q)
    qdd = np.zeros_like(q)
    for j in range(m):
        for k in range(1, harmonics + 1):
            w = 2 * np.pi * f0 * k * (1 + 0.3 * j)
            a, b = rng.normal(size=2) * amp / k
            q[:, j] += a * np.sin(w * t) + b * np.cos(w * t)
            qd[:, j] += w * (a * np.cos(w * t) - b * np.sin(w * t))
            qdd[:, j] -= w * w * (a * np.sin(w * t) + b * np.cos(w * t))
    return q, qd, qdd


def torques(chain, q, qd, qdd, rng=None, noise=NOISE):
    tau = chain.rnea(q, qd, qdd) + FC * np.sign(qd) + FV * qd
    return tau if rng is None else tau + rng.normal(size=tau.shape) * noise


@pytest.fixture(scope="module")
def fit(finger):
    rng = np.random.default_rng(0)
    q, qd, qdd = fourier_states(20_000, 1000.0, rng)
    return identify_dynamics(finger, q, qd, qdd, torques(finger, q, qd, qdd, rng))


def test_base_structure_rank(finger, fit):
    """The number of base parameters is the rank of the regressor on random states."""
    rng = np.random.default_rng(9)
    Y = finger.regressor(*(rng.uniform(-3, 3, (200, 3)) for _ in range(3))).reshape(600, -1)
    assert fit.n_base == np.linalg.matrix_rank(Y, tol=1e-9 * np.linalg.norm(Y, 2))
    # every base parameter reproduces the standard parameters' torque: Y φ = Y₁ K φ
    q, qd, qdd = fourier_states(50, 100.0, rng)
    Yf = finger.regressor(q, qd, qdd)
    phi = finger.standard_parameters()
    np.testing.assert_allclose(Yf[:, :, fit.structure.independent] @ fit.structure.base(phi),
                               Yf @ phi, atol=1e-13)


def test_recovers_base_parameters_and_friction(finger, fit):
    truth = fit.structure.base(finger.standard_parameters())
    est = np.array(list(fit.base_parameters.values()))
    std = np.array(list(fit.base_parameters_std.values()))
    assert np.all(np.abs(est - truth) < 4.5 * std), np.max(np.abs(est - truth) / std)
    for j, name in enumerate(finger.joint_names):
        f = fit.friction[name]
        assert abs(f["coulomb"] - FC[j]) < 4 * f["coulomb_std"]
        assert abs(f["viscous"] - FV[j]) < 4 * f["viscous_std"]
        assert f["coulomb_std"] < 0.01 * FC[j]
    # the per-joint noise level is estimated
    np.testing.assert_allclose(list(fit.residual_std.values()), NOISE, rtol=0.05)


def test_prediction_on_new_trajectory_at_noise_level(finger, fit):
    rng = np.random.default_rng(7)
    q, qd, qdd = fourier_states(5_000, 1000.0, rng, amp=0.25, f0=0.13)
    clean = torques(finger, q, qd, qdd)
    err = fit.predict(q, qd, qdd) - clean
    # model error far below the noise, so the error against noisy torque is the noise itself
    assert np.all(np.sqrt(np.mean(err ** 2, axis=0)) < 0.2 * NOISE)
    noisy = clean + rng.normal(size=clean.shape) * NOISE
    np.testing.assert_allclose(np.std(fit.predict(q, qd, qdd) - noisy, axis=0), NOISE, rtol=0.1)


def test_sigma_is_honest_monte_carlo(finger):
    """z = (estimate − truth)/σ over 40 independent noisy data sets has unit spread."""
    rng = np.random.default_rng(11)
    q, qd, qdd = fourier_states(3_000, 500.0, rng)
    clean = torques(finger, q, qd, qdd)
    zs = []
    truth = None
    for _ in range(40):
        r = identify_dynamics(finger, q, qd, qdd, clean + rng.normal(size=clean.shape) * NOISE,
                              check_consistency=False)
        if truth is None:
            truth = np.concatenate([r.structure.base(finger.standard_parameters()),
                                    np.ravel(np.column_stack([FC, FV]))])
        zs.append((r.theta - truth) / r.std)
    z = np.array(zs)
    spread = np.std(z, axis=0)
    assert 0.8 < np.median(spread) < 1.2, np.median(spread)
    assert np.all(spread < 1.6) and np.all(spread > 0.55)
    assert abs(np.mean(z)) < 0.15


def test_consistency_true_parameters(finger):
    rng = np.random.default_rng(3)
    q, qd, qdd = fourier_states(4_000, 500.0, rng)
    r = (identify_dynamics(finger, q, qd, qdd,
                           torques(finger, q, qd, qdd) + rng.normal(size=(4000, 3)) * 1e-7))
    assert r.consistency.consistent, r.consistency.message()


def test_inconsistent_link_is_named_and_constrained_fit(finger):
    """A negative Izz of the distal link (a base parameter on its own) has no rigid body behind
    it."""
    names = finger.parameter_names
    phi = finger.standard_parameters().copy()
    phi[names.index("Izz_link4")] = -2e-4
    rng = np.random.default_rng(4)
    q, qd, qdd = fourier_states(6_000, 500.0, rng)
    tau = (finger.regressor(q, qd, qdd) @ phi + FC * np.sign(qd) + FV * qd
           + rng.normal(size=(6000, 3)) * 1e-6)
    r = identify_dynamics(finger, q, qd, qdd, tau)
    assert not r.consistency.consistent
    assert r.consistency.failing_links == ("link 'link4'",)
    assert "link 'link4'" in r.consistency.message() and r.consistency.distance > 10
    rc = identify_dynamics(finger, q, qd, qdd, tau, constrained=True)
    assert rc.base_parameters["Izz_link4"] >= -1e-9
    # the consistent standard parameters reproduce the constrained base parameters
    np.testing.assert_allclose(rc.structure.base(rc.consistency.standard_parameters),
                               rc.theta[:rc.n_base], atol=1e-12)
    from gripkit.sysid.rigid_body.dynamics import pseudo_inertia
    for k in range(4):
        assert np.linalg.eigvalsh(
            pseudo_inertia(rc.consistency.standard_parameters[10 * k:10 * k + 10]))[0] > -1e-12


def test_offset_friction_and_armature(finger):
    rng = np.random.default_rng(5)
    q, qd, qdd = fourier_states(8_000, 500.0, rng)
    arm = np.array([0.02, 0.03, 0.01])
    tau = torques(finger, q, qd, qdd, rng) + arm * qdd + np.array([0.01, -0.02, 0.005])
    r = identify_dynamics(finger, q, qd, qdd, tau, friction="coulomb-viscous-offset", armature=True)
    for j, name in enumerate(finger.joint_names):
        f = r.friction[name]
        assert abs(f["offset"] - [0.01, -0.02, 0.005][j]) < 4 * f["offset_std"]
    # rotor inertias join the base parameters, here always combined with link inertias
    # (e.g. 'Izz_link4 + 0.5·armature_theta3': the distal wire drives links 3 and 4 together)
    truth = r.structure.base(np.concatenate([finger.standard_parameters(), arm]))
    est = np.array(list(r.base_parameters.values()))
    std = np.array(list(r.base_parameters_std.values()))
    assert np.all(np.abs(est - truth) < 4.5 * std)
    assert any("armature_theta3" in name for name in r.armature)


def test_bad_input(finger):
    q = np.zeros((100, 3))
    with pytest.raises(DataError, match=r"qd: expected shape \(N, 3\) for the joints theta1, "
                                        r"theta2, theta3, found \(100, 2\)"):
        identify_dynamics(finger, q, q[:, :2], q, q)
    bad = q.copy()
    bad[5, 1] = np.nan
    with pytest.raises(DataError, match="tau: 1 NaN or inf values \\(first at sample 5, "
                                        "joint theta2\\)"):
        identify_dynamics(finger, q, q, q, bad)
    with pytest.raises(DataError, match="friction: expected one of"):
        identify_dynamics(finger, q, q, q, q, friction="stribeck")
    with pytest.raises(UnidentifiableError, match="the data never excite"):
        identify_dynamics(finger, q, q, q, q)
