"""AMADEUS fingertip position control without a tip sensor (``000_8f66dcc7ab06470c.txt`` §II-C,
§II-D, §III-C).

The seed, §II-C: "no sensor is incorporated to measure fingertip position ... a calibrated model of
the finger motion is used for closed-loop position control, driven by pressures measured from
sensors within each tube [18]". gripkit builds that loop from its own parts:

1. **Inverse model (tip → pressures).** The calibrated static model of
   :class:`~gripkit.systems.amadeus.bellows_finger.BellowsFinger` has three inputs (the tube
   pressures) and three outputs (the fingertip position): the pressure *differences* set the bend
   angle θ and the plane ψ, the *mean* pressure P̄ sets the centre-line length s. So a tip position
   t = (x, y, z) in the finger base frame fixes all three pressures:

   * ψ = atan2(z, y) and the lateral tip offset λ = √(y² + z²);
   * with the tip length l along the end-plate normal, x = s sinθ/θ + l cosθ and
     λ = s (1 − cosθ)/θ + l sinθ. Eliminating s = (x − l cosθ)/(sinθ/θ) leaves one equation
     g(θ) = s(θ)(1 − cosθ)/θ + l sinθ − λ = 0, with g(0) = −λ ≤ 0 and g increasing (the tip
     swings outward as θ grows), solved by bracketing on [0, π/2];
   * M₀ = k_b θ and P̄ = (s − L₀) k_ax / A (the bellows' axial spring, module docstring of
     :mod:`.bellows_finger`), and P_i = P̄ + (2/3) (M₀/(A r)) cos(θ_i − ψ) (the zero-mean part
     reproduces M₀ along ψ exactly because Σ e^{2jθ_i} = 0).

   The target is *reachable* when every P_i lies in the operating range [12, 30] bar (§II-D: the
   valves are linear above 12 bar, the supply is 30 bar) and the end-plate deflection is within
   the 20 mm of Fig. 2(c)'s specification table. Otherwise
   :meth:`FingerPositionController.reference` raises :class:`~gripkit.errors.ModelError` naming
   the violated limit, or, with ``saturate=True``, keeps the direction ψ, shrinks the bend until
   the pressure spread and the deflection fit, clips the mean pressure to what remains, and warns
   (:class:`~gripkit.errors.AccuracyWarning`) with the tip that will be reached instead.

2. **Per-tube pressure loops.** Each tube's valve (:class:`~.valve.ProportionalValve`: static
   curve with leakage floor, supply, hysteresis, 10 ms delay, first-order lag τ) is driven by a
   static feed-forward, the inverse static curve i_ff = P⁻¹(P_ref), plus a PI on the *measured*
   tube pressure in units of the valve's central slope k_v:

       i = i_ff + (K_p e + K_p (Δt/T_i) Σ e) / k_v,     e = P_ref − P_measured.

   With T_i = τ the integral zero cancels the valve's lag and the loop is
   L(s) = K_p e^{−sT_d}/(τ s): crossover ω_c = K_p/τ (20 rad/s for the default K_p = 0.5,
   τ = 25 ms) and phase margin 90° − ω_c T_d (78.5° for T_d = 10 ms). The feed-forward inverts
   the play operator too (i_ff + h in the direction of the step; without it the pressure falls
   short by k_v h = 0.56 bar with the assumed h = 15 mA), and the PI acts on the difference
   between the pressure the controller's valve model predicts for the step and the measured one,
   so with an exact valve model nothing is left to correct and nothing overshoots. What the
   valve model gets wrong (hysteresis width, slope, lag) the integral removes. One limit is
   structural: once the error changes sign, the current must cross the 2h play before the
   pressure moves back, so an overshoot of the correction stays frozen as a residual (a small
   fraction of the model error: the loop's margin of 78.5° keeps the overshoot small). The
   current is clamped to the drive range (assumed 0-2 A) with conditional integration.

3. **Tip estimate.** The tip position is the forward model of the measured pressures: there is
   no tip sensor, so the estimate is as good as the calibration of k_b (and the pressure sensors).
   A mis-calibrated k_b moves the real tip while the estimate still reads the target; the
   controller cannot see it (``simulate(plant_finger=...)`` shows the size of that error).

Tolerance derived from the model: with pressure error δP per tube, the tip error is bounded by
Σ_i |∂t/∂P_i| δP (the forward model's Jacobian, :meth:`FingerPositionController.tip_tolerance`).
"""

from __future__ import annotations

import math
from collections import namedtuple
from dataclasses import dataclass

import numba
import numpy as np

from ...errors import AccuracyWarning, DataError, ModelError, ParameterError, emit_warning
from .bellows_finger import BAR, TUBE_PUSH_ANGLES, BellowsFinger
from .valve import VX, ProportionalValve, valve_static

__all__ = ["FingerPositionController", "PositionResponse", "tip_inverse"]

_SEED = "000_8f66dcc7ab06470c.txt"


def _tip_geometry(finger: BellowsFinger, tip) -> tuple[float, float, float]:
    """(ψ, θ, s) for a tip position (solving g(θ) = 0 of the module docstring)."""
    from scipy.optimize import brentq

    t = np.asarray(tip, dtype=np.float64).reshape(-1)
    if t.shape != (3,) or not np.isfinite(t).all():
        raise DataError(f"tip: expected a finite position (x, y, z) in m, found {tip!r}")
    x, y, z = (float(v) for v in t)
    lam = math.hypot(y, z)
    psi = math.atan2(z, y) if lam > 0 else 0.0
    lt = finger.parameters.value("tip_length")

    def s_of(th):
        sinc = 1.0 - th * th / 6.0 if th < 1e-6 else math.sin(th) / th
        return (x - lt * math.cos(th)) / sinc

    def g(th):
        cosc = th / 2.0 if th < 1e-6 else (1.0 - math.cos(th)) / th
        return s_of(th) * cosc + lt * math.sin(th) - lam

    if x <= lt:
        raise ModelError(f"tip x = {x * 1e3:.4g} mm is not beyond the {lt * 1e3:.4g} mm fingertip: "
                         "no finger length reaches it", hint="x is the axial distance from the "
                         "finger base (about 165 mm for a straight finger at 12 bar)")
    if lam == 0.0:
        return psi, 0.0, x - lt
    hi = math.pi / 2
    if g(hi) < 0:
        raise ModelError(f"tip lateral offset {lam * 1e3:.4g} mm at x = {x * 1e3:.4g} mm needs "
                         "a bend beyond 90°: out of reach", hint="ask for a smaller lateral offset")
    th = brentq(g, 0.0, hi, xtol=1e-15, rtol=1e-14)
    return psi, th, s_of(th)


def tip_inverse(finger: BellowsFinger, tip) -> np.ndarray:
    """Tube pressures (Pa, (3,)) that put the fingertip at ``tip`` (m, finger base frame), from the
    calibrated model (module docstring, step 1), without checking the pressure limits."""
    psi, th, s = _tip_geometry(finger, tip)
    pr = finger.parameters
    area = pr.value("tube_area")
    m0 = pr.value("bending_stiffness") * th
    pbar = (s - pr.value("length")) * finger.axial_stiffness / area
    return pbar + (2.0 / 3.0) * (m0 / (area * finger.radius)) * np.cos(TUBE_PUSH_ANGLES - psi)


@dataclass(frozen=True)
class PositionResponse:
    """A closed-loop run: ``t`` (n,) s; ``pressure`` (n, 3) tube pressures (Pa, true);
    ``measured`` (n, 3) the pressure sensors' readings; ``current`` (n, 3) valve currents (A);
    ``tip_estimate`` (n, 3) the forward model of the measured pressures (m); ``tip`` (n, 3) the
    real finger's tip (m; equal to the estimate when the model is the finger); ``reference`` (3,)
    the pressures demanded (Pa); ``target`` (3,) the tip demanded (m)."""

    t: np.ndarray
    pressure: np.ndarray
    measured: np.ndarray
    current: np.ndarray
    tip_estimate: np.ndarray
    tip: np.ndarray
    reference: np.ndarray
    target: np.ndarray

    def settling_time(self, tol: float) -> float:
        """First time after which every tube stays within ``tol`` Pa of its reference (s)."""
        err = np.abs(self.pressure - self.reference).max(axis=1)
        out = np.nonzero(err > tol)[0]
        if out.size == 0:
            return 0.0
        if out[-1] == err.size - 1:
            return math.inf
        return float(self.t[out[-1] + 1])


@numba.njit(cache=True)
def _delay_and_lag(delay: float, tau: float, dt: float):  # pragma: no cover - compiled
    """A pure delay of ``delay`` s followed by a first-order lag ``tau`` over one sample of a held
    input: ``delay = (m + f) dt`` splits the sample at f, and the lag's exact factors over the two
    parts are ``a1 = e^{−f dt/τ}`` and ``a2 = e^{−(1−f) dt/τ}``; returns ``(m, a1, a2)``."""
    d = delay / dt
    m = int(math.floor(d + 1e-9))
    f = d - m
    if f < 1e-9:
        f = 0.0
    return m, math.exp(-f * dt / tau), math.exp(-(1.0 - f) * dt / tau)


#: the pressure loops' settings for the kernel: PI gains (kp, ki per sample), valve gain kv
#: (Pa/A), current limits (A), reading quantum (Pa), dt (s), samples n, and the controller's valve
#: model (lag tau_c, delay td_c, s)
PressureLoops = namedtuple("PressureLoops", "kp ki kv i_min i_max quantum dt n tau_c td_c")
#: the kernel's outputs (n, 3) each: true pressure, measured pressure (Pa), valve current (A)
LoopRecord = namedtuple("LoopRecord", "pressure measured current")


@numba.njit(cache=True)
def _position_loop(p_ref, i_ff, p0, vpar, loops, rec):  # pragma: no cover - compiled
    """Three tubes: PI on the measured pressure through the valve model of valve.py (play
    operator, static curve, delay with a ring buffer, exact first-order lag for a held input);
    ``loops`` a :data:`PressureLoops`, ``rec`` a :data:`LoopRecord`."""
    kp, ki, kv, i_min, i_max = loops.kp, loops.ki, loops.kv, loops.i_min, loops.i_max
    quantum, dt, n, tau_c, td_c = loops.quantum, loops.dt, loops.n, loops.tau_c, loops.td_c
    pres_out, meas_out, cur_out = rec.pressure, rec.measured, rec.current
    p_min = vpar[VX.p_min]
    p_sup = vpar[VX.p_supply]
    i_lo = vpar[VX.i_lo]
    i_hi = vpar[VX.i_hi]
    w = vpar[VX.elbow]
    h = vpar[VX.hysteresis]
    m, a1, a2 = _delay_and_lag(vpar[VX.delay], vpar[VX.tau], dt)
    nb = m + 2
    # the controller's valve model (delay td_c, lag tau_c) predicts the pressure of the step
    mc, c1, c2 = _delay_and_lag(td_c, tau_c, dt)
    for k in range(3):
        # start at rest at p0: the current of the inverse static curve, the play centred on it
        lo = i_lo - 50.0 * w
        hi = i_hi + 50.0 * w
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if valve_static(mid, p_min, p_sup, i_lo, i_hi, w) < p0[k]:
                lo = mid
            else:
                hi = mid
        play = 0.5 * (lo + hi)
        s0 = valve_static(play, p_min, p_sup, i_lo, i_hi, w)
        buf = np.empty(nb)
        for j in range(nb):
            buf[j] = s0
        pres = s0
        pm = p0[k]  # the pressure the valve model predicts for the feed-forward step
        integ = 0.0
        for step in range(n):
            meas = pres
            if quantum > 0.0:
                meas = quantum * math.floor(pres / quantum + 0.5)
            e = pm - meas
            u = i_ff[k] + (kp * e + integ) / kv
            if u > i_max:
                u = i_max
            elif u < i_min:
                u = i_min
            elif ki > 0.0:
                integ += ki * e  # conditional integration: only while the current is not clamped
            pres_out[step, k] = pres
            meas_out[step, k] = meas
            cur_out[step, k] = u
            if play < u - h:
                play = u - h
            elif play > u + h:
                play = u + h
            st = valve_static(play, p_min, p_sup, i_lo, i_hi, w)
            buf[step % nb] = st
            old = buf[(step - m - 1) % nb] if step - m - 1 >= 0 else s0
            new = buf[(step - m) % nb] if step - m >= 0 else s0
            pres = a1 * pres + (1.0 - a1) * old
            pres = a2 * pres + (1.0 - a2) * new
            old = p_ref[k] if step - mc - 1 >= 0 else p0[k]
            new = p_ref[k] if step - mc >= 0 else p0[k]
            pm = c1 * pm + (1.0 - c1) * old
            pm = c2 * pm + (1.0 - c2) * new


class FingerPositionController:
    """Fingertip position control from tube pressures (module docstring).

    Parameters
    ----------
    finger
        The calibrated finger model (the controller's inverse and tip estimate). Default
        :class:`BellowsFinger` with the zoo calibration.
    valve
        The valve model of each tube (default :class:`ProportionalValve`).
    kp
        Proportional gain of each pressure loop (dimensionless: Pa of correction per Pa of error,
        divided by k_v to give A).
    ti
        Integral time (s); default the valve's lag τ (pole-zero cancellation).
    dt
        Control period (s), default 5 ms (the 200 Hz of §V-C).
    current_range
        Drive current limits (A), assumed (0, 2) A.
    pressure_quantum
        Resolution of the tube pressure sensors (Pa); 0 for ideal sensors.
    """

    def __init__(self, finger: BellowsFinger | None = None,
                 valve: ProportionalValve | None = None, *,
                 kp: float = 0.5, ti: float | None = None, dt: float = 0.005,
                 current_range: tuple[float, float] = (0.0, 2.0), pressure_quantum: float = 0.0):
        self.finger = finger or BellowsFinger()
        self.valve = valve or ProportionalValve()
        tau = self.valve.parameters.value("tau")
        self.ti = tau if ti is None else float(ti)
        for name, v in (("kp", kp), ("ti", self.ti), ("dt", dt)):
            if not (math.isfinite(v) and v > 0):
                raise ParameterError(f"{name}: expected a positive number, found {v!r}")
        if not (pressure_quantum >= 0 and math.isfinite(pressure_quantum)):
            raise ParameterError(f"pressure_quantum: expected >= 0 Pa, found {pressure_quantum!r}")
        lo, hi = (float(c) for c in current_range)
        if not lo < hi:
            raise ParameterError("current_range: expected (low, high) with low < high, found "
                                 f"{current_range!r}")
        self.kp, self.dt, self.current_range = float(kp), float(dt), (lo, hi)
        self.quantum = float(pressure_quantum)
        pr = self.finger.parameters
        self.p_low, self.p_high = pr.value("p_operating"), pr.value("p_max")

    # -- analysis ---------------------------------------------------------------------------
    def loop_margins(self) -> tuple[float, float]:
        """(crossover ω_c rad/s, phase margin deg) of L(s) = K_p e^{−sT_d}/(T_i s) · 1/(τ s + 1) ·
        (T_i s + 1), exact for T_i = τ (module docstring); evaluated numerically otherwise."""
        from scipy.optimize import brentq

        tau = self.valve.parameters.value("tau")
        td = self.valve.parameters.value("delay")

        def L(w):
            s = 1j * w
            return self.kp * (1 + self.ti * s) / (self.ti * s) / (tau * s + 1) * np.exp(-s * td)

        wc = brentq(lambda w: abs(L(w)) - 1.0, 1e-6, 1e6)
        return wc, 180.0 + math.degrees(float(np.angle(L(wc))))

    def tip_tolerance(self, pressure_error: float, pressures) -> float:
        """Bound (m) on the tip error from a per-tube pressure error ``pressure_error`` (Pa) near
        ``pressures``: Σ_i |∂t/∂P_i| δP by central differences of the forward model."""
        p = np.asarray(pressures, dtype=np.float64)
        h = 10.0  # Pa
        tot = 0.0
        for i in range(3):
            dp = np.zeros(3)
            dp[i] = h
            d = (self.finger.bending(p + dp).tip - self.finger.bending(p - dp).tip) / (2 * h)
            tot += float(np.linalg.norm(d))
        return tot * float(pressure_error)

    # -- reference --------------------------------------------------------------------------
    def reference(self, tip, *, saturate: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """(pressures Pa, tip m) to command for a tip target: the exact inverse when reachable;
        otherwise a :class:`ModelError`, or with ``saturate=True`` the nearest bend in the same
        direction that fits the limits (warns :class:`AccuracyWarning` with the tip reached)."""
        f = self.finger
        pr = f.parameters
        lo, hi = self.p_low, self.p_high
        dlim = pr.value("max_deflection")
        psi, th, s = _tip_geometry(f, tip)
        P = tip_inverse(f, tip)
        delta = s * (th / 2.0 if th < 1e-6 else (1.0 - math.cos(th)) / th)  # end-plate δ of the arc
        problems = []
        if P.min() < lo - 1e-6 or P.max() > hi + 1e-6:
            problems.append(f"tube pressures {P[0] / BAR:.4g}, {P[1] / BAR:.4g}, "
                            f"{P[2] / BAR:.4g} bar leave the operating range "
                            f"[{lo / BAR:g}, {hi / BAR:g}] bar ({_SEED} §II-D)")
        if delta > dlim + 1e-12:
            problems.append(f"end-plate deflection {delta * 1e3:.4g} mm exceeds the "
                            f"{dlim * 1e3:g} mm limit ({_SEED} Fig. 2(c))")
        t = np.asarray(tip, dtype=np.float64).reshape(3)
        if not problems:
            return P, t.copy()
        msg = (f"tip target ({t[0] * 1e3:.4g}, {t[1] * 1e3:.4g}, {t[2] * 1e3:.4g}) mm "
               "is out of reach: " + "; ".join(problems))
        if not saturate:
            raise ModelError(msg, hint="ask for a reachable tip, or pass saturate=True to go as "
                                       "far as the limits allow in the same direction")
        Ps = self._saturated(psi, th, s)
        reached = f.bending(Ps).tip
        emit_warning(f"{msg}; saturated to ({reached[0] * 1e3:.4g}, {reached[1] * 1e3:.4g}, "
                     f"{reached[2] * 1e3:.4g}) mm", AccuracyWarning)
        return Ps, reached

    def _saturated(self, psi, th, s):
        from scipy.optimize import brentq

        f = self.finger
        pr = f.parameters
        area = pr.value("tube_area")
        lo, hi = self.p_low, self.p_high
        unit = (2.0 / 3.0) / (area * f.radius) * np.cos(TUBE_PUSH_ANGLES - psi)
        pbar0 = (s - pr.value("length")) * f.axial_stiffness / area

        def pressures(m0):
            d = m0 * unit
            pbar = min(max(pbar0, lo - d.min()), hi - d.max())
            return pbar + d

        m0 = pr.value("bending_stiffness") * th
        m_fit = (hi - lo) / np.ptp(unit)  # largest moment whose spread fits the range
        m0 = min(m0, m_fit)
        dlim = pr.value("max_deflection")
        if f.bending(pressures(m0)).deflection > dlim:
            m0 = brentq(lambda m: float(f.bending(pressures(m)).deflection) - dlim, 0.0, m0,
                        xtol=1e-14)
        return pressures(m0)

    # -- simulation -------------------------------------------------------------------------
    def simulate(self, tip, duration: float = 1.0, *, initial_pressure=None, saturate: bool = False,
                 feedback: bool = True, plant_valve: ProportionalValve | None = None,
                 plant_finger: BellowsFinger | None = None) -> PositionResponse:
        """Closed-loop step from rest at ``initial_pressure`` (Pa, (3,), default all tubes at the
        12 bar operating floor: a straight finger) to the tip target.

        The feed-forward current is the controller's inverse static curve of the reference plus
        the assumed hysteresis half-width h in the direction of the step (the play operator's
        inverse); the PI acts on the difference between the pressure the controller's valve model
        predicts for that step (delay, lag) and the measured pressure, so an exact valve model
        leaves nothing to correct (no overshoot). ``plant_valve`` / ``plant_finger``: the real
        valve and finger when they differ from the controller's models (default: the same).
        ``feedback=False`` runs the feed-forward alone."""
        P_ref, target = self.reference(tip, saturate=saturate)
        v = self.valve
        vp = v.parameters
        plant = plant_valve or v
        pp = plant.parameters
        p0 = (np.full(3, self.p_low) if initial_pressure is None
              else np.asarray(initial_pressure, float))
        if p0.shape != (3,) or not np.isfinite(p0).all():
            raise DataError("initial_pressure: expected 3 finite pressures in Pa, found "
                            f"{initial_pressure!r}")
        if not (math.isfinite(duration) and duration > 0):
            raise DataError(f"duration: expected a positive time in s, found {duration!r}")
        psup, pmin = pp.value("p_supply"), pp.value("p_min")
        if (p0 <= pmin).any() or (p0 >= psup).any():
            raise DataError(f"initial_pressure must lie strictly between {pmin / BAR:g} and "
                            f"{psup / BAR:g} bar (what the valve delivers), found "
                            f"{np.round(p0 / BAR, 4)} bar")
        lo_c, hi_c = vp.value("p_min"), vp.value("p_supply")
        i_ff = v.current_for(np.clip(P_ref, lo_c + 1.0, hi_c - 1.0))
        i_ff = i_ff + vp.value("hysteresis") * np.sign(P_ref - p0)
        n = int(round(duration / self.dt)) + 1
        pres = np.empty((n, 3))
        meas = np.empty((n, 3))
        cur = np.empty((n, 3))
        kp = self.kp if feedback else 0.0
        ki = self.kp * self.dt / self.ti if feedback else 0.0
        vpar = np.array([pp.value(k) for k in pp.names])
        loops = PressureLoops(float(kp), float(ki), float(v.gain), float(self.current_range[0]),
                              float(self.current_range[1]), float(self.quantum), float(self.dt), n,
                              float(vp.value("tau")), float(vp.value("delay")))
        _position_loop(P_ref, i_ff, p0, vpar, loops, LoopRecord(pres, meas, cur))
        est = self.finger.bending(meas).tip
        true = (plant_finger or self.finger).bending(pres).tip
        return PositionResponse(np.arange(n) * self.dt, pres, meas, cur, est, true, P_ref, target)
