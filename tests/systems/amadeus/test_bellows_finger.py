"""Three-bellows finger: eqs 1-8 (000_8f66dcc7ab06470c.txt §III), deflection and the inverse of
§III-C."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from gripkit.errors import DataError, ModelError
from gripkit.systems.amadeus.bellows_finger import (BAR, PRINCIPAL_DIRECTIONS, TUBE_PUSH_ANGLES,
                                                    BellowsFinger, bending_direction,
                                                    calibrate_bending_stiffness)

F = BellowsFinger()
pressure = st.floats(7.5, 30.0).map(lambda b: b * BAR)


def _angdiff(a, b):
    return abs(math.remainder(a - b, 2 * math.pi))


@given(pressure)
def test_equal_pressures_do_not_bend(p):
    """§III-B: equal pressures give no resultant moment, whatever their magnitude."""
    b = F.bending(np.full(3, p))
    assert b.moment == pytest.approx(0.0, abs=1e-12)
    assert b.deflection == pytest.approx(0.0, abs=1e-15)
    assert b.tip[1] == 0.0 and b.tip[2] == 0.0


@given(pressure, pressure, pressure, st.floats(-5, 5))
def test_eq8_matches_eqs_1_to_4_and_common_mode_invariance(p1, p2, p3, dc):
    """Derived eq 8 equals atan2(M_z, M_y) of eqs 1-2; adding a common pressure changes nothing;
    eqs 5-6 about ψ: cross-plane part 0, in-plane part = M0 (eqs 3, 7); M0 closed form."""
    P = np.array([p1, p2, p3])
    if np.ptp(P) < 1e3:
        return
    my, mz = F.moments(P)
    psi = float(bending_direction(P))
    assert _angdiff(psi, math.atan2(mz, my)) < 1e-9
    assert _angdiff(psi, float(bending_direction(P + dc * BAR))) < 1e-9
    along, across = F.plane_moments(P, psi)
    m0 = math.hypot(my, mz)
    assert across == pytest.approx(0.0, abs=1e-9 * m0)
    assert along == pytest.approx(m0, rel=1e-9)
    c = F.parameters.value("tube_area") * F.radius
    closed = c * math.sqrt(p1 * p1 + p2 * p2 + p3 * p3 - p1 * p2 - p2 * p3 - p3 * p1)
    assert m0 == pytest.approx(closed, rel=1e-9)


def test_single_tube_bends_along_its_push_direction():
    """Eqs 1-2: tube i alone pushes along θ_i = 0°, 240°, 120°; geometry 2h/3 = PCD/2."""
    for i in range(3):
        P = np.full(3, 12 * BAR)
        P[i] = 30 * BAR
        assert _angdiff(float(F.bending(P).direction), TUBE_PUSH_ANGLES[i]) < 1e-12
    a, h = F.triangle
    assert 2 * h / 3 == pytest.approx(0.015) and a == pytest.approx(0.015 * math.sqrt(3))


@given(st.floats(0, 2 * math.pi), st.floats(0.5e-3, 17.2e-3), st.sampled_from(["min", "max"]))
def test_inverse_then_forward_returns_direction(psi, d, variant):
    """§III-C inverse: forward model of the pressures returns the requested direction within 0.1°
    (in fact 1e-9°) and deflection; pressures within 12-30 bar; one tube at the minimum ('min') or
    at the maximum ('max')."""
    P = F.pressures_for(psi, d, variant)
    b = F.bending(P)
    assert math.degrees(_angdiff(float(b.direction), psi)) < 0.1
    assert math.degrees(_angdiff(float(b.direction), psi)) < 1e-9
    assert float(b.deflection) == pytest.approx(d, rel=1e-9)
    assert P.min() >= 12 * BAR - 1e-6 and P.max() <= 30 * BAR + 1e-6
    if variant == "min":
        assert P.min() == pytest.approx(12 * BAR)
    else:
        assert P.max() == pytest.approx(30 * BAR)


def test_lowest_and_highest_total_pressure_variants():
    for psi in PRINCIPAL_DIRECTIONS:
        lo = F.pressures_for(psi, 0.012, "min")
        hi = F.pressures_for(psi, 0.012, "max")
        assert lo.sum() < hi.sum()
        # same differences up to the length change (higher mean pressure -> longer finger, less
        # moment)
        assert np.ptp(hi) < np.ptp(lo)


def test_reach_is_a_hexagon_with_20mm_in_principal_directions():
    """Fig. 2(c): 20 mm maximum deflection, reached in the two-tubes-high principal directions (the
    longest finger, calibrated); one-tube-high directions reach slightly less (shorter finger);
    midway between them the moment reach is cos 30° of it."""
    reach = np.array([F.max_deflection(psi, "max") for psi in PRINCIPAL_DIRECTIONS])
    assert reach.max() == pytest.approx(0.020, rel=1e-9)
    np.testing.assert_allclose(reach[1::2], 0.020, rtol=1e-9)
    assert np.all(reach[0::2] > 0.0195) and np.all(reach[0::2] < 0.020)
    assert F.max_moment(math.radians(30)) == pytest.approx(math.cos(math.radians(30))
                                                           * F.max_moment(0), rel=1e-12)
    assert F.max_deflection(math.radians(30)) < 0.019
    with pytest.raises(ModelError, match="out of reach"):
        F.pressures_for(math.radians(30), 0.0195)
    with pytest.raises(ModelError, match="exceeds the finger's 20 mm"):
        F.pressures_for(0.0, 0.021)
    with pytest.raises(DataError, match="variant"):
        F.pressures_for(0.0, 0.01, "middle")


def test_bending_stiffness_calibration_recovers_truth():
    """Recovery of k_b from noisy synthetic needle measurements (§III-C) within 3 std."""
    rng = np.random.default_rng(2)
    truth = BellowsFinger(F.parameters.replace(bending_stiffness=12.0), check=False)
    P = np.array([truth.pressures_for(psi, d, v) for psi in rng.uniform(0, 2 * np.pi, 12)
                  for d in (0.004, 0.008, 0.012) for v in ("min", "max")])
    d = truth.bending(P).deflection + rng.normal(0, 2e-4, P.shape[0])
    k, sd = calibrate_bending_stiffness(P, d, F)
    assert abs(k - 12.0) < 3 * sd
    assert sd / k < 0.02
    with pytest.raises(DataError, match="unidentifiable"):
        calibrate_bending_stiffness(np.full((3, 3), 20 * BAR), [0.0, 0.0, 0.0])


def test_bad_pressures_raise():
    with pytest.raises(DataError, match="shape"):
        F.bending([1.0, 2.0])
    with pytest.raises(DataError, match="absolute"):
        F.bending([-1.0, 2.0, 3.0])
