"""``--scheduler`` at an address that answers but is not a Dask scheduler (issue 22, item 12):
an HTTP server (it waits for a request, so distributed's handshake hung for ever) and a service
that greets with a banner (read as a frame length: "unable to allocate 3 EiB") each give a
ConfigError naming the address, within the timeout. Servers listen on 127.0.0.1 only, in a
thread of the test; each test is bounded by the probe's timeout."""

from __future__ import annotations

import asyncio
import contextlib
import socket
import threading
import time

import pytest
from corpus import assert_user_error

from gripkit.batch.executors import probe_scheduler
from gripkit.errors import ConfigError


def _serve(handler):
    """A loopback TCP server running ``handler(conn)`` per connection; returns (address, stop)."""
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(8)
    srv.settimeout(0.2)
    stop = threading.Event()

    def loop():
        while not stop.is_set():
            try:
                conn, _ = srv.accept()
            except OSError:
                continue
            threading.Thread(target=_guarded, args=(handler, conn, stop), daemon=True).start()
        srv.close()

    threading.Thread(target=loop, daemon=True).start()
    return f"tcp://127.0.0.1:{srv.getsockname()[1]}", stop


def _guarded(handler, conn, stop):
    with conn:
        conn.settimeout(0.2)
        with contextlib.suppress(OSError):  # the probe closing the connection early is the point
            handler(conn, stop)


def http_server(conn, stop):
    """Waits for the end of a request's head, as an HTTP server does, then answers 400."""
    buf = b""
    while not stop.is_set() and b"\r\n\r\n" not in buf:
        try:
            part = conn.recv(4096)
        except TimeoutError:
            continue
        if not part:
            return
        buf += part
    conn.sendall(b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n")


def banner_server(conn, stop):
    """Greets first, as SSH, SMTP or FTP servers do, then waits."""
    conn.sendall(b"SSH-2.0-OpenSSH_9.6 gripkit-test\r\n")
    stop.wait(30)


@pytest.fixture
def server():
    stops = []

    def start(handler):
        address, stop = _serve(handler)
        stops.append(stop)
        return address

    yield start
    for s in stops:
        s.set()


def test_http_server_times_out_with_the_address(server):
    address = server(http_server)
    t0 = time.perf_counter()
    with pytest.raises(ConfigError) as e:
        probe_scheduler(address, timeout=1.0)
    assert time.perf_counter() - t0 < 4.0
    msg = str(e.value)
    assert f"'{address}' accepts connections but no Dask scheduler answered within 1 s" in msg
    assert "8787 is its dashboard" in msg  # what to check


def test_banner_is_not_a_scheduler(server):
    address = server(banner_server)
    with pytest.raises(ConfigError,
                       match="answered but is not a Dask scheduler: it sent b'SSH-2.0-OpenSSH"):
        probe_scheduler(address, timeout=5.0)


def test_closed_port_cannot_be_reached():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()  # nothing listens there now
    with pytest.raises(ConfigError,
                       match=f"cannot reach the Dask scheduler at 'tcp://127.0.0.1:{port}'"):
        probe_scheduler(f"tcp://127.0.0.1:{port}", timeout=2.0)


def test_a_real_scheduler_passes_the_probe():
    """The probe accepts what distributed's scheduler sends (its handshake)."""
    import distributed  # a dev dependency (tests/test_dev_dependencies.py): fail, never skip
    ready, done = threading.Event(), threading.Event()
    box = {}

    async def main():
        sched = await distributed.Scheduler(host="127.0.0.1", port=0, dashboard_address=None)
        box["address"] = sched.address
        ready.set()
        while not done.is_set():
            await asyncio.sleep(0.05)
        await sched.close()

    th = threading.Thread(target=lambda: asyncio.run(main()), daemon=True)
    th.start()
    assert ready.wait(30)
    try:
        probe_scheduler(box["address"], timeout=5.0)  # no error
        host_port = box["address"].removeprefix("tcp://")
        probe_scheduler(host_port, timeout=5.0)  # host:port means tcp
    finally:
        done.set()
        th.join(10)


def test_executor_and_cli_say_not_a_scheduler(server, cli, tmp_path):
    import distributed  # noqa: F401  (a dev dependency: fail, never skip)
    from gripkit.batch.executors import DaskExecutor

    address = server(http_server)
    t0 = time.perf_counter()
    with pytest.raises(ConfigError, match="no Dask scheduler answered within 1 s"):
        DaskExecutor(address, timeout=1.0)
    assert time.perf_counter() - t0 < 4.0

    sweep = tmp_path / "sweep.toml"
    sweep.write_text('[sweep]\nname = "msd"\nscenario = "step-response"\n'
                     'model = "mass-spring-damper"\nsamples = 2\nseed = 1\n[parameters]\n'
                     'k = { grid = [1.0, 4.0] }\n[scenario]\nduration = 10.0\n')
    banner = server(banner_server)
    res = cli("sweep", sweep, "--scheduler", banner, "--out", tmp_path / "out")
    assert_user_error(res, "ConfigError", f"'{banner}' answered but is not a Dask scheduler")
    assert not (tmp_path / "out").exists()


def trickle_server(conn, stop):
    """Sends a byte every 0.4 s: no single read waits long, the handshake never completes."""
    for b in b"\x01\x00\x00\x00\x00\x00\x00\x00" * 100:
        if stop.wait(0.4):
            return
        conn.sendall(bytes([b]))


def test_trickling_server_times_out_as_a_whole(server):
    address = server(trickle_server)
    t0 = time.perf_counter()
    with pytest.raises(ConfigError, match="no Dask scheduler answered within 1.5 s"):
        probe_scheduler(address, timeout=1.5)
    assert time.perf_counter() - t0 < 4.0
