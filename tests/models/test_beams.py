"""Clamped-clamped beam suspensions (gripkit.models.beams): the linear stiffness of eqs 4/13 of
``003_abd62b560633beaf.txt`` is two beams of 192 E I / L³ each (Euler-Bernoulli, central point
load, I = h w³/12); the stretching term is the one-term Galerkin estimate β = π⁴/128."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from gripkit.errors import ParameterError
from gripkit.models.beams import (STRETCHING_BETA, clamped_clamped_stiffness, cubic_stiffness,
                                  stretching_ratio, suspension_force, tangent_stiffness)

# a generic silicon flexure (no seed): E = 170 GPa, h = 20 µm, w = 5 µm, L = 500 µm
E, H, W, L = 170e9, 20e-6, 5e-6, 500e-6


def test_stiffness_is_two_central_loaded_clamped_clamped_beams():
    """K = 2 · 192 E I / L³ with I = h w³/12 (Roark, clamped-clamped beam, central load), i.e.
    32 E h w³/L³ = 108.8 N/m for these numbers; K scales with w³ and 1/L³."""
    K = clamped_clamped_stiffness(E, H, W, L)
    assert K == pytest.approx(2 * 192 * E * (H * W ** 3 / 12) / L ** 3, rel=1e-12)
    assert K == pytest.approx(108.8, rel=1e-12)
    assert clamped_clamped_stiffness(E, H, 2 * W, L) == pytest.approx(8 * K, rel=1e-12)
    assert clamped_clamped_stiffness(E, H, W, 2 * L) == pytest.approx(K / 8, rel=1e-12)


def test_stretching_coefficient_galerkin():
    """β = π⁴/128: axial energy (E h w/2L)(½∫y'²)² of y = x(1 - cos 2πs/L)/2, differentiated twice
    in x and set against the bending stiffness 16 E h w³/L³ of the same beam (quadrature)."""
    E, h, w, L = 190e9, 50e-6, 8e-6, 1830e-6
    # per x²
    stretch = quad(lambda s: (math.pi / L * math.sin(2 * math.pi * s / L)) ** 2, 0, L)[0] / 2
    k3_one_beam = 4 * (E * h * w / (2 * L)) * stretch ** 2  # d/dx of U = (EA/2L) stretch² x⁴
    ratio = k3_one_beam / (16 * E * h * w ** 3 / L ** 3) * w ** 2
    assert ratio == pytest.approx(STRETCHING_BETA, rel=1e-9)
    K = clamped_clamped_stiffness(E, h, w, L)
    k3 = cubic_stiffness(E, h, w, L)
    x = np.array([0.0, 2e-6, w])
    r2 = STRETCHING_BETA * (x / w) ** 2
    np.testing.assert_allclose(suspension_force(x, K, k3), K * x * (1 + r2))
    np.testing.assert_allclose(tangent_stiffness(x, K, k3), K * (1 + 3 * r2))


def test_tangent_stiffness_is_the_derivative_of_the_force():
    """dF/dx by central differences equals K + 3 K₃ x² (to 1e-7 relative)."""
    K = clamped_clamped_stiffness(E, H, W, L)
    k3 = K * stretching_ratio(W)
    assert k3 == pytest.approx(cubic_stiffness(E, H, W, L), rel=1e-12)
    x = np.linspace(-2 * W, 2 * W, 9)
    d = 1e-10
    fd = (suspension_force(x + d, K, k3) - suspension_force(x - d, K, k3)) / (2 * d)
    np.testing.assert_allclose(fd, tangent_stiffness(x, K, k3), rtol=1e-6)


@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan, math.inf])
def test_non_positive_geometry_is_refused(bad):
    with pytest.raises(ParameterError, match="length: expected a positive finite number"):
        clamped_clamped_stiffness(E, H, W, bad)
