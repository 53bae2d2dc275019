"""Online adaptation of a friction model while the finger runs: recursive least squares with
exponential forgetting on a scale and an offset of the friction table.

The thesis proposes "an algorithm to adjust the friction model" because friction "differs from
finger to finger and the parameters may change over time" (``002_ddea254371185ad3.txt``,
abstract, §6.3, §8). gripkit adapts, per actuator k, the friction model

    F_k(v) = s_k · F_table,k(v) + o_k · sign(v)

(a scale of the identified lookup table and a Coulomb-like offset) from the running finger's
signals: the motor torque τ_m (from the PWM command and the measured speed through eq 5.10), the
actuator velocity v and the bias torque h = Γᵀ(C + G) of the multibody model. The actuator's
equation J v̇ = τ_m − h − F(v) is low-pass filtered with H(s) = a/(s + a) on both sides, which
removes the need for an acceleration signal (H[s·v] = a(v − H[v])):

    y = H[τ_m − h] − J·a·(v − H[v]) = s·H[F_table(v)] + o·H[sign(v)] = φᵀθ.

RLS with forgetting factor λ (per sample of period T_s) updates θ = (s, o) on the samples where
the actuator has slid in one direction (|v| above ``v_min``) for three filter time constants: at
rest friction is a reaction, not a function of v, and right after a stick phase or a reversal the
filtered signals still carry it. Neither estimates nor covariance change otherwise, so the
covariance cannot wind up. The standard deviations are σ̂·sqrt(diag P) with σ̂² an exponentially weighted
average of the a-priori residuals.

Convergence time. After a change of friction, the weight of data older than k sliding samples is
λᵏ, and the error of the estimate decays like λᵏ; it falls to 5 % after
k = ln 20 / (−ln λ) samples, i.e. t₉₅ = T_s · ln 20 / (−ln λ) ≈ 3·T_s/(1 − λ) of *sliding* time
(:meth:`FrictionAdapter.convergence_time`): 3.0 s for λ = 0.999 at 1 kHz.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import DataError, ModelError
from ..models.friction import FrictionTable, table_arrays, table_friction
from ..multibody.kernels import hot

__all__ = ["FrictionAdapter", "AdaptationResult"]


@hot
def _rls_run(tau, bias, vel, J, tv, tf, tn, tipos, lam, a_filt, dt, vmin, p0, s0, o0,
             theta, P, filt, sig2, out_theta, out_std, out_active):  # pragma: no cover - compiled
    """RLS over N samples for m actuators. State arrays (updated in place so a later call
    continues): theta (m, 2), P (m, 2, 2), filt (m, 5) = H[τ−h], H[v], H[F], H[sign], samples
    sliding in the current direction; sig2 (m,)."""
    N = tau.shape[0]
    m = tau.shape[1]
    al = 1.0 - math.exp(-a_filt * dt)  # exact discretisation of a/(s + a)
    hold = math.ceil(3.0 / (a_filt * dt))  # three filter time constants
    for n in range(N):
        for k in range(m):
            v = vel[n, k]
            sg = 1.0 if v > 0.0 else (-1.0 if v < 0.0 else 0.0)
            fr = table_friction(v, tv[k], tf[k], tn[k], tipos[k]) if v != 0.0 else 0.0
            filt[k, 0] += al * (tau[n, k] - bias[n, k] - filt[k, 0])
            vf_old = filt[k, 1]
            filt[k, 1] += al * (v - filt[k, 1])
            filt[k, 2] += al * (fr - filt[k, 2])
            filt[k, 3] += al * (sg - filt[k, 3])
            # sliding in one direction for `hold` samples: the filtered signals no longer carry
            # the holding torque of a stick phase or the friction step of a reversal
            if abs(v) > vmin and sg * filt[k, 4] >= 0.0:
                filt[k, 4] += sg
            else:
                filt[k, 4] = sg if abs(v) > vmin else 0.0
            active = abs(filt[k, 4]) > hold
            out_active[n, k] = 1.0 if active else 0.0
            if active:
                # y = H[τ − h] − J·H[v̇], with H[v̇] = d/dt H[v] as a difference of the filter state
                y = filt[k, 0] - J[k] * (filt[k, 1] - vf_old) / dt
                f1 = filt[k, 2]
                f2 = filt[k, 3]
                e = y - f1 * theta[k, 0] - f2 * theta[k, 1]
                p00 = P[k, 0, 0]
                p01 = P[k, 0, 1]
                p11 = P[k, 1, 1]
                g0 = p00 * f1 + p01 * f2
                g1 = p01 * f1 + p11 * f2
                den = lam + f1 * g0 + f2 * g1
                k0 = g0 / den
                k1 = g1 / den
                theta[k, 0] += k0 * e
                theta[k, 1] += k1 * e
                P[k, 0, 0] = (p00 - k0 * g0) / lam
                P[k, 0, 1] = (p01 - k0 * g1) / lam
                P[k, 1, 0] = P[k, 0, 1]
                P[k, 1, 1] = (p11 - k1 * g1) / lam
                sig2[k] = lam * sig2[k] + (1.0 - lam) * e * e / (1.0 + (f1 * g0 + f2 * g1) / lam)
            out_theta[n, k, 0] = theta[k, 0]
            out_theta[n, k, 1] = theta[k, 1]
            s = math.sqrt(max(sig2[k], 0.0))
            out_std[n, k, 0] = s * math.sqrt(max(P[k, 0, 0], 0.0))
            out_std[n, k, 1] = s * math.sqrt(max(P[k, 1, 1], 0.0))


@dataclass(frozen=True)
class AdaptationResult:
    """Estimates over time: ``scale`` and ``offset`` (N, m), their ``std`` (N, m, 2), and
    ``active`` (N, m) marking the samples that updated (sliding)."""

    t: np.ndarray
    scale: np.ndarray
    offset: np.ndarray
    std: np.ndarray
    active: np.ndarray
    names: tuple

    def settling_time(self, k: int, true_scale: float, t_change: float, tol: float = 0.05) -> float:
        """Time after ``t_change`` until the scale of actuator k stays within ``tol`` (relative) of
        ``true_scale`` (inf if it never does)."""
        err = np.abs(self.scale[:, k] - true_scale) / abs(true_scale)
        after = self.t >= t_change
        bad = after & (err > tol)
        if not after.any():
            return math.inf
        if not bad.any():
            return 0.0
        last_bad = np.flatnonzero(bad)[-1]
        if last_bad == self.t.size - 1:
            return math.inf
        return float(self.t[last_bad + 1] - t_change)


class FrictionAdapter:
    """Recursive friction correction for m actuators (see the module docstring).

    Parameters
    ----------
    tables
        The friction tables being corrected (one :class:`FrictionTable` per actuator).
    inertia
        Apparent inertia of each actuator (kg·m²), e.g. the diagonal of M_p.
    dt
        Sample period (s).
    forgetting
        λ ∈ (0, 1]; memory ≈ dt/(1 − λ).
    filter_hz
        Corner frequency of H (Hz).
    v_min
        Sliding threshold (rad/s).
    """

    def __init__(self, tables, inertia, dt: float, *, forgetting: float = 0.999,
                 filter_hz: float = 10.0, v_min: float = 0.05, p0: float = 100.0,
                 names=None):
        self.tables = tuple(tables)
        if not self.tables or not all(isinstance(t, FrictionTable) for t in self.tables):
            raise ModelError("tables: expected one FrictionTable per actuator")
        m = len(self.tables)
        J = np.asarray(inertia, dtype=np.float64)
        if J.shape != (m,) or not (J > 0).all():
            raise ModelError(f"inertia: expected {m} positive values, found {inertia!r}")
        if not (0 < forgetting <= 1):
            raise ModelError(f"forgetting factor must lie in (0, 1], found {forgetting!r}")
        if not (dt > 0 and filter_hz > 0 and v_min >= 0 and p0 > 0):
            raise ModelError("dt, filter_hz and p0 must be > 0 and v_min >= 0")
        if filter_hz >= 0.5 / dt:
            raise ModelError(f"filter_hz = {filter_hz:g} Hz must lie below the Nyquist frequency {0.5 / dt:g} Hz")
        self.J = J
        self.dt = float(dt)
        self.lam = float(forgetting)
        self.a = 2 * math.pi * float(filter_hz)
        self.v_min = float(v_min)
        self.p0 = float(p0)
        self.names = tuple(names) if names is not None else tuple(f"a{k}" for k in range(m))
        self._tv, self._tf, self._tn, self._tip = table_arrays(self.tables)
        self.reset()

    @property
    def m(self) -> int:
        return len(self.tables)

    def reset(self, scale: float = 1.0, offset: float = 0.0) -> None:
        """Start again from ``scale``, ``offset`` with covariance p0·I."""
        m = self.m
        self.theta = np.tile([scale, offset], (m, 1)).astype(np.float64)
        self.P = np.tile(np.eye(2) * self.p0, (m, 1, 1))
        self.filt = np.zeros((m, 5))
        self.sig2 = np.zeros(m)
        self.t = 0.0

    def convergence_time(self, tol: float = 0.05) -> float:
        """Sliding time (s) for the estimate error to fall to ``tol`` of a step change:
        dt·ln(1/tol)/(−ln λ)."""
        if self.lam == 1.0:
            return math.inf
        return self.dt * math.log(1.0 / tol) / (-math.log(self.lam))

    def update(self, tau_motor, bias, velocity) -> AdaptationResult:
        """Feed samples (N, m) (or one sample (m,)) of motor torque, bias torque and velocity;
        the adapter keeps its state between calls."""
        tau = np.atleast_2d(np.asarray(tau_motor, dtype=np.float64))
        h = np.atleast_2d(np.asarray(bias, dtype=np.float64))
        v = np.atleast_2d(np.asarray(velocity, dtype=np.float64))
        m = self.m
        for name, a in (("tau_motor", tau), ("bias", h), ("velocity", v)):
            if a.ndim != 2 or a.shape[1] != m or a.shape[0] != tau.shape[0]:
                raise DataError(f"{name}: expected shape (N, {m}) like tau_motor, found {a.shape}")
            if not np.isfinite(a).all():
                raise DataError(f"{name} contains NaN or inf")
        N = tau.shape[0]
        th = np.empty((N, m, 2))
        sd = np.empty((N, m, 2))
        act = np.empty((N, m))
        _rls_run(np.ascontiguousarray(tau), np.ascontiguousarray(h), np.ascontiguousarray(v), self.J,
                 self._tv, self._tf, self._tn, self._tip, self.lam, self.a, self.dt, self.v_min,
                 self.p0, 1.0, 0.0, self.theta, self.P, self.filt, self.sig2, th, sd, act)
        t = self.t + np.arange(N) * self.dt
        self.t = float(t[-1] + self.dt)
        return AdaptationResult(t, th[:, :, 0], th[:, :, 1], sd, act.astype(bool), self.names)

    def corrected_tables(self) -> tuple[FrictionTable, ...]:
        """The tables with the current scale applied (offsets are reported, not tabulated)."""
        return tuple(t.scaled(float(s)) for t, s in zip(self.tables, self.theta[:, 0]))
