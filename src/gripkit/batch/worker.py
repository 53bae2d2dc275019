"""A gripkit batch worker: ``python -m gripkit.batch.worker``.

Started by :class:`gripkit.batch.executors.ProcessExecutor` as a plain subprocess (never by
forking, never by re-importing the user's script), with BLAS/OpenMP/numba threads pinned to one.
It reads tasks from stdin and writes results to stdout, each a length-prefixed pickle frame:

    task:   (key, fn, args)        fn and args serialised with cloudpickle
    result: (key, ok, value)       value is the return value, or "Type: message" when fn raised
"""

from __future__ import annotations

import os
import pickle
import struct
import sys

import cloudpickle

PIN_ENV = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
           "NUMBA_NUM_THREADS": "1", "VECLIB_MAXIMUM_THREADS": "1", "NUMEXPR_NUM_THREADS": "1"}
_HEADER = struct.Struct("<Q")


def write_frame(stream, payload: bytes) -> None:
    """Write one length-prefixed frame (handles partial writes of unbuffered pipes)."""
    data = memoryview(_HEADER.pack(len(payload)) + payload)
    while data:
        n = stream.write(data)
        data = data[n if n is not None else len(data):]
    stream.flush()


def _read_exact(stream, n: int) -> bytes | None:
    chunks = []
    while n > 0:
        b = stream.read(n)
        if not b:
            return None
        chunks.append(b)
        n -= len(b)
    return b"".join(chunks)


def read_frame(stream) -> bytes | None:
    """Read one frame; None at end of stream. The coordinator reads its workers' pipes unbuffered,
    so that ``select`` never misses a frame sitting in a Python-side buffer."""
    head = _read_exact(stream, _HEADER.size)
    if head is None:
        return None
    (n,) = _HEADER.unpack(head)
    return _read_exact(stream, n)


def main() -> int:
    for k, v in PIN_ENV.items():
        os.environ.setdefault(k, v)
    stdin, stdout = sys.stdin.buffer, sys.stdout.buffer
    sys.stdout = sys.stderr  # stray prints from jobs must not corrupt the frame stream
    while True:
        frame = read_frame(stdin)
        if frame is None:
            return 0
        key, fn, args = cloudpickle.loads(frame)
        try:
            out = (key, True, fn(*args))
            payload = pickle.dumps(out, protocol=pickle.HIGHEST_PROTOCOL)
        except Exception as exc:  # recorded by the coordinator, never fatal to the sweep
            payload = pickle.dumps((key, False, f"{type(exc).__name__}: {exc}"),
                                   protocol=pickle.HIGHEST_PROTOCOL)
        write_frame(stdout, payload)


if __name__ == "__main__":
    raise SystemExit(main())
