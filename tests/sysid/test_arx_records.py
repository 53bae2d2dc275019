"""ARX fitted to several records at once (issue 25): each record with its own initial
conditions, one θ and one σ from all of them; the truth is the Table II [2 2 2] model of
000_8f66dcc7ab06470c.txt (A222, B222), simulated from known initial conditions."""

import sys

import numpy as np
import pytest
from arx_cases import A222, B222, THETA222

from gripkit import Trajectory
from gripkit.errors import ArgumentError, DataError
from gripkit.sysid import arx, arx_records, identify
from gripkit.sysid.linear.arx_mimo import arx_mimo, arx_mimo_records
from gripkit.sysid.regression import arx_regression

#: static gain B(1)/A(1) of the [2 2 2] model: an operating point (u0, G·u0) is an equilibrium
GAIN222 = B222.sum() / A222.sum()


def simulate(n, *, seed, y_init=(0.0, 0.0), noise=2.0, u0=0.0):
    """The [2 2 2] ARX around the equilibrium (u0, G·u0), started from the deviations
    ``y_init`` (y(0), y(1)) and u = u0 before the record: A y = B u + e, sample by sample."""
    rng = np.random.default_rng(seed)
    du = 100.0 * rng.standard_normal(n)
    e = noise * rng.standard_normal(n)
    dy = np.zeros(n)
    dy[:2] = y_init
    for t in range(2, n):
        dy[t] = -A222[1] * dy[t - 1] - A222[2] * dy[t - 2] + B222[2] * du[t - 2] + e[t]
        if t >= 3:
            dy[t] += B222[3] * du[t - 3]
    return du + u0, dy + GAIN222 * u0


def test_one_record_is_arx_bit_for_bit():
    u, y = simulate(3000, seed=1, y_init=(40.0, 35.0))
    a, b = arx(u, y, 2, 2, 2), arx_records([(u, y)], 2, 2, 2)
    np.testing.assert_array_equal(a.theta, b.theta)
    np.testing.assert_array_equal(a.covariance, b.covariance)
    assert (a.noise_variance, a.loss, a.n_used) == (b.noise_variance, b.loss, b.n_used)
    assert b.fit_percent == pytest.approx(a.fit_percent, rel=1e-13)


def test_equals_least_squares_of_the_stacked_rows_no_row_crosses_a_seam():
    """The solution is numpy's lstsq of each record's own regression rows stacked (rows t = 3 …
    N_i − 1 of every record), σ² = RSS/(Σ M_i − p)."""
    recs = [simulate(700, seed=2, y_init=(50.0, 45.0)),
            simulate(1300, seed=3, y_init=(-60.0, -20.0)),
            simulate(40, seed=4, y_init=(10.0, 0.0))]
    m = arx_records(recs, 2, 2, 2)
    X = np.vstack([arx_regression(u, y, 2, 2, 2) for u, y in recs])
    theta, rss = np.linalg.lstsq(X[:, :4], X[:, 4], rcond=None)[:2]
    np.testing.assert_allclose(m.theta, theta, rtol=1e-10)
    M = 700 + 1300 + 40 - 3 * 3
    assert m.n_used == M and m.n_samples == 2040
    assert m.noise_variance == pytest.approx(rss[0] / (M - 4), rel=1e-9)
    cov = m.noise_variance * np.linalg.inv(X[:, :4].T @ X[:, :4])
    np.testing.assert_allclose(m.covariance, cov, rtol=1e-8)
    assert [r["n_used"] for r in m.info["records"]] == [697, 1297, 37]
    assert m.info["record_starts"] == [0, 697, 1994] and m.estimation_residuals.size == M


def test_summed_normal_equations_agree_with_qr(monkeypatch):
    """Above QR_MAX_ELEMENTS the records' Gram matrices are summed: the same θ and σ."""
    recs = [simulate(2000, seed=5, y_init=(30.0, 20.0)),
            simulate(2500, seed=6, y_init=(-30.0, 0.0))]
    qr = arx_records(recs, 2, 2, 2)
    monkeypatch.setattr(sys.modules["gripkit.sysid.linear.arx"], "QR_MAX_ELEMENTS", 10)
    ne = arx_records(recs, 2, 2, 2)
    assert "Cholesky" in ne.info["method"] and "QR" in qr.info["method"]
    np.testing.assert_allclose(ne.theta, qr.theta, rtol=1e-9)
    np.testing.assert_allclose(ne.theta_std, qr.theta_std, rtol=1e-9)


def test_two_records_recover_the_truth_with_sigma_over_sqrt2():
    """Two records of equal length, different initial conditions and noise: the pooled θ lies
    within 3σ of the truth and its σ is that of one record divided by about √2 (twice the data)."""
    r1 = simulate(3000, seed=7, y_init=(80.0, 60.0), noise=2.0)
    r2 = simulate(3000, seed=8, y_init=(-70.0, -90.0), noise=2.0)
    m = arx_records([r1, r2], 2, 2, 2)
    assert np.all(np.abs(m.theta - THETA222) < 3 * m.theta_std), (m.theta, m.theta_std)
    s1, s2 = arx(*r1, 2, 2, 2).theta_std, arx(*r2, 2, 2, 2).theta_std
    assert np.all(m.theta_std < s1) and np.all(m.theta_std < s2)
    single = np.sqrt(0.5 * (s1**2 + s2**2))
    np.testing.assert_allclose(m.theta_std / single, 1 / np.sqrt(2), rtol=0.1)
    assert m.noise_variance == pytest.approx(4.0, rel=0.1)  # σ_e² = 2²
    for rec, (u, y) in zip(m.info["records"], (r1, r2)):
        one = arx(u, y, 2, 2, 2)
        assert rec["fit_percent"] == pytest.approx(one.fit_percent, abs=0.5)


def test_joined_records_are_biased_by_the_seam_the_pooled_fit_is_not():
    """Two records at different operating points (each an equilibrium of the model, data taken
    as they are: detrend none). Joined into one array, the rows at the seam regress the second
    record's start on the first one's end: a false step (400 in u, 494 in y) that biases θ by
    many σ. The pooled fit, each record with its own initial conditions, stays within 3σ."""
    r1 = simulate(2000, seed=9, y_init=(0.0, 0.0), u0=0.0)
    r2 = simulate(2000, seed=10, y_init=(0.0, 0.0), u0=-400.0)  # y around G·u0 ≈ 494
    pooled = arx_records([r1, r2], 2, 2, 2)
    joined = arx(np.concatenate([r1[0], r2[0]]), np.concatenate([r1[1], r2[1]]), 2, 2, 2)
    assert np.all(np.abs(pooled.theta - THETA222) < 3 * pooled.theta_std)
    assert np.max(np.abs(joined.theta - THETA222) / joined.theta_std) > 10.0
    assert joined.noise_variance > 10 * pooled.noise_variance  # the seam's error dominates its loss


def test_identify_with_a_list_of_trajectories_one_operating_point():
    """identify([tr1, tr2]) with detrend 'mean' removes the mean of all the samples together: the
    same model as arx_records on the data minus the pooled means, with those means as offsets."""
    r1 = simulate(1500, seed=11, y_init=(20.0, 10.0), u0=850.0)
    r2 = simulate(2500, seed=12, y_init=(-20.0, 0.0), u0=900.0)
    trs = [Trajectory.uniform(dt=0.005, current=u, force=y, units={"current": "mA", "force": "N"})
           for u, y in (r1, r2)]
    m = identify(trs, "arx", input="current", output="force", na=2, nb=2, nk=2)
    u0 = np.concatenate([r1[0], r2[0]]).mean()
    y0 = np.concatenate([r1[1], r2[1]]).mean()
    assert (m.u_offset, m.y_offset) == pytest.approx((u0, y0), rel=1e-12)
    ref = arx_records([(u - u0, y - y0) for u, y in (r1, r2)], 2, 2, 2)
    np.testing.assert_allclose(m.theta, ref.theta, rtol=1e-9)
    assert m.dt == 0.005 and m.input_unit == "mA" and m.info["n_records"] == 2
    none = identify(trs, "arx", input="current", output="force", na=2, nb=2, nk=2, detrend="none")
    assert (none.u_offset, none.y_offset) == (0.0, 0.0)
    assert np.all(np.abs(none.theta - THETA222) < 3 * none.theta_std)


@pytest.mark.parametrize("case, error, phrase", [
    ("linear", DataError, "one operating point"),
    ("frf", ArgumentError, "fitted by method 'arx', 'armax', 'oe', 'ss', 'tf', 'narx', 'hw', "
                           "'hysteresis', 'nlss' only"),
    ("dt", DataError, "must share the sample interval"),
    ("units", DataError, "must use the same units"),
    ("short", DataError, "data[1]: ARX [2 2 2] takes the first 3 samples of every record"),
    ("empty", DataError, "non-empty list"),
])
def test_records_refused_with_a_message(case, error, phrase):
    u, y = simulate(500, seed=13)
    tr = Trajectory.uniform(dt=0.01, u=u, y=y, units={"u": "A", "y": "N"})
    units = {"u": "A", "y": "N"}
    other = {"dt": Trajectory.uniform(dt=0.02, u=u, y=y, units=units),
             "units": Trajectory.uniform(dt=0.01, u=u, y=y, units={"u": "mA", "y": "N"}),
             "short": Trajectory.uniform(dt=0.01, u=u[:3], y=y[:3], units=units)}.get(case, tr)
    kw = dict(input="u", output="y", na=2, nb=2, nk=2)
    if case == "linear":
        kw["detrend"] = "linear"
    with pytest.raises(error) as exc:
        data = [] if case == "empty" else [tr, other]
        identify(data, "frf" if case == "frf" else "arx", **kw)
    assert phrase in str(exc.value)


# --- MIMO ------------------------------------------------------------------------------------
A1 = np.array([[0.5, 0.1], [0.0, 0.7]])


def simulate_mimo(n, *, seed, y_init):
    """y(t) = A1 y(t−1) + u(t−1) + e(t), e white with σ 0.05, from y(0) = ``y_init``."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal((n, 2))
    y = np.zeros((n, 2))
    y[0] = y_init
    for t in range(1, n):
        y[t] = A1 @ y[t - 1] + u[t - 1] + 0.05 * rng.standard_normal(2)
    return u, y


def test_mimo_one_record_is_arx_mimo_and_two_records_pool():
    r1 = simulate_mimo(1500, seed=14, y_init=(8.0, -6.0))
    r2 = simulate_mimo(1500, seed=15, y_init=(-9.0, 7.0))
    one = arx_mimo(*r1, 1, 1, 1)
    rec = arx_mimo_records([r1], 1, 1, 1)
    np.testing.assert_array_equal(one.A[1], rec.A[1])
    np.testing.assert_array_equal(one.noise_covariance, rec.noise_covariance)
    assert one.fit_percent == rec.fit_percent
    m = arx_mimo_records([r1, r2], 1, 1, 1)
    A, S = -m.A[1], m.A_std[1]
    assert np.all(np.abs(A - A1) < 3 * S), (A, S)
    s1 = one.A_std[1]
    np.testing.assert_allclose(S / s1, 1 / np.sqrt(2), rtol=0.15)
    np.testing.assert_allclose(m.noise_covariance, 0.0025 * np.eye(2), atol=3e-4)
    # every record from its own estimated initial state: x0 = the record's y(0)-driven state
    assert len(m.info["records"]) == 2
    for r, (u, y) in zip(m.info["records"], (r1, r2)):
        assert r["n_samples"] == 1500 and len(r["fit_percent"]) == 2
        assert min(r["fit_percent"]) > 90.0
    X = np.vstack([np.hstack([-y[:-1], u[:-1]]) for u, y in (r1, r2)])
    Y = np.vstack([y[1:] for _, y in (r1, r2)])
    theta = np.linalg.lstsq(X, Y, rcond=None)[0].T
    np.testing.assert_allclose(-m.A[1], -theta[:, :2], rtol=1e-9)


def test_identify_mimo_records_pooled_offsets():
    r1 = simulate_mimo(800, seed=16, y_init=(3.0, 1.0))
    r2 = simulate_mimo(1200, seed=17, y_init=(-3.0, 2.0))
    trs = [Trajectory.uniform(dt=0.01, u1=u[:, 0], u2=u[:, 1], y1=y[:, 0], y2=y[:, 1])
           for u, y in (r1, r2)]
    m = identify(trs, "arx", input="u1,u2", output="y1,y2", na=1, nb=1, nk=1)
    ymean = np.vstack([r1[1], r2[1]]).mean(axis=0)
    np.testing.assert_allclose(m.y_offset, ymean, rtol=1e-12)
    assert m.info["n_records"] == 2 and m.n_samples == 2000
