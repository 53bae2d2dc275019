"""Proportional valve: static curve with hysteresis (Fig. 5), leakage floor and supply (§II-D),
delay
(Fig. 15, §V-C) and first-order pressure dynamics (000_8f66dcc7ab06470c.txt)."""


import numpy as np
import pytest

from gripkit.consistency import check
from gripkit.errors import DataError
from gripkit.systems.amadeus.parameters import force_plant
from gripkit.systems.amadeus.valve import ProportionalValve, pressure_to_force_plant

BAR = 1e5
V = ProportionalValve()


def test_static_curve_limits_and_linear_region():
    """Leakage floor 7.5 bar and 30 bar supply approached asymptotically; central slope k_v; the
    slope reaches 95 % of k_v at 12 bar (§II-D 'operated above 12 bar')."""
    i = np.linspace(0.0, 2.0, 20001)
    P = V.static_pressure(i)
    assert P.min() > 7.5 * BAR and P.min() == pytest.approx(7.5 * BAR, rel=1e-6)
    assert P.max() < 30 * BAR and P.max() == pytest.approx(30 * BAR, rel=1e-6)
    slope = np.gradient(P, i)
    pv = V.parameters
    sig = lambda x: 1 / (1 + np.exp(-x))  # noqa: E731
    w = pv.value("elbow")
    exact = V.gain * (sig((i - pv.value("i_lo")) / w) - sig((i - pv.value("i_hi")) / w))
    np.testing.assert_allclose(slope[1:-1], exact[1:-1], rtol=1e-5, atol=1e-6 * V.gain)
    central = (i > 0.65) & (i < 0.95)
    assert np.all(slope[central] > 0.97 * V.gain) and np.all(slope[central] <= V.gain)
    j = np.argmax(slope >= 0.95 * V.gain)
    assert P[j] == pytest.approx(12 * BAR, rel=2e-3)
    assert check(V).ok


def test_hysteresis_loop_width():
    """Play operator of half-width h: in the linear region the rising and falling branches are 2h
    apart in current, i.e. 2 h k_v in pressure."""
    up = np.linspace(0.6, 1.0, 400)
    cyc = np.r_[up, up[::-1]]
    P = V.hysteresis_loop(cyc)
    rise = np.interp(0.8, up, P[:400])
    fall = np.interp(0.8, up, P[400:][::-1])
    h = V.parameters.value("hysteresis")
    exact = V.static_pressure(0.8 + h) - V.static_pressure(0.8 - h)
    assert fall - rise == pytest.approx(exact, rel=1e-6)
    assert fall - rise == pytest.approx(2 * h * V.gain, rel=3e-3)


def _analytic(t, t_step, delay, tau, p0, p1):
    s = np.clip(t - t_step - delay, 0, None)
    return p1 + (p0 - p1) * np.exp(-s / tau)


@pytest.mark.parametrize("fs", [200.0, 400.0, 250.0])
def test_step_response_exact_with_delay(fs):
    """Current step: the pressure stays put for the 0.01 s delay (two samples at 200 Hz, Fig. 15),
    then follows the exact first-order lag — also for a delay of 2.5 samples (250 Hz)."""
    v = ProportionalValve(hysteresis=0.0)
    n = int(0.3 * fs)
    i = np.full(n, 0.7)
    k0 = 10
    i[k0:] = 0.9
    y = v.simulate(i, dt=1 / fs)["p"]
    t = np.arange(n) / fs
    p0, p1 = v.static_pressure(0.7), v.static_pressure(0.9)
    np.testing.assert_allclose(y, _analytic(t, k0 / fs, 0.01, v.parameters.value("tau"), p0, p1),
                               rtol=1e-12)
    if fs == 200.0:
        assert np.all(y[: k0 + 3] == p0) and y[k0 + 3] > p0


def test_inverse_and_demand_current():
    i = np.linspace(0.55, 1.15, 50)
    np.testing.assert_allclose(V.current_for(V.static_pressure(i)), i, atol=1e-9)
    v0 = ProportionalValve(hysteresis=0.0)
    np.testing.assert_allclose(v0.demand_current([0.7, 0.8, 0.9]), [0.7, 0.8, 0.9], atol=5e-4)
    assert v0.demand_current([2.0])[0] == pytest.approx(1.1, abs=1e-6)  # saturates at the supply
    with pytest.raises(DataError, match="strictly between"):
        V.current_for(31 * BAR)


def test_pressure_to_force_plant_gain():
    """The identified model per unit pressure demand: DC gain G0 / k_v, same poles and zeros."""
    plant, _ = force_plant()
    pf = pressure_to_force_plant(plant, V)
    assert pf.dc_gain() == pytest.approx(plant.dc_gain() / V.gain, rel=1e-12)
    np.testing.assert_allclose(np.sort_complex(pf.poles()), np.sort_complex(plant.poles()))
    assert pf.input_unit == "Pa"
