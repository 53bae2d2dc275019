"""Synthetic MIMO systems with known truth for the subspace/PEM/FRF/tfest tests."""

from __future__ import annotations

import numpy as np

from gripkit.lti import StateSpace


def two_by_two(order4_seed: int = 3) -> StateSpace:
    """A 2-input 2-output discrete system of order 4 (dt = 0.01 s): a lightly damped pair
    0.9 ± 0.2j (|z| = 0.922) and real poles 0.7, −0.4, in a random basis."""
    rng = np.random.default_rng(order4_seed)
    A = np.array([[0.9, 0.2, 0, 0], [-0.2, 0.9, 0, 0], [0, 0, 0.7, 0], [0, 0, 0, -0.4]])
    T = rng.standard_normal((4, 4)) + 3 * np.eye(4)
    A = T @ A @ np.linalg.inv(T)
    B = rng.standard_normal((4, 2))
    C = rng.standard_normal((2, 4))
    return StateSpace(A, B, C, dt=0.01, inputs=["a", "b"], outputs=["c", "d"],
                      input_units=["V", "V"],
                      output_units=["N", "m"])


TRUE_POLES = np.array([0.9 + 0.2j, 0.9 - 0.2j, 0.7, -0.4])


def oe_data(g: StateSpace, n: int, noise: float, seed: int):
    """White inputs, outputs with white measurement noise of std ``noise`` × output std."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal((n, g.n_inputs))
    y0 = g.simulate(u)
    return u, y0 + noise * y0.std(axis=0) * rng.standard_normal(y0.shape)


def match_poles(est, true):
    """Each true pole's nearest estimated pole index (greedy, poles are well separated)."""
    est = list(est)
    idx = []
    for p in true:
        k = int(np.argmin([abs(e - p) if i not in idx else np.inf for i, e in enumerate(est)]))
        idx.append(k)
    return np.array(idx)
