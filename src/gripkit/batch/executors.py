"""Executors: run many independent tasks in-process, in a local process pool, or on Dask.

All three share one interface, :meth:`Executor.map_unordered`, which yields ``(key, ok, value)``
as tasks finish (``value`` is the error text when ``ok`` is False). A task that raises is reported,
never fatal. Tasks are whole chunks of jobs (≥ 0.1 s each, see :mod:`gripkit.batch.sweep`), so
per-task overhead stays small.

* :class:`InProcessExecutor` — runs tasks one after another in this process; a chunk function
  that calls a numba ``prange`` kernel uses every core.
* :class:`ProcessExecutor` (the default) — ``workers`` subprocesses started with
  ``python -m gripkit.batch.worker`` and BLAS/OpenMP/numba threads pinned to one. Workers never fork
  the caller and never re-import its script, so no ``if __name__ == "__main__"`` guard is needed.
  A worker that dies (killed, out of memory) is replaced and its task is re-run; a task that kills
  workers repeatedly is reported as failed.
* :class:`DaskExecutor` — a ``dask.distributed`` cluster given its scheduler address, or a
  ``LocalCluster`` started for the purpose (optional extra ``gripkit[dask]``).
"""

from __future__ import annotations

import abc
import collections
import contextlib
import multiprocessing
import os
import pickle
import selectors
import socket
import struct
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterable, Iterator, Sequence

import cloudpickle

from ..errors import ConfigError
from .budget import usable_cores
from .worker import PIN_ENV, read_frame, write_frame

__all__ = ["Executor", "InProcessExecutor", "ProcessExecutor", "DaskExecutor", "make_executor",
           "check_not_bootstrapping"]

Task = tuple[object, Callable, Sequence]


def check_not_bootstrapping() -> None:
    """Raise a clear error when a sweep is started while a spawned worker re-imports the user's
    script (a script without a ``__main__`` guard, run with a backend that spawns processes)."""
    if multiprocessing.current_process().name != "MainProcess" or \
            getattr(sys.modules.get("__main__"), "__name__", "") == "__mp_main__":
        raise ConfigError(
            "a gripkit sweep was started while a worker process was importing your script",
            hint="put the code that starts the sweep under `if __name__ == "
                 "\"__main__\":`, or use the "
                 "default process backend, which needs no guard")


class Executor(abc.ABC):
    """Runs tasks ``fn(*args)`` and yields ``(key, ok, value)`` as they finish."""

    name = "executor"
    workers = 1

    @abc.abstractmethod
    def map_unordered(self, tasks: Iterable[Task]) -> Iterator[tuple[object, bool, object]]:
        ...

    def close(self) -> None:
        """Release workers (the in-process executor holds none)."""

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class InProcessExecutor(Executor):
    """Tasks one after another in this process."""

    name = "in-process"

    def map_unordered(self, tasks):
        for key, fn, args in tasks:
            try:
                value = fn(*args)
            except Exception as exc:
                yield key, False, f"{type(exc).__name__}: {exc}"
                continue
            yield key, True, value


class _Worker:
    def __init__(self, log):
        env = dict(os.environ)
        env.update(PIN_ENV)
        # unbuffered pipes: a frame must never hide in a Python buffer while select() waits
        self.proc = subprocess.Popen([sys.executable, "-m", "gripkit.batch.worker"],
                                     stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, stderr=log, env=env, bufsize=0)
        self.tasks: collections.deque = collections.deque()  # sent, not yet answered (oldest first)

    @property
    def pid(self) -> int:
        return self.proc.pid

    def send(self, task: Task, payload: bytes) -> None:
        self.tasks.append(task)
        write_frame(self.proc.stdin, payload)

    def stop(self) -> None:
        with contextlib.suppress(OSError):  # the worker already closed its end
            self.proc.stdin.close()
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        self.proc.stdout.close()  # (left open, it is a ResourceWarning when collected)


class ProcessExecutor(Executor):
    """A pool of ``workers`` subprocesses (default: the cores this process may use,
    :func:`~gripkit.batch.budget.usable_cores`)."""

    name = "process"

    def __init__(self, workers: int | None = None, max_attempts: int = 3):
        n = usable_cores() if workers is None else int(workers)
        if n < 1:
            raise ConfigError(f"workers: expected a positive number, found {workers!r}")
        self.workers = n
        self.max_attempts = max_attempts
        self._log = tempfile.TemporaryFile()
        self._pool: list[_Worker] = []

    @property
    def pids(self) -> list[int]:
        """Process ids of the live workers (tests kill one to check recovery)."""
        return [w.pid for w in self._pool]

    def _spawn(self) -> _Worker:
        w = _Worker(self._log)
        self._pool.append(w)
        return w

    #: tasks queued ahead in a worker's pipe so it never waits for the coordinator between tasks
    #: (only frames this small: a full pipe must not block the coordinator)
    PREFETCH = 2
    PREFETCH_MAX_BYTES = 32 * 1024

    def map_unordered(self, tasks):
        pending = collections.deque(tasks)
        attempts: dict = collections.defaultdict(int)
        sel = selectors.DefaultSelector()
        try:
            while len(self._pool) < min(self.workers, max(len(pending), 1)):
                self._spawn()
            for w in self._pool:
                sel.register(w.proc.stdout, selectors.EVENT_READ, w)
            while pending or any(w.tasks for w in self._pool):
                for w in list(self._pool):  # fill every worker up to its prefetch depth
                    while pending and len(w.tasks) < self.PREFETCH:
                        task = pending[0]
                        payload = cloudpickle.dumps(task, protocol=pickle.HIGHEST_PROTOCOL)
                        if w.tasks and len(payload) > self.PREFETCH_MAX_BYTES:
                            break
                        pending.popleft()
                        try:
                            w.send(task, payload)
                        except (BrokenPipeError, OSError):
                            break  # it died: its death is read below and its tasks re-queued
                for skey, _ in sel.select():
                    w: _Worker = skey.data
                    frame = read_frame(w.proc.stdout)
                    if frame is None:  # the worker died while running its oldest task
                        code = w.proc.wait()
                        lost = list(w.tasks)
                        self._retire(w, sel)
                        culprit = lost[0] if lost else None
                        for task in reversed(lost[1:]):  # never started: not at fault
                            pending.appendleft(task)
                        if culprit is not None:
                            attempts[culprit[0]] += 1
                            if attempts[culprit[0]] >= self.max_attempts:
                                yield culprit[0], False, (
                                    f"WorkerDied: a worker exited with code {code} while "
                                    "running this task "
                                    f"({attempts[culprit[0]]} attempts)")
                            else:
                                pending.appendleft(culprit)
                        if pending or any(x.tasks for x in self._pool) or not self._pool:
                            if pending:
                                nw = self._spawn()
                                sel.register(nw.proc.stdout, selectors.EVENT_READ, nw)
                        continue
                    w.tasks.popleft()
                    key, ok, value = pickle.loads(frame)
                    yield key, ok, value
        finally:
            sel.close()

    def _retire(self, w: _Worker, sel) -> None:
        # not registered, or its pipe already closed
        with contextlib.suppress(KeyError, ValueError):
            sel.unregister(w.proc.stdout)
        if w in self._pool:
            self._pool.remove(w)
        w.stop()

    def close(self) -> None:
        for w in list(self._pool):
            w.stop()
        self._pool.clear()
        self._log.close()


class DaskExecutor(Executor):
    """Tasks on a ``dask.distributed`` cluster (``address``) or a new LocalCluster."""

    name = "dask"

    def __init__(self, address: str | None = None, workers: int | None = None,
                 timeout: float = 10.0):
        check_not_bootstrapping()
        try:
            from distributed import Client, LocalCluster
        except ImportError:
            raise ConfigError("the Dask backend needs dask.distributed",
                              hint="pip install 'gripkit[dask]'") from None
        self._cluster = None
        if address:
            # distributed's own timeout does not cover its handshake: a server that accepts and
            # stays silent (HTTP) would hang it, and a banner is read as a frame length (an
            # "out of memory" of exabytes). The probe answers both within ``timeout``.
            probe_scheduler(address, timeout)
            try:
                self.client = Client(address, timeout=timeout)
            except (OSError, ValueError, TypeError, MemoryError) as exc:  # unreachable, bad address
                raise ConfigError(f"cannot reach the Dask scheduler at {address!r}: {exc}",
                                  hint="give its address as tcp://host:8786") from None
        else:
            n = workers or usable_cores()
            self._cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                         dashboard_address=None, env=dict(PIN_ENV))
            self.client = Client(self._cluster)
        self.workers = len(self.client.scheduler_info().get("workers", {})) or (workers or 1)

    def map_unordered(self, tasks):
        from distributed import as_completed

        futures = {}
        for key, fn, args in tasks:
            fut = self.client.submit(fn, *args, pure=False, retries=2)
            futures[fut] = key
        for fut in as_completed(list(futures)):
            key = futures[fut]
            try:
                value = fut.result()
            except Exception as exc:
                yield key, False, f"{type(exc).__name__}: {exc}"
                continue
            yield key, True, value

    def close(self) -> None:
        self.client.close()
        if self._cluster is not None:
            self._cluster.close()


#: the most bytes a scheduler's first message (its handshake, ~60 bytes) may declare
_HANDSHAKE_MAX = 1 << 16
_SCHEDULER_HINT = ("check the host and port: the scheduler's, printed by `dask scheduler` as "
                   "tcp://host:8786 (8787 is its dashboard, a web page), and that it is running")


def _tcp_host_port(address: str) -> tuple[str, int] | None:
    """(host, port) of a ``tcp://host:port`` (or ``host:port``) address; None for another
    transport (tls://, ws://, inproc://, ucx://), which the probe leaves to distributed."""
    scheme, sep, rest = address.partition("://")
    if not sep:
        scheme, rest = "tcp", address
    if scheme != "tcp":
        return None
    host, sep, port = rest.rpartition(":")
    if not sep or not port.isdigit():
        return None  # distributed says what is wrong with the address
    return host.strip("[]") or "127.0.0.1", int(port)


def probe_scheduler(address: str, timeout: float = 10.0) -> None:
    """Check that a Dask scheduler answers at the ``tcp://`` ``address`` within ``timeout`` s: a
    scheduler sends its handshake as soon as a connection opens (a length, a frame count, frame
    lengths, then a msgpack map with ``compression`` and ``python``). Anything else (no answer,
    a banner, an HTTP reply) is a :class:`ConfigError` naming the address and the timeout.
    Addresses of other transports are not probed."""
    hp = _tcp_host_port(address)
    if hp is None:
        return
    try:
        conn = socket.create_connection(hp, timeout=timeout)
    except OSError as exc:
        raise ConfigError(f"cannot reach the Dask scheduler at {address!r}: {exc}",
                          hint=_SCHEDULER_HINT) from None
    deadline = time.monotonic() + timeout  # for the whole handshake, however it trickles in
    with conn:
        try:
            head = _recv_exactly(conn, 8, deadline)
            (n,) = struct.unpack("<Q", head)
            if 16 <= n <= _HANDSHAKE_MAX:
                body = _recv_exactly(conn, n, deadline)
            else:
                body = _recv_some(conn, 32)
        except TimeoutError:
            raise ConfigError(f"{address!r} accepts connections but no Dask scheduler answered "
                              f"within {timeout:g} s (a scheduler greets at once; an HTTP or other "
                              f"server waits)", hint=_SCHEDULER_HINT) from None
        except OSError as exc:  # closed or reset before a whole handshake came
            raise ConfigError(f"{address!r} is not a Dask scheduler: the connection ended "
                              f"before its handshake ({exc})", hint=_SCHEDULER_HINT) from None
    if not _is_handshake(body):
        raise ConfigError(f"{address!r} answered but is not a Dask scheduler: it sent "
                          f"{(head + body)[:40]!r} instead of a Dask handshake",
                          hint=_SCHEDULER_HINT)


def _recv_exactly(conn, n: int, deadline: float) -> bytes:
    """``n`` bytes, all by ``deadline`` (time.monotonic) or TimeoutError."""
    buf = bytearray()
    while len(buf) < n:
        left = deadline - time.monotonic()
        if left <= 0:
            raise TimeoutError
        conn.settimeout(left)
        part = conn.recv(n - len(buf))
        if not part:
            raise ConnectionError(f"closed after {len(buf)} of {n} bytes")
        buf += part
    return bytes(buf)


def _recv_some(conn, n: int) -> bytes:
    """Up to ``n`` more bytes if they come within 0.2 s (to show a banner in the message)."""
    conn.settimeout(0.2)
    try:
        return conn.recv(n)
    except OSError:
        return b""


def _is_handshake(body: bytes) -> bool:
    """``body`` framed as distributed frames it (count, lengths, frames) and its last frame a
    msgpack map with the handshake's keys (``compression``, ``python``)."""
    if len(body) < 16:
        return False
    (count,) = struct.unpack_from("<Q", body)
    if not 1 <= count <= 16 or len(body) < 8 * (count + 1):
        return False
    lengths = struct.unpack_from(f"<{count}Q", body, 8)
    start = 8 * (count + 1)
    if start + sum(lengths) != len(body):
        return False
    last = body[len(body) - lengths[-1]:]
    return b"\xabcompression" in last and b"\xa6python" in last  # msgpack str keys


def make_executor(backend: str = "process", workers: int | None = None,
                  scheduler: str | None = None) -> Executor:
    """``backend``: 'in-process', 'process' or 'dask' (a ``scheduler`` address implies 'dask')."""
    if scheduler:
        return DaskExecutor(scheduler, workers)
    if backend == "in-process":
        return InProcessExecutor()
    if backend == "process":
        return ProcessExecutor(workers)
    if backend == "dask":
        return DaskExecutor(None, workers)
    raise ConfigError(f"backend: expected 'in-process', 'process' or 'dask', found {backend!r}")
