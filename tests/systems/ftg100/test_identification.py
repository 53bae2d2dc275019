"""Levenberg-Marquardt identification of the FT-G100 subsystems (§III-B, §III-D) from simulated
experiments with known truth (the seed's values)."""

import numpy as np
import pytest

from gripkit import Trajectory
from gripkit.errors import DataError, IdentificationError
from gripkit.systems.ftg100.identification import (identify_actuated, identify_sensing,
                                                   release_experiment, step_experiment)
from gripkit.systems.ftg100.parameters import PAPER_VALUES


@pytest.fixture(scope="module")
def long_fit():
    """§III-B: 10 V steps between 70 and 80 V (period 50 ms) for 20 s at 20 kHz with the ball
    grasped, 1 % output noise (σ = 1 % of the step's static amplitude, 1.9 nm)."""
    return identify_actuated(step_experiment(duration=20.0, period=0.05, seed=11))


def test_recovers_Ma_Kfa_k0_within_2_percent(long_fit):
    res = long_fit
    assert res.identifiability.ok
    for name in ("M_a", "K_fa", "k0"):
        true = PAPER_VALUES[name][0]
        est, sd = res.value(name), res.stdev(name)
        assert abs(est - true) / true < 0.02, name
        assert abs(est - true) < 4 * sd, name
        assert 0 < sd < 0.01 * true, name  # σ is reported (and small here)
    cov = res.covariance
    np.testing.assert_allclose(cov, cov.T, rtol=1e-10, atol=0)
    assert np.all(np.linalg.eigvalsh(cov / np.outer(res.std, res.std)) > -1e-9)


def test_short_step_reports_k0_as_poorly_determined():
    """A paper-like 20 ms record (1 ms before the step): M_a and K_fa are determined to < 1 %, but
    k0
    in series with k2 = 6.45 N/m moves the response by only 0.5 % per 100 %: σ(k0)/k0 > 20 %."""
    res = identify_actuated(step_experiment(duration=0.02, seed=5))
    assert res.stdev("M_a") / res.value("M_a") < 0.01
    assert res.stdev("K_fa") / res.value("K_fa") < 0.01
    assert abs(res.value("M_a") / PAPER_VALUES["M_a"][0] - 1) < 0.01
    assert res.stdev("k0") / res.value("k0") > 0.2


def test_sensing_release_recovers_Mb_Kfb():
    """§III-D, Fig. 9: release from a 27 µm thrust, 1 % noise: M_b and K_fb within 2 % and 4σ."""
    res = identify_sensing(release_experiment(seed=3, duration=0.02))
    for name in ("M_b", "K_fb"):
        true = PAPER_VALUES[name][0]
        assert abs(res.value(name) - true) / true < 0.02
        assert abs(res.value(name) - true) < 4 * res.stdev(name)
    assert abs(res.correlation[0, 1]) < 0.5


def test_sensor_zero_is_estimated():
    """An interferometer zero of 3 µm in the record is estimated, not absorbed by the physics."""
    d = step_experiment(duration=2.0, period=0.05, seed=2)
    shifted = d.with_channels(x_a=d["x_a"] + 3e-6)
    a, b = identify_actuated(d), identify_actuated(shifted)
    assert b.value("x_off") - a.value("x_off") == pytest.approx(3e-6, rel=1e-6)
    assert b.value("M_a") == pytest.approx(a.value("M_a"), rel=1e-6)


def test_bad_experiments():
    d = step_experiment(duration=0.02)
    with pytest.raises(DataError, match="never changes"):
        identify_actuated(d.with_channels(V_in=np.full(d.n, 70.0)))
    with pytest.raises(DataError, match="operating voltage"):
        identify_actuated(d.with_channels(V_in=d["V_in"] - 70.0))
    with pytest.raises(IdentificationError, match="non-positive static gain"):
        identify_actuated(d.with_channels(x_a=-d["x_a"]))
    r = release_experiment()
    with pytest.raises(DataError, match="does not match the applied force"):
        identify_sensing(r.with_channels(F_c=2 * r["F_c"]))
    with pytest.raises(DataError, match="expected a Trajectory"):
        identify_sensing({"F_c": [1, 2]})
    assert isinstance(r, Trajectory)
