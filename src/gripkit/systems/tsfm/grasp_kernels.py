"""The numba kernels behind :mod:`gripkit.systems.tsfm.grasp_batch` (CPU) and
:mod:`gripkit.systems.tsfm.grasp_gpu` (CUDA): per-job contact-mode setup, one grasp reduced to its
metrics on the fly, the job loop, and the per-gripper template the jobs share."""

from __future__ import annotations

import math
import threading
import warnings

import numba
import numpy as np
from numba import prange

from ...errors import ConsistencyWarning
from ...sim.hybrid import MAX_EVENTS_PER_STEP
from ...sim.integrators import zoh_levels_into
from ...sim.noise import normal_draw
from . import parameters as z
from .grasp import _est_stack, _static_gain, _values, grasp_step
from .gripper import FINGER_NAMES, finger_state_space, gripper_advance, gripper_measure

METRICS = ("t_contact1", "t_contact2", "t_squeeze", "peak_force", "damage", "max_displacement", "grasped",
           "lost", "settling_time", "final_error", "final_force", "width_error", "stiffness_error")
_NM = len(METRICS)
_SQUEEZE = 2.0
_PHASE, _CONTACT_T = 0, 6


# ------------------------------------------------------------------------------------------------
# numba kernels
# ------------------------------------------------------------------------------------------------

@numba.njit(cache=True)
def _job_setup(A, B0, bF, iy, part, dt, K, Phi, Gam, C, D, Hg, Ac, Bc, PhiC, GamC):  # pragma: no cover
    """Write the contact mode (index 1) of both fingers for the part ``part`` = [w, gap, k_side,
    c_side, F_po, F_stick] into Phi (2, 2, K+1, n, n), Gam (2, 2, K+1, n, 3), C (2, 2, 4, n),
    D (2, 2, 4, 3), Hg (2, 2, J, 3); the free mode (index 0) is left as it is. Mirrors
    :func:`gripkit.systems.tsfm.gripper.finger_hybrid`: A_c = A + b_F kᵀ (k = k_side at y_C, c_side at
    ẏ_C), B_c = [B_W, −k_side b_F, 0], F_g = kᵀ x − k_side x_face, release at −F_po/k_side."""
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


@numba.njit(cache=True)
def _grasp_core(bw, Phi, Gam, C, D, G, Hg, target, ng, K, part, noise, nstd, seed, n_steps, ebw, ePhi, eGam,
                ecy, cp, mset, det, buf, est, cs, X, modes, hyst, ps, ext, out, ua, xt, ev_frac, ev_to, yout,
                rng, met):  # pragma: no cover - compiled
    """One grasp from rest, reduced to the metrics ``met`` (len(METRICS)); no allocation (every
    work array is passed in, so the function also compiles for CUDA, one job per thread).

    ``noise`` (N, 2): the force-sensor noise per sample when it has rows, else white noise of std
    ``nstd`` from a splitmix64 stream seeded with ``seed``. ``mset`` = [damage_force,
    lost_displacement, band]. The loop is the one of ``_grasp_run`` (two_finger_grasp.py)."""
    dt = cp[15]
    fcmd = cp[3]
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
    x0p = part[6]
    ps[0] = x0p
    rng[0] = np.uint64(seed) * np.uint64(0x2545F4914F6CDD1D) + np.uint64(1)
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
    gripper_measure(X, modes, ps[0], C, D, part, ua, yout)
    for k in range(n_steps):
        if explicit:
            F1 = yout[0, 3] + noise[k, 0]
            F2 = yout[1, 3] + noise[k, 1]
        else:
            F1 = yout[0, 3] + nstd * normal_draw(rng)
            F2 = yout[1, 3] + nstd * normal_draw(rng)
        grasp_step(F1, F2, det, buf, est, ebw, ePhi, eGam, ecy, cs, cp, ext, out)
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
        if t_sq >= 0.0 and abs(fbar - fcmd) > mset[2] * fcmd:
            last_out = k
        if k >= tail:
            sum_f += fbar
            sum_fm += 0.5 * (F1 + F2)
            sum_s += out[0, 1] + out[1, 1]
            n_tail += 1
        if k == n_steps - 1:
            grasped = modes[0] == 1 and modes[1] == 1 and out[0, 4] == _SQUEEZE and out[1, 4] == _SQUEEZE
        gripper_advance(out[0, 0], out[1, 0], X, modes, hyst, ps, bw, Phi, Gam, C, D, G, Hg, target, ng, K, part,
                        ua, xt, ev_frac, ev_to, yout)
    nan = math.nan
    met[0] = t_c1 if t_c1 >= 0.0 else nan
    met[1] = t_c2 if t_c2 >= 0.0 else nan
    met[2] = t_sq if t_sq >= 0.0 else nan
    met[3] = peak
    met[4] = 1.0 if peak > mset[0] else 0.0
    met[5] = maxd
    met[6] = 1.0 if grasped else 0.0
    met[7] = 1.0 if (not grasped or maxd > mset[1]) else 0.0
    if t_sq < 0.0 or last_out == n_steps - 1:
        met[8] = math.inf
    else:
        met[8] = (last_out + 1) * dt - t_sq
        if met[8] < 0.0:
            met[8] = 0.0
    met[9] = (sum_f / n_tail - fcmd) / fcmd
    met[10] = sum_f / n_tail
    if det1 and det2:
        met[11] = part[1] - (y1c + y2c) - part[0]
        delta = sum_s / n_tail - (y1c + y2c)
        met[12] = (sum_fm / n_tail) / delta / (0.5 * part[2]) - 1.0 if (grasped and delta > 0.0) else nan
    else:
        met[11] = nan
        met[12] = nan


@numba.njit(cache=True, nogil=True)
def _grasp_jobs(tA, tB0, tbF, iy, tPhi, tGam, tC, tD, G, tH, target, ng, K, bw, parts, noise, nstd, seeds, n_steps,
                window, ebw, ePhi, eGam, ecy, cps, mset, met):  # pragma: no cover - compiled
    """Jobs one after another on this core (rows of parts, cps, nstd, seeds, met): for each, the
    template's matrices with the contact mode of its part (:func:`_job_setup`), then
    :func:`_grasp_core`. ``noise`` (P, N, 2) explicit noise per job, or (1, 0, 2) for generated
    noise. ``nogil``: :func:`tsfm_grasp_batch` runs slices of the jobs on several threads.

    Compile time (measured, cold cache): one level of calls above :func:`_grasp_core` — each
    extra level, and a ``prange`` variant (+15 s), re-optimises the whole linked grasp step."""
    n = tA.shape[1]
    L = K + 1
    Phi = tPhi.copy()
    Gam = tGam.copy()
    C = tC.copy()
    D = tD.copy()
    Hg = tH.copy()
    Ac, Bc, PhiC, GamC = np.empty((2, n, n)), np.empty((2, n, 3)), np.empty((2, L, n, n)), np.empty((2, L, n, 3))
    det, buf, est, cs = np.empty((2, 5)), np.empty((2, window)), np.empty((2, 6)), np.empty((2, 7))
    X, modes, hyst, ps = np.empty((2, n)), np.empty(2, dtype=np.int64), np.empty(4), np.empty(1)
    ext, out, ua, xt = np.empty(4), np.empty((2, 5)), np.empty(3), np.empty(n)
    ev_frac, ev_to = np.empty(MAX_EVENTS_PER_STEP), np.empty(MAX_EVENTS_PER_STEP, dtype=np.int64)
    yout, rng = np.empty((2, tC.shape[2])), np.empty(1, dtype=np.uint64)
    for p in range(parts.shape[0]):
        q = p if noise.shape[0] > 1 else 0
        _job_setup(tA, tB0, tbF, iy, parts[p], cps[p, 15], K, Phi, Gam, C, D, Hg, Ac, Bc, PhiC, GamC)
        _grasp_core(bw, Phi, Gam, C, D, G, Hg, target, ng, K, parts[p], noise[q],
                    nstd[p], seeds[p], n_steps, ebw, ePhi, eGam, ecy, cps[p], mset, det, buf, est, cs, X, modes,
                    hyst, ps, ext, out, ua, xt, ev_frac, ev_to, yout, rng, met[p])


@numba.njit(cache=True, parallel=True)
def _setup_jobs(tA, tB0, tbF, iy, parts, dt, K, Phi, Gam, C, D, Hg):  # pragma: no cover - compiled
    """Contact modes of every job into stacks with a leading job index (the GPU path's setup)."""
    n = tA.shape[1]
    L = K + 1
    for p in prange(parts.shape[0]):
        _job_setup(tA, tB0, tbF, iy, parts[p], dt, K, Phi[p], Gam[p], C[p], D[p], Hg[p], np.empty((2, n, n)),
                   np.empty((2, n, 3)), np.empty((2, L, n, n)), np.empty((2, L, n, 3)))


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
        e, _ = _est_stack(vals, dt)
        self.est = (e["bw"], e["Phi"], e["Gam"], e["cy"])
        self.gains = (_static_gain(vals[0]), _static_gain(vals[1]))
        self.dt = float(dt)

    def value(self, name: str) -> float:
        return float(self.theta[self.names.index(name)])

    def kernel_args(self) -> tuple:
        return (self.A, self.B0, self.bF, self.iy, self.Phi, self.Gam, self.C, self.D, self.G, self.H, self.target,
                self.ng, self.K, self.bw)


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
