"""The cores a sweep's pool and its backend choice count: the process's CPU affinity, lowered to
a cgroup's CPU quota (``os.cpu_count()`` counts the host's cores, also under ``taskset`` or
``docker --cpus``)."""

from __future__ import annotations

import os

import pytest

from gripkit.batch.budget import usable_cores
from gripkit.batch.executors import ProcessExecutor

pytestmark = pytest.mark.skipif(not hasattr(os, "sched_getaffinity"),
                                reason="CPU affinity and cgroup quotas (os.sched_getaffinity) "
                                       "exist on Linux only; elsewhere gripkit counts "
                                       "os.cpu_count() cores")


def _cgroup(tmp_path, v2=None, v1=None):
    if v2 is not None:
        (tmp_path / "cpu.max").write_text(v2 + "\n")
    if v1 is not None:
        (tmp_path / "cpu").mkdir()
        (tmp_path / "cpu" / "cpu.cfs_quota_us").write_text(v1[0] + "\n")
        (tmp_path / "cpu" / "cpu.cfs_period_us").write_text(v1[1] + "\n")
    return tmp_path


def test_without_a_quota_the_affinity_decides(tmp_path, monkeypatch):
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 3, 5})
    assert usable_cores(tmp_path) == 3
    assert usable_cores(_cgroup(tmp_path, v2="max 100000")) == 3


@pytest.mark.parametrize(("v2", "v1", "expected"), [
    ("200000 100000", None, 2),    # docker --cpus=2, cgroup v2
    ("150000 100000", None, 1),    # 1.5 CPUs: one whole core for a process of its own
    ("50000 100000", None, 1),     # half a CPU: still one
    (None, ("300000", "100000"), 3),  # cgroup v1
    (None, ("-1", "100000"), 8),      # v1 without a quota
    ("800000 100000", None, 8),    # a quota above the affinity: the affinity
])
def test_a_cgroup_quota_lowers_the_affinity(tmp_path, monkeypatch, v2, v1, expected):
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: set(range(8)))
    assert usable_cores(_cgroup(tmp_path, v2=v2, v1=v1)) == expected


def test_unreadable_quota_files_are_ignored(tmp_path, monkeypatch):
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: set(range(4)))
    assert usable_cores(_cgroup(tmp_path, v2="garbage")) == 4


def test_this_process_counts_its_affinity_not_the_host():
    assert 1 <= usable_cores() <= len(os.sched_getaffinity(0))


def test_a_pool_defaults_to_the_usable_cores(monkeypatch):
    import gripkit.batch.executors as executors

    monkeypatch.setattr(executors, "usable_cores", lambda: 3)
    pool = ProcessExecutor()
    assert pool.workers == 3


def test_auto_backend_counts_the_usable_cores_not_the_host(monkeypatch):
    """On 2 usable cores of a 16-core host with 1.5 cores busy, a pool of 16 runs no faster than
    one process: in-process, whatever the work."""
    import importlib

    sweep_module = importlib.import_module("gripkit.batch.sweep")  # the package exports sweep()
    monkeypatch.setattr(sweep_module, "usable_cores", lambda: 2)
    assert sweep_module._auto_backend(100.0, 16, busy=1.5)[0] == "in-process"
    assert sweep_module._auto_backend(100.0, 16, busy=0.0)[0] == "process"
