"""Lateral comb drive (gripkit.models.comb_drive): eq 5 of ``003_abd62b560633beaf.txt``,
F = N ε h V² / (2 g), is the derivative in the engagement x of the co-energy ½ C(x) V² of
C(x) = N ε h x / g (one lateral capacitor of area h·x over the gap g per electrode pair): it
does not depend on x, and its voltage derivative is N ε h V / g (eqs 8-9)."""

import numpy as np
import pytest

from gripkit.errors import ParameterError
from gripkit.models.comb_drive import (comb_drive_coefficient, comb_drive_force, comb_drive_gain,
                                       comb_drive_voltage)

# a generic comb (no seed): 200 pairs, air (8.854 pF/m), 25 µm thick fingers, 3 µm gaps
N, EPS, H, G = 200, 8.854e-12, 25e-6, 3e-6


def test_force_is_the_co_energy_derivative():
    """F = d/dx (½ (N ε h x / g) V²) by central differences in x at two engagements (the force
    is the same: it does not depend on x), at 10, 40 and 100 V."""
    V = np.array([10.0, 40.0, 100.0])
    F = comb_drive_force(V, N, EPS, H, G)

    def coenergy(x):
        return 0.5 * (N * EPS * H * x / G) * V ** 2

    for x in (5e-6, 20e-6):
        fd = (coenergy(x + 1e-9) - coenergy(x - 1e-9)) / 2e-9
        np.testing.assert_allclose(F, fd, rtol=1e-6)
    np.testing.assert_allclose(F, N * EPS * H * V ** 2 / (2 * G), rtol=1e-12)
    assert comb_drive_coefficient(N, EPS, H, G) == pytest.approx(7.378e-9, rel=1e-3)


def test_small_signal_gain_and_square_law_inversion():
    """∂F/∂V at V₀ is N ε h V₀ / g; V = √(F/c) inverts eq 5, clipped to [0, v_max]."""
    c = comb_drive_coefficient(N, EPS, H, G)
    assert comb_drive_gain(50.0, N, EPS, H, G) == pytest.approx(N * EPS * H * 50.0 / G, rel=1e-12)
    f = np.array([0.0, 1e-6, 5e-5])
    back = comb_drive_force(comb_drive_voltage(f, c), N, EPS, H, G)
    np.testing.assert_allclose(back, f, rtol=1e-12)
    np.testing.assert_array_equal(comb_drive_voltage([-1e-6, 1.0], c, v_max=80.0), [0.0, 80.0])


def test_a_zero_gap_is_refused():
    with pytest.raises(ParameterError, match="gap: expected a positive finite number"):
        comb_drive_force(10.0, N, EPS, H, 0.0)
