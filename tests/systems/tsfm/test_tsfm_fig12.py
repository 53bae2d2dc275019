"""Fig. 12 of 001_0b92a7da96e7aa46.txt (§IV-C): tip B of the left finger under 100 V sines at 10,
50, 100 and 500 Hz, no force, the identified model against the measurement; the seed: "The model
can estimate the actuator displacement for several frequencies with errors less than 10%".

The same experiment as the demo's section "Sine responses at 10, 50, 100 and 500 Hz (Fig. 12)"
(gripkit.systems.tsfm.demo._sines): the 'measurement' is the Table II left finger simulated at
20 kHz with the Keyence laser's 20 nm noise (§IV), the model is the finger identified by the §IV
protocol from the demo's records (the 0.1 Hz loops with seed 10, step, compliance and free
vibration with seeds 30, 40, 20), the error is Fig. 9b's and Fig. 12's max |y − ŷ| / peak-to-peak
over the last two of three periods."""

import warnings

import numpy as np
import pytest

from gripkit.errors import AccuracyWarning
from gripkit.sysid.physical.bouc_wen import loop_error
from gripkit.systems.tsfm import parameters as z
from gripkit.systems.tsfm.identification import identify_finger

FREQS = (10.0, 50.0, 100.0, 500.0)
DT = 5e-05  # s, 20 kHz (the dSpace's rate, §IV-A)
NOISE = 20e-9  # m, the laser's resolution (§IV)
STROKE = "beyond the finger's 100 µm displacement range"


@pytest.fixture(scope="module")
def fig12():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        f = z.finger("left", check=False)
        tr = z.hysteresis_experiment(f, (100.0, 60.0, 30.0), seed=10)
        ext = tr.take(np.flatnonzero(tr["loop"] == 0))
        res = identify_finger(ext, z.step_experiment(f, seed=30),
                              z.compliance_experiment(f, seed=40),
                              z.free_vibration_experiment(f, seed=20),
                              k_s=f.parameters.value("k_s"),
                              k_s_std=0.02 * f.parameters.value("k_s"), **z.ASSUMED_LENGTHS)
    rng = np.random.default_rng(50)
    out = {}
    for fr in FREQS:
        n = int(round(3 / (fr * DT)))
        U = 100.0 * np.sin(2 * np.pi * fr * np.arange(n) * DT)
        inputs = {"U": U, "F_g": np.zeros(n)}
        # Fig. 12's 100 V sines take the tip C beyond Table I's 100 µm stroke (zoo check finding
        # stroke-100V): both simulations say so
        with pytest.warns(AccuracyWarning, match=STROKE):
            true = f.simulate(inputs, dt=DT)["y_B"]
        with pytest.warns(AccuracyWarning, match=STROKE):
            pred = res.finger.simulate(inputs, dt=DT)["y_B"]
        meas = true + NOISE * rng.standard_normal(n)
        last = slice(n // 3, n)
        out[fr] = (true[last], meas[last], pred[last])
    return f, out


def test_fig12_errors_below_the_seeds_10_percent(fig12):
    """At every frequency the error is below the seed's 10 %; it is set by the laser noise and
    not by the model: against the noise-free finger the identified model is within 0.01 % of
    the peak-to-peak (the demo's table: 0.027, 0.027, 0.023, 0.019 % with noise), and with the
    noise the error stays below that plus 6 σ of the 20 nm noise (the largest of the ≤ 4000
    samples of a record exceeds 6σ with probability < 1e-5)."""
    _, out = fig12
    for fr, (true, meas, pred) in out.items():
        ptp = np.ptp(meas)
        err = loop_error(meas, pred)
        assert err < 0.10, fr
        assert loop_error(true, pred) < 1e-4, fr
        assert err <= loop_error(true, pred) + 6 * NOISE / ptp, fr


def test_fig12_amplitude_follows_d_of_s(fig12):
    """Rate-dependent hysteresis = static Bouc-Wen followed by D(s) = 1/(a s² + b s + 1) (eqs 2,
    4): the loops' peak-to-peak grows with frequency as |D(jω)| does. With Table II's a, b
    (left finger, resonance near 1 kHz) |D| is 1.0001, 1.0022, 1.0087, 1.2593 at 10, 50, 100,
    500 Hz; the peak-to-peak ratios to 10 Hz (283.5 µm) match |D(jω)/D(j2π10)| to 0.1 % up to
    100 Hz and to 3 % at 500 Hz (measured 1.288 against 1.259: the hysteresis output's harmonics,
    1.5 kHz and up, are shaped by D(s) differently from the fundamental)."""
    f, out = fig12
    v = f.values()

    def gain(fr):
        s = 2j * np.pi * fr
        return 1.0 / abs(v["a"] * s * s + v["b"] * s + 1.0)

    assert [gain(fr) for fr in FREQS] == pytest.approx([1.0001, 1.0022, 1.0087, 1.2593], abs=1e-4)
    p10 = np.ptp(out[10.0][0])
    assert p10 == pytest.approx(283.5e-6, rel=2e-3)
    for fr, tol in ((50.0, 1e-3), (100.0, 1e-3), (500.0, 0.03)):
        assert np.ptp(out[fr][0]) / p10 == pytest.approx(gain(fr) / gain(10.0), rel=tol), fr
