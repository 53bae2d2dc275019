"""AMADEUS hand: palm, knuckles, fingertip kinematics and force closure (000_8f66dcc7ab06470c.txt
§II-B, §II-C)."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from gripkit.consistency import check
from gripkit.errors import DataError, ModelError
from gripkit.systems.amadeus.bellows_finger import BAR
from gripkit.systems.amadeus.hand import AmadeusHand, force_closure

HAND = AmadeusHand()


def _rot(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


@given(st.floats(-math.radians(20), math.radians(20)), st.floats(0, 2 * math.pi),
       st.floats(0, 0.012))
def test_symmetric_triangle(angle, psi, d):
    """§II-B: three fingers in a symmetric triangle — the same knuckle angle and bending put the
    tips 120° apart about the hand axis."""
    P = HAND.finger.pressures_for(psi, d)
    tips = HAND.fingertip_positions(angle, P)
    np.testing.assert_allclose(_rot(2 * math.pi / 3) @ tips[0], tips[1], atol=1e-12)
    np.testing.assert_allclose(_rot(4 * math.pi / 3) @ tips[0], tips[2], atol=1e-12)


def test_straight_finger_tip_position():
    """Straight fingers: tip radius R_p + L sin θ and height L cos θ (L = knuckle offset +
    length)."""
    P = np.full(3, 21 * BAR)
    L = HAND.reach(21 * BAR)
    for th in np.radians([-20, -7, 0, 13, 20]):
        tips = HAND.fingertip_positions(th, P)
        rho = np.hypot(tips[:, 0], tips[:, 1])
        np.testing.assert_allclose(rho, HAND.hand_parameters.value("palm_radius") + L
                                   * math.sin(th), rtol=1e-12)
        np.testing.assert_allclose(tips[:, 2], L * math.cos(th), rtol=1e-12)


def test_bending_toward_the_palm_axis_closes_the_hand():
    """ψ = 0 (tube 1 high) moves every tip toward the hand axis by the tip's lateral deflection."""
    straight = HAND.fingertip_positions(0.0, np.full(3, 21 * BAR))
    P = HAND.finger.pressures_for(0.0, 0.010, "max")
    bent = HAND.fingertip_positions(0.0, P)
    lat = float(HAND.finger.bending(P).tip_deflection)
    np.testing.assert_allclose(np.hypot(bent[:, 0], bent[:, 1]),
                               HAND.hand_parameters.value("palm_radius") - lat,
                               rtol=1e-12)
    assert np.all(np.hypot(bent[:, 0], bent[:, 1]) < np.hypot(straight[:, 0], straight[:, 1]))


def test_knuckle_potentiometer_and_object_sizes():
    """§II-C potentiometer (assumed ±2 V over ±20°) and §II-B object range ∅10-150 mm within
    ±20°."""
    for th in np.radians([-20, 0, 11.5]):
        assert HAND.knuckle_angle(HAND.potentiometer_voltage(th)) == pytest.approx(th)
    with pytest.raises(DataError, match="beyond the ±20° knuckle range"):
        HAND.knuckle_angle(5.0)
    assert HAND.knuckle_angle_for_object(0.010) == pytest.approx(-math.radians(20), abs=1e-9)
    assert abs(HAND.knuckle_angle_for_object(0.150)) <= math.radians(20)
    with pytest.raises(ModelError, match="outside ±20"):
        HAND.knuckle_angle_for_object(0.400)
    assert check(HAND).ok


def _equator(angles_deg, R=0.03):
    a = np.radians(angles_deg)
    p = np.column_stack([R * np.cos(a), R * np.sin(a), np.zeros_like(a)])
    return p, -p / R


def test_force_closure_classics():
    """Point contacts with friction: three contacts 120° apart on a sphere's equator are force
    closure for any μ > 0 but not for μ = 0; two antipodal contacts never (no torque about their
    axis); three contacts bunched within 60° need a large μ (here 0.3 fails, 3.0 succeeds)."""
    p, n = _equator([0, 120, 240])
    for mu in (0.05, 0.3, 1.0):
        assert force_closure(p, n, mu).closure
    assert not force_closure(p, n, 0.0).closure
    p2, n2 = _equator([0, 180])
    for mu in (0.3, 1.0, 5.0):
        fc = force_closure(p2, n2, mu)
        assert not fc.closure and fc.rank < 6
    p3, n3 = _equator([0, 30, 60])
    assert not force_closure(p3, n3, 0.3).closure
    assert force_closure(p3, n3, 3.0).closure


def test_closure_quality_grows_with_friction():
    p, n = _equator([0, 120, 240])
    eps = [force_closure(p, n, mu).epsilon for mu in (0.1, 0.3, 0.6, 1.0)]
    assert all(b > a for a, b in zip(eps, eps[1:]))


def test_hand_precision_grasp_is_force_closure():
    P = HAND.finger.pressures_for(0.0, 0.005)
    assert HAND.force_closure(math.radians(5), P, 0.5).closure
    with pytest.raises(DataError, match="friction"):
        force_closure(*_equator([0, 120, 240]), -0.1)
