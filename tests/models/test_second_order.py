"""Second-order systems (gripkit.models.second_order): the closed-form step response of
K ω_n²/(s² + 2ζω_n s + ω_n²) against scipy.signal.step for ζ < 1, = 1, > 1, and the exact ZOH
simulation of SecondOrderSystem (with its operating-point offsets) against the same response
sampled: a held step is integrated exactly by a ZOH discretisation."""

import numpy as np
import pytest
from scipy import signal

from gripkit.models import SecondOrderSystem
from gripkit.models.second_order import second_order_step


@pytest.mark.parametrize("zeta", [0.15, 0.7, 1.0, 2.5])
def test_closed_form_step_equals_scipy(zeta):
    K, wn = 2.5, 12.0
    t = np.linspace(0.0, 3.0, 601)
    _, ref = signal.step(([K * wn ** 2], [1.0, 2 * zeta * wn, wn ** 2]), T=t)
    np.testing.assert_allclose(second_order_step(t, K, wn, zeta), ref, atol=1e-9 * K)
    assert second_order_step([-1.0], K, wn, zeta)[0] == 0.0


@pytest.mark.parametrize("zeta", [0.3, 1.0, 1.8])
def test_simulated_step_with_offsets_is_the_sampled_response(zeta):
    """u steps from u₀ = 1 to 3 at sample 0: y = y₀ + K·2·step(t) exactly (to 1e-12)."""
    K, wn, y0, u0, dt = 0.8, 40.0, -0.2, 1.0, 1e-3
    m = SecondOrderSystem(gain=K, wn=wn, zeta=zeta, y0=y0, u0=u0)
    n = 400
    y = m.simulate(np.full(n, 3.0), dt=dt)["y"]
    expected = y0 + second_order_step(np.arange(n) * dt, K * 2.0, wn, zeta)
    np.testing.assert_allclose(y, expected, atol=1e-12)
    (w, z), = m.modes(m.theta())
    assert (w, z) == pytest.approx((wn, zeta))
