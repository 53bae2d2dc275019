"""Flush-to-zero (FTZ) and denormals-are-zero (DAZ) for timing runs, on x86-64.

There is no portable Python API for the MXCSR control register, so a ten-line C file calling
``_mm_getcsr``/``_mm_setcsr`` is compiled with the system C compiler into a temporary directory
and loaded with ctypes. MXCSR is per thread: :func:`flush_denormals` sets it for the calling thread
only, which is the thread that runs a (non-parallel) numba kernel called from it. Bits 15 (FTZ)
and 6 (DAZ)."""

from __future__ import annotations

import contextlib
import ctypes
import platform
import shutil
import subprocess
import tempfile
from pathlib import Path

_SOURCE = r"""
#include <xmmintrin.h>
unsigned int gk_getcsr(void) { return _mm_getcsr(); }
void gk_setcsr(unsigned int v) { _mm_setcsr(v); }
"""
FTZ_DAZ = (1 << 15) | (1 << 6)
_LIB = None


def _library():
    """The compiled helper (built once per process), or None with the reason."""
    global _LIB
    if _LIB is not None:
        return _LIB, ""
    if platform.machine().lower() not in ("x86_64", "amd64"):
        return None, f"MXCSR exists on x86-64 only (this is {platform.machine()})"
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        return None, "no C compiler on PATH to build the MXCSR helper"
    tmp = Path(tempfile.mkdtemp(prefix="gk-mxcsr-"))
    (tmp / "mxcsr.c").write_text(_SOURCE)
    so = tmp / "libmxcsr.so"
    done = subprocess.run([cc, "-O2", "-shared", "-fPIC", "-o", str(so), str(tmp / "mxcsr.c")],
                          capture_output=True, text=True)
    if done.returncode != 0:
        return None, f"C compiler failed: {done.stderr.strip()[:200]}"
    lib = ctypes.CDLL(str(so))
    lib.gk_getcsr.restype = ctypes.c_uint
    lib.gk_setcsr.argtypes = [ctypes.c_uint]
    _LIB = lib
    return lib, ""


def available() -> tuple[bool, str]:
    """Whether FTZ/DAZ can be set here, and why not."""
    lib, why = _library()
    return lib is not None, why


@contextlib.contextmanager
def flush_denormals(on: bool = True):
    """Within the block, this thread's MXCSR has FTZ and DAZ set (``on``) or cleared."""
    lib, why = _library()
    if lib is None:
        raise RuntimeError(why)
    old = lib.gk_getcsr()
    lib.gk_setcsr((old | FTZ_DAZ) if on else (old & ~FTZ_DAZ))
    try:
        yield
    finally:
        lib.gk_setcsr(old)


def cpu_model() -> str:
    """The CPU's model name from /proc/cpuinfo (or platform.processor())."""
    with contextlib.suppress(OSError):
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    return platform.processor() or "unknown CPU"
