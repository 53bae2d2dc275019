"""The AMADEUS knuckle drive: central hydraulic cylinder, linkage, three-position valve and a
bang-bang angle controller on the potentiometer (``000_8f66dcc7ab06470c.txt`` §II-B, §II-C, §II-D,
Fig. 2(c)).

What the seed says
------------------
* "Knuckle movement ±20°" (Fig. 2(c)); the knuckles "are driven in concert from a small single
  central hydraulic cylinder via a simple linkage and provides each finger with 40° of angular
  rotation" (§II-B).
* "A small hydraulic cylinder (O.D. 22 mm), with both ports at the closed end ... Extension of
  the piston causes the gripper to flex by movement of a sliding rotary joint on each of the
  knuckle manifolds. Another rotational joint on each knuckle manifold is attached to the
  stationary outer bearing cylinder" (§II-B).
* "The angle of the knuckle joint is measured by a rotary potentiometer" (§II-C).
* "The control valve for the knuckle joint is a solenoid-operated three-position direction
  control valve with spring center alignment ... the flow to the knuckle joint to be either
  extended, retracted, or switched off" (§II-D), from the 30 bar supply.

Cylinder (assumed where the seed is silent)
-------------------------------------------
Only the outside diameter (22 mm) is given. gripkit assumes a 16 mm bore (3 mm wall) and an 8 mm
rod, so the cap-side area is A_A = π/4 D² = 201.1 mm² and the rod-side area
A_B = π/4 (D² − d_r²) = 150.8 mm². Oil is taken as incompressible and the valve's closed centre
as leak-free, so the valve's *off* position locks the piston (the seed's "switched off").

Linkage
-------
The knuckle manifold turns about its fixed joint on the bearing cylinder; the piston carries the
sliding rotary joint, a pin that moves along the hand axis at a perpendicular distance e from the
manifold's fixed joint and slides in a slot of the manifold. With x the piston position from
mid-stroke, the manifold turns by θ = −atan(x/e) (extension flexes, i.e. closes, the hand: θ < 0
in :mod:`.hand`'s convention, where θ > 0 opens). The stroke that gives exactly ±20° is
S = 2 e tan 20°: 8.735 mm with the assumed e = 12 mm; the end stops sit at x = ±S/2. The
transmission dθ/dx = −cos²θ / e is largest at mid-stroke (1/e) and 12 % smaller at the ends.

Valve: orifice flow (quasi-static)
----------------------------------
Each open valve path is an orifice Q = K √Δp, K = C_d A_o √(2/ρ). Extending, the supply feeds
the cap side through one orifice and the rod side drains to the tank through the other; with the
piston speed v, P_A = P_s − (v A_A / K)² and P_B = P_T + (v A_B / K)², and the force balance
P_A A_A − P_B A_B = F (F the load resisting extension) gives

    v_ext = K √((P_s A_A − P_T A_B − F) / (A_A³ + A_B³)),
    v_ret = K √((P_s A_B − P_T A_A + F) / (A_A³ + A_B³))     (retracting, speed magnitude),

and zero when the load stalls the piston (the bracket ≤ 0; back-driving through the valve is not
modelled). The seed gives no orifice size; gripkit sets K so that an unloaded extension covers the
whole stroke in 0.5 s (assumed). The spring-centred spool follows its command after a switching
delay t_s (assumed 10 ms, a small solenoid valve).

Bang-bang controller with a dead band
-------------------------------------
At each control period Δt (5 ms, the 200 Hz of §V-C) the controller reads the potentiometer
(quantised by a 12-bit converter over 0-5 V, assumed; gain and offset from
:func:`.hand.hand_parameters`) and commands u = sign(e) (extend to close, retract to open) if
|e| > b, else off, with e = θ_cmd − θ_measured. When it commands off at |e| = b the piston keeps
moving until the spool centres: at most Δt (the reading is a period old) plus t_s, i.e. an angle
of at most c = (v_max / e)(Δt + t_s) (the *coast*). The error then stops in (b − c − q, b],
q the converter's angle quantum; it stays inside the dead band (no new switch, no chatter) when
b − c − q > −b, i.e. b > (c + q)/2. :func:`minimum_dead_band` gives (c + q)/2; the default dead
band is twice that (c + q), and a smaller one warns (:class:`~gripkit.errors.StabilityWarning`).
Each step of the command then costs exactly two switches (on, off) and ends within ±b.
"""

from __future__ import annotations

import math
from collections import namedtuple
from dataclasses import dataclass

import numba
import numpy as np

from ...consistency import Finding, compare, warn_inconsistent
from ...errors import DataError, ParameterError, StabilityWarning, emit_warning
from ...params import Parameter, ParameterSet
from .hand import hand_parameters

__all__ = ["KnuckleDrive", "KnuckleResponse", "knuckle_parameters", "minimum_dead_band"]

_SEED = "000_8f66dcc7ab06470c.txt"
BAR = 1.0e5
_NAMES = ("cylinder_od", "bore", "rod", "pin_offset", "range", "p_supply", "p_tank",
          "flow_coefficient", "switch_delay", "pot_gain", "pot_offset", "adc_quantum")


def _flow_for_travel(bore, rod, pin_offset, rng, p_supply, p_tank, travel_time):
    a_a = math.pi / 4.0 * bore ** 2
    a_b = math.pi / 4.0 * (bore ** 2 - rod ** 2)
    v = 2.0 * pin_offset * math.tan(rng) / travel_time
    return v / math.sqrt((p_supply * a_a - p_tank * a_b) / (a_a ** 3 + a_b ** 3))


def knuckle_parameters(*, cylinder_od: float = 0.022, bore: float = 0.016, rod: float = 0.008,
                       pin_offset: float = 0.012, knuckle_range: float = math.radians(20.0),
                       p_supply: float = 30.0 * BAR, p_tank: float = 0.0, travel_time: float = 0.5,
                       switch_delay: float = 0.010,
                       adc_quantum: float = 5.0 / 4096) -> ParameterSet:
    """The knuckle drive's ParameterSet (SI). ``travel_time`` (s) fixes the valve's flow
    coefficient: an unloaded extension covers the stroke in that time (assumed 0.5 s)."""
    if not 0 < rod < bore < cylinder_od:
        raise ParameterError(f"cylinder: need 0 < rod < bore < outside diameter, found rod "
                             f"{rod * 1e3:g} mm, bore {bore * 1e3:g} mm, "
                             f"OD {cylinder_od * 1e3:g} mm",
                             hint="the seed gives OD 22 mm (§II-B); bore and rod are assumptions")
    if not (travel_time > 0 and pin_offset > 0 and 0 < knuckle_range < math.pi / 2):
        raise ParameterError("travel_time, pin_offset must be > 0 and knuckle_range in (0, 90°)")
    if not p_supply > p_tank >= 0:
        raise ParameterError(f"need p_supply > p_tank >= 0, found {p_supply / BAR:g} and "
                             f"{p_tank / BAR:g} bar")
    k = _flow_for_travel(bore, rod, pin_offset, knuckle_range, p_supply, p_tank, travel_time)
    hp = hand_parameters()
    return ParameterSet([
        Parameter("cylinder_od", cylinder_od, "m", "outside diameter of the central cylinder",
                  bounds=(0.0, 0.5), source=f"{_SEED} §II-B (O.D. 22 mm)", display_unit="mm"),
        Parameter("bore", bore, "m", "cylinder bore (piston diameter)", bounds=(0.0, 0.5),
                  source="assumed: 3 mm wall inside the 22 mm OD (bore not given)",
                  display_unit="mm"),
        Parameter("rod", rod, "m", "piston rod diameter", bounds=(0.0, 0.5),
                  source="assumed: half the bore (not given)", display_unit="mm"),
        Parameter("pin_offset", pin_offset, "m",
                  "perpendicular distance e of the sliding joint's line from the manifold's "
                  "fixed joint",
                  bounds=(1e-4, 0.5), source="assumed: linkage dimensions not given (§II-B)",
                  display_unit="mm"),
        Parameter("range", knuckle_range, "rad", "knuckle travel either side of parallel fingers",
                  bounds=(0.0, math.pi / 2), source=f"{_SEED} Fig. 2(c) (±20°), §II-B (40°)",
                  display_unit="deg"),
        Parameter("p_supply", p_supply, "Pa", "supply pressure", bounds=(0.0, None),
                  source=f"{_SEED} §II-D (30 bar system pressure)", display_unit="bar"),
        Parameter("p_tank", p_tank, "Pa", "return (tank) pressure, gauge", bounds=(0.0, None),
                  source="assumed: return at ambient", display_unit="bar"),
        Parameter("flow_coefficient", k, "m**3/s/Pa**0.5",
                  "orifice coefficient K = C_d A_o sqrt(2/rho) of each open valve path",
                  bounds=(0.0, None),
                  source=f"derived: unloaded extension over the stroke in {travel_time:g} s "
                         "(assumed)"),
        Parameter("switch_delay", switch_delay, "s", "solenoid valve switching delay t_s",
                  bounds=(0.0, 1.0), source="assumed: small solenoid valve (not given)",
                  display_unit="ms"),
        Parameter("pot_gain", hp.value("pot_gain"), "V/rad", "potentiometer sensitivity",
                  bounds=(1e-6, None),
                  source="assumed: ±2 V over ±20° (as gripkit.systems.amadeus.hand)"),
        Parameter("pot_offset", hp.value("pot_offset"), "V", "potentiometer voltage at 0°",
                  source="assumed: mid-range of a 0-5 V potentiometer "
                         "(as gripkit.systems.amadeus.hand)"),
        Parameter("adc_quantum", adc_quantum, "V", "potentiometer converter resolution",
                  bounds=(0.0, None), source="assumed: 12-bit converter over 0-5 V",
                  display_unit="mV"),
    ], "knuckle-drive")


@dataclass(frozen=True)
class KnuckleResponse:
    """A knuckle run at the control rate: ``t`` (n,) s, ``angle`` (n,) rad (true),
    ``measured`` (n,) rad (potentiometer), ``command`` (n,) valve command (+1 extend, −1 retract,
    0 off), ``spool`` (n,) the spool position, ``stroke`` (n,) piston position from mid-stroke (m),
    ``target`` (n,) commanded angle (rad). ``switches`` counts command changes, the valve off
    before the run."""

    t: np.ndarray
    angle: np.ndarray
    measured: np.ndarray
    command: np.ndarray
    spool: np.ndarray
    stroke: np.ndarray
    target: np.ndarray

    @property
    def switches(self) -> int:
        return int(np.count_nonzero(np.diff(self.command, prepend=0)))


#: the kernel's outputs, one row per sample: time (s), stroke (m), angle (rad), reading (V),
#: command and spool position (-1, 0, 1)
KnuckleRecord = namedtuple("KnuckleRecord", "t stroke angle reading command spool")
#: the constants :func:`_knuckle_loop` runs with, by name: pin offset e (m), half stroke (m),
#: extension and retraction speeds (m/s), the valve's switching delay (s), the potentiometer's
#: gain (V/rad) and offset (V), the ADC quantum (V)
KnuckleConstants = namedtuple("KnuckleConstants", "e_pin half v_ext v_ret t_s kpot v0 q")


@numba.njit(cache=True)
def _knuckle_loop(target, x0, prm, dead_band, closed_loop, open_cmd, dt, n_sub,
                  rec):  # pragma: no cover
    """``prm`` a :data:`KnuckleConstants`.
    Piston speed from the orifice model (constant per spool position and load), end stops,
    spool = command delayed by the switching delay, bang-bang with dead band on the reading;
    ``rec`` a :data:`KnuckleRecord`."""
    t_out, x_out, th_out, meas_out, cmd_out, spool_out = (rec.t, rec.stroke, rec.angle,
                                                          rec.reading, rec.command, rec.spool)
    e_pin, half, v_ext, v_ret, t_s, kpot, v0, q = prm
    n = target.shape[0]
    h = dt / n_sub
    x = x0
    for k in range(n):
        th = -math.atan(x / e_pin)
        volt = v0 + kpot * th
        if q > 0.0:
            volt = q * math.floor(volt / q + 0.5)
        meas = (volt - v0) / kpot
        if closed_loop:
            err = target[k] - meas
            c = 0
            if err > dead_band:
                c = -1  # opening (θ up) needs a retraction
            elif err < -dead_band:
                c = 1
        else:
            c = open_cmd[k]
        t_out[k] = k * dt
        x_out[k] = x
        th_out[k] = th
        meas_out[k] = meas
        cmd_out[k] = c
        sp = 0
        for j in range(n_sub):
            # the spool at time t follows the command issued at t - t_s (zero before the first)
            tj = k * dt + j * h
            kk = int(math.floor((tj - t_s) / dt + 1e-9))
            sp = cmd_out[kk] if kk >= 0 else 0
            if sp == 1:
                x += v_ext * h
            elif sp == -1:
                x -= v_ret * h
            if x > half:
                x = half
            elif x < -half:
                x = -half
        spool_out[k] = sp


def minimum_dead_band(params: ParameterSet, dt: float = 0.005) -> float:
    """(c + q)/2 (rad): the dead band above which the bang-bang loop cannot chatter (module
    docstring), c the coast angle (v_max/e)(Δt + t_s), q the converter's angle quantum."""
    drive = KnuckleDrive(params, check=False)
    c = max(drive.speeds(0.0)) / params.value("pin_offset") * (dt + params.value("switch_delay"))
    q = params.value("adc_quantum") / params.value("pot_gain")
    return 0.5 * (c + q)


class KnuckleDrive:
    """Cylinder, linkage, three-position valve and bang-bang controller (module docstring)."""

    name = "knuckle-drive"
    description = ("AMADEUS knuckle: hydraulic cylinder, linkage, three-position valve, "
                   "bang-bang control")

    def __init__(self, parameters: ParameterSet | None = None, *, check: bool = True, **kw):
        self.parameters = parameters if parameters is not None else knuckle_parameters(**kw)
        if tuple(self.parameters.names) != _NAMES:
            raise ParameterError(f"knuckle parameters must be {_NAMES}, found "
                                 f"{self.parameters.names}")
        if check:
            warn_inconsistent(self.consistency_checks())

    def _p(self, n):
        return self.parameters.value(n)

    # -- cylinder and linkage ------------------------------------------------------------
    @property
    def areas(self) -> tuple[float, float]:
        """(A_A cap side, A_B rod side) in m²."""
        d, r = self._p("bore"), self._p("rod")
        return math.pi / 4 * d * d, math.pi / 4 * (d * d - r * r)

    @property
    def stroke(self) -> float:
        """S = 2 e tan(range) (m): the stroke between the end stops."""
        return 2.0 * self._p("pin_offset") * math.tan(self._p("range"))

    def angle(self, x) -> np.ndarray:
        """Knuckle angle θ = −atan(x/e) (rad) for the piston position x from mid-stroke (m);
        DataError beyond the end stops."""
        xa = np.asarray(x, dtype=np.float64)
        half = 0.5 * self.stroke
        if not np.isfinite(xa).all() or (np.abs(xa) > half * (1 + 1e-12)).any():
            raise DataError(f"piston position must lie within the end stops ±{half * 1e3:.4g} mm, "
                            f"found {np.nanmax(np.abs(xa)) * 1e3:.4g} mm")
        return -np.arctan(xa / self._p("pin_offset"))

    def position(self, angle) -> np.ndarray:
        """Piston position (m) for a knuckle angle (rad) within the range (inverse linkage)."""
        a = np.asarray(angle, dtype=np.float64)
        self._check_angle(a)
        return -self._p("pin_offset") * np.tan(a)

    def transmission(self, x) -> np.ndarray:
        """dθ/dx = −cos²θ / e (rad/m)."""
        th = self.angle(x)
        return -np.cos(th) ** 2 / self._p("pin_offset")

    def _check_angle(self, a):
        lim = self._p("range")
        if not np.isfinite(a).all() or (np.abs(a) > lim + 1e-12).any():
            raise DataError(f"knuckle angle: expected within ±{math.degrees(lim):.3g}° "
                            "(Fig. 2(c)), "
                            f"found {math.degrees(float(np.nanmax(np.abs(a)))):.4g}°")

    # -- valve -----------------------------------------------------------------------------
    def speeds(self, load: float = 0.0) -> tuple[float, float]:
        """(v_ext, v_ret) piston speed magnitudes (m/s) through the open valve against ``load``
        (N, resisting extension); zero where the load stalls the piston."""
        a_a, a_b = self.areas
        k = self._p("flow_coefficient")
        ps, pt = self._p("p_supply"), self._p("p_tank")
        den = a_a ** 3 + a_b ** 3
        ext = ps * a_a - pt * a_b - load
        ret = ps * a_b - pt * a_a + load
        return (k * math.sqrt(ext / den) if ext > 0 else 0.0,
                k * math.sqrt(ret / den) if ret > 0 else 0.0)

    def chamber_pressures(self, velocity: float) -> tuple[float, float]:
        """(P_A, P_B) in Pa at piston velocity v (m/s, > 0 extending) with the valve open."""
        a_a, a_b = self.areas
        k = self._p("flow_coefficient")
        ps, pt = self._p("p_supply"), self._p("p_tank")
        if velocity >= 0:
            return ps - (velocity * a_a / k) ** 2, pt + (velocity * a_b / k) ** 2
        return pt + (velocity * a_a / k) ** 2, ps - (velocity * a_b / k) ** 2

    # -- simulation ------------------------------------------------------------------------
    def simulate(self, target=None, duration: float = 1.0, *, initial_angle: float = 0.0,
                 dead_band: float | None = None, load: float = 0.0, commands=None,
                 dt: float = 0.005, substeps: int = 20) -> KnuckleResponse:
        """Run the knuckle for ``duration`` s at the control period ``dt``.

        ``target``: commanded angle (rad), a number or one per control period, for the
        bang-bang loop (dead band default 2 × :func:`minimum_dead_band`); or ``commands``: the
        valve command per period (+1 extend, −1 retract, 0 off) for an open-loop run.
        ``load`` (N) resists extension (the fingers' reaction, constant)."""
        if not (math.isfinite(duration) and duration > 0 and math.isfinite(dt) and dt > 0):
            raise DataError(f"duration and dt must be positive, found {duration!r}, {dt!r}")
        n = int(round(duration / dt)) + 1
        if (target is None) == (commands is None):
            raise DataError("give either target (closed loop) or commands (open loop)")
        self._check_angle(np.asarray(initial_angle, dtype=np.float64))
        if commands is not None:
            cmd = np.asarray(commands, dtype=np.int64).reshape(-1)
            if cmd.size != n or not np.isin(cmd, (-1, 0, 1)).all():
                raise DataError(f"commands: expected {n} values in {{-1, 0, 1}} (one per period), "
                                f"found {cmd.size} values {np.unique(cmd)[:5]}")
            tgt = np.zeros(n)
        else:
            tgt = np.broadcast_to(np.asarray(target, dtype=np.float64), (n,)).copy()
            self._check_angle(tgt)
            cmd = np.zeros(n, dtype=np.int64)
        bmin = minimum_dead_band(self.parameters, dt)
        b = 2.0 * bmin if dead_band is None else float(dead_band)
        if target is not None and b <= bmin:
            emit_warning(f"dead band {math.degrees(b):.3g}° is not above the coast bound "
                         f"{math.degrees(bmin):.3g}° (half the angle travelled during a "
                         "control period and the valve's switching delay, plus the reading's "
                         "quantum): the valve may chatter", StabilityWarning)
        v_ext, v_ret = self.speeds(load)
        prm = KnuckleConstants(
            float(self._p("pin_offset")), float(0.5 * self.stroke), float(v_ext), float(v_ret),
            float(self._p("switch_delay")), float(self._p("pot_gain")),
            float(self._p("pot_offset")), float(self._p("adc_quantum")))
        out = [np.empty(n) for _ in range(4)]
        cmd_out = np.empty(n, dtype=np.int64)
        spool = np.empty(n, dtype=np.int64)
        x0 = float(self.position(initial_angle))
        _knuckle_loop(tgt, x0, prm, b, commands is None, cmd, dt, int(substeps),
                      KnuckleRecord(out[0], out[1], out[2], out[3], cmd_out, spool))
        return KnuckleResponse(out[0], out[2], out[3], cmd_out, spool, out[1], tgt)

    # -- checks ----------------------------------------------------------------------------
    def consistency_checks(self) -> list[Finding]:
        return [compare(
            "knuckle-linkage-range", self.name,
            computed=math.degrees(float(self.angle(-0.5 * self.stroke))
                                  - float(self.angle(0.5 * self.stroke))),
            stated=40.0, rtol=1e-9, what="knuckle rotation over the cylinder stroke", unit="deg",
            used="θ = −atan(x/e) over the stroke 2 e tan 20°",
            source=f"{_SEED} §II-B (40° of angular rotation), Fig. 2(c) (±20°)")]
