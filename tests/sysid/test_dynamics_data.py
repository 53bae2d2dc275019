"""The preprocessing of a joint log for inverse-dynamics identification in the library
(gripkit.sysid.rigid_body.dynamics_data): filtered states against their analytic derivatives,
the row weights (slow rows and reversal bands out), and the errors."""

import numpy as np
import pytest

from gripkit import Trajectory
from gripkit.errors import DataError, UnidentifiableError
from gripkit.sysid.rigid_body.dynamics_data import dynamics_data

W = 2 * np.pi * 0.5  # rad/s: two joints on sines of 0.5 Hz


def _log(still: bool = False) -> Trajectory:
    t = np.arange(20000) * 1e-3
    q0, q1 = np.sin(W * t), 0.5 * np.cos(W * t)
    if still:
        q1 = np.zeros_like(t)
    return Trajectory.uniform(dt=1e-3, p0=q0, p1=q1, e0=2.0 * q0, e1=np.cos(W * t),
                              meta={"source": "log.csv"})


def test_states_are_the_analytic_derivatives():
    dd = dynamics_data(_log(), ["j0", "j1"], ["p0", "p1"], ["e0", "e1"], effort_scale=0.5)
    st = dd.samples
    assert st.cutoff == pytest.approx(20.0) and st.decimation == 10  # fs/50, 1/(2q dt) >= 2.5 fc
    assert dd.t[1] == pytest.approx(0.01)  # decimated rows, 10 ms apart
    # q0 = sin(W t): q̇0² + (W q0)² = W², q̈0 = −W² q0 (a 20 Hz filter leaves 0.5 Hz untouched)
    np.testing.assert_allclose(dd.qd[:, 0] ** 2 + (W * dd.q[:, 0]) ** 2, W ** 2, rtol=1e-3)
    # (the first and last rows carry what is left of the filter's edges)
    np.testing.assert_allclose(dd.qdd[10:-10, 0], -W ** 2 * dd.q[10:-10, 0], atol=1e-3 * W ** 2)
    np.testing.assert_allclose(dd.effort[:, 0], dd.q[:, 0], atol=1e-6)  # 0.5 × 2 q0
    # weights: 0 where a joint is slower than 2 % of its peak speed or near a reversal
    slow = np.abs(dd.qd) <= 0.02 * np.max(np.abs(dd.qd), axis=0)
    assert np.all(dd.weights[slow] == 0)
    assert np.all(dd.weights[~slow & ~st.near_reversal] == 1)
    assert 0.5 < dd.weights.mean() < 1.0


def test_bad_logs_are_refused():
    with pytest.raises(UnidentifiableError, match="joint\\(s\\) j1 never move in log.csv"):
        dynamics_data(_log(still=True), ["j0", "j1"], ["p0", "p1"], ["e0", "e1"])
    with pytest.raises(DataError, match=r"position: 1 column\(s\) \['p0'\] for the 2 actuated "
                                        r"joints j0, j1"):
        dynamics_data(_log(), ["j0", "j1"], ["p0"], ["e0", "e1"])
    with pytest.raises(DataError, match="effort_scale: expected a finite positive factor"):
        dynamics_data(_log(), ["j0", "j1"], ["p0", "p1"], ["e0", "e1"], effort_scale=0.0)
