"""The extended and unscented Kalman filters on gripkit's own models (issue 27):
``UnscentedKalmanFilter(model, Q=, R=)`` / ``ExtendedKalmanFilter(model, Q=, R=)`` through
:func:`gripkit.estimation.state_functions.state_functions`.

(1) The state functions reproduce each model's own noise-free simulation (to 1e-12).
(2) For each family, the true model is simulated with seeded process noise ``w ~ N(0, Q)`` and
measurement noise ``v ~ N(0, R)`` (M Monte Carlo runs of N samples), and both filters, built from
the model, are run: the filtered output ``h(x[t|t], u)`` is closer to the noise-free output than
the measurement is (RMS ratio < 0.8), and the average NEES of the hidden states over the M runs
lies inside the two-sided 99 % χ²(M·d)/M band (Bar-Shalom, Li, Kirubarajan, *Estimation with
Applications to Tracking*, §5.4) on at least 90 % of the samples.
(3) On a linear grey-box model (MassSpringDamper), the UKF is the Kalman filter of the same
discrete model to 1e-8 at every sample.
(4) A model without what the filters need raises ModelError naming it.
(5) A grey-box model's own ``state_functions(dt)`` is used; the functions are cached per model
and built again when a value changes."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.stats import chi2

from gripkit.errors import ArgumentError, ModelError
from gripkit.estimation import ExtendedKalmanFilter, KalmanFilter, UnscentedKalmanFilter
from gripkit.estimation.state_functions import state_functions, state_labels
from gripkit.lti import StateSpace
from gripkit.models import BoucWen, MassSpringDamper, PiezoActuator
from gripkit.params import Parameter, ParameterSet
from gripkit.signals import Trajectory
from gripkit.sim.model import Model, Signal
from gripkit.sysid import LinearModel
from gripkit.sysid.nonlinear.hammerstein_wiener import HWModel, Nonlinearity
from gripkit.sysid.nonlinear.hysteresis import (BoucWenModel, BoucWenOscillatorModel,
                                               PrandtlIshlinskiiModel)
from gripkit.sysid.nonlinear.narx import NARXModel
from gripkit.sysid.nonlinear.nlss import NLSSModel, monomial_exponents

M_RUNS, N = 20, 300
DT = 0.05


def _input(n=N, seed=0):
    t = np.arange(n) * DT
    rng = np.random.default_rng(seed)
    return (np.sin(0.9 * t) + 0.5 * np.sin(2.3 * t + 1.0) + 0.1 * rng.standard_normal(n))[:, None]


def msd():
    return MassSpringDamper(m=1.0, b=0.4, k=4.0)


def hw():
    # saturation into B/F (nb = nf = 2, nk = 1) into a cubic output: theta = [lo, hi, b1, b2,
    # f1, f2, c2, c3, y0]
    return HWModel(Nonlinearity("saturation"), Nonlinearity("poly", 3), 2, 2, 1,
                   np.array([-0.8, 0.8, 0.4, 0.2, -1.2, 0.5, 0.1, -0.05, 0.3]),
                   np.zeros(9), np.zeros((9, 9)), dt=DT, y_range=(-10.0, 10.0))


def bw():
    return BoucWenModel(d=1.0, alpha=0.6, beta=1.5, gamma=0.5, offset=0.1, dt=DT)


def bwo():
    return BoucWenOscillatorModel(mass=1.0, damping=0.5, k_e=2.0, k_h=1.0, beta=1.0, gamma=0.5,
                                  dt=DT, substeps=4)


def narx():
    # y(t) = 1.2 y(t−1) − 0.5 y(t−2) + 0.5 u(t−1) − 0.05 y(t−1)³ + 0.05 y(t−1) u(t−1)
    bases = np.array([[0, 1], [0, 2], [1, 1]])
    rows = np.array([[0, -1, -1], [1, -1, -1], [2, -1, -1], [0, 0, 0], [0, 2, -1]])
    theta = np.array([1.2, -0.5, 0.5, -0.05, 0.05])
    return NARXModel(2, 1, 3, False, bases, rows, theta, np.zeros(5), np.zeros((5, 5)), dt=DT,
                     y_range=(-10.0, 10.0))


def nlss():
    # 2 states, 2 inputs, 2 outputs, degree 3 with feedthrough: ζ and η over [x; ũ] (30 terms
    # each), small seeded coefficients; ũ = (u − [0.2, −0.1]) / [0.7, 1.3]
    exz = monomial_exponents(2, 2, 3)
    exe = monomial_exponents(2, 2, 3, inputs=True)
    rng = np.random.default_rng(26)
    return NLSSModel(A=np.array([[0.8, 0.2], [-0.2, 0.7]]), B=np.array([[0.5, 0.1], [0.0, 0.3]]),
                     C=np.array([[1.0, 0.3], [0.2, -0.5]]), D=np.array([[0.1, 0.0], [0.05, 0.2]]),
                     E=0.02 * rng.standard_normal((2, len(exz))),
                     F=0.02 * rng.standard_normal((2, len(exe))), exz=exz, exe=exe,
                     u_offset=np.array([0.2, -0.1]), u_scale=np.array([0.7, 1.3]),
                     y_offset=np.array([0.3, -1.0]), dirs=np.zeros((0, 3), dtype=np.int64),
                     covariance=np.zeros((0, 0)), x0=np.zeros(2), state_limit=1e3, dt=DT,
                     degree=3, feedthrough=True, input_names=("u1", "u2"),
                     output_names=("y1", "y2"))


def _nlss_input(n, seed=0):
    return np.column_stack([_input(n, seed)[:, 0], 0.8 * _input(n, seed + 1)[:, 0]])


def pi():
    # four plays (r = 0 … 0.6, all driven by the ±1.5 input), input offset a = 0.05
    return PrandtlIshlinskiiModel(thresholds=np.array([0.0, 0.2, 0.4, 0.6]),
                                  weights=np.array([0.5, 0.3, 0.2, 0.1]), offset=0.1,
                                  input_offset=0.05, dt=DT)


def _piezo():
    return PiezoActuator(loads=False)


def _piezo_input(n):
    t = np.arange(n) * 2e-5
    return 60.0 * np.sin(2 * np.pi * 200 * t)[:, None] + 30.0


# ---------------------------------------------------------------- (1) the model's own simulation


def _free_run(f, h, x, u):
    y = []
    for k in range(len(u)):
        y.append(np.array(h(x, u[k])))
        x = np.array(f(x, u[k]))
    return np.array(y)


def test_state_functions_reproduce_each_models_simulation():
    u = _input(200)
    m = msd()
    f, h, x0, nx = state_functions(m, dt=DT)
    assert nx == 2 and state_labels(m, dt=DT) == ["x", "v"]
    ref = m.simulate(u, dt=DT)["x"]
    np.testing.assert_allclose(_free_run(f, h, x0, u)[:, 0], ref, rtol=0, atol=1e-12)

    g = BoucWen()
    U = 30.0 * u  # volts
    f, h, x0, _ = state_functions(g)
    ref = g.simulate(U, dt=DT)
    run = _free_run(f, h, x0, U)
    np.testing.assert_allclose(run[:, 0], ref["y"], rtol=0, atol=1e-18)
    np.testing.assert_allclose(run[:, 1], ref["H"], rtol=0, atol=1e-18)

    for loads in (False, True):
        g = PiezoActuator(loads=loads)
        dtp = 2e-5  # D(s): ω_n = 6.3 krad/s, ζ = 0.25
        t = np.arange(300) * dtp
        U = np.column_stack([60.0 * np.sin(2 * np.pi * 300 * t), 0.01 * np.cos(2e3 * t),
                             1e-4 * np.sin(3e3 * t)])[:, :len(g.inputs)]
        f, h, x0, nx = state_functions(g, dt=dtp)
        assert nx == 6
        ref = g.simulate(U, dt=dtp)
        run = _free_run(f, h, x0, U)
        for i, name in enumerate(("y_A", "alpha_A")):
            scale = np.abs(ref[name]).max()
            np.testing.assert_allclose(run[:, i], ref[name], rtol=0, atol=1e-12 * scale)

    m = hw()
    f, h, x0, nx = state_functions(m)
    assert nx == 2  # the linear block's order
    ref = m.simulate(u[:, 0], initial_input=0.0)[:, 0]
    np.testing.assert_allclose(_free_run(f, h, x0, u)[:, 0], ref, rtol=0, atol=1e-12)

    m = bw()
    f, h, x0, nx = state_functions(m)
    assert nx == 2 and state_labels(m) == ["h", "u_prev"]
    ref = m.simulate(u[:, 0])[:, 0]
    x0[1] = u[0, 0]  # simulate starts with h = 0 at the first input
    np.testing.assert_allclose(_free_run(f, h, x0, u)[:, 0], ref, rtol=0, atol=1e-12)

    m = bwo()
    f, h, x0, nx = state_functions(m)
    ref = m.simulate(u[:, 0])[:, 0]
    np.testing.assert_allclose(_free_run(f, h, x0, u)[:, 0], ref, rtol=0, atol=1e-12)

    m = narx()
    f, h, x0, nx = state_functions(m)
    assert nx == 3 and state_labels(m) == ["s(t-1)", "s(t-2)", "u(t-1)"]
    ref = m.simulate(u[:, 0])  # y[:2] = 0, then the free run
    x = np.array([ref[1], ref[0], u[1, 0]])
    np.testing.assert_allclose(_free_run(f, h, x, u[2:])[:, 0], ref[2:], rtol=0, atol=1e-12)

    m = nlss()
    U = _nlss_input(200)
    f, h, x0, nx = state_functions(m)
    assert nx == 2 and state_labels(m) == ["x1", "x2"]
    ref = m.simulate(U)  # from x = 0, the equilibrium of the mean input
    assert np.ptp(ref, axis=0).min() > 1.0  # a real excursion, not a run at rest
    np.testing.assert_allclose(_free_run(f, h, x0, U), ref, rtol=0, atol=1e-12)

    m = pi()
    f, h, x0, nx = state_functions(m)
    assert nx == 4 and state_labels(m) == ["play_0", "play_1", "play_2", "play_3"]
    np.testing.assert_array_equal(x0, np.zeros(4))  # every play relaxed at u = a
    ref = m.simulate(u[:, 0])[:, 0]
    x0[:] = u[0, 0] - m.input_offset  # simulate relaxes every play at the first input
    np.testing.assert_allclose(_free_run(f, h, x0, u)[:, 0], ref, rtol=0, atol=1e-12)


def test_narx_state_model_is_its_free_run_bit_for_bit():
    """The NARX state functions and the free run evaluate the polynomial with one function
    (``narx.narx_output``): the state model run from the free run's first two outputs gives the
    same numbers to the bit, also with a direct input term u(t), which the state does not hold."""
    u = _input(200)
    # y(t) = 1.2 y(t−1) − 0.5 y(t−2) + 0.5 u(t) + 0.2 u(t−1) − 0.05 y(t−1)³ + 0.05 y(t−1) u(t)
    bases = np.array([[0, 1], [0, 2], [1, 0], [1, 1]])
    rows = np.array([[0, -1, -1], [1, -1, -1], [2, -1, -1], [3, -1, -1], [0, 0, 0], [0, 2, -1]])
    direct = NARXModel(2, 1, 3, True, bases, rows, np.array([1.2, -0.5, 0.5, 0.2, -0.05, 0.05]),
                       np.zeros(6), np.zeros((6, 6)), dt=DT, y_range=(-10.0, 10.0))
    assert direct.terms[2] == "u(t)" and direct.terms[5] == "y(t-1)*u(t)"
    for m in (narx(), direct):
        f, h, x0, nx = state_functions(m)
        ref = m.simulate(u[:, 0])  # y[:2] = 0, then the free run
        assert nx == 3 and np.ptp(ref) > 1.0
        x = np.array([ref[1], ref[0], u[1, 0]])
        np.testing.assert_array_equal(_free_run(f, h, x, u[2:])[:, 0], ref[2:])


# ---------------------------------------------------------------- (2) filters on noisy models

# family: (model, dt for state_functions, Q, R, P0, hidden state indices for NEES)
CASES = {
    "mass-spring-damper": (msd, DT, np.diag([1e-6, 1e-4]), 1e-4, np.diag([1e-4, 1e-3]), [0, 1]),
    "hammerstein-wiener": (hw, None, np.diag([1e-4, 1e-4]), 1e-2, np.diag([1e-2, 1e-2]), [0, 1]),
    "bouc-wen": (bw, None, np.diag([1e-4, 1e-12]), 1e-2, np.diag([1e-3, 1e-12]), [0]),
    "bouc-wen-oscillator": (bwo, None, np.diag([1e-6, 1e-4, 1e-4]), 1e-4,
                            np.diag([1e-4, 1e-3, 1e-3]), [0, 1, 2]),
    "narx": (narx, None, np.diag([1e-4, 1e-12, 1e-12]), 1e-2, np.diag([1e-2, 1e-2, 1e-12]),
             [0, 1]),
    "nlss": (nlss, None, np.diag([1e-4, 1e-4]), np.diag([1e-2, 1e-2]), np.diag([1e-2, 1e-2]),
             [0, 1]),
    # Q: a random walk of the held plays' memories (state_functions docstring); play_0 (r = 0)
    # is always driven, its state is u − a and carries only the last step's Q: not in the NEES
    "prandtl-ishlinskii": (pi, None, np.diag([1e-12, 1e-6, 1e-6, 1e-6]), 1e-4,
                           np.diag([1e-12, 1e-4, 1e-4, 1e-4]), [1, 2, 3]),
    # state [H, U, y_A, v_A, α_A, w_A] (m, V, m, m/s, rad, rad/s); outputs y_A, α_A
    "piezo-actuator": (_piezo, 2e-5, np.diag([1e-16, 1e-12, 1e-18, 1e-10, 1e-14, 1e-6]),
                       np.diag([1e-16, 1e-12]), np.diag([1e-14, 1e-12, 1e-16, 1e-8, 1e-12, 1e-4]),
                       [0, 2, 3, 4, 5]),
}


def _truth(f, h, x0, P0, Q, R, u, rng):
    n, p = len(x0), R.shape[0]
    LQ, LP = np.linalg.cholesky(Q), np.linalg.cholesky(P0)
    x = x0 + LP @ rng.standard_normal(n)
    xs, ys = np.empty((len(u), n)), np.empty((len(u), p))
    for k in range(len(u)):
        xs[k] = x
        ys[k] = h(x, u[k])
        x = np.array(f(x, u[k])) + LQ @ rng.standard_normal(n)
    return xs, ys, ys + rng.standard_normal((len(u), p)) @ np.linalg.cholesky(R).T


@pytest.mark.parametrize("family", list(CASES))
@pytest.mark.parametrize("Filter", [UnscentedKalmanFilter, ExtendedKalmanFilter])
def test_filter_on_model_tracks_hidden_state_consistently(family, Filter):
    make, dt, Q, R, P0, hidden = CASES[family]
    model = make()
    f, h, x0, nx = state_functions(model, dt)
    R = np.atleast_2d(R)
    rng = np.random.default_rng(27)
    u = _piezo_input(N) if family == "piezo-actuator" else _input(N, seed=1)
    if family == "nlss":
        u = _nlss_input(N, seed=1)
    if family in ("bouc-wen", "piezo-actuator"):
        x0[1] = u[0, 0]  # the input last applied
    if family == "prandtl-ishlinskii":
        x0[:] = u[0, 0] - model.input_offset  # every play relaxed at the first input
    d = len(hidden)
    nees = np.zeros((M_RUNS, N))
    ratios = []
    for r in range(M_RUNS):
        xs, y_clean, y = _truth(f, h, x0, P0, Q, R, u, rng)
        filt = Filter(model, Q=Q, R=R, x0=x0, P0=P0, dt=dt)
        assert filt._jit  # the model's numba functions reach the specialised kernels
        out = filt.run_arrays(u, y)
        yf = np.array([filt.h(out.x[k], u[k]) for k in range(N)])
        ratios.append(np.mean(np.sqrt(np.mean((yf - y_clean) ** 2, axis=0) / np.diag(R))))
        e = out.x[:, hidden] - xs[:, hidden]
        Ph = out.P[:, hidden][:, :, hidden]
        nees[r] = np.einsum("ki,ki->k", e, np.linalg.solve(Ph, e[:, :, None])[:, :, 0])
    assert np.mean(ratios) < 0.8, np.mean(ratios)
    lo, hi = chi2.ppf([0.005, 0.995], M_RUNS * d) / M_RUNS
    avg = nees.mean(axis=0)
    inside = np.mean((avg >= lo) & (avg <= hi))
    assert inside >= 0.9, (inside, avg.mean(), d)


def test_filter_from_model_runs_on_the_models_columns():
    """run(data) takes the model's input and output names; the model's x0 is the default."""
    m = msd()
    u = _input(100)
    y = m.simulate(u, dt=DT)["x"]
    data = Trajectory(np.arange(100) * DT, {"F": u[:, 0], "x": y})
    ukf = UnscentedKalmanFilter(m, Q=np.diag([1e-8, 1e-8]), R=[[1e-6]], dt=DT)
    np.testing.assert_array_equal(ukf.x_pred, [0.0, 0.0])
    out = ukf.run(data)
    assert np.sqrt(np.mean((out.x[:, 0] - y) ** 2)) < 1e-3

    m = nlss()  # two inputs, two outputs: the columns by name, in the model's order
    U = _nlss_input(100)
    Y = m.simulate(U)
    data = Trajectory(np.arange(100) * DT, {"y2": Y[:, 1], "u2": U[:, 1], "y1": Y[:, 0],
                                            "u1": U[:, 0]})
    Q, R = np.diag([1e-4, 1e-4]), np.diag([1e-2, 1e-2])
    by_name = UnscentedKalmanFilter(m, Q=Q, R=R).run(data)
    by_array = UnscentedKalmanFilter(m, Q=Q, R=R).run_arrays(U, Y)
    np.testing.assert_array_equal(by_name.x, by_array.x)
    assert np.abs(by_name.x).max() > 0.5  # the states move with the input


# ---------------------------------------------------------------- (3) the Kalman filter


def test_ukf_on_linear_greybox_model_is_the_kalman_filter():
    m = msd()
    Ad, Bd = m.discrete_matrices(DT)
    lin = LinearModel(StateSpace(Ad, Bd, [[1.0, 0.0]], [[0.0]], dt=DT, inputs=["F"],
                                 outputs=["x"]), "greybox")
    Q, R, P0 = np.diag([1e-5, 1e-3]), np.array([[1e-3]]), np.diag([1e-2, 1e-1])
    u = _input(200, seed=3)
    rng = np.random.default_rng(5)
    y = m.simulate(u, dt=DT)["x"] + np.sqrt(R[0, 0]) * rng.standard_normal(200)
    kf = KalmanFilter(lin, Q=Q, R=R, x0=[0.0, 0.0], P0=P0)
    ukf = UnscentedKalmanFilter(m, Q=Q, R=R, P0=P0, dt=DT)
    ekf = ExtendedKalmanFilter(m, Q=Q, R=R, P0=P0, dt=DT)
    for k in range(200):
        xk, Pk = kf.step(u[k], y[k:k + 1])
        for filt in (ukf, ekf):
            xu, Pu = filt.step(u[k], y[k:k + 1])
            np.testing.assert_allclose(xu, xk, rtol=0, atol=1e-8 * max(1.0, np.abs(xk).max()))
            np.testing.assert_allclose(Pu, Pk, rtol=0, atol=1e-8 * np.abs(Pk).max())


# ---------------------------------------------------------------- (4) bad input


class _BatchOnly(Model):
    name = "batch-only"
    inputs = (Signal("u", "1"),)
    outputs = (Signal("y", "1"),)
    states = (Signal("x", "1"),)

    def _simulate_batch(self, thetas, u, dt, substeps, x0, y):
        y[:] = 0.0


def test_models_without_what_the_filters_need_raise_model_error():
    batch_only = _BatchOnly(ParameterSet([Parameter("a", 1.0, "1", "gain")], "p"))
    with pytest.raises(ModelError, match="has no per-sample state transition") as err:
        UnscentedKalmanFilter(batch_only, Q=[[1.0]], R=[[1.0]], dt=0.1)
    assert "\n" not in str(err.value) and "state_functions(dt)" in str(err.value)
    with pytest.raises(ModelError, match="no sample time; give dt="):
        ExtendedKalmanFilter(msd(), Q=np.eye(2), R=[[1.0]])
    with pytest.raises(ModelError, match="dt must be a positive number of seconds, found '1'"):
        state_functions(msd(), dt="1")
    with pytest.raises(ModelError, match="dict has no state-space form"):
        UnscentedKalmanFilter({"A": 1}, Q=[[1.0]], R=[[1.0]])
    with pytest.raises(ModelError, match="keeps its own sample time"):
        state_functions(bwo(), dt=0.01)
    static = NARXModel(0, 2, 1, False, np.array([[1, 1], [1, 2]]), np.array([[0], [1]]),
                       np.array([1.0, 0.5]), np.zeros(2), np.zeros((2, 2)))
    with pytest.raises(ModelError, match="no output lags"):
        state_functions(static)
    with pytest.raises(ModelError, match="NLSS model has order 0"):
        state_functions(dataclasses.replace(nlss(), A=np.zeros((0, 0))))
    bad_pi = pi()
    bad_pi.weights = np.array([0.5, 0.3])
    with pytest.raises(ModelError, match="one weight per play operator, found 4 thresholds"):
        state_functions(bad_pi)
    with pytest.raises(ArgumentError, match="give both f"):
        ExtendedKalmanFilter(lambda x, u: x, Q=[[1.0]], R=[[1.0]])


class _WithTransition(_BatchOnly):
    """A grey-box model that gives its own transition: x⁺ = a x + u, y = x."""

    name = "with-transition"

    def state_functions(self, dt):
        a = self.parameters.value("a")
        return (lambda x, u: a * x + u), (lambda x, u: x), np.zeros(1)


def test_state_functions_hook_and_cache():
    g = _WithTransition(ParameterSet([Parameter("a", 0.5, "1", "pole")], "p"))
    ukf = UnscentedKalmanFilter(g, Q=[[0.1]], R=[[1.0]], P0=[[1.0]])
    assert not ukf._jit  # Python functions: called from Python between the kernels
    x, P = ukf.step([0.0], [2.0])
    # scalar Kalman filter: K = 1/(1 + 1), x = 0 + K·2, P = 1 − K
    np.testing.assert_allclose([x[0], P[0, 0]], [1.0, 0.5], rtol=1e-12)
    data = Trajectory(np.arange(3.0), {"u": np.zeros(3), "y": np.ones(3)})
    assert ukf.run(data).x.shape == (3, 1)  # the model's own column names

    m = bw()
    first = state_functions(m)
    assert state_functions(m).f is first.f  # same model, same values: the same numba functions
    m.beta = 1.0
    assert state_functions(m).f is not first.f  # a value changed: built again
