"""Array-level c2d/d2c: zero-order hold, first-order hold and Tustin (with optional prewarp).

Continuous ẋ = A x + B u, y = C x + D u; discrete x[k+1] = Φ x[k] + Γ u[k], y[k] = C_d x[k] + D_d
u[k].

* ZOH (u held over each step; Van Loan):  ``expm([[A, B], [0, 0]]·dt) = [[Φ, Γ], [0, I]]``,
  C_d = C, D_d = D. Inverse: ``logm`` of the same block matrix, which exists (real) when no pole
  of Φ lies on the closed negative real axis.
* FOH (u interpolated linearly between samples, the triangle hold of Franklin–Powell §6.3.2):
  ``expm([[A dt, B dt, 0], [0, 0, I], [0, 0, 0]]) = [[Φ, Γ₁, Γ₂], …]``,
  ``Γ = Γ₁ − Γ₂ + Φ Γ₂``, ``C_d = C``, ``D_d = D + C Γ₂``. Inverse: A from logm Φ, then B from
  the linear relation Γ = (M₁ − M₂ + Φ M₂) B, D = D_d − C M₂ B (M₁, M₂: the blocks for B = I).
* Tustin (bilinear) ``s = (2/T)(z − 1)/(z + 1)``, with prewarp at ω_p: T = 2 tan(ω_p dt/2)/ω_p
  so the response matches exactly at ω_p. With E = I − (T/2) A:
  ``Φ = E⁻¹ (I + (T/2) A)``, ``Γ = E⁻¹ B T``, ``C_d = C E⁻¹``, ``D_d = D + (T/2) C E⁻¹ B``
  (scipy's ``cont2discrete(method='bilinear')`` realisation).
"""

from __future__ import annotations

import numpy as np

from ..errors import ModelError

__all__ = ["METHODS", "c2d_matrices", "d2c_matrices", "tustin_step"]

METHODS = ("zoh", "foh", "tustin")


def check_method(method: str, prewarp) -> str:
    m = {"bilinear": "tustin"}.get(method, method)
    if m not in METHODS:
        raise ModelError(f"method: expected one of {', '.join(METHODS)}, found {method!r}")
    if prewarp is not None and m != "tustin":
        raise ModelError(f"prewarp applies to the Tustin method only, found method={method!r}")
    return m


def tustin_step(dt: float, prewarp) -> float:
    """The equivalent step T of a (prewarped) bilinear map: dt, or 2 tan(ω_p dt/2)/ω_p."""
    if prewarp is None:
        return dt
    w = float(prewarp)
    if not (np.isfinite(w) and 0 < w < np.pi / dt):
        raise ModelError(f"prewarp: expected a frequency in (0, π/dt = {np.pi / dt:.6g}) rad/s, "
                         f"found {prewarp!r}")
    return 2.0 * np.tan(w * dt / 2.0) / w


def _foh_blocks(A, B, dt):
    n, m = B.shape
    M = np.zeros((n + 2 * m, n + 2 * m))
    M[:n, :n] = A * dt
    M[:n, n:n + m] = B * dt
    M[n:n + m, n + m:] = np.eye(m)
    from scipy import linalg  # on first use: scipy.linalg is ~0.2 s of a CLI start-up

    E = linalg.expm(M)
    return E[:n, :n], E[:n, n:n + m], E[:n, n + m:]


def c2d_matrices(A, B, C, D, dt: float, method: str = "zoh", prewarp=None):
    """Discrete (Φ, Γ, C_d, D_d) of continuous (A, B, C, D) at ``dt`` (s), by ``method``
    (``'zoh'``, ``'foh'``, ``'tustin'``; equations in the module docstring). Array level, for
    kernels and batch code; systems use :meth:`gripkit.lti.LinearSystem.c2d`.

    Examples
    --------
    >>> import numpy as np
    >>> Phi, Gam, _, _ = c2d_matrices(np.array([[-1.0]]), np.array([[1.0]]), np.eye(1),
    ...                               np.zeros((1, 1)), 0.1)
    >>> round(float(Phi[0, 0]), 6), round(float(Gam[0, 0]), 6)      # e^{-0.1}, 1 − e^{-0.1}
    (0.904837, 0.095163)
    """
    method = check_method(method, prewarp)
    n, m = B.shape
    if method == "zoh":
        from scipy import linalg  # on first use: scipy.linalg is ~0.2 s of a CLI start-up

        M = np.zeros((n + m, n + m))
        M[:n, :n] = A * dt
        M[:n, n:] = B * dt
        E = linalg.expm(M)
        return E[:n, :n], E[:n, n:], C, D
    if method == "foh":
        Phi, G1, G2 = _foh_blocks(A, B, dt)
        return Phi, G1 - G2 + Phi @ G2, C, D + C @ G2
    T = tustin_step(dt, prewarp)
    E = np.eye(n) - 0.5 * T * A
    _check_invertible(E, "Tustin c2d: I − (T/2) A", "a pole at s = 2/T")
    Phi = np.linalg.solve(E, np.eye(n) + 0.5 * T * A)
    G = np.linalg.solve(E, B * T)
    Cd = np.linalg.solve(E.T, C.T).T
    return Phi, G, Cd, D + 0.5 * T * C @ np.linalg.solve(E, B)


def _check_invertible(M, what, meaning):
    if M.size == 0:
        return
    s = np.linalg.svd(M, compute_uv=False)
    # the solve loses all digits when σ_min/σ_max approaches ε·n
    if s[-1] <= M.shape[0] * np.finfo(float).eps * s[0]:
        raise ModelError(f"{what} is singular: the system has {meaning}")


def _real_logm(M, what):
    ev = np.linalg.eigvals(M)
    bad = ev[(np.abs(ev.imag) <= 1e-12 * np.maximum(np.abs(ev), 1.0)) & (ev.real <= 0)]
    if bad.size:
        raise ModelError(f"{what}: a pole at z = {bad[0].real:.6g} lies on the closed "
                         "negative real axis, "
                         "where no continuous-time pole maps to under sampling",
                         hint="use method='tustin', or identify at a sample rate where "
                              "no pole sits at "
                              "or beyond Nyquist")
    from scipy import linalg  # on first use (start-up)

    L = linalg.logm(M)
    if np.iscomplexobj(L):
        if np.abs(L.imag).max() > 1e-9 * max(np.abs(L).max(), 1.0):
            raise ModelError(f"{what}: the matrix logarithm is not real")
        L = L.real
    return L


def d2c_matrices(Ad, Bd, Cd, Dd, dt: float, method: str = "zoh", prewarp=None):
    """Continuous (A, B, C, D) whose ``c2d_matrices(…, dt, method)`` is (Φ, Γ, C_d, D_d).

    Examples
    --------
    >>> import numpy as np
    >>> A, B, _, _ = d2c_matrices(np.array([[np.exp(-0.1)]]), np.array([[1 - np.exp(-0.1)]]),
    ...                           np.eye(1), np.zeros((1, 1)), 0.1)
    >>> round(float(A[0, 0]), 12), round(float(B[0, 0]), 12)
    (-1.0, 1.0)
    """
    method = check_method(method, prewarp)
    n, m = Bd.shape
    if method == "zoh":
        M = np.zeros((n + m, n + m))
        M[:n, :n] = Ad
        M[:n, n:] = Bd
        M[n:, n:] = np.eye(m)
        L = _real_logm(M, "d2c (zoh)") / dt
        return L[:n, :n], L[:n, n:], Cd, Dd
    if method == "foh":
        A = _real_logm(Ad, "d2c (foh)") / dt
        Phi, M1, M2 = _foh_blocks(A, np.eye(n), dt)
        K = M1 - M2 + Phi @ M2
        _check_invertible(K, "d2c (foh): the input map", "no FOH preimage")
        B = np.linalg.solve(K, Bd)
        return A, B, Cd, Dd - Cd @ M2 @ B
    T = tustin_step(dt, prewarp)
    P = Ad + np.eye(n)
    _check_invertible(P, "Tustin d2c: Φ + I", "a pole at z = −1")
    Pinv = np.linalg.inv(P)
    A = (2.0 / T) * (Ad - np.eye(n)) @ Pinv
    B = (2.0 / T) * Pinv @ Bd
    C = 2.0 * Cd @ Pinv
    return A, B, C, Dd - 0.5 * T * Cd @ B
