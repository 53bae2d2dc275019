"""AMADEUS (000_8f66dcc7ab06470c.txt): Fig. 14's stepped-sine experiment simulated with the Table II
[2 2 2] model against the seed's first-order-like amplitude (§V-C), and the §V-F "factor of 4"
statement, both in `gripkit zoo check amadeus-finger-force`."""

import json
import math

import numpy as np
import pytest
from scipy.signal import freqz

from gripkit.cli import main
from gripkit.consistency import check
from gripkit.errors import DataError
from gripkit.systems.amadeus.force_dynamics import (FIG14_FREQUENCIES, finger_force_model,
                                                     fig14_finding,
                                                     stepped_sine_experiment)

A = [1.0, -1.8732, 0.8996]          # Table II, S1 [2 2 2]
B = [0.0, 0.0, 0.1950, -0.2276]     # units/mA as printed


@pytest.fixture(scope="module")
def plant():
    return finger_force_model()


def test_stepped_sine_matches_the_frequency_response(plant):
    """Gain and phase read from the simulated waveforms equal scipy's freqz of B/A at each Fig. 14
    frequency (gain within 1e-6 relative, phase within 1e-4°): the experiment measures what it
    should; relative to the static gain B(1)/A(1) = −1.235 units/mA."""
    ss = stepped_sine_experiment(plant)
    w, h = freqz(B, A, worN=2 * np.pi * np.asarray(FIG14_FREQUENCIES) * 0.005)
    g0 = sum(B) / sum(A)
    assert g0 == pytest.approx(-1.2348, abs=1e-4)
    np.testing.assert_allclose(ss.gain_db, 20 * np.log10(np.abs(h) / abs(g0)), atol=1e-5)
    ref_phase = np.degrees(np.angle(h / g0))
    np.testing.assert_allclose(ss.phase, ref_phase, atol=1e-4)
    assert ss.dc_gain == pytest.approx(1e3 * plant.force_scale * g0, rel=1e-12)


def test_table_II_222_peaks_7p4_dB_at_5_Hz(plant):
    """The selected model has a resonant pole pair (|p| = 0.9485: 5.32 Hz, ζ = 0.32) and peaks at
    +7.43 dB at 5 Hz over its static gain; a first-order amplitude (what §V-C measured) never
    exceeds its static value: the finding is inconsistent, with the raw-force peak (+7.81 dB,
    the 9 Hz Butterworth taking 0.39 dB at 5 Hz) and the other Table II rows in its message."""
    p = np.roots(A)[0]
    s = np.log(p) / 0.005
    assert abs(s) / (2 * math.pi) == pytest.approx(5.32, abs=0.01)
    assert -s.real / abs(s) == pytest.approx(0.32, abs=0.01)
    ss = stepped_sine_experiment(plant)
    assert ss.peak[0] == 5.0 and ss.peak[1] == pytest.approx(7.43, abs=0.01)
    f = fig14_finding(plant)
    assert not f.consistent and f.computed == pytest.approx(7.425, abs=1e-3) and f.stated == 0.0
    assert "+7.81 dB" in f.message
    assert "S2 [2 2 2] +10.7 dB" in f.message
    assert "S1 [3 2 2] +1.0 dB" in f.message


def test_zoo_check_lists_fig14_and_the_sigma_factor(capsys):
    """`gripkit zoo check amadeus-finger-force --json`: exit 3, fig14-first-order-amplitude (+7.43
    dB) and filter-sigma-factor-B (σ(b) shrinks 24.7×, stated 4×) inconsistent; σ(a) 3.99× ok."""
    code = main(["zoo", "check", "amadeus-finger-force", "--json"])
    out, _ = capsys.readouterr()
    assert code == 3
    f = {x["check"]: x for x in json.loads(out)["findings"]}
    assert not f["fig14-first-order-amplitude"]["consistent"]
    assert f["fig14-first-order-amplitude"]["computed"] == pytest.approx(7.425, abs=1e-3)
    assert not f["filter-sigma-factor-B"]["consistent"]
    assert f["filter-sigma-factor-B"]["computed"] == pytest.approx(24.7, abs=0.05)
    assert f["filter-sigma-factor-A"]["consistent"]
    assert f["filter-sigma-factor-A"]["computed"] == pytest.approx(3.99, abs=0.01)
    fig14 = check(finger_force_model()).find("fig14-first-order-amplitude")
    assert fig14.source.endswith("Table II")


@pytest.mark.parametrize("kwargs, pattern", [
    (dict(amplitude=0.3), "amplitude: expected 0 < amplitude <= 0.25 A"),
    (dict(frequencies=[5.0, 120.0]), "frequencies: expected positive frequencies below the 100 Hz "
                                     "Nyquist"),
    (dict(frequencies=[]), "frequencies: expected positive frequencies"),
])
def test_bad_stepped_sine(plant, kwargs, pattern):
    with pytest.raises(DataError, match=pattern):
        stepped_sine_experiment(plant, **kwargs)
