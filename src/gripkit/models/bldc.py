"""Brushless DC motor driven by PWM: torque versus PWM, speed and winding temperature.

The DLR/HIT Hand II motor (maxon EC 20 flat) was characterised on a test bed in
``002_ddea254371185ad3.txt`` chapter 5. With the PWM duty count u ∈ [−4096, 4096] (§5.2: "from
0 (no voltage) to 4096 (continuous voltage)"; the sign selects the direction) and the shaft speed
n in rpm, the thesis's model (eq 5.10 = eqs 5.7 + 5.8) is

    τ(u, n) = c·u + b(|u|)·n,                                                     (5.7)
    c = 1.43·10⁻⁴ Ncm per PWM count,
    b(|u|) = 1.215·10⁻⁸ Ncm/(rpm·PWM)·|u| − 7.711·10⁻⁵ Ncm/rpm                    (5.8)

with Appendix E's guard: if |c·u| < |b(|u|)·n| the torque is zero (the speed term may never
overturn the PWM term). The slopes b printed in §5.4.2 for PWM 2000/2500/3000/3500 are the
magnitudes −5.332, −4.688, −3.876, −3.582 ·10⁻⁵ Ncm/rpm; eq 5.8 is their least-squares line
(largest deviation 4.9 % at PWM 3000; see :meth:`BLDCMotor.consistency_checks`).

**Power balance** (§5.2, eqs 5.1–5.4 and 5.6). The thesis balances the electrical input against
mechanical output, Joule heat and friction, P_el = P_mech + P_J + P_F (5.1), with P_el = U·I (5.2),
P_mech = π·τ·n/30000 (5.3; τ in mN·m, n in rpm, the π lost in the text extraction) and
P_J = R(T)·I² (5.4), combined as U·I = π·τ·n/30000 + R(T)·I² + P_F (5.6). gripkit lumps P_F into
the drive-train friction (Appendix G) and, with τ = k_t·I, divides eq 5.6 by I: U = k_t·ω + R(T)·I,
i.e. τ = k_t(U − k_t·ω)/R(T) — the physical law behind the 1/R temperature scaling below and the
k_t, R₀ derivation of the thermal model. The thermal model heats the winding with eq 5.4's P_J
(:func:`motor_heat_step`).

**Temperature** (eq 5.5). The winding resistance is R(T) = R₀(1 + α(T − T₀)) with T₀ the ambient
temperature. Both terms of the physical motor law τ = k_t (u·V/4096 − k_e ω)/R scale with 1/R, so
gripkit multiplies eq 5.10 by ρ(T) = R(T_ref)/R(T), where T_ref is the temperature at which eqs
5.7–5.8 were measured (the "operating temperature" after the heat-up phase of §5.4.1).

*Derivation of α and T_ref.* Fig. 5.7 states that PWM 4000 at stall gives "nearly 1 Ncm at room
temperature" and "less than 0.6 Ncm" as the motor reaches about 80 °C; eq 5.7 gives
1.43·10⁻⁴·4000 = 0.572 Ncm at the operating temperature. Taking T_ref = 80 °C (so eq 5.7 is the
hot value, < 0.6 Ncm) and 1.0 Ncm at T₀ = 25 °C gives ρ(T₀) = 1.748, i.e. α = 0.748/55 K =
0.0136 K⁻¹. That is 3.5 times copper's 0.0039 K⁻¹ — and the thesis itself says (§5.2) that 50 K
raise the resistance by about 20 % (α ≈ 0.004 K⁻¹), which would only drop the torque to
0.82 Ncm at 80 °C. gripkit uses the effective α that reproduces Fig. 5.7 (the winding is hotter
than the measured 80 °C, and the magnets weaken) and reports the contradiction.

**Thermal model** (gripkit's addition: the thesis gives eq 5.5 and Fig. 5.7's course, no model of
the winding temperature). A first-order lumped model, C_th dT/dt = R(T) I² − (T − T₀)/R_th, with
the current I = τ/k_t. k_t and R₀ follow from an assumed 12 V supply and the physical reading of
the speed slope (|b(3000)| = k_t²/R(T_ref)): k_t = 7.95 mN·m/A, R₀ = 9.32 Ω; R_th = 7.2 K/W and
C_th = 5.5 J/K make the Fig. 5.7 experiment (PWM 4000 held at stall) settle near 84 °C with a 40 s
time constant, so the torque falls from 1.0 Ncm to 0.57 Ncm within the figure's 120 s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np
from numba import prange

from ..consistency import Finding, compare
from ..errors import ModelError
from ..multibody.kernels import hot
from ..params import Parameter, ParameterSet
from ..sim.model import Model, Signal

__all__ = ["bldc_torque", "temperature_factor", "motor_parameters", "BLDCMotor",
           "MotorTestBed", "PowerBalance", "RPM", "SLOPES_5_4_2", "PWM_MAX", "SEED",
           "SUPPLY_VOLTAGE", "RATED_SPEED_RPM"]

SEED = "002_ddea254371185ad3.txt"
RPM = 2.0 * math.pi / 60.0  # rad/s per rpm
NCM = 0.01  # N·m per Ncm
PWM_MAX = 4096.0
#: §5.4.2: slopes of torque over speed at constant PWM (Ncm/rpm; printed as magnitudes)
SLOPES_5_4_2 = {2000: -5.332e-5, 2500: -4.688e-5, 3000: -3.876e-5, 3500: -3.582e-5}
#: supply voltage assumed for the derivation of k_t and R₀ (V; the seed gives none)
SUPPLY_VOLTAGE = 12.0
#: rated speed of the finger motor (§2: "The rated speed and torque of the motor are 6000 rpm and
#: 3.2 mNm")
RATED_SPEED_RPM = 6000.0
#: largest speed on Fig. 5.6's axis (printed "rotationalspeed[rps]", 0..3000)
FIG_5_6_MAX_SPEED = 3000.0


@dataclass(frozen=True)
class PowerBalance:
    """The terms of eqs 5.1–5.6 at given PWM counts and speeds (arrays broadcast together), all
    in W except ``voltage`` (V), ``current`` (A), ``torque`` (N·m) and ``speed`` (rpm):
    P_el = U·I (5.2), P_mech = π·τ·n/30000 (5.3; τ in mN·m, n in rpm), P_J = R(T)·I² (5.4),
    and the friction loss the balance leaves, P_F = P_el − P_mech − P_J (5.1, 5.6).
    ``friction_fraction`` = P_F/P_mech (NaN where P_mech = 0)."""

    pwm: np.ndarray
    speed: np.ndarray
    voltage: np.ndarray
    current: np.ndarray
    torque: np.ndarray
    electrical: np.ndarray
    mechanical: np.ndarray
    joule: np.ndarray
    friction: np.ndarray

    units = {"pwm": "1", "speed": "rpm", "voltage": "V", "current": "A", "torque": "N*m",
             "electrical": "W", "mechanical": "W", "joule": "W", "friction": "W"}

    @property
    def friction_fraction(self) -> np.ndarray:
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(self.mechanical != 0, self.friction / self.mechanical, np.nan)

    def as_dict(self) -> dict:
        """Each term with its unit: ``{name: (value, unit)}``."""
        return {k: (getattr(self, k), u) for k, u in self.units.items()}


@hot
def temperature_factor(T, T_ref, T_amb, alpha):  # pragma: no cover - compiled
    """ρ(T) = R(T_ref)/R(T) with R(T) = R₀(1 + α(T − T_amb))  (eq 5.5)."""
    return (1.0 + alpha * (T_ref - T_amb)) / (1.0 + alpha * (T - T_amb))


@hot
def bldc_torque(pwm, omega, c, b1, b0, pwm_max, rho):  # pragma: no cover - compiled
    """Shaft torque (N·m) of eq 5.10 with Appendix E's guard.

    ``pwm`` duty count (clipped to ±pwm_max), ``omega`` shaft speed (rad/s), ``c`` (N·m per
    count), ``b1`` (N·m·s/rad per count), ``b0`` (N·m·s/rad), ``rho`` the temperature factor."""
    if pwm > pwm_max:
        pwm = pwm_max
    elif pwm < -pwm_max:
        pwm = -pwm_max
    a = c * pwm
    s = (b1 * abs(pwm) + b0) * omega
    if abs(a) < abs(s):
        return 0.0
    return rho * (a + s)


def motor_parameters(*, name: str = "bldc") -> ParameterSet:
    """Parameters of the DLR/HIT Hand II motor with the thesis's values (SI units)."""
    src57 = f"{SEED}, eq 5.7 (1.43e-4 Ncm/PWM)"
    src58 = f"{SEED}, eq 5.8"
    return ParameterSet([
        Parameter("c_pwm", 1.43e-4 * NCM, "N*m", "torque per PWM count at stall and T_ref",
                  bounds=(0.0, None), source=src57, display_unit="N*cm"),
        Parameter("b_pwm", 1.215e-8 * NCM / RPM, "N*m*s/rad",
                  "PWM-proportional part of the torque-speed slope (per count)",
                  source=f"{src58} (1.215e-8 Ncm/(rpm·PWM))"),
        Parameter("b_0", -7.711e-5 * NCM / RPM, "N*m*s/rad", "constant part of the "
                                                             "torque-speed slope",
                  source=f"{src58} (-7.711e-5 Ncm/rpm)"),
        Parameter("pwm_max", PWM_MAX, "1", "largest PWM count (continuous voltage)",
                  bounds=(1.0, None), fixed=True, source=f"{SEED}, §5.2"),
        Parameter("T_ref", 353.15, "K", "winding temperature at which eqs 5.7-5.8 hold",
                  bounds=(200.0, 500.0), display_unit="degC",
                  source="derived: Fig. 5.7 (<0.6 Ncm near 80 °C) with eq 5.7 (0.572 Ncm)"),
        Parameter("T_amb", 298.15, "K", "ambient (room) temperature T0 of eq 5.5",
                  bounds=(200.0, 400.0), display_unit="degC", source="assumed: 25 °C room"),
        Parameter("alpha_R", 0.0136, "1/K", "effective temperature coefficient of the "
                                            "winding resistance",
                  bounds=(0.0, 0.1),
                  source="derived: Fig. 5.7, ~1.0 Ncm at 25 °C -> 0.572 Ncm at 80 °C "
                         "(see module doc)"),
        Parameter("k_t", 7.95e-3, "N*m/A", "torque constant",
                  bounds=(1e-6, None), source="derived: 12 V supply (assumed) and |b(3000)| "
                                              "= k_t²/R(T_ref)"),
        Parameter("R_0", 9.32, "ohm", "winding resistance at T_amb",
                  bounds=(1e-6, None), source="derived: 12 V supply (assumed) and eq 5.7 at 25 °C"),
        Parameter("R_th", 7.2, "K/W", "thermal resistance winding to ambient",
                  bounds=(1e-6, None), source="calibrated: Fig. 5.7 settles near 80 °C"),
        Parameter("C_th", 5.5, "J/K", "heat capacity of the motor",
                  bounds=(1e-6, None), source="calibrated: Fig. 5.7 time constant ~40 s"),
    ], name)


class BLDCMotor:
    """The PWM-driven BLDC motor of eq 5.10 with temperature dependence (eq 5.5).

    Every method takes numpy arrays (broadcast) and SI units: speed in rad/s at the shaft,
    temperature in K (``None``: T_ref, i.e. eq 5.10 as printed).
    """

    name = "dlr-hit-bldc"
    description = ("maxon EC 20 flat BLDC motor of the DLR/HIT Hand II, torque vs "
                   "PWM/speed/temperature")

    def __init__(self, parameters: ParameterSet | None = None):
        self.parameters = parameters if parameters is not None else motor_parameters()

    def _p(self, name):
        return self.parameters.value(name)

    def rho(self, T=None):
        """ρ(T) = R(T_ref)/R(T); 1 at T_ref."""
        if T is None:
            return 1.0
        T = np.asarray(T, dtype=np.float64)
        a = self._p("alpha_R")
        return (1.0 + a * (self._p("T_ref") - self._p("T_amb"))) / (1.0 + a
                                                                    * (T - self._p("T_amb")))

    def slope(self, pwm) -> np.ndarray:
        """b(|u|) of eq 5.8 in N·m·s/rad (multiply by RPM/NCM for Ncm/rpm)."""
        return self._p("b_pwm") * np.abs(np.asarray(pwm, dtype=np.float64)) + self._p("b_0")

    def torque(self, pwm, speed=0.0, T=None) -> np.ndarray:
        """Shaft torque (N·m), eq 5.10 with the Appendix E guard; ``speed`` in rad/s."""
        u = np.clip(np.asarray(pwm, dtype=np.float64), -self._p("pwm_max"), self._p("pwm_max"))
        a = self._p("c_pwm") * u
        s = self.slope(u) * np.asarray(speed, dtype=np.float64)
        return np.where(np.abs(a) < np.abs(s), 0.0, (a + s) * self.rho(T))

    def pwm_for_torque(self, torque, speed=0.0, T=None) -> np.ndarray:
        """PWM count that yields ``torque`` (N·m) at ``speed`` (rad/s): the inverse of eq 5.10,
        clipped to ±pwm_max (used by torque controllers)."""
        tau = np.asarray(torque, dtype=np.float64) / self.rho(T)
        w = np.asarray(speed, dtype=np.float64)
        c, b1, b0 = self._p("c_pwm"), self._p("b_pwm"), self._p("b_0")
        up = (tau - b0 * w) / (c + b1 * w)
        um = (tau - b0 * w) / (c - b1 * w)
        u = np.where(up >= 0, up, um)
        return np.clip(u, -self._p("pwm_max"), self._p("pwm_max"))

    def current(self, torque, T=None) -> np.ndarray:
        """Winding current I = τ/k_t (A): the current of eqs 5.2 and 5.4 (P_el = U·I, P_J =
        R(T)·I²)."""
        return np.asarray(torque, dtype=np.float64) / self._p("k_t")

    def resistance(self, T) -> np.ndarray:
        """R(T) = R₀(1 + α(T − T_amb)) (Ω), eq 5.5: the resistance of the Joule loss P_J = R(T)·I²
        (eq 5.4) in the power balance of eq 5.6."""
        return (self._p("R_0") * (1.0 + self._p("alpha_R")
                                  * (np.asarray(T, dtype=np.float64) - self._p("T_amb"))))

    def electrical_constants(self, supply_voltage: float = SUPPLY_VOLTAGE) -> tuple[float, float]:
        """(k_t in N·m/A, R₀ in Ω) that make a DC motor on ``supply_voltage`` (V) give eq 5.10's
        stall torque and its speed slope at PWM 3000, at T_ref.

        A DC motor fed the mean voltage U = V·u/4096 gives τ = k_t(U − k_t·ω)/R: the stall term
        k_t·V/(4096·R) = c (eq 5.7) and the slope −k_t²/R = b(3000) (eq 5.8). Hence
        k_t = V·|b(3000)|/(4096·c) and R(T_ref) = k_t²/|b(3000)|, R₀ = R(T_ref)/(1 + α(T_ref − T₀)).
        At 12 V: k_t = 7.955 mN·m/A, R₀ = 9.32 Ω (the parameters ``k_t``, ``R_0``); k_t ∝ V, R ∝ V².
        """
        if not (isinstance(supply_voltage, (int, float)) and math.isfinite(supply_voltage)
                and supply_voltage > 0):
            raise ModelError(f"supply_voltage: expected a positive voltage in V, "
                             f"found {supply_voltage!r}")
        b3000 = abs(float(self.slope(3000.0)))
        kt = supply_voltage * b3000 / (PWM_MAX * self._p("c_pwm"))
        R_ref = kt * kt / b3000
        R0 = R_ref / (1.0 + self._p("alpha_R") * (self._p("T_ref") - self._p("T_amb")))
        return kt, R0

    def power_balance(self, pwm, speed_rpm, T=None, *,
                      supply_voltage: float | None = None) -> PowerBalance:
        """Eqs 5.1–5.6 for eq 5.10's torque at ``pwm`` (count) and ``speed_rpm`` (rpm, ≥ 0 in the
        direction of the torque; the quadrant of Fig. 5.6), winding temperature ``T`` (K, default
        T_ref).

        U = V·|u|/4096 (the PWM's mean voltage, §5.2), I = τ/k_t, P_el = U·I (5.2),
        P_mech = π·τ[mN·m]·n/30000 (5.3, = τ·ω), P_J = R(T)·I² (5.4, R(T) of 5.5) and
        P_F = P_el − P_mech − P_J (5.6). With ``supply_voltage`` None the parameters' k_t, R₀ and
        the 12 V they were derived with; with a voltage, k_t and R₀ re-derived for it
        (:meth:`electrical_constants`).

        *Why P_F < 0 above PWM 3000, at any supply voltage and speed.* With k_t, R from
        :meth:`electrical_constants`, U·I = τ·u·c/|b(3000)| and R·I² = τ²/|b(3000)| at T_ref, so
        P_F = τ·[(c·u − τ)/|b(3000)| − ω] = τ·ω·(|b(u)|/|b(3000)| − 1), because eq 5.10 gives
        c·u − τ = |b(u)|·ω. Hence P_F/P_mech = |b(u)|/|b(3000)| − 1, independent of V and n: eq 5.8
        makes the slope shrink with PWM, while a DC motor's slope −k_t²/R does not depend on the
        voltage. Above PWM 3000 eq 5.10 delivers more mechanical power than the electrical input
        less Joule heat: −14.9 % of P_mech at 3500, −29.9 % at 4000 (+14.9 % at 2500, +29.9 % at
        2000, 0 at 3000 by construction). The parameters' rounded k_t = 7.95 mN·m/A and
        R₀ = 9.32 Ω (``supply_voltage=None``) shift these by up to 0.3 points."""
        pmax = self._p("pwm_max")
        u = np.abs(np.clip(np.asarray(pwm, dtype=np.float64), -pmax, pmax))
        n = np.asarray(speed_rpm, dtype=np.float64)
        if not (np.isfinite(u).all() and np.isfinite(n).all()) or (n < 0).any():
            raise ModelError("power_balance: expected finite PWM counts and speeds >= 0 rpm "
                             "(the driving quadrant of Fig. 5.6)")
        if supply_voltage is None:
            V, kt, R0 = SUPPLY_VOLTAGE, self._p("k_t"), self._p("R_0")
        else:
            V = float(supply_voltage)
            kt, R0 = self.electrical_constants(V)
        Tk = self._p("T_ref") if T is None else np.asarray(T, dtype=np.float64)
        tau = self.torque(u, n * RPM, Tk)
        I = tau / kt
        U = V * u / PWM_MAX
        R = R0 * (1.0 + self._p("alpha_R") * (Tk - self._p("T_amb")))
        p_el = U * I
        p_mech = math.pi * (tau * 1e3) * n / 30000.0  # eq 5.3 with τ in mN·m, n in rpm
        p_j = R * I * I
        u, n = np.broadcast_arrays(u, n)
        return PowerBalance(u, n, U, I, tau, p_el, p_mech, p_j, p_el - p_mech - p_j)

    def consistency_checks(self) -> list[Finding]:
        """Eq 5.8 against the slopes printed in §5.4.2; the temperature coefficient implied by
        Fig. 5.7 against the thesis's own statement for copper (§5.2); the power balance of eq
        5.6 with eq 5.10 over Fig. 5.6's PWM range; Fig. 5.6's speed unit."""
        out = [self._power_balance_finding(), self._speed_unit_finding()]
        for pwm, stated in SLOPES_5_4_2.items():
            out.append(compare(f"eq5.8-slope-pwm{pwm}", self.name,
                               computed=float(self.slope(pwm)) * RPM / NCM, stated=stated,
                               rtol=0.06,
                               what=f"eq 5.8 slope at PWM {pwm}", unit="Ncm/rpm",
                               used="gripkit uses eq 5.8 (the least-squares line through "
                                    "the four slopes)",
                               source=f"{SEED}, §5.4.2"))
        a_eff = self._p("alpha_R")
        dT = 55.0
        drop_copper = 1.0 / (1.0 + 0.2 / 50.0 * dT)
        drop_eff = 1.0 / (1.0 + a_eff * dT)
        out.append(compare("fig5.7-temperature-coefficient", self.name,
                           computed=a_eff, stated=0.2 / 50.0, rtol=0.25,
                           what="α implied by Fig. 5.7 with eq 5.7 (vs §5.2: '50 K raise R "
                                "by about 20 %')",
                           unit="1/K",
                           used=(f"gripkit uses α = {a_eff:.4g}/K, which reproduces "
                                 "Fig. 5.7 (1.0 -> "
                                 f"{drop_eff:.2f} Ncm from 25 to 80 °C); §5.2's α would give only "
                                 f"{drop_copper:.2f} Ncm"),
                           source=f"{SEED}, §5.2 and Fig. 5.7"))
        return out

    def _power_balance_finding(self) -> Finding:
        """Eq 5.6 with eq 5.10 at PWM 2000..4000 (Fig. 5.6) and 1000 rpm: the smallest
        P_F/P_mech must be ≥ 0 (friction cannot return power)."""
        pwm = np.arange(2000.0, 4001.0, 500.0)
        kt, R0 = self.electrical_constants(SUPPLY_VOLTAGE)
        bal = self.power_balance(pwm, 1000.0, supply_voltage=SUPPLY_VOLTAGE)
        frac = bal.friction_fraction
        i = int(np.argmin(frac))
        worst = float(frac[i])
        neg = ", ".join(f"{frac[j]:+.1%} at PWM {pwm[j]:.0f}" for j in range(pwm.size)
                        if frac[j] < -1e-9)
        R_ref = R0 * (1.0 + self._p("alpha_R") * (self._p("T_ref") - self._p("T_amb")))
        msg = (f"friction loss P_F = U·I − π·τ·n/30000 − R(T)·I² (eq 5.6) with eq 5.10's torque at "
               f"1000 rpm, {SUPPLY_VOLTAGE:g} V, k_t = {kt * 1e3:.3g} mN·m/A, R(T_ref) = "
               f"{R_ref:.3g} Ω: P_F/P_mech = {worst:+.1%} at PWM "
               f"{pwm[i]:.0f} (must be >= 0); negative: {neg or 'none'}. P_F/P_mech = "
               f"|b(PWM)|/|b(3000)| − 1 at every speed and supply voltage (eq 5.8's slope shrinks "
               f"with PWM; a DC motor's −k_t²/R does not)")
        return Finding("eq5.6-power-balance", self.name, worst >= 0.0, msg,
                       used=("gripkit keeps eq 5.10 (the measured torque) for the motor and "
                             "the thermal model's Joule heat; the balance says eq 5.8's "
                             "PWM-dependent slope is not a DC motor's at one k_t and R above "
                             "PWM 3000"),
                       computed=worst, stated=0.0, rel_error=abs(min(worst, 0.0)), tolerance=0.0,
                       source=f"{SEED}, eqs 5.1-5.6, 5.8, 5.10 and Fig. 5.6")

    def _speed_unit_finding(self) -> Finding:
        """Fig. 5.6's axis (and eq 5.8's closing label) say rps; §5.4.2, Fig. 5.5 and eq 5.8's
        slopes say rpm. Read as rps, Fig. 5.6 would reach 3000·60 rpm, 30× the motor's rated
        speed."""
        as_rpm = FIG_5_6_MAX_SPEED * 60.0
        rel = as_rpm / RATED_SPEED_RPM - 1.0
        drop = (self._p("c_pwm") * 4000.0 + float(self.slope(4000.0)) * 2500 * 60 * RPM) / NCM
        msg = (f"Fig. 5.6's speed axis (0..{FIG_5_6_MAX_SPEED:.0f}) and eq 5.8's last label read "
               f"'rps': {as_rpm:.0f} rpm, {as_rpm / RATED_SPEED_RPM:.0f}× the motor's rated "
               f"{RATED_SPEED_RPM:.0f} rpm (§2), and eq 5.10 at PWM 4000 would give "
               f"{drop:.3g} Ncm at 2500 rps before Appendix E's guard (Fig. 5.6 shows 0..0.6 "
               f"Ncm); §5.4.2 ('steps of around "
               f"500 rpm from zero to 2500'), Fig. 5.5 (rpm) and eq 5.8's slopes (Ncm/rpm) "
               f"read rpm")
        return Finding("fig5.6-speed-unit", self.name, False, msg,
                       used=("gripkit reads rpm: eq 5.8's slopes are per rpm, the experiment "
                             "of Fig. 5.5 ran in rpm, and rps would exceed the rated speed 30×"),
                       computed=as_rpm, stated=RATED_SPEED_RPM, rel_error=rel, tolerance=0.0,
                       source=f"{SEED}, §2, §5.4.2, Figs 5.5-5.6, eq 5.8")

    def __repr__(self) -> str:
        return f"BLDCMotor({self.parameters!r})"


# --- test-bed simulation (Fig. 5.2, 5.7) --------------------------------------------------------

@hot
def motor_heat_step(T, tau_shaft, h, T_amb, alpha, R0, kt, Rth, Cth):  # pragma: no cover - compiled
    """One explicit step of C_th dT/dt = P_J − (T − T_amb)/R_th, with the Joule heat
    P_J = R(T)·I² of eq 5.4, I = τ/k_t, and R(T) of eq 5.5."""
    cur = tau_shaft / kt
    R = R0 * (1.0 + alpha * (T - T_amb))
    return T + h * (R * cur * cur - (T - T_amb) / Rth) / Cth


@numba.njit(cache=True, parallel=True, error_model="numpy")
def _testbed_batch(thetas, u, dt, substeps, x0, y):  # pragma: no cover - compiled
    P = thetas.shape[0]
    N = u.shape[0]
    h = dt / substeps
    for p in prange(P):
        th = thetas[p]
        c, b1, b0, pmax = th[0], th[1], th[2], th[3]
        T_ref, T_amb, alpha, kt, R0, Rth, Cth = th[4], th[5], th[6], th[7], th[8], th[9], th[10]
        T = x0[p, 0]
        for n in range(N):
            rho = temperature_factor(T, T_ref, T_amb, alpha)
            tau = bldc_torque(u[n, 0], u[n, 1], c, b1, b0, pmax, rho)
            y[p, n, 0] = tau
            y[p, n, 1] = T
            y[p, n, 2] = tau / kt
            for _ in range(substeps):
                rho = temperature_factor(T, T_ref, T_amb, alpha)
                tau = bldc_torque(u[n, 0], u[n, 1], c, b1, b0, pmax, rho)
                T = motor_heat_step(T, tau, h, T_amb, alpha, R0, kt, Rth, Cth)


class MotorTestBed(Model):
    """The §5.3 test bed: the motor held at an imposed shaft speed (hysteresis brake) under a PWM
    command, with its winding temperature evolving (first-order thermal model).

    Inputs ``pwm`` (count) and ``speed`` (rad/s); outputs ``torque`` (N·m), ``temperature`` (K)
    and ``current`` (A); state: winding temperature (starts at ``T_amb``).
    """

    name = "dlr-hit-motor-test-bed"
    description = "BLDC motor on the torque test bed of §5.3 (eq 5.10 with temperature, Fig. 5.7)"
    inputs = (Signal("pwm", "1", "PWM duty count"), Signal("speed", "rad/s", "imposed shaft speed"))
    outputs = (Signal("torque", "N*m", "shaft torque"),
               Signal("temperature", "K", "winding temperature"),
               Signal("current", "A", "winding current"))
    states = (Signal("temperature", "K", "winding temperature"),)
    integrator = "semi-implicit"

    def __init__(self, parameters: ParameterSet | None = None, *, check: bool = True):
        parameters = parameters if parameters is not None else motor_parameters()
        if parameters.names != motor_parameters().names:
            raise ModelError("MotorTestBed: expected the parameters of "
                             "motor_parameters(), in order",
                             hint=f"found {', '.join(parameters.names)}")
        super().__init__(parameters, check=check)

    def _simulate_batch(self, thetas, u, dt, substeps, x0, y):
        _testbed_batch(thetas, u, dt, substeps, x0, y)

    def initial_state(self, theta):
        return np.array([theta[self.parameters.names.index("T_amb")]])

    def modes(self, theta):
        p = dict(zip(self.parameters.names, theta))
        return [(1.0 / (p["R_th"] * p["C_th"]), 1.0)]

    @property
    def motor(self) -> BLDCMotor:
        return BLDCMotor(self.parameters)

    def consistency_checks(self):
        return self.motor.consistency_checks()
