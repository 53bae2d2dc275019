"""Bad input to data files and the identify commands (issue 11, items 6–11): each case asserts the
error class and a key phrase of the one-line message, or the warning.

The truth of every identification case is known: the data are simulated from the ARX system
y(t) = 1.5 y(t−1) − 0.7 y(t−2) + 1.0 u(t−1) + 0.5 u(t−2) + e(t) (poles 0.75 ± 0.37j)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from gripkit import DataError, DataWarning, IdentificationError
from gripkit.errors import AccuracyWarning
from gripkit.io import load
from gripkit.signals.outliers import THRESHOLD, corrupt_samples
from gripkit.sysid import RLS, armax, arx, oe, rls, structure_search
from corpus import assert_user_error, assert_warned


TRUE = np.array([-1.5, 0.7, 1.0, 0.5])  # a1, a2, b1, b2
FS = 200.0


def simulate(n: int = 1000, noise: float = 0.05, seed: int = 5) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = np.zeros(n)
    e = noise * rng.standard_normal(n)
    for t in range(2, n):
        y[t] = 1.5 * y[t - 1] - 0.7 * y[t - 2] + 1.0 * u[t - 1] + 0.5 * u[t - 2] + e[t]
    return u, y


def write_csv(path, u, y, t=None, fmt="%.17g"):
    t = np.arange(u.size) / FS if t is None else t
    np.savetxt(path, np.column_stack([t, u, y]), delimiter=",", header="t,current [A],force [N]",
               comments="", fmt=fmt)
    return path


@pytest.fixture
def clean_csv(tmp_path):
    u, y = simulate()
    return write_csv(tmp_path / "run.csv", u, y)


ARX = ("identify", "arx")
ORDERS = ("--input", "current", "--output", "force", "--na", 2, "--nb", 2, "--nk", 1)


# ---------------------------------------------------------------- 6. truncated CSV files
def test_cli_csv_cut_in_its_last_value_warns_naming_the_line(cli, tmp_path):
    """The issue's case: the file ends in the middle of its last value, 1.529 cut to 1."""
    u, y = simulate()
    y[-1] = 1.529
    p = write_csv(tmp_path / "run.csv", u, y)
    text = p.read_text()
    assert text.endswith(",1.5289999999999999\n")
    p.write_text(text[: -len(".5289999999999999\n")])
    res = cli(*ARX, p, *ORDERS, "--json")
    assert res.code == 0, res.err
    assert_warned(res, "line 1001, the last, has no line ending: the file looks truncated")


def test_api_unterminated_last_line_warns_and_keeps_the_other_rows(tmp_path):
    p = tmp_path / "d.csv"
    p.write_text("t,u,y\n0,1,2\n0.01,2,1.529\n0.02,3,4\n0.03,1,1")
    with pytest.warns(DataWarning, match=r"line 5, the last, has no line ending: the file "
                                         r"looks truncated"):
        tr = load(p)
    np.testing.assert_array_equal(tr["y"][:3], [2, 1.529, 4])


def test_api_line_with_missing_fields_is_refused_naming_it(tmp_path):
    p = tmp_path / "d.csv"
    p.write_text("t,u,y\n0,1,2\n0.01,2\n0.02,3,4\n")
    with pytest.raises(DataError, match=r"d.csv: line 3 has 2 fields, the header has 3: the file "
                                        r"looks truncated"):
        load(p)


def test_cli_last_line_with_missing_fields_is_refused_as_truncated(cli, clean_csv):
    text = clean_csv.read_text().rstrip("\n")
    clean_csv.write_text(text[: text.rindex(",")])  # the last line loses its last field
    assert_user_error(cli(*ARX, clean_csv, *ORDERS), "DataError",
                      "line 1001 has 2 fields, the header has 3 and is the last line, without "
                      "a line ending: "
                      "the file looks truncated")


def test_a_complete_file_gives_no_warning(tmp_path, clean_csv):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tr = load(clean_csv)
    assert tr.n == 1000


# ---------------------------------------------------------------- 7. --fs against a time column
def test_cli_fs_disagreeing_with_the_time_column_is_refused(cli, clean_csv):
    res = cli(*ARX, clean_csv, *ORDERS, "--fs", 1000)
    assert_user_error(res, "DataError", "fs=1000 Hz disagrees with the time column 't' (its "
                                        "stamps give 200 Hz)")


def test_cli_fs_agreeing_with_rounded_stamps_passes(cli, tmp_path):
    """Stamps written with 4 decimals (0.1 ms resolution) at 200 Hz: within half a sample of
    k/200 s, so --fs 200 is accepted and gives the same model as the time column alone."""
    u, y = simulate()
    p = write_csv(tmp_path / "r.csv", u, y, fmt="%.4f")
    a, b = cli(*ARX, p, *ORDERS, "--json"), cli(*ARX, p, *ORDERS, "--fs", 200, "--json")
    assert a.code == b.code == 0, (a.err, b.err)
    assert b.json()["B"] == a.json()["B"]


def test_api_fs_tolerance_is_half_a_sample_of_drift(tmp_path):
    """N = 1000 samples: a rate 0.04 % off drifts 0.4 samples by the end (passes), 0.06 % off
    drifts 0.6 samples (refused)."""
    u, y = simulate()
    p = write_csv(tmp_path / "r.csv", u, y)
    assert load(p, fs=FS * (1 + 0.4 / 999)).dt == pytest.approx(1 / (FS * (1 + 0.4 / 999)))
    with pytest.raises(DataError, match=r"0.6 samples apart \(tolerance: half a sample\)"):
        load(p, fs=FS * (1 + 0.6 / 999))


def test_api_explicit_time_column_and_fs_must_agree(tmp_path):
    u, y = simulate()
    p = write_csv(tmp_path / "r.csv", u, y)
    with pytest.raises(DataError, match=r"fs=100 Hz disagrees with the time column 't'"):
        load(p, time="t", fs=100.0)


# ---------------------------------------------------------------- 8. options before data
def test_cli_fill_banana_on_clean_data_is_refused(cli, clean_csv):
    assert_user_error(cli(*ARX, clean_csv, *ORDERS, "--fill", "banana"), "DataError",
                      "fill: expected None, 'drop' or 'interpolate', found 'banana'")


@pytest.mark.parametrize("args,phrase", [
    (("arx", "--input", "u", "--output", "y", "--na", 2, "--nb", 2, "--nk", 1, "--detrend",
      "banana"),
     "--detrend: expected one of mean, linear, none"),
    (("arx", "--input", "u", "--output", "y", "--na", 2, "--nb", 0, "--nk", 1),
     "--nb: expected an integer >= 1"),
    (("armax", "--input", "u", "--output", "y", "--na", 2, "--nb", 2, "--nc", -1, "--nk", 1),
     "--nc: expected an integer >= 0"),
    (("oe", "--input", "u", "--output", "y", "--nb", 2, "--nf", 2, "--nk", 1, "--fill", "zero"),
     "fill: expected None, 'drop' or 'interpolate'"),
    (("rls", "--input", "u", "--output", "y", "--na", 2, "--nb", 2, "--nk", 1, "--windup",
      "banana"),
     "windup: expected one of none, trace, directional"),
    (("rls", "--input", "u", "--output", "y", "--na", 2, "--nb", 2, "--nk", 1, "--forgetting", 1.5),
     "forgetting factor: expected 0 < λ <= 1"),
    (("search", "--input", "u", "--output", "y", "--criterion", "bic"), "--criterion: expected one "
                                                                        "of aic, fpe, loss"),
    (("search", "--input", "u", "--output", "y", "--na", "1:x"), "--na: expected a "
                                                                 "range like '1:4'"),
    (("search", "--input", "u", "--output", "y", "--top", 0), "--top: expected an integer >= 1"),
    (("step", "--input", "u", "--output", "y", "--fs", 0), "fs: expected a positive sampling rate"),
    (("modal", "--signal", "y", "--fill", "banana"), "fill: expected None"),
    (("bouc-wen", "--input", "u", "--output", "y", "--burn-in", -3), "--burn-in: expected "
                                                                     "an integer >= 0"),
    (("friction", "--position", "u", "--effort", "y", "--cutoff", -5), "--cutoff: expected a "
                                                                       "finite number > 0"),
    (("friction", "--position", "u", "--effort", "y", "--effort-scale", 0),
     "--effort-scale: expected a finite positive factor, found 0.0"),
])
def test_cli_every_identify_option_is_checked_before_the_data(cli, tmp_path, args, phrase):
    """The data file does not exist: the option error must come first (it would otherwise be
    reported only after a possibly long load, or never on clean data)."""
    command, rest = args[0], args[1:]
    assert_user_error(cli("identify", command, tmp_path / "missing.csv", *rest), "DataError",
                      phrase)


def test_cli_missing_validation_file_is_reported_before_the_fit(cli, clean_csv, tmp_path):
    assert_user_error(cli(*ARX, clean_csv, *ORDERS, "--validate", tmp_path / "nope.csv"),
                      "DataError",
                      "--validate: data file")


@pytest.mark.parametrize("kw,phrase", [({"fill": "banana"}, "fill: expected None, 'drop' "
                                                            "or 'interpolate'"),
                                       ({"fs": -5.0}, "fs: expected a positive "
                                                      "sampling rate in Hz")])
def test_api_load_checks_options_before_reading(tmp_path, kw, phrase):
    """An unreadable file: the option error comes first, so it was checked before any reading."""
    p = tmp_path / "broken.parquet"
    p.write_bytes(b"not a parquet file")
    with pytest.raises(DataError, match=phrase):
        load(p, **kw)


# ---------------------------------------------------------------- 9. corrupt samples and extreme
# scales
def test_cli_corrupt_sample_warns_naming_its_time(cli, tmp_path):
    """One force value of 1e29 at t = 2 s: the warning names the column, the value and the time,
    also when the fit then refuses or warns about the data."""
    u, y = simulate()
    y[400] = 1e29
    p = write_csv(tmp_path / "spike.csv", u, y)
    res = cli(*ARX, p, *ORDERS, "--json")
    assert_warned(res, "column 'force' has 1 sample far outside the rest of the "
                       "channel, which looks "
                       "corrupt: 1e+29 N at t=2 s")


def test_api_sentinel_value_warns_naming_its_time(tmp_path):
    u, y = simulate()
    u[123] = -9999.0
    p = write_csv(tmp_path / "s.csv", u, y)
    with pytest.warns(DataWarning, match=r"column 'current' has 1 sample .* -9999 A at t=0.615 s"):
        load(p)


@pytest.mark.parametrize("n", [20, 1000, 100_000])
def test_outlier_check_is_silent_on_gaussian_data(n):
    """The threshold K = Φ⁻¹(1 − 1e-6/(2·1e9)) = 8.03 σ cannot fire on Gaussian samples of these
    sizes (chance < 1e-10 each); 20 seeds per size."""
    assert THRESHOLD == pytest.approx(8.0269, abs=1e-3)
    for seed in range(20):
        x = np.random.default_rng(seed).standard_normal(n)
        assert corrupt_samples(x).size == 0


def test_outlier_check_is_silent_on_structured_signals():
    """Steps, PRBS, a fast-decaying vibration, a decaying σ(t) trajectory and a train of 50
    one-sample trigger pulses (more than the 2m = 10 samples a corruption may touch) are not
    corrupt."""
    t = np.arange(5000) / 1000
    rng = np.random.default_rng(0)
    signals = {
        "late step": (t > 4.98).astype(float),
        "PRBS": np.sign(rng.standard_normal(5000)),
        "decay": np.exp(-30 * t) * np.sin(2 * np.pi * 30 * t),
        "sigma(t)": 1.0 / np.sqrt(np.arange(1, 5001)),
        "trigger pulses": (np.arange(5000) % 100 == 0).astype(float),
    }
    for name, x in signals.items():
        assert corrupt_samples(x).size == 0, name


@pytest.mark.parametrize("scale", [1e300, 1e-300])
@pytest.mark.parametrize("fit", [lambda u, y: arx(u, y, 2, 2, 1), lambda u,
                                 y: armax(u, y, 2, 2, 1, 1),
                                 lambda u, y: oe(u, y, 2, 2, 1)], ids=["arx", "armax", "oe"])
def test_extreme_but_valid_scales_are_identified_in_the_users_units(scale, fit):
    """Both signals scaled by 1e±300: the same A (and C, F) and B as at unit scale (the internal
    scaling is by exact powers of two: agreement to rounding of the decimal scale factor)."""
    u, y = simulate(2000, noise=0.01)
    ref, m = fit(u, y), fit(u * scale, y * scale)
    np.testing.assert_allclose(m.theta, ref.theta, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(m.theta_std, ref.theta_std, rtol=1e-6)


def test_only_the_output_at_1e300_scales_b_by_1e300():
    u, y = simulate(2000, noise=0.01)
    m = arx(u, y * 1e300, 2, 2, 1)
    np.testing.assert_allclose(m.A[1:], TRUE[:2], atol=0.01)
    np.testing.assert_allclose(m.B[1:] / 1e300, TRUE[2:], atol=0.01)


@pytest.mark.parametrize("scale", [1e300, 1e-300])
def test_structure_search_at_extreme_scales_ranks_as_at_unit_scale(scale):
    """Same ranking and fit % as at unit scale; the AIC shifts by the constant −2M·ln(scale)."""
    u, y = simulate(1000, noise=0.05)
    ref = structure_search(u, y, "1:3", "1:3", "1:2", progress=False)
    res = structure_search(u * scale, y * scale, "1:3", "1:3", "1:2", progress=False)
    assert [(c.na, c.nb, c.nk) for c in res] == [(c.na, c.nb, c.nk) for c in ref]
    assert res.best.na >= 2 and res.best.nb >= 2 and res.best.nk == 1  # holds the true [2 2 1]
    assert res.best.fit_percent == pytest.approx(ref.best.fit_percent, rel=1e-9)
    assert res.best.aic - ref.best.aic == pytest.approx(2 * res.n_used * math.log(scale), rel=1e-9)


@pytest.mark.parametrize("scale", [1e300, 1e-300])
def test_step_and_modal_identification_at_extreme_scales(scale):
    """A 1 kHz, ζ = 0.05 second-order system (gain 0.2): the step fit and the free-vibration
    analysis give the same frequency, damping and gain as at unit scale (before: "output does not
    change" and "damped-sine fit is singular" at 1e-300)."""
    from scipy import signal

    from gripkit import Trajectory
    from gripkit.sysid.physical.modal import free_vibration
    from gripkit.sysid.physical.step_response import identify_step

    fs, wn, zeta = 20000.0, 2 * np.pi * 1000, 0.05
    t = np.arange(4000) / fs
    u = (t > 0.01).astype(float)
    y = signal.lsim(([0.2 * wn**2], [1, 2 * zeta * wn, wn**2]), u, t)[1]
    y = y + 1e-4 * np.random.default_rng(0).standard_normal(t.size)
    ref = identify_step(Trajectory(t, {"u": u, "y": y}), input="u", output="y").to_dict()
    res = (identify_step(Trajectory(t, {"u": u * scale, "y": y * scale}), input="u",
                         output="y").to_dict())
    for key in ("gain", "natural_frequency_hz", "damping_ratio"):
        assert res[key] == pytest.approx(ref[key], rel=1e-6), key
    x = np.exp(-zeta * wn * t) * np.cos(wn * np.sqrt(1 - zeta**2) * t)
    x = x + 1e-4 * np.random.default_rng(1).standard_normal(t.size)
    ref, res = free_vibration(x, dt=1 / fs), free_vibration(x * scale, dt=1 / fs)
    assert res.natural_frequency_hz == pytest.approx(ref.natural_frequency_hz, rel=1e-9)
    assert res.damping_ratio == pytest.approx(ref.damping_ratio, rel=1e-6)
    assert res.amplitude / scale == pytest.approx(ref.amplitude, rel=1e-6)


@pytest.mark.parametrize("scale", [1e300, 1e-300])
def test_friction_identification_at_extreme_scales(scale):
    """IDIM-LS of τ = J q̈ + F_v q̇ + F_c sign(q̇) with both signals scaled: J and F_v (ratios of
    effort to motion) unchanged, F_c in the effort's units (before: "ill-conditioned 4e301" and
    "a regressor column is zero")."""
    from gripkit.sysid.rigid_body.friction import idim_ls

    q = np.sin(2 * np.pi * np.arange(20000) / 1000)
    qd = np.gradient(q) * 1000
    tau = 0.01 * np.gradient(qd) * 1000 + 0.1 * qd + 0.5 * np.sign(qd)
    ref, res = idim_ls(q, tau, dt=0.001), idim_ls(q * scale, tau * scale, dt=0.001)
    for k in ("inertia", "viscous"):
        assert res.params[k] == pytest.approx(ref.params[k], rel=1e-2), k
    assert res.params["coulomb"] / scale == pytest.approx(ref.params["coulomb"], rel=1e-2)


def test_cli_identifies_a_file_at_1e_minus_300(cli, tmp_path):
    u, y = simulate(2000, noise=0.01)
    p = write_csv(tmp_path / "tiny.csv", u * 1e-300, y * 1e-300)
    res = cli(*ARX, p, *ORDERS, "--json")
    assert res.code == 0, res.err
    np.testing.assert_allclose(res.json()["B"][1:], TRUE[2:], atol=0.01)


def test_rls_at_1e300_is_refused_as_overflow_not_as_windup():
    u, y = simulate()
    with pytest.raises(DataError, match=r"values up to [\d.]+e\+30\d in u and y make φᵀPφ "
                                        r"overflow float64"):
        rls(u * 1e300, y * 1e300, 2, 2, 1)


def test_rls_at_1e_minus_300_is_refused_as_outweighed_by_the_prior():
    u, y = simulate()
    with pytest.raises(IdentificationError, match=r"carries almost no information "
                                                  r"next to the prior"):
        rls(u * 1e-300, y * 1e-300, 2, 2, 1)


# ---------------------------------------------------------------- 10. ill-conditioned least squares
def collinear(eps: float, n: int = 2000, seed: int = 3):
    """FIR y = 1.0 u(t−1) + 0.5 u(t−2) + 0.2 u(t−3) + 0.01 e driven by a slow sine plus eps noise:
    the three lagged inputs are nearly collinear (κ ≈ 1.26/eps)."""
    rng = np.random.default_rng(seed)
    u = np.sin(2 * np.pi * 0.001 * np.arange(n)) + eps * rng.standard_normal(n)
    y = np.zeros(n)
    y[3:] = 1.0 * u[2:-1] + 0.5 * u[1:-2] + 0.2 * u[:-3]
    return u, y + 0.01 * rng.standard_normal(n)


def test_ill_conditioned_fit_warns_naming_the_poor_parameters():
    """κ = 1.3e5 < 1e10 (no error), the B estimate is tens of units off the truth [1, 0.5, 0.2]."""
    u, y = collinear(1e-5)
    with pytest.warns(AccuracyWarning, match=r"the data barely determine the parameters "
                                             r"\(regressor condition "
                                             r"number 1.26e\+05 > .*poorly determined are "
                                             r"b\d .*b\d .*b\d "):
        m = arx(u, y, 0, 3, 1)
    assert 1e5 < m.info["cond"] < 1e10 and np.max(np.abs(m.B[1:] - [1.0, 0.5, 0.2])) > 5


def test_the_issue_case_near_the_hard_limit_warns():
    """κ ≈ 9e9, just below the 1e10 hard limit, where the issue found B = [-18100, 36131,
    -18101]."""
    u, y = collinear(1.4e-10)
    with pytest.warns(AccuracyWarning, match="barely determine"):
        m = arx(u, y, 0, 3, 1)
    assert 1e9 < m.info["cond"] < 1e10


def test_well_conditioned_fit_does_not_warn():
    u, y = simulate(2000, noise=0.05)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        m = arx(u, y, 2, 2, 1)
    np.testing.assert_allclose(m.theta, TRUE, atol=5 * np.max(m.theta_std))


def test_cli_ill_conditioned_fit_warns_on_stderr_and_in_json(cli, tmp_path):
    u, y = collinear(1e-5)
    p = write_csv(tmp_path / "c.csv", u, y)
    res = cli("identify", "arx", p, "--input", "current", "--output", "force", "--na", 0, "--nb", 3,
              "--nk", 1,
              "--detrend", "none", "--json")
    assert res.code == 0, res.err
    assert_warned(res, "AccuracyWarning: the data barely determine the parameters")


# ---------------------------------------------------------------- 11. streaming RLS
@pytest.mark.parametrize("bad", [(math.nan, 1.0), (1.0, math.inf), (-math.inf, 0.0)])
def test_rls_update_refuses_non_finite_samples_and_keeps_its_state(bad):
    u, y = simulate(300)
    est = RLS(2, 2, 1)
    for t in range(200):
        est.update(u[t], y[t])
    theta, P, n = est.theta, est.P, est.n_updates
    with pytest.raises(DataError, match="RLS.update: sample 200 is not finite.*the "
                                        "estimator is unchanged"):
        est.update(*bad)
    np.testing.assert_array_equal(est.theta, theta)
    np.testing.assert_array_equal(est.P, P)
    assert est.n_updates == n
    # and it goes on exactly as if the bad sample had never come
    ref = RLS(2, 2, 1)
    for t in range(300):
        ref.update(u[t], y[t])
    for t in range(200, 300):
        est.update(u[t], y[t])
    np.testing.assert_array_equal(est.theta, ref.theta)


def test_rls_update_refuses_text():
    with pytest.raises(DataError, match=r"RLS.update\(u, y\): expected two numbers, found str"):
        RLS(2, 2, 1).update("1.5", 0.0)


def test_rls_update_detects_windup_divergence_like_run():
    """windup='none', λ = 0.9, no excitation: P grows by 1/λ per sample and overflows after
    ln(1.8e308/1e4)/ln(1/0.9) ≈ 6640 samples. update() raises at that sample and keeps the last
    finite state, as run() detects it after the record."""
    est = RLS(2, 2, 1, forgetting=0.9, windup="none")
    with pytest.raises(IdentificationError, match=r"diverged at update \d+; .*windup='none'"):
        for _ in range(10_000):
            est.update(0.0, 0.0)
    assert 6000 < est.n_updates < 7000
    assert np.isfinite(est.P).all() and np.isfinite(est.theta).all()
    with pytest.raises(IdentificationError, match=r"diverged after \d+ updates"):
        # excites a1, a2; u excites b only once
        y = 1e-3 * np.random.default_rng(0).standard_normal(10_000)
        RLS(2, 2, 1, forgetting=0.9, windup="none").run(np.r_[1.0, np.zeros(9999)], y)


def test_one_row_csv_names_the_file(cli, tmp_path):
    p = tmp_path / "one.csv"
    p.write_text("t,u,y\n0,1,2\n")
    res = (cli("identify", "arx", p, "--input", "u", "--output", "y", "--na", 1, "--nb", 1, "--nk",
               1))
    assert_user_error(res, "DataError", "one.csv: 1 sample(s) have no sample interval")


def test_junk_mcap_is_not_read_as_mcap(cli, tmp_path):
    p = tmp_path / "log.mcap"
    p.write_text("junk\n")
    res = (cli("identify", "arx", p, "--input", "u", "--output", "y", "--na", 1, "--nb", 1, "--nk",
               1))
    assert_user_error(res, "DataError", "log.mcap: not an MCAP file")


def test_repeated_column_name_is_refused(cli, tmp_path):
    p = tmp_path / "dup.csv"
    p.write_text("t,u,u\n" + "".join(f"{k / 100},{np.sin(k)},{np.cos(k)}\n" for k in range(50)))
    res = (cli("identify", "arx", p, "--input", "u", "--output", "u", "--na", 1, "--nb", 1, "--nk",
               1))
    assert_user_error(res, "DataError", "column name 'u' appears 2 times")


def test_header_without_rows_names_the_file(cli, tmp_path):
    p = tmp_path / "hdr.csv"
    p.write_text("t,u,y\n")
    res = (cli("identify", "arx", p, "--input", "u", "--output", "y", "--na", 1, "--nb", 1, "--nk",
               1))
    assert_user_error(res, "DataError", "hdr.csv: the file has column names but no data rows")
