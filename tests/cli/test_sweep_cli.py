"""`gripkit sweep`: runs a TOML sweep, resumes it, reports bad specs in one line."""

import json

from gripkit.cli import main

SPEC = """[sweep]
name = "msd"
scenario = "step-response"
model = "mass-spring-damper"
chunk_size = 2
[parameters]
k = { grid = [1.0, 4.0, 9.0] }
[scenario]
duration = 60.0
fs = 20.0
amplitude = 1.0
"""


def test_sweep_runs_and_resumes(tmp_path, capsys):
    spec = tmp_path / "s.toml"
    spec.write_text(SPEC)
    out = tmp_path / "out"
    assert main(["--quiet", "sweep", str(spec), "--backend", "in-process", "--out", str(out),
                 "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["n_jobs"] == 3 and res["n_failed"] == 0 and res["chunk_size"] == 2
    assert main(["--quiet", "sweep", str(spec), "--backend", "in-process", "--out", str(out),
                 "--resume", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["n_jobs"] == 3


def test_bad_spec_one_line(tmp_path, capsys):
    spec = tmp_path / "s.toml"
    spec.write_text(SPEC.replace('{ grid = [1.0, 4.0, 9.0] }', '{ uniform = [2, 1] }'))
    assert main(["sweep", str(spec), "--out", str(tmp_path / "o")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "ConfigError" in err[0] and "a < b" in err[0]
