"""Step-resolution checks: refuse unstable steps, warn on under-resolved modes, choose substeps."""

import math

import pytest

from gripkit.errors import AccuracyWarning, SimulationError
from gripkit.sim import check_step, substeps_for

# TSFM force sensor, 001_0b92a7da96e7aa46.txt §IV-B: f0 = 8520 Hz, ζ = 0.006; 20 kHz sampling.
SENSOR = [(2 * math.pi * 8520.0, 0.006)]


def test_tsfm_sensor_at_20khz_is_under_resolved():
    with pytest.warns(AccuracyWarning, match="8520 Hz mode"):
        check_step(1 / 20000, SENSOR, "rk4")


def test_refuses_unstable_step():
    with pytest.raises(SimulationError, match="exceeds the stability limit 2.83"):
        check_step(1 / 10000, SENSOR, "rk4")  # ω·h = 5.35
    with pytest.raises(SimulationError, match="stability limit 2"):
        check_step(1 / 15000, SENSOR, "semi-implicit")  # ω·h = 3.57


def test_substeps_resolve_every_mode():
    n = substeps_for(1 / 20000, SENSOR, "rk4")
    check_step(1 / 20000 / n, SENSOR, "rk4")  # no warning, no error
    assert n >= 9  # at least 20 points per 8.52 kHz period at 20 kHz sampling: ceil(20*8520/20000)
    with pytest.warns(AccuracyWarning):
        check_step(1 / 20000 / (n - 1), SENSOR, "rk4")


def test_exact_discretisation_is_never_refused():
    check_step(1 / 20000, SENSOR, "zoh")
