"""AMADEUS fingertip position control from tube pressures (000_8f66dcc7ab06470c.txt §II-C: "a
calibrated model of the finger motion is used for closed-loop position control, driven by
pressures measured from sensors within each tube"; limits §II-D and the Fig. 2(c) table)."""

import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gripkit.errors import AccuracyWarning, ModelError
from gripkit.systems.amadeus.bellows_finger import BAR
from gripkit.systems.amadeus.position_control import FingerPositionController, tip_inverse
from gripkit.systems.amadeus.valve import ProportionalValve, valve_parameters

C = FingerPositionController()
P_LOW, P_HIGH = 12.0 * BAR, 30.0 * BAR  # §II-D: linear above 12 bar, 30 bar supply
TARGET_P = np.array([22.0, 14.0, 17.0]) * BAR


@settings(max_examples=40, deadline=None)
@given(st.floats(12, 30), st.floats(12, 30), st.floats(12, 30))
def test_tip_inverse_recovers_the_pressures(p1, p2, p3):
    """Three pressures ↔ three tip coordinates: the inverse of the forward model (ψ, θ from the tip,
    M₀ = k_b θ, P̄ from the length) gives back the pressures that produced the tip."""
    P = np.array([p1, p2, p3]) * BAR
    tip = C.finger.bending(P).tip
    assert tip_inverse(C.finger, tip) == pytest.approx(P, rel=1e-9, abs=1e-3)


def test_loop_margins_are_the_analytic_ones():
    """T_i = τ cancels the valve lag: L = K_p e^{-sT_d}/(τ s), ω_c = K_p/τ = 0.5/0.025 = 20 rad/s,
    phase margin 90° − ω_c T_d = 90° − 20·0.01 rad = 78.54°."""
    wc, pm = C.loop_margins()
    assert wc == pytest.approx(20.0, rel=1e-9)
    assert pm == pytest.approx(90.0 - math.degrees(0.2), abs=1e-6)


def test_step_converges_to_the_inverse_pressures_and_the_tip():
    """Nominal (the controller's valve model is the valve): the pressures reach the inverse model's
    exact pressures (22, 14, 17 bar) to 1e-3 Pa within 0.6 s (12 τ_cl, τ_cl = τ/K_p = 50 ms)
    and the tip estimate reaches the target within the model's tolerance Σ|∂t/∂P_i|·1e-3 Pa;
    no tube leaves [12, 30] bar (§II-D)."""
    tip = C.finger.bending(TARGET_P).tip
    r = C.simulate(tip, 1.0)
    assert r.reference == pytest.approx(TARGET_P, rel=1e-9)
    assert r.settling_time(1e-3) <= 0.6
    tol = C.tip_tolerance(1e-3, TARGET_P)
    assert 0 < tol < 1e-9
    assert np.abs(r.tip_estimate[-1] - tip).max() <= tol
    assert r.pressure.min() >= P_LOW - 1e-6 and r.pressure.max() <= P_HIGH


def test_integral_removes_a_valve_model_error():
    """The real valve has a wider hysteresis than the controller assumes (h = 25 mA against 15 mA):
    the feed-forward alone leaves, in steady state, exactly the static-curve error
    P_ref − P(P⁻¹(P_ref) + h_c − h_true) (0.37 bar), the PI loop leaves less than 1 % of it (a
    frozen overshoot, see the module docstring), and the real tip is within the tolerance of that
    residual."""
    plant = ProportionalValve(valve_parameters(hysteresis=0.025))
    tip = C.finger.bending(TARGET_P).tip
    ff = C.simulate(tip, 1.0, feedback=False, plant_valve=plant)
    expected = TARGET_P - plant.static_pressure(C.valve.current_for(TARGET_P) + 0.015 - 0.025)
    assert ff.pressure[-1] - TARGET_P == pytest.approx(-expected, rel=1e-6)
    assert expected.min() > 0.36 * BAR
    cl = C.simulate(tip, 1.0, plant_valve=plant)
    residual = np.abs(cl.pressure[-1] - TARGET_P)
    assert (residual < 0.01 * expected).all()
    assert np.abs(cl.tip[-1] - tip).max() <= C.tip_tolerance(residual.max(), TARGET_P)
    assert cl.pressure.min() >= P_LOW - 1e-6 and cl.pressure.max() <= P_HIGH


def test_pressures_stay_in_range_near_the_supply():
    """A target with one tube at 29.5 bar (0.5 bar under the 30 bar supply, §II-D): the loop
    reaches it and no tube exceeds 30 bar or drops under 12 bar on the way."""
    P = np.array([29.5, 12.0, 20.0]) * BAR
    r = C.simulate(C.finger.bending(P).tip, 1.0)
    assert r.pressure[-1] == pytest.approx(P, abs=1e-2)
    assert r.pressure.min() >= P_LOW - 1e-6 and r.pressure.max() <= P_HIGH


def test_unreachable_targets_are_refused_or_saturated():
    """Beyond the pressure range: a ModelError naming the range; with saturate=True an
    AccuracyWarning, pressures in [12, 30] bar with the target's bend (its pressure spread) kept,
    the mean lowered to put the highest tube at 30 bar, the direction ψ kept. Beyond the 20 mm
    of Fig. 2(c) or behind the fingertip: ModelError."""
    far = np.array([0.165, 0.030, 0.0])
    with pytest.raises(ModelError, match="out of reach.*operating range \\[12, 30\\] bar"):
        C.reference(far)
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        P, reached = C.reference(far, saturate=True)
    assert any(issubclass(x.category, AccuracyWarning) and "saturated to" in str(x.message)
               for x in w)
    assert P.min() >= P_LOW - 1e-6 and P.max() <= P_HIGH + 1e-6
    want = tip_inverse(C.finger, far)  # 34.5, 16.7, 16.7 bar: the spread fits, the mean not
    assert want.max() == pytest.approx(34.51 * BAR, abs=0.01 * BAR)
    assert np.ptp(P) == pytest.approx(np.ptp(want), rel=1e-9)
    assert P.max() == pytest.approx(P_HIGH, rel=1e-12)
    assert math.atan2(reached[2], reached[1]) == pytest.approx(0.0, abs=1e-9)
    with pytest.raises(ModelError, match="exceeds the 20 mm limit"):
        C.reference([0.150, 0.045, 0.0])
    with pytest.raises(ModelError, match="not beyond the"):
        C.reference([0.01, 0.0, 0.0])


def test_saturated_step_stays_in_range():
    """Closed loop to a saturated target: every tube within [12, 30] bar throughout."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AccuracyWarning)
        r = C.simulate([0.166, 0.0, 0.035], 1.0, saturate=True)
    assert r.pressure.min() >= P_LOW - 1e-6 and r.pressure.max() <= P_HIGH
    psi = math.atan2(r.tip_estimate[-1, 2], r.tip_estimate[-1, 1])
    assert psi == pytest.approx(math.pi / 2, abs=1e-6)
