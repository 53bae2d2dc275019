"""BLDC motor characterisation from test-bed logs by least squares (``002_ddea254371185ad3.txt``
chapter 5).

The thesis measures the motor on a test bed (torque sensor, hysteresis brake) in two experiments
and fits two lines:

1. **stall sweep** (§5.4.1): the brake holds the shaft (n = 0), the PWM steps through 0…4000;
   torque ∝ PWM gives eq 5.7, τ = c·PWM (a line through the origin);
2. **torque-speed runs** (§5.4.2): at PWM 2000, 2500, 3000, 3500 (and 4000) the speed is varied;
   each run gives a slope b(PWM) of torque over speed (printed in §5.4.2), and a line through those
   slopes gives eq 5.8, b(PWM) = b₁·PWM + b₀.

:func:`characterize_motor` reproduces that two-stage procedure with standard deviations (the
slope of each run from its own residual scatter; eq 5.8 by weighted least squares on the slopes).
:func:`fit_motor` fits eq 5.10 to all samples at once, τ = c·u + (b₁|u| + b₀)·ω, which is linear
in (c, b₁, b₀); with a winding temperature column it also fits the resistance coefficient of
eq 5.5 by nonlinear least squares, τ = (c·u + (b₁|u| + b₀)·ω)/(1 + α′(T − T_ref)) with
α′ = α/(1 + α(T_ref − T_amb)).

Units: PWM counts, speed in rad/s at the motor shaft, torque in N·m (SI). Results also give the
thesis's units (Ncm per count, Ncm/rpm) through :meth:`MotorFit.thesis_units`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ...errors import DataError, UnidentifiableError
from ...models.bldc import NCM, RPM
from ..scaling import unit_scale

__all__ = ["MotorFit", "fit_motor", "MotorCharacterization", "characterize_motor"]


def _check(name, a, n=None):
    a = np.asarray(a, dtype=np.float64)
    if a.ndim != 1:
        raise DataError(f"{name}: expected a 1-D array of samples, found shape {a.shape}")
    if n is not None and a.size != n:
        raise DataError(f"{name}: expected {n} samples (like pwm), found {a.size}")
    bad = ~np.isfinite(a)
    if bad.any():
        raise DataError(f"{name} has {int(bad.sum())} non-finite values (first at sample "
                        f"{int(np.argmax(bad))})")
    return a


def _lstsq(X, y, names):
    """LS with covariance σ̂²(XᵀX)⁻¹; raises when X is rank deficient."""
    sc = np.sqrt(np.mean(X ** 2, axis=0))
    if (sc == 0).any():
        raise UnidentifiableError("the data do not excite "
                                  f"{', '.join(n for n, s in zip(names, sc) if s == 0)}")
    sv = np.linalg.svd(X / sc, compute_uv=False)
    cond = float(sv[0] / max(sv[-1], 1e-300))
    if cond > 1e10:
        raise UnidentifiableError(f"the regressors of {', '.join(names)} are collinear "
                                  f"(condition {cond:.3g})",
                                  hint="vary PWM and speed independently")
    theta, *_ = np.linalg.lstsq(X, y, rcond=None)
    r = y - X @ theta
    dof = max(y.size - X.shape[1], 1)
    s2 = float(r @ r / dof)
    cov = s2 * np.linalg.inv(X.T @ X)
    return theta, cov, r


@dataclass(frozen=True)
class MotorFit:
    """Least-squares motor model: ``values``/``std`` (SI): ``c_pwm`` (N·m per count), ``b_pwm``
    (N·m·s/rad per count), ``b_0`` (N·m·s/rad) and, with temperatures, ``alpha_ref`` (1/K, at
    ``T_ref``) and ``alpha_R`` (1/K at T_amb, eq 5.5)."""

    values: dict
    std: dict
    covariance: np.ndarray
    names: tuple
    rms: float
    n: int

    def thesis_units(self) -> dict:
        """c in Ncm/PWM, b₁ in Ncm/(rpm·PWM), b₀ in Ncm/rpm (eqs 5.7, 5.8) with their std."""
        f = {"c_pwm": 1 / NCM, "b_pwm": RPM / NCM, "b_0": RPM / NCM}
        return {k: (self.values[k] * f[k], self.std[k] * f[k]) for k in f}


def fit_motor(pwm, speed, torque, temperature=None, *, T_ref: float | None = None,
              T_amb: float | None = None) -> MotorFit:
    """Fit eq 5.10 (and eq 5.5 when ``temperature`` in K is given) to test-bed samples.

    Samples with zero PWM are dropped (eq 5.10's guard makes them zero whatever the speed), as are
    samples in the guard region (zero torque at non-zero PWM).
    """
    from scipy.optimize import least_squares

    u = _check("pwm", pwm)
    w = _check("speed", speed, u.size)
    tau = _check("torque", torque, u.size)
    keep = (u != 0) & ~((tau == 0) & (w != 0))
    if temperature is not None:
        T = _check("temperature", temperature, u.size)[keep]
    u, w, tau = u[keep], w[keep], tau[keep]
    if u.size < 6:
        raise DataError(f"only {u.size} usable samples (non-zero PWM); a motor fit "
                        "needs at least 6")
    X = np.column_stack([u, np.abs(u) * w, w])
    names = ("c_pwm", "b_pwm", "b_0")
    theta, cov, r = _lstsq(X, tau, names)
    if temperature is None:
        std = np.sqrt(np.diag(cov))
        return MotorFit(dict(zip(names, map(float, theta))), dict(zip(names, map(float, std))), cov,
                        names, float(np.sqrt(np.mean(r ** 2))), int(u.size))
    if np.ptp(T) == 0:
        raise UnidentifiableError("the temperature never changes: α cannot be identified",
                                  hint="drop the temperature column or log a heating run")
    T_ref = float(np.mean(T)) if T_ref is None else float(T_ref)
    # a scale-free problem: z = θ/scale with each coefficient's size (its value or its σ, in the
    # data's units) and α′ in 1/K, the torque residual times the power of two ct that brings the
    # torque to unit size (exact); scipy's absolute gtol on Jᵀr otherwise ended fits to torques
    # of ~0.3 mN·m at the start α′ = 0
    scale = np.r_[np.abs(theta) + np.sqrt(np.diag(cov)) + 1e-300, 1e-3]
    ct = unit_scale(tau)

    def res(z):
        c, b1, b0, ap = z * scale
        return ((c * u + (b1 * np.abs(u) + b0) * w) / (1.0 + ap * (T - T_ref)) - tau) * ct

    sol = least_squares(res, np.r_[theta, 0.0] / scale, x_scale="jac")
    sol.fun, sol.jac = sol.fun / ct, sol.jac / ct
    J = sol.jac / scale
    dof = max(u.size - 4, 1)
    s2 = float(sol.fun @ sol.fun / dof)
    sv = np.linalg.svd(J, compute_uv=False)
    if sv[-1] < 1e-12 * sv[0]:
        raise UnidentifiableError("temperature and speed effects cannot be told "
                                  "apart in these data")
    cov = s2 * np.linalg.inv(J.T @ J)
    est = sol.x * scale
    names4 = ("c_pwm", "b_pwm", "b_0", "alpha_ref")
    values = dict(zip(names4, map(float, est)))
    std = dict(zip(names4, map(float, np.sqrt(np.diag(cov)))))
    if T_amb is not None:
        ap = values["alpha_ref"]
        d = 1.0 - ap * (T_ref - float(T_amb))
        if d <= 0:
            raise UnidentifiableError("the fitted α′ implies a non-positive resistance at T_amb")
        values["alpha_R"] = ap / d
        std["alpha_R"] = std["alpha_ref"] / d ** 2
    values["T_ref"] = T_ref
    std["T_ref"] = 0.0
    return MotorFit(values, std, cov, names4, float(np.sqrt(np.mean(sol.fun ** 2))), int(u.size))


@dataclass(frozen=True)
class MotorCharacterization:
    """The thesis's two-stage characterisation (§5.4): eq 5.7 (``c``), the slope of each
    torque-speed run (``slopes``: rows of PWM, slope, std, intercept) and eq 5.8 (``b1``, ``b0``)
    — all in SI (N·m per count, N·m·s/rad)."""

    c: float
    c_std: float
    slopes: tuple
    b1: float
    b1_std: float
    b0: float
    b0_std: float
    covariance_58: np.ndarray

    def table(self) -> list[list]:
        """Slopes in the thesis's units (Ncm/rpm) for reports."""
        k = RPM / NCM
        return [[pwm, b * k, s * k] for pwm, b, s, _ in self.slopes]


def characterize_motor(stall_pwm, stall_torque, runs: Sequence[tuple]) -> MotorCharacterization:
    """Two-stage LS of §5.4.

    Parameters
    ----------
    stall_pwm, stall_torque
        The stall sweep (n = 0): PWM counts and torques (N·m).
    runs
        One ``(pwm, speed, torque)`` per torque-speed run at constant PWM: speed (rad/s) and torque
        (N·m) arrays of that run.
    """
    u = _check("stall_pwm", stall_pwm)
    t = _check("stall_torque", stall_torque, u.size)
    if np.count_nonzero(u) < 2:
        raise DataError("the stall sweep needs at least two non-zero PWM values")
    (c,), cov, _ = _lstsq(u[:, None], t, ("c_pwm",))
    c_std = float(math.sqrt(cov[0, 0]))
    if len(runs) < 3:
        raise DataError("eq 5.8 needs torque-speed runs at three or more PWM values, "
                        f"found {len(runs)}")
    rows = []
    for i, run in enumerate(runs):
        try:
            pwm, w, tau = run
        except (TypeError, ValueError):
            raise DataError(f"runs[{i}]: expected (pwm, speed, torque)") from None
        w = _check(f"runs[{i}] speed", w)
        tau = _check(f"runs[{i}] torque", tau, w.size)
        if w.size < 3 or np.ptp(w) == 0:
            raise DataError(f"runs[{i}] (PWM {pwm}): the speed must vary over at least 3 samples")
        (a, b), cv, _ = _lstsq(np.column_stack([np.ones_like(w), w]), tau, ("intercept", "slope"))
        rows.append((float(pwm), float(b), float(math.sqrt(cv[1, 1])), float(a)))
    P = np.array([r[0] for r in rows])
    B = np.array([r[1] for r in rows])
    S = np.array([r[2] for r in rows])
    if np.ptp(P) == 0:
        raise UnidentifiableError("all torque-speed runs have the same PWM: eq 5.8's PWM term "
                                  "is undetermined")
    Wt = 1.0 / np.maximum(S, 1e-300) ** 2
    X = np.column_stack([P, np.ones_like(P)])
    A = X.T @ (Wt[:, None] * X)
    theta = np.linalg.solve(A, X.T @ (Wt * B))
    r = B - X @ theta
    chi2 = float(np.sum(Wt * r ** 2) / max(P.size - 2, 1))
    cov58 = np.linalg.inv(A) * max(chi2, 1.0)
    return MotorCharacterization(float(c), c_std, tuple(rows), float(theta[0]),
                                 float(math.sqrt(cov58[0, 0])), float(theta[1]),
                                 float(math.sqrt(cov58[1, 1])), cov58)
