"""Brushless DC motor driven by PWM: torque versus PWM, speed and winding temperature.

The DLR/HIT Hand II motor (maxon EC 20 flat) was characterised on a test bed in
``002_ddea254371185ad3.txt`` chapter 5. With the PWM duty count u ∈ [−4096, 4096] (§5.2: "from
0 (no voltage) to 4096 (continuous voltage)"; the sign selects the direction) and the shaft speed
n in rpm, the thesis's model (eq 5.10 = eqs 5.7 + 5.8) is

    τ(u, n) = c·u + b(|u|)·n,        c = 1.43·10⁻⁴ Ncm per PWM count              (5.7)
                                     b(|u|) = 1.215·10⁻⁸ Ncm/(rpm·PWM)·|u| − 7.711·10⁻⁵ Ncm/rpm  (5.8)

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

**Thermal model.** A first-order lumped model, C_th dT/dt = R(T) I² − (T − T₀)/R_th, with the
current I = τ/k_t. k_t and R₀ follow from an assumed 12 V supply and the physical reading of the
speed slope (|b(3000)| = k_t²/R(T_ref)): k_t = 7.95 mN·m/A, R₀ = 9.32 Ω; R_th = 7.2 K/W and
C_th = 5.5 J/K make the Fig. 5.7 experiment (PWM 4000 held at stall) settle near 84 °C with a
40 s time constant, so the torque falls from 1.0 Ncm to 0.57 Ncm within the figure's 120 s.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba import prange

from ..consistency import Finding, compare
from ..errors import ModelError
from ..multibody.kernels import hot
from ..params import Parameter, ParameterSet
from ..sim.model import Model, Signal

__all__ = ["bldc_torque", "temperature_factor", "motor_parameters", "BLDCMotor",
           "MotorTestBed", "RPM", "SLOPES_5_4_2", "PWM_MAX", "SEED"]

SEED = "002_ddea254371185ad3.txt"
RPM = 2.0 * math.pi / 60.0  # rad/s per rpm
NCM = 0.01  # N·m per Ncm
PWM_MAX = 4096.0
#: §5.4.2: slopes of torque over speed at constant PWM (Ncm/rpm; printed as magnitudes)
SLOPES_5_4_2 = {2000: -5.332e-5, 2500: -4.688e-5, 3000: -3.876e-5, 3500: -3.582e-5}


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
        Parameter("b_0", -7.711e-5 * NCM / RPM, "N*m*s/rad", "constant part of the torque-speed slope",
                  source=f"{src58} (-7.711e-5 Ncm/rpm)"),
        Parameter("pwm_max", PWM_MAX, "1", "largest PWM count (continuous voltage)",
                  bounds=(1.0, None), fixed=True, source=f"{SEED}, §5.2"),
        Parameter("T_ref", 353.15, "K", "winding temperature at which eqs 5.7-5.8 hold",
                  bounds=(200.0, 500.0), display_unit="degC",
                  source="derived: Fig. 5.7 (<0.6 Ncm near 80 °C) with eq 5.7 (0.572 Ncm)"),
        Parameter("T_amb", 298.15, "K", "ambient (room) temperature T0 of eq 5.5",
                  bounds=(200.0, 400.0), display_unit="degC", source="assumed: 25 °C room"),
        Parameter("alpha_R", 0.0136, "1/K", "effective temperature coefficient of the winding resistance",
                  bounds=(0.0, 0.1),
                  source="derived: Fig. 5.7, ~1.0 Ncm at 25 °C -> 0.572 Ncm at 80 °C (see module doc)"),
        Parameter("k_t", 7.95e-3, "N*m/A", "torque constant",
                  bounds=(1e-6, None), source="derived: 12 V supply (assumed) and |b(3000)| = k_t²/R(T_ref)"),
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
    description = "maxon EC 20 flat BLDC motor of the DLR/HIT Hand II, torque vs PWM/speed/temperature"

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
        return (1.0 + a * (self._p("T_ref") - self._p("T_amb"))) / (1.0 + a * (T - self._p("T_amb")))

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
        """Winding current I = τ/k_t (A): the current of eqs 5.2 and 5.4 (P_el = U·I, P_J = R(T)·I²)."""
        return np.asarray(torque, dtype=np.float64) / self._p("k_t")

    def resistance(self, T) -> np.ndarray:
        """R(T) = R₀(1 + α(T − T_amb)) (Ω), eq 5.5: the resistance of the Joule loss P_J = R(T)·I²
        (eq 5.4) in the power balance of eq 5.6."""
        return self._p("R_0") * (1.0 + self._p("alpha_R") * (np.asarray(T, dtype=np.float64) - self._p("T_amb")))

    def consistency_checks(self) -> list[Finding]:
        """Eq 5.8 against the slopes printed in §5.4.2; the temperature coefficient implied by
        Fig. 5.7 against the thesis's own statement for copper (§5.2)."""
        out = []
        for pwm, stated in SLOPES_5_4_2.items():
            out.append(compare(f"eq5.8-slope-pwm{pwm}", self.name,
                               computed=float(self.slope(pwm)) * RPM / NCM, stated=stated, rtol=0.06,
                               what=f"eq 5.8 slope at PWM {pwm}", unit="Ncm/rpm",
                               used="gripkit uses eq 5.8 (the least-squares line through the four slopes)",
                               source=f"{SEED}, §5.4.2"))
        a_eff = self._p("alpha_R")
        dT = 55.0
        drop_copper = 1.0 / (1.0 + 0.2 / 50.0 * dT)
        drop_eff = 1.0 / (1.0 + a_eff * dT)
        out.append(compare("fig5.7-temperature-coefficient", self.name,
                           computed=a_eff, stated=0.2 / 50.0, rtol=0.25,
                           what="α implied by Fig. 5.7 with eq 5.7 (vs §5.2: '50 K raise R by about 20 %')",
                           unit="1/K",
                           used=(f"gripkit uses α = {a_eff:.4g}/K, which reproduces Fig. 5.7 (1.0 -> "
                                 f"{drop_eff:.2f} Ncm from 25 to 80 °C); §5.2's α would give only "
                                 f"{drop_copper:.2f} Ncm"),
                           source=f"{SEED}, §5.2 and Fig. 5.7"))
        return out

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
    outputs = (Signal("torque", "N*m", "shaft torque"), Signal("temperature", "K", "winding temperature"),
               Signal("current", "A", "winding current"))
    states = (Signal("temperature", "K", "winding temperature"),)
    integrator = "semi-implicit"

    def __init__(self, parameters: ParameterSet | None = None, *, check: bool = True):
        parameters = parameters if parameters is not None else motor_parameters()
        if parameters.names != motor_parameters().names:
            raise ModelError("MotorTestBed: expected the parameters of motor_parameters(), in order",
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
