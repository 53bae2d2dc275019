"""Bad measured data that gripkit used to take silently (the data-check audit): several corrupt
samples in one channel, extreme scales in the nonlinear families, the same record given twice, and
records filled mostly by interpolation. Each case asserts the error class and a key phrase of the
one-line message, or the warning; the records are synthetic (built here in ``tmp_path``)."""

from __future__ import annotations

import dataclasses
import warnings
from pathlib import Path

import numpy as np
import pytest

from gripkit import DataError, DataWarning, Trajectory
from gripkit.errors import ModelError
from gripkit.io import load
from gripkit.io.table import MAX_FILL_FRACTION
from gripkit.signals.outliers import GROSS, THRESHOLD, corrupt_samples
from gripkit.sysid import identify, narx
from corpus import assert_user_error, assert_warned

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


@pytest.mark.parametrize("method,label", [("arx", "ARX [2 2 1]"), ("oe", "OE [2 2 1]")])
def test_cli_five_spikes_of_1e300_give_the_spike_warning_with_the_error(cli, tmp_path, method,
                                                                        label):
    """The fit on 1e300 samples cannot succeed (σ = inf); was only 'ModelError: covariance has
    non-finite entries'. Now the spike warning, then an IdentificationError saying why."""
    u, y = record()
    y[SPIKES] = 1e300
    res = cli("identify", method, write(tmp_path / "spk5_300.csv", u, y), *IO)
    assert "column 'force' has 5 samples far outside" in res.err, res.err
    assert "look corrupt: 1e+300 N at t=0.1 s" in res.err, res.err
    assert_user_error(res, "IdentificationError", f"{label}: the fit gives parameters or σ that "
                                                  "are not finite")
    assert "drop or repair the samples that the corrupt-sample warning names" in res.err


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
    """50 one-sample pulses of 20 σ on Gaussian noise, and 50 trigger pulses of 5 V logged by a
    16-bit converter over ±10 V (noise ±2 LSB = ±0.6 mV): more than the 2m = 10 a corruption may
    touch, and closer than GROSS = 1e4 ranges of the other samples: pulses of the signal."""
    rng = np.random.default_rng(3)
    x = rng.standard_normal(5000)
    x[::100] += 20.0
    lsb = 20.0 / 2**16
    trigger = lsb * rng.integers(-2, 3, 5000)
    trigger[::100] += 5.0
    assert 5.0 / np.ptp(trigger[trigger < 1]) < GROSS
    assert corrupt_samples(x).size == 0 and corrupt_samples(trigger).size == 0
    assert THRESHOLD * np.std(x) < 20.0  # each pulse alone would be flagged


# ---------------------------------------------------------------- 2. extreme scales
NONLINEAR = [("narx", "NARX"), ("hw", "Hammerstein-Wiener"), ("nlss", "NLSS"),
             ("hysteresis", "hysteresis")]


@pytest.mark.parametrize("scale", [1e300, 1e-300])
@pytest.mark.parametrize("family,work", NONLINEAR)
def test_cli_nonlinear_families_at_extreme_scales_name_the_scale(cli, tmp_path, family, work,
                                                                 scale):
    """Was: fit nan % and a model file (narx), an unexpected LinAlgError (hw), 'input channel 0
    is identically zero' (nlss), 'constant output' (narx, hysteresis at 1e-300). Now the check of
    state space (peak between 1e-100 and 1e+100), before any fit."""
    u, y = record()
    out = tmp_path / "m.json"
    res = cli("identify", family, write(tmp_path / "s.csv", u * scale, y * scale), *IO,
              "--out", out)
    assert_user_error(res, "DataError", f"input column 'current' has values up to {scale:.3g}: "
                                        f"{work} identification forms sums of squares")
    assert "between 1e-100 and 1e+100" in res.error_lines[0]
    assert not out.exists()


@pytest.mark.parametrize("family,work", NONLINEAR)
def test_cli_one_1e300_sample_is_refused_by_the_scale_check_after_the_spike_warning(
        cli, tmp_path, family, work):
    u, y = record()
    y[100] = 1e300
    out = tmp_path / "m.json"
    res = cli("identify", family, write(tmp_path / "huge.csv", u, y), *IO, "--out", out)
    assert_user_error(res, "DataError", f"output column 'force' has values up to 1e+300: "
                                        f"{work} identification")
    assert "column 'force' has 1 sample far outside" in res.err
    assert "RuntimeWarning" not in res.err
    assert not out.exists()


def test_api_narx_at_1e300_refuses_naming_the_signal():
    u, y = record()
    with pytest.raises(DataError, match=r"output column 'y' has values up to 1e\+300"):
        narx(u, y * 1e300 / np.abs(y).max())


@pytest.mark.parametrize("bad", [("fit_percent", float("nan")), ("theta_std", "inf")])
def test_a_failed_fit_is_not_written_to_a_model_file(tmp_path, bad):
    """A model whose fit is NaN or whose σ is infinite is refused by ``save``, with no file."""
    u, y = record()
    m = narx(u, y, degree=1, lags=2)
    field, value = bad
    if value == "inf":
        value = np.array(m.theta_std, dtype=float)
        value[0] = np.inf
    broken = dataclasses.replace(m, **{field: value})
    out = tmp_path / "m.json"
    with pytest.raises(ModelError, match="m.json: not written: .*the fit failed"):
        broken.save(out)
    assert not out.exists()
    m.save(out)  # the fit itself is written
    assert out.exists()


# ---------------------------------------------------------------- 3. a record given twice
@pytest.mark.parametrize("method", ["arx", "oe", "nlss", "hysteresis"])
def test_cli_the_same_record_twice_is_refused_naming_both(cli, tmp_path, method):
    """Was: θ unchanged and theta_std × 0.705 (1/√2), silently. The copy under another name is
    found by the content of its input and output columns, not by its file name."""
    u, y = record()
    a = write(tmp_path / "run.csv", u, y)
    b = write(tmp_path / "copy.csv", u, y)
    res = cli("identify", method, a, b, *IO, "--json")
    assert_user_error(res, "DataError", f"'{a}' and '{b}' hold the same samples of 'current', "
                                        "'force'")
    assert "σ too small" in res.error_lines[0]


def test_api_identify_records_refuses_a_duplicate_and_takes_distinct_records():
    u1, y1 = record(seed=1)
    u2, y2 = record(seed=2)
    tr1 = Trajectory.uniform(dt=0.01, u=u1, y=y1)
    tr2 = Trajectory.uniform(dt=0.01, u=u2, y=y2)
    shifted = Trajectory(tr1.t + 5.0, {"u": u1, "y": y1})  # the same samples, later in time
    with pytest.raises(DataError, match=r"data\[0\] and data\[2\] hold the same samples of "
                                        r"'u', 'y'"):
        identify([tr1, tr2, shifted], "arx", input="u", output="y", na=2, nb=1, nk=1)
    one = identify([tr1], "arx", input="u", output="y", na=2, nb=1, nk=1)
    two = identify([tr1, tr2], "arx", input="u", output="y", na=2, nb=1, nk=1)
    assert two.theta_std.max() < one.theta_std.max()  # real new evidence still narrows σ


# ---------------------------------------------------------------- 4. interpolated samples
def _with_gaps(tmp_path, missing: int, lead: bool = False) -> Path:
    """The record with ``missing`` force samples blanked (every third from sample 20 on; and the
    first one when ``lead``)."""
    u, y = record()
    y[20:20 + 3 * missing:3][:missing - lead] = np.nan
    if lead:
        y[0] = np.nan
    return write(tmp_path / "gaps.csv", u, y)


def test_cli_interpolated_samples_warn_with_count_and_fraction(cli, tmp_path):
    """Was: the fit reported with warnings []."""
    res = cli("identify", "arx", _with_gaps(tmp_path, 40, lead=True), *IO, "--fill",
              "interpolate", "--json")
    assert res.code == 0, res.err
    assert_warned(res, "column 'force': 40 of 400 samples (10 %) were missing and were made up "
                       "by linear interpolation, 1 of them before the first or after the last "
                       "measured value, copied from the nearest one")


def test_cli_more_than_a_fifth_interpolated_is_refused(cli, tmp_path):
    """81 of 400 (20.25 %) is over the documented MAX_FILL_FRACTION = 0.2; 80 (20 %) is not."""
    assert MAX_FILL_FRACTION == 0.2
    res = cli("identify", "arx", _with_gaps(tmp_path, 81), *IO, "--fill", "interpolate")
    assert_user_error(res, "DataError", "column 'force' has 81 of 400 samples (20.2 %) missing; "
                                        "interpolation fills at most 20 % of a channel")
    assert "--fill drop" in res.error_lines[0]
    with pytest.warns(DataWarning, match=r"80 of 400 samples \(20 %\) were missing"):
        load(_with_gaps(tmp_path, 80), fill="interpolate")


def test_a_two_level_channel_s_chatter_is_no_corrupt_sample():
    """A contact force: 1e-12 N of noise while free, then pressing at 0.4 mN with a short
    ±1e-10 N chatter at the contact (as the simulated contact of 001_0b92a7da96e7aa46.txt Fig. 13
    gives): the MAD (the free level's noise) puts the chatter 10 MADs out, but it lies within
    what the channel holds, so nothing is flagged; five 1 N spikes beyond its range still are."""
    from gripkit.signals.outliers import corrupt_samples

    rng = np.random.default_rng(11)
    n = 20000
    f = 1e-12 * rng.standard_normal(n)
    f[12000:] += 4e-4 * (1 - np.exp(-np.arange(n - 12000) / 50.0))
    f[11990:11998] = 1.1e-10 * np.array([-1, 1, -1, 1, -1, 1, -1, 1.0])
    assert corrupt_samples(f).size == 0
    spiky = f.copy()
    at = [1000, 3000, 5000, 15000, 17000]
    spiky[at] = 1.0
    assert corrupt_samples(spiky).tolist() == at
