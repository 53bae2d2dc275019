"""Demo section "dlr-hit": the DLR/HIT Hand II finger of ``002_ddea254371185ad3.txt`` — motor
maps, friction tables and fits, the velocity responses of Figs 7.3–7.5, friction identification,
online adaptation (on a log, and inside the impedance loop under a friction drift), and the
impedance experiment."""

from __future__ import annotations

import math
import warnings

import numpy as np

from ...consistency import check
from ...errors import ConsistencyWarning
from ...models.bldc import RPM, SLOPES_5_4_2, BLDCMotor, MotorTestBed
from ...progress import status
from ...report.plots import subplots
from ...signals import Trajectory
from ...sysid.rigid_body.friction import detect_breakaway, fit_stribeck, idim_ls
from ...sysid.rigid_body.motor import characterize_motor
from .finger import ACTUATORS, JOINTS
from .friction_adaptation import (THERMAL_CASES, THERMAL_MODES, adapt_finger_friction,
                                  compare_adaptation, thermal_adaptation_study, tracking_reference)
from .friction_drift import stiction_step, warmup_drift
from .hand import hand
from .impedance import ImpedanceController, Wall, impedance_margins, simulate_impedance
from .parameters import finger

DEG = math.pi / 180
NCM = 0.01


def _fig(n, w=11.0, h=3.4):
    fig, ax = subplots(1, n, figsize=(w, h))
    return fig, np.atleast_1d(ax)


def run(report, *, quick: bool = False) -> dict:
    summary: dict = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConsistencyWarning)
        f = finger()
    sec = report.section(
        "DLR/HIT Hand II finger: motor, friction, dynamics, identification and control",
        "The complete finger of the thesis (ch. 7, Fig. 7.1): PWM → BLDC motor (eq 5.10 with the "
        "Appendix E guard) → timing belts and 100:1 harmonic drive → Appendix G "
        "friction tables with "
        "Karnopp stick-slip → coupled Newton-Euler dynamics (Craig DH, θ4 = θ3, ±45° bevel "
        "differential, rotor inertia Im·N²), compliant end stops for the belt "
        "elasticity. Where the "
        "thesis's printed numbers disagree, gripkit derives the value it uses and reports the "
        "contradiction:")
    status("  dlr-hit: consistency")
    rep = check(f)
    sec.findings(rep)
    summary["inconsistent_checks"] = [x.check for x in rep.inconsistent]
    status("  dlr-hit: motor maps and identification (§5.4)")
    rng = _motor_maps(sec, summary, quick)
    status("  dlr-hit: friction tables (Appendix G)")
    _friction(sec, f)
    status("  dlr-hit: velocity responses (Figs 7.3-7.5)")
    _velocity_responses(sec, f, summary)
    status("  dlr-hit: breakaway and IDIM-LS friction identification")
    _stiction_and_idim(sec, summary, quick, rng)
    status("  dlr-hit: friction adaptation")
    _adaptation(sec, f, summary, quick)
    _loop_adaptation(sec, f, summary)
    _thermal_adaptation(sec, summary)
    status("  dlr-hit: impedance control")
    _impedance(sec, f, summary)
    status("  dlr-hit: five-finger hand")
    _hand(sec, summary)
    return summary


def _motor_maps(sec, summary, quick):
    """BLDC motor maps and their two-stage identification (§5.4); returns the random stream the
    later parts continue."""
    motor = BLDCMotor()
    fig, ax = _fig(2)
    pwm = np.linspace(0, 4096, 50)
    ax[0].plot(pwm, motor.torque(pwm, 0.0) / NCM, "k-", label="eq 5.7, stall (T_ref = 80 °C)")
    ax[0].plot(pwm, motor.torque(pwm, 0.0, 298.15) / NCM, "k--", label="stall, 25 °C (eq 5.5)")
    n = np.linspace(0, 6000, 200)
    for p in (2000, 3000, 4000):
        ax[1].plot(n, motor.torque(p, n * RPM) / NCM, label=f"PWM {p}")
    ax[0].set(xlabel="PWM", ylabel="torque [Ncm]", title="torque vs PWM (eq 5.7)")
    ax[1].set(xlabel="speed [rpm]", ylabel="torque [Ncm]", title="torque vs speed (eq 5.10, guard)")
    ax[0].legend(fontsize=8)
    ax[1].legend(fontsize=8)
    sec.figure(fig, "Motor maps: eq 5.7 at stall (and the cold motor through eq 5.5), eq "
                    "5.10 over speed; "
                    "the torque drops to zero where Appendix E's guard lets the "
                    "speed term win.", "dlr-motor-maps")
    tb = MotorTestBed(check=False)
    dur = 60 if quick else 120
    tr = (tb.simulate(np.column_stack([np.full(dur * 10 + 1, 4000.0), np.zeros(dur * 10 + 1)]),
                      dt=0.1))
    fig, ax = _fig(1, 6.0, 3.2)
    ax[0].plot(tr.t, tr["torque"] / NCM, "b-")
    ax[0].set(xlabel="time [s]", ylabel="torque [Ncm]", title="PWM 4000 at stall (Fig. 5.7)")
    a2 = ax[0].twinx()
    a2.plot(tr.t, tr["temperature"] - 273.15, "r--")
    a2.set_ylabel("winding temperature [°C]", color="r")
    sec.figure(fig, "Fig. 5.7 reproduced by the thermal model: "
                    f"{tr['torque'][0] / NCM:.2f} Ncm cold, "
                    f"{tr['torque'][-1] / NCM:.2f} Ncm at {tr['temperature'][-1] - 273.15:.0f} "
                    f"°C after {dur} s.",
               "dlr-fig57")
    summary["fig57_torque_ncm"] = [float(tr["torque"][0] / NCM), float(tr["torque"][-1] / NCM)]
    rng = np.random.default_rng(1)
    stall = np.arange(0, 4001, 50.0)
    runs = []
    for p in (2000, 2500, 3000, 3500, 4000):
        w = np.repeat(np.arange(0, 2501, 500.0), 40) * RPM
        runs.append((p, w, motor.torque(p, w) + rng.normal(0, 0.005 * NCM, w.size)))
    mc = (characterize_motor(stall, motor.torque(stall, 0.0) + rng.normal(0, 0.005 * NCM,
                                                                          stall.size), runs))
    k = RPM / NCM
    sec.table(["quantity", "identified", "± std", "thesis"],
              [["c (eq 5.7) [Ncm/PWM]", mc.c / NCM, mc.c_std / NCM, 1.43e-4],
               ["b1 (eq 5.8) [Ncm/(rpm·PWM)]", mc.b1 * k, mc.b1_std * k, 1.215e-8],
               ["b0 (eq 5.8) [Ncm/rpm]", mc.b0 * k, mc.b0_std * k, -7.711e-5]]
              + [[f"slope at PWM {int(p)} [Ncm/rpm]", b, s,
                  SLOPES_5_4_2.get(int(p), "not printed (§5.4.2 lists 2000-3500)")]
                 for p, b, s in mc.table()],
              caption="Two-stage motor characterisation (§5.4) on simulated test-bed "
                      "data (sensor noise "
                      "0.005 Ncm): eq 5.7 and eq 5.8 are recovered; the printed slopes "
                      "differ from eq 5.8 "
                      "by up to 4.9 %.")
    return rng


def _friction(sec, f):
    """Appendix G friction tables and the fitted Stribeck curves."""
    fig, ax = _fig(2)
    fits = []
    for a_i, (name, tab) in enumerate((("distal", f.tables[2]), ("base 1", f.tables[0]))):
        v = tab.velocity
        fit = fit_stribeck(v, tab.values, fixed=dict(fs=0.36, vs=0.1, delta=2.0))
        fits.append([name, fit.values["fc"], fit.std["fc"], fit.values["sigma"], fit.std["sigma"],
                     fit.values["cubic"], fit.std["cubic"], fit.rms])
        vv = np.linspace(v[0], v[-1], 400)
        ax[a_i].plot(v / DEG, tab.values, ".", ms=4, label="Appendix G table")
        ax[a_i].plot(vv / DEG, fit(vv), "-", label="Stribeck + cubic fit")
        if name == "base 1":
            ax[a_i].plot(v / DEG, f.tables[1].values * f.parameters.value("scale_base2"), "x", ms=3,
                         label="base 2 (× 1.25)")
        out = tab.outliers()
        if out:
            idx = [i for i, _ in out]
            ax[a_i].plot(v[idx] / DEG, tab.values[idx], "ro", mfc="none", ms=9,
                         label="outlying point")
        ax[a_i].axhline(0.36, color="gray", ls=":")
        ax[a_i].axhline(-0.36, color="gray", ls=":", label="stiction ±0.36 N·m")
        ax[a_i].set(xlabel="velocity [°/s]", ylabel="friction [N·m]",
                    title=f"{name} (Figs 6.4–6.6)")
        ax[a_i].legend(fontsize=7)
    sec.figure(fig, "Appendix G's friction tables, recovered from the interleaved extraction, "
                    "with Stribeck + "
                    "cubic fits (F_s = 0.36 N·m, v_s = 0.1 rad/s fixed); circles: points "
                    "50 % off their "
                    "neighbours.", "dlr-friction")
    sec.table(["table", "F_c [N·m]", "±", "σ [N·m·s/rad]", "±", "σ₃ [N·m·s³/rad³]", "±",
               "rms [N·m]"], fits,
              caption="Stribeck + cubic fits of the tables (the data hold no point below 20 °/s, "
                      "so v_s is fixed).")


def _velocity_responses(sec, f, summary):
    """Velocity responses of the finger (Figs 7.3-7.5)."""
    start = ({"distal": (0.0, 0.0, 0.0), "base1": (30 * DEG, 0.0, 0.0),
              "base2": (-30 * DEG, 0.0, 0.0)})
    fig, ax = _fig(3, 12.0, 3.3)
    rows = []
    steady = {}
    for i, a in enumerate(("distal", "base1", "base2")):
        for p in (2000, 3000, 4000):
            u = np.zeros((1500, 3))
            u[:, ACTUATORS.index(a)] = p
            trv = f.simulate(u, dt=1e-3, x0=f.state(q=start[a]))
            v = trv[f"{a}_vel"] / DEG
            vs = f.steady_velocity(a, p) / DEG
            ax[i].plot(trv.t, v, label=f"PWM {p}")
            ax[i].axhline(vs, color="gray", lw=0.6, ls="--")
            rows.append([a, p, vs, float(v.max())])
            steady[f"{a}_{p}"] = round(float(vs), 1)
        ax[i].set(xlabel="time [s]", ylabel="velocity [°/s]", title={"distal": "distal (Fig. 7.3)",
                  "base1": "base 1 (Fig. 7.4)", "base2": "base 2 (Fig. 7.5)"}[a])
        ax[i].legend(fontsize=7)
    sec.figure(fig, "Velocity responses from one end of the travel to the other: "
                    "acceleration, plateau "
                    "(dashed: eq 5.10 against the table, no gravity), and braking on the "
                    "belt-elastic end "
                    "stop with a rebound (the thesis's simulation drops to "
                    "zero vertically).", "dlr-velocity")
    sec.table(["actuator", "PWM", "steady velocity, "
                                  "no gravity [°/s]", "peak, palm down [°/s]"], rows,
              caption="Velocities gripkit predicts (Figs 7.3–7.5 show 100–300 °/s, distal "
                      "fastest). Base 2 "
                      "at PWM 4000 settles on Appendix G's outlying point at 172 °/s "
                      "without gravity.")
    summary["steady_velocity_deg_s"] = steady


def _stiction_and_idim(sec, summary, quick, rng):
    """Breakaway detection and IDIM-LS friction identification on a simulated log."""
    fz = finger(check=False, g_x=0.0, g_y=-9.81, g_z=0.0)
    pw, vel, pos = [], [], []
    for q3 in (20, 60):
        for s in (1, -1):
            x = fz.state(q=(0.0, 0.0, q3 * DEG))
            for level in range(1000, 1401, 50):
                u = np.zeros((300, 3))
                u[:150, 2] = s * level
                tr = fz.simulate(u, dt=1e-3, x0=x)
                x = fz.state(q=(tr["abd"][-1], tr["flex"][-1], tr["prox"][-1]))
                pw.append(u[:, 2])
                vel.append(tr["distal_vel"])
                pos.append(tr["prox"])
    br = detect_breakaway(np.concatenate(pw), np.concatenate(vel), np.concatenate(pos),
                          torque_at=lambda u, q: float(fz.motor_torque("distal", u, 0.0)))
    sec.text(f"Breakaway test (§6.2, Appendix C) on the simulated distal drive: breakaway PWM "
             f"{sorted({abs(r['pwm']) for r in br.breakaway})}, stiction {br.stiction:.4f} ± "
             f"{br.stiction_std:.4f} N·m (true 0.36 N·m).")
    summary["stiction_estimate"] = [br.stiction, br.stiction_std]
    fi = finger(check=False, friction="stribeck", fs_distal=0.19, fc_distal=0.19, visc_distal=0.05,
                cubic_distal=0.0, g_x=0.0, g_y=-9.81, g_z=0.0)
    N = 15_000 if quick else 30_000
    t = np.arange(N) * 1e-3
    ref = np.zeros((N, 3))
    ref[:, 1] = 30 * DEG
    ref[:, 2] = (45 + 25 * np.sin(2 * np.pi * 0.7 * t) + 10 * np.sin(2 * np.pi * 1.9 * t + 1)
                 + 5 * np.sin(2 * np.pi * 3.1 * t + 2)) * DEG
    tr = simulate_impedance(fi, ImpedanceController("joint", (10, 10, 10), (0.8, 0.8, 0.8)), ref)
    posn = np.round((tr["prox"] + rng.normal(0, 0.02 * DEG, N)) / (0.1 * DEG)) * (0.1 * DEG)
    eff = tr["tau_distal"] + rng.normal(0, 0.005, N)
    res = idim_ls(posn, eff, dt=1e-3)
    J = float(fi.chain().mass_matrix(np.array([0.0, 0.0, 45 * DEG]))[2, 2])
    truth = dict(inertia=J, viscous=0.05, coulomb=0.19, offset=0.0)
    sec.table(["parameter", "true", "IDIM-LS", "± std", "error [%]"],
              [[k, truth[k], res.params[k], res.std[k],
                100 * (res.params[k] - truth[k]) / truth[k] if truth[k]
                else "true value 0 (absolute error in ± std)"]
               for k in truth],
              caption=f"IDIM-LS (zero-phase Butterworth {res.cutoff:g} Hz, "
                      "differentiation, decimation by "
                      f"{res.decimation}) on {N / 1000:g} s of closed-loop excitation of "
                      "the distal drive; "
                      f"position quantised to 0.1° (§2.8), torque noise 5 mN·m; relative error "
                      f"{res.relative_error_percent:.2f} %.")
    summary["idim_error_percent"] = ({k: 100 * (res.params[k] - truth[k]) / truth[k]
                                      for k in ("inertia", "viscous", "coulomb")})


def _adaptation(sec, f, summary, quick):
    """Online friction adaptation on a finger whose friction drifts."""
    n = 10_000 if quick else 20_000
    ref = tracking_reference(2 * n * 1e-3)
    c = ImpedanceController("joint", (8, 8, 8), (0.6, 0.6, 0.6))
    drift = dict(scale_distal=1.3, scale_base1=1.2, scale_base2=1.25 * 0.9)
    f2 = finger(check=False, **drift)
    a = simulate_impedance(f, c, ref[:n])
    x1 = (f2.state(q=[a[j][-1] for j in ("abd", "flex", "prox")],
                   qd=[a[f"{j}_vel"][-1] for j in ("abd", "flex", "prox")]))
    b = simulate_impedance(f2, c, ref[n:], x0=x1)
    names = ("abd", "flex", "prox", "abd_vel", "flex_vel", "prox_vel", "pwm_base1", "pwm_base2",
             "pwm_distal")
    log = Trajectory.uniform(dt=1e-3, **{k_: np.concatenate([a[k_], b[k_]]) for k_ in names})
    ad, ares = adapt_finger_friction(f, log, forgetting=0.999)
    true_after = (1.2, 0.9, 1.3)
    fig, ax = _fig(1, 8.0, 3.2)
    for k_, name in enumerate(ACTUATORS):
        line, = ax[0].plot(ares.t, ares.scale[:, k_], label=name)
        ax[0].plot([0, n / 1000, n / 1000, 2 * n / 1000], [1, 1, true_after[k_], true_after[k_]],
                   ":",
                   color=line.get_color())
    ax[0].set(xlabel="time [s]", ylabel="friction scale", title="online friction adaptation "
                                                                "(RLS, λ = 0.999)")
    ax[0].legend(fontsize=8)
    sec.figure(fig, f"Friction drifts at t = {n / 1000:g} s (distal +30 %, base 1 +20 %, base 2 "
                    "−10 %) while the "
                    "finger tracks a periodic reference; dotted: true scales.", "dlr-adaptation")
    settle = [ares.settling_time(k_, true_after[k_], n / 1000) for k_ in range(3)]
    sec.table(["actuator", "settling to 5 % [s]", "final scale", "true"],
              [[name, settle[k_], float(ares.scale[-1, k_]),
                true_after[k_]] for k_, name in enumerate(ACTUATORS)],
              caption="Stated convergence time dt·ln 20/(−ln λ) = "
                      f"{ad.convergence_time():.2f} s of sliding.")
    summary["adaptation_settling_s"] = settle
    summary["adaptation_stated_s"] = ad.convergence_time()


def _loop_adaptation(sec, f, summary):
    """Friction adaptation inside the impedance loop while the plant's friction drifts."""
    T, t_step = 120.0, 60.0
    drift = warmup_drift(T).combine(stiction_step(t_step))
    c = ImpedanceController("joint", (8, 8, 8), (0.6, 0.6, 0.6))
    cmp = compare_adaptation(f, c, tracking_reference(T), drift)
    fig, ax = _fig(3, 13.0, 3.4)
    tr = cmp.runs["adaptive", "drift"]
    for a in ACTUATORS:
        line, = ax[0].plot(tr.t, tr[f"scale_hat_{a}"], "-", lw=1, label=a)
        ax[0].plot(tr.t, tr[f"drift_scale_{a}"], ":", color="k", lw=1.5)
        ax[1].plot(tr.t, tr[f"offset_hat_{a}"], "-", lw=1, color=line.get_color(), label=a)
        ax[1].plot(tr.t, tr[f"drift_offset_{a}"], ":", color="k", lw=1.5)
    ax[0].set(xlabel="time [s]", ylabel="friction scale", ylim=(0.6, 1.8),
              title="scale ŝ (dotted: plant)")
    ax[1].set(xlabel="time [s]", ylabel="offset [N·m]", ylim=(-0.1, 0.25),
              title="offset ô (dotted: plant)")
    ax[0].legend(fontsize=7)
    # 10 s windows hold whole periods of the 0.4, 0.5 and 0.7 Hz reference
    win = np.ones(10_000) / 10_000
    for (mode, plant), style in ((("fixed", "drift"), "r-"), (("adaptive", "drift"), "b-"),
                                 (("fixed", "nominal"), "k:"), (("adaptive", "nominal"), "c--")):
        r = cmp.runs[mode, plant]
        e2 = np.mean([(r[j] - r[f"ref_{j}"]) ** 2 for j in JOINTS], axis=0)
        rms = np.sqrt(np.convolve(e2, win, "valid"))
        ax[2].plot(r.t[:rms.size] + 5.0, rms / DEG, style, lw=1.2,
                   label=f"{mode}, {'drifting' if plant == 'drift' else 'nominal'} plant")
    ax[2].axvline(t_step, color="gray", lw=0.6)
    ax[2].set(xlabel="time [s]", ylabel="RMS joint error, 10 s window [°]", title="tracking error")
    ax[2].legend(fontsize=7)
    sec.figure(fig, "Online friction adaptation inside the joint impedance loop (RLS step in "
                    "the 1 kHz control "
                    "kernel, compensation ŝ·F_table + ô·sign v). The plant warms up like "
                    "Fig. 5.7 (friction "
                    "1.5× at room temperature, assumed, decaying with the 39.6 s thermal "
                    "time constant) and "
                    f"its stiction and Coulomb level step up by 0.09 N·m at {t_step:g} s; the "
                    "controller is not "
                    "told.", "dlr-loop-adaptation")
    rows = [[f"{mode}, {plant} plant", cmp.rms[mode, plant] / DEG, cmp.max[mode, plant] / DEG]
            for mode in ("fixed", "adaptive") for plant in ("nominal", "drift")]
    rows.append(["ratio fixed/adaptive, drifting plant", cmp.rms_ratio, cmp.max_ratio])
    sec.table(["compensation, plant", "RMS joint error [°]", "max joint error [°]"], rows,
              caption=(
        f"Joint tracking errors after the first {cmp.t_skip:g} s of the {T:g} s run. On the "
        f"drifting plant adaptation lowers the RMS error {cmp.rms_ratio:.2f}× and the largest "
        f"error {cmp.max_ratio:.2f}× (to {cmp.rms['adaptive', 'drift'] / DEG:.2f}°, against "
        f"{cmp.rms['fixed', 'nominal'] / DEG:.2f}° for the fixed compensation on the nominal "
        "plant); on the nominal plant it changes the RMS error by "
        f"{100 * (cmp.rms['adaptive', 'nominal'] / cmp.rms['fixed', 'nominal'] - 1):+.1f} %."))
    summary["loop_adaptation_rms_deg"] = {f"{m}/{p}": cmp.rms[m, p] / DEG for m, p in cmp.rms}
    summary["loop_adaptation_max_deg"] = {f"{m}/{p}": cmp.max[m, p] / DEG for m, p in cmp.max}
    summary["loop_adaptation_ratio"] = {"rms": cmp.rms_ratio, "max": cmp.max_ratio}


def _thermal_adaptation(sec, summary):
    """Friction adaptation with the thermal motor on: the eq 5.10 estimator against the one with
    the thermal observer's torque factor and guard (docs/dlr_hit.md)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConsistencyWarning)
        ft = finger(thermal=True)
    st = thermal_adaptation_study(ft, ImpedanceController("joint", (8, 8, 8), (0.6, 0.6, 0.6)),
                                  tracking_reference(120.0))
    rows = [[case] + [st.rms[case, m] / DEG for m in THERMAL_MODES]
            + [" ".join(f"{x:.2f}" for x in st.friction[case, m]) for m in THERMAL_MODES[1:]]
            for case in THERMAL_CASES]
    sec.table(["case", "fixed [°]", "adaptive, eq 5.10 [°]", "adaptive, thermal observer [°]",
               "F̂/F eq 5.10", "F̂/F observer"], rows,
              caption="RMS joint tracking error (after 5 s of 120 s) with the motors' thermal "
                      "model on (Fig. 5.7: the torque falls as the winding warms) and the "
                      "controller reading 0.1° angles with differentiated velocity. Fed eq 5.10 "
                      "as printed, the estimator reads the cold motor's extra torque as lower "
                      "friction (F̂/F: estimated over the plant's friction at 1 rad/s, last 10 s, "
                      "per drive base1 base2 distal) and tracking gets worse; with the thermal "
                      "observer's torque factor in its regressor, frozen while the start "
                      "temperature leaves it uncertain by more than 5 %, it beats the fixed "
                      "compensation under drift "
                      f"({st.rms['cold+drift', 'adaptive-thermal'] / DEG:.4f}° vs "
                      f"{st.rms['cold+drift', 'fixed'] / DEG:.4f}°), and its band (an estimate "
                      "applied only once settled, 3 s of sliding, and more than 20 % from the "
                      "table) keeps it equal to the fixed compensation without drift. The "
                      "estimator, the observer and the thermal model are gripkit's, not the "
                      "thesis's.")
    summary["thermal_adaptation_rms_deg"] = {f"{c}/{m}": st.rms[c, m] / DEG for c, m in st.rms}


def _impedance(sec, f, summary):
    """Joint and Cartesian impedance control against a wall."""
    N = 4000
    t = np.arange(N) * 1e-3
    ref = np.column_stack([0 * t, (30 + 20 * np.sin(2 * np.pi * 0.5 * t)) * DEG,
                           (30 + 20 * np.sin(2 * np.pi * 0.5 * t + 1)) * DEG])
    fig, ax = _fig(2)
    track = {}
    for comp, style in ((True, "-"), (False, "--")):
        cj = ImpedanceController("joint", (5, 5, 5), (0.5, 0.5, 0.5), friction_compensation=comp)
        trj = simulate_impedance(f, cj, ref)
        e = np.column_stack([trj["flex"] - ref[:, 1], trj["prox"] - ref[:, 2]])[1000:]
        track[comp] = float(np.sqrt(np.mean(e ** 2)) / DEG)
        ax[0].plot(trj.t, (trj["prox"] - ref[:, 2]) / DEG, style,
                   label=f"compensation {'on' if comp else 'off'}")
    ax[0].set(xlabel="time [s]", ylabel="proximal error [°]", title="joint impedance, free motion")
    ax[0].legend(fontsize=8)
    q0 = (0.0, 30 * DEG, 45 * DEG)
    ch = f.chain()
    tip0 = ch.tip_position(np.linalg.solve(ch.coupling.matrix[:3], np.array(q0)))
    K, kw, depth = 1000.0, 3000.0, 0.005
    wall = Wall((0, 0, 1), (0, 0, tip0[2] - 0.01), kw, 2.0)
    Nc = 5000
    tc = np.arange(Nc) * 1e-3
    xd = np.tile(tip0, (Nc, 1))
    xd[:, 2] = tip0[2] - (0.01 + depth) * np.clip(tc / 2.0, 0, 1)
    expect = K * kw / (K + kw) * depth
    force = {}
    for comp, style in ((True, "-"), (False, "--")):
        cc = ImpedanceController("cartesian", (K, K, K), (1.4 * math.sqrt(K * 4.4),) * 3,
                                 friction_compensation=comp, actuator_damping=(0.3, 0.3, 0.3))
        trc = simulate_impedance(f, cc, xd, x0=f.state(q=q0), wall=wall)
        force[comp] = float(trc["force_z"][-1])
        ax[1].plot(trc.t, trc["force_z"], style, label=f"compensation {'on' if comp else 'off'}")
    ax[1].axhline(expect, color="gray", ls=":", label="K·k_w/(K+k_w)·δ")
    ax[1].set(xlabel="time [s]", ylabel="contact force [N]",
              title="Cartesian impedance against a wall")
    ax[1].legend(fontsize=8)
    sec.figure(fig, "Impedance control (eq 3.1) with gravity and friction compensation: "
                    "tracking a 0.5 Hz "
                    f"motion, and pressing on a {kw:g} N/m wall with K = {K:g} N/m, set point "
                    f"{1e3 * depth:g} mm "
                    "behind it.", "dlr-impedance")
    free = (impedance_margins(f, ImpedanceController("joint", (5, 5, 5), (0.5, 0.5, 0.5)),
                              q=(0.0, 30 * DEG, 30 * DEG)))
    cont = impedance_margins(f, ImpedanceController("cartesian", (K, K, K),
                                                    (1.4 * math.sqrt(K * 4.4),) * 3,
                                                    actuator_damping=(0.3, 0.3, 0.3)), q=q0,
                                                    wall=wall)
    sec.table(["case", "actuator", "gain margin", "phase margin [°]", "crossover [Hz]", "stable"],
              [["joint, free", m["actuator"], m["gain_margin"], m["phase_margin_deg"],
                m["gain_crossover_hz"], m["stable"]]
               for m in free]
              + [["Cartesian, wall", m["actuator"], m["gain_margin"], m["phase_margin_deg"],
                  m["gain_crossover_hz"],
                  m["stable"]] for m in cont],
              caption="Stability margins of the linearised loops (ZOH at 1 kHz, one "
                      "sample of delay).")
    sec.table(["experiment", "compensation on", "compensation off"],
              [["RMS tracking error [°]", track[True], track[False]],
               [f"contact force [N] (expected {expect:.2f})", force[True], force[False]],
               ["force error [%]", 100 * (force[True] - expect) / expect,
                100 * (force[False] - expect) / expect]],
              caption="Friction compensation on vs off: stiction (0.36 N·m per drive) stops "
                      "the uncompensated "
                      "finger before it reaches the wall.")
    summary["tracking_rms_deg"] = track
    summary["contact_force_N"] = {"expected": expect, "on": force[True], "off": force[False]}


def _hand(sec, summary):
    """The five-finger hand (§3.1)."""
    h = hand(check=False, scales={"thumb": {"distal": 1.3}, "little": {"distal": 0.8}})
    uh = np.tile([0.0, 0.0, 3000.0] * 5, (600, 1))
    trh = h.simulate(uh, dt=1e-3)
    tips = h.fingertips(trh)
    fig, ax = _fig(1, 5.5, 4.0)
    for name, p in tips.items():
        ax[0].plot(1e3 * p[:, 0], 1e3 * p[:, 1], "-", label=name)
        ax[0].plot(1e3 * p[-1, 0], 1e3 * p[-1, 1], "k.")
    ax[0].set(xlabel="palm x [mm]", ylabel="palm y [mm]", title="five fingers closing (PWM 3000)",
              aspect="equal")
    ax[0].legend(fontsize=7)
    sec.figure(fig, "The hand (§3.1): five fingers from the finger model on assumed palm frames, "
                    "the thumb fixed "
                    "in an opposing orientation; the thumb's distal friction is 30 % "
                    "above, the little "
                    "finger's 20 % below the measured finger (§6.3: friction differs from "
                    "finger to finger).",
               "dlr-hand")
