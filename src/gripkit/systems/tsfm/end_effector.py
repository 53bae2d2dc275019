"""The sensorized end-effector: a rigid lever plus a mass-spring-damper force sensor
(``001_0b92a7da96e7aa46.txt`` §III-C/D, eqs 1 and 5–10, Fig. 7).

Geometry (Fig. 3, 7): the rigid silicon socket runs from the actuator tip A to B (length L_r),
the piezoresistive sensor from B to C (length L_s, 1 mm in §II); L = L_r + L_s. The lever's tip D
is where C would be if the sensor did not bend. With small angles (eq 6) a point at distance ℓ
from A moves by y_ℓ = y_A + ℓ α_A.

Sensor (eq 8): m_s ÿ_C + b_s (ẏ_C − ẏ_D) + k_s (y_C − y_D) = F_s = −F_g, with F_g the force the
tip C applies on the micropart (positive when gripping). Reaction on the actuator tip (eq 1):
F_A = F_g + m_s ÿ_C, M_A = L F_g (the seed neglects the moment of the sensor's inertia force).
In transfer-function form (eq 10):

    Y_C = (b_s s + k_s)/(m_s s² + b_s s + k_s) · Y_D − 1/(m_s s² + b_s s + k_s) · F_g.

Lever coefficients. Putting eq 1 into eq 4 and eq 4 into y_ℓ = y_A + ℓ α_A gives, for a point at
distance ℓ while the force acts at C (distance L),

    Y_ℓ = [ α_u(ℓ) W − α_f(ℓ, L) s_p F_g − α_m(ℓ) m_s s_p s² Y_C ] D(s),
    α_u = 1 + 2ℓ/L_a,  α_m = 1 + 3ℓ/(2L_a),  α_f = 1 + 3L/(2L_a) + 3ℓ/(2L_a) + 3ℓL/L_a²,

which for ℓ = L is eq 7 (α_f = 1 + 3L/L_a + 3L²/L_a²). Eq 14 (tip B) writes L_r for every L;
that is exact for its W term and its inertia term, and for the force term when the force acts at
B (eq 15's experiment), which is how the seed uses it.

The strain gauges measure the sensor's bending, so the force the sensor reports is
F_m = k_s (y_D − y_C); in statics F_m = F_g, dynamically it also shows the 8.52 kHz ringing (Fig.
8).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import DataError
from ...params import Parameter, ParameterSet
from ...lti import StateSpace

__all__ = ["LeverCoefficients", "lever_coefficients", "sensor_state_space",
           "end_effector_parameters",
           "sensor_parameters"]


@dataclass(frozen=True)
class LeverCoefficients:
    """α_u, α_f, α_m of a point at distance ``ell`` from A with the force at distance ``L``."""

    ell: float
    L: float
    L_a: float
    alpha_u: float
    alpha_f: float
    alpha_m: float


def lever_coefficients(ell: float, L_a: float, L: float | None = None) -> LeverCoefficients:
    """Coefficients of the point at ``ell`` (m) from A for a force at ``L`` (default ``ell``)."""
    L = ell if L is None else L
    return LeverCoefficients(ell, L, L_a, 1.0 + 2.0 * ell / L_a,
                             1.0 + 1.5 * L / L_a + 1.5 * ell / L_a + 3.0 * ell * L / L_a**2,
                             1.0 + 1.5 * ell / L_a)


def sensor_state_space(m_s: float, b_s: float, k_s: float) -> StateSpace:
    """Eq 8 with base motion: inputs [y_D, ẏ_D, F_g], states [y_C, ẏ_C], outputs
    [y_C, F_A (reaction on the lever, eq 1), F_m (measured force k_s (y_D − y_C))]."""
    A = np.array([[0.0, 1.0], [-k_s / m_s, -b_s / m_s]])
    B = np.array([[0.0, 0.0, 0.0], [k_s / m_s, b_s / m_s, -1.0 / m_s]])
    C = np.array([[1.0, 0.0], [-k_s, -b_s], [-k_s, 0.0]])
    D = np.array([[0.0, 0.0, 0.0], [k_s, b_s, 0.0], [k_s, 0.0, 0.0]])
    return StateSpace(A, B, C, D, inputs=("y_D", "v_D", "F_g"), outputs=("y_C", "F_A", "F_m"),
                      input_units=("m", "m/s", "N"), output_units=("m", "N", "N"))


def end_effector_parameters(m_s: float, b_s: float, k_s: float, L_r: float, L_s: float, *,
                            source: str = "", length_source: str = "") -> list[Parameter]:
    """The sensor (m_s, b_s, k_s) and lever (L_r, L_s) parameters, SI."""
    return [
        Parameter("m_s", m_s, "kg", "force-sensor effective mass (eq 8)", bounds=(1e-15, None),
                  source=source,
                  display_unit="mg"),
        Parameter("b_s", b_s, "N*s/m", "force-sensor damping (eq 8)", bounds=(0.0, None),
                  source=source),
        Parameter("k_s", k_s, "N/m", "force-sensor stiffness (eq 8)", bounds=(1e-9, None),
                  source=source),
        Parameter("L_r", L_r, "m", "rigid socket length, actuator tip "
                                   "A to B (Fig. 7)", bounds=(0.0, None),
                  fixed=True, source=length_source or source, display_unit="mm"),
        Parameter("L_s", L_s, "m", "force-sensor length, "
                                   "B to C (Fig. 7)", bounds=(0.0, None), fixed=True,
                  source=length_source or source, display_unit="mm"),
    ]


def sensor_parameters(f0_hz: float, zeta: float, *, k_s: float | None = None,
                      m_s: float | None = None,
                      b_s: float | None = None, f0_std: float = 0.0, zeta_std: float = 0.0,
                      known_std: float = 0.0,
                      source: str = "identified from free vibration") -> ParameterSet:
    """m_s, b_s, k_s of the force sensor (eq 8) from its natural frequency ``f0_hz``, damping ratio
    ``zeta`` and exactly one of them known (with its std ``known_std``), §IV-B:

        k_s = m_s ω₀²,   b_s = 2ζ √(k_s m_s) = 2ζ m_s ω₀,   ω₀ = 2π f0.

    First-order error propagation gives the std of the other two (independent errors assumed)."""
    given = {k: v for k, v in (("k_s", k_s), ("m_s", m_s), ("b_s", b_s)) if v is not None}
    if len(given) != 1:
        raise DataError(f"give exactly one of k_s, m_s, b_s (found {sorted(given) or 'none'})")
    if not (f0_hz > 0 and (zeta > 0 or (zeta == 0 and b_s is None))):
        raise DataError(f"f0 must be positive and ζ positive (or 0 when b_s is not the given one), "
                        f"found f0 = {f0_hz!r} Hz, ζ = {zeta!r}")
    w = 2.0 * math.pi * f0_hz
    rw, rz = f0_std / f0_hz, (zeta_std / zeta if zeta > 0 else 0.0)
    (name, val), = given.items()
    rk = known_std / val
    if name == "k_s":
        k = val
        m = k / w**2
        b = 2.0 * zeta * math.sqrt(k * m)
        sk, sm, sb = known_std, m * math.hypot(rk, 2 * rw), b * math.sqrt(rz**2 + rk**2 + rw**2)
    elif name == "m_s":
        m = val
        k = m * w**2
        b = 2.0 * zeta * m * w
        sm, sk, sb = known_std, k * math.hypot(rk, 2 * rw), b * math.sqrt(rz**2 + rk**2 + rw**2)
    else:
        b = val
        m = b / (2.0 * zeta * w)
        k = m * w**2
        sb, sm, sk = (known_std, m * math.sqrt(rk**2 + rz**2 + rw**2),
                      k * math.sqrt(rk**2 + rz**2 + rw**2))
    src = f"{source} (f0 = {f0_hz:.6g} Hz, ζ = {zeta:.4g}, {name} given)"
    return ParameterSet([
        Parameter("m_s", m, "kg", "force-sensor effective mass (eq 8)", (0.0, None),
                  source=src if name != "m_s" else "given",
                  std=sm, display_unit="mg"),
        Parameter("b_s", b, "N*s/m", "force-sensor damping (eq 8)", (0.0, None),
                  source=src if name != "b_s" else "given",
                  std=sb),
        Parameter("k_s", k, "N/m", "force-sensor stiffness (eq 8)", (0.0, None),
                  source=src if name != "k_s" else "given",
                  std=sk),
    ], "force-sensor")
