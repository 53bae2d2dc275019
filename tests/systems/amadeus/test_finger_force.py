"""Finger force control on the Table II [2 2 2] model (000_8f66dcc7ab06470c.txt §V-F, §V-G).

Stated specification of the default design (ω_n = 15 rad/s, ζ = 0.9): closed loop stable with the
NMP zero kept; 10-90 % rise time <= 0.20 s; overshoot <= 2 %; NMP undershoot <= 10 %; 2 % settling
<= 0.40 s; gain margin >= 6 dB; phase margin >= 45°.
"""

import math

import numpy as np
import pytest

from gripkit.control import DiscretePlant, RSTController, design_rst, simulate_loop
from gripkit import zoo
from gripkit.errors import ParameterError
from gripkit.sysid.physical.step_response import step_metrics
from gripkit.systems.amadeus import GraspScenario, simulate_finger_grasp
from gripkit.systems.amadeus.parameters import TABLE2_A, TABLE2_B, force_plant

RAW = DiscretePlant(TABLE2_A, TABLE2_B, 0.005)


def _step(y, dt):
    """Metrics of a unit-reference step response from rest."""
    return step_metrics(np.arange(y.size) * dt, y, y_initial=0.0, y_final=1.0)

PLANT, _ = force_plant()


def test_table2_plant_is_nonminimum_phase():
    """Table II [2 2 2]: zero at 0.2276/0.1950 = 1.1672 (outside the unit circle, §V-F), two-sample
    delay, stable complex poles; the SI scaling keeps poles and zeros."""
    assert RAW.nk == 2
    np.testing.assert_allclose(RAW.zeros(), [0.2276 / 0.1950], rtol=1e-12)
    assert not RAW.minimum_phase and RAW.stable
    assert RAW.dc_gain() == pytest.approx((0.1950 - 0.2276) / (1 - 1.8732 + 0.8996))
    np.testing.assert_allclose(PLANT.zeros(), RAW.zeros())
    assert PLANT.dc_gain() == pytest.approx(-15.45 / 0.5)


def test_plant_from_state_space_and_to_control():
    import control  # a dev dependency: the cross-check fails, never skips, without it
    ss = RAW.to_ss()
    back = DiscretePlant.from_model(ss)
    np.testing.assert_allclose(back.A, RAW.A, atol=1e-12)
    np.testing.assert_allclose(back.B, RAW.B, atol=1e-12)
    u = np.sin(np.arange(200) * 0.1)
    np.testing.assert_allclose(ss.simulate(u)[:, 0], RAW.simulate(u), atol=1e-10)
    tf = RAW.to_control()
    _, y = control.forced_response(tf, U=u)
    np.testing.assert_allclose(y, RAW.simulate(u), atol=1e-10)


@pytest.fixture(scope="module")
def rst():
    return design_rst(PLANT, wn=15.0, zeta=0.9, u_min=-0.25, u_max=0.25)


def test_closed_loop_poles_as_designed_and_zero_kept(rst):
    """The characteristic polynomial A R + B S equals the designed A_m A_o (no pole/zero
    cancellation: the NMP zero and the delay remain in B T, the reference transfer);
    python-control's
    feedback loop has the same poles."""
    import control  # a dev dependency: the cross-check fails, never skips, without it
    np.testing.assert_allclose(rst.characteristic()[:6], rst.design["P"], atol=1e-10)
    assert rst.is_stable()
    zeros = np.roots(np.trim_zeros(np.convolve(PLANT.B, rst.T), "f"))  # zeros of B T in z
    assert np.min(np.abs(zeros - 1.1672)) < 1e-3
    assert np.min(np.abs(rst.closed_loop_poles() - 1.1672)) > 0.2  # no pole cancels it
    G = PLANT.to_control()
    Cfb = control.tf(np.r_[rst.S, np.zeros(rst.R.size - rst.S.size)] if rst.S.size < rst.R.size
                     else rst.S, rst.R, PLANT.dt)
    cl = control.feedback(G * Cfb, 1)
    p_ref = np.sort_complex(np.asarray(control.poles(cl)))
    p_ref = p_ref[np.abs(p_ref) > 1e-9]
    # the observer pole is triple: its numerical roots scatter by ~eps^(1/3)
    np.testing.assert_allclose(np.sort_complex(rst.closed_loop_poles()), p_ref, atol=1e-4)


def steady_state_tolerance(c, plant, n: int) -> float:
    """Bound on |1 − y[n−1]| of the loop's unit-step response, derived rather than chosen.

    The unit DC gain Σnum/Σden is a ratio of two sums that cancel heavily (Σ|den|/|Σden| ≈ 1e7 for
    these designs), so each carries a relative rounding error up to len·ε·Σ|c|/|Σc| (Higham,
    Accuracy and Stability of Numerical Algorithms, §4.2). The transient left after n samples is of
    order ρⁿ·max|y| for the slowest closed-loop pole ρ."""
    num, den = np.convolve(plant.B, c.T), c.characteristic(plant)
    eps = np.finfo(np.float64).eps
    cancel = np.abs(den).sum() / abs(den.sum()) + np.abs(num).sum() / abs(num.sum())
    rho = np.abs(np.roots(den)).max()
    return den.size * eps * cancel + rho ** n * np.abs(c.reference_response(n)).max()


@pytest.mark.filterwarnings("ignore:stability_margins")
def test_step_response_meets_the_stated_specification(rst):
    m = _step(rst.reference_response(400), PLANT.dt)
    assert m["rise_time"] <= 0.20
    assert m["overshoot_percent"] <= 2.0
    assert 0.0 < m["undershoot_percent"] <= 10.0  # the NMP zero must show: an inverse response
    assert m["settling_time"] <= 0.40
    assert m["steady_state_error_percent"] < 100 * steady_state_tolerance(rst, PLANT, 400)
    mg = rst.margins()
    assert mg["gain_margin_db"] >= 6.0
    assert mg["phase_margin_deg"] >= 45.0
    import control  # a dev dependency: the cross-check fails, never skips, without it
    gm, pm, _, _ = control.margin(PLANT.to_control() * control.tf(
        np.r_[rst.S, np.zeros(max(0, rst.R.size - rst.S.size))], rst.R, PLANT.dt))
    assert 20 * math.log10(gm) == pytest.approx(mg["gain_margin_db"], abs=0.05)
    assert pm == pytest.approx(mg["phase_margin_deg"], abs=0.2)


def test_tracking_and_disturbance_rejection_with_valve_limits(rst):
    """Integral action: zero steady-state error to a force step and to a step load on the valve
    current; the applied current stays inside 600-1100 mA (deviations ±0.25 A)."""
    n = 600
    r = np.r_[np.zeros(20), np.full(n - 20, 3.0)]
    d = np.r_[np.zeros(300), np.full(n - 300, 0.01)]
    res = simulate_loop(rst, PLANT, r, d_in=d)
    assert res.y[290] == pytest.approx(3.0, abs=1e-4)
    assert res.y[-1] == pytest.approx(3.0, abs=1e-4)
    assert res.u.min() >= -0.25 and res.u.max() <= 0.25


def test_anti_windup_limits_overshoot_under_saturation(rst):
    """A load on the valve current that the limits cannot compensate drives u into saturation for
    1 s; when it goes away, the anti-windup form recovers in a fraction of the time and error of the
    same RST law with windup (clamped only)."""
    naive = (RSTController(rst.R, rst.S, rst.T, anti_windup=False, u_min=-0.1, u_max=0.1,
                           plant=PLANT))
    aw = RSTController(rst.R, rst.S, rst.T, A_aw=rst.A_aw, u_min=-0.1, u_max=0.1, plant=PLANT)
    n = 800
    r = np.full(n, 2.0)  # needs u = -0.065 A
    d = np.r_[np.zeros(200), np.full(200, 0.08), np.zeros(n - 400)]  # would need u = -0.145 A
    res_n = simulate_loop(naive, PLANT, r, d_in=d)
    res_a = simulate_loop(aw, PLANT, r, d_in=d)
    assert res_a.u.min() == -0.1 and res_n.u.min() == -0.1  # both saturate
    iae_n = np.abs(res_n.y[400:] - 2.0).sum() * PLANT.dt
    iae_a = np.abs(res_a.y[400:] - 2.0).sum() * PLANT.dt
    t_n = np.flatnonzero(np.abs(res_n.y[400:] - 2.0) > 0.05)[-1] * PLANT.dt
    t_a = np.flatnonzero(np.abs(res_a.y[400:] - 2.0) > 0.05)[-1] * PLANT.dt
    assert iae_a < 0.4 * iae_n
    assert t_a < 0.5 * t_n
    assert res_a.y[-1] == pytest.approx(2.0, abs=1e-3)


def test_robust_to_compliant_objects(rst):
    """Softer contacts lower the plant gain: the loop stays stable from 5 % to 200 % of the rigid
    gain."""
    for g in (0.05, 0.2, 0.5, 1.0, 1.5, 2.0):
        assert rst.is_stable(PLANT.scaled(g))


@pytest.fixture(scope="module")
def detector():
    from gripkit.systems.amadeus import SlipDetector
    from gripkit.systems.amadeus.pvdf import StickSlipContact, nonslip_grasp_inputs, pvdf_noise

    rng = np.random.default_rng(8)
    c = StickSlipContact()
    u = nonslip_grasp_inputs(20.0, dt=0.0005, rng=rng)
    x = (c.simulate(u, dt=1 / 2000.0, x0=c.equilibrium_state(u[0, 1]))["v_pvdf"]
         + pvdf_noise(u.shape[0], dt=0.0005, rng=rng))
    return SlipDetector(dt=0.0005).calibrate(x)


@pytest.mark.parametrize("k_object, hold_tol", [(300.0, 0.25), (2000.0, 0.1), (math.inf, 0.1)])
def test_grasp_respects_the_force_limit_and_arrests_slip(rst, detector, k_object, hold_tol):
    """Guarded approach, force control to 2 N, a load increase beyond μ_s F_n: the slip is detected
    within 20 ms of its onset, the reflex raises the grip until the slip stops, and the contact
    force
    never exceeds the 4 N limit (compliant and rigid objects). The fixed controller, designed on the
    rigid-plate model, is slower on a very soft object (300 N/m: 28 % of the loop gain), hence the
    looser hold tolerance there."""
    sc = GraspScenario(k_object=k_object, seed=3)
    g = simulate_finger_grasp(rst, PLANT, sc, detector=detector)
    assert g.contact_time is not None and g.contact_time < 1.0
    assert g.max_force <= sc.force_limit
    hold = (g.t > 1.8) & (g.t < 2.2)
    assert abs(g.force[hold].mean() - sc.force_target) < hold_tol
    onset = g.t[np.argmax(g.slipping > 0)]
    assert g.slipping[g.t < 2.2].max() == 0.0
    alarms = [a for a in g.alarms if a >= onset - 0.02]
    assert alarms and alarms[0] - onset <= 0.020
    assert g.slipping[g.t > 3.6].max() == 0.0  # the reflex stopped it
    assert g.force[-1] > sc.force_target + 0.5


# -- the force scale (N per sensor unit) is an assumed, user-settable calibration
# ---------------------

def test_force_scale_default_is_derived_from_fig2c_peak_over_the_valve_span():
    from gripkit.systems.amadeus.force_dynamics import FORCE_SCALE, TABLE_II
    row = next(r for r in TABLE_II if (r.na, r.nb, r.nk, r.data) == (2, 2, 2, "S1"))
    gain = abs(sum(row.B) / sum(row.A))  # Table II [2 2 2]: 0.0326/0.0264 units/mA
    assert gain == pytest.approx(1.235, abs=5e-4)
    assert FORCE_SCALE == pytest.approx(15.45 / (gain * 500.0), rel=1e-12)  # Fig. 2(c), §V-E
    p = zoo.build("amadeus-finger-force").parameters["force_scale"]
    assert p.value == FORCE_SCALE and p.unit == "N"
    assert p.source.startswith("assumed:") and "15.45 N" in p.source and "500 mA" in p.source


def test_force_scale_is_user_settable_and_scales_b_only():
    ref = zoo.build("amadeus-finger-force")
    m = zoo.build("amadeus-finger-force", force_scale=0.04)
    assert (m.force_scale == 0.04
            and m.parameters["force_scale"].source.startswith("set by the user"))
    np.testing.assert_allclose(m.model.B, ref.model.B * 0.04 / ref.force_scale, rtol=1e-12)
    np.testing.assert_array_equal(m.model.A, ref.model.A)
    hand = zoo.build("amadeus-hand", force_scale=0.04)
    np.testing.assert_allclose(hand.plant.B, m.model.B, rtol=1e-12)
    assert hand.parameters.value("force_scale") == 0.04


@pytest.mark.parametrize("bad", [0.0, -0.025, float("nan"), float("inf"), "a lot"])
def test_force_scale_rejects_non_positive_or_non_numbers(bad):
    with pytest.raises(ParameterError, match="force_scale"):
        zoo.build("amadeus-finger-force", force_scale=bad)


def test_design_rst_accepts_the_zoo_model_directly():
    m = zoo.build("amadeus-finger-force")
    c = design_rst(m, wn=15.0, zeta=0.9, u_min=-0.25, u_max=0.25)
    ref = design_rst(m.model, wn=15.0, zeta=0.9, u_min=-0.25, u_max=0.25)
    np.testing.assert_allclose(np.sort_complex(c.closed_loop_poles()),
                               np.sort_complex(ref.closed_loop_poles()),
                               atol=1e-12)
    assert np.abs(c.closed_loop_poles()).max() < 1
    assert DiscretePlant.from_model(m).output_unit == "N"
