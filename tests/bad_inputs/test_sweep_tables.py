"""Parameter tables of a sweep (issue 22, items 3 and 11): a table is read only from the sweep
file's folder or below it (an absolute path, a ``..`` or a link out of it is refused before
anything is read, so nothing of another file reaches a message), and crossed tables are counted
from their lengths and refused by the memory estimate before their product is allocated."""

from __future__ import annotations

import os

import numpy as np
import pytest

from gripkit.batch import SweepSpec, budget
from gripkit.errors import ConfigError
from corpus import assert_user_error

MSD = ('[sweep]\nscenario = "step-response"\nmodel = "mass-spring-damper"\n'
       '[scenario]\nduration = 2.0\nfs = 50.0\n[parameters]\n')
SECRET = "TOPSECRET_first_line,k\n1,2\n"


@pytest.fixture
def folders(tmp_path):
    """TMP/run (the sweep file's folder, with tables/objects.csv) and TMP/private/secret.csv."""
    run, private = tmp_path / "run", tmp_path / "private"
    (run / "tables").mkdir(parents=True)
    private.mkdir()
    (private / "secret.csv").write_text(SECRET)
    (run / "tables" / "objects.csv").write_text("k\n1.0\n2.0\n3.0\n")
    return run, private


def _sweep(cli, run, table):
    path = run / "s.toml"
    path.write_text(MSD + f'k = {{ table = "{table}" }}\n')
    return cli("sweep", path, "--out", run / "out", "--backend", "in-process")


@pytest.mark.parametrize("name, phrase", [
    ("absolute", "is an absolute path; tables are read only from the sweep file's folder"),
    ("dotdot", "leaves that folder through '..'; tables are read only from"),
    ("link", "is a link that leads out of that folder; tables are read only from"),
    ("linked folder", "is a link that leads out of that folder"),
])
def test_table_outside_the_sweep_folder_is_refused(cli, folders, name, phrase):
    run, private = folders
    table = {"absolute": str(private / "secret.csv"), "dotdot": "../private/secret.csv",
             "link": "tables/innocent.csv", "linked folder": "elsewhere/secret.csv"}[name]
    os.symlink(private / "secret.csv", run / "tables" / "innocent.csv")
    os.symlink(private, run / "elsewhere")
    res = _sweep(cli, run, table)
    assert_user_error(res, "ConfigError", f"[parameters] k: table {table!r} {phrase}")
    assert repr(str(run.resolve())) in res.err and "copy the table into that folder" in res.err
    assert "TOPSECRET" not in res.err + res.out  # nothing of the file is echoed
    assert not (run / "out").exists()


def test_tables_inside_the_folder_are_read(cli, folders):
    """Below the folder, through a '..' that stays inside, and through a link that stays inside."""
    run, _ = folders
    os.symlink(run / "tables" / "objects.csv", run / "same.csv")
    for table in ("tables/objects.csv", "tables/../tables/objects.csv", "same.csv"):
        spec = SweepSpec.from_toml(_write(run, table))
        np.testing.assert_array_equal(spec.jobs()["k"], [1.0, 2.0, 3.0])
    res = cli("sweep", _write(run, "tables/objects.csv"), "--out", run / "out",
              "--backend", "in-process", "--json")
    assert res.code == 0, res.err
    assert res.json()["n_jobs"] == 3


def _write(run, table):
    path = run / "s.toml"
    path.write_text(MSD + f'k = {{ table = "{table}" }}\n')
    return path


def test_api_dict_tables_are_read_from_base_dir(folders):
    run, private = folders
    d = {"sweep": {"scenario": "step-response"},
         "parameters": {"k": {"table": str(private / "secret.csv")}}}
    with pytest.raises(ConfigError, match="is an absolute path") as err:
        SweepSpec.from_dict(d, base_dir=str(run))
    assert "TOPSECRET" not in str(err.value)


# --- item 11: crossed tables ------------------------------------------------------------------
@pytest.fixture
def two_long_tables(tmp_path):
    """Two files of 1e5 rows each: crossed, 1e10 jobs."""
    n = 100_000
    np.savetxt(tmp_path / "ks.csv", np.linspace(1.0, 2.0, n), header="k", comments="")
    np.savetxt(tmp_path / "bs.csv", np.linspace(0.1, 0.2, n), header="b", comments="")
    path = tmp_path / "s.toml"
    path.write_text(MSD + 'k = { table = "ks.csv" }\nb = { table = "bs.csv" }\n')
    return path


def test_crossed_tables_of_1e5_rows_are_refused_before_allocation(cli, two_long_tables, tmp_path,
                                                                  monkeypatch):
    """The estimate is that of two grids of 1e5 points (tests/bad_inputs/test_sweeps.py): 1e10 jobs
    × (job_id, 2 parameters, 5 step metrics, error) × 8 B × 3 copies = 2.16 TB."""
    monkeypatch.setattr(budget, "available_memory", lambda: 8 * 10**9)
    spec = SweepSpec.from_toml(two_long_tables)  # reads 2 × 1e5 rows, crosses nothing
    assert spec.n_jobs() == 10**10
    res = cli("sweep", two_long_tables, "--out", tmp_path / "out", "--backend", "in-process")
    assert_user_error(res, "ConfigError", "10,000,000,000 jobs need an estimated 2.16 TB")
    assert "above the limit of 4 GB (half the 8 GB available)" in res.err
    assert not (tmp_path / "out").exists()


def test_api_job_table_refused_with_its_estimate(two_long_tables):
    """spec.jobs() on its own: 1e10 jobs × (job_id, 2 parameters, 1) × 8 B × 3 = 960 GB."""
    spec = SweepSpec.from_toml(two_long_tables)
    phrase = (r"sweep 'sweep': the job table: 10,000,000,000 jobs need an estimated 960 GB of "
              r"memory .* above the limit of 1 GB given")
    with pytest.raises(ConfigError, match=phrase):
        spec.jobs(memory_limit="1 GB")
