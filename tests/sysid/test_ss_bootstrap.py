"""σ of a kept subspace model (gripkit.sysid.linear.ss_bootstrap): when PEM's refinement scores
lower than its subspace start, identify_ss returns the start with the covariance of a seeded
parametric (sieve) bootstrap of the subspace estimate, whose σ of the poles, natural frequency
and damping agree with the Monte Carlo spread of the estimator over independent noise."""

import json
import warnings

import numpy as np
import pytest

import gripkit.sysid.linear.pem_ss as pem_ss
from gripkit import Trajectory
from gripkit.cli import main
from gripkit.errors import AccuracyWarning, ArgumentError, DataError
from gripkit.sysid.linear import ss_bootstrap
from gripkit.sysid import identify, n4sid
from gripkit.sysid.linear.identify_mimo import identify_ss

#: the plant: y[t] = 1.8 y[t−1] − 0.85 y[t−2] + 0.3 u[t−1] + 0.1 u[t−2], poles 0.9 ± 0.2j
POLE = 0.9 + 0.2j


def _record(seed: int, n: int = 500, noise: float = 0.05) -> Trajectory:
    """The plant driven by unit white noise, white output noise of σ ``noise``, dt = 0.01 s."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = np.zeros(n)
    for t in range(2, n):
        y[t] = 1.8 * y[t - 1] - 0.85 * y[t - 2] + 0.3 * u[t - 1] + 0.1 * u[t - 2]
    return Trajectory.uniform(dt=0.01, u=u, y=y + noise * rng.standard_normal(n))


def _losing_pem(model, u=None, y=None, form="innovation", max_iterations=50, progress=False):
    """A "refinement" that damages the model (A scaled by 0.9): it loses by the free-run fit,
    so identify_ss keeps the subspace start."""
    ss = model.system
    return model.replace(system=ss.replace(A=0.9 * ss.A), structure=f"pem-{form}",
                         info={**model.info, "pem": {"converged": True}})


def _mode(model):
    """(|p|, f_n [Hz], ζ) of the upper pole and, when the model carries σ, their σ."""
    d = model.system.damping()
    i = int(np.argmax(d.poles.imag))
    z = d.poles[i]
    out = [abs(z), d.wn[i] / (2 * np.pi), d.zeta[i]]
    if d.wn_std is None:
        return out, None
    _, cov = model.system.pole_covariance()
    g = np.array([z.real, z.imag]) / abs(z)  # ∂|p|/∂(Re p, Im p)
    return out, [float(np.sqrt(g @ cov[i] @ g)), d.wn_std[i] / (2 * np.pi), d.zeta_std[i]]


@pytest.fixture(scope="module")
def monte_carlo():
    """The spread (σ, ddof 1) of |p|, f_n and ζ of the order-2 n4sid estimate over 100
    independent noise records of N = 500 (the estimator's own σ: what the bootstrap must give)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est = [_mode(identify_ss(_record(1000 + s), input="u", output="y", order=2,
                                 refine=False, bootstrap_replicates=0)[0])[0]
               for s in range(100)]
    est = np.array(est)
    assert np.allclose(est.mean(axis=0)[0], abs(POLE), atol=2e-3)  # the estimator is unbiased
    return est.std(axis=0, ddof=1)



def _assert_kept_with_bootstrap_sigma(model, replicates: int, spread, factor: float) -> None:
    """The subspace model was kept, with the covariance of ``replicates`` bootstrap replicates
    (none failed, seed 0), and its σ of |p|, f_n and ζ lie within ``factor`` of the Monte Carlo
    ``spread``."""
    assert model.structure == "n4sid" and model.info["focus"]["kept"] == "subspace"
    assert model.info["covariance"] == {
        "method": "parametric bootstrap", "replicates": replicates, "failed": 0, "seed": 0,
        "estimator": "n4sid (order 2, horizon 6)"}
    ratio = np.array(_mode(model)[1]) / spread
    assert np.all((ratio > 1 / factor) & (ratio < factor)), ratio


def test_bootstrap_sigma_matches_the_monte_carlo_spread(monte_carlo, monkeypatch):
    """On three records, the bootstrap σ (B = 100) of |p|, f_n and ζ lies within a factor 1.5
    of the Monte Carlo spread of 100 records. The band: the Monte Carlo σ and the bootstrap σ
    each carry a sampling error of about 1/√(2·99) = 7 %, and the bootstrap is evaluated at one
    record's estimate, not at the plant (its σ varies from record to record by some 10 % at
    N = 500): a factor 1.5 is about four combined standard errors. Measured ratios 0.90 to 1.29;
    the innovation-form bootstrap this replaced (resampled innovations through the subspace K)
    gave 1.5 to 3.3, so the band tells the two apart."""
    monkeypatch.setattr(pem_ss, "pem", _losing_pem)
    for seed in (7, 8, 9):
        with pytest.warns(AccuracyWarning, match="the subspace model is returned, with σ from a "
                                                 "parametric bootstrap of the subspace "
                                                 "estimate where its replicates allow, not "
                                                 "PEM's covariance"):
            model, _ = identify_ss(_record(seed), input="u", output="y", order=2,
                                   bootstrap_replicates=100)
        _assert_kept_with_bootstrap_sigma(model, 100, monte_carlo, 1.5)


def _pem_warnings(fn):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        model = fn()
    return model, [str(w.message) for w in caught if "PEM refinement lowered" in str(w.message)
                   or "PEM over the records lowered" in str(w.message)]


def test_the_sigma_is_promised_only_to_the_model_that_has_it(monkeypatch):
    """A refinement that loses keeps the subspace model: the warning promises the bootstrap's σ
    when that model is returned with it, not with bootstrap_replicates=0 (no σ: the model has
    none) and not for the candidates of an order search (they are warned about before the
    search picks one; the one returned says its σ in info['covariance'])."""
    monkeypatch.setattr(pem_ss, "pem", _losing_pem)
    monkeypatch.setattr(pem_ss, "pem_records",
                        lambda m, recs, **kw: _losing_pem(m, form=kw.get("form", "innovation")))
    with_sigma, msgs = _pem_warnings(lambda: identify_ss(_record(7), input="u", output="y",
                                                         order=2, bootstrap_replicates=10)[0])
    assert with_sigma.system.uncertainty is not None
    assert len(msgs) == 1 and "with σ from a parametric bootstrap" in msgs[0]
    cases = {"no bootstrap": lambda: identify_ss(_record(7), input="u", output="y", order=2,
                                                 bootstrap_replicates=0)[0],
             "order search": lambda: identify_ss(_record(7), input="u", output="y",
                                                 order="2:3", bootstrap_replicates=10)[0],
             "records, no bootstrap": lambda: identify(
                 [_record(7), _record(8)], "ss", input="u", output="y", order=2,
                 bootstrap_replicates=0)}
    for name, fn in cases.items():
        model, msgs = _pem_warnings(fn)
        assert msgs, name
        assert all("σ from" not in m and "the subspace model is kept (without PEM's "
                   "covariance)" in m for m in msgs), (name, msgs)
    assert model.system.uncertainty is None  # the records' model with 0 replicates: no σ


def test_same_seed_same_sigma_other_seed_close():
    """The draws come from default_rng(seed): the same seed gives the same covariance to the
    last bit; another seed gives another draw of the same σ (within the 1/√(2B) sampling error
    of B = 30 replicates: 13 %, so within 40 %)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start, _ = identify_ss(_record(3), input="u", output="y", order=2, refine=False,
                               bootstrap_replicates=0)
    from gripkit.sysid.linear.identify_mimo import mimo_data
    from gripkit.sysid.linear.subspace import from_factor, subspace_factor

    d = mimo_data(_record(3), "u", "y")
    refit = lambda u, y: from_factor(subspace_factor(u, y, horizon=6, method="n4sid"),  # noqa
                                     2, dt=d.dt)
    runs = [ss_bootstrap.bootstrap_covariance(start, d.u, d.y, refit, estimator="n4sid",
                                              replicates=30, seed=s, demean=True)
            for s in (ss_bootstrap.BOOTSTRAP_SEED, ss_bootstrap.BOOTSTRAP_SEED, 1)]
    a, b, c = (r.system.uncertainty.covariance for r in runs)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)
    sa, sc = np.array(_mode(runs[0])[1]), np.array(_mode(runs[2])[1])
    assert np.all(np.abs(sa / sc - 1) < 0.4), sa / sc
    assert ss_bootstrap.covariance_method(runs[2]) == ("parametric bootstrap of the n4sid "
                                                       "estimate, B = 30 replicates, seed 1")


def test_replicates_follow_the_record_length():
    """100 replicates up to 20 000 samples, then 2e6 / N, never below 30."""
    assert [ss_bootstrap.bootstrap_replicates(n) for n in (500, 20_000, 40_000, 100_000, 10**7)] \
        == [100, 100, 50, 30, 30]
    assert (ss_bootstrap.MAX_REPLICATES, ss_bootstrap.MIN_REPLICATES) == (100, 30)


def test_bad_bootstrap_options():
    """One validation (ss_bootstrap.check_bootstrap) for identify_ss's bootstrap_replicates,
    the records' fit and n4sid's bootstrap: an ArgumentError naming the argument."""
    tr = _record(4, n=300)
    with pytest.raises(ArgumentError, match="bootstrap_replicates: expected None or True .* 0 or "
                                            "False .* or an integer >= 10 .*found 3"):
        identify_ss(tr, input="u", output="y", order=2, bootstrap_replicates=3)
    with pytest.raises(ArgumentError, match="bootstrap_seed: expected a non-negative integer, "
                                            "found -1"):
        identify_ss(tr, input="u", output="y", order=2, bootstrap_seed=-1)
    with pytest.raises(ArgumentError, match="bootstrap_replicates: .*found -1"):
        identify([tr, _record(5, n=300)], "ss", input="u", output="y", order=2,
                 bootstrap_replicates=-1)
    with pytest.raises(ArgumentError, match="bootstrap: expected None or True .*found 3"):
        n4sid(np.ones(300), np.ones(300), 2, bootstrap=3)
    with pytest.raises(ArgumentError, match="bootstrap_seed: .*found 'a'"):
        n4sid(np.ones(300), np.ones(300), 2, bootstrap=True, bootstrap_seed="a")


def test_zero_replicates_is_no_bootstrap_in_both():
    """``n4sid(bootstrap=0)`` is ``bootstrap=False`` (no σ, info['sigma'] says so), as
    ``identify_ss(bootstrap_replicates=0)`` is (it was a DataError in n4sid)."""
    from gripkit.sysid.linear.identify_mimo import mimo_data
    from gripkit.sysid.linear.subspace import NO_SIGMA

    d = mimo_data(_record(7), "u", "y", detrend="none")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        zero = n4sid(d.u, d.y, 2, dt=d.dt, bootstrap=0)
        false = n4sid(d.u, d.y, 2, dt=d.dt, bootstrap=False)
        ss0, _ = identify_ss(_record(7), input="u", output="y", order=2, refine=False,
                             detrend="none", bootstrap_replicates=0)
    assert zero.system.uncertainty is None and zero.info["sigma"] == NO_SIGMA
    assert np.array_equal(zero.system.A, false.system.A)
    assert ss0.system.uncertainty is None and np.array_equal(ss0.system.A, zero.system.A)


def test_cli_prints_and_writes_the_bootstrap_sigma(tmp_path, capsys, monkeypatch):
    """`gripkit identify ss` with a refinement that loses: the text and the report give the σ
    method, the text every pole with its σ; the JSON carries poles_std (those of the Python call
    on the same file), covariance_method and info.covariance, and the warning names the
    bootstrap. Run twice: the same output (the default seed). A refinement that wins: σ from
    PEM, said so."""
    from gripkit.io import load, save

    path = tmp_path / "est.csv"
    save(_record(5), path)
    args = ["identify", "ss", str(path), "--input", "u", "--output", "y", "--order", "2"]
    real = pem_ss.pem
    monkeypatch.setattr(pem_ss, "pem", _losing_pem)
    assert main(args + ["--report", str(tmp_path / "rep")]) == 0
    text = capsys.readouterr().out
    assert ("The covariance is that of a parametric bootstrap of the n4sid (order 2, horizon 6) "
            "estimate, B = 100 replicates, seed 0: the subspace model was kept in place of the "
            "PEM refinement, and this is no PEM covariance.") \
        in (tmp_path / "rep" / "index.html").read_text()
    assert "σ: parametric bootstrap of the n4sid (order 2, horizon 6) estimate, B = 100 " \
           "replicates, seed 0" in text
    poles = [ln for ln in text.splitlines() if ln.strip().startswith("pole ")]
    assert len(poles) == 2 and all(" ± (" in ln for ln in poles)
    outs = []
    for _ in range(2):
        assert main(args + ["--json"]) == 0
        outs.append(capsys.readouterr().out)
    assert outs[0] == outs[1]
    r = json.loads(outs[0])
    assert r["covariance_method"].startswith("parametric bootstrap of the n4sid")
    assert r["info"]["covariance"]["replicates"] == 100 and r["info"]["covariance"]["seed"] == 0
    assert any("with σ from a parametric bootstrap" in w for w in r["warnings"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model, _ = identify_ss(load(path), input="u", output="y", order=2)
    _, cov = model.system.pole_covariance()
    want = [[np.sqrt(c[0, 0]), np.sqrt(c[1, 1])] for c in cov]
    assert np.allclose(r["poles_std"], want, rtol=1e-9) and np.all(np.array(want) > 0)
    monkeypatch.setattr(pem_ss, "pem", real)
    assert main(args + ["--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["structure"].startswith("pem") and r["covariance_method"].startswith("PEM")
    assert "covariance" not in r["info"]


def _losing_pem_records(model, records, form="innovation", max_iterations=50, progress=False):
    """:func:`_losing_pem` over several records: identify_ss_records keeps the subspace start."""
    return _losing_pem(model, form=form)


def _records(first: int, n: int = 300) -> list:
    """Three records of the plant (seeds first, first + 1, first + 2), N = ``n`` each."""
    return [_record(first + r, n=n) for r in range(3)]


def test_records_bootstrap_sigma_matches_the_monte_carlo_spread(monkeypatch):
    """Several records (three of N = 300), the refinement over the records losing: the subspace
    model of all records carries the σ of a bootstrap whose replicates are each record's free
    run from its own initial state plus its own resampled disturbance, refitted jointly. Its σ
    of |p|, f_n and ζ (B = 40) lies within a factor 1.6 of the Monte Carlo spread of the same
    estimator over 60 independent sets of three records. The band: sampling errors of about
    1/√(2·59) = 9 % (Monte Carlo) and 1/√(2·39) = 11 % (bootstrap), and some 10 % from one set's
    estimate to the next: 1.6 is about three combined standard errors; measured 0.77 to 1.21 on
    six sets. The same seed gives the same covariance to the last bit, another seed another."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est = np.array([_mode(identify(_records(2000 + 10 * s), "ss", input="u", output="y",
                                       order=2, refine=False, bootstrap_replicates=0))[0]
                        for s in range(60)])
    assert est.mean(axis=0)[0] == pytest.approx(abs(POLE), abs=2e-4)  # unbiased
    spread = est.std(axis=0, ddof=1)
    monkeypatch.setattr(pem_ss, "pem_records", _losing_pem_records)
    for first in (100, 110, 120):
        with pytest.warns(AccuracyWarning, match="PEM over the records lowered .* the subspace "
                                                 "model is returned, with σ from a parametric "
                                                 "bootstrap of the subspace estimate"):
            model = identify(_records(first), "ss", input="u", output="y", order=2,
                             bootstrap_replicates=40)
        _assert_kept_with_bootstrap_sigma(model, 40, spread, 1.6)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        runs = [identify(_records(100), "ss", input="u", output="y", order=2,
                         bootstrap_replicates=10, bootstrap_seed=seed) for seed in (0, 0, 1)]
    a, b, c = (m.system.uncertainty.covariance for m in runs)
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    assert ss_bootstrap.covariance_method(runs[2]) == (
        "parametric bootstrap of the n4sid (order 2, horizon 6) estimate, B = 10 replicates, "
        "seed 1")


def test_records_replicates_follow_all_samples(monkeypatch):
    """The count rule on the samples of all records together: with the budget set to 40 × 900,
    three records of 300 samples get 40 replicates (by one record's 300 samples they would get
    100)."""
    monkeypatch.setattr(ss_bootstrap, "SAMPLE_BUDGET", 40 * 900)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = identify(_records(130), "ss", input="u", output="y", order=2, refine=False)
    assert model.info["covariance"]["replicates"] == 40 and model.info["refined"] is False


def test_cli_several_files_print_the_bootstrap_sigma(tmp_path, capsys, monkeypatch):
    """`gripkit identify ss A B C` whose refinement over the records loses: the σ line, every
    pole with its σ, and the JSON's covariance_method, info.covariance and poles_std, those of
    the Python call on the same files (B = 100 by the 900 samples, seed 0)."""
    from gripkit.io import load, save

    paths = []
    for i, tr in enumerate(_records(140)):
        paths.append(tmp_path / f"rec{i}.csv")
        save(tr, paths[-1])
    monkeypatch.setattr(pem_ss, "pem_records", _losing_pem_records)
    args = ["identify", "ss", *map(str, paths), "--input", "u", "--output", "y", "--order", "2"]
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "σ: parametric bootstrap of the n4sid (order 2, horizon 6) estimate, B = 100 " \
           "replicates, seed 0" in text
    poles = [ln for ln in text.splitlines() if ln.strip().startswith("pole ")]
    assert len(poles) == 2 and all(" ± (" in ln for ln in poles)
    assert main(args + ["--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["covariance_method"].startswith("parametric bootstrap of the n4sid")
    assert r["info"]["covariance"]["replicates"] == 100 and len(r["records"]) == 3
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = identify([load(p) for p in paths], "ss", input="u", output="y", order=2)
    _, cov = model.system.pole_covariance()
    want = [[np.sqrt(c[0, 0]), np.sqrt(c[1, 1])] for c in cov]
    assert np.allclose(r["poles_std"], want, rtol=1e-9) and np.all(np.array(want) > 0)


def test_no_refine_carries_the_bootstrap_sigma(tmp_path, capsys):
    """`identify ss --no-refine`: the subspace model with the bootstrap σ (B = 100 by the 500
    samples, seed 0), said in the σ line, the JSON (covariance_method, info.covariance,
    info.refined false) and the report (PEM skipped, not 'kept in place of the refinement');
    the same poles_std as the Python call. bootstrap_replicates=0 gives the subspace model
    alone, without σ, and the same poles."""
    from gripkit.io import load, save

    path = tmp_path / "est.csv"
    save(_record(6), path)
    args = ["identify", "ss", str(path), "--input", "u", "--output", "y", "--order", "2",
            "--no-refine"]
    assert main(args + ["--report", str(tmp_path / "rep")]) == 0
    text = capsys.readouterr().out
    assert "σ: parametric bootstrap of the n4sid (order 2, horizon 6) estimate, B = 100 " \
           "replicates, seed 0" in text
    assert ("estimate, B = 100 replicates, seed 0: the subspace model was not refined (PEM "
            "skipped, --no-refine), and this is no PEM covariance.") \
        in (tmp_path / "rep" / "index.html").read_text()
    assert main(args + ["--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["refined"] is False and r["info"]["refined"] is False
    assert r["covariance_method"].startswith("parametric bootstrap of the n4sid")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model, _ = identify_ss(load(path), input="u", output="y", order=2, refine=False)
        alone, _ = identify_ss(load(path), input="u", output="y", order=2, refine=False,
                               bootstrap_replicates=0)
    _, cov = model.system.pole_covariance()
    want = [[np.sqrt(c[0, 0]), np.sqrt(c[1, 1])] for c in cov]
    assert np.allclose(r["poles_std"], want, rtol=1e-9) and np.all(np.array(want) > 0)
    assert alone.system.uncertainty is None and "covariance" not in alone.info
    assert np.array_equal(alone.system.A, model.system.A)


def test_n4sid_sigma_only_when_asked():
    """A direct n4sid() call: without ``bootstrap`` no σ, and info['sigma'] says how to get it;
    ``bootstrap=30`` gives the covariance that identify_ss(refine=False, detrend='none') gives
    with 30 replicates (the same estimation and draws: equal to the last bit). PEM from a
    bootstrapped start carries PEM's covariance and says so (the start's σ note dropped)."""
    from gripkit.sysid import pem
    from gripkit.sysid.linear.identify_mimo import mimo_data
    from gripkit.sysid.linear.subspace import NO_SIGMA

    d = mimo_data(_record(7), "u", "y", detrend="none")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plain = n4sid(d.u, d.y, 2, dt=d.dt)
        boot = n4sid(d.u, d.y, 2, dt=d.dt, bootstrap=30, bootstrap_seed=3)
        ref, _ = identify_ss(_record(7), input="u", output="y", order=2, refine=False,
                             detrend="none", bootstrap_replicates=30, bootstrap_seed=3)
    assert plain.system.uncertainty is None and plain.info["sigma"] == NO_SIGMA
    assert "n4sid(..., bootstrap=True) gives σ" in NO_SIGMA
    assert np.array_equal(boot.system.uncertainty.covariance, ref.system.uncertainty.covariance)
    assert ss_bootstrap.covariance_method(boot) == ("parametric bootstrap of the n4sid (order 2, "
                                                    "horizon 6) estimate, B = 30 replicates, "
                                                    "seed 3")
    refined = pem(boot, u=d.u, y=d.y)
    assert "covariance" not in refined.info and "sigma" not in refined.info
    assert ss_bootstrap.covariance_method(refined).startswith("PEM")
    assert "sigma" not in pem(plain, u=d.u, y=d.y).info


def _start_and_refit(record, detrend="mean"):
    from gripkit.sysid.linear.identify_mimo import mimo_data
    from gripkit.sysid.linear.subspace import from_factor, subspace_factor

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start, _ = identify_ss(record, input="u", output="y", order=2, refine=False,
                               detrend=detrend, bootstrap_replicates=0)
    d = mimo_data(record, "u", "y", detrend=detrend)
    refit = lambda u, y: from_factor(subspace_factor(u, y, horizon=6, method="n4sid"),  # noqa
                                     2, dt=d.dt)
    return start, d, refit


def test_a_linalg_error_is_a_failed_replicate():
    """A replicate whose refit raises numpy's LinAlgError (a degenerate replicate) counts as
    failed (it aborted the whole identification): every 5th of 30 refits raising, 24 replicates
    give σ and info['covariance']['failed'] is 6; a refit whose system is not finite (the
    alignment's SVD does not converge) is a failed replicate too (None)."""
    start, d, refit = _start_and_refit(_record(3))
    calls = []

    def flaky(u, y):
        calls.append(1)
        if len(calls) % 5 == 0:
            raise np.linalg.LinAlgError("Singular matrix")
        return refit(u, y)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out = ss_bootstrap.bootstrap_covariance(start, d.u, d.y, flaky, estimator="n4sid",
                                                replicates=30, demean=True)
    assert out.info["covariance"]["failed"] == 6 and out.info["covariance"]["replicates"] == 24
    assert out.system.uncertainty is not None
    ss = start.system
    bad = type("Refit", (), {"A": np.full_like(ss.A, np.nan), "B": ss.B, "C": ss.C, "D": ss.D})
    w = np.ones(1)
    assert ss_bootstrap._aligned(bad, ss_bootstrap._observability(ss.A, ss.C, w), w,
                                 False) is None


def test_linear_detrending_is_redone_on_every_replicate():
    """bootstrap_covariance(detrend='linear'): the data's least-squares line was taken off before
    the fit, so each replicate's simulated output has its line taken off too (only the 'mean'
    was redone); every output the refit sees has a zero line (mean and slope within 1e-12 of the
    output's span). identify_ss itself refuses detrend='linear' (a line per column leaves the
    model no operating point), so 'mean' and 'none' are what it passes."""
    from scipy.signal import detrend

    tr = _record(5)
    t = np.arange(500) * 0.01
    tr = Trajectory.uniform(dt=0.01, u=np.asarray(tr["u"]), y=np.asarray(tr["y"]) + 0.8 * t + 2)
    start, d, refit = _start_and_refit(tr, detrend="none")
    u, y = detrend(d.u, axis=0), detrend(d.y, axis=0)
    seen = []
    spy = lambda uu, yy: seen.append(np.array(yy)) or refit(uu, yy)  # noqa: E731
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out = ss_bootstrap.bootstrap_covariance(start, u, y, spy, estimator="n4sid",
                                                replicates=10, detrend="linear")
    assert out.info["covariance"]["replicates"] + out.info["covariance"]["failed"] == 10
    assert len(seen) == 10
    x = np.arange(500) - 249.5
    for yy in seen:
        span = np.ptp(yy)
        assert abs(np.mean(yy)) < 1e-12 * span and abs(x @ yy[:, 0] / (x @ x)) < 1e-12 * span
    with pytest.raises(ArgumentError, match="detrend: expected 'mean', 'linear' or 'none', "
                                            "found 'quadratic'"):
        ss_bootstrap.bootstrap_covariance(start, u, y, refit, estimator="n4sid",
                                          replicates=10, detrend="quadratic")
    with pytest.raises(DataError, match="detrend: expected 'mean' or 'none', found 'linear'"):
        identify_ss(tr, input="u", output="y", order=2, detrend="linear")
