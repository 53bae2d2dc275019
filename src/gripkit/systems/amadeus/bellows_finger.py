"""The AMADEUS three-bellows continuum finger: bending from tube pressures, and its inverse
(``000_8f66dcc7ab06470c.txt`` §II-A, §III, eqs 1–8, Figs 3, 7, 8).

Geometry (Fig. 7)
-----------------
Three bellows sit at the vertices of an equilateral triangle of pitch-circle diameter PCD = 30 mm,
so each is r = PCD/2 = 15 mm from the finger axis; the triangle has side a = r√3 and height
h = 3r/2, and the lever of eqs 5–6, 2h/3, is r again. Finger base frame: x along the finger axis
(distal), y and z across it. Each tube, pressurised alone, bends the finger *away* from itself
(Fig. 3b); eqs 1–2 put those push directions at θ₁ = 0° (+y), θ₂ = 240° and θ₃ = 120°
(measured from +y toward +z), i.e. the tubes themselves sit at 180°, 60° and 300°.

Moments (eqs 1–4)
-----------------
A pressure P_i on a bellows of effective area A pushes the end plate with P_i A at lever r:
M_i = P_i A r. The components along the push directions (eqs 1, 2) are

    M_y = M₁ − M₂ cos 60° − M₃ cos 60°,     M_z = −M₂ sin 60° + M₃ sin 60°,

with resultant M₀ = √(M_y² + M_z²) (eq 3) and bending-plane orientation ψ = atan2(M_z, M_y) (eq 4,
written with the two-argument arctangent so that all four quadrants come out right). ψ is the
direction in which the tip moves; the moment *vector* itself is x̂ × (cos ψ, sin ψ), normal to the
bending plane.

Eq 8, derived (the printed eq 8 is garbled by the extraction)
-------------------------------------------------------------
Eqs 5–7 split the tube moments into in-plane and cross-plane parts relative to a trial plane ψ:
with ψ_i = θ_i − ψ, ΣM_bi = Σ P_i A r sin ψ_i and ΣM_ci = Σ P_i A r cos ψ_i (eqs 5, 6; which sum
is called "in-plane" depends on whether one names a moment by its vector or by the plane it bends
in). The finger bends in the plane where the moment component *across* that plane vanishes:
Σ P_i sin(θ_i − ψ) = 0, i.e. sin ψ Σ P_i cos θ_i = cos ψ Σ P_i sin θ_i, so with equal areas

    tan ψ = Σ P_i sin θ_i / Σ P_i cos θ_i = (√3/2)(P₃ − P₂) / (P₁ − P₂/2 − P₃/2),        (eq 8)

and the remaining sum is the resultant, M_r = A r Σ P_i cos(θ_i − ψ) = M₀ (eq 7), with the closed
form M₀ = A r √(P₁² + P₂² + P₃² − P₁P₂ − P₂P₃ − P₃P₁). ψ depends only on pressure *differences*
(adding the same pressure to all tubes changes neither numerator nor denominator), and equal
pressures give M₀ = 0: no bending, whatever the absolute pressure (§III-B; tested).

Deflection
----------
The end plate is rigid and carries no other load, so each bellows, a linear axial spring of
stiffness k_ax, extends by P_i A / k_ax (three tubes, three end-plate degrees of freedom). A rigid
plate on three unequal tubes takes a constant-curvature arc of bend angle

    θ = M₀ / k_b,   k_b = (3/2) k_ax r²   (N·m/rad, the finger's bending stiffness),

(Σ_i d_i² = 3r²/2 for any direction of an equilateral triad), and the centre-line length is
s = L₀ + P̄ A / k_ax with P̄ the mean tube pressure. The end-plate centre then sits at

    axial x = s sin θ / θ,   lateral δ = s (1 − cos θ) / θ   along ψ,

and the fingertip (length l_tip along the end-plate normal) at x + l_tip cos θ, δ + l_tip sin θ.
The bending stiffness k_b is calibrated (:func:`calibrate_bending_stiffness`); the zoo value makes
the largest deflection inside the operating pressure range equal the 20 mm of Fig. 2(c).

Inverse (§III-C)
----------------
Only pressure differences bend the finger; the common pressure is free. For a direction ψ and a
resultant moment M₀ the zero-mean solution is P_i⁰ = (2/3)(M₀/(A r)) cos(θ_i − ψ) (it reproduces the
moment exactly because Σ e^{2jθ_i} = 0), and the two data sets of §III-C fix the common part:
``variant='min'`` puts the lowest tube at the lower pressure limit (lowest total pressure),
``variant='max'`` the highest tube at the upper limit (highest total pressure). The limits are
7.5–30 bar (valve leakage floor and supply, §II-D); by default the lower limit is the 12 bar above
which the valves are linear. The achievable moments form a hexagon: the largest deflection is
reached in the six principal directions of Fig. 8 (one tube high, or two tubes high) and is cos 30°
of that midway between them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...consistency import Finding, compare, warn_inconsistent
from ...errors import DataError, ModelError, ParameterError
from ...params import Parameter, ParameterSet

__all__ = [
    "BellowsFinger",
    "BendingState",
    "bellows_parameters",
    "calibrate_bending_stiffness",
    "TUBE_PUSH_ANGLES",
    "PRINCIPAL_DIRECTIONS",
    "bending_direction",
    "stiffness_for_max_deflection",
]

_SEED = "000_8f66dcc7ab06470c.txt"
BAR = 1.0e5
#: push directions θ_i of tubes 1, 2, 3 in the finger base frame (rad, from +y toward +z), eqs 1–2
TUBE_PUSH_ANGLES = np.deg2rad([0.0, 240.0, 120.0])
#: the six principal directions of Fig. 8 (rad): one tube high (0°, 120°, 240°), two high (60°, ...)
PRINCIPAL_DIRECTIONS = np.deg2rad([0.0, 60.0, 120.0, 180.0, 240.0, 300.0])
_SIN60 = math.sqrt(3.0) / 2.0


def bellows_parameters(*, pcd: float = 0.030, tube_area: float | None = None, length: float = 0.125,
                       bending_stiffness: float | None = None, tip_length: float = 0.035,
                       p_min: float = 7.5 * BAR, p_max: float = 30.0 * BAR,
                       p_operating: float = 12.0 * BAR,
                       max_deflection: float = 0.020, source_k: str = "") -> ParameterSet:
    """The finger's ParameterSet (SI). Defaults are the AMADEUS phase-I values (seed §II)."""
    if tube_area is None:
        od, idia = 14.3e-3, 9.0e-3
        tube_area = math.pi / 16.0 * (od + idia) ** 2
    if bending_stiffness is None:
        bending_stiffness = stiffness_for_max_deflection(
            pcd=pcd, tube_area=tube_area, length=length, p_low=p_operating, p_high=p_max,
            max_deflection=max_deflection)
    return ParameterSet([
        Parameter("pcd", pcd, "m", "pitch-circle diameter of the three bellows", bounds=(1e-4, 1.0),
                  source=f"{_SEED} §II-A (PCD 30 mm)", display_unit="mm"),
        Parameter("tube_area", tube_area, "m**2", "effective pressure area of one bellows",
                  bounds=(1e-8, 1e-2),
                  source="assumed: π/16 (OD + ID)² with OD 14.3 mm (§II-A) and an "
                         "assumed ID of 9.0 mm",
                  display_unit="mm**2"),
        Parameter("length", length, "m", "unpressurised bellows length L₀", bounds=(1e-3, 2.0),
                  source=f"{_SEED} §II-A (125 mm bellows)", display_unit="mm"),
        Parameter("bending_stiffness", bending_stiffness, "N*m/rad",
                  "bending stiffness k_b = M₀/θ of the bellows triad (k_ax = k_b / (1.5 r²))",
                  bounds=(1e-6, None),
                  source=source_k or "calibrated: 20 mm maximum deflection (Fig. 2(c)) in the "
                                     "operating range",
                  ),
        Parameter("tip_length", tip_length, "m", "fingertip length beyond the end plate",
                  bounds=(0.0, 0.5), source="assumed: detachable fingertip of Fig. 4 "
                                            "(length not given)",
                  display_unit="mm"),
        Parameter("p_min", p_min, "Pa", "lowest pressure a valve can deliver (leakage)",
                  bounds=(0.0, None), source=f"{_SEED} §II-D (7.5 bar)", display_unit="bar"),
        Parameter("p_max", p_max, "Pa", "supply pressure (highest tube pressure)",
                  bounds=(0.0, None), source=f"{_SEED} §II-D (30 bar "
                                             "system pressure)", display_unit="bar"),
        Parameter("p_operating", p_operating, "Pa", "lowest pressure of the valves' linear region",
                  bounds=(0.0, None), source=f"{_SEED} §II-D (operated above 12 bar)",
                  display_unit="bar"),
        Parameter("max_deflection", max_deflection, "m", "largest allowed tip deflection",
                  bounds=(0.0, None), source=f"{_SEED} Fig. 2(c) "
                                             "and §II-B (20 mm)", display_unit="mm"),
    ], "bellows-finger")


def stiffness_for_max_deflection(*, pcd: float, tube_area: float, length: float, p_low: float,
                                 p_high: float, max_deflection: float) -> float:
    """k_b (N·m/rad) that makes the largest deflection with tubes in [p_low, p_high] equal
    ``max_deflection`` (reached in a principal direction, highest-total-pressure variant: one tube
    at p_low, two at p_high). Solves δ(k_b) = δ_max, with δ = s (1 − cos θ)/θ, θ = M₀/k_b,
    M₀ = (p_high − p_low) A r and s = L₀ + P̄ A 1.5 r²/k_b."""
    from scipy.optimize import brentq

    r = 0.5 * pcd
    m0 = (p_high - p_low) * tube_area * r
    pbar = (p_low + 2.0 * p_high) / 3.0

    def f(logk):
        k = math.exp(logk)
        s = length + pbar * tube_area * 1.5 * r * r / k
        return float(_arc(s, m0 / k)[1]) - max_deflection

    if not (max_deflection > 0 and m0 > 0):
        raise ParameterError("max_deflection and the pressure range must be positive "
                             "to calibrate k_b")
    return math.exp(brentq(f, math.log(m0 / 1.5), math.log(m0 * 1e6), xtol=1e-14))


def bending_direction(pressures) -> np.ndarray:
    """ψ (rad, in (−π, π]) from tube pressures (eq 8 as derived in the module docstring).

    ``pressures`` (..., 3) in any one unit. Equal pressures give ψ = 0 with zero moment (check
    :meth:`BellowsFinger.bending` ``moment`` to tell "no bending" from "bending along +y")."""
    p = np.asarray(pressures, dtype=np.float64)
    num = _SIN60 * (p[..., 2] - p[..., 1])
    den = p[..., 0] - 0.5 * p[..., 1] - 0.5 * p[..., 2]
    return np.arctan2(num, den)


@dataclass(frozen=True)
class BendingState:
    """The static bending of a finger for given tube pressures (arrays over leading axes).

    Attributes
    ----------
    direction
        ψ (rad): bending-plane orientation, the direction the tip moves (eq 4 / eq 8).
    moment
        M₀ (N·m): resultant bending moment (eq 3).
    moment_y, moment_z
        M_y, M_z (N·m) of eqs 1–2.
    angle
        θ = M₀/k_b (rad): bend angle of the end plate.
    arc_length
        s (m): centre-line length including the pressure extension.
    deflection
        δ (m): lateral displacement of the end-plate centre along ψ.
    tip
        (..., 3) fingertip position (m) in the finger base frame [x axial, y, z].
    tip_deflection
        lateral displacement of the fingertip (m).
    """

    direction: np.ndarray
    moment: np.ndarray
    moment_y: np.ndarray
    moment_z: np.ndarray
    angle: np.ndarray
    arc_length: np.ndarray
    deflection: np.ndarray
    tip: np.ndarray
    tip_deflection: np.ndarray


def _arc(s, theta):
    """(axial, lateral) of a constant-curvature arc of length s and bend angle θ (stable at θ→0)."""
    t = np.asarray(theta, dtype=np.float64)
    small = np.abs(t) < 1e-6
    ts = np.where(small, 1.0, t)
    sinc = np.where(small, 1.0 - t * t / 6.0, np.sin(ts) / ts)
    cosc = np.where(small, t / 2.0 - t ** 3 / 24.0, (1.0 - np.cos(ts)) / ts)
    return s * sinc, s * cosc


class BellowsFinger:
    """The static model of one three-bellows finger (see the module docstring for the equations).

    Pressures are absolute tube pressures in Pa (``gripkit.units.to_si('30 bar')``), shape (..., 3)
    for tubes 1, 2, 3.
    """

    name = "bellows-finger"
    description = "AMADEUS three-bellows continuum finger: static bending model (eqs 1-8)"

    def __init__(self, parameters: ParameterSet | None = None, *, check: bool = True, **kw):
        self.parameters = parameters if parameters is not None else bellows_parameters(**kw)
        p = self.parameters
        if p.value("p_min") >= p.value("p_max"):
            raise ParameterError(f"p_min = {p.value('p_min') / BAR:g} bar must be below p_max = "
                                 f"{p.value('p_max') / BAR:g} bar")
        if not p.value("p_min") <= p.value("p_operating") < p.value("p_max"):
            raise ParameterError(f"p_operating = {p.value('p_operating') / BAR:g} bar must lie in "
                                 f"[p_min, p_max) = [{p.value('p_min') / BAR:g}, "
                                 f"{p.value('p_max') / BAR:g}) bar")
        if check:
            warn_inconsistent(self.consistency_checks())

    # -- derived geometry ------------------------------------------------------------------
    @property
    def radius(self) -> float:
        """r = PCD/2 = 2h/3 (m), the lever of each tube."""
        return 0.5 * self.parameters.value("pcd")

    @property
    def triangle(self) -> tuple[float, float]:
        """(side a, height h) of the equilateral triangle of Fig. 7 (m)."""
        r = self.radius
        return r * math.sqrt(3.0), 1.5 * r

    @property
    def axial_stiffness(self) -> float:
        """k_ax = k_b / (1.5 r²) (N/m), the axial stiffness of one bellows implied by k_b."""
        return self.parameters.value("bending_stiffness") / (1.5 * self.radius ** 2)

    # -- forward model -------------------------------------------------------------------
    def _pressures(self, pressures, check_limits: bool = False) -> np.ndarray:
        p = np.asarray(pressures, dtype=np.float64)
        if p.shape[-1:] != (3,):
            raise DataError(f"pressures: expected shape (..., 3) for tubes 1-3, found {p.shape}")
        if not np.isfinite(p).all():
            raise DataError("pressures contain NaN or inf")
        if (p < 0).any():
            raise DataError(f"pressures must be absolute (>= 0 Pa), found {p.min():g} Pa",
                            hint="give pressures in Pa, e.g. gripkit.units.to_si('20 bar')")
        if check_limits:
            lo, hi = self.parameters.value("p_min"), self.parameters.value("p_max")
            if (p < lo - 1e-6).any() or (p > hi + 1e-6).any():
                raise DataError(f"pressures outside the valve range [{lo / BAR:g}, "
                                f"{hi / BAR:g}] bar: "
                                f"min {p.min() / BAR:.4g}, max {p.max() / BAR:.4g} bar")
        return p

    def moments(self, pressures) -> tuple[np.ndarray, np.ndarray]:
        """(M_y, M_z) in N·m, eqs 1–2, with M_i = P_i A r."""
        p = self._pressures(pressures)
        c = self.parameters.value("tube_area") * self.radius
        m1, m2, m3 = c * p[..., 0], c * p[..., 1], c * p[..., 2]
        return m1 - 0.5 * m2 - 0.5 * m3, _SIN60 * (m3 - m2)

    def plane_moments(self, pressures, direction) -> tuple[np.ndarray, np.ndarray]:
        """Eqs 5–6 about a trial plane ψ: (Σ M_ci, Σ M_bi) = (A r Σ P_i cos(θ_i−ψ), A r Σ P_i
        sin(θ_i−ψ)).

        The first is the resultant along ψ (eq 7's M_r when ψ is the bending direction), the second
        the part across it, which vanishes at the bending direction."""
        p = self._pressures(pressures)
        c = self.parameters.value("tube_area") * self.radius
        d = np.asarray(direction, dtype=np.float64)[..., None]
        rel = TUBE_PUSH_ANGLES - d
        return c * (p * np.cos(rel)).sum(-1), c * (p * np.sin(rel)).sum(-1)

    def bending(self, pressures) -> BendingState:
        """Bending state for tube pressures (..., 3) Pa."""
        p = self._pressures(pressures)
        pr = self.parameters
        my, mz = self.moments(p)
        m0 = np.hypot(my, mz)
        psi = np.arctan2(mz, my)
        theta = m0 / pr.value("bending_stiffness")
        s = pr.value("length") + p.mean(-1) * pr.value("tube_area") / self.axial_stiffness
        ax, lat = _arc(s, theta)
        lt = pr.value("tip_length")
        tip_ax = ax + lt * np.cos(theta)
        tip_lat = lat + lt * np.sin(theta)
        tip = np.stack([tip_ax, tip_lat * np.cos(psi), tip_lat * np.sin(psi)], axis=-1)
        return BendingState(psi, m0, my, mz, theta, s, lat, tip, tip_lat)

    def deflection(self, pressures) -> np.ndarray:
        """Lateral end-plate deflection δ (m)."""
        return self.bending(pressures).deflection

    # -- inverse -------------------------------------------------------------------------
    def _limits(self, p_low, p_high) -> tuple[float, float]:
        pr = self.parameters
        lo = pr.value("p_operating") if p_low is None else float(p_low)
        hi = pr.value("p_max") if p_high is None else float(p_high)
        if lo < pr.value("p_min") - 1e-9 or hi > pr.value("p_max") + 1e-9 or lo >= hi:
            raise DataError(f"pressure limits [{lo / BAR:g}, {hi / BAR:g}] bar must lie "
                            "inside the valve "
                            f"range [{pr.value('p_min') / BAR:g}, {pr.value('p_max') / BAR:g}] bar")
        return lo, hi

    def _pressures_for_moment(self, direction: float, moment: float, variant: str, lo: float,
                              hi: float):
        unit = self.parameters.value("tube_area") * self.radius
        p0 = (2.0 / 3.0) * (moment / unit) * np.cos(TUBE_PUSH_ANGLES - direction)
        if variant == "min":
            return p0 + (lo - p0.min())
        return p0 + (hi - p0.max())

    def max_moment(self, direction: float, p_low: float | None = None,
                   p_high: float | None = None) -> float:
        """Largest resultant moment (N·m) in ``direction`` with every tube in [p_low, p_high]
        (defaults: 12 bar operating floor, 30 bar supply)."""
        lo, hi = self._limits(p_low, p_high)
        spread = np.ptp((2.0 / 3.0) * np.cos(TUBE_PUSH_ANGLES - float(direction)))
        return (hi - lo) / spread * self.parameters.value("tube_area") * self.radius

    def max_deflection(self, direction: float, variant: str = "max", p_low: float | None = None,
                       p_high: float | None = None) -> float:
        """Largest end-plate deflection (m) reachable in ``direction`` within the limits."""
        lo, hi = self._limits(p_low, p_high)
        m = self.max_moment(direction, lo, hi)
        return (float(self.bending(self._pressures_for_moment(float(direction), m, variant, lo,
                                                              hi)).deflection))

    def pressures_for(self, direction, deflection, variant: str = "min", p_low: float | None = None,
                      p_high: float | None = None) -> np.ndarray:
        """Tube pressures (Pa, shape (3,)) that bend the end plate by ``deflection`` (m) toward
        ``direction`` ψ (rad).

        ``variant='min'``: lowest total pressure (one tube at ``p_low``); ``'max'``: highest total
        pressure (one tube at ``p_high``) — the two data sets of §III-C. Limits default to the
        12 bar operating floor and the 30 bar supply. Raises :class:`ModelError` when the
        deflection cannot be reached in that direction within the limits.
        """
        from scipy.optimize import brentq

        if variant not in ("min", "max"):
            raise DataError("variant: expected 'min' (lowest total pressure) or 'max' (highest), "
                            f"found {variant!r}")
        psi = float(direction)
        d = float(deflection)
        if not (math.isfinite(psi) and math.isfinite(d)) or d < 0:
            raise DataError(f"deflection must be a finite number >= 0 m, found {deflection!r}")
        lo, hi = self._limits(p_low, p_high)
        dmax_spec = self.parameters.value("max_deflection")
        if d > dmax_spec + 1e-12:
            raise ModelError(f"deflection {d * 1e3:.3g} mm exceeds the finger's "
                             f"{dmax_spec * 1e3:.3g} mm limit",
                             hint="larger deflections damage the phosphor-bronze bellows (§II-B)")
        if d == 0.0:
            mid = lo if variant == "min" else hi
            return np.full(3, mid)
        mmax = self.max_moment(psi, lo, hi)

        def f(m):
            return (float(self.bending(self._pressures_for_moment(psi, m, variant, lo,
                                                                  hi)).deflection) - d)

        top = f(mmax)
        if top < 0:
            raise ModelError(
                f"deflection {d * 1e3:.4g} mm toward {math.degrees(psi):.4g}° is out of "
                "reach: at most "
                f"{(top + d) * 1e3:.4g} mm within [{lo / BAR:g}, {hi / BAR:g}] bar "
                f"({variant!r} variant)",
                hint="ask for less, widen the pressure limits, or use the knuckle (§II-B)")
        m = brentq(f, 0.0, mmax, xtol=1e-14, rtol=1e-13)
        return self._pressures_for_moment(psi, m, variant, lo, hi)

    # -- checks --------------------------------------------------------------------------
    def consistency_checks(self) -> list[Finding]:
        pr = self.parameters
        a, h = self.triangle
        out = [
            compare("lever-2h/3", self.name, computed=2.0 * h / 3.0, stated=self.radius, rtol=1e-12,
                    what="2h/3 of the equilateral triangle (eqs 5-6 lever)", unit="m",
                    used="r = PCD/2", source=f"{_SEED} Fig. 7, eqs 5-6; PCD §II-A"),
        ]
        dmax = (max(self.max_deflection(psi, "max",
                                        pr.value("p_operating")) for psi in PRINCIPAL_DIRECTIONS))
        out.append(compare(
            "max-deflection", self.name, computed=dmax, stated=pr.value("max_deflection"),
            rtol=0.02,
            what=f"largest deflection with tubes in [{pr.value('p_operating') / BAR:g}, "
                 f"{pr.value('p_max') / BAR:g}] bar from k_b", unit="m",
            used="k_b as given; recalibrate with calibrate_bending_stiffness()",
            source=f"{_SEED} Fig. 2(c): finger deflection (maximum) 20 mm"))
        return out


def calibrate_bending_stiffness(pressures, deflections, finger: BellowsFinger | None = None,
                                deflection_std: float | None = None) -> tuple[float, float]:
    """Least-squares k_b (N·m/rad) from measured end-plate deflections under known pressures.

    ``pressures`` (n, 3) Pa, ``deflections`` (n,) m (the §III-C needle measurements). Returns
    ``(k_b, std)``; ``std`` from the residual scatter (or from ``deflection_std`` when given).
    Uses the full arc model (the pressure-dependent length included)."""
    from scipy.optimize import least_squares

    finger = finger or BellowsFinger(check=False)
    p = np.asarray(pressures, dtype=np.float64)
    d = np.asarray(deflections, dtype=np.float64).reshape(-1)
    if p.ndim != 2 or p.shape != (d.size, 3):
        raise DataError("expected pressures (n, 3) and deflections (n,), found "
                        f"{p.shape} and {d.shape}")
    if d.size < 2:
        raise DataError("calibrate_bending_stiffness needs at least 2 measurements")
    if not (np.isfinite(p).all() and np.isfinite(d).all()):
        raise DataError("calibration data contain NaN or inf")
    if np.ptp(p, axis=1).max() <= 0:
        raise DataError("every measurement has equal tube pressures: nothing bends, k_b "
                        "is unidentifiable",
                        hint="apply pressure differences")

    def model(logk):
        f = (BellowsFinger(finger.parameters.replace(bending_stiffness=float(np.exp(logk[0]))),
                           check=False))
        return f.bending(p).deflection

    k0 = finger.parameters.value("bending_stiffness")
    sol = least_squares(lambda x: model(x) - d, [math.log(k0)], method="lm")
    k = float(math.exp(sol.x[0]))
    J = sol.jac[:, 0]
    dof = max(d.size - 1, 1)
    s2 = deflection_std ** 2 if deflection_std is not None else float(sol.fun @ sol.fun) / dof
    var_log = s2 / float(J @ J)
    return k, k * math.sqrt(var_log)
