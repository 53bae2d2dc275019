"""Packed vectors (gripkit.estimation.packed): one layout per vector, read alike by Python and
by the kernels of the Kalman filter and the LQG controller."""

import os
import subprocess
import sys

import numba
import numpy as np
from hypothesis import given, settings, strategies as st

from gripkit.control import lqg
from gripkit.estimation import kalman
from gripkit.estimation.packed import block_offsets, block_starts


@numba.njit
def _compiled_starts(sizes):
    return block_starts(sizes)


@settings(max_examples=40, deadline=None)
@given(st.lists(st.integers(0, 10_000), min_size=1, max_size=16))
def test_compiled_starts_are_the_running_sums(sizes):
    """Compiled and Python ``block_starts`` give 0, s0, s0 + s1, … and Σs for any length."""
    sizes = tuple(sizes)
    want = (tuple(int(v) for v in np.concatenate([[0], np.cumsum(sizes)[:-1]])), sum(sizes))
    assert block_starts(sizes) == want
    assert _compiled_starts(sizes) == want


@numba.njit
def _kernel_offsets(n, m, p):
    return (kalman._par_offsets(n, m, p), kalman._st_offsets(n, m, p),
            block_starts(lqg._par_sizes(n, m, p))[0], block_starts(lqg._st_sizes(n, m, p))[0])


@settings(max_examples=25, deadline=None)
@given(st.integers(1, 9), st.integers(1, 5), st.integers(1, 5))
def test_kernels_and_python_read_one_layout(n, m, p):
    """The offsets a kernel reads are those of the Python layout, block for block, and the
    layouts tile their vector (each block ends where the next starts)."""
    kp, ks, lp, ls = _kernel_offsets(n, m, p)
    for starts, names, sizes in ((kp, kalman.PAR_BLOCKS, kalman._par_sizes),
                                 (ks, kalman.ST_BLOCKS, kalman._st_sizes),
                                 (lp, lqg.PAR_BLOCKS, lqg._par_sizes),
                                 (ls, lqg.ST_BLOCKS, lqg._st_sizes)):
        lay, size = block_offsets(names, sizes(n, m, p))
        assert tuple(lay[k] for k in names) == starts and len(starts) == len(names)
        assert size == starts[-1] + sizes(n, m, p)[-1]


def test_kalman_and_lqg_run_without_jit():
    """Under NUMBA_DISABLE_JIT=1 (a debugger) the filter and the controller run through the
    Python ``block_starts`` and give the compiled results."""
    code = ("from gripkit.lti import StateSpace; from gripkit.sysid import LinearModel;"
            "from gripkit.estimation import KalmanFilter; from gripkit.control.lqg import LQG;"
            "m = LinearModel(StateSpace([[0.9, 0.1], [0.0, 0.5]], [[1.0], [0.5]],"
            " [[1.0, 0.0]], dt=0.1), 'n4sid');"
            "kf = KalmanFilter(m, Q=[[1.0, 0], [0, 1]], R=[[1.0]], steady_state=False);"
            "x, P = kf.step([1.0], [2.0]); c = LQG(m, Q=[[1.0, 0], [0, 1]], R=[[1.0]],"
            " Qn=[[1.0, 0], [0, 1]], Rn=[[1.0]]);"
            "print(repr([*x.tolist(), *P.ravel().tolist(), *c.step([1.0]).tolist()]))")
    runs = [subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                           env=dict(os.environ, NUMBA_DISABLE_JIT=flag), timeout=300)
            for flag in ("1", "0")]
    assert all(r.returncode == 0 for r in runs), [r.stderr[-500:] for r in runs]
    plain, compiled = (eval(r.stdout) for r in runs)
    assert len(plain) == 7 and np.allclose(plain, compiled, rtol=1e-13, atol=0)
