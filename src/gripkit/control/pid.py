"""Discrete PID controller with setpoint weighting, a filtered derivative, back-calculation
anti-windup and bumpless transfer — usable from Python (:class:`PID`) and inside numba kernels
(:func:`pid_step`, :func:`pid_transfer` on plain float64 arrays).

At sample k, with setpoint r, measurement y and a feedforward term f (Åström & Hägglund, *Advanced
PID Control*, §13 "computer implementation"):

    P_k = K_p (b r_k − y_k)
    D_k = (T_f D_{k−1} + K_d (e_d,k − e_d,k−1)) / (T_f + Δt),     e_d = c r − y
          (backward-Euler discretisation of K_d s/(T_f s + 1); no kick on the first sample)
    v_k = P_k + I_k + D_k + f_k,      u_k = min(max(v_k, u_min), u_max)
    I_{k+1} = I_k + K_i Δt (r_k − y_k) + (Δt/T_t)(u_k − v_k)       (back-calculation)

The last term bleeds the integrator while the output is saturated, so it does not wind up (T_t is
the tracking time constant; defaults: √(T_i T_d) with a derivative, T_i = K_p/K_i without, Δt
for a pure integrator, which is integrator clamping). **Bumpless transfer**
(:meth:`PID.transfer`, :func:`pid_transfer`) sets the state so that the next step with the same
r, y, f returns a given u exactly: I = u − P − f, D = 0, e_d,prev = c r − y.

Linear region, b = c = 1 (:meth:`PID.transfer_function`):

    U(z)/E(z) = K_p + K_i Δt/(z − 1) + K_d (z − 1)/((T_f + Δt) z − T_f).

Array layouts (for kernels): parameters ``p`` = [K_p, K_i, K_d, T_f, b, c, T_t, u_min, u_max,
Δt] (``PID_NPARAM``); state ``s`` = [I, D, e_d,prev, started] (``PID_NSTATE``).
"""

from __future__ import annotations

import math
from collections import namedtuple

import numba
import numpy as np

from ..errors import ConfigError
from ..lti import TransferFunction

__all__ = ["PID", "pid_step", "pid_transfer", "pid_run", "PID_NPARAM", "PID_NSTATE"]

#: the parameter vector ``p`` of the kernels, in order, and its index table (``p[PIDX.dt]``, a
#: module-level namedtuple of ints generated from the names, which numba folds as constants)
PID_PARAMETERS = ("kp", "ki", "kd", "tf", "b", "c", "tt", "u_min", "u_max", "dt")
PIDX = namedtuple("PIDParameterIndex", PID_PARAMETERS)(*range(len(PID_PARAMETERS)))
#: the state vector ``s``: integral, filtered derivative, previous derivative error, started flag
PID_STATE = ("integral", "derivative", "error_prev", "started")
PIDS = namedtuple("PIDStateIndex", PID_STATE)(*range(len(PID_STATE)))
PID_NPARAM = len(PID_PARAMETERS)
PID_NSTATE = len(PID_STATE)


@numba.njit(cache=True)
def pid_step(p, s, r, y, ff):  # pragma: no cover - compiled
    """One PID sample: returns u_k and updates the state ``s`` in place (module docstring)."""
    kp = p[PIDX.kp]
    ki = p[PIDX.ki]
    kd = p[PIDX.kd]
    tf = p[PIDX.tf]
    dt = p[PIDX.dt]
    ed = p[PIDX.c] * r - y
    if s[PIDS.started] == 0.0:
        s[PIDS.derivative] = 0.0
        s[PIDS.error_prev] = ed
        s[PIDS.started] = 1.0
    d = (tf * s[PIDS.derivative] + kd * (ed - s[PIDS.error_prev])) / (tf + dt)
    v = kp * (p[PIDX.b] * r - y) + s[PIDS.integral] + d + ff
    u = v
    if u < p[PIDX.u_min]:
        u = p[PIDX.u_min]
    elif u > p[PIDX.u_max]:
        u = p[PIDX.u_max]
    s[PIDS.integral] += ki * dt * (r - y)
    if p[PIDX.tt] > 0.0:
        s[PIDS.integral] += dt / p[PIDX.tt] * (u - v)
    s[PIDS.derivative] = d
    s[PIDS.error_prev] = ed
    return u


@numba.njit(cache=True)
def pid_transfer(p, s, r, y, ff, u):  # pragma: no cover - compiled
    """Bumpless transfer: set ``s`` so that ``pid_step(p, s, r, y, ff)`` returns ``u``."""
    s[PIDS.derivative] = 0.0
    s[PIDS.error_prev] = p[PIDX.c] * r - y
    s[PIDS.started] = 1.0
    s[PIDS.integral] = u - p[PIDX.kp] * (p[PIDX.b] * r - y) - ff


@numba.njit(cache=True)
def pid_run(p, s, r, y, ff, u):  # pragma: no cover - compiled
    """Run over sequences r, y, ff (N,) writing u (N,) (open loop: y is given)."""
    for k in range(r.shape[0]):
        u[k] = pid_step(p, s, r[k], y[k], ff[k])


def _finite(name: str, v, positive: bool = False, allow_inf: bool = False) -> float:
    try:
        v = float(v)
    except (TypeError, ValueError):
        raise ConfigError(f"PID {name}: expected a number, found {v!r}") from None
    if math.isnan(v) or (math.isinf(v) and not allow_inf):
        raise ConfigError(f"PID {name}: expected a finite number, found {v!r}")
    if positive and not v > 0:
        raise ConfigError(f"PID {name}: expected a positive number, found {v!r}")
    return v


class PID:
    """Discrete PID (module docstring).

    Parameters
    ----------
    kp, ki, kd
        Parallel gains: output units per error unit, per (error unit·s), times seconds.
    dt
        Sample interval Δt (s), the name gripkit uses everywhere (docs/ARCHITECTURE.md).
    tf
        Derivative filter time constant (s); default K_d/(10 K_p) (N = 10), or Δt without K_p.
    b, c
        Setpoint weights of the proportional and derivative parts (c = 0: derivative on the
        measurement only, the usual choice; c = 1: on the error).
    tt
        Anti-windup tracking time constant (s); ``None`` for the default, ``inf`` to disable.
    u_min, u_max
        Output limits (the actuator's range).
    design
        Provenance of the gains (kept as ``pid.design``; :func:`gripkit.control.tune_pid`).

    >>> pid = PID(2.0, 100.0, dt=1e-3, u_min=-1.0, u_max=1.0)
    >>> round(pid.step(0.1, 0.0), 6)
    0.2
    """

    def __init__(self, kp: float, ki: float = 0.0, kd: float = 0.0, *, dt: float,
                 tf: float | None = None,
                 b: float = 1.0, c: float = 0.0, tt: float | None = None, u_min: float = -math.inf,
                 u_max: float = math.inf, design: dict | None = None):
        kp, ki, kd = _finite("kp", kp), _finite("ki", ki), _finite("kd", kd)
        dt = _finite("dt", dt, positive=True)
        if tf is None:
            tf = kd / (10.0 * abs(kp)) if (kd != 0 and kp != 0) else (dt if kd != 0 else 0.0)
            tf = tf if math.isfinite(tf) else dt
        tf = _finite("tf", tf)
        if tf < 0:
            raise ConfigError(f"PID tf: expected a time constant >= 0 s, found {tf!r}")
        u_min, u_max = (_finite("u_min", u_min, allow_inf=True),
                        _finite("u_max", u_max, allow_inf=True))
        if not u_min < u_max:
            raise ConfigError(f"PID limits: expected u_min < u_max, found [{u_min:g}, {u_max:g}]")
        if tt is None:
            if ki == 0:
                tt = 0.0
            elif kp == 0:
                tt = dt
            else:  # Åström's T_t = sqrt(T_i T_d) = sqrt(kd/ki) (kp cancels), T_i without derivative
                tt = math.sqrt(abs(kd / ki)) if kd != 0 else abs(kp / ki)
                tt = max(tt, dt)
        tt = _finite("tt", tt, allow_inf=True)
        if tt < 0:
            raise ConfigError(f"PID tt: expected a time constant >= 0 s (or inf), found {tt!r}")
        if math.isinf(tt):
            tt = 0.0  # 0 disables the back-calculation term in the kernel
        v = dict(kp=kp, ki=ki, kd=kd, tf=tf, b=_finite("b", b), c=_finite("c", c), tt=tt,
                 u_min=u_min,
                 u_max=u_max, dt=dt)
        self._p = np.array([v[k] for k in PID_PARAMETERS])
        self._p.flags.writeable = False
        self.state = np.zeros(PID_NSTATE)
        #: how the gains were obtained (:func:`gripkit.control.tune_pid` fills it), else empty
        self.design = dict(design or {})

    # --- properties ------------------------------------------------------------------------------
    @property
    def params(self) -> np.ndarray:
        """The parameter array for :func:`pid_step` (read-only)."""
        return self._p

    kp = property(lambda self: float(self._p[PIDX.kp]))
    ki = property(lambda self: float(self._p[PIDX.ki]))
    kd = property(lambda self: float(self._p[PIDX.kd]))
    tf = property(lambda self: float(self._p[PIDX.tf]))
    tt = property(lambda self: float(self._p[PIDX.tt]) if self._p[PIDX.tt] > 0 else math.inf)
    dt = property(lambda self: float(self._p[PIDX.dt]))
    limits = property(lambda self: (float(self._p[PIDX.u_min]), float(self._p[PIDX.u_max])))

    def __repr__(self) -> str:
        return (f"PID(kp={self.kp:g}, ki={self.ki:g}, kd={self.kd:g}, dt={self.dt:g}, "
                f"tf={self.tf:g}, "
                f"tt={self.tt:g}, limits={self.limits})")

    # --- operation -------------------------------------------------------------------------------
    def reset(self, integral: float = 0.0) -> None:
        """Forget the past (derivative memory) and set the integral term."""
        self.state[:] = 0.0
        self.state[0] = float(integral)

    def step(self, r: float, y: float, ff: float = 0.0) -> float:
        """One sample: the limited output u_k for setpoint ``r``, measurement ``y``, feedforward
        ``ff``."""
        return float(pid_step(self._p, self.state, float(r), float(y), float(ff)))

    def transfer(self, u: float, r: float, y: float, ff: float = 0.0) -> None:
        """Bumpless transfer: the next :meth:`step` with (r, y, ff) returns ``u``."""
        pid_transfer(self._p, self.state, float(r), float(y), float(ff), float(u))

    def run(self, r, y, ff=None) -> np.ndarray:
        """Outputs for whole sequences (open loop, y given); continues from the current state."""
        r = np.ascontiguousarray(np.broadcast_to(np.asarray(r, dtype=np.float64), np.shape(y)))
        y = np.ascontiguousarray(np.asarray(y, dtype=np.float64))
        if y.ndim != 1:
            raise ConfigError(f"PID.run: expected 1-D sequences, found shape {y.shape}")
        f = (np.zeros_like(y) if ff is None
             else np.ascontiguousarray(np.broadcast_to(np.asarray(ff, float), y.shape)))
        if not (np.isfinite(r).all() and np.isfinite(y).all() and np.isfinite(f).all()):
            raise ConfigError("PID.run: r, y or ff contains NaN or inf")
        u = np.empty_like(y)
        pid_run(self._p, self.state, r, y, f, u)
        return u


    def transfer_function(self) -> TransferFunction:
        """U(z)/E(z) (linear region, b = c = 1): a discrete :class:`gripkit.lti.TransferFunction`
        at ``dt`` from the error ``e`` to the output ``u``."""
        kp, ki, kd, tf, dt = self.kp, self.ki, self.kd, self.tf, self.dt
        a = np.array([tf + dt, -tf])      # (T_f + Δt) z − T_f
        zm1 = np.array([1.0, -1.0])       # z − 1
        num = (kp * np.polymul(zm1, a) + ki * dt * np.concatenate([[0.0],
                                                                   a]) + kd * np.polymul(zm1, zm1))
        den = np.polymul(zm1, a)
        return TransferFunction(num / den[0], den / den[0], dt=dt, inputs="e", outputs="u")
