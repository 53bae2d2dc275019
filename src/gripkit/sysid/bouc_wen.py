"""The identification procedures of ``001_0b92a7da96e7aa46.txt`` §IV for one TSFM finger.

1. **Static Bouc-Wen parameters** (§IV-C1, Fig. 9): d_p, λ, β, γ of y = d_p U − H, eq 3, from a
   quasi-static voltage sweep (the seed: 0.1 Hz, 100 V) by nonlinear least squares on the
   simulation error (:mod:`gripkit.sysid.greybox` on :class:`~gripkit.models.hysteresis.BoucWen`),
   validated on internal loops by the maximal error relative to the loop's peak-to-peak output
   (Fig. 9b: < 5 % external, < 10 % internal). :func:`identify_bouc_wen`.
2. **D(s) = 1/(a s² + b s + 1)** (§IV-C2, Fig. 10) from a voltage step, the static part held at
   the values of step 1: :func:`identify_actuator_dynamics`.
3. **s_p** from a force–displacement test at the tip B (§IV-C3, eq 15, Fig. 11):
   y_B = −(1 + 3L_r/L_a + 3L_r²/L_a²) s_p F_g, a straight line: :func:`identify_compliance`.
4. **Force sensor m_s, b_s, k_s** (§IV-B) from the free-vibration f_0 and ζ
   (:func:`gripkit.sysid.modal.free_vibration`) and one of them known:
   :func:`sensor_parameters` (k_s = m_s ω₀², b_s = 2ζ √(k_s m_s)).

Lengths. The seed measures the actuator at the tip B (the laser does not reach A), so steps 1–3
identify the parameters *of the point measured*: with the lever of eq 14, a free point at
distance ℓ moves by (1 + 2ℓ/L_a)(d_p U − H) D(s); Bouc-Wen is homogeneous in (H, λ), so the
identified d_p and λ are (1 + 2L_r/L_a) times those at A, while β, γ, a, b do not depend on the
lengths at all. Likewise step 3 gives the compliance at B. gripkit reports the point-B values,
which need no length, and converts to the tip A only when L_r and L_a are given
(:func:`to_tip_a`).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..arguments import entry_point
from ..errors import AccuracyWarning, DataError, IdentificationError
from ..models.end_effector import lever_coefficients
from ..models.hysteresis import BoucWen, bouc_wen_parameters, bouc_wen_response
from ..models.piezo import PiezoActuator, actuator_parameters
from ..params import Parameter, ParameterSet
from ..signals.trajectory import Trajectory
from .greybox import GreyboxResult, fit

__all__ = ["BoucWenResult", "DynamicsResult", "ComplianceResult", "FingerIdentification", "identify_finger",
           "identify_bouc_wen", "loop_error",
           "identify_actuator_dynamics", "identify_compliance", "sensor_parameters", "to_tip_a",
           "step_initial_guess"]

_KEYS = (("d_p", "d_p"), ("lambda", "lam"), ("beta", "beta"), ("gamma", "gamma"))


@dataclass(frozen=True)
class BoucWenResult:
    """Identified static Bouc-Wen parameters (SI: d_p, lambda in m/V; beta, gamma in 1/V)."""

    params: dict
    std: dict
    parameters: ParameterSet
    fit: GreyboxResult
    relative_error: float

    def predict(self, U, H0: float = 0.0, U0: float = 0.0) -> np.ndarray:
        """Displacement y (m) for the voltages U (V), from the hysteresis state (H0, U0)."""
        p = self.params
        return bouc_wen_response(U, p["d_p"], p["lambda"], p["beta"], p["gamma"], H0, U0)[0]

    def loop_error(self, U, y) -> float:
        """Fig. 9b's metric on a validation loop: max |y − ŷ| / (max y − min y)."""
        return loop_error(y, self.predict(U))

    def to_dict(self) -> dict:
        return {"params": dict(self.params), "std": dict(self.std), "relative_error": self.relative_error,
                "fit_percent": float(self.fit.fit_percent[0]), "n_samples": self.fit.n_samples,
                "identifiability": str(self.fit.identifiability), "units": {"d_p": "m/V", "lambda": "m/V",
                                                                             "beta": "1/V", "gamma": "1/V"}}

    def summary(self) -> str:
        p, s = self.params, self.std
        return (f"Bouc-Wen: d_p = {p['d_p'] * 1e6:.5g} ± {s['d_p'] * 1e6:.2g} µm/V, λ = {p['lambda'] * 1e6:.5g} ± "
                f"{s['lambda'] * 1e6:.2g} µm/V, β = {p['beta']:.5g} ± {s['beta']:.2g} 1/V, γ = {p['gamma']:.5g} ± "
                f"{s['gamma']:.2g} 1/V; max error {100 * self.relative_error:.3g} % of the loop")


def loop_error(y, y_model) -> float:
    """max |y − ŷ| / (max y − min y) (Fig. 9b, Fig. 12's 'relative error')."""
    y = np.asarray(y, dtype=np.float64)
    ptp = float(np.ptp(y))
    if ptp <= 0:
        raise DataError("the measured output does not vary: no loop to compare")
    return float(np.max(np.abs(y - np.asarray(y_model)))) / ptp


def _branch_gap(U: np.ndarray, y: np.ndarray) -> float:
    """Vertical distance between the descending and ascending branches at mid-voltage."""
    dU = np.diff(U)
    mid = 0.5 * (U.max() + U.min())
    gaps = []
    for sgn in (1, -1):
        idx = np.flatnonzero(sgn * dU > 0)
        if idx.size < 4:
            return math.nan
        u, v = U[idx + 1], y[idx + 1]
        o = np.argsort(u)
        u, v = u[o], v[o]
        if not (u[0] <= mid <= u[-1]):
            return math.nan
        gaps.append(np.interp(mid, u, v))
    return gaps[1] - gaps[0]


@entry_point
def identify_bouc_wen(data: Trajectory, input: str = "U", output: str = "y", *,
                      initial: dict | None = None, burn_in: int = 0, multistart: int = 2,
                      H0: float = 0.0, delay: float = 0.0, progress: bool = True) -> BoucWenResult:
    """Static Bouc-Wen parameters from a quasi-static voltage sweep (§IV-C1).

    ``data`` holds the voltage (column ``input``, V) and the displacement (``output``, m) of the
    point measured. The record is simulated from the hysteresis state ``H0`` at its first voltage
    (virgin: 0); a record that starts mid-loop should skip its first ``burn_in`` samples.
    Starting values come from the data (slope → d_p, gap between the branches → λ/(β+γ)) unless
    ``initial`` gives them (keys d_p, lambda, beta, gamma).

    ``delay`` (s): how far the measured displacement lags the static hysteresis. Even at 0.1 Hz
    the actuator's D(s) ≈ e^{−b s} delays the output by b (80 µs in Table II), and a DAC holding
    each voltage sample for dt adds dt/2; at the seed's 20 nm resolution that lag (≈ 10 nm on a
    100 V loop) biases γ by a few %. Bouc-Wen is rate independent, so the model fitted is
    y(t) = d_p U(t − delay) − H(U(t − delay)), exact to first order in the delay. Identify
    D(s) from a step first (:func:`identify_actuator_dynamics`), then refit with
    ``delay = b + dt/2`` — the order of §IV, iterated once.
    """
    if not isinstance(data, Trajectory):
        raise DataError(f"data: expected a Trajectory, found {type(data).__name__}")
    U = np.asarray(data[input], dtype=np.float64)
    y = np.asarray(data[output], dtype=np.float64)
    if np.ptp(U) <= 0:
        raise DataError(f"column {input!r} (voltage) is constant: a hysteresis needs a voltage sweep")
    if not (np.isfinite(delay) and delay >= 0):
        raise DataError(f"delay: expected a lag >= 0 s, found {delay!r}")
    if delay > 0:
        U = np.interp(data.t - delay, data.t, U)
    turns = int(np.sum(np.diff(np.sign(np.diff(U[np.abs(np.diff(U, prepend=U[0])) > 0]))) != 0))
    if turns < 1:
        raise DataError(f"column {input!r} never reverses: the hysteresis loop is not closed",
                        hint="record at least one rise and one fall of the voltage")
    if initial is None:
        d0 = float(np.polyfit(U, y, 1)[0])
        gap = _branch_gap(U, y)
        hs = abs(gap) / 2 if math.isfinite(gap) and gap != 0 else 0.02 * abs(d0) * np.ptp(U)
        c0 = 10.0 / np.ptp(U)
        initial = {"d_p": abs(d0), "lambda": hs * c0, "beta": 0.9 * c0, "gamma": 0.1 * c0}
    model = BoucWen(bouc_wen_parameters(initial["d_p"], initial["lambda"], initial["beta"], initial["gamma"],
                                        source="starting value"), check=False)
    tr = Trajectory(data.t, {"U": U, "y": y}, {"U": "V", "y": "m"}, {**data.meta, "fs": data.fs})
    res = fit(model, tr, outputs=["y"], x0=np.array([H0, U[0]]), multistart=multistart, burn_in=burn_in,
              progress=progress)
    params = {k: res.value(n) for k, n in _KEYS}
    std = {k: res.stdev(n) for k, n in _KEYS}
    rel = loop_error(y[burn_in:], res.y_model[:, 0])
    _warn_if_poor(res, "Bouc-Wen identification")
    return BoucWenResult(params, std, res.parameters, res, rel)


@dataclass(frozen=True)
class DynamicsResult:
    """a (s²), b (s) of D(s) with standard deviations, and what they mean."""

    a: float
    b: float
    a_std: float
    b_std: float
    fit: GreyboxResult

    @property
    def natural_frequency_hz(self) -> float:
        return 1.0 / (2.0 * math.pi * math.sqrt(self.a))

    @property
    def damping_ratio(self) -> float:
        return self.b / (2.0 * math.sqrt(self.a))

    def to_dict(self) -> dict:
        return {"a": self.a, "b": self.b, "a_std": self.a_std, "b_std": self.b_std,
                "natural_frequency_hz": self.natural_frequency_hz, "damping_ratio": self.damping_ratio,
                "fit_percent": float(self.fit.fit_percent[0])}


def step_initial_guess(t: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """(a, b) of D(s) from the overshoot and peak time of a (rising) step response."""
    y = np.asarray(y, dtype=np.float64)
    i0 = int(np.argmax(np.abs(np.diff(y)) > 0.05 * np.max(np.abs(np.diff(y))))) if np.ptp(y) > 0 else 0
    y0 = y[:max(i0, 1)].mean()
    yf = y[-max(len(y) // 10, 1):].mean()
    if yf == y0:
        raise DataError("the output does not change: no step response")
    yn = (y - y0) / (yf - y0)
    k = i0 + int(np.argmax(yn[i0:]))
    mp = yn[k] - 1.0
    tp = max(t[k] - t[i0], t[1] - t[0])
    if mp > 1e-3:
        lm = math.log(mp)
        zeta = -lm / math.sqrt(math.pi**2 + lm * lm)
        wn = math.pi / (tp * math.sqrt(1 - zeta * zeta))
    else:
        zeta = 1.0
        k63 = i0 + int(np.argmax(yn[i0:] > 0.63))
        wn = 2.0 / max(t[k63] - t[i0], t[1] - t[0])
    return 1.0 / wn**2, 2.0 * zeta / wn


def identify_actuator_dynamics(data: Trajectory, static: BoucWenResult | dict, input: str = "U", output: str = "y",
                               *, free=("a", "b"), initial: tuple[float, float] | None = None,
                               progress: bool = True) -> DynamicsResult:
    """a and b of D(s) (eq 4) from a voltage step measured at the same point as ``static``
    (§IV-C2, Fig. 10): a grey-box fit of Bouc-Wen (held at ``static``) followed by D(s)."""
    sp = static.params if isinstance(static, BoucWenResult) else dict(static)
    U = np.asarray(data[input], dtype=np.float64)
    y = np.asarray(data[output], dtype=np.float64)
    a0, b0 = step_initial_guess(data.t, y) if initial is None else initial
    params = actuator_parameters(sp["d_p"], 1e-3, sp["lambda"], sp["beta"], sp["gamma"], a0, b0, 1e-2,
                                 source="identified (static) / starting value (a, b)")
    model = PiezoActuator(params, loads=False, check=False)
    tr = Trajectory(data.t, {"U": U, "y_A": y}, {"U": "V", "y_A": "m"}, {**data.meta, "fs": data.fs})
    res = fit(model, tr, outputs=["y_A"], free=list(free), progress=progress)
    _warn_if_poor(res, "D(s) identification")
    return DynamicsResult(res.value("a"), res.value("b"), res.stdev("a"), res.stdev("b"), res)


@dataclass(frozen=True)
class ComplianceResult:
    """Compliance at the loaded point (m/N) from y = y₀ − c F, with std; s_p (m/N, at A, eq 15)
    when the lengths were given."""

    compliance: float
    compliance_std: float
    offset: float
    s_p: float | None
    s_p_std: float | None
    n_samples: int
    residual_std: float

    def to_dict(self) -> dict:
        return dict(self.__dict__)


def identify_compliance(F, y, *, L_r: float | None = None, L_a: float | None = None,
                        min_force: float | None = None) -> ComplianceResult:
    """Eq 15: fit y_B = y₀ − c F_g by least squares (c = (1 + 3L_r/L_a + 3L_r²/L_a²) s_p).

    ``F`` (N): force applied at B; ``y`` (m): displacement of B; samples with |F| below
    ``min_force`` are left out (the approach before contact, where the pull-in effect of Fig. 11b
    spoils the force). With ``L_r`` and ``L_a``, s_p at the tip A is returned too.
    """
    F = np.asarray(F, dtype=np.float64).ravel()
    y = np.asarray(y, dtype=np.float64).ravel()
    if F.shape != y.shape:
        raise DataError(f"force and displacement must have the same length, found {F.size} and {y.size}")
    if not (np.isfinite(F).all() and np.isfinite(y).all()):
        raise DataError("force or displacement contains NaN or inf")
    keep = np.abs(F) >= (min_force or 0.0)
    F, y = F[keep], y[keep]
    if F.size < 3 or np.ptp(F) <= 0:
        raise DataError(f"eq 15 needs at least 3 samples at different forces, found {F.size} "
                        f"(spread {np.ptp(F) if F.size else 0:g} N)", hint="load the tip over a range of forces")
    M = np.column_stack([np.ones_like(F), -F])
    coef, *_ = np.linalg.lstsq(M, y, rcond=None)
    r = y - M @ coef
    s2 = float(r @ r) / max(F.size - 2, 1)
    cov = s2 * np.linalg.inv(M.T @ M)
    c, c_std = float(coef[1]), math.sqrt(cov[1, 1])
    if c <= 0:
        raise IdentificationError(f"the tip moves with the force, not against it (compliance {c:g} m/N)",
                                  hint="check the sign convention: F is the force pressing on the tip")
    s_p = s_p_std = None
    if L_r is not None and L_a is not None:
        af = lever_coefficients(L_r, L_a).alpha_f
        s_p, s_p_std = c / af, c_std / af
    return ComplianceResult(c, c_std, float(coef[0]), s_p, s_p_std, int(F.size), math.sqrt(s2))


def sensor_parameters(f0_hz: float, zeta: float, *, k_s: float | None = None, m_s: float | None = None,
                      b_s: float | None = None, f0_std: float = 0.0, zeta_std: float = 0.0,
                      known_std: float = 0.0, source: str = "identified from free vibration") -> ParameterSet:
    """m_s, b_s, k_s of the force sensor from its natural frequency ``f0_hz``, damping ratio
    ``zeta`` and exactly one of them known (with its std ``known_std``); first-order error
    propagation gives the std of the other two (independent errors assumed)."""
    given = {k: v for k, v in (("k_s", k_s), ("m_s", m_s), ("b_s", b_s)) if v is not None}
    if len(given) != 1:
        raise DataError(f"give exactly one of k_s, m_s, b_s (found {sorted(given) or 'none'})")
    if not (f0_hz > 0 and zeta > 0):
        raise DataError(f"f0 and ζ must be positive, found f0 = {f0_hz!r} Hz, ζ = {zeta!r}")
    w = 2.0 * math.pi * f0_hz
    rw, rz = f0_std / f0_hz, zeta_std / zeta
    (name, val), = given.items()
    rk = known_std / val
    if name == "k_s":
        k = val
        m = k / w**2
        b = 2.0 * zeta * k / w
        sk, sm, sb = known_std, m * math.hypot(rk, 2 * rw), b * math.sqrt(rz**2 + rk**2 + rw**2)
    elif name == "m_s":
        m = val
        k = m * w**2
        b = 2.0 * zeta * m * w
        sm, sk, sb = known_std, k * math.hypot(rk, 2 * rw), b * math.sqrt(rz**2 + rk**2 + rw**2)
    else:
        b = val
        m = b / (2.0 * zeta * w)
        k = m * w**2
        sb, sm, sk = known_std, m * math.sqrt(rk**2 + rz**2 + rw**2), k * math.sqrt(rk**2 + rz**2 + rw**2)
    src = f"{source} (f0 = {f0_hz:.6g} Hz, ζ = {zeta:.4g}, {name} given)"
    return ParameterSet([
        Parameter("m_s", m, "kg", "force-sensor effective mass (eq 8)", (0.0, None), source=src if name != "m_s" else "given",
                  std=sm, display_unit="mg"),
        Parameter("b_s", b, "N*s/m", "force-sensor damping (eq 8)", (0.0, None), source=src if name != "b_s" else "given",
                  std=sb),
        Parameter("k_s", k, "N/m", "force-sensor stiffness (eq 8)", (0.0, None), source=src if name != "k_s" else "given",
                  std=sk),
    ], "force-sensor")


def to_tip_a(values: dict, L_r: float, L_a: float, stds: dict | None = None) -> tuple[dict, dict]:
    """Convert point-B parameters (d_p, lambda, compliance) to the tip A with the lever of eq 14/15:
    d_p and λ divide by 1 + 2L_r/L_a, the compliance by 1 + 3L_r/L_a + 3L_r²/L_a² (→ s_p)."""
    lc = lever_coefficients(L_r, L_a)
    out, sd = {}, {}
    for k, v in values.items():
        f = lc.alpha_u if k in ("d_p", "lambda", "lam") else (lc.alpha_f if k in ("compliance", "s_p") else 1.0)
        out["s_p" if k == "compliance" else k] = v / f
        if stds and k in stds:
            sd["s_p" if k == "compliance" else k] = stds[k] / f
    return out, sd


def _warn_if_poor(res: GreyboxResult, what: str) -> None:
    if res.fit_percent[0] < 90:
        warnings.warn(f"{what}: the model reproduces only {res.fit_percent[0]:.3g} % of the data", AccuracyWarning,
                      stacklevel=3)


@dataclass(frozen=True)
class FingerIdentification:
    """A finger identified by the procedure of §IV (:func:`identify_finger`): the model
    (``finger``, a TSFMFinger whose parameters carry std and provenance) and each step's result."""

    finger: object
    bouc_wen: BoucWenResult
    dynamics: DynamicsResult
    compliance: ComplianceResult
    modal: object
    sensor: ParameterSet

    def table(self) -> list[dict]:
        return self.finger.parameters.table()


def identify_finger(loops: Trajectory, step: Trajectory, compliance: Trajectory, vibration: Trajectory, *,
                    k_s: float, k_s_std: float = 0.0, L_r: float, L_s: float, L_a: float,
                    dac_dt: float = 5e-5, sensitivity: float = 5e3, voltage: str = "U", displacement: str = "y_B",
                    force: str = "F", progress: bool = False):
    """The identification procedure of §IV for one finger, from four records:

    ``loops``: quasi-static voltage sweep at B (columns ``voltage``, ``displacement``) — the seed
    uses the 100 V external loop; ``step``: a voltage step at B; ``compliance``: force on B and its
    displacement, no voltage (eq 15); ``vibration``: the sensor's free vibration (column ``force``).
    ``k_s``: the sensor stiffness known from its calibration (§IV-B needs one of m_s, b_s, k_s).
    Order: Bouc-Wen → D(s) → Bouc-Wen again with the lag b + dac_dt/2 → D(s) again; s_p (eq 15);
    f0, ζ → m_s, b_s. Point-B values are converted to the tip A with the lengths (eq 14).
    """
    from ..models.tsfm import TSFMFinger, finger_parameters
    from .modal import free_vibration

    bw = identify_bouc_wen(loops, voltage, displacement, progress=progress)
    dyn = identify_actuator_dynamics(step, bw, voltage, displacement, progress=progress)
    bw = identify_bouc_wen(loops, voltage, displacement, delay=dyn.b + 0.5 * dac_dt, progress=progress,
                           initial=bw.params)
    dyn = identify_actuator_dynamics(step, bw, voltage, displacement, progress=progress, initial=(dyn.a, dyn.b))
    comp = identify_compliance(compliance[force], compliance[displacement], L_r=L_r, L_a=L_a, min_force=5e-6)
    vib = free_vibration(vibration[force], vibration.fs)
    sensor = sensor_parameters(vib.natural_frequency_hz, vib.damping_ratio, k_s=k_s, f0_std=vib.natural_frequency_std_hz,
                               zeta_std=vib.damping_ratio_std, known_std=k_s_std)
    at_a, sd_a = to_tip_a({"d_p": bw.params["d_p"], "lambda": bw.params["lambda"]}, L_r, L_a,
                          {"d_p": bw.std["d_p"], "lambda": bw.std["lambda"]})
    src = {"d_p": "identified: hysteresis loops (Fig. 9), converted to A with eq 14",
           "lam": "identified: hysteresis loops (Fig. 9), converted to A with eq 14",
           "beta": "identified: hysteresis loops (Fig. 9)", "gamma": "identified: hysteresis loops (Fig. 9)",
           "a": "identified: step response (Fig. 10), whole-finger model",
           "b": "identified: step response (Fig. 10), whole-finger model",
           "s_p": "identified: force-displacement at B (eq 15, Fig. 11)",
           "m_s": "identified: free vibration (Fig. 8) and k_s", "b_s": "identified: free vibration (Fig. 8) and k_s",
           "k_s": "given (sensor calibration)", "L_r": "given", "L_s": "given", "L_a": "given",
           "sensitivity": "given (nominal 200 µN/V, 001_0b92a7da96e7aa46.txt §IV-B)"}
    params = finger_parameters(d_p=at_a["d_p"], s_p=comp.s_p, lam=at_a["lambda"], beta=bw.params["beta"],
                               gamma=bw.params["gamma"], a=dyn.a, b=dyn.b, m_s=sensor.value("m_s"),
                               b_s=sensor.value("b_s"), k_s=k_s, L_r=L_r, L_s=L_s, L_a=L_a, sensitivity=sensitivity,
                               sources=src, name="identified finger")
    stds = {"d_p": sd_a["d_p"], "lam": sd_a["lambda"], "beta": bw.std["beta"], "gamma": bw.std["gamma"],
            "a": dyn.a_std, "b": dyn.b_std, "s_p": comp.s_p_std, "m_s": sensor["m_s"].std,
            "b_s": sensor["b_s"].std, "k_s": k_s_std}
    # last: a, b again, now through the whole finger — the step at B also carries the sensor's
    # inertia on the actuator (0.3 % on a with Table II), which the bare actuator model absorbs into a
    whole = TSFMFinger(params, name="identified finger", check=False)
    st = Trajectory(step.t, {"U": step[voltage], "F_g": np.zeros(step.n), "y_B": step[displacement]},
                    {"U": "V", "F_g": "N", "y_B": "m"}, {**step.meta, "fs": step.fs})
    ab = fit(whole, st, outputs=["y_B"], free=["a", "b"], progress=progress)
    dyn = DynamicsResult(ab.value("a"), ab.value("b"), ab.stdev("a"), ab.stdev("b"), ab)
    params = params.replace(a=dyn.a, b=dyn.b)
    stds.update(a=dyn.a_std, b=dyn.b_std)
    params = ParameterSet([p if p.name not in stds else p.with_value(p.value, std=stds[p.name], source=p.source)
                           for p in params.values()], params.name)
    return FingerIdentification(TSFMFinger(params, name="identified finger", check=False), bw, dyn, comp, vib, sensor)
