"""Demo section: Monte Carlo grasp robustness of the TSFM two-finger grasp (seed
``001_0b92a7da96e7aa46.txt`` §I, §V) — a population of microparts (stiffness 10-1000 N/m, width,
position, approach speed, sensor noise), the probability of damaging or losing a part and the
settling-time distribution, with confidence intervals; the hold strategy against the naive grasp."""

from __future__ import annotations

import time
from dataclasses import asdict

from ..systems.tsfm.grasp_batch import FAST_GRASP
from ..systems.tsfm.robustness import DEFAULT_POPULATION, DEFAULT_SETTINGS, robustness_study


def run(report, *, quick: bool = False) -> dict:
    n = 120 if quick else 400
    t0 = time.perf_counter()
    hold = robustness_study(n=n, seed=1, backend="in-process", progress=True, name="demo-hold")
    naive = robustness_study(n=n, seed=1, backend="in-process", progress=True, name="demo-naive",
                             settings={**DEFAULT_SETTINGS, "wait_for_other": False})
    seconds = time.perf_counter() - t0
    pop = "; ".join(f"{k} {next(iter(v))} "
                    f"{v[next(iter(v))]}" for k, v in DEFAULT_POPULATION.items())
    s = FAST_GRASP
    intro = (f"{n} closed-loop grasps of the TSFM gripper (both fingers of Table II, eq-11 "
             "position estimates from "
             "voltage and force, contact detection at 5 µN, the §I strategy: the finger that "
             "touches first holds "
             f"until the other touches, then both squeeze to {s.grip_force * 1e6:.0f} µN) on parts "
             f"drawn from: {pop}. "
             f"Controller: approach {s.approach_speed * 1e3:g} mm/s (drawn per part), force ramp "
             f"{s.force_ramp_time * 1e3:g} ms, force loop {s.force_bandwidth_hz:g} "
             "Hz, position loop "
             f"{s.position_bandwidth_hz:g} Hz; 0.15 s at 20 kHz per grasp. Damage: a contact "
             "force above 250 µN; "
             "lost: not held by both fingers at the end, or pushed more than 10 µm on the "
             "substrate (20 µN "
             "friction); settling: the grip force within ±5 % of the command, timed from the "
             "second contact. "
             "Probabilities with Wilson intervals, quantiles with order-statistic intervals "
             "(grasps that never "
             f"settle count as +∞). Both studies ran in {seconds:.1f} s in-process "
             f"(`gripkit.systems.tsfm.robustness`; "
             "the same study as a checkpointed sweep: `gripkit sweep "
             "examples/sweep_tsfm_robustness.toml`).")
    hold.report(report, "Batch: Monte Carlo grasp robustness (TSFM, hold strategy)", intro)
    sec = naive.report(report, "Batch: the naive grasp on the same population",
                       "The same parts and noise with wait_for_other=False: the first finger keeps "
                       "closing until the "
                       "second touches, pushing the part "
                       "across the substrate.", name="batch-robustness-naive")
    sec.table(["controller", "P(damage)", "P(lost)", "settling median (ms)"],
              [[name, f"{r.p_damage.value:.3f} [{r.p_damage.low:.3f}, {r.p_damage.high:.3f}]",
                f"{r.p_lost.value:.3f} [{r.p_lost.low:.3f}, {r.p_lost.high:.3f}]",
                f"{r.settling_median.value * 1e3:.1f} [{r.settling_median.low * 1e3:.1f}, "
                f"{r.settling_median.high * 1e3:.1f}]"] for name, r in (("hold (§I)", hold),
                                                                        ("naive", naive))],
              caption="Hold strategy vs naive grasp (95 % intervals)")
    return {"n": n, "seconds": round(seconds, 2), "settings": asdict(FAST_GRASP),
            "hold": {k: v for k, v in hold.summary().items() if not k.endswith("stiffness")},
            "naive": {k: v for k, v in naive.summary().items() if not k.endswith("stiffness")}}
