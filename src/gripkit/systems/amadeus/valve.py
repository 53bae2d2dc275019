"""The AMADEUS proportional pressure valve: static curve with hysteresis, leakage floor, transport
delay and first-order pressure dynamics (``000_8f66dcc7ab06470c.txt`` §II-D, Fig. 5, §V-C, Fig. 15).

Static response (Fig. 5)
------------------------
The valve maps solenoid current i to tube pressure. Fig. 5 shows an S-shaped curve with a
hysteresis loop; the text gives its ends: valve leakage keeps the pressure above p_min = 7.5 bar,
the supply caps it at p_sup = 30 bar, and the fingers are "operated above 12 bar to ensure that
operation is within the central linear portion". gripkit uses a smooth clamp of a straight line,

    P(i) = p_min + k_v [ sp(i − i_lo) − sp(i − i_hi) ],   sp(x) = w ln(1 + e^{x/w}),
    k_v = (p_sup − p_min) / (i_hi − i_lo),

linear with slope k_v between the elbows at i_lo and i_hi and flattening to p_min and p_sup with
elbow width w. The local slope is k_v σ((i − i_lo)/w); it reaches 95 % of k_v where
(i − i_lo)/w = ln 19, at P = p_min + k_v w ln 20. Requiring that point to be the 12 bar of §II-D
gives
w = (12 bar − p_min) / (k_v ln 20) — :func:`valve_parameters` derives w this way and
:meth:`ProportionalValve.consistency_checks` verifies it. The current range 0.5–1.1 A is an
assumption anchored on §V-E (the valve was driven over 600–1100 mA around 850 mA).

Hysteresis is a play (backlash) operator of half-width h on the current ahead of the static
curve — a loop of constant width 2h in current, the usual model of the magnetic hysteresis and
spool friction of a proportional solenoid. The width of Fig. 5's loop is not in the extracted
text; h = 15 mA (a 30 mA loop, 5 % of the driven span) is assumed.

Dynamics (Fig. 15, §V-C)
------------------------
The pressure follows the static value after a transport delay T_d = 0.01 s ("two time steps" at
200 Hz) through a first-order lag τ: τ Ṗ = P_static(i(t − T_d)) − P. The kernel integrates this
exactly for the zero-order-held input, including a delay that is not a whole number of samples.
τ = 25 ms is assumed (a corner of 6.4 Hz, just above the finger's 5.5 Hz maximum frequency
response of Fig. 2(c), so the valve is not what limits the finger's bandwidth).

Pressure → contact force
------------------------
The finger-force model of §V (Table II, ``[2 2 2]``) was identified from valve current to
fingertip force, so it already contains the valve's delay and lag. The force path therefore takes
the valve's *static* characteristic only: :meth:`ProportionalValve.demand_current` turns the valve's
static (hysteretic, saturated) pressure back into the equivalent current of the linear central
region, which is what the identified model expects. In the central region the chain reduces
exactly to the identified model; near the limits the leakage floor, the supply and the hysteresis
appear. :func:`pressure_to_force_plant` expresses the identified model per unit of pressure demand
(the seed's own description of §V: "pressure demand" to "force sensor readings", Fig. 14).
"""

from __future__ import annotations

import math
from collections import namedtuple

import numba
import numpy as np
from numba import prange

from ...consistency import Finding, compare
from ...control.rst import DiscretePlant
from ...errors import DataError, SimulationError
from ...params import Parameter, ParameterSet
from ...sim.model import Model, Signal

__all__ = ["ProportionalValve", "valve_parameters", "valve_static", "pressure_to_force_plant"]

_SEED = "000_8f66dcc7ab06470c.txt"
BAR = 1.0e5
_LN20 = math.log(20.0)
_NAMES = ("p_min", "p_supply", "i_lo", "i_hi", "elbow", "hysteresis", "delay", "tau")
#: the index of each valve parameter in the vectors the kernels take, by name
#: (``thetas[p, VX.i_lo]``), generated from the names: numba folds these module-level ints
VX = namedtuple("ValveParameterIndex", _NAMES)(*range(len(_NAMES)))


def valve_parameters(*, p_min: float = 7.5 * BAR, p_supply: float = 30.0 * BAR, i_lo: float = 0.5,
                     i_hi: float = 1.1, p_linear: float = 12.0 * BAR, elbow: float | None = None,
                     hysteresis: float = 0.015, delay: float = 0.01,
                     tau: float = 0.025) -> ParameterSet:
    """The valve's ParameterSet (SI: Pa, A, s). ``elbow`` defaults to the width that puts the
    start of the linear region (95 % of the central slope) at ``p_linear`` (12 bar, §II-D)."""
    if elbow is None:
        kv = (p_supply - p_min) / (i_hi - i_lo)
        elbow = (p_linear - p_min) / (kv * _LN20)
    return ParameterSet([
        Parameter("p_min", p_min, "Pa", "lowest deliverable pressure "
                                        "(valve leakage)", bounds=(0.0, None),
                  source=f"{_SEED} §II-D (7.5 bar)", display_unit="bar"),
        Parameter("p_supply", p_supply, "Pa", "supply pressure (upper end of the static curve)",
                  bounds=(0.0, None), source=f"{_SEED} §II-D (30 bar)", display_unit="bar"),
        Parameter("i_lo", i_lo, "A", "current where the linear region extrapolates to p_min",
                  bounds=(0.0, None), source="assumed: anchored on the 600-1100 mA "
                                             "drive range of §V-E",
                  display_unit="mA"),
        Parameter("i_hi", i_hi, "A", "current where the linear region reaches the supply pressure",
                  bounds=(0.0, None), source="assumed: 1100 mA, the 'held constant' level of §V-E",
                  display_unit="mA"),
        Parameter("elbow", elbow, "A", "width w of the smooth elbows of the static curve",
                  bounds=(1e-9, None),
                  source="derived: linear (95 % slope) from 12 "
                         f"bar, {_SEED} §II-D", display_unit="mA"),
        Parameter("hysteresis", hysteresis, "A", "half-width h of the play operator "
                                                 "(loop width 2h)",
                  bounds=(0.0, None), source="assumed: Fig. 5 loop width not in the extracted text",
                  display_unit="mA"),
        Parameter("delay", delay, "s", "transport delay from "
                                       "current to pressure", bounds=(0.0, 1.0),
                  source=f"{_SEED} §V-C, Fig. 15 (about 0.01 s, two "
                         "samples at 200 Hz)", display_unit="ms"),
        Parameter("tau", tau, "s", "first-order pressure time constant", bounds=(1e-6, 10.0),
                  source="assumed: 6.4 Hz corner, above the 5.5 Hz finger response of Fig. 2(c)",
                  display_unit="ms"),
    ], "proportional-valve")


@numba.njit(cache=True)
def _softplus(x, w):  # pragma: no cover - compiled
    z = x / w
    if z > 30.0:
        return x
    if z < -30.0:
        return w * math.exp(z)
    return w * math.log1p(math.exp(z))


@numba.njit(cache=True)
def valve_static(i, p_min, p_supply, i_lo, i_hi, w):  # pragma: no cover - compiled
    """P(i) of the static curve without hysteresis (Pa), scalar."""
    kv = (p_supply - p_min) / (i_hi - i_lo)
    return p_min + kv * (_softplus(i - i_lo, w) - _softplus(i - i_hi, w))


@numba.njit(cache=True)
def _play(x, i, h):  # pragma: no cover - compiled
    if x < i - h:
        return i - h
    if x > i + h:
        return i + h
    return x


@numba.njit(cache=True, parallel=True)
def _valve_batch(thetas, u, dt, x0, y):  # pragma: no cover - compiled
    """Outputs y[p, n] = [pressure, static pressure (undelayed)] at t_n, states [play, pressure]."""
    P = thetas.shape[0]
    N = u.shape[0]
    for p in prange(P):
        p_min = thetas[p, VX.p_min]
        p_sup = thetas[p, VX.p_supply]
        i_lo = thetas[p, VX.i_lo]
        i_hi = thetas[p, VX.i_hi]
        w = thetas[p, VX.elbow]
        h = thetas[p, VX.hysteresis]
        d = thetas[p, VX.delay] / dt
        tau = thetas[p, VX.tau]
        m = int(math.floor(d + 1e-9))
        f = d - m
        if f < 1e-9:
            f = 0.0
        buf = np.empty(m + 2)  # static pressures of the last m+2 samples (ring)
        play = x0[p, 0]
        if math.isnan(play):
            play = u[0, 0]
        s0 = valve_static(_play(play, u[0, 0], h), p_min, p_sup, i_lo, i_hi, w)
        pres = x0[p, 1]
        if math.isnan(pres):
            pres = s0
        for j in range(m + 2):
            buf[j] = s0
        a1 = math.exp(-f * dt / tau)
        a2 = math.exp(-(1.0 - f) * dt / tau)
        for n in range(N):
            play = _play(play, u[n, 0], h)
            st = valve_static(play, p_min, p_sup, i_lo, i_hi, w)
            buf[n % (m + 2)] = st
            y[p, n, 0] = pres
            y[p, n, 1] = st
            # over [t_n, t_n+1): delayed input is st[n-m-1] for f*dt, then st[n-m]
            old = buf[(n - m - 1) % (m + 2)] if n - m - 1 >= 0 else s0
            new = buf[(n - m) % (m + 2)] if n - m >= 0 else s0
            pres = a1 * pres + (1.0 - a1) * old
            pres = a2 * pres + (1.0 - a2) * new


class ProportionalValve(Model):
    """Solenoid proportional pressure valve: current (A) → tube pressure (Pa).

    Outputs ``p`` (the tube pressure, delayed and lagged) and ``p_static`` (the static curve with
    hysteresis, undelayed). States: the play-operator output (A) and the pressure (Pa); the default
    initial state (NaN) starts at the steady state of the first input sample.
    """

    name = "proportional-valve"
    description = "proportional pressure valve: hysteresis, leakage floor, delay, first-order lag"
    inputs = (Signal("i", "A", "solenoid current"),)
    outputs = (Signal("p", "Pa", "tube pressure"),
               Signal("p_static", "Pa", "static (quasi-steady) pressure"))
    states = (Signal("play", "A", "play-operator output"), Signal("p", "Pa", "tube pressure"))
    integrator = "zoh"

    def __init__(self, parameters: ParameterSet | None = None, *, check: bool = True, **kw):
        params = parameters if parameters is not None else valve_parameters(**kw)
        missing = [n for n in _NAMES if n not in params]
        if missing or tuple(params.names) != _NAMES:
            raise DataError(f"valve parameters must be {_NAMES} in this order, "
                            f"found {params.names}")
        if (params.value("i_hi") <= params.value("i_lo")
                or params.value("p_supply") <= params.value("p_min")):
            raise DataError("valve: need i_hi > i_lo and p_supply > p_min")
        super().__init__(params, check=check)

    def initial_state(self, theta):
        return np.array([np.nan, np.nan])

    def _simulate_batch(self, thetas, u, dt, substeps, x0, y):
        _valve_batch(thetas, u, dt, x0, y)

    def modes(self, theta):
        return []

    # -- static helpers (vectorised numpy) -------------------------------------------------
    def _p(self, n):
        return self.parameters.value(n)

    @property
    def gain(self) -> float:
        """k_v (Pa/A): slope of the linear central region."""
        return (self._p("p_supply") - self._p("p_min")) / (self._p("i_hi") - self._p("i_lo"))

    def static_pressure(self, current) -> np.ndarray:
        """The static curve P(i) without hysteresis (Pa), vectorised."""
        i = np.asarray(current, dtype=np.float64)
        w = self._p("elbow")

        def sp(x):
            return w * np.logaddexp(0.0, x / w)

        return self._p("p_min") + self.gain * (sp(i - self._p("i_lo")) - sp(i - self._p("i_hi")))

    def hysteresis_loop(self, current) -> np.ndarray:
        """Static pressure (Pa) along a current sequence, with the play operator (Fig. 5)."""
        i = np.asarray(current, dtype=np.float64).reshape(-1)
        if not np.isfinite(i).all():
            raise DataError("current contains NaN or inf")
        h = self._p("hysteresis")
        x = np.empty_like(i)
        play = i[0]
        for n in range(i.size):
            play = min(max(play, i[n] - h), i[n] + h)
            x[n] = play
        return self.static_pressure(x)

    def current_for(self, pressure) -> np.ndarray:
        """Inverse of the static curve (no hysteresis): current (A) for a pressure in (p_min,
        p_supply)."""
        p = np.asarray(pressure, dtype=np.float64)
        lo, hi = self._p("p_min"), self._p("p_supply")
        if ((p <= lo) | (p >= hi)).any():
            raise DataError(f"pressure must lie strictly between p_min = {lo / BAR:g} bar and "
                            f"p_supply = {hi / BAR:g} bar, found "
                            f"{p.min() / BAR:.4g}..{p.max() / BAR:.4g} bar",
                            hint="the valve cannot deliver pressures outside its leakage "
                                 "floor and supply")
        # monotone: Newton from the linear-region guess, safeguarded by bisection bounds
        kv = self.gain
        i = self._p("i_lo") + (p - lo) / kv
        a = np.full_like(p, self._p("i_lo") - 50 * self._p("elbow"))
        b = np.full_like(p, self._p("i_hi") + 50 * self._p("elbow"))
        w = self._p("elbow")
        for _ in range(60):
            g = self.static_pressure(i) - p
            a = np.where(g < 0, i, a)
            b = np.where(g > 0, i, b)
            s1 = 1.0 / (1.0 + np.exp(-(i - self._p("i_lo")) / w))
            s2 = 1.0 / (1.0 + np.exp(-(i - self._p("i_hi")) / w))
            slope = kv * (s1 - s2)
            step = np.where(slope > 0, g / np.maximum(slope, 1e-30), 0.0)
            inew = i - step
            bad = (inew <= a) | (inew >= b) | ~np.isfinite(inew)
            i = np.where(bad, 0.5 * (a + b), inew)
            if np.max(np.abs(g)) < 1e-6:
                break
        return i

    def demand_current(self, current, play0: float | None = None) -> np.ndarray:
        """The equivalent linear-region current of the valve's static (hysteretic, saturated)
        response: ``i_lo + (P_static(play(i)) − p_min)/k_v``. Equal to ``current`` in the central
        region (up to the hysteresis offset ±h); it saturates near the leakage floor and the supply.
        This is the input of the identified force model inside the hand simulation."""
        return self._p("i_lo") + (self.hysteresis_loop(current) - self._p("p_min")) / self.gain

    def delay_samples(self, dt: float) -> float:
        """Transport delay in samples at step ``dt`` (2 at 200 Hz)."""
        if not (np.isfinite(dt) and dt > 0):
            raise SimulationError(f"dt: expected a positive sample time, found {dt!r}")
        return self._p("delay") / dt

    def consistency_checks(self) -> list[Finding]:
        kv = self.gain
        w = self._p("elbow")
        p95 = self._p("p_min") + kv * w * _LN20
        return [
            compare("linear-from-12-bar", self.name, computed=p95, stated=12.0 * BAR, rtol=0.02,
                    what="pressure where the static slope reaches 95 % of "
                         "the central slope", unit="Pa",
                    used="the elbow width as given",
                    source=f"{_SEED} §II-D ('operated above 12 bar')"),
            compare("delay-samples-200Hz", self.name, computed=self._p("delay") * 200.0, stated=2.0,
                    rtol=0.05,
                    what="transport delay x 200 Hz", unit="samples", used="the delay as given",
                    source=f"{_SEED} §V-C (two time steps at 200 Hz)"),
        ]


def pressure_to_force_plant(force_plant, valve: ProportionalValve):
    """The identified current → force model expressed per unit of pressure demand (Pa → N·…):
    B(q) is divided by the valve's central slope k_v (the input becomes the static pressure
    demand in the linear region, as in the seed's Fig. 14). ``force_plant`` is anything
    :meth:`gripkit.control.DiscretePlant.from_model` accepts."""
    plant = DiscretePlant.from_model(force_plant)
    return DiscretePlant(plant.A, np.asarray(plant.B) / valve.gain, plant.dt, input_name="p_demand",
                         input_unit="Pa", output_name=plant.output_name,
                         output_unit=plant.output_unit,
                         source=f"{plant.source}; per unit pressure demand (÷ k_v = "
                                f"{valve.gain:.4g} Pa/A)")
