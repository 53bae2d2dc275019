"""The DLR/HIT Hand II finger and five-finger hand (``002_ddea254371185ad3.txt``), with the
thesis's parameters and their provenance, and the checks of where its printed numbers disagree.

Finger parameters (Appendices B and F, SI units): l1 = 55 mm, l2 = l3 = 25 mm; m1, m2, m3 and the
centre-of-mass vectors pc1..pc3 as printed, in the DH frames of the links they belong to (link 2
= proximal phalanx after the flexion joint, link 3 and link 4 after the proximal and distal joints;
the zero-length link between the two base joints is massless, Appendix A sets l0 = m0 = 0).

Inertia tensors — the thesis does not print them. Its printed mass term (Appendix F, M1) contains
every centre-of-mass term twice (``2·l1c²·m1·cos(t2)²``, ``l2c²·m2 + l2c²·m2·cos(2t2+2t3)``, ...):
once as the point mass and once as the link's own inertia. That is exactly a thin-rod tensor with
the centre of mass on the link axis at distance lc = |pc|, I_C = diag(0, m·lc², m·lc²) in the link
frame (x along the link). gripkit uses these tensors (with the printed pc vectors, not their
norms) and its tests reproduce M1 and the centrifugal terms C2, C3 of Appendices B/F exactly when
the centres of mass are put on the link axes as the thesis does.

Rotor inertia I_m = 5.1·10⁻⁷ kg·m² (Appendix A), reflected through N = 208.3 (distal) and
234.3 (base): 0.0221 and 0.0280 kg·m² — a hundred times the links' own inertia.
"""

from __future__ import annotations

import math
from importlib import resources

import numpy as np

from ...consistency import Finding, compare
from ...errors import ModelError
from ...models.bldc import BLDCMotor, motor_parameters
from ...models.friction import FrictionTable
from ...params import Parameter, ParameterSet
from .finger import ACTUATORS, FINGER_PARAMETERS, DLRFinger

__all__ = ["thesis_finger_parameters", "dlr_hit_table", "finger_tables", "finger", "DLRHITFinger",
           "FINGERS",
           "TABLE_6_1", "BASE2_CORRECTION"]

SEED = "002_ddea254371185ad3.txt"
DEG = math.pi / 180.0
#: Table 6.1 (distal stiction): (position °, breakaway PWM); the PWMs of the last seven positions
#: (43–59°) are lost in the extraction
TABLE_6_1 = ((8, -1300), (8, 1200), (11, -1250), (13, 1250), (19, -1350), (23, 1250), (24, 1300),
             (27, -1300), (29, 1300), (33, -1350), (34, 1350), (37, -1350), (38, 1100), (43, -1200))
#: friction correction factor of base joint 2 (§6.3, §7: base 1's table "multiplied with a
#: correcting factor"; its value is not printed). Derived: Fig. 6.6 (base 2) reaches −1 N·m on
#: its friction axis where Fig. 6.5 (base 1) ends at −0.8 N·m.
BASE2_CORRECTION = 1.25
#: §6.3: "The maximum influence of dynamics (equations 4.18–4.20) is 7.1 mNm"
DYNAMICS_INFLUENCE = 7.1e-3
FINGERS = ("thumb", "index", "middle", "ring", "little")


def dlr_hit_table(joint: str, scale: float = 1.0) -> FrictionTable:
    """Appendix G's friction table for ``'distal'`` or ``'base'`` (recovered from the extraction;
    see the comment header of the shipped CSV files)."""
    if joint not in ("distal", "base"):
        raise ModelError(f"joint: expected 'distal' or 'base', found {joint!r}")
    fname = f"dlr_hit_friction_{joint}.csv"
    text = resources.files("gripkit.systems.dlr_hit").joinpath("data", fname).read_text()
    return FrictionTable.from_text(text, f"DLR/HIT II {joint} friction",
                                   f"002_ddea254371185ad3.txt, Appendix G "
                                   f"(gripkit/systems/dlr_hit/data/{fname})", scale)


def _pc(k):
    return {1: (3.0164510e-02, -1.0130813e-03, 5.0813186e-04),
            2: (5.7271879e-03, -1.6164173e-03, -1.1567914e-03),
            3: (6.1007977e-03, -8.3348211e-04, 1.7728256e-03)}[k]


def _link_parameters() -> list[Parameter]:
    """The phalanges' lengths, masses, centres of mass and inertias (Appendix F), in
    :data:`FINGER_PARAMETERS` order."""
    F = f"{SEED}, Appendix F"
    masses = (4.4370598e-02, 2.7110192e-02, 1.8179709e-02)
    ps = [
        Parameter("l1", 55e-3, "m", "proximal phalanx length (flexion → "
                                    "proximal joint)", bounds=(0, None), source=F,
                                    display_unit="mm"),
        Parameter("l2", 25e-3, "m", "middle phalanx length (proximal "
                                    "→ distal joint)", bounds=(0, None), source=F,
                                    display_unit="mm"),
        Parameter("l3", 25e-3, "m", "distal phalanx length (distal "
                                    "joint → fingertip)", bounds=(0, None), source=F,
                                    display_unit="mm"),
    ]
    for k in range(3):
        ps.append(Parameter(f"m{k + 1}", masses[k], "kg", f"mass of phalanx {k + 1}",
                            bounds=(0, None), source=F, display_unit="g"))
    for k in range(3):
        for j, ax in enumerate("xyz"):
            ps.append(Parameter(f"pc{k + 1}_{ax}", _pc(k + 1)[j], "m",
                                f"centre of mass of phalanx {k + 1}, {ax} (link frame)",
                                source=F, display_unit="mm"))
    for k in range(3):
        lc2 = float(np.sum(np.square(_pc(k + 1))))
        I = masses[k] * lc2  # noqa: E741
        src = "derived: Appendix F's M1 implies a thin rod, I = m·|pc|² about axes ⟂ the link"
        ps += [Parameter(f"I{k + 1}_xx", 0.0, "kg*m^2", f"phalanx {k + 1} inertia "
                                                        "about its axis (COM)", bounds=(0, None),
                                                        source=src),
               Parameter(f"I{k + 1}_yy", I, "kg*m^2", f"phalanx {k + 1} inertia "
                                                      "⟂ axis, y (COM)", bounds=(0, None),
                                                      source=src),
               Parameter(f"I{k + 1}_zz", I, "kg*m^2", f"phalanx {k + 1} inertia "
                                                      "⟂ axis, z (COM)", bounds=(0, None),
                                                      source=src)]
    return ps


def _drive_parameters() -> list[Parameter]:
    """The rotor inertia, motor angle, gravity and transmission ratios (Appendices A, E, F;
    Fig. 7.2), in :data:`FINGER_PARAMETERS` order."""
    return [
        Parameter("I_m", 5.1e-7, "kg*m^2", "motor rotor inertia", bounds=(0, None),
                  source=f"{SEED}, Appendix A (Im1m = 5.1e-07)"),
        Parameter("beta", math.pi / 4, "rad", "angle of the base motors to "
                                              "the dynamics axes", bounds=(0.01, 1.56),
                  fixed=True, source=f"{SEED}, Fig. 7.2 (±45°)", display_unit="deg"),
        Parameter("g_x", 0.0, "m/s^2", "gravity in the finger base frame, x",
                  source="assumed: palm horizontal, facing down"),
        Parameter("g_y", 0.0, "m/s^2", "gravity in the finger base frame, y",
                  source="assumed: palm horizontal, facing down"),
        Parameter("g_z", -9.81, "m/s^2", "gravity in the finger base frame, z (abduction axis)",
                  source=f"{SEED}, Appendix F (g = 9.81); direction assumed"),
        Parameter("N_hd", 100.0, "1", "harmonic drive reduction", bounds=(1e-3, None),
                  source=f"{SEED}, §3.1 and Appendix E"),
        Parameter("N_belt", 2.083, "1", "timing belt motor "
                                        "→ harmonic drive", bounds=(1e-3, None),
                                        source=f"{SEED}, Appendix E"),
        Parameter("N_belt_base", 1.125, "1", "timing belt harmonic drive → "
                                             "bevel gears (base)", bounds=(1e-3, None),
                  source=f"{SEED}, Appendix E"),
        Parameter("eta", 1.0, "1", "transmission efficiency (losses are in the "
                                   "friction tables)", bounds=(0.05, 1.0),
                  source=f"{SEED}, Appendix E (no losses)"),
    ]


def _friction_parameters() -> list[Parameter]:
    """The drives' friction: stiction, table factors, Stribeck, LuGre, ripple and Karnopp
    (Appendices F, G; §3.2.2, §6.3), in :data:`FINGER_PARAMETERS` order."""
    return [
        Parameter("fs_base1", 0.36, "N*m", "stiction of base drive 1", bounds=(0, None),
                  source=f"{SEED}, Appendix F (stiction = 0.36)"),
        Parameter("fs_base2", 0.36, "N*m", "stiction of base drive 2", bounds=(0, None),
                  source=f"{SEED}, Appendix F (stiction = 0.36)"),
        Parameter("fs_distal", 0.36, "N*m", "stiction of the proximal/distal drive",
                  bounds=(0, None),
                  source=f"{SEED}, Appendix F (stiction = 0.36; PWM 1200 via eq 5.7 × 208.3)"),
        Parameter("scale_base1", 1.0, "1", "factor on Appendix G's base "
                                           "table, base drive 1", bounds=(0, None),
                                           source=f"{SEED}, §6.3"),
        Parameter("scale_base2", BASE2_CORRECTION, "1", "correction factor on the base "
                                                        "table, base drive 2", bounds=(0, None),
                  source=f"derived: {SEED}, Fig. 6.6 vs Fig. 6.5 friction axes (−1 vs −0.8 N·m); "
                         "§6.3 prints no value"),
        Parameter("scale_distal", 1.0, "1", "factor on Appendix "
                                            "G's distal table", bounds=(0, None),
                                            source=f"{SEED}, §6.3"),
        Parameter("fc_base1", 0.0940, "N*m", "Coulomb friction (Stribeck "
                                             "option), base 1", bounds=(0, None),
                  source="fitted to Appendix G's base table (fs = 0.36, v_s = 0.1 rad/s, δ = 2 "
                         "fixed): 0.094 ± 0.021"),
        Parameter("fc_base2", 0.0940 * BASE2_CORRECTION, "N*m", "Coulomb friction (Stribeck "
                                                                "option), base 2", bounds=(0, None),
                  source="base 1 value × the base-2 correction factor"),
        Parameter("fc_distal", 0.1877, "N*m", "Coulomb friction (Stribeck "
                                              "option), distal", bounds=(0, None),
                  source="fitted to Appendix G's distal table (fs = 0.36, v_s = 0.1 rad/s, δ = 2 "
                         "fixed): 0.188 ± 0.011"),
        Parameter("visc_base1", 0.0555, "N*m*s/rad", "viscous friction (Stribeck "
                                                     "option), base 1", bounds=(0, None),
                  source="fitted to Appendix G's base table: 0.055 ± 0.014"),
        Parameter("visc_base2", 0.0555 * BASE2_CORRECTION, "N*m*s/rad", "viscous friction "
                                                                        "(Stribeck option), base 2",
                                                                        bounds=(0, None),
                  source="base 1 value × the base-2 correction factor"),
        Parameter("visc_distal", 0.0, "N*m*s/rad", "viscous friction (Stribeck "
                                                   "option), distal", bounds=(0, None),
                  source="fitted to Appendix G's distal table: -0.001 ± 0.007, i.e. 0"),
        Parameter("cubic_base1", 0.00578, "N*m*s^3/rad^3", "cubic velocity friction (Stribeck "
                                                           "option), base 1",
                  source="fitted to Appendix G's base table: 0.0058 ± 0.0008 (cubic term "
                         "of [50], §3.2.2)"),
        Parameter("cubic_base2", 0.00578 * BASE2_CORRECTION, "N*m*s^3/rad^3",
                  "cubic velocity friction, base 2",
                  source="base 1 value × the base-2 correction factor"),
        Parameter("cubic_distal", 0.00352, "N*m*s^3/rad^3", "cubic velocity friction (Stribeck "
                                                            "option), distal",
                  source="fitted to Appendix G's distal table: 0.0035 ± 0.0003"),
        Parameter("v_s", 0.1, "rad/s", "Stribeck velocity (Stribeck "
                                       "and LuGre options)", bounds=(1e-9, None),
                  source="assumed: below the tables' lowest velocity (20 °/s)"),
        Parameter("delta", 2.0, "1", "Stribeck shape factor", bounds=(-10.0, 10.0),
                  source="assumed (Gaussian Stribeck)"),
        Parameter("sigma0", 360.0, "N*m/rad", "LuGre bristle stiffness", bounds=(1e-9, None),
                  source="assumed: pre-sliding deflection fs/σ0 = 1 mrad"),
        Parameter("sigma1", 2.8, "N*m*s/rad", "LuGre bristle damping", bounds=(0, None),
                  source="assumed: σ1 = sqrt(σ0·J), damping ratio ~0.5 in pre-sliding"),
        Parameter("ripple_amp", 0.0, "N*m", "harmonic-drive friction "
                                            "ripple amplitude", bounds=(0, None),
                  source=f"{SEED}, §3.2.2 (not quantified; off)"),
        Parameter("ripple_cycles", 200.0, "1", "ripple periods per output revolution",
                  bounds=(0, None), source="assumed: two per wave-generator turn, 100:1"),
        Parameter("v_stick", 1e-5, "rad/s", "Karnopp zero-velocity band", bounds=(0, None),
                  source="assumed"),
    ]


def _limit_parameters() -> list[Parameter]:
    """The joint limits and the end stops' stiffness and damping (§7.1), in
    :data:`FINGER_PARAMETERS` order."""
    return [
        Parameter("abd_min", -30 * DEG, "rad", "abduction limit, lower",
                  source="assumed (range not printed)", display_unit="deg"),
        Parameter("abd_max", 30 * DEG, "rad", "abduction limit, upper",
                  source="assumed (range not printed)", display_unit="deg"),
        Parameter("flex_min", 0.0, "rad", "base flexion limit, lower",
                  source="assumed (range not printed)", display_unit="deg"),
        Parameter("flex_max", 90 * DEG, "rad", "base flexion limit, upper",
                  source="assumed (range not printed)", display_unit="deg"),
        Parameter("prox_min", 0.0, "rad", "proximal (= distal) limit, lower",
                  source="assumed (range not printed)", display_unit="deg"),
        Parameter("prox_max", 90 * DEG, "rad", "proximal (= distal) limit, upper",
                  source="assumed (range not printed)", display_unit="deg"),
        Parameter("k_stop", 60.0, "N*m/rad", "end-stop stiffness (belt and "
                                             "harmonic-drive elasticity)", bounds=(0, None),
                  source="assumed: brakes the finger within ~30 ms (§7.1, 'high negative slope')"),
        Parameter("d_stop", 0.45, "N*m*s/rad", "end-stop damping", bounds=(0, None),
                  source="assumed: damping ratio ~0.2, 'resilience ... after the braking' (§7.1)"),
    ]


def thesis_finger_parameters(**overrides) -> ParameterSet:
    """The finger's parameters (every name of :data:`FINGER_PARAMETERS`) with provenance;
    ``overrides`` replace values (SI, or strings with units)."""
    ps = (_link_parameters() + _drive_parameters() + list(motor_parameters().values())
          + _friction_parameters() + _limit_parameters())
    pset = ParameterSet(ps, "dlr-hit-finger")
    if tuple(pset.names) != FINGER_PARAMETERS:
        raise ModelError("internal: finger parameter order does not match FINGER_PARAMETERS")
    return pset.replace(**overrides) if overrides else pset


def finger_tables(base2_scale: float = 1.0, clean: bool = False):
    """Appendix G's tables for (base1, base2, distal); the base-2 correction factor is the
    ``scale_base2`` parameter, so the tables themselves are unscaled by default. ``clean`` drops
    the two printed points that lie ~50 % off their neighbours (see the consistency checks)."""
    base = dlr_hit_table("base")
    distal = dlr_hit_table("distal")
    if clean:
        base, distal = base.without_outliers(), distal.without_outliers()
    return (base, base.scaled(base2_scale), distal)


class DLRHITFinger(DLRFinger):
    """:class:`~gripkit.systems.dlr_hit.finger.DLRFinger` with the thesis's numbers and its
    checks."""

    def consistency_checks(self) -> list[Finding]:
        return finger_consistency_checks(self)


def finger(*, friction: str = "table", integrator: str = "semi-implicit", thermal: bool = False,
           check: bool = True, clean_tables: bool = False, **overrides) -> DLRHITFinger:
    """The DLR/HIT Hand II finger of chapter 7 (Fig. 7.1); ``overrides`` replace parameter values
    (SI), ``clean_tables`` drops Appendix G's two outlying points."""
    return DLRHITFinger(thesis_finger_parameters(**overrides), finger_tables(clean=clean_tables),
                        friction=friction, integrator=integrator, thermal=thermal, check=check)


# --- consistency checks ---------------------------------------------------------------------------

def _motor(model) -> BLDCMotor:
    names = motor_parameters().names
    return BLDCMotor(ParameterSet([model.parameters[n] for n in names], "bldc"))


def _thesis_M1(model, t2: float, t3: float) -> float:
    """Appendix F's printed M1 (abduction mass term) with lc = |pc| (the thesis's
    simplification)."""
    v = model.parameters.value
    l1, l2 = v("l1"), v("l2")
    m1, m2, m3 = v("m1"), v("m2"), v("m3")
    l1c, l2c, l3c = (math.sqrt(v(f"pc{k}_x") ** 2 + v(f"pc{k}_y") ** 2 + v(f"pc{k}_z") ** 2)
                     for k in (1, 2, 3))
    N1 = v("N_hd") * v("N_belt") * v("N_belt_base")
    c = math.cos
    return (v("I_m") * N1 ** 2 + (l2 ** 2 * m3) / 2 + l2c ** 2 * m2 + l3c ** 2 * m3
            + (l2 ** 2 * m3 * c(2 * t2 + 2 * t3)) / 2 + l2c ** 2 * m2 * c(2 * t2 + 2 * t3)
            + l3c ** 2 * m3 * c(2 * t2 + 4 * t3) + l1 ** 2 * m2 * c(t2) ** 2 + l1 ** 2 * m3
            * c(t2) ** 2
            + 2 * l1c ** 2 * m1 * c(t2) ** 2 + l1 * l3c * m3 * c(2 * t2 + 2 * t3)
            + l2 * l3c * m3 * c(2 * t2 + 3 * t3) + l1 * l2 * m3 * c(t3) + l1 * l2c * m2 * c(t3)
            + l2 * l3c * m3 * c(t3) + l1 * l2 * m3 * c(2 * t2 + t3) + l1 * l2c * m2 * c(2 * t2 + t3)
            + l1 * l3c * m3 * c(2 * t3))


def max_gravity_torque(model, n: int = 13) -> np.ndarray:
    """Largest |G| per joint (abduction, flexion, proximal incl. the coupled distal torque) over a
    grid of the joint ranges, N·m."""
    v = model.parameters.value
    ch = model.chain()
    grids = [np.linspace(v(f"{j}_min"), v(f"{j}_max"), n) for j in ("abd", "flex", "prox")]
    Q = np.array(np.meshgrid(*grids, indexing="ij")).reshape(3, -1).T
    q4 = np.column_stack([Q, Q[:, 2]])
    g = ch.chain.gravity(q4)
    return np.array([np.abs(g[:, 0]).max(), np.abs(g[:, 1]).max(), np.abs(g[:, 2] + g[:, 3]).max()])


def finger_consistency_checks(model) -> list[Finding]:
    subj = model.name
    v = model.parameters.value
    out = list(_motor(model).consistency_checks())
    N = model.ratios()
    c = v("c_pwm")
    # stiction: §6.2's procedure (PWM 1200 through eq 5.7 and the gear ratio) vs Appendix F's 0.36
    for k, a in enumerate(ACTUATORS):
        out.append(compare(f"stiction-{a}", subj, computed=c * 1200 * N[k], stated=v(f"fs_{a}"),
                           rtol=0.03,
                           what=f"§6.2: PWM 1200 × eq 5.7 × N = {N[k]:.4g}", unit="N*m",
                           used=f"gripkit uses fs_{a} = {v(f'fs_{a}'):.3g} N·m (Appendix F, the "
                                "value the thesis "
                                f"simulated); set fs_{a}={c * 1200 * N[k]:.3g} to follow §6.2",
                           source=f"{SEED}, §6.2 and Appendix F"))
    pw = np.array([abs(p) for _, p in TABLE_6_1], dtype=float)
    out.append(compare("table-6.1-mean", subj, computed=float(pw.mean()), stated=1200.0, rtol=0.05,
                       what=f"mean |PWM| of the {pw.size} legible rows of Table 6.1 "
                            "(distal breakaway)",
                       used="gripkit uses PWM 1200 (0.36 N·m) as the thesis does; the distal "
                            "mean would give "
                            f"{c * pw.mean() * N[2]:.3g} N·m (seven rows, 43–59°, are lost in "
                            "the extraction)",
                       source=f"{SEED}, Table 6.1 and §6.2"))
    # dynamics influence: §6.3 says at most 7.1 mNm
    gmax = max_gravity_torque(model)
    out.append(compare("dynamics-influence-distal", subj, computed=float(gmax[2]),
                       stated=DYNAMICS_INFLUENCE,
                       rtol=0.25, what="largest gravity torque on the proximal/distal "
                                       "joints (θ4 = θ3)", unit="N*m",
                       used="gripkit keeps all dynamic terms, as the thesis finally does",
                       source=f"{SEED}, §6.3"))
    out.append(compare("dynamics-influence-flexion", subj, computed=float(gmax[1]),
                       stated=DYNAMICS_INFLUENCE,
                       rtol=0.25, what="largest gravity torque on the "
                                       "base flexion joint", unit="N*m",
                       used="gripkit keeps all dynamic terms: at the base, gravity reaches "
                            f"{1e3 * gmax[1]:.3g} mN·m, {100 * gmax[1] / 0.2:.0f} % of the "
                            "smallest friction (200 mN·m)",
                       source=f"{SEED}, §6.3 ('maximum influence of dynamics is 7.1 mNm')"))
    # Appendix G: the fastest breakpoint of each table is where PWM ±4000 balances friction
    for a, k in (("distal", 2), ("base1", 0)):
        t = model.tables[k]
        for i, sgn in ((-1, 1.0), (0, -1.0)):
            vb = t.velocity[i]
            tau = float(model.motor_torque(a, sgn * 4000.0, vb))
            out.append(compare(f"appendix-G-{a}-{'max' if sgn > 0 else 'min'}", subj, computed=tau,
                               stated=float(t.friction[i] * t.scale), rtol=0.03,
                               what=f"eq 5.10 at PWM {sgn * 4000:+.0f} and the table's "
                                    "last breakpoint "
                                    f"{vb / DEG:.4g} °/s", unit="N*m",
                               used="confirms the recovered table assignment (distal spans ±290 "
                                    "°/s, base ±240 °/s)",
                               source=f"{SEED}, Appendix G with eq 5.10"))
    # the lowest breakpoints should be reached at the lowest PWM of Appendix D (1500)
    t = model.tables[2]
    vlow = float(np.min(t.velocity[t.velocity > 0]))
    v1500 = model.steady_velocity("distal", 1500.0)
    out.append(compare("appendix-G-distal-lowest-velocity", subj, computed=v1500 / DEG,
                       stated=vlow / DEG, rtol=0.25,
                       what="steady velocity of eq 5.10 against the distal table at PWM 1500 "
                            "(lowest PWM of §6.2)",
                       unit="deg/s",
                       used="gripkit uses eq 5.10 and the table as printed; the table's slowest "
                            "points imply PWM "
                            "≈ 1000, below the stiction level, so motor model and table "
                            "disagree at low speed",
                       source=f"{SEED}, §6.2 and Appendix G"))
    for name, k in (("distal", 2), ("base", 0)):
        t = model.tables[k]
        for i, med in dlr_hit_table(name).outliers():
            out.append(compare(f"appendix-G-{name}-point-{t.velocity[i] / DEG:.1f}", subj,
                               computed=float(t.friction[i]), stated=med, rtol=0.3,
                               what=f"Appendix G {name} table at {t.velocity[i] / DEG:.1f} "
                                    "°/s (against the "
                                    f"median of its four neighbours)", unit="N*m",
                               used="gripkit keeps the printed point (the thesis "
                                    "simulated with it); "
                                    "finger(clean_tables=True) drops it",
                               source=f"{SEED}, Appendix G ('wrong measurement points were "
                                      "deleted', §6.2)"))
    out.append(compare("belt-ratio", subj, computed=v("N_belt"), stated=2.1, rtol=0.02,
                       what="Appendix E's belt ratio 2.083 against §3.1's '1:2.1'",
                       used="gripkit uses 2.083 (Appendix E)",
                       source=f"{SEED}, §3.1 and Appendix E"))
    # the thesis's Appendix F mass term (lc = |pc|) against gripkit's (full pc vectors)
    ch = model.chain()
    M = ch.mass_matrix(np.zeros(3))
    # M1 is the abduction term in joint coordinates: Γ is orthogonal at β = 45°, so M_q = Γ M_p Γᵀ
    G = ch.coupling.matrix[:3]
    Mq = G @ M @ G.T
    out.append(compare("appendix-F-M1", subj, computed=float(Mq[0, 0]),
                       stated=_thesis_M1(model, 0.0, 0.0), rtol=0.01,
                       what="abduction mass term at θ = 0 with the "
                            "printed pc vectors", unit="kg*m^2",
                       used="gripkit uses the full pc vectors; the thesis puts the centres of mass "
                            "on the link axes",
                       source=f"{SEED}, Appendix F (M1)"))
    return out
