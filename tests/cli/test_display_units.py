"""Outputs kept in the file's units (issue 25): gripkit computes in SI, but a model identified
from ``current [mA]``, ``force [mN]`` keeps those units in its file (``display_unit``), and
``gripkit simulate`` writes ``force [mN]`` in mN; a model file without them simulates in SI."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.signal import lfilter

from gripkit.cli import main
from gripkit.errors import ModelError
from gripkit.io import load, save
from gripkit.sysid import load_model
from gripkit.sysid.model_file import write_document

#: plant in SI: force [N] = (2 q^-1 + 0.5 q^-2) / (1 − 1.2 q^-1 + 0.4 q^-2) current [A]
B_SI, A_SI = [0.0, 2.0, 0.5], [1.0, -1.2, 0.4]


@pytest.fixture
def record(tmp_path):
    """400 samples at 100 Hz, written in mA and mN (the same numbers × 1000)."""
    rng = np.random.default_rng(25)
    u = 1.0 + 0.2 * rng.standard_normal(400)
    y = lfilter(B_SI, A_SI, u) + 1e-3 * rng.standard_normal(400)
    p = tmp_path / "grasp.csv"
    rows = "".join(f"{k / 100:.17g},{1e3 * a:.17g},{1e3 * b:.17g}\n" for k, (a, b) in
                   enumerate(zip(u, y)))
    p.write_text("t,current [mA],force [mN]\n" + rows)
    return p


def run(capsys, *args):
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    assert code == 0, err
    return out


def _identify(capsys, data, out):
    run(capsys, "identify", "arx", data, "--input", "current", "--output", "force", "--na", 2,
        "--nb", 2, "--nk", 1, "--out", out)


def test_model_file_keeps_the_file_units_and_simulate_writes_them(record, tmp_path, capsys):
    model = tmp_path / "m.json"
    _identify(capsys, record, model)
    doc = json.loads(model.read_text())
    assert [(d["unit"], d["display_unit"]) for d in doc["inputs"]] == [("A", "mA")]
    assert [(d["unit"], d["display_unit"]) for d in doc["outputs"]] == [("N", "mN")]
    m = load_model(model)
    assert m.display_units == {"current": "mA", "force": "mN"}
    si = m.simulate(load(record))[:, 0]  # the model computes in SI: newtons
    sim = tmp_path / "sim.csv"
    run(capsys, "simulate", model, "--data", record, "--out", sim)
    assert sim.read_text().splitlines()[0] == "t [s],force [mN]"
    written = np.loadtxt(sim, delimiter=",", skiprows=1)
    np.testing.assert_allclose(written[:, 1], 1000.0 * si, rtol=1e-14, atol=0)
    np.testing.assert_allclose(load(sim)["force"], si, rtol=1e-14, atol=0)  # read back in SI
    d = json.loads(run(capsys, "simulate", model, "--data", record, "--json"))
    assert (d["outputs"]["force"]["unit"], d["outputs"]["force"]["si_unit"]) == ("mN", "N")
    assert d["outputs"]["force"]["final"] == pytest.approx(1000.0 * si[-1], rel=1e-14)


def test_old_model_file_without_display_units_simulates_in_si(record, tmp_path, capsys):
    model = tmp_path / "m.json"
    _identify(capsys, record, model)
    doc = json.loads(model.read_text())
    for entry in doc["inputs"] + doc["outputs"]:
        del entry["display_unit"]
    old = tmp_path / "old.json"
    write_document({k: v for k, v in doc.items() if k != "content_sha256"}, old)
    assert load_model(old).display_units == {}
    sim = tmp_path / "sim.csv"
    run(capsys, "simulate", old, "--data", record, "--out", sim)
    assert sim.read_text().splitlines()[0] == "t [s],force [N]"
    si = load_model(model).simulate(load(record))[:, 0]
    np.testing.assert_allclose(np.loadtxt(sim, delimiter=",", skiprows=1)[:, 1], si,
                               rtol=1e-14, atol=0)


def test_compare_fit_does_not_depend_on_the_file_units(record, tmp_path, capsys):
    """The same record in mA/mN and in A/N: the same fit, to rounding."""
    model = tmp_path / "m.json"
    _identify(capsys, record, model)
    in_si = tmp_path / "si.csv"
    save(load(record), in_si)
    assert in_si.read_text().splitlines()[0] == "t [s],current [A],force [N]"
    fits = [json.loads(run(capsys, "compare", model, d, "--json"))["fit_percent"][0]
            for d in (record, in_si)]
    assert fits[0] == pytest.approx(fits[1], abs=1e-9)


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".h5"])
def test_save_in_display_units_round_trips(record, tmp_path, suffix):
    tr = load(record)
    assert (tr.unit("force"), tr.display_unit("force")) == ("N", "mN")
    out = tmp_path / f"copy{suffix}"
    save(tr, out, units="display")
    back = load(out)
    np.testing.assert_allclose(back["force"], tr["force"], rtol=1e-15, atol=0)
    np.testing.assert_allclose(back["current"], tr["current"], rtol=1e-15, atol=0)
    assert back.meta["display_units"] == {"current": "mA", "force": "mN"}
    if suffix == ".csv":
        assert out.read_text().splitlines()[0] == "t [s],current [mA],force [mN]"
        raw = np.loadtxt(record, delimiter=",", skiprows=1)
        np.testing.assert_allclose(np.loadtxt(out, delimiter=",", skiprows=1)[:, 1:], raw[:, 1:],
                                   rtol=1e-15, atol=0)


def test_renamed_channel_keeps_its_display_unit(record):
    assert load(record).rename(force="f").display_unit("f") == "mN"


def test_display_unit_of_another_quantity_is_refused(record, tmp_path, capsys):
    model = tmp_path / "m.json"
    _identify(capsys, record, model)
    doc = json.loads(model.read_text())
    doc["outputs"][0]["display_unit"] = "mA"
    bad = tmp_path / "bad.json"
    write_document({k: v for k, v in doc.items() if k != "content_sha256"}, bad)
    with pytest.raises(ModelError, match=r"bad.json.*display unit of 'force': 'mA' is not a unit "
                                         r"of the same quantity as the model's 'N'"):
        load_model(bad)


def test_identify_ss_model_file_keeps_the_file_units(record, tmp_path, capsys):
    model = tmp_path / "ss.json"
    run(capsys, "identify", "ss", record, "--input", "current", "--output", "force", "--order", 2,
        "--no-refine", "--out", model)
    assert load_model(model).display_units == {"current": "mA", "force": "mN"}


def test_python_identify_ss_keeps_the_file_units(record):
    from gripkit.sysid import identify

    m = identify(load(record), "ss", input="current", output="force", order=2, refine=False)
    assert m.display_units == {"current": "mA", "force": "mN"}
    assert (m.display_unit("force"), m.system.output_units) == ("mN", ("N",))
