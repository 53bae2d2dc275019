"""TOML model descriptions and ``gripkit simulate``."""

import json
import warnings
from pathlib import Path

import numpy as np
import pytest

from gripkit.cli import main
from gripkit.description import input_signal, load_description, simulate_description
from gripkit.errors import ConfigError
from gripkit.io import load
from gripkit.models import MassSpringDamper

MSD = (Path(__file__).resolve().parents[1] / "examples"
       / "mass_spring_damper_step.toml").read_text()


def test_description_simulates_like_the_python_api(tmp_path):
    p = tmp_path / "msd.toml"
    p.write_text(MSD)
    tr = simulate_description(p)
    u = np.where(np.arange(500) / 1000 < 0.1, 0.0, 0.1)
    ref = MassSpringDamper(m=2e-3, b=0.05, k=20.0).simulate(u, dt=1e-3)
    np.testing.assert_array_equal(tr["x"], ref["x"])
    assert tr.unit("x") == "m" and tr.n == 500


def test_input_kinds():
    t = np.arange(10) / 10.0
    np.testing.assert_allclose(input_signal({"kind": "ramp", "start": 0, "end": 1, "t0": 0.2,
                                             "t1": 0.6}, t, "x"),
                               np.clip((t - 0.2) / 0.4, 0, 1))
    np.testing.assert_allclose(input_signal({"kind": "sine", "amplitude": 2, "frequency": 1,
                                             "offset": 1}, t, "x"),
                               1 + 2 * np.sin(2 * np.pi * t))
    s = input_signal({"kind": "steps", "levels": [1, 2, 3], "durations": [0.3, 0.3, 0.3]}, t, "x")
    np.testing.assert_array_equal(s, [1, 1, 1, 2, 2, 2, 3, 3, 3, 3])
    with pytest.raises(ConfigError, match="unknown keys \\['amp'\\]"):
        input_signal({"kind": "sine", "amp": 1, "frequency": 1}, t, "x")
    with pytest.raises(ConfigError, match="kind = 'square'"):
        input_signal({"kind": "square"}, t, "x")


@pytest.mark.parametrize("edit, message", [
    (("[simulation]", "[simulations]"), "unknown sections"),
    (('k = "20 N/m"', 'k = "20 N/m"\nq = 1'), "not parameters of mass-spring-damper"),
    (("[inputs.F]", "[inputs.G]"), "misses \\['F'\\]"),
    (('type = "mass-spring-damper"', 'type = "piano"'), "type = 'piano' is unknown"),
    (("fs = 1000", "fs = 1000\ndt = 0.001"), "exactly one of fs"),
    (('k = "20 N/m"', 'k = "20 kg"'), "expected a value in 'N/m'"),
])
def test_errors_name_the_problem(tmp_path, edit, message):
    p = tmp_path / "bad.toml"
    p.write_text(MSD.replace(*edit))
    with pytest.raises(ConfigError, match=message):
        load_description(p)


def test_cli_simulate_writes_parquet(tmp_path, capsys):
    """``gripkit simulate`` on the Fig. 13 contact (001_0b92a7da96e7aa46.txt §V-B): a 72.5 N/m part
    whose face is where tip C is at 44 V."""
    p = tmp_path / "fig13.toml"
    p.write_text("""
[model]
type = "tsfm-finger-contact"
zoo = "tsfm-left"
[parameters]
x_w = "62.37 um"
k_e = "72.5 N/m"
[simulation]
fs = 20000
duration = 10.0
[inputs.U]
kind = "sine"
amplitude = 25.0
offset = 25.0
frequency = 0.1
phase_deg = -90.0
""")
    out = tmp_path / "fig13.parquet"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        code = main(["simulate", str(p), "--out", str(out), "--json"])
    assert code == 0
    res = json.loads(capsys.readouterr().out)
    assert res["samples"] == 200000 and res["out"] == str(out)
    # the seed's contradiction, reported
    assert any("sensor-natural-frequency" in w for w in res["warnings"])
    tr = load(out)
    on = np.flatnonzero(tr["contact"] > 0.5)
    assert abs(tr["U"][on[0]] - 44.0) < 0.1   # Fig. 13: contact at U = 44 V
    assert tr.unit("F_g") == "N"
