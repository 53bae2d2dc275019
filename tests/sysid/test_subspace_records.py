"""Subspace identification of several records at once (issue 25): the block-Hankel rows of every
record stacked (none across a seam), B and D from all records with one initial state per record.
Truth: the two-state system of gripkit.sysid.n4sid's example (poles 0.9 and 0.7, static gain
C(I − A)⁻¹B = 20/3)."""

import numpy as np
import pytest

from gripkit import Trajectory
from gripkit.errors import DataError
from gripkit.lti import StateSpace
from gripkit.sysid.linear import identify_mimo
from gripkit.sysid import identify, n4sid, pem
from gripkit.sysid.linear.pem_ss import pem_records
from gripkit.sysid.linear.subspace import n4sid_records

G = StateSpace([[0.9, 0.2], [0.0, 0.7]], [[0.0], [1.0]], [[1.0, 0.0]], dt=0.01)
GAIN = 20.0 / 3.0


def record(n, seed, x0=(0.0, 0.0), u0=0.0, noise=0.05):
    """u white around u0; y from the state x0 at t = 0 around the equilibrium (u0, GAIN·u0)."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = G.simulate(u, x0=np.array(x0)).reshape(-1) + noise * rng.standard_normal(n)
    return u + u0, y + GAIN * u0


def test_one_record_is_n4sid():
    u, y = record(1500, 1, x0=(10.0, 3.0))
    a, b = n4sid(u, y, 2), n4sid_records([(u, y)], 2)
    np.testing.assert_allclose(b.singular_values, a.singular_values, rtol=1e-9)
    np.testing.assert_allclose(np.sort(b.system.poles().real), np.sort(a.system.poles().real),
                               rtol=1e-9)
    np.testing.assert_allclose(b.fit_percent, a.fit_percent, rtol=1e-9)
    np.testing.assert_allclose(b.system.dc_gain(), a.system.dc_gain(), rtol=1e-9)


def test_each_record_from_its_own_initial_state():
    """Records started from x0 = ±(20, 5): the poles within 0.005 of the truth, and each record's
    estimated initial state reproduces its own transient (free-run fit above 97 % per record, the
    noise allowing 97.3 %); with one x0 for both the second record would start wrong."""
    recs = [record(1500, 2, x0=(20.0, 5.0)), record(1500, 3, x0=(-20.0, -5.0))]
    m = n4sid_records(recs, 2)
    np.testing.assert_allclose(np.sort(m.system.poles().real), [0.7, 0.9], atol=0.005)
    assert m.system.dc_gain()[0, 0] == pytest.approx(GAIN, rel=0.01)
    fits = [r["fit_percent"][0] for r in m.info["records"]]
    assert min(fits) > 97.0 and m.fit_percent[0] > 97.0
    x0a, x0b = (r["x0"] for r in m.info["records"])
    np.testing.assert_allclose(x0a, -x0b, rtol=0.05, atol=0.05 * np.abs(x0a).max())
    # the same model simulated from the first record's x0 on the second record misfits it
    ss = m.system
    wrong = ss.simulate(recs[1][0], x0=x0a).reshape(-1)
    y2 = recs[1][1]
    assert 100 * (1 - np.linalg.norm(y2 - wrong) / np.linalg.norm(y2 - y2.mean())) < fits[1] - 5.0


def test_joined_records_are_biased_records_are_not():
    """Two records at operating points u0 = 0 and 10 (y0 = 0 and 66.7), data as they are: joined,
    the jump at the seam biases the poles by more than 0.01; stacked, they are within 0.005."""
    recs = [record(1500, 4), record(1500, 5, u0=10.0)]
    m = n4sid_records(recs, 2)
    joined = n4sid(np.concatenate([r[0] for r in recs]), np.concatenate([r[1] for r in recs]), 2)
    np.testing.assert_allclose(np.sort(m.system.poles().real), [0.7, 0.9], atol=0.005)
    assert np.max(np.abs(np.sort(joined.system.poles().real) - [0.7, 0.9])) > 0.01


def test_identify_list_ss_keeps_one_operating_point():
    recs = [record(1200, 6, x0=(5.0, 1.0), u0=2.0), record(1500, 7, x0=(-5.0, 0.0), u0=2.0)]
    trs = [Trajectory.uniform(dt=0.01, u=u, y=y) for u, y in recs]
    m = identify(trs, "ss", input="u", output="y", order=2, refine=False)
    assert m.structure == "n4sid"
    u0 = np.concatenate([r[0] for r in recs]).mean()
    assert m.u_offset[0] == pytest.approx(u0, rel=1e-12)
    assert m.info["n_records"] == 2 and m.n_samples == 2700
    # the order search over the records (issue 25), as for one record: AIC of the innovation
    # predictor over all of them finds the true order 2 (poles 0.7 and 0.9)
    s = identify(trs, "ss", input="u", output="y", order="1:3", refine=False)
    assert s.order == 2 and sorted(r["order"] for r in s.info["search"]) == [1, 2, 3]
    assert s.info["search_criterion"] == "aic"
    np.testing.assert_allclose(np.sort(s.system.poles().real), [0.7, 0.9], atol=0.01)


def test_identify_list_ss_search_refines_the_best_by_focus():
    """The search over records refines its best order by PEM over the records, kept when it does
    not lose by the focus (free run for 'simulation', the innovation predictor for
    'prediction'); the first row is the returned model, with its focus fit."""
    recs = [record(1200, 8, x0=(5.0, 1.0)), record(1500, 9, x0=(-5.0, 0.0))]
    trs = [Trajectory.uniform(dt=0.01, u=u, y=y) for u, y in recs]
    for focus in ("simulation", "prediction"):
        m = identify(trs, "ss", input="u", output="y", order="1:3", focus=focus)
        rows = m.info["search"]
        assert rows[0]["order"] == m.order == 2 and "refined_percent" in rows[0]
        assert not any("refined_percent" in r for r in rows[1:])
        assert m.info["focus"]["criterion"] == focus and m.structure == "pem-innovation"
        dev = [(u - m.u_offset[0], y - m.y_offset[0]) for u, y in recs]
        assert rows[0]["refined_percent"] == pytest.approx(
            identify_mimo.records_score(m, dev, focus), rel=1e-12)
        assert m.info["focus"]["refined_percent"] >= m.info["focus"]["subspace_percent"] - 0.01
        np.testing.assert_allclose(np.sort(m.system.poles().real), [0.7, 0.9], atol=0.01)


def test_short_record_refused():
    with pytest.raises(DataError, match=r"records\[1\]: 9 samples, fewer than the 2k = 10"):
        n4sid_records([record(500, 8), record(9, 9)], 2, horizon=5)


def test_pem_one_record_is_pem():
    u, y = record(1500, 10, x0=(20.0, 5.0), noise=0.3)
    start = n4sid(u, y, 2)
    a, b = pem(start, u=u, y=y, form="oe"), pem_records(start, [(u, y)], form="oe")
    np.testing.assert_allclose(np.sort(b.system.poles().real), np.sort(a.system.poles().real),
                               rtol=1e-8)
    np.testing.assert_allclose(b.system.pole_covariance()[1], a.system.pole_covariance()[1],
                               rtol=1e-5)
    np.testing.assert_allclose(b.fit_percent, a.fit_percent, rtol=1e-9)


def test_pem_two_records_poles_within_3_sigma_and_sigma_over_sqrt2():
    """PEM (output-error form) over two records from x0 = ±(20, 5) with noise σ 0.3, one x0 per
    record estimated: both poles within 3σ of 0.9 and 0.7, their σ about 1/√2 of one record's,
    and each record's estimated x0 near its own true initial state (the model's state basis is
    arbitrary, so compared through the free response C Aᵗ x0 over the first 30 samples)."""
    recs = [record(1500, 11, x0=(20.0, 5.0), noise=0.3),
            record(1500, 12, x0=(-20.0, -5.0), noise=0.3)]
    start = n4sid_records(recs, 2)
    m = pem_records(start, recs, form="oe")
    poles, cov = m.system.pole_covariance()
    order = np.argsort(poles.real)
    sd = np.sqrt(cov[order, 0, 0])
    assert np.all(np.abs(poles.real[order] - [0.7, 0.9]) < 3 * sd), (poles, sd)
    single = [pem(n4sid(u, y, 2), u=u, y=y, form="oe").system.pole_covariance() for u, y in recs]
    sd1 = np.sqrt(np.mean([c[np.argsort(p.real), 0, 0] for p, c in single], axis=0))
    np.testing.assert_allclose(sd / sd1, 1 / np.sqrt(2), rtol=0.2)
    ss = m.system
    for rec, x0 in zip(m.info["records"], ((20.0, 5.0), (-20.0, -5.0))):
        free = ss.simulate(np.zeros(30), x0=rec["x0"]).reshape(-1)
        true = G.simulate(np.zeros(30), x0=np.array(x0)).reshape(-1)
        np.testing.assert_allclose(free, true, atol=0.5)
    assert m.info["pem"]["converged"] and m.info["n_records"] == 2


def test_identify_list_ss_refines_with_pem():
    recs = [record(1500, 13, x0=(10.0, 2.0)), record(1500, 14, x0=(-10.0, 0.0))]
    trs = [Trajectory.uniform(dt=0.01, u=u, y=y) for u, y in recs]
    m = identify(trs, "ss", input="u", output="y", order=2, form="oe")
    assert m.structure == "pem-oe" and len(m.info["records"]) == 2
    np.testing.assert_allclose(np.sort(m.system.poles().real), [0.7, 0.9], atol=0.005)
