"""The TSFM grasp batch on a CUDA GPU (optional): the same scalar kernel as the CPU path,
:func:`gripkit.systems.tsfm.grasp_kernels._grasp_core`, compiled by ``numba.cuda`` — one grasp per
thread.

numba compiles an ``@njit`` function called from a CUDA kernel for the device (with every njit
function it calls: ``grasp_step``, ``gripper_advance``, ``pwa_step``, ``bouc_wen_advance``, the
detector and estimator steps), so there is one source for both targets. The core allocates
nothing: every work array (controller, detector, estimator and finger states, the part's contact-
mode matrices) is a slice, per thread, of arrays allocated on the device before the launch. The
per-job contact-mode ZOH matrices (matrix exponentials, which allocate) are computed on the CPU
by the numba kernel :func:`~gripkit.systems.tsfm.grasp_kernels._setup_jobs` and
copied to the device with the jobs, in launches of at most ``batch`` jobs.

Use: ``tsfm_grasp_batch(..., backend="cuda")`` or ``backend = "cuda"`` in a sweep's
``[scenario]``. Without a device the call raises a ConfigError; gripkit never needs a GPU.
Checked without a GPU by the tests: the kernel runs in numba's CUDA simulator
(``NUMBA_ENABLE_CUDASIM=1``, with ``NUMBA_DISABLE_JIT=1`` so the njit callees run as Python too)
and agrees with the CPU kernel; and, where the CUDA toolkit's NVVM is installed, the whole kernel
compiles to PTX (:func:`compile_ptx`).
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import cuda

from ...errors import ConfigError
from ...sim.hybrid import MAX_EVENTS_PER_STEP
from .grasp import Estimators, GraspLoop
from .grasp_kernels import SensorNoise, _default_gripper, _grasp_core, _setup_jobs, _template
from .gripper import GripperModel, GripperState, GripperWork

__all__ = ["cuda_available", "run_cuda", "compile_ptx"]


def cuda_available() -> bool:
    """True when numba finds a usable CUDA device (or runs the CUDA simulator)."""
    try:
        return bool(cuda.is_available())
    except Exception:  # no driver, no numba.cuda
        return False


#: what every job of a launch shares: the gripper's Bouc-Wen parameters, switching guards, contact
#: targets, guard count and event levels K, the samples per grasp and the metric settings
DeviceShared = namedtuple("DeviceShared", "bw G target ng K n_steps mset")
#: the jobs' arrays, leading index: job (contact-mode matrices, parts, noise, noise levels, seeds,
#: controller settings)
DeviceJobs = namedtuple("DeviceJobs", "Phi Gam C D Hg parts noise nstd seeds cps")
#: every job's work arrays on the device, leading index: job (the fields of GraspLoop,
#: GripperState and GripperWork, and the random-number state), allocated by :func:`run_cuda`
DeviceWork = namedtuple("DeviceWork", "det buf est cs X modes hyst ps ext out ua xt "
                                      "ev_frac ev_to yout rng")


def _kernel_py(shared, estimators, jobs, work, met):  # pragma: no cover - runs on the device
    """Thread p runs job p on its slice of every job-indexed array, into ``met[p]``; the records
    :func:`_grasp_core` takes are built here, on the device, from those slices."""
    p = cuda.grid(1)
    if p < jobs.parts.shape[0]:
        q = p if jobs.noise.shape[0] > 1 else 0
        w = work
        _grasp_core(GripperModel(shared.bw, jobs.Phi[p], jobs.Gam[p], jobs.C[p], jobs.D[p],
                                 shared.G, jobs.Hg[p],
                                 shared.target, shared.ng, shared.K, jobs.parts[p]),
                    SensorNoise(jobs.noise[q], jobs.nstd[p], jobs.seeds[p]), shared.n_steps,
                    estimators, jobs.cps[p], shared.mset,
                    GraspLoop(w.det[p], w.buf[p], w.est[p], w.cs[p], w.ext[p], w.out[p]),
                    GripperState(w.X[p], w.modes[p], w.hyst[p], w.ps[p]),
                    GripperWork(w.ua[p], w.xt[p], w.ev_frac[p], w.ev_to[p], w.yout[p]), w.rng[p],
                    met[p])


_KERNEL = []


def _kernel():
    if not _KERNEL:
        _KERNEL.append(cuda.jit(_kernel_py))
    return _KERNEL[0]


def _host_arrays(tpl, parts):
    """The jobs' matrices with their contact modes (computed on the CPU), leading index: job."""
    P = parts.shape[0]
    stack = ([np.ascontiguousarray(np.broadcast_to(a, (P,) + a.shape))
              for a in (tpl.Phi, tpl.Gam, tpl.C, tpl.D, tpl.H)])
    Phi, Gam, C, D, Hg = (s.copy() for s in stack)
    _setup_jobs(tpl.kernel_args(), parts, tpl.dt, Phi, Gam, C, D, Hg)
    return Phi, Gam, C, D, Hg


def run_cuda(tpl, parts, nz, nstd, seeds, n_steps, window, cps, mset, met, batch: int = 16384,
             threads_per_block: int = 64) -> None:
    """Run the jobs on the GPU (see the module docstring); fills ``met`` (P, len(METRICS))."""
    if not cuda_available():
        raise ConfigError("backend 'cuda': no CUDA device is available to numba",
                          hint="use backend='cpu' (the default), or install the NVIDIA driver "
                               "and CUDA toolkit")
    kern = _kernel()
    n = tpl.A.shape[1]
    P = parts.shape[0]
    for a in range(0, P, batch):
        b = min(P, a + batch)
        m = b - a
        Phi, Gam, C, D, Hg = _host_arrays(tpl, np.ascontiguousarray(parts[a:b]))
        d = cuda.to_device
        work = DeviceWork(*(cuda.device_array(s, dtype=dt) for s, dt in (
            ((m, 2, 5), np.float64), ((m, 2, window), np.float64), ((m, 2, 6), np.float64),
            ((m, 2, 7), np.float64),
            ((m, 2, n), np.float64), ((m, 2), np.int64), ((m, 4), np.float64), ((m, 1), np.float64),
            ((m, 4), np.float64), ((m, 2, 5), np.float64), ((m, 3), np.float64),
            ((m, n), np.float64),
            ((m, MAX_EVENTS_PER_STEP), np.float64), ((m, MAX_EVENTS_PER_STEP), np.int64),
            ((m, 2, tpl.C.shape[2]), np.float64), ((m, 1), np.uint64))))
        out = cuda.device_array((m, met.shape[1]), dtype=np.float64)
        noise = nz if nz.shape[0] == 1 else nz[a:b]
        blocks = (m + threads_per_block - 1) // threads_per_block
        shared = (DeviceShared(d(tpl.bw), d(tpl.G), d(tpl.target), d(tpl.ng), tpl.K, n_steps,
                               d(mset)))
        jobs = DeviceJobs(d(Phi), d(Gam), d(C), d(D), d(Hg), d(np.ascontiguousarray(parts[a:b])),
                          d(np.ascontiguousarray(noise)), d(nstd[a:b]), d(seeds[a:b]),
                          d(np.ascontiguousarray(cps[a:b])))
        kern[blocks, threads_per_block](shared, Estimators(*(d(e) for e in tpl.est)), jobs, work,
                                        out)
        met[a:b] = out.copy_to_host()


def compile_ptx(cc: tuple[int, int] = (8, 0)) -> str:
    """PTX of the whole grasp kernel for compute capability ``cc`` — a check that every function
    it calls compiles for the GPU, possible without a GPU where NVVM (the CUDA toolkit) is
    installed. numba asks the current device for its compute capability when it compiles an
    @njit callee for CUDA; without a device this answers ``cc``."""
    import numba
    from numba import typeof
    from numba.cuda import dispatcher

    tpl = _template(_default_gripper(), 5e-5, None)
    f8, i8 = numba.float64, numba.int64

    def arr(nd, dtype=f8):
        return dtype[(slice(None),) * (nd - 1) + (slice(None, None, 1),)]

    def record(cls, *types):
        return numba.types.NamedTuple(types, cls)

    args = (record(DeviceShared, typeof(tpl.bw), typeof(tpl.G), typeof(tpl.target), typeof(tpl.ng),
                   i8, i8, arr(1)),
            record(Estimators, *(typeof(e) for e in tpl.est)),
            record(DeviceJobs, arr(6), arr(6), arr(5), arr(5), arr(5), arr(2), arr(3), arr(1),
                   arr(1, i8), arr(2)),
            record(DeviceWork, arr(3), arr(3), arr(3), arr(3), arr(3), arr(2, i8), arr(2), arr(2),
                   arr(2), arr(3),
                   arr(2), arr(2), arr(2), arr(2, i8), arr(3), arr(2, numba.uint64)),
            arr(2))

    class _Device:
        compute_capability = cc

    patched = False
    if not cuda_available():
        orig, dispatcher.get_current_device = dispatcher.get_current_device, lambda: _Device()
        patched = True
    try:
        ptx, _ = cuda.compile_ptx(_kernel_py, args, cc=cc)
    finally:
        if patched:
            dispatcher.get_current_device = orig
    return ptx
