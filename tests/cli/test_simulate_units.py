"""``gripkit simulate MODEL.json --data DATA`` writes each output in its unit (issue 23): every
model family has ``input_units`` / ``output_units`` (tuples, one per channel), and the simulated
columns of a nonlinear model fitted on ``u [V]``, ``y [mm]`` are ``y [m]`` in metres (the
nonlinear families keep no display unit), of a linear one ``y [mm]`` (its display unit)."""

from __future__ import annotations

import io
import warnings

import numpy as np
import pytest

from gripkit.cli import main
from gripkit.io import load
from gripkit.sysid import identify, load_model


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    """A first-order system with a cubic input term, y in metres written in mm, 600 samples at
    100 Hz."""
    rng = np.random.default_rng(23)
    n = 600
    u = np.repeat(rng.uniform(-1.0, 1.0, n // 10), 10)
    y = np.zeros(n)
    for t in range(1, n):
        y[t] = 0.8 * y[t - 1] + 0.5 * u[t - 1] + 0.2 * u[t - 1] ** 3
    y = 1e-3 * y + 1e-6 * rng.normal(size=n)
    path = tmp_path_factory.mktemp("sim") / "record.csv"
    np.savetxt(path, np.column_stack([np.arange(n) / 100, u, 1e3 * y]), delimiter=",",
               header="time [s],u [V],y [mm]", comments="")
    return path


FAMILIES = {"narx": dict(degree=3, lags=1), "hw": dict(nb=1, nf=1, nk=1,
                                                     input_nonlinearity="poly:3"),
            "hysteresis": dict(model="prandtl-ishlinskii", operators=4),
            "nlss": dict(order=1, degree=2)}


def _simulate_csv(capsys, model, data) -> tuple[str, np.ndarray]:
    assert main(["simulate", str(model), "--data", str(data)]) == 0
    out = capsys.readouterr().out
    return out.splitlines()[0], np.loadtxt(io.StringIO(out), delimiter=",", skiprows=1)


@pytest.mark.parametrize("method", sorted(FAMILIES))
def test_nonlinear_simulate_writes_the_output_unit(method, record, tmp_path, capsys):
    tr = load(record)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = identify(tr, method, input="u", output="y", **FAMILIES[method])
    path = tmp_path / f"{method}.json"
    m.save(path)
    loaded = load_model(path)
    assert (loaded.input_units, loaded.output_units) == (("V",), ("m",))
    if method != "nlss":  # the singular names of the single-channel families still answer
        assert (loaded.input_unit, loaded.output_unit) == ("V", "m")
    header, values = _simulate_csv(capsys, path, record)
    assert header == "t [s],y [m]"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        expected = np.asarray(loaded.simulate(tr), dtype=float).reshape(-1)
    assert values[:, 1] == pytest.approx(expected, rel=1e-8, abs=1e-15)
    assert np.max(np.abs(values[:, 1])) < 0.1  # metres: the record's outputs are ≤ 8 mm


def test_linear_simulate_writes_the_display_unit(record, tmp_path, capsys):
    """An ARX model keeps the file's mm as its display unit: ``y [mm]``, values × 1000 of the SI
    free run; its ``output_units`` are the SI ones."""
    model = tmp_path / "arx.json"
    assert main(["identify", "arx", str(record), "--input", "u", "--output", "y", "--na", "1",
                 "--nb", "1", "--nk", "1", "--out", str(model)]) == 0
    capsys.readouterr()
    m = load_model(model)
    assert (m.input_units, m.output_units) == (("V",), ("m",))
    header, values = _simulate_csv(capsys, model, record)
    assert header == "t [s],y [mm]"
    si = np.asarray(m.simulate(load(record)), dtype=float).reshape(-1)
    assert values[:, 1] == pytest.approx(1e3 * si, rel=1e-8, abs=1e-12)


def test_state_space_model_units_from_its_system(record):
    tr = load(record)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = identify(tr, "ss", input="u", output="y", order=1)
    assert (m.input_units, m.output_units) == (("V",), ("m",))
    assert (m.system.input_units, m.system.output_units) == (("V",), ("m",))
