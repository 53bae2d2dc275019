"""TSFM benchmarks (``001_0b92a7da96e7aa46.txt``): simulation speed of a whole finger with contact,
and a 5-parameter grey-box fit, each against the scipy code a user would write without gripkit.

1. The whole finger — Bouc-Wen (eq 3) + the 4th-order linear part of eq 11 + a contact with a
   72.5 N/m part (Fig. 13) — at 20 kHz: gripkit's exact ZOH hybrid kernel against real time
   (target ≥ 1000×), and against ``scipy.integrate.solve_ivp`` (RK45, the contact as
   k_e·max(0, y_C − x_w), U interpolated linearly) on the same 1 s cycle.
2. A grey-box fit of 5 parameters (d_p, λ, β, a, b; γ held) of Bouc-Wen + D(s) on 20 000 samples
   at 20 kHz (a 2 Hz, 100 V sine then voltage steps; tip B with 20 nm noise): gripkit's
   :func:`gripkit.sysid.physical.greybox.fit` (target < 1 s) against
   ``scipy.optimize.least_squares`` on a
   ``solve_ivp`` simulation (target ≥ 10×).

Compile time is excluded (warm-up call). Timings: benchmarks/common.py measure (median, min), except
the solve_ivp peers, timed once (labelled pure-Python: their right-hand side is interpreted).
The grey-box fit is also compared with least_squares driving the same compiled simulator.
"""

from __future__ import annotations

import time
import warnings

import numpy as np
from common import measure, row


def _contact_peer(finger, x_w, k_e, U, fs):
    """The finger with contact as a user writes it with solve_ivp (eqs 7, 9, 3; smooth contact)."""
    from scipy.integrate import solve_ivp

    from gripkit.systems.tsfm.gripper import finger_minimal_state_space

    v = finger.values()
    ss = finger_minimal_state_space(v)
    A, B = ss.A, ss.B
    d_p, lam, beta, gamma = v["d_p"], v["lam"], v["beta"], v["gamma"]
    t = np.arange(U.size) / fs
    slope = np.append(np.diff(U) * fs, 0.0)

    def rhs(tt, x):
        k = min(int(tt * fs), U.size - 1)
        du = slope[k]
        u = U[k] + du * (tt - t[k])
        H = x[4]
        F = k_e * max(0.0, x[2] - x_w)
        dx = A @ x[:4] + B[:, 0] * (d_p * u - H) + B[:, 1] * F
        return np.append(dx, lam * du - beta * abs(du) * H - gamma * du * abs(H))

    sol = solve_ivp(rhs, (0.0, t[-1]), np.zeros(5), t_eval=t, method="RK45", rtol=1e-6, atol=1e-12)
    return sol.y[2]


def _fit_data(seed=0):
    from gripkit import Trajectory
    from gripkit.models.piezo import PiezoActuator

    fs = 20000.0
    t = np.arange(20000) / fs
    U = np.where(t < 0.5, 100.0 * np.sin(2 * np.pi * 2.0 * t), 0.0)
    for i, level in enumerate([0, 40, -30, 70, 10, -60, 90, -90, 20, 0]):
        U[(t >= 0.5 + 0.05 * i) & (t < 0.55 + 0.05 * i)] = level
    true = PiezoActuator(loads=False, d_p=1.49e-6, lam=0.83e-6, beta=0.108, gamma=7.5e-3, a=2.5e-8,
                         b=8e-5,
                         check=False)
    y = (true.simulate(U, dt=1 / fs)["y_A"] + 20e-9
         * np.random.default_rng(seed).standard_normal(U.size))
    return Trajectory.uniform(dt=1 / fs, U=U, y_A=y, units={"U": "V", "y_A": "m"}), true


def _kernel_time(m, th, U, fs):
    """The numba row kernel alone, on arrays prepared once (what a loop calling it would pay)."""
    from gripkit.sim.hybrid import PWAGuards
    from gripkit.systems.tsfm import gripper as T

    nf = len(T.FINGER_NAMES)
    d = T._hybrid_arrays([(th[0, :nf], th[0, nf + 1], th[0, nf + 2], th[0, nf + 3])], 1 / fs,
                         m.levels,
                         m.realisation)
    bw = np.ascontiguousarray(th[0, [0, 2, 3, 4]])
    y = np.empty((U.shape[0], len(m.outputs)))
    x0 = np.zeros(len(m.states))
    guards = PWAGuards(d["G"][0], d["H"][0], d["target"], d["ng"])
    return measure(lambda: T._bw_pwa_row(bw, d["Phi"][0], d["Gam"][0], d["C"][0], d["D"][0],
                                         guards, m.levels, th[0, nf], U, x0.copy(), y))


FREE = ("d_p", "lam", "beta", "a", "b")
START = (1.1, 0.9, 1.15, 0.9, 1.1)


def _peer_fit(data, true, max_nfev=None):
    """The same fit written with solve_ivp and least_squares, as a user would."""
    from scipy.integrate import solve_ivp
    from scipy.optimize import least_squares

    U, y, t = data["U"], data["y_A"], data.t
    fs = 1.0 / data.dt
    slope = np.append(np.diff(U) * fs, 0.0)
    gamma = true.parameters.value("gamma")
    p0 = np.array([true.parameters.value(n) * s for n, s in zip(FREE, START)])
    w = y.std()

    def simulate(p):
        d_p, lam, beta, a, b = p

        def rhs(tt, x):
            k = min(int(tt * fs), U.size - 1)
            du = slope[k]
            u = U[k] + du * (tt - t[k])
            H, q, v = x
            return ([lam * du - beta * abs(du) * H - gamma * du * abs(H), v,
                     (d_p * u - H - q - b * v) / a])

        return (solve_ivp(rhs, (0.0, t[-1]), [0.0, 0.0, 0.0], t_eval=t, method="RK45", rtol=1e-6,
                          atol=1e-12).y[1])

    nsim = [0]

    def resid(z):
        nsim[0] += 1
        return (simulate(z * p0) - y) / w

    t0 = time.perf_counter()
    # diff_step: the default (≈1.5e-8) is below solve_ivp's rtol = 1e-6 noise and the fit stalls
    # (measured: 15 % off after 59 simulations); a user who got it working sets a larger step
    sol = (least_squares(resid, np.ones(5), x_scale="jac", bounds=(0.0, np.inf), max_nfev=max_nfev,
                         diff_step=1e-3))
    return time.perf_counter() - t0, sol.x * p0, nsim[0], simulate


def _compiled_peer_fit(start, data):
    """The expert's route: scipy least_squares driving the same compiled simulator
    (``simulate_batch``, exact ZOH kernel, output buffer reused), so the ratio isolates what
    gripkit's fit adds (its own Gauss-Newton/LM with σ, covariance and checks)."""
    from scipy.optimize import least_squares

    U = np.ascontiguousarray(data["U"][:, None])
    y = data["y_A"]
    dt = data.dt
    names = list(start.parameters.names)
    pos = [names.index(n) for n in FREE]
    th0 = start.theta()
    p0 = th0[pos].copy()
    j = [s.name for s in start.outputs].index("y_A")
    buf = np.empty((1, U.shape[0], len(start.outputs)))
    w = y.std()
    nsim = [0]

    def resid(z):
        nsim[0] += 1
        th = th0.copy()
        th[pos] = z * p0
        return (start.simulate_batch(th[None, :], U, dt, out=buf)[0, :, j] - y) / w

    sol = least_squares(resid, np.ones(len(FREE)), x_scale="jac", bounds=(0.0, np.inf))
    return sol.x * p0, nsim[0]


def run(quick: bool = False) -> list[dict]:
    from gripkit.sysid.physical.greybox import fit
    from gripkit.systems.tsfm import parameters as z

    warnings.simplefilter("ignore")
    rows = []
    fs = 20000.0
    f = z.finger("left", check=False)
    x_w = z.contact_voltage(f, 44.0)
    # 1a. one Fig. 13 cycle (0.1 Hz, 10 s) against real time
    dur = 10.0
    t = np.arange(int(dur * fs)) / fs
    U = np.ascontiguousarray((25.0 * (1.0 - np.cos(2 * np.pi * 0.1 * t)))[:, None])
    for realisation, states in (("minimal", 4), ("component", 6)):
        m = f.contact(x_w=x_w, k_e=72.5, realisation=realisation)
        th = m.theta()[None, :]
        y = m.simulate_batch(th, U, 1 / fs)
        buf = np.empty_like(y)  # a loop simulating many times reuses its output buffer
        tg = measure(lambda: m.simulate_batch(th, U, 1 / fs, out=buf))
        tk = _kernel_time(m, th, U, fs)
        rows.append(row("tsfm", f"finger: Bouc-Wen + {states}-state linear + contact, "
                                f"{dur:g} s at 20 kHz "
                                f"(one Fig. 13 cycle)", tg, "real time", dur,
                        target="≥ 1000× faster than real time" if states == 4 else "",
                        notes=f"{tg / U.shape[0] * 1e9:.1f} ns/sample through Model.simulate_batch "
                              "(discretisation, "
                              "input/output checks included, output buffer reused), "
                              f"{tk / U.shape[0] * 1e9:.1f} ns/sample in the "
                              f"kernel alone ({dur / tk:.0f}× real time); "
                              f"{'eq 11 (minimal)' if states == 4 else 'component-wise (with y_B)'}"
                              " realisation; "
                              f"{int(np.sum(np.diff(y[0, :, 4]) != 0))} contact events"))
        if states == 4:
            ts_pub = measure(lambda: m.simulate(U, dt=1 / fs))
            tb_new = measure(lambda: m.simulate_batch(th, U, 1 / fs))
            rows.append(row("tsfm", f"finger (4-state + contact), {dur:g} s at 20 kHz "
                                    "through the public "
                                    f"Model.simulate (returns a Trajectory)", ts_pub,
                            "Model.simulate_batch, new output array each call", tb_new,
                            target="ratio ≥ 0.83 (simulate ≤ 1.2× simulate_batch); ≥ "
                                   "1000× real time",
                            notes=f"{dur / ts_pub:.0f}× real time through Model.simulate; "
                                  "simulate/simulate_batch = "
                                  f"{ts_pub / tb_new:.2f}",
                            extra={"real_time_factor_simulate": dur / ts_pub}))
    # 1b. one 1 Hz cycle against solve_ivp
    t1 = np.arange(int(fs)) / fs
    U1 = 25.0 * (1.0 - np.cos(2 * np.pi * 1.0 * t1))
    m = f.contact(x_w=x_w, k_e=72.5, realisation="minimal")
    th = m.theta()[None, :]
    yg = m.simulate_batch(th, U1[:, None], 1 / fs)[0, :, 0]
    tg = measure(lambda: m.simulate_batch(th, U1[:, None], 1 / fs))
    t0 = time.perf_counter()
    yp = _contact_peer(f, x_w, 72.5, U1, fs)
    tp = time.perf_counter() - t0
    rows.append(row("tsfm", "finger with contact, one 1 Hz cycle "
                            "(20 000 samples)", tg, "scipy solve_ivp RK45, "
                    "Python right-hand side, timed once", tp, pure_python_peer=True,
                    notes=f"max |Δy_C| = {np.max(np.abs(yp - yg)) * 1e9:.1f} nm "
                          "(peer: linear input "
                          f"interpolation, smooth contact, rtol 1e-6)"))
    # 2. grey-box fit
    data, true = _fit_data()
    from gripkit.models.piezo import PiezoActuator

    start = PiezoActuator(loads=False, check=False, d_p=1.49e-6 * START[0], lam=0.83e-6 * START[1],
                          beta=0.108 * START[2], gamma=7.5e-3, a=2.5e-8 * START[3],
                          b=8e-5 * START[4])
    res = fit(start, data, outputs=["y_A"], free=list(FREE), progress=False)
    tg = measure(lambda: fit(start, data, outputs=["y_A"], free=list(FREE), progress=False))
    err = max(abs(res.value(n) / true.parameters.value(n) - 1) for n in FREE)
    if quick:  # estimate: one peer simulation × the simulations gripkit needed
        _, _, _, simulate = _peer_fit(data, true, max_nfev=1)
        p = np.array([true.parameters.value(n) for n in FREE])
        t0 = time.perf_counter()
        simulate(p)
        tp = (time.perf_counter() - t0) * res.nfev
        note = (f"peer estimated as one solve_ivp simulation × {res.nfev} (gripkit's count); run "
                "without --quick to time it")
    else:
        tp, p_peer, nsim, _ = _peer_fit(data, true)
        perr = max(abs(p_peer[i] / true.parameters.value(n) - 1) for i, n in enumerate(FREE))
        note = (f"peer: {nsim} simulations, max parameter error {100 * perr:.3g} % (its linear "
                "input interpolation "
                "cannot represent the held voltage steps of the data: a half-sample lag "
                "that biases a, b)")
    label = "grey-box fit, 5 parameters (d_p, λ, β, a, b), 20 000 samples"
    gk_acc = f"max parameter error {100 * err:.3g} %"
    p_c, nsim_c = _compiled_peer_fit(start, data)
    cerr = max(abs(p_c[i] / true.parameters.value(n) - 1) for i, n in enumerate(FREE))
    tc = measure(lambda: _compiled_peer_fit(start, data))
    rows.append(row("tsfm", label, tg, "scipy least_squares driving gripkit's "
                                       "compiled simulate_batch", tc,
                    target="< 1 s", gripkit_accuracy=gk_acc, peer_accuracy="max parameter error "
                                                                           f"{100 * cerr:.3g} %",
                    notes=f"gripkit: {res.nfev} simulated rows, with σ and covariance; peer: "
                          f"{nsim_c} simulations "
                          "(2-point finite differences), no σ; same simulator, so the ratio is "
                          "what the fit adds"))
    rows.append(row("tsfm", label, tg, "scipy least_squares + solve_ivp (Python "
                                       "right-hand side)", tp,
                    pure_python_peer=True, gripkit_accuracy=gk_acc,
                    notes=f"peer timed once (one fit takes minutes); {note}"))
    return rows
