"""Friction models: Coulomb, viscous, Stribeck, velocity lookup tables, harmonic-drive position
ripple, Karnopp stick-slip and LuGre.

Sign convention: a friction function returns the torque F(v) that *opposes* motion, so the
equation of motion reads J v̇ = τ − F. Velocities in rad/s (or m/s), torques in N·m (or N).

Kinetic friction (``002_ddea254371185ad3.txt`` chapter 6):

* Coulomb (eq 6.2) and viscous (eq 6.3): F = sign(v)·F_c + σ v.
* Stribeck (eq 6.5, garbled in the extraction; the standard form with the symbols the thesis lists
  — Coulomb F_C, stiction F_S, viscous σ, Stribeck velocity v_S, shape factor δ)::

      F(v) = sign(v)·(F_c + (F_s − F_c)·exp(−|v/v_s|^δ)) + σ v

  δ > 0 gives the usual dip after breakaway; δ < 0 a friction that rises from F_c to F_s
  (Fig. 6.2 (b), "negative shape factor").
* Lookup table (§6.3, Appendix G): friction measured at constant velocities, linearly
  interpolated. gripkit evaluates the positive and the negative branch separately: below the
  smallest measured |v| the value of the nearest breakpoint is held (no fictitious viscous ramp
  through zero — rest is the stiction state machine's business), beyond the last breakpoint the
  last segment is extended linearly (Simulink's default).
* Harmonic-drive ripple (§3.2.2, after Tuttle [49, 50]): a sinusoidal friction component that
  varies with the output position, ΔF = A·sin(k·θ + φ)·sign(v).

Stiction: **Karnopp**'s state machine — a joint at rest stays exactly at rest while the torque
needed to hold it is at most F_s, and breaks away (with kinetic friction) when it exceeds F_s; a
sliding joint sticks when its velocity crosses zero and the holding torque is below F_s. This is
true stick-slip: no creep under a sub-stiction load (§6.2: "undesired stick-slip effect occurs" at
PWM 1200–1500).

**LuGre** (Canudas de Wit et al., 1995), an option and gripkit's addition (the DLR/HIT thesis,
``002_ddea254371185ad3.txt``, uses lookup tables and Stribeck's eq 6.5): an internal bristle
state z with

    ż = v − σ₀|v| z / g(v),  g(v) = F_c + (F_s − F_c) exp(−(v/v_s)²),  F = σ₀ z + σ₁ ż + σ₂ v;

it reproduces pre-sliding displacement and frictional lag, but unlike Karnopp it moves under a
constant sub-stiction load (a pre-sliding displacement of many times F_s/σ₀ before it settles).
gripkit integrates z exactly for the velocity held over a step
(z relaxes exponentially towards sign(v)·g(v)/σ₀ at rate σ₀|v|/g(v)), stable for any step.
"""

from __future__ import annotations

import math
from collections import namedtuple
from dataclasses import dataclass
from pathlib import Path

import numba
import numpy as np
from numba import prange

from ..errors import DataError, ModelError
from ..multibody.kernels import hot
from ..params import Parameter, ParameterSet
from ..sim.model import Model, Signal

__all__ = ["coulomb_viscous", "stribeck", "table_friction", "ripple", "lugre_g", "lugre_update",
           "lugre_force", "FrictionTable", "Stribeck", "FrictionDrive",
           "friction_drive_parameters", "table_arrays", "TableArrays"]

DEG = math.pi / 180.0


# --- scalar kernels -----------------------------------------------------------------------------

@hot
def coulomb_viscous(v, fc, sigma):  # pragma: no cover - compiled
    """sign(v)·F_c + σ v (eqs 6.2–6.3); 0 at v = 0."""
    if v > 0.0:
        return fc + sigma * v
    if v < 0.0:
        return -fc + sigma * v
    return 0.0


@hot
def stribeck(v, fc, fs, vs, delta, sigma):  # pragma: no cover - compiled
    """Stribeck curve (eq 6.5); 0 at v = 0 (rest is handled by the stiction logic)."""
    if v == 0.0:
        return 0.0
    av = abs(v)
    mag = fc + (fs - fc) * math.exp(-((av / vs) ** delta))
    if v > 0.0:
        return mag + sigma * v
    return -mag + sigma * v


@hot
def table_friction(v, bp, fr, n, ipos):  # pragma: no cover - compiled
    """Friction from a lookup table ``bp[:n]`` (strictly increasing, both signs) → ``fr[:n]``;
    ``ipos`` is the index of the first positive breakpoint. See the module docstring."""
    if v > 0.0:
        lo = ipos
        hi = n - 1
        if v <= bp[lo]:
            return fr[lo]
    elif v < 0.0:
        lo = 0
        hi = ipos - 1
        if v >= bp[hi]:
            return fr[hi]
    else:
        return 0.0
    if v >= bp[hi]:
        k = hi - 1
    elif v <= bp[lo]:
        k = lo
    else:
        a = lo
        b = hi
        while b - a > 1:
            mid = (a + b) // 2
            if bp[mid] <= v:
                a = mid
            else:
                b = mid
        k = a
    return fr[k] + (fr[k + 1] - fr[k]) * (v - bp[k]) / (bp[k + 1] - bp[k])


@hot
def ripple(theta, v, amp, cycles, phase):  # pragma: no cover - compiled
    """Harmonic-drive position ripple A·sin(k·θ + φ)·sign(v) (§3.2.2)."""
    if amp == 0.0 or v == 0.0:
        return 0.0
    s = amp * math.sin(cycles * theta + phase)
    return s if v > 0.0 else -s


@hot
def lugre_g(v, fc, fs, vs):  # pragma: no cover - compiled
    return fc + (fs - fc) * math.exp(-(v / vs) * (v / vs))


@hot
def lugre_update(z, v, h, fc, fs, vs, sigma0):  # pragma: no cover - compiled
    """Bristle state after a step h at constant velocity v (exact solution of ż = v − σ₀|v|z/g)."""
    if v == 0.0:
        return z
    g = lugre_g(v, fc, fs, vs)
    zss = g / sigma0 if v > 0.0 else -g / sigma0
    return zss + (z - zss) * math.exp(-sigma0 * abs(v) * h / g)


@hot
def lugre_force(z, v, fc, fs, vs, sigma0, sigma1, sigma2):  # pragma: no cover - compiled
    """F = σ₀ z + σ₁ ż + σ₂ v."""
    zd = v - sigma0 * abs(v) * z / lugre_g(v, fc, fs, vs)
    return sigma0 * z + sigma1 * zd + sigma2 * v


@numba.njit(cache=True, error_model="numpy")
def _table_eval(bp, fr, n, ipos, v, out):  # pragma: no cover - compiled
    for i in range(v.shape[0]):
        out[i] = table_friction(v[i], bp, fr, n, ipos)


# --- lookup tables ------------------------------------------------------------------------------

class FrictionTable:
    """Friction torque (N·m) measured at constant velocities (rad/s): the lookup table of §6.3.

    ``velocity`` must be strictly increasing and contain both negative and positive values.
    ``scale`` multiplies the friction (the thesis's "correcting factor" for base joint 2).
    """

    def __init__(self, velocity, friction, *, name: str = "friction table", source: str = "",
                 scale: float = 1.0):
        v = np.asarray(velocity, dtype=np.float64)
        f = np.asarray(friction, dtype=np.float64)
        if v.ndim != 1 or f.shape != v.shape or v.size < 4:
            raise DataError(f"{name}: expected two 1-D arrays of equal length >= 4, found shapes "
                            f"{v.shape} and {f.shape}")
        if not (np.isfinite(v).all() and np.isfinite(f).all()):
            raise DataError(f"{name}: breakpoints or values contain NaN or inf")
        d = np.diff(v)
        if (d <= 0).any():
            i = int(np.argmax(d <= 0)) + 1
            raise DataError(f"{name}: breakpoints must increase strictly; breakpoint {i} "
                            f"({v[i]:.6g}) follows {v[i - 1]:.6g}",
                            hint="sort the table by velocity")
        if not ((v < 0).sum() >= 2 and (v > 0).sum() >= 2):
            raise DataError(f"{name}: needs at least two breakpoints of each sign (found "
                            f"{(v < 0).sum()} negative, {(v > 0).sum()} positive)")
        if not np.isfinite(scale) or scale <= 0:
            raise ModelError(f"{name}: scale must be > 0, found {scale!r}")
        self.velocity = v
        self.friction = f
        self.name = name
        self.source = source
        self.scale = float(scale)
        self.ipos = int(np.argmax(v > 0))

    def __call__(self, v) -> np.ndarray:
        """Friction torque at velocities ``v`` (rad/s), shape of ``v``; 0 at v = 0."""
        v = np.asarray(v, dtype=np.float64)
        flat = np.ascontiguousarray(v.ravel())
        out = np.empty_like(flat)
        _table_eval(self.velocity, self.friction * self.scale, self.velocity.size, self.ipos,
                    flat, out)
        return out.reshape(v.shape) if v.ndim else float(out[0])

    def scaled(self, factor: float) -> "FrictionTable":
        return FrictionTable(self.velocity, self.friction, name=self.name, source=self.source,
                             scale=self.scale * factor)

    @property
    def values(self) -> np.ndarray:
        """The (scaled) friction values at the breakpoints (N·m)."""
        return self.friction * self.scale

    def outliers(self, rtol: float = 0.3, half_width: int = 2) -> list[tuple[int, float]]:
        """Breakpoints whose value lies more than ``rtol`` (relative) from the median of its
        ``half_width`` neighbours on each side (same-sign branch only): ``[(index, median)]``."""
        out = []
        for lo, hi in ((0, self.ipos), (self.ipos, self.velocity.size)):
            f = self.friction[lo:hi]
            for i in range(f.size):
                nb = np.r_[f[max(0, i - half_width):i], f[i + 1:i + 1 + half_width]]
                if nb.size >= 2:
                    med = float(np.median(nb))
                    if abs(f[i] - med) > rtol * abs(med):
                        out.append((lo + i, med))
        return out

    def without_outliers(self, rtol: float = 0.3) -> "FrictionTable":
        """A copy without the :meth:`outliers` (measurement points the thesis meant to delete)."""
        bad = {i for i, _ in self.outliers(rtol)}
        keep = np.array([i not in bad for i in range(self.velocity.size)])
        return FrictionTable(self.velocity[keep], self.friction[keep],
                             name=f"{self.name} (outliers removed)",
                             source=self.source, scale=self.scale)

    @classmethod
    def from_csv(cls, path, *, name: str | None = None, scale: float = 1.0) -> "FrictionTable":
        """Read ``velocity_deg_s,friction_N_m`` CSV (``#`` lines are comments)."""
        p = Path(path)
        try:
            text = p.read_text()
        except OSError as exc:
            raise DataError(f"friction table {str(p)!r}: {exc}") from None
        return cls.from_text(text, name or p.stem, str(p), scale)

    @classmethod
    def from_text(cls, text: str, name: str, source: str, scale: float = 1.0) -> "FrictionTable":
        """Parse ``velocity_deg_s,friction_N_m`` CSV text (``#`` lines are comments)."""
        rows = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
        if not rows or rows[0].replace(" ", "") != "velocity_deg_s,friction_N_m":
            raise DataError(f"{name}: expected the header 'velocity_deg_s,friction_N_m'")
        try:
            data = np.array([[float(x) for x in r.split(",")] for r in rows[1:]])
        except ValueError as exc:
            raise DataError(f"{name}: non-numeric cell ({exc})") from None
        if data.ndim != 2 or data.shape[1] != 2:
            raise DataError(f"{name}: expected two columns per row")
        return cls(data[:, 0] * DEG, data[:, 1], name=name, source=source, scale=scale)

    def __repr__(self) -> str:
        return (f"FrictionTable({self.name!r}, {self.velocity.size} breakpoints "
                f"{self.velocity[0] / DEG:.4g}..{self.velocity[-1] / DEG:.4g} deg/s, scale "
                f"{self.scale:g})")


#: FrictionTables padded into kernel arrays: breakpoints (m, K), scaled values (m, K), lengths (m,)
#: and first-positive indices (m,); a record the compiled kernels take as one argument
TableArrays = namedtuple("TableArrays", "velocity values length ipos")


def table_arrays(tables) -> TableArrays:
    """Pad FrictionTables into kernel arrays (:data:`TableArrays`)."""
    m = len(tables)
    K = max(t.velocity.size for t in tables)
    tv = np.zeros((m, K))
    tf = np.zeros((m, K))
    tn = np.zeros(m, dtype=np.int64)
    tipos = np.zeros(m, dtype=np.int64)
    for k, t in enumerate(tables):
        n = t.velocity.size
        tv[k, :n] = t.velocity
        tf[k, :n] = t.values
        tv[k, n:] = t.velocity[-1]
        tn[k] = n
        tipos[k] = t.ipos
    return TableArrays(tv, tf, tn, tipos)


@dataclass(frozen=True)
class Stribeck:
    """Stribeck friction (eq 6.5): Coulomb ``fc`` and stiction ``fs`` (N·m), Stribeck velocity
    ``vs`` (rad/s), shape factor ``delta`` and viscous coefficient ``sigma`` (N·m·s/rad)."""

    fc: float
    fs: float
    vs: float
    delta: float = 2.0
    sigma: float = 0.0

    def __post_init__(self):
        if self.fc < 0 or self.fs < 0 or self.vs <= 0 or self.delta == 0:
            raise ModelError(f"Stribeck: need fc, fs >= 0, vs > 0 and delta != 0; found {self}")

    def __call__(self, v) -> np.ndarray:
        v = np.asarray(v, dtype=np.float64)
        mag = self.fc + (self.fs - self.fc) * np.exp(-np.abs(v / self.vs) ** self.delta)
        return np.where(v == 0, 0.0, np.sign(v) * mag + self.sigma * v)


# --- a single friction-loaded inertia (for studies and tests) -----------------------------------

def friction_drive_parameters(J: float = 0.0221, fc: float = 0.19, fs: float = 0.36,
                              vs: float = 0.3, delta: float = 2.0, sigma: float = 0.02,
                              sigma0: float = 360.0, sigma1: float = 2.8, v_stick: float = 1e-6,
                              name: str = "friction-drive") -> ParameterSet:
    """Defaults: the DLR/HIT II distal drive — rotor inertia 5.1e-7 kg·m² × 208.3² (Appendix A,
    E), stiction 0.36 N·m (Appendix F), Coulomb ≈ the low-speed level of Appendix G's distal
    table; v_s, δ, σ and the LuGre stiffness/damping are assumed."""
    seed = "002_ddea254371185ad3.txt"
    return ParameterSet([
        Parameter("J", J, "kg*m^2", "inertia at the joint (rotor "
                                    "inertia reflected)", bounds=(1e-12, None),
                  source=f"{seed}, Appendix A (Im = 5.1e-7 kg·m²) × 208.3²"),
        Parameter("fc", fc, "N*m", "Coulomb friction", bounds=(0, None),
                  source=f"{seed}, Appendix G (low speed)"),
        Parameter("fs", fs, "N*m", "stiction (breakaway torque)", bounds=(0, None),
                  source=f"{seed}, Appendix F"),
        Parameter("vs", vs, "rad/s", "Stribeck velocity", bounds=(1e-9, None), source="assumed"),
        Parameter("delta", delta, "1", "Stribeck shape factor", bounds=(0.1, 10.0),
                  source="assumed"),
        Parameter("sigma", sigma, "N*m*s/rad", "viscous friction", bounds=(0, None),
                  source="assumed"),
        Parameter("sigma0", sigma0, "N*m/rad", "LuGre bristle stiffness", bounds=(1e-9, None),
                  source="assumed: pre-sliding displacement fs/σ0 = 1 mrad"),
        Parameter("sigma1", sigma1, "N*m*s/rad", "LuGre bristle damping", bounds=(0, None),
                  source="assumed: critically damped pre-sliding, 2·sqrt(σ0 J)/2"),
        Parameter("v_stick", v_stick, "rad/s", "Karnopp zero-velocity band", bounds=(0, None),
                  source="assumed"),
    ], name)


@numba.njit(cache=True, parallel=True, error_model="numpy")
def _drive_batch(thetas, u, dt, substeps, x0, y, lugre):  # pragma: no cover - compiled
    P = thetas.shape[0]
    N = u.shape[0]
    h = dt / substeps
    for p in prange(P):
        J, fc, fs, vs, delta, sigma, s0, s1, vstick = (thetas[p, 0], thetas[p, 1], thetas[p, 2],
                                                       thetas[p, 3], thetas[p, 4], thetas[p, 5],
                                                       thetas[p, 6], thetas[p, 7], thetas[p, 8])
        x = x0[p, 0]
        v = x0[p, 1]
        z = x0[p, 2]
        stuck = x0[p, 3] != 0.0
        f = 0.0
        for n in range(N):
            tau = u[n, 0]
            y[p, n, 0] = x  # sample n: the state at t_n and the friction acting at t_n
            y[p, n, 1] = v
            for s in range(substeps):
                if lugre:
                    f = lugre_force(z, v, fc, fs, vs, s0, s1, sigma)
                    z = lugre_update(z, v, h, fc, fs, vs, s0)
                    v += h * (tau - f) / J
                    x += h * v
                elif stuck and abs(tau) <= fs:
                    f = tau
                else:
                    if stuck:  # breakaway: kinetic friction in the direction of the torque
                        stuck = False
                        f = stribeck(1e-300 if tau > 0 else -1e-300, fc, fs, vs, delta, sigma)
                    else:
                        f = stribeck(v, fc, fs, vs, delta, sigma)
                    vn = v + h * (tau - f) / J
                    if (vn * v < 0.0 or abs(vn) <= vstick) and abs(tau) <= fs:
                        vn = 0.0
                        stuck = True
                    v = vn
                    x += h * v
                if s == 0:
                    y[p, n, 2] = f


class FrictionDrive(Model):
    """An inertia J driven by a torque against friction: J v̇ = τ − F.

    ``kind='karnopp'``: Stribeck kinetic friction with Karnopp stick-slip (exact rest below
    stiction); ``kind='lugre'``: the LuGre model with the same F_c, F_s, v_s, σ.
    Input ``tau`` (N·m); outputs ``position`` (rad), ``velocity`` (rad/s), ``friction`` (N·m);
    semi-implicit Euler steps.
    """

    name = "friction-drive"
    description = "inertia with Karnopp or LuGre friction"
    inputs = (Signal("tau", "N*m", "applied torque"),)
    outputs = (Signal("position", "rad", "position"), Signal("velocity", "rad/s", "velocity"),
               Signal("friction", "N*m", "friction torque (opposing)"))
    states = (Signal("position", "rad"), Signal("velocity", "rad/s"),
              Signal("z", "rad", "LuGre bristle"),
              Signal("stuck", "1", "1 when at rest in stiction"))
    integrator = "semi-implicit"

    def __init__(self, parameters: ParameterSet | None = None, *, kind: str = "karnopp",
                 check: bool = True, **values):
        if kind not in ("karnopp", "lugre"):
            raise ModelError(f"kind: expected 'karnopp' or 'lugre', found {kind!r}")
        ps = parameters if parameters is not None else friction_drive_parameters(**values)
        if ps.names != friction_drive_parameters().names:
            raise ModelError("FrictionDrive: expected the parameters of "
                             "friction_drive_parameters()")
        self.kind = kind
        super().__init__(ps, check=check)

    def initial_state(self, theta):
        return np.array([0.0, 0.0, 0.0, 1.0])

    def _simulate_batch(self, thetas, u, dt, substeps, x0, y):
        _drive_batch(thetas, u, dt, substeps, x0, y, self.kind == "lugre")

    def modes(self, theta):
        J, s0, s1, sig = theta[0], theta[6], theta[7], theta[5]
        if self.kind == "lugre":
            wn = math.sqrt(s0 / J)
            return [(wn, (s1 + sig) / (2.0 * math.sqrt(s0 * J)))]
        return [(max(sig / J, 1e-12), 1.0)]
