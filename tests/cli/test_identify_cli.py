"""`gripkit identify arx|armax|oe|rls|search`: the exact interfaces of issue 2, JSON fields, human
output, and one-line errors (no traceback). Data: the zoo plant (Table II [2 2 2] of
000_8f66dcc7ab06470c.txt) driven by the paper's S2 and S1 excitations."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from gripkit.cli import main
from gripkit.excitation import bandlimited_noise, multisine
from gripkit.io import load
from gripkit.io import save
from gripkit.sysid import identify
from gripkit.systems.amadeus.force_dynamics import finger_force_model

SRC = str(Path(__file__).resolve().parents[2] / "src")


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    d = tmp_path_factory.mktemp("cli")
    plant = finger_force_model()
    s2 = (bandlimited_noise(0.3, 10.0, 20.0, dt=0.005, operating_point=0.85, limits=(0.6, 1.1),
                            unit="A"))
    s1 = multisine(range(1, 11), 2.0, dt=0.005, operating_point=0.85, limits=(0.6, 1.1), unit="A")
    est = plant.simulate(s2.u, noise_std=0.0125, seed=1).select("current", "force")
    val = plant.simulate(np.tile(s1.u, 2), noise_std=0.0125, seed=2).select("current", "force")
    paths = {"est": d / "s2.parquet", "val": d / "s1.csv"}
    save(est, paths["est"])
    save(val, paths["val"])
    return paths


def run(capsys, *args):
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def arx_args(path, *extra):
    return ["identify", "arx", path, "--input", "current", "--output", "force", "--na", 2, "--nb",
            2,
            "--nk", 2, *extra]


def test_arx_json_has_the_issue_fields(capsys, data):
    code, out, err = run(capsys, *arx_args(data["est"], "--validate", data["val"], "--json"))
    assert code == 0, err
    d = json.loads(out)
    for k in ("structure", "na", "nb", "nk", "A", "B", "A_std", "B_std", "loss", "fit_percent",
              "poles",
              "zeros", "minimum_phase", "n_samples", "validation_fit_percent"):
        assert k in d, k
    assert (d["structure"], d["na"], d["nb"], d["nk"]) == ("arx", 2, 2, 2)
    assert d["A"][0] == 1.0 and len(d["A"]) == 3 and len(d["A_std"]) == 3 and d["A_std"][0] == 0
    assert d["B"][:2] == [0.0, 0.0] and len(d["B"]) == 4 and d["B_std"][:2] == [0.0, 0.0]
    assert all(len(p) == 2 for p in d["poles"]) and len(d["zeros"]) == 1
    assert d["minimum_phase"] is False and d["zeros"][0][0] == pytest.approx(1.167, abs=0.01)
    assert d["n_samples"] == 4000 and d["validation_fit_percent"] > 90
    # the same numbers as the Python API on the same file
    m = identify(load(data["est"]), "arx", input="current", output="force", na=2, nb=2, nk=2)
    np.testing.assert_allclose(d["A"], m.A, rtol=1e-12)
    np.testing.assert_allclose(d["B_std"], m.B_std, rtol=1e-12)


def test_arx_human_readable_table(capsys, data):
    code, out, err = run(capsys, *arx_args(data["est"], "--validate", data["val"]))
    assert code == 0
    assert ("ARX [2 2 2]" in out and "b3" in out and "NON-minimum phase" in out
            and "free-run fit" in out)


def test_rls_json_and_trajectory(capsys, data, tmp_path):
    traj = tmp_path / "theta.parquet"
    code, out, err = run(capsys, "identify", "rls", data["est"], "--input", "current", "--output",
                         "force",
                         "--na", 2, "--nb", 2, "--nk", 2, "--forgetting", 0.995, "--trajectory",
                         traj, "--json")
    assert code == 0, err
    d = json.loads(out)
    assert (d["forgetting"] == 0.995 and len(d["theta_final"]) == 4
            and len(d["theta_std_final"]) == 4)
    # order a1..a_na then the nb B coefficients; close to the plant (A = [1, −1.8732, 0.8996])
    assert d["theta_final"][0] == pytest.approx(-1.8732, abs=0.05)
    # N/A, Table II × force_scale
    assert d["theta_final"][2] == pytest.approx(195.0 * 0.02502, rel=0.2)
    tr = load(traj)
    assert {"a1", "a2", "b2", "b3", "a1_std"} <= set(tr.names) and tr.dt == pytest.approx(0.005)
    assert tr["b3"][-1] == pytest.approx(d["theta_final"][3])


def test_search_json_list_ranked(capsys, data):
    code, out, err = run(capsys, "identify", "search", data["est"], "--input", "current",
                         "--output", "force",
                         "--na", "1:4", "--nb", "1:4", "--nk", "1:10", "--json")
    assert code == 0, err
    rows = json.loads(out)
    # AIC prefers na on the edge 4 of 1:4 (ARX of output-error data wants long A): the search
    # widens past it three times (na 1:7) and nb once (1:5): 7 × 5 × 10 structures
    assert isinstance(rows, list) and len(rows) == 7 * 5 * 10
    assert max(r["na"] for r in rows) == 7 and max(r["nb"] for r in rows) == 5
    assert "the best structure lies on the edge of the searched range: na = 7 (searched 1:7)" in err
    assert all({"na", "nb", "nk", "loss", "aic", "fit_percent"} <= set(r) for r in rows)
    assert [r["aic"] for r in rows] == sorted(r["aic"] for r in rows)
    code, out, _ = run(capsys, "identify", "search", data["est"], "--input", "current", "--output",
                       "force",
                       "--na", "1:2", "--nb", "1:2", "--nk", "1:3", "--top", 3)
    assert code == 0 and "ranked by AIC" in out


@pytest.mark.parametrize("cmd,orders,structure",
                         [("armax", ["--na", 2, "--nb", 2, "--nc", 1, "--nk", 2], "armax"),
                                                  ("oe", ["--nb", 2, "--nf", 2, "--nk", 2], "oe")])
def test_armax_and_oe_json(capsys, data, cmd, orders, structure):
    code, out, err = run(capsys, "identify", cmd, data["est"], "--input", "current", "--output",
                         "force",
                         *orders, "--json")
    assert code == 0, err
    d = json.loads(out)
    assert d["structure"] == structure and d["B"][:2] == [0.0, 0.0]
    if cmd == "oe":  # output-error is the right model for this output noise: close to the plant
        assert d["F"] == pytest.approx([1.0, -1.8732, 0.8996], abs=5e-3)


def _one_line_error(code, err, pattern):
    assert code != 0
    lines = [ln for ln in err.strip().splitlines() if ln.strip()]
    assert len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith("error: ")
    import re

    assert re.search(pattern, lines[0]), lines[0]


def test_missing_column_is_one_line(capsys, data):
    code, out, err = run(capsys, "identify", "arx", data["est"], "--input", "curent", "--output",
                         "force",
                         "--na", 2, "--nb", 2, "--nk", 2)
    _one_line_error(code, err, r"DataError: .*column 'curent' not found; available columns: "
                               r"t, current, force")
    assert out == ""


def _csv(path, t, u, y):
    np.savetxt(path, np.column_stack([t, u, y]), delimiter=",", header="t,current,force",
               comments="")
    return path


@pytest.mark.parametrize("case,pattern", [
    ("nan", r"DataError: nan.csv: column .force. has 1 NaN values \(first at t=0.05 s\)"),
    ("repeated", r"DataError: repeated.csv: time stamps must increase strictly; found repeated"),
    ("decreasing", r"DataError: decreasing.csv: time stamps must increase strictly; found "
                   r"decreasing time"),
    ("nonuniform", r"DataError: ARX identification needs uniform sampling"),
    ("short", r"DataError: ARX \[2 2 2\] .* needs at least 8 samples, found 6"),
    ("constant", r"UnidentifiableError: input column .current. is constant \(0.85 for all 200 "
                 r"samples\): a constant input cannot identify B"),
])
def test_bad_data_is_one_line(capsys, tmp_path, case, pattern):
    n = 6 if case == "short" else 200
    rng = np.random.default_rng(3)
    t = np.arange(n) * 0.005
    u = 0.85 + 0.1 * rng.standard_normal(n)
    y = rng.standard_normal(n)
    if case == "nan":
        y[10] = np.nan
    elif case == "repeated":
        t[5] = t[4]
    elif case == "decreasing":
        t[5] = t[3]
    elif case == "nonuniform":
        t[100:] += 0.002
    elif case == "constant":
        u[:] = 0.85
    path = _csv(tmp_path / f"{case}.csv", t, u, y)
    code, out, err = run(capsys, *arx_args(path, "--json"))
    _one_line_error(code, err, pattern)
    assert out == ""


def test_unstable_model_in_validation_warns_and_reports_null(capsys, tmp_path):
    """Data from an unstable first-order system: the fitted model is unstable; --validate prints a
    warning line and validation_fit_percent is null instead of an absurd number."""
    rng = np.random.default_rng(4)
    u = rng.standard_normal(300)
    y = np.zeros(300)
    for k in range(1, 300):
        y[k] = 1.04 * y[k - 1] + u[k - 1] + 0.01 * rng.standard_normal()
    t = np.arange(300) * 0.005
    p = _csv(tmp_path / "unstable.csv", t, u, y)
    code, out, err = run(capsys, "identify", "arx", p, "--input", "current", "--output", "force",
                         "--na", 1,
                         "--nb", 1, "--nk", 1, "--detrend", "none", "--validate", p, "--json")
    assert code == 0
    d = json.loads(out)
    assert d["validation_fit_percent"] is None and d["stable"] is False
    assert "warning: StabilityWarning" in err and "Traceback" not in err
    assert any("unstable" in w for w in d["warnings"])


def test_bad_range_and_options_are_one_line(capsys, data):
    code, _, err = run(capsys, "identify", "search", data["est"], "--input", "current", "--output",
                       "force",
                       "--nk", "10:1")
    _one_line_error(code, err, r"nk: expected a range like '1:4'")
    code, _, err = run(capsys, "identify", "rls", data["est"], "--input", "current", "--output",
                       "force",
                       "--na", 2, "--nb", 2, "--nk", 2, "--forgetting", 1.2)
    _one_line_error(code, err, r"forgetting factor: expected 0 < λ <= 1, found 1.2")


def test_subprocess_entry_point(data):
    """The real command line (a fresh interpreter): JSON on stdout, exit 0; bad column: exit 1,
    one line on stderr."""
    env = {**os.environ, "PYTHONPATH": SRC + os.pathsep + os.environ.get("PYTHONPATH", "")}
    cmd = [sys.executable, "-c", "import sys; from gripkit.cli import main; sys.exit(main())"]
    ok = subprocess.run(cmd + [str(a) for a in arx_args(data["est"], "--json")],
                        capture_output=True,
                        text=True, env=env, timeout=120)
    assert ok.returncode == 0, ok.stderr
    assert json.loads(ok.stdout)["structure"] == "arx"
    bad = subprocess.run(cmd + ["identify", "arx", str(data["est"]), "--input", "nope", "--output",
                                "force",
                                "--na", "2", "--nb", "2", "--nk", "2"], capture_output=True,
                                text=True, env=env,
                         timeout=120)
    assert (bad.returncode == 1 and bad.stderr.count("\n") == 1
            and "column 'nope' not found" in bad.stderr)


def test_tables_printed_into_a_pipe_keep_their_numbers_whole(capsys, data):
    """stdout captured (no terminal, as in a pipe or a file): the search table is laid out for
    120 columns, not rich's default 80, which cut the loss and FPE to '4.8232e…'."""
    code, out, err = run(capsys, "identify", "search", data["est"], "--input", "current",
                         "--output", "force", "--na", "1:2", "--nb", "1:2", "--nk", "1:2")
    assert code == 0, err
    assert "ranked by AIC" in out and "…" not in out
    assert max(len(line) for line in out.splitlines()) <= 120


@pytest.mark.parametrize("command", [["ss", "--order", "2"],
                                     ["tf", "--poles", "2", "--zeros", "1"]])
def test_identify_says_what_out_and_report_wrote(capsys, data, tmp_path, command):
    """The text summary ends with the files written (`identify ss` and `tf` said nothing of
    --report)."""
    model, report = tmp_path / "m.json", tmp_path / "rep"
    code, out, err = run(capsys, "identify", *command[:1], data["est"], *command[1:], "--input",
                         "current", "--output", "force", "--out", model, "--report", report)
    assert code == 0, err
    assert f"model written to {model}" in out and f"report written to {report}" in out
    assert (report / "index.html").is_file() and model.is_file()
