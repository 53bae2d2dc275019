"""C code of controllers and of the RLS update (issue 27): each generated file compiles with
``gcc -std=c99 -O2 -Wall -Wextra -Werror``, runs through its harness on a recorded sequence, and
equals the Python ``.step`` (PID, RST, LQR state feedback) or ``RLS.update`` (error, θ and P
after every sample) to 1e-12 relative; the controller file round-trips; the CLI writes the
files and refuses bad requests in one line."""

from __future__ import annotations

import json
import math
import os
import shutil
import subprocess

import numpy as np
import pytest

from gripkit.cli import main
from gripkit.control import (PID, StateFeedback, design_rst, load_controller, lqr_controller,
                             save_controller, tune_pid)
from gripkit.errors import ConfigError
from gripkit.export import controller_c_sources, controller_harness, rls_c_sources, rls_harness
from gripkit.lti import StateSpace, TransferFunction
from gripkit.sysid import RLS

GCC = shutil.which("gcc")
#: as in test_c_export.py: skipped without gcc unless GRIPKIT_C_TESTS=1 (.ci/run) makes that fail
REQUIRED = os.environ.get("GRIPKIT_C_TESTS") == "1"
needs_gcc = pytest.mark.skipif(GCC is None and not REQUIRED,
                               reason="gcc is not on PATH: the generated C cannot be compiled "
                                      "(set GRIPKIT_C_TESTS=1 to make this a failure)")
FLAGS = ["-std=c99", "-O2", "-Wall", "-Wextra", "-Werror"]


@pytest.fixture(autouse=True)
def _compiler_when_required():
    if REQUIRED and GCC is None:
        pytest.fail("GRIPKIT_C_TESTS=1 but gcc is not on PATH: install it (Debian: apt-get "
                    "install gcc)")


def run_c(tmp_path, files: dict, harness: str, name: str, rows: np.ndarray) -> np.ndarray:
    """Compile ``files`` with ``harness``, feed it ``rows`` (N, k), return its output (N, q)."""
    for fname, text in files.items():
        (tmp_path / fname).write_text(text)
    (tmp_path / "harness.c").write_text(harness)
    exe = tmp_path / "harness"
    res = subprocess.run([GCC, *FLAGS, "-o", str(exe), str(tmp_path / "harness.c"),
                          str(tmp_path / f"{name}.c"), "-lm"], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    inp = tmp_path / "in.txt"
    np.savetxt(inp, rows, fmt="%.17g", delimiter=",")
    out = subprocess.run([str(exe), str(inp)], capture_output=True, text=True, check=True).stdout
    return np.loadtxt(out.splitlines(), delimiter=",", ndmin=2)


def same(a, b):
    np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12 * np.max(np.abs(b)))


def _plant():
    return TransferFunction.from_polynomials([1.0, -1.5, 0.56], [0.0, 0.0, 0.2, 0.1], dt=0.01)


@needs_gcc
@pytest.mark.parametrize("pid", [
    PID(2.0, 40.0, 0.05, dt=0.01, c=1.0, b=0.7, u_min=-3.0, u_max=3.0),   # saturates
    PID(0.8, 5.0, dt=0.01),                                                # PI, no limits
], ids=["pid-limited", "pi"])
def test_pid_c_step_equals_python(tmp_path, pid):
    rng = np.random.default_rng(27)
    n = 500
    rows = np.column_stack([np.repeat(rng.uniform(-1, 1, 10), 50), 0.5 * rng.standard_normal(n),
                            0.1 * rng.standard_normal(n)])
    c_out = run_c(tmp_path, controller_c_sources(pid, "pid1"), controller_harness(pid, "pid1"),
                  "pid1", rows)[:, 0]
    pid.reset()
    py = np.array([pid.step(*row) for row in rows])
    same(c_out, py)
    if np.isfinite(pid.limits[1]):
        assert np.count_nonzero(np.abs(py) == 3.0) > 20  # the limits and anti-windup ran


@needs_gcc
def test_rst_c_step_equals_python(tmp_path):
    c = design_rst(_plant(), wn=12.0, zeta=0.8, u_min=-0.3, u_max=0.3)
    rng = np.random.default_rng(5)
    rows = np.column_stack([np.repeat(rng.uniform(-1, 1, 8), 60), 0.3 * rng.standard_normal(480)])
    c_out = run_c(tmp_path, controller_c_sources(c, "rst1"), controller_harness(c, "rst1"),
                  "rst1", rows)[:, 0]
    c.reset()
    py = np.array([c.step(*row) for row in rows])
    same(c_out, py)
    assert np.count_nonzero(np.abs(py) == 0.3) > 5


@needs_gcc
@pytest.mark.parametrize("reference", [True, False])
def test_lqr_c_step_equals_python(tmp_path, reference):
    A = np.array([[0.9, 0.1, 0.0], [0.0, 0.8, 0.2], [0.05, 0.0, 0.7]])
    B = np.array([[1.0, 0.0], [0.2, 0.5], [0.0, 1.0]])
    g = StateSpace(A, B, np.array([[1.0, 0, 0], [0, 0, 1.0]]), np.zeros((2, 2)), dt=0.01)
    sf = lqr_controller(g, np.eye(3), 0.1 * np.eye(2), reference=reference,
                        u_min=[-1.0, -math.inf], u_max=[1.0, 0.5])
    rng = np.random.default_rng(9)
    x = 2 * rng.standard_normal((300, 3))
    r = rng.standard_normal((300, 2))
    rows = np.hstack([x, r]) if reference else x
    c_out = run_c(tmp_path, controller_c_sources(sf, "lqr1"), controller_harness(sf, "lqr1"),
                  "lqr1", rows)
    py = np.array([sf.step(xk, rk if reference else None) for xk, rk in zip(x, r)])
    same(c_out, py)
    assert np.any(py[:, 0] == 1.0) and np.any(py[:, 1] == 0.5)


@needs_gcc
@pytest.mark.parametrize("orders,windup,lam", [((3, 3, 1), "trace", 0.99),
                                               ((2, 2, 2), "directional", 0.98),
                                               ((1, 2, 0), "none", 1.0)])
def test_rls_c_update_equals_rls_update(tmp_path, orders, windup, lam):
    """ARX data y = (0.5 q⁻¹ + 0.3 q⁻²)/(1 − 1.2 q⁻¹ + 0.5 q⁻²) u + noise: error, θ and P of each
    sample (the regressor's fill-in included) equal RLS.update's."""
    from scipy.signal import lfilter

    rng = np.random.default_rng(31)
    u = rng.standard_normal(800)
    y = lfilter([0.0, 0.5, 0.3], [1.0, -1.2, 0.5], u) + 0.01 * rng.standard_normal(800)
    est = RLS(*orders, forgetting=lam, windup=windup, p0=100.0)
    c_out = run_c(tmp_path, rls_c_sources(est, "rls1"), rls_harness("rls1"), "rls1",
                  np.column_stack([u, y]))
    p = est.n_params
    py = []
    for a, b in zip(u, y):
        e = est.update(float(a), float(b))
        py.append(np.concatenate([[e], est.theta, est.P.ravel()]))
    py = np.array(py)
    assert c_out.shape == (800, 1 + p + p * p)
    same(c_out, py)
    if orders == (3, 3, 1):  # holds the true [2 2 1]: the last a-priori errors are at the noise
        assert np.std(py[-300:, 0]) < 0.02  # level (σ = 0.01)


@needs_gcc
def test_rls_c_refuses_a_non_finite_sample_and_keeps_its_state(tmp_path):
    est = RLS(2, 2, 1, p0=100.0)
    for fname, text in rls_c_sources(est, "rlsn").items():
        (tmp_path / fname).write_text(text)
    (tmp_path / "h.c").write_text(rls_harness("rlsn"))
    inp = tmp_path / "in.txt"
    inp.write_text("1.0,0.5\n0.2,0.1\n-1.0,0.3\nnan,0.2\n0.5,0.4\n")
    exe = tmp_path / "h"
    subprocess.run([GCC, *FLAGS, "-o", str(exe), str(tmp_path / "h.c"),
                    str(tmp_path / "rlsn.c"), "-lm"], check=True)
    out = subprocess.run([str(exe), str(inp)], capture_output=True, text=True, check=True).stdout
    lines = [ln.split(",") for ln in out.splitlines()]
    assert len(lines) == 5
    assert lines[3][0].lower().lstrip("-") == "nan" and lines[3][1:] == lines[2][1:]
    assert lines[4][1:] != lines[2][1:]  # the next finite sample updates again


def test_controller_file_round_trip(tmp_path):
    pid = tune_pid(_plant(), tau_c=0.05, u_min=-1.0)
    save_controller(pid, tmp_path / "pid.json")
    back = load_controller(tmp_path / "pid.json")
    assert back.params.tolist() == pid.params.tolist() and back.design["tau_c"] == 0.05
    d = json.loads((tmp_path / "pid.json").read_text())
    assert d["format"] == "gripkit.controller" and d["kind"] == "pid" and d["parameters"][
        "u_max"] is None
    c = design_rst(_plant(), wn=12.0)
    save_controller(c, tmp_path / "rst.json")
    rb = load_controller(tmp_path / "rst.json")
    assert rb.R.tolist() == c.R.tolist() and rb.A_aw.tolist() == c.A_aw.tolist()
    assert rb.dt == 0.01 and rb.run(1.0, np.zeros(20)).tolist() == c.run(1.0, np.zeros(20)).tolist()
    sf = StateFeedback([[1.0, 2.0]], dt=0.1, u_max=[3.0])
    save_controller(sf, tmp_path / "sf.json")
    sb = load_controller(tmp_path / "sf.json")
    assert sb.K.tolist() == [[1.0, 2.0]] and not sb.has_reference and sb.u_max.tolist() == [3.0]


@pytest.mark.parametrize("content,phrase", [
    ('{"format": "gripkit.model"}', "not a controller file"),
    ('{"format": "gripkit.controller", "version": 1, "kind": "pid", "dt": 0.01, '
     '"parameters": {"kp": "1"}}', "'kp' must be a finite number"),
    ('{"format": "gripkit.controller", "version": 1, "kind": "rst", "dt": 0.01, '
     '"parameters": {"R": [2.0, 1.0], "S": [1.0], "T": [1.0], "A_aw": [1.0, 0.0], '
     '"u_min": null, "u_max": null}}', "R must be monic"),
    ('{"format": "gripkit.controller", "version": 2}', "version 2 is not supported"),
    ("{oops", "not valid JSON"),
])
def test_a_bad_controller_file_is_refused_with_its_name(tmp_path, content, phrase):
    p = tmp_path / "ctl.json"
    p.write_text(content)
    with pytest.raises(ConfigError, match=phrase) as e:
        load_controller(p)
    assert "'ctl.json'" in str(e.value)


@needs_gcc
def test_cli_exports_a_controller_file_and_the_rls(tmp_path, capsys):
    pid = PID(1.0, 10.0, dt=0.01)
    save_controller(pid, tmp_path / "force_pid.json")
    assert main(["export", "c", str(tmp_path / "force_pid.json"), "--kind", "pid", "--out",
                 str(tmp_path / "c"), "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["name"] == "force_pid" and res["warnings"] == [] and len(res["files"]) == 2
    assert "double force_pid_step(force_pid_state *s, double r, double y, double ff);" in \
        (tmp_path / "c" / "force_pid.h").read_text()
    assert main(["export", "c", "--rls", "--na", "3", "--nb", "3", "--nk", "1", "--lam", "0.99",
                 "--out", str(tmp_path / "c"), "--name", "est"]) == 0
    h = (tmp_path / "c" / "est.h").read_text()
    assert "#define EST_NP 6" in h and "forgetting 0.99" in h
    for stem in ("force_pid", "est"):
        subprocess.run([GCC, *FLAGS, "-c", "-o", str(tmp_path / f"{stem}.o"),
                        str(tmp_path / "c" / f"{stem}.c")], check=True)


@pytest.mark.parametrize("args,phrase", [
    (["--kind", "rst"], "holds a pid controller"),
    (["--kind", "kalmann"], "--kind: expected one of model, kalman, pid, rst, lqr"),
    (["--rls", "--na", "2"], "--rls: give the ARX orders --na and --nb"),
    (["--rls", "--na", "2", "--nb", "2", "--lam", "1.5"], "forgetting factor"),
])
def test_cli_refuses_bad_requests_in_one_line(tmp_path, capsys, args, phrase):
    save_controller(PID(1.0, dt=0.01), tmp_path / "p.json")
    target = [] if "--rls" in args else [str(tmp_path / "p.json")]
    assert main(["export", "c", *target, *args, "--out", str(tmp_path / "o")]) != 0
    err = capsys.readouterr().err
    assert err.startswith(("error: ArgumentError: ", "error: DataError: ")) and phrase in err
    assert err.count("\n") == 1
