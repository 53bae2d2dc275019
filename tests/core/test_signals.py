"""Filters and processing: seed numbers (§V-D) and analytic properties."""

import re

import numpy as np
import pytest

from gripkit import DataError, Trajectory
from gripkit.signals import (ac_couple, bandpass, butter_zpk, decimate, detrend, highpass, lowpass,
                             resample, split, to_uniform)


def test_amadeus_butterworth_poles_and_zeros():
    """000_8f66dcc7ab06470c.txt §V-D: 2nd-order 9 Hz Butterworth at 200 Hz has poles
    0.8021 ± j0.1648 and a double zero at -1."""
    z, p, k = butter_zpk(2, 9.0, dt=0.005)
    np.testing.assert_allclose(np.sort_complex(p), [0.8021 - 0.1648j, 0.8021 + 0.1648j], atol=1e-4)
    np.testing.assert_allclose(z, [-1, -1], atol=1e-12)


def test_lowpass_dc_gain_and_cutoff():
    fs = 200.0
    t = np.arange(4000) / fs
    dc = lowpass(np.full(t.size, 3.0), 9.0, dt=1 / fs)
    # no start transient
    assert dc[-1] == pytest.approx(3.0, rel=1e-9) and dc[0] == pytest.approx(3.0)
    x = np.sin(2 * np.pi * 9.0 * t)
    y = lowpass(x, 9.0, dt=1 / fs, zero_phase=True)  # forward-backward: |H|^2 = 1/2 at the cutoff
    assert np.std(y[1000:-1000]) / np.std(x[1000:-1000]) == pytest.approx(0.5, rel=0.02)


def test_lowpass_on_trajectory_and_errors():
    tr = Trajectory.uniform(dt=0.005, y=np.random.default_rng(0).standard_normal(500))
    out = lowpass(tr, 9.0)
    assert out.n == 500
    with pytest.raises(DataError, match="between 0 and the Nyquist frequency"):
        lowpass(tr, 150.0)


def test_filters_refuse_nan_and_name_the_first_sample():
    """One NaN would spread over every later sample (a causal filter) or all of them (its first
    sample's steady state): a DataError with the count, the first sample and the hint."""
    x = np.sin(np.arange(100) * 0.1)
    bad = x.copy()
    bad[[50, 70]] = np.nan
    with pytest.raises(DataError, match=r"x has 2 NaN or infinite values \(first at sample 50\)"
                                        r".*interpolate them before filtering"):
        lowpass(bad, 1.0, dt=0.1)
    bad = x.copy()
    bad[0] = np.inf
    with pytest.raises(DataError, match=r"1 NaN or infinite values \(first at sample 0\)"):
        highpass(bad, 1.0, dt=0.1, zero_phase=True)
    two = np.column_stack([x, x])
    two[30, 1] = np.nan
    with pytest.raises(DataError, match=r"first at sample 30"):
        lowpass(two, 1.0, dt=0.1)


def test_filters_refuse_empty_complex_and_too_low_cutoffs():
    """No samples, complex samples: a DataError naming x. A cut-off whose sections round to
    nonsense (order 8, cut-off × dt = 1e-10: scipy's steady state is singular) is refused with
    the lowest cut-off that works; filtering a constant at that cut-off keeps it (gain 1)."""
    with pytest.raises(DataError, match="x: the signal holds no samples"):
        lowpass(np.array([]), 1.0, dt=0.1)
    with pytest.raises(DataError, match="x: expected real numbers, found complex"):
        lowpass(np.ones(10) * (1 + 1j), 1.0, dt=0.1)
    with pytest.raises(DataError, match=r"too low for an order-8 Butterworth at dt = 0.1 s") as e:
        lowpass(np.ones(100), 1e-9, dt=0.1, order=8)
    assert "below 1/(N dt) = 0.1 Hz" in str(e.value)
    lo = float(re.search(r"from about ([0-9.e+-]+) Hz up to the Nyquist frequency 5 Hz",
                         str(e.value)).group(1))
    assert 1e-9 < lo < 1e-4
    assert np.allclose(lowpass(np.full(100, 2.0), lo, dt=0.1, order=8), 2.0, rtol=1e-3)
    with pytest.raises(DataError, match=r"highpass cut-off 1e-09 Hz is too low .*poles round"):
        highpass(np.ones(100), 1e-9, dt=0.1, order=4)


def test_ac_couple_with_reference():
    tr = Trajectory.uniform(dt=0.1, f=np.full(20, 5.0))
    ref = Trajectory.uniform(dt=0.1, f=np.full(20, 4.0))
    assert np.allclose(ac_couple(tr, ["f"], ref)["f"], 1.0)


def test_detrend_removes_line():
    tr = Trajectory.uniform(dt=0.1, y=3.0 + 2.0 * np.arange(50) / 10.0)
    assert np.allclose(detrend(tr)["y"], 0.0, atol=1e-12)


def test_decimate_and_resample_preserve_low_frequency():
    fs = 1000.0
    t = np.arange(5000) / fs
    tr = Trajectory.uniform(dt=1 / fs, y=np.sin(2 * np.pi * 5 * t))
    d = decimate(tr, 5)
    assert d.dt == pytest.approx(0.005)
    np.testing.assert_allclose(d["y"][50:-50], np.sin(2 * np.pi * 5 * d.t[50:-50]), atol=1e-3)
    r = resample(tr, 0.005)
    np.testing.assert_allclose(r["y"][50:-50], np.sin(2 * np.pi * 5 * r.t[50:-50]), atol=1e-3)


def test_to_uniform_and_split():
    t = np.sort(np.random.default_rng(1).uniform(0, 1, 200))
    tr = Trajectory(t, {"y": 2 * t})
    u = to_uniform(tr, 0.01)
    assert u.is_uniform()
    np.testing.assert_allclose(u["y"], 2 * u.t, atol=1e-12)
    a, b = split(u, 2)
    assert a.n + b.n == u.n


def test_bandpass_too_low_band_is_a_data_error_with_a_scaled_band_that_works():
    """A band whose sections round to nonsense is refused with a DataError (not scipy's
    ValueError about Wn from a search with one cut-off): the message gives the band scaled as a
    whole (same edge ratio, 10) to the lowest quarter decade that works. That band filters, and
    the quarter decade below it is refused."""
    x = np.random.default_rng(0).standard_normal(1000)
    with pytest.raises(DataError, match=r"bandpass cut-off \[1.e-06 1.e-05\] Hz is too low for an "
                                        r"order-4 Butterworth at dt = 0.001 s") as e:
        bandpass(x, (1e-6, 1e-5), dt=1e-3, order=4)
    m = re.search(r"the band scaled up to about \(([0-9.e+-]+), ([0-9.e+-]+)\) Hz \(the same "
                  r"ratio of its edges, 10\) works at this order", str(e.value))
    lo, hi = float(m.group(1)), float(m.group(2))
    assert hi / lo == pytest.approx(10.0, rel=1e-2) and 1e-6 < lo < 1e-3
    assert bandpass(x, (lo, hi), dt=1e-3, order=4).shape == x.shape
    below = np.array([lo, hi]) / 10 ** 0.25
    with pytest.raises(DataError, match="too low for an order-4"):
        bandpass(x, tuple(below), dt=1e-3, order=4)


def test_bandpass_passes_its_centre_frequency():
    """Butterworth band-pass: gain 1 at the pre-warped centre sqrt(f1 f2) (bilinear transform,
    2 atan(sqrt(tan(pi f1 dt) tan(pi f2 dt)))), the frequency that the section check evaluates;
    a 10 Hz band at 1 kHz is not refused and passes its centre with amplitude 1."""
    dt, band = 1e-3, (8.0, 12.0)
    f0 = np.arctan(np.sqrt(np.tan(np.pi * band[0] * dt) * np.tan(np.pi * band[1] * dt)))
    f0 /= np.pi * dt
    t = np.arange(20000) * dt
    y = bandpass(np.sin(2 * np.pi * f0 * t), band, dt=dt, order=4)
    assert np.max(np.abs(y[10000:])) == pytest.approx(1.0, abs=2e-3)


def test_filtering_a_plain_array_checks_its_samples_once(monkeypatch):
    """samples() (a copy and a finiteness scan of every sample) runs once per plain-array call."""
    from gripkit.signals import filters

    calls = []
    check = filters.samples
    monkeypatch.setattr(filters, "samples", lambda *a: calls.append(1) or check(*a))
    lowpass(np.ones(50), 1.0, dt=0.1)
    assert len(calls) == 1
