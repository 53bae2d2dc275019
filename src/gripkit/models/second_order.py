"""Second-order linear systems with an input gain and operating-point offsets, simulated exactly.

    m ÿ + c ẏ + k y = g (u − u₀),    output y₀ + y                     (SI, any units)

covers the standard form  G(s) = K ω_n² / (s² + 2ζω_n s + ω_n²)  (m = 1, c = 2ζω_n, k = ω_n²,
g = K ω_n²) used by the step-response identification (:mod:`gripkit.sysid.physical.step_response`)
and the
FT-G100 subsystems (eqs 9, 15 of ``003_abd62b560633beaf.txt``). The response is linear in g, so
each parameter vector runs the exact zero-order-hold mass-spring-damper kernel
(:func:`gripkit.models.mass_spring_damper.msd_zoh`) on the unit-gain input and is scaled afterwards.
"""

from __future__ import annotations

import math

import numpy as np

from ..params import Parameter, ParameterSet
from ..sim.model import Model, Signal
from ..units import ratio_unit
from .mass_spring_damper import _msd_batch

__all__ = ["second_order_batch", "SecondOrderSystem", "second_order_step"]


def second_order_batch(coef: np.ndarray, u: np.ndarray, dt: float, x0: np.ndarray,
                       y: np.ndarray) -> None:
    """Simulate P systems: ``coef`` (P, 6) rows [m, c, k, g, u₀, y₀]; ``u`` (N, ≥1) (first column
    used); ``x0`` (P, 2) initial [y, ẏ] (without y₀); writes ``y`` (P, N, 1)."""
    gains = coef[:, 3]
    groups: dict[float, list[int]] = {}
    for p, v in enumerate(coef[:, 4]):
        groups.setdefault(float(v), []).append(p)
    safe = np.where(gains != 0.0, gains, 1.0)
    for v, idx in groups.items():
        idx = np.asarray(idx)
        out = np.empty((len(idx), u.shape[0], 1))
        _msd_batch(np.ascontiguousarray(coef[idx, :3]), np.ascontiguousarray(u[:, :1] - v), dt, 1,
                   np.ascontiguousarray(x0[idx] / safe[idx, None]), out)
        y[idx, :, 0] = out[:, :, 0] * gains[idx, None] + coef[idx, 5, None]


def second_order_step(t, gain: float, wn: float, zeta: float) -> np.ndarray:
    """Unit-step response of K ω_n²/(s² + 2ζω_n s + ω_n²) at times ``t`` ≥ 0 (closed form for
    under-, critically and over-damped cases)."""
    t = np.asarray(t, dtype=np.float64)
    if zeta < 1.0 - 1e-9:
        wd = wn * math.sqrt(1.0 - zeta * zeta)
        r = 1.0 - np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta * wn / wd * np.sin(wd * t))
    elif zeta <= 1.0 + 1e-9:
        r = 1.0 - np.exp(-wn * t) * (1.0 + wn * t)
    else:
        q = math.sqrt(zeta * zeta - 1.0)
        p1, p2 = wn * (zeta - q), wn * (zeta + q)  # decay rates, p1 < p2
        r = 1.0 - (p2 * np.exp(-p1 * t) - p1 * np.exp(-p2 * t)) / (p2 - p1)
    return gain * np.where(t >= 0, r, 0.0)


class SecondOrderSystem(Model):
    """y = y₀ + K ω_n²/(s² + 2ζω_n s + ω_n²) (u − u₀), exact ZOH simulation.

    Parameters: ``gain`` K (output unit per input unit), ``wn`` ω_n (rad/s), ``zeta`` ζ,
    ``y0`` output offset, ``u0`` input operating point (fixed by default).
    """

    name = "second-order"
    description = "standard second-order system K wn^2/(s^2 + 2 zeta wn s + wn^2) with offsets"
    integrator = "zoh"
    states = (Signal("y", "1", "output deviation"), Signal("ydot", "1/s", "its rate"))

    def __init__(self, parameters: ParameterSet | None = None, *, gain: float = 1.0,
                 wn: float = 1.0,
                 zeta: float = 0.5, y0: float = 0.0, u0: float = 0.0, input_unit: str = "1",
                 output_unit: str = "1", input_name: str = "u", output_name: str = "y",
                 check: bool = True):
        gunit = ratio_unit(output_unit, input_unit)
        if parameters is None:
            parameters = ParameterSet([
                Parameter("gain", gain, gunit, "static gain K"),
                Parameter("wn", wn, "rad/s", "natural frequency ω_n", (1e-12, None)),
                Parameter("zeta", zeta, "1", "damping ratio ζ", (1e-9, None)),
                Parameter("y0", y0, output_unit, "output at the operating point"),
                Parameter("u0", u0, input_unit, "input at the operating point", fixed=True),
            ], "second-order")
        self.inputs = (Signal(input_name, input_unit, "input"),)
        self.outputs = (Signal(output_name, output_unit, "output"),)
        super().__init__(parameters, check=check)

    @staticmethod
    def coefficients(thetas: np.ndarray) -> np.ndarray:
        K, wn, z, y0, u0 = np.atleast_2d(thetas).T
        return np.column_stack([np.ones_like(wn), 2 * z * wn, wn * wn, K * wn * wn, u0, y0])

    def _simulate_batch(self, thetas, u, dt, substeps, x0, y):
        second_order_batch(self.coefficients(thetas), u, dt, x0, y)

    def modes(self, theta):
        return [(float(theta[1]), float(theta[2]))]
