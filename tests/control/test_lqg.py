"""``gripkit.control.LQG`` (issue 27): the controller equals the LQG compensator composed by hand
from python-control's ``dlqr`` and ``dlqe`` (a ``control.ss`` run through
``control.forced_response``), in both estimate forms; the closed loop on the model has the
eigenvalues of ``A − B K`` and ``A − L C`` (the separation principle), all inside the unit
circle; with a reference the loop settles at it; bad use is refused."""

from __future__ import annotations

import control
import numpy as np
import pytest

from gripkit.control import LQG
from gripkit.errors import ArgumentError, DataError, ModelError
from gripkit.lti import StateSpace
from gripkit.sysid import LinearModel

r1, w1, r2, w2 = 0.97, 0.3, 0.85, 1.1
A = np.zeros((4, 4))
A[:2, :2] = r1 * np.array([[np.cos(w1), -np.sin(w1)], [np.sin(w1), np.cos(w1)]])
A[2:, 2:] = r2 * np.array([[np.cos(w2), -np.sin(w2)], [np.sin(w2), np.cos(w2)]])
A[0, 2] = 0.1
B = np.array([[1.0, 0.2], [0.0, 0.5], [0.3, -1.0], [0.7, 0.1]])
C = np.array([[0.4, -0.2, 1.0, 0.0], [0.0, 0.9, -0.3, 0.5]])
U0, Y0 = (0.85, -2.0), (1.5, 0.01)
Q, R = np.diag([1.0, 2.0, 0.5, 1.0]), np.diag([0.1, 0.3])
QN, RN = np.diag([0.01, 0.02, 0.01, 0.05]), np.array([[0.04, 0.01], [0.01, 0.09]])


def model(D=None) -> LinearModel:
    sys = StateSpace(A, B, C, np.zeros((2, 2)) if D is None else D, dt=0.001,
                     inputs=["current", "voltage"], outputs=["force", "position"])
    return LinearModel(sys, "n4sid", u_offset=U0, y_offset=Y0)


def reference_controller(estimate):
    """The LQG compensator from y − y0 to u − u0, composed from python-control's gains."""
    K = control.dlqr(A, B, Q, R)[0]
    L, P, _ = control.dlqe(A, np.eye(4), C, QN, RN)
    if estimate == "predicted":  # u = −K x[t|t−1]
        return K, L, control.ss(A - B @ K - L @ C, L, -K, np.zeros((2, 2)), 0.001)
    Kf = P @ C.T @ np.linalg.inv(C @ P @ C.T + RN)  # u = −K x[t|t]
    I_KC = np.eye(4) - Kf @ C
    return K, L, control.ss((A - B @ K) @ I_KC, (A - B @ K) @ Kf, -K @ I_KC, -K @ Kf, 0.001)


@pytest.mark.parametrize("estimate", ["filtered", "predicted"])
def test_the_controller_equals_the_compensator_composed_from_python_control(estimate):
    rng = np.random.default_rng(27)
    y = np.array(Y0) + 0.5 * rng.standard_normal((300, 2))
    K, L, ref = reference_controller(estimate)
    c = LQG(model(), Q, R, QN, RN, estimate=estimate)
    np.testing.assert_allclose(c.K, K, rtol=1e-10)
    np.testing.assert_allclose(c.predictor_gain, L, rtol=1e-9)
    u_ref = control.forced_response(ref, U=(y - Y0).T).outputs.T + U0
    u = np.array([c.step(yk) for yk in y])
    np.testing.assert_allclose(u, u_ref, rtol=1e-9, atol=1e-9 * np.max(np.abs(u_ref - U0)))
    assert np.max(np.abs(u - U0)) > 0.1  # the controller does act


def test_the_closed_loop_is_stable_with_the_separated_eigenvalues():
    """Plant x+ = A x + B du, y = C x + y0 in the loop with LQG.step: the loop's state matrix
    (plant state, the controller's prediction) has the eigenvalues of A − B K and A − L C
    (python-control's gains), all of modulus < 1, and a disturbed start decays."""
    K, L, _ = reference_controller("filtered")
    want = np.sort_complex(np.concatenate([np.linalg.eigvals(A - B @ K),
                                           np.linalg.eigvals(A - L @ C)]))
    c = LQG(model(), Q, R, QN, RN)
    np.testing.assert_allclose(np.sort_complex(c.poles), want, rtol=1e-9, atol=1e-12)
    # the loop matrix, column by column, from the controller itself: unit initial conditions
    Acl = np.zeros((8, 8))
    for j in range(8):
        x = np.eye(8)[j, :4].copy()
        c.reset()
        c.x_pred[:] = np.eye(8)[j, 4:]
        du = c.step(C @ x + Y0) - U0
        Acl[:4, j] = A @ x + B @ du
        Acl[4:, j] = c.x_pred
    np.testing.assert_allclose(np.sort_complex(np.linalg.eigvals(Acl)), want, rtol=1e-8,
                               atol=1e-10)
    assert np.max(np.abs(want)) < 1.0
    x, c = np.array([1.0, -1.0, 0.5, 0.2]), LQG(model(), Q, R, QN, RN)
    for _ in range(2000):
        x = A @ x + B @ (c.step(C @ x + Y0) - U0)
    assert np.linalg.norm(x) < 1e-6


def test_with_a_reference_the_loop_settles_at_it():
    r = np.array([2.0, -0.3])
    c, x = LQG(model(), Q, R, QN, RN), np.zeros(4)
    for _ in range(3000):
        u = c.step(C @ x + Y0, r, copy=False)
        x = A @ x + B @ (u - U0)
    np.testing.assert_allclose(C @ x + Y0, r, rtol=1e-9)
    assert not u.flags.writeable


def test_bad_use_is_refused():
    with pytest.raises(ModelError, match="direct feedthrough"):
        LQG(model(D=np.eye(2)), Q, R, QN, RN)
    with pytest.raises(ModelError, match="no innovation gain K"):
        LQG(model(), Q, R)
    with pytest.raises(ArgumentError, match="estimate must be 'filtered' or 'predicted'"):
        LQG(model(), Q, R, QN, RN, estimate="smoothed")
    c = LQG(model(), Q, R, QN, RN)
    with pytest.raises(DataError, match="y and r must hold 2 value"):
        c.step([1.0, 2.0, 3.0])
    sys = StateSpace(A, B[:, :1], C, np.zeros((2, 1)), dt=0.001)
    thin = LQG(LinearModel(sys, "n4sid"), Q, R[:1, :1], QN, RN)
    with pytest.raises(ArgumentError, match="r needs a square model"):
        thin.step([0.0, 0.0], r=[1.0, 1.0])
