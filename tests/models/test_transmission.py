"""Rigid transmissions (gripkit.models.transmission): ω_out = ω_in/N; τ_out = N η τ_in when the
input drives, N τ_in/η when the output back-drives, so power flows out reduced by η in the first
case and in reduced by η in the second; stages in series multiply ratios and efficiencies."""

import numpy as np
import pytest

from gripkit.errors import ModelError
from gripkit.models import Transmission, harmonic_drive, timing_belt
from gripkit.models.transmission import transmit_torque


def test_power_balance_driving_and_back_driven():
    """Driving: P_out = τ_out ω_out = η P_in. Back-driven (the load pushes the motor): the power
    reaching the motor is η times the load's, P_in = η P_out."""
    tr = Transmission(50.0, 0.7)
    w_in = 120.0
    w_out = tr.output_speed(w_in)
    assert w_out == pytest.approx(2.4) and tr.input_speed(w_out) == pytest.approx(w_in)
    tau_in = 0.02
    assert tr.output_torque(tau_in, w_out) * w_out == pytest.approx(0.7 * tau_in * w_in, rel=1e-12)
    back = tr.output_torque(tau_in, -w_out)  # output moves against the motor torque
    assert tau_in * w_in == pytest.approx(0.7 * back * w_out, rel=1e-12)
    for w in (w_out, -w_out):  # the compiled kernel agrees
        expected = float(tr.output_torque(tau_in, w))
        assert transmit_torque(tau_in, w, 50.0, 0.7) == pytest.approx(expected)


def test_stages_in_series_multiply():
    """A 3:1 belt then a 100:1 harmonic drive (η 0.9 and 0.8): N = 300, η = 0.72; the reflected
    rotor inertia is I_m N²; the chain's torque equals the two stages applied in turn."""
    chain = timing_belt(3.0, 0.9).then(harmonic_drive(100.0, 0.8))
    assert (chain.ratio, chain.efficiency) == pytest.approx((300.0, 0.72))
    assert chain.reflected_inertia(2e-7) == pytest.approx(2e-7 * 300.0 ** 2)
    tau = np.array([-0.01, 0.004])
    w = np.array([-1.0, 2.0])
    two = harmonic_drive(100.0, 0.8).output_torque(timing_belt(3.0, 0.9).output_torque(tau, w), w)
    np.testing.assert_allclose(chain.output_torque(tau, w), two, rtol=1e-12)


@pytest.mark.parametrize("ratio,eff,phrase", [(0.0, 1.0, "ratio must be finite and non-zero"),
                                              (10.0, 1.5, "efficiency must lie in"),
                                              (10.0, 0.0, "efficiency must lie in")])
def test_bad_stages_are_refused(ratio, eff, phrase):
    with pytest.raises(ModelError, match=phrase):
        Transmission(ratio, eff)
