"""Trajectory validation: each bad input gives one clear DataError."""

import numpy as np
import pytest

from gripkit import DataError, Trajectory


def test_uniform_construction():
    tr = Trajectory.uniform(dt=0.005, u=np.zeros(400), y=np.arange(400.0), units={"y": "N"})
    assert tr.dt == 0.005 and tr.n == 400 and tr.unit("y") == "N" and tr.unit("u") == "1"
    assert tr.duration == pytest.approx(399 / 200)
    with pytest.raises(ValueError):
        tr["y"][0] = 1.0  # read-only


def test_nan_reports_count_and_first_time():
    y = np.ones(10)
    y[[3, 5, 6]] = np.nan
    with pytest.raises(DataError, match=r"column 'force' has 3 NaN values \(first at "
                                        r"t=0.015 s\).*fill"):
        Trajectory.uniform(dt=0.005, force=y)


def test_inf_reported():
    y = np.ones(10)
    y[2] = np.inf
    with pytest.raises(DataError, match="infinite"):
        Trajectory.uniform(dt=0.005, force=y)


@pytest.mark.parametrize("t, kind", [([0, 1, 1, 2], "repeated"), ([0, 1, 0.5, 2], "decreasing")])
def test_time_must_increase(t, kind):
    with pytest.raises(DataError, match=kind):
        Trajectory(np.array(t, float), {"y": np.zeros(4)})


def test_non_uniform_detected_on_request():
    t = np.arange(100) * 0.005
    t[50:] += 0.002
    tr = Trajectory(t, {"y": np.zeros(100)})
    assert not tr.is_uniform()
    with pytest.raises(DataError, match=r"uniform sampling; the interval at t=0.245 s"):
        tr.require_uniform()


def test_require_samples_and_missing_column():
    tr = Trajectory.uniform(dt=0.1, y=np.zeros(5))
    with pytest.raises(DataError, match="needs at least 8 samples, found 5"):
        tr.require_samples(8, "ARX [4 4 2]")
    with pytest.raises(DataError, match="column 'u' not found; available columns: y"):
        tr["u"]


def test_length_mismatch_and_text():
    with pytest.raises(DataError, match="expected 3 values"):
        Trajectory(np.arange(3.0), {"y": np.zeros(4)})
    with pytest.raises(DataError, match="expected numbers"):
        Trajectory(np.arange(2.0), {"y": np.array(["a", "b"])})


def test_window_take_rename():
    tr = Trajectory.uniform(dt=0.1, y=np.arange(20.0))
    w = tr.window(0.5, 1.0)
    assert w.n == 5 and w["y"][0] == 5.0
    assert "z" in tr.rename(y="z")


@pytest.mark.parametrize("d", [[3.0, 1.0, 2.0], [4.0, 1.0, 3.0, 2.0], [0.1, 0.3], [2.5],
                               [1e-3, np.nan, 1e-3], [0.1 + 0.2, 0.3, 0.1, 1e300, -1e300, 0.7]])
def test_median_of_intervals_is_numpys(d):
    """Trajectory's interval median (no numpy.ma import at start-up) is np.median bit for bit:
    the middle value, the mean of the two middle values, NaN when a NaN is present."""
    from gripkit.signals.trajectory import _median

    d = np.array(d)
    ref = float(np.median(d))
    got = _median(d.copy())
    assert got == ref or (np.isnan(got) and np.isnan(ref))
