"""Contact detection (gripkit.estimation.contact_detection): a moving average of ``window``
samples against a threshold, released below ``release``. A force step of height A > threshold
is seen after ⌊threshold·w/A⌋ + 1 samples (the average of k samples after the step is k·A/w),
never later than the window; on zero-mean Gaussian noise the average exceeds the threshold on a
fraction of the samples given by :func:`false_alarm_probability` (a normal tail, σ/√w)."""

import math

import numpy as np
import pytest

from gripkit.errors import DataError
from gripkit.estimation import ContactDetector
from gripkit.estimation.contact_detection import detector_step, false_alarm_probability


@pytest.mark.parametrize("height", [1.01, 1.5, 3.0, 100.0])
@pytest.mark.parametrize("window", [1, 4, 16])
def test_a_force_step_is_detected_within_the_stated_delay(height, window):
    thr = 1.0
    F = np.r_[np.zeros(2 * window), np.full(2 * window, height)]
    c, avg = ContactDetector(thr, window=window).run(F)
    delay = int(np.argmax(c)) - 2 * window  # samples after the first sample of the step
    assert delay == math.floor(thr * window / height)  # k + 1 samples, counted from 0
    assert delay <= window - 1
    ramp = height * np.arange(1, window + 1) / window
    np.testing.assert_allclose(avg[2 * window:3 * window], ramp)


def test_false_alarm_rate_on_noise_is_the_stated_probability():
    """σ = 1, window 8, threshold 1.06 (3σ/√8): P = Φ̄(3) = 1.35e-3 per sample. 400 000 noise
    samples: the fraction of samples whose average exceeds the threshold is within 25 % of P
    (runs of correlated samples: about 3 standard deviations); the erfc formula equals the
    normal tail from scipy."""
    from scipy.stats import norm

    thr = 3.0 / math.sqrt(8)
    p = false_alarm_probability(thr, 1.0, 8)
    assert p == pytest.approx(norm.sf(3.0), rel=1e-12)
    noise = np.random.default_rng(23).standard_normal(400_000)
    _, avg = ContactDetector(thr, window=8).run(noise)
    rate = np.mean(avg[7:] > thr)
    assert rate == pytest.approx(p, rel=0.25)


def test_no_false_alarm_on_noise_with_a_negligible_stated_rate():
    """Threshold at 6.5σ/√w (P = 4e-11 per sample): 200 000 noise samples, not one contact."""
    thr = 6.5 / math.sqrt(8)
    assert false_alarm_probability(thr, 1.0, 8) < 1e-10
    c, _ = ContactDetector(thr, window=8).run(np.random.default_rng(5).standard_normal(200_000))
    assert not c.any()


def test_hysteresis_holds_contact_until_release():
    """After contact, an average between release and threshold keeps it; below release drops it;
    the numba step and ContactDetector.update agree sample by sample."""
    F = np.r_[np.full(4, 2.0), np.full(8, 0.8), np.full(8, 0.3)]
    det = ContactDetector(1.0, release=0.5, window=4)
    c = [det.update(f) for f in F]
    assert c[3] and all(c[3:14]) and not c[-1]
    # k samples of 0.3 after the 0.8s: average 0.8 − k·(0.8 − 0.3)/4 < 0.5 first at k = 3
    assert c.index(False, 4) == 12 + math.floor((0.8 - 0.5) / ((0.8 - 0.3) / 4))
    st, buf = np.zeros(5), np.zeros(4)
    assert [detector_step(st, buf, f, 1.0, 0.5) > 0.5 for f in F] == c


@pytest.mark.parametrize("kw,phrase", [(dict(threshold=0.0), "threshold: expected a positive"),
                                       (dict(threshold=1.0, release=1.0), "release: expected"),
                                       (dict(threshold=1.0, window=0), "window: expected >= 1")])
def test_bad_settings_are_refused(kw, phrase):
    with pytest.raises(DataError, match=phrase):
        ContactDetector(**kw)


def test_a_non_finite_record_is_refused():
    with pytest.raises(DataError, match="F: expected a finite 1-D force record"):
        ContactDetector(1.0).run([0.0, math.nan])
