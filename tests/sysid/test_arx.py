"""ARX least squares: recovery of known parameters, Monte Carlo check of σ, agreement with a
reference least-squares solve, and the MATLAB layout of the result."""

import doctest
import importlib
import math

import numpy as np
import pytest
from arx_cases import A222, B222, THETA222, simulate_arx

from gripkit.sysid import arx


def test_recovers_table2_222_within_3_sigma():
    """Data from Table II [2 2 2] (000_8f66dcc7ab06470c.txt) with white equation noise: every
    estimate lies within 3σ of the truth."""
    u, y = simulate_arx(4000, noise=2.0, seed=3)
    m = arx(u, y, 2, 2, 2)
    assert np.all(np.abs(m.theta - THETA222) < 3 * m.theta_std), (m.theta, m.theta_std)
    assert m.noise_variance == pytest.approx(4.0, rel=0.1)  # σ_e² = 2²


def test_std_agrees_with_monte_carlo_spread():
    """Monte Carlo, 200 repetitions of N = 1000 samples: the spread of the estimates matches the
    mean reported σ within 20 % for every parameter."""
    est, sig = [], []
    for rep in range(200):
        u, y = simulate_arx(1000, noise=2.0, seed=100 + rep)
        m = arx(u, y, 2, 2, 2)
        est.append(m.theta)
        sig.append(m.theta_std)
    spread = np.std(est, axis=0, ddof=1)
    reported = np.mean(sig, axis=0)
    np.testing.assert_allclose(reported / spread, 1.0, atol=0.2)
    # and the estimator is unbiased: mean within 3 standard errors of the truth
    assert np.all(np.abs(np.mean(est, axis=0) - THETA222) < 3 * spread / math.sqrt(200))


def test_agrees_with_reference_lstsq_and_matlab_layout():
    """Same regression solved by numpy's SVD-based lstsq (reference): θ agrees to 1e-9."""
    u, y = simulate_arx(600, noise=1.0, seed=4)
    na, nb, nk = 3, 2, 4
    t0 = max(na, nk + nb - 1)
    Phi = np.column_stack([-y[t0 - i:len(y) - i] for i in range(1, na + 1)]
                          + [u[t0 - nk - j:len(u) - nk - j] for j in range(nb)])
    ref = np.linalg.lstsq(Phi, y[t0:], rcond=None)[0]
    m = arx(u, y, na, nb, nk)
    np.testing.assert_allclose(m.theta, ref, rtol=1e-9, atol=1e-12)
    assert m.A[0] == 1.0 and m.A.size == na + 1
    assert m.B.size == nk + nb and np.all(m.B[:nk] == 0)
    assert m.A_std.shape == m.A.shape and m.A_std[0] == 0
    assert m.B_std.shape == m.B.shape and np.all(m.B_std[:nk] == 0) and np.all(m.B_std[nk:] > 0)
    # covariance = σ² (ΦᵀΦ)⁻¹ (textbook formula, evaluated here the long way as a check)
    e = y[t0:] - Phi @ ref
    s2 = e @ e / (len(e) - na - nb)
    np.testing.assert_allclose(m.covariance, s2 * np.linalg.inv(Phi.T @ Phi), rtol=1e-6)


def test_loss_fit_aic_fpe_definitions():
    """Eq (29) V_N = (1/N)Σ½e²; fit = 100(1 − ‖e‖/‖y − ȳ‖); AIC = N ln(2πV) + N + 2p and
    FPE = V(1 + p/N)/(1 − p/N) with V = Σe²/N (MATLAB's definitions)."""
    u, y = simulate_arx(800, noise=1.0, seed=5)
    m = arx(u, y, 2, 2, 2)
    e = m.estimation_residuals
    n = e.size
    assert n == 800 - 3 == m.n_used and m.n_samples == 800
    assert m.loss == pytest.approx(0.5 * np.mean(e ** 2), rel=1e-12)
    yt = y[3:]
    assert m.fit_percent == pytest.approx(100
                                          * (1 - np.linalg.norm(e)
                                                 / np.linalg.norm(yt - yt.mean())))
    v = np.mean(e ** 2)
    assert m.aic == pytest.approx(n * math.log(2 * math.pi * v) + n + 8)
    assert m.fpe == pytest.approx(v * (1 + 4 / n) / (1 - 4 / n))


@pytest.mark.parametrize("na,nb,nk", [(0, 3, 1), (2, 1, 0), (1, 2, 5)])
def test_other_structures_recover_exact_data(na, nb, nk):
    """Noise-free data from a known model are fitted exactly (FIR na = 0, direct feedthrough nk =
    0)."""
    A = np.r_[1.0, [-0.5, 0.2][:na]] if na else np.ones(1)
    B = np.r_[np.zeros(nk), [0.4, -0.3, 0.1][:nb]]
    u, y = simulate_arx(300, noise=0.0, seed=6, A=A, B=B)
    m = arx(u, y, na, nb, nk)
    np.testing.assert_allclose(m.A, A, atol=1e-10)
    np.testing.assert_allclose(m.B, B, atol=1e-10)


def test_recovers_from_s2_like_bandlimited_excitation():
    """The paper's S2 excitation (0.3–10 Hz band-limited noise, 4000 samples at 200 Hz, 600–1100 mA
    around 850 mA; §V-E) identifies [2 2 2] within 3σ."""
    from gripkit.excitation import bandlimited_noise

    s2 = bandlimited_noise(0.3, 10.0, 20.0, dt=0.005, operating_point=850.0, limits=(600.0, 1100.0))
    u, y = simulate_arx(4000, noise=1.0, seed=8, u=s2.u - 850.0)
    m = arx(u, y, 2, 2, 2, dt=0.005)
    assert m.dt == 0.005
    assert np.all(np.abs(m.theta - THETA222) < 3 * m.theta_std)


def test_docstring_examples_run():
    for name in ("gripkit.sysid.linear.arx", "gripkit.sysid.identify"):
        res = doctest.testmod(importlib.import_module(name))
        assert res.failed == 0 and res.attempted > 0


def test_simulated_truth_matches_seed_coefficients():
    """Guard on the fixture itself: it uses Table II's [2 2 2] numbers."""
    assert A222.tolist() == [1.0, -1.8732, 0.8996] and B222.tolist() == [0, 0, 0.1950, -0.2276]


@pytest.mark.parametrize("na, nb, nk, n", [(2, 2, 2, 4000), (4, 4, 2, 20000), (2, 3, 1, 20000),
                                           (1, 3, 7, 60), (3, 2, 0, 500),
                                           (0, 2, 3, 30)])
def test_lagged_sums_route_equals_qr_of_the_regressor(na, nb, nk, n, monkeypatch):
    """The Gram matrix from compensated lagged sums equals [Φ|Y]ᵀ[Φ|Y] of the materialised
    regressor to rounding (BLOCK·u), and the normal-equations estimate, σ, loss and fit equal the
    QR route's within the derived bound κ²·BLOCK·u (κ: the column-scaled condition number), or
    the QR route is taken when κ exceeds GRAM_COND_LIMIT."""
    from gripkit.sysid.linear.lagged_sums import BLOCK, GRAM_COND_LIMIT, arx_gram
    from gripkit.sysid.regression import arx_regression, arx_start, qr_solve

    # the lagged-sums route at every size
    monkeypatch.setattr(importlib.import_module("gripkit.sysid.linear.arx"), "QR_MAX_ELEMENTS", 0)
    u, y = simulate_arx(n, noise=0.5, seed=11)
    X = arx_regression(u, y, na, nb, nk)
    G = arx_gram(u, y, na, nb, nk, arx_start(na, nb, nk))
    assert np.all(np.abs(G - X.T @ X) <= 4 * BLOCK * 2**-53 * (np.abs(X).T @ np.abs(X)))
    m = arx(u, y, na, nb, nk)
    # an over-parameterised [4 4 2] on this second-order system is near-collinear: QR then
    assert (m.info["method"].startswith("least squares (normal equations")
            == (m.info["cond"] <= GRAM_COND_LIMIT))
    names = tuple(f"p{i}" for i in range(na + nb))
    ref = qr_solve(X, names)
    tol = max(m.info["cond"] ** 2 * BLOCK * 2**-53, 1e-12)
    np.testing.assert_allclose(m.theta, ref.theta, rtol=0, atol=tol * np.max(np.abs(ref.theta)))
    e = X[:, -1] - X[:, :-1] @ ref.theta
    assert m.loss == pytest.approx(0.5 * (e @ e) / e.size, rel=1e-9)
    assert m.fit_percent == pytest.approx(100
                                          * (1 - np.linalg.norm(e)
                                                 / np.linalg.norm(X[:, -1] - X[:, -1].mean())),
                                          rel=1e-9)
    np.testing.assert_allclose(m.theta_std,
                               np.sqrt(np.diag(ref.cov_unscaled) * (e @ e) / (e.size - na - nb)),
                               rtol=1e-8)


@pytest.mark.parametrize("na, nb, nk, n", [(2, 2, 2, 10_000), (4, 4, 2, 8000), (2, 3, 1, 20_000),
                                           (1, 1, 1, 30_000), (0, 3, 1, 12_000)])
def test_blas_normal_equations_route_equals_qr_of_the_regressor(na, nb, nk, n):
    """Regressors of 2^15 … 2^18 elements (N ≈ 10⁴) are solved from the normal equations of the
    BLAS Gram matrix when the column-scaled κ ≤ blas_gram_cond_limit(m) (κ²·m·u ≤ 1e-8: an
    uncompensated sum of m products errs by m·u), else by QR; θ, σ, loss, fit and the residuals
    equal the QR route's within the derived bound κ²·m·u."""
    arx_mod = importlib.import_module("gripkit.sysid.linear.arx")
    from gripkit.sysid.regression import NUMPY_QR_MAX_ELEMENTS, arx_regression, qr_solve

    u, y = simulate_arx(n, noise=0.5, seed=13)
    X = arx_regression(u, y, na, nb, nk)
    assert NUMPY_QR_MAX_ELEMENTS < X.size <= arx_mod.QR_MAX_ELEMENTS
    m = arx(u, y, na, nb, nk)
    rows = X.shape[0]
    blas = m.info["method"].startswith("least squares (normal equations of the BLAS Gram")
    # the over-parameterised [4 4 2] of this second-order system is near-collinear: QR then
    assert blas == (m.info["cond"] <= arx_mod.blas_gram_cond_limit(rows)) == ((na, nb) != (4, 4))
    ref = qr_solve(X, tuple(f"p{i}" for i in range(na + nb)))
    tol = max(m.info["cond"] ** 2 * rows * 2**-53, 1e-12)
    np.testing.assert_allclose(m.theta, ref.theta, rtol=0, atol=tol * np.max(np.abs(ref.theta)))
    e = X[:, -1] - X[:, :-1] @ ref.theta
    scale = np.max(np.abs(X) @ np.append(np.abs(ref.theta), 1.0))  # max Σ|x_j θ_j| over rows
    np.testing.assert_allclose(m.estimation_residuals, e, rtol=0, atol=2 * tol * scale)
    assert m.loss == pytest.approx(0.5 * (e @ e) / rows, rel=1e-9)
    assert m.fit_percent == pytest.approx(
        100 * (1 - np.linalg.norm(e) / np.linalg.norm(X[:, -1] - X[:, -1].mean())), rel=1e-9)
    np.testing.assert_allclose(m.theta_std,
                               np.sqrt(np.diag(ref.cov_unscaled) * (e @ e) / (rows - na - nb)),
                               rtol=4 * tol)
    np.testing.assert_allclose(m.covariance, ref.cov_unscaled * (e @ e) / (rows - na - nb),
                               rtol=4 * tol, atol=4 * tol * np.max(np.abs(m.covariance)))


def test_blas_route_warns_as_the_qr_route(monkeypatch):
    """A barely excited [1 6 1] fit (a sine plus 1.5 % noise, κ ≈ 111, within the BLAS route's
    limit at m = 4594) warns from the normal equations as from QR: an AccuracyWarning naming the
    same poorly determined parameters, at the same condition number (to 3 digits)."""
    import re
    import warnings

    from scipy.signal import lfilter

    from gripkit.errors import AccuracyWarning

    arx_mod = importlib.import_module("gripkit.sysid.linear.arx")
    rng = np.random.default_rng(1)
    n = 4600
    u = np.sin(0.3 * np.arange(n)) + 0.015 * rng.standard_normal(n)
    y = lfilter([0, 1, 0.5, 0.2], [1, -0.5], u) + rng.standard_normal(n)
    fits = []
    for limit in (arx_mod.blas_gram_cond_limit, lambda m: 0.0):  # then QR
        monkeypatch.setattr(arx_mod, "blas_gram_cond_limit", limit)
        with warnings.catch_warnings(record=True) as w:
            warnings.simplefilter("always")
            m = arx(u, y, 1, 6, 1)
        (msg,) = [str(x.message) for x in w if issubclass(x.category, AccuracyWarning)]
        fits.append((m, re.findall(r"(\w+) \(σ/", msg), re.search(r"number (\S+) >", msg)[1]))
    (blas, names_blas, k_blas), (qr, names_qr, k_qr) = fits
    assert blas.info["method"].startswith("least squares (normal equations of the BLAS Gram")
    assert qr.info["method"] == "least squares (QR of [Φ | Y])"
    assert names_blas == names_qr and len(names_blas) >= 2 and k_blas == k_qr
    tol = blas.info["cond"] ** 2 * (n - 6) * 2**-53
    np.testing.assert_allclose(blas.theta, qr.theta, rtol=0, atol=tol * np.max(np.abs(qr.theta)))


@pytest.mark.parametrize("qr_max", [None, 0])
def test_model_built_without_post_init_equals_the_checked_constructor(qr_max, monkeypatch):
    """``arx`` builds its model by ``PolynomialModel._estimated`` (no second copy and check of
    the arrays it made): every field equals the one the checked constructor gives from the same
    values, and the arrays are read-only as the constructor leaves them (BLAS normal-equations
    route at N = 10⁴; with ``QR_MAX_ELEMENTS = 0`` the lagged-sums route, residuals on demand)."""
    import dataclasses

    from gripkit.sysid.linear.polynomial import PolynomialModel

    if qr_max is not None:
        monkeypatch.setattr(importlib.import_module("gripkit.sysid.linear.arx"),
                            "QR_MAX_ELEMENTS", qr_max)
    u, y = simulate_arx(10_000, noise=0.5, seed=17)
    m = arx(u, y, 2, 2, 2, dt=0.01, input_name="i", output_unit="N")
    names = [f.name for f in dataclasses.fields(PolynomialModel)]
    ref = PolynomialModel(**{k: getattr(m, k) for k in names})
    for k in names:
        a, b = getattr(m, k), getattr(ref, k)
        if isinstance(b, np.ndarray):
            np.testing.assert_array_equal(a, b)
            assert a.dtype == b.dtype and not a.flags.writeable and not b.flags.writeable, k
        else:
            assert a == b and type(a) is type(b), k
    assert (m.dt, m.input_name, m.output_unit, m.output_name) == (0.01, "i", "N", "y")


@pytest.mark.parametrize("offset", [0.0, 0.3, 5.0, -1e6])
def test_centred_sum_of_squares_within_its_bound(offset):
    """Σ(y − ȳ)² by ``Σy² − (Σy)²/m`` (mean at most the spread) or from the centred samples
    (larger means) agrees with an exactly rounded sum (math.fsum of the centred squares, the
    mean itself by fsum) within the stated 6·m·u."""
    from fractions import Fraction

    from gripkit.sysid.linear.arx import _centred_sum_of_squares

    y = np.random.default_rng(4).standard_normal(20_000) + offset
    mean = Fraction(math.fsum(y)) / y.size
    exact = float(sum((Fraction(v) - mean) ** 2 for v in y.tolist()))
    assert abs(_centred_sum_of_squares(y) - exact) <= 6 * y.size * 2**-53 * exact


def test_small_problem_takes_the_qr_route_without_numba():
    """2000 samples of [2 2 2] (2000·5 regressor elements, below QR_MAX_ELEMENTS) are solved by QR
    in a fresh process without importing numba, and give the lagged-sums route's estimate."""
    import subprocess
    import sys

    code = ("import sys, numpy as np; from gripkit.sysid import arx; rng = "
            "np.random.default_rng(0); "
            "u = rng.standard_normal(2000); y = np.convolve(u, [0, 0, 0.195, -0.2276])[:2000]; "
            "m = arx(u, y, 2, 2, 2); print(m.info['method'], 'numba' in sys.modules)")
    out = (subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=True).stdout)
    assert out.split()[-1] == "False" and "QR of" in out


def test_ill_conditioned_regressor_takes_the_qr_route(monkeypatch):
    """A nearly collinear input (a slow sine plus 1e-4 noise, two adjacent lags) gives κ above
    GRAM_COND_LIMIT: the normal equations would lose κ²·u of accuracy, so QR is used, and the
    estimate still recovers the exact data."""
    from gripkit.sysid.linear.lagged_sums import GRAM_COND_LIMIT

    # would be small enough for QR anyway
    monkeypatch.setattr(importlib.import_module("gripkit.sysid.linear.arx"), "QR_MAX_ELEMENTS", 0)
    rng = np.random.default_rng(5)
    n = 3000
    u = np.sin(0.001 * np.arange(n)) + 1e-4 * rng.standard_normal(n)
    y = np.zeros(n)
    for t in range(2, n):
        y[t] = 0.5 * y[t - 1] + 1.0 * u[t - 1] - 0.7 * u[t - 2]
    m = arx(u, y, 1, 2, 1)
    assert m.info["cond"] > GRAM_COND_LIMIT
    assert m.info["method"] == "least squares (QR of [Φ | Y])"
    np.testing.assert_allclose(m.theta, [-0.5, 1.0, -0.7], atol=1e-6)


@pytest.mark.parametrize("u_writable, y_writable", [(True, False), (False, True), (False, False)])
def test_read_only_signals_in_any_mix(u_writable, y_writable):
    """Read-only arrays (a Trajectory's channels are) next to writable ones give the same model:
    the lagged-sums kernel once failed to compile for a mixed (read-only, writable) pair."""
    rng = np.random.default_rng(3)
    u = rng.standard_normal(3000)
    y = np.convolve(u, [0.0, 0.5, 0.3])[:3000] + 0.01 * rng.standard_normal(3000)
    ref = arx(u, y, 2, 2, 1, dt=0.01)
    uu, yy = u.copy(), y.copy()
    uu.flags.writeable, yy.flags.writeable = u_writable, y_writable
    np.testing.assert_array_equal(arx(uu, yy, 2, 2, 1, dt=0.01).theta, ref.theta)


def test_large_fit_computes_residuals_on_demand_from_its_record():
    """Above QR_MAX_ELEMENTS the fit keeps no N-sample residual array (issue 14: ARX peak memory);
    ``residuals`` is computed on first access from the record and equals the compensated kernel's
    errors e = y − Φθ to rounding, in the user's units also when the data were scaled for the
    fit."""
    from gripkit.sysid.linear.lagged_sums import arx_residuals

    u, y = simulate_arx(100_000, noise=0.5, seed=21)
    for scale in (1.0, 2.0**120):  # the second one is fitted on scaled copies (peak beyond 2^100)
        m = arx(u, y * scale, 2, 2, 2)
        assert m.info["method"].startswith("least squares (normal equations")
        assert m.stored_residuals is None  # nothing stored by the fit itself
        e_ref, see, _ = arx_residuals(u, y * scale, m.theta, 2, 2, 2, 3)
        e = m.estimation_residuals
        assert m.stored_residuals is e  # computed once, then kept
        assert not e.flags.writeable and e.size == m.n_used == 100_000 - 3
        np.testing.assert_allclose(e, e_ref, rtol=0, atol=1e-12 * scale)
        assert m.loss == pytest.approx(0.5 * see / e.size, rel=1e-12)
        assert m.replace(output_name="y2").estimation_residuals is not None


def test_pickled_model_carries_its_residuals_not_its_record():
    """A model sent to another process (pickle) holds its N residuals, not the 2N samples of the
    record, and equals the original."""
    import pickle

    u, y = simulate_arx(100_000, noise=0.5, seed=24)
    m = arx(u, y, 2, 2, 2)
    data = pickle.dumps(m)
    assert len(data) < 1.1 * 8 * m.n_used  # the residuals, not u and y (16 × N bytes)
    back = pickle.loads(data)
    assert back.estimation_data is None
    np.testing.assert_array_equal(back.estimation_residuals, m.estimation_residuals)
    np.testing.assert_array_equal(back.theta, m.theta)
    assert back.loss == m.loss and back.covariance.tolist() == m.covariance.tolist()


def test_residuals_refuse_a_record_changed_after_the_fit():
    """Changing the estimation record in place before the first access to ``estimation_residuals``
    would give
    another record's errors: a DataError names the cause instead of a silent wrong answer."""
    from gripkit.errors import DataError

    u, y = simulate_arx(100_000, noise=0.5, seed=22)
    m = arx(u, y, 2, 2, 2)
    y[5000:6000] += 3.0
    with pytest.raises(DataError, match="changed in place after the fit"):
        m.estimation_residuals


def test_large_fit_allocates_no_record_sized_array(tmp_path, traced_peak):
    """ARX [2 2 2] on N = 4e5 samples allocates (numpy, traced) under 5 % of its input arrays:
    the Gram pass is O(p²) and the residual sums reuse one block of scratch (before: +50 %, the
    residuals). Measured in a process of its own (``traced_peak``)."""
    u, y = simulate_arx(400_000, noise=0.5, seed=23)
    np.save(tmp_path / "u.npy", u)
    np.save(tmp_path / "y.npy", y)
    setup = ("import sys\nimport numpy as np\nfrom gripkit.sysid import arx\n"
             "u, y = np.load(sys.argv[1]), np.load(sys.argv[2])\n"
             "arx(u[:100_000], y[:100_000], 2, 2, 2)  # kernels loaded outside the measurement")
    method, peak = traced_peak(setup, 'result = arx(u, y, 2, 2, 2).info["method"]',
                               tmp_path / "u.npy", tmp_path / "y.npy")
    assert method.startswith("least squares (normal equations")
    assert peak < 0.05 * (u.nbytes + y.nbytes), peak


@pytest.mark.parametrize("m, q", [(40, 3), (2000, 5), (6000, 6), (9000, 5)])
def test_qr_factor_by_numpy_or_scipy_lapack_is_the_same(m, q):
    """`qr_r` factors regressors up to NUMPY_QR_MAX_ELEMENTS with numpy's geqrf (no scipy.linalg
    import at start-up) and larger ones with scipy's in place (sizes on both sides of 2^15 here):
    R is scipy.linalg.qr's R to rounding, ‖ΔR‖ ≤ 1e-13 ‖R‖ (Householder QR is backward stable,
    Golub & Van Loan Thm 5.2.1: both are exact for X + E with ‖E‖ ≲ m q u ‖X‖)."""
    import scipy.linalg as sla

    from gripkit.sysid.regression import NUMPY_QR_MAX_ELEMENTS, qr_r

    rng = np.random.default_rng(m + q)
    X = np.asfortranarray(rng.standard_normal((m, q)) * np.logspace(-3, 3, q))
    ref = sla.qr(X, mode="r")[0][:q]
    R = qr_r(X.copy(order="F"), True)
    assert (X.size <= NUMPY_QR_MAX_ELEMENTS) == (m * q <= 2**15)
    assert np.allclose(np.abs(R), np.abs(ref), rtol=0, atol=1e-13 * np.abs(ref).max())
    assert np.array_equal(R, np.triu(R))


@pytest.mark.parametrize("trans", [0, 1])
def test_triangular_solve_without_scipy_matches_solve_triangular(trans):
    """`solve_upper` (numpy's gesv on an upper-triangular matrix: no pivoting, so a back
    substitution) against scipy.linalg.solve_triangular, for r1 x = b and r1ᵀ x = b with
    κ(r1) ≈ 1e6: equal within 8·κ·u relative (the forward error bound of a triangular solve,
    Higham, Accuracy and Stability, Thm 8.5), and exact on an integer system."""
    import scipy.linalg as sla

    from gripkit.sysid.regression import solve_upper

    rng = np.random.default_rng(7 + trans)
    r1 = np.triu(rng.standard_normal((6, 6))) + np.diag(np.logspace(0, 3, 6))
    b = rng.standard_normal(6)
    x = solve_upper(r1, b, trans)
    ref = sla.solve_triangular(r1, b, trans=trans)
    kappa = np.linalg.cond(r1)
    assert np.max(np.abs(x - ref)) <= 8 * kappa * 2.0**-53 * np.max(np.abs(ref))
    A = np.array([[2.0, 1.0, -1.0], [0.0, 4.0, 2.0], [0.0, 0.0, 8.0]])
    exact = np.array([1.0, -2.0, 0.5])
    rhs = (A.T if trans else A) @ exact
    assert np.array_equal(solve_upper(A, rhs, trans), exact)
