"""The AMADEUS fingertip force sensor: six strain-gauge bridges on a two-prong beam skeleton
(``000_8f66dcc7ab06470c.txt`` §IV-A, Fig. 9, eqs 9–15).

For a force F = [f_x, f_y, f_z] (N) at the distal end of the fingertip, the bridge readings are

    R₁ = K₁ l f_z                                              (9)
    R₂ = K₂ l (1 + cos(φ₂ − φ₁)) f_z                           (10)
    R₃ = K₃ l (1 + cos φ₁ + cos φ₂) f_z                        (11)
    R₄ = K₄ l (cos φ₂ f_y − sin φ₂ f_x)                        (12)
    R₅ = K₅ l ((cos φ₁ + cos φ₂) f_y − sin φ₁ f_x)             (13)
    R₆ = K₆ l (1 + cos φ₁ + cos φ₂) f_y                        (14)

i.e. R = H f with the 6×3 sensitivity matrix H(K, φ₁, φ₂, l) of :func:`sensitivity_matrix`.
(Eqs 11 and 14 carry an unbalanced ")" in the extraction; the forms above are the only readings
consistent with eq 10's pattern.) K_j (V/(N·m)) lumps amplifier gain, beam stiffness, gauge
adhesion and the electrical conversion; l is the beam length; φ₁, φ₂ are the beam angles. Gauges
1–3 see only f_z and gauge 6 only f_y; gauges 4–5 mix f_y and f_x, so f_x is observable only
through them (it needs sin φ ≠ 0). Six readings, three unknowns: redundancy to exploit.

Noise (§IV-A, eq 19): "the magnitude of the noise variance is linearly related to the magnitude
of the measured signal", so each reading carries noise of standard deviation
√(σ²_Nj R_j² + σ₀_j²): a signal-proportional part with normalised variance σ²_Nj plus an electronics
floor σ₀_j (Fig. 16 shows noise with no load). The seed's K_j, φ, l and per-gauge noise are not
printed; the zoo values are assumed and labelled so, except the normalised variances, which are
Table I's (see :mod:`gripkit.systems.amadeus.parameters`).
"""

from __future__ import annotations

import math

import numpy as np

from ...consistency import Finding
from ...errors import DataError, ModelError
from ...params import Parameter, ParameterSet

__all__ = (["StrainGaugeSensor", "sensor_parameters", "sensitivity_matrix",
            "single_bridge_estimates"])

_SEED = "000_8f66dcc7ab06470c.txt"


def sensitivity_matrix(K, phi1: float, phi2: float, l: float) -> np.ndarray:
    """H (6, 3) of eqs 9–14: readings = H @ [f_x, f_y, f_z]."""
    K = np.asarray(K, dtype=np.float64).reshape(-1)
    if K.size != 6:
        raise ModelError(f"K: expected 6 calibration constants K1..K6, found {K.size}")
    c1, c2, s1, s2 = math.cos(phi1), math.cos(phi2), math.sin(phi1), math.sin(phi2)
    H = np.zeros((6, 3))
    H[0, 2] = K[0] * l
    H[1, 2] = K[1] * l * (1.0 + math.cos(phi2 - phi1))
    H[2, 2] = K[2] * l * (1.0 + c1 + c2)
    H[3, 0] = -K[3] * l * s2
    H[3, 1] = K[3] * l * c2
    H[4, 0] = -K[4] * l * s1
    H[4, 1] = K[4] * l * (c1 + c2)
    H[5, 1] = K[5] * l * (1.0 + c1 + c2)
    return H


def sensor_parameters(*, K=(12.0, 9.0, 6.0, 10.0, 8.0, 7.0), phi1: float = math.radians(25.0),
                      phi2: float = math.radians(40.0), beam_length: float = 0.010,
                      sigma_n2=(0.01309, 0.00459, 0.00301, 0.01309, 0.00459, 0.00301),
                      floor: float = 1.0e-3, k_std=None, phi_std=None,
                      source: str = "") -> ParameterSet:
    """The sensor's ParameterSet: K1..K6 (V/(N·m)), φ₁, φ₂ (rad), l (m), σ²_N1..6 (1), σ₀ (V)."""
    K = np.asarray(K, dtype=np.float64).reshape(-1)
    sn = np.asarray(sigma_n2, dtype=np.float64).reshape(-1)
    if K.size != 6 or sn.size != 6:
        raise ModelError(f"expected 6 values of K and of sigma_n2, found {K.size} and {sn.size}")
    src_k = source or "assumed: the seed prints no calibration constants"
    ks = [None] * 6 if k_std is None else [float(s) for s in k_std]
    ps = [None, None] if phi_std is None else [float(s) for s in phi_std]
    params = [Parameter(f"K{j + 1}", float(K[j]), "V/(N*m)", "calibration constant of "
                                                             f"bridge R{j + 1}",
                        bounds=(0.0, None), source=src_k, std=ks[j]) for j in range(6)]
    params += [
        Parameter("phi1", phi1, "rad", "beam angle φ₁ relative to "
                                       "the sensor base", bounds=(-math.pi, math.pi),
                  source=source or "assumed: Fig. 9(c) angles not given numerically", std=ps[0],
                  display_unit="deg"),
        Parameter("phi2", phi2, "rad", "beam angle φ₂ relative to "
                                       "the sensor base", bounds=(-math.pi, math.pi),
                  source=source or "assumed: Fig. 9(c) angles not given numerically", std=ps[1],
                  display_unit="deg"),
        Parameter("beam_length", beam_length, "m", "length l of each beam", bounds=(1e-5, 1.0),
                  source="assumed: fingertip scale (Fig. 9)", display_unit="mm"),
    ]
    for j in range(6):
        params.append(Parameter(f"sigma_n2_{j + 1}", float(sn[j]), "1",
                                "normalised noise variance of single-bridge estimate from "
                                f"R{j + 1} (eq 19)",
                                bounds=(0.0, None),
                                source=(f"{_SEED} Table I (ε_N{j % 3 + 1}, actual); mapping to "
                                        "bridges assumed")))
    params.append(Parameter("noise_floor", floor, "V", "electronics noise std of each "
                                                       "bridge at zero load",
                            bounds=(0.0, None), source="assumed: Fig. 16 shows "
                                                       "load-independent noise",
                            display_unit="mV"))
    return ParameterSet(params, "strain-gauge-sensor")


def single_bridge_estimates(readings, H) -> np.ndarray:
    """Force-component estimates from each bridge alone, (N, 6): R_j divided by its one
    sensitivity (bridges 1–3 → f_z, bridge 6 → f_y, bridges 4–5 → f_y assuming f_x = 0).
    These are the ε_i "strain gauge combinations" of §IV-A that :func:`gripkit.estimation.fuse`
    combines; for bridges 4–5 they are biased unless f_x = 0 (use the WLS estimator otherwise)."""
    R = np.atleast_2d(np.asarray(readings, dtype=np.float64))
    H = np.asarray(H, dtype=np.float64)
    sens = np.array([H[0, 2], H[1, 2], H[2, 2], H[3, 1], H[4, 1], H[5, 1]])
    return R / sens


class StrainGaugeSensor:
    """The six-bridge fingertip force sensor (eqs 9–14) with the eq-19 noise model.

    ``readings(f)`` gives noise-free bridge outputs (V) for forces (..., 3) N;
    ``simulate(f, rng)`` adds signal-proportional noise and the floor.
    """

    name = "strain-gauge-sensor"
    description = "AMADEUS fingertip force sensor, six strain-gauge bridges (eqs 9-14)"

    def __init__(self, parameters: ParameterSet | None = None, **kw):
        self.parameters = parameters if parameters is not None else sensor_parameters(**kw)
        H = self.H
        if np.linalg.matrix_rank(H, tol=1e-12 * np.abs(H).max()) < 3:
            raise ModelError("the sensor cannot observe all three force components",
                             hint="f_x needs sin φ₁ or sin φ₂ nonzero, and the (R4, R5) "
                                  "pair must not be "
                                  "degenerate")

    @property
    def K(self) -> np.ndarray:
        return np.array([self.parameters.value(f"K{j}") for j in range(1, 7)])

    @property
    def phi(self) -> tuple[float, float]:
        return self.parameters.value("phi1"), self.parameters.value("phi2")

    @property
    def beam_length(self) -> float:
        return self.parameters.value("beam_length")

    @property
    def sigma_n2(self) -> np.ndarray:
        return np.array([self.parameters.value(f"sigma_n2_{j}") for j in range(1, 7)])

    @property
    def noise_floor(self) -> float:
        return self.parameters.value("noise_floor")

    @property
    def H(self) -> np.ndarray:
        """The 6×3 sensitivity matrix (V/N)."""
        return sensitivity_matrix(self.K, *self.phi, self.beam_length)

    def readings(self, force) -> np.ndarray:
        """Noise-free bridge readings R₁..R₆ (V), shape (..., 6), for forces (..., 3) N (eqs
        9–14)."""
        f = np.asarray(force, dtype=np.float64)
        if f.shape[-1:] != (3,):
            raise DataError(f"force: expected shape (..., 3) for [f_x, f_y, f_z], found {f.shape}")
        if not np.isfinite(f).all():
            raise DataError("force contains NaN or inf")
        return f @ self.H.T

    def noise_variance(self, readings) -> np.ndarray:
        """Per-reading noise variance (V²): σ²_Nj R_j² + σ₀² (eq 19 plus the floor)."""
        R = np.asarray(readings, dtype=np.float64)
        return self.sigma_n2 * R * R + self.noise_floor ** 2

    def simulate(self, force, rng=None) -> np.ndarray:
        """Noisy readings (..., 6) V for forces (..., 3) N; ``rng`` a numpy Generator or seed."""
        rng = np.random.default_rng(rng)
        R = self.readings(force)
        return R + rng.standard_normal(R.shape) * np.sqrt(self.noise_variance(R))

    def magnitude(self, force) -> np.ndarray:
        """|F| (eq 15)."""
        f = np.asarray(force, dtype=np.float64)
        return np.sqrt((f * f).sum(-1))

    def consistency_checks(self) -> list[Finding]:
        return []
