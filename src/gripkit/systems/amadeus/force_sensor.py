"""Fingertip force from six strain-gauge bridges: calibration, weighted least squares, and a
Kalman filter for use inside a control loop (``000_8f66dcc7ab06470c.txt`` §IV-A, eqs 9–19).

* :func:`calibrate` — K₁..K₆ (and φ₁, φ₂, bridge offsets) from readings under known loads, by
  weighted nonlinear least squares on eqs 9–14, with the eq-19 noise model (σ² = σ²_N R² + σ₀²)
  estimated from the residuals; covariance and standard errors of every constant; a cross-talk
  test of the equations' structural zeros.
* :func:`estimate_force` — f = [f_x, f_y, f_z] at every sample by weighted least squares
  f̂ = (Hᵀ W H)⁻¹ Hᵀ W R with W = diag(1/σ_j²), covariance (Hᵀ W H)⁻¹ and a χ² test of the six
  readings' agreement. This is the multi-variable form of the fusion of eqs 16–18: for one force
  component seen by several bridges alone it *is* :func:`gripkit.estimation.fuse` (tested).
  The weights follow eq 19; the first pass uses the measured readings (as the seed does), later
  passes the predicted ones, which removes the small bias of weighting with noisy signals.
* :class:`ForceKalmanFilter` — the "dynamic" estimator the seed leaves as future work (§IV-A, last
  paragraph): a linear force-dynamics model (random walk per axis, or the identified finger-force
  model driven by the valve command plus a random-walk disturbance) and the six readings as
  measurements with eq-19 noise evaluated at the predicted readings. Independent measurement
  noise lets the update process the six readings one at a time (exactly equivalent to the joint
  update, tested), in an allocation-free numba kernel; ``step()`` runs the same kernel one sample
  at a time inside a control loop.
"""

from __future__ import annotations

import math
from collections import namedtuple
from dataclasses import dataclass

import numba
import numpy as np

from ...control.rst import as_plant
from ...errors import (AccuracyWarning, DataError, IdentificationError, ModelError,
                       UnidentifiableError, emit_warning)
from ...lti import affine_row, flush_tiny
from .strain_gauge_sensor import StrainGaugeSensor, sensitivity_matrix, sensor_parameters

__all__ = [
    "calibrate",
    "SensorCalibration",
    "estimate_force",
    "ForceEstimate",
    "ForceDynamics",
    "ForceKalmanFilter",
    "KalmanResult",
]

# structural zeros of H (eqs 9-14): (bridge, component) pairs that must not respond
_STRUCT_ZERO = (np.array([[1, 1, 0], [1, 1, 0], [1, 1, 0], [0, 0, 1], [0, 0, 1], [1, 0, 1]],
                         dtype=bool))


# ----------------------------------------------------------------------------------- calibration
@dataclass(frozen=True)
class SensorCalibration:
    """Result of :func:`calibrate`.

    Attributes
    ----------
    sensor
        A :class:`StrainGaugeSensor` carrying the calibrated constants (with ``std``) and noise
        model.
    K, K_std
        (6,) calibration constants K₁..K₆ (V/(N·m)) and standard errors.
    phi, phi_std
        (φ₁, φ₂) beam angles (rad) and standard errors (0 when given, not estimated).
    offsets, offsets_std
        (6,) zero offsets of the bridges (V) (zeros when ``offsets=False``).
    names, covariance
        Names and covariance of the estimated parameters.
    sigma_n2, sigma_n2_std
        (6,) normalised noise variances σ²_Nj of eq 19 estimated from the residuals.
    floor
        (6,) absolute noise std σ₀_j (V) at zero load.
    chi2_dof
        Weighted residual sum of squares per degree of freedom (≈ 1 when the noise model fits).
    cross_talk_z
        (6, 3) z-scores of the sensitivities eqs 9–14 say are zero (free per-bridge fit); |z| > 5
        means a bridge responds where the equations say it must not.
    n
        Number of load cases.
    """

    sensor: StrainGaugeSensor
    K: np.ndarray
    K_std: np.ndarray
    phi: tuple[float, float]
    phi_std: tuple[float, float]
    offsets: np.ndarray
    offsets_std: np.ndarray
    names: tuple[str, ...]
    covariance: np.ndarray
    sigma_n2: np.ndarray
    sigma_n2_std: np.ndarray
    floor: np.ndarray
    chi2_dof: float
    cross_talk_z: np.ndarray
    n: int

    def table(self) -> list[list]:
        rows = [[f"K{j + 1}", self.K[j], self.K_std[j], "V/(N*m)"] for j in range(6)]
        rows += [["phi1", math.degrees(self.phi[0]), math.degrees(self.phi_std[0]), "deg"],
                 ["phi2", math.degrees(self.phi[1]), math.degrees(self.phi_std[1]), "deg"]]
        return rows


def _variance_model(pred: np.ndarray, resid: np.ndarray,
                    proportional: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Maximum-likelihood fit of σ_j² = a_j + b_j R̂² per bridge to residuals (Gaussian,
    heteroscedastic: minimise Σ log σ² + r²/σ² over log a, log b); returns (a (6,), b (6,),
    std of b (6,)) with the std from the Fisher information ½ Σ (∂σ²/∂θ)²/σ⁴."""
    from scipy.optimize import minimize

    n, m = resid.shape
    a = np.zeros(m)
    b = np.zeros(m)
    sb = np.zeros(m)
    for j in range(m):
        r2 = resid[:, j] ** 2
        if not proportional:
            a[j] = r2.mean()
            continue
        p2 = pred[:, j] ** 2
        small = p2 <= np.quantile(p2, 0.2)
        a0 = max(float(r2[small].mean()) if small.any() else float(r2.mean()), 1e-300)
        big = p2 > 0
        b0 = max(float(np.median(r2[big] / p2[big])) if big.any() else 1e-12, 1e-12)

        def nll(th):
            ea, eb = math.exp(th[0]), math.exp(th[1])
            v = ea + eb * p2
            q = r2 / v
            f = float(np.sum(np.log(v) + q))
            dv = (1.0 - q) / v
            return f, np.array([float(np.sum(dv) * ea), float(np.sum(dv * p2) * eb)])

        sol = minimize(nll, [math.log(a0), math.log(b0)], jac=True, method="L-BFGS-B",
                       bounds=[(math.log(a0) - 40, math.log(a0) + 40),
                               (math.log(b0) - 40, math.log(b0) + 40)])
        a[j], b[j] = math.exp(sol.x[0]), math.exp(sol.x[1])
        v = a[j] + b[j] * p2
        J = np.column_stack([np.ones(n), p2]) / v[:, None]
        try:
            cov = np.linalg.inv(0.5 * J.T @ J)
            sb[j] = math.sqrt(max(cov[1, 1], 0.0))
        except np.linalg.LinAlgError:
            sb[j] = math.inf
    return a, b, sb


def _calibration_data(loads, readings, beam_length, phi, offsets, noise):
    """Loads F (n, 3), readings R (n, 6) and the regressor Fc (with a column of ones for the
    offsets), checked: shapes, finite values, enough load cases, all axes excited."""
    F = np.asarray(loads, dtype=np.float64)
    R = np.asarray(readings, dtype=np.float64)
    if F.ndim != 2 or F.shape[1] != 3:
        raise DataError(f"loads: expected shape (n, 3) [f_x, f_y, f_z], found {F.shape}")
    if R.ndim != 2 or R.shape != (F.shape[0], 6):
        raise DataError(f"readings: expected shape ({F.shape[0]}, 6) to match the loads, "
                        f"found {R.shape}")
    if not (np.isfinite(F).all() and np.isfinite(R).all()):
        bad = ~(np.isfinite(F).all(1) & np.isfinite(R).all(1))
        raise DataError(f"calibration data have NaN or inf in {int(bad.sum())} rows (first row "
                        f"{int(np.argmax(bad))})",
                        hint="drop those load cases")
    if noise not in ("proportional", "constant"):
        raise DataError(f"noise: expected 'proportional' or 'constant', found {noise!r}")
    if not (np.isfinite(beam_length) and beam_length > 0):
        raise DataError(f"beam_length: expected a positive length in m, found {beam_length!r}")
    n = F.shape[0]
    n_par = 6 + (0 if phi is not None else 2) + (6 if offsets else 0)
    if 6 * n <= n_par + 12:
        raise DataError(f"calibration needs more load cases: {n} give {6 * n} readings for "
                        f"{n_par} constants "
                        "and the noise model", hint="apply at least 10 loads spanning x, y and z")
    Fc = np.column_stack([F, np.ones(n)]) if offsets else F
    sv = np.linalg.svd(Fc / np.maximum(np.abs(Fc).max(0), 1e-300), compute_uv=False)
    if sv[-1] < 1e-8 * sv[0]:
        raise UnidentifiableError("the loads do not excite all three force axes (and the offsets)",
                                  hint="apply loads along x, y and z (several levels each)")
    if phi is None and (np.ptp(F[:, 0]) == 0 or np.ptp(F[:, 1]) == 0):
        raise UnidentifiableError("φ₁, φ₂ need loads with varying x and y components",
                                  hint="add x and y loads, or pass phi=(φ1, φ2)")
    return F, R, Fc


def _free_rows(Fc, R, offsets, noise):
    """Step 1: free per-bridge rows by linear least squares, reweighted with the fitted noise model
    (three passes); the weights W (n, 6) and the cross-talk z-scores of the entries eqs 9-14 say
    are zero."""
    n = Fc.shape[0]
    rows = np.zeros((6, Fc.shape[1]))
    W = np.ones((n, 6))
    for _ in range(3):
        for j in range(6):
            sw = np.sqrt(W[:, j])
            rows[j] = np.linalg.lstsq(Fc * sw[:, None], R[:, j] * sw, rcond=None)[0]
        pred = Fc @ rows.T
        a, b, _ = (_variance_model(pred - (rows[:, 3] if offsets else 0.0), R - pred,
                                   noise == "proportional"))
        W = 1.0 / np.maximum(a + b * (pred - (rows[:, 3] if offsets else 0.0)) ** 2, 1e-30)
    cross = np.zeros((6, 3))
    for j in range(6):
        sw = np.sqrt(W[:, j])
        X = Fc * sw[:, None]
        res = (R[:, j] - Fc @ rows[j]) * sw
        dof = max(n - Fc.shape[1], 1)
        cov = np.linalg.inv(X.T @ X) * (res @ res) / dof
        se = np.sqrt(np.diag(cov))[:3]
        cross[j] = np.where(_STRUCT_ZERO[j], rows[j, :3] / np.maximum(se, 1e-300), 0.0)
    return rows, W, cross


def _start_values(rows, l, phi, offsets, initial_phi):
    """Closed-form start values from the free rows (module docstring of strain_gauge_sensor):
    φ₁, φ₂ (unless given), K_j, the offsets; and the parameter names in vector order."""
    h = rows[:, :3]
    if phi is None:
        p2 = math.atan2(-h[3, 0], h[3, 1])
        ax, by = -h[4, 0], h[4, 1]
        rho = math.hypot(ax, by)
        arg = ax * math.cos(p2) / rho if rho > 0 else 0.0
        p1 = math.atan2(ax, by) + math.asin(max(-1.0, min(1.0, arg)))
        if not (np.isfinite(p1) and np.isfinite(p2)):
            p1, p2 = initial_phi
    else:
        p1, p2 = float(phi[0]), float(phi[1])
    Hs = sensitivity_matrix(np.ones(6), p1, p2, l)
    sens = np.array([Hs[0, 2], Hs[1, 2], Hs[2, 2], Hs[3, 1], Hs[4, 1], Hs[5, 1]])
    hs = np.array([h[0, 2], h[1, 2], h[2, 2], h[3, 1], h[4, 1], h[5, 1]])
    K0 = np.abs(hs / sens)
    x0 = list(K0) + ([] if phi is not None else [p1, p2]) + (list(rows[:, 3]) if offsets else [])
    names = tuple([f"K{j}" for j in range(1, 7)] + ([] if phi is not None else ["phi1", "phi2"])
                  + ([f"offset{j}" for j in range(1, 7)] if offsets else []))
    return p1, p2, x0, names


def calibrate(loads, readings, *, beam_length: float, phi: tuple[float, float] | None = None,
              offsets: bool = True, noise: str = "proportional",
              initial_phi=(0.4, 0.7)) -> SensorCalibration:
    """Calibrate the six-bridge sensor from readings under known loads (eqs 9–14, 19).

    Parameters
    ----------
    loads
        (n, 3) applied forces [f_x, f_y, f_z] (N). Must load all three axes; φ₁, φ₂ need loads
        with both x and y components.
    readings
        (n, 6) bridge readings R₁..R₆ (V).
    beam_length
        l (m); only the products K_j l are identifiable, so l must be given.
    phi
        (φ₁, φ₂) in rad if known; ``None`` estimates them (from bridges 4 and 5).
    offsets
        Estimate a zero offset per bridge (recommended: real bridges are never balanced).
    noise
        ``'proportional'`` (eq 19 plus a floor, fitted to the residuals) or ``'constant'``.
    """
    from scipy.optimize import least_squares

    F, R, Fc = _calibration_data(loads, readings, beam_length, phi, offsets, noise)
    n = F.shape[0]
    rows, W, cross = _free_rows(Fc, R, offsets, noise)
    l = float(beam_length)
    p1, p2, x0, names = _start_values(rows, l, phi, offsets, initial_phi)

    def unpack(x):
        K = x[:6]
        if phi is None:
            q1, q2 = x[6], x[7]
            off = x[8:14] if offsets else np.zeros(6)
        else:
            q1, q2 = p1, p2
            off = x[6:12] if offsets else np.zeros(6)
        return K, q1, q2, off

    def model(x):
        K, q1, q2, off = unpack(x)
        return F @ sensitivity_matrix(K, q1, q2, l).T + off

    sig = np.sqrt(1.0 / W)
    for _ in range(2):
        sol = least_squares(lambda x: ((model(x) - R) / sig).ravel(),
                            np.asarray(x0, dtype=np.float64),
                            method="lm", x_scale="jac")
        x0 = sol.x
        K, q1, q2, off = unpack(sol.x)
        clean = model(sol.x) - off
        a, b, sb = _variance_model(clean, R - model(sol.x), noise == "proportional")
        sig = np.sqrt(np.maximum(a + b * clean ** 2, 1e-30))
    sol = least_squares(lambda x: ((model(x) - R) / sig).ravel(), x0, method="lm", x_scale="jac")
    if not sol.success:
        raise IdentificationError(f"sensor calibration did not converge: {sol.message}")
    J = sol.jac
    dof = max(6 * n - len(names), 1)
    chi2 = float(sol.fun @ sol.fun) / dof
    try:
        jtj_inv = np.linalg.inv(J.T @ J)
    except np.linalg.LinAlgError:
        raise UnidentifiableError("the calibration Jacobian is singular: the loads "
                                  "do not determine "
                                  f"all of {', '.join(names)}") from None
    cov = jtj_inv * max(chi2, 1.0) if noise == "constant" else jtj_inv * chi2
    std = np.sqrt(np.diag(cov))
    K, q1, q2, off = unpack(sol.x)
    if (K <= 0).any():
        raise IdentificationError("calibration gave non-positive constants K = "
                                  f"{np.round(K, 6).tolist()}",
                                  hint="check the sign convention of the readings and of the loads")
    K_std = std[:6]
    if phi is None:
        phi_std = (float(std[6]), float(std[7]))
        off_std = std[8:14] if offsets else np.zeros(6)
    else:
        phi_std = (0.0, 0.0)
        off_std = std[6:12] if offsets else np.zeros(6)
    if np.abs(cross).max() > 5.0:
        j, c = np.unravel_index(np.argmax(np.abs(cross)), cross.shape)
        emit_warning(f"bridge R{j + 1} responds to f_{'xyz'[c]} (z = {cross[j, c]:.1f}), which "
                     "eqs 9-14 say it "
                     "must not: cross-talk or a mislabelled axis", AccuracyWarning)
    floor = np.sqrt(a)
    q1n = (q1 + math.pi) % (2 * math.pi) - math.pi
    q2n = (q2 + math.pi) % (2 * math.pi) - math.pi
    params = sensor_parameters(K=K, phi1=q1n, phi2=q2n, beam_length=l, sigma_n2=b,
                               floor=float(np.sqrt(np.mean(a))), k_std=K_std, phi_std=phi_std,
                               source=f"calibrated from {n} known loads "
                                      "(gripkit.systems.amadeus.force_sensor.calibrate)")
    return SensorCalibration(StrainGaugeSensor(params), K, K_std, (q1n, q2n), phi_std,
                             off, off_std, names, cov, b, sb, floor, chi2, cross, n)


# ----------------------------------------------------------------------------------- WLS
@dataclass(frozen=True)
class ForceEstimate:
    """Per-sample force estimates.

    Attributes
    ----------
    force
        (N, 3) [f_x, f_y, f_z] (N).
    covariance
        (N, 3, 3) (N²).
    std
        (N, 3) one-sigma uncertainties.
    magnitude, magnitude_std
        (N,) |F| (eq 15) and its delta-method std.
    chi2
        (N,) weighted residual Σ (R_j − (H f̂)_j)²/σ_j²; χ² with 3 degrees of freedom when the
        readings agree with eqs 9–14 and the noise model (large: a faulty or saturated bridge).
    """

    force: np.ndarray
    covariance: np.ndarray
    std: np.ndarray
    magnitude: np.ndarray
    magnitude_std: np.ndarray
    chi2: np.ndarray
    dof: int = 3


def _sensor_arrays(sensor: StrainGaugeSensor,
                   offsets) -> tuple[np.ndarray, np.ndarray, float, np.ndarray]:
    if not isinstance(sensor, StrainGaugeSensor):
        raise ModelError("sensor: expected a StrainGaugeSensor (or a SensorCalibration), found "
                         f"{type(sensor).__name__}")
    off = np.zeros(6) if offsets is None else np.asarray(offsets, dtype=np.float64).reshape(6)
    return sensor.H, sensor.sigma_n2, sensor.noise_floor, off


def estimate_force(readings, sensor, *, variances=None, iterations: int = 2,
                   offsets=None) -> ForceEstimate:
    """Weighted-least-squares force from six bridge readings at every sample.

    Parameters
    ----------
    readings
        (N, 6) or (6,) bridge readings (V).
    sensor
        A :class:`StrainGaugeSensor` or a :class:`SensorCalibration` (its offsets are then removed).
    variances
        Optional (N, 6) or (6,) known noise variances (V²); default: eq 19 with the sensor's
        σ²_N and floor.
    iterations
        Eq-19 weighting passes: the first uses the measured readings, later ones the predicted.
    offsets
        (6,) bridge zero offsets (V) to subtract (taken from a SensorCalibration by default).
    """
    if isinstance(sensor, SensorCalibration):
        offsets = sensor.offsets if offsets is None else offsets
        sensor = sensor.sensor
    H, sn2, floor, off = _sensor_arrays(sensor, offsets)
    R = np.atleast_2d(np.asarray(readings, dtype=np.float64))
    if R.shape[-1] != 6 or R.ndim != 2:
        raise DataError(f"readings: expected shape (N, 6) for R1..R6, found {np.shape(readings)}")
    if not np.isfinite(R).all():
        bad = ~np.isfinite(R).all(1)
        raise DataError(f"readings have NaN or inf in {int(bad.sum())} samples (first at sample "
                        f"{int(np.argmax(bad))})",
                        hint="drop or interpolate those samples")
    R = R - off
    if int(iterations) != iterations or iterations < 1:
        raise DataError(f"iterations: expected a positive integer, found {iterations!r}")
    if variances is not None:
        V = np.broadcast_to(np.asarray(variances, dtype=np.float64), R.shape)
        if (V <= 0).any() or not np.isfinite(V).all():
            raise DataError("variances must be positive and finite")
        passes = [V]
    else:
        passes = None
    if passes is None and floor == 0 and (R == 0).any():
        raise DataError("a reading is exactly zero and the sensor has no noise floor: eq "
                        "19 gives it zero "
                        "variance (infinite weight)", hint="give the sensor a noise_floor > 0")
    ref = R
    for it in range(1 if passes else int(iterations)):
        V = passes[0] if passes else sn2 * ref * ref + floor * floor
        W = 1.0 / V
        M = np.einsum("jk,nj,jl->nkl", H, W, H)
        rhs = np.einsum("jk,nj->nk", H, W * R)
        try:
            f = np.linalg.solve(M, rhs[..., None])[..., 0]
        except np.linalg.LinAlgError:
            raise DataError("the weighted normal equations are singular (all readings "
                            "of an axis have "
                            "infinite variance)") from None
        ref = f @ H.T
    cov = np.linalg.inv(M)
    resid = R - f @ H.T
    chi2 = (resid * resid * W).sum(1)
    mag = np.sqrt((f * f).sum(1))
    g = f / np.where(mag > 0, mag, 1.0)[:, None]
    mag_var = np.einsum("nk,nkl,nl->n", g, cov, g)
    mag_var = np.where(mag > 0, mag_var, np.trace(cov, axis1=1, axis2=2))
    return ForceEstimate(f, cov, np.sqrt(np.einsum("nkk->nk", cov)), mag, np.sqrt(mag_var), chi2)


# ----------------------------------------------------------------------------------- Kalman filter
@dataclass(frozen=True)
class ForceDynamics:
    """Linear force dynamics x⁺ = A x + B u + w (cov Q), f = C x, at step ``dt``.

    ``C`` (3, n) maps the state to [f_x, f_y, f_z]. Build with :meth:`random_walk` or
    :meth:`from_plant`.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    Q: np.ndarray
    dt: float
    description: str = ""
    state_names: tuple[str, ...] = ()

    def __post_init__(self):
        A = np.ascontiguousarray(self.A, dtype=np.float64)
        n = A.shape[0]
        B = np.ascontiguousarray(np.asarray(self.B, dtype=np.float64).reshape(n, -1))
        C = np.ascontiguousarray(self.C, dtype=np.float64)
        Q = np.ascontiguousarray(self.Q, dtype=np.float64)
        if A.shape != (n, n) or C.shape != (3, n) or Q.shape != (n, n):
            raise ModelError(f"ForceDynamics: need A (n, n), C (3, n), Q (n, n); found {A.shape}, "
                             f"{C.shape}, {Q.shape}")
        if not (np.isfinite(A).all() and np.isfinite(B).all() and np.isfinite(C).all()
                and np.isfinite(Q).all()):
            raise ModelError("ForceDynamics matrices contain NaN or inf")
        if np.linalg.eigvalsh(0.5 * (Q + Q.T)).min() < -1e-12 * max(1.0, np.abs(Q).max()):
            raise ModelError("ForceDynamics: Q must be positive semi-definite")
        for k, v in (("A", A), ("B", B), ("C", C), ("Q", Q)):
            object.__setattr__(self, k, v)

    @property
    def n_states(self) -> int:
        return self.A.shape[0]

    @property
    def n_inputs(self) -> int:
        return self.B.shape[1]

    @classmethod
    def random_walk(cls, q, dt: float) -> "ForceDynamics":
        """Each force component a random walk with intensity ``q`` (N²/s; scalar or 3 values)."""
        qv = np.broadcast_to(np.asarray(q, dtype=np.float64), (3,))
        if (qv < 0).any() or not (dt > 0):
            raise ModelError(f"random_walk: need q >= 0 and dt > 0, found q={q}, dt={dt}")
        return cls(np.eye(3), np.zeros((3, 1)), np.eye(3), np.diag(qv * dt), dt,
                   f"random walk, q = {qv.tolist()} N²/s", ("f_x", "f_y", "f_z"))

    @classmethod
    def from_plant(cls, plant, *, axis: int = 2, q_disturbance: float = 1.0, q_other: float = 1.0,
                   force_offset: float = 0.0) -> "ForceDynamics":
        """The identified finger-force model on one axis (driven by the valve command u), plus a
        random-walk disturbance force on that axis (intensity ``q_disturbance`` N²/s, it absorbs
        model error, contact changes and offsets) and random walks (``q_other``) on the others.

        ``plant`` is anything :func:`gripkit.control.as_plant` accepts; its output
        must be in N and its input is what ``u`` will hold (deviation from the operating point)."""
        p = as_plant(plant)
        ss = p.to_ss(minimal=False, form="controllable")
        npl = ss.n_states
        n = npl + 3
        A = np.zeros((n, n))
        A[:npl, :npl] = ss.A
        A[npl:, npl:] = np.eye(3)
        B = np.zeros((n, 1))
        B[:npl, 0] = ss.B[:, 0]
        others = [k for k in range(3) if k != axis]
        C = np.zeros((3, n))
        C[axis, :npl] = ss.C[0]
        C[axis, npl] = 1.0
        C[others[0], npl + 1] = 1.0
        C[others[1], npl + 2] = 1.0
        Q = np.zeros((n, n))
        Q[npl, npl] = q_disturbance * p.dt
        Q[npl + 1, npl + 1] = q_other * p.dt
        Q[npl + 2, npl + 2] = q_other * p.dt
        names = (tuple(f"plant{i}" for i in range(npl)) + (f"d_{'xyz'[axis]}",)
                 + tuple(f"f_{'xyz'[k]}" for k in others))
        return cls(A, B, C, Q, p.dt, f"identified plant on {'xyz'[axis]} + "
                                     "random-walk disturbance", names)


#: the filter's model as :func:`_kf_run` takes it: dynamics A, B, force map C and process noise
#: Q of :class:`ForceDynamics`, the readings' map HC (6, n), the relative noise variances sn2 (6)
#: and the noise floor² (V²)
KalmanArrays = namedtuple("KalmanArrays", "A B C Q HC sn2 floor2")
#: what :func:`_kf_run` writes per sample: forces (N, 3), their covariances (N, 3, 3), NIS (N,)
KalmanOut = namedtuple("KalmanOut", "force cov nis")
#: its scratch: (n, n+1) matrix, two n-vectors
KalmanWork = namedtuple("KalmanWork", "tmp ph kg")


@numba.njit(cache=True)
def _kf_run(model, Z, U, x, P, out, work):  # pragma: no cover - compiled
    """Kalman filter over N samples of readings Z (N, 6) and inputs U; x (n,) and P (n, n) hold
    the prior at entry, the next prior at exit. ``model`` is :data:`KalmanArrays`, ``out``
    :data:`KalmanOut`, ``work`` :data:`KalmanWork`.

    Per sample: sequential scalar updates with R_j = sn2_j r̂_j² + floor2 (r̂ from the prior),
    outputs f = C x⁺ and C P⁺ Cᵀ, then the time update with input U[k]."""
    A, B, C, Q, HC, sn2, floor2 = model
    fout, cout, nis = out
    tmp, ph, kg = work
    n = A.shape[0]
    N = Z.shape[0]
    for k in range(N):
        s_nis = 0.0
        # measurement noise from the prior prediction (computed before the updates)
        for j in range(6):
            r = 0.0
            for i in range(n):
                r += HC[j, i] * x[i]
            tmp[j, 0] = sn2[j] * r * r + floor2
        for j in range(6):
            pred = 0.0
            for i in range(n):
                pred += HC[j, i] * x[i]
            for i in range(n):
                acc = 0.0
                for l in range(n):
                    acc += P[i, l] * HC[j, l]
                ph[i] = acc
            s = tmp[j, 0]
            for i in range(n):
                s += HC[j, i] * ph[i]
            nu = Z[k, j] - pred
            s_nis += nu * nu / s
            for i in range(n):
                kg[i] = ph[i] / s
                x[i] += kg[i] * nu
            for i in range(n):
                for l in range(n):
                    P[i, l] -= kg[i] * ph[l]
            for i in range(n):  # keep P symmetric
                for l in range(i + 1, n):
                    v = 0.5 * (P[i, l] + P[l, i])
                    P[i, l] = v
                    P[l, i] = v
        nis[k] = s_nis
        for a in range(3):
            acc = 0.0
            for i in range(n):
                acc += C[a, i] * x[i]
            fout[k, a] = acc
            for b in range(3):
                acc = 0.0
                for i in range(n):
                    ci = C[a, i]
                    if ci != 0.0:
                        for l in range(n):
                            acc += ci * P[i, l] * C[b, l]
                cout[k, a, b] = acc
        # time update: x = A x + B u ; P = A P A' + Q   (tmp rows 0..n-1 as scratch, n <= tmp rows)
        for i in range(n):
            ph[i] = affine_row(A, i, x, B, U, k)
        for i in range(n):  # entries below 1e-280 carried as zero: never subnormal (flush_tiny)
            x[i] = flush_tiny(ph[i])
        for i in range(n):
            for l in range(n):
                acc = 0.0
                for r2 in range(n):
                    acc += A[i, r2] * P[r2, l]
                tmp[i, l + 1] = acc
        for i in range(n):
            for l in range(n):
                acc = Q[i, l]
                for r2 in range(n):
                    acc += tmp[i, r2 + 1] * A[l, r2]
                P[i, l] = flush_tiny(acc)


@dataclass(frozen=True)
class KalmanResult:
    """Filtered forces: ``force`` (N, 3), ``covariance`` (N, 3, 3), ``std`` (N, 3), and ``nis``
    (N,): the normalised innovation squared (χ² with 6 degrees of freedom when the filter's noise
    model is right — its mean is the filter's honesty check)."""

    force: np.ndarray
    covariance: np.ndarray
    std: np.ndarray
    nis: np.ndarray


class ForceKalmanFilter:
    """Kalman filter for the fingertip force: dynamics :class:`ForceDynamics`, measurements the six
    bridge readings with eq-19 noise (σ²_Nj r̂_j² + σ₀²) at the predicted readings r̂ = H C x̂⁻.

    Parameters
    ----------
    sensor
        :class:`StrainGaugeSensor` or :class:`SensorCalibration` (its offsets are removed).
    dynamics
        :class:`ForceDynamics` (default: random walk with q = 10 N²/s at ``dt``).
    dt
        Sample time (s) when ``dynamics`` is not given.
    x0, P0
        Initial state and covariance (default: zero force, 100 N² per state).
    """

    def __init__(self, sensor, dynamics: ForceDynamics | None = None, *, dt: float | None = None,
                 x0=None, P0=None, offsets=None):
        if isinstance(sensor, SensorCalibration):
            offsets = sensor.offsets if offsets is None else offsets
            sensor = sensor.sensor
        H, sn2, floor, off = _sensor_arrays(sensor, offsets)
        if dynamics is None:
            if dt is None:
                raise ModelError("give dynamics= or the sample time dt= for the "
                                 "default random walk")
            dynamics = ForceDynamics.random_walk(10.0, dt)
        self.sensor = sensor
        self.dynamics = dynamics
        self.offsets = off
        self._HC = np.ascontiguousarray(H @ dynamics.C)
        self._sn2 = np.ascontiguousarray(sn2)
        self._floor2 = float(floor) ** 2
        if self._floor2 == 0.0:
            raise ModelError("the Kalman filter needs a sensor noise floor > 0 (eq 19 "
                             "alone gives zero "
                             "variance at zero force)")
        n = dynamics.n_states
        self.x = np.zeros(n) if x0 is None else np.array(x0, dtype=np.float64).reshape(n)
        self.P = np.eye(n) * 100.0 if P0 is None else np.array(P0, dtype=np.float64).reshape(n, n)
        self._tmp = np.zeros((max(n, 6), n + 1))
        self._ph = np.zeros(n)
        self._kg = np.zeros(n)

    def reset(self, x0=None, P0=None):
        n = self.dynamics.n_states
        self.x = np.zeros(n) if x0 is None else np.array(x0, dtype=np.float64).reshape(n)
        self.P = np.eye(n) * 100.0 if P0 is None else np.array(P0, dtype=np.float64).reshape(n, n)

    def _inputs(self, u, N):
        m = self.dynamics.n_inputs
        if u is None:
            return np.zeros((N, m))
        U = np.asarray(u, dtype=np.float64).reshape(N, -1)
        if U.shape[1] != m or not np.isfinite(U).all():
            raise DataError(f"u: expected {N} finite samples of {m} input(s), found "
                            f"shape {np.shape(u)}")
        return np.ascontiguousarray(U)

    def run(self, readings, u=None) -> KalmanResult:
        """Filter a record: readings (N, 6) V, inputs u (N, m) (the valve command for a plant
        model).
        Continues from the filter's current state."""
        Z = np.atleast_2d(np.asarray(readings, dtype=np.float64))
        if Z.ndim != 2 or Z.shape[1] != 6:
            raise DataError(f"readings: expected shape (N, 6), found {np.shape(readings)}")
        if not np.isfinite(Z).all():
            raise DataError("readings contain NaN or inf (first at sample "
                            f"{int(np.argmax(~np.isfinite(Z).all(1)))})")
        Z = np.ascontiguousarray(Z - self.offsets)
        N = Z.shape[0]
        U = self._inputs(u, N)
        f = np.empty((N, 3))
        c = np.empty((N, 3, 3))
        nis = np.empty(N)
        d = self.dynamics
        _kf_run(KalmanArrays(d.A, d.B, d.C, d.Q, self._HC, self._sn2, self._floor2), Z, U, self.x,
                self.P, KalmanOut(f, c, nis), KalmanWork(self._tmp, self._ph, self._kg))
        return KalmanResult(f, c, np.sqrt(np.einsum("nkk->nk", c)), nis)

    def step(self, reading, u=None) -> tuple[np.ndarray, np.ndarray]:
        """One sample inside a control loop: returns (force (3,), covariance (3, 3)) after the
        measurement update with ``reading`` (6,), then predicts the next sample with input ``u``."""
        r = self.run(np.asarray(reading, dtype=np.float64).reshape(1, 6),
                     None if u is None else np.asarray(u, dtype=np.float64).reshape(1, -1))
        return r.force[0], r.covariance[0]
