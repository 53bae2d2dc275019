"""The numba kernels behind :mod:`gripkit.systems.tsfm.grasp_batch` (CPU) and
:mod:`gripkit.systems.tsfm.grasp_gpu` (CUDA): per-job contact-mode setup, one grasp reduced to its
metrics on the fly, the job loop, and the per-gripper template the jobs share."""

from __future__ import annotations

import math
import threading
import warnings
from collections import namedtuple

import numba
import numpy as np
from numba import prange

from ...errors import ConsistencyWarning
from ...sim.hybrid import MAX_EVENTS_PER_STEP
from ...sim.integrators import zoh_levels_into
from ...sim.noise import normal_draw
from . import parameters as z
from .grasp import SX, GraspLoop, _est_stack, _static_gain, _values, grasp_step
from .gripper import (FINGER_NAMES, GripperModel, GripperState, GripperWork, finger_state_space,
                      gripper_advance,
                      gripper_measure)

METRICS = ("t_contact1", "t_contact2", "t_squeeze", "peak_force", "damage", "max_displacement",
           "grasped",
           "lost", "settling_time", "final_error", "final_force", "width_error", "stiffness_error")
_NM = len(METRICS)
#: index of each metric in a row of ``met``: ``met[MX.peak_force]`` (generated from METRICS)
MX = namedtuple("MetricIndex", METRICS)(*range(len(METRICS)))
#: the metric settings ``mset`` the kernels take, and their index table ``mset[MSX.band]``
METRIC_SETTINGS = ("damage_force", "lost_displacement", "band")
MSX = namedtuple("MetricSettingIndex", METRIC_SETTINGS)(*range(len(METRIC_SETTINGS)))
_SQUEEZE = 2.0
_PHASE, _CONTACT_T = 0, 6

#: what the jobs of one gripper share (:meth:`GraspTemplate.kernel_args`): the fingers' continuous
#: matrices for the contact modes (``A`` (2, n, n), ``B0``, ``bF`` (2, n), ``iy`` the index of y_C),
#: the discretised free modes and outputs (``Phi``, ``Gam``, ``C``, ``D``, ``G``, ``H``: leading
#: index finger), the hybrid step's ``target``, ``ng``, ``K``, the Bouc-Wen ``bw`` (2, 4) and the
#: estimators ``est`` (:class:`~gripkit.systems.tsfm.grasp.Estimators`)
JobTemplate = namedtuple("JobTemplate", "A B0 bF iy Phi Gam C D G H target ng K bw est")
#: scratch of :func:`_job_setup`: the contact mode's continuous ``Ac`` (2, n, n), ``Bc`` (2, n, 3)
#: and discretised ``PhiC`` (2, K+1, n, n), ``GamC`` (2, K+1, n, 3)
ContactWork = namedtuple("ContactWork", "Ac Bc PhiC GamC")
#: the force-sensor noise of one grasp: explicit samples (N, 2) when it has rows, else white noise
#: of standard deviation ``std`` (N) from a splitmix64 stream seeded with ``seed``
SensorNoise = namedtuple("SensorNoise", "samples std seed")


# ------------------------------------------------------------------------------------------------
# numba kernels
# ------------------------------------------------------------------------------------------------

@numba.njit(cache=True)
def _job_setup(tpl, part, dt, Phi, Gam, C, D, Hg, cw):  # pragma: no cover - compiled
    """Write the contact mode (index 1) of both fingers for the part ``part`` = [w, gap, k_side,
    c_side, F_po, F_stick] into Phi (2, 2, K+1, n, n), Gam (2, 2, K+1, n, 3), C (2, 2, 4, n),
    D (2, 2, 4, 3), Hg (2, 2, J, 3); the free mode (index 0) is left as it is. ``tpl``: the
    :class:`JobTemplate` (A, B0, bF, iy, K used); ``cw``: :class:`ContactWork`. Mirrors
    :func:`gripkit.systems.tsfm.gripper.finger_hybrid`: A_c = A + b_F kᵀ (k = k_side at y_C, c_side
    at
    ẏ_C), B_c = [B_W, −k_side b_F, 0], F_g = kᵀ x − k_side x_face, release at −F_po/k_side."""
    A, B0, bF, iy, K = tpl.A, tpl.B0, tpl.bF, tpl.iy, tpl.K
    Ac, Bc, PhiC, GamC = cw.Ac, cw.Bc, cw.PhiC, cw.GamC
    n = A.shape[1]
    k = part[2]
    c = part[3]
    for i in range(2):
        for r in range(n):
            for q in range(n):
                kv = k if q == iy else (c if q == iy + 1 else 0.0)
                Ac[i, r, q] = A[i, r, q] + bF[i, r] * kv
            Bc[i, r, 0] = B0[i, r]
            Bc[i, r, 1] = -k * bF[i, r]
            Bc[i, r, 2] = 0.0
    zoh_levels_into(Ac, Bc, dt, K, PhiC, GamC)
    for i in range(2):
        for lev in range(K + 1):
            for r in range(n):
                for q in range(n):
                    Phi[i, 1, lev, r, q] = PhiC[i, lev, r, q]
                for q in range(3):
                    Gam[i, 1, lev, r, q] = GamC[i, lev, r, q]
        for q in range(n):
            C[i, 1, 2, q] = k if q == iy else (c if q == iy + 1 else 0.0)
        D[i, 1, 2, 0] = 0.0
        D[i, 1, 2, 1] = -k
        D[i, 1, 2, 2] = 0.0
        Hg[i, 1, 0, 2] = part[4] / k


@numba.njit(cache=True, _nrt=False, inline="always")
def _grasp_reset(loop, state, part, rng, seed):  # pragma: no cover - compiled
    """Rest before a grasp: detector, buffers, estimators and controller zero (no contact time
    yet), fingers at rest in free mode, hysteresis states zero, the part at its initial X_p, the
    noise stream seeded (splitmix64)."""
    det, buf, est, cs = loop.det, loop.buf, loop.est, loop.cs
    X, modes, hyst, ps = state.X, state.modes, state.hyst, state.ps
    for i in range(2):
        for j in range(det.shape[1]):
            det[i, j] = 0.0
        for j in range(buf.shape[1]):
            buf[i, j] = 0.0
        for j in range(est.shape[1]):
            est[i, j] = 0.0
        for j in range(cs.shape[1]):
            cs[i, j] = 0.0
        cs[i, _CONTACT_T] = -1.0
        for j in range(X.shape[1]):
            X[i, j] = 0.0
        modes[i] = 0
    for j in range(4):
        hyst[j] = 0.0
    ps[0] = part[6]
    rng[0] = np.uint64(seed) * np.uint64(0x2545F4914F6CDD1D) + np.uint64(1)


@numba.njit(cache=True, _nrt=False, inline="always")
def _settling_time(t_sq, last_out, n_steps, dt):  # pragma: no cover - compiled
    """Time from the squeeze until the mean force last left its band (inf: never squeezed, or
    still outside at the end)."""
    if t_sq < 0.0 or last_out == n_steps - 1:
        return math.inf
    ts = (last_out + 1) * dt - t_sq
    return ts if ts > 0.0 else 0.0


@numba.njit(cache=True, _nrt=False, inline="always")
def _stiffness_metrics(met, part, detected, grasped, y_contact, y_sum,
                       f_mean):  # pragma: no cover - compiled
    """``width_error`` (the part width from the two detected contact positions) and
    ``stiffness_error``: k̂_e/k − 1 with k̂_e = F_g/δ (eq 16 of ``001_0b92a7da96e7aa46.txt``) from
    the tail's mean force and squeeze beyond contact, k the two sides in series (k_side/2); NaN
    unless both contacts were detected."""
    if not detected:
        met[MX.width_error] = math.nan
        met[MX.stiffness_error] = math.nan
        return
    met[MX.width_error] = part[1] - y_contact - part[0]
    delta = y_sum - y_contact
    met[MX.stiffness_error] = (f_mean / delta / (0.5 * part[2]) - 1.0 if (grasped and delta > 0.0)
                               else math.nan)


@numba.njit(cache=True, _nrt=False)
def _grasp_core(model, sensor, n_steps, e, cp, mset, loop, state, work, rng,
                met):  # pragma: no cover - compiled
    """One grasp from rest on the gripper ``model`` (:class:`GripperModel`, its part with the
    initial X_p appended), reduced to the metrics ``met`` (len(METRICS)); no allocation (every
    work array is passed in: ``loop`` (:class:`~gripkit.systems.tsfm.grasp.GraspLoop`), ``state``
    (:class:`GripperState`), ``work`` (:class:`GripperWork`), ``rng`` (1,) uint64; so the function
    also compiles for CUDA, one job per thread).

    ``sensor`` (:data:`SensorNoise`): the force-sensor noise per sample when ``sensor.samples``
    has rows, else white noise of std ``sensor.std`` from a stream seeded with ``sensor.seed``.
    ``e``: the estimators; ``cp``:
    :meth:`GraspSettings.vector`; ``mset`` = [damage_force, lost_displacement, band]. The loop is
    the one of :func:`gripkit.systems.tsfm.grasp._grasp_run`. Compiled without numba's reference
    counting (``_nrt=False``, like its callees :func:`grasp_step`, :func:`gripper_advance` and
    :func:`gripper_measure`): taking the records apart would otherwise cost an atomic
    incref/decref pair per array per call (docs/performance.md, "Named records in kernels")."""
    out, modes, ps = loop.out, state.modes, state.ps
    part, yout = model.part, work.yout
    noise, nstd, seed = sensor.samples, sensor.std, sensor.seed
    dt = cp[SX.dt]
    fcmd = cp[SX.grip_force]
    _grasp_reset(loop, state, part, rng, seed)
    x0p = part[6]
    explicit = noise.shape[0] > 0
    t_c1 = -1.0
    t_c2 = -1.0
    t_sq = -1.0
    peak = 0.0
    maxd = 0.0
    y1c = 0.0
    y2c = 0.0
    det1 = False
    det2 = False
    last_out = -1
    n_tail_max = n_steps // 10   # builtin max/min are avoided here: numba.cuda cannot retarget them
    if n_tail_max < 1:
        n_tail_max = 1
    tail = n_steps - n_tail_max
    sum_f = 0.0
    sum_fm = 0.0
    sum_s = 0.0
    n_tail = 0
    grasped = False
    gripper_measure(state, model, work)
    for k in range(n_steps):
        if explicit:
            F1 = yout[0, 3] + noise[k, 0]
            F2 = yout[1, 3] + noise[k, 1]
        else:
            F1 = yout[0, 3] + nstd * normal_draw(rng)
            F2 = yout[1, 3] + nstd * normal_draw(rng)
        grasp_step(F1, F2, loop, e, cp)
        # --- metrics of sample k (the record row k of the single grasp)
        fg1 = yout[0, 2]
        fg2 = yout[1, 2]
        if fg1 > peak:
            peak = fg1
        if fg2 > peak:
            peak = fg2
        d = abs(ps[0] - x0p)
        if d > maxd:
            maxd = d
        if t_c1 < 0.0 and modes[0] == 1:
            t_c1 = k * dt
        if t_c2 < 0.0 and modes[1] == 1:
            t_c2 = k * dt
        if not det1 and out[0, 3] > 0.5:
            det1 = True
            y1c = out[0, 1]
        if not det2 and out[1, 3] > 0.5:
            det2 = True
            y2c = out[1, 1]
        if t_sq < 0.0 and out[0, 4] == _SQUEEZE:
            t_sq = k * dt
        fbar = 0.5 * (fg1 + fg2)
        if t_sq >= 0.0 and abs(fbar - fcmd) > mset[MSX.band] * fcmd:
            last_out = k
        if k >= tail:
            sum_f += fbar
            sum_fm += 0.5 * (F1 + F2)
            sum_s += out[0, 1] + out[1, 1]
            n_tail += 1
        if k == n_steps - 1:
            grasped = (modes[0] == 1 and modes[1] == 1 and out[0, 4] == _SQUEEZE
                       and out[1, 4] == _SQUEEZE)
        gripper_advance(out[0, 0], out[1, 0], state, model, work)
    met[MX.t_contact1] = t_c1 if t_c1 >= 0.0 else math.nan
    met[MX.t_contact2] = t_c2 if t_c2 >= 0.0 else math.nan
    met[MX.t_squeeze] = t_sq if t_sq >= 0.0 else math.nan
    met[MX.peak_force] = peak
    met[MX.damage] = 1.0 if peak > mset[MSX.damage_force] else 0.0
    met[MX.max_displacement] = maxd
    met[MX.grasped] = 1.0 if grasped else 0.0
    met[MX.lost] = 1.0 if (not grasped or maxd > mset[MSX.lost_displacement]) else 0.0
    met[MX.settling_time] = _settling_time(t_sq, last_out, n_steps, dt)
    met[MX.final_error] = (sum_f / n_tail - fcmd) / fcmd
    met[MX.final_force] = sum_f / n_tail
    _stiffness_metrics(met, part, det1 and det2, grasped, y1c + y2c, sum_s / n_tail,
                       sum_fm / n_tail)


@numba.njit(cache=True, nogil=True)
def _grasp_jobs(tpl, parts, noise, nstd, seeds, n_steps, window, cps, mset,
                met):  # pragma: no cover - compiled
    """Jobs one after another on this core (rows of parts, cps, nstd, seeds, met): for each, the
    template's (:class:`JobTemplate`) matrices with the contact mode of its part
    (:func:`_job_setup`), then :func:`_grasp_core`. ``noise`` (P, N, 2) explicit noise per job, or
    (1, 0, 2) for generated noise. ``nogil``: :func:`tsfm_grasp_batch` runs slices of the jobs on
    several threads.

    One level of calls above :func:`_grasp_core`, for compile time: each extra level, and a
    ``prange`` variant, re-optimises the whole linked grasp step (docs/performance.md)."""
    n = tpl.A.shape[1]
    L = tpl.K + 1
    Phi = tpl.Phi.copy()
    Gam = tpl.Gam.copy()
    C = tpl.C.copy()
    D = tpl.D.copy()
    Hg = tpl.H.copy()
    cw = (ContactWork(np.empty((2, n, n)), np.empty((2, n, 3)), np.empty((2, L, n, n)),
                      np.empty((2, L, n, 3))))
    loop = GraspLoop(np.empty((2, 5)), np.empty((2, window)), np.empty((2, 6)), np.empty((2, 7)),
                     np.empty(4),
                     np.empty((2, 5)))
    state = GripperState(np.empty((2, n)), np.empty(2, dtype=np.int64), np.empty(4), np.empty(1))
    work = GripperWork(np.empty(3), np.empty(n), np.empty(MAX_EVENTS_PER_STEP),
                       np.empty(MAX_EVENTS_PER_STEP, dtype=np.int64), np.empty((2, tpl.C.shape[2])))
    rng = np.empty(1, dtype=np.uint64)
    for p in range(parts.shape[0]):
        q = p if noise.shape[0] > 1 else 0
        _job_setup(tpl, parts[p], cps[p, SX.dt], Phi, Gam, C, D, Hg, cw)
        model = GripperModel(tpl.bw, Phi, Gam, C, D, tpl.G, Hg, tpl.target, tpl.ng, tpl.K, parts[p])
        _grasp_core(model, SensorNoise(noise[q], nstd[p], seeds[p]), n_steps, tpl.est, cps[p], mset,
                    loop, state, work, rng, met[p])


@numba.njit(cache=True, parallel=True)
def _setup_jobs(tpl, parts, dt, Phi, Gam, C, D, Hg):  # pragma: no cover - compiled
    """Contact modes of every job into stacks with a leading job index (the GPU path's setup)."""
    n = tpl.A.shape[1]
    L = tpl.K + 1
    for p in prange(parts.shape[0]):
        _job_setup(tpl, parts[p], dt, Phi[p], Gam[p], C[p], D[p], Hg[p],
                   ContactWork(np.empty((2, n, n)), np.empty((2, n, 3)), np.empty((2, L, n, n)),
                               np.empty((2, L, n, 3))))


# ------------------------------------------------------------------------------------------------
# Python side
# ------------------------------------------------------------------------------------------------

class GraspTemplate:
    """What the jobs of one gripper share: the discretised free modes, the fingers' continuous
    matrices for the per-job contact modes, the Bouc-Wen parameters, the estimators (of
    ``estimator_fingers``, default the gripper's own) and the nominal part."""

    def __init__(self, gripper, dt: float, estimator_fingers=None):
        th = gripper.theta()
        names = gripper.parameters.names
        self.names = names
        self.theta = th
        d = gripper.arrays(th[None, :], dt)
        nf = len(FINGER_NAMES)
        A, B0, bF = [], [], []
        for i in range(2):
            ss = finger_state_space(th[i * nf:(i + 1) * nf])
            A.append(ss.A)
            B0.append(ss.B[:, 0])
            bF.append(ss.B[:, 1])
        c = np.ascontiguousarray
        self.A, self.B0, self.bF = c(np.array(A)), c(np.array(B0)), c(np.array(bF))
        self.iy = 4  # y_C in the component-wise state (finger_state_space)
        self.Phi, self.Gam, self.C, self.D = (c(d[k][0]) for k in ("Phi", "Gam", "C", "D"))
        self.G, self.H, self.bw = c(d["G"][0]), c(d["H"][0]), c(d["bw"][0])
        self.target, self.ng, self.K = d["target"], d["ng"], int(d["K"])
        self.part = d["part"][0].copy()
        fingers = estimator_fingers or gripper.fingers
        vals = [_values(f) for f in fingers]
        self.est, _ = _est_stack(vals, dt)
        self.gains = (_static_gain(vals[0]), _static_gain(vals[1]))
        self.dt = float(dt)

    def value(self, name: str) -> float:
        return float(self.theta[self.names.index(name)])

    def kernel_args(self) -> JobTemplate:
        return JobTemplate(self.A, self.B0, self.bF, self.iy, self.Phi, self.Gam, self.C, self.D,
                           self.G, self.H,
                           self.target, self.ng, self.K, self.bw, self.est)


_TEMPLATES: dict = {}
_LOCK = threading.Lock()


def _template(gripper, dt, estimator_fingers) -> GraspTemplate:
    """One template per (gripper, dt, estimator fingers) and process (a sweep's chunks share it)."""
    key = (id(gripper), float(dt), id(estimator_fingers))
    with _LOCK:
        hit = _TEMPLATES.get(key)
        if hit is None or hit[0] is not gripper or hit[1] is not estimator_fingers:
            if len(_TEMPLATES) > 16:
                _TEMPLATES.clear()
            hit = (gripper, estimator_fingers, GraspTemplate(gripper, dt, estimator_fingers))
            _TEMPLATES[key] = hit
    return hit[2]


def _default_gripper():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConsistencyWarning)
        return z.gripper(check=False)
