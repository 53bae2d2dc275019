"""Bad measured data that gripkit used to take silently (the data-check audit): several corrupt
samples in one channel, extreme scales in the nonlinear families, the same record given twice, and
records filled mostly by interpolation. Each case asserts the error class and a key phrase of the
one-line message, or the warning; the records are synthetic (built here in ``tmp_path``)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from gripkit import DataWarning
from gripkit.io import load
from gripkit.signals.outliers import GROSS, THRESHOLD, corrupt_samples
from corpus import assert_warned

FS = 100.0
FIXTURES = Path(__file__).resolve().parents[1] / "fixtures"
IO = ("--input", "current", "--output", "force")


def record(n: int = 400, seed: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """A PRBS current and the force of the stable second-order ARX system
    y(t) = 1.2 y(t−1) − 0.5 y(t−2) + 0.4 u(t−1) + e(t), |y| ≲ 1 N."""
    rng = np.random.default_rng(seed)
    u = np.sign(rng.standard_normal(n))
    y = np.zeros(n)
    for t in range(2, n):
        y[t] = 1.2 * y[t - 1] - 0.5 * y[t - 2] + 0.4 * u[t - 1] + 0.02 * rng.standard_normal()
    return u, y


def write(path: Path, u: np.ndarray, y: np.ndarray) -> Path:
    t = np.arange(u.size) / FS
    np.savetxt(path, np.column_stack([t, u, y]), delimiter=",",
               header="time [s],current [A],force [N]", comments="", fmt="%.17g")
    return path


# ---------------------------------------------------------------- 1. several corrupt samples
SPIKES = [10, 19, 28, 37, 46]


@pytest.mark.parametrize("count", [5, 20, 40])
def test_api_several_spikes_still_warn_naming_their_count(tmp_path, count):
    """5, 20 and 40 samples of 1e6 N in a ±1 N channel of 400: the order-statistic scale alone
    (m = 4 samples set aside per side) was widened by the fifth spike and the check fell silent;
    the MAD (breakdown 50 %) keeps the scale at the noise level."""
    u, y = record()
    idx = np.arange(count) * 9 + 10
    y[idx] = 1e6
    p = write(tmp_path / "spk.csv", u, y)
    with pytest.warns(DataWarning, match=rf"column 'force' has {count} samples far outside"):
        load(p)
    np.testing.assert_array_equal(corrupt_samples(y), idx)


def test_cli_five_spikes_warn_before_the_fit(cli, tmp_path):
    u, y = record()
    y[SPIKES] = 1e6
    res = cli("identify", "arx", write(tmp_path / "spk5.csv", u, y), *IO, "--json")
    assert_warned(res, "column 'force' has 5 samples far outside the rest of the channel")


def test_cli_five_spikes_of_1e300_give_the_spike_warning_with_the_error(cli, tmp_path):
    """The fit on 1e300 samples cannot succeed; the warning that explains why is printed with
    the error, not only 'covariance has non-finite entries'."""
    u, y = record()
    y[SPIKES] = 1e300
    res = cli("identify", "arx", write(tmp_path / "spk5_300.csv", u, y), *IO)
    assert "column 'force' has 5 samples far outside" in res.err, res.err
    assert "look corrupt: 1e+300 N at t=0.1 s" in res.err, res.err


def test_spike_rule_is_silent_on_the_clean_record(tmp_path):
    u, y = record()
    with warnings.catch_warnings():
        warnings.simplefilter("error", DataWarning)
        load(write(tmp_path / "good.csv", u, y))
    assert corrupt_samples(u).size == 0 and corrupt_samples(y).size == 0


@pytest.mark.parametrize("name", ["emps/emps_est.csv", "silverbox/silverbox_est.csv",
                                  "evaporator/evaporator.csv", "cd_player_arm/cd_player_arm.csv"])
def test_spike_rule_is_silent_on_the_fixture_records(name):
    a = np.genfromtxt(FIXTURES / name, delimiter=",", skip_header=1)
    for j in range(a.shape[1]):
        assert corrupt_samples(a[:, j]).size == 0, (name, j)


def test_many_moderate_pulses_on_noise_are_a_pulse_train_not_corruption():
    """50 one-sample pulses of 20 σ on Gaussian noise (more than the 2m = 10 a corruption may
    touch, and far below GROSS·K·σ): a property of the signal, not reported."""
    x = np.random.default_rng(3).standard_normal(5000)
    x[::100] += 20.0
    assert 20.0 < GROSS * THRESHOLD
    assert corrupt_samples(x).size == 0
