"""Monte Carlo grasp robustness of the TSFM two-finger grasp (``001_0b92a7da96e7aa46.txt`` §I,
§V): for the gripper, its grasp controller and a micropart population, the probability of
damaging the part, of losing it, and the distribution of the settling time, each with a
confidence interval, and the probabilities against the part's stiffness.

>>> from gripkit.systems.tsfm.robustness import robustness_study
>>> res = robustness_study(n=400, backend="in-process")            # doctest: +SKIP
>>> print(res.p_damage, res.p_lost, res.settling_median)          # doctest: +SKIP

The study is a sweep (:func:`gripkit.batch.sweep`): any backend, checkpointing, resume, per-job
failure records. Statistics (:mod:`gripkit.batch.montecarlo`, the generic part): Wilson
intervals for the probabilities, order-statistic intervals for the settling-time quantiles
(grasps that never settle count as +inf, so they push the quantiles up instead of being
dropped), Wilson intervals per stiffness bin. Failed jobs (errors) are excluded and counted.

The same numbers come from ``gripkit sweep examples/sweep_tsfm_robustness.toml`` followed by
:func:`analyse` on the result folder's table.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...arguments import entry_point
from ...batch.montecarlo import Estimate, binned_probability, probability, quantile
from ...batch.spec import SweepSpec
from ...batch.store import ResultStore
from ...batch.sweep import sweep
from ...errors import ConfigError, DataError
from ...units import to_si

__all__ = (["DEFAULT_POPULATION", "DEFAULT_SETTINGS", "RobustnessResult", "robustness_study",
            "analyse"])

#: parts between the TSFM fingers (400 µm gap): stiffness over Table III's range and beyond,
#: widths leaving 10-80 µm of travel, off-centre by up to 10 µm, contact timing through the
#: approach speed, force-sensor noise around the seed's < 2 µN
DEFAULT_POPULATION = {
    "k_e": {"loguniform": ["10 N/m", "1000 N/m"]},
    "w": {"uniform": ["320 um", "380 um"]},
    "offset": {"uniform": ["-10 um", "10 um"]},
    "approach_speed": {"uniform": ["1 mm/s", "2 mm/s"]},
    "noise_std": {"uniform": ["0.5 uN", "3 uN"]},
}
# : the controller (:data:`gripkit.systems.tsfm.grasp_batch.FAST_GRASP`, 200 µN) and the pass
# criteria
DEFAULT_SETTINGS = {"duration": 0.15, "grip_force": "200 uN", "damage_force": "250 uN",
                    "lost_displacement": "10 um", "band": 0.05}


@dataclass
class RobustnessResult:
    """The study's estimates; ``columns`` holds every job's parameters and metrics."""

    columns: dict[str, np.ndarray]
    n: int
    n_failed: int
    p_damage: Estimate
    p_lost: Estimate | None
    p_not_settled: Estimate
    settling_median: Estimate
    settling_q90: Estimate
    peak_median: Estimate
    stiffness: str
    damage_vs_stiffness: list[dict]
    lost_vs_stiffness: list[dict]
    damage_force: float | None = None
    seconds: float = math.nan
    backend: str = ""
    notes: list[str] = field(default_factory=list)

    def summary(self) -> dict:
        """Numbers for reports and JSON (probabilities, times in s, forces in N)."""
        def est(e):
            return None if e is None else {"value": e.value, "low": e.low, "high": e.high, "n": e.n}

        return {"n": self.n, "n_failed": self.n_failed, "p_damage": est(self.p_damage),
                "p_lost": est(self.p_lost),
                "p_not_settled": est(self.p_not_settled),
                "settling_median_s": est(self.settling_median),
                "settling_q90_s": est(self.settling_q90),
                "peak_force_median_N": est(self.peak_median),
                "damage_vs_stiffness": self.damage_vs_stiffness,
                "lost_vs_stiffness": self.lost_vs_stiffness,
                "seconds": self.seconds, "backend": self.backend}

    def report(self, report, title: str = "Monte Carlo grasp robustness", intro: str = "",
               name: str = "batch-robustness"):
        """Add a section: the estimates as a table, histograms of the peak force and of the settling
        time, and P(damage), P(lost) against stiffness with their confidence bands."""
        from ...report.plots import plain, pyplot

        plt = pyplot()
        sec = report.section(title, intro)
        rows = [["P(damage)", _fmt_p(self.p_damage)]]
        if self.p_lost is not None:
            rows.append(["P(lost)", _fmt_p(self.p_lost)])
        rows += [["P(not settled within the record)", _fmt_p(self.p_not_settled)],
                 ["settling time, median", _fmt_t(self.settling_median)],
                 ["settling time, 90 % quantile", _fmt_t(self.settling_q90)],
                 ["peak contact force, median", f"{self.peak_median.value * 1e6:.1f} µN "
                                                f"[{self.peak_median.low * 1e6:.1f}, "
                                                f"{self.peak_median.high * 1e6:.1f}]"]]
        sec.table(["quantity", f"estimate [{100 * self.p_damage.confidence:.0f} % CI]"], rows,
                  caption=f"{self.n} grasps ({self.n_failed} failed jobs excluded)")
        c = self.columns
        ok = _ok(c)
        fig, ax = plt.subplots(1, 3, figsize=(14, 3.7))
        peak = c["peak_force"][ok] * 1e6
        ax[0].hist(peak, bins=40, color="C0", alpha=0.8)
        if self.damage_force is not None:
            ax[0].axvline(self.damage_force * 1e6, color="C3",
                          label=f"damage ({self.damage_force * 1e6:.0f} µN)")
            ax[0].legend()
        ax[0].set_xlabel("peak contact force (µN)")
        ax[0].set_ylabel("grasps")
        st = c["settling_time"][ok]
        fin = st[np.isfinite(st)] * 1e3
        ax[1].hist(fin, bins=40, color="C2", alpha=0.8,
                   label=f"settled ({fin.size}); never: {int(np.isinf(st).sum())}")
        for e, label, ls in ((self.settling_median, "median", "-"),
                             (self.settling_q90, "90 %", "--")):
            if math.isfinite(e.value):
                ax[1].axvline(e.value * 1e3, color="k", ls=ls,
                              label=f"{label} {e.value * 1e3:.1f} ms")
        ax[1].set_xlabel("settling time of the grip force (ms)")
        ax[1].legend(fontsize=8)
        for rows_, label, col in ((self.damage_vs_stiffness, "P(damage)", "C3"),
                                  (self.lost_vs_stiffness, "P(lost)", "C1")):
            if not rows_:
                continue
            x = np.array([math.sqrt(r["low"] * r["high"]) for r in rows_])
            p = np.array([r["p"] for r in rows_])
            lo = np.array([r["p_low"] for r in rows_])
            hi = np.array([r["p_high"] for r in rows_])
            ax[2].fill_between(x, lo, hi, color=col, alpha=0.2)
            ax[2].plot(x, p, "o-", color=col,
                       label=f"{label} ({100 * self.p_damage.confidence:.0f} % band)")
        ax[2].set_xscale("log")
        from matplotlib.ticker import NullFormatter

        ax[2].xaxis.set_minor_formatter(NullFormatter())
        ax[2].set_ylim(-0.02, 1.02)
        ax[2].set_xlabel(plain(f"{self.stiffness} (N/m)"))
        ax[2].set_ylabel("probability")
        ax[2].legend(fontsize=8)
        fig.tight_layout()
        sec.figure(fig, "Peak contact force and settling time over the population; "
                        "probabilities against the "
                        "object's stiffness (Wilson intervals per bin)", name=name)
        return sec


def _fmt_p(e: Estimate) -> str:
    return f"{e.value:.3f} [{e.low:.3f}, {e.high:.3f}]"


def _fmt_t(e: Estimate) -> str:
    def f(v):
        return "∞" if math.isinf(v) else f"{v * 1e3:.1f}"

    return f"{f(e.value)} ms [{f(e.low)}, {f(e.high)}]"


def _ok(c: dict) -> np.ndarray:
    err = c.get("error")
    ok = np.ones(len(c["job_id"]) if "job_id" in c else len(c["peak_force"]), bool)
    if err is not None:
        ok &= np.array([e is None for e in err])
    return ok & np.isfinite(c["peak_force"])


def analyse(columns: dict | str | Path, *, stiffness: str | None = None, bins=None,
            confidence: float = 0.95,
            damage_force: float | None = None) -> RobustnessResult:
    """Robustness statistics from a sweep's table (a dict of columns, a :class:`SweepResult`, or
    the output folder of ``gripkit sweep``). Needs the metrics ``damage``, ``peak_force`` and
    ``settling_time``; ``lost`` when present. ``stiffness``: the column to bin by (default
    ``k_e``, or ``k0`` for the FT-G100); ``bins``: edges (default 6 log-spaced bins over its
    range)."""
    if isinstance(columns, (str, Path)):
        columns = ResultStore(columns).read()
    elif hasattr(columns, "columns") and not isinstance(columns, dict):
        columns = columns.columns
    c = {k: np.asarray(v) for k, v in columns.items()}
    missing = [m for m in ("damage", "peak_force", "settling_time") if m not in c]
    if missing:
        raise DataError(f"robustness analysis: the table lacks the metrics {missing}",
                        hint="run the 'tsfm-grasp' or 'ftg100-grasp' scenario")
    ok = _ok(c)
    n = int(ok.sum())
    if n == 0:
        raise DataError("robustness analysis: no successful grasp in the table")
    if stiffness is None:
        stiffness = next((s for s in ("k_e", "k0") if s in c), None)
    st = c["settling_time"][ok].astype(float)
    res_bins: tuple[list, list] = ([], [])
    if stiffness is not None:
        if stiffness not in c:
            raise DataError("robustness analysis: no "
                            f"column {stiffness!r}", hint=f"columns: {', '.join(c)}")
        k = c[stiffness][ok].astype(float)
        if bins is None:
            lo, hi = float(k.min()), float(k.max())
            bins = (np.geomspace(lo, hi * (1 + 1e-12),
                                 7) if lo > 0 and hi > lo else np.array([lo, hi + 1.0]))
        res_bins = (binned_probability(k, c["damage"][ok], bins, confidence),
                    binned_probability(k, c["lost"][ok], bins, confidence) if "lost" in c else [])
    return RobustnessResult(
        columns=c, n=n, n_failed=int((~ok).sum()),
        p_damage=probability(c["damage"][ok], confidence),
        p_lost=probability(c["lost"][ok], confidence) if "lost" in c else None,
        p_not_settled=probability(np.isinf(st), confidence),
        settling_median=quantile(st, 0.5, confidence), settling_q90=quantile(st, 0.9, confidence),
        peak_median=quantile(c["peak_force"][ok], 0.5, confidence), stiffness=stiffness or "",
        damage_vs_stiffness=res_bins[0], lost_vs_stiffness=res_bins[1], damage_force=damage_force)


@entry_point
def robustness_study(population: dict | None = None, *, settings: dict | None = None, n: int = 600,
                     seed: int = 1, model: str | None = "tsfm-gripper",
                     scenario: str = "tsfm-grasp",
                     backend: str = "in-process", workers: int | None = None,
                     scheduler: str | None = None,
                     out=None, resume: bool = False, bins=None, confidence: float = 0.95,
                     progress: bool = True, name: str = "grasp-robustness",
                     allow_code: bool = False) -> RobustnessResult:
    """Run ``n`` grasps of ``scenario`` on ``model`` for objects drawn from ``population`` (sweep
    ``[parameters]`` entries; default :data:`DEFAULT_POPULATION`) with the controller and pass
    criteria ``settings`` (the sweep's ``[scenario]`` table; default :data:`DEFAULT_SETTINGS`), and
    analyse them (:func:`analyse`). ``backend``, ``allow_code`` etc. as in
    :func:`gripkit.batch.sweep`."""
    if n < 1:
        raise ConfigError(f"n: expected a positive number of grasps, found {n}")
    pop = dict(DEFAULT_POPULATION if population is None else population)
    sett = (dict(DEFAULT_SETTINGS if settings is None and scenario == "tsfm-grasp"
                 else (settings or {})))
    spec = SweepSpec.from_dict({"sweep": {"name": name, "scenario": scenario, "model": model,
                                          "samples": int(n),
                                          "seed": int(seed)},
                                "parameters": pop, "scenario": sett})
    if len(spec.jobs()["job_id"]) != n:
        raise ConfigError("population: use random draws (uniform, normal, loguniform) only: grids "
                          "would multiply n")
    res = sweep(spec, backend=backend, workers=workers, scheduler=scheduler, out=out, resume=resume,
                progress=progress, allow_code=allow_code)
    dmg = sett.get("damage_force", sett.get("damage_threshold"))
    dmg = to_si(dmg)[0] if isinstance(dmg, str) else (None if dmg is None else float(dmg))
    out_ = analyse(res.columns, bins=bins, confidence=confidence, damage_force=dmg)
    out_.seconds, out_.backend = res.seconds, res.backend
    return out_
