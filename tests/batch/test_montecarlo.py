"""Monte Carlo statistics (the generic part of a robustness study) on synthetic populations whose
true probabilities and quantiles are known: coverage of the Wilson and order-statistic intervals."""

import math

import numpy as np
import pytest
from scipy import stats

from gripkit.batch.montecarlo import binned_probability, probability, quantile
from gripkit.errors import ArgumentError, DataError


@pytest.mark.parametrize("p", [0.02, 0.2, 0.5])
def test_wilson_interval_covers_the_true_probability_95_percent_of_the_time(p):
    """2000 synthetic studies of n = 150 Bernoulli(p) outcomes: the 95 % Wilson interval contains
    p in 95 % of them (within the Monte Carlo error, ±1.5 %; the exact coverage of the Wilson
    interval oscillates around the nominal value)."""
    rng = np.random.default_rng(int(p * 1000))
    hits = 0
    for _ in range(2000):
        e = probability(rng.random(150) < p)
        hits += e.low <= p <= e.high
    assert 0.925 <= hits / 2000 <= 0.975


@pytest.mark.parametrize("q", [0.5, 0.9])
def test_quantile_interval_covers_the_true_quantile(q):
    """Exponential(1) samples (true q-quantile −ln(1 − q)): the order-statistic interval is
    distribution-free and conservative: coverage ≥ 95 % up to the Monte Carlo error."""
    rng = np.random.default_rng(11)
    truth = -math.log(1 - q)
    cover = np.mean([(lambda e: e.low <= truth <= e.high)(quantile(rng.exponential(size=200), q))
                     for _ in range(1000)])
    assert 0.935 <= cover <= 0.99


def test_quantiles_count_never_settled_as_infinite():
    x = np.r_[np.linspace(1.0, 2.0, 70), np.full(30, np.inf), [np.nan] * 5]
    assert quantile(x, 0.5).value == pytest.approx(1.0 + 49 / 69)
    e = quantile(x, 0.9)
    assert math.isinf(e.value) and math.isinf(e.high)
    assert probability(np.isinf(x[~np.isnan(x)])).value == pytest.approx(0.3)


def test_binned_probability_recovers_a_known_dose_response():
    """P(damage | k) = logistic((ln k − ln 300)/0.3) over log-uniform k: in every bin the 95 %
    interval contains the bin's true mean probability (computed by quadrature)."""
    rng = np.random.default_rng(3)
    k = np.exp(rng.uniform(np.log(10), np.log(1000), 6000))
    pk = stats.logistic.cdf((np.log(k) - np.log(300)) / 0.3)
    flags = rng.random(k.size) < pk
    edges = np.geomspace(10, 1000, 7)
    rows = binned_probability(k, flags, edges)
    assert len(rows) == 6
    inside = 0
    for r in rows:
        # k log-uniform: uniform in ln k
        u = np.linspace(np.log(r["low"]), np.log(r["high"]), 2001)
        truth = stats.logistic.cdf((u - np.log(300)) / 0.3).mean()
        inside += r["p_low"] <= truth <= r["p_high"]
    assert inside >= 5   # each interval misses with probability 5 %
    assert rows[0]["p"] < 0.05 and rows[-1]["p"] > 0.9


@pytest.mark.parametrize("flags, phrase", [
    ([0.3, 0.7, 0.2], r"found 3 other values \(first 0.3 at index 0\)"),
    ([-1, 1, 1], r"found 1 other values \(first -1 at index 0\)"),
    ([2, 2, 2], r"first 2 at index 0"),
    ([1.0, np.nan, 0.5], r"found 1 other values \(first 0.5 at index 2\)"),
    (["yes", "no"], "found text values"),
    ([1j, 0], "found complex values"),
])
def test_probability_needs_outcomes_of_trials(flags, phrase):
    """A Wilson interval is for k successes in n trials: anything but True/False, 1/0 (or NaN,
    a run without an outcome) is refused instead of summed (−1 + 1 + 1 = 1 "success" in 3)."""
    with pytest.raises(DataError, match=r"^flags: expected outcomes True/False or 1/0.*" + phrase):
        probability(flags)


@pytest.mark.parametrize("call, phrase", [
    (lambda: probability([True, False], confidence=1.5), "confidence: .* strictly between 0 and 1"
                                                         ", found 1.5"),
    (lambda: probability([True, False], confidence=95), "found 95; a level, not a percentage"),
    (lambda: probability([True], confidence=math.nan), "found nan"),
    (lambda: quantile([1.0, 2.0], 0.5, confidence=2), "confidence: .*found 2"),
    (lambda: quantile([1.0, 2.0], 1.5), "q: expected a number from 0 to 1, found 1.5"),
    (lambda: quantile([1.0, 2.0], -0.1), "q: .*found -0.1"),
    (lambda: quantile([1.0, 2.0], True), "q: .*found True"),
])
def test_levels_are_checked(call, phrase):
    with pytest.raises(ArgumentError, match=phrase):
        call()


def test_quantile_levels_zero_and_one_and_the_interval_label():
    """q = 0 and q = 1 are the least and the greatest value; the population's lie beyond them,
    so the intervals reach −inf and +inf (binomial(n, 0) and binomial(n, 1) order statistics).
    The label gives the confidence as a percentage with its decimals."""
    x = np.arange(10.0)
    least, greatest = quantile(x, 0.0), quantile(x, 1.0)
    assert (least.value, least.low, least.high) == (0, -math.inf, 0)
    assert (greatest.value, greatest.low, greatest.high) == (9, 9, math.inf)
    assert "(99.5 % CI, n=4)" in str(probability([1, 0, 1, 1], confidence=0.995))
    assert probability([True, False, np.nan, 1.0]).n == 3  # NaN: a run without an outcome


@pytest.mark.parametrize("bad", [np.inf, -np.inf, 0.5])
def test_binned_probability_refuses_what_probability_refuses_at_the_callers_index(bad):
    """±inf (or 0.5) among the flags is not the outcome of a trial: refused as probability refuses
    it (±inf was dropped with NaN before), the index being the entry's in the caller's array (8),
    not its place in its bin's subset (3)."""
    flags = np.zeros(10)
    flags[8] = bad
    with pytest.raises(DataError, match=rf"found 1 other values \(first {bad:g} at index 8\)"):
        binned_probability(np.arange(10.0), flags, [0, 5, 10])
    with pytest.raises(DataError, match=r"first .* at index 8\)"):
        probability(flags)
    with pytest.raises(DataError, match=r"one outcome per value of x \(10\), found 9"):
        binned_probability(np.arange(10.0), np.zeros(9), [0, 5, 10])


def _ranks(n, q, confidence):
    """(l, u) of quantile's interval on 1 … n (rank 0: −inf, n + 1: +inf)."""
    e = quantile(np.arange(1.0, n + 1), q, confidence)
    return (0 if math.isinf(e.low) else int(e.low)), (n + 1 if math.isinf(e.high) else int(e.high))


def test_quantile_point_lies_in_its_interval_at_extreme_levels():
    """Review case: the 0.999 quantile of 1 … 100 at 50 % was 99.9 in [100, inf]. The interval is
    widened to the order statistic below the point, x(99) = 99; the point is numpy's linear one."""
    e = quantile(np.arange(1, 101), 0.999, 0.5)
    assert e.value == pytest.approx(99.901) and (e.low, e.high) == (99.0, math.inf)
    low = quantile(np.arange(1, 101), 0.001, 0.5)
    assert low.value == pytest.approx(1.099) and (low.low, low.high) == (-math.inf, 2.0)
    # numpy's a + (b - a) g overflowed to -inf between -1e308 and 1e308: the midpoint is 0
    assert quantile([-1e308, 1e308], 0.5).value == 0.0


@pytest.mark.parametrize("n, q, confidence", [(100, 0.999, 0.5), (20, 0.9, 0.9), (15, 0.02, 0.6)])
def test_quantile_interval_coverage_matches_its_binomial_value(n, q, confidence):
    """Distribution-free order-statistic interval (Hahn & Meeker 1991, §5.2): for ranks (l, u) its
    coverage is P(l ≤ B ≤ u − 1), B ~ binomial(n, q), whatever the continuous distribution. That
    exact value is ≥ the confidence (also where the interval was widened to hold the point, the
    first case: 0.9954 instead of 0.905), and 2000 seeded studies of exponential samples (true
    quantile −ln(1 − q)) cover it as often, within 4 Monte Carlo σ."""
    lo, hi = _ranks(n, q, confidence)
    exact = stats.binom.cdf(hi - 1, n, q) - stats.binom.cdf(lo - 1, n, q)
    assert exact >= confidence
    rng = np.random.default_rng(n)
    truth = -math.log(1 - q)
    hits = 0
    for _ in range(2000):
        e = quantile(rng.exponential(size=n), q, confidence)
        hits += e.low <= truth <= e.high
    assert abs(hits / 2000 - exact) <= 4 * math.sqrt(exact * (1 - exact) / 2000) + 1e-3


def test_quantile_point_lies_in_its_interval_for_any_sample():
    """Property (hypothesis): for any sample (±inf and ties included), level and confidence, the
    point estimate lies in its interval and the interval's ends are ordered."""
    import hypothesis  # a dependency of the tests (pyproject.toml)
    st = hypothesis.strategies

    @hypothesis.settings(max_examples=300, deadline=None, derandomize=True)
    @hypothesis.given(st.lists(st.floats(allow_nan=False), min_size=1, max_size=60),
                      st.floats(0.0, 1.0), st.floats(0.01, 0.99))
    def check(x, q, confidence):
        e = quantile(np.array(x), q, confidence)
        assert e.low <= e.value <= e.high

    check()
