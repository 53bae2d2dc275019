"""A mass-spring-damper driven by a force, discretised exactly (zero-order hold).

    m ẍ + b ẋ + k x = F(t)        (x in m, F in N)

The TSFM force sensor (``001_0b92a7da96e7aa46.txt`` eq 8) and the FT-G100 arms
(``003_abd62b560633beaf.txt`` eqs 2 and 11) are of this form. With F held constant over a step h,
the state z = [x, ẋ] advances exactly as z⁺ = e^{Ah} z + A⁻¹(e^{Ah} − I) B F with
A = [[0, 1], [−k/m, −b/m]], B = [0, 1/m]. For a 2×2 matrix with trace 2μ and determinant Δ,

    e^{Ah} = e^{μh} [ c I + s (A − μ I) ],   δ = μ² − Δ,
    c = cosh(√δ h), s = sinh(√δ h)/√δ  (δ > 0);  c = cos(√−δ h), s = sin(√−δ h)/√−δ  (δ < 0);
    c = 1, s = h  (δ = 0),

which :func:`msd_zoh` evaluates in scalar code, so the kernel stays exact for any step —
including the 8.52 kHz, ζ = 0.006 sensor sampled at 20 kHz.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba import prange

from ..params import Parameter, ParameterSet
from ..sim.model import Model, Signal

__all__ = ["MassSpringDamper", "msd_zoh", "msd_parameters"]


@numba.njit(cache=True)
def msd_zoh(m, b, k, h, out):  # pragma: no cover - compiled
    """Exact ZOH matrices of m ẍ + b ẋ + k x = F: out = [a11, a12, a21, a22, b1, b2]."""
    a21 = -k / m
    a22 = -b / m
    mu = 0.5 * a22
    delta = mu * mu + a21  # mu^2 - det(A), det(A) = k/m = -a21
    if delta > 1e-300:
        r = math.sqrt(delta)
        c = math.cosh(r * h)
        s = math.sinh(r * h) / r
    elif delta < -1e-300:
        r = math.sqrt(-delta)
        c = math.cos(r * h)
        s = math.sin(r * h) / r
    else:
        c = 1.0
        s = h
    e = math.exp(mu * h)
    E11 = e * (c - mu * s)
    E12 = e * s
    E21 = e * s * a21
    E22 = e * (c + (a22 - mu) * s)
    out[0] = E11
    out[1] = E12
    out[2] = E21
    out[3] = E22
    # B_d = A^{-1}(E - I) B with B = [0, 1/m];  A^{-1} = [[a22, -1], [-a21, 0]] / det, det = -a21
    if k > 0.0:
        det = -a21
        g1 = E12 / m
        g2 = (E22 - 1.0) / m
        out[4] = (a22 * g1 - g2) / det
        out[5] = (-a21 * g1) / det
    elif a22 != 0.0:  # no spring, damped: v' = a22 v + F/m
        ev = (math.exp(a22 * h) - 1.0) / a22
        out[4] = (ev - h) / a22 / m
        out[5] = ev / m
    else:  # free mass
        out[4] = 0.5 * h * h / m
        out[5] = h / m


@numba.njit(cache=True, parallel=True)
def _msd_batch(thetas, u, dt, substeps, x0, y):  # pragma: no cover - compiled
    P = thetas.shape[0]
    N = u.shape[0]
    for p in prange(P):
        mat = np.empty(6)
        msd_zoh(thetas[p, 0], thetas[p, 1], thetas[p, 2], dt, mat)
        x = x0[p, 0]
        v = x0[p, 1]
        for n in range(N):
            y[p, n, 0] = x
            f = u[n, 0]
            xn = mat[0] * x + mat[1] * v + mat[4] * f
            v = mat[2] * x + mat[3] * v + mat[5] * f
            x = xn


def msd_parameters(m: float, b: float, k: float, *, source: str = "",
                   name: str = "msd") -> ParameterSet:
    """A ParameterSet (m [kg], b [N·s/m], k [N/m]) with positivity bounds."""
    return ParameterSet([
        Parameter("m", m, "kg", "moving mass", bounds=(1e-15, None), source=source),
        Parameter("b", b, "N*s/m", "viscous damping", bounds=(0.0, None), source=source),
        Parameter("k", k, "N/m", "stiffness", bounds=(0.0, None), source=source),
    ], name)


class MassSpringDamper(Model):
    """m ẍ + b ẋ + k x = F; input F (N), output x (m); exact ZOH discretisation."""

    name = "mass-spring-damper"
    description = "m x'' + b x' + k x = F"
    inputs = (Signal("F", "N", "applied force"),)
    outputs = (Signal("x", "m", "position"),)
    states = (Signal("x", "m", "position"), Signal("v", "m/s", "velocity"))
    integrator = "zoh"

    def __init__(self, parameters: ParameterSet | None = None, *, m: float = 1.0, b: float = 0.1,
                 k: float = 1.0, check: bool = True):
        super().__init__(parameters if parameters is not None else msd_parameters(m, b, k),
                         check=check)

    def _simulate_batch(self, thetas, u, dt, substeps, x0, y):
        _msd_batch(thetas, u, dt, substeps, x0, y)

    def modes(self, theta):
        m, b, k = theta[:3]
        if k <= 0:
            return []
        wn = math.sqrt(k / m)
        return [(wn, b / (2.0 * math.sqrt(k * m)))]

    def natural_frequency_hz(self) -> float:
        return math.sqrt(self.parameters.value("k") / self.parameters.value("m")) / (2 * math.pi)

    def damping_ratio(self) -> float:
        p = self.parameters
        return p.value("b") / (2 * math.sqrt(p.value("k") * p.value("m")))

    def discrete_matrices(self, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """(A_d (2, 2), B_d (2, 1)) at step ``dt``."""
        out = np.empty(6)
        p = self.parameters
        msd_zoh(p.value("m"), p.value("b"), p.value("k"), float(dt), out)
        return out[:4].reshape(2, 2), out[4:].reshape(2, 1)
