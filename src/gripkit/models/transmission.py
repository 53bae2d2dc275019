"""Rigid transmissions: reduction ratio and efficiency (harmonic drives, timing belts, gear chains).

A stage with reduction N and efficiency η turns an input (motor-side) torque τ_in and speed ω_in
into

    ω_out = ω_in / N,     τ_out = N η τ_in   when the input drives the output (τ_in·ω_in ≥ 0),
                          τ_out = N τ_in / η  when the output back-drives the input.

The DLR/HIT Hand II (``002_ddea254371185ad3.txt`` §3.1 and Appendix E) uses a 100:1 harmonic drive
behind a 2.083:1 timing belt for the proximal/distal joint (N = 208.3) and, for each base motor,
a further 1.125:1 belt to the bevel gears (N = 234.3). Appendix E multiplies motor torque by the
ratios without losses, so the default efficiency is 1; the thesis lumps all losses into its
friction tables (§3.2.2: "the whole system of transfer elements is considered a black box").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..multibody.kernels import hot

__all__ = ["Transmission", "harmonic_drive", "timing_belt", "transmit_torque", "DLR_DISTAL",
           "DLR_BASE"]


@hot
def transmit_torque(tau_in, omega_out, ratio, eta):  # pragma: no cover - compiled
    """Output torque of a stage (see module docstring); ``omega_out`` decides the power flow."""
    if tau_in * omega_out >= 0.0:
        return ratio * eta * tau_in
    return ratio * tau_in / eta


@dataclass(frozen=True)
class Transmission:
    """A chain of reduction stages. ``ratio`` = ω_in/ω_out, ``efficiency`` ∈ (0, 1]."""

    ratio: float
    efficiency: float = 1.0
    name: str = "transmission"

    def __post_init__(self):
        if not (np.isfinite(self.ratio) and self.ratio != 0):
            raise ModelError(f"{self.name}: ratio must be finite and non-zero, "
                             f"found {self.ratio!r}")
        if not (0 < self.efficiency <= 1):
            raise ModelError(f"{self.name}: efficiency must lie in (0, 1], found "
                             f"{self.efficiency!r}")

    def then(self, other: "Transmission") -> "Transmission":
        """This stage followed by ``other`` (ratios and efficiencies multiply)."""
        return Transmission(self.ratio * other.ratio, self.efficiency * other.efficiency,
                            f"{self.name} + {other.name}")

    def output_speed(self, omega_in):
        return np.asarray(omega_in, dtype=np.float64) / self.ratio

    def input_speed(self, omega_out):
        return np.asarray(omega_out, dtype=np.float64) * self.ratio

    def output_torque(self, tau_in, omega_out=1.0):
        """τ_out for motor torque ``tau_in``; ``omega_out`` (sign) decides driving/back-driving."""
        tau_in = np.asarray(tau_in, dtype=np.float64)
        driving = tau_in * np.asarray(omega_out, dtype=np.float64) >= 0
        return (np.where(driving, self.ratio * self.efficiency * tau_in,
                         self.ratio * tau_in / self.efficiency))

    def reflected_inertia(self, rotor_inertia: float) -> float:
        """Rotor inertia seen at the output, I_m·N² (thesis Appendix A)."""
        return float(rotor_inertia) * self.ratio ** 2


def harmonic_drive(ratio: float = 100.0, efficiency: float = 1.0) -> Transmission:
    """Harmonic drive (§3.1: 100:1, 20 mm diameter, up to 2.4 N·m)."""
    return Transmission(ratio, efficiency, f"harmonic drive {ratio:g}:1")


def timing_belt(ratio: float, efficiency: float = 1.0) -> Transmission:
    """Timing belt stage (Appendix E: 2.083 motor→HD, 1.125 HD→bevel gears)."""
    return Transmission(ratio, efficiency, f"timing belt {ratio:g}:1")


#: proximal/distal drive: motor → belt 2.083 → HD 100 (Appendix E)
DLR_DISTAL = timing_belt(2.083).then(harmonic_drive(100.0))
#: base drives: motor → belt 2.083 → HD 100 → belt 1.125 → bevel gears (Appendix E, §3.1)
DLR_BASE = timing_belt(2.083).then(harmonic_drive(100.0)).then(timing_belt(1.125))
