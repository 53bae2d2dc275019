"""Bad inputs of the model-identification workflow (issue 13): each gets one clear line."""

import json

import numpy as np
import pytest

from gripkit import Trajectory
from gripkit.io import save
from gripkit.lti import StateSpace
from corpus import assert_user_error, assert_warned


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("bad13")
    g = (StateSpace([[0.9, 0.2], [-0.2, 0.9]], [[1.0, 0.0], [0.0, 1.0]], [[1.0, 0.0], [0.0, 1.0]],
                    dt=0.01))
    rng = np.random.default_rng(0)
    u = rng.standard_normal((3000, 2))
    y = g.simulate(u)
    save(Trajectory.uniform(dt=0.01, a=u[:, 0], b=u[:, 1], c=y[:, 0], d=y[:, 1]), d / "clean.csv")
    save(Trajectory.uniform(dt=0.01, a=u[:40, 0], b=u[:40, 1], c=y[:40, 0], d=y[:40, 1]),
         d / "short.csv")
    save(Trajectory.uniform(dt=0.01, a=u[:, 0], c=y[:, 0]), d / "only_a.csv")
    save(Trajectory.uniform(dt=0.01, a=u[:, 0], b=np.full(3000, 0.85), c=y[:, 0], d=y[:, 1]),
         d / "flat_b.csv")
    n = np.arange(64 * 60)
    v = np.cos(2 * np.pi * 8 * n / 64) + np.cos(2 * np.pi * 20 * n / 64)
    tones = (Trajectory.uniform(dt=0.01, v=v, x=np.convolve(v, [0.5, 0.3], "same"),
                                w=rng.standard_normal(n.size)))
    save(tones, d / "tones.csv")
    return d


def test_more_outputs_than_samples_allow(cli, files):
    res = cli("identify", "ss", files / "short.csv", "--input", "a,b", "--output", "c,d")
    assert_user_error(res, "DataError", "samples")


def test_order_above_data_support(cli, files):
    res = (cli("identify", "ss", files / "clean.csv", "--input", "a,b", "--output", "c,d",
               "--order", "5"))
    assert_user_error(res, "IdentificationError", "the data support at most")


def test_non_periodic_data_with_periods(cli, files):
    res = (cli("identify", "frf", files / "clean.csv", "--input", "a", "--output", "c", "--periods",
               "3"))
    assert_user_error(res, "DataError", "not periodic")


def test_frf_line_without_excitation(cli, files):
    res = (cli("identify", "frf", files / "tones.csv", "--input", "v", "--output", "x", "--nperseg",
               "64", "--json"))
    assert res.code == 0, res.err
    assert_warned(res, "no input power")
    assert_warned(res, "σ is infinite")
    std = res.json()["H_std"]
    assert std[8] is not None and std[0] is None       # inf is written as null in JSON


def test_model_file_with_wrong_schema(cli, files, tmp_path):
    p = tmp_path / "wrong.json"
    p.write_text(json.dumps({"schema": "other", "A": [[1.0]]}))
    assert_user_error(cli("compare", p, files / "clean.csv"), "ModelError",
                      "unknown schema 'other'")


def test_model_file_hash_mismatch_warns(cli, files, tmp_path):
    p = tmp_path / "m.json"
    assert cli("identify", "ss", files / "clean.csv", "--input", "a,b", "--output", "c,d",
               "--order", "2",
               "--out", p).code == 0
    doc = json.loads(p.read_text())
    doc["outputs"][0]["offset"] = 1.0
    p.write_text(json.dumps(doc))
    res = cli("compare", p, files / "clean.csv", "--json")
    assert res.code == 0, res.err
    assert_warned(res, "its content differs from what gripkit wrote")


def test_simulate_data_missing_an_input_column(cli, files, tmp_path):
    p = tmp_path / "m.json"
    assert cli("identify", "ss", files / "clean.csv", "--input", "a,b", "--output", "c,d",
               "--order", "2",
               "--out", p).code == 0
    res = cli("simulate", p, "--data", files / "only_a.csv")
    assert_user_error(res, "DataError", "input column(s) 'b' are missing")


def test_constant_input_column(cli, files):
    res = cli("identify", "ss", files / "flat_b.csv", "--input", "a,b", "--output", "c,d")
    assert_user_error(res, "UnidentifiableError", "input column 'b' is constant (0.85 for all 3000 "
                                                  "samples): a constant input cannot identify B")


def test_bad_order_text(cli, files):
    res = (cli("identify", "ss", files / "clean.csv", "--input", "a,b", "--output", "c,d",
               "--order", "4-8"))
    assert_user_error(res, "DataError", "expected N or LO:HI")
