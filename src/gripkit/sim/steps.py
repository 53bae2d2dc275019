"""Does a fixed step resolve the model's fastest mode? Refuse or warn instead of returning garbage.

For a mode with natural frequency ω_n (rad/s) and damping ratio ζ, a fixed-step integrator with
step h sees the dimensionless number ω_n·h:

* **stability** — the scheme's amplification factor must not exceed 1 for the lightly damped
  eigenvalue λ = ω_n(-ζ ± j√(1-ζ²)). On the imaginary axis RK4 is stable for ω h < 2√2 ≈ 2.83 and
  the semi-implicit (symplectic) Euler scheme for ω h < 2. Above the bound the answer diverges:
  gripkit refuses (:class:`SimulationError`).
* **accuracy** — the step must sample the period 2π/ω_d at least ``points_per_period`` times
  (default 20), and for lightly damped modes the scheme's own numerical damping must stay well
  below the physical damping ζ ω_n h per step: RK4 loses ≈ (ω h)^6/144 of amplitude per step, so
  gripkit requires (ω h)^5/144 ≤ 0.1 ζ. Below that it warns (:class:`AccuracyWarning`), or picks
  internal substeps (:func:`substeps_for`).

The TSFM force sensor (``001_0b92a7da96e7aa46.txt`` §IV-B: 8.52 kHz, ζ = 0.006) at the seed's
20 kHz sampling has ω h = 2.68: inside RK4's stability bound, yet only 2.3 samples per period, so
integrating it at 20 kHz directly would be badly wrong; gripkit substeps (or discretises the linear
part exactly, :mod:`gripkit.sim.linear`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable

from ..errors import AccuracyWarning, SimulationError, emit_warning

__all__ = ["STABILITY_LIMIT", "check_step", "substeps_for", "step_report"]

# Largest stable ω·h on the imaginary axis.
STABILITY_LIMIT = {"rk4": 2.0 * math.sqrt(2.0), "semi-implicit": 2.0, "euler": 0.0, "zoh": math.inf}


def _max_wh_accurate(zeta: float, points_per_period: int, method: str) -> float:
    """Largest ω·h meeting the accuracy rules for one mode."""
    bound = 2.0 * math.pi / points_per_period
    if method == "rk4" and zeta > 0:
        bound = min(bound, (0.1 * zeta * 144.0) ** 0.2)
    return bound


def step_report(dt: float, modes: Iterable[tuple[float, float]], method: str = "rk4",
                points_per_period: int = 20) -> list[dict]:
    """For each mode (ω_n rad/s, ζ): ω h, the stable and accurate limits, and verdicts."""
    if method not in STABILITY_LIMIT:
        raise SimulationError(f"method: expected one of {sorted(STABILITY_LIMIT)}, "
                              f"found {method!r}")
    rows = []
    for wn, zeta in modes:
        wh = wn * dt
        stable_lim = STABILITY_LIMIT[method]
        acc_lim = _max_wh_accurate(zeta, points_per_period, method) if method != "zoh" else math.pi
        rows.append(dict(omega_n=wn, f_n_hz=wn / (2 * math.pi), zeta=zeta, omega_h=wh,
                         stable=wh < stable_lim, accurate=wh <= acc_lim,
                         stable_limit=stable_lim, accurate_limit=acc_lim))
    return rows


def check_step(dt: float, modes: Iterable[tuple[float, float]], method: str = "rk4",
               points_per_period: int = 20, what: str = "model") -> None:
    """Raise :class:`SimulationError` if ``dt`` makes ``method`` unstable on a mode; warn
    (:class:`AccuracyWarning`) if it under-resolves one. ``method='zoh'`` (exact discretisation)
    only warns when a mode lies above the Nyquist frequency of the output sampling."""
    if not (math.isfinite(dt) and dt > 0):
        raise SimulationError(f"time step dt: expected a positive number of seconds, found {dt!r}")
    for r in step_report(dt, modes, method, points_per_period):
        if not r["stable"]:
            raise SimulationError(
                f"{what}: step dt = {dt:.6g} s cannot integrate the {r['f_n_hz']:.6g} Hz mode "
                f"(ζ = {r['zeta']:.3g}) with {method}: ω·dt = {r['omega_h']:.3g} "
                "exceeds the stability "
                f"limit {r['stable_limit']:.3g}",
                hint=f"use dt <= {r['accurate_limit'] / r['omega_n']:.3g} s or substeps")
        if not r["accurate"]:
            emit_warning(
               f"{what}: step dt = {dt:.6g} s under-resolves the {r['f_n_hz']:.6g} Hz mode "
               f"(ζ = {r['zeta']:.3g}): ω·dt = {r['omega_h']:.3g} > {r['accurate_limit']:.3g}; "
               f"use dt <= {r['accurate_limit'] / r['omega_n']:.3g} s", AccuracyWarning)


def substeps_for(dt: float, modes: Iterable[tuple[float, float]], method: str = "rk4",
                 points_per_period: int = 20) -> int:
    """Smallest number of internal substeps per output step ``dt`` that resolves every mode."""
    n = 1
    for r in step_report(dt, modes, method, points_per_period):
        n = max(n, math.ceil(r["omega_h"] / r["accurate_limit"] - 1e-12))
    return n
