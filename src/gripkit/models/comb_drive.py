"""Lateral electrostatic comb-drive actuator: force quadratic in voltage, independent of travel.

Seed ``003_abd62b560633beaf.txt`` eq 5 (FT-G100 actuator). The extracted text reads
``Fx = N_a.H.h / 2.g. Vin^2`` where the PDF's Symbol-font ε was extracted as ``H`` (the same
glyph appears as ``İ =8.85pF/m`` a few lines later), so the equation is

    F_x = N_a ε h V² / (2 g)                                         (eq 5)

with N_a electrode pairs, ε the permittivity of the gap (air, 8.85 pF/m), h the finger thickness
and g the gap between neighbouring fingers. (Each pair has two lateral capacitors of area h·x over
the gap g; the co-energy ½ N_a·2εh x V²/g differentiated in the travel x gives eq 5: the force
does not depend on the engagement x, which is why lateral comb drives give long linear strokes.)

Around an operating voltage V₀ the small-signal gain is the derivative of eq 5,

    ∂F_x/∂V |_{V₀} = N_a ε h V₀ / g                                  (eqs 8-9: "N_a.H.t.Vin0/g")

(eq 8 writes the thickness as ``t``; it is the h of eq 5). For the FT-G100 (N_a = 1300,
g = 6 µm, h = 50 µm) the force coefficient is c = N_a ε h/(2g) = 47.9 nN/V², i.e. 235 µN at
70 V and 6.71 µN/V of small-signal gain there.
"""

from __future__ import annotations

import numpy as np

from .beams import _pos

__all__ = ["comb_drive_coefficient", "comb_drive_force", "comb_drive_gain", "comb_drive_voltage"]


def comb_drive_coefficient(n_pairs: float, eps: float, thickness: float, gap: float) -> float:
    """Force per volt squared, c = N ε h / (2 g) [N/V²] (eq 5).

    Parameters: ``n_pairs`` electrode pairs (1), ``eps`` permittivity (F/m), ``thickness`` h (m),
    ``gap`` g (m).
    """
    n = _pos("n_pairs", n_pairs)
    return n * _pos("eps", eps) * _pos("thickness", thickness) / (2.0 * _pos("gap", gap))


def comb_drive_force(voltage, n_pairs: float, eps: float, thickness: float, gap: float):
    """Lateral comb-drive force F_x = N ε h V² / (2 g) [N] (eq 5); ``voltage`` in V (array ok)."""
    return comb_drive_coefficient(n_pairs, eps, thickness, gap) * np.square(voltage)


def comb_drive_gain(v0: float, n_pairs: float, eps: float, thickness: float, gap: float) -> float:
    """Small-signal gain ∂F_x/∂V at V₀: N ε h V₀ / g [N/V] (the numerator of eqs 8-9)."""
    return 2.0 * comb_drive_coefficient(n_pairs, eps, thickness, gap) * float(v0)


def comb_drive_voltage(force, coefficient: float, v_max: float = np.inf):
    """Voltage that produces ``force`` (N): V = √(F/c), clipped to [0, v_max] (square-law inversion
    used by force-commanding controllers; a negative force request gives 0 V: comb drives only
    pull)."""
    c = _pos("coefficient", coefficient)
    return np.clip(np.sqrt(np.clip(np.asarray(force, dtype=np.float64), 0.0, None) / c), 0.0, v_max)
