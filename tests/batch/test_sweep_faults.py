"""Sweeps under faults (issue 11): a worker killed mid-run, the coordinating process killed and
the sweep resumed, chunk files truncated or copied over one another. In every case each job's
result appears exactly once and equals the uninterrupted run's, bit for bit.

The scenario is a tiny module written to a temporary folder and named as ``"faultscen:scenario"``
(so the sweep needs ``allow_code``): x² and x³ + job_id per job, plus hooks that kill or stall the
process running a given chunk."""

import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from gripkit.batch import ProcessExecutor, SweepSpec, sweep
from gripkit.batch.store import ResultStore, collect
from gripkit.errors import DataError, GripkitWarning

SCENARIO = '''
import os, signal, time
from pathlib import Path


def scenario(model, params, settings):
    """x**2 and x**3 + job_id; hooks: at job `kill_at`, SIGKILL this process once (a marker file
    says it happened); at job `stall_at`, write this process's pid to `beacon` and sleep."""
    ids, x = params["job_id"], params["x"]
    marker = Path(settings["marker"])
    if settings.get("kill_at", -1) in ids and not marker.exists():
        marker.write_text("killed")
        os.kill(os.getpid(), signal.SIGKILL)
    if settings.get("stall_at", -1) in ids and not marker.exists():
        marker.write_text(str(os.getpid()))
        time.sleep(30.0)  # the test kills this worker long before
    return {"square": x * x, "cube": x ** 3 + ids}


scenario.uses_job_id = True
'''

N_JOBS, CHUNK = 40, 4


@pytest.fixture
def scen_dir(tmp_path, monkeypatch):
    """The scenario module on the import path of this process and of its workers."""
    d = tmp_path / "mod"
    d.mkdir()
    (d / "faultscen.py").write_text(SCENARIO)
    monkeypatch.syspath_prepend(str(d))
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(d), os.environ.get("PYTHONPATH", "")]))
    sys.modules.pop("faultscen", None)
    return d


def spec_file(tmp_path, name="faults", **settings) -> Path:
    p = tmp_path / f"{name}.toml"
    table = "\n".join(f"{k} = {v!r}".replace("'", '"') for k, v in settings.items())
    p.write_text('[sweep]\nname = "faults"\nscenario = '
                 f'"faultscen:scenario"\nchunk_size = {CHUNK}\n'
                 f'[parameters]\nx = {{ linspace = [0.0, 2.0, {N_JOBS}] }}\n'
                 f'[scenario]\nmarker = "{tmp_path / "marker"}"\n{table}\n')
    return p


def assert_same_as_uninterrupted(res, tmp_path):
    ref = sweep(SweepSpec.from_toml(spec_file(tmp_path, "reference")), backend="in-process",
                progress=False,
                allow_code=True)
    np.testing.assert_array_equal(res["job_id"], np.arange(N_JOBS))
    for col in ("x", "square", "cube"):
        np.testing.assert_array_equal(res[col], ref[col], err_msg=col)
    assert not res.failed.any() and not ref.failed.any()
    np.testing.assert_array_equal(ref["cube"], ref["x"] ** 3 + np.arange(N_JOBS))


def job_ids_on_disk(out: Path) -> list[int]:
    return sorted(np.concatenate([pq.read_table(p)["job_id"].to_numpy()
                                  for p in (out / "chunks").glob("chunk-*.parquet")]).tolist())


def test_worker_killed_mid_task_from_outside(scen_dir, tmp_path):
    """A worker SIGKILLed by someone else (the OOM killer) while it runs a chunk: the chunk is
    re-run on a new worker, every job once, results equal to an uninterrupted run."""
    spec = SweepSpec.from_toml(spec_file(tmp_path, stall_at=17))
    marker, killed = tmp_path / "marker", {}

    def killer():
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not (marker.exists()
                                                   and marker.read_text().isdigit()):
            time.sleep(0.01)
        pid = int(marker.read_text())
        os.kill(pid, signal.SIGKILL)
        killed["pid"] = pid

    th = threading.Thread(target=killer, daemon=True)
    th.start()
    with ProcessExecutor(2) as ex:
        res = sweep(spec, executor=ex, out=tmp_path / "run", progress=False, allow_code=True)
        pids_after = set(ex.pids)
    th.join(5)
    assert "pid" in killed and killed["pid"] not in pids_after and killed["pid"] != os.getpid()
    assert job_ids_on_disk(tmp_path / "run") == list(range(N_JOBS))
    assert_same_as_uninterrupted(res, tmp_path)


def test_parent_killed_then_resumed_over_damaged_chunks(scen_dir, tmp_path):
    """`gripkit sweep` SIGKILLed mid-run (in-process backend: the scenario kills the coordinating
    process itself at job 22); then one chunk on disk is truncated and another overwritten with a
    copy of a third. Resume warns about both, recomputes them and the chunks never written, and
    the table equals an uninterrupted run."""
    path = spec_file(tmp_path, kill_at=22)
    out = tmp_path / "run"
    env = ({**os.environ, "PYTHONPATH": os.pathsep.join([str(scen_dir),
                                                         str(Path(__file__).parents[2] / "src")])})
    proc = subprocess.run([sys.executable, "-c", "import sys; from gripkit.cli import main; "
                                                 "sys.exit(main())",
                           "sweep", str(path), "--out", str(out), "--backend", "in-process",
                           "--allow-code"],
                          env=env, capture_output=True, text=True, timeout=120)
    assert proc.returncode == -signal.SIGKILL, proc.stderr
    on_disk = sorted(int(p.name[6:12]) for p in (out / "chunks").glob("chunk-*.parquet"))
    # chunks 0-4 written, chunk 5 (jobs 20-23) died with the process
    assert on_disk == [0, 1, 2, 3, 4]
    c1, c2 = out / "chunks" / "chunk-000001.parquet", out / "chunks" / "chunk-000002.parquet"
    c1.write_bytes(c1.read_bytes()[: c1.stat().st_size // 2])  # truncated
    shutil.copyfile(out / "chunks" / "chunk-000000.parquet", c2)  # jobs 0-3 where 8-11 belong
    with pytest.warns(GripkitWarning) as caught:
        res = sweep(SweepSpec.from_toml(path), backend="in-process", out=out, resume=True,
                    progress=False,
                    allow_code=True)
    text = " | ".join(str(w.message) for w in caught)
    assert "chunk 1" in text and "unreadable" in text, text
    assert "chunk 2" in text and "holds job ids 0..3, expected 8..11" in text, text
    assert res.computed_chunks == N_JOBS // CHUNK - 3  # 1 and 2 again, 5..9 for the first time
    assert job_ids_on_disk(out) == list(range(N_JOBS))
    assert sorted(p.name for p in (out / "chunks").glob("*.bad")) == ["chunk-000001.parquet.bad",
                                                                      "chunk-000002.parquet.bad"]
    assert_same_as_uninterrupted(res, tmp_path)


def test_damaged_output_is_refused_when_read(scen_dir, tmp_path):
    """A finished sweep whose folder is damaged afterwards: reading it (robustness.analyse does)
    raises a DataError naming the chunk, never returns 4 duplicated and 4 missing jobs."""
    path = spec_file(tmp_path)
    out = tmp_path / "run"
    sweep(SweepSpec.from_toml(path), backend="in-process", out=out, progress=False, allow_code=True)
    assert ResultStore(out).read()["square"].shape == (N_JOBS,)
    shutil.copyfile(out / "chunks" / "chunk-000003.parquet",
                    out / "chunks" / "chunk-000007.parquet")
    with pytest.raises(DataError, match="chunk 7 holds job ids 12..15, expected 28..31"):
        ResultStore(out).read()


def test_collect_asserts_each_job_exactly_once():
    jobs = {"job_id": np.arange(6), "x": np.arange(6.0)}
    part = lambda ids: {  # noqa: E731
        "job_id": np.array(ids), "y": np.array(ids, float), "error": np.full(len(ids), None)}
    ok = collect(jobs, [part([0, 1, 2]), part([3, 4, 5])])
    np.testing.assert_array_equal(ok["y"], np.arange(6.0))
    with pytest.raises(DataError, match=r"1 jobs missing \(first \[5\]\) and 1 held more than once "
                                        r"\(first \[0\]\)"):
        collect(jobs, [part([0, 1, 2]), part([3, 4, 0])])
    with pytest.raises(DataError, match="outside 0..5"):
        collect(jobs, [part([0, 1, 2, 3, 4, 6])])
