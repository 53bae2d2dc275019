"""The generic components with reference values (gripkit.models.reference, the zoo's ``generic``
entries): each value is the one its source gives, and the built models show it — Table II of
``001_0b92a7da96e7aa46.txt`` (left finger) for Bouc-Wen and the piezo actuator, the illustrative
ζ = 0.05 oscillator for the mass-spring-damper."""

import numpy as np
import pytest

from gripkit.models import (reference_bouc_wen, reference_mass_spring_damper,
                            reference_piezo_actuator)
from gripkit.models.reference import SOURCES, TABLE_II_LEFT


def test_bouc_wen_has_table_ii_values_and_its_saturation():
    """d_p = 0.77 µm/V, λ = 0.43 µm/V, β = 0.108 1/V, γ = 7.5e-3 1/V: |H| → λ/(β+γ) = 3.72 µm,
    each parameter citing Table II."""
    bw = reference_bouc_wen()
    p = bw.parameters
    assert [p.value(k) for k in ("d_p", "lam", "beta", "gamma")] == [0.77e-6, 0.43e-6, 0.108,
                                                                     7.5e-3]
    assert bw.saturation() == pytest.approx(0.43e-6 / 0.1155, rel=1e-12)
    assert round(bw.saturation() * 1e6, 2) == 3.72
    assert all("Table II" in p[k].source for k in p.names)


def test_piezo_actuator_takes_table_ii_and_the_assumed_length():
    """Every Table II value as given (a = 2.5e-8 s², b = 8e-5 s: ω_n = 1/√a = 6325 rad/s,
    ζ = b ω_n/2 = 0.253); L_a = 15 mm is marked as assumed; loads=False leaves U alone."""
    act = reference_piezo_actuator()
    p = act.parameters
    for k, v in TABLE_II_LEFT.items():
        assert p.value(k) == v
    assert p.value("L_a") == 15e-3 and p["L_a"].source == SOURCES["L_a"]
    assert "assumed" in p["L_a"].source
    (wn, zeta), = act.modes(act.theta())
    assert (wn, zeta) == pytest.approx((6324.555, 0.25298), rel=1e-5)
    assert [s.name for s in reference_piezo_actuator(loads=False).inputs] == ["U"]


def test_reference_oscillator_is_lightly_damped():
    """The zoo's generic oscillator: m = 1 kg, k = 1 N/m, b = 0.1 N·s/m, so ζ = 0.05 and
    f_n = 1/(2π) Hz (models.reference, no seed); static deflection F/k under a held force."""
    msd = reference_mass_spring_damper()
    assert msd.damping_ratio() == pytest.approx(0.05, rel=1e-12)
    assert msd.natural_frequency_hz() == pytest.approx(1 / (2 * np.pi), rel=1e-12)
    x = msd.simulate(np.full(6000, 0.3), dt=0.05)["x"]  # 300 s, e^{-ζ ω_n t} = 3e-7
    assert x[-1] == pytest.approx(0.3, rel=1e-5)
