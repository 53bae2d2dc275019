"""Online friction adaptation (the thesis's "algorithm to adjust the friction model", abstract and
§6.3): recursive least squares with forgetting converges to a changed friction within its stated
convergence time."""

import math

import numpy as np
import pytest

from gripkit.errors import DataError, ModelError
from gripkit.estimation.friction_adaptation import FrictionAdapter
from gripkit.signals import Trajectory
from gripkit.systems.dlr_hit.friction_adaptation import adapt_finger_friction, tracking_reference
from gripkit.systems.dlr_hit.impedance import ImpedanceController, simulate_impedance
from gripkit.systems.dlr_hit.parameters import dlr_hit_table
from gripkit.systems.dlr_hit.parameters import finger

T_HALF = 20.0
#: friction drift in the second half (ageing/temperature): distal +30 %, base 1 +20 %, base 2 −10 %
DRIFT = dict(scale_distal=1.3, scale_base1=1.2, scale_base2=1.25 * 0.9)
TRUE_AFTER = np.array([1.2, 0.9, 1.3])


@pytest.fixture(scope="module")
def drifting_log():
    n = int(T_HALF * 1000)
    ref = tracking_reference(2 * T_HALF)
    c = ImpedanceController("joint", (8, 8, 8), (0.6, 0.6, 0.6))
    f1, f2 = finger(check=False), finger(check=False, **DRIFT)
    a = simulate_impedance(f1, c, ref[:n])
    x1 = (f2.state(q=[a[j][-1] for j in ("abd", "flex", "prox")],
                   qd=[a[f"{j}_vel"][-1] for j in ("abd", "flex", "prox")]))
    b = simulate_impedance(f2, c, ref[n:], x0=x1)
    names = ("abd", "flex", "prox", "abd_vel", "flex_vel", "prox_vel", "pwm_base1", "pwm_base2",
             "pwm_distal")
    return f1, Trajectory.uniform(dt=0.001, **{k: np.concatenate([a[k], b[k]]) for k in names})


def test_adaptation_converges_to_a_changed_friction(drifting_log):
    """λ = 0.999 at 1 kHz: the stated 95 % convergence time is dt·ln 20/(−ln λ) = 3.0 s of sliding.
    Before the drift the scales stay at 1 (±2 %); after it every scale is within 5 % of its new
    value (1.2, 0.9, 1.3) no later than 1.5× the stated time divided by the fraction of samples
    the drive slides, and ends within 2 %."""
    f, log = drifting_log
    ad, res = adapt_finger_friction(f, log, forgetting=0.999)
    t95 = ad.convergence_time()
    assert t95 == pytest.approx(1e-3 * math.log(20) / -math.log(0.999))
    assert 2.99 < t95 < 3.0
    before = (res.t > 6) & (res.t < T_HALF)
    assert np.all(np.abs(res.scale[before] - 1.0) < 0.02)
    for k in range(3):
        duty = res.active[res.t >= T_HALF, k].mean()
        settle = res.settling_time(k, TRUE_AFTER[k], T_HALF, tol=0.05)
        assert settle <= 1.5 * t95 / duty, (k, settle, duty)
        assert res.scale[-1, k] == pytest.approx(TRUE_AFTER[k], rel=0.02)
    # the reported standard deviations are small and honest about the noise-free data
    assert np.all(res.std[-1, :, 0] < 0.05)


def test_shorter_memory_converges_faster(drifting_log):
    f, log = drifting_log
    slow = adapt_finger_friction(f, log, forgetting=0.9995)[1].settling_time(2, 1.3, T_HALF)
    fast = adapt_finger_friction(f, log, forgetting=0.998)[1].settling_time(2, 1.3, T_HALF)
    assert fast < slow


def test_adapter_continues_across_calls_and_checks_input():
    t = dlr_hit_table("distal")
    a = FrictionAdapter([t], [0.0221], 1e-3)
    rng = np.random.default_rng(0)
    n = np.arange(4000)
    v = 2.0 * np.sin(2 * np.pi * 1.5 * n * 1e-3)[:, None]
    acc = np.gradient(v[:, 0], 1e-3)[:, None]
    tau = 1.2 * t(v) + 0.0221 * acc + rng.normal(0, 1e-3, v.shape)
    whole = FrictionAdapter([t], [0.0221], 1e-3).update(tau, np.zeros_like(v), v)
    a.update(tau[:2000], np.zeros((2000, 1)), v[:2000])
    second = a.update(tau[2000:], np.zeros((2000, 1)), v[2000:])
    np.testing.assert_allclose(second.scale[-1], whole.scale[-1], rtol=1e-12)
    assert second.scale[-1, 0] == pytest.approx(1.2, rel=0.05)
    assert a.corrected_tables()[0].scale == pytest.approx(a.theta[0, 0])
    with pytest.raises(DataError, match="shape"):
        a.update(tau, np.zeros((10, 1)), v)
    with pytest.raises(ModelError, match="forgetting"):
        FrictionAdapter([t], [0.0221], 1e-3, forgetting=1.5)
    with pytest.raises(ModelError, match="Nyquist"):
        FrictionAdapter([t], [0.0221], 1e-3, filter_hz=600)
