"""ARX structure search ranked by free-run fit on a validation record, and the edge-of-range
warning (issue 13, "Structure search"). Data: Table II [2 2 2] of 000_8f66dcc7ab06470c.txt."""

import warnings

import pytest

from gripkit.errors import GripkitWarning
from gripkit.sysid import structure_search


def test_ranked_by_validation_fit(arx_data):
    simulate_arx = arx_data
    u, y = simulate_arx(3000, noise=1.0, seed=0)
    uv, yv = simulate_arx(3000, noise=1.0, seed=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GripkitWarning)
        res = structure_search(u, y, "1:3", "1:3", "1:4", validate=(uv, yv), progress=False)
    assert res.criterion == "validation"
    v = [c.validation_fit_percent for c in res.candidates]
    n_ok = sum(x is not None for x in v)
    # unstable candidates (no free-run fit) rank last
    assert all(x is None for x in v[n_ok:])
    v = v[:n_ok]
    assert all(a >= b for a, b in zip(v, v[1:]))
    assert (res.best.na, res.best.nk) == (2, 2)        # the true denominator order and delay
    one_step = [c.fit_percent for c in res.candidates]
    # validation separates, one-step does not
    assert max(one_step) - min(one_step[:5]) < max(v) - min(v)


def test_edge_of_range_warned(arx_data):
    u, y = arx_data(2000, noise=1.0, seed=0)
    with pytest.warns(GripkitWarning, match="edge of the searched range: na = 3"):
        structure_search(u, y, "3:5", "2", "2", progress=False)
