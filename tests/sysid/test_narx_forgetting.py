"""Polynomial NARX with a forgetting factor (issue 26): θ by exponentially weighted least squares
``min Σ λ^age e²`` with the sandwich σ, on the DC-motor record against SysIdentPy's published
figures, on a drifting system, and against a Monte Carlo spread."""

import json
from pathlib import Path

import numpy as np
import pytest

from gripkit.errors import ArgumentError
from gripkit.sysid import narx
from gripkit.sysid.nonlinear.narx import _Regression, candidate_terms, _regression_matrix
from test_narx import TRUE, _true_system  # Billings' example (Billings 2013)

FIXTURE = Path(__file__).resolve().parents[1] / "fixtures" / "dc_motor" / "dc_motor.csv"

#: SysIdentPy's best published free-run figure on this record (its tutorial
#: docs/en/user-guide/tutorials/electromechanical-system-identification-metamss.md, repository
#: wilsonrljr/sysidentpy at 76b75e4: MetaMSS, degree 2, lags 5, RecursiveLeastSquares(lam=0.95),
#: "Free-run RRSE: 0.031354" on the last 500 samples after max_lag), as a fit: 100 (1 − RRSE)
SYSIDENTPY_BEST = 100.0 * (1.0 - 0.031354)

@pytest.fixture(scope="module")
def dc_motor():
    d = np.loadtxt(FIXTURE, delimiter=",", skiprows=1)
    return d[:500, 0], d[:500, 1], d[500:, 0], d[500:, 1]


def test_dc_motor_forgetting_reaches_sysidentpy_best_published_fit(dc_motor):
    """SysIdentPy's split. Its figures above 94.1 % all estimate θ by recursive least squares
    with a forgetting factor (0.98 its default, 0.95): the record's first ~300 samples behave
    unlike the rest (a model of the validation half explains samples 0–99 at 46 %, 300–999 at
    97–99 %). The cubic NARX (lags 2) with λ = 0.98: 97.84 % without looking at the validation
    record (BIC), 97.97 % with the number of terms by validation fit (measured), against
    SysIdentPy's best published 96.86 % and 94.03 % for λ = 1 (the same structure search)."""
    ue, ye, uv, yv = dc_motor
    blind = narx(ue, ye, degree=3, lags=2, forgetting=0.98)
    assert blind.compare(uv, yv).fit_percent[0] >= SYSIDENTPY_BEST
    assert "exponentially weighted least squares (forgetting 0.98" in blind.criterion
    chosen = narx(ue, ye, degree=3, lags=2, forgetting=0.98, validate=(uv, yv))
    assert chosen.validation_fit_percent >= SYSIDENTPY_BEST
    plain = narx(ue, ye, degree=3, lags=2, validate=(uv, yv))
    assert chosen.validation_fit_percent > plain.validation_fit_percent + 3.0
    # why: the model of the validation half explains the estimation half's first 100 samples at
    # 46 % and its samples 300–499 at 97.6 % and 98.1 % (measured)
    later = narx(uv, yv, degree=3, lags=2)
    assert later.compare(ue[:100], ye[:100]).fit_percent[0] < 60.0
    for a in (300, 400):
        assert later.compare(ue[a:a + 100], ye[a:a + 100]).fit_percent[0] > 96.0


def test_unit_weights_give_the_least_squares_fit_and_sigma():
    """With every weight 1 the weighted path (sandwich covariance, σ² = Σwe²/(Σw − tr A⁻¹B))
    is the ordinary least squares with σ² (ΦᵀΦ)⁻¹, σ² = SSE/(N − k)."""
    u, y = _true_system(np.random.default_rng(3))
    bases, rows = candidate_terms(2, 2, 2)
    P, target = _regression_matrix(bases, rows, [(u, y)], 2)
    cols = [1, 3, 4, 9, 12]
    th0, cov0, sse0 = _Regression(P, target).fit(cols)
    th1, cov1, sse1 = _Regression(P, target, np.ones(len(target))).fit(cols)
    np.testing.assert_allclose(th1, th0, rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(cov1, cov0, rtol=1e-8, atol=1e-18)
    assert sse1 == pytest.approx(sse0, rel=1e-10)


def test_forgetting_theta_is_weighted_lstsq_and_sigma_matches_monte_carlo():
    """Billings' example, constant parameters, σ_e = 0.05, N = 1000, λ = 0.99 (memory ≈ 100
    rows), the four true terms: θ equals numpy's lstsq on the √λ^age-scaled rows (10⁻⁹), and
    over 120 runs the empirical spread of each θ_k over its mean predicted σ lies in 0.75–1.3
    (measured 0.82–1.10; 0.90–1.03 over 300 runs, 0.97–1.09 for λ = 1); the spread is ≥ 1.5×
    that of λ = 1 (measured 1.6–2.5; √(998 (1 − λ)/(1 + λ)) = 2.2 for a memory of 100 rows)."""
    est, sds, plain = [], [], []
    for i in range(120):
        u, y = _true_system(np.random.default_rng(500 + i))
        m = narx(u, y, degree=2, lags=2, terms=4, prune=False, forgetting=0.99)
        assert set(m.terms) == set(TRUE)
        order = [m.terms.index(k) for k in TRUE]
        est.append(m.theta[order])
        sds.append(m.theta_std[order])
        plain.append(narx(u, y, degree=2, lags=2, terms=4, prune=False).theta[order])
        if i == 0:
            w = 0.99 ** np.arange(len(y) - 3, -1, -1)
            Phi = np.column_stack([y[1:-1], y[:-2] ** 2, u[1:-1], u[:-2]])
            ref = np.linalg.lstsq(Phi * np.sqrt(w)[:, None], y[2:] * np.sqrt(w), rcond=None)[0]
            np.testing.assert_allclose(m.theta[order], ref, rtol=1e-9)
    est, sds, plain = np.array(est), np.array(sds), np.array(plain)
    np.testing.assert_allclose(est.mean(axis=0), list(TRUE.values()), atol=0.03)
    ratio = est.std(axis=0, ddof=1) / sds.mean(axis=0)
    assert np.all((ratio > 0.75) & (ratio < 1.3)), ratio
    assert np.all(est.std(axis=0) > 1.5 * plain.std(axis=0))


def test_forgetting_tracks_a_drifting_coefficient():
    """y(t) = a(t) y(t−1) + 0.5 u(t−1) + e(t), a rising linearly from 0.3 to 0.8 over 3000
    samples (σ_e = 0.02): λ = 0.98 estimates a at its recent value (within 0.03 of 0.8), the
    unweighted least squares near its average (≥ 0.1 away from 0.8)."""
    rng = np.random.default_rng(11)
    n = 3000
    a = np.linspace(0.3, 0.8, n)
    u = rng.uniform(-1.0, 1.0, n)
    e = rng.normal(0.0, 0.02, n)
    y = np.zeros(n)
    for t in range(1, n):
        y[t] = a[t] * y[t - 1] + 0.5 * u[t - 1] + e[t]
    recent = narx(u, y, degree=1, lags=1, terms=2, prune=False, forgetting=0.98)
    whole = narx(u, y, degree=1, lags=1, terms=2, prune=False)
    assert set(recent.terms) == {"y(t-1)", "u(t-1)"} and set(whole.terms) == set(recent.terms)
    k = recent.terms.index("y(t-1)")
    assert abs(recent.theta[k] - 0.8) < 0.03
    assert abs(whole.theta[whole.terms.index("y(t-1)")] - 0.8) > 0.1


def test_forgetting_argument_is_checked():
    u, y = _true_system(np.random.default_rng(1), n=300)
    for bad in (0.0, 1.5, -0.5, True, "0.9", float("nan")):
        with pytest.raises(ArgumentError, match=r"forgetting must be a number in \(0, 1\]"):
            narx(u, y, forgetting=bad)
    with pytest.raises(ArgumentError, match="applies to the least-squares estimate"):
        narx(u, y, forgetting=0.99, refine="simulation")
    with pytest.raises(ArgumentError, match="remembers 10 rows, enough for at most 5 terms"):
        narx(u, y, forgetting=0.9, terms=8)
    with pytest.raises(ArgumentError, match="too few for one term"):
        narx(u, y, forgetting=0.3)


def test_cli_identify_narx_forgetting(dc_motor, tmp_path, capsys):
    """``--forgetting 0.98``: the Python call's validation fit and terms, the factor in the JSON
    structure; a factor outside (0, 1] is one error line."""
    from gripkit.cli import main

    ue, ye, uv, yv = dc_motor
    est, val = tmp_path / "est.csv", tmp_path / "val.csv"
    for path, (u, y) in ((est, (ue, ye)), (val, (uv, yv))):
        np.savetxt(path, np.column_stack([u, y]), delimiter=",", header="voltage,output",
                   comments="", fmt="%.10g")
    args = ["identify", "narx", str(est), "--input", "voltage", "--output", "output", "--fs", "1",
            "--degree", "3"]
    code = main(args + ["--forgetting", "0.98", "--validate", str(val), "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    d = json.loads(out)
    py = narx(ue, ye, degree=3, lags=2, forgetting=0.98, validate=(uv, yv))
    assert d["validation"]["fit_percent"] == pytest.approx(py.validation_fit_percent, abs=1e-6)
    assert d["structure"]["forgetting"] == 0.98 and d["structure"]["terms"] == py.terms
    assert d["validation"]["fit_percent"] >= SYSIDENTPY_BEST
    code = main(args + ["--forgetting", "1.5"])
    out, err = capsys.readouterr()
    assert code != 0
    assert err.startswith("error: ArgumentError: narx: forgetting must be a number in (0, 1]")
