"""Missing measurements in the Kalman filters (``KalmanFilter``, ``ExtendedKalmanFilter``,
``UnscentedKalmanFilter``): a NaN in ``y`` is a missing measurement, updated with the measured
outputs only (C's rows and R's rows and columns of the finite ones; none: the time update alone).
Each filter equals a plain numpy filter that skips the update at a fully missing sample and uses
the reduced C, R at a partly missing one (to 1e-10, state and covariance at every sample); one
DataWarning per record gives their count and the first; ``run.missing`` marks them; NEES stays
within its χ² bounds on records with 10 % dropouts. A NaN or ±inf in ``u``, a ±inf in ``y`` is a
DataError naming the sample and the channel; a NaN from ``f`` or ``h`` a ModelError naming the
function and the sample, with the prediction left as it was."""

from __future__ import annotations

import warnings

import numba
import numpy as np
import pytest
from scipy.stats import chi2

from gripkit.errors import DataError, DataWarning, ModelError
from gripkit.estimation import ExtendedKalmanFilter, KalmanFilter, UnscentedKalmanFilter

from kalman_cases import A, B, C, D, P0, Q, R, U0, Y0, f_nb, f_py, h_nb, h_py, model


def record(N, seed, drop=0.0):
    """States, inputs and measurements of the model (x0 ~ N(0, P0)); with ``drop``, each
    measured value is NaN with that probability."""
    rng = np.random.default_rng(seed)
    x, xs, us, ys = np.linalg.cholesky(P0) @ rng.standard_normal(3), [], [], []
    for _ in range(N):
        u = U0 + rng.standard_normal(2)
        xs.append(x)
        us.append(u)
        ys.append(h_py(x, u) + np.linalg.cholesky(R) @ rng.standard_normal(2))
        x = f_py(x, u) + np.linalg.cholesky(Q) @ rng.standard_normal(3)
    ys = np.array(ys)
    ys[rng.random(ys.shape) < drop] = np.nan
    return np.array(xs), np.array(us), ys


def reference(us, ys, P=P0):
    """x[t|t], P[t|t] of the plain filter: at each sample, the update with the rows of C, D
    and the rows and columns of R of the finite measurements (none: no update)."""
    x, P, xs, Ps = np.zeros(3), P.copy(), [], []
    for u, y in zip(us, ys):
        du, ok = u - U0, np.isfinite(y)
        if ok.any():
            Cr, Rr = C[ok], R[np.ix_(ok, ok)]
            K = P @ Cr.T @ np.linalg.inv(Cr @ P @ Cr.T + Rr)
            x = x + K @ (y[ok] - Y0[ok] - Cr @ x - D[ok] @ du)
            P = P - K @ Cr @ P
        xs.append(x)
        Ps.append(P)
        x, P = A @ x + B @ du, A @ P @ A.T + Q
    return np.array(xs), np.array(Ps)


def with_gaps(ys):
    """A copy of ``ys`` with sample 5 missing whole, and output 0 of samples 9 and 10 and
    output 1 of sample 20 missing."""
    y = ys.copy()
    y[5] = np.nan
    y[9:11, 0] = np.nan
    y[20, 1] = np.nan
    return y


FILTERS = {
    "kalman": lambda: KalmanFilter(model(), Q=Q, R=R, P0=P0),
    "ekf python": lambda: ExtendedKalmanFilter(f_py, h_py, Q, R, P0=P0),
    "ekf numba": lambda: ExtendedKalmanFilter(f_nb, h_nb, Q, R, P0=P0),
    "ukf python": lambda: UnscentedKalmanFilter(f_py, h_py, Q, R, P0=P0),
    "ukf numba": lambda: UnscentedKalmanFilter(f_nb, h_nb, Q, R, P0=P0),
}


@pytest.mark.parametrize("name", FILTERS)
def test_missing_samples_update_with_the_measured_outputs(name):
    """Whole and partial gaps: the states and covariances of the reduced-C filter (1e-10), the
    innovations of the missing outputs NaN and the others finite, ``missing`` = isnan(y)."""
    _, us, ys = record(40, 3)
    y = with_gaps(ys)
    with pytest.warns(DataWarning):
        run = FILTERS[name]().run_arrays(us, y)
    xr, Pr = reference(us, y)
    assert np.allclose(run.x, xr, rtol=0, atol=1e-10)
    assert np.allclose(run.P, Pr, rtol=0, atol=1e-10)
    assert np.array_equal(run.missing, np.isnan(y))
    assert np.array_equal(np.isnan(run.e), np.isnan(y))
    assert np.isnan(run.S[9, 0, :]).all() and np.isfinite(run.S[9, 1, 1])
    assert np.allclose(run.x[5], f_py(run.x[4], us[4]), rtol=0, atol=1e-12)  # time update only


@pytest.mark.parametrize("name", FILTERS)
def test_a_run_still_unpacks_to_four_arrays(name):
    """``x, P, e, S = run`` (the four arrays it had before ``missing``) unpacks the run;
    ``run.missing`` = isnan(y) rides outside the tuple (len 4, fields x, P, e, S)."""
    _, us, ys = record(12, 5)
    y = ys.copy()
    y[3] = np.nan
    y[7, 1] = np.nan
    with pytest.warns(DataWarning):
        run = FILTERS[name]().run_arrays(us, y)
    x, P, e, S = run
    assert (x is run.x, P is run.P, e is run.e, S is run.S) == (True,) * 4
    assert len(run) == 4 and run._fields == ("x", "P", "e", "S")
    assert np.array_equal(run.missing, np.isnan(y)) and run.missing.sum() == 3


@pytest.mark.parametrize("name", FILTERS)
def test_steps_skip_the_update_and_keep_the_state_finite(name):
    """``step`` with a whole sample missing: x[t|t] = x[t|t−1], P[t|t] = P[t|t−1]; the next
    finite step gives the reference (the NaN does not reach the state)."""
    _, us, ys = record(3, 4)
    flt = FILTERS[name]()
    flt.step(us[0], ys[0])
    xp, Pp = flt.x_pred.copy(), flt.P_pred.copy()
    x, P = flt.step(us[1], [np.nan, np.nan])
    assert np.allclose(x, xp, rtol=0, atol=1e-14) and np.allclose(P, Pp, rtol=0, atol=1e-14)
    assert np.isnan(flt.innovation).all()
    x, _ = flt.step(us[2], ys[2])
    xr, _ = reference(us, np.vstack([ys[0], [np.nan, np.nan], ys[2]]))
    assert np.allclose(x, xr[2], rtol=0, atol=1e-10)


def test_one_warning_counts_the_samples_and_names_the_first():
    """One DataWarning per record: 4 samples (5 values) missing, the first at sample 5."""
    _, us, ys = record(40, 3)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        KalmanFilter(model(), Q=Q, R=R).run_arrays(us, with_gaps(ys))
    msgs = [str(w.message) for w in caught if issubclass(w.category, DataWarning)]
    assert len(msgs) == 1
    assert "4 of 40 samples have missing (NaN) measurements" in msgs[0]
    assert "5 values; first at sample 5" in msgs[0]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a record without gaps warns nothing
        KalmanFilter(model(), Q=Q, R=R).run_arrays(us, ys)


def test_steady_state_filter_with_missing_samples():
    """Steady gains: a whole gap is the time update alone (x[t|t] = A x[t−1|t−1] + B du,
    P = the steady prediction covariance); a partial gap takes its gain from the steady
    prediction covariance with C's measured row (the one-sample reduced filter)."""
    _, us, ys = record(12, 5)
    y = ys.copy()
    y[4] = np.nan
    y[8, 1] = np.nan
    kf = KalmanFilter(model(), Q=Q, R=R, steady_state=True)
    with pytest.warns(DataWarning):
        run = kf.run_arrays(us, y)
    Pp = kf.P_steady_pred
    assert np.allclose(run.x[4], A @ run.x[3] + B @ (us[3] - U0), rtol=0, atol=1e-12)
    assert np.allclose(run.P[4], Pp, rtol=0, atol=1e-12)
    xp = A @ run.x[7] + B @ (us[7] - U0)
    Cr, Rr = C[:1], R[:1, :1]
    K = Pp @ Cr.T @ np.linalg.inv(Cr @ Pp @ Cr.T + Rr)
    assert np.allclose(run.x[8], xp + K @ (y[8, :1] - Y0[:1] - Cr @ xp - D[:1] @ (us[8] - U0)),
                       rtol=0, atol=1e-10)
    assert np.allclose(run.P[8], Pp - K @ Cr @ Pp, rtol=0, atol=1e-12)
    assert np.allclose(run.P[9], kf.P_steady, rtol=0, atol=0)  # the fixed gains again


@pytest.mark.parametrize("name", ["kalman", "ekf numba", "ukf python"])
def test_nees_with_ten_percent_dropouts(name):
    """30 seeded records of 300 samples, 10 % of the measured values NaN: the filter's NEES
    (from x0 = 0, P0 = I, the true x0 ~ N(0, I)) averaged over the records lies within the
    two-sided 99 % χ² bounds at 95 % of the samples, and its mean over all is 3 ± 0.15
    (Bar-Shalom et al. §5.4)."""
    M, N = 30, 300
    nees = np.empty((M, N))
    for r in range(M):
        xs, us, ys = record(N, 100 + r, drop=0.1)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DataWarning)
            run = FILTERS[name]().run_arrays(us, ys)
        e = xs - run.x
        nees[r] = np.einsum("ki,kij,kj->k", e, np.linalg.inv(run.P), e)
    lo, hi = chi2.ppf([0.005, 0.995], 3 * M) / M
    avg = nees.mean(axis=0)
    assert np.mean((avg > lo) & (avg < hi)) > 0.95
    assert abs(nees.mean() - 3.0) < 0.15


def test_bad_inputs_and_infinite_measurements_name_sample_and_channel():
    """A NaN in u, or a ±inf in y: a DataError naming the sample and the channel, from the
    record and from one step; the filter's state is unchanged by a refused step."""
    _, us, ys = record(10, 6)
    u, y = us.copy(), ys.copy()
    u[4, 1] = np.nan
    for flt in (FILTERS["kalman"](), FILTERS["ekf numba"](), FILTERS["ukf python"]()):
        with pytest.raises(DataError, match=r"run \(sample 4\): u\[4, 1\] is nan \(input channel"
                                            r" 1, sample 4\); the inputs must be finite"):
            flt.run_arrays(u, ys)
    y[7, 0] = -np.inf
    with pytest.raises(DataError, match=r"y\[7, 0\] is -inf .*finite, or NaN for a missing one"):
        FILTERS["ekf python"]().run_arrays(us, y)
    for name, make in FILTERS.items():
        flt = make()
        flt.step(us[0], ys[0])
        xp = flt.x_pred.copy()
        with pytest.raises(DataError, match=r"step: y\[1\] is inf \(output channel 1\)"):
            flt.step(us[0], [1.0, np.inf])
        with pytest.raises(DataError, match=r"step: u\[0\] is inf"):
            flt.step([np.inf, 0.0], ys[0])
        assert np.array_equal(flt.x_pred, xp), name


@numba.njit
def f_nan_nb(x, u):
    return x * np.nan if u[0] > 10.0 else 0.9 * x + u[0]


def f_nan_py(x, u):
    return x * np.nan if u[0] > 10.0 else 0.9 * x + u[0]


def h1(x, u):
    return x.copy()


h1_nb = numba.njit(h1)


@pytest.mark.parametrize("cls", [ExtendedKalmanFilter, UnscentedKalmanFilter])
@pytest.mark.parametrize("jit", [False, True])
def test_non_finite_model_function_is_a_model_error(cls, jit):
    """f returning NaN at sample 3 (u > 10 there): a ModelError naming f and the sample, the
    prediction x_pred, P_pred left as the step found it; h returning NaN names h."""
    f, h = (f_nan_nb, h1_nb) if jit else (f_nan_py, h1)
    u = np.array([[0.0], [1.0], [0.0], [20.0], [0.0]])
    y = np.ones((5, 1))
    with pytest.raises(ModelError, match=r"run \(sample 3\): f\(x, u\) returned a NaN or ±inf"):
        cls(f, h, Q=[[0.1]], R=[[1.0]]).run_arrays(u, y)
    flt = cls(f, h, Q=[[0.1]], R=[[1.0]])
    flt.step([1.0], [1.0])
    xp, Pp = flt.x_pred.copy(), flt.P_pred.copy()
    with pytest.raises(ModelError, match=r"step: f\(x, u\) .*x_pred, P_pred is left as it was"):
        flt.step([20.0], [1.0])
    assert np.array_equal(flt.x_pred, xp) and np.array_equal(flt.P_pred, Pp)
    x, _ = flt.step([0.0], [1.0])  # the filter goes on from its prediction
    assert np.isfinite(x).all()
    with pytest.raises(ModelError, match=r"step: h\(x, u\) returned a NaN or ±inf"):
        cls(lambda x, u: x, lambda x, u: np.full(1, np.nan), Q=[[0.1]], R=[[1.0]]).step(
            [0.0], [1.0])


def test_the_gains_of_a_pattern_of_missing_outputs():
    """``gains_measuring([False, True])`` of the steady filter: P_p C₂ᵀ/Σ₂₂ and A P_p C₂ᵀ/Σ₂₂
    with C₂ the measured row, Σ₂₂ = C₂ P_p C₂ᵀ + R₂₂ (numpy, to 1e-12), column 0 zero; all
    measured: the steady gains; a wrong length is an ArgumentError."""
    from gripkit.errors import ArgumentError

    kf = KalmanFilter(model(), Q=Q, R=R, steady_state=True)
    Pp = kf.P_steady_pred
    c = C[1]
    sig = c @ Pp @ c + R[1, 1]
    Kf, Kp = kf.gains_measuring([False, True])
    np.testing.assert_allclose(Kf[:, 1], Pp @ c / sig, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(Kp[:, 1], A @ Pp @ c / sig, rtol=1e-12, atol=1e-15)
    assert np.array_equal(Kf[:, 0], np.zeros(3)) and np.array_equal(Kp[:, 0], np.zeros(3))
    Kf, Kp = kf.gains_measuring([True, True])
    np.testing.assert_allclose(Kf, kf.filter_gain, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(Kp, kf.predictor_gain, rtol=1e-12, atol=1e-15)
    with pytest.raises(ArgumentError, match="expected 2 booleans"):
        kf.gains_measuring([True])


def test_one_kernel_drops_and_marks_the_missing_outputs_of_every_filter():
    """The linear filter and the EKF/UKF share kalman._drop_missing and _mark_missing (one
    block of code, where each had its own copy): the nonlinear update calls those two and
    blanks no Σ row itself (the filters' results: the tests above)."""
    import inspect

    from gripkit.estimation import kalman
    from gripkit.estimation import nonlinear_kalman as nk

    assert nk._drop_missing is kalman._drop_missing and nk._mark_missing is kalman._mark_missing
    src = inspect.getsource(nk._gain_update.py_func)
    assert "_drop_missing(" in src and "_mark_missing(" in src and "= 1.0" not in src


def test_replace_keeps_the_missing_flags():
    """``run._replace(x=…)`` keeps ``missing`` (it fell back to isnan(e)); unknown fields are
    refused as by any named tuple."""
    from gripkit.estimation.kalman import KalmanRun

    run = KalmanRun(np.zeros((1, 1)), np.zeros((1, 1, 1)), np.array([[1.0, np.nan]]),
                    np.zeros((1, 2, 2)), missing=np.array([[True, True]]))
    again = run._replace(x=np.ones((1, 1)))
    assert again.missing.tolist() == [[True, True]] and again.x[0, 0] == 1.0 and len(again) == 4
    with pytest.raises(ValueError, match="unexpected field"):
        run._replace(y=1)
