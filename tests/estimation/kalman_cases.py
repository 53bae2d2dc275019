"""The linear three-state, two-input, two-output system shared by the Kalman filter tests
(imported as ``from kalman_cases import ...``, a unique name): its matrices, noise covariances,
operating point, the ``LinearModel`` and its state and output functions, in Python and numba
(for the extended and unscented filters, which on a linear model must equal the Kalman filter)."""

import numba
import numpy as np

from gripkit.lti import StateSpace
from gripkit.sysid import LinearModel

A = np.array([[0.95, 0.2, 0.0], [-0.2, 0.95, 0.1], [0.0, 0.0, 0.7]])
B = np.array([[0.0, 1.0], [1.0, 0.0], [0.5, 0.5]])
C = np.array([[1.0, 0.0, 0.0], [0.0, 0.3, 1.0]])
D = np.array([[0.1, 0.0], [0.0, 0.0]])
Q = np.diag([1e-2, 2e-2, 5e-3])
R = np.array([[0.04, 0.01], [0.01, 0.09]])
U0, Y0 = np.array([0.3, -1.0]), np.array([2.0, 0.5])
P0 = np.eye(3)


def model() -> LinearModel:
    sys = StateSpace(A, B, C, D, dt=0.01, inputs=["u1", "u2"], outputs=["y1", "y2"])
    return LinearModel(sys, "n4sid", u_offset=tuple(U0), y_offset=tuple(Y0))


def f_py(x, u):
    return A @ x + B @ (u - U0)


def h_py(x, u):
    return C @ x + D @ (u - U0) + Y0


@numba.njit
def f_nb(x, u):
    return A @ x + B @ (u - U0)


@numba.njit
def h_nb(x, u):
    return C @ x + D @ (u - U0) + Y0
