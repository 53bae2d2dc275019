"""Matrix polynomials of a MIMO ARX model and their state-space realisation.

    y(t) + A_1 y(t−1) + … + A_na y(t−na) = B_nk u(t−nk) + … + B_{nk+nb−1} u(t−nk−nb+1) + e(t)

``A`` (na+1, p, p) with ``A[0] = I``, ``B`` (nk+nb, p, m) with ``B[:nk] = 0`` (the layout of
:class:`~gripkit.sysid.linear.polynomial.PolynomialModel`, MATLAB's ``idpoly`` for several
channels). The free parameters are ``θ`` (p, q), q = p·na + m·nb, row i the coefficients of
output i: ``[A_1[i], …, A_na[i], B_nk[i], …, B_{nk+nb−1}[i]]``; a covariance is over
``θ.ravel()`` (output 0's row first).

The realisation has the state x(t) = [y(t−1); …; y(t−na); u(t−1); …; u(t−L)], L = nk + nb − 1
(non-minimal, n = p·na + m·L), and the innovation gain K = [I_p; 0] makes its one-step predictor
the ARX predictor. Its A, B, C, D are affine in θ, so the tangents of the parameter covariance
are exact.
"""

from __future__ import annotations

import numpy as np

from ...lti import StateSpace, Uncertainty

__all__ = ["theta_rows", "realisation", "innovation_gain", "state_space", "prediction_errors"]


def theta_rows(A: np.ndarray, B: np.ndarray, nk: int) -> np.ndarray:
    """``θ`` (p, q) of the matrix polynomials ``A``, ``B`` (see the module docstring)."""
    return np.hstack([*A[1:], *B[nk:]])


def realisation(theta, p: int, m: int, na: int, nb: int, nk: int):
    """(A, B, C, D) of the ARX with coefficient rows ``theta`` (p, q)."""
    L = nk + nb - 1
    n = p * na + m * L
    Ay = theta[:, :p * na]                   # multiplies −y(t−1) … −y(t−na)
    Bu = theta[:, p * na:]                   # multiplies u(t−nk) … u(t−nk−nb+1)
    C = np.zeros((p, n))
    D = np.zeros((p, m))
    C[:, :p * na] = -Ay
    for j in range(nb):
        lag = nk + j
        blk = Bu[:, j * m:(j + 1) * m]
        if lag == 0:
            D += blk
        else:
            C[:, p * na + (lag - 1) * m:p * na + lag * m] += blk
    A = np.zeros((n, n))
    B = np.zeros((n, m))
    if na:
        A[:p] = C
        B[:p] = D
        A[p:p * na, :p * (na - 1)] = np.eye(p * (na - 1))
    if L:
        B[p * na:p * na + m] = np.eye(m)
        A[p * na + m:, p * na:p * na + m * (L - 1)] = np.eye(m * (L - 1))
    return A, B, C, D


def innovation_gain(p: int, n: int, na: int) -> np.ndarray:
    """K = [I_p; 0] (n, p): the realisation's one-step predictor is the ARX predictor."""
    K = np.zeros((n, p))
    if na:
        K[:p] = np.eye(p)
    return K


def state_space(A, B, nk: int, dt: float, covariance, *, inputs, outputs, input_units,
                output_units) -> StateSpace:
    """The realisation of the matrix polynomials as a :class:`gripkit.lti.StateSpace` with the
    channel names and units and, with ``covariance`` (over ``θ.ravel()``), exact tangents."""
    na, p, m = A.shape[0] - 1, A.shape[1], B.shape[2]
    nb = B.shape[0] - nk
    theta = theta_rows(A, B, nk)
    mats = realisation(theta, p, m, na, nb, nk)
    unc = None
    if covariance is not None:
        k = theta.size
        zero = realisation(np.zeros_like(theta), p, m, na, nb, nk)
        tangents = [np.empty((k,) + X.shape) for X in mats]
        for i in range(k):
            e = np.zeros(k)
            e[i] = 1.0
            for t, a, z in zip(tangents, realisation(e.reshape(theta.shape), p, m, na, nb, nk),
                               zero):
                t[i] = a - z
        names = tuple(f"y{i}:θ{j}" for i in range(p) for j in range(theta.shape[1]))
        cov = np.asarray(covariance, dtype=np.float64)
        unc = Uncertainty(names, 0.5 * (cov + cov.T), tuple(tangents))
    return StateSpace(*mats, dt=dt, inputs=list(inputs), outputs=list(outputs),
                      input_units=list(input_units), output_units=list(output_units),
                      uncertainty=unc, meta={"identified_by": "arx (least squares)"})


def prediction_errors(A, B, u, y, start: int) -> np.ndarray:
    """One-step prediction errors ``e(t) = Σ_i A_i y(t−i) − Σ_j B_j u(t−j)``, t = start … N−1
    (shape (N − start, p)): the exact ARX predictor ``ŷ(t|t−1) = y(t) − e(t)``."""
    N = y.shape[0]
    e = y[start:] @ A[0].T
    for i in range(1, A.shape[0]):
        e += y[start - i:N - i] @ A[i].T
    for j in range(B.shape[0]):
        if B[j].any():
            e -= u[start - j:N - j] @ B[j].T
    return e
