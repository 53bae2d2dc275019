"""Bad input to sweeps (issue 11, section 2 items 1-5), on the command line and in Python: each
case asserts the error class and a key phrase of the one-line message, or the warning.

1. units of the wrong dimension; 2. unknown names and invalid settings, and jobs that fail at run
time (exit code 3, counted); 3. job count and memory estimated up front; 4. code named in a sweep
file needs --allow-code; 5. damaged chunks on resume."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from gripkit.batch import SweepSpec, budget, sweep
from gripkit.errors import ConfigError, GripkitWarning
from corpus import assert_user_error, assert_warned


MSD = '[sweep]\nscenario = "step-response"\nmodel = "mass-spring-damper"\n'
SCENARIO = '\n[scenario]\nduration = 2.0\nfs = 50.0\n'

# a scenario module named as "sweepscen:twice" (needs --allow-code): fails for x == 3
MODULE = '''
def twice(model, params, settings):
    x = params["x"]
    if (x == 3.0).any():
        raise ValueError("x = 3 is not allowed here")
    return {"y": 2.0 * x}
'''
OWN = ('[sweep]\nscenario = "sweepscen:twice"\nchunk_size = 2\n[parameters]\nx = { grid = [1.0, '
       '2.0, 4.0, 5.0] }\n')


@pytest.fixture
def write(tmp_path):
    def w(text: str, name: str = "s.toml"):
        p = tmp_path / name
        p.write_text(text)
        return p

    return w


@pytest.fixture
def sweep_cli(cli, tmp_path):
    """``gripkit sweep FILE --out TMP/out --backend in-process ARGS``."""
    return lambda path, *args: cli("sweep", path, "--out", tmp_path / "out", "--backend",
                                   "in-process", *args)


@pytest.fixture
def own_module(tmp_path, monkeypatch):
    d = tmp_path / "mod"
    d.mkdir()
    (d / "sweepscen.py").write_text(MODULE)
    monkeypatch.syspath_prepend(str(d))


@pytest.fixture
def eight_gb(monkeypatch):
    """The machine has 8 GB available (so the default limit, half of it, is 4 GB)."""
    monkeypatch.setattr(budget, "available_memory", lambda: 8 * 10**9)


# --- 1. units of the wrong dimension ----------------------------------------------------------
def test_stiffness_in_furlongs(sweep_cli, write):
    res = sweep_cli(write(MSD + '[parameters]\nk = { grid = ["3 furlong"] }' + SCENARIO))
    assert_user_error(res, "ConfigError", "[parameters] k: '3 furlong' is a quantity in m, "
                                          "expected one in N/m")
    assert not (write("", "x").parent / "out" / "chunks").exists()  # refused before any job ran


def test_mass_range_in_seconds(sweep_cli, write):
    res = sweep_cli(write(MSD + '[parameters]\nm = { uniform = ["1 s", "2 s"] }' + SCENARIO))
    assert_user_error(res, "ConfigError", "[parameters] m: '1 s' is a quantity in s, "
                                          "expected one in kg")


def test_setting_of_the_wrong_dimension(sweep_cli, write):
    res = sweep_cli(write(MSD + '[parameters]\nk = { grid = [1.0] '
                                '}\n[scenario]\nduration = "2 m"\n'))
    assert_user_error(res, "ConfigError", "[scenario] duration: '2 m' is a quantity in m, "
                                          "expected one in s")


def test_grasp_force_in_micrometres(sweep_cli, write):
    res = sweep_cli(write('[sweep]\nscenario = "tsfm-grasp"\nmodel = "tsfm-gripper"\n[parameters]\n'
                          'k_e = { grid = ["100 N/m"] }\n[scenario]\ngrip_force = "200 um"\n'))
    assert_user_error(res, "ConfigError", "[scenario] grip_force: '200 um' is a quantity in m, "
                                          "expected one in N")


def test_api_unit_of_the_wrong_dimension():
    d = ({"sweep": {"scenario": "ftg100-grasp"},
          "parameters": {"k0": {"linspace": ["1 N", "2 N", 3]}}})
    with pytest.raises(ConfigError, match=r"\[parameters\] k0: '1 N' is a quantity in N, "
                                          r"expected one in N/m"):
        sweep(d, backend="in-process", progress=False)


# --- 2. unknown names, invalid settings, jobs failing at run time ----------------------------
def test_unknown_parameter_name(sweep_cli, write):
    res = sweep_cli(write(MSD + '[parameters]\nkk = { grid = [1.0, 2.0] }' + SCENARIO))
    assert_user_error(res, "ConfigError", "['kk'] are not parameters of scenario 'step-response'")
    assert "k [N/m]" in res.err  # the hint lists the parameters with their units


def test_unknown_scenario_setting(sweep_cli, write):
    res = sweep_cli(write(MSD + '[parameters]\nk = { grid = [1.0] '
                                '}\n[scenario]\ndurration = 2.0\n'))
    assert_user_error(res, "ConfigError", "[scenario] (step-response): unknown keys ['durration']")


def test_negative_duration(sweep_cli, write):
    res = sweep_cli(write(MSD + '[parameters]\nk = { grid = [1.0] '
                                '}\n[scenario]\nduration = -1.0\n'))
    assert_user_error(res, "ConfigError", "[scenario] duration: expected a value > 0 s, found -1.0")


def test_zero_sampling_rate(sweep_cli, write):
    res = sweep_cli(write(MSD + '[parameters]\nk = { grid = [1.0] }\n[scenario]\nfs = 0\n'))
    assert_user_error(res, "ConfigError", "[scenario] fs: expected a value > 0 Hz, found 0")


def test_too_short_a_record(sweep_cli, write):
    res = sweep_cli(write(MSD + '[parameters]\nk = { grid = [1.0] }\n[scenario]\nduration = "1 '
                                'ms"\nfs = 100\n'))
    assert_user_error(res, "ConfigError", "gives 0 samples, expected at least 2")


def test_samples_as_text(sweep_cli, write):
    res = sweep_cli(write(MSD + 'samples = "ten"\n[parameters]\nk = { grid = [1.0] }\n'))
    assert_user_error(res, "ConfigError", "[sweep] samples: expected an integer >= 1, found 'ten'")


def test_fractional_linspace_count(sweep_cli, write):
    res = sweep_cli(write(MSD + '[parameters]\nk = { linspace = [1.0, 2.0, 2.5] }\n'))
    assert_user_error(res, "ConfigError", "[parameters] k (linspace count): expected an integer "
                                          ">= 1, found 2.5")


def test_misspelt_table(sweep_cli, write):
    res = sweep_cli(write(MSD + '[parameter]\nk = { grid = [1.0] }\n'))
    assert_user_error(res, "ConfigError", "unknown tables ['parameter']")


def test_metric_the_scenario_does_not_compute(sweep_cli, write):
    res = sweep_cli(write(MSD + '[parameters]\nk = { grid = [1.0] }\n[metrics]\nrecord '
                                '= ["overshot"]\n'))
    assert_user_error(res, "ConfigError", "does not compute ['overshot']")


def test_api_not_a_number():
    with pytest.raises(ConfigError, match=r"\[parameters\] k: expected a finite number"):
        SweepSpec.from_dict({"sweep": {"scenario": "step-response"},
                             "parameters": {"k": {"grid": [float("nan")]}}})
    with pytest.raises(ConfigError, match=r"\[parameters\] k: unknown keys \['unit'\] for a grid"):
        SweepSpec.from_dict({"sweep": {"scenario": "step-response"},
                             "parameters": {"k": {"grid": [1.0], "unit": "mN/m"}}})


def test_failed_jobs_give_a_non_zero_exit_and_are_counted(sweep_cli, write, own_module):
    res = sweep_cli(write(OWN.replace("5.0", "3.0")), "--allow-code")
    assert res.code == 3 and "Traceback" not in res.err
    assert "4 jobs, 1 of them FAILED" in res.out
    assert (len(res.error_lines) == 1
            and "1 of 4 jobs failed (first: job 3: ValueError: x = 3" in res.error_lines[0])


def test_failed_jobs_in_json(sweep_cli, write, own_module):
    res = sweep_cli(write(OWN.replace("5.0", "3.0")), "--allow-code", "--json")
    assert res.code == 3
    assert res.json()["n_failed"] == 1 and res.json()["failures"][0][0] == 3


# --- 3. job count and memory, estimated up front ---------------------------------------------
def test_a_billion_samples(sweep_cli, write, eight_gb):
    res = sweep_cli(write(MSD + 'samples = 1000000000\n[parameters]\nk = { '
                                'uniform = [1.0, 2.0] }' + SCENARIO))
    assert_user_error(res, "ConfigError", "1,000,000,000 jobs need an estimated 192 GB of memory")
    assert "above the limit of 4 GB (half the 8 GB available)" in res.err


def test_two_grids_of_1e5_points(sweep_cli, write, eight_gb):
    res = sweep_cli(write(MSD + '[parameters]\nk = { linspace = [1.0, 2.0, 100000] }\n'
                                'b = { linspace = [0.1, 0.2, 100000] }' + SCENARIO))
    assert_user_error(res, "ConfigError", "10,000,000,000 jobs need an estimated 2.16 TB")
    assert "above the limit of 4 GB" in res.err


def test_no_machine_holds_1e15_jobs(sweep_cli, write):
    """The default limit, from the memory this machine has now."""
    grid = "{ linspace = [1.0, 2.0, 100000] }"
    res = sweep_cli(write(MSD + f'[parameters]\nk = {grid}\nb = {grid}\nm = {grid}' + SCENARIO))
    assert_user_error(res, "ConfigError", "1,000,000,000,000,000 jobs need an estimated")
    assert "available)" in res.err


def test_a_billion_time_samples_per_job(sweep_cli, write, eight_gb):
    res = sweep_cli(write(MSD + '[parameters]\nk = { grid = [1.0] }\n[scenario]\nduration = '
                                '50000.0\nfs = 20000\n'))
    assert_user_error(res, "ConfigError", "1 job needs an estimated 48 GB")
    assert "1 task of 1 job in flight, 48 GB each" in res.err


def test_explicit_memory_limit(sweep_cli, write):
    res = sweep_cli(write(MSD + 'samples = 1000\n[parameters]\nk = { '
                                'uniform = [1.0, 2.0] }' + SCENARIO),
                    "--memory-limit", "10 kB")
    assert_user_error(res, "ConfigError", "above the limit of 10 kB given")


def test_memory_limit_not_a_size(sweep_cli, write):
    res = sweep_cli(write(MSD + '[parameters]\nk = '
                                '{ grid = [1.0] }' + SCENARIO), "--memory-limit", "lots")
    assert_user_error(res, "ConfigError", "memory_limit: expected a size such as '8 GB'")


def test_api_memory_limit():
    d = {"sweep": {"scenario": "step-response", "model": "mass-spring-damper", "samples": 10**6},
         "parameters": {"k": {"uniform": [1.0, 2.0]}}}
    with pytest.raises(ConfigError, match="1,000,000 jobs need an estimated 192 MB of memory"):
        sweep(d, backend="in-process", progress=False, memory_limit="1 MB")


# --- 4. code named in a sweep file -----------------------------------------------------------
def test_model_names_code(sweep_cli, write):
    res = sweep_cli(write('[sweep]\nscenario = "step-response"\nmodel = '
                          '"os:getpid"\n[parameters]\nk = { grid = [1.0] }\n'))
    assert_user_error(res, "ConfigError", "model 'os:getpid' names Python code to import; "
                                          "without --allow-code")


def test_scenario_names_code(sweep_cli, write):
    res = sweep_cli(write('[sweep]\nscenario = "os:getpid"\n[parameters]\nk = { grid = [1.0] }\n'))
    assert_user_error(res, "ConfigError", "scenario 'os:getpid' names Python code to import")


def test_a_file_cannot_allow_itself(sweep_cli, write):
    res = sweep_cli(write('[sweep]\nscenario = "os:getpid"\nallow_code = true\n[parameters]\nk = { '
                          'grid = [1.0] }\n'))
    assert_user_error(res, "ConfigError", "cannot be allowed from inside a sweep file: "
                                          "pass --allow-code")


def test_api_needs_the_keyword(own_module):
    d = {"sweep": {"scenario": "sweepscen:twice"}, "parameters": {"x": {"grid": [1.0, 2.0]}}}
    with pytest.raises(ConfigError, match="names Python code to import"):
        sweep(d, backend="in-process", progress=False)
    res = sweep(d, backend="in-process", progress=False, allow_code=True)
    np.testing.assert_array_equal(res["y"], [2.0, 4.0])


# --- 5. damaged chunks on resume -------------------------------------------------------------
@pytest.fixture
def finished(sweep_cli, write, own_module, tmp_path):
    """A finished sweep of 4 jobs in 2 chunks in TMP/out; returns its file."""
    path = write(OWN)
    assert sweep_cli(path, "--allow-code").code == 0
    return path


def test_truncated_chunk_is_recomputed_with_a_warning(sweep_cli, finished, tmp_path):
    c = tmp_path / "out" / "chunks" / "chunk-000001.parquet"
    c.write_bytes(c.read_bytes()[:40])
    res = sweep_cli(finished, "--allow-code", "--resume", "--json")
    assert res.code == 0, res.err
    assert_warned(res, "chunk 1 (chunk-000001.parquet) is unreadable")
    assert_warned(res, "its jobs 2..3 are computed again")


def test_chunk_copied_over_another_is_recomputed(sweep_cli, finished, tmp_path):
    chunks = tmp_path / "out" / "chunks"
    shutil.copyfile(chunks / "chunk-000000.parquet", chunks / "chunk-000001.parquet")
    res = sweep_cli(finished, "--allow-code", "--resume")
    assert res.code == 0, res.err
    assert_warned(res, "chunk 1 (chunk-000001.parquet) holds job ids 0..1, expected 2..3")
    assert "4 jobs, none failed" in res.out and "1 computed" in res.out


def test_api_resume_warns(finished, tmp_path):
    shutil.copyfile(tmp_path / "out" / "chunks" / "chunk-000000.parquet",
                    tmp_path / "out" / "chunks" / "chunk-000001.parquet")
    with pytest.warns(GripkitWarning, match="holds job ids 0..1, expected 2..3"):
        res = sweep(SweepSpec.from_toml(finished), backend="in-process", out=tmp_path / "out",
                    resume=True,
                    progress=False, allow_code=True)
    np.testing.assert_array_equal(res["y"], [2.0, 4.0, 8.0, 10.0])


def test_unreadable_manifest(sweep_cli, finished, tmp_path):
    (tmp_path / "out" / "manifest.json").write_text("{not json")
    res = sweep_cli(finished, "--allow-code", "--resume")
    assert_user_error(res, "ConfigError", "manifest.json is unreadable")


def test_backend_and_workers_checked_before_the_output_folder(cli, write, tmp_path):
    path = write(MSD + '[parameters]\nk = { grid = [1.0] }' + SCENARIO)
    assert_user_error(cli("sweep", path, "--out", tmp_path / "o", "--backend", "banana"),
                      "ConfigError",
                      "backend: expected 'auto', 'in-process', 'process' or 'dask', found 'banana'")
    assert_user_error(cli("sweep", path, "--out", tmp_path / "o", "--workers", "0"), "ConfigError",
                      "workers: expected a positive number, found 0")
    assert not (tmp_path / "o").exists()


def test_controller_settings_checked_before_the_run(sweep_cli, write):
    """ftg100-grasp builds its controller once up front: its own checks refuse the sweep."""
    base = '[sweep]\nscenario = "ftg100-grasp"\n[parameters]\nk0 = { grid = [520.0] }\n[scenario]\n'
    assert_user_error(sweep_cli(write(base + 'v_min = 250.0\n')), "ConfigError",
                      "expected 0 <= v_min < v_max")
    assert_user_error(sweep_cli(write(base + 'band = 1.0\n')), "ConfigError",
                      "[scenario] band: expected a value < 1")


def test_api_spec_built_directly_is_checked_too():
    with pytest.raises(ConfigError, match=r"\[sweep\] samples: expected an integer >= 1, found 0"):
        SweepSpec(scenario="step-response", parameters={"k": {"grid": [1.0]}}, samples=0)
    with pytest.raises(ConfigError, match=r"\[metrics\] record: expected a non-empty list "
                                          r"of metric names"):
        SweepSpec(scenario="step-response", parameters={}, metrics="peak")


def test_values_outside_the_parameter_bounds(sweep_cli, write):
    """k >= 0 (the mass-spring-damper's bound): a normal draw that goes negative is refused with
    the count, instead of failing those jobs one by one."""
    res = sweep_cli(write(MSD + 'samples = 200\n[parameters]\nk = { '
                                'normal = [1.0, 1.0] }' + SCENARIO))
    assert_user_error(res, "ConfigError", "[parameters] k: ")
    assert ("of 200 jobs have values outside its bounds [0, inf] N/m" in res.err
            and "clip" in res.err)
    ok = sweep_cli(write(MSD + 'samples = 20\n[parameters]\nk = { normal = [1.0, 1.0], '
                               'clip = [0.1, 10] }' + SCENARIO))
    assert ok.code == 0, ok.err


# --- an executor that cannot start leaves --out untouched; a folder without results is reused -----
def test_unreachable_executor_writes_nothing_and_the_retry_runs(sweep_cli, cli, write, tmp_path,
                                                                monkeypatch,
                                                               own_module):
    import importlib

    sweep_module = importlib.import_module("gripkit.batch.sweep")

    def unreachable(*args, **kwargs):
        raise ConfigError("cannot reach the Dask scheduler at 'tcp://127.0.0.1:1'")

    path = write(OWN)
    with monkeypatch.context() as m:
        m.setattr(sweep_module, "make_executor", unreachable)
        res = cli("sweep", path, "--out", tmp_path / "out", "--backend", "dask", "--allow-code")
    assert_user_error(res, "ConfigError", "cannot reach the Dask scheduler")
    assert not (tmp_path / "out").exists()
    # a folder holding a manifest but no results (an earlier run stopped before its first chunk)
    # is reused, whatever chunk size that run had calibrated
    (tmp_path / "out" / "chunks").mkdir(parents=True)
    (tmp_path / "out" / "manifest.json").write_text('{"fingerprint": "0000", '
                                                    '"spec": {"sweep": {}}}')
    res = sweep_cli(path, "--allow-code")
    assert res.code == 0, res.err
