"""``gripkit.estimation.KalmanFilter`` (issue 27): the time-varying filter equals a textbook
implementation (numpy, the covariance form of Simon, *Optimal State Estimation*, eqs 5.19); its
covariance converges to the stabilising solution of ``scipy.linalg.solve_discrete_are``, whose
gains the steady-state filter uses; an innovation-form model's default filter is its own
predictor (gain K); NEES and NIS on synthetic data lie within their χ² bounds."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import solve_discrete_are
from scipy.stats import chi2

from gripkit.errors import DataError, ModelError
from gripkit.estimation import KalmanFilter
from gripkit.lti import StateSpace
from gripkit.signals import Trajectory
from gripkit.sysid import LinearModel

A = np.array([[0.95, 0.2, 0.0], [-0.2, 0.95, 0.1], [0.0, 0.0, 0.7]])
B = np.array([[0.0, 1.0], [1.0, 0.0], [0.5, 0.5]])
C = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
D = np.zeros((2, 2))
Q = np.diag([1e-2, 2e-2, 5e-3])
R = np.array([[0.04, 0.01], [0.01, 0.09]])
U0, Y0 = (0.3, -1.0), (2.0, 0.5)


def model(K=None, lam=None) -> LinearModel:
    sys = StateSpace(A, B, C, D, dt=0.01, inputs=["u1", "u2"], outputs=["y1", "y2"])
    return LinearModel(sys, "n4sid", K=K, noise_covariance=lam, u_offset=U0, y_offset=Y0)


def synthetic(N, rng, P0=None):
    """States, inputs and measurements of the model with noises of covariance Q and R, from
    x0 = 0 or x0 ~ N(0, P0)."""
    x = np.zeros(3) if P0 is None else np.linalg.cholesky(P0) @ rng.standard_normal(3)
    xs, us, ys = [], [], []
    Lq, Lr = np.linalg.cholesky(Q), np.linalg.cholesky(R)
    for _ in range(N):
        u = np.array(U0) + rng.standard_normal(2)
        y = C @ x + D @ (u - U0) + Lr @ rng.standard_normal(2) + Y0
        xs.append(x)
        us.append(u)
        ys.append(y)
        x = A @ x + B @ (u - U0) + Lq @ rng.standard_normal(3)
    return np.array(xs), np.array(us), np.array(ys)


def textbook(us, ys, P0):
    """x[t|t], P[t|t] by the predict/update recursion, written plainly."""
    x, P, out = np.zeros(3), P0.copy(), []
    for u, y in zip(us, ys):
        du = u - U0
        Kk = P @ C.T @ np.linalg.inv(C @ P @ C.T + R)
        xf = x + Kk @ (y - Y0 - C @ x - D @ du)
        Pf = (np.eye(3) - Kk @ C) @ P
        out.append((xf, Pf))
        x, P = A @ xf + B @ du, A @ Pf @ A.T + Q
    return out


def test_time_varying_filter_equals_the_textbook_one():
    rng = np.random.default_rng(1)
    _, us, ys = synthetic(200, rng)
    P0 = np.eye(3)
    kf = KalmanFilter(model(), Q=Q, R=R, P0=P0)
    for (xr, Pr), u, y in zip(textbook(us, ys, P0), us, ys):
        x, P = kf.step(u, y)
        np.testing.assert_allclose(x, xr, rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(P, Pr, rtol=1e-10, atol=1e-14)


def test_the_covariance_converges_to_the_riccati_solution_and_steady_gains_match():
    P_dare = solve_discrete_are(A.T, C.T, Q, R)
    K_pred = A @ P_dare @ C.T @ np.linalg.inv(C @ P_dare @ C.T + R)
    kf = KalmanFilter(model(), Q=Q, R=R, P0=10 * np.eye(3))
    for _ in range(500):
        kf.step(U0, Y0)
    np.testing.assert_allclose(kf.P_pred, P_dare, rtol=1e-9)
    np.testing.assert_allclose(kf.predictor_gain, K_pred, rtol=1e-12)
    rng = np.random.default_rng(2)
    _, us, ys = synthetic(300, rng)
    steady = KalmanFilter(model(), Q=Q, R=R, steady_state=True).run_arrays(us, ys)
    varying = KalmanFilter(model(), Q=Q, R=R).run_arrays(us, ys)  # starts at the steady P
    np.testing.assert_allclose(steady.x, varying.x, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(varying.P[-1], steady.P[-1], rtol=1e-9)


def test_an_innovation_form_model_is_its_own_predictor():
    """Q = K Λ Kᵀ, R = Λ, S = K Λ: P = 0, predictor gain K; the predictions are the model's."""
    K = np.array([[0.3, 0.0], [0.1, 0.2], [0.0, 0.4]])
    lam = np.array([[0.02, 0.0], [0.0, 0.05]])
    m = model(K, lam)
    kf = KalmanFilter(m)
    np.testing.assert_allclose(kf.predictor_gain, K, rtol=1e-15, atol=1e-16)
    rng = np.random.default_rng(3)
    _, us, ys = synthetic(100, rng)
    run = kf.run(Trajectory(np.arange(100) * 0.01, {"u1": us[:, 0], "u2": us[:, 1],
                                                    "y1": ys[:, 0], "y2": ys[:, 1]}))
    x = np.zeros(3)  # the one-step predictor of the innovation form, written plainly
    for k in range(100):
        du = us[k] - U0
        e = ys[k] - Y0 - C @ x - D @ du
        np.testing.assert_allclose(run.e[k], e, rtol=1e-10, atol=1e-12)
        x = A @ x + B @ du + K @ e
    np.testing.assert_allclose(kf.x_pred, x, rtol=1e-10)
    assert np.max(np.abs(run.P)) < 1e-15


@pytest.mark.parametrize("steady", [False, True])
def test_nees_and_nis_lie_within_their_chi2_bounds(steady):
    """Monte Carlo of M = 60 runs of 80 samples (x0 ~ N(0, P0), the filter's P0): the
    run-averaged NEES (n = 3) and NIS (p = 2)
    at each time lie within the two-sided 99 % bounds of χ²(M n)/M and χ²(M p)/M at ≥ 95 % of
    the times (Bar-Shalom, Li, Kirubarajan, *Estimation with Applications to Tracking*, §5.4)."""
    M, N = 60, 80
    rng = np.random.default_rng(27)
    nees, nis = np.zeros((M, N)), np.zeros((M, N))
    P0 = solve_discrete_are(A.T, C.T, Q, R) if steady else 0.5 * np.eye(3)
    for r in range(M):
        xs, us, ys = synthetic(N, rng, P0)
        run = KalmanFilter(model(), Q=Q, R=R, P0=P0, steady_state=steady).run_arrays(us, ys)
        err = xs - run.x
        nees[r] = np.einsum("ti,tij,tj->t", err, np.linalg.inv(run.P), err)
        nis[r] = np.einsum("ti,tij,tj->t", run.e, np.linalg.inv(run.S), run.e)
    for stat, dof in ((nees.mean(axis=0), 3), (nis.mean(axis=0), 2)):
        lo, hi = chi2.ppf([0.005, 0.995], M * dof) / M
        inside = np.mean((stat >= lo) & (stat <= hi))
        assert inside >= 0.95, (dof, inside)
        assert abs(stat.mean() - dof) < 0.1 * dof


def test_bad_noise_is_refused():
    with pytest.raises(ModelError, match="no innovation gain K"):
        KalmanFilter(model())
    with pytest.raises(ModelError, match="give both Q and R"):
        KalmanFilter(model(), Q=Q)
    with pytest.raises(ModelError, match="R must be positive definite"):
        KalmanFilter(model(), Q=Q, R=np.zeros((2, 2)))
    with pytest.raises(ModelError, match="Q must be a finite 3×3 matrix"):
        KalmanFilter(model(), Q=np.eye(2), R=R)


@pytest.mark.parametrize("steady", [False, True])
def test_run_is_the_step_kernel_over_the_record_and_views_are_read_only(steady):
    """``run_arrays`` (one numba call over the record) gives the states, covariances and
    innovations of ``step`` called sample by sample, bit for bit; ``copy=False`` returns
    read-only views of the filter's buffers, which the next step overwrites."""
    rng = np.random.default_rng(4)
    _, us, ys = synthetic(50, rng)
    run = KalmanFilter(model(), Q=Q, R=R, P0=np.eye(3), steady_state=steady).run_arrays(us, ys)
    kf = KalmanFilter(model(), Q=Q, R=R, P0=np.eye(3), steady_state=steady)
    for k in range(50):
        x, P = kf.step(us[k], ys[k], copy=False)
        np.testing.assert_array_equal(x, run.x[k])
        np.testing.assert_array_equal(P, run.P[k])
        np.testing.assert_array_equal(kf.innovation, run.e[k])
    assert not x.flags.writeable and not P.flags.writeable
    kept = x.copy()
    kf.step(us[0], ys[0], copy=False)
    assert not np.array_equal(x, kept)  # the view follows the filter
    with pytest.raises(ValueError, match="read-only"):
        x[0] = 1.0


def test_wrong_sample_lengths_are_refused():
    kf = KalmanFilter(model(), Q=Q, R=R)
    with pytest.raises(DataError, match="u must hold 2 value"):
        kf.step([1.0], [0.0, 0.0])
    with pytest.raises(DataError, match="y must hold 2 value"):
        kf.step([1.0, 0.0], [0.0, 0.0, 1.0])
    with pytest.raises(DataError, match=r"expected u \(N, 2\) and y \(N, 2\)"):
        kf.run_arrays(np.zeros((5, 2)), np.zeros((4, 2)))


def test_a_sample_given_as_a_row_or_a_list_is_the_same_sample():
    a, b = KalmanFilter(model(), Q=Q, R=R), KalmanFilter(model(), Q=Q, R=R)
    xa, _ = a.step(np.array([[0.5, 1.0]]), np.array([[2.5, 0.0]]))  # (1, m) and (1, p)
    xb, _ = b.step([0.5, 1], (2.5, 0))                                # a list and ints
    np.testing.assert_array_equal(xa, xb)
    assert np.max(np.abs(xa)) > 0.01
