"""FemtoTools FT-G100 electrostatic MEMS microgripper: knowledge-based models (seed
``003_abd62b560633beaf.txt``, Boudaoud, Haddab & Le Gorrec, IROS 2010, §II-III, eqs 1-18).
Every number of the seed they use, with its provenance, is in
:mod:`gripkit.systems.ftg100.parameters`; the zoo's factories are at the end of this module.

The extracted text interleaves the paper's two columns and loses Greek letters, minus signs and
fraction bars. The equations as gripkit reconstructs them (SI units throughout; the seed's own
numbers are in µm, µN, mg, mN·s/m):

Actuated subsystem (comb drive + actuated arm), eq 2, electrode displacement x_ea:
    M_a ẍ_ea + K_fa ẋ_ea + K_sa x_ea = F_x − D_a F_c
  F_x = N_a ε h V²/(2g) (eq 5, :mod:`gripkit.models.comb_drive`), K_sa = 32 E h w³/L₁³ (eq 4,
  :mod:`gripkit.models.beams`), F_c the gripping force at the arm tip, x_a = D_a x_ea.

Amplification (eqs 3, 12). The extracted ``Da = (H  l / 2)/(a l / 2)`` lost both signs. With a
hinge at l/2 from the arm's clamp (Fig. 6) the four candidates give, for H = 5300, l = 300,
a = 950, b = 700 µm:
    (H − l/2)/(a + l/2) = 4.682 | 6.059   <- the seed's D_a = 4.7, D_b = 6.05
    (H + l/2)/(a + l/2) = 4.955 | 6.412
    (H − l/2)/(a − l/2) = 6.438 | 9.364
    (H + l/2)/(a − l/2) = 6.813 | 9.909
  so D = x_tip/x_e = (H − l/2)/(arm + l/2) (:func:`amplification_ratio`).

Object and coupling (eqs 6-7): the grasped object is a spring k0 between the arm tips,
    F_c = k0 (x_a − x_b) = k2 x_b   ⇒   x_b = k0/(k0 + k2) x_a,   F_c = k_k x_a,
    k_k = k0 k2/(k0 + k2)  (k0 and the sensing arm's stiffness k2 in series).

Linearisation at V_in0 = 70 V (eqs 8-9). Writing x_ea = x̃_a/D_a and F_c = k_k x̃_a in eq 2 and
expanding F_x to first order (∂F_x/∂V = N_a ε h V₀/g; eq 8 writes h as ``t`` and ε as ``H``):
    (M_a/D_a) x̃_a'' + (K_fa/D_a) x̃_a' + (K_sa/D_a + D_a k_k) x̃_a = N_a ε h V₀/g · Ṽ_in   (eq 8)
    G_a(s) = X̃_a/Ṽ_in = D_a N_a ε h V₀/g / (M_a s² + K_fa s + K_sa + D_a² k_k)          (eq 9)

Sensing subsystem (eqs 11-16), electrode displacement x_eb, x_b = D_b x_eb:
    M_b ẍ_eb + K_fb ẋ_eb + K_sb x_eb = D_b F_c                                           (eq 11)
    M_b ẍ_b + K_fb ẋ_b + K_sb x_b = D_b² F_c,  G_b(s) = D_b²/(M_b s² + K_fb s + K_sb)   (eqs 14-15)
    K_sb = 32 E h w³/L₂³ (eq 13),  k2 = K_sb/D_b² (eq 16: the tip stiffness of the sensing arm).

Discrete models (eqs 10, 17, 18). G_a and G_b are discretised with a zero-order hold at 20 kHz and
written in MATLAB's controllable canonical form x(k+1) = [[−a₁, −a₂], [1, 0]] x + [s, 0]ᵀ u,
y = [b₁, b₂]/s · x, where G(z) = (b₁z + b₂)/(z² + a₁z + a₂) in the seed's units (µm/V, µm/µN)
and s is a power-of-two balancing scale (:func:`controllable_form`). The coupled model (eq 18):
    [x1; x2](k+1) = [[A_a, 0], [B_c k_k C_a, A_c]] [x1; x2](k) + [B_a; 0] V_in(k)
    V_out(k) = [0, (k2/r) C_c] [x1; x2](k)
  with r the readout sensitivity. The seed prints "r ... (50 N/Volts)". Fig. 10's sensor reads up
  to 140 µN: with r = 50 N/V that is 2.8 µV at the MS3110 readout's output, which delivers volts;
  in the seed's own unit system (µm, µN, V: k2 in µN/µm times x_b in µm is µN) the number 50 is
  50 µN/V, giving 2.8 V at 140 µN. gripkit uses r = 50 µN/V = 5e-5 N/V and reports the printed unit
  as a finding.

Damping units. The seed prints K_fa = 1.3 "mNs²/m" and K_fb = 0.71 "mNs²/m"; a damping coefficient
is force per velocity, N·s/m, and with K_fa = 1.3 mN·s/m eq 10's pole radius √0.9536 = 0.9765 is
reproduced to 0.01 % (a check below), so the unit is mN·s/m.

Nonlinear plant (the paper's future work, :class:`FTG100Plant`): both arms as second-order
systems in electrode coordinates, suspensions K x (linear, eqs 4 and 8-10, the default) or, as an
option, stiffening as K x (1 + β (x/w)²) (beams.py), the quadratic comb-drive force clipped to
0-200 V, and the object as a unilateral spring(-damper) between the tips that engages when the
free gap closes:
    δ = x_a − x_b − gap,   F_c = max(0, k0 δ + c0 δ̇) while δ > 0, else 0,
with the contact instant located inside the integration step (see :func:`advance_plant`). The plant
has no arm-to-arm contact: without an object it is valid while the tip travel stays below the
100 µm opening (106 V for the default plant).

Static displacement at 70 V: two readings. §III-A, after Fig. 4: "since the size of the grasped
objects is about 80 µm, a work around V_in0 = 70 V is chosen. This actuation voltage allows a
displacement of 20 µm in static mode at the tip of the actuated arm." The printed constants give
    eq 5:  c = N_a ε h/(2g) = 1300 · 8.85 pF/m · 50 µm/(2 · 6 µm) = 47.94 nN/V²,
           F_x(70 V) = c · 70² = 234.9 µN
    eq 4:  K_sa = 32 E h w³/L₁³ = 25.40 N/m (the printed 25.4);  eq 3: D_a = 4.7
and eq 10, the seed's own small-signal model at 70 V with the ball grasped, is eq 9 with eq 5's
force and these linear suspensions: its DC gain 0.1878 µm/V is eq 9's 0.1889 µm/V within 0.56 %
(check ``eq10-dc-gain`` of ``ftg100-actuated``). Whatever "20 µm" means, eqs 5 and 10 agree.

(A) 20 µm is the free tip's displacement. With F_c = 0, eq 2 at rest is K_sa x_ea = F_x and
    x_a(70 V) = D_a c V₀²/K_sa = 4.7 · 234.9 µN/25.4 N/m = 43.5 µm   vs 20 µm (2.17×).
  Eq 8's free gain D_a N_a ε h V₀/(g K_sa) = 1.242 µm/V against 2 · 20 µm/70 V = 0.571 µm/V for a V²
  actuator at 20 µm. The §III-B identification could not have absorbed the factor (p = [M_a, K_fa,
  k0]; k_k = k0 k2/(k0 + k2) < k2 = 6.45 N/m, so no k0 stiffens K_sa + D_a² k_k by more than 0.53 %
  above its value at k0 = 1043 N/m; Fig. 4's step responses are normalised). Meeting 20 µm needs the
  force scaled by κ = K_sa x_ea/(c V₀²) = 108.1 µN/234.9 µN = 0.4601 (x_ea = 20 µm/D_a; with the
  stretching suspensions (K_sa x_ea + K3_a x_ea³)/(c V₀²) = 0.5592), and every small-signal gain at
  70 V with it: the plant's grasped gain becomes 0.0871 µm/V, 53.6 % below eq 10 (48.7 % with
  stretching). Reading (A) thus contradicts eq 10 as much as eq 5: a 2.17× disagreement inside the
  seed with no measured number to arbitrate it (the earlier "48 % gap" of gripkit's plant was this
  disagreement reduced by the assumed π⁴/128 stiffening, not a property of eq 5).

(B) 20 µm is the travel to the ball: the 100 µm opening (§II-A) less the 80 µm ball is 20 µm, the
  displacement 70 V must "allow" for the tip to reach the object, the sentence's own reason for
  choosing 70 V. Eq 5 with linear suspensions puts the free tip past it at 70 V (43.5 µm; it reaches
  20 µm at 70 · √(20/43.46) = 47.5 V), so with the ball the tip closes the gap and grips: the static
  balance in tip coordinates (eqs 2, 6-7),
    (K_sa/D_a²) x_a + k_k (x_a − gap) = F_x/D_a,
    x_a = (49.98 µN + 6.41 N/m · 20 µm)/(1.150 + 6.41) N/m = 23.58 µm,   F_c = 22.87 µN,
  i.e. 20 µm of travel + 3.56 µm of sensing arm pushed back (x_b = F_c/k2) + 0.022 µm of ball
  compression (F_c/k0): 17.9 % beyond 20 µm with no rescaling (13.1 % with the stretching law,
  22.63 µm), the grip a small force well inside Fig. 10's 140 µN range, as §III-A's "small gripping
  forces" regime requires. The plant linearised there has eq 10's gain within 0.82 %.

gripkit adopts (B): the default plant (``ftg100-plant``) is eq 5's force (κ = 1) with the linear
suspensions of eqs 4 and 8-10, so that its small-signal model at 70 V grasped *is* eq 9/10, and the
``gap`` of 20 µm is the seed's 20 µm. The full close (§II-A, "achieved while applying the maximum
actuation voltage (200V)") is then reached at √(K_sa (100 µm/D_a)/c) = 106.2 V and holds at 200 V;
the π⁴/128 stretching law would leave the free tip at 79.9 µm at 200 V (closing only at 268 V), so
the earlier "full close not reached" finding was an artefact of that assumed law. Reading (A) is
kept as ``plant_parameters(force_factor='static-70V')`` (zoo ``ftg100-plant-calibrated``: κ =
0.4601, linear suspensions, closing at 156.5 V) and reported: ``gripkit zoo check ftg100-plant``
lists ``static-70V-eq5`` and ``static-70V`` (reading A, inconsistent, with the κ it needs),
``static-70V-grasp`` (reading B, 17.9 %), ``eq10-plant-gain`` (0.82 %), ``full-close-200V`` and
``eq5-force-factor``; the calibrated entry lists the same checks with ``eq10-plant-gain`` 53.6 % off
and ``eq5-force-factor`` 54 % off. Fig. 5's rising resonance needs some stiffening the seed does not
quantify; ``plant_parameters(suspension='stretching')`` adds the Galerkin β = π⁴/128 (an upper
bound, rigid anchors) for that qualitative trend, at the cost of eq 10 (10.5 % off) and the full
close. (Meeting the free 20 µm and a full close at exactly 200 V with a V² force needs a
secant-stiffness ratio of (200/70)²/(100/20) = 1.63 between 100 µm and 20 µm of tip travel: β ≈
0.096 with κ = 0.473; gripkit does not adopt it, the seed has no stiffness data.)
"""

from __future__ import annotations

import abc
from collections import namedtuple
import math

import numba
import numpy as np
from scipy.optimize import brentq

from ...arguments import sample_interval
from ...consistency import Finding, compare
from ...errors import AccuracyWarning, ModelError, ParameterError, emit_warning
from ...models.beams import STRETCHING_BETA, clamped_clamped_stiffness
from ...models.comb_drive import comb_drive_coefficient
from ...models.second_order import second_order_batch
from ...params import Parameter, ParameterSet
from ...lti import StateSpace, TransferFunction
from ...sim.linear import c2d_zoh, simulate_discrete
from ...sim.model import Model, Signal
from .parameters import (DT, R_SENSITIVITY, SEED, SEED_EQ10, SEED_EQ17, STATIC_70V, ftg100_geometry,
                         ftg100_parameters, plant_table)

__all__ = [
    "SEED", "amplification_ratio", "ftg100_geometry", "ftg100_parameters", "controllable_form",
    "balancing_scale", "seed_state_space", "SEED_EQ10", "SEED_EQ17", "FTG100Actuated",
    "FTG100Sensing", "FTG100Coupled", "FTG100Plant", "plant_parameters", "advance_plant",
    "R_SENSITIVITY", "STATIC_70V", "static_force_factor", "full_close_voltage", "actuated_model",
    "sensing_model", "coupled_model", "plant_model", "calibrated_plant_model",
]

_S = SEED + ", "

_UNIT = {"um": 1e-6, "uN": 1e-6, "V": 1.0, "m": 1.0, "N": 1.0}


def amplification_ratio(H: float, l: float, arm: float) -> float:
    """Tip-to-electrode displacement ratio D = (H − l/2)/(arm + l/2) (eqs 3, 12; signs reconstructed
    in the module docstring). ``H``, ``l``, ``arm`` (a or b) in any one length unit."""
    H, l, arm = float(H), float(l), float(arm)
    if not (H > 0 and l > 0 and arm > 0) or H <= l / 2:
        raise ModelError(f"amplification ratio: expected positive dimensions with H > l/2, found "
                         f"H={H:g}, l={l:g}, arm={arm:g}")
    return (H - l / 2.0) / (arm + l / 2.0)


#: the two flexure arms: actuation (§III-A, eqs 3-4) and sensing (§III-C, eqs 12-13). Each
#: arm's stiffness is 32 E h w³/L³ with its beam length ``L`` and its amplification
#: (H − l/2)/(lever + l/2) with its lever arm; the stated values they are checked against, the
#: equations, the stiffness tolerance and what the text says of the stated values
_ARMS = {
    "a": dict(L="L1", L_sym="L₁", lever="a", K="K_sa", D="D_a", eq_K="4", eq_D="3",
              rtol_K=0.005, note_K="", used_K="the stated K_sa", used_D="the stated D_a = 4.7",
              section="§III-A"),
    "b": dict(L="L2", L_sym="L₂", lever="b", K="K_sb", D="D_b", eq_K="13", eq_D="12",
              rtol_K=0.01, note_K="; L₂ = 871.2 µm gives the printed value",
              used_K="the stated K_sb = 235.36 N/m", used_D="the stated D_b = 6.05",
              section="§III-C"),
}


def _arm_findings(sub: str, p: ParameterSet, arm: str) -> list[Finding]:
    """One arm's stiffness (eq 4 / eq 13) and amplification (eq 3 / eq 12) from the geometry
    against the stated values in ``p`` (:data:`_ARMS`)."""
    a = _ARMS[arm]
    gv = ftg100_geometry().value
    source = _S + a["section"]
    return [
        compare(f"{a['K']}-eq{a['eq_K']}", sub,
                computed=clamped_clamped_stiffness(gv("E"), gv("h"), gv("w"), gv(a["L"])),
                stated=p.value(a["K"]), rtol=a["rtol_K"], unit="N/m",
                what=f"32 E h w³/{a['L_sym']}³ (eq {a['eq_K']}{a['note_K']})", used=a["used_K"],
                source=source),
        compare(f"{a['D']}-eq{a['eq_D']}", sub,
                computed=amplification_ratio(gv("H"), gv("l"), gv(a["lever"])),
                stated=p.value(a["D"]), rtol=0.01,
                what=f"(H − l/2)/({a['lever']} + l/2) (eq {a['eq_D']}, signs reconstructed)",
                used=a["used_D"], source=source),
    ]


# ------------------------------------------------------------------------------------------------
# discrete canonical forms
# ------------------------------------------------------------------------------------------------

def balancing_scale(num: np.ndarray, unit_factor: float = 1.0) -> float:
    """Power-of-two input scale s of MATLAB's controllable form: s = 2^round(log₂ √Σ|b_i|), with the
    numerator b in the units the seed printed (``unit_factor`` converts SI to them, e.g. 1e6 for
    m/V -> µm/V). This rule reproduces both printed forms: B_a = 0.25 (eq 10, Σ|b| = 0.0548 µm/V)
    and B_c = 0.5 (eq 17, Σ|b| = 0.131 µm/µN). The scale is a similarity transform: poles, DC gain
    and the transfer function do not depend on it."""
    total = float(np.sum(np.abs(num))) * float(unit_factor)
    if not total > 0:
        return 1.0
    return float(2.0 ** round(math.log2(math.sqrt(total))))


def controllable_form(sys: StateSpace, *, scale: float | str = "balanced",
                      unit_factor: float = 1.0) -> StateSpace:
    """A SISO system in controllable canonical form (MATLAB's ``ss(tf(...))`` layout):

        x(k+1) = [[−a₁, −a₂, …, −a_n], [1, 0, …], …] x(k) + [s, 0, …]ᵀ u(k),
        y(k)   = [b₁, …, b_n]/s · x(k) + b₀ u(k),

    for G = (b₀zⁿ + b₁zⁿ⁻¹ + … + b_n)/(zⁿ + a₁zⁿ⁻¹ + … + a_n) (or the same in s). ``scale`` is the
    input scale s: ``'balanced'`` (:func:`balancing_scale` with ``unit_factor``), ``1.0`` for the
    plain form, or any positive number.
    """
    from scipy.signal import ss2tf

    if sys.B.shape[1] != 1 or sys.C.shape[0] != 1:
        raise ModelError(f"controllable_form: expected a single-input single-output system, found "
                         f"{sys.B.shape[1]} inputs and {sys.C.shape[0]} outputs")
    num, den = ss2tf(sys.A, sys.B, sys.C, sys.D)
    num = np.atleast_2d(num)[0]
    n = sys.n_states
    a = den[1:] / den[0]
    b = num / den[0]
    b0 = b[0]
    bn = b[1:] - b0 * a  # strictly proper part
    if scale == "balanced":
        s = balancing_scale(bn, unit_factor)
    else:
        s = float(scale)
        if not (math.isfinite(s) and s > 0):
            raise ModelError(f"scale: expected 'balanced' or a positive number, found {scale!r}")
    A = np.zeros((n, n))
    A[0, :] = -a
    A[1:, :-1] += np.eye(n - 1)
    B = np.zeros((n, 1))
    B[0, 0] = s
    C = (bn / s).reshape(1, n)
    meta = dict(sys.meta, form="controllable canonical", scale=s)
    return StateSpace(A, B, C, np.array([[b0]]), sys.dt, sys.inputs, sys.outputs,
                      sys.input_units, sys.output_units, meta)


def seed_state_space(eq: dict) -> StateSpace:
    """The seed's printed discrete system (``SEED_EQ10`` or ``SEED_EQ17``) converted to SI."""
    fin, fout = _UNIT[eq["input_unit"]], _UNIT[eq["output_unit"]]
    C = np.asarray(eq["C"], dtype=float) * fout / fin  # y_SI = fout y_seed, u_seed = u_SI/fin
    return StateSpace(eq["A"], eq["B"], C, None, eq["dt"], (eq["input"],), (eq["output"],),
                      ("N" if eq["input_unit"] == "uN" else "V",), ("m",), {"source": eq["source"]})


def _canonical_findings(subject: str, computed: StateSpace, eq: dict, pole_tol: float,
                        dc_tol: float,
                        used: str) -> list[Finding]:
    seed = seed_state_space(eq)
    pc = np.sort_complex(computed.poles())
    ps = np.sort_complex(seed.poles())
    # worst relative pole distance (conjugate pairs sorted alike)
    rel = float(np.max(np.abs(pc - ps) / np.abs(ps)))
    name = eq["source"].split(", ")[-1]
    out = [Finding(f"{name.replace(' ', '')}-poles", subject, rel <= pole_tol,
                   f"discrete poles from the parameters {_fmt_poles(pc)} vs {name} "
                   f"{_fmt_poles(ps)}: "
                   f"{100 * rel:.3g} % apart (tolerance {100 * pole_tol:.3g} %); "
                   "continuous equivalents "
                   f"{_fmt_modes(pc, computed.dt)} vs {_fmt_modes(ps, seed.dt)}",
                   used, float(abs(pc[0])), float(abs(ps[0])), rel, pole_tol, eq["source"])]
    dc_c = float(computed.dc_gain()[0, 0])
    dc_s = float(seed.dc_gain()[0, 0])
    unit = "m/V" if eq["input_unit"] == "V" else "m/N"
    out.append(compare(f"{name.replace(' ', '')}-dc-gain", subject, computed=dc_c, stated=dc_s,
                       rtol=dc_tol,
                       what=f"DC gain C(I−A)⁻¹B from the parameters vs the printed {name} matrices",
                       unit=unit, used=used, source=eq["source"]))
    return out


def _fmt_poles(p) -> str:
    return "{" + ", ".join(f"{z.real:.6f}{z.imag:+.6f}j" for z in p) + "}"


def _fmt_modes(p, dt) -> str:
    s = np.log(p[0]) / dt
    return f"{abs(s) / (2 * math.pi):.5g} Hz, ζ = {-s.real / abs(s):.4f}"


# ------------------------------------------------------------------------------------------------
# linear models (eqs 8-10, 14-17, 18)
# ------------------------------------------------------------------------------------------------

def _sub(names):
    full = ftg100_parameters()
    return ParameterSet([full[n] for n in names], "ftg100")


class _SecondOrderFTG(Model):
    """Shared machinery of the two second-order subsystems: m ẍ + c ẋ + k x = gain (u − u0),
    simulated exactly (zero-order hold, :func:`gripkit.models.second_order.second_order_batch`)."""

    integrator = "zoh"

    @abc.abstractmethod
    def _coefficients(self, thetas: np.ndarray) -> np.ndarray:
        """(P, 6): m, c, k, gain, u0, y0 of each parameter vector (each subsystem's own reading)."""

    def _simulate_batch(self, thetas, u, dt, substeps, x0, y):
        second_order_batch(self._coefficients(thetas), u, dt, x0, y)

    def modes(self, theta):
        m, c, k = self._coefficients(np.atleast_2d(np.asarray(theta, float)))[0, :3]
        if k <= 0:
            return []
        return [(math.sqrt(k / m), c / (2 * math.sqrt(k * m)))]

    def natural_frequency_hz(self) -> float:
        return self.modes(self.theta())[0][0] / (2 * math.pi)

    def damping_ratio(self) -> float:
        return self.modes(self.theta())[0][1]

    def state_space(self) -> StateSpace:
        """Continuous state space, states [y, ẏ] (output coordinates)."""
        m, c, k, gain, _, _ = self._coefficients(self.theta()[None, :])[0]
        A = [[0.0, 1.0], [-k / m, -c / m]]
        B = [[0.0], [gain / m]]
        return StateSpace(A, B, [[1.0, 0.0]], None, None, (self.inputs[0].name,),
                          (self.outputs[0].name,),
                          (self.inputs[0].unit,), (self.outputs[0].unit,), {"model": self.name})

    def transfer_function(self) -> TransferFunction:
        """G(s) = gain/(m s² + c s + k) in SI (eqs 9, 15), a continuous
        :class:`gripkit.lti.TransferFunction` with the model's input and output names and units
        (stored monic: divided by m)."""
        m, c, k, gain, _, _ = self._coefficients(self.theta()[None, :])[0]
        return TransferFunction([gain], [m, c, k], None, (self.inputs[0].name,),
                                (self.outputs[0].name,), (self.inputs[0].unit,),
                                (self.outputs[0].unit,), {"model": self.name})

    def discrete(self, dt: float = DT, form: str = "canonical") -> StateSpace:
        """ZOH discretisation every ``dt`` s: ``form='canonical'`` is the controllable canonical
        form the seed prints (eqs 10, 17; balancing scale chosen in the seed's units),
        ``'physical'`` keeps the states [y, ẏ]."""
        dt = sample_interval(dt, ModelError)
        d = self.state_space().c2d(dt)
        if form == "physical":
            return d
        if form != "canonical":
            raise ModelError(f"form: expected 'canonical' or 'physical', found {form!r}")
        return controllable_form(d, unit_factor=self._seed_unit_factor)


class FTG100Actuated(_SecondOrderFTG):
    """Actuated subsystem linearised at V_in0 while the object is grasped (eqs 8-9):

        M_a x̃_a'' + K_fa x̃_a' + (K_sa + D_a² k_k) x̃_a = D_a N_a ε h V₀/g · (V_in − V₀),
        k_k = k0 k2/(k0 + k2).

    Input ``V_in`` (V, absolute actuation voltage); output ``x_a`` (m, tip displacement from the
    operating point, plus the sensor zero ``x_off``, 0 by default). Free by default: M_a, K_fa, k0
    (the LM estimates of §III-B).
    """

    name = "ftg100-actuated"
    description = "FT-G100 actuated subsystem linearised at 70 V, object grasped (eqs 8-10)"
    inputs = (Signal("V_in", "V", "actuation voltage (absolute)"),)
    outputs = (Signal("x_a", "m", "actuated-arm tip displacement from the operating point"),)
    states = (Signal("x_a", "m", "tip displacement"), Signal("v_a", "m/s", "tip velocity"))
    _seed_unit_factor = 1e6  # eq 10 is in µm per V
    _names = ("M_a", "K_fa", "k0", "K_sa", "D_a", "k2", "N_a", "eps", "h", "g", "V0", "x_off")

    def __init__(self, parameters: ParameterSet | None = None, *, check: bool = True, **values):
        ps = parameters if parameters is not None else _sub(self._names).fix(*self._names[3:])
        if values:
            ps = ps.replace(**values)
        super().__init__(ps, check=check)

    def _coefficients(self, thetas):
        M, c, k0, Ksa, Da, k2, Na, eps, h, g, V0, off = thetas.T
        kk = k0 * k2 / (k0 + k2)
        gain = Da * Na * eps * h * V0 / g
        return np.column_stack([M, c, Ksa + Da * Da * kk, gain, V0, off])

    def series_stiffness(self) -> float:
        """k_k = k0 k2/(k0 + k2) [N/m] (eq 7)."""
        p = self.parameters
        return p.value("k0") * p.value("k2") / (p.value("k0") + p.value("k2"))

    def dc_gain(self) -> float:
        """Static gain x̃_a/Ṽ_in [m/V] of eq 9."""
        _, _, k, gain, _, _ = self._coefficients(self.theta()[None, :])[0]
        return float(gain / k)

    def consistency_checks(self) -> list[Finding]:
        p = self.parameters
        sub = self.name
        out = _arm_findings(sub, p, "a")
        # damping unit: the pole radius of eq 10 is exp(−K_fa/(2 M_a)·T) only if K_fa is in N·s/m
        T = SEED_EQ10["dt"]
        radius = math.exp(-p.value("K_fa") / (2.0 * p.value("M_a")) * T)
        out.append(compare("damping-unit", sub, computed=radius, stated=math.sqrt(0.9536),
                           rtol=0.002,
                           what="pole radius exp(−K_fa T/(2 M_a)) with K_fa = 1.3 "
                                "mN·s/m (the printed "
                                "'mNs²/m' is not a damping unit)",
                           used="K_fa in mN·s/m", source=_S + "§III-B, eq 10"))
        out += _canonical_findings(sub, self.discrete(SEED_EQ10["dt"]), SEED_EQ10, pole_tol=0.003,
                                   dc_tol=0.015, used="the parameters (the printed "
                                                      "matrices are rounded)")
        return out


class FTG100Sensing(_SecondOrderFTG):
    """Sensing subsystem (eqs 14-15): M_b ẍ_b + K_fb ẋ_b + K_sb x_b = D_b² F_c.

    Input ``F_c`` (N, gripping force at the sensing-arm tip); output ``x_b`` (m, tip deflection,
    plus the sensor zero ``x_off``, 0 by default). Free by default: M_b, K_fb (§III-D).
    """

    name = "ftg100-sensing"
    description = ("FT-G100 sensing subsystem, gripping force to sensing-arm tip "
                   "deflection (eqs 14-17)")
    inputs = (Signal("F_c", "N", "gripping force at the sensing-arm tip"),)
    outputs = (Signal("x_b", "m", "sensing-arm tip deflection"),)
    states = (Signal("x_b", "m", "tip deflection"), Signal("v_b", "m/s", "tip velocity"))
    _seed_unit_factor = 1.0  # eq 17 is in µm per µN = m/N
    _names = ("M_b", "K_fb", "K_sb", "D_b", "x_off")

    def __init__(self, parameters: ParameterSet | None = None, *, check: bool = True, **values):
        ps = parameters if parameters is not None else _sub(self._names).fix("K_sb", "D_b", "x_off")
        if values:
            ps = ps.replace(**values)
        super().__init__(ps, check=check)

    def _coefficients(self, thetas):
        M, c, K, D, off = thetas.T
        return np.column_stack([M, c, K, D * D, np.zeros_like(M), off])

    def stiffness(self) -> float:
        """k2 = K_sb/D_b² [N/m] (eq 16)."""
        return self.parameters.value("K_sb") / self.parameters.value("D_b") ** 2

    def consistency_checks(self) -> list[Finding]:
        p = self.parameters
        sub = self.name
        out = _arm_findings(sub, p, "b") + [
            compare("k2-eq16", sub, computed=self.stiffness(),
                    stated=ftg100_parameters().value("k2"),
                    rtol=0.01, unit="N/m",
                    what="K_sb/D_b² (eq 16)", used="k2 = 6.45 N/m where k2 appears",
                    source=_S + "§III-C"),
            compare("k2-measured", sub, computed=self.stiffness(),
                    stated=ftg100_geometry().value("k2_measured"),
                    rtol=0.01, unit="N/m", what="K_sb/D_b² (eq 16) vs the Fig. 10 slope",
                    used="k2 = 6.45 N/m", source=_S + "§III-D, Fig. 10"),
        ]
        out += self._eq17_findings()
        return out

    def _eq17_findings(self) -> list[Finding]:
        """Eq 17 against the stated M_b, K_fb, K_sb, D_b — and the M_b its poles imply."""
        sub = self.name
        used = ("the stated M_b = 0.5 mg (the identified value in the text); the printed "
                "A_c is not used")
        out = _canonical_findings(sub, self.discrete(SEED_EQ17["dt"]), SEED_EQ17, pole_tol=0.003,
                                  dc_tol=0.015, used=used)
        seed = seed_state_space(SEED_EQ17)
        s = np.log(seed.poles()[0]) / seed.dt
        wn, sigma = abs(s), -s.real
        p = self.parameters
        m_from_k = p.value("K_sb") / wn ** 2
        m_from_c = p.value("K_fb") / (2.0 * sigma)
        out.append(compare("eq17-implied-M_b", sub, computed=m_from_k, stated=p.value("M_b"),
                           rtol=0.02, unit="kg",
                           what=("the mass the printed A_c implies, K_sb/ω_n² with ω_n = "
                                 f"2π·{wn / (2 * math.pi):.5g} Hz "
                                 f"(K_fb/(2σ) gives {m_from_c * 1e6:.4g} mg, "
                                 f"{100 * abs(m_from_c / m_from_k - 1):.2g} % "
                                 f"from it)"),
                           used=used, source=_S + "§III-D, eq 17"))
        return out


class FTG100Coupled(Model):
    """Coupled gripper model (eq 18), continuous form: the actuated subsystem (eq 9) drives the
    sensing subsystem (eq 15) through F_c = k_k x̃_a (eq 7); the readout gives V_out = k2 x_b / r.

    States [x̃_a, ẋ̃_a, x_b, ẋ_b]; input ``V_in`` (V); outputs ``x_a`` (m), ``x_b`` (m), ``F_c``
    (N),
    ``V_out`` (V). :meth:`discrete_eq18` builds the seed's discrete block form from the two
    discretised subsystems; :meth:`simulate` uses the exact ZOH of the continuous cascade.
    """

    name = "ftg100-coupled"
    description = "FT-G100 coupled actuated/sensing model through the object stiffness (eq 18)"
    inputs = (Signal("V_in", "V", "actuation voltage (absolute)"),)
    outputs = (Signal("x_a", "m", "actuated tip displacement from the operating point"),
               Signal("x_b", "m", "sensing tip deflection"),
               Signal("F_c", "N", "gripping force k_k x_a"),
               Signal("V_out", "V", "force-sensor readout voltage k2 x_b / r"))
    states = (Signal("x_a", "m"), Signal("v_a", "m/s"), Signal("x_b", "m"), Signal("v_b", "m/s"))
    integrator = "zoh"
    _names = FTG100Actuated._names[:-1] + FTG100Sensing._names[:-1] + ("r",)

    def __init__(self, parameters: ParameterSet | None = None, *, check: bool = True, **values):
        ps = parameters if parameters is not None else _sub(self._names).fix(
            *(n for n in self._names if n not in ("M_a", "K_fa", "k0", "M_b", "K_fb")))
        if values:
            ps = ps.replace(**values)
        super().__init__(ps, check=check)

    def actuated(self) -> FTG100Actuated:
        return self._parts(self.parameters)[0]

    def sensing(self) -> FTG100Sensing:
        return self._parts(self.parameters)[1]

    @staticmethod
    def _parts(ps: ParameterSet):
        """(actuated, sensing, k_k, k2/r) for the coupled parameter set ``ps``."""
        full = ftg100_parameters()

        def pick(names):
            return ParameterSet([ps[n] if n in ps else full[n] for n in names], "ftg100")

        kk = ps.value("k0") * ps.value("k2") / (ps.value("k0") + ps.value("k2"))
        return (FTG100Actuated(pick(FTG100Actuated._names), check=False),
                FTG100Sensing(pick(FTG100Sensing._names), check=False), kk,
                ps.value("k2") / ps.value("r"))

    @staticmethod
    def _cascade(a: StateSpace, b: StateSpace, kk: float, readout: float):
        """Eq 18's structure for two subsystems (continuous or discrete): the sensing input is
        F_c = k_k x_a; outputs x_a, x_b, F_c, V_out = (k2/r) x_b."""
        A = np.zeros((4, 4))
        A[:2, :2] = a.A
        A[2:, 2:] = b.A
        A[2:, :2] = b.B @ (kk * a.C)
        B = np.vstack([a.B, np.zeros((2, 1))])
        C = np.zeros((4, 4))
        C[0, :2] = a.C[0]
        C[1, 2:] = b.C[0]
        C[2, :2] = kk * a.C[0]
        C[3, 2:] = readout * b.C[0]
        return A, B, C

    def _matrices(self, theta):
        ps = self.parameters.from_vector(theta, self.parameters.names)
        act, sen, kk, readout = self._parts(ps)
        A, B, C = self._cascade(act.state_space(), sen.state_space(), kk, readout)
        return A, B, C, ps.value("V0")

    def state_space(self) -> StateSpace:
        A, B, C, _ = self._matrices(self.theta())
        return StateSpace(A, B, C, None, None, ("V_in",), tuple(s.name for s in self.outputs),
                          ("V",),
                          tuple(s.unit for s in self.outputs), {"model": self.name})

    def _simulate_batch(self, thetas, u, dt, substeps, x0, y):
        for p in range(thetas.shape[0]):
            A, B, C, V0 = self._matrices(thetas[p])
            Ad, Bd = c2d_zoh(A, B, dt)
            simulate_discrete(Ad, Bd, C, np.zeros((4, 1)), np.ascontiguousarray(u[:, :1] - V0),
                              x0[p].copy(), y[p])

    def modes(self, theta):
        A, _, _, _ = self._matrices(theta)
        lam = np.linalg.eigvals(A)
        return [(abs(v), -v.real / abs(v)) for v in lam if v.imag >= 0]

    def discrete(self, dt: float = DT, form: str = "canonical") -> StateSpace:
        """``form='canonical'``: the seed's eq 18 block form (:meth:`discrete_eq18`);
        ``'physical'``:
        the exact zero-order hold of the continuous cascade (states [x̃_a, ẋ̃_a, x_b, ẋ_b])."""
        if form == "canonical":
            return self.discrete_eq18(dt)
        if form != "physical":
            raise ModelError(f"form: expected 'canonical' or 'physical', found {form!r}")
        dt = sample_interval(dt, ModelError)
        return self.state_space().c2d(dt)

    def discrete_eq18(self, dt: float = DT) -> StateSpace:
        """The seed's eq 18: [[A_a, 0], [B_c k_k C_a, A_c]] from the canonical subsystems (eqs 10,
        17);
        outputs x_a, x_b, F_c, V_out (SI). The sensing subsystem sees F_c = k_k x_a held over each
        sample (a ZOH approximation of the continuous cascade; the DC gain is exact)."""
        act, sen, kk, readout = self._parts(self.parameters)
        A, B, C = self._cascade(act.discrete(dt), sen.discrete(dt), kk, readout)
        return StateSpace(A, B, C, None, dt, ("V_in",), tuple(s.name for s in self.outputs), ("V",),
                          tuple(s.unit for s in self.outputs),
                          {"model": self.name, "form": "eq 18 block form"})

    def consistency_checks(self) -> list[Finding]:
        ps = self.parameters
        out = self.actuated().consistency_checks() + self.sensing().consistency_checks()
        out = [Finding(f.check, self.name, f.consistent, f.message, f.used, f.computed, f.stated,
                       f.rel_error,
                       f.tolerance, f.source) for f in out]
        full_scale = ftg100_geometry().value("force_range")
        printed_r = 50.0  # N/V as printed
        out.append(Finding(
            "readout-sensitivity-unit", self.name, False,
            f"eq 18 prints r = 50 N/V: the {full_scale * 1e6:.0f} µN range of Fig. "
            "10 would then be "
            f"{full_scale / printed_r * 1e6:.3g} µV at the MS3110 readout, which outputs "
            "volts; in the seed's "
            f"µm/µN/V units r = 50 µN/V gives {full_scale / ps.value('r'):.3g} V",
            f"r = {ps.value('r') * 1e6:.3g} µN/V", full_scale / printed_r,
            full_scale / ps.value("r"),
            math.nan, math.nan, _S + "eq 18, Fig. 10"))
        return out


# ------------------------------------------------------------------------------------------------
# nonlinear plant
# ------------------------------------------------------------------------------------------------

_PLANT_NAMES = ("M_a", "K_fa", "K_sa", "K3_a", "D_a", "c_e", "M_b", "K_fb", "K_sb", "K3_b", "D_b",
                "k0", "c0", "gap", "V_max")
#: the index of each plant parameter in the vector ``th`` the kernels take: ``th[PX.D_a]``
PX = namedtuple("PlantParameterIndex", _PLANT_NAMES)(*range(len(_PLANT_NAMES)))
#: the index of each plant output in ``out`` (:func:`plant_outputs`): ``out[PO.F_c]``
PLANT_OUTPUTS = ("x_a", "x_b", "F_c", "F_s")
PO = namedtuple("PlantOutputIndex", PLANT_OUTPUTS)(*range(len(PLANT_OUTPUTS)))


#: Suspension laws of :func:`plant_parameters` and the provenance of their ``K3_a``.
_SUSPENSIONS = {
    "linear": _S + "eqs 4 and 8-10 (linear suspensions: 'only small deflections are considered')",
    "stretching": ("assumed: Galerkin estimate K_sa·(π⁴/128)/w² (beams.py), Fig. 5 trend "
                   "(no seed number)"),
}


def _eq5_coefficient() -> float:
    """N_a ε h/(2g) from the printed constants (eq 5) [N/V²]."""
    gv = ftg100_geometry().value
    return comb_drive_coefficient(gv("N_a"), gv("eps"), gv("h"), gv("g"))


def static_force_factor(parameters: ParameterSet | None = None, *, voltage: float = STATIC_70V[0],
                        tip_displacement: float = STATIC_70V[1]) -> float:
    """Comb-drive force factor κ that puts the free actuated tip at ``tip_displacement`` (m) at
    ``voltage`` (V), relative to the ``c_e`` of ``parameters`` (a plant parameter set, default
    :func:`plant_parameters`, i.e. relative to eq 5):

        κ c_e V² = K_sa x_ea + K3_a x_ea³,  x_ea = x_a/D_a   (eq 2 at rest with F_c = 0, eq 3)

    Defaults: the seed's 20 µm at 70 V, κ = 0.4601 (linear suspensions; 0.5592 with the π⁴/128
    stretching); see the module docstring.
    """
    p = (parameters if parameters is not None else plant_parameters()).value
    V, x = float(voltage), float(tip_displacement)
    if not (math.isfinite(V) and V > 0):
        raise ParameterError(f"voltage: expected a positive voltage in V, found {voltage!r}")
    if not (math.isfinite(x) and x > 0):
        raise ParameterError("tip_displacement: expected a positive displacement in m, found "
                             f"{tip_displacement!r}",
                             hint="give metres, e.g. 20e-6 for 20 µm")
    xe = x / p("D_a")
    return (p("K_sa") * xe + p("K3_a") * xe ** 3) / (p("c_e") * V * V)


def full_close_voltage(parameters: ParameterSet | None = None,
                       opening: float | None = None) -> float:
    """Voltage [V] at which the free actuated tip travels ``opening`` (m, default the seed's 100 µm,
    §II-A): c_e V² = K_sa x_e + K3_a x_e³ with x_e = opening/D_a (eq 2 at rest, eq 3). 106.2 V for
    the linear plant, 268.2 V with the π⁴/128 stretching (beyond the 200 V limit)."""
    p = (parameters if parameters is not None else plant_parameters()).value
    x = ftg100_geometry().value("opening") if opening is None else float(opening)
    if not (math.isfinite(x) and x > 0):
        raise ParameterError(f"opening: expected a positive displacement in m, found {opening!r}",
                             hint="give metres, e.g. 100e-6 for the seed's 100 µm")
    xe = x / p("D_a")
    return math.sqrt((p("K_sa") * xe + p("K3_a") * xe ** 3) / p("c_e"))


def plant_parameters(*, force_factor: float | str = 1.0, suspension: str = "linear",
                     **values) -> ParameterSet:
    """Parameters of :class:`FTG100Plant` (SI): the seed's values plus the nonlinear terms.

    ``suspension``: ``'linear'`` (default, ``K3_a`` = 0: the suspensions of eqs 4 and 8-10, which
    makes the plant's small-signal model at 70 V with the ball grasped eq 9/10 itself) or
    ``'stretching'`` (``K3_a`` = K_sa β/w², β = π⁴/128, the Galerkin clamped-clamped stretching of
    :mod:`gripkit.models.beams`: gripkit's assumption for Fig. 5's rising resonance, no seed
    number); ``K3_b`` = 0 (Fig. 10: the sensor is linear up to 140 µN); ``c_e`` = κ N_a ε h/(2g) (eq
    5) with κ = ``force_factor``: 1 (default, eq 5 as printed), a positive number, or
    ``'static-70V'`` (κ from :func:`static_force_factor` with the other ``values``: the free tip at
    20 µm at 70 V, κ = 0.4601 with linear suspensions, 0.5592 with stretching); ``gap`` = 100 µm
    opening − 80 µm ball; ``c0`` = 0 (the seed's object is a pure spring). ``values`` replace any
    parameter (``c_e`` only with κ = 1). The two readings of the seed's "20 µm at 70 V" are in the
    module docstring.
    """
    calibrate = isinstance(force_factor, str)
    if calibrate and force_factor != "static-70V":
        raise ParameterError("force_factor: expected a positive number or 'static-70V', found "
                             f"{force_factor!r}")
    if not calibrate:
        try:
            kappa = float(force_factor)
        except (TypeError, ValueError):
            kappa = math.nan
        if not (math.isfinite(kappa) and kappa > 0):
            raise ParameterError("force_factor: expected a positive number or 'static-70V', found "
                                 f"{force_factor!r}",
                                 hint="1 is eq 5 as printed; 'static-70V' fits the "
                                      "seed's 20 µm at 70 V")
    if suspension not in _SUSPENSIONS:
        raise ParameterError(f"suspension: expected 'linear' or 'stretching', found {suspension!r}",
                             hint="'linear' is eqs 4 and 8-10; 'stretching' adds the π⁴/128 "
                                  "stiffening")
    if "c_e" in values and (calibrate or kappa != 1.0):
        raise ParameterError(f"c_e and force_factor={force_factor!r} both set the "
                             "comb-drive coefficient",
                             hint="give one of them: c_e in N/V², or force_factor relative to eq 5")
    full, own = ftg100_parameters(), plant_table()
    P = Parameter
    ce = _eq5_coefficient()
    w = ftg100_geometry().value("w")
    ps = ParameterSet([
        full["M_a"], full["K_fa"], full["K_sa"],
        P("K3_a",
          full.value("K_sa") * STRETCHING_BETA / w ** 2 if suspension == "stretching" else 0.0,
          "N/m**3", "cubic stiffening of the actuator suspension (beam stretching)", (0, None),
          source=_SUSPENSIONS[suspension], display_unit="N/um**3"),
        full["D_a"],
        P("c_e", ce, "N/V**2", "comb-drive force "
                               "coefficient N_a ε h/(2g)", (0, None), source=_S + "eq 5",
          display_unit="nN/V**2"),
        full["M_b"], full["K_fb"], full["K_sb"], own["K3_b"], full["D_b"], full["k0"],
        own["c0"], own["gap"], own["V_max"],
    ], "ftg100-plant")
    if values:
        ps = ps.replace(**values)
    if calibrate:
        kappa = static_force_factor(ps)
    if kappa != 1.0:
        how = ("fitted to the free tip's 20 µm at 70 V (§III-A, after Fig. 4; "
               "static_force_factor)" if calibrate
               else "set by the user (force_factor)")
        ps = ParameterSet([P("c_e", kappa * ce, "N/V**2",
                             "effective comb-drive force coefficient κ N_a ε h/(2g), "
                             f"κ = {kappa:.4g}", (0, None),
                             source=_S + f"eq 5 × κ, {how}", display_unit="nN/V**2")
                           if n == "c_e" else ps[n] for n in ps.names], ps.name)
    return ps


@numba.njit(cache=True)
def _plant_rhs(th, xa, va, xb, vb, V, contact):  # pragma: no cover - compiled
    """Derivatives of [x_ea, v_ea, x_eb, v_eb] in mode ``contact`` (0 free, 1 touching)."""
    fc = 0.0
    if contact:
        d = th[PX.D_a] * xa - th[PX.D_b] * xb - th[PX.gap]
        dd = th[PX.D_a] * va - th[PX.D_b] * vb
        fc = th[PX.k0] * d + th[PX.c0] * dd
        if fc < 0.0 and th[PX.c0] > 0.0:  # a Kelvin-Voigt contact cannot pull
            fc = 0.0
    fx = th[PX.c_e] * V * V
    aa = ((fx - th[PX.K_fa] * va - th[PX.K_sa] * xa - th[PX.K3_a] * xa * xa * xa - th[PX.D_a] * fc)
          / th[PX.M_a])
    ab = ((th[PX.D_b] * fc - th[PX.K_fb] * vb - th[PX.K_sb] * xb - th[PX.K3_b] * xb * xb * xb)
          / th[PX.M_b])
    return va, aa, vb, ab


@numba.njit(cache=True)
def _plant_rk4(th, s0, s1, s2, s3, V, mode, h):  # pragma: no cover - compiled
    k1a, k1b, k1c, k1d = _plant_rhs(th, s0, s1, s2, s3, V, mode)
    hh = 0.5 * h
    k2a, k2b, k2c, k2d = (_plant_rhs(th, s0 + hh * k1a, s1 + hh * k1b, s2 + hh * k1c, s3 + hh * k1d,
                                     V, mode))
    k3a, k3b, k3c, k3d = (_plant_rhs(th, s0 + hh * k2a, s1 + hh * k2b, s2 + hh * k2c, s3 + hh * k2d,
                                     V, mode))
    k4a, k4b, k4c, k4d = (_plant_rhs(th, s0 + h * k3a, s1 + h * k3b, s2 + h * k3c, s3 + h * k3d, V,
                                     mode))
    h6 = h / 6.0
    return (s0 + h6 * (k1a + 2.0 * k2a + 2.0 * k3a + k4a),
            s1 + h6 * (k1b + 2.0 * k2b + 2.0 * k3b + k4b),
            s2 + h6 * (k1c + 2.0 * k2c + 2.0 * k3c + k4c),
            s3 + h6 * (k1d + 2.0 * k2d + 2.0 * k3d + k4d))


@numba.njit(cache=True)
def _gap(th, s0, s2):  # pragma: no cover - compiled
    return th[PX.D_a] * s0 - th[PX.D_b] * s2 - th[PX.gap]


@numba.njit(cache=True)
def advance_plant(th, s, mode, V, h, substeps):  # pragma: no cover - compiled
    """Advance the plant state ``s`` = [x_ea, v_ea, x_eb, v_eb] (in place) by ``substeps`` RK4 steps
    of ``h`` s at voltage ``V`` (clipped to [0, V_max]); returns the contact mode at the end.

    Contact events: when the gap function δ = D_a x_ea − D_b x_eb − gap changes sign over a step
    (δ > 0 while free, δ < 0 while touching), the crossing fraction θ of the step is found by the
    Illinois (modified regula falsi) method on RK4 steps of θh from the step's start, the state is
    advanced to the event, the mode switches, and the rest of the step is integrated in the new
    mode.
    This keeps RK4's order across contact instead of smearing the kink over a step.
    """
    if th[PX.k0] <= 0.0:
        mode = 0
    if V < 0.0:
        V = 0.0
    elif V > th[PX.V_max]:
        V = th[PX.V_max]
    s0 = s[0]
    s1 = s[1]
    s2 = s[2]
    s3 = s[3]
    for _ in range(substeps):
        rem = h
        events = 0
        while rem > 0.0:
            # one RK4 call site (compile time): the first trial is the whole remaining step, later
            # trials are Illinois iterations on the fraction theta of it
            d0 = _gap(th, s0, s2)
            lo, hi, flo, fhi = 0.0, 1.0, d0, 0.0
            theta = 1.0
            side = 0
            for it in range(41):
                n0, n1, n2, n3 = _plant_rk4(th, s0, s1, s2, s3, V, mode, theta * rem)
                fm = _gap(th, n0, n2)
                if it == 0:
                    crossed = (mode == 0 and fm > 0.0) or (mode == 1 and fm < 0.0)
                    if th[PX.k0] <= 0.0 or not crossed or events >= 4:
                        break
                    fhi = fm
                else:
                    if (fm == 0.0 or (hi - lo) * rem < 1e-15
                            or abs(fm) <= 1e-13 * (abs(flo) + abs(fhi))):
                        break
                    if (fm > 0.0) == (fhi > 0.0):
                        hi, fhi = theta, fm
                        if side == 1:
                            flo *= 0.5
                        side = 1
                    else:
                        lo, flo = theta, fm
                        if side == -1:
                            fhi *= 0.5
                        side = -1
                if fhi == flo:
                    break
                theta = min(max((lo * fhi - hi * flo) / (fhi - flo), 0.0), 1.0)
            s0, s1, s2, s3 = n0, n1, n2, n3
            if it == 0:  # no event in this step
                break
            # (if not located after 41 iterations, the last iterate is the best estimate)
            mode = 1 - mode
            rem -= theta * rem
            events += 1
            if rem <= 1e-15 * h:
                break
    s[0] = s0
    s[1] = s1
    s[2] = s2
    s[3] = s3
    return mode


@numba.njit(cache=True)
def plant_outputs(th, s, mode, out):  # pragma: no cover - compiled
    """out = [x_a, x_b, F_c (true contact force), F_s (sensor force k2 x_b)] for state ``s``."""
    xa = th[PX.D_a] * s[0]
    xb = th[PX.D_b] * s[2]
    fc = 0.0
    if mode == 1 and th[PX.k0] > 0.0:
        fc = (th[PX.k0] * (xa - xb - th[PX.gap]) + th[PX.c0]
              * (th[PX.D_a] * s[1] - th[PX.D_b] * s[3]))
        if fc < 0.0:
            fc = 0.0
    out[PO.x_a] = xa
    out[PO.x_b] = xb
    out[PO.F_c] = fc
    out[PO.F_s] = th[PX.K_sb] / (th[PX.D_b] * th[PX.D_b]) * xb


@numba.njit(cache=True, parallel=True)
def _plant_batch(thetas, u, dt, substeps, x0, y):  # pragma: no cover - compiled
    P = thetas.shape[0]
    N = u.shape[0]
    h = dt / substeps
    for p in numba.prange(P):
        th = thetas[p]
        s = np.empty(4)
        o = np.empty(4)
        for i in range(4):
            s[i] = x0[p, i]
        mode = 1 if _gap(th, s[0], s[2]) > 0.0 and th[PX.k0] > 0.0 else 0
        for n in range(N):
            plant_outputs(th, s, mode, o)
            for j in range(4):
                y[p, n, j] = o[j]
            mode = advance_plant(th, s, mode, u[n, 0], h, substeps)


class FTG100Plant(Model):
    """Nonlinear FT-G100 plant (the paper's deferred model): the suspensions of eqs 4 and 8-10
    (linear by default, optionally stiffening at large deflection), quadratic comb-drive force with
    the 0-200 V limit, and the arms closing around an object (contact switching located inside the
    step). See the module docstring for the equations and the two readings of the seed's 20 µm.

    Input ``V`` (V); outputs ``x_a``, ``x_b`` (m, tip displacements from rest), ``F_c`` (N, true
    contact force), ``F_s`` (N, force sensor reading k2·x_b without noise). States are the
    electrode displacements and velocities [x_ea, v_ea, x_eb, v_eb].
    """

    name = "ftg100-plant"
    description = ("FT-G100 nonlinear plant: eq 4 suspensions (optionally stiffening), V² "
                   "actuation, "
                   "object contact")
    inputs = (Signal("V", "V", "actuation voltage (clipped to [0, V_max])"),)
    outputs = (Signal("x_a", "m", "actuated tip displacement"),
               Signal("x_b", "m", "sensing tip deflection"),
               Signal("F_c", "N", "contact force on the object"),
               Signal("F_s", "N", "force sensor reading"))
    states = (Signal("x_ea", "m", "actuator electrode displacement"), Signal("v_ea", "m/s"),
              Signal("x_eb", "m", "sensor electrode displacement"), Signal("v_eb", "m/s"))
    integrator = "rk4"

    def __init__(self, parameters: ParameterSet | None = None, *, check: bool = True, **values):
        ps = parameters if parameters is not None else plant_parameters()
        if values:
            ps = ps.replace(**values)
        if tuple(ps.names) != _PLANT_NAMES:
            raise ModelError(f"{self.name}: expected parameters {_PLANT_NAMES}, found {ps.names}")
        super().__init__(ps, check=check)

    def _simulate_batch(self, thetas, u, dt, substeps, x0, y):
        _plant_batch(thetas, u, dt, substeps, x0, y)

    def simulate(self, u, **kwargs):
        """:meth:`Model.simulate`; warns (AccuracyWarning) where the tips come closer than the
        seed's 100 µm opening allows (x_a − x_b > opening, §II-A): the arms would touch there, and
        the plant has no arm-to-arm contact (the default plant's free tip gets there at 106.2 V)."""
        tr = super().simulate(u, **kwargs)
        opening = ftg100_geometry().value("opening")
        closing = float(np.max(tr["x_a"] - tr["x_b"])) if tr.n else 0.0
        if closing > opening:
            emit_warning(f"{self.name}: the tips close by {closing * 1e6:.4g} µm, more than the "
                         f"{opening * 1e6:.3g} µm opening ({SEED} §II-A): the arms would touch, "
                         "which the plant does not model (keep the free arm below 106 V)",
                         AccuracyWarning)
        return tr

    # --- statics and linearisation --------------------------------------------------------------
    def _p(self, theta=None):
        th = self.theta() if theta is None else np.asarray(theta, float)
        return dict(zip(_PLANT_NAMES, th))

    @staticmethod
    def _solve_cubic(k1, k3, f):
        """x with k1 x + k3 x³ = f (monotonic for k1 > 0, k3 ≥ 0)."""
        # linear: f/k1 exactly (brentq's bracket [0, f/k1] may not change sign)
        if f == 0.0 or k3 == 0.0:
            return f / k1
        hi = abs(f) / k1
        return (math.copysign(brentq(lambda x: k1 * x + k3 * x ** 3 - abs(f), 0.0, hi, xtol=1e-18,
                                     rtol=1e-14), f))

    def equilibrium(self, V: float, theta=None) -> dict:
        """Static equilibrium at voltage ``V``: electrode and tip displacements, contact force, and
        the state vector ``x`` to start a simulation from."""
        p = self._p(theta)
        V = min(max(float(V), 0.0), p["V_max"])
        fx = p["c_e"] * V * V
        xea = self._solve_cubic(p["K_sa"], p["K3_a"], fx)
        xeb, fc = 0.0, 0.0
        if p["k0"] > 0 and p["D_a"] * xea - p["gap"] > 0:
            def resid(F):
                xeb_ = self._solve_cubic(p["K_sb"], p["K3_b"], p["D_b"] * F)
                xa = p["gap"] + F / p["k0"] + p["D_b"] * xeb_
                xe = xa / p["D_a"]
                return fx - p["K_sa"] * xe - p["K3_a"] * xe ** 3 - p["D_a"] * F
            fc = brentq(resid, 0.0, fx / p["D_a"], xtol=1e-20, rtol=1e-14)
            xeb = self._solve_cubic(p["K_sb"], p["K3_b"], p["D_b"] * fc)
            xea = (p["gap"] + fc / p["k0"] + p["D_b"] * xeb) / p["D_a"]
        return dict(V=V, x_ea=xea, x_eb=xeb, x_a=p["D_a"] * xea, x_b=p["D_b"] * xeb, F_c=fc,
                    x=np.array([xea, 0.0, xeb, 0.0]), contact=fc > 0)

    def linearize(self, V: float, theta=None) -> StateSpace:
        """Continuous small-signal model at the static equilibrium for ``V``: input ΔV (V), outputs
        Δx_a, Δx_b, ΔF_c, ΔF_s; states [Δx_ea, Δv_ea, Δx_eb, Δv_eb]."""
        p = self._p(theta)
        eq = self.equilibrium(V, theta)
        ka = p["K_sa"] + 3 * p["K3_a"] * eq["x_ea"] ** 2
        kb = p["K_sb"] + 3 * p["K3_b"] * eq["x_eb"] ** 2
        Da, Db, k0, c0 = p["D_a"], p["D_b"], p["k0"], p["c0"]
        on = 1.0 if eq["contact"] else 0.0
        Ma, Mb = p["M_a"], p["M_b"]
        A = np.zeros((4, 4))
        A[0, 1] = A[2, 3] = 1.0
        A[1, 0] = -(ka + on * Da * Da * k0) / Ma
        A[1, 1] = -(p["K_fa"] + on * Da * Da * c0) / Ma
        A[1, 2] = on * Da * Db * k0 / Ma
        A[1, 3] = on * Da * Db * c0 / Ma
        A[3, 0] = on * Db * Da * k0 / Mb
        A[3, 1] = on * Db * Da * c0 / Mb
        A[3, 2] = -(kb + on * Db * Db * k0) / Mb
        A[3, 3] = -(p["K_fb"] + on * Db * Db * c0) / Mb
        B = np.array([[0.0], [2 * p["c_e"] * eq["V"] / Ma], [0.0], [0.0]])
        C = np.array([[Da, 0, 0, 0], [0, 0, Db, 0],
                      [on * k0 * Da, on * c0 * Da, -on * k0 * Db, -on * c0 * Db],
                      [0, 0, p["K_sb"] / Db, 0]], float)
        return StateSpace(A, B, C, None, None, ("V",), ("x_a", "x_b", "F_c", "F_s"), ("V",),
                          ("m", "m", "N", "N"),
                          {"model": self.name, "V0": eq["V"], "contact": bool(eq["contact"])})

    def resonance(self, V: float, theta=None) -> tuple[float, float]:
        """(f_n Hz, ζ) of the slowest mode of the small-signal model at ``V``."""
        lam = self.linearize(V, theta).poles()
        lam = lam[np.argsort(np.abs(lam))][0]
        return abs(lam) / (2 * math.pi), -lam.real / abs(lam)

    def modes(self, theta):
        """Modes for the step-size rule: the free arms at rest and, if an object is present, the
        arms in contact with the suspensions at their stiffest (free equilibrium at V_max)."""
        p = self._p(theta)
        lin = []
        for V, contact in ((0.0, False), (p["V_max"], p["k0"] > 0)):
            q = dict(p)
            xe = self._solve_cubic(p["K_sa"], p["K3_a"], p["c_e"] * V * V)
            ka = p["K_sa"] + 3 * p["K3_a"] * xe ** 2
            on = 1.0 if contact else 0.0
            Da, Db = q["D_a"], q["D_b"]
            K = np.array([[ka + on * Da * Da * q["k0"], -on * Da * Db * q["k0"]],
                          [-on * Da * Db * q["k0"], q["K_sb"] + on * Db * Db * q["k0"]]])
            Cm = np.array([[q["K_fa"] + on * Da * Da * q["c0"], -on * Da * Db * q["c0"]],
                           [-on * Da * Db * q["c0"], q["K_fb"] + on * Db * Db * q["c0"]]])
            Minv = np.diag([1 / q["M_a"], 1 / q["M_b"]])
            A = np.block([[np.zeros((2, 2)), np.eye(2)], [-Minv @ K, -Minv @ Cm]])
            for v in np.linalg.eigvals(A):
                if v.imag >= 0 and abs(v) > 0:
                    lin.append((abs(v), max(-v.real / abs(v), 0.0)))
        return lin

    def consistency_checks(self) -> list[Finding]:
        """The seed's static statements against each other and against this plant (module docstring,
        "Static displacement at 70 V: two readings"): ``static-70V-eq5`` (eqs 3-5 with linear
        suspensions, the printed numbers alone, free-arm reading), ``static-70V`` (this plant, free
        arm: the free-arm reading), ``static-70V-grasp`` (this plant with the ball: the gap
        reading), ``eq10-plant-gain`` (this plant's small-signal gain at 70 V, grasped, against eq
        10), ``full-close-200V`` (the voltage that closes the 100 µm opening against 200 V) and
        ``eq5-force-factor`` (the plant's c_e against eq 5)."""
        p = self.parameters.value
        V0, x70_stated = STATIC_70V
        free = self.with_parameters(check=False, k0=0.0)
        x70 = free.equilibrium(V0)["x_a"]
        lin70 = p("D_a") * p("c_e") * V0 ** 2 / p("K_sa")
        # the printed numbers alone: eq 5 force, stated K_sa and D_a, linear suspensions (eq 2 at
        # rest)
        printed = ftg100_parameters().value
        ce5 = _eq5_coefficient()
        x_eq5 = printed("D_a") * ce5 * V0 ** 2 / printed("K_sa")
        gain_eq8 = printed("D_a") * 2.0 * ce5 * V0 / printed("K_sa")
        kappa = p("c_e") / ce5
        kappa_free = kappa * static_force_factor(self.parameters)  # × eq 5 for 20 µm free
        return [
            compare("static-70V-eq5", self.name, computed=x_eq5, stated=x70_stated, rtol=0.1,
                    unit="m",
                    what=("free tip displacement at 70 V from the printed numbers, D_a N_a ε "
                          "h V²/(2g K_sa) "
                          f"(eqs 2-5, F_x = {ce5 * V0 ** 2 * 1e6:.4g} µN; small-signal gain of eq "
                          "8 with "
                          f"k_k = 0: {gain_eq8 * 1e6:.4g} µm/V where 20 µm at 70 V with F ∝ V² "
                          "means "
                          f"{2 * x70_stated / V0 * 1e6:.3g} µm/V), if 20 µm is the free tip's "
                          "travel"),
                    used=("20 µm read as the gap to the ball (static-70V-grasp) where force_factor "
                          "= 1; "
                          "plant_parameters(force_factor='static-70V') adopts the free-arm "
                          "reading"),
                    source=_S + "§III-A, eqs 3-5 and the statement after Fig. 4"),
            compare("static-70V", self.name, computed=x70, stated=x70_stated, rtol=0.1, unit="m",
                    what=(f"free tip displacement at 70 V of this plant (c_e = {kappa:.4g} × eq 5, "
                          "K3_a = "
                          f"{p('K3_a'):.4g} N/m³; linear suspensions: {lin70 * 1e6:.3g} µm), if 20 "
                          "µm is the "
                          f"free tip's travel"),
                    used=(f"c_e = {p('c_e') * 1e9:.4g} nN/V²; the free-arm reading needs "
                          "force_factor = "
                          f"{kappa_free:.4g} (× eq 5): "
                          "plant_parameters(force_factor='static-70V'), whose "
                          f"small-signal gain is then {kappa_free:.4g} × eq 10's"),
                    source=_S + "§III-A, after Fig. 4"),
            self._grasp_finding(V0, x70_stated),
            self._eq10_finding(V0),
            self._full_close_finding(),
            compare("eq5-force-factor", self.name, computed=p("c_e"), stated=ce5, rtol=1e-3,
                    unit="N/V**2",
                    what=(f"comb-drive coefficient c_e of this plant (κ = {kappa:.4g}) vs N_a ε "
                          "h/(2g) of eq 5; "
                          f"its small-signal gains at 70 V are κ × those of eqs 8-10"),
                    used=f"c_e = {kappa:.4g} × eq 5", source=_S + "eq 5"),
        ]

    def _grasped(self) -> "FTG100Plant":
        """This plant with an object (the seed's k0 = 1043 N/m if it has none)."""
        if self.parameters.value("k0") > 0:
            return self
        return self.with_parameters(check=False, k0=ftg100_parameters().value("k0"))

    def _grasp_finding(self, V0: float, x_stated: float) -> Finding:
        """The gap reading of §III-A's 20 µm: the 100 µm opening less the 80 µm ball is the travel
        70 V must give to reach the ball; with the ball, the tip stands beyond it by the sensing
        arm's
        deflection x_b = F_c/k2 and the ball's compression F_c/k0 (eqs 6-7)."""
        p = self.parameters.value
        g = self._grasped()
        e = g.equilibrium(V0)
        k0 = g.parameters.value("k0")
        if e["F_c"] < 1e-12:  # the tip just reaches the ball (the calibrated plant): print zeros
            e = dict(e, F_c=0.0, x_b=0.0)
        what = (f"tip at 70 V with the 80 µm ball (gap {p('gap') * 1e6:.3g} µm = 100 µm opening − "
                "80 µm ball, "
                f"F_c = {e['F_c'] * 1e6:.4g} µN: sensing arm pushed back x_b = "
                f"{e['x_b'] * 1e6:.3g} µm, ball "
                f"compressed F_c/k0 = {e['F_c'] / k0 * 1e6:.2g} µm), if 20 µm is the travel to the "
                "ball; "
                f"tolerance 20 %: the excess is the grip itself (linear suspensions 17.9 %, "
                f"stretching 13.1 %), against 117 % for the free-arm reading")
        return compare("static-70V-grasp", self.name, computed=e["x_a"], stated=x_stated,
                       rtol=0.2, unit="m",
                       what=what, used="gap = 20 µm: 70 V closes the arm on the ball",
                       source=_S + "§II-A opening, §III-A '80 µm' and the statement after Fig. 4")

    def _eq10_finding(self, V0: float) -> Finding:
        """Eq 10 is eq 9 at V_in0 = 70 V, grasped: this plant linearised there must give its DC
        gain."""
        g = self._grasped()
        gain = float(g.linearize(V0).dc_gain()[0, 0])
        seed = float(seed_state_space(SEED_EQ10).dc_gain()[0, 0])
        return compare("eq10-plant-gain", self.name, computed=gain, stated=seed, rtol=0.015,
                       unit="m/V",
                       what=("small-signal gain ∂x_a/∂V of this plant at 70 V with the ball "
                             "grasped vs the DC "
                             "gain of the printed eq 10 (eq 9 with eq 5's force: 0.56 % from it; "
                             "tolerance "
                             "1.5 % as for eq 10's own check)"),
                       used="this plant's parameters", source=_S + "eqs 9-10")

    def _full_close_finding(self) -> Finding:
        """§II-A: "the full close is achieved while applying the maximum actuation voltage (200V)":
        the free tip must close the 100 µm opening at or below V_max."""
        p = self.parameters.value
        opening = ftg100_geometry().value("opening")
        V = full_close_voltage(self.parameters, opening)
        ok = bool(V <= p("V_max") * (1 + 1e-9))
        x200 = self.with_parameters(check=False, k0=0.0).equilibrium(p("V_max"))["x_a"]
        msg = (f"voltage at which the free tip closes the {opening * 1e6:.3g} µm opening, "
               f"√((K_sa x_e + K3_a x_e³)/c_e) with x_e = opening/D_a, = {V:.4g} V, stated "
               f"{p('V_max'):.3g} V (full close achieved at the maximum voltage); free tip at "
               f"{p('V_max'):.3g} V: {x200 * 1e6:.4g} µm" + ("" if ok else " (does not close)")
               + ". Linear suspensions close at 106.2 V (the arms meet there; the plant has no "
               "arm-to-arm contact), β = π⁴/128 stretching reaches only 79.9 µm")
        return Finding("full-close-200V", self.name, ok, msg,
                       f"K3_a = {p('K3_a'):.4g} N/m³, c_e = {p('c_e') * 1e9:.4g} nN/V²", V,
                       p("V_max"),
                       abs(V - p("V_max")) / p("V_max"), 0.0, _S + "§II-A")


# ------------------------------------------------------------------------------------------------
# the zoo's factories
# ------------------------------------------------------------------------------------------------

def actuated_model(**values) -> FTG100Actuated:
    """Zoo ``ftg100-actuated``: eqs 8-10 at the seed's values (M_a, K_fa, k0 free)."""
    return FTG100Actuated(**values)


def sensing_model(**values) -> FTG100Sensing:
    """Zoo ``ftg100-sensing``: eqs 14-17 at the seed's values (M_b, K_fb free)."""
    return FTG100Sensing(**values)


def coupled_model(**values) -> FTG100Coupled:
    """Zoo ``ftg100-coupled``: eq 18 (actuated and sensing subsystems through k_k, readout r)."""
    return FTG100Coupled(**values)


def plant_model(**values) -> FTG100Plant:
    """Zoo ``ftg100-plant``: the nonlinear plant with eq 5's force as printed and the linear
    suspensions of eqs 4 and 8-10 (its small-signal model at 70 V grasped is eq 9/10, 0.82 % from
    eq 10's gain), V² actuation, contact with the ball after the 20 µm gap (100 µm opening − 80 µm
    ball: the seed's "20 µm at 70 V" read as the travel to the ball; derivation of both readings in
    :mod:`gripkit.systems.ftg100.model`)."""
    return FTG100Plant(**values)


def calibrated_plant_model(**values) -> FTG100Plant:
    """Zoo ``ftg100-plant-calibrated``: the other reading of the seed's 20 µm at 70 V (the free
    tip's displacement): the default plant with the comb-drive force factor fitted to it (κ = 0.4601
    × eq 5 with the linear suspensions, ``plant_parameters(force_factor='static-70V')``), which puts
    its small-signal gain at 70 V 53.6 % below eq 10 (reported by ``zoo check``). ``values`` replace
    parameters before the fit."""
    check = values.pop("check", True)
    return FTG100Plant(plant_parameters(force_factor="static-70V", **values), check=check)
