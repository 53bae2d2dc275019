"""Shared helpers of the lti tests (imported by name: pytest puts this folder on sys.path):
random well-conditioned systems."""

import numpy as np

EPS = np.finfo(float).eps


def recursion_bound(A, B, C, u, x_max):
    """Bound on the difference of two evaluations of x⁺ = A x + B u, y = C x + D u that round
    differently: a rounding at step k (≤ 4 ε (‖A‖ ‖x‖∞ + ‖B‖ ‖u‖∞) per state) reaches y[n]
    through C A^(n−k), so |Δy| ≤ 4 ε Σ_k ‖C A^k‖ (‖A‖ ‖x‖∞ + ‖B‖ ‖u‖∞) (sums of |entries|)."""
    Ak, h1 = np.eye(A.shape[0]), 0.0
    for _ in range(u.shape[0]):
        h1 += np.abs(C @ Ak).sum()
        Ak = A @ Ak
    return 4 * EPS * h1 * (np.abs(A).sum() * x_max + np.abs(B).sum() * np.abs(u).max())


def random_ss(rng, n, m, p, *, dt=None, pole_radius=(0.3, 3.0), max_angle=None, cond=3.0):
    """A random stable system with prescribed poles and an eigenvector matrix of condition ≤ ~cond.

    Continuous: poles with Re p ∈ −pole_radius, |Im p| ≤ max_angle (rad/s) when given. Discrete:
    poles with |p| ∈ (0.2, 0.9). Returns (A, B, C, D, V) where A = V Λ V⁻¹ in real block form.
    """
    blocks = []
    k = 0
    while k < n:
        if n - k >= 2 and rng.random() < 0.5:
            if dt is None:
                re = -rng.uniform(*pole_radius)
                im = rng.uniform(0.2, max_angle if max_angle else 3.0)
            else:
                r, th = rng.uniform(0.2, 0.9), rng.uniform(0.2, 2.5)
                re, im = r * np.cos(th), r * np.sin(th)
            blocks.append(np.array([[re, im], [-im, re]]))
            k += 2
        else:
            blocks.append(np.array([[-rng.uniform(*pole_radius) if dt is None
                                     else rng.uniform(0.1, 0.9)]]))
            k += 1
    Lam = np.zeros((n, n))
    o = 0
    for b in blocks:
        q = b.shape[0]
        Lam[o:o + q, o:o + q] = b
        o += q
    # V = Q diag(s) with singular values in [1, cond]: κ(V) ≤ cond
    Q = np.linalg.qr(rng.standard_normal((n, n)))[0]
    V = Q @ np.diag(np.linspace(1.0, cond, n))
    A = V @ Lam @ np.linalg.inv(V)
    return (A, rng.standard_normal((n, m)), rng.standard_normal((p, n)),
            rng.standard_normal((p, m)), V)
