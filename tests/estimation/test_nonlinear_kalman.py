"""``ExtendedKalmanFilter`` and ``UnscentedKalmanFilter`` (issue 27), tested as dynamax tests its
nonlinear filters: on a linear model both are the Kalman filter (to 1e-10, state, covariance and
innovation at every sample), with Python and numba model functions and every Jacobian route;
on a nonlinear pendulum with synthetic noise their NEES and NIS lie within the χ² bounds
(Bar-Shalom, Li, Kirubarajan, *Estimation with Applications to Tracking*, §5.4) and they track
the unmeasured angular rate."""

from __future__ import annotations

import numba
import numpy as np
import pytest
from scipy.stats import chi2

from gripkit.errors import ArgumentError, DataError, ModelError
from gripkit.estimation import ExtendedKalmanFilter, KalmanFilter, UnscentedKalmanFilter
from gripkit.signals import Trajectory

from kalman_cases import A, C, P0, Q, R, U0, Y0, f_nb, f_py, h_nb, h_py, model


@numba.njit
def F_nb(x, u):
    return A.copy()


@numba.njit
def H_nb(x, u):
    return C.copy()


def record(N, seed):
    rng = np.random.default_rng(seed)
    x, us, ys = np.linalg.cholesky(P0) @ rng.standard_normal(3), [], []
    for _ in range(N):
        u = U0 + rng.standard_normal(2)
        us.append(u)
        ys.append(h_py(x, u) + np.linalg.cholesky(R) @ rng.standard_normal(2))
        x = f_py(x, u) + np.linalg.cholesky(Q) @ rng.standard_normal(3)
    return np.array(us), np.array(ys)


FILTERS = {
    "ekf python, given Jacobians": lambda: ExtendedKalmanFilter(
        f_py, h_py, Q, R, F=lambda x, u: A, H=lambda x, u: C, P0=P0),
    "ekf python, complex step": lambda: ExtendedKalmanFilter(f_py, h_py, Q, R, P0=P0,
                                                             jacobian="complex"),
    "ekf numba, given Jacobians": lambda: ExtendedKalmanFilter(f_nb, h_nb, Q, R, F=F_nb, H=H_nb,
                                                               P0=P0),
    "ukf of the model": lambda: UnscentedKalmanFilter(model(), Q=Q, R=R, P0=P0),
    "ukf python": lambda: UnscentedKalmanFilter(f_py, h_py, Q, R, P0=P0),
    "ukf numba": lambda: UnscentedKalmanFilter(f_nb, h_nb, Q, R, P0=P0),
    "ukf numba, alpha 0.5, kappa 1": lambda: UnscentedKalmanFilter(f_nb, h_nb, Q, R, P0=P0,
                                                                   alpha=0.5, kappa=1.0),
}


@pytest.mark.parametrize("name", FILTERS)
def test_on_a_linear_model_each_filter_is_the_kalman_filter(name):
    us, ys = record(150, 11)
    ref = KalmanFilter(model(), Q=Q, R=R, P0=P0).run_arrays(us, ys)
    flt = FILTERS[name]()
    half = 75  # the first half step by step, the rest in one run
    for k in range(half):
        x, P = flt.step(us[k], ys[k])
        np.testing.assert_allclose(x, ref.x[k], rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(P, ref.P[k], rtol=1e-10, atol=1e-13)
        np.testing.assert_allclose(flt.innovation, ref.e[k], rtol=1e-10, atol=1e-12)
    run = flt.run_arrays(us[half:], ys[half:])
    for got, want in zip(run, ref):
        np.testing.assert_allclose(got, want[half:], rtol=1e-10, atol=1e-12)


def test_central_differences_agree_with_the_kalman_filter_to_their_rounding():
    """Numba f, h with central-difference Jacobians, the whole record in one kernel call: on a
    linear model the differences are exact but for rounding (ε |f| / δ ≈ 1e-11)."""
    us, ys = record(150, 12)
    ref = KalmanFilter(model(), Q=Q, R=R, P0=P0).run_arrays(us, ys)
    for f, h in ((f_nb, h_nb), (f_py, h_py)):
        run = ExtendedKalmanFilter(f, h, Q, R, P0=P0).run_arrays(us, ys)
        np.testing.assert_allclose(run.x, ref.x, rtol=1e-8, atol=1e-9)
        np.testing.assert_allclose(run.P, ref.P, rtol=1e-8, atol=1e-10)


def test_run_reads_a_models_columns_by_name():
    us, ys = record(40, 13)
    data = Trajectory(np.arange(40) * 0.01, {"y2": ys[:, 1], "u1": us[:, 0], "u2": us[:, 1],
                                             "y1": ys[:, 0]})
    run = UnscentedKalmanFilter(model(), Q=Q, R=R).run(data)
    ref = KalmanFilter(model(), Q=Q, R=R).run_arrays(us, ys)  # both from the steady P
    np.testing.assert_allclose(run.x, ref.x, rtol=1e-10, atol=1e-12)


# -------------------------------------------------------------- a nonlinear pendulum

DT, W2, ZETA, L = 0.01, 19.62, 0.5, 0.5  # g/l (1/s²), damping (1/s), length (m)
QP = np.diag([1e-8, 1e-5])                  # process noise on angle and rate
RP = np.array([[1e-4]])                     # tip position measured to 1 cm


@numba.njit
def pend_f(x, u):
    """Explicit Euler of θ'' = −(g/l) sin θ − ζ θ' + u."""
    out = np.empty(2)
    out[0] = x[0] + DT * x[1]
    out[1] = x[1] + DT * (-W2 * np.sin(x[0]) - ZETA * x[1] + u[0])
    return out


@numba.njit
def pend_h(x, u):
    """The tip's horizontal position l sin θ (m)."""
    out = np.empty(1)
    out[0] = L * np.sin(x[0])
    return out


def pend_record(N, rng, P0p):
    x = np.array([1.0, 0.0]) + np.linalg.cholesky(P0p) @ rng.standard_normal(2)
    xs, us, ys = [], [], []
    for k in range(N):
        u = np.array([2.0 * np.sin(0.5 * k * DT)])
        xs.append(x)
        us.append(u)
        ys.append(pend_h(x, u) + np.sqrt(RP[0, 0]) * rng.standard_normal(1))
        x = pend_f(x, u) + np.linalg.cholesky(QP) @ rng.standard_normal(2)
    return np.array(xs), np.array(us), np.array(ys)


PENDULUM = {"ekf": lambda P0p: ExtendedKalmanFilter(pend_f, pend_h, QP, RP, x0=[1.0, 0.0],
                                                    P0=P0p),
            "ukf": lambda P0p: UnscentedKalmanFilter(pend_f, pend_h, QP, RP, x0=[1.0, 0.0],
                                                     P0=P0p)}


@pytest.mark.parametrize("name", PENDULUM)
def test_nees_and_nis_on_the_pendulum_lie_within_their_chi2_bounds(name):
    """M = 50 runs of 300 samples (1.5 swings of about ±1 rad), x0 ~ N([1, 0], P0): the
    run-averaged NEES (2 dof) and NIS (1 dof) lie within the two-sided 99 % bounds of
    χ²(M·dof)/M at ≥ 90 % of the times, and their time averages within 15 % of the dof."""
    M, N = 50, 300
    P0p = np.diag([1e-3, 1e-2])
    rng = np.random.default_rng(26)
    nees, nis = np.zeros((M, N)), np.zeros((M, N))
    for r in range(M):
        xs, us, ys = pend_record(N, rng, P0p)
        run = PENDULUM[name](P0p).run_arrays(us, ys)
        err = xs - run.x
        nees[r] = np.einsum("ti,tij,tj->t", err, np.linalg.inv(run.P), err)
        nis[r] = run.e[:, 0] ** 2 / run.S[:, 0, 0]
    for stat, dof in ((nees.mean(axis=0), 2), (nis.mean(axis=0), 1)):
        lo, hi = chi2.ppf([0.005, 0.995], M * dof) / M
        inside = np.mean((stat >= lo) & (stat <= hi))
        assert inside >= 0.90, (dof, inside)
        assert abs(stat.mean() - dof) < 0.15 * dof, (dof, stat.mean())


@pytest.mark.parametrize("name", PENDULUM)
def test_the_filters_track_the_pendulums_unmeasured_rate(name):
    """Started 0.3 rad and 2 rad/s off, from the tip position alone: after 1 s the angle is
    within 3 mrad RMS (the measurement alone gives ≈ 20 mrad near θ = 1) and the rate within
    0.05 rad/s RMS of the truth (its swing is ±4 rad/s)."""
    rng = np.random.default_rng(8)
    xs, us, ys = pend_record(1000, rng, np.diag([1e-12, 1e-12]))
    flt = (ExtendedKalmanFilter if name == "ekf" else UnscentedKalmanFilter)(
        pend_f, pend_h, QP, RP, x0=[0.7, 2.0], P0=np.diag([0.1, 4.0]))
    run = flt.run_arrays(us, ys)
    err = np.sqrt(np.mean((run.x[100:] - xs[100:]) ** 2, axis=0))
    assert err[0] < 3e-3 and err[1] < 0.05, err
    assert np.ptp(xs[:, 1]) > 6.0  # the rate does swing
    first = np.abs(run.x[0] - xs[0])
    assert first[1] > 1.0  # and the filter did not start on it


# -------------------------------------------------------------- bad input


def test_bad_functions_and_arguments_are_refused():
    with pytest.raises(ModelError, match=r"f\(x, u\) returned the wrong number of values"):
        ExtendedKalmanFilter(lambda x, u: x[:1], h_py, Q, R).step(U0, Y0)
    with pytest.raises(ModelError, match=r"h\(x, u\) returned the wrong number of values"):
        UnscentedKalmanFilter(f_py, lambda x, u: x, Q, R).step(U0, Y0)
    with pytest.raises(ModelError, match="a Jacobian returned the wrong shape"):
        ExtendedKalmanFilter(f_py, h_py, Q, R, F=lambda x, u: A, H=lambda x, u: A).step(U0, Y0)
    with pytest.raises(ModelError, match="R must be positive definite"):
        ExtendedKalmanFilter(f_py, h_py, Q, np.zeros((2, 2)))
    with pytest.raises(ArgumentError, match="jacobian must be 'central' or 'complex'"):
        ExtendedKalmanFilter(f_py, h_py, Q, R, jacobian="forward")
    with pytest.raises(ArgumentError, match="give both Jacobians F and H"):
        ExtendedKalmanFilter(f_py, h_py, Q, R, F=lambda x, u: A)
    with pytest.raises(ArgumentError, match="give the noise covariances"):
        UnscentedKalmanFilter(model())
    with pytest.raises(DataError, match="y must hold 2 value"):
        UnscentedKalmanFilter(f_nb, h_nb, Q, R).step(U0, [1.0])
    with pytest.raises(ModelError, match="x0 must hold 3 values"):
        UnscentedKalmanFilter(f_py, h_py, Q, R, x0=[0.0])


def test_kernels_that_take_model_functions_are_not_disk_cached():
    """numba keys a cache entry of a kernel with function arguments by those functions' types: a
    model's functions are new objects in every process, so such entries can never be hit, and the
    index they grow by one per process fails to load after a while ("ReferenceError: underlying
    object has vanished", numba issues #2956, #9348; seen here after many test runs). Those
    kernels compile per process; the ones without function arguments stay cached."""
    import inspect

    from numba.core.caching import NullCache

    from gripkit.estimation import nonlinear_kalman as nk

    takes_functions = {"f", "h", "fn", "Jf", "Jfn", "Fj", "Hj"}
    kernels = {name: obj for name, obj in vars(nk).items()
               if isinstance(obj, numba.core.registry.CPUDispatcher)}
    with_functions = {name for name, k in kernels.items()
                      if takes_functions & set(inspect.signature(k.py_func).parameters)}
    assert {"_ekf_step_jit", "_ukf_run_jit", "_jac_central"} <= with_functions
    for name in with_functions:
        assert isinstance(kernels[name]._cache, NullCache), name
    assert any(not isinstance(k._cache, NullCache) for name, k in kernels.items()
               if name not in with_functions)
