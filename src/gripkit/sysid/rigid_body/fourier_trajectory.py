"""Optimal excitation trajectories for multi-joint dynamics identification (Swevers, Ganseman,
Tükel, De Schutter & Van Brussel, "Optimal robot excitation and identification", IEEE T-RA 13(5),
1997): every joint follows a finite Fourier series of base frequency f₀,

    q_j(t) = q0_j + Σ_{l=1..H} [ a_jl/(ω_f l)·sin(ω_f l t) − b_jl/(ω_f l)·cos(ω_f l t) ],
    ω_f = 2π f₀,
    q̇_j(t) = Σ_l [ a_jl cos(ω_f l t) + b_jl sin(ω_f l t) ],
    q̈_j(t) = Σ_l ω_f l [ −a_jl sin(ω_f l t) + b_jl cos(ω_f l t) ],

periodic (so periods can be averaged), and the coefficients minimise the condition number of the
identification regressor — the base-parameter columns of ``chain.regressor`` plus the Coulomb and
viscous friction columns, each column scaled to unit RMS — over one period. The limits are kept
by the conservative bounds (c_jl = √(a_jl² + b_jl²))

    |q_j − q0_j| ≤ Σ_l c_jl/(ω_f l),   |q̇_j| ≤ Σ_l c_jl,   |q̈_j| ≤ Σ_l ω_f l·c_jl,

so the trajectory stays inside the position, velocity and acceleration limits at every instant,
not only at the samples. The chain is any object with ``regressor``, ``dof``,
``coordinate_names``, ``parameter_names`` (and optionally ``limits``): this module does not import
:mod:`gripkit.multibody`.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...arguments import entry_point
from ...atomic import atomic_write
from ...errors import ConfigError, DataError, IdentificationError
from ...progress import status, track
from .dynamics import base_structure, friction_columns

__all__ = ["FourierTrajectory", "fourier_trajectory", "fourier_states"]


def fourier_states(a, b, q0, f0: float, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """q, q̇, q̈ (N, m) of the Fourier series (module doc) with coefficients a, b (m, H)."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    t = np.asarray(t, dtype=np.float64)
    H = a.shape[1]
    w = 2 * math.pi * f0 * np.arange(1, H + 1)
    s = np.sin(np.outer(t, w))
    c = np.cos(np.outer(t, w))
    q = np.asarray(q0, dtype=np.float64) + s @ (a / w).T - c @ (b / w).T
    qd = c @ a.T + s @ b.T
    qdd = -s @ (a * w).T + c @ (b * w).T
    return q, qd, qdd


@dataclass(frozen=True)
class FourierTrajectory:
    """A designed excitation: time ``t`` (s), ``q``, ``qd``, ``qdd`` (N, m) in the chain's
    coordinates ``joint_names``; coefficients ``a``, ``b`` (m, H), centre ``q0``, base frequency
    ``f0`` (Hz); ``condition_number`` of the scaled identification regressor over one period, and
    the ``limits`` that hold (position lower/upper, velocity, acceleration per joint)."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    a: np.ndarray
    b: np.ndarray
    q0: np.ndarray
    f0: float
    dt: float
    joint_names: tuple
    condition_number: float
    initial_condition_number: float
    limits: dict
    info: dict = field(default_factory=dict)

    def columns(self) -> dict:
        """``{'t': ..., 'q_<joint>': ..., 'qd_<joint>': ..., 'qdd_<joint>': ...}``."""
        out = {"t": self.t}
        for prefix, x in (("q", self.q), ("qd", self.qd), ("qdd", self.qdd)):
            for j, name in enumerate(self.joint_names):
                out[f"{prefix}_{name}"] = x[:, j]
        return out

    def to_csv(self, path) -> Path:
        """Write :meth:`columns` as CSV (header row, SI units: s, rad or m, per s, per s²)."""
        cols = self.columns()
        path = Path(path)
        data = np.column_stack(list(cols.values()))
        header = ",".join(cols)
        atomic_write(path, lambda tmp: np.savetxt(tmp, data, delimiter=",", header=header,
                                                  comments="", fmt="%.10g"),
                     what="excitation trajectory")
        return path

    def to_dict(self) -> dict:
        return dict(f0_hz=self.f0, dt_s=self.dt, harmonics=int(self.a.shape[1]),
                    joints=list(self.joint_names),
                    q0=self.q0.tolist(), a=self.a.tolist(), b=self.b.tolist(),
                    n_samples=int(self.t.size),
                    duration_s=float(self.t.size * self.dt), condition_number=self.condition_number,
                    initial_condition_number=self.initial_condition_number,
                    limits={k: np.asarray(v).tolist() for k, v in self.limits.items()},
                    info=self.info)


def _limit(name, given, from_chain, m, default):
    v = given if given is not None else from_chain
    if v is None:
        v = default
    v = np.broadcast_to(np.asarray(v, dtype=np.float64), (m,)).copy()
    if np.isnan(v).any() or (v <= 0).any():
        raise DataError(f"{name}: expected positive limits for the {m} joints, found {v.tolist()}")
    return v


def _check_design(f0: float, dt: float, harmonics, periods) -> None:
    """DataError unless f0 > 0, dt > 0 samples the highest harmonic above twice its frequency, and
    ``harmonics`` and ``periods`` are positive integers."""
    if not (math.isfinite(f0) and f0 > 0) or not (math.isfinite(dt) and dt > 0 and 1.0 / dt > 2
                                                  * f0 * harmonics):
        raise DataError(f"f0 = {f0!r} Hz and dt = {dt!r} s: need f0 > 0 and a sampling rate 1/dt "
                        "above twice the "
                        f"highest harmonic {f0 * harmonics:g} Hz")
    if int(harmonics) != harmonics or harmonics < 1 or int(periods) != periods or periods < 1:
        raise DataError("harmonics and periods: expected positive integers, found "
                        f"{harmonics!r}, {periods!r}")


def _position_limits(position_limits, chain_limits, m: int) -> tuple[np.ndarray, np.ndarray]:
    """(lower, upper) per joint: ``position_limits`` broadcast, else the chain's finite limits,
    else ±π/2; finite with lower < upper."""
    lo_c = getattr(chain_limits, "lower", None)
    hi_c = getattr(chain_limits, "upper", None)
    if position_limits is not None:
        lo = np.broadcast_to(np.asarray(position_limits[0], dtype=np.float64), (m,)).copy()
        hi = np.broadcast_to(np.asarray(position_limits[1], dtype=np.float64), (m,)).copy()
    else:
        lo = (np.where(np.isfinite(lo_c), lo_c,
                       -math.pi / 2) if lo_c is not None else np.full(m, -math.pi / 2))
        hi = (np.where(np.isfinite(hi_c), hi_c,
                       math.pi / 2) if hi_c is not None else np.full(m, math.pi / 2))
    if not (np.isfinite(lo).all() and np.isfinite(hi).all() and (hi > lo).all()):
        raise DataError("position_limits: expected finite lower < upper per joint, found "
                        f"{lo.tolist()}, {hi.tolist()}")
    return lo, hi


class _Design:
    """The optimisation problem of the module doc over x = [a, b] (2·m·H): the objective
    log10 cond of the scaled regressor over one period (1e3 when a column is never excited),
    the margins of the conservative bounds (≥ 0 inside the limits), random feasible starts and
    the projection of a solution back inside the bounds."""

    def __init__(self, chain, st, q0, half, vmax, amax, f0: float, H: int, friction: bool,
                 samples_per_period: int):
        self.chain, self.st, self.q0, self.f0, self.H, self.friction = (chain, st, q0, f0, H,
                                                                        friction)
        self.half, self.vmax, self.amax = half, vmax, amax
        self.m = q0.size
        self.w = 2 * math.pi * f0 * np.arange(1, H + 1)
        self.t_eval = np.arange(samples_per_period) / (samples_per_period * f0)

    def unpack(self, x):
        m, H = self.m, self.H
        return x[:m * H].reshape(m, H), x[m * H:].reshape(m, H)

    def objective(self, x):
        a, b = self.unpack(x)
        q, qd, qdd = fourier_states(a, b, self.q0, self.f0, self.t_eval)
        X = self.chain.regressor(q, qd, qdd)[:, :, self.st.independent]
        if self.friction:
            X = np.concatenate([X, friction_columns(qd, ("coulomb", "viscous"))], axis=2)
        X = X.reshape(-1, X.shape[2])
        s = np.sqrt(np.mean(X ** 2, axis=0))
        if (s == 0).any():
            return 1e3
        sv = np.linalg.svd(X / s, compute_uv=False)
        return float(np.log10(sv[0] / max(sv[-1], 1e-300)))

    def bounds_margin(self, x):
        a, b = self.unpack(x)
        c = np.sqrt(a ** 2 + b ** 2 + 1e-30)
        return (np.concatenate([self.half - c @ (1 / self.w), self.vmax - c.sum(axis=1),
                                self.amax - c @ self.w]))

    def _joint_factors(self, c):
        """Per joint, the factor that scales amplitudes c (m, H) onto the tightest bound."""
        w = self.w
        return (np.min(np.column_stack([self.half / (c @ (1 / w)), self.vmax / c.sum(axis=1),
                                        self.amax / (c @ w)]), axis=1))

    def start(self, rng):
        """Random coefficients, each joint scaled into its limits with a margin (80 %)."""
        a = rng.normal(size=(self.m, self.H))
        b = rng.normal(size=(self.m, self.H))
        k = self._joint_factors(np.sqrt(a ** 2 + b ** 2)) * 0.8
        return np.concatenate([(a * k[:, None]).ravel(), (b * k[:, None]).ravel()])

    def shrink(self, x):
        """Scale each joint's coefficients back inside its bounds (SLSQP may end just outside)."""
        a, b = self.unpack(x)
        with np.errstate(divide="ignore"):
            k = self._joint_factors(np.sqrt(a ** 2 + b ** 2))
        k = np.minimum(1.0, k * (1 - 1e-9))[:, None]
        return np.concatenate([(a * k).ravel(), (b * k).ravel()])


#: the design time (s, estimated up front) above which a design is refused unless the caller
#: raises ``time_limit`` (CLI ``--time-limit``)
TIME_LIMIT = 1800.0
#: a floating-point rate no single machine exceeds on these dense SVDs and QRs (flop/s): a design
#: whose operation count alone gives more than the limit at this rate is refused before any work
_FAST_FLOPS = 1e11
#: a design estimated above this many seconds shows its progress on stderr
_SHOW_PROGRESS_S = 10.0
#: seconds between two iteration lines of a design that shows its progress
_PROGRESS_EVERY_S = 10.0


def _check_counts(seed, restarts, max_iterations, samples_per_period) -> None:
    """DataError unless the seed and the counts are non-negative (positive) integers."""
    for name, v, lo in (("seed", seed, 0), ("restarts", restarts, 0),
                        ("max_iterations", max_iterations, 1),
                        ("samples_per_period", samples_per_period, 8)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < lo:
            raise DataError(f"{name}: expected an integer >= {lo}, found {v!r}",
                            hint="the seed of the random starts is 0, 1, 2, ... (numpy's generator "
                                 "takes no negative seed)" if name == "seed" else "")


def _evaluations(m: int, H: int, restarts: int, max_iterations: int) -> int:
    """Objective evaluations of the design at most: SLSQP's finite-difference gradient costs
    2·m·H + 1 evaluations per iteration, its line search about one more."""
    return (1 + int(restarts)) * (int(max_iterations) * (2 * m * H + 2) + 1)


def _refuse(what: str, estimate: str, limit: str, memory: bool = False) -> ConfigError:
    if memory:
        hint = ("design a sub-chain (--base-link/--tip-link) or sample the period more coarsely "
                "(Python: samples_per_period=)")
    else:
        hint = ("use fewer joints (a sub-chain: --base-link/--tip-link), fewer --harmonics or "
                "--restarts, fewer iterations (Python: max_iterations=), or raise the limit with "
                "--time-limit (Python: time_limit=)")
    return ConfigError(f"{what}: {estimate}, above {limit}", hint=hint)


def _time_limit(time_limit) -> float:
    """Seconds > 0 (math.inf: no limit); None: :data:`TIME_LIMIT`."""
    if time_limit is None:
        return TIME_LIMIT
    try:
        limit = float(time_limit)
    except (TypeError, ValueError):
        limit = math.nan
    if not limit > 0:
        raise DataError(f"time_limit (CLI --time-limit): expected seconds > 0 (or math.inf), "
                        f"found {time_limit!r}")
    return limit


def _what(chain_name: str, m: int, H: int, restarts: int) -> str:
    return (f"excitation design of {chain_name} ({m} joints, {2 * m * H} coefficients, "
            f"{1 + restarts:,} start{'s' if restarts else ''})")


def _precheck(chain_name: str, m: int, p: int, H: int, restarts: int, max_iterations: int,
              samples_per_period: int, time_limit: float) -> None:
    """Refuse, before any work, a design whose memory or operation count cannot fit: the
    regressor over one period (samples_per_period·m rows, p + 2m columns, three copies) and the
    base-parameter QR (B·m rows, p columns, B = max(20, 4p/m + 10)); the SVD of each evaluation
    (rows·cols² flops) at :data:`_FAST_FLOPS`."""
    B = max(20, 4 * p // max(m, 1) + 10)
    rows, cols = samples_per_period * m, p + 2 * m
    need = 8 * 3 * (rows * cols + B * m * p)
    room = _memory_room()
    what = _what(chain_name, m, H, restarts)
    if need > room:
        raise _refuse(what, f"one evaluation of the regressor needs an estimated "
                            f"{need / 1e9:.3g} GB of memory",
                      f"the limit of {room / 1e9:.3g} GB (half the machine's memory)", memory=True)
    n_eval = _evaluations(m, H, restarts, max_iterations)
    flops = 4.0 * B * m * p ** 2 + n_eval * float(rows) * cols ** 2
    if flops / _FAST_FLOPS > time_limit:
        raise _refuse(what, f"an estimated {flops:.2g} floating-point operations take at least "
                            f"{_duration(flops / _FAST_FLOPS)} even at {_FAST_FLOPS:.0e} flop/s",
                      f"the time limit of {_duration(time_limit)}")


def _memory_room() -> int:
    """Bytes a design may use: half the machine's physical memory (no limit where the system
    does not say)."""
    try:
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE") // 2
    except (ValueError, OSError, AttributeError):
        return 2**62


def _duration(s: float) -> str:
    if s < 0.1:
        return f"{s * 1e3:.3g} ms"
    if s < 120:
        return f"{s:.3g} s"
    if s < 7200:
        return f"{s / 60:.3g} min"
    if s < 2 * 86400:
        return f"{s / 3600:.3g} h"
    return f"{s / 86400:.3g} days"


def _measured_estimate(design: "_Design", seed: int, restarts: int, max_iterations: int,
                       limit: float) -> tuple[float, float]:
    """(seconds of one objective evaluation, measured after a warm-up; seconds of the whole
    design at most). An estimate above ``limit`` is measured twice more and the fastest kept (a
    busy machine slows single calls). The starting point is drawn from its own generator: the
    design's draws are unchanged."""
    x = design.start(np.random.default_rng(seed))
    design.objective(x)  # compiles the regressor's kernels on first use
    n_eval = _evaluations(design.m, design.H, restarts, max_iterations)
    t_eval = math.inf
    for _ in range(3):
        t0 = time.perf_counter()
        design.objective(x)
        t_eval = min(t_eval, time.perf_counter() - t0)
        if t_eval * n_eval <= limit:
            break
    return t_eval, t_eval * n_eval


class _Progress:
    """SLSQP callback: a status line at most every 10 s (start, iteration, condition number)."""

    def __init__(self, design: "_Design", start: int, starts: int, max_iterations: int):
        self.design, self.start, self.starts = design, start, starts
        self.max_iterations = max_iterations
        self.t0 = self.last = time.perf_counter()
        self.k = 0

    def __call__(self, x, *args):
        self.k += 1
        now = time.perf_counter()
        if now - self.last >= _PROGRESS_EVERY_S:
            self.last = now
            status(f"  excitation design: start {self.start}/{self.starts}, iteration {self.k} "
                   f"of at most {self.max_iterations}, condition number "
                   f"{10 ** self.design.objective(x):.4g}, {now - self.t0:.0f} s")


def _best_design(design: _Design, restarts: int, max_iterations: int, seed: int,
                 progress: bool = False):
    """SLSQP from 1 + ``restarts`` random starts, each result kept only if it improves on its
    start; returns (log10 cond, x) of the best and the condition number of the first start.
    ``progress``: a line per ~10 % of the starts and an iteration line every 10 s on stderr."""
    from scipy.optimize import minimize

    rng = np.random.default_rng(seed)
    best = None
    first_cond = None
    starts = 1 + int(restarts)
    for k in track(range(starts), description="excitation design: starts",
                   enabled=progress and starts > 1):
        x0 = design.start(rng)
        f_start = design.objective(x0)
        first_cond = 10 ** f_start if first_cond is None else first_cond
        callback = _Progress(design, k + 1, starts, int(max_iterations)) if progress else None
        sol = minimize(design.objective, x0, method="SLSQP",
                       constraints=[{"type": "ineq", "fun": design.bounds_margin}],
                       options=dict(maxiter=int(max_iterations), ftol=1e-6), callback=callback)
        x = design.shrink(sol.x) if np.isfinite(sol.x).all() else x0
        f = design.objective(x)
        if f > f_start:
            x, f = x0, f_start
        if best is None or f < best[0]:
            best = (f, x)
    return best[0], best[1], first_cond


@entry_point
def fourier_trajectory(chain, *, f0: float = 0.1, harmonics: int = 5, dt: float = 0.01,
                       periods: int = 1,
                       position_limits=None, velocity_limits=None, acceleration_limits=None,
                       q0=None, friction: bool = True, samples_per_period: int = 200, seed: int = 0,
                       restarts: int = 0, max_iterations: int = 200,
                       time_limit: float | None = None) -> FourierTrajectory:
    """Design the excitation trajectory of ``chain`` (module doc).

    Parameters
    ----------
    chain
        Any object with ``regressor(q, qd, qdd)``, ``dof``, ``coordinate_names``,
        ``parameter_names`` (a gripkit chain); its ``limits`` (URDF) are the defaults.
    f0, harmonics
        Base frequency (Hz; the trajectory's period is 1/f0) and number of harmonics H.
    dt, periods
        Sample interval (s) and number of periods of the returned trajectory.
    position_limits
        (lower, upper), each scalar or (m,) (rad or m); default the chain's, else ±π/2.
    velocity_limits, acceleration_limits
        Per joint, > 0; default the chain's velocity limits, else 2 rad/s and 10 rad/s².
    q0
        Centre of the motion (default: the middle of the position limits).
    friction
        Include the Coulomb and viscous friction columns in the condition number.
    restarts
        Random starting points besides the first; the best design is kept.
    seed
        Seed (an integer >= 0) of the random starting points.
    time_limit
        Seconds the design may take at most, estimated before it starts (default
        :data:`TIME_LIMIT`, 30 min): first from the memory and the operation count of the
        regressor, then from one timed evaluation times the evaluations SLSQP may make. A
        larger design is refused (ConfigError with the estimate); one above 10 s shows its
        progress on stderr.
    """
    m = int(chain.dof)
    names = tuple(chain.coordinate_names)
    _check_design(f0, dt, harmonics, periods)
    _check_counts(seed, restarts, max_iterations, samples_per_period)
    limit = _time_limit(time_limit)
    H = int(harmonics)
    chain_name = getattr(chain, "name", "the chain")
    _precheck(chain_name, m, len(chain.parameter_names), H, int(restarts), int(max_iterations),
              int(samples_per_period), limit)
    lim = getattr(chain, "limits", None)
    lo, hi = _position_limits(position_limits, lim, m)
    v_c = getattr(lim, "velocity", None)
    vmax = (_limit("velocity_limits", velocity_limits,
                   None if v_c is None else np.where(np.isfinite(v_c), v_c, 2.0), m, 2.0))
    amax = _limit("acceleration_limits", acceleration_limits, None, m, 10.0)
    q0 = (0.5 * (lo + hi) if q0 is None else np.broadcast_to(np.asarray(q0, dtype=np.float64),
                                                             (m,)).copy())
    if ((q0 <= lo) | (q0 >= hi)).any():
        raise DataError(f"q0: the centre {q0.tolist()} must lie inside the position limits")
    st = base_structure(chain)
    design = (_Design(chain, st, q0, np.minimum(q0 - lo, hi - q0), vmax, amax, f0, H, friction,
                      samples_per_period))
    t_eval, t_max = _measured_estimate(design, int(seed), int(restarts), int(max_iterations), limit)
    n_eval = _evaluations(m, H, int(restarts), int(max_iterations))
    if t_max > limit:
        raise _refuse(_what(chain_name, m, H, int(restarts)),
                      f"up to {n_eval:,} evaluations of {_duration(t_eval)} each (measured) "
                      f"take up to {_duration(t_max)}", f"the time limit of {_duration(limit)}")
    progress = t_max > _SHOW_PROGRESS_S
    if progress:
        status(f"excitation design: up to {n_eval:,} evaluations of {_duration(t_eval)} each "
               f"(at most {_duration(t_max)}; usually far fewer)")
    f, x, first_cond = _best_design(design, restarts, max_iterations, seed, progress=progress)
    if not math.isfinite(f) or f >= 3:
        raise IdentificationError("no excitation found that excites every base parameter of "
                                  f"{getattr(chain, 'name', 'the chain')} "
                                  f"within the limits (best condition number {10 ** f:.3g})",
                                  hint="widen the limits, add harmonics or lower f0")
    a, b = design.unpack(x)
    t = np.arange(int(round(periods / (f0 * dt)))) * dt
    q, qd, qdd = fourier_states(a, b, q0, f0, t)
    return FourierTrajectory(t, q, qd, qdd, a, b, q0, float(f0), float(dt), names, float(10 ** f),
                             float(first_cond),
                             dict(lower=lo, upper=hi, velocity=vmax, acceleration=amax),
                             dict(n_base_parameters=int(st.independent.size),
                                  friction_columns=bool(friction),
                                  restarts=int(restarts), seed=int(seed)))
