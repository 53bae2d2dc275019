"""Transfer functions: ss ↔ tf round trips (hypothesis), MIMO realisations, the q⁻¹ layout of
ARX/RST code (000_8f66dcc7ab06470c.txt Table II) and initial states from past samples."""

import control  # a dev dependency: the cross-checks fail, not skip, without it
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy import signal

from gripkit.errors import ModelError
from gripkit.lti import StateSpace, TransferFunction
from lti_systems import EPS

# 000_8f66dcc7ab06470c.txt, Table II: ARX [2 2 2] of the AMADEUS finger force, fs = 200 Hz
A222 = [1.0, -1.8732, 0.8996]
B222 = [0.0, 0.0, 0.1950, -0.2276]


def _poly_tol(roots, n):
    """np.poly of roots r_i: coefficient errors ≲ n ε Π(1 + |r_i|) (bound of the expanded
    product), and the roots come from an eigen-solver with errors ε‖companion‖; 1e3 covers both
    for separated roots."""
    return 1e3 * n * EPS * np.prod(1 + np.abs(roots))


@given(st.integers(0, 10_000), st.integers(1, 6), st.integers(0, 6), st.booleans())
def test_tf_ss_tf_round_trip(seed, n, nz, discrete):
    """Property: tf → ss → tf returns the coefficients (SISO, coprime num/den)."""
    rng = np.random.default_rng(seed)
    nz = min(nz, n)
    if discrete:
        poles = rng.uniform(-0.9, 0.9, n)
        zeros = rng.uniform(1.1, 2.0, nz) * rng.choice([-1, 1], nz)
    else:
        poles = -rng.uniform(0.5, 5.0, n)
        zeros = rng.uniform(6.0, 9.0, nz) * rng.choice([-1, 1], nz)
    num = rng.uniform(0.5, 2.0) * np.poly(zeros)
    den = np.poly(poles)
    g = TransferFunction(num, den, dt=0.01 if discrete else None)
    back = g.to_ss().to_tf()
    tol = _poly_tol(np.r_[poles, zeros], n)
    assert back.denominator().size == den.size
    np.testing.assert_allclose(back.denominator(), den, atol=tol)
    np.testing.assert_allclose(back.numerator(), num, atol=tol * max(1.0, np.abs(num).max()))


def test_ss_to_tf_matches_python_control_ss2tf():
    """A 3-state SISO system: same coefficients as control.ss2tf (scipy's formula, the same
    arithmetic on the same eigenvalues: agreement to a few ε Σ|coef| ≈ 1e-14; 1e-12 asserted)."""
    A = np.array([[-1.0, 2.0, 0.0], [0.0, -3.0, 1.0], [1.0, 0.0, -4.0]])
    B, C, D = np.array([[1.0], [0.0], [2.0]]), np.array([[0.0, 1.0, 1.0]]), np.array([[0.5]])
    g = StateSpace(A, B, C, D).to_tf()
    ref = control.ss2tf(control.ss(A, B, C, D))
    np.testing.assert_allclose(g.numerator(), np.squeeze(ref.num_array[0, 0]), rtol=1e-12,
                               atol=1e-12)
    np.testing.assert_allclose(g.denominator(), np.squeeze(ref.den_array[0, 0]), rtol=1e-12,
                               atol=1e-12)


def test_mimo_tf_to_ss_is_minimal_and_keeps_the_response():
    """G = [[1/(s+1), 1/(s+1)], [2/(s+1), 2/(s+1)]] is rank one with a single pole: its minimal
    realisation has one state (McMillan degree 1); the frequency response is kept."""
    g = TransferFunction([[[1.0], [1.0]], [[2.0], [2.0]]],
                         [[[1, 1.0], [1, 1.0]], [[1, 1.0], [1, 1.0]]],
                         inputs=("a", "b"), outputs=("x", "y"))
    s = g.to_ss()
    assert s.n_states == 1 and s.inputs == ("a", "b") and s.outputs == ("x", "y")
    w = np.array([0.1, 1.0, 10.0])
    np.testing.assert_allclose(s.frequency_response(w), g.frequency_response(w), rtol=1e-12)
    assert g.to_ss(minimal=False).n_states == 4
    # back to a transfer-function matrix: each entry's cancelled modes are gone
    gt = s.to_tf()
    assert gt.denominator(1, 0).tolist() == pytest.approx([1.0, 1.0])
    assert gt.numerator(1, 0).tolist() == pytest.approx([2.0])


def test_mimo_tf_response_matches_python_control():
    num = [[[1.0, 2.0], [0.5]], [[3.0], [1.0, 0.0]]]
    den = [[[1.0, 3.0, 2.0], [1.0, 1.0]], [[1.0, 4.0], [1.0, 2.0, 5.0]]]
    g = TransferFunction(num, den)
    ref = control.tf(num, den)
    w = np.logspace(-1, 1, 9)
    np.testing.assert_allclose(g.frequency_response(w), np.moveaxis(ref(1j * w), -1, 0), rtol=1e-13)
    np.testing.assert_allclose(g.to_ss().frequency_response(w), g.frequency_response(w), rtol=1e-10)
    # entry 00 is (s+2)/((s+1)(s+2)) = 1/(s+1) and row 0 is rank one: McMillan degree 4,
    # poles −1, −4, −1 ± 2j
    expect = np.sort_complex([-4.0, -1 - 2j, -1 + 2j, -1.0])
    np.testing.assert_allclose(np.sort_complex(g.poles().round(9)), expect, atol=1e-9)


def test_from_polynomials_table_ii():
    """Table II's ARX [2 2 2]: y = B/A u with nk = 2 at 200 Hz. Poles are the roots of A (plus
    the delay's pole at the origin), the zero is at 0.2276/0.1950 = 1.167 (§V-F: non-minimum
    phase), and the q⁻¹ view returns the coefficients. Roots and sums of the same coefficients:
    1e-12; simulation against lfilter: same recursion, summation order only (N n ε ≈ 3e-13)."""
    g = TransferFunction.from_polynomials(A222, B222, dt=0.005, inputs="i", outputs="F",
                                          input_units="A", output_units="N")
    assert g.den_zinv().tolist() == A222 and g.num_zinv().tolist() == B222
    assert g.relative_degree() == 2
    p = np.sort_complex(g.poles())
    np.testing.assert_allclose(np.sort_complex(np.r_[np.roots(A222), 0.0]), p, atol=1e-12)
    assert g.zeros()[0].real == pytest.approx(0.2276 / 0.1950, rel=1e-12)
    assert g.dc_gain()[0, 0] == pytest.approx(sum(B222) / sum(A222), rel=1e-12)
    # simulation equals scipy.signal.lfilter on the q⁻¹ arrays
    u = np.sin(np.arange(400) * 0.05)
    np.testing.assert_allclose(g.simulate(u)[:, 0], signal.lfilter(B222, A222, u), rtol=1e-12,
                               atol=1e-14)
    # non-monic A (DiscretePlant layout) is normalised; trailing zeros are padding
    g2 = (TransferFunction.from_polynomials(np.r_[2 * np.array(A222), 0.0],
                                            np.r_[2 * np.array(B222), 0.0], dt=0.005))
    assert (g2.den_zinv().tolist() == pytest.approx(A222)
            and g2.num_zinv().tolist() == pytest.approx(B222))
    with pytest.raises(ModelError, match="B is all zeros"):
        TransferFunction.from_polynomials(A222, [0.0, 0.0], dt=0.005)
    with pytest.raises(ModelError, match="positive sample time"):
        TransferFunction.from_polynomials(A222, B222, dt=0.0)


def test_output_error_form_b_over_f():
    """OE: y = B/F u; ARMAX's C does not enter the input-output transfer function."""
    g = TransferFunction.from_polynomials([1.0], [0.0, 0.5], F=[1.0, -0.7], dt=0.1)
    assert g.den_zinv().tolist() == [1.0, -0.7]
    h = TransferFunction.from_polynomials([1.0, -0.7], [0.0, 0.5], C=[1.0, 0.3], dt=0.1)
    assert h.den_zinv().tolist() == [1.0, -0.7]


def test_initial_state_continues_like_lfiltic():
    """Continuing from past samples: simulate(u, initial_state(u_past, y_past)) equals
    lfilter(B, A, u, zi=lfiltic(B, A, y_past reversed, u_past reversed)). The observable form is
    lfilter's transposed direct form II, so the arithmetic is the same up to summation order
    (N n ε ‖y‖ ≈ 50 · 3 · 2e-16 → 1e-13 absolute)."""
    g = TransferFunction.from_polynomials(A222, B222, dt=0.005)
    rng = np.random.default_rng(1)
    u_past, y_past, u = rng.standard_normal(5), rng.standard_normal(5), rng.standard_normal(50)
    zi = signal.lfiltic(B222, A222, y_past[::-1], u_past[::-1])
    ref = signal.lfilter(B222, A222, u, zi=zi)[0]
    np.testing.assert_allclose(g.simulate(u, g.initial_state(u_past, y_past))[:, 0], ref,
                               rtol=1e-12, atol=1e-13)


def test_controllable_form_is_scipys_tf2ss_bit_for_bit():
    """form='controllable' reproduces scipy.signal.tf2ss (the realisation DiscretePlant and
    PolynomialModel exported) with the same arithmetic: equality, not closeness."""
    g = TransferFunction.from_polynomials(A222, B222, dt=0.005)
    ref = signal.tf2ss(np.trim_zeros(np.array(B222), "f"), np.r_[A222, 0.0])
    s = g.to_ss(form="controllable")
    for X, R in zip(s._arrays(), ref):
        np.testing.assert_array_equal(X, R)
    with pytest.raises(ModelError, match="form: expected one of observable, controllable"):
        g.to_ss(form="jordan")
