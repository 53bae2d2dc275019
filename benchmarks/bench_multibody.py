"""Rigid-body dynamics and the complete DLR/HIT finger against Pinocchio.

* batched RNEA of the 3-actuator coupled finger (gripkit, numba kernel over a batch of states)
  vs ``pin.rnea`` called in a Python loop on the equivalent 4-joint Pinocchio model (plus the Γ
  projection a user would add) — per state; target: gripkit no slower;
* the joint-space mass matrix the same way (gripkit CRBA vs ``pin.crba``);
* the complete finger (PWM → motor → transmission → Appendix G friction with stick-slip → coupled
  dynamics) simulated at 1 kHz: gripkit's kernel vs the same step written in Python around
  ``pin.aba`` (semi-implicit Euler, table friction, motor model), per simulated second; target:
  gripkit ≥ 1000× faster than real time.

Numba compile time is excluded (warm-up call), as everywhere in the benchmarks.
"""

from __future__ import annotations

import math
import time
import warnings

import numpy as np
from common import measure, measure_alternating, row


def _setup():
    from gripkit.errors import ConsistencyWarning
    from gripkit.multibody.pinocchio import to_pinocchio
    from gripkit.systems.dlr_hit.parameters import finger

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConsistencyWarning)
        f = finger()
    ch = f.chain()
    model, data = to_pinocchio(ch.chain)
    return f, ch, model, data


def _python_finger_step(pin, model, data, f, ch, x, pwm, h):
    """One semi-implicit Euler step of the finger in Python around pin.aba (the peer)."""
    G = ch.coupling.matrix
    arm = ch.coupling.armature
    p, pd = x[:3], x[3:6]
    q, qd = G @ p, G @ pd
    M = G.T @ pin.crba(model, data, q) @ G
    M = np.triu(M) + np.triu(M, 1).T + np.diag(arm)
    h_p = G.T @ pin.nonLinearEffects(model, data, q, qd)
    tau = (np.array([float(f.motor_torque(a, pwm[k], pd[k]))
                     for k, a in enumerate(("base1", "base2", "distal"))]))
    fr = (np.array([float(f.kinetic_friction(a, pd[k])) for k, a in enumerate(("base1", "base2",
                                                                               "distal"))]))
    acc = np.linalg.solve(M, tau - h_p - fr)
    x[3:6] = pd + h * acc
    x[:3] = p + h * x[3:6]


def run(quick: bool = False) -> list[dict]:
    import pinocchio as pin

    f, ch, model, data = _setup()
    rng = np.random.default_rng(0)
    B = 2_000 if quick else 20_000
    p, pd, pdd = (rng.normal(size=(B, 3)) for _ in range(3))
    G = ch.coupling.matrix
    arm = ch.coupling.armature
    q, qd, qdd = p @ G.T, pd @ G.T, pdd @ G.T
    rows = []

    t_gk = measure(lambda: ch.rnea(p, pd, pdd, parallel=False)) / B
    t_gk_par = measure(lambda: ch.rnea(p, pd, pdd, parallel=True)) / B
    n_pin = min(B, 5_000)

    def pin_loop():  # Pinocchio alone on the 4-joint chain (the Γ projection left out: a bound)
        for i in range(n_pin):
            pin.rnea(model, data, q[i], qd[i], qdd[i])

    t_pin = measure(pin_loop) / n_pin
    np.testing.assert_allclose(ch.rnea(p[:5], pd[:5], pdd[:5]),
                               [G.T @ pin.rnea(model, data, q[i], qd[i],
                                               qdd[i]) + arm * pdd[i] for i in range(5)],
                               atol=1e-10)
    rows.append(row("multibody", "RNEA, coupled 3-actuator finger, per state "
                                 "(batch, 1 thread)", t_gk,
                    "pin.rnea, one call per state in a Python loop", t_pin, target="ratio >= 1",
                    notes=f"batch of {B}; gripkit includes the coupling Γ, "
                          "Pinocchio's time does not"))
    rows.append(row("multibody", "RNEA, coupled finger, per state (batch, all cores)", t_gk_par,
                    "pin.rnea in a Python loop", t_pin, target="ratio >= 1",
                    notes=f"batch of {B}, prange"))

    t_gk_m = measure(lambda: ch.mass_matrix(p)) / B

    def pin_crba():
        for i in range(n_pin):
            pin.crba(model, data, q[i])

    t_pin_m = measure(pin_crba) / n_pin
    rows.append(row("multibody", "mass matrix (CRBA), coupled finger, per state", t_gk_m,
                    "pin.crba in a Python loop", t_pin_m, target="ratio >= 1",
                    notes=f"batch of {B}"))

    # one state per public call, as a controller calls it each step, against single pin calls;
    # the three callables of each row alternate (median of 15 runs, thread CPU time)
    n_one = 2_000
    p1, pd1, pdd1 = ([np.ascontiguousarray(a[i]) for i in range(n_one)] for a in (p, pd, pdd))
    q1, qd1, qdd1 = ([np.ascontiguousarray(a[i]) for i in range(n_one)] for a in (q, qd, qdd))
    rnea_err = max(float(np.max(np.abs(ch.rnea(p1[i], pd1[i], pdd1[i])
                                       - (G.T @ pin.rnea(model, data, q1[i], qd1[i],
                                                         qdd1[i]) + arm * pdd1[i]))))
                   for i in range(20))
    # what pin.crba / pin.rnea hand back: Pinocchio computes into its Data (data.M, data.tau)
    # and its Python binding returns a new array copied from it (Pinocchio 3-4 / eigenpy), or
    # a view of it; the labels say which, as checked here
    r_m, r_t = pin.crba(model, data, q1[0]), pin.rnea(model, data, q1[0], qd1[0], qdd1[0])
    pin_new = (r_m.flags.owndata and not np.shares_memory(r_m, data.M)
               and r_t.flags.owndata and not np.shares_memory(r_t, data.tau))
    pin_returns = ("fills its data, returns a new array copied from it" if pin_new
                   else "fills its data, returns a view of it")
    tau_ws, M_ws = np.empty(3), np.empty((3, 3))

    def gk_one():
        for i in range(n_one):
            ch.rnea(p1[i], pd1[i], pdd1[i])

    def gk_one_out():
        for i in range(n_one):
            ch.rnea(p1[i], pd1[i], pdd1[i], out=tau_ws)

    def pin_one():
        for i in range(n_one):
            pin.rnea(model, data, q1[i], qd1[i], qdd1[i])

    def gk_one_m():
        for i in range(n_one):
            ch.mass_matrix(p1[i])

    def gk_one_m_out():
        for i in range(n_one):
            ch.mass_matrix(p1[i], out=M_ws)

    def pin_one_m():
        for i in range(n_one):
            pin.crba(model, data, q1[i])

    one_state = [gk_one, gk_one_out, pin_one, gk_one_m, gk_one_m_out, pin_one_m]
    t_r, t_r_out, t_pr, t_m, t_m_out, t_pm = (
        t / n_one for t in measure_alternating(one_state, runs=15, clock=time.thread_time))
    rnea_acc = f"max |τ − (Γᵀ τ_pin + arm·p̈)| = {rnea_err:.1e} N·m"
    rows.append(row("multibody", "RNEA, one state per public call (a "
                                 "controller step)", t_r,
                    f"pin.rnea, one call per state ({pin_returns})", t_pr,
                    target="ratio ≥ 0.67 (≤ 1.5×)", gripkit_accuracy=rnea_acc,
                    notes="gripkit returns a new array per call, the caller's to keep; both "
                          "called from a Python loop; gripkit checks its inputs on every call "
                          "and includes Γ; thread CPU time, alternating"))
    rows.append(row("multibody", "mass matrix (CRBA), one state "
                                 "per public call", t_m,
                    f"pin.crba, one call per state ({pin_returns})", t_pm,
                    target="ratio ≥ 0.91 (≤ 1.1×, issue 24)",
                    notes="gripkit returns a new array per call, the caller's to keep; both "
                          "called from a Python loop; gripkit projects through Γ (3×3), "
                          "Pinocchio returns 4×4; thread CPU time, alternating"))
    rows.append(row("multibody", "RNEA, one state per public call, out= workspace", t_r_out,
                    f"pin.rnea, one call per state ({pin_returns})", t_pr,
                    target="ratio ≥ 0.67 (≤ 1.5×)", gripkit_accuracy=rnea_acc,
                    notes="rnea(..., out=τ): written into the caller's array, no allocation per "
                          "call; same checks of the state as without out"))
    rows.append(row("multibody", "mass matrix (CRBA), one state per public call, out= workspace",
                    t_m_out, f"pin.crba, one call per state ({pin_returns})", t_pm,
                    target="ratio ≥ 0.67 (≤ 1.5×)",
                    notes="mass_matrix(q, out=M): written into the caller's array, no "
                          "allocation per call; gripkit projects through Γ (3×3)"))

    T = 2.0 if quick else 10.0
    N = int(T * 1000)
    t = np.arange(N) * 1e-3
    u = np.column_stack([2500 * np.sign(np.sin(2 * np.pi * 0.3 * t)),
                         -2500 * np.sign(np.sin(2 * np.pi * 0.35 * t)),
                         3000 * np.sign(np.sin(2 * np.pi * 0.5 * t))])
    x0 = f.state(q=(0.0, 20 * math.pi / 180, 20 * math.pi / 180))
    th = f.theta()[None]
    y = np.empty((1, N, 18))
    f._simulate_batch(th, u, 1e-3, 1, x0[None].copy(), y)  # warm-up (compile)
    t_sim = measure(lambda: f._simulate_batch(th, u, 1e-3, 1, x0[None].copy(), y)) / T
    t_wrap = measure(lambda: f.simulate(u, dt=1e-3, x0=x0)) / T
    n_py = 200

    def py_sim():
        x = x0.copy()
        for i in range(n_py):
            _python_finger_step(pin, model, data, f, ch, x, u[i], 1e-3)

    t_py = measure(py_sim) * (1000 / n_py)
    rows.append(row("multibody", "complete finger at 1 kHz, per simulated second (kernel)", t_sim,
                    "Python loop around "
                    "pin.aba-equivalent step", t_py, target="≥ 1000× real time (≤ 1 ms)",
                    pure_python_peer=True,
                    notes=f"{1.0 / t_sim:.0f}× real time; with the simulate() wrapper "
                          "(Trajectory, checks): "
                          f"{1.0 / t_wrap:.0f}×",
                    extra=dict(real_time_factor=1.0 / t_sim,
                               real_time_factor_wrapper=1.0 / t_wrap)))
    return rows
