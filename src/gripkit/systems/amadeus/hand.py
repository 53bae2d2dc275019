"""The AMADEUS three-finger hand: palm, knuckles, fingertip kinematics and force closure
(``000_8f66dcc7ab06470c.txt`` §II-B, §II-C, Fig. 2).

Palm and knuckles (§II-B)
-------------------------
Three fingers stand on the palm "as a symmetrical triangle": finger i's knuckle pivot is at
radius R_p and azimuth α_i = 90° + 120° i (hand frame: Z along the fingers when straight, X, Y in
the palm). A single central cylinder drives the three knuckles together through ±20° ("40° of
angular rotation"); the angle is read by a rotary potentiometer through a rack and pinion (§II-C),
θ = (V − V₀)/k_pot. θ > 0 opens the hand. Finger i's base frame has x_f along the finger
(cos θ Z + sin θ r̂_i), y_f toward the hand axis (−cos θ r̂_i + sin θ Z) — so bending direction
ψ = 0 (tube 1 high) closes the finger onto the object — and z_f = x_f × y_f. The bellows start
``knuckle_offset`` along x_f from the pivot.

Object sizes. A straight finger's fingertip is at radius ρ(θ) = R_p + L sin θ from the hand axis,
L = knuckle_offset + (bellows length + tip length); three pads of radius r_pad touch a cylinder or
sphere of diameter D when ρ = D/2 + r_pad. The seed says the knuckle "is sufficient to enable the
finger tips to touch and grasp small objects (∅ 10 mm) or move apart so that larger objects (up
to ∅ 150 mm) may be considered". The palm radius is not given; gripkit derives it from the first
half of that sentence (fully closed knuckles, −20°, bring the pads onto a ∅10 mm object) and
:meth:`AmadeusHand.consistency_checks` checks the second: the ∅150 mm object needs a knuckle angle
inside ±20°.

Force closure (precision grasp, §I "fingertip precision grasps")
---------------------------------------------------------------
Point contacts with Coulomb friction: each contact transmits forces inside its friction cone
|f_t| ≤ μ f_n, linearised by ``n_edges`` edges f_j = n + μ(cos φ_j t₁ + sin φ_j t₂). The primitive
wrenches w_j = [f_j; (p − c) × f_j / ρ] (c the contacts' centroid, ρ a torque scale) achieve
*force closure* iff they positively span R⁶, i.e. the origin lies strictly inside their convex
hull: rank 6 and a strictly positive combination Σ λ_j w_j = 0 exists — found by the linear
program max s s.t. Σλ_j w_j = 0, Σλ_j = 1, λ_j ≥ s (:func:`force_closure`). The Ferrari–Canny
quality ε (radius of the largest origin-centred ball inside the hull, unit total normal force)
comes from the hull's facets. Classical checks (tested): two antipodal point contacts never give
force closure (no torque about their axis); three contacts 120° apart on a sphere's equator do for
any μ > 0; contacts bunched on one side do not unless μ is large.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...consistency import Finding, compare, warn_inconsistent
from ...errors import DataError, ModelError
from ...params import Parameter, ParameterSet
from .bellows_finger import BAR, BellowsFinger

__all__ = ["AmadeusHand", "hand_parameters", "force_closure", "ForceClosure", "FINGER_AZIMUTHS"]

_SEED = "000_8f66dcc7ab06470c.txt"
#: azimuths α_i of the three knuckle pivots on the palm (rad)
FINGER_AZIMUTHS = np.deg2rad([90.0, 210.0, 330.0])


def hand_parameters(*, palm_radius: float = 0.0756, knuckle_offset: float = 0.015,
                    knuckle_range: float = math.radians(20.0), pad_radius: float = 0.008,
                    pot_gain: float = 2.0 / math.radians(20.0),
                    pot_offset: float = 2.5) -> ParameterSet:
    """Palm, knuckle and potentiometer parameters (SI)."""
    return ParameterSet([
        Parameter("palm_radius", palm_radius, "m", "radius of the knuckle pivots' "
                                                   "circle on the palm",
                  bounds=(0.0, 1.0),
                  source=f"derived: at -20° the pads just touch a ∅10 mm object ({_SEED} "
                         "§II-B), with the "
                         "assumed finger reach; AmadeusHand.palm_radius_for() recomputes it",
                  display_unit="mm"),
        Parameter("knuckle_offset", knuckle_offset, "m", "from knuckle pivot to the bellows base",
                  bounds=(0.0, 1.0), source="assumed: knuckle "
                                            "manifold (Fig. 2(b))", display_unit="mm"),
        Parameter("knuckle_range", knuckle_range, "rad", "knuckle travel either side of "
                                                         "parallel fingers",
                  bounds=(0.0, math.pi / 2), source=f"{_SEED} Fig. 2(c) (±20°), "
                                                    "§II-B (40° rotation)",
                  display_unit="deg"),
        Parameter("pad_radius", pad_radius, "m", "radius of the fingertip's contact surface",
                  bounds=(0.0, 0.1), source="assumed: fingertip of Fig. 4", display_unit="mm"),
        Parameter("pot_gain", pot_gain, "V/rad", "knuckle potentiometer sensitivity "
                                                 "(rack and pinion)",
                  bounds=(1e-6, None), source="assumed: ±2 V over ±20° (§II-C gives no scale)"),
        Parameter("pot_offset", pot_offset, "V", "potentiometer voltage with parallel fingers",
                  source="assumed: mid-range of a 0-5 V potentiometer"),
    ], "amadeus-hand")


@dataclass(frozen=True)
class ForceClosure:
    """Result of :func:`force_closure`: ``closure`` (bool), LP ``margin`` s* (> 0 for closure),
    Ferrari–Canny ``epsilon`` (0 without closure), wrench-space ``rank``, and the primitive
    ``wrenches`` (6, n_contacts·n_edges)."""

    closure: bool
    margin: float
    epsilon: float
    rank: int
    wrenches: np.ndarray


def _tangents(n):
    a = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t1 = np.cross(n, a)
    t1 /= np.linalg.norm(t1)
    return t1, np.cross(n, t1)


def force_closure(points, normals, mu: float, *, n_edges: int = 8,
                  torque_scale: float | None = None) -> ForceClosure:
    """Force-closure test for point contacts with friction (see the module docstring).

    Parameters
    ----------
    points
        (k, 3) contact positions (m).
    normals
        (k, 3) inward contact normals (pointing into the object), normalised here.
    mu
        Friction coefficient (>= 0).
    n_edges
        Edges of each linearised friction cone.
    torque_scale
        ρ (m) dividing torques (default: the largest contact distance from the centroid).
    """
    from scipy.optimize import linprog
    from scipy.spatial import ConvexHull, QhullError

    P = np.atleast_2d(np.asarray(points, dtype=np.float64))
    Nn = np.atleast_2d(np.asarray(normals, dtype=np.float64))
    if P.shape != Nn.shape or P.shape[1] != 3:
        raise DataError(f"points and normals must both be (k, 3), found {P.shape} and {Nn.shape}")
    if not (np.isfinite(P).all() and np.isfinite(Nn).all()):
        raise DataError("contact points or normals contain NaN or inf")
    if not (np.isfinite(mu) and mu >= 0):
        raise DataError(f"mu: expected a friction coefficient >= 0, found {mu!r}")
    if int(n_edges) < 3:
        raise DataError(f"n_edges: expected >= 3 edges per friction cone, found {n_edges}")
    norms = np.linalg.norm(Nn, axis=1)
    if (norms == 0).any():
        raise DataError("a contact normal is zero")
    Nn = Nn / norms[:, None]
    c = P.mean(0)
    rho = (torque_scale if torque_scale is not None
           else max(float(np.linalg.norm(P - c, axis=1).max()), 1e-12))
    cols = []
    ph = 2 * np.pi * np.arange(int(n_edges)) / int(n_edges)
    for p, n in zip(P, Nn):
        t1, t2 = _tangents(n)
        for a in ph:
            f = n + mu * (math.cos(a) * t1 + math.sin(a) * t2)
            cols.append(np.concatenate([f, np.cross(p - c, f) / rho]))
    W = np.array(cols).T
    rank = int(np.linalg.matrix_rank(W, tol=1e-9 * max(1.0, np.abs(W).max())))
    K = W.shape[1]
    # max s  s.t.  W λ = 0, Σλ = 1, λ_j - s >= 0
    cvec = np.zeros(K + 1)
    cvec[-1] = -1.0
    A_eq = np.zeros((7, K + 1))
    A_eq[:6, :K] = W
    A_eq[6, :K] = 1.0
    b_eq = np.zeros(7)
    b_eq[6] = 1.0
    A_ub = np.hstack([-np.eye(K), np.ones((K, 1))])
    res = linprog(cvec, A_ub=A_ub, b_ub=np.zeros(K), A_eq=A_eq, b_eq=b_eq,
                  bounds=[(0, None)] * K + [(None, None)], method="highs")
    margin = float(res.x[-1]) if res.status == 0 else -math.inf
    closure = bool(rank == 6 and margin > 1e-9)
    eps = 0.0
    if closure:
        try:
            hull = ConvexHull(W.T)
            eps = float(max(0.0, np.min(-hull.equations[:, -1])))
        except QhullError:
            eps = 0.0
    return ForceClosure(closure, margin, eps, rank, W)


class AmadeusHand:
    """Three bellows fingers on a palm with coupled knuckles (see the module docstring)."""

    name = "amadeus-hand"
    description = "AMADEUS three-finger hand: palm, knuckles, fingertip kinematics, force closure"

    def __init__(self, finger: BellowsFinger | None = None, parameters: ParameterSet | None = None,
                 *,
                 check: bool = True, **kw):
        self.finger = finger if finger is not None else BellowsFinger(check=False)
        if parameters is None and "palm_radius" not in kw:
            self.hand_parameters = hand_parameters(**kw)
            kw["palm_radius"] = self.palm_radius_for(0.010)
        self.hand_parameters = parameters if parameters is not None else hand_parameters(**kw)
        if check:
            warn_inconsistent(self.consistency_checks())

    @property
    def parameters(self) -> ParameterSet:
        return self.hand_parameters.merged(self.finger.parameters, "amadeus-hand")

    def _hp(self, n):
        return self.hand_parameters.value(n)

    # -- knuckle --------------------------------------------------------------------------
    def knuckle_angle(self, voltage) -> np.ndarray:
        """Knuckle angle θ (rad) from the potentiometer voltage (V); raises when the reading
        implies an angle beyond the mechanical range (by more than 1°)."""
        v = np.asarray(voltage, dtype=np.float64)
        if not np.isfinite(v).all():
            raise DataError("potentiometer voltage contains NaN or inf")
        th = (v - self._hp("pot_offset")) / self._hp("pot_gain")
        lim = self._hp("knuckle_range")
        if (np.abs(th) > lim + math.radians(1.0)).any():
            bad = float(v.flat[int(np.argmax(np.abs(th)))])
            raise DataError(
                f"potentiometer reads {bad:.4g} V = "
                f"{math.degrees((bad - self._hp('pot_offset')) / self._hp('pot_gain')):.3g}°, "
                f"beyond the ±{math.degrees(lim):.3g}° knuckle range",
                hint="check the potentiometer wiring, offset and gain")
        return th

    def potentiometer_voltage(self, angle) -> np.ndarray:
        return self._hp("pot_offset") + self._hp("pot_gain") * np.asarray(angle, dtype=np.float64)

    def _check_angle(self, angle: float) -> float:
        a = float(angle)
        lim = self._hp("knuckle_range")
        if not math.isfinite(a) or abs(a) > lim + 1e-12:
            raise DataError(f"knuckle angle {math.degrees(a):.4g}° is outside "
                            f"±{math.degrees(lim):.3g}°")
        return a

    def finger_frames(self, angle: float) -> list[tuple[np.ndarray, np.ndarray]]:
        """For each finger: (origin (3,), rotation (3, 3) with columns x_f, y_f, z_f) in the hand
        frame, at knuckle angle ``angle`` (rad)."""
        th = self._check_angle(angle)
        out = []
        Z = np.array([0.0, 0.0, 1.0])
        for a in FINGER_AZIMUTHS:
            r = np.array([math.cos(a), math.sin(a), 0.0])
            xf = math.cos(th) * Z + math.sin(th) * r
            yf = -math.cos(th) * r + math.sin(th) * Z
            zf = np.cross(xf, yf)
            origin = self._hp("palm_radius") * r + self._hp("knuckle_offset") * xf
            out.append((origin, np.column_stack([xf, yf, zf])))
        return out

    def fingertip_positions(self, angle: float, pressures) -> np.ndarray:
        """Fingertip positions (3, 3) m in the hand frame for knuckle ``angle`` (rad) and tube
        pressures (3, 3) Pa (row = finger) or (3,) (the same for every finger)."""
        P = np.asarray(pressures, dtype=np.float64)
        P = np.broadcast_to(P, (3, 3)) if P.shape == (3,) else P
        if P.shape != (3, 3):
            raise DataError(f"pressures: expected (3,) or (3 fingers, 3 tubes), found {P.shape}")
        tips = self.finger.bending(P).tip
        return np.array([o + R @ tip for (o, R), tip in zip(self.finger_frames(angle), tips)])

    def palm_radius_for(self, smallest_object: float, mean_pressure: float = 21.0 * BAR) -> float:
        """Palm radius (m) at which fully closed knuckles (−range) bring the straight fingers' pads
        onto an object of diameter ``smallest_object`` (§II-B: ∅10 mm)."""
        return (0.5 * smallest_object + self._hp("pad_radius")
                + self.reach(mean_pressure) * math.sin(self._hp("knuckle_range")))

    def reach(self, mean_pressure: float = 21.0 * BAR) -> float:
        """L (m): knuckle pivot to the straight fingertip at ``mean_pressure``."""
        b = self.finger.bending(np.full(3, mean_pressure))
        return self._hp("knuckle_offset") + float(b.tip[0])

    def knuckle_angle_for_object(self, diameter: float, mean_pressure: float = 21.0 * BAR) -> float:
        """Knuckle angle (rad) at which the straight fingers' pads touch a ∅``diameter`` object
        centred on the hand axis; raises ModelError if beyond the knuckle range."""
        d = float(diameter)
        if not (math.isfinite(d) and d > 0):
            raise DataError(f"diameter: expected a positive size in m, found {diameter!r}")
        L = self.reach(mean_pressure)
        s = (0.5 * d + self._hp("pad_radius") - self._hp("palm_radius")) / L
        lim = self._hp("knuckle_range")
        if abs(s) > 1 or abs(math.asin(s)) > lim + 1e-12:
            need = "beyond 90°" if abs(s) > 1 else f"{math.degrees(math.asin(s)):.3g}°"
            raise ModelError(f"a ∅{d * 1e3:.4g} mm object needs a knuckle angle of {need}, outside "
                             f"±{math.degrees(lim):.3g}°",
                             hint="use finger bending (up to 20 mm) or the arm")
        return math.asin(s)

    # -- grasp -----------------------------------------------------------------------------
    def sphere_contacts(self, angle: float, pressures, diameter: float | None = None):
        """Contact points and inward normals of the three pads on a sphere through the fingertips
        (centre on the hand axis at the tips' mean height; diameter from the tips if not given)."""
        tips = self.fingertip_positions(angle, pressures)
        centre = np.array([0.0, 0.0, tips[:, 2].mean()])
        radial = tips - centre
        dist = np.linalg.norm(radial, axis=1)
        if (dist < 1e-9).any():
            raise ModelError("a fingertip is on the hand axis: the sphere contact is undefined")
        n_in = -radial / dist[:, None]
        R = 0.5 * diameter if diameter is not None else float(dist.mean() - self._hp("pad_radius"))
        pts = centre - n_in * R
        return pts, n_in

    def force_closure(self, angle: float, pressures, mu: float, **kw) -> ForceClosure:
        """Force closure of the three-fingertip precision grasp of the sphere through the tips."""
        pts, n = self.sphere_contacts(angle, pressures)
        return force_closure(pts, n, mu, **kw)

    # -- checks ----------------------------------------------------------------------------
    def consistency_checks(self) -> list[Finding]:
        lim = self._hp("knuckle_range")
        L = self.reach()
        out = [compare("knuckle-travel-40deg", self.name, computed=math.degrees(2 * lim),
                       stated=40.0,
                       rtol=1e-9, what="total knuckle travel 2 x range", unit="deg", used="±range",
                       source=f"{_SEED} §II-B (40° of angular rotation) vs Fig. 2(c) (±20°)")]
        for d in (0.010, 0.150):
            s = (0.5 * d + self._hp("pad_radius") - self._hp("palm_radius")) / L
            ang = math.degrees(math.asin(max(-1.0, min(1.0, s))))
            ok = abs(ang) <= math.degrees(lim) + 1e-9
            out.append(Finding(f"object-{int(round(d * 1e3))}mm-reachable", self.name, ok,
                               f"knuckle angle needed for a ∅{d * 1e3:.0f} mm object: {ang:.3g}° "
                               f"(range ±{math.degrees(lim):.3g}°; assumed palm radius "
                               f"{self._hp('palm_radius') * 1e3:.3g} mm, reach {L * 1e3:.4g} mm)",
                               "assumed palm geometry", ang, math.degrees(lim), math.nan, math.nan,
                               f"{_SEED} §II-B and Fig. 2(c): target objects ∅10-150 mm"))
        return out
