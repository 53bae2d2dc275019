"""Friction models (gripkit.models.friction): Coulomb/viscous and Stribeck (eqs 6.2, 6.3, 6.5 of
``002_ddea254371185ad3.txt``), lookup tables, LuGre's steady state and exact bristle update, and
Karnopp stick-slip in the friction-loaded inertia."""

import math

import numpy as np
import pytest

from gripkit.errors import DataError, ModelError
from gripkit.models.friction import (FrictionDrive, FrictionTable, Stribeck, coulomb_viscous,
                                     lugre_force, lugre_g, lugre_update, stribeck)


def test_table_lookup_rules():
    t = FrictionTable([-2.0, -1.0, 1.0, 2.0, 3.0], [-0.5, -0.2, 0.3, 0.4, 0.6])
    assert t(0.0) == 0.0
    assert t(0.5) == pytest.approx(0.3)  # held below the smallest breakpoint
    assert t(-0.01) == pytest.approx(-0.2)
    assert t(1.5) == pytest.approx(0.35)  # linear interpolation
    assert t(4.0) == pytest.approx(0.8)  # last segment extended
    assert t(-3.0) == pytest.approx(-0.8)
    assert t.scaled(2.0)(1.5) == pytest.approx(0.7)
    with pytest.raises(DataError, match="increase strictly"):
        FrictionTable([-1.0, -2.0, 1.0, 2.0], [0, 0, 0, 0])
    with pytest.raises(DataError, match="each sign"):
        FrictionTable([1.0, 2.0, 3.0, 4.0], [0, 0, 0, 0])


def test_stribeck_eq_6_5():
    s = Stribeck(fc=0.2, fs=0.36, vs=0.1, delta=2.0, sigma=0.05)
    v = np.array([-1.0, -0.1, 0.0, 0.05, 0.1, 1.0])
    expected = np.sign(v) * (0.2 + 0.16 * np.exp(-np.abs(v / 0.1) ** 2)) + 0.05 * v
    np.testing.assert_allclose(s(v), expected)
    assert s(1e-9) == pytest.approx(0.36)  # stiction level at v → 0+
    rising = Stribeck(fc=0.2, fs=0.36, vs=0.1, delta=-1.0)  # negative shape factor, Fig. 6.2(b)
    assert rising(0.01) < rising(1.0)
    for v in (-0.7, 0.02, 3.0):  # the compiled kernel is the same curve
        assert stribeck(v, 0.2, 0.36, 0.1, 2.0, 0.05) == pytest.approx(float(s(v)), rel=1e-14)
    with pytest.raises(ModelError, match="vs > 0"):
        Stribeck(fc=0.2, fs=0.36, vs=0.0)


def test_coulomb_viscous_kernel_is_stribeck_without_stiction_peak():
    for v in (-2.0, -0.01, 0.0, 0.3, 4.0):
        assert coulomb_viscous(v, 0.2, 0.05) == pytest.approx(stribeck(v, 0.2, 0.2, 0.1, 2.0, 0.05))


@pytest.mark.parametrize("v", [-2.0, -0.05, 0.01, 0.3, 5.0])
def test_lugre_steady_state_is_the_stribeck_curve(v):
    """At constant velocity the bristle state settles at z = sign(v) g(v)/σ₀ (ż = 0), so the
    LuGre force is sign(v) g(v) + σ₂ v: Stribeck's curve with δ = 2 (Canudas de Wit 1995)."""
    fc, fs, vs, s0, s1, s2 = 0.2, 0.36, 0.1, 360.0, 2.8, 0.02
    z = lugre_update(0.0, v, 1e3, fc, fs, vs, s0)  # σ₀|v|h/g ≥ 1e5: fully settled
    assert z == pytest.approx(math.copysign(lugre_g(v, fc, fs, vs) / s0, v), rel=1e-12)
    assert lugre_force(z, v, fc, fs, vs, s0, s1, s2) == pytest.approx(
        float(Stribeck(fc, fs, vs, 2.0, s2)(v)), rel=1e-12)


def test_lugre_update_is_exact_for_a_held_velocity():
    """z after one step h equals z after ten steps h/10 (exponential solution, not Euler), and
    equals zss + (z₀ − zss)·exp(−σ₀|v|h/g(v))."""
    fc, fs, vs, s0, v, h = 0.2, 0.36, 0.1, 360.0, 0.04, 2e-3
    one = lugre_update(-1e-3, v, h, fc, fs, vs, s0)
    z = -1e-3
    for _ in range(10):
        z = lugre_update(z, v, h / 10, fc, fs, vs, s0)
    assert one == pytest.approx(z, rel=1e-12)
    g = lugre_g(v, fc, fs, vs)
    assert one == pytest.approx(g / s0 + (-1e-3 - g / s0) * math.exp(-s0 * v * h / g), rel=1e-12)


def test_karnopp_rests_exactly_below_stiction_and_lugre_does_not():
    """Karnopp: a constant torque below F_s leaves the inertia exactly at rest for 10 s; above it,
    it slides. LuGre with the same F_c, F_s moves under the same sub-stiction torque (pre-sliding
    displacement, then it settles) — why the finger's default model is the state machine."""
    tau = 0.34  # N·m, below F_s = 0.36
    u = np.full(10000, tau)
    kar = FrictionDrive(kind="karnopp").simulate(u, dt=1e-3)
    assert np.all(kar["position"] == 0.0) and np.all(kar["velocity"] == 0.0)
    assert np.allclose(kar["friction"], tau)
    moving = FrictionDrive(kind="karnopp").simulate(np.full(2000, 0.37), dt=1e-3)
    assert moving["position"][-1] > 0.1
    lug = FrictionDrive(kind="lugre").simulate(u, dt=1e-3)
    assert lug["position"][-1] > 1e-3  # rad: it moved although τ < F_s
    assert abs(lug["velocity"][-1]) < 1e-6  # and settled


def test_stick_slip_velocity_reversal():
    """A sinusoidal torque of amplitude 0.5 N·m > F_s at 1 Hz: the inertia stops at each velocity
    reversal and stays stuck until |τ| exceeds F_s again (two stick episodes per period), and
    while stuck the friction equals the applied torque exactly."""
    t = np.arange(4000) * 1e-3
    tau = 0.5 * np.sin(2 * np.pi * 1.0 * t)
    tr = FrictionDrive(kind="karnopp").simulate(tau, dt=1e-3)
    stuck = tr["velocity"] == 0
    episodes = np.count_nonzero(stuck[1:] & ~stuck[:-1])
    assert episodes >= 7
    held = np.flatnonzero(stuck[:-1] & stuck[1:])  # at rest at t_n and still at t_n+1
    assert np.all(np.abs(tau[held]) <= 0.36)
    np.testing.assert_allclose(tr["friction"][held], tau[held])


def test_friction_drive_refuses_an_unknown_kind():
    with pytest.raises(ModelError, match="kind: expected 'karnopp' or 'lugre'"):
        FrictionDrive(kind="dahl")


def test_harmonic_drive_ripple_kernel():
    """ΔF = A·sin(k·θ + φ)·sign(v) (§3.2.2): odd in v, zero at rest or with A = 0, period 2π/k."""
    from gripkit.models.friction import ripple

    A, k, phi = 0.03, 200.0, 0.4
    for th in (0.0, 0.0123, 1.7):
        assert ripple(th, 0.5, A, k, phi) == pytest.approx(A * math.sin(k * th + phi), rel=1e-14)
        assert ripple(th, -0.5, A, k, phi) == -ripple(th, 0.5, A, k, phi)
        assert ripple(th + 2 * math.pi / k, 0.5, A, k, phi) == pytest.approx(
            ripple(th, 0.5, A, k, phi), abs=1e-12)
    assert ripple(1.0, 0.0, A, k, phi) == 0.0 and ripple(1.0, 0.5, 0.0, k, phi) == 0.0
