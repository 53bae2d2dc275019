"""Sweep output folders (issue 22, item 5): a sweep never adopts or overwrites what is not its
own. A non-empty folder without a manifest (another sweep's results, unrelated files) is refused
with what is there and left untouched; on resume each chunk is checked against the sweep's
fingerprint, its columns and types and its job ids, and a tampered or foreign chunk is computed
again with a warning. The final table holds each job exactly once, with the uninterrupted run's
numbers (y = 2 x of the scenario below)."""

from __future__ import annotations

import re
import shutil

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from gripkit.batch import SweepSpec, sweep
from gripkit.errors import ConfigError, GripkitWarning
from corpus import assert_user_error

MODULE = '''
def twice(model, params, settings):
    return {"y": 2.0 * params["x"]}
'''
GRID = [1.0, 2.0, 4.0, 5.0]


def _spec(grid=GRID) -> SweepSpec:
    sw = {"name": "folders", "scenario": "foldscen:twice", "chunk_size": 2}
    return SweepSpec.from_dict({"sweep": sw, "parameters": {"x": {"grid": list(grid)}}})


def _run(out, grid=GRID, **kw):
    return sweep(_spec(grid), backend="in-process", out=out, progress=False, allow_code=True, **kw)


@pytest.fixture(autouse=True)
def own_module(tmp_path, monkeypatch):
    d = tmp_path / "mod"
    d.mkdir()
    (d / "foldscen.py").write_text(MODULE)
    monkeypatch.syspath_prepend(str(d))


def _snapshot(folder):
    return {p.relative_to(folder): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def _each_job_once(res, grid=GRID):
    np.testing.assert_array_equal(res["job_id"], np.arange(len(grid)))
    np.testing.assert_array_equal(res["x"], grid)
    np.testing.assert_array_equal(res["y"], 2.0 * np.asarray(grid))
    assert res.n_failed == 0


# --- folders that are not this sweep's --------------------------------------------------------
def test_results_without_a_manifest_are_not_adopted(tmp_path):
    """Another sweep's results copied in without its manifest: formerly adopted (exit 0, nothing
    computed, its numbers paired with this sweep's parameters)."""
    _run(tmp_path / "other", grid=[10.0, 20.0, 30.0, 40.0])
    out = tmp_path / "out"
    shutil.copytree(tmp_path / "other", out)
    (out / "manifest.json").unlink()
    before = _snapshot(out)
    with pytest.raises(ConfigError, match="is not empty and holds no manifest.json") as err:
        _run(out)
    assert "2 entries (chunks/, jobs.parquet), 2 result chunks among them" in str(err.value)
    assert _snapshot(out) == before
    with pytest.raises(ConfigError, match="holds no manifest.json"):
        _run(out, resume=True)


def test_folder_of_unrelated_files_is_refused_on_the_command_line(tmp_path, cli):
    out = tmp_path / "out"
    out.mkdir()
    for k in range(7):
        (out / f"file{k}.csv").write_text("mine\n")
    (out / "jobs.parquet").write_text("my own jobs table\n")
    before = _snapshot(out)
    toml = tmp_path / "s.toml"
    toml.write_text('[sweep]\nscenario = "foldscen:twice"\n'
                    '[parameters]\nx = { grid = [1.0, 2.0] }\n')
    res = cli("sweep", toml, "--out", out, "--backend", "in-process", "--allow-code")
    assert_user_error(res, "ConfigError", f"output folder {str(out)!r} is not empty")
    assert "8 entries (file0.csv, file1.csv, file2.csv, file3.csv, file4.csv, ...)" in res.err
    assert "choose a new or empty --out folder" in res.err
    assert _snapshot(out) == before  # jobs.parquet is not overwritten


def test_another_sweeps_folder_with_results_is_refused(tmp_path):
    _run(tmp_path / "out", grid=[10.0, 20.0, 30.0, 40.0])
    before = _snapshot(tmp_path / "out")
    with pytest.raises(ConfigError, match="holds a different sweep"):
        _run(tmp_path / "out", resume=True)
    assert _snapshot(tmp_path / "out") == before


def test_empty_or_own_folder_is_used(tmp_path):
    """An empty folder, or one left by a run killed while it wrote its manifest (an empty chunks
    folder and the manifest's temporary file, removed), is used; then resumed."""
    (tmp_path / "out" / "chunks").mkdir(parents=True)
    (tmp_path / "out" / ".manifest.json.k2j4h.tmp").write_text('{"fingerp')
    _each_job_once(_run(tmp_path / "out"))
    listing = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert listing == ["chunks", "jobs.parquet", "manifest.json"]
    res = _run(tmp_path / "out", resume=True)
    _each_job_once(res)
    assert res.computed_chunks == 0


# --- chunks on resume -------------------------------------------------------------------------
def _drop(t):
    return t.drop_columns(["y"])


def _extra(t):
    return t.append_column("z", pa.array([0.0] * t.num_rows))


def _retype(t):
    return t.set_column(t.column_names.index("y"), "y", t["y"].cast(pa.float32()))


def _plain(t):
    """The same columns and numbers written without gripkit's metadata (a hand-made file)."""
    return t.replace_schema_metadata(None)


@pytest.mark.parametrize("change, phrase", [
    (_drop, "differs from the columns it was written with: column 'y' dropped"),
    (_extra, "differs from the columns it was written with: column 'z' added"),
    (_retype, "differs from the columns it was written with: "
              "column 'y' changed from double to float"),
    (_plain, "carries no sweep fingerprint"),
])
def test_tampered_chunk_is_recomputed(tmp_path, change, phrase):
    out = tmp_path / "out"
    _run(out)
    chunk = out / "chunks" / "chunk-000001.parquet"
    table = pq.read_table(chunk)
    if change is _plain:
        table = table.set_column(table.column_names.index("y"), "y", pa.array([-1.0, -1.0]))
    pq.write_table(change(table), chunk)
    with pytest.warns(GripkitWarning, match=re.escape(f"chunk 1 (chunk-000001.parquet) {phrase}")):
        res = _run(out, resume=True)
    assert res.computed_chunks == 1
    _each_job_once(res)
    assert (out / "chunks" / "chunk-000001.parquet.bad").exists()


def test_chunk_copied_from_another_sweep_is_recomputed(tmp_path):
    """Same chunk size, job ids and columns; only the fingerprint tells it is another sweep's
    (x = 6 where this sweep has 5)."""
    _run(tmp_path / "other", grid=[1.0, 2.0, 4.0, 6.0])
    out = tmp_path / "out"
    _run(out)
    name = "chunk-000001.parquet"
    shutil.copyfile(tmp_path / "other" / "chunks" / name, out / "chunks" / name)
    with pytest.warns(GripkitWarning, match="chunk 1 .* was written by another sweep"):
        res = _run(out, resume=True)
    assert res.computed_chunks == 1
    _each_job_once(res)  # y = 10 at x = 5, not the other sweep's 12


def test_chunk_with_other_metrics_than_the_rest_is_recomputed(tmp_path):
    """A sweep that records every metric the scenario returns (no [metrics]): a chunk rewritten
    with its metric renamed, metadata and all, differs from the other chunks."""
    grid = [1.0, 2.0, 4.0, 5.0, 7.0, 8.0]  # three chunks: two hold 'y'
    out = tmp_path / "out"
    _run(out, grid)
    chunk = out / "chunks" / "chunk-000000.parquet"
    table = pq.read_table(chunk)
    meta = dict(table.schema.metadata)
    meta[b"gripkit.columns"] = meta[b"gripkit.columns"].replace(b'"y"', b'"w"')
    renamed = table.rename_columns(["job_id", "w", "error"]).replace_schema_metadata(meta)
    pq.write_table(renamed, chunk)
    phrase = r"chunk 0 .* holds the metrics \['w'\], the other chunks \['y'\]"
    with pytest.warns(GripkitWarning, match=phrase):
        res = _run(out, grid, resume=True)
    _each_job_once(res, grid)
    assert "w" not in res.columns and res.computed_chunks == 1


def test_deeply_nested_manifest_is_a_clear_error(tmp_path):
    """A manifest.json nested beyond Python's recursion limit is a ConfigError naming the folder,
    not an unexpected RecursionError."""
    out = tmp_path / "out"
    _run(out)
    (out / "manifest.json").write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(ConfigError, match="manifest.json is unreadable"):
        _run(out, resume=True)
