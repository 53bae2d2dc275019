"""FRF estimation with σ per line: periodic averaging, Welch H1, SPA; against the true response
(python-control evaluates it, as a reference implementation), with coverage of the stated σ."""

import warnings

import numpy as np
import pytest

from gripkit.errors import AccuracyWarning, DataError
from gripkit.excitation import periodic_multisine
from gripkit.lti import TransferFunction
from gripkit.sysid import frf

G = TransferFunction([1.0], [1.0, 0.4, 4.0]).c2d(0.01)   # ω_n = 2 rad/s, ζ = 0.1, sampled at 100 Hz


def _true(w):
    import control
    sys = control.tf(*[np.asarray(x) for x in (G.numerator(), G.denominator())], 0.01)
    return control.frequency_response(sys, w).complex.ravel()


def _coverage(r, k=3.0):
    z = np.abs(r.H[:, 0, 0] - _true(r.w)) / r.H_std[:, 0, 0]
    return float(np.mean(z <= k))


def test_periodic_multisine_design():
    ex = periodic_multisine(0.1, 10.0, 1000, 3, dt=0.01, lines="odd", amplitude=1.0)
    L = 1000
    assert ex.u.size == 3 * L and np.allclose(ex.u[:L], ex.u[L:2 * L])
    spec = np.abs(np.fft.rfft(ex.u[:L]))
    lines = np.flatnonzero(spec > 1e-8 * spec.max())
    assert lines.tolist() == ex.info["lines"] and all(k % 2 == 1 for k in lines)
    assert ex.crest_factor < 2.0          # Schroeder ≈ 1.7 for flat spectra; random phases ≈ 3–4


def test_periodic_average_with_sigma():
    ex = periodic_multisine(0.1, 10.0, 1000, 6, dt=0.01, amplitude=1.0)
    rng = np.random.default_rng(0)
    y = G.simulate(ex.u)[:, 0] + 0.01 * rng.standard_normal(ex.u.size)
    r = frf(ex.u, y, dt=0.01, periods=6)
    assert r.info["periods_used"] == 5 and r.frequency_hz.size == len(ex.info["lines"])
    assert _coverage(r) >= 0.9
    # σ from the spread: σ_H = σ_noise √(L/2)/(|U| √P') on each line within a factor 2
    U = np.abs(np.fft.rfft(ex.u[:1000]))[ex.info["lines"]]
    expected = 0.01 * np.sqrt(1000 / 1.0) / (U * np.sqrt(5))
    assert np.median(r.H_std[:, 0, 0] / expected) == pytest.approx(1.0, rel=0.25)


def test_periodic_keep_transient_changes_periods_used():
    ex = periodic_multisine(0.5, 10.0, 200, 4, dt=0.01)
    y = G.simulate(ex.u)[:, 0]
    assert frf(ex.u, y, dt=0.01, periods=4, keep_transient=True).info["periods_used"] == 4


def test_h1_coverage_and_coherence():
    rng = np.random.default_rng(1)
    u = rng.standard_normal(100000)
    y = G.simulate(u)[:, 0] + 0.05 * rng.standard_normal(u.size)
    r = frf(u, y, dt=0.01, nperseg=512)
    assert _coverage(r) >= 0.9
    assert np.all((r.coherence >= 0) & (r.coherence <= 1))
    # SISO: σ² = |H|²(1 − γ²)/((K − 1)γ²) · 1.056 (Bendat & Piersol eq 9.90)
    g2 = r.coherence[:, 0]
    K = r.info["segments"]
    expected = np.abs(r.H[:, 0, 0]) * np.sqrt(1.056 * (1 - g2) / ((K - 1) * g2))
    assert np.allclose(r.H_std[1:, 0, 0], expected[1:], rtol=1e-6)


def test_spa_coverage():
    rng = np.random.default_rng(2)
    u = rng.standard_normal(20000)
    y = G.simulate(u)[:, 0] + 0.05 * rng.standard_normal(u.size)
    assert _coverage(frf(u, y, dt=0.01, method="spa", lag_window=200)) >= 0.9


def test_mimo_h1_recovers_each_entry():
    from mimo_systems import two_by_two

    g = two_by_two()
    rng = np.random.default_rng(3)
    u = rng.standard_normal((60000, 2))
    y = g.simulate(u) + 0.02 * rng.standard_normal((60000, 2))
    r = frf(u, y, dt=0.01, nperseg=256)
    z = np.abs(r.H[1:] - g.frequency_response(r.w[1:])) / r.H_std[1:]
    assert np.mean(z <= 3) >= 0.9


def test_line_without_excitation_has_infinite_sigma():
    n = np.arange(64 * 100)
    u = np.cos(2 * np.pi * 8 * n / 64) + np.cos(2 * np.pi * 20 * n / 64)
    y = G.simulate(u)[:, 0]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = frf(u, y, dt=0.01, nperseg=64)
    assert any(issubclass(w.category, AccuracyWarning) and "no input power" in str(w.message)
               for w in caught)
    excited = np.isfinite(r.H_std[:, 0, 0])
    assert np.flatnonzero(excited).tolist() == [7, 8, 9, 19, 20, 21]
    assert np.all(np.isinf(r.H_std[~excited])) and np.all(np.isnan(r.H[~excited]))


def test_non_periodic_input_refused():
    u = np.random.default_rng(0).standard_normal(3000)
    with pytest.raises(DataError, match="not periodic"):
        frf(u, u, dt=0.01, periods=3)


def test_the_frf_carries_output_per_input_units():
    """identify(traj, 'frf') kept the columns' names but dropped their units: H of x [m] over
    v [V] is in m/V (its repr and to_dict say so); arrays without units leave it unlabelled, and
    a MIMO FRF labels each entry. The estimate itself is unchanged: H = 0.5 at every line."""
    from gripkit import Trajectory
    from gripkit.errors import ArgumentError
    from gripkit.sysid import identify

    u = np.random.default_rng(0).standard_normal(4000)
    y = 0.5 * np.concatenate([[0.0], u[:-1]])
    tr = Trajectory(np.arange(4000) * 1e-3, {"v": u, "x": y}, {"v": "V", "x": "m"})
    r = identify(tr, "frf", input="v", output="x", nperseg=256)
    assert r.input_units == ("V",) and r.output_units == ("m",) and r.H_units == [["m/V"]]
    assert r.to_dict()["H_unit"] == "m/V" and repr(r).endswith("['v'] → ['x'], H in m/V)")
    np.testing.assert_allclose(np.abs(r.H[1:, 0, 0]), 0.5, atol=0.01)
    bare = frf(u, y, dt=1e-3)
    assert bare.H_units == [[""]] and "H in" not in repr(bare)
    two = frf(np.column_stack([u, u[::-1]]), y, input_units=["V", "A"], output_units="m")
    assert two.H_units == [["m/V", "m/A"]]
    with pytest.raises(ArgumentError, match=r"input_units: expected 1 unit string\(s\), one per "
                                            r"channel, found \('V', 'A'\)"):
        frf(u, y, input_units=("V", "A"))
