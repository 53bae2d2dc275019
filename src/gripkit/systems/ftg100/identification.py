"""The FemtoTools FT-G100 microgripper (seed ``003_abd62b560633beaf.txt``): the seed's
identification experiments (simulated) and their Levenberg-Marquardt identification (§III-B,
§III-D).

§III-B: "the electrostatic actuator has been excited with a 10V step voltage around the operating
point while the object seizure was happening ... p = [M_a K_fa k0]ᵀ which minimize a quadratic
criterion of the error between the measured displacement x_a and the estimated one" (eq 9 model,
Levenberg-Marquardt). §III-D: the sensing arm is pushed by a rigid beam (27 µm in Fig. 9) and
released — a negative force step — and M_b, K_fb are estimated the same way.

:func:`identify_actuated` and :func:`identify_sensing` start from the general second-order step
fit (:func:`gripkit.sysid.physical.step_response.identify_step`), map its K, ω_n, ζ to the physical
parameters, and refine them by output-error Levenberg-Marquardt on the grey-box engine (positive
parameters in log space), returning the grey-box result with standard deviations, covariance and
correlation.

Identifiability of k0. The object is in series with the sensing arm (k_k = k0 k2/(k0 + k2)) and
k0 ≈ 1043 N/m ≫ k2 = 6.45 N/m, so ∂ln(K_sa + D_a² k_k)/∂ln k0 = D_a² k_k/(K_sa + D_a² k_k) ·
k2/(k0 + k2) = 0.0052: doubling k0 moves the step response by half a percent. With output noise of
1 % of the step, σ(k0)/k0 is about 10 % from a 20 ms record and about 0.65 % from a 5 s record
(the steady level carries most of the information); M_a and K_fa are determined far better
(0.04 % and 0.4 % from 20 ms). gripkit reports these standard deviations instead of hiding them.
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np

from ...errors import ConsistencyWarning, DataError, IdentificationError
from ...signals.trajectory import Trajectory
from ...sysid.physical.greybox import GreyboxResult, fit
from ...sysid.physical.step_response import identify_step
from .model import FTG100Actuated, FTG100Sensing

__all__ = ["step_experiment", "release_experiment", "identify_actuated", "identify_sensing"]

def _noise(y: np.ndarray, sigma: float, seed: int) -> np.ndarray:
    return y + sigma * np.random.default_rng(seed).standard_normal(y.shape)


def step_experiment(model: FTG100Actuated | None = None, *, dt: float = 5e-05,
                    duration: float = 0.02,
                    t_step: float = 1e-3, step: float = 10.0, period: float | None = None,
                    noise: float = 0.01,
                    seed: int = 0) -> Trajectory:
    """The §III-B experiment, simulated: V_in steps from V₀ to V₀ + ``step`` at ``t_step`` with the
    object grasped (and, with ``period``, back and forth as a square wave of that period); x_a (m,
    from the operating point) with white noise of σ = ``noise`` × the step's static amplitude.
    Columns ``V_in`` (V) and ``x_a`` (m)."""
    rate = 1.0 / dt
    m = model if model is not None else FTG100Actuated(check=False)
    n = int(round(duration * rate))
    if n < 20 or not 0 <= t_step < duration:
        raise DataError("step_experiment: expected duration ≥ 20 samples and 0 ≤ t_step < "
                        "duration, found "
                        f"duration={duration!r} s, t_step={t_step!r} s")
    V0 = m.parameters.value("V0")
    t = np.arange(n) / rate
    on = t >= t_step
    if period is not None:
        if not period > 2.0 / rate:
            raise DataError(f"period: expected more than two samples, found {period!r} s")
        on &= ((t - t_step) % period) < period / 2
    V = np.where(on, V0 + step, V0)
    y = m.simulate({"V_in": V}, dt=dt)["x_a"]
    sigma = noise * abs(m.dc_gain() * step)
    return Trajectory(t, {"V_in": V, "x_a": _noise(y, sigma, seed)}, {"V_in": "V", "x_a": "m"},
                      {"dt": dt, "source": f"simulated §III-B step ({noise:.3g} "
                                           f"noise, seed {seed})",
                       "noise_std": sigma})


def release_experiment(model: FTG100Sensing | None = None, *, thrust: float = 27e-6,
                       dt: float = 5e-05,
                       duration: float = 0.01, t_release: float = 1e-3, noise: float = 0.01,
                       seed: int = 0) -> Trajectory:
    """The §III-D experiment (Fig. 9), simulated: the sensing arm is held at ``thrust`` (m) by a
    rigid beam, which is withdrawn at ``t_release`` — a negative force step from
    F₀ = K_sb·thrust/D_b² to 0. Columns ``F_c`` (N, the beam's force) and ``x_b`` (m, from rest)
    with white noise of σ = ``noise`` × thrust."""
    rate = 1.0 / dt
    m = model if model is not None else FTG100Sensing(check=False)
    n = int(round(duration * rate))
    if n < 20 or not 0 <= t_release < duration or not thrust > 0:
        raise DataError("release_experiment: expected thrust > 0, ≥ 20 samples and 0 ≤ "
                        "t_release < duration")
    F0 = thrust * m.stiffness()
    t = np.arange(n) / rate
    F = np.where(t < t_release, F0, 0.0)
    y = m.simulate({"F_c": F}, dt=dt, x0=np.array([thrust, 0.0]))["x_b"]
    return Trajectory(t, {"F_c": F, "x_b": _noise(y, noise * thrust, seed)},
                      {"F_c": "N", "x_b": "m"},
                      {"dt": dt, "source": f"simulated §III-D release ({noise:.3g} "
                                           f"noise, seed {seed})",
                       "noise_std": noise * thrust})


def _quiet_build(cls, **kw):
    with warnings.catch_warnings():
        # eq-17 findings are reported by `zoo check`
        warnings.simplefilter("ignore", ConsistencyWarning)
        return cls(**kw)


def _pre_step(u: np.ndarray) -> int:
    """Number of samples before the input first changes (at least 1)."""
    ch = np.flatnonzero(np.abs(u - u[0]) > 1e-9 * max(1.0, abs(u[0])))
    if ch.size == 0:
        raise DataError("the input never changes: a step response needs a step",
                        hint="check the input column")
    return max(1, int(ch[0]))


def identify_actuated(data: Trajectory, *, input: str = "V_in", output: str = "x_a",
                      model: FTG100Actuated | None = None, free=("M_a", "K_fa", "k0"),
                      progress: bool = False) -> GreyboxResult:
    """Levenberg-Marquardt estimate of M_a, K_fa, k0 (§III-B) from a voltage step recorded while the
    object is grasped. ``input`` is the absolute actuation voltage (V) and ``output`` the tip
    displacement (m); the output's level before the step is removed and the operating voltage V₀
    is taken from the input before the step. Fixed parameters (D_a, K_sa, k2, comb drive) come from
    ``model`` (default: the seed's). The sensor zero ``x_off`` is estimated with them (its
    uncertainty enters k0's: see the module docstring). Returns the grey-box result (values, std,
    covariance).
    """
    if not isinstance(data, Trajectory):
        raise DataError(f"data: expected a Trajectory, found {type(data).__name__}")
    u = np.asarray(data[input], float)
    y = np.asarray(data[output], float)
    k = _pre_step(u)
    V0 = float(u[:k].mean())
    if not 0 < V0 <= 200:
        raise DataError(f"input {input!r}: the operating voltage before the step is "
                        f"{V0:g} V; expected "
                        f"(0, 200] V", hint="give the absolute actuation voltage, "
                                            "not its deviation")
    off0 = float(y[:k].mean())
    y = y - off0
    base = model if model is not None else _quiet_build(FTG100Actuated, check=False)
    base = base.with_parameters(check=False, V0=V0)
    data = Trajectory(data.t, {"V_in": u, "x_a": y}, {"V_in": "V", "x_a": "m"}, data.meta)
    st = identify_step(data, input="V_in", output="x_a")
    p = base.parameters
    gain = p.value("D_a") * p.value("N_a") * p.value("eps") * p.value("h") * V0 / p.value("g")
    if not st.gain > 0:
        raise IdentificationError("the step response has a non-positive static gain "
                                  f"({st.gain:.3g} m/V): the "
                                  "arm must close with "
                                  "increasing voltage", hint="check the sign of the output")
    wn = st.natural_frequency
    k_tot = gain / st.gain
    M = k_tot / wn ** 2
    kk = (k_tot - p.value("K_sa")) / p.value("D_a") ** 2
    k2 = p.value("k2")
    k0 = kk * k2 / (k2 - kk) if 0 < kk < 0.999 * k2 else (1e5 if kk >= 0.999 * k2 else 1.0)
    start = ({"M_a": M, "K_fa": 2 * st.damping_ratio * wn * M, "k0": min(max(k0, 1.0), 1e6),
              "x_off": 0.0})
    free = tuple(free) + (("x_off",) if "x_off" not in free else ())
    start = {n: v for n, v in start.items() if n in free}
    res = (fit(base, data, outputs=["x_a"], free=list(free), initial=start, method="lm",
               progress=progress))
    return _shift_offset(res, off0)


def identify_sensing(data: Trajectory, *, input: str = "F_c", output: str = "x_b",
                     model: FTG100Sensing | None = None, free=("M_b", "K_fb"),
                     progress: bool = False) -> GreyboxResult:
    """Levenberg-Marquardt estimate of M_b, K_fb (§III-D) from the release of the sensing arm: the
    force ``input`` (N) applied by the pushing beam drops to zero; ``output`` is the tip deflection
    from rest (m). K_sb and D_b are fixed (``model``, default the seed's); the record must start at
    rest under the initial force.
    """
    if not isinstance(data, Trajectory):
        raise DataError(f"data: expected a Trajectory, found {type(data).__name__}")
    u = np.asarray(data[input], float)
    y = np.asarray(data[output], float)
    k = _pre_step(u)
    base = model if model is not None else _quiet_build(FTG100Sensing, check=False)
    p = base.parameters
    x_start = u[:k].mean() * p.value("D_b") ** 2 / p.value("K_sb")
    y_start = float(y[:k].mean())
    if "K_sb" not in free and "D_b" not in free and (x_start == 0
                                                     or abs(y_start / x_start - 1) > 0.05):
        raise DataError(
            f"the deflection before release, {y_start * 1e6:.4g} µm, does not match the "
            "applied force: "
            f"F₀ D_b²/K_sb = {x_start * 1e6:.4g} µm",
            hint="give the force in N and the deflection from rest in m, or free K_sb")
    data = Trajectory(data.t, {"F_c": u, "x_b": y}, {"F_c": "N", "x_b": "m"}, data.meta)
    st = identify_step(data, input="F_c", output="x_b")
    wn = st.natural_frequency
    M = p.value("K_sb") / wn ** 2
    start = {"M_b": M, "K_fb": 2 * st.damping_ratio * wn * M}
    start = {n: v for n, v in start.items() if n in free}
    start["x_off"] = 0.0  # the data are shifted so that the level before release is x_start
    off0 = y_start - x_start
    data = Trajectory(data.t, {"F_c": u, "x_b": y - off0}, {"F_c": "N", "x_b": "m"}, data.meta)
    free = tuple(free) + (("x_off",) if "x_off" not in free else ())
    x0 = np.array([x_start, 0.0])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConsistencyWarning)
        res = fit(base, data, outputs=["x_b"], free=list(free), initial=start, x0=x0, method="lm",
                  progress=progress)
    return _shift_offset(res, off0)


def _shift_offset(res: GreyboxResult, off0: float) -> GreyboxResult:
    """The result with the fitted sensor zero expressed in the data's own zero (+ ``off0``)."""
    off = res.parameters["x_off"]
    ps = res.parameters.from_vector(np.array([off.value + off0]), ["x_off"],
                                    std=np.array([off.std]),
                                    source=off.source)
    theta = np.array([ps.value(n) for n in res.free])
    return dataclasses.replace(res, parameters=ps, theta=theta)

