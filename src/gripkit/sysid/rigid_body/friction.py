"""Friction identification: stiction from breakaway tests, dynamic friction from constant-velocity
runs (lookup table or fitted Stribeck curve with uncertainty), and inverse-dynamics least squares
(IDIM-LS).

Stiction (``002_ddea254371185ad3.txt`` §6.2, Appendix C). The joint is held at a position and
driven by PWM pulses of increasing amplitude (500 → 1500 in steps of 50), each followed by a
pause. A pulse "moves" the joint when the velocity is non-zero for more than a given number of
samples (Appendix C counts samples with ``velocity ~= 0`` and requires more than 1000). The first
moving pulse of a series is the breakaway PWM (Table 6.1); through the motor model at zero speed
and the gear ratio it gives the stiction torque. The true breakaway level lies between the last
still and the first moving pulse: gripkit reports the midpoint with the quantisation uncertainty
(step/√12) combined with the spread over positions.

Dynamic friction (§6.2, Appendix D). At constant PWM the joint settles to a constant velocity
(acceleration ≈ 0), where friction = motor torque(PWM, v) − gravity (eq 6.6 without the inertial
term). Each run gives one (v, F) point; the points form the lookup table of §6.3, or are fitted
with a Stribeck curve plus viscous and cubic terms (:func:`fit_stribeck`) whose covariance gives
the uncertainty.

IDIM-LS (the standard robot identification method, e.g. Gautier & Khalil; Swevers et al.; gripkit's
addition: the DLR/HIT thesis identifies friction from constant-velocity runs only). For one
axis with position q and effort τ (= K × a logged column):

    τ = J q̈ + F_v q̇ + F_c sign(q̇) + τ₀.

Position and effort are low-pass filtered with the same zero-phase Butterworth filter (parallel
filtering keeps the linear relation exact), q̇ and q̈ come from central differences of the filtered
position, the filtered signals are decimated (keeping every q-th sample: fewer, less correlated
rows), the filter's edge transients, the samples with |q̇| below a threshold (where the joint may
stick) and those within about one filter time constant of a velocity reversal (where the filtered
Coulomb step no longer follows sign(q̇)) are dropped, and the overdetermined system is solved by
least squares. Standard deviations: σ̂² = RSS/(N − 4), Cov = σ̂² (XᵀX)⁻¹; relative error
100·‖τ − Xθ‖/‖τ‖.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ...arguments import entry_point, sample_interval
from ...errors import ArgumentError, DataError, IdentificationError, UnidentifiableError
from ...models.friction import FrictionTable
from ...signals.filters import apply_sos, butter_sos
from ...units import ratio_unit
from ..scaling import unit_scale
from ..regression import hac_covariance

__all__ = ["Pulse", "BreakawayResult", "detect_breakaway", "ConstantVelocityPoint",
           "constant_velocity_friction", "table_from_points", "StribeckFit", "fit_stribeck",
           "IdimResult", "IdimSamples", "idim_samples", "idim_ls", "idim_units"]


def _same_length(**named) -> list[np.ndarray]:
    """The named sequences as finite 1-D float arrays of one length (DataError otherwise)."""
    arrays = [np.asarray(a, dtype=np.float64) for a in named.values()]
    shapes = [a.shape for a in arrays]
    if any(a.ndim != 1 for a in arrays) or len(set(shapes)) != 1:
        raise DataError(f"{', '.join(named)}: expected 1-D arrays of equal length, found "
                        f"{', '.join(map(str, shapes))}")
    for name, a in zip(named, arrays):
        bad = ~np.isfinite(a)
        if bad.any():
            raise DataError(f"{name} has {int(bad.sum())} non-finite values (first at sample "
                            f"{int(np.argmax(bad))})")
    return arrays


# --- stiction -----------------------------------------------------------------------------------

@dataclass(frozen=True)
class Pulse:
    """One PWM pulse of a breakaway test."""

    start: int
    stop: int
    pwm: float
    moved: bool
    position: float  # at the pulse start
    moving_samples: int


@dataclass(frozen=True)
class BreakawayResult:
    """Result of :func:`detect_breakaway`.

    ``breakaway`` holds one row per series: position at the first moving pulse, its PWM (the
    thesis's Table 6.1 value), the last still PWM before it, and the stiction torque estimate
    (midpoint) with its quantisation std, when a motor model was given.
    """

    pulses: tuple[Pulse, ...]
    breakaway: tuple[dict, ...]
    stiction: float | None = None
    stiction_std: float | None = None
    pwm_mean: float | None = None

    def table(self) -> list[list]:
        return [[b["position"], b["pwm"], b["pwm_still"], b.get("torque")] for b in self.breakaway]


def _pulses(pwm: np.ndarray) -> list[tuple[int, int]]:
    on = pwm != 0
    d = np.diff(on.astype(np.int8))
    starts = list(np.flatnonzero(d == 1) + 1)
    stops = list(np.flatnonzero(d == -1) + 1)
    if on[0]:
        starts.insert(0, 0)
    if on[-1]:
        stops.append(len(pwm))
    return list(zip(starts, stops))


def detect_breakaway(pwm, velocity, position=None, *, velocity_threshold: float = 0.0,
                     min_moving_samples: int = 1,
                     torque_at: Callable[[float, float], float] | None = None) -> BreakawayResult:
    """Breakaway PWM of each series of increasing PWM pulses (§6.2, Appendix C).

    Parameters
    ----------
    pwm, velocity, position
        Logged PWM command, joint velocity (rad/s) and, optionally, joint position (rad), one
        value per sample.
    velocity_threshold
        A sample "moves" when |velocity| > threshold (Appendix C: ``~= 0``, i.e. 0).
    min_moving_samples
        A pulse moved the joint when more than this many samples moved (Appendix C: 1000 at its
        logging rate).
    torque_at
        ``torque_at(pwm, position)`` → joint torque (N·m) the motor exerts at zero speed minus any
        load at that position; when given, the stiction torque is estimated.
    """
    u, v, x = _same_length(pwm=pwm, velocity=velocity,
                           position=np.zeros(np.shape(pwm)) if position is None else position)
    pulses = []
    for a, b in _pulses(u):
        seg = u[a:b]
        if np.ptp(seg) != 0:
            raise DataError(f"pulse at samples {a}..{b} does not hold a constant PWM "
                            f"({seg.min():g}..{seg.max():g})", hint="give the raw command, "
                                                                    "one pulse per step")
        nmov = int((np.abs(v[a:b]) > velocity_threshold).sum())
        pulses.append(Pulse(a, b, float(seg[0]), nmov > min_moving_samples, float(x[a]), nmov))
    if not pulses:
        raise DataError("no PWM pulses found (the PWM column is zero everywhere)")
    rows = []
    prev = None
    found = False
    still = math.nan
    for pl in pulses:
        new_series = (prev is None or abs(pl.pwm) <= abs(prev.pwm)
                      or np.sign(pl.pwm) != np.sign(prev.pwm))
        if new_series:
            found = False
            still = math.nan
        if not found:
            if pl.moved:
                row = dict(position=pl.position, pwm=pl.pwm, pwm_still=still)
                if torque_at is not None:
                    lo = still if math.isfinite(still) else pl.pwm
                    t_hi = float(torque_at(pl.pwm, pl.position))
                    t_lo = float(torque_at(lo, pl.position))
                    row["torque"] = 0.5 * (t_hi + t_lo)
                    row["torque_std"] = abs(t_hi - t_lo) / math.sqrt(12.0)
                rows.append(row)
                found = True
            else:
                still = pl.pwm
        prev = pl
    if not rows:
        raise IdentificationError("no pulse moved the joint: the PWM never exceeded stiction",
                                  hint="extend the PWM ramp or lower velocity_threshold")
    stiction = stiction_std = None
    pwm_mean = float(np.mean([abs(r["pwm"]) for r in rows]))
    if torque_at is not None:
        t = np.array([abs(r["torque"]) for r in rows])
        q = np.array([r["torque_std"] for r in rows])
        stiction = float(t.mean())
        spread = t.std(ddof=1) if t.size > 1 else 0.0
        # std of the mean: scatter over positions and the (correlated) quantisation
        stiction_std = float(math.sqrt(spread ** 2 / t.size + np.mean(q) ** 2))
    return BreakawayResult(tuple(pulses), tuple(rows), stiction, stiction_std, pwm_mean)


# --- dynamic friction from constant-velocity runs -----------------------------------------------

@dataclass(frozen=True)
class ConstantVelocityPoint:
    pwm: float
    velocity: float
    velocity_std: float
    friction: float
    friction_std: float
    n_samples: int


def constant_velocity_friction(pwm, velocity, *, motor_torque: Callable[[float, float], float],
                               load: Callable[[int], float] | None = None,
                               inertia: float | None = None,
                               dt: float | None = None, plateau: float = 0.05,
                               min_samples: int = 10) -> list[ConstantVelocityPoint]:
    """One friction point per constant-PWM run (Appendix D).

    The plateau of each run is the set of samples whose velocity lies within ``plateau``
    (relative) of the run's peak speed; friction = ``motor_torque(pwm, v)`` − ``load(i)`` at the
    plateau's mean velocity. A short run (the joint reaches its end stop) may still be speeding up
    on its plateau: given the joint's ``inertia`` and the sample interval ``dt`` (s), the inertial
    torque
    J·a (a from a line fitted to the plateau's velocity) is subtracted too. The friction std
    propagates the plateau's velocity scatter through the motor's torque-speed slope.
    """
    u, v = _same_length(pwm=pwm, velocity=velocity)
    pts = []
    for a, b in _pulses(u):
        seg = v[a:b]
        peak = np.max(np.abs(seg))
        if peak == 0:
            continue
        sel = np.abs(seg) >= (1.0 - plateau) * peak
        if sel.sum() < min_samples:
            continue
        vv = seg[sel]
        vm = float(vv.mean())
        vs = float(vv.std(ddof=1) / math.sqrt(vv.size)) if vv.size > 1 else 0.0
        tau = float(motor_torque(u[a], vm))
        dv = max(abs(vm) * 1e-6, 1e-9)
        slope = (float(motor_torque(u[a], vm + dv)) - float(motor_torque(u[a], vm - dv))) / (2 * dv)
        ld = (0.0 if load is None
              else float(np.mean([load(i) for i in range(a, b)][::max(1, (b - a) // 20)])))
        if inertia is not None:
            if dt is None:
                raise DataError("constant_velocity_friction: give dt (the sample interval in "
                                "s) with inertia")
            idx = np.flatnonzero(sel)
            acc = float(np.polyfit(idx * dt, vv, 1)[0]) if idx.size > 2 else 0.0
            ld += inertia * acc
        pts.append(ConstantVelocityPoint(float(u[a]), vm, vs, tau - ld, abs(slope) * vs,
                                         int(sel.sum())))
    if len(pts) < 2:
        raise IdentificationError(f"only {len(pts)} constant-PWM runs reached a plateau",
                                  hint="log longer runs, or lower min_samples")
    return pts


def table_from_points(points: Sequence[ConstantVelocityPoint],
                      name: str = "identified friction") -> FrictionTable:
    """A lookup table (§6.3) from constant-velocity points, sorted by velocity; points at equal
    velocity are averaged."""
    v = np.array([p.velocity for p in points])
    f = np.array([p.friction for p in points])
    order = np.argsort(v)
    v, f = v[order], f[order]
    uv, inv = np.unique(v, return_inverse=True)
    uf = np.bincount(inv, weights=f) / np.bincount(inv)
    return FrictionTable(uv, uf, name=name, source="identified from constant-velocity runs")


@dataclass(frozen=True)
class StribeckFit:
    """Result of :func:`fit_stribeck`: parameter values and standard deviations (SI), the
    covariance over the free ones, residual RMS (N·m)."""

    values: dict
    std: dict
    free: tuple[str, ...]
    covariance: np.ndarray
    rms: float
    n: int

    def __call__(self, v) -> np.ndarray:
        p = self.values
        v = np.asarray(v, dtype=np.float64)
        mag = p["fc"] + (p["fs"] - p["fc"]) * np.exp(-np.abs(v / p["vs"]) ** p["delta"])
        return np.where(v == 0, 0.0, np.sign(v) * mag + p["sigma"] * v + p["cubic"] * v ** 3)


_STRIBECK = ("fc", "fs", "vs", "delta", "sigma", "cubic")


def fit_stribeck(velocity, friction, *, weights=None, fixed: dict | None = None,
                 initial: dict | None = None) -> StribeckFit:
    """Fit F(v) = sign(v)(F_c + (F_s − F_c) e^{−|v/v_s|^δ}) + σ v + σ₃ v³ (eq 6.5 plus the cubic
    term of [50]) by nonlinear least squares.

    ``fixed`` holds parameters known from elsewhere (e.g. ``fs`` from a breakaway test; ``vs`` and
    ``delta`` when the data hold no low-velocity points — constant-velocity tables rarely do);
    ``weights`` are per-point 1/σ. Raises :class:`UnidentifiableError` when the data do not
    determine the free parameters (and names them).
    """
    from scipy.optimize import least_squares

    v, f = _same_length(velocity=velocity, friction=friction)
    if (v == 0).any():
        raise DataError("friction at zero velocity is stiction, not kinetic friction; "
                        "drop those points")
    fixed = dict(fixed or {})
    unknown = set(fixed) - set(_STRIBECK)
    if unknown:
        raise DataError(f"fixed: unknown parameters {sorted(unknown)}; known: {_STRIBECK}")
    lo_mag = float(np.min(np.abs(f)))
    start = dict(fc=0.8 * lo_mag, fs=1.2 * lo_mag, vs=0.1 * float(np.max(np.abs(v))), delta=2.0,
                 sigma=0.0, cubic=0.0)
    start.update(initial or {})
    start.update(fixed)
    free = tuple(n for n in _STRIBECK if n not in fixed)
    if v.size <= len(free):
        raise DataError(f"{v.size} points cannot determine {len(free)} parameters {free}")
    w = np.ones_like(v) if weights is None else np.asarray(weights, dtype=np.float64)
    vmax = float(np.max(np.abs(v)))
    # a scale-free problem (scipy's gtol on Jᵀr is absolute: friction of ~1e-6 N used to end the
    # fit at its start): z = θ/scale, each parameter's start floored at 1e-3 of its natural size
    # in the data's units (F = 1/cf a power of two of the size of |f|, vmax), and the residual
    # times the power of two cr that brings (f·w) to unit size (exact)
    cf, cr = unit_scale(f), unit_scale(f * w)
    size = dict(fc=1 / cf, fs=1 / cf, vs=vmax, delta=1.0, sigma=1 / cf / vmax,
                cubic=1 / cf / vmax ** 3)
    scale = np.array([max(abs(start[n]), 1e-3 * size[n]) for n in free])

    def unpack(z):
        p = dict(start)
        p.update(dict(zip(free, z * scale)))
        return p

    def model(p):
        mag = p["fc"] + (p["fs"] - p["fc"]) * np.exp(-np.abs(v / p["vs"]) ** p["delta"])
        return np.sign(v) * mag + p["sigma"] * v + p["cubic"] * v ** 3

    lb = {"fc": 0.0, "fs": 0.0, "vs": 1e-6 * vmax, "delta": 0.2, "sigma": -np.inf, "cubic": -np.inf}
    ub = ({"fc": np.inf, "fs": np.inf, "vs": 10 * vmax, "delta": 10.0, "sigma": np.inf,
           "cubic": np.inf})
    res = least_squares(lambda z: (model(unpack(z)) - f) * w * cr,
                        np.array([start[n] for n in free]) / scale,
                        bounds=(np.array([lb[n] for n in free]) / scale,
                                np.array([ub[n] for n in free]) / scale),
                        x_scale="jac")
    res.fun, res.jac = res.fun / cr, res.jac / cr
    p = {k: float(val) for k, val in unpack(res.x).items()}
    J = res.jac / scale  # d r / d θ
    dof = v.size - len(free)
    s2 = float(np.sum(res.fun ** 2) / dof)
    U, sv, Vt = np.linalg.svd(J * scale, full_matrices=False)
    if sv[-1] < 1e-10 * sv[0]:
        null = Vt[-1]
        names = [free[i] for i in np.argsort(-np.abs(null))[:2]]
        raise UnidentifiableError(f"the data do not determine {' and '.join(names)} (singular "
                                  f"Jacobian, condition {sv[0] / max(sv[-1], 1e-300):.3g})",
                                  hint="fix one of them (fixed={...}) or add low-velocity points")
    cov = s2 * np.linalg.inv(J.T @ J)
    std = {n: float(math.sqrt(max(cov[i, i], 0.0))) for i, n in enumerate(free)}
    std.update({n: 0.0 for n in fixed})
    rms = float(np.sqrt(np.mean((model(p) - f) ** 2)))
    return StribeckFit(p, std, free, cov, rms, int(v.size))


# --- IDIM-LS ------------------------------------------------------------------------------------

@dataclass(frozen=True)
class IdimResult:
    """Single-axis IDIM-LS result: ``params`` and ``std`` hold ``inertia`` (kg·m² or kg),
    ``viscous`` (N·m·s/rad or N·s/m), ``coulomb`` and ``offset`` (N·m or N); ``units`` the unit
    of each (:func:`idim_units` of the position and effort units given to :func:`idim_ls`; empty
    when none were given). ``str()`` is a table of value ± σ and unit."""

    params: dict
    std: dict
    covariance: np.ndarray
    relative_error_percent: float
    n_samples: int
    dt: float
    cutoff: float
    decimation: int
    condition_number: float
    residual_std: float
    notes: list = field(default_factory=list)
    units: dict = field(default_factory=dict)

    def __str__(self) -> str:
        rows = [f"IDIM-LS: {self.n_samples} samples, relative error "
                f"{self.relative_error_percent:.2f} %"]
        rows += [f"  {k:<8} {self.params[k]:12.6g} ± {self.std[k]:<9.2g} "
                 f"{self.units.get(k, '')}".rstrip() for k in _IDIM]
        if not self.units:
            rows.append("  (units unknown: give idim_ls position_unit= and effort_unit=)")
        return "\n".join(rows + [f"note: {n}" for n in self.notes])

    def to_dict(self) -> dict:
        return dict(params=self.params, std=self.std, units=dict(self.units),
                    relative_error_percent=self.relative_error_percent,
                    n_samples=self.n_samples, dt=self.dt, cutoff_hz=self.cutoff,
                    decimation=self.decimation,
                    condition_number=self.condition_number, residual_std=self.residual_std,
                    covariance=self.covariance.tolist(), notes=list(self.notes))


_IDIM = ("inertia", "viscous", "coulomb", "offset")


def idim_units(position: str | None, effort: str | None, scale: float = 1.0) -> dict[str, str]:
    """Units of IDIM-LS's parameters from the position and effort units: inertia effort·s²/position,
    viscous effort·s/position, Coulomb and offset in effort units, where the effort is
    ``scale × effort`` (a factor other than 1 leads the effort unit: ``0.5 A``). A '1' (no unit)
    drops out of products and quotients: 'N*m*s^2/rad', 's^2' rather than '(1)*s^2/1'.

    Examples
    --------
    >>> idim_units("m", "N")
    {'inertia': '(N*s^2)/m', 'viscous': '(N*s)/m', 'coulomb': 'N', 'offset': 'N'}
    """
    def times(a: str, b: str) -> str:
        a, b = a or "1", b or "1"
        return b if a == "1" else a if b == "1" else f"{a}*{b}"

    eu = effort or "1"
    if scale != 1.0:
        eu = f"{scale:g}" if eu == "1" else f"{scale:g} {eu}"
    return {"inertia": ratio_unit(times(eu, "s^2"), position or "1"),
            "viscous": ratio_unit(times(eu, "s"), position or "1"), "coulomb": eu, "offset": eu}


@dataclass(frozen=True)
class IdimSamples:
    """Filtered, differentiated and decimated samples for inverse-dynamics least squares (columns:
    joints). ``near_reversal`` marks the samples within the guard band of a velocity reversal of
    that joint, where the filtered Coulomb step does not follow sign(q̇)."""

    position: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    effort: np.ndarray
    near_reversal: np.ndarray
    dt: float
    cutoff: float
    decimation: int
    notes: tuple


def idim_samples(position, effort, *, dt: float, cutoff: float | None = None, order: int = 4,
                 decimation: int | None = None, guard: float = 1.0) -> IdimSamples:
    """The signal chain of IDIM-LS (module doc), for one joint (1-D arrays) or several ((N, m)
    arrays): the same zero-phase Butterworth filter on position and effort, q̇ and q̈ by central
    differences, the filter's edge transients cut, decimation by ``decimation`` (default: the
    largest q with 1/(2q·dt) ≥ 2.5·cutoff), and the guard bands (``guard/cutoff`` s) around every
    velocity reversal marked."""
    x = np.asarray(position, dtype=np.float64)
    e = np.asarray(effort, dtype=np.float64)
    x = x[:, None] if x.ndim == 1 else x
    e = e[:, None] if e.ndim == 1 else e
    if x.ndim != 2 or x.shape != e.shape:
        raise DataError(f"position and effort: expected arrays of one shape (N,) or (N, m), found "
                        f"{np.shape(position)} and {np.shape(effort)}")
    rate = 1.0 / sample_interval(dt)
    cutoff = rate / 50.0 if cutoff is None else float(cutoff)
    if not 0 < cutoff < rate / 2:
        raise DataError(f"cutoff {cutoff:g} Hz must lie between 0 and the Nyquist frequency "
                        f"{rate / 2:g} Hz")
    q = decimation if decimation is not None else max(1, int(rate / (2 * 2.5 * cutoff)))
    if int(q) != q or q < 1:
        raise DataError(f"decimation: expected a positive integer, found {decimation!r}")
    q = int(q)
    notes = []
    if rate / (2 * q) < cutoff:
        notes.append(f"decimation {q} puts the new Nyquist frequency "
                     f"{rate / (2 * q):g} Hz below the "
                     f"cutoff {cutoff:g} Hz: the decimated rows alias")
    n = x.shape[0]
    edge = int(math.ceil(3 * rate / cutoff))
    if n < 2 * edge + 50 * q:
        raise DataError(f"{n} samples are too few for IDIM-LS at dt = {dt:g} s with "
                        f"a {cutoff:g} Hz "
                        f"filter (need more than {2 * edge + 50 * q})", hint="log a longer run")
    sos = butter_sos(order, cutoff, dt=dt)
    xf = apply_sos(sos, x, zero_phase=True)
    ef = apply_sos(sos, e, zero_phase=True)
    vel = np.gradient(xf, dt, axis=0)
    acc = np.gradient(vel, dt, axis=0)
    # the filter smears the friction step of each velocity reversal over ~1/cutoff: those samples
    # do not obey the sign(q̇) model of the filtered signals
    near = np.zeros(x.shape, dtype=bool)
    g = int(math.ceil(guard * rate / cutoff))
    for j in range(x.shape[1]):
        rev = np.flatnonzero(np.sign(vel[1:, j]) != np.sign(vel[:-1, j]))
        if rev.size and g > 0:
            lo = np.clip(rev - g, 0, n)
            hi = np.clip(rev + g + 1, 0, n)
            cover = np.zeros(n + 1, dtype=np.int64)
            np.add.at(cover, lo, 1)
            np.add.at(cover, hi, -1)
            near[:, j] = np.cumsum(cover[:-1]) > 0
    sl = slice(edge, n - edge, q)
    return (IdimSamples(xf[sl], vel[sl], acc[sl], ef[sl], near[sl], float(dt), cutoff, q,
                        tuple(notes)))


#: what to do instead of a non-positive effort scale (the CLI's --effort-scale too)
EFFORT_SCALE_HINT = ("give its magnitude (e.g. k_t·N for a current); for an effort column whose "
                     "sign is opposite to the position's, negate that column in the file")


def check_effort_scale(value, name: str = "effort scale") -> None:
    """The effort factor K (effort = K × column): finite and positive, else a DataError naming
    ``name`` (the argument or CLI option); a negative K would turn the efforts' sign (negative
    inertia and friction, units like '(-1 N*s^2)/m')."""
    if not (np.isfinite(value) and value > 0):
        turned = (" (a negative one turns the efforts' sign: negative inertia and friction)"
                  if value < 0 else "")
        raise DataError(f"{name}: expected a finite positive factor, found {value!r}{turned}",
                        hint=EFFORT_SCALE_HINT)


@entry_point
def idim_ls(position, effort, *, dt: float, effort_scale: float = 1.0, cutoff: float | None = None,
            order: int = 4, decimation: int | None = None,
            velocity_threshold: float | None = None, guard: float = 1.0,
            position_unit: str | None = None, effort_unit: str | None = None) -> IdimResult:
    """Identify τ = J q̈ + F_v q̇ + F_c sign(q̇) + τ₀ from position and effort logs (module doc).
    With ``position_unit`` and ``effort_unit`` (the columns' units, e.g. 'm' and 'N'; the effort
    column's unit before ``effort_scale``) the result carries its parameters' units
    (:func:`idim_units`).

    Parameters
    ----------
    position
        Joint position samples (rad, or m), one sample every ``dt`` s.
    effort
        Effort column; the effort is ``effort_scale × effort`` (e.g. a current in A times the
        torque constant and gear ratio, or a PWM count times N·m per count).
    cutoff
        Low-pass cutoff (Hz) of the zero-phase Butterworth filter; default 1/(50 dt) (20 Hz at 1
        kHz).
        Choose 5–10 times the bandwidth of the motion: higher lets the position noise into q̈.
    order
        Filter order (the zero-phase filter has twice this order).
    decimation
        Keep every q-th filtered sample; default the largest q with 1/(2q·dt) ≥ 2.5·cutoff.
    velocity_threshold
        Drop samples with |q̇| below it; default 2 % of the largest |q̇|.
    guard
        Also drop the samples within ``guard/cutoff`` seconds of a velocity reversal, where the
        filtered Coulomb step does not follow sign(q̇).
    """
    x, e = _same_length(position=position, effort=effort)
    check_effort_scale(effort_scale)
    # work at unit size (exact powers of two: data at any scale); q' = cx·q, τ' = ce·τ give
    # J' = J·ce/cx, F_v' = F_v·ce/cx, F_c' = F_c·ce, τ₀' = τ₀·ce, mapped back at the end
    cx, ce = unit_scale(x), unit_scale(e * effort_scale)
    x, e = x * cx, e * ce
    if velocity_threshold is not None:
        velocity_threshold = float(velocity_threshold) * cx
    st = (idim_samples(x, e * effort_scale, dt=dt, cutoff=cutoff, order=order,
                       decimation=decimation, guard=guard))
    vel, acc, y, near = (st.velocity[:, 0], st.acceleration[:, 0], st.effort[:, 0],
                         st.near_reversal[:, 0])
    cutoff, q, notes = st.cutoff, st.decimation, list(st.notes)
    vmax = float(np.max(np.abs(vel)))
    if vmax == 0:
        raise UnidentifiableError("the position never changes: the data cannot identify "
                                  "friction or inertia")
    thr = 0.02 * vmax if velocity_threshold is None else float(velocity_threshold)
    keep = (np.abs(vel) > thr) & ~near
    if keep.sum() < 20:
        raise UnidentifiableError(f"only {int(keep.sum())} samples move faster than {thr / cx:.3g}",
                                  hint="excite the joint more, or lower --velocity-threshold")
    vel, acc, y = vel[keep], acc[keep], y[keep]
    if (vel > 0).all() or (vel < 0).all():
        raise UnidentifiableError("the joint moves in one direction only: Coulomb friction and the "
                                  "offset cannot be told apart", hint="excite both directions")
    hi, lo = float(np.max(e)), float(np.min(e))
    if hi - lo <= 1e-12 * max(hi, -lo):  # relative: efforts at any scale
        level = "zero" if hi == lo == 0 else f"constant ({hi / ce:.6g})"
        raise UnidentifiableError(
            f"the effort is {level} for all {e.size} samples: it carries no information about "
            f"inertia or friction (every parameter would come out as "
            f"{'0 ± 0' if hi == lo == 0 else 'an offset'}); no estimate returned",
            hint="check that the effort column is the logged torque, force or motor current")
    X = np.column_stack([acc, vel, np.sign(vel), np.ones_like(vel)])
    colscale = np.sqrt(np.mean(X ** 2, axis=0))
    if (colscale == 0).any():
        raise UnidentifiableError("a regressor column is zero (no acceleration or no motion)")
    Xs = X / colscale
    sv = np.linalg.svd(Xs, compute_uv=False)
    cond = float(sv[0] / max(sv[-1], 1e-300))
    if cond > 1e8:
        raise UnidentifiableError("the regressor is ill-conditioned (condition number "
                                  f"{cond:.3g}): the "
                                  f"motion does not separate inertia, viscous and Coulomb friction",
                                  hint="use a richer excitation (several frequencies, "
                                       "both directions)")
    theta_s, *_ = np.linalg.lstsq(Xs, y, rcond=None)
    theta = theta_s / colscale
    r = y - X @ theta
    n = y.size
    s2 = float(r @ r / (n - 4))
    # filtering, differentiation and decimation leave the residuals autocorrelated: the
    # Newey-West covariance, not s²(XᵀX)⁻¹ (which would understate σ)

    cov = hac_covariance(X, r)
    std = np.sqrt(np.diag(cov))
    rel = float(100.0 * np.linalg.norm(r) / max(np.linalg.norm(y), 1e-300))
    if cond > 1e4:
        notes.append(f"regressor condition number {cond:.3g}: weak excitation")
    d = np.array([cx / ce, cx / ce, 1.0 / ce, 1.0 / ce])  # back to the data's units
    with np.errstate(over="ignore", under="ignore"):
        theta, std, cov = theta * d, std * d, cov * d[:, None] * d[None, :]
    return IdimResult(dict(zip(_IDIM, map(float, theta))), dict(zip(_IDIM, map(float, std))), cov,
                      rel, int(n), float(dt), float(cutoff), q, cond, float(math.sqrt(s2)) / ce,
                      notes, _result_units(position_unit, effort_unit, effort_scale))


def _result_units(position_unit, effort_unit, effort_scale) -> dict:
    """:func:`idim_units` where a unit was given, else none."""
    for name, u in (("position_unit", position_unit), ("effort_unit", effort_unit)):
        if u is not None and not isinstance(u, str):
            raise ArgumentError(f"idim_ls {name}: expected a unit string such as 'm' or 'N', "
                                f"found {type(u).__name__}")
    if position_unit is None and effort_unit is None:
        return {}
    return idim_units(position_unit, effort_unit, effort_scale)
