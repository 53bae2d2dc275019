"""Fixed-step integrators as scalar numba steps, and exact zero-order-hold discretisation.

Three ways to advance a model by one step h, chosen by what the model is:

* **RK4** (:func:`rk4_lti_step`, :func:`rk4_msd_step`): 4th-order Runge-Kutta, for smooth
  nonlinear parts. Stable for ω h < 2.83 on lightly damped modes, but it adds numerical damping
  ≈ (ω h)^6/144 per step, so a mode must be sampled finely (see :mod:`gripkit.sim.steps`).
* **Semi-implicit (symplectic) Euler** (:func:`semi_implicit_msd_step`): for a mass-spring-damper
  m ẍ + b ẋ + k x = F,

      v⁺ = (v + h (F − k x)/m) / (1 + h b/m),     x⁺ = x + h v⁺.

  Without damping this is the symplectic Euler map: it keeps a modified energy
  E_h = ½ m v² + ½ k x² − ½ h k x v within O(h) for ever (no drift), which is what lightly damped
  mechanical parts need over long runs; the damping is taken implicitly so it never destabilises.
  Stable for ω h < 2, first-order accurate.
* **Exact ZOH** (:func:`zoh_levels`, :func:`lti_step`): a linear part with inputs held over the
  step advances exactly, x⁺ = Φ x + Γ u with Φ = e^{A h}, Γ = ∫₀ʰ e^{A s} ds B, whatever ω h is.
  :func:`zoh_levels` also returns the matrices of the dyadic sub-steps h/2, h/4, … h/2^K that
  :mod:`gripkit.sim.hybrid` uses to locate contact events inside a step.

All numba functions here are module-level, allocation-free and take work arrays from the
caller, so kernels can call them in their inner loops (and they would compile for numba.cuda).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ..errors import ModelError
from ..lti import flush_tiny
from .steps import check_step

__all__ = ["rk4_lti_step", "rk4_msd_step", "semi_implicit_msd_step", "lti_step", "zoh_levels",
           "zoh_levels_into",
           "expm_small", "integrate_lti", "modes_of"]


@numba.njit(cache=True, inline="always")
def lti_rhs(A, B, x, u, out):  # pragma: no cover - compiled
    """out = A x + B u: the right-hand side ẋ of a linear system, and any other affine map of a
    state and an input (a ZOH step Φ x + Γ u, an output C x + D u)."""
    n = A.shape[1]
    m = B.shape[1]
    for i in range(A.shape[0]):
        acc = 0.0
        for j in range(n):
            acc += A[i, j] * x[j]
        for j in range(m):
            acc += B[i, j] * u[j]
        out[i] = acc


@numba.njit(cache=True)
def rk4_lti_step(A, B, x, u, h, k1, k2, k3, k4, tmp):  # pragma: no cover - compiled
    """One classical RK4 step of ẋ = A x + B u (u held), in place on ``x``; k1..k4, tmp: work (n,).
    Entries of x below 1e-280 are carried as zero (:func:`gripkit.lti.flush_tiny`)."""
    n = x.shape[0]
    lti_rhs(A, B, x, u, k1)
    for i in range(n):
        tmp[i] = x[i] + 0.5 * h * k1[i]
    lti_rhs(A, B, tmp, u, k2)
    for i in range(n):
        tmp[i] = x[i] + 0.5 * h * k2[i]
    lti_rhs(A, B, tmp, u, k3)
    for i in range(n):
        tmp[i] = x[i] + h * k3[i]
    lti_rhs(A, B, tmp, u, k4)
    for i in range(n):  # entries below 1e-280 carried as zero (gripkit.lti.flush_tiny)
        x[i] = flush_tiny(x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))


@numba.njit(cache=True)
def rk4_msd_step(x, v, F, m, b, k, h):  # pragma: no cover - compiled
    """One RK4 step of m ẍ + b ẋ + k x = F (F held); returns (x⁺, v⁺)."""
    a1 = (F - b * v - k * x) / m
    x2 = x + 0.5 * h * v
    v2 = v + 0.5 * h * a1
    a2 = (F - b * v2 - k * x2) / m
    x3 = x + 0.5 * h * v2
    v3 = v + 0.5 * h * a2
    a3 = (F - b * v3 - k * x3) / m
    x4 = x + h * v3
    v4 = v + h * a3
    a4 = (F - b * v4 - k * x4) / m
    return (x + h / 6.0 * (v + 2.0 * v2 + 2.0 * v3 + v4),
            v + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4))


@numba.njit(cache=True)
def semi_implicit_msd_step(x, v, F, m, b, k, h):  # pragma: no cover - compiled
    """Semi-implicit (symplectic) Euler step of m ẍ + b ẋ + k x = F; returns (x⁺, v⁺)."""
    v1 = (v + h * (F - k * x) / m) / (1.0 + h * b / m)
    return x + h * v1, v1


@numba.njit(cache=True, inline="always")
def lti_step(Phi, Gam, x, u, xt):  # pragma: no cover - compiled
    """Exact ZOH step x ← Φ x + Γ u (``xt``: work array (n,)); entries below 1e-280 are carried as
    zero (:func:`gripkit.lti.flush_tiny`: an unforced response would otherwise sink into the
    subnormal range, slow on Intel CPUs; outputs of order one are unchanged)."""
    lti_rhs(Phi, Gam, x, u, xt)
    for i in range(x.shape[0]):
        x[i] = flush_tiny(xt[i])


@numba.njit(cache=True)
def _matmul(X, Y, out):  # pragma: no cover - compiled
    n = X.shape[0]
    for i in range(n):
        for j in range(n):
            acc = 0.0
            for k in range(n):
                acc += X[i, k] * Y[k, j]
            out[i, j] = acc


@numba.njit(cache=True)
def _balance(M, d):  # pragma: no cover - compiled
    """M ← D⁻¹ M D with D = diag(d), powers of 2 making rows and columns of similar size
    (LAPACK's gebal scaling). Mechanical states in SI (m next to m/s at kHz) differ by 1e4–1e9."""
    n = M.shape[0]
    for i in range(n):
        d[i] = 1.0
    done = False
    while not done:
        done = True
        for i in range(n):
            c = 0.0
            r = 0.0
            for j in range(n):
                if j != i:
                    c += abs(M[j, i])
                    r += abs(M[i, j])
            if c == 0.0 or r == 0.0:
                continue
            total = c + r
            f = 1.0
            while c < r / 2.0:
                f *= 2.0
                c *= 4.0
            while c >= r * 2.0:
                f /= 2.0
                c /= 4.0
            if (c + r) / f < 0.95 * total:
                done = False
                d[i] *= f
                for j in range(n):
                    M[i, j] /= f
                    M[j, i] *= f


@numba.njit(cache=True)
def expm_small(M, out):  # pragma: no cover - compiled
    """e^M for a small square matrix: diagonal balancing (:func:`_balance`), then scaling and
    squaring around a degree-16 Taylor polynomial (‖M/2^s‖₁ ≤ 1/2, truncation < 0.5^17/17! ≈
    2e-20 relative). No BLAS: scipy's expm calls BLAS for every product, which on small matrices
    costs more than the arithmetic (docs/performance.md); agrees with scipy to ~1e-14 (tested)."""
    n = M.shape[0]
    Mb = M.copy()
    d = np.empty(n)
    _balance(Mb, d)
    M = Mb
    norm = 0.0
    for j in range(n):
        c = 0.0
        for i in range(n):
            c += abs(M[i, j])
        norm = max(norm, c)
    s = 0
    if norm > 0.5:
        s = int(math.ceil(math.log2(norm / 0.5)))
    scale = 2.0 ** (-s)
    A = np.empty((n, n))
    R = np.empty((n, n))
    T = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            A[i, j] = M[i, j] * scale
            R[i, j] = 1.0 if i == j else 0.0
    for k in range(16, 0, -1):  # Horner: R = I + A R / k
        _matmul(A, R, T)
        for i in range(n):
            for j in range(n):
                R[i, j] = T[i, j] / k + (1.0 if i == j else 0.0)
    for _ in range(s):
        _matmul(R, R, T)
        R[:, :] = T
    for i in range(n):
        for j in range(n):
            out[i, j] = d[i] * R[i, j] / d[j]


@numba.njit(cache=True)
def zoh_levels_into(A, B, dt, levels, Phi, Gam):  # pragma: no cover - compiled
    """Kernel of :func:`zoh_levels`, writing into preallocated arrays (callable from other kernels):
    stacks A (P, n, n), B (P, n, m) → Phi (P, L+1, n, n), Gam (P, L+1, n, m). The full step
    (level L, used at every sample) is one expm of the augmented matrix; the finer levels (used
    only to locate events inside a step) come from the finest one by squaring, e^{2Mh} =
    (e^{Mh})²."""
    P, n, m = B.shape[0], B.shape[1], B.shape[2]
    M = np.zeros((n + m, n + m))
    E = np.empty((n + m, n + m))
    T = np.empty((n + m, n + m))
    for p in range(P):
        for top in (True, False):
            h = dt if top else dt * 2.0 ** (-levels)
            M[:, :] = 0.0
            for i in range(n):
                for j in range(n):
                    M[i, j] = A[p, i, j] * h
                for j in range(m):
                    M[i, n + j] = B[p, i, j] * h
            expm_small(M, E)
            for lev in range(levels + 1) if not top else range(levels, levels + 1):
                if not top and lev > 0:
                    _matmul(E, E, T)
                    E[:, :] = T
                if not top and lev == levels:
                    break  # the full step is the direct exponential
                for i in range(n):
                    for j in range(n):
                        Phi[p, lev, i, j] = E[i, j]
                    for j in range(m):
                        Gam[p, lev, i, j] = E[i, n + j]


def zoh_levels(A: np.ndarray, B: np.ndarray, dt: float,
               levels: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Exact ZOH matrices for the steps dt·2^(j−levels), j = 0..levels.

    ``A`` (..., n, n) and ``B`` (..., n, m) may be stacks (one system per leading index).
    Returns Φ (..., levels+1, n, n) and Γ (..., levels+1, n, m); index ``levels`` is the full
    step ``dt``: one matrix exponential of the augmented [[A, B], [0, 0]]·dt (Van Loan) by
    :func:`expm_small` (≈1e-15 relative); the finer levels square up from the finest (≈1e-13).
    """
    A = np.asarray(A, dtype=np.float64)
    B = np.asarray(B, dtype=np.float64)
    if A.shape[-1] != A.shape[-2] or B.shape[-2] != A.shape[-1] or A.shape[:-2] != B.shape[:-2]:
        raise ModelError("zoh_levels: A must be (..., n, n) and B (..., n, m) with "
                         "the same leading "
                         f"shape, found {A.shape} and {B.shape}")
    if not (np.isfinite(dt) and dt > 0):
        raise ModelError(f"dt: expected a positive sample time, found {dt!r}")
    if not (np.isfinite(A).all() and np.isfinite(B).all()):
        raise ModelError("zoh_levels: A or B contains NaN or inf")
    if not 0 <= int(levels) <= 40:
        raise ModelError(f"levels: expected 0..40, found {levels!r}")
    lead = A.shape[:-2]
    n, m = B.shape[-2], B.shape[-1]
    A2 = np.ascontiguousarray(A.reshape(-1, n, n))
    B2 = np.ascontiguousarray(B.reshape(-1, n, m))
    Phi = np.empty((A2.shape[0], levels + 1, n, n))
    Gam = np.empty((A2.shape[0], levels + 1, n, m))
    zoh_levels_into(A2, B2, float(dt), int(levels), Phi, Gam)
    return Phi.reshape(lead + Phi.shape[1:]), Gam.reshape(lead + Gam.shape[1:])


@numba.njit(cache=True)
def _integrate_lti(A, B, Phi, Gam, u, h, substeps, method, x, y, C,
                   D):  # pragma: no cover - compiled
    n = A.shape[0]
    m = B.shape[1]
    p = C.shape[0]
    k1 = np.empty(n)
    k2 = np.empty(n)
    k3 = np.empty(n)
    k4 = np.empty(n)
    tmp = np.empty(n)
    ui = np.empty(m)
    yk = np.empty(p)
    for t in range(u.shape[0]):
        for j in range(m):
            ui[j] = u[t, j]
        lti_rhs(C, D, x, ui, yk)
        for i in range(p):
            y[t, i] = yk[i]
        if method == 0:
            lti_step(Phi, Gam, x, ui, tmp)
        else:
            for _ in range(substeps):
                rk4_lti_step(A, B, x, ui, h, k1, k2, k3, k4, tmp)


def modes_of(A: np.ndarray) -> list[tuple[float, float]]:
    """(ω_n rad/s, ζ) of each eigenvalue of A (one entry per complex pair; zero eigenvalues
    skipped)."""
    out = []
    for lam in np.linalg.eigvals(np.asarray(A, dtype=np.float64)):
        if lam.imag < 0 or abs(lam) == 0:
            continue
        out.append((float(abs(lam)), float(-lam.real / abs(lam))))
    return out


def integrate_lti(A, B, C, D, u, dt: float, x0=None, *, method: str = "zoh",
                  substeps: int = 1) -> np.ndarray:
    """Outputs (N, p) of ẋ = A x + B u, y = C x + D u for inputs ``u`` (N, m) held over each
    sample ``dt``: ``method='zoh'`` (exact) or ``'rk4'`` with ``substeps`` RK4 steps per sample."""
    A, B, C, D = (np.atleast_2d(np.asarray(v, dtype=np.float64)) for v in (A, B, C, D))
    u2 = np.asarray(u, dtype=np.float64).reshape(len(u), -1)
    x = np.zeros(A.shape[0]) if x0 is None else np.array(x0, dtype=np.float64)
    if method not in ("zoh", "rk4"):
        raise ModelError(f"method: expected 'zoh' or 'rk4', found {method!r}")
    # refuse an unstable step, warn on an under-resolved mode (gripkit.sim.steps)
    if method == "rk4":
        check_step(dt / substeps, modes_of(A), "rk4", what="integrate_lti")
    Phi, Gam = zoh_levels(A, B, dt, 0) if method == "zoh" else (np.eye(A.shape[0])[None], B[None])
    y = np.empty((u2.shape[0], C.shape[0]))
    _integrate_lti(A, B, Phi[0], Gam[0], np.ascontiguousarray(u2), dt / substeps, int(substeps),
                   0 if method == "zoh" else 1, x, y, C, D)
    return y
