"""Subspace identification (N4SID/MOESP/CVA): recovery of a known 2×2 system of order 4 from noisy
data, the innovation model, x0, and agreement with SIPPY's N4SID on the same data."""

import numpy as np
import pytest

from gripkit.errors import DataError, IdentificationError, UnidentifiableError
from gripkit.lti import StateSpace
from gripkit.sysid import moesp, n4sid, pem

from mimo_systems import TRUE_POLES, match_poles, oe_data, two_by_two


@pytest.fixture(scope="module")
def data():
    g = two_by_two()
    u, y = oe_data(g, 4000, 0.05, seed=1)
    return g, u, y


@pytest.mark.parametrize("method", ["n4sid", "moesp", "cva"])
def test_order_found_and_poles_within_sigma(data, method):
    """The order is read off the singular values (4), and the subspace poles lie within 5σ of the
    truth, σ being the PEM covariance of the same data (the subspace estimate is consistent but
    not efficient, so it gets a little more room than the 4σ of the PEM estimate)."""
    g, u, y = data
    m = n4sid(u, y, None, method=method, dt=0.01)
    assert m.order == 4
    sv = m.singular_values
    assert sv[3] > 5 * np.median(sv[10:]) > sv[4]
    r = pem(m, u=u, y=y, form="oe")
    p, cov = r.system.pole_covariance()
    sd = np.sqrt(cov[:, 0, 0] + cov[:, 1, 1])
    i = match_poles(p, TRUE_POLES)
    assert np.all(np.abs(p[i] - TRUE_POLES) <= 4 * sd[i])
    ps = m.system.poles()
    j = match_poles(ps, TRUE_POLES)
    assert np.all(np.abs(ps[j] - TRUE_POLES) <= 5 * sd[i])
    assert m.stable and all(f > 94.5 for f in m.fit_percent)   # 5 % output noise: at best ≈ 95.0 %


def test_fit_matches_noise_level(data):
    """With 5 % white output noise the free-run fit of the true model is 100 (1 − 0.05/√(1+0.05²))
    ≈ 95.0 %; the identified model reaches it within 0.2 points."""
    g, u, y = data
    m = moesp(u, y, 4, dt=0.01)
    expected = 100 * (1 - 0.05 / np.sqrt(1 + 0.05**2))
    assert np.allclose(m.fit_percent, expected, atol=0.3)


def test_innovation_model_recovers_noise_model():
    """Data from a known innovation form (K, Λ): the identified Λ is within 5 % and the noise
    spectrum H(z) = C(zI − A)⁻¹K + I within 0.1 (abs) at five frequencies."""
    rng = np.random.default_rng(5)
    A = np.array([[0.8, 0.3], [-0.3, 0.8]])
    B = np.array([[1.0], [0.5]])
    C = np.array([[1.0, 0.0]])
    K = np.array([[0.6], [0.2]])
    N = 20000
    u = rng.standard_normal((N, 1))
    e = 0.3 * rng.standard_normal((N, 1))
    x = np.zeros(2)
    y = np.empty((N, 1))
    for t in range(N):
        y[t] = C @ x + e[t]
        x = A @ x + B @ u[t] + K @ e[t]
    m = n4sid(u, y, 2, dt=1.0)
    assert m.noise_covariance[0, 0] == pytest.approx(0.09, rel=0.05)
    w = np.array([0.1, 0.5, 1.0, 2.0, 3.0])
    true = StateSpace(A, K, C, np.eye(1), dt=1.0).frequency_response(w)
    est = StateSpace(m.system.A, m.K, m.system.C, np.eye(1), dt=1.0).frequency_response(w)
    assert np.max(np.abs(true - est)) < 0.1


def test_initial_state_estimated(data):
    """A record that starts away from rest: compare() estimates x0 and the fit stays at the noise
    level, while a zero initial state would lose the transient."""
    g, u, _ = data
    x0 = np.array([3.0, -2.0, 1.0, 2.0])
    rng = np.random.default_rng(9)
    y = g.simulate(u[:300], x0=x0)
    y = y + 0.01 * y.std(axis=0) * rng.standard_normal(y.shape)
    m = n4sid(*oe_data(g, 4000, 0.01, seed=2), 4, dt=0.01)
    fit = m.compare(u[:300], y).fit_percent
    assert min(fit) > 98.5


def test_agrees_with_sippy_n4sid(data):
    """SIPPY's N4SID (sippy_unipi, its own implementation) on the same data and order gives the
    same poles within 0.01."""
    import sippy_unipi as sippy
    g, u, y = data
    sys = sippy.system_identification(y.T, u.T, "N4SID", SS_fixed_order=4, SS_f=12, SS_p=12)
    ps = np.linalg.eigvals(np.asarray(sys.A))
    m = n4sid(u, y, 4, dt=0.01)
    p = m.system.poles()
    j = match_poles(ps, p)
    assert np.max(np.abs(ps[j] - p)) < 0.01


def test_noise_free_order_above_data_support_is_refused():
    g = two_by_two()
    rng = np.random.default_rng(0)
    u = rng.standard_normal((2000, 2))
    y = g.simulate(u)
    with pytest.raises(IdentificationError, match="support at most 4"):
        n4sid(u, y, 6)


def test_too_few_samples_for_the_outputs():
    rng = np.random.default_rng(0)
    with pytest.raises(DataError, match="samples"):
        n4sid(rng.standard_normal((50, 2)), rng.standard_normal((50, 2)), 2)


def test_a_zero_channel_is_refused_with_the_estimators_constant_message():
    """A direct n4sid call: an identically zero column is refused by the check and message that
    ``identify`` gives a constant column (checks.check_excitation / check_output_varies)."""
    rng = np.random.default_rng(0)
    u, y = rng.standard_normal((2000, 2)), rng.standard_normal((2000, 1))
    u[:, 1] = 0.0
    with pytest.raises(UnidentifiableError, match=r"^input channel 1 is constant \(0 for all "
                                                  r"2000 samples\): a constant input cannot"):
        n4sid(u, y, 2)
    with pytest.raises(UnidentifiableError, match=r"^output channel 0 is constant \(0 for all "
                                                  r"2000 samples\): there are no dynamics"):
        n4sid(rng.standard_normal((2000, 2)), np.zeros((2000, 1)), 2)


def test_names_units_and_dt_carried(data):
    g, u, y = data
    m = n4sid(u, y, 4, dt=0.01, inputs=["a", "b"], outputs=["c", "d"], output_units=["N", "m"])
    assert m.system.inputs == ("a", "b") and m.system.output_units == ("N", "m") and m.dt == 0.01


def test_stable_by_construction_or_stated_reason():
    """Data from an unstable system (pole 1.01): the shift-invariance estimate is unstable, so the
    default replaces it by A = Γ⁺[Γ↓; 0], stable (Chui & Maciejowski 1996), and says so; with
    stable=False the unstable model is kept with a StabilityWarning."""
    from gripkit.errors import StabilityWarning

    g = StateSpace([[1.01, 0.0], [0.0, 0.5]], [[1.0], [1.0]], [[1.0, 1.0]], dt=1.0)
    u = np.random.default_rng(0).standard_normal((400, 1))
    y = g.simulate(u)
    with pytest.warns(StabilityWarning, match=r"it was stabilised to largest \|pole\| 0\."):
        m = n4sid(u, y, 2)
    assert m.stable and "stable by construction" in m.info["stability"]
    with pytest.warns(StabilityWarning, match="unstable"):
        k = n4sid(u, y, 2, stable=False)
    assert not k.stable and np.max(np.abs(k.system.poles())) == pytest.approx(1.01, abs=1e-3)


def test_bd_x0_normal_equations_equal_least_squares_on_the_regressor():
    """B, D and x0 from the normal equations accumulated without forming Φ equal lstsq on the
    formed regressor; with an input that is zero throughout (two columns of Φ zero: the normal
    equations are singular) the fallback is gelsy's minimum-norm solution on Φ."""
    import scipy.linalg as sla

    from gripkit.sysid.linear.subspace import _bdx_least_squares, _bdx_regressor

    rng = np.random.default_rng(7)
    A = np.array([[0.9, 0.2], [-0.1, 0.7]])
    C = rng.standard_normal((2, 2))
    u = rng.standard_normal((400, 2))
    y = rng.standard_normal((400, 2))
    for uu, ft in ((u, True), (np.column_stack([u[:, 0], np.zeros(400)]), False)):
        Phi = _bdx_regressor(A, C, uu, ft)
        ref = sla.lstsq(Phi, y.reshape(-1), lapack_driver="gelsy")[0]
        np.testing.assert_allclose(_bdx_least_squares(A, C, uu, y, ft), ref, rtol=1e-9, atol=1e-12)
