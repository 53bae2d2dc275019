"""A discrete SISO plant B(q)/A(q) and RST pole placement with integral action that never cancels
the plant's zeros (generic; the AMADEUS finger-force loop built on it is
:mod:`gripkit.systems.amadeus.force_control`).

RST pole placement with integral action (no zero cancellation)
--------------------------------------------------------------
The controller R(q) u = T(q) r − S(q) y with R = (1 − q⁻¹) R′ (integral action: zero steady-state
error to steps of reference and of load disturbances) solves the Diophantine equation

    A(q) (1 − q⁻¹) R′(q) + B(q) S(q) = P(q) = A_m(q) A_o(q)

with the minimal degrees deg R′ = deg B − 1, deg S = deg A, deg P = deg A + deg B (a square
Sylvester system, solvable when A(1 − q⁻¹) and B are coprime: no plant zero at z = 1 and no common
pole/zero). A_m is the dominant pair (natural frequency ω_n, damping ζ, mapped by z = e^{sh}), A_o
holds the remaining (observer) poles, and T = A_o · A_m(1)/B(1). The reference response is then

    y/r = B(q) A_m(1) / (B(1) A_m(q)):

unit DC gain, the dominant dynamics, and *all* of B — so a non-minimum-phase zero shows up as a
small initial undershoot, as it must (a zero outside the unit circle cannot be removed by any
stable, causal controller), and the achievable speed is limited by that zero (§V-F of
``000_8f66dcc7ab06470c.txt`` calls zero-cancelling pole placement "a risky endeavor").

Actuator limits and anti-windup
-------------------------------
The controller runs in the anti-windup form of Åström and Wittenmark,

    A_aw(q) v = T r − S y + (A_aw − R) u,     u = sat(v),

which is the RST law whenever u is not saturated and keeps the controller state bounded (driven by
the stable A_aw = A_o) when it is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import DataError, ModelError, SimulationError
from ..sim.linear import StateSpace

__all__ = ["DiscretePlant", "RSTController", "design_rst", "LoopResult", "simulate_loop"]


def _poly(x, name: str) -> np.ndarray:
    a = np.array(x, dtype=np.float64, copy=True).ravel()
    if a.size == 0 or not np.isfinite(a).all():
        raise ModelError(f"{name}: expected finite coefficients, found {x!r}")
    a.flags.writeable = False
    return a


def _padd(a, b) -> np.ndarray:
    n = max(a.size, b.size)
    return np.pad(a, (0, n - a.size)) + np.pad(b, (0, n - b.size))


def _pval(c: np.ndarray, zinv: np.ndarray) -> np.ndarray:
    """Evaluate a polynomial in q⁻¹ (coefficients in increasing powers) at q⁻¹ = zinv."""
    return np.polyval(c[::-1], zinv)


# ------------------------------------------------------------------------------- the plant
@dataclass(frozen=True)
class DiscretePlant:
    """A SISO discrete-time plant y = B(q)/A(q) u, coefficients in increasing powers of q⁻¹
    (MATLAB ``idpoly`` layout: ``A = [1, a1, ...]``, ``B = [0]*nk + [b_nk, ...]``).

    Build from identified models with :meth:`from_model` (anything with ``A``, ``B``, ``dt``
    attributes — e.g. ``gripkit.sysid`` polynomial models —, a discrete SISO
    :class:`gripkit.sim.StateSpace`, or a tuple ``(A, B, dt)``).
    """

    A: np.ndarray
    B: np.ndarray
    dt: float
    input_name: str = "u"
    input_unit: str = "1"
    output_name: str = "y"
    output_unit: str = "1"
    source: str = ""

    def __post_init__(self):
        A = _poly(self.A, "A")
        B = _poly(self.B, "B")
        # trailing zeros are padding in the q⁻¹ layout (not factors): drop them
        A = _poly(A[: max(1, np.flatnonzero(A)[-1] + 1)] if np.any(A) else A, "A")
        B = _poly(B[: np.flatnonzero(B)[-1] + 1] if np.any(B) else B, "B")
        if A[0] != 1.0:
            if A[0] == 0.0:
                raise ModelError("A must start with a nonzero (monic) coefficient")
            B = _poly(B / A[0], "B")
            A = _poly(A / A[0], "A")
        if not np.any(B != 0):
            raise ModelError("B is all zeros: the plant has no input path")
        if not (np.isfinite(self.dt) and self.dt > 0):
            raise ModelError(f"dt: expected a positive sample time (s), found {self.dt!r}")
        object.__setattr__(self, "A", A)
        object.__setattr__(self, "B", B)

    @classmethod
    def from_model(cls, model, **kw) -> "DiscretePlant":
        if isinstance(model, DiscretePlant):
            return model
        if isinstance(model, tuple) and len(model) == 3:
            return cls(model[0], model[1], float(model[2]), **kw)
        if isinstance(model, StateSpace):
            if not model.is_discrete:
                raise ModelError("the state-space plant must be discrete: call discretize(dt) first")
            if model.B.shape[1] != 1 or model.C.shape[0] != 1:
                raise ModelError(f"the plant must be SISO, found {model.C.shape[0]} outputs and {model.B.shape[1]} inputs")
            from scipy import signal

            num, den = signal.ss2tf(model.A, model.B, model.C, model.D)
            num = np.real_if_close(num[0])
            num[np.abs(num) < 1e-13 * max(np.abs(num).max(), 1e-300)] = 0.0
            u = model.input_units[0] if model.input_units else "1"
            y = model.output_units[0] if model.output_units else "1"
            return cls(den, num, model.dt, input_unit=u, output_unit=y, source="state space", **kw)
        if all(hasattr(model, k) for k in ("A", "B", "dt")):
            extra = {}
            for src, dst in (("input_name", "input_name"), ("input_unit", "input_unit"),
                             ("output_name", "output_name"), ("output_unit", "output_unit")):
                if hasattr(model, src) and dst not in kw:
                    extra[dst] = getattr(model, src)
            F = np.atleast_1d(getattr(model, "F", np.ones(1)))
            if F.size > 1:  # output-error form B/F
                return cls(F, model.B, float(model.dt), source=type(model).__name__, **extra, **kw)
            return cls(model.A, model.B, float(model.dt), source=type(model).__name__, **extra, **kw)
        raise ModelError(f"cannot build a discrete plant from {type(model).__name__}",
                         hint="give a DiscretePlant, a gripkit.sysid polynomial model, a discrete "
                              "StateSpace, or a tuple (A, B, dt)")

    @property
    def nk(self) -> int:
        """Input delay in samples (leading zeros of B; includes the sampling delay)."""
        return int(np.flatnonzero(self.B)[0])

    def poles(self) -> np.ndarray:
        return np.roots(self.A)

    def zeros(self) -> np.ndarray:
        b = np.trim_zeros(self.B, "fb")
        return np.roots(b) if b.size > 1 else np.zeros(0)

    def dc_gain(self) -> float:
        a1 = float(self.A.sum())
        if abs(a1) < 1e-14:
            raise ModelError("the plant has a pole at z = 1: its DC gain is infinite")
        return float(self.B.sum()) / a1

    def is_stable(self) -> bool:
        return bool(np.all(np.abs(self.poles()) < 1.0))

    def is_minimum_phase(self) -> bool:
        z = self.zeros()
        return bool(np.all(np.abs(z) < 1.0))

    def scaled(self, gain: float, **kw) -> "DiscretePlant":
        """The plant with B multiplied by ``gain`` (unit changes, contact compliance)."""
        d = dict(input_name=self.input_name, input_unit=self.input_unit, output_name=self.output_name,
                 output_unit=self.output_unit, source=self.source)
        d.update(kw)
        return DiscretePlant(self.A, self.B * float(gain), self.dt, **d)

    def simulate(self, u, y_offset: float = 0.0) -> np.ndarray:
        """Output for input ``u`` (N,) from rest (scipy.signal.lfilter)."""
        from scipy import signal

        u = np.asarray(u, dtype=np.float64).reshape(-1)
        return signal.lfilter(self.B, self.A, u) + y_offset

    def _padded(self):
        n = max(self.A.size, self.B.size)
        return np.pad(self.B, (0, n - self.B.size)), np.pad(self.A, (0, n - self.A.size))

    def to_state_space(self):
        """Controllable canonical :class:`gripkit.sim.StateSpace` at ``dt``."""
        from scipy import signal

        num, den = self._padded()
        Ass, Bss, Css, Dss = signal.tf2ss(np.trim_zeros(num, "f"), den)
        return StateSpace(Ass, Bss, Css, Dss, self.dt, (self.input_name,), (self.output_name,),
                          (self.input_unit,), (self.output_unit,))

    def to_control(self):
        """A python-control ``TransferFunction`` (optional dependency)."""
        try:
            import control
        except ImportError:
            raise ModelError("python-control is not installed", hint="pip install 'gripkit[interop]'") from None
        num, den = self._padded()
        return control.tf(num, den, self.dt)


# ------------------------------------------------------------------------------- RST controller
class RSTController:
    """R(q) u = T(q) r − S(q) y with anti-windup (A_aw v = T r − S y + (A_aw − R) u, u = sat(v)).

    ``A_aw`` is a stable monic polynomial (default 1: dead-beat anti-windup; :func:`design_rst`
    uses the observer polynomial A_o); ``anti_windup=False`` gives the plain, clamped RST law.
    ``step(r, y)`` returns u for the current sample. Limits ``u_min``/``u_max`` are in the plant's
    input unit (deviation from the operating point). ``reset(u0, y0)`` initialises a bumpless start
    at the steady state (u0, y0 = r0).
    """

    def __init__(self, R, S, T, *, A_aw=None, u_min: float = -math.inf, u_max: float = math.inf,
                 plant: DiscretePlant | None = None, design: dict | None = None, anti_windup: bool = True):
        self.R = _poly(R, "R")
        self.S = _poly(S, "S")
        self.T = _poly(T, "T")
        if abs(self.R[0] - 1.0) > 1e-12:
            raise ModelError(f"R must be monic (R[0] = 1), found {self.R[0]:g}")
        if not anti_windup:  # A_aw = R: the plain RST law, clamped (winds up when saturated)
            aw = self.R.copy()
        elif A_aw is None:
            aw = np.ones(1)
        else:
            aw = _poly(A_aw, "A_aw")
        if abs(aw[0] - 1.0) > 1e-12 or aw.size > self.R.size:
            raise ModelError("A_aw must be monic with degree <= deg R")
        self.A_aw = np.pad(aw, (0, self.R.size - aw.size))
        trimmed = np.trim_zeros(self.A_aw, "b")
        if anti_windup and trimmed.size > 1 and np.any(np.abs(np.roots(trimmed)) >= 1.0):
            raise ModelError("A_aw must be stable (roots inside the unit circle)")
        self.anti_windup = bool(anti_windup)
        if not u_min < u_max:
            raise ModelError(f"u_min = {u_min} must be below u_max = {u_max}")
        self.u_min = float(u_min)
        self.u_max = float(u_max)
        self.plant = plant
        self.design = dict(design or {})
        self.reset()

    def reset(self, u0: float = 0.0, y0: float = 0.0):
        """Bumpless start: histories at the steady state u = v = u0, r = y = y0."""
        n = max(self.R.size, self.S.size, self.T.size)
        self._r = np.full(n, float(y0))
        self._y = np.full(n, float(y0))
        self._u = np.full(n, float(u0))
        self._v = np.full(n, float(u0))

    def step(self, r: float, y: float) -> float:
        """Control for this sample from reference ``r`` and measurement ``y``."""
        if not (math.isfinite(r) and math.isfinite(y)):
            raise SimulationError(f"controller input is not finite (r={r}, y={y})")
        for a in (self._r, self._y, self._u, self._v):
            a[1:] = a[:-1]
        self._r[0] = r
        self._y[0] = y
        t, s, rr, aw = self.T, self.S, self.R, self.A_aw
        acc = float(t @ self._r[:t.size]) - float(s @ self._y[:s.size])
        acc += float((aw[1:] - rr[1:]) @ self._u[1:rr.size])
        acc -= float(aw[1:] @ self._v[1:aw.size])
        v = acc
        u = min(max(v, self.u_min), self.u_max)
        self._v[0] = v
        self._u[0] = u
        return u

    # -- analysis -------------------------------------------------------------------------
    def resolve_plant(self, plant):
        p = plant if plant is not None else self.plant
        if p is None:
            raise ModelError("give the plant to analyse the closed loop")
        return DiscretePlant.from_model(p)

    def characteristic(self, plant=None) -> np.ndarray:
        """P = A R + B S (coefficients in q⁻¹)."""
        p = self.resolve_plant(plant)
        return _padd(np.convolve(p.A, self.R), np.convolve(p.B, self.S))

    def closed_loop_poles(self, plant=None) -> np.ndarray:
        return np.roots(np.trim_zeros(self.characteristic(plant), "b"))

    def is_stable(self, plant=None) -> bool:
        return bool(np.all(np.abs(self.closed_loop_poles(plant)) < 1.0))

    def reference_response(self, n: int, plant=None) -> np.ndarray:
        """Unit-step response of y to r (linear, unsaturated), n samples."""
        from scipy import signal

        p = self.resolve_plant(plant)
        return signal.lfilter(np.convolve(p.B, self.T), self.characteristic(p), np.ones(n))

    def disturbance_response(self, n: int, plant=None, where: str = "input") -> np.ndarray:
        """Unit-step response of y to a disturbance at the plant ``input`` (B R/P) or ``output``
        (A R/P)."""
        from scipy import signal

        p = self.resolve_plant(plant)
        num = np.convolve(p.B if where == "input" else p.A, self.R)
        return signal.lfilter(num, self.characteristic(p), np.ones(n))

    def loop_frequency_response(self, w, plant=None) -> np.ndarray:
        """L(e^{jωh}) = B S / (A R) at angular frequencies ``w`` (rad/s)."""
        p = self.resolve_plant(plant)
        zinv = np.exp(-1j * np.asarray(w, dtype=np.float64) * p.dt)
        return _pval(p.B, zinv) * _pval(self.S, zinv) / (_pval(p.A, zinv) * _pval(self.R, zinv))

    def margins(self, plant=None, n: int = 20000) -> dict:
        """Gain margin (dB, smallest upward), phase margin (deg), gain and phase crossover
        frequencies (rad/s), and the sensitivity peak Ms = max |1/(1 + L)| (dB-free ratio)."""
        p = self.resolve_plant(plant)
        w = np.linspace(1e-4, math.pi / p.dt, n)
        L = self.loop_frequency_response(w, p)
        mag = np.abs(L)
        ph = np.angle(L)
        ms = float(np.max(1.0 / np.abs(1.0 + L)))
        pm, wc = math.inf, math.nan
        for i in np.flatnonzero(np.diff(np.sign(mag - 1.0)) != 0):
            m = math.degrees(abs(math.pi - abs(ph[i])))
            if m < pm:
                pm, wc = m, float(w[i])
        gm, w180 = math.inf, math.nan
        im = np.imag(L)
        for i in np.flatnonzero(np.diff(np.sign(im)) != 0):
            if np.real(L[i]) < 0:
                g = -20.0 * math.log10(mag[i])
                if 0 < g < gm:
                    gm, w180 = g, float(w[i])
        return dict(gain_margin_db=gm, phase_margin_deg=pm, w_gain_crossover=wc, w_phase_crossover=w180,
                    sensitivity_peak=ms)


def design_rst(plant, *, wn: float = 15.0, zeta: float = 0.9, observer: float = 2.0, observer_poles=None,
               u_min: float = -math.inf, u_max: float = math.inf) -> RSTController:
    """RST pole placement with integral action that keeps B (delay and NMP zeros) in the loop.

    Parameters
    ----------
    plant
        Anything :meth:`DiscretePlant.from_model` accepts (an identified model, a StateSpace, ...).
    wn, zeta
        Dominant closed-loop pair (rad/s and damping), mapped to z = e^{s h}. Keep ω_n well below
        the continuous equivalent of any NMP zero (ln|z₀|/h).
    observer
        The remaining closed-loop (observer) poles sit at z = e^{−observer·ω_n·h}, unless
        ``observer_poles`` (z-plane) are given.
    u_min, u_max
        Actuator limits (plant input units) for the anti-windup controller.
    """
    p = DiscretePlant.from_model(plant)
    if p.nk < 1:
        raise ModelError("the plant has direct feedthrough (nk = 0); the RST design needs nk >= 1")
    h = p.dt
    if not (wn > 0 and 0 < zeta and math.isfinite(wn)):
        raise ModelError(f"need wn > 0 and zeta > 0, found wn={wn}, zeta={zeta}")
    nmp = [z for z in p.zeros() if abs(z) >= 1.0]
    A1 = np.convolve(p.A, [1.0, -1.0])
    dA1 = A1.size - 1
    B = p.B
    dB = B.size - 1
    dP = dA1 + dB - 1
    if zeta < 1:
        wd = wn * math.sqrt(1 - zeta * zeta)
        r = math.exp(-zeta * wn * h)
        Am = np.array([1.0, -2.0 * r * math.cos(wd * h), r * r])
    else:
        s1 = -wn * (zeta - math.sqrt(zeta * zeta - 1))
        s2 = -wn * (zeta + math.sqrt(zeta * zeta - 1))
        Am = np.poly([math.exp(s1 * h), math.exp(s2 * h)])
    n_obs = dP - 2
    if observer_poles is not None:
        zo = np.atleast_1d(np.asarray(observer_poles, dtype=complex))
        if zo.size != n_obs:
            raise ModelError(f"this plant needs {n_obs} observer poles, found {zo.size}")
        if np.any(np.abs(zo) >= 1):
            raise ModelError("observer poles must lie inside the unit circle")
        Ao = np.real(np.poly(zo))
    else:
        Ao = np.poly(np.full(n_obs, math.exp(-observer * wn * h))) if n_obs > 0 else np.ones(1)
    P = np.convolve(Am, Ao)
    n = dA1 + dB
    M = np.zeros((n, n))
    for j in range(dB):
        M[j:j + A1.size, j] = A1
    for j in range(dA1):
        M[j:j + B.size, dB + j] = B
    if np.linalg.cond(M) > 1e12:
        raise ModelError("A(q)(1 − q⁻¹) and B(q) have a common factor: the plant has a zero at z = 1 or a "
                         "pole/zero pair cancels", hint="integral action is impossible with a zero at z = 1")
    x = np.linalg.solve(M, np.pad(P, (0, n - P.size)))
    Rp, S = x[:dB], x[dB:]
    R = np.convolve(Rp, [1.0, -1.0])
    r0 = R[0]
    B1 = float(B.sum())
    T = Ao * float(Am.sum()) / B1
    R, S, T = R / r0, S / r0, T / r0
    aw = Ao / Ao[0]
    design = dict(wn=wn, zeta=zeta, observer=observer, Am=Am, Ao=Ao, P=P, nmp_zeros=np.array(nmp),
                  dt=h, method="RST pole placement, integral action, B not cancelled")
    return RSTController(R, S, T, A_aw=aw, u_min=u_min, u_max=u_max, plant=p, design=design)


# ------------------------------------------------------------------------------- loop simulation
@dataclass(frozen=True)
class LoopResult:
    """Closed-loop simulation: time ``t`` (s), reference ``r``, plant output ``y``, measured
    ``y_meas``, applied input ``u`` (after the limits) and controller demand ``v``."""

    t: np.ndarray
    r: np.ndarray
    y: np.ndarray
    y_meas: np.ndarray
    u: np.ndarray
    v: np.ndarray


def simulate_loop(controller: RSTController, plant=None, r=None, *, n: int | None = None,
                  d_in=None, d_out=None, noise=None) -> LoopResult:
    """Simulate the RST loop around a linear plant, with actuator limits, an input disturbance
    ``d_in`` (added to u), an output disturbance ``d_out`` and measurement ``noise`` (arrays)."""
    p = controller.resolve_plant(plant)
    if r is None:
        if n is None:
            raise DataError("give the reference r (array) or its length n")
        r = np.ones(n)
    r = np.asarray(r, dtype=np.float64).reshape(-1)
    N = r.size

    def arr(x, name):
        if x is None:
            return np.zeros(N)
        a = np.broadcast_to(np.asarray(x, dtype=np.float64), (N,))
        if not np.isfinite(a).all():
            raise DataError(f"{name} contains NaN or inf")
        return a

    di, do, nz = arr(d_in, "d_in"), arr(d_out, "d_out"), arr(noise, "noise")
    A, B = p.A, p.B
    na, nb = A.size, B.size
    y = np.zeros(N)
    ym = np.zeros(N)
    u = np.zeros(N)
    v = np.zeros(N)
    ue = np.zeros(N)  # plant input (u + d_in)
    yp = np.zeros(N)  # undisturbed plant output
    for k in range(N):
        acc = 0.0
        for i in range(1, nb):
            if k - i >= 0:
                acc += B[i] * ue[k - i]
        for i in range(1, na):
            if k - i >= 0:
                acc -= A[i] * yp[k - i]
        yp[k] = acc
        y[k] = acc + do[k]
        ym[k] = y[k] + nz[k]
        u[k] = controller.step(r[k], ym[k])
        v[k] = controller._v[0]
        ue[k] = u[k] + di[k]
    return LoopResult(np.arange(N) * p.dt, r, y, ym, u, v)
