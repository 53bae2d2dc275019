"""The older linear types are gripkit.lti systems or views of one (issue 12; issue 23 removed
``sim.linear.StateSpace``: the simulators use ``lti.StateSpace``): ``sysid.PolynomialModel.system``
and ``control.DiscretePlant.lti`` are ``lti.TransferFunction``s that compute their poles, zeros,
DC gain, responses and realisations. References come from scipy.signal on the seed models.

Tolerances: scipy and gripkit compute each quantity by backward-stable routes that differ only in
realisation or summation order, so they agree to ~n ε κ; for these second- and third-order models
κ < 1e3 (TSFM sensor after scaling, Table II's poles 0.94 ± 0.12j), hence 1e-12 relative (exact
where both run the same arithmetic: roots of the same polynomial, scipy's tf2ss realisation)."""

import numpy as np
import pytest
from scipy import signal

from gripkit import lti
from gripkit.control import DiscretePlant, as_plant, design_rst
from gripkit.errors import ModelError
from gripkit.sim.linear import c2d_zoh, simulate_discrete
from gripkit.sysid import PolynomialModel

# 000_8f66dcc7ab06470c.txt, Table II: ARX [2 2 2], fs = 200 Hz; σ from Table III
A222 = [1.0, -1.8732, 0.8996]
B222 = [0.0, 0.0, 0.1950, -0.2276]
STD222 = {"A": [0, 0.0117, 0.0117], "B": [0, 0, 0.0221, 0.0225]}
DT = 0.005
# 001_0b92a7da96e7aa46.txt: TSFM force sensor, k_s = 128 N/m, m_s = 1.8e-6 kg (b_s = 7e-4 N s/m)
A_SENSOR = [[0.0, 1.0], [-128 / 1.8e-6, -7e-4 / 1.8e-6]]
B_SENSOR = [[0.0], [1 / 1.8e-6]]
C_SENSOR = [[1.0, 0.0]]


def _zpk_zinv(A, B):
    """scipy's zeros and poles of B(q)/A(q) (q⁻¹ layout), without the roots at the origin that the
    delay and the padding add in positive powers."""
    L = max(len(A), len(B))
    z, p, _ = signal.tf2zpk(np.pad(B, (0, L - len(B))), np.pad(A, (0, L - len(A))))
    return np.sort_complex(z[z != 0]), np.sort_complex(p[p != 0])


# ------------------------------------------------------------------ lti.StateSpace in simulation
def test_sensor_state_space_matches_scipy():
    old = lti.StateSpace(A_SENSOR, B_SENSOR, C_SENSOR, None, None, ("F",), ("y",), ("N",), ("m",))
    assert isinstance(old, lti.StateSpace) and lti.as_system(old) is old
    ref = (signal.StateSpace(np.array(A_SENSOR), np.array(B_SENSOR), np.array(C_SENSOR),
                             np.zeros((1, 1))))
    np.testing.assert_allclose(np.sort_complex(old.poles()), np.sort_complex(ref.poles), rtol=1e-12)
    assert old.zeros().size == 0 == ref.zeros.size
    np.testing.assert_allclose(old.dc_gain(), [[1 / 128]], rtol=1e-12)      # 1/k_s
    f = np.array([10.0, 1e3, 8.5e3])
    _, H = signal.freqresp(ref, 2 * np.pi * f)
    np.testing.assert_allclose(old.frequency_response(2 * np.pi * f)[:, 0, 0], H, rtol=1e-12)
    d = old.c2d(5e-5)
    assert type(d) is lti.StateSpace and d.dt == 5e-5
    assert d.inputs == ("F",) and d.output_units == ("m",)
    Ad, Bd, _, _, _ = signal.cont2discrete((ref.A, ref.B, ref.C, ref.D), 5e-5, method="zoh")
    np.testing.assert_allclose(d.A, Ad, rtol=1e-12, atol=1e-12 * np.abs(Ad).max())
    np.testing.assert_allclose(d.B, Bd, rtol=1e-12)
    _, (ys,) = signal.dstep((Ad, Bd, ref.C, ref.D, 5e-5), n=400)
    np.testing.assert_allclose(d.step(400)[:, 0, 0], ys[:, 0], rtol=1e-9,
                               atol=1e-12 * np.abs(ys).max())
    assert d.stable and old.stable


def test_sim_array_kernels_delegate_to_lti():
    """c2d_zoh ≡ lti.c2d_matrices (bit for bit, C-contiguous) and simulate_discrete ≡
    lti.simulate_ss."""
    A, B = np.array(A_SENSOR), np.array(B_SENSOR)
    Ad, Bd = c2d_zoh(A, B, 5e-5)
    ref = lti.c2d_matrices(A, B, np.zeros((0, 2)), np.zeros((0, 1)), 5e-5)
    np.testing.assert_array_equal(Ad, ref[0])
    np.testing.assert_array_equal(Bd, ref[1])
    assert Ad.flags.c_contiguous and Bd.flags.c_contiguous
    C, D = np.array(C_SENSOR), np.zeros((1, 1))
    u = np.sin(np.arange(300) * 0.05).reshape(-1, 1)
    y1, x1 = np.empty((300, 1)), np.array([1e-6, 0.0])
    simulate_discrete(Ad, Bd, C, D, u, x1, y1)
    y2, x2 = np.empty((300, 1)), np.array([1e-6, 0.0])
    lti.simulate_ss(Ad, Bd, C, D, u, x2, np.empty(2), y2)
    np.testing.assert_array_equal(y1, y2)
    np.testing.assert_array_equal(x1, x2)
    _, yref, _ = signal.dlsim((Ad, Bd, C, D, 5e-5), u[:, 0], x0=[1e-6, 0.0])
    np.testing.assert_allclose(y1[:, 0], yref[:, 0], rtol=1e-9, atol=1e-9 * np.abs(yref).max())


def test_state_space_errors():
    with pytest.raises(ModelError, match="sample time"):
        lti.StateSpace([[-1.0]], [[1.0]], [[1.0]], None).simulate(np.ones(3))
    with pytest.raises(ModelError, match="already discrete"):
        lti.StateSpace([[0.5]], [[1.0]], [[1.0]], None, 0.1).c2d(0.1)
    with pytest.raises(ModelError, match="dt"):
        c2d_zoh(np.eye(1), np.ones((1, 1)), 0.0)


# ------------------------------------------------------------------ sysid.PolynomialModel
def test_polynomial_model_delegates_to_its_transfer_function():
    m = PolynomialModel.from_coefficients(A222, B222, dt=DT, std=STD222, input_name="i",
                                          output_name="F",
                                          input_unit="A", output_unit="N")
    g = m.system
    assert isinstance(g, lti.TransferFunction) and m.to_tf() is g and lti.as_system(m) is g
    assert (g.dt, g.inputs, g.outputs, g.input_units,
            g.output_units) == (DT, ("i",), ("F",), ("A",), ("N",))
    assert g.uncertainty.names == m.parameter_names == ("a1", "a2", "b2", "b3")
    np.testing.assert_array_equal(g.uncertainty.covariance, m.covariance)
    assert m.linear_record().system is g
    z_ref, p_ref = _zpk_zinv(A222, B222)
    np.testing.assert_allclose(np.sort_complex(m.poles()), p_ref, rtol=1e-12)
    np.testing.assert_allclose(m.zeros(), z_ref, rtol=1e-12)                  # 1.1672, §V-F
    assert m.zeros()[0].real == pytest.approx(0.2276 / 0.1950, rel=1e-12)
    assert m.stable and not m.minimum_phase
    assert m.dc_gain == pytest.approx((0.1950 - 0.2276) / (1 - 1.8732 + 0.8996), rel=1e-12)
    np.testing.assert_allclose(m.step(60), signal.lfilter(B222, A222, np.ones(60)), rtol=1e-12,
                               atol=1e-14)
    pulse = np.r_[1.0, np.zeros(59)]
    np.testing.assert_allclose(m.impulse(60), signal.lfilter(B222, A222, pulse), rtol=1e-12,
                               atol=1e-14)
    w, H = m.frequency_response(n=64)                                          # rad/s
    f_ref, H_ref = signal.freqz(B222, A222, worN=64, fs=1 / DT)
    np.testing.assert_allclose(w, 2 * np.pi * f_ref, rtol=1e-15)
    np.testing.assert_allclose(H, H_ref, rtol=1e-11)
    u = np.cos(np.arange(300) * 0.07)
    np.testing.assert_allclose(m.simulate(u), signal.lfilter(B222, A222, u), rtol=1e-12, atol=1e-14)
    yp, up = np.array([0.3, -0.1, 0.2]), np.array([1.0, 0.5, -0.5])
    zi = signal.lfiltic(B222, A222, yp[::-1], up[::-1])
    np.testing.assert_allclose(m.simulate(u, initial="given", y_past=yp, u_past=up),
                               signal.lfilter(B222, A222, u, zi=zi)[0], rtol=1e-12, atol=1e-14)
    for X, Y in zip(m.to_ss(form="controllable")._arrays(), signal.tf2ss(B222, A222 + [0.0])):
        np.testing.assert_array_equal(X, Y)                                    # scipy's realisation
    np.testing.assert_array_equal(m.to_scipy().den, signal.dlti(B222, A222 + [0.0], dt=DT).den)


def test_polynomial_model_layout_roots_and_integrator():
    """Poles and zeros in the q⁻¹ layout leave out the origin roots of the delay and of the padding
    (ARX [2 1 1]: B/A = b1 z/(z² + a1 z + a2) has a zero at z = 0 in positive powers); an
    integrator's
    DC gain is ±inf."""
    m = PolynomialModel.from_coefficients([1.0, -1.5, 0.7], [0.0, 2.0], dt=0.1)
    assert m.zeros().size == 0 and m.system.zeros().tolist() == [0.0]
    np.testing.assert_allclose(np.sort_complex(m.poles()),
                               _zpk_zinv([1.0, -1.5, 0.7], [0.0, 2.0])[1], rtol=1e-12)
    assert m.dc_gain == pytest.approx(2.0 / 0.2, rel=1e-12)
    integ = PolynomialModel.from_coefficients([1.0, -1.0], [0.0, 0.5], dt=0.1)
    assert integ.dc_gain == np.inf and not integ.stable


def test_polynomial_model_armax_oe_covariances():
    # ARMAX: the covariance over a1 b1 c1 keeps its order; c1 does not move B/A (zero tangent)
    armax = PolynomialModel.from_coefficients([1.0, -0.5], [0.0, 1.0], C=[1.0, 0.3], dt=0.1,
                                              std={"A": [0, 0.01], "B": [0, 0.02], "C": [0, 0.05]})
    g = armax.system
    assert g.uncertainty.names == ("a1", "b1", "c1") == armax.parameter_names
    assert np.all(g.uncertainty.tangents[0][2] == 0) and np.all(g.uncertainty.tangents[1][2] == 0)
    # OE: B/F with the f's as the denominator's parameters: ∂p/∂f1 = −1
    oe = PolynomialModel.from_coefficients([1.0], [0.0, 1.0], F=[1.0, -0.7], dt=0.1,
                                           std={"B": [0, 0.02], "F": [0, 0.01]})
    h = oe.system
    assert h.uncertainty.names == ("b1", "f1") and h.den_zinv().tolist() == [1.0, -0.7]
    np.testing.assert_allclose(oe.poles(), [0.7], rtol=1e-15)
    np.testing.assert_allclose(h.pole_covariance()[1][0, 0, 0], 0.01 ** 2, rtol=1e-12)


# ------------------------------------------------------------------ control.DiscretePlant
def test_discrete_plant_is_a_view_of_its_transfer_function():
    # a non-monic A with trailing padding: normalised as before (both divided by A[0] = 2)
    p = DiscretePlant([2 * a for a in A222] + [0.0], [2 * b for b in B222] + [0.0], DT,
                      input_name="i",
                      input_unit="A", output_name="F", output_unit="N")
    np.testing.assert_allclose(p.A, A222, rtol=1e-15)
    np.testing.assert_allclose(p.B, B222, rtol=1e-15)
    g = p.lti
    assert isinstance(g, lti.TransferFunction) and as_plant(p) is g and lti.as_system(p) is g
    assert (g.inputs, g.outputs, g.input_units, g.output_units) == (("i",), ("F",), ("A",), ("N",))
    assert p.nk == 2 == g.relative_degree()
    z_ref, p_ref = _zpk_zinv(A222, B222)
    np.testing.assert_allclose(np.sort_complex(p.poles()), p_ref, rtol=1e-12)
    np.testing.assert_allclose(p.zeros(), z_ref, rtol=1e-12)
    assert p.dc_gain() == pytest.approx((0.1950 - 0.2276) / (1 - 1.8732 + 0.8996), rel=1e-12)
    assert p.stable and not p.minimum_phase
    u = np.ones(200)
    np.testing.assert_allclose(p.simulate(u, y_offset=2.0), signal.lfilter(B222, A222, u) + 2.0,
                               rtol=1e-12)
    np.testing.assert_allclose(p.scaled(3.0).B, 3.0 * np.array(B222), rtol=1e-15)
    ss = p.to_ss()
    assert isinstance(ss, lti.StateSpace) and ss.inputs == ("i",) and ss.output_units == ("N",)
    for X, Y in zip(ss._arrays(), signal.tf2ss(B222, A222 + [0.0])):
        np.testing.assert_array_equal(X, Y)
    back = DiscretePlant.from_model(ss)                                       # state space → q⁻¹
    np.testing.assert_allclose(back.A, p.A, atol=1e-12)
    np.testing.assert_allclose(back.B, p.B, atol=1e-12)
    assert back.output_unit == "N" and back.input_name == "i"
    with pytest.raises(ModelError, match="discrete"):
        as_plant(lti.TransferFunction([1.0], [1.0, 1.0]))
    with pytest.raises(ModelError, match="no input path"):
        DiscretePlant([1.0, -0.5], [0.0, 0.0], DT)
    with pytest.raises(ModelError, match="cannot build a discrete plant from object: as_system"):
        as_plant(object())
    with pytest.raises(ModelError, match="SISO, found 2 outputs"):
        as_plant(lti.StateSpace([[0.5]], [[1.0]], [[1.0], [2.0]], dt=DT))


def test_discrete_plant_from_a_zoh_state_space_matches_scipy():
    """A ZOH-discretised second-order plant read as a q⁻¹ plant: scipy's cont2discrete + ss2tf."""
    wn, z = 30.0, 0.4
    A, B, C = (np.array([[0, 1], [-wn ** 2, -2 * z * wn]]), np.array([[0], [wn ** 2]]),
               np.array([[1.0, 0]]))
    p = DiscretePlant.from_model(lti.StateSpace(A, B, C, None).c2d(DT))
    Ad, Bd, Cd, Dd, _ = signal.cont2discrete((A, B, C, np.zeros((1, 1))), DT, method="zoh")
    num, den = signal.ss2tf(Ad, Bd, Cd, Dd)
    np.testing.assert_allclose(p.A, den, rtol=1e-12)
    np.testing.assert_allclose(p.B, num[0], rtol=1e-10, atol=1e-14)
    assert p.nk == 1


def test_design_rst_accepts_lti_transfer_functions_and_what_it_accepted():
    """design_rst on an lti transfer function, a DiscretePlant, a tuple and a PolynomialModel gives
    one controller, whose closed loop A R + B S = P has the designed poles."""
    g = lti.TransferFunction.from_polynomials(A222, B222, dt=DT)
    designs = [design_rst(x, wn=15.0, zeta=0.9) for x in
               (g, DiscretePlant(A222, B222, DT), (A222, B222, DT),
                PolynomialModel.from_coefficients(A222, B222, dt=DT))]
    for c in designs[1:]:
        for k in "RST":
            np.testing.assert_array_equal(getattr(c, k), getattr(designs[0], k))
    c = designs[0]
    assert isinstance(c.plant, lti.TransferFunction)
    np.testing.assert_allclose(c.characteristic(),
                               np.pad(c.design["P"],
                                                          (0,
                                                                          c.characteristic().size
                                                                          - c.design["P"].size)),
                               atol=1e-12)
    # the loop's frequency response is that of K·G in scipy: B S/(A R) at z = e^{jωh}; near the
    # integrator's pole at z = 1 both evaluations lose digits as 1/|z − 1| = 1/(ωh) (400 at 0.5
    # rad/s)
    w = np.array([0.5, 4.0, 40.0])
    _, hg = signal.freqz(B222, A222, worN=w * DT)
    _, hk = signal.freqz(c.S, c.R, worN=w * DT)
    np.testing.assert_allclose(c.loop_frequency_response(w), hg * hk, rtol=1e-9)
