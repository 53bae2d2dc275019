"""AMADEUS knuckle drive (000_8f66dcc7ab06470c.txt §II-B: central cylinder OD 22 mm, linkage,
40° of rotation; Fig. 2(c): ±20°; §II-C: potentiometer; §II-D: three-position spring-centred
valve, 30 bar supply). Derivations in gripkit.systems.amadeus.knuckle."""

import math
import warnings

import numpy as np
import pytest

from gripkit.errors import DataError, ParameterError, StabilityWarning
from gripkit.systems.amadeus.knuckle import KnuckleDrive, knuckle_parameters, minimum_dead_band
from gripkit.systems.amadeus.parameters import amadeus_hand

K = KnuckleDrive()
DEG = math.pi / 180


def test_linkage_covers_exactly_plus_minus_20_degrees():
    """θ = −atan(x/e) over the stroke S = 2 e tan 20° = 2·12 mm·0.36397 = 8.7353 mm: the end stops
    are at exactly +20° (retracted) and −20° (extended, closed), 40° in all (§II-B); monotone;
    dθ/dx = −cos²θ/e against central differences; the inverse linkage round-trips."""
    assert K.stroke == pytest.approx(0.0087352856, rel=1e-8)
    half = 0.5 * K.stroke
    assert float(K.angle(-half)) == pytest.approx(20 * DEG, rel=1e-12)
    assert float(K.angle(half)) == pytest.approx(-20 * DEG, rel=1e-12)
    x = np.linspace(-half, half, 201)
    th = K.angle(x)
    assert (np.diff(th) < 0).all()
    h = 1e-7
    num = (K.angle(x[1:-1] + h) - K.angle(x[1:-1] - h)) / (2 * h)
    assert K.transmission(x[1:-1]) == pytest.approx(num, rel=1e-6)
    assert float(K.transmission(0.0)) == pytest.approx(-1 / 0.012, rel=1e-12)
    assert K.position(th) == pytest.approx(x, abs=1e-15)
    with pytest.raises(DataError, match="end stops"):
        K.angle(half * 1.01)
    (f,) = K.consistency_checks()
    assert f.consistent and f.computed == pytest.approx(40.0, rel=1e-12)


def test_cylinder_areas_and_dimensions():
    """Bore 16 mm and rod 8 mm (assumed, inside the seed's 22 mm OD): A_A = π/4·16² = 201.06 mm²,
    A_B = π/4·(16² − 8²) = 150.80 mm²; a bore not inside the OD is refused."""
    a_a, a_b = K.areas
    assert a_a == pytest.approx(201.0619e-6, rel=1e-6)
    assert a_b == pytest.approx(150.7964e-6, rel=1e-6)
    assert K.parameters.value("cylinder_od") == 0.022
    with pytest.raises(ParameterError, match="rod < bore < outside diameter"):
        knuckle_parameters(bore=0.024)


def test_orifice_model_speeds_and_force_balance():
    """Quasi-static orifice flow: the chamber pressures at v_ext(F) balance the load,
    P_A A_A − P_B A_B = F; at zero load and tank 0, v_ret/v_ext = √(A_B/A_A) = 0.8660; the
    unloaded extension crosses the stroke in the assumed 0.5 s (the flow coefficient's
    definition recovered); a load above P_s A_A = 6032 N stalls the extension."""
    a_a, a_b = K.areas
    for load in (0.0, 300.0, -200.0):
        v_ext, v_ret = K.speeds(load)
        pa, pb = K.chamber_pressures(v_ext)
        assert pa * a_a - pb * a_b == pytest.approx(load, abs=1e-6)
        pa, pb = K.chamber_pressures(-v_ret)
        assert pa * a_a - pb * a_b == pytest.approx(load, abs=1e-6)
    v_ext, v_ret = K.speeds(0.0)
    assert v_ret / v_ext == pytest.approx(math.sqrt(a_b / a_a), rel=1e-12)
    assert K.stroke / v_ext == pytest.approx(0.5, rel=1e-12)
    assert K.speeds(30e5 * a_a + 1.0)[0] == 0.0


def test_open_loop_extension_and_off_position_holds():
    """Extend for 40 periods (0.2 s) then off: the spool follows 10 ms late and the piston moves
    exactly v_ext · 0.2 s (3.494 mm) under a 300 N load; with the valve off (closed centre,
    incompressible oil, no leakage) the angle then stays constant to the last bit for 1.3 s."""
    n = 301
    cmd = np.zeros(n, dtype=int)
    cmd[:40] = 1
    r = K.simulate(commands=cmd, duration=1.5, load=300.0)
    v_ext, _ = K.speeds(300.0)
    assert r.stroke[-1] == pytest.approx(v_ext * 0.2, rel=1e-9)
    assert r.spool[1] == 0 and r.spool[2] == 1 and r.spool[42] == 0
    hold = r.angle[45:]
    assert np.ptp(hold) == 0.0
    assert float(hold[0]) == pytest.approx(float(K.angle(v_ext * 0.2)), rel=1e-12)


@pytest.mark.parametrize("target_deg", [-19.9, -10.0, -5.0, 5.0, 12.0, 19.9])
@pytest.mark.parametrize("load", [0.0, 300.0])
def test_bang_bang_reaches_the_dead_band_with_two_switches(target_deg, load):
    """From 0°, the loop ends within the dead band b = 2·(c + q)/2 (c the coast angle
    (v_max/e)(Δt + t_s) = 0.0175/0.012·0.015 rad = 1.25°, q the 12-bit converter's 0.0122°;
    b = 1.263°), with exactly two valve switches (on, off), and holds there (no switch for the
    last second)."""
    b = 2 * minimum_dead_band(K.parameters)
    c = K.speeds(0.0)[0] / 0.012 * 0.015
    q = (5.0 / 4096) / (2.0 / (20 * DEG))
    assert b == pytest.approx(c + q, rel=1e-12)
    assert math.degrees(b) == pytest.approx(1.263, abs=1e-3)
    r = K.simulate(target_deg * DEG, 2.0, load=load)
    assert abs(r.angle[-1] - target_deg * DEG) <= b
    assert r.switches == 2
    assert np.ptp(r.angle[-200:]) == 0.0 and (r.command[-200:] == 0).all()


def test_a_schedule_of_steps_never_chatters():
    """Six set-point changes over 6 s: at most two switches each (12), every plateau ends within
    the dead band."""
    steps = np.repeat(np.deg2rad([15.0, -18.0, -3.0, 8.0, 19.5, -12.0]), 200)
    r = K.simulate(np.append(steps, steps[-1]), 6.0)
    b = 2 * minimum_dead_band(K.parameters)
    assert r.switches <= 12
    ends = np.arange(199, 1200, 200)
    assert (np.abs(r.angle[ends] - r.target[ends]) <= b).all()


def test_a_dead_band_below_the_coast_bound_warns_and_chatters():
    """b = (c + q)/6, a third of the bound: StabilityWarning naming the bound, and the valve
    hunts around the target (more than 20 switches in 1.5 s)."""
    with pytest.warns(StabilityWarning, match="not above the coast bound"):
        r = K.simulate(10 * DEG, 1.5, dead_band=minimum_dead_band(K.parameters) / 3)
    assert r.switches > 20


def test_bad_targets_and_commands_are_refused():
    with pytest.raises(DataError, match="expected within ±20°"):
        K.simulate(25 * DEG, 1.0)
    with pytest.raises(DataError, match="values in"):
        K.simulate(commands=np.full(201, 2), duration=1.0)
    with pytest.raises(DataError, match="either target"):
        K.simulate(duration=1.0)


def test_knuckle_in_the_zoo_entry():
    """The zoo entry carries the knuckle's parameters with units and sources, and its check."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        z = amadeus_hand(check=False)
    p = z.parameters
    assert p.value("knuckle_cylinder_od") == 0.022
    assert "22 mm" in p["knuckle_cylinder_od"].source
    assert "assumed" in p["knuckle_bore"].source
    assert any(f.check == "knuckle-linkage-range" and f.consistent for f in z.consistency_checks())
