"""Carried states of the state-space kernels never hold subnormal numbers (< 2.2e-308), whose
arithmetic takes a microcode assist on Intel CPUs (each multiply ~100 cycles): a free response
x ← A x of a stable A sinks into that range and, for a non-normal A, stays there in a rounding
limit cycle. The kernels flush carried entries below 1e-280 to zero (gripkit.lti.flush_tiny):
what is left of a decayed response then stays below Σ‖Aᵏ‖·1e-280·√n (normal numbers), and the
sums the kernels accumulate equal the formed regressor's products at the usual rounding level.
CPU-independent: the tests look at the numbers, not at timings."""

import numpy as np
import pytest

from gripkit.lti import flush_tiny, simulate_ss
from gripkit.sysid.linear.linear_model import observability_regressor
from gripkit.sysid.linear.pem_ss import (_directions, _predict_sensitivity, _predict_states,
                                  _sensitivity_gram)
from gripkit.sysid.linear.subspace import _bdx_normal_equations, _bdx_regressor

TINY = np.finfo(np.float64).tiny  # 2.2250738585072014e-308, the smallest normal number
#: 0.95**t < 1e-308 from t ≈ 13 800: the free responses spend more than half the record there
N_LONG = 30_000


def _subnormal(a) -> int:
    """How many entries of ``a`` are subnormal (non-zero, below the smallest normal number)."""
    a = np.asarray(a)
    return int(np.count_nonzero((a != 0) & (np.abs(a) < TINY)))


def _stable_nonnormal():
    """A 4-state stable A with poles 0.95 e^{±0.3i}, 0.8, −0.6 in a random (non-normal) basis."""
    rng = np.random.default_rng(11)
    z = 0.95 * np.exp(0.3j)
    Ad = np.zeros((4, 4))
    Ad[:2, :2] = [[z.real, z.imag], [-z.imag, z.real]]
    Ad[2, 2], Ad[3, 3] = 0.8, -0.6
    T = rng.standard_normal((4, 4))
    return T @ Ad @ np.linalg.inv(T), rng


def _flush_bound(A) -> float:
    """The largest magnitude a decayed free response can keep under flushing: each step perturbs
    the state by at most 1e-280 per entry (‖δ‖ ≤ 1e-280·√n), so x stays within
    Σ_k ‖Aᵏ‖₂ · 1e-280·√n of the exact (vanishing) response."""
    Ak, total, term = np.eye(A.shape[0]), 0.0, 1.0
    while term > 1e-20 * total:  # the geometric tail beyond adds nothing
        term = np.linalg.norm(Ak, 2)
        total += term
        Ak = A @ Ak
    return total * 1e-280 * np.sqrt(A.shape[0])


def test_flush_tiny_threshold():
    """Entries below 1e-280 become zero, the rest (and NaN, ±inf) pass unchanged."""
    assert flush_tiny(9.99e-281) == 0.0 and flush_tiny(-5e-300) == 0.0 and flush_tiny(5e-320) == 0.0
    assert flush_tiny(1e-280) == 1e-280 and flush_tiny(-3.5) == -3.5
    assert np.isnan(flush_tiny(np.nan)) and flush_tiny(-np.inf) == -np.inf


def test_unflushed_free_response_would_be_subnormal():
    """The premise: iterating x ← A x in numpy (no flushing) leaves subnormal entries at the end
    of the record, so the kernels below would carry them without the flush."""
    A, _ = _stable_nonnormal()
    X = np.eye(4)
    n_sub = 0
    for _ in range(N_LONG):
        X = A @ X
        n_sub = max(n_sub, _subnormal(X))
    assert n_sub > 0


def test_bdx_normal_equations_carry_no_subnormals_and_match_the_regressor():
    """B/D/x0 normal equations over 30 000 samples: the final carried state (the x0 columns are
    A^N) has no subnormal entry and is zero in those columns, and ΦᵀΦ, Φᵀy equal the products of
    the formed regressor (numpy, unflushed) to 1e-12 of their largest entry."""
    A, rng = _stable_nonnormal()
    C = rng.standard_normal((2, 4))
    u = rng.standard_normal((N_LONG, 2))
    y = rng.standard_normal((N_LONG, 2))
    cols = 4 * 2 + 2 * 2 + 4
    G, r = np.empty((cols, cols)), np.empty(cols)
    X = _bdx_normal_equations(A, C, u, y, True, G, r)
    assert X.shape == (4, 12)
    assert _subnormal(X) == 0
    # the x0 columns are A^N, ‖A^N‖ ≈ 0.95^30000 ≈ 1e-668: what flushing leaves is within the bound
    assert 0.0 < _flush_bound(A) < 1e-276 and np.abs(X[:, 8:]).max() <= _flush_bound(A)
    Phi = _bdx_regressor(A, C, u, True).reshape(-1, cols)
    np.testing.assert_allclose(G, Phi.T @ Phi, rtol=0, atol=1e-12 * np.abs(G).max())
    np.testing.assert_allclose(r, Phi.T @ y.reshape(-1), rtol=0, atol=1e-12 * np.abs(r).max())


@pytest.mark.parametrize("innovation", [False, True])
def test_pem_sensitivities_carry_no_subnormals(innovation):
    """PEM Gauss-Newton terms over 30 000 samples: the final sensitivity state S of the unit
    directions and of x0 (free responses of A − KC) has no subnormal entry, and neither has the
    Jacobian J formed by the parallel kernel (its x0 columns are C (A − KC)^t)."""
    A, rng = _stable_nonnormal()
    n, m, p = 4, 1, 2
    B, C = rng.standard_normal((n, m)), rng.standard_normal((p, n))
    D = np.zeros((p, m))
    K = 0.05 * rng.standard_normal((n, p)) if innovation else np.zeros((n, p))
    assert np.max(np.abs(np.linalg.eigvals(A - K @ C))) < 1.0
    x0 = rng.standard_normal(n)
    u, y = rng.standard_normal((N_LONG, m)), rng.standard_normal((N_LONG, p))
    dA, dB, dC, dD, dK, entries = _directions(A, B, C, D, K, False, innovation)
    e, X = np.empty((N_LONG, p)), np.empty((N_LONG, n))
    _predict_states(A, B, C, D, K, x0, u, y, e, X)
    Q = entries.shape[0] + n
    H, g = np.empty((Q, Q)), np.empty(Q)
    S = _sensitivity_gram(np.ascontiguousarray(A - K @ C), C, K, entries, n, X, u, e, H, g)
    assert _subnormal(S) == 0
    # the x0 directions have decayed: what flushing leaves is within the bound
    assert np.abs(S[:, entries.shape[0]:]).max() <= _flush_bound(A - K @ C)
    _, J = _predict_sensitivity(A, B, C, D, K, dA, dB, dC, dD, dK, x0, u, y)
    assert _subnormal(J) == 0
    np.testing.assert_allclose(H, J.T @ J, rtol=0, atol=1e-12 * np.abs(H).max())


def test_simulation_and_observability_regressor_carry_no_subnormals():
    """simulate_ss from x0 with zero input (a free response) ends with no subnormal state entry and
    within the flushing bound of zero, and every output is zero or normal; so is O[t] = C A^t,
    which estimate_x0 forms for a whole validation record."""
    A, rng = _stable_nonnormal()
    C = rng.standard_normal((2, 4))
    x = np.ones(4)
    y = np.empty((N_LONG, 2))
    simulate_ss(A, np.zeros((4, 1)), C, np.zeros((2, 1)), np.zeros((N_LONG, 1)), x, np.empty(4), y)
    assert _subnormal(x) == 0 and np.abs(x).max() <= _flush_bound(A)
    assert _subnormal(y) == 0
    assert np.all(y[:100] != 0.0)  # the start of the response is untouched
    assert _subnormal(observability_regressor(A, C, N_LONG)) == 0


@pytest.mark.parametrize("method", ["zoh", "rk4"])
def test_continuous_integrators_carry_no_subnormals(method):
    """integrate_lti (exact ZOH step and RK4, the steps of the hybrid and piezo simulators) of an
    unforced damped oscillator (ω = 100 rad/s, ζ = 0.5, 1 ms steps) from x0 over 30 000 steps:
    the response decays as e^{-50 t}, past 1e-308 after ~14 s, and every output is zero or a
    normal number, the last within the flushing bound; the first 0.2 s match the analytic
    response (ZOH to 1e-9; RK4 to 1e-5: its local error (ωh)⁵/120 ≈ 8e-8 over ~20 steps per
    e-fold of the decay)."""
    from scipy.linalg import expm

    from gripkit.sim.integrators import integrate_lti

    w, z = 100.0, 0.5
    A = np.array([[0.0, 1.0], [-w * w, -2 * z * w]])
    y = integrate_lti(A, np.zeros((2, 1)), np.eye(2), np.zeros((2, 1)), np.zeros((N_LONG, 1)), 1e-3,
                      np.array([1.0, 0.0]), method=method)
    assert _subnormal(y) == 0
    assert np.abs(y[-1]).max() <= _flush_bound(expm(1e-3 * A))  # the step's transition matrix
    t = np.arange(200) * 1e-3
    wd = w * np.sqrt(1 - z * z)
    exact = np.exp(-z * w * t) * (np.cos(wd * t) + z / np.sqrt(1 - z * z) * np.sin(wd * t))
    np.testing.assert_allclose(y[:200, 0], exact, rtol=0, atol=1e-9 if method == "zoh" else 1e-5)


def test_kalman_and_lqg_states_end_normal():
    """The general Kalman filter (x_p, and P_p where Q = 0 lets it decay from P0 = I) and the LQG
    controller's predicted state, run from x0 = (1, …, 1) on 30 000 zero samples (a sensor at
    rest with its offset removed reads exact zeros): no carried entry ends subnormal, and x_p
    stays within the flushing bound of the vanishing exact response."""
    from gripkit.control.lqg import LQG
    from gripkit.estimation import KalmanFilter
    from gripkit.lti import StateSpace
    from gripkit.sysid import LinearModel

    A, _ = _stable_nonnormal()
    B, C = np.array([[1.0], [0.0], [0.5], [0.0]]), np.array([[1.0, 0.0, 0.0, 0.0]])
    model = LinearModel(StateSpace(A, B, C, np.zeros((1, 1)), dt=0.01), "n4sid")
    zeros = np.zeros((N_LONG, 1))
    kf = KalmanFilter(model, Q=np.zeros((4, 4)), R=[[1.0]], x0=np.ones(4), P0=np.eye(4))
    kf.run_arrays(zeros, zeros)
    assert _subnormal(kf.x_pred) == 0 and _subnormal(kf.P_pred) == 0 and _subnormal(kf.P) == 0
    assert 0 < np.abs(kf.P_pred).max() < 1e-270   # P_p did decay (to the flushing floor)
    assert np.abs(kf.x_pred).max() <= _flush_bound(A)
    ctrl = LQG(model, Q=np.eye(4), R=[[1.0]], Qn=np.eye(4), Rn=[[1.0]])
    ctrl.x_pred[:] = 1.0
    for _ in range(N_LONG // 10):   # the closed loop decays faster than A alone
        ctrl.step([0.0], [0.0], copy=False)
    assert _subnormal(ctrl.x_pred) == 0
