"""Friction that changes while the finger runs — the plant's side of an adaptation study, unknown
to the controller.

A drift schedule gives, per actuator k, a scale s_k(t) (dimensionless) and an offset Δ_k(t) (N·m)
of the finger's friction:

    F_k(t, v) = s_k(t)·F_k,0(v) + Δ_k(t)·sign(v),     F_s,k(t) = s_k(t)·F_s,k,0 + Δ_k(t)

(F_k,0 the kinetic friction of the finger's model — Appendix G table, Stribeck or LuGre curve —
and F_s,k,0 its stiction), piecewise linear in time between the schedule's points and held beyond
its ends; a time listed twice is a step. This is the class of change the online estimator
(:mod:`gripkit.estimation.friction_adaptation`) adapts to.

Two changes the thesis (``002_ddea254371185ad3.txt``) motivates:

* **Warm-up** (:func:`warmup_drift`). Fig. 5.7 (§5.4.3) holds PWM 4000 on the stalled motor: the
  winding goes from room temperature to "about 80 °C" within the figure's 120 s. gripkit's thermal
  model of that figure (:mod:`gripkit.models.bldc`: T_amb = 25 °C, T_ref = 80 °C, time constant
  R_th·C_th = 7.2 K/W · 5.5 J/K = 39.6 s) gives the course T(t) = T_ref − (T_ref − T_amb)e^(−t/τ).
  The thesis says that friction depends on temperature through the lubricant's viscosity (§3.2,
  §6.1) but gives no friction-versus-temperature number, and that its tables hold at the operating
  temperature reached after a few minutes of use (§5.4.3, §8). gripkit therefore takes friction
  linear in temperature between an assumed ``cold_scale`` at T_amb (default 1.5) and 1 at T_ref:
  s(t) = 1 + (cold_scale − 1)·e^(−t/τ).
* **Stiction step** (:func:`stiction_step`). Stiction and Coulomb level rise at once by Δ (a drive
  that picks up dirt, or the spread between drives: the thesis multiplies base 1's table by 1.25
  for the mechanically identical base 2, §6.3 and §7). Default Δ = 0.25 × 0.36 N·m = 0.09 N·m
  (Appendix F's stiction times that spread).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import ModelError
from .finger import ACTUATORS

__all__ = ["FrictionDrift", "warmup_drift", "stiction_step", "STICTION_STEP"]

#: default stiction step (N·m): Appendix F's 0.36 N·m times the 25 % base-2 spread of §6.3
STICTION_STEP = 0.25 * 0.36


def _per_actuator(name, a, K):
    a = np.asarray(a, dtype=np.float64)
    if a.ndim == 1 and a.shape == (K,):
        a = np.repeat(a[:, None], 3, axis=1)
    if a.shape != (K, 3) or not np.isfinite(a).all():
        raise ModelError(f"{name}: expected {K} finite values (one per time) or ({K}, "
                         "3) (per actuator "
                         f"{', '.join(ACTUATORS)}), found shape {a.shape}")
    return a


@dataclass(frozen=True)
class FrictionDrift:
    """A friction drift schedule (see the module docstring).

    Parameters
    ----------
    times
        (K,) schedule times (s), non-decreasing; a time listed twice makes a step.
    scale
        (K,) or (K, 3) friction scale s (dimensionless, ≥ 0) per actuator (base1, base2, distal).
    offset
        (K,) or (K, 3) offset Δ (N·m) added to kinetic friction (times sign v) and to stiction.
    """

    times: np.ndarray
    scale: np.ndarray
    offset: np.ndarray | None = None
    name: str = "friction drift"

    def __post_init__(self):
        t = np.asarray(self.times, dtype=np.float64)
        if t.ndim != 1 or t.size < 1 or not np.isfinite(t).all() or (np.diff(t) < 0).any():
            raise ModelError("times: expected a non-decreasing, finite 1-D array in s, "
                             f"found {self.times!r}")
        d = np.diff(t)
        if ((d[1:] == 0) & (d[:-1] == 0)).any():
            raise ModelError("times: a time may appear at most twice (a step)")
        s = _per_actuator("scale", self.scale, t.size)
        if (s < 0).any():
            raise ModelError(f"scale: friction scales must be >= 0, found min {s.min():g}")
        o = (_per_actuator("offset", np.zeros(t.size) if self.offset is None else self.offset,
                           t.size))
        object.__setattr__(self, "times", t)
        object.__setattr__(self, "scale", s)
        object.__setattr__(self, "offset", o)

    def _eval(self, t, side):
        t = np.asarray(t, dtype=np.float64)
        K = self.times.size
        i = np.searchsorted(self.times, t, side=side)
        lo = np.clip(i - 1, 0, K - 1)
        hi = np.clip(i, 0, K - 1)
        span = self.times[hi] - self.times[lo]
        w = np.where(span > 0, (t - self.times[lo]) / np.where(span > 0, span, 1.0), 1.0)[..., None]
        s = self.scale[lo] + w * (self.scale[hi] - self.scale[lo])
        o = self.offset[lo] + w * (self.offset[hi] - self.offset[lo])
        return np.concatenate([s, o], axis=-1)

    def at(self, t) -> np.ndarray:
        """(N, 6) = (s_base1, s_base2, s_distal, Δ_base1, Δ_base2, Δ_distal) at times t (s);
        right-continuous at a step."""
        return self._eval(t, "right")

    def combine(self, other: FrictionDrift) -> FrictionDrift:
        """Both drifts at once: scales multiply, offsets add."""
        if not isinstance(other, FrictionDrift):
            raise ModelError(f"combine: expected a FrictionDrift, found {type(other).__name__}")
        times, rows = [], []
        for u in np.unique(np.concatenate([self.times, other.times])):
            left = [d._eval(u, "left") for d in (self, other)]
            right = [d._eval(u, "right") for d in (self, other)]
            for a, b in ((left[0], left[1]), (right[0], right[1])):
                row = np.concatenate([a[:3] * b[:3], a[3:] + b[3:]])
                if not rows or times[-1] != u or not np.array_equal(rows[-1], row):
                    times.append(u)
                    rows.append(row)
        r = np.array(rows)
        return (FrictionDrift(np.array(times), r[:, :3], r[:, 3:],
                              name=f"{self.name} + {other.name}"))


def warmup_drift(duration: float, *, cold_scale: float = 1.5, time_constant: float = 7.2 * 5.5,
                 points: int = 200) -> FrictionDrift:
    """Friction of a finger that starts at room temperature and warms up like Fig. 5.7:
    s(t) = 1 + (cold_scale − 1)·e^(−t/τ) on 0..``duration`` s (see the module docstring).
    ``time_constant`` τ (s, default R_th·C_th = 39.6 s of the Fig. 5.7 thermal model);
    ``cold_scale`` (assumed; the seed gives no friction-temperature number)."""
    if not (math.isfinite(duration) and duration > 0):
        raise ModelError(f"duration: expected a positive time in s, found {duration!r}")
    if not (math.isfinite(cold_scale) and cold_scale >= 0):
        raise ModelError("cold_scale: expected a non-negative friction scale, "
                         f"found {cold_scale!r}")
    if not (math.isfinite(time_constant) and time_constant > 0):
        raise ModelError(f"time_constant: expected a positive time in s, found {time_constant!r}")
    if int(points) != points or points < 2:
        raise ModelError(f"points: expected an integer >= 2, found {points!r}")
    t = np.linspace(0.0, duration, int(points))
    return FrictionDrift(t, 1.0 + (cold_scale - 1.0) * np.exp(-t / time_constant),
                         name=f"warm-up (Fig. 5.7, cold ×{cold_scale:g}, τ = "
                              f"{time_constant:.3g} s)")


def stiction_step(time: float, delta: float = STICTION_STEP, actuators=ACTUATORS) -> FrictionDrift:
    """Stiction and Coulomb level of ``actuators`` rise by ``delta`` (N·m) at ``time`` (s)."""
    if not (math.isfinite(time) and time >= 0):
        raise ModelError(f"time: expected a step time >= 0 s, found {time!r}")
    if not math.isfinite(delta):
        raise ModelError(f"delta: expected a finite torque in N·m, found {delta!r}")
    unknown = [a for a in actuators if a not in ACTUATORS]
    if unknown:
        raise ModelError(f"actuators: expected names from {ACTUATORS}, found {unknown}")
    d = np.array([delta if a in actuators else 0.0 for a in ACTUATORS])
    return FrictionDrift(np.array([time, time]), np.ones(2), np.vstack([np.zeros(3), d]),
                         name=f"stiction step {delta:+g} N·m at {time:g} s")
