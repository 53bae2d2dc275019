"""The CUDA path without a GPU: the kernel runs in numba's CUDA simulator and agrees with the CPU
kernel; where the CUDA toolkit's NVVM is installed, the whole kernel compiles to PTX."""

import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from gripkit.systems.tsfm.grasp_batch import METRICS, tsfm_grasp_batch

JOBS = dict(k_e=[72.5, 800.0], w=[396e-6, 394e-6], offset=[0.0, 1e-6],
            approach_speed=[1e-3, 1.5e-3],
            noise_std=[2e-6, 1e-6])
DUR = 0.006   # 120 samples: contact after ~40, detection, hold, the start of the squeeze

SCRIPT = textwrap.dedent(f"""
    import json, warnings
    warnings.simplefilter("ignore")
    from gripkit.systems.tsfm.grasp_batch import tsfm_grasp_batch
    from gripkit.systems.tsfm.grasp_gpu import cuda_available
    assert cuda_available()            # the simulator stands in for a device
    res = tsfm_grasp_batch(backend="cuda", duration={DUR}, **{JOBS!r})
    print(json.dumps({{k: [None if v != v else v for v in map(float, res[k])]
                      for k in {list(METRICS)!r}}}))
""")


def test_cuda_kernel_in_the_simulator_matches_the_cpu_kernel():
    """Two jobs (one soft, one stiff part): the kernel launched through numba.cuda (simulated: one
    Python thread per GPU thread, njit callees as Python) gives the CPU kernel's metrics."""
    env = dict(os.environ, NUMBA_ENABLE_CUDASIM="1", NUMBA_DISABLE_JIT="1")
    proc = (subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, env=env,
                           timeout=300))
    assert proc.returncode == 0, proc.stderr[-3000:]
    sim = json.loads(proc.stdout.strip().splitlines()[-1])
    cpu = tsfm_grasp_batch(duration=DUR, **JOBS)
    # the case has contacts
    assert np.isfinite(cpu["t_contact1"]).all() and np.isfinite(cpu["t_squeeze"]).all()
    for m in METRICS:
        got = np.array([np.nan if v is None else v for v in sim[m]])
        np.testing.assert_allclose(got, cpu[m], rtol=1e-9, atol=1e-15, err_msg=m)


def _nvvm():
    try:
        from numba.cuda.cudadrv import nvvm

        return nvvm.is_available()
    except Exception:
        return False


@pytest.mark.skipif(not _nvvm(), reason="compiling to PTX needs the CUDA toolkit's NVVM "
                                        "library, absent here; "
                    "the simulator test above still checks the kernel's values")
def test_the_grasp_kernel_compiles_to_ptx():
    """Every function the GPU kernel calls (grasp step, gripper step, hybrid contact step,
    Bouc-Wen, detector, estimator, noise) compiles for the device: no allocation, no object."""
    from gripkit.systems.tsfm.grasp_gpu import compile_ptx

    ptx = compile_ptx((8, 0))
    assert ".entry" in ptx and "_kernel_py" in ptx
    assert "malloc" not in ptx   # nothing allocated in device code
