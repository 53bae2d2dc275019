"""Clamped-clamped beam suspensions: linear stiffness (eqs 4, 13) and stretching stiffening.

Seed ``003_abd62b560633beaf.txt``: the FT-G100 actuator and force sensor are each held by two
pairs of clamped-clamped beams loaded at mid-span; "by applying the Bernoulli's principle"

    K = 32 E h w³ / L³                                               (eqs 4, 13)

(E Young's modulus, h thickness, w width in the bending direction, L length). One clamped-clamped
beam with a central point load has k = 192 E I / L³ = 16 E h w³ / L³ (I = h w³/12); eq 4's 32 is
two such beams in parallel. With E = 190 GPa, h = 50 µm, w = 8 µm: L₁ = 1830 µm gives
K_sa = 25.40 N/m (seed: 25.4 N/m); L₂ = 870 µm gives K_sb = 236.37 N/m (seed: 235.36 N/m,
0.43 % lower: the printed L₂ = 870 µm is rounded; 871.2 µm gives the printed value).

Large deflection. §III-A notes that the actuated arm's resonance rises with voltage (Fig. 5)
because clamped-clamped beams stiffen at large deflection (ref [7]): a beam whose ends cannot move
axially must stretch to deflect. A one-term Galerkin estimate with the first-mode shape
y(s) = x (1 − cos 2πs/L)/2 gives the stretch ΔL = ½∫y'² ds = π² x² / (4L) and the axial energy
U = (E h w / 2L) ΔL² = π⁴ E h w x⁴ / (32 L³), hence a cubic force term π⁴ E h w x³ / (8 L³) per
beam. Relative to the bending stiffness 16 E h w³/L³ of the same beam,

    F(x) = K x (1 + β (x/w)²),   β = π⁴/128 ≈ 0.761,   K₃ = K β / w²   [N/m³]

independently of the number of beams. This is an upper bound (rigid anchors); compliant anchors or
folded beams stiffen less. The tangent stiffness K (1 + 3β (x/w)²) sets the small-signal resonance.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError

__all__ = ["clamped_clamped_stiffness", "stretching_ratio", "cubic_stiffness", "suspension_force",
           "tangent_stiffness", "STRETCHING_BETA"]

#: Galerkin estimate of the stretching stiffening of a clamped-clamped beam, F = K x (1 + β (x/w)²).
STRETCHING_BETA = math.pi ** 4 / 128.0


def _pos(name: str, v: float) -> float:
    v = float(v)
    if not math.isfinite(v) or v <= 0:
        raise ParameterError(f"{name}: expected a positive finite number (SI), found {v!r}")
    return v


def clamped_clamped_stiffness(E: float, thickness: float, width: float, length: float) -> float:
    """Two pairs of clamped-clamped beams under a mid-span load: K = 32 E h w³ / L³ [N/m] (eqs 4,
    13).

    ``E`` in Pa, ``thickness`` h, ``width`` w and ``length`` L in m.
    """
    return 32.0 * _pos("E", E) * _pos("thickness", thickness) * _pos("width", width) ** 3 \
        / _pos("length", length) ** 3


def stretching_ratio(width: float, beta: float = STRETCHING_BETA) -> float:
    """K₃/K = β / w² [1/m²]: the cubic coefficient relative to the linear stiffness."""
    return float(beta) / _pos("width", width) ** 2


def cubic_stiffness(E: float, thickness: float, width: float, length: float,
                    beta: float = STRETCHING_BETA) -> float:
    """Cubic (stretching) coefficient K₃ = K β / w² [N/m³] of the suspension of eqs 4/13."""
    return clamped_clamped_stiffness(E, thickness, width, length) * stretching_ratio(width, beta)


def suspension_force(x, k1: float, k3: float = 0.0):
    """Restoring force K x + K₃ x³ [N] for deflection ``x`` (m)."""
    x = np.asarray(x, dtype=np.float64)
    return k1 * x + k3 * x ** 3


def tangent_stiffness(x, k1: float, k3: float = 0.0):
    """dF/dx = K + 3 K₃ x² [N/m]."""
    x = np.asarray(x, dtype=np.float64)
    return k1 + 3.0 * k3 * x ** 2
