"""Identification of a piezoelectric actuator: static Bouc-Wen hysteresis and the linear dynamics
D(s), the first two steps of ``001_0b92a7da96e7aa46.txt`` §IV.

1. **Static Bouc-Wen parameters** (§IV-C1, Fig. 9): d_p, λ, β, γ of y = d_p U − H, eq 3, from a
   quasi-static voltage sweep (the seed: 0.1 Hz, 100 V) by nonlinear least squares on the
   simulation error (:mod:`gripkit.sysid.physical.greybox` on
   :class:`~gripkit.models.hysteresis.BoucWen`),
   validated on internal loops by the maximal error relative to the loop's peak-to-peak output
   (Fig. 9b: < 5 % external, < 10 % internal). :func:`identify_bouc_wen`.
2. **D(s) = 1/(a s² + b s + 1)** (§IV-C2, Fig. 10) from a voltage step, the static part held at
   the values of step 1: :func:`identify_actuator_dynamics`.

Steps 3 and 4 of the seed (the compliance s_p through the end-effector's lever, and the force
sensor) and the whole procedure for one finger are TSFM-specific:
:mod:`gripkit.systems.tsfm.identification`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...arguments import entry_point
from ...errors import AccuracyWarning, DataError, emit_warning
from ...models.hysteresis import BoucWen, bouc_wen_parameters, bouc_wen_response
from ...models.piezo import PiezoActuator, actuator_parameters
from ...params import ParameterSet
from ...signals.trajectory import Trajectory
from ..checks import check_dimension
from .greybox import GreyboxResult, fit

__all__ = ["BoucWenResult", "ActuatorDynamicsResult", "identify_bouc_wen", "loop_error",
           "identify_actuator_dynamics",
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
        return {"params": dict(self.params), "std": dict(self.std),
                "relative_error": self.relative_error,
                "fit_percent": float(self.fit.fit_percent[0]), "n_samples": self.fit.n_samples,
                "identifiability": str(self.fit.identifiability),
                "units": {"d_p": "m/V", "lambda": "m/V",
                                                                             "beta": "1/V",
                                                                             "gamma": "1/V"}}

    def summary(self) -> str:
        p, s = self.params, self.std
        return (f"Bouc-Wen: d_p = {p['d_p'] * 1e6:.5g} ± {s['d_p'] * 1e6:.2g} µm/V, λ = "
                f"{p['lambda'] * 1e6:.5g} ± "
                f"{s['lambda'] * 1e6:.2g} µm/V, β = {p['beta']:.5g} ± {s['beta']:.2g} 1/V, γ = "
                f"{p['gamma']:.5g} ± "
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
    check_dimension(input, data.unit(input), {"a voltage": "V"}, "input (voltage)")
    check_dimension(output, data.unit(output), {"a length": "m"}, "output (displacement)")
    if np.ptp(U) <= 0:
        raise DataError(f"column {input!r} (voltage) is constant: a hysteresis needs "
                        "a voltage sweep")
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
    model = BoucWen(bouc_wen_parameters(initial["d_p"], initial["lambda"], initial["beta"],
                                        initial["gamma"],
                                        source="starting value"), check=False)
    tr = Trajectory(data.t, {"U": U, "y": y}, {"U": "V", "y": "m"}, {**data.meta, "dt": data.dt})
    res = fit(model, tr, outputs=["y"], x0=np.array([H0, U[0]]), multistart=multistart,
              burn_in=burn_in,
              progress=progress)
    params = {k: res.value(n) for k, n in _KEYS}
    std = {k: res.stdev(n) for k, n in _KEYS}
    rel = loop_error(y[burn_in:], res.y_model[:, 0])
    _warn_if_poor(res, "Bouc-Wen identification")
    return BoucWenResult(params, std, res.parameters, res, rel)


@dataclass(frozen=True)
class ActuatorDynamicsResult:
    """The piezo actuator's dynamics D(s) = 1/(a s² + b s + 1) (eq 4, §IV-C2): a (s²), b (s)
    with standard deviations, and what they mean (natural frequency, damping ratio)."""

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
                "natural_frequency_hz": self.natural_frequency_hz,
                "damping_ratio": self.damping_ratio,
                "fit_percent": float(self.fit.fit_percent[0])}


def step_initial_guess(t: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """(a, b) of D(s) from the overshoot and peak time of a (rising) step response."""
    y = np.asarray(y, dtype=np.float64)
    i0 = (int(np.argmax(np.abs(np.diff(y)) > 0.05 * np.max(np.abs(np.diff(y))))) if np.ptp(y) > 0
          else 0)
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


def identify_actuator_dynamics(data: Trajectory, static: BoucWenResult | dict, input: str = "U",
                               output: str = "y",
                               *, free=("a", "b"), initial: tuple[float, float] | None = None,
                               progress: bool = True) -> ActuatorDynamicsResult:
    """a and b of D(s) (eq 4) from a voltage step measured at the same point as ``static``
    (§IV-C2, Fig. 10): a grey-box fit of Bouc-Wen (held at ``static``) followed by D(s)."""
    sp = static.params if isinstance(static, BoucWenResult) else dict(static)
    U = np.asarray(data[input], dtype=np.float64)
    y = np.asarray(data[output], dtype=np.float64)
    a0, b0 = step_initial_guess(data.t, y) if initial is None else initial
    params = actuator_parameters(sp["d_p"], 1e-3, sp["lambda"], sp["beta"], sp["gamma"], a0, b0,
                                 1e-2,
                                 source="identified (static) / starting value (a, b)")
    model = PiezoActuator(params, loads=False, check=False)
    tr = (Trajectory(data.t, {"U": U, "y_A": y}, {"U": "V", "y_A": "m"},
                     {**data.meta, "dt": data.dt}))
    res = fit(model, tr, outputs=["y_A"], free=list(free), progress=progress)
    _warn_if_poor(res, "D(s) identification")
    return ActuatorDynamicsResult(res.value("a"), res.value("b"), res.stdev("a"), res.stdev("b"),
                                  res)


def _warn_if_poor(res: GreyboxResult, what: str) -> None:
    if res.fit_percent[0] < 90:
        emit_warning(f"{what}: the model reproduces only "
                     f"{res.fit_percent[0]:.3g} % of the data", AccuracyWarning)
