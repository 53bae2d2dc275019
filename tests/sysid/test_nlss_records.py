"""Nonlinear state space (PNLSS) of several records (issues 25 and 26): each record's free run
from its own estimated initial state, windows inside the records (never across a seam), one θ,
σ from all records. The estimate is checked as the stationary point of Σ_r ‖y_r − ŷ_r(θ, x0_r)‖²
(finite differences through the model's own free run, independent of the fit's sensitivity
kernels), against the joined record, and σ of the simulated output (basis invariant)."""

import numpy as np
import pytest
from test_nlss import _input, duffing  # the Duffing oscillator and input of the one-record tests

from gripkit import Trajectory
from gripkit.errors import DataError
from gripkit.sysid import identify, nlss
from gripkit.sysid.nonlinear.nlss import _apply

N = 1500


@pytest.fixture(scope="module")
def records():
    """Two records that start settled at the inputs +1.5 and −1.5 (their own initial states,
    x ≈ ±0.6), output noise 1 % of its standard deviation."""
    rng = np.random.default_rng(0)
    out = []
    for level in (1.5, -1.5):
        u = np.r_[np.full(100, level), _input(rng, N)]
        y0 = duffing(u)
        out.append((u[100:], y0[100:] + rng.normal(0.0, 0.01 * y0.std(), N + 100)[100:]))
    return out


@pytest.fixture(scope="module")
def fit(records):
    return nlss(records, order=2, degree=3, progress=False)


def _sse(model, runs):
    """Σ over ``runs`` = [(u, y, x0)] of the free run's squared error (model.simulate)."""
    total = 0.0
    for u, y, x0 in runs:
        e = y - model.simulate(u, x0, warn=False)[:, 0]
        total += float(e @ e)
    return total


def _newton_steps(model, runs):
    """Per free parameter j, the Newton step g_j / c_j (central differences, h = 0.1 σ_j) of
    :func:`_sse` in units of σ_j."""
    sd = np.sqrt(np.diag(model.covariance))
    out = np.empty(len(sd))
    v0 = _sse(model, runs)
    for j, s in enumerate(sd):
        d = np.zeros(len(sd))
        d[j] = 0.1 * s
        vp, vm = _sse(_apply(model, model.dirs, d), runs), _sse(_apply(model, model.dirs, -d), runs)
        g, c = (vp - vm) / (0.2 * s), (vp - 2 * v0 + vm) / (0.1 * s) ** 2
        out[j] = g / c / s
    return out


def test_two_records_are_the_optimum_with_each_records_own_initial_state(records, fit):
    x0s = [np.array(r["x0"]) for r in fit.info["records"]]
    runs = [(u, y, x0) for (u, y), x0 in zip(records, x0s)]
    steps = _newton_steps(fit, runs)
    # every parameter within 0.1σ of the minimum of the per-record criterion (0.04σ here; the
    # fit stops when a step lowers the SSE by < 0.01 σ², i.e. about 0.1σ from the minimum)
    assert np.max(np.abs(steps)) < 0.1, np.max(np.abs(steps))
    # each record's initial state is its own (settled at ±1.5: opposite signs)
    assert np.sign(x0s[0][0]) == -np.sign(x0s[1][0])
    assert [r["n_samples"] for r in fit.info["records"]] == [N, N]
    assert fit.info["windows"] >= 2 * 2 and fit.fit_percent[0] > 98.5
    assert all(r["fit_percent"][0] > 98.5 for r in fit.info["records"])
    # the joined record, run from the first record's state across the seam, is NOT at its
    # minimum there: some parameter would move by more than 1σ (14σ here)
    (u1, y1), (u2, y2) = records
    joined_run = [(np.r_[u1, u2], np.r_[y1, y2], x0s[0])]
    assert np.max(np.abs(_newton_steps(fit, joined_run))) > 1.0


def test_joined_record_is_worse_at_the_seam(records, fit):
    (u1, y1), (u2, y2) = records
    uj, yj = np.r_[u1, u2], np.r_[y1, y2]
    joined = nlss((uj, yj), order=2, degree=3, progress=False)
    noise = 0.01 * np.std(yj)
    e_joined = (yj - joined.simulate(uj, joined.x0)[:, 0])[N:N + 30]
    e_rec = (y2 - fit.simulate(u2, np.array(fit.info["records"][1]["x0"]))[:, 0])[:30]
    assert np.sqrt(np.mean(e_joined**2)) > 10 * noise  # a false transient (≈ 0.45 here)
    assert np.sqrt(np.mean(e_rec**2)) < 2 * noise
    assert joined.fit_percent[0] < fit.fit_percent[0] - 5  # 87 % against 98.9 %


def test_sigma_of_the_output_from_both_records_about_one_over_sqrt2(records, fit):
    """σ of the simulated output (invariant to the state basis) on a fresh input."""
    one = nlss(records[0], order=2, degree=3, progress=False)
    u = _input(np.random.default_rng(5), 1000)
    ratio = np.median(fit.simulate(u, std=True)[1] / one.simulate(u, std=True)[1])
    assert 0.55 < ratio < 0.85, ratio


def test_identify_and_a_mismatched_record_is_named(records, fit):
    trs = [Trajectory.uniform(dt=0.1, f=u, x=y) for u, y in records]
    m = identify(trs, "nlss", input="f", output="x", order=2, degree=3, progress=False)
    assert m.inputs == ("f",) and m.outputs == ("x",) and m.dt == 0.1
    assert m.fit_percent[0] == pytest.approx(fit.fit_percent[0], abs=1e-6)
    (u2, y2) = records[1]
    with pytest.raises(DataError, match=r"data\[1\] is sampled at 5 Hz, data\[0\] at 10 Hz"):
        nlss([trs[0], Trajectory.uniform(dt=0.2, f=u2, x=y2)], input="f", output="x", order=2)
    with pytest.raises(DataError, match=r"data\[1\] has no column"):
        nlss([trs[0], Trajectory.uniform(dt=0.1, f=u2, z=y2)], input="f", output="x", order=2)
    with pytest.raises(DataError, match=r"data\[1\].*'x'"):
        identify([trs[0], Trajectory.uniform(dt=0.1, f=u2, z=y2)], "nlss", input="f",
                 output="x", order=2)


def test_cli_identify_nlss_of_two_files(records, fit, tmp_path, capsys):
    import json

    from gripkit.cli import main

    paths = [tmp_path / "run1.csv", tmp_path / "run2.csv"]
    for path, (u, y) in zip(paths, records):
        np.savetxt(path, np.column_stack([u, y]), delimiter=",", header="f,x", comments="",
                   fmt="%.17g")
    code = main([*map(str, ["identify", "nlss", *paths, "--input", "f", "--output", "x", "--fs",
                            10, "--order", 2, "--degree", 3, "--json"])])
    out, err = capsys.readouterr()
    assert code == 0, err
    d = json.loads(out)
    assert d["data"] == [str(p) for p in paths]
    assert [r["data"] for r in d["records"]] == [str(p) for p in paths]
    assert "x0" not in d["records"][0] and d["records"][0]["n_samples"] == N
    assert d["fit_percent"][0] == pytest.approx(fit.fit_percent[0], abs=1e-6)
    np.testing.assert_allclose([r["fit_percent"][0] for r in d["records"]],
                               [r["fit_percent"][0] for r in fit.info["records"]], atol=1e-6)
