"""Hammerstein–Wiener fits of several records (issues 25 and 26): each record's free run from its
own steady state (its own w₋), one θ, σ from all records; against an independent scipy fit with
per-record initial states, and against the joined record's false transient at the seam."""

import numpy as np
import pytest
from scipy.optimize import least_squares
from scipy.signal import lfilter, lfilter_zi

from gripkit import Trajectory
from gripkit.errors import ArgumentError, DataError
from gripkit.sysid import hammerstein_wiener, identify

#: a Wiener system with memory (poles 0.75 ± 0.37j) and g(x) = x + 0.2 x² − 0.1 x³
B, F = [0.0, 0.1, 0.06], [1.0, -1.5, 0.7]
KW = dict(output_nonlinearity="poly:3", nb=2, nf=2, nk=1)


def _record(rng, n, level, noise=0.05):
    """A record that starts settled at the constant input ``level`` (its own initial state)."""
    u = np.r_[np.full(200, level), rng.uniform(-2.0, 2.0, n)]
    x = lfilter(B, F, u)
    y = x + 0.2 * x**2 - 0.1 * x**3 + noise * rng.normal(size=len(u))
    return u[200:], y[200:]


@pytest.fixture(scope="module")
def records():
    rng = np.random.default_rng(1)
    return [_record(rng, 400, 1.2), _record(rng, 400, -1.2)]


@pytest.fixture(scope="module")
def fit(records):
    return hammerstein_wiener(records, **KW)


def _scipy_records(recs):
    """θ of the same Wiener model by scipy's least_squares, each record run by lfilter from the
    steady state of its own constant input w₋ (lfilter_zi), started at the true values."""
    def resid(p):
        out = []
        for (u, y), w in zip(recs, p[7:]):
            b, f = np.r_[0.0, p[0:2]], np.r_[1.0, p[2:4]]
            x = lfilter(b, f, u, zi=lfilter_zi(b, f) * w)[0]
            out.append(y - (x + p[4] * x**2 + p[5] * x**3 + p[6]))
        return np.concatenate(out)

    p0 = np.r_[0.1, 0.06, -1.5, 0.7, 0.2, -0.1, 0.0, 1.2, -1.2]
    return least_squares(resid, p0, xtol=1e-12, ftol=1e-12, gtol=1e-12).x


def test_two_records_equal_the_fit_with_each_records_own_initial_state(records, fit):
    ref = _scipy_records(records)
    assert fit.names == ["b1", "b2", "f1", "f2", "out_c2", "out_c3", "y0"]
    # θ within 0.001σ of the independent reference; each record's w₋ its own (≈ ±1.2, settled)
    assert np.all(np.abs(fit.theta - ref[:7]) < 1e-3 * fit.theta_std)
    np.testing.assert_allclose([r["initial_input"] for r in fit.records], ref[7:], atol=1e-4)
    assert [r["n_samples"] for r in fit.records] == [400, 400]
    # and the truth within 3σ
    truth = np.r_[0.1, 0.06, -1.5, 0.7, 0.2, -0.1, 0.0]
    assert np.all(np.abs(fit.theta - truth) < 3 * fit.theta_std)
    assert all(r["fit_percent"] > 85 for r in fit.records) and fit.fit_percent > 85


def test_structure_and_orders_found_on_two_records(records):
    """Nothing given: the Wiener structure poly:3 and the orders [2 2 1] chosen by BIC."""
    m = hammerstein_wiener(records)
    assert (m.kind, m.output_nl.label, m.nb, m.nf, m.nk) == ("wiener", "poly:3", 2, 2, 1)


def test_joined_record_is_different_and_worse_at_the_seam(records, fit):
    (u1, y1), (u2, y2) = records
    joined = hammerstein_wiener(np.r_[u1, u2], np.r_[y1, y2], **KW)
    # the joined fit moves θ (up to ~2σ here) ...
    assert np.max(np.abs(joined.theta - fit.theta) / fit.theta_std) > 1.0
    # ... and its free run carries a false transient after the seam: the first 20 samples of the
    # second record are > 3× the noise (0.05) off, where the records fit is at the noise level
    e_joined = (np.r_[y1, y2] - joined.simulate(np.r_[u1, u2])[:, 0])[400:420]
    e_rec = (y2 - fit.compare(u2, y2).simulated[:, 0])[:20]
    assert np.sqrt(np.mean(e_joined**2)) > 0.15
    assert np.sqrt(np.mean(e_rec**2)) < 0.07


def test_sigma_from_both_records_about_one_over_sqrt2(records, fit):
    one = hammerstein_wiener(*records[0], **KW)
    ratio = fit.theta_std / one.theta_std
    assert np.all((ratio > 0.55) & (ratio < 0.85)), ratio


def test_identify_with_a_list_of_trajectories(records, fit):
    trs = [Trajectory.uniform(dt=0.01, valve=u, force=y) for u, y in records]
    m = identify(trs, "hw", input="valve", output="force", nb=2, nf=2, nk=1,
                 output_nonlinearity="poly:3")
    np.testing.assert_allclose(m.theta, fit.theta, rtol=0, atol=1e-10)
    assert m.inputs == ("valve",) and m.outputs == ("force",) and m.dt == 0.01
    assert len(m.to_dict()["records"]) == 2


def test_a_mismatched_record_is_named(records):
    (u1, y1), (u2, y2) = records
    tr1 = Trajectory.uniform(dt=0.01, valve=u1, force=y1)
    with pytest.raises(DataError, match=r"data\[1\] is sampled at 50 Hz"):
        identify([tr1, Trajectory.uniform(dt=0.02, valve=u2, force=y2)], "hw", input="valve",
                 output="force", **KW)
    with pytest.raises(DataError, match=r"data\[1\].*'force'"):
        identify([tr1, Trajectory.uniform(dt=0.01, valve=u2, grip=y2)], "hw", input="valve",
                 output="force", **KW)
    with pytest.raises(DataError, match=r"data\[1\]: the output is constant"):
        identify([tr1, Trajectory.uniform(dt=0.01, valve=u2, force=np.ones_like(y2))], "hw",
                 input="valve", output="force", **KW)
    with pytest.raises(DataError, match=r"records\[1\]: u has 400 samples but y has 399"):
        hammerstein_wiener([(u1, y1), (u2, y2[:-1])], **KW)
    with pytest.raises(ArgumentError, match="non-empty list of records"):
        hammerstein_wiener([], **KW)


def _cli(capsys, *args):
    from gripkit.cli import main

    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_identify_hw_of_two_files(records, fit, tmp_path, capsys):
    import json

    paths = [tmp_path / "grasp1.csv", tmp_path / "grasp2.csv"]
    for path, (u, y) in zip(paths, records):
        np.savetxt(path, np.column_stack([u, y]), delimiter=",", header="valve,force",
                   comments="", fmt="%.17g")
    code, out, err = _cli(capsys, "identify", "hw", *paths, "--input", "valve", "--output",
                          "force", "--fs", 100, "--output-nonlinearity", "poly:3", "--nb", 2,
                          "--nf", 2, "--nk", 1, "--json")
    assert code == 0, err
    d = json.loads(out)
    assert d["data"] == [str(p) for p in paths]
    assert [r["data"] for r in d["records"]] == [str(p) for p in paths]
    np.testing.assert_allclose([r["fit_percent"] for r in d["records"]],
                               [r["fit_percent"] for r in fit.records], atol=1e-6)
    np.testing.assert_allclose([p["value"] for p in d["parameters"]], fit.theta, atol=1e-8)
    assert d["fit_percent"] == pytest.approx(fit.fit_percent, abs=1e-6)
    code, out, err = _cli(capsys, "identify", "hw", *paths, "--input", "valve", "--output",
                          "force", "--fs", 100, "--output-nonlinearity", "poly:3", "--nb", 2,
                          "--nf", 2, "--nk", 1)
    assert code == 0, err
    assert "2 records, each with its own initial conditions" in out and "free run" in out
    bad = tmp_path / "other.csv"
    np.savetxt(bad, np.column_stack(records[1]), delimiter=",", header="valve,grip",
               comments="")
    code, out, err = _cli(capsys, "identify", "hw", paths[0], bad, "--input", "valve",
                          "--output", "force", "--fs", 100)
    assert code != 0 and err.startswith("error: ") and "other.csv" in err and "force" in err
