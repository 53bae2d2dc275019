"""FT-G100 physics: comb drive (eq 5), clamped-clamped beams (eqs 4, 13), amplification (eqs 3, 12),
sensing stiffness (eq 16) — the numbers printed in seed 003_abd62b560633beaf.txt (the generic beam
and comb-drive formulas: tests/models/)."""

import pytest

from gripkit.errors import ModelError, ParameterError
from gripkit.models.beams import clamped_clamped_stiffness
from gripkit.models.comb_drive import (comb_drive_coefficient, comb_drive_force, comb_drive_gain,
                                       comb_drive_voltage)
from gripkit.systems.ftg100.model import amplification_ratio, ftg100_geometry

GEO = ftg100_geometry()
g = GEO.value


def test_suspension_stiffness_eqs_4_13():
    """§III-A: E = 190 GPa, h = 50 µm, w = 8 µm, L1 = 1830 µm -> K_sa = 25.4 N/m (eq 4);
    §III-C: L2 = 870 µm -> K_sb = 235.36 N/m (eq 13; 0.43 % above: L2 is rounded)."""
    Ksa = clamped_clamped_stiffness(g("E"), g("h"), g("w"), g("L1"))
    Ksb = clamped_clamped_stiffness(g("E"), g("h"), g("w"), g("L2"))
    assert Ksa == pytest.approx(25.4, rel=1e-3)
    assert Ksb == pytest.approx(235.36, rel=5e-3)
    # one clamped-clamped beam under a central load is 192 E I / L^3 (I = h w^3/12); eq 4 is two
    I = g("h") * g("w") ** 3 / 12
    assert Ksa == pytest.approx(2 * 192 * g("E") * I / g("L1") ** 3, rel=1e-12)


def test_amplification_ratios_eqs_3_12():
    """§III-A/C: H = 5300, l = 300, a = 950, b = 700 µm give D_a = 4.7 and D_b = 6.05 with
    D = (H - l/2)/(arm + l/2); the other sign choices give 4.95/6.41, 6.44/9.36, 6.81/9.91."""
    Da = amplification_ratio(g("H"), g("l"), g("a"))
    Db = amplification_ratio(g("H"), g("l"), g("b"))
    assert Da == pytest.approx(4.7, rel=5e-3)
    assert Db == pytest.approx(6.05, rel=2e-3)
    H, l, a = 5300, 300, 950
    assert abs((H + l / 2) / (a + l / 2) - 4.7) > 0.2 and abs((H - l / 2) / (a - l / 2) - 4.7) > 1
    with pytest.raises(ModelError):
        amplification_ratio(100, 300, 950)


def test_sensing_stiffness_eq_16():
    """§III-C: k2 = K_sb / D_b^2 = 6.45 N/m (from eq 13's K_sb and D_b = 6.05); Fig. 10 measures
    6.48."""
    Ksb = clamped_clamped_stiffness(g("E"), g("h"), g("w"), g("L2"))
    assert Ksb / 6.05 ** 2 == pytest.approx(6.45, rel=2e-3)
    assert 235.36 / 6.05 ** 2 == pytest.approx(6.45, rel=5e-3)
    assert Ksb / 6.05 ** 2 == pytest.approx(g("k2_measured"), rel=5e-3)


def test_comb_drive_eq_5():
    """F_x = N_a eps h V^2/(2 g): 47.94 nN/V^2 for N_a = 1300, eps = 8.85 pF/m, h = 50 µm, g = 6 µm;
    its derivative at 70 V is eq 8's N_a eps h V0/g = 6.711 µN/V."""
    c = comb_drive_coefficient(g("N_a"), g("eps"), g("h"), g("g"))
    assert c == pytest.approx(1300 * 8.85e-12 * 50e-6 / 12e-6, rel=1e-12)
    assert c == pytest.approx(47.94e-9, rel=1e-3)
    assert comb_drive_force(70.0, g("N_a"), g("eps"), g("h"), g("g")) == pytest.approx(c * 4900)
    gain = comb_drive_gain(70.0, g("N_a"), g("eps"), g("h"), g("g"))
    assert gain == pytest.approx(6.711e-6, rel=1e-3)
    # numerical derivative of eq 5
    f = lambda v: comb_drive_force(v, g("N_a"), g("eps"), g("h"), g("g"))  # noqa: E731
    assert (f(70 + 1e-4) - f(70 - 1e-4)) / 2e-4 == pytest.approx(gain, rel=1e-8)
    # square-law inversion, clipped to [0, V_max]
    assert comb_drive_voltage(c * 90.0 ** 2, c, 200.0) == pytest.approx(90.0)
    assert comb_drive_voltage(-1.0, c, 200.0) == 0.0 and comb_drive_voltage(1.0, c, 200.0) == 200.0
    with pytest.raises(ParameterError):
        comb_drive_coefficient(1300, 8.85e-12, 50e-6, 0.0)
