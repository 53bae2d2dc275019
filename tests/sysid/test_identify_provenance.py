"""Provenance in the library: gripkit.io.load records the file's name and SHA-256 in the
trajectory's meta, and sysid.identify hands them to the model it returns (one record: name and
hash; several: the names joined, no hash; data built in memory: none)."""

import hashlib

import numpy as np
import pytest

from gripkit import Trajectory
from gripkit.io import load, save
from gripkit.sysid import identify, load_model


def _record(seed: int, n: int = 600) -> Trajectory:
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = np.zeros(n)
    for t in range(2, n):
        y[t] = 1.2 * y[t - 1] - 0.5 * y[t - 2] + 0.4 * u[t - 1]
    y += 0.01 * rng.standard_normal(n)
    return Trajectory.uniform(dt=0.01, u=u, y=y, units={"u": "V", "y": "N"})


@pytest.fixture
def files(tmp_path):
    paths = [tmp_path / "run1.csv", tmp_path / "run2.parquet"]
    for i, p in enumerate(paths):
        save(_record(i), p)
    return paths


def test_load_records_name_and_sha256(files):
    for p in files:
        tr = load(p)
        assert tr.meta["source"] == p.name
        assert tr.meta["sha256"] == hashlib.sha256(p.read_bytes()).hexdigest()


def test_identify_sets_the_model_provenance(files, tmp_path):
    digest = hashlib.sha256(files[0].read_bytes()).hexdigest()
    tr = load(files[0])
    ss = identify(tr, "ss", input="u", output="y", order=2)
    assert (ss.data_file, ss.data_hash) == ("run1.csv", digest)
    arx = identify(tr, "arx", input="u", output="y", na=2, nb=1, nk=1)
    assert (arx.data_file, arx.data_hash) == ("run1.csv", digest)
    ss.save(tmp_path / "m.json")
    back = load_model(tmp_path / "m.json")
    assert (back.data_file, back.data_hash) == ("run1.csv", digest)


def test_several_records_join_the_names_without_a_hash(files):
    m = identify([load(p) for p in files], "ss", input="u", output="y", order=2, refine=False)
    assert (m.data_file, m.data_hash) == ("run1.csv, run2.parquet", None)


def test_memory_data_leave_the_provenance_empty():
    m = identify(_record(3), "ss", input="u", output="y", order=2, refine=False)
    assert (m.data_file, m.data_hash) == (None, None)
