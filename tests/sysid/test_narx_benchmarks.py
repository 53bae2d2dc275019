"""Polynomial NARX on the public nonlinear benchmarks of tests/fixtures (Silverbox, cascaded
tanks; each folder's README: source, licence, the estimation/validation cut) beside gripkit's
linear models on the same split. The full records run as ``slow``; a smaller case of each in the
default run. Numbers measured 2026-11-27 (docs/sysid.md, "Nonlinear benchmarks")."""

import warnings
from pathlib import Path

import numpy as np
import pytest

from gripkit.sysid import arx, narx

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures"


def _load(stem, cols):
    est = np.loadtxt(FIXTURES / f"{stem}_est.csv", delimiter=",", skiprows=1)
    val = np.loadtxt(FIXTURES / f"{stem}_val.csv", delimiter=",", skiprows=1)
    return est[:, cols[0]], est[:, cols[1]], val[:, cols[0]], val[:, cols[1]]


@pytest.fixture(scope="module")
def silverbox():
    return _load("silverbox/silverbox", (0, 1))


@pytest.fixture(scope="module")
def tanks():
    return _load("cascaded_tanks/cascaded_tanks", (1, 2))


def _best_arx(ue, ye, uv, yv):
    """The best ARX [n n 1], n = 1…4, by its free-run validation fit (x0 by least squares, the
    estimation record's means removed): gripkit's linear model at its best on this split."""
    um, ym = ue.mean(), ye.mean()
    with warnings.catch_warnings():  # the tanks' ARX [4 4 1] is poorly determined: named, kept
        warnings.simplefilter("ignore")
        return max(arx(ue - um, ye - ym, n, n, 1, dt=1.0).compare(uv - um, yv - ym).fit_percent[0]
                   for n in (1, 2, 3, 4))


def _rms(m, u, y):
    k = m.max_lag
    ys = m.simulate(u, y[:k])
    return float(np.sqrt(np.mean((ys[k:] - y[k:]) ** 2)))


def test_silverbox_narx_beats_linear_small(silverbox):
    """First 2048 samples of each record. Cubic NARX, lags 2, BIC, θ refined on the simulation
    error: measured 98.3 % validation fit (e_RMS 0.81 mV, 10 terms) against 85.6 % for the best
    ARX [n n 1]; asserted ≥ 96 % and ≥ 10 points above the best ARX, e_RMS < 1.2 mV."""
    ue, ye, uv, yv = (a[:2048] for a in silverbox)
    m = narx(ue, ye, degree=3, lags=2, refine="simulation")
    best = _best_arx(ue, ye, uv, yv)
    assert m.compare(uv, yv).fit_percent[0] >= 96.0
    assert m.compare(uv, yv).fit_percent[0] >= best + 10.0
    assert _rms(m, uv, yv) < 1.2e-3


def test_cascaded_tanks_refinement_and_the_linear_floor(tanks):
    """Cascaded tanks (1024 + 1024 samples). The polynomial NARX is not the right class here (a
    hard overflow saturation and square-root outflows): measured, cubic NARX lags 2 by BIC
    62.9 % one-step, 69.0 % refined on the simulation error (e_RMS 0.652 V), the best ARX
    [n n 1] 69.7 %. Asserted: the refinement gains ≥ 4 points, and the refined NARX is within
    3 points of the best ARX (not a gain: reported in docs/sysid.md as such)."""
    ue, ye, uv, yv = tanks
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        one = narx(ue, ye, degree=3, lags=2)
        ref = narx(ue, ye, degree=3, lags=2, refine="simulation")
    best = _best_arx(ue, ye, uv, yv)
    assert ref.compare(uv, yv).fit_percent[0] >= one.compare(uv, yv).fit_percent[0] + 4.0
    assert abs(ref.compare(uv, yv).fit_percent[0] - best) < 3.0
    assert _rms(ref, uv, yv) < 0.70


@pytest.mark.slow
def test_silverbox_narx_beats_the_best_linear_model_full(silverbox):
    """Full cut (8192 + 8192 samples): the refined cubic NARX (lags 2, BIC, 13 terms) reaches
    98.2 % validation fit, e_RMS 0.91 mV; gripkit's best linear model, `identify ss` (order 2,
    subspace + PEM, the better by the free-run validation fit) 87.8 %, e_RMS 6.07 mV. Asserted:
    ≥ 8 points above it and e_RMS below a fifth of the linear model's."""
    from gripkit import Trajectory
    from gripkit.sysid.linear.identify_mimo import identify_ss

    ue, ye, uv, yv = silverbox
    m = narx(ue, ye, degree=3, lags=2, refine="simulation")
    dt = 2 ** 14 / 1e7
    est = Trajectory.uniform(dt=dt, input=ue, output=ye)
    val = Trajectory.uniform(dt=dt, input=uv, output=yv)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _, extras = identify_ss(est, input="input", output="output", order=2, validate=val)
    linear = extras["validation_fit_percent"][0]
    linear_rms = (1.0 - linear / 100.0) * float(np.linalg.norm(yv - yv.mean())) / np.sqrt(len(yv))
    assert m.compare(uv, yv).fit_percent[0] >= linear + 8.0
    assert _rms(m, uv, yv) < 0.2 * linear_rms


@pytest.mark.slow
def test_cascaded_tanks_hammerstein_wiener_beats_the_linear_model(tanks):
    """gripkit's other nonlinear family on the tanks, where the NARX gains nothing: the
    Hammerstein–Wiener model with the structure and orders chosen by BIC (no look at the test
    record) reaches 75.2 % validation fit against 68.7 % for `identify ss` at order 3 (the
    corpus setting; orders 4–8 give 71–73 %). Asserted: ≥ 4 points above order 3."""
    from gripkit import Trajectory
    from gripkit.sysid import hammerstein_wiener
    from gripkit.sysid.linear.identify_mimo import identify_ss

    ue, ye, uv, yv = tanks
    est = Trajectory.uniform(dt=4.0, pump=ue, level=ye)
    val = Trajectory.uniform(dt=4.0, pump=uv, level=yv)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _, extras = identify_ss(est, input="pump", output="level", order=3, validate=val)
        hw = hammerstein_wiener(ue, ye, dt=4.0)
    linear = extras["validation_fit_percent"][0]
    assert linear == pytest.approx(68.7, abs=1.0)
    assert hw.compare(uv, yv).fit_percent[0] >= linear + 4.0
