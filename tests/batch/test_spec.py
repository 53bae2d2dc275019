"""Sweep specifications: grids cross, distributions draw, units convert, errors are clear."""

import numpy as np
import pytest

from gripkit.batch import SweepSpec
from gripkit.errors import ConfigError


def spec(params, samples=1, seed=0):
    return SweepSpec.from_dict({"sweep": {"scenario": "step-response", "samples": samples,
                                          "seed": seed},
                                "parameters": params})


def test_grids_cross_and_samples_repeat():
    jobs = spec({"k": {"grid": [1.0, 2.0, 3.0]}, "m": {"values": [10.0, 20.0]}}, samples=4).jobs()
    assert len(jobs["job_id"]) == 3 * 2 * 4
    pairs = set(zip(jobs["k"], jobs["m"]))
    assert pairs == {(k, m) for k in (1.0, 2.0, 3.0) for m in (10.0, 20.0)}


def test_distributions_respect_their_laws():
    jobs = spec({"a": {"uniform": [1.0, 2.0]}, "b": {"loguniform": ["1 mg", "100 mg"]},
                 "c": {"normal": [5.0, 0.5], "clip": [4.0, 6.0]}}, samples=20000, seed=3).jobs()
    assert 1.0 <= jobs["a"].min() and jobs["a"].max() <= 2.0
    assert jobs["a"].mean() == pytest.approx(1.5, abs=0.01)
    logb = np.log10(jobs["b"])  # mg -> kg: log-uniform on [-6, -4]
    assert logb.min() >= -6 and logb.max() <= -4 and logb.mean() == pytest.approx(-5.0, abs=0.02)
    assert jobs["c"].min() >= 4.0 and jobs["c"].max() <= 6.0
    assert jobs["c"].std() == pytest.approx(0.5, rel=0.05)


def test_same_seed_same_jobs():
    a = spec({"x": {"uniform": [0, 1]}}, samples=5, seed=7).jobs()
    b = spec({"x": {"uniform": [0, 1]}}, samples=5, seed=7).jobs()
    np.testing.assert_array_equal(a["x"], b["x"])


def test_table_rows(tmp_path):
    (tmp_path / "objects.csv").write_text("k0,gap\n520,1e-5\n1043,2e-5\n")
    s = SweepSpec.from_dict({"sweep": {"scenario": "step-response"},
                             "parameters": {"k0": {"table": "objects.csv"},
                                            "gap": {"table": "objects.csv"},
                                            "k": {"grid": [1.0, 2.0]}}}, base_dir=str(tmp_path))
    jobs = s.jobs()
    assert len(jobs["job_id"]) == 4
    assert set(zip(jobs["k0"], jobs["gap"])) == {(520.0, 1e-5), (1043.0, 2e-5)}


@pytest.mark.parametrize("params, match", [
    ({"k": {"grid": []}}, "empty grid"),
    ({"k": {"uniform": [2, 1]}}, "a < b"),
    ({"k": {"bogus": 1}}, "exactly one of"),
    ({"k": {"loguniform": [0, 1]}}, "positive"),
    ({"k": {"grid": ["3 furlongz"]}}, "cannot read"),
])
def test_bad_specs(params, match):
    with pytest.raises(ConfigError, match=match):
        spec(params)


def test_toml_roundtrip(tmp_path):
    p = tmp_path / "s.toml"
    p.write_text('[sweep]\nscenario = "step-response"\nmodel = "mass-spring-damper"\nsamples = 2\n'
                 '[parameters]\nk = { grid = [1.0, 4.0] }\n[scenario]\nduration = 0.5\nfs = 1000\n')
    s = SweepSpec.from_toml(p)
    assert s.model == "mass-spring-damper" and s.settings["duration"] == 0.5
    assert len(s.jobs()["job_id"]) == 4
    with pytest.raises(ConfigError, match="not valid TOML"):
        (tmp_path / "bad.toml").write_text("[sweep\n")
        SweepSpec.from_toml(tmp_path / "bad.toml")


def test_job_order_is_the_nested_loop(tmp_path):
    """job = ((grid point) × table row) × sample, the first grid varying slowest: the table built
    by index arithmetic equals the nested loops written out."""
    import itertools

    (tmp_path / "rows.csv").write_text("r\n10\n20\n30\n")
    s = SweepSpec.from_dict({"sweep": {"scenario": "step-response", "samples": 2},
                             "parameters": {"a": {"grid": [1.0, 2.0]},
                                            "t": {"table": "rows.csv", "column": "r"},
                                            "b": {"linspace": [0.0, 1.0, 3]}}},
                                            base_dir=str(tmp_path))
    jobs = s.jobs()
    loops = [(a, b, t) for a, b in itertools.product([1.0, 2.0],
                                                     [0.0, 0.5, 1.0]) for t in (10.0, 20.0, 30.0)
             for _ in range(2)]
    assert s.n_jobs() == len(loops) == 36
    assert list(zip(jobs["a"], jobs["b"], jobs["t"])) == loops
    np.testing.assert_array_equal(jobs["job_id"], np.arange(36))


@pytest.mark.parametrize("name", ["sweep_mass_spring_damper.toml", "sweep_tsfm_robustness.toml"])
def test_example_sweep_files_pass_the_checks(name):
    """The shipped sweep files use registered names only and pass every check made before a run
    (names, units, settings, metrics), without --allow-code."""
    from pathlib import Path

    from gripkit.batch.scenarios import prepare

    spec = SweepSpec.from_toml(Path(__file__).resolve().parents[2] / "examples" / name)
    prep = prepare(spec)
    assert set(spec.parameters) <= set(prep.interface.parameters)
    assert set(spec.metrics) <= set(prep.interface.metrics)
