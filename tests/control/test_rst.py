"""RST pole placement (gripkit.control.rst) on plants of any order and on what identification
returns (issue 25, "Identify → control"): the closed loop has exactly the designed characteristic
polynomial P = A_m A_o (the Diophantine equation A(1 − q⁻¹)R′ + B S = P), unit DC gain from the
reference, zero steady-state error to an input step disturbance (integral action), and an
anti-windup polynomial that is monic, stable and no longer than R."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gripkit.control import DiscretePlant, RSTController, as_plant, design_rst, simulate_loop
from gripkit.errors import ModelError
from gripkit.lti import StateSpace, TransferFunction


def _plant(poles, zeros, nk, dt=0.01, gain=1.0):
    """B/A in the q⁻¹ layout with the given z-plane poles and zeros, nk samples of delay and
    DC gain ``gain``."""
    A = np.real(np.poly(poles))
    Bz = np.real(np.poly(zeros)) if len(zeros) else np.ones(1)
    Bz *= gain * A.sum() / Bz.sum()
    return TransferFunction.from_polynomials(A, np.concatenate([np.zeros(nk), Bz]), dt=dt)


def _check_design(g, wn=8.0, zeta=0.8):
    c = design_rst(g, wn=wn, zeta=zeta)
    P = c.design["P"]
    char = c.characteristic()
    assert char.size >= P.size
    np.testing.assert_allclose(char[:P.size], P, atol=1e-8 * np.abs(P).max())
    np.testing.assert_allclose(char[P.size:], 0.0, atol=1e-8 * np.abs(P).max())
    assert c.is_stable()
    # unit DC gain from r to y: B(1) T(1) / P(1) = 1; integral action: R(1) = 0, so an input step
    # disturbance is rejected (B R / P at z = 1); both also seen in the simulated responses
    B = c.resolve_plant(None).num_zinv()
    scale = np.abs(char).sum()  # P(1) is a small difference of O(1) terms for slow observers
    assert abs(B.sum() * c.T.sum() - char.sum()) < 1e-9 * scale
    assert abs(c.R.sum()) < 1e-12 * np.abs(c.R).sum()
    assert c.reference_response(4000)[-1] == pytest.approx(1.0, abs=1e-4)
    assert abs(c.disturbance_response(4000, where="input")[-1]) < 1e-4
    aw = c.A_aw
    assert aw[0] == 1.0 and aw.size == c.R.size
    trimmed = np.trim_zeros(aw, "b")
    assert trimmed.size == 1 or np.all(np.abs(np.roots(trimmed)) < 1.0)
    return c


@pytest.mark.parametrize("order", [1, 2, 3, 4, 6])
def test_design_rst_for_any_denominator_degree(order):
    """Degree ≥ 3 used to fail with 'A_aw must be monic …' (deg A_o > deg R)."""
    poles = [0.9 * math.exp(-0.2 * k) for k in range(order)]
    g = _plant(poles, [0.5] if order > 1 else [], nk=1)
    c = _check_design(g)
    assert c.design["Ao"].size - 1 == (order + 1) + (g.num_zinv().size - 1) - 3


@settings(max_examples=25, deadline=None)
@given(poles=st.lists(st.floats(-0.9, 0.95), min_size=1, max_size=5),
       zero=st.floats(-0.8, 0.8), nk=st.integers(1, 3))
def test_closed_loop_has_the_designed_poles(poles, zero, nk):
    """Property: for random stable plants (up to 5 poles, a zero, delays 1–3) the closed loop's
    characteristic polynomial equals the designed P to 1e-8."""
    if any(abs(p - zero) < 0.05 for p in poles) or min(abs(p - 1.0) for p in poles) < 0.05:
        return  # a near-cancelling pair or a near-integrator: the design refuses those
    _check_design(_plant(poles, [zero], nk))


def test_design_rst_takes_an_identified_state_space_model_and_its_file(tmp_path):
    """A state-space model from identification (the LinearModel of n4sid) and the same model
    loaded from its file are both accepted, and give the same controller."""
    from gripkit.sysid import LinearModel, load_model

    ss = StateSpace([[1.6, -0.64], [1.0, 0.0]], [[1.0], [0.0]], [[0.02, 0.018]], [[0.0]], dt=0.01,
                    inputs="V", outputs="x", input_units="V", output_units="m")
    m = LinearModel(ss, "n4sid")
    c = _check_design(m)
    m.save(tmp_path / "m.json")
    c2 = design_rst(load_model(tmp_path / "m.json"), wn=8.0, zeta=0.8)
    np.testing.assert_allclose(c2.R, c.R, rtol=1e-10)
    np.testing.assert_allclose(c2.S, c.S, rtol=1e-10)
    assert as_plant(m).den_zinv().size == 3


def test_saturated_loop_recovers_for_a_third_order_plant():
    """The anti-windup form keeps a fourth-order loop bounded under tight limits, and it settles at
    the reference once the limits allow it."""
    g = _plant([0.95, 0.9, 0.8], [0.3], nk=2)
    c = design_rst(g, wn=6.0, zeta=0.9)
    c_lim = design_rst(g, wn=6.0, zeta=0.9, u_min=-1.5, u_max=1.5)
    r = np.ones(3000)
    free = simulate_loop(c, r=r)
    lim = simulate_loop(c_lim, r=r)
    assert np.max(np.abs(free.u)) > 1.5  # the limits do bind
    assert np.all(np.abs(lim.u) <= 1.5 + 1e-12)
    assert abs(lim.y[-1] - 1.0) < 1e-3
    assert np.max(lim.y) < 1.5  # no windup overshoot


def test_design_rst_refuses_what_it_cannot_do():
    with pytest.raises(ModelError, match="zero at z = 1"):
        design_rst(_plant([0.5, 0.3], [], nk=1).replace() * TransferFunction([1.0, -1.0],
                                                                             [1.0, 0.0], dt=0.01))
    with pytest.raises(ModelError, match="feedthrough"):
        design_rst(TransferFunction.from_polynomials([1.0, -0.5], [1.0, 0.2], dt=0.01))
    with pytest.raises(ModelError, match="discrete"):
        design_rst(TransferFunction([1.0], [1.0, 1.0]))


def test_discrete_plant_is_the_q_inverse_view_of_its_transfer_function():
    """DiscretePlant([1, −1.5, 0.7], [0, 0, 0.5, −0.6]): two samples of delay, a zero at 1.2
    (non-minimum phase), poles at 0.75 ± 0.37j, DC gain B(1)/A(1) = −0.1/0.2 = −0.5; it simulates
    as scipy.signal.lfilter(B, A), its state-space realisation and python-control's
    forced_response; scaled() multiplies B and keeps the poles."""
    import control  # a dev dependency: the cross-check fails, never skips, without it
    from scipy.signal import lfilter

    A, B = [1.0, -1.5, 0.7], [0.0, 0.0, 0.5, -0.6]
    p = DiscretePlant(A, B, 0.02)
    assert p.nk == 2
    np.testing.assert_allclose(p.zeros(), [1.2], rtol=1e-12)
    np.testing.assert_allclose(np.sort_complex(p.poles()), np.sort_complex(np.roots(A)), rtol=1e-12)
    assert p.dc_gain() == pytest.approx(-0.5, rel=1e-12)
    assert p.stable and not p.minimum_phase
    u = np.sin(0.3 * np.arange(150)) + (np.arange(150) > 40)
    ref = lfilter(B, A, u)
    np.testing.assert_allclose(p.simulate(u), ref, atol=1e-12)
    ss = p.to_ss()
    np.testing.assert_allclose(ss.simulate(u)[:, 0], ref, atol=1e-10)
    back = DiscretePlant.from_model(ss)
    np.testing.assert_allclose(back.A, p.A, atol=1e-12)
    np.testing.assert_allclose(back.B, p.B, atol=1e-12)
    _, y = control.forced_response(p.to_control(), U=u)
    np.testing.assert_allclose(y, ref, atol=1e-10)
    s = p.scaled(3.0)
    assert s.dc_gain() == pytest.approx(-1.5, rel=1e-12)
    np.testing.assert_allclose(s.A, p.A)


@pytest.mark.filterwarnings("ignore:stability_margins")
def test_design_for_a_zoh_second_order_plant_with_a_delay_and_its_margins():
    """Any discrete plant: a ZOH-discretised K ω_n²/(s² + 2ζω_n s + ω_n²) (ω_n = 30 rad/s,
    ζ = 0.4, 5 ms) with one more sample of delay gets exactly the designed closed loop; the
    margins equal python-control's for the loop S/R · B/A."""
    import control  # a dev dependency: the cross-check fails, never skips, without it

    wn, z = 30.0, 0.4
    ss = StateSpace([[0, 1], [-wn ** 2, -2 * z * wn]], [[0], [wn ** 2]], [[1, 0]], [[0]]).c2d(0.005)
    p = DiscretePlant.from_model(ss)
    p = DiscretePlant(p.A, np.r_[0.0, p.B], p.dt)  # one more sample of delay
    assert p.nk == 2
    c = _check_design(p, wn=10.0, zeta=0.8)
    mg = c.margins()
    gm, pm, _, _ = control.margin(p.to_control() * control.tf(
        np.r_[c.S, np.zeros(max(0, c.R.size - c.S.size))], c.R, p.dt))
    assert 20 * math.log10(gm) == pytest.approx(mg["gain_margin_db"], abs=0.05)
    assert pm == pytest.approx(mg["phase_margin_deg"], abs=0.2)


def test_integral_action_impossible_with_zero_at_one():
    with pytest.raises(ModelError, match="zero at z = 1"):
        design_rst(DiscretePlant([1, -0.5], [0, 1, -1], 0.01))


def test_anti_windup_recovers_faster_than_the_clamped_law():
    """A load the limits cannot compensate saturates u for 150 samples; afterwards the anti-windup
    form (A_aw = A_o) returns to the reference with less than half the integrated error of the
    same R, S, T clamped only (anti_windup=False, A_aw = R, whose winding-up state is still far
    from the reference 6 s later), and it settles at r once the load is within reach."""
    g = _plant([0.9, 0.7], [0.4], nk=1)
    c = design_rst(g, wn=8.0, zeta=0.8, u_min=-0.3, u_max=0.3)
    plain = RSTController(c.R, c.S, c.T, anti_windup=False, u_min=-0.3, u_max=0.3, plant=g)
    np.testing.assert_array_equal(plain.A_aw, c.R)
    n = 900
    r = np.full(n, 0.2)
    d = np.r_[np.zeros(150), np.full(150, 0.6), np.zeros(n - 300)]
    res = [simulate_loop(k, g, r, d_in=d) for k in (c, plain)]
    assert all(x.u.min() == -0.3 for x in res)  # both saturate under the load
    iae = [np.abs(x.y[300:] - 0.2).sum() for x in res]
    assert iae[0] < 0.5 * iae[1]
    assert abs(res[0].y[-1] - 0.2) < 1e-6


@pytest.mark.parametrize("kw,phrase", [(dict(R=[2.0, 1.0]), "R must be monic"),
                                       (dict(A_aw=[1.0, -1.5]), "A_aw must be stable"),
                                       (dict(u_min=1.0, u_max=1.0), "must be below u_max")])
def test_rst_controller_refuses_bad_polynomials_and_limits(kw, phrase):
    args = dict(R=[1.0, -1.0], S=[0.5, 0.1], T=[0.6])
    args.update(kw)
    with pytest.raises(ModelError, match=phrase):
        RSTController(args.pop("R"), args.pop("S"), args.pop("T"), **args)
