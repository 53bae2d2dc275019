"""The zoo plant amadeus-finger-force (Table II [2 2 2], 000_8f66dcc7ab06470c.txt) as a simulable,
documented object for controller design."""

import warnings

import control
import numpy as np
import pytest

from gripkit import zoo
from gripkit.errors import ConsistencyWarning
from gripkit.excitation import multisine
from gripkit.sysid import identify
from gripkit.systems.amadeus.force_dynamics import FingerForcePlant, finger_force_model


@pytest.fixture(scope="module")
def plant() -> FingerForcePlant:
    with warnings.catch_warnings():
        warnings.simplefilter("error", ConsistencyWarning)  # building it must not warn
        return zoo.build("amadeus-finger-force")


def test_registry_builds_the_plant(plant):
    assert plant.name == "amadeus-finger-force" and plant.description
    assert plant.dt == 0.005 and plant.delay == 2 and plant.operating_point == 0.850


def test_coefficients_units_and_provenance(plant):
    """SI: B in N/A = 1000 × force_scale × the printed units-per-mA values, force_scale =
    15.45 N / (1.235 units/mA × 500 mA) = 0.02502 N/unit (Fig. 2(c) peak force over the valve
    span)."""
    from gripkit.systems.amadeus.force_dynamics import FORCE_SCALE

    assert FORCE_SCALE == pytest.approx(15.45 / (0.0326 / 0.0264 * 500), rel=1e-9)
    np.testing.assert_allclose(plant.model.A, [1.0, -1.8732, 0.8996])
    np.testing.assert_allclose(plant.model.B, np.array([0.0, 0.0, 195.0, -227.6]) * FORCE_SCALE)
    ps = plant.parameters
    for p in ps.values():
        assert p.unit and p.doc and "000_8f66dcc7ab06470c.txt" in p.source
    assert ps["b2"].unit == "N/A" and ps["b2"].display() == "b2 = 0.00488 ± 0.00055 N/mA"
    assert "Table II" in ps["a1"].source and ps["a1"].std == 0.0117  # σ from Table III
    assert ps["operating_point"].display() == "operating_point = 850 mA"


def test_simulate_from_rest_and_with_given_past(plant):
    s1 = (multisine(range(1, 11), 2.0, dt=0.005, operating_point=0.850, limits=(0.600, 1.100),
                    unit="A"))
    tr = plant.simulate(s1.u)
    f = tr["force"]
    assert tr.unit("force") == "N" and tr.unit("current") == "A" and tr.dt == 0.005
    assert f[0] == f[1] == 0.0  # two-sample delay, at rest before t = 0
    # force = B/A (i − 0.850 A): the same as the model's own simulation of the currents (its
    # u_offset 0.850 A removed inside) and the state space
    np.testing.assert_allclose(f, plant.model.simulate(s1.u))
    ss = plant.to_ss()
    Ad, Bd, Cd, Dd = ss.A, ss.B, ss.C, ss.D
    x = np.zeros(Ad.shape[0])
    for k in range(50):
        assert (Cd @ x)[0] + Dd[0, 0] * (s1.u[k] - 0.85) == pytest.approx(f[k], abs=1e-9)
        x = Ad @ x + Bd[:, 0] * (s1.u[k] - 0.85)
    cont = plant.simulate(s1.u[100:], initial="given", force_past=f[:100], current_past=s1.u[:100])
    np.testing.assert_allclose(cont["force"], f[100:], atol=1e-9)


def test_simulated_plant_is_identified_back(plant):
    """Noisy simulation with the S1 input, identified with the Trajectory entry point: the
    estimates contain the plant's coefficients within 3σ (equation-error noise is not what we add,
    so use a small noise: the ARX bias stays well below σ)."""
    s1 = (multisine(range(1, 11), 2.0, dt=0.005, operating_point=0.850, limits=(0.600, 1.100),
                    unit="A"))
    tr = plant.simulate(np.tile(s1.u, 3), noise_std=0.00125, seed=1)
    # the plant's input variable
    dev = tr.with_channels(current=tr["current"] - plant.operating_point)
    m = identify(dev, "arx", input="current", output="force", na=2, nb=2, nk=2, detrend="none")
    assert np.all(np.abs(m.theta - plant.model.theta) < 3 * m.theta_std)
    assert np.std(tr["force"] - tr["force_true"]) == pytest.approx(0.00125, rel=0.1)


def test_prefilter_and_exports(plant):
    tr = plant.simulate(np.full(400, 0.95), noise_std=0.125, seed=2, prefilter=True)
    # the filtered force keeps the step's steady state (unit DC gain) and removes most noise
    ff, f = tr["force_filtered"], tr["force"]
    assert np.std(ff[300:] - tr["force_true"][300:]) < 0.5 * np.std(f[300:]
                                                                    - tr["force_true"][300:])
    assert tr["force_true"][-1] == pytest.approx(plant.model.dc_gain * 0.1, rel=1e-3)
    g = plant.to_control()
    assert isinstance(g, control.TransferFunction) and g.dt == 0.005
    assert np.max(np.abs(control.poles(g))) == pytest.approx(0.9485, abs=1e-4)
    assert plant.to_scipy().dt == 0.005


def test_finger_force_model_is_fresh_each_call():
    a, b = finger_force_model(), finger_force_model()
    assert a is not b and a.parameters == b.parameters
