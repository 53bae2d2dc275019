"""The nearest physically consistent parameters of an inverse-dynamics estimate, in the metric of
its own covariance, and the χ² test built on that distance (:func:`gripkit.sysid.identify_dynamics`,
``check_consistency`` and ``constrained``).

**What is measured, and in which metric.** The data determine only the identified parameters
θ = [φ_b, f]: the r base parameters φ_b = K φ
(:class:`~gripkit.sysid.rigid_body.dynamics.BaseStructure`,
rotor inertias included when identified) and the friction coefficients f. Their estimate θ̂ has
the covariance C; the standard parameters φ (10 per link) do not have one, since the data say
nothing about the directions of null(K), so a distance measured in φ is arbitrary. A
parameter vector θ is *physically consistent* when it belongs to

    S = {(K φ, f) : J_k(φ) ⪰ 0 for every link k, rotor inertias ≥ 0, Coulomb and viscous f ≥ 0}

with J_k = [[½tr(I_k)·1 − I_k, h_k], [h_kᵀ, m_k]] the link's pseudo-inertia (Wensing, Kim &
Slotine 2017: J ⪰ 0 ⇔ m ≥ 0, centre of mass inside the inertia ellipsoid, triangle
inequalities). S is convex: the image of a product of convex cones under a linear map. The
distance of the estimate to it is the Mahalanobis distance in the identified coordinates,

    d² = min_{θ ∈ S} (θ − θ̂)ᵀ C⁻¹ (θ − θ̂),                                            (1)

and its minimiser θ_c is the *constrained estimate*. Since the model is linear in θ, the weighted
residual of the data at any θ is ‖r(θ̂)‖²_W + (θ − θ̂)ᵀ (XᵀWX) (θ − θ̂), and with the white-noise
covariance (``covariance='ols'``) (XᵀWX)⁻¹ = C/σ̂²: (1) is then the weighted least-squares fit on
the data subject to physical consistency, without another pass over the data (Sousa & Cortesão
2014 solve the same problem as an LMI). With the Newey-West covariance (``'hac'``) (1) weighs the
parameters by that covariance, the metric in which the test below holds.

**The test.** Let θ* be the true parameters. If the model is right, θ* ∈ S, and d² ≤ (θ* − θ̂)ᵀ
C⁻¹ (θ* − θ̂) because d² is a minimum over S. With an honest C the right-hand side is χ²
distributed with n degrees of freedom, n = dim θ (the parameters the constraints act on; offsets
are free in S, minimising over them leaves the marginal distribution of the others, so they are
not counted). Hence

    P(d² > χ²_n(1 − α) | θ* ∈ S) ≤ P(χ²_n > χ²_n(1 − α)) = α,

and "inconsistent" (d² > χ²_n(1 − α), α = 0.05) is a test of level at most α of the hypothesis
"some physically consistent parameters explain the data". The p-value reported is
P(χ²_n > d²), an upper bound of the true one for the same reason. d = 0 means the estimate
itself is consistent.

**The constrained estimate is never further from the truth.** θ_c is the projection of θ̂ onto
the closed convex set S_T (S bounded, see *The bound T*) in the norm ‖v‖ = √(vᵀ C⁻¹ v). A
projection onto a convex set containing
θ* is non-expansive towards it: ‖θ_c − θ*‖² ≤ ‖θ̂ − θ*‖² − ‖θ̂ − θ_c‖² (the obtuse-angle
property of projections), for every data set, not only in expectation.

**The solver.** (1) is a semidefinite program. gripkit solves it over the standard parameters
x = [φ, rotor inertias, f] by a log-det barrier method (Boyd & Vandenberghe 2004, §11.3): for
t = t₀, 10 t₀, … it minimises

    t · ½ ‖Cᵢᵀ(A x − θ̂)‖² − Σ_k [log det J_k + log(T − tr J_k)] − Σ_i log s_i          (2)

(A x = θ(x), Cᵢ Cᵢᵀ = C⁻¹, s_i the rotor inertias and the Coulomb and viscous coefficients, each
rotor inertia also below T) by Newton's method with a backtracking line search that stays in the
interior. Each Newton step is an orthogonal least-squares solve with the Hessian's square root
(the data rows √t·Cᵢᵀ A and each link's whitened directions L⁻¹B_iL⁻ᵀ), so its accuracy follows
the condition number of that factor, not of the Hessian; the line search uses the exact
decrease, free of the cancellation of t·f₀ at large t. Each centring stops at a Newton
decrement² ≤ 2·10⁻¹⁰; the central point at t is within ν/t of the minimum of ½d² (ν = 5 per
link + 2 per rotor inertia + 1 per signed friction coefficient, the barrier's parameter), t grows
tenfold until that gap is below 10⁻⁸·max(1, ½d²): converged, and the constrained estimate is
then within √(2·gap) σ of the exact projection. The start is the chain's own standard parameters
with each pseudo-inertia moved inside by 1 % of its scale (any strictly consistent point will do:
the problem is convex). The DLR/HIT finger takes 120–140 Newton steps, about 0.1 s.

**The bound T.** S as written need not be closed: a mass where a link's joint axes meet (the
DLR/HIT proximal phalanx) acts on no torque, yet a large one relaxes that link's J ⪰ 0, so the
infimum of (1) can be approached only as that mass grows without limit. gripkit therefore uses
S_T, S with every link's tr J = m + ½tr(I_o) (kg + kg·m², SI) and every rotor inertia at most
T = 1000 × max(the chain's mean tr J, the largest |θ̂_b|). S_T is closed and convex and holds the
truth of any chain within three orders of magnitude of its model, so the test and the
non-expansion above hold for it exactly; the distance to S_T exceeds the infimum over S by
O(1/T) (2·10⁻⁵ σ on that finger). Where the bound is reached the solver says so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["ProjectionResult", "project_consistent", "pseudo_inertia_basis"]


def pseudo_inertia_basis() -> np.ndarray:
    """B (10, 4, 4) with J(φ) = Σ_i φ_i B_i for one link's standard parameters
    φ = (m, mx, my, mz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz)."""
    B = np.zeros((10, 4, 4))
    B[0, 3, 3] = 1.0
    for i, a in enumerate((0, 1, 2)):
        B[1 + i, a, 3] = B[1 + i, 3, a] = 1.0
    # Σ = ½tr(I)·1 − I with I = [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]
    for i, (a, b) in zip((4, 5, 6, 7, 8, 9), ((0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2))):
        E = np.zeros((3, 3))
        E[a, b] = E[b, a] = 1.0
        B[i, :3, :3] = 0.5 * np.trace(E) * np.eye(3) - E
    return B


_B = pseudo_inertia_basis()
_TRB = np.trace(_B, axis1=1, axis2=2)   # tr J = _TRB · φ


@dataclass(frozen=True)
class ProjectionResult:
    """The solution of (1) (module doc): ``x`` the standard parameters (with rotor inertias and
    friction), ``theta`` = A x, ``distance`` d in σ, ``converged`` (duality gap below the
    tolerance), ``gap`` the final bound on ½d² − its minimum, ``iterations`` (Newton steps),
    ``at_bound`` (the links whose tr J reached the bound T) and ``message``."""

    x: np.ndarray
    theta: np.ndarray
    distance: float
    converged: bool
    gap: float
    iterations: int
    at_bound: np.ndarray
    message: str


class _Barrier:
    """The barrier problem (2) of the module doc, with the Newton step split between the
    directions the data see (the row space of A) and those they do not (its null space), in
    variables scaled by ``D``: the objective's t-weighted Hessian lives on the first only, so
    the two scales never meet in one matrix."""

    def __init__(self, A, Ci, theta_hat, n_links: int, signed: np.ndarray, bounded: np.ndarray,
                 T: float, D: np.ndarray):
        self.G = Ci.T @ A                       # residual r = G x − c
        self.c = Ci.T @ theta_hat
        self.n_links = n_links
        self.signed = signed                    # indices of x that must be > 0
        self.bounded = bounded                  # indices of x that must be < T (rotor inertias)
        self.T = T
        self.nu = 5 * n_links + signed.size + bounded.size
        self.D = D
        _, sv, Vt = np.linalg.svd(A * D, full_matrices=True)
        rank = int(np.sum(sv > 1e-12 * sv[0]))
        self.R, self.N = Vt[:rank].T, Vt[rank:].T
        self.GDR = self.G @ (D[:, None] * self.R)

    def f0(self, x) -> float:
        r = self.G @ x - self.c
        return 0.5 * float(r @ r)

    def feasible(self, x) -> tuple:
        """(feasible, the Cholesky factors (n_links, 4, 4) of the J_k) at x."""
        P = x[:10 * self.n_links].reshape(self.n_links, 10)
        if ((P @ _TRB >= self.T).any() or (x[self.signed] <= 0).any()
                or (x[self.bounded] >= self.T).any()):
            return False, None
        try:
            return True, np.linalg.cholesky(np.einsum("ki,iab->kab", P, _B))
        except np.linalg.LinAlgError:
            return False, None

    def barrier(self, x, Ls) -> float:
        P = x[:10 * self.n_links].reshape(self.n_links, 10)
        logdet = 2.0 * np.log(np.diagonal(Ls, axis1=1, axis2=2)).sum()
        return float(-logdet - np.log(self.T - P @ _TRB).sum() - np.log(x[self.signed]).sum()
                     - np.log(self.T - x[self.bounded]).sum())

    def barrier_grad_hess(self, x, Ls):
        n = self.n_links
        g = np.zeros(x.size)
        H = np.zeros((x.size, x.size))
        P = x[:10 * n].reshape(n, 10)
        Li = np.linalg.inv(Ls)
        Jinv = np.einsum("kba,kbc->kac", Li, Li)                 # J⁻¹ = L⁻ᵀ L⁻¹
        M = np.einsum("kab,ibc->kiac", Jinv, _B)                 # J⁻¹ B_i
        u = 1.0 / (self.T - P @ _TRB)
        g[:10 * n] = (-np.trace(M, axis1=2, axis2=3) + u[:, None] * _TRB).ravel()
        Hb = np.einsum("kiab,kjba->kij", M, M) + (u * u)[:, None, None] * np.outer(_TRB, _TRB)
        for k in range(n):
            H[10 * k:10 * k + 10, 10 * k:10 * k + 10] = Hb[k]
        xs = x[self.signed]
        g[self.signed] -= 1.0 / xs
        H[self.signed, self.signed] += 1.0 / xs ** 2
        ub = 1.0 / (self.T - x[self.bounded])
        g[self.bounded] += ub
        H[self.bounded, self.bounded] += ub ** 2
        return g, H

    def newton(self, x, t, Ls):
        """The Newton step Δ of t·f₀ + barrier at x, its decrement λ² = −∇ᵀΔ, the residual r
        and w = G Δ (f₀(x + aΔ) − f₀(x) = a rᵀw + ½a²wᵀw, free of cancellation).

        The Hessian is FᵀF and the gradient Fᵀh with F the rows √t·G (the data), the whitened
        pseudo-inertia directions vec(L⁻¹ B_i L⁻ᵀ) of each link (tr(J⁻¹B_iJ⁻¹B_j) is their
        inner product, −tr(J⁻¹B_i) their product with −vec(1)), and one row per scalar barrier,
        so Δ = −argmin ‖F Δ + h‖ by an orthogonal least-squares solve on the scaled columns:
        the condition number of F, not its square."""
        n, nx = self.n_links, x.size
        r = self.G @ x - self.c
        P = x[:10 * n].reshape(n, 10)
        Li = np.linalg.inv(Ls)
        Q = np.einsum("kab,ibc,kdc->kiad", Li, _B, Li).reshape(n, 10, 16)   # L⁻¹ B_i L⁻ᵀ
        rows = [np.sqrt(t) * self.G]
        rhs = [np.sqrt(t) * r]
        eye = np.eye(4).ravel()
        u = 1.0 / (self.T - P @ _TRB)
        for k in range(n):
            Fk = np.zeros((17, nx))
            Fk[:16, 10 * k:10 * k + 10] = Q[k].T
            Fk[16, 10 * k:10 * k + 10] = u[k] * _TRB
            rows.append(Fk)
            rhs.append(np.concatenate([-eye, [1.0]]))
        ns, nbd = self.signed.size, self.bounded.size
        Fs = np.zeros((ns + nbd, nx))
        Fs[np.arange(ns), self.signed] = 1.0 / x[self.signed]
        Fs[ns + np.arange(nbd), self.bounded] = 1.0 / (self.T - x[self.bounded])
        rows.append(Fs)
        rhs.append(np.concatenate([-np.ones(ns), np.ones(nbd)]))
        F = np.vstack(rows) * self.D
        h = np.concatenate(rhs)
        dy = -np.linalg.lstsq(F, h, rcond=None)[0]
        lam2 = -float(h @ (F @ dy))
        dx = self.D * dy
        return dx, lam2, r, self.G @ dx


def _centre(pb: _Barrier, x, t, max_steps: int):
    """Newton's method on (2) at t from the interior point x, with a backtracking (Armijo) line
    search on the exact decrease. Returns (x, steps, centred)."""
    ok, Ls = pb.feasible(x)
    B0 = pb.barrier(x, Ls)
    for step in range(1, max_steps + 1):
        dx, lam2, r, w = pb.newton(x, t, Ls)
        if lam2 <= 2e-10:
            return x, step, True
        rw, ww = float(r @ w), float(w @ w)
        a = 1.0
        while a > 1e-10:
            xn = x + a * dx
            ok, Ln = pb.feasible(xn)
            if ok:
                Bn = pb.barrier(xn, Ln)
                if t * (a * rw + 0.5 * a * a * ww) + (Bn - B0) <= -0.01 * a * lam2:
                    break
            a *= 0.5
        else:  # no decrease along the Newton direction: as central as rounding allows
            return x, step, lam2 <= 1e-6
        x, Ls, B0 = xn, Ln, Bn
    return x, max_steps, False


def project_consistent(A, Ci, theta_hat, x_start, n_links: int, signed, bounded, scale: float,
                       *, rel_gap: float = 1e-8, max_newton: int = 600,
                       link_names=None) -> ProjectionResult:
    """Solve (1) of the module doc by the barrier method (2).

    ``A`` maps x (standard parameters of the ``n_links`` links, then rotor inertias, then
    friction) to θ; ``Ci`` is a factor with Ci Ciᵀ = C⁻¹; ``x_start`` a strictly consistent
    point (every J_k ≻ 0, x[signed] > 0); ``signed`` the indices that must stay positive,
    ``bounded`` those also kept below the bound T = 1000 · ``scale`` (at least 10 times the
    start's), which also bounds every link's tr J = m + ½tr(I)."""
    signed = np.asarray(signed, dtype=np.intp)
    bounded = np.asarray(bounded, dtype=np.intp)
    x = np.asarray(x_start, dtype=np.float64).copy()
    T = max(1e3 * scale, 10.0 * float(np.max(np.concatenate(
        [x[:10 * n_links].reshape(n_links, 10) @ _TRB, x[bounded], [0.0]]))))
    pb = _Barrier(A, Ci, theta_hat, n_links, signed, bounded, T, np.ones(x.size))
    ok, Ls = pb.feasible(x)
    if not ok:
        raise ValueError("project_consistent: the start is not strictly consistent")
    # the variables scaled by the barrier's curvature at the start (the data's for the free ones)
    hb = np.diag(pb.barrier_grad_hess(x, Ls)[1])
    hg = np.einsum("ij,ij->j", pb.G, pb.G)
    pb = _Barrier(A, Ci, theta_hat, n_links, signed, bounded, T,
                  1.0 / np.sqrt(np.where(hb > 0, hb, np.where(hg > 0, hg, 1.0))))
    t = pb.nu / max(pb.f0(x), 1.0)
    steps = 0
    while True:
        x, n, centred = _centre(pb, x, t, max_newton - steps)
        steps += n
        gap = pb.nu / t
        if not centred or gap <= rel_gap * max(1.0, pb.f0(x)) or steps >= max_newton:
            break
        t *= 10.0
    d = float(np.sqrt(2.0 * pb.f0(x)))
    converged = bool(centred and gap <= rel_gap * max(1.0, pb.f0(x)))
    # the bound binds where its multiplier 1/(t·slack) times T, what doubling T would gain,
    # exceeds 100 gaps (a direction free of data sits at the analytic centre, slack ≈ T/5: 5/t)
    slack = T - x[:10 * n_links].reshape(n_links, 10) @ _TRB
    at_bound = np.flatnonzero(slack < T / (100.0 * pb.nu))
    msg = (f"log-det barrier (Newton): converged in {steps} steps, duality gap {gap:.2g} on ½d²"
           if converged else
           f"log-det barrier (Newton): stopped after {steps} steps with duality gap {gap:.2g} on "
           f"½d²; the distance is an upper bound")
    if at_bound.size:
        names = list(link_names) if link_names is not None else [str(k) for k in range(n_links)]
        msg += (f"; m + ½tr(I) of link(s) {', '.join(names[k] for k in at_bound)} at the bound "
                f"{T:.3g}: the nearest consistent parameters are approached only as a link's "
                f"mass grows on its joint axis")
    return ProjectionResult(x, A @ x, d, converged, float(gap), steps, at_bound, msg)
