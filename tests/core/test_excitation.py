"""Excitation design: limits respected, spectra where asked, crest factor minimised."""

import numpy as np
import pytest

from gripkit import DataError
from gripkit.excitation import bandlimited_noise, chirp, crest_factor, multisine, prbs, steps


def test_s1_multisine_matches_seed_design():
    """S1 of 000_8f66dcc7ab06470c.txt §V-E: 400 samples at 200 Hz, 1..10 Hz at 1 Hz steps,
    600..1100 mA around 850 mA."""
    ex = (multisine(range(1, 11), 2.0, dt=0.005, operating_point=0.850, limits=(0.600, 1.100),
                    unit="A"))
    assert ex.u.size == 400
    assert ex.u.min() >= 0.600 - 1e-12 and ex.u.max() <= 1.100 + 1e-12
    assert max(ex.u.max() - 0.85, 0.85 - ex.u.min()) == pytest.approx(0.25)
    spec = np.abs(np.fft.rfft(ex.u - 0.85))
    freqs = np.fft.rfftfreq(400, 1 / 200)
    excited = spec > 1e-6 * spec.max()
    np.testing.assert_allclose(freqs[excited], np.arange(1, 11))
    lines = spec[excited]
    assert lines.max() / lines.min() == pytest.approx(1.0, abs=1e-9)  # equal amplitudes


def test_min_crest_beats_schroeder_and_zero_phase():
    f = range(1, 11)
    cf_min = multisine(f, 2.0, dt=0.005, phases="min-crest").crest_factor
    cf_sch = multisine(f, 2.0, dt=0.005, phases="schroeder").crest_factor
    cf_zero = multisine(f, 2.0, dt=0.005, phases="zero").crest_factor
    assert cf_min <= cf_sch < cf_zero
    assert cf_zero == pytest.approx(np.sqrt(2 * 10), rel=1e-6)  # all peaks aligned: sqrt(2K)


def test_s2_noise_band_and_limits():
    ex = (bandlimited_noise(0.3, 10.0, 20.0, dt=0.005, operating_point=0.85, limits=(0.6, 1.1),
                            seed=3))
    assert ex.u.size == 4000 and ex.u.min() >= 0.6 and ex.u.max() <= 1.1
    p = np.abs(np.fft.rfft(ex.u - ex.u.mean())) ** 2
    f = np.fft.rfftfreq(4000, 1 / 200)
    assert p[(f > 0.3) & (f < 10)].sum() / p.sum() > 0.95
    assert p[f > 30].sum() / p.sum() < 1e-4


def test_prbs_is_maximal_length():
    ex = prbs(7, 127 / 100.0, dt=0.01, operating_point=0.0, limits=(-1, 1))
    bits = ex.u
    assert set(np.unique(bits)) == {-1.0, 1.0}
    assert (bits > 0).sum() == 64  # an m-sequence has 2^(n-1) ones
    c = np.correlate(bits, np.roll(bits, 5), "valid")[0] / bits.size
    assert c == pytest.approx(-1 / 127)  # two-level circular autocorrelation


def test_chirp_and_steps_and_errors():
    ex = chirp(1.0, 20.0, 5.0, dt=0.005, operating_point=0.5, limits=(0.0, 1.0))
    assert ex.u.min() >= 0 and ex.u.max() <= 1
    st = steps([0.6, 1.1, 0.85], [1.0, 1.0, 1.0], dt=0.005, limits=(0.6, 1.1))
    assert st.u.size == 600 and st.u[250] == 1.1
    with pytest.raises(DataError, match="outside the limits"):
        multisine([1.0], 1.0, dt=0.01, operating_point=2.0, limits=(0, 1))
    with pytest.raises(DataError, match="largest amplitude that fits"):
        multisine([1.0], 1.0, dt=0.01, operating_point=0.9, limits=(0, 1), amplitude=0.5)
    with pytest.raises(DataError, match=r"1/\(2 dt\)"):
        multisine([60.0], 1.0, dt=0.01)


def test_crest_factor_of_sine():
    t = np.arange(1000) / 1000
    assert crest_factor(np.sin(2 * np.pi * 5 * t)) == pytest.approx(np.sqrt(2), rel=1e-6)
