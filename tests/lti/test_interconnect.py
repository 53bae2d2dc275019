"""series, parallel and feedback against python-control; series associativity (hypothesis);
names, units and time bases checked."""

import control  # a dev dependency: the cross-checks fail, not skip, without it
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from gripkit.errors import ModelError
from gripkit.lti import StateSpace, TransferFunction, feedback, parallel, series
from lti_systems import EPS, random_ss

W = np.logspace(-1, 1.5, 11)


def _resp(sys):
    return (np.moveaxis(sys(1j * W), -1, 0) if sys.ninputs * sys.noutputs > 1
            else sys(1j * W).reshape(-1, 1, 1))


def _close(ours, ref_ctrl):
    """Same frequency response. Each side solves (sI − A) X = B for its own realisation, with
    error ≲ n ε κ(sI − A) |G|; python-control's realisation is conditioned like ours within a
    factor of ~10 here, so 1e3 n ε κ_ours bounds the difference."""
    H, R = ours.frequency_response(W), _resp(ref_ctrl)
    s = ours.to_ss(minimal=False)
    n = max(s.n_states, 1)
    kappa = (max([np.linalg.cond(1j * w * np.eye(s.n_states) - s.A) for w in W] if s.n_states
                 else [1.0]))
    assert np.abs(H - R).max() <= 1e3 * n * EPS * kappa * max(np.abs(R).max(), 1.0)


def test_siso_tf_series_parallel_feedback_match_python_control():
    g1 = ([2.0, 1.0], [1.0, 3.0, 2.0])
    g2 = ([5.0], [1.0, 5.0])
    G1, G2 = TransferFunction(*g1), TransferFunction(*g2)
    C1, C2 = control.tf(*g1), control.tf(*g2)
    _close(series(G1, G2), C2 * C1)
    _close(parallel(G1, G2), C1 + C2)
    _close(feedback(G1, G2), control.feedback(C1, C2))
    _close(feedback(G1, G2, sign=+1), control.feedback(C1, C2, sign=+1))
    _close(G2 * G1, C2 * C1)
    _close(G1 - G2, C1 - C2)
    _close(3.0 * G1, 3 * C1)
    assert isinstance(series(G1, G2), TransferFunction)


def test_mimo_state_space_interconnections_match_python_control():
    rng = np.random.default_rng(7)
    P = StateSpace(*random_ss(rng, 3, 2, 2)[:4], inputs=("u1", "u2"), outputs=("y1", "y2"))
    K = StateSpace(*random_ss(rng, 2, 2, 2)[:4]).replace(D=np.zeros((2, 2)))
    cP, cK = P.to_control(), K.to_control()
    _close(series(P, K), cK * cP)
    _close(parallel(P, K), cP + cK)
    fb = feedback(P, K)
    _close(fb, control.feedback(cP, cK))
    assert fb.inputs == ("u1", "u2") and fb.outputs == ("y1", "y2") and fb.n_states == 5
    # a static gain as controller: T = (I + P k)⁻¹ P
    _close(feedback(P, 0.5), control.feedback(cP, 0.5 * np.eye(2)))


@given(st.integers(0, 10_000))
def test_series_is_associative(seed):
    """Property: (G1 → G2) → G3 and G1 → (G2 → G3) have the same frequency response (and the
    same state matrices: the block-triangular construction is associative exactly)."""
    rng = np.random.default_rng(seed)
    g = [StateSpace(*random_ss(rng, int(rng.integers(1, 4)), 2, 2)[:4]) for _ in range(3)]
    a = series(series(g[0], g[1]), g[2])
    b = series(g[0], series(g[1], g[2]))
    for X, Y in zip(a._arrays(), b._arrays()):
        np.testing.assert_allclose(X, Y, rtol=0, atol=10 * EPS * max(np.abs(Y).max(), 1.0))


def test_interconnection_checks():
    g = TransferFunction([1.0], [1.0, 1.0], output_units="N")
    with pytest.raises(ModelError, match="one time base"):
        series(g, TransferFunction([1.0], [1.0, 0.5], dt=0.1))
    with pytest.raises(ModelError, match="units differ"):
        series(g, TransferFunction([1.0], [1.0, 1.0], input_units="V"))
    with pytest.raises(ModelError, match="first system has 1 outputs but the second 2 inputs"):
        series(g, StateSpace(np.eye(1), np.ones((1, 2)), np.ones((1, 1))))
    with pytest.raises(ModelError, match="algebraic loop"):
        feedback(TransferFunction([1.0], [1.0]), 1.0, sign=+1)
    with pytest.raises(ModelError, match="sign: expected -1"):
        feedback(g, 1.0, sign=2)
    with pytest.raises(ModelError, match="at least two systems"):
        series(g)
    two_inputs = StateSpace(np.eye(1), np.ones((1, 2)), np.ones((1, 1)))
    with pytest.raises(ModelError, match=r"parallel: g2 must be 1×1 \(the shape of g1\), "
                                         "found 1×2"):
        parallel(g, two_inputs)
    with pytest.raises(ModelError, match=r"feedback: the controller must be 2×1 \(plant "
                                         r"outputs → plant inputs\), found 1×1"):
        feedback(two_inputs, TransferFunction([1.0], [1.0, 1.0]))
