"""FT-G100 benchmarks: the closed-loop grasp simulation (nonlinear plant with contact events +
hybrid force/position controller) against scipy's solve_ivp with event location, and the
Levenberg-Marquardt identification of §III-B against scipy.optimize.least_squares on a
scipy.signal.dlsim model.

Notes on what was measured are in the rows; numba compile time is excluded (warm-up call).
"""

from __future__ import annotations

import warnings

import numpy as np
from common import measure, row


def _scipy_grasp(duration: float, gap: float, noise: bool = True, seed: int = 0):
    """The same closed loop with scipy: the controller (gripkit's, sample by sample) and the plant
    integrated between samples by solve_ivp (RK45, rtol 1e-9) with a terminal contact event."""
    from scipy.integrate import solve_ivp

    from gripkit.systems.ftg100.hybrid_control import HybridForcePosition
    from gripkit.systems.ftg100.model import FTG100Plant

    pl = FTG100Plant(check=False, gap=gap)
    p = dict(zip(pl.parameters.names, pl.theta()))
    ctl = HybridForcePosition.for_plant(pl.parameters).controller()
    rng = np.random.default_rng(seed)
    sx, sf = (1e-9, 50e-9) if noise else (0.0, 0.0)
    ts = ctl.design.dt

    def rhs(t, s, V, contact):
        xa, va, xb, vb = s
        fc = p["k0"] * (p["D_a"] * xa - p["D_b"] * xb - p["gap"]) if contact else 0.0
        return [va, (p["c_e"] * V * V - p["K_fa"] * va - p["K_sa"] * xa - p["K3_a"] * xa ** 3
                     - p["D_a"] * fc) / p["M_a"],
                vb, (p["D_b"] * fc - p["K_fb"] * vb - p["K_sb"] * xb) / p["M_b"]]

    def event(contact):
        def ev(t, s, V, c):
            return p["D_a"] * s[0] - p["D_b"] * s[2] - p["gap"]
        ev.terminal, ev.direction = True, (-1 if contact else 1)
        return ev

    s, F = np.zeros(4), []
    for k in range(int(round(duration / ts))):
        xa, xb = p["D_a"] * s[0], p["D_b"] * s[2]
        V = (ctl.step(xa + sx * rng.standard_normal(),
                      p["K_sb"] / p["D_b"] ** 2 * xb + sf * rng.standard_normal(), 20e-6))
        V = min(max(V, 0.0), p["V_max"])
        t, t1 = k * ts, (k + 1) * ts
        stalled = 0
        while t < t1:
            # the mode from the state: penetration, or at the surface the relative velocity (an
            # event located on the wrong side of the surface would otherwise be missed)
            d = p["D_a"] * s[0] - p["D_b"] * s[2] - p["gap"]
            contact = d > 1e-15 or (abs(d) <= 1e-15 and p["D_a"] * s[1] - p["D_b"] * s[3] > 0.0)
            sol = solve_ivp(rhs, (t, t1), s, args=(V, contact), events=event(contact), rtol=1e-9,
                            atol=1e-18,
                            max_step=ts / 20)
            stalled = stalled + 1 if sol.t[-1] == t else 0
            if stalled > 3:  # the event fires again at once, in either mode: a grazing touch
                raise RuntimeError(f"the scipy peer stalls at a grazing contact (t = {t:.9g} s: "
                                   "the contact event fires where it starts, in either mode)")
            if stalled == 2:  # grazing: one short step in the mode the relative velocity gives,
                # without the event, then events again
                rel = p["D_a"] * s[1] - p["D_b"] * s[3]
                tg = min(t + ts / 1000.0, t1)
                sol = solve_ivp(rhs, (t, tg), s, args=(V, rel > 0.0), rtol=1e-9, atol=1e-18)
                stalled = 0
            s, t = sol.y[:, -1], sol.t[-1]
        F.append(p["k0"] * max(p["D_a"] * s[0] - p["D_b"] * s[2] - p["gap"], 0.0))
    return np.array(F)


def run(quick: bool) -> list[dict]:
    from gripkit.systems.ftg100.hybrid_control import simulate_hybrid_grasp
    from gripkit.systems.ftg100.identification import identify_actuated, step_experiment

    warnings.simplefilter("ignore")
    rows = []
    # 1. closed-loop grasp: approach (gap 5 µm), contact, force control; 20 kHz controller
    dur = 0.02 if quick else 0.03
    simulate_hybrid_grasp(gap=5e-6, duration=dur)  # compile
    g = measure(lambda: simulate_hybrid_grasp(gap=5e-6, duration=dur))
    p = measure(lambda: _scipy_grasp(dur, 5e-6))
    # without noise both must give the same contact force (gripkit records F_c at the start of a
    # sample, the scipy loop after it: shift by one)
    a = (simulate_hybrid_grasp(gap=5e-6, duration=dur, noise_force=0.0,
                               noise_position=0.0).trajectory["F_c"][1:])
    try:
        b = _scipy_grasp(dur, 5e-6, noise=False)[:-1]
        agree = (f"same controller, no noise: contact force agrees within "
                 f"{100 * float(np.max(np.abs(a - b)) / 20e-6):.2g} % of the command at every "
                 "sample")
    except RuntimeError as exc:
        agree = f"same controller; the noise-free agreement is not checked: {exc}"
    rows.append(row("ftg100", f"closed-loop grasp, {dur * 1e3:.0f} ms at 20 kHz (plant with "
                              "contact events + hybrid controller)",
                    g, "scipy solve_ivp RK45 + events, once per sample "
                       "in a Python loop", p, pure_python_peer=True, notes=agree))
    # 2. LM identification of M_a, K_fa, k0 (+ sensor zero)
    data = step_experiment(duration=1.0 if quick else 2.0, period=0.05, seed=1)
    identify_actuated(data)
    g = measure(lambda: identify_actuated(data))
    p = measure(lambda: _scipy_lm(data))
    ours = identify_actuated(data)
    theirs = _scipy_lm(data)
    rel = max(abs(ours.value(n) / theirs[i] - 1) for i, n in enumerate(("M_a", "K_fa", "k0")))
    rows.append(row("ftg100", f"LM identification of M_a, K_fa, k0 ({data.n} samples, §III-B)", g,
                    "scipy least_squares(lm) + signal.dlsim", p, pure_python_peer=True,
                    notes=f"same start (step fit), estimates agree to {rel:.1e}; gripkit "
                          "adds σ/covariance"))
    return rows


def _scipy_lm(data):
    """The §III-B fit written directly with scipy: dlsim of the ZOH-discretised eq 9, LM on
    (log M_a, log K_fa, log k0, offset), started like gripkit (from the step fit)."""
    from scipy import signal
    from scipy.optimize import least_squares

    from gripkit.sysid.physical.step_response import identify_step

    u = data["V_in"] - 70.0
    y = data["x_a"]
    Da, Ksa, k2, gain = 4.7, 25.4, 6.45, 4.7 * 1300 * 8.85e-12 * 50e-6 * 70.0 / 6e-6
    st = identify_step(data, input="V_in", output="x_a")
    wn = st.natural_frequency
    ktot = gain / st.gain
    M = ktot / wn ** 2
    kk = (ktot - Ksa) / Da ** 2
    k0 = kk * k2 / (k2 - kk) if 0 < kk < k2 else 1e5
    z0 = np.array([np.log(M), np.log(2 * st.damping_ratio * wn * M), np.log(k0), 0.0])
    dt = data.dt
    scale = np.std(y)

    def res(z):
        M, c, k0 = np.exp(z[:3])
        kkk = k0 * k2 / (k0 + k2)
        num, den, _ = signal.cont2discrete(([gain], [M, c, Ksa + Da * Da * kkk]), dt, method="zoh")
        _, yy = signal.dlsim((np.ravel(num), den, dt), u)
        return (yy[:, 0] + z[3] * scale - y) / scale

    sol = least_squares(res, z0, method="lm")
    return np.exp(sol.x[:3])
