"""Model files: save/load round trip (arrays, covariance, names, units, offsets, provenance),
schema and hash checks, python-control interop with names."""

import json
import warnings

import numpy as np
import pytest

from gripkit.errors import DataWarning, ModelError
from gripkit.lti import from_control
from gripkit.sysid import load_model, n4sid, pem, tfest

from mimo_systems import oe_data, two_by_two


@pytest.fixture(scope="module")
def model():
    g = two_by_two()
    u, y = oe_data(g, 2000, 0.05, seed=1)
    m = n4sid(u, y, 4, dt=0.01, inputs=["a", "b"], outputs=["c", "d"], input_units=["V", "V"],
              output_units=["N", "m"], u_offset=[1.0, 0.0], y_offset=[3.0, -1.0])
    return pem(m, u=u, y=y).replace(data_file="run.csv", data_hash="ab" * 32)


def test_round_trip_exact(model, tmp_path):
    p = tmp_path / "m.json"
    model.save(p)
    back = load_model(p)
    s, b = model.system, back.system
    for x, z in ((s.A, b.A), (s.B, b.B), (s.C, b.C), (s.D, b.D), (model.K, back.K),
                 (model.x0, back.x0)):
        assert np.array_equal(x, z)
    assert np.array_equal(s.uncertainty.covariance, b.uncertainty.covariance)
    p1, c1 = s.pole_covariance()
    p2, c2 = b.pole_covariance()
    assert np.array_equal(p1, p2) and np.array_equal(c1, c2)
    assert (b.inputs, b.outputs, b.input_units,
            b.output_units) == (("a", "b"), ("c", "d"), ("V", "V"), ("N", "m"))
    assert back.u_offset == (1.0, 0.0) and back.y_offset == (3.0, -1.0) and back.dt == 0.01
    assert (back.structure == "pem-innovation" and back.data_file == "run.csv"
            and back.data_hash == "ab" * 32)
    doc = json.loads(p.read_text())
    assert doc["schema"] == "gripkit.linear-model" and doc["schema_version"] == 2
    assert "gripkit_version" in doc


def test_tfest_model_round_trip(tmp_path):
    from gripkit.lti import TransferFunction

    rng = np.random.default_rng(0)
    u = rng.standard_normal(2000)
    y = (TransferFunction([4.0], [1.0, 0.8, 4.0]).c2d(0.05).simulate(u)[:, 0] + 0.01
         * rng.standard_normal(2000))
    m = tfest(u, y, 2, 0, dt=0.05)
    m.save(tmp_path / "tf.json")
    b = load_model(tmp_path / "tf.json")
    assert b.system.dt is None and np.array_equal(b.system.denominator(), m.system.denominator())
    assert np.array_equal(b.system.uncertainty.std, m.system.uncertainty.std)


def test_edited_file_warns_hash_mismatch(model, tmp_path):
    p = tmp_path / "m.json"
    model.save(p)
    doc = json.loads(p.read_text())
    doc["system"]["A"][0][0] += 1e-3
    p.write_text(json.dumps(doc))
    with pytest.warns(DataWarning, match="its content differs from what gripkit wrote"):
        load_model(p)


def test_wrong_schema_refused(tmp_path):
    p = tmp_path / "x.json"
    p.write_text(json.dumps({"schema": "something-else", "A": [[1]]}))
    with pytest.raises(ModelError, match="unknown schema 'something-else'; gripkit reads"):
        load_model(p)


def test_load_model_gives_back_the_saved_family(tmp_path):
    """One door (sysid.load_model) for every family: a NARX file comes back as a NARXModel."""
    from gripkit.sysid import NARXModel, narx

    rng = np.random.default_rng(3)
    u = rng.standard_normal(400)
    y = np.zeros(400)
    for t in range(1, 400):
        y[t] = 0.5 * y[t - 1] + u[t - 1] + 0.1 * u[t - 1] ** 2
    m = narx(u, y, degree=2, lags=1)
    m.save(tmp_path / "n.json")
    back = load_model(tmp_path / "n.json")
    assert isinstance(back, NARXModel)
    np.testing.assert_array_equal(back.theta, m.theta)


def test_to_control_keeps_names_and_from_control_goes_back(model):
    c = model.to_control()
    assert c.input_labels == ["a", "b"] and c.output_labels == ["c", "d"]
    back = from_control(c, output_units=["N", "m"])
    w = [0.5, 5.0, 50.0]
    assert np.allclose(back.frequency_response(w), model.system.frequency_response(w), rtol=1e-12)


def test_simulate_and_compare_data_by_name(model):
    from gripkit import Trajectory

    g = two_by_two()
    u, y = oe_data(g, 1500, 0.0, seed=8)
    tr = Trajectory.uniform(dt=0.01, b=u[:, 1], a=u[:, 0] + 1.0, c=y[:, 0] + 3.0, d=y[:, 1] - 1.0)
    assert min(model.compare(tr).fit_percent) > 99.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sim = model.simulate(tr)
    # the arrays of the record's inputs: the model's u_offset (1, 0) removed, y_offset (3, −1)
    # added, as for the trajectory; the deviations' free run plus the output offsets
    assert np.allclose(sim, model.simulate(u + [1.0, 0.0], dt=0.01))
    at_zero = model.replace(u_offset=(0.0, 0.0), y_offset=(0.0, 0.0))
    assert np.allclose(sim, at_zero.simulate(u, dt=0.01) + [3.0, -1.0])


def test_polynomial_model_saves_as_model_file(tmp_path, arx_data):
    """An ARX [2 2 2] (Table II of 000_8f66dcc7ab06470c.txt) saves through the same file format and
    comes back as a PolynomialModel: the reloaded transfer function has the same poles, and the σ of
    its coefficients are the ARX σ."""
    from gripkit.sysid import PolynomialModel
    from gripkit.sysid import arx

    u, y = arx_data(2000, noise=1.0, seed=0)
    pm = arx(u, y, 2, 2, 2, dt=0.005, input_name="current", output_name="force", input_unit="A",
             output_unit="N", u_offset=0.85, y_offset=0.0)
    pm.save(tmp_path / "arx.json")
    m = load_model(tmp_path / "arx.json")
    assert m.structure == "arx" and m.inputs == ("current",) and m.system.output_units == ("N",)
    assert isinstance(m, PolynomialModel) and m.u_offset == 0.85 and m.dt == 0.005
    p = m.system.poles()
    p = p[np.abs(p) > 1e-9]                       # the delay's poles at z = 0 are states of B/(A F)
    assert np.allclose(np.sort_complex(p), np.sort_complex(pm.poles()), atol=1e-12)
    assert np.allclose(m.system.uncertainty.std, pm.theta_std, rtol=1e-12)


def test_simulate_trajectory_is_what_gripkit_simulate_writes(tmp_path):
    """Issue 23 ("the library, not the CLI, simulates a model file"): sysid.simulated_trajectory
    gives the SI outputs of model.simulate(data) on the record's time base, with the model's display
    units in meta, and io.save(units="display") writes them as the estimation file did."""
    from gripkit import Trajectory
    from gripkit.io import load, save
    from gripkit.lti import StateSpace
    from gripkit.sysid import LinearModel, simulated_trajectory

    ss = StateSpace([[0.5]], [[1.0]], [[2.0]], [[0.0]], dt=0.1, inputs="i", outputs="f",
                    input_units="A", output_units="N")
    m = LinearModel(ss, "n4sid", display_units={"f": "mN"})
    tr = Trajectory.uniform(dt=0.1, i=np.sin(np.arange(50) * 0.3), units={"i": "A"})
    sim = simulated_trajectory(m, tr)
    np.testing.assert_array_equal(sim["f"], m.simulate(tr)[:, 0])
    assert sim.unit("f") == "N" and sim.meta["display_units"] == {"f": "mN"}
    save(sim, tmp_path / "sim.csv", units="display")
    assert (tmp_path / "sim.csv").read_text().splitlines()[0].endswith("f [mN]")
    np.testing.assert_allclose(load(tmp_path / "sim.csv")["f"], sim["f"], rtol=1e-9)
