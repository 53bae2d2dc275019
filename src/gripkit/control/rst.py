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

import numba
import numpy as np

from ..errors import DataError, ModelError, SimulationError
from ..lti import StateSpace, TransferFunction, as_system

__all__ = ["DiscretePlant", "as_plant", "RSTController", "design_rst", "LoopResult",
           "simulate_loop", "rst_step", "rst_run"]


def _poly(x, name: str) -> np.ndarray:
    a = np.array(x, dtype=np.float64, copy=True).ravel()
    if a.size == 0 or not np.isfinite(a).all():
        raise ModelError(f"{name}: expected finite coefficients, found {x!r}")
    a.flags.writeable = False
    return a


def _padd(a, b) -> np.ndarray:
    n = max(a.size, b.size)
    return np.pad(a, (0, n - a.size)) + np.pad(b, (0, n - b.size))


# ------------------------------------------------------------------------------- the plant
def as_plant(model) -> TransferFunction:
    """A discrete SISO plant as the :class:`gripkit.lti.TransferFunction` ``y = B(q)/A(q) u`` that
    the RST design works on (``den_zinv()`` = A, ``num_zinv()`` = B, ``relative_degree()`` = nk).

    Accepts an lti system (a state space is converted, uncontrollable and unobservable modes
    cancelled), anything :func:`gripkit.lti.as_system` reads (an identified
    :class:`gripkit.sysid.PolynomialModel`, a :class:`DiscretePlant`, python-control or scipy
    systems, an object with ``A``, ``B``, ``dt`` in powers of q⁻¹), or a tuple ``(A, B, dt)``.

    Examples
    --------
    >>> from gripkit.control import as_plant
    >>> g = as_plant(([1.0, -1.8732, 0.8996], [0.0, 0.0, 0.1950, -0.2276], 0.005))
    >>> g.relative_degree(), g.den_zinv().tolist()
    (2, [1.0, -1.8732, 0.8996])
    """
    try:
        g = as_system(model)
    except ModelError as e:
        raise ModelError(f"cannot build a discrete plant from {type(model).__name__}: {e.message}",
                         hint=e.hint or "give a gripkit.lti transfer function or state space, "
                                        "a gripkit.sysid "
                                        "polynomial model, a DiscretePlant, or a "
                                        "tuple (A, B, dt)") from None
    if not g.is_discrete:
        raise ModelError("the plant must be discrete: discretise it with c2d(dt) first")
    if not g.is_siso:
        raise ModelError(f"the plant must be SISO, found {g.n_outputs} outputs and "
                         f"{g.n_inputs} inputs")
    return g if isinstance(g, TransferFunction) else g.to_tf()


@dataclass(frozen=True)
class DiscretePlant:
    """A SISO discrete-time plant y = B(q)/A(q) u, coefficients in increasing powers of q⁻¹
    (MATLAB ``idpoly`` layout: ``A = [1, a1, ...]``, ``B = [0]*nk + [b_nk, ...]``): a view of the
    :class:`gripkit.lti.TransferFunction` :attr:`lti` in the q⁻¹ layout, which computes
    everything (poles, zeros, DC gain, simulation, realisations).

    ``A`` is made monic (B divided by the same leading coefficient) and trailing zeros (padding
    in this layout) are dropped. Build from identified models with :meth:`from_model` (anything
    :func:`as_plant` accepts).
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
        # trailing zeros are padding in the q⁻¹ layout (not factors): drop them
        A, B = (np.trim_zeros(_poly(x, k), "b") for x, k in ((self.A, "A"), (self.B, "B")))
        g = TransferFunction.from_polynomials(A if A.size else np.zeros(1),
                                              B if B.size else np.zeros(1),
                                              dt=self.dt, inputs=self.input_name,
                                              outputs=self.output_name, input_units=self.input_unit,
                                              output_units=self.output_unit)
        object.__setattr__(self, "lti", g)
        object.__setattr__(self, "A", _poly(g.den_zinv(), "A"))
        object.__setattr__(self, "B", _poly(g.num_zinv(), "B"))
        object.__setattr__(self, "dt", g.dt)

    @classmethod
    def from_model(cls, model, **kw) -> "DiscretePlant":
        """The q⁻¹ view of :func:`as_plant` ``(model)``; ``kw`` overrides names, units and
        source."""
        if isinstance(model, DiscretePlant):
            return model
        g = as_plant(model)
        d = dict(input_name=g.inputs[0], input_unit=g.input_units[0] or "1",
                 output_name=g.outputs[0],
                 output_unit=g.output_units[0] or "1", source=type(model).__name__)
        d.update(kw)
        return cls(g.den_zinv(), g.num_zinv(), g.dt, **d)

    @property
    def nk(self) -> int:
        """Input delay in samples (leading zeros of B; includes the sampling delay)."""
        return self.lti.relative_degree()

    def poles(self) -> np.ndarray:
        """Roots of A(z): the first ``len(A) − 1`` poles of :attr:`lti` (the delay's poles at the
        origin come last there)."""
        return self.lti.poles()[:self.A.size - 1]

    def zeros(self) -> np.ndarray:
        """Roots of B(z) without the delay: the first zeros of :attr:`lti`."""
        return self.lti.zeros()[:np.trim_zeros(self.B).size - 1]

    def dc_gain(self) -> float:
        """B(1)/A(1); ModelError at a pole at z = 1."""
        return float(self.lti.dc_gain()[0, 0])

    @property
    def stable(self) -> bool:
        """Every pole of :attr:`lti` strictly inside the unit circle."""
        return self.lti.stable

    @property
    def minimum_phase(self) -> bool:
        """Every zero of :attr:`lti` strictly inside the unit circle."""
        return self.lti.minimum_phase

    def scaled(self, gain: float, **kw) -> "DiscretePlant":
        """The plant with B multiplied by ``gain`` (unit changes, contact compliance)."""
        d = dict(input_name=self.input_name, input_unit=self.input_unit,
                 output_name=self.output_name,
                 output_unit=self.output_unit, source=self.source)
        d.update(kw)
        return DiscretePlant(self.A, (float(gain) * self.lti).num_zinv(), self.dt, **d)

    def simulate(self, u, y_offset: float = 0.0) -> np.ndarray:
        """Output (N,) for input ``u`` (N,) from rest."""
        y = self.lti.simulate(np.asarray(u, dtype=np.float64).reshape(-1))[:, 0]
        y += y_offset
        return y

    def to_ss(self) -> StateSpace:
        """Controllable canonical :class:`gripkit.lti.StateSpace` at ``dt`` (scipy's ``tf2ss``
        realisation, delay states included)."""
        return self.lti.to_ss(minimal=False, form="controllable")

    def to_control(self):
        """A python-control ``TransferFunction`` (optional dependency), names kept."""
        return self.lti.to_control()


# ------------------------------------------------------------------------------- RST controller
class RSTController:
    """R(q) u = T(q) r − S(q) y with anti-windup (A_aw v = T r − S y + (A_aw − R) u, u = sat(v)).

    ``A_aw`` is a stable monic polynomial (default 1: dead-beat anti-windup; :func:`design_rst`
    uses the observer polynomial A_o); ``anti_windup=False`` gives the plain, clamped RST law.
    ``step(r, y)`` returns u for the current sample. Limits ``u_min``/``u_max`` are in the plant's
    input unit (deviation from the operating point). ``reset(u0, y0)`` initialises a bumpless start
    at the steady state (u0, y0 = r0). ``dt``: the sample time (default the plant's).
    """

    def __init__(self, R, S, T, *, A_aw=None, u_min: float = -math.inf, u_max: float = math.inf,
                 plant=None, design: dict | None = None, anti_windup: bool = True,
                 dt: float | None = None):
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
        #: sample time (s): ``dt``, else the plant's (None without either)
        self.dt = float(dt) if dt is not None else (
            float(plant.dt) if getattr(plant, "dt", None) is not None else None)
        self.design = dict(design or {})
        self.reset()


    def reset(self, u0: float = 0.0, y0: float = 0.0):
        """Bumpless start: histories at the steady state u = v = u0, r = y = y0."""
        n = max(self.R.size, self.S.size, self.T.size)
        # rows r, y, u, v (newest first): one buffer for the kernel, the rows as views
        self._h = np.empty((4, n))
        self._h[0:2] = float(y0)
        self._h[2:4] = float(u0)
        self._r, self._y, self._u, self._v = self._h

    def step(self, r: float, y: float) -> float:
        """Control for this sample from reference ``r`` and measurement ``y`` (one call of the
        allocation-free kernel :func:`rst_step` on the controller's history buffer)."""
        if not (math.isfinite(r) and math.isfinite(y)):
            raise SimulationError(f"controller input is not finite (r={r}, y={y})")
        return rst_step(self.R, self.S, self.T, self.A_aw, self._h, float(r), float(y),
                        self.u_min, self.u_max)

    def run(self, r, y) -> np.ndarray:
        """Outputs u (N,) for whole sequences r, y (open loop: y is given; r may be a scalar),
        continuing from the current state: the same kernel as :meth:`step`, in one call."""
        y = np.ascontiguousarray(np.asarray(y, dtype=np.float64))
        if y.ndim != 1:
            raise DataError(f"RSTController.run: expected a 1-D sequence y, found shape {y.shape}")
        r = np.ascontiguousarray(np.broadcast_to(np.asarray(r, dtype=np.float64), y.shape))
        if not (np.isfinite(r).all() and np.isfinite(y).all()):
            raise DataError("RSTController.run: r or y contains NaN or inf",
                            hint="interpolate or drop the missing samples first")
        u = np.empty_like(y)
        rst_run(self.R, self.S, self.T, self.A_aw, self._h, r, y, self.u_min, self.u_max, u)
        return u

    # -- analysis -------------------------------------------------------------------------
    def resolve_plant(self, plant) -> TransferFunction:
        """``plant`` (or the design's plant when None) as :func:`as_plant` gives it."""
        p = plant if plant is not None else self.plant
        if p is None:
            raise ModelError("give the plant to analyse the closed loop")
        return as_plant(p)

    def characteristic(self, plant=None) -> np.ndarray:
        """P = A R + B S (coefficients in q⁻¹)."""
        p = self.resolve_plant(plant)
        return _padd(np.convolve(p.den_zinv(), self.R), np.convolve(p.num_zinv(), self.S))

    def closed_loop_poles(self, plant=None) -> np.ndarray:
        return np.roots(np.trim_zeros(self.characteristic(plant), "b"))

    def is_stable(self, plant=None) -> bool:
        return bool(np.all(np.abs(self.closed_loop_poles(plant)) < 1.0))

    def reference_response(self, n: int, plant=None) -> np.ndarray:
        """Unit-step response of y to r (linear, unsaturated), n samples."""
        from scipy import signal

        p = self.resolve_plant(plant)
        return signal.lfilter(np.convolve(p.num_zinv(), self.T), self.characteristic(p), np.ones(n))

    def disturbance_response(self, n: int, plant=None, where: str = "input") -> np.ndarray:
        """Unit-step response of y to a disturbance at the plant ``input`` (B R/P) or ``output``
        (A R/P)."""
        from scipy import signal

        p = self.resolve_plant(plant)
        num = np.convolve(p.num_zinv() if where == "input" else p.den_zinv(), self.R)
        return signal.lfilter(num, self.characteristic(p), np.ones(n))

    def feedback_path(self, plant=None) -> TransferFunction:
        """The controller's feedback path K = S(q)/R(q) as a :class:`gripkit.lti.TransferFunction`
        on the plant's time base (u = −K y when r = 0)."""
        p = self.resolve_plant(plant)
        return TransferFunction.from_polynomials(self.R, self.S, dt=p.dt)

    def loop_frequency_response(self, w, plant=None) -> np.ndarray:
        """L(e^{jωh}) = B S / (A R) at angular frequencies ``w`` (rad/s): the frequency response
        of the open loop ``K·G`` (:meth:`feedback_path` in series with the plant)."""
        p = self.resolve_plant(plant)
        return (self.feedback_path(p) * p).frequency_response(w)[:, 0, 0]

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
        return dict(gain_margin_db=gm, phase_margin_deg=pm, w_gain_crossover=wc,
                    w_phase_crossover=w180,
                    sensitivity_peak=ms)


# ------------------------------------------------------------------------------- RST kernels
@numba.njit(cache=True)
def rst_step(R, S, T, aw, h, r, y, u_min, u_max):  # pragma: no cover - compiled
    """One sample of the anti-windup RST law (:class:`RSTController`), allocation-free: the
    history ``h`` (4, n) holds r, y, u, v, newest first, and is shifted in place; returns u.

    v = Σ T_i r_{k−i} − Σ S_i y_{k−i} + Σ_{i≥1} (A_aw,i − R_i) u_{k−i} − Σ_{i≥1} A_aw,i v_{k−i},
    u = min(max(v, u_min), u_max) (``R``, ``A_aw`` of equal length, monic)."""
    n = h.shape[1]
    for i in range(n - 1, 0, -1):
        h[0, i] = h[0, i - 1]
        h[1, i] = h[1, i - 1]
        h[2, i] = h[2, i - 1]
        h[3, i] = h[3, i - 1]
    h[0, 0] = r
    h[1, 0] = y
    at = 0.0
    for i in range(T.shape[0]):
        at += T[i] * h[0, i]
    bs = 0.0
    for i in range(S.shape[0]):
        bs += S[i] * h[1, i]
    acc = at - bs
    cu = 0.0
    for i in range(1, R.shape[0]):
        cu += (aw[i] - R[i]) * h[2, i]
    acc += cu
    cv = 0.0
    for i in range(1, aw.shape[0]):
        cv += aw[i] * h[3, i]
    v = acc - cv
    u = v
    if u < u_min:
        u = u_min
    elif u > u_max:
        u = u_max
    h[3, 0] = v
    h[2, 0] = u
    return u


@numba.njit(cache=True)
def rst_run(R, S, T, aw, h, r, y, u_min, u_max, u):  # pragma: no cover - compiled
    """:func:`rst_step` over sequences r, y (N,), writing u (N,)."""
    for k in range(y.shape[0]):
        u[k] = rst_step(R, S, T, aw, h, r[k], y[k], u_min, u_max)


def _anti_windup_polynomial(Ao: np.ndarray, deg_r: int) -> np.ndarray:
    """A_aw for the anti-windup form: the observer polynomial A_o when deg A_o <= deg R (Åström and
    Wittenmark's choice), else (1 − ρ q⁻¹)^deg R with ρ the largest observer-pole magnitude. The
    controller state driven by A_aw must fit in R's memory (deg A_aw <= deg R), and a plant of
    deg A >= 3 has deg A_o = deg A + deg B − 2 > deg B = deg R observer poles; the slowest of them
    keeps the recovery after saturation no faster than the unsaturated loop's observer."""
    Ao = Ao / Ao[0]
    if Ao.size - 1 <= deg_r:
        return Ao
    rho = float(np.max(np.abs(np.roots(Ao))))
    return np.real(np.poly(np.full(deg_r, rho)))


def design_rst(plant, *, wn: float = 15.0, zeta: float = 0.9, observer: float = 2.0,
               observer_poles=None,
               u_min: float = -math.inf, u_max: float = math.inf) -> RSTController:
    """RST pole placement with integral action that keeps B (delay and NMP zeros) in the loop.

    Parameters
    ----------
    plant
        A discrete SISO :class:`gripkit.lti.TransferFunction`, or anything :func:`as_plant` accepts
        (an identified model, a DiscretePlant, a discrete StateSpace, a tuple (A, B, dt), ...).
    wn, zeta
        Dominant closed-loop pair (rad/s and damping), mapped to z = e^{s h}. Keep ω_n well below
        the continuous equivalent of any NMP zero (ln|z₀|/h).
    observer
        The remaining closed-loop (observer) poles sit at z = e^{−observer·ω_n·h}, unless
        ``observer_poles`` (z-plane) are given. A plant of denominator degree n_A and numerator
        degree n_B (q⁻¹ layout, delay included) has n_A + n_B − 2 of them; the anti-windup
        polynomial is A_o, or (1 − ρ q⁻¹)^{n_B} when A_o is longer than R
        (:func:`_anti_windup_polynomial`).
    u_min, u_max
        Actuator limits (plant input units) for the anti-windup controller.
    """
    p = as_plant(plant)
    if p.relative_degree() < 1:
        raise ModelError("the plant has direct feedthrough (nk = 0); the RST design needs nk >= 1")
    h = p.dt
    if not (wn > 0 and 0 < zeta and math.isfinite(wn)):
        raise ModelError(f"need wn > 0 and zeta > 0, found wn={wn}, zeta={zeta}")
    nmp = [z for z in p.zeros() if abs(z) >= 1.0]
    A1 = np.convolve(p.den_zinv(), [1.0, -1.0])
    dA1 = A1.size - 1
    B = p.num_zinv()
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
        raise ModelError("A(q)(1 − q⁻¹) and B(q) have a common factor: the plant has a "
                         "zero at z = 1 or a "
                         "pole/zero pair cancels", hint="integral action is impossible with "
                                                        "a zero at z = 1")
    x = np.linalg.solve(M, np.pad(P, (0, n - P.size)))
    Rp, S = x[:dB], x[dB:]
    R = np.convolve(Rp, [1.0, -1.0])
    r0 = R[0]
    B1 = float(B.sum())
    T = Ao * float(Am.sum()) / B1
    R, S, T = R / r0, S / r0, T / r0
    aw = _anti_windup_polynomial(Ao, R.size - 1)
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
    A, B = p.den_zinv(), p.num_zinv()
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
