"""Array-level conversions between state space and transfer functions, minimal realisations and
transmission zeros. The classes in :mod:`._statespace` and :mod:`._transfer` wrap these."""

from __future__ import annotations

import numpy as np

__all__ = ["tf2ss", "ss2tf", "balance", "minreal", "ss_zeros", "MINREAL_TOL"]

_EPS = np.finfo(float).eps
#: Relative rank tolerance of minimal realisations (MATLAB's ``minreal`` default, √ε): a pole and
#: a zero closer than about √ε·‖system‖ are taken to cancel.
MINREAL_TOL = np.sqrt(_EPS)


def _trim_leading(c: np.ndarray) -> np.ndarray:
    nz = np.flatnonzero(c)
    return c[nz[0]:] if nz.size else c[-1:]


def siso_observable_form(num: np.ndarray, den: np.ndarray):
    """Observable canonical form of num/den (descending powers, equal length n+1, den[0] ≠ 0).

    With monic a = den/den[0], b = num/den[0]: ``A = [[-a1, 1, 0, …], [-a2, 0, 1, …], …]``,
    ``B_i = b_{i+1} − a_{i+1} b_0``, ``C = [1, 0, …]``, ``D = b_0``. Its state is that of
    ``scipy.signal.lfilter`` (transposed direct form II), so ``lfiltic`` gives initial states.
    """
    a = den / den[0]
    b = num / den[0]
    n = a.size - 1
    A = np.zeros((n, n), dtype=np.result_type(a, b))
    if n:
        A[:, 0] = -a[1:]
    A[np.arange(n - 1), np.arange(1, n)] = 1.0
    B = (b[1:] - a[1:] * b[0]).reshape(n, 1)
    C = np.zeros((1, n), dtype=A.dtype)
    if n:
        C[0, 0] = 1.0
    return A, B, C, np.array([[b[0]]])


def siso_controllable_form(num: np.ndarray, den: np.ndarray):
    """Controller canonical form of num/den (the realisation of ``scipy.signal.tf2ss``, with the
    same arithmetic): ``A = [[-a1, -a2, …], [1, 0, …], …]``, ``B = e₁``, ``C = b[1:] − b₀ a[1:]``,
    ``D = b₀`` (a = den/den[0], b = num/den[0])."""
    A, B, C, D = siso_observable_form(num, den)
    return A.T.copy(), C.T.copy(), B.T.copy(), D


FORMS = ("observable", "controllable")


def tf2ss(num: np.ndarray, den: np.ndarray, form: str = "observable"):
    """(A, B, C, D) of a (p, m) matrix of SISO transfer functions.

    ``num``, ``den``: shape (p, m, L), descending powers, common length. Each entry becomes a
    canonical block (``form``: observable, the state of ``lfilter``; or controllable, that of
    ``scipy.signal.tf2ss``) of its own degree (leading zeros of its denominator dropped),
    stacked in parallel: x = [x_11; x_12; …], B places block ij on input j, C on output i. The
    result is controllable and observable entry by entry, not necessarily as a whole: call
    :func:`minreal` for a minimal realisation.
    """
    siso = siso_observable_form if form == "observable" else siso_controllable_form
    p, m, _ = num.shape
    blocks = []
    for i in range(p):
        for j in range(m):
            d = den[i, j]
            k = np.flatnonzero(d)[0]
            blocks.append((i, j) + siso(num[i, j, k:], d[k:]))
    n = sum(b[2].shape[0] for b in blocks)
    A = np.zeros((n, n))
    B = np.zeros((n, m))
    C = np.zeros((p, n))
    D = np.zeros((p, m))
    o = 0
    for i, j, Ai, Bi, Ci, Di in blocks:
        q = Ai.shape[0]
        A[o:o + q, o:o + q] = Ai
        B[o:o + q, j] = Bi[:, 0]
        C[i, o:o + q] = Ci[0]
        D[i, j] = Di[0, 0]
        o += q
    return A, B, C, D


def ss2tf(A, B, C, D, minimal: bool = True, tol: float = MINREAL_TOL):
    """``(num, den)`` of shape (p, m, L), descending powers, monic denominators.

    Entry ij: ``den = det(sI − A)`` and ``num = det(sI − A + b_j c_i) + (d_ij − 1) det(sI − A)``
    (the identity scipy's ``ss2tf`` uses). With ``minimal`` each entry is first reduced to its
    own minimal realisation (A, b_j, c_i), so uncontrollable and unobservable modes cancel.
    """
    p, m = D.shape
    entries = []
    for i in range(p):
        for j in range(m):
            a, b, c = A, B[:, j:j + 1], C[i:i + 1]
            if minimal:
                a, b, c, _ = minreal(a, b, c, D[i:i + 1, j:j + 1], tol)
            if a.shape[0] == 0:
                entries.append((D[i, j] * np.ones(1), np.ones(1)))
                continue
            lam, mu = np.linalg.eigvals(a), np.linalg.eigvals(a - b @ c)
            # eigenvalues within the eigen-solver's backward error (10 n ε ‖·‖₁) of the origin are
            # zero (delays: poles at z = 0), so the polynomials get exact trailing zeros
            lam[np.abs(lam) <= 10 * a.shape[0] * _EPS * np.abs(a).sum(0).max()] = 0.0
            mu[np.abs(mu) <= 10 * a.shape[0] * _EPS * np.abs(a - b @ c).sum(0).max()] = 0.0
            den = np.poly(lam).real
            num = np.poly(mu).real + (D[i, j] - 1.0) * den
            # leading coefficients that are zero in exact arithmetic (relative degree) come out as
            # rounding noise of the subtraction: bounded by n ε times the coefficients of
            # Π(s + |λ_i|) and Π(s + |μ_i|); 100× that is taken as zero
            noise = 100 * a.shape[0] * _EPS * (np.poly(-np.abs(lam)).real
                                               + np.poly(-np.abs(mu)).real
                                                * max(1.0, abs(D[i, j] - 1.0)))
            k = 0
            while k < num.size - 1 and abs(num[k]) <= noise[k]:
                num[k] = 0.0
                k += 1
            entries.append((num, den))
    L = max(e[1].size for e in entries)
    num = np.zeros((p, m, L))
    den = np.zeros((p, m, L))
    for k, (nu, de) in enumerate(entries):
        i, j = divmod(k, m)
        num[i, j, L - nu.size:] = nu
        den[i, j, L - de.size:] = de
    return num, den


def _reachable_basis(A, B, tol):
    """Orthonormal basis of the reachable subspace span[B, AB, A²B, …] (block Krylov with
    re-orthogonalisation; a direction counts when its singular value exceeds tol·‖[A B]‖)."""
    n = A.shape[0]
    scale = (max(np.linalg.norm(A, 2) if n else 0.0, np.linalg.norm(B, 2) if B.size else 0.0,
                 np.finfo(float).tiny))
    Q = np.zeros((n, 0))
    blk = B
    while Q.shape[1] < n:
        for _ in range(2):
            blk = blk - Q @ (Q.T @ blk)
        if blk.size == 0:
            break
        U, s, _ = np.linalg.svd(blk, full_matrices=False)
        r = int(np.sum(s > tol * scale))
        if r == 0:
            break
        Q = np.hstack([Q, U[:, :r]])
        blk = A @ U[:, :r]
    return Q


def balance(A, B, C, sweeps: int = 20):
    """A diagonal similarity T = diag(2^k) making each state's row [A_i·, B_i·] and column
    [A_·i; C_·i] of similar size (as MATLAB's ``ssbal``): (T⁻¹AT, T⁻¹B, CT). Rank decisions and
    eigenvalues of badly scaled realisations (a 8.5 kHz mode in SI units) need it."""
    n = A.shape[0]
    A, B, C = A.copy(), B.copy(), C.copy()
    for _ in range(sweeps):
        changed = False
        for i in range(n):
            r = np.abs(A[i]).sum() - abs(A[i, i]) + np.abs(B[i]).sum()
            c = np.abs(A[:, i]).sum() - abs(A[i, i]) + np.abs(C[:, i]).sum()
            if r == 0 or c == 0:
                continue
            f = 2.0 ** np.round(0.5 * np.log2(c / r))
            if f != 1.0:
                A[i] *= f
                B[i] *= f
                A[:, i] /= f
                C[:, i] /= f
                changed = True
        if not changed:
            break
    return A, B, C


def minreal(A, B, C, D, tol: float = MINREAL_TOL):
    """A minimal realisation: balance (:func:`balance`), project onto the reachable subspace,
    then onto the observable one (orthogonal bases, so the kept part is well conditioned)."""
    A, B, C = balance(A, B, C)
    Q = _reachable_basis(A, B, tol)
    A1, B1, C1 = Q.T @ A @ Q, Q.T @ B, C @ Q
    P = _reachable_basis(A1.T, C1.T, tol)
    return P.T @ A1 @ P, P.T @ B1, C1 @ P, D.copy()


def _finite_generalized_eigs(M, N, tol):
    from scipy import linalg  # on first use: scipy.linalg is ~0.2 s of a CLI start-up

    alpha, beta = linalg.eig(M, N, right=False, homogeneous_eigvals=True)
    scale = max(np.linalg.norm(M, 2), 1.0)
    keep = np.abs(beta) * scale > tol * np.abs(alpha)
    return alpha[keep] / beta[keep]


def ss_zeros(A, B, C, D, tol: float = MINREAL_TOL):
    """Transmission zeros: the values z where the system matrix
    ``P(z) = [[A − zI, B], [C, D]]`` of a *minimal* realisation loses rank.

    SISO, relative degree r (first Markov parameter g = C A^{r−1} B ≠ 0, or D ≠ 0 for r = 0):
    the zeros are the eigenvalues of the zero dynamics ``A − B C A^r / g`` restricted to
    ker[C; CA; …; CA^{r−1}] (for r = 0, of ``A − B C / D``). Square MIMO with D invertible:
    eig(A − B D⁻¹ C). Otherwise: the finite generalised eigenvalues of the (squared-down) pencil,
    kept where the full pencil's rank drops below its normal rank.
    """
    A, B, C, D = minreal(A, B, C, D, tol)
    n = A.shape[0]
    p, m = D.shape
    if n == 0:
        return np.zeros(0, dtype=complex)
    scale = (max(np.linalg.norm(A, 2), np.linalg.norm(B, 2), np.linalg.norm(C, 2),
                 np.linalg.norm(D, 2)))
    if p == m:
        sD = np.linalg.svd(D, compute_uv=False)
        if sD.size and sD.min() > tol * scale:
            return np.linalg.eigvals(A - B @ np.linalg.solve(D, C)).astype(complex)
    if p == 1 and m == 1:
        rows = []
        M = C.copy()
        for _r in range(n):
            rows.append(M[0])
            g = float((M @ B)[0, 0])
            if abs(g) > tol * np.linalg.norm(M) * np.linalg.norm(B):
                break
            M = M @ A
        else:
            return np.zeros(0, dtype=complex)
        from scipy import linalg  # on first use (start-up)

        N = linalg.null_space(np.array(rows))
        Azd = N.T @ (A - B @ (M @ A) / g) @ N
        return np.linalg.eigvals(Azd).astype(complex) if Azd.size else np.zeros(0, dtype=complex)
    # MIMO, non-square or singular D: square the pencil down with fixed orthogonal mixes
    rng = np.random.default_rng(0)
    k = min(p, m)
    Wo = np.linalg.qr(rng.standard_normal((p, p)))[0][:k]
    Wi = np.linalg.qr(rng.standard_normal((m, m)))[0][:, :k]
    Ms = np.block([[A, B @ Wi], [Wo @ C, Wo @ D @ Wi]])
    Ns = np.zeros_like(Ms)
    Ns[:n, :n] = np.eye(n)
    cand = _finite_generalized_eigs(Ms, Ns, tol)
    full = np.block([[A, B], [C, D]]).astype(complex)
    s0 = complex(rng.standard_normal(), rng.standard_normal()) * scale
    E = np.zeros_like(full)
    E[:n, :n] = np.eye(n)
    normal_rank = int(np.sum(np.linalg.svd(full - s0 * E, compute_uv=False) > tol * scale))
    zs = []
    for z in cand:
        s = np.linalg.svd(full - z * E, compute_uv=False)
        if s[normal_rank - 1] <= tol * max(s[0], scale):
            zs.append(z)
    return np.array(zs, dtype=complex)
