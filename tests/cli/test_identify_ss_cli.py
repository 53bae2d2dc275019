"""`gripkit identify ss|frf|tf`, `compare`, `simulate MODEL.json --data`, `report`: the exact
interfaces of issue 13 (JSON fields per output, in --output order) on a known 2×2 system."""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

from gripkit import Trajectory
from gripkit.cli import main
from gripkit.excitation import periodic_multisine
from gripkit.io import load, save
from gripkit.lti import TransferFunction

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "sysid"))
from mimo_systems import oe_data, two_by_two  # noqa: E402


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("ss")
    g = two_by_two()
    out = {}
    for name, seed in (("est", 1), ("val", 2)):
        u, y = oe_data(g, 4000, 0.05, seed)
        tr = Trajectory.uniform(dt=0.01, a=u[:, 0] + 1.0, b=u[:, 1], c=y[:, 0] + 3.0, d=y[:, 1],
                                units={"a": "V", "b": "V", "c": "N", "d": "m"})
        out[name] = d / f"{name}.csv"
        save(tr, out[name])
    ex = periodic_multisine(0.05, 5.0, 400, 5, dt=0.05, amplitude=1.0)
    y = TransferFunction([2.0, 4.0], [1.0, 0.8, 4.0]).c2d(0.05).simulate(ex.u)[:, 0]
    y = y + 0.01 * np.random.default_rng(0).standard_normal(y.size)
    out["siso"] = d / "siso.csv"
    save(Trajectory.uniform(dt=0.05, v=ex.u, x=y, units={"v": "V", "x": "m"}), out["siso"])
    out["dir"] = d
    return out


def run(capsys, *args):
    code = main([str(a) for a in args])
    o, e = capsys.readouterr()
    return code, o, e


def test_identify_ss_json_fields(capsys, files):
    model = files["dir"] / "m.json"
    code, out, err = run(capsys, "identify", "ss", files["est"], "--input", "a,b", "--output",
                         "d,c",
                         "--validate", files["val"], "--out", model, "--report",
                         files["dir"] / "ssrep", "--json")
    assert "Subspace singular values" in (files["dir"] / "ssrep" / "index.html").read_text()
    assert code == 0, err
    r = json.loads(out)
    for k in ("A", "B", "C", "D", "K", "dt", "order", "singular_values", "stable", "fit_percent"):
        assert k in r
    assert r["order"] == 4 and r["dt"] == pytest.approx(0.01) and r["stable"] is True
    assert np.shape(r["A"]) == (4, 4) and np.shape(r["B"]) == (4, 2) and np.shape(r["C"]) == (2, 4)
    assert np.shape(r["K"]) == (4, 2) and r["outputs"] == ["d", "c"]
    assert len(r["fit_percent"]) == 2 and len(r["validation"]["fit_percent"]) == 2
    assert min(r["validation"]["fit_percent"]) > 94.0 and r["structure"] == "pem-innovation"
    assert model.exists()


def test_identify_ss_order_range_ranked_by_validation(capsys, files):
    code, out, err = run(capsys, "identify", "ss", files["est"], "--input", "a,b", "--output",
                         "c,d",
                         "--order", "2:7", "--validate", files["val"], "--no-refine", "--json")
    assert code == 0, err
    r = json.loads(out)
    assert r["order"] == 4 and r["search_criterion"] == "validation_fit"
    assert [row["order"] for row in r["search"]][0] == 4


def test_order_search_widens_past_the_edge(capsys, files):
    """The system has order 4: the range 1:3 has its best on the edge, so the search goes on
    past it (issue 25) and finds 4, without the edge warning."""
    code, out, err = run(capsys, "identify", "ss", files["est"], "--input", "a,b", "--output",
                         "c,d",
                         "--order", "1:3", "--no-refine", "--json")
    assert code == 0, err
    r = json.loads(out)
    assert r["order"] == 4 and 4 in [row["order"] for row in r["search"]]
    assert "(1:3 widened)" in r["info"]["order_selection"]
    assert not any("edge of the searched range" in w for w in r["warnings"])


def test_compare_simulate_report(capsys, files):
    model = files["dir"] / "m2.json"
    assert run(capsys, "identify", "ss", files["est"], "--input", "a,b", "--output", "c,d", "--out",
               model)[0] == 0
    code, out, err = run(capsys, "compare", model, files["val"], "--json")
    assert code == 0, err
    r = json.loads(out)
    assert r["outputs"] == ["c", "d"] and min(r["fit_percent"]) > 94.0
    sim = files["dir"] / "sim.csv"
    code, out, err = run(capsys, "simulate", model, "--data", files["val"], "--out", sim)
    assert code == 0, err
    head = sim.read_text().splitlines()[0]
    assert head.split(",")[1].startswith("c") and head.split(",")[2].startswith("d")
    tr = load(sim)
    val = load(files["val"])
    assert np.corrcoef(tr["c"], val["c"])[0, 1] > 0.99
    code, out, err = run(capsys, "report", model, files["val"], "--out", files["dir"] / "rep")
    assert code == 0, err
    html = (files["dir"] / "rep" / "index.html").read_text()
    for section in ("Measured and simulated outputs", "Residual analysis", "Poles and zeros",
                    "Frequency response",
                    "Subspace singular values", "Warnings"):
        assert section in html


def test_identify_frf_json(capsys, files):
    code, out, err = run(capsys, "identify", "frf", files["siso"], "--input", "v", "--output", "x",
                         "--periods", "5",
                         "--json")
    assert code == 0, err
    r = json.loads(out)
    H = np.array(r["H_real"]) + 1j * np.array(r["H_imag"])
    true = TransferFunction([2.0, 4.0], [1.0, 0.8, 4.0]).c2d(0.05).frequency_response(
        2 * np.pi * np.array(r["frequency_hz"]))[:, 0, 0]
    assert np.mean(np.abs(H - true) <= 3 * np.array(r["H_std"])) >= 0.9
    code, out, err = (run(capsys, "identify", "frf", files["siso"], "--input", "v", "--output", "x",
                          "--json"))
    assert "coherence" in json.loads(out)
    assert json.loads(out)["H_unit"] == "m/V"  # x [m] per v [V] of the data file
    code, out, err = run(capsys, "identify", "frf", files["siso"], "--input", "v", "--output", "x")
    assert code == 0 and "['v'] → ['x'], H in m/V" in out and " m/V  phase" in out


def test_identify_tf_json(capsys, files):
    rep = files["dir"] / "tfrep"
    code, out, err = run(capsys, "identify", "tf", files["siso"], "--input", "v", "--output", "x",
                         "--poles", "2",
                         "--zeros", "1", "--out", files["dir"] / "tf.json", "--report", rep,
                         "--json")
    assert "Poles and zeros" in (rep / "index.html").read_text()
    assert code == 0, err
    r = json.loads(out)
    assert (len(r["num"]) == 2 and len(r["den"]) == 3 and len(r["num_std"]) == 2
            and len(r["den_std"]) == 3)
    assert abs(r["den"][2] - 4.0) <= 4 * r["den_std"][2]
    assert r["natural_frequency_hz"][0] == pytest.approx(1 / np.pi, rel=0.02)
    assert r["damping_ratio"][0] == pytest.approx(0.2, abs=0.02) and r["fit_percent"][0] > 95


def test_identify_python_dispatch(files):
    from gripkit.sysid import identify

    tr = load(files["est"])
    m = identify(tr, "ss", input="a,b", output=["c", "d"], order=4)
    assert m.order == 4 and m.inputs == ("a", "b") and m.u_offset[0] == pytest.approx(1.0, abs=0.05)


def test_identify_arx_out_then_compare(capsys, files):
    """`identify arx --out` writes the model file; `compare` on it reproduces the ARX's own free-run
    validation fit (two code paths, the same number within 0.1 point: they differ only in how the
    initial condition is estimated)."""
    model = files["dir"] / "arx.json"
    code, out, err = run(capsys, "identify", "arx", files["siso"], "--input", "v", "--output", "x",
                         "--na", "2",
                         "--nb", "2", "--nk", "1", "--validate", files["siso"], "--out", model,
                         "--json")
    assert code == 0, err
    own = json.loads(out)["validation_fit_percent"]
    code, out, err = run(capsys, "compare", model, files["siso"], "--json")
    assert code == 0, err
    r = json.loads(out)
    assert abs(r["fit_percent"][0] - own) < 0.1 and r["estimation_data"] is True


def test_simulate_without_out_prints_csv(capsys, files):
    model = files["dir"] / "m3.json"
    assert run(capsys, "identify", "ss", files["est"], "--input", "a,b", "--output", "c,d",
               "--order", "4",
               "--no-refine", "--out", model)[0] == 0
    code, out, err = run(capsys, "simulate", model, "--data", files["val"])
    assert code == 0, err
    lines = out.splitlines()
    assert lines[0] == "t [s],c [N],d [m]" and len(lines) == 4001
    assert float(lines[2].split(",")[0]) == pytest.approx(0.01)


def test_identify_search_ranked_by_validation(capsys, files):
    code, out, err = run(capsys, "identify", "search", files["siso"], "--input", "v", "--output",
                         "x", "--na", "1:3",
                         "--nb", "1:3", "--nk", "0:2", "--validate", files["siso"], "--json")
    assert code == 0, err
    rows = json.loads(out)
    # (a row without a validation fit: an unstable structure, which ranks last)
    v = [r["validation_fit_percent"] for r in rows if r.get("validation_fit_percent") is not None]
    assert v == sorted(v, reverse=True) and rows[0]["validation_fit_percent"] == v[0]
