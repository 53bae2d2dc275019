"""Rate-independent Bouc-Wen hysteresis of a piezoelectric actuator (``001_0b92a7da96e7aa46.txt``
eq 3).

    y = d_p U − H,        dH/dt = λ dU/dt − β |dU/dt| H − γ dU/dt |H|          (eq 3)

with U the voltage (V), y the displacement (m) and H the hysteresis term (m). H is a length, so
**λ is in m/V** (like d_p) and **β, γ are in 1/V**.

Reading of Table II. The seed prints d_p in µm/V (0.77) and λ without a unit (0.43). λ must have
the unit of d_p (H is subtracted from d_p U), and 0.43 m/V is absurd for a 100 µm actuator, so
gripkit reads λ in the same µm/V column: λ = 0.43 µm/V = 4.3e-7 m/V. β = 10.8e-2 and γ = 7.5e-3
are in 1/V (their product with a voltage is dimensionless). Then the hysteresis saturates at
|H| = λ/(β + γ) = 3.7 µm, 5 % of the 77 µm stroke at 100 V — the size of loop Fig. 9b shows.

Rate independence. Dividing eq 3 by dU/dt (sign s) gives an ODE in the voltage itself,

    dH/dU = λ − β s H − γ |H|,

so H depends on the path of U, not on its speed. With σ the sign of H (σ = s when H = 0) and
v = |U − U₀| the distance travelled, dH/dv = sλ − c H with c = β + s σ γ: linear in H, hence
exactly

    H(v) = H₀ + (sλ − c H₀) · v · φ(c v),     φ(z) = (1 − e^{−z}) / z  (φ(0) = 1),

until H crosses zero, at v₀ = log1p(−s c H₀ / λ) / c (or −s H₀/λ when c = 0), where σ flips and
the formula restarts. :func:`bouc_wen_advance` applies this per sample, so a held (zero-order
hold) voltage step is integrated exactly whatever its size — no substeps, no rate effects.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba import prange

from ..consistency import Finding
from ..params import Parameter, ParameterSet
from ..sim.model import Model, Signal

__all__ = ["BoucWen", "bouc_wen_advance", "bouc_wen_parameters", "bouc_wen_response"]


@numba.njit(cache=True)
def _phi(z):  # pragma: no cover - compiled
    """(1 − e^{−z}) / z, accurate near 0 (series below |z| = 1e-3: error < z⁵/720 < 2e-18)."""
    if abs(z) < 1e-3:
        return 1.0 - z * (0.5 - z * (1.0 / 6.0 - z * (1.0 / 24.0 - z * (1.0 / 120.0))))
    return -math.expm1(-z) / z


@numba.njit(cache=True)
def bouc_wen_advance(H, dU, lam, beta, gamma):  # pragma: no cover - compiled
    """Exact H after the voltage moves monotonically by ``dU`` (V) from a state with hysteresis
    ``H`` (m); ``lam`` in m/V, ``beta``/``gamma`` in 1/V. See the module docstring."""
    if dU == 0.0:
        return H
    s = 1.0 if dU > 0.0 else -1.0
    rem = abs(dU)
    if H * s >= 0.0:  # H has the sign of the motion (or is 0): no zero crossing, one formula
        c = beta + gamma
        return H + (s * lam - c * H) * rem * _phi(c * rem)
    # H opposes the motion: it moves towards zero with c = β − γ; it may cross it within rem
    c = beta - gamma
    if c != 0.0:
        arg = -s * c * H / lam
        v0 = math.log1p(arg) / c if arg > -1.0 else math.inf
    else:
        v0 = -s * H / lam
    if v0 < rem:
        rem -= v0
        c = beta + gamma
        return s * lam * rem * _phi(c * rem)
    return H + (s * lam - c * H) * rem * _phi(c * rem)


@numba.njit(cache=True)
def _bouc_wen_row(theta, u, x0, y):  # pragma: no cover - compiled
    d_p, lam, beta, gamma = theta[0], theta[1], theta[2], theta[3]
    H = x0[0]
    Uh = x0[1]
    for n in range(u.shape[0]):
        U = u[n, 0]
        H = bouc_wen_advance(H, U - Uh, lam, beta, gamma)
        Uh = U
        y[n, 0] = d_p * U - H
        y[n, 1] = H


@numba.njit(cache=True, parallel=True)
def _bouc_wen_batch(thetas, u, dt, substeps, x0, y):  # pragma: no cover - compiled
    # rows in parallel; the row body is a plain function (faster code)
    for p in prange(thetas.shape[0]):
        _bouc_wen_row(thetas[p], u, x0[p], y[p])


def bouc_wen_parameters(d_p: float, lam: float, beta: float, gamma: float, *, source: str = "",
                        name: str = "bouc-wen") -> ParameterSet:
    """A ParameterSet for eq 3 (SI: d_p, lam in m/V; beta, gamma in 1/V)."""
    return ParameterSet([
        Parameter("d_p", d_p, "m/V", "piezoelectric coefficient (free displacement per volt)",
                  bounds=(0.0, None), source=source, display_unit="um/V"),
        Parameter("lam", lam, "m/V", "Bouc-Wen λ: amplitude of the hysteresis (eq 3)",
                  bounds=(0.0, None), source=source, display_unit="um/V"),
        Parameter("beta", beta, "1/V", "Bouc-Wen β: shape of the hysteresis (eq 3)",
                  bounds=(0.0, None), source=source),
        Parameter("gamma", gamma, "1/V", "Bouc-Wen γ: shape of the hysteresis (eq 3)",
                  bounds=(None, None), source=source),
    ], name)


class BoucWen(Model):
    """Static (rate-independent) Bouc-Wen hysteresis, eq 3: y = d_p U − H.

    Input ``U`` (V); outputs ``y`` (m) and ``H`` (m); states ``H`` (m) and ``U`` (V, the voltage
    last applied: the operator needs it to know how far the next sample moves). The initial
    state is the virgin one, H = 0 at U = 0 V.

    >>> bw = BoucWen(d_p=0.77e-6, lam=0.43e-6, beta=0.108, gamma=7.5e-3)
    >>> round(bw.saturation() * 1e6, 2)   # λ/(β+γ) in µm
    3.72
    """

    name = "bouc-wen"
    description = "y = d_p U − H, dH/dt = λ dU/dt − β|dU/dt|H − γ dU/dt|H| (eq 3)"
    inputs = (Signal("U", "V", "actuator voltage"),)
    outputs = (Signal("y", "m", "displacement d_p U − H"), Signal("H", "m", "hysteresis term"))
    states = (Signal("H", "m", "hysteresis term"), Signal("U", "V", "voltage last applied"))
    integrator = "zoh"  # exact per sample (rate independent)

    def __init__(self, parameters: ParameterSet | None = None, *, d_p: float = 0.77e-6,
                 lam: float = 0.43e-6, beta: float = 0.108, gamma: float = 7.5e-3,
                 check: bool = True):
        super().__init__(parameters if parameters is not None
                         else bouc_wen_parameters(d_p, lam, beta, gamma), check=check)

    def _simulate_batch(self, thetas, u, dt, substeps, x0, y):
        if len(thetas) == 1:  # one row: no parallel region
            _bouc_wen_row(thetas[0], u, x0[0], y[0])
        else:
            _bouc_wen_batch(thetas, u, dt, substeps, x0, y)

    def saturation(self) -> float:
        """|H| reached after a long monotone voltage sweep, λ/(β + γ) (m)."""
        p = self.parameters
        return p.value("lam") / (p.value("beta") + p.value("gamma"))

    def consistency_checks(self) -> list[Finding]:
        p = self.parameters
        c = p.value("beta") + p.value("gamma")
        ok = c > 0
        msg = (f"β + γ = {c:.4g} 1/V: on a monotone sweep H tends to λ/(β+γ) = "
               f"{p.value('lam') / c:.4g} m" if ok else
               f"β + γ = {c:.4g} 1/V ≤ 0: on a monotone sweep H grows without bound")
        return [Finding("bounded-hysteresis", self.name, ok, msg,
                        used="" if ok else "simulated as given; the loop is not bounded",
                        computed=c, stated=0.0, source="eq 3")]


def bouc_wen_response(U: np.ndarray, d_p: float, lam: float, beta: float, gamma: float,
                      H0: float = 0.0, U0: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """(y, H) of eq 3 for the voltage samples ``U`` (V), from hysteresis ``H0`` at ``U0``."""
    bw = BoucWen(bouc_wen_parameters(d_p, lam, beta, gamma), check=False)
    out = bw.simulate_batch(bw.theta()[None, :], np.asarray(U, dtype=np.float64), dt=1.0,
                            x0=np.array([[H0, U0]]))[0]
    return out[:, 0], out[:, 1]
