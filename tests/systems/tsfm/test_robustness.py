"""The TSFM grasp robustness study (:mod:`gripkit.systems.tsfm.robustness`): its analysis of a
synthetic sweep table with exact proportions, and the study end to end."""

import math

import numpy as np
import pytest

from gripkit.systems.tsfm.robustness import analyse, robustness_study


def test_analyse_a_synthetic_table():
    """A table with exact proportions (shuffled): P(damage) = 0.3, P(lost) = 0.1, settling times
    evenly spread over (0, 10 ms) with 20 % never settling, so the median is at 5/8 of 10 ms;
    three failed jobs (NaN metrics, an error) are excluded and counted."""
    rng = np.random.default_rng(8)
    n = 4000

    def exact(frac):
        return rng.permutation(np.arange(n) < frac * n).astype(float)

    st = rng.permutation(np.r_[np.linspace(0, 0.01, int(0.8 * n)), np.full(int(0.2 * n), np.inf)])
    err = np.full(n + 3, None, dtype=object)
    err[n:] = "ValueError: part slipped"
    tab = {"job_id": np.arange(n + 3), "k_e": np.exp(rng.uniform(np.log(10), np.log(1000), n + 3)),
           "damage": np.r_[exact(0.3), [np.nan] * 3], "lost": np.r_[exact(0.1), [np.nan] * 3],
           "peak_force": np.r_[rng.uniform(1e-4, 3e-4, n), [np.nan] * 3],
           "settling_time": np.r_[st, [np.nan] * 3],
           "error": err}
    r = analyse(tab)
    assert r.n == n and r.n_failed == 3
    for e, p in ((r.p_damage, 0.3), (r.p_lost, 0.1), (r.p_not_settled, 0.2)):
        assert e.value == pytest.approx(p) and e.low < p < e.high and e.high - e.low < 0.04
    assert r.settling_median.value == pytest.approx(0.01 * 0.5 / 0.8, rel=1e-3)
    assert math.isinf(r.settling_q90.value)
    assert len(r.damage_vs_stiffness) == 6 and sum(row["n"] for row in r.damage_vs_stiffness) == n


def test_robustness_study_end_to_end():
    """A small TSFM study (60 grasps of the default population): the hold strategy loses no part,
    the stiffest third is damaged more often than the softest third (none of which is), and the
    report section renders."""
    from gripkit.report import Report

    r = robustness_study(n=60, seed=4, backend="in-process", progress=False)
    assert r.n == 60 and r.n_failed == 0
    assert r.p_lost.value == 0.0 and r.p_lost.high < 0.07
    k = r.columns["k_e"]
    soft, stiff = k < np.quantile(k, 1 / 3), k > np.quantile(k, 2 / 3)
    assert r.columns["damage"][soft].sum() == 0
    assert r.columns["damage"][stiff].mean() > r.columns["damage"][soft].mean()
    assert r.settling_median.low <= r.settling_median.value <= r.settling_median.high
    rep = Report("t")
    sec = r.report(rep)
    assert [kind for kind, _ in sec.items] == ["table", "figure"]
