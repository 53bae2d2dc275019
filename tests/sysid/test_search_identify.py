"""Structure search and the Trajectory entry point."""

import numpy as np
import pytest
from arx_cases import simulate_arx

from gripkit import DataError, Trajectory
from gripkit.sysid import arx, identify, structure_search
from gripkit.sysid.linear.search import parse_range


def test_search_finds_the_true_structure_by_aic():
    """Data from Table II [2 2 2] (ARX noise): AIC ranks [2 2 2] first over 1:4 × 1:4 × 1:10."""
    u, y = simulate_arx(4000, noise=2.0, seed=50)
    r = structure_search(u, y, "1:4", "1:4", "1:10", progress=False)
    assert len(r) == 160 and (r.best.na, r.best.nb, r.best.nk) == (2, 2, 2)
    aics = [c.aic for c in r.candidates]
    assert aics == sorted(aics)
    # every candidate is fitted on the same samples: t0 = max(4, 10 + 4 − 1) = 13
    assert r.n_used == 4000 - 13
    c = r.best
    m = arx(u[13 - 3:], y[13 - 3:], 2, 2, 2)  # same equations as the search's
    assert (c.loss == pytest.approx(m.loss, rel=1e-10)
            and c.fit_percent == pytest.approx(m.fit_percent))


def test_search_by_loss_prefers_the_largest_model():
    """§V-E: more coefficients always lower the loss on the estimation data."""
    u, y = simulate_arx(2000, noise=2.0, seed=51)
    r = structure_search(u, y, [1, 2, 3], [1, 2], [2], criterion="loss", progress=False)
    assert (r.best.na, r.best.nb) == (3, 2)


def test_parse_range():
    assert parse_range("1:4", "na") == [1, 2, 3, 4]
    assert parse_range("1:2:7", "nk") == [1, 3, 5, 7]
    assert parse_range("2", "na") == [2] and parse_range("1,3", "nb") == [1, 3]
    with pytest.raises(DataError, match="nk: expected a range like '1:4'"):
        parse_range("4:1", "nk")
    with pytest.raises(DataError, match="criterion"):
        structure_search(np.arange(50.0), np.arange(50.0), 1, 1, 1, criterion="bic")


def test_identify_trajectory_removes_operating_point():
    """With the input centred on 850 mA and detrend='mean' (default) the Trajectory entry point
    gives the same model as arx() on the centred arrays, with units and dt from the data."""
    u, y = simulate_arx(2000, noise=1.0, seed=52)
    tr = (Trajectory.uniform(dt=0.005, current=0.850 + 1e-3 * u, force=12.0 + y,
                             units={"current": "A", "force": "N"}))
    m = identify(tr, "arx", input="current", output="force", na=2, nb=2, nk=2)
    ref = arx(1e-3 * u - np.mean(1e-3 * u), y - y.mean(), 2, 2, 2)
    np.testing.assert_allclose(m.theta, ref.theta, rtol=1e-9)
    assert m.dt == 0.005 and m.u_offset == pytest.approx(0.850 + 1e-3 * u.mean())
    assert m.parameters["b2"].unit == "N/A" and m.input_name == "current"
    raw = identify(tr, "arx", input="current", output="force", na=2, nb=2, nk=2, detrend="none")
    assert np.max(np.abs(raw.theta - ref.theta) / ref.theta_std) > 3  # the offset biases the fit


def test_identify_dispatches_every_method():
    u, y = simulate_arx(1500, noise=1.0, seed=53)
    tr = Trajectory.uniform(dt=0.005, u=u, y=y)
    assert identify(tr, "oe", input="u", output="y", nb=2, na=2, nk=2).structure == "oe"
    assert identify(tr, "armax", input="u", output="y", na=2, nb=2, nc=1, nk=2).structure == "armax"
    assert identify(tr, "rls", input="u", output="y", na=2, nb=2, nk=2,
                    forgetting=0.99).forgetting == 0.99
    assert identify(tr, "search", input="u", output="y", na="1:2", nb="1:2", nk="2",
                    progress=False).best
    with pytest.raises(DataError, match="method: expected one of"):
        identify(tr, "bj", input="u", output="y")
    with pytest.raises(DataError, match="input and output must be different"):
        identify(tr, "arx", input="u", output="u")
