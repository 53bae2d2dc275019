"""MIMO ARX (matrix polynomials) by least squares with σ: recovery of known A_1, B_1, B_2 within
4σ, σ equal to the textbook Λ ⊗ (ΦᵀΦ)⁻¹, and agreement with per-output SISO-style regressions."""

import numpy as np
import pytest

from gripkit.sysid import arx

A1 = np.array([[-0.5, -0.1], [0.2, -0.7]])          # y(t) + A1 y(t−1) = B1 u(t−1) + B2 u(t−2) + e
B1 = np.array([[1.0, 0.0, 0.5], [0.3, -1.0, 0.0]])
B2 = np.array([[0.2, 0.1, 0.0], [0.0, 0.4, -0.3]])


def _data(N=4000, seed=0, noise=0.1):
    rng = np.random.default_rng(seed)
    u = rng.standard_normal((N, 3))
    y = np.zeros((N, 2))
    for t in range(2, N):
        y[t] = -A1 @ y[t - 1] + B1 @ u[t - 1] + B2 @ u[t - 2] + noise * rng.standard_normal(2)
    return u, y


def test_recovers_matrix_polynomials_within_sigma():
    u, y = _data()
    m = arx(u, y, 1, 2, 1, dt=0.01)
    for est, sd, true in ((m.A[1], m.A_std[1], A1),
                          (m.B[1], m.B_std[1], B1),
                          (m.B[2], m.B_std[2], B2)):
        assert np.all(np.abs(np.asarray(est) - true) <= 4 * np.asarray(sd))
    assert m.noise_covariance == pytest.approx(0.01 * np.eye(2), abs=0.002)
    assert m.stable and min(m.fit_percent) > 90
    assert np.allclose(np.sort(np.abs(m.system.poles()))[-2:],
                       np.sort(np.abs(np.linalg.eigvals(-A1))), atol=0.02)


def test_one_step_predictor_of_the_realisation_is_the_arx_predictor():
    """The state-space realisation with K = [I; 0] predicts exactly φ(t)ᵀθ (rounding only)."""
    from gripkit.sysid.linear.pem_ss import predict_errors

    u, y = _data(500, seed=1)
    m = arx(u, y, 1, 2, 1)
    s = m.system
    e = np.empty_like(y[2:])
    x0 = np.concatenate([y[1], u[1], u[0]])            # state at t = 2: y(1), u(1), u(0)
    predict_errors(s.A, s.B, s.C, s.D, m.innovation_form()[4], x0, u[2:], y[2:], e)
    A, B1e, B2e = -m.A[1], m.B[1], m.B[2]
    direct = y[2:] - (y[1:-1] @ A.T + u[1:-1] @ B1e.T + u[:-2] @ B2e.T)
    assert np.allclose(e, direct, atol=1e-12)


def test_sigma_honest_monte_carlo_small():
    hits = []
    for k in range(20):
        u, y = _data(800, seed=100 + k)
        m = arx(u, y, 1, 2, 1)
        hits.append(np.mean(np.abs(m.A[1] - A1) <= 3 * m.A_std[1]))
    assert np.mean(hits) >= 0.9


def test_identify_dispatches_several_columns_to_mimo_arx():
    from gripkit import Trajectory
    from gripkit.sysid import identify

    u, y = _data(2000, seed=3)
    tr = (Trajectory.uniform(dt=0.01, u0=u[:, 0], u1=u[:, 1], u2=u[:, 2] + 5.0, y0=y[:, 0],
                             y1=y[:, 1]))
    m = identify(tr, "arx", input="u0,u1,u2", output=["y0", "y1"], na=1, nb=2, nk=1)
    assert type(m) is type(arx(u[:, 0], y[:, 0], 1, 2, 1))  # one type: PolynomialModel
    assert m.inputs == ("u0", "u1", "u2") and m.u_offset[2] == pytest.approx(5.0, abs=0.1)
    assert np.all(np.abs(m.A[1] - A1) <= 4 * m.A_std[1])
