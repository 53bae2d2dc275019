"""Multi-joint inverse-dynamics identification (IDIM-LS on all joints of a chain), with base
parameters, per-joint friction, uncertainties and a physical-consistency check.

The model (Khalil & Dombre, *Modeling, Identification and Control of Robots*, ch. 12; Gautier &
Khalil 1990 for the base parameters; Wensing, Kim & Slotine 2017 for consistency):

    τ = Y(q, q̇, q̈) φ + diag(I_a) q̈ + F_c ∘ sign(q̇) + F_v ∘ q̇ (+ τ₀)          (per actuated joint)

with φ the standard inertial parameters of every link (:mod:`gripkit.multibody.regressor`),
I_a optional rotor inertias (``armature=True``) and per-joint Coulomb F_c, viscous F_v and offset
τ₀ friction.

**Base parameters.** Not every column of Y is independent: some are zero (a link that cannot move
a parameter), some are combinations of others (parameters that only act together). The structure
is found from the model alone, on random states. The rank r comes from the QR decomposition with
column pivoting (|R_kk| above 1e-9·|R_00|). Which r columns stand for the others is then chosen
in a fixed order — proximal links first, within a link the inertias before the first moments
before the mass (Khalil's regrouping), rotor inertias last — keeping a column when it is not in the
span of those before it (|R_kk| of the QR in that order against the column's norm): equal columns
(the DLR/HIT finger has four) would otherwise be picked by rounding, and the names with them. With
Y₁ the kept columns and Y₂ = Y₁ β (least squares, exact here), Y φ = Y₁ (φ₁ + β φ₂) = Y₁ φ_b.
Each base parameter is named as the combination it stands for
(``Izz_link3 + 0.003·m_link4 + ...``).

**Estimation.** Weighted least squares on the stacked rows (sample, joint) of [Y₁, friction
columns]; each joint's rows are weighted by 1/σ̂ⱼ² from a first pass (Gautier & Poignet 2001), so
joints with different noise levels count by their noise, times the user's ``weights``.
Cov = σ̂² (XᵀWX)⁻¹, σ̂² = rᵀWr/(N_rows − p) (``covariance="ols"``, white noise), or the Newey-West
covariance of :func:`gripkit.sysid.regression.hac_covariance` for filtered, differentiated or
decimated logs (``covariance="hac"``).

**Physical consistency** (:mod:`gripkit.sysid.rigid_body.dynamics_projection`, where it is
derived). A base-parameter estimate is physically consistent when some standard parameters reproduce
it with every link's pseudo-inertia

    J = [[½tr(I_o)·1 − I_o, h], [hᵀ, m]]   positive semidefinite

(positive mass, centre of mass inside the inertia ellipsoid, triangle inequality), rotor
inertias and Coulomb and viscous friction ≥ 0. The distance of the estimate θ̂ to that convex
set is measured where the data put a covariance, in the identified parameters (base parameters
and friction): d² = min (θ − θ̂)ᵀ Cov⁻¹ (θ − θ̂) over consistent θ, found by a log-det barrier
method (converged to a duality gap of 1e-8 of ½d², with its status reported). Since the true
parameters are consistent, d² is at most their own χ²-distributed distance, so "inconsistent"
is the test d² > χ²_n(0.95) (n identified parameters, offsets excluded), of level at most 5 %.
First, though, the standard parameters that keep the chain's own values for what the data cannot
see are tried: if every link is consistent there, so is the estimate (d = 0), without a search.
The failing links are those whose pseudo-inertia is indefinite there (or, if none, those on the
boundary at the nearest consistent parameters). "Those standard parameters" are the least change
from the chain's own values (each parameter relative to its size, so a massless link stays
massless) that reproduces the estimate. ``constrained=True`` returns the nearest consistent
parameters as the estimate: for a linear model the weighted least-squares fit on the data
subject to consistency, without another pass over it, and never further from the truth than the
unconstrained estimate in the same metric (a projection onto a convex set holding the truth).
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from scipy.linalg import qr

from ...arguments import entry_point
from ...errors import (AccuracyWarning, DataError, IdentificationError, ModelError,
                      UnidentifiableError, emit_warning)
from ...multibody import from_urdf
from ..checks import as_io_matrix
from .dynamics_file import float_array, read_dynamics_document, save_dynamics_model
from .dynamics_projection import project_consistent
from ..regression import hac_covariance

__all__ = (["identify_dynamics", "DynamicsResult", "base_structure", "BaseStructure",
            "load_dynamics_model"])

FRICTION_MODELS = {"none": (), "coulomb-viscous": ("coulomb", "viscous"),
                   "coulomb-viscous-offset": ("coulomb", "viscous", "offset")}


@dataclass(frozen=True)
class BaseStructure:
    """The base parameters of a chain: φ_b = φ[independent] + β φ[dependent] (module doc)."""

    independent: np.ndarray   # column indices (r,)
    dependent: np.ndarray     # column indices (p − r,)
    beta: np.ndarray          # (r, p − r)
    names: tuple              # (r,) combination names
    standard_names: tuple     # (p,)

    @property
    def matrix(self) -> np.ndarray:
        """K (r × p) with φ_b = K φ."""
        K = np.zeros((self.independent.size, len(self.standard_names)))
        K[np.arange(self.independent.size), self.independent] = 1.0
        K[:, self.dependent] = self.beta
        return K

    def base(self, phi) -> np.ndarray:
        return self.matrix @ np.asarray(phi, dtype=np.float64)


def _combination_name(names, i, dep, beta_row) -> str:
    s = names[i]
    for j, b in zip(dep, beta_row):
        if b == 0.0:
            continue
        s += f" {'+' if b > 0 else '-'} {abs(b):.6g}·{names[j]}"
    return s


def base_structure(chain, *, armature: bool = False, seed: int = 0,
                   tol: float = 1e-9) -> BaseStructure:
    """Base parameters of ``chain`` from its regressor on random states (module doc); with
    ``armature`` a rotor-inertia column per actuated joint joins the standard parameters."""
    rng = np.random.default_rng(seed)
    m = chain.dof
    names = list(chain.parameter_names)
    if armature:
        names += [f"armature_{j}" for j in chain.coordinate_names]
    p = len(names)
    B = max(20, 4 * p // m + 10)
    q = rng.uniform(-math.pi, math.pi, (B, m))
    qd = rng.normal(size=(B, m))
    qdd = rng.normal(size=(B, m))
    # columns in comparable units: parameter k times Lᵏ (k = 0 mass, 1 first moment, 2 inertia,
    # armature) with L the chain's size, so the rank tests below hold for 30 µm links as for 1 m
    scale = _column_scale(chain, p)
    X = _inertial_columns(chain, q, qd, qdd, armature).reshape(B * m, p) * scale
    # greedy in a fixed order (module doc): a column is independent when it is not in the span of
    # the columns before it, |R_kk| of the QR in that order against its norm
    link = np.array([k // 10 if k < 10 * (p // 10) else -1 for k in range(p)])
    order = (np.array(sorted(range(p), key=lambda k: (link[k],
                                                      -(k % 10)) if link[k] >= 0 else (p, k))))
    norms = np.linalg.norm(X, axis=0)
    R = qr(X[:, order], mode="r")[0]
    d = np.abs(np.diag(R))
    live = norms[order] > 1e-10 * norms.max() if norms.max() > 0 else np.zeros(p, dtype=bool)
    is_ind = live & (d > tol * np.maximum(norms[order], 1e-300))
    _, Rp, piv = qr(X, mode="economic", pivoting=True)
    dp = np.abs(np.diag(Rp))
    rank = int(np.sum(dp > tol * dp[0])) if dp.size and dp[0] > 0 else 0
    if rank == 0:
        raise UnidentifiableError(f"{chain.name}: the regressor is zero: no inertial parameter "
                                  "acts on the joints")
    # the fixed order disagrees with the pivoted rank: take the pivots
    if int(is_ind.sum()) != rank:
        is_ind = np.isin(order, piv[:rank])
    ind, dep = order[is_ind], order[~is_ind]
    beta = (np.linalg.lstsq(X[:, ind], X[:, dep],
                            rcond=None)[0] if dep.size else np.zeros((ind.size, 0)))
    # rounding: a term whose share of its dependent column is below 1e-8 (relative: β has units,
    # and the β = L² ≈ 1e-9 m² of a MEMS chain's 30 µm links is real), and every term of a
    # column that is zero but for rounding (not live)
    small = np.abs(beta) * norms[ind][:, None] < 1e-8 * norms[dep][None, :]
    beta[small | (norms[dep] <= 1e-10 * norms.max())[None, :]] = 0.0
    beta = beta * scale[ind][:, None] / scale[dep][None, :]  # back to the parameters' units
    keep = np.argsort(ind)  # the standard order
    ind, beta = ind[keep], beta[keep]
    base_names = tuple(_combination_name(names, i, dep, beta[k]) for k, i in enumerate(ind))
    return BaseStructure(ind, dep, beta, base_names, tuple(names))


def _column_scale(chain, p: int) -> np.ndarray:
    """Lᵏ per standard parameter (k = 0 for m, 1 for m·c, 2 for the inertias and a rotor
    inertia), L = the median radius of gyration about the link frames, √(tr I / 2m), of the
    chain's links with mass (1 m when none has one, or when the chain object gives no standard
    parameters): the columns of Y·diag(Lᵏ) are of one size whatever the chain's scale."""
    nominal = getattr(chain, "standard_parameters", None)
    phi = (np.zeros((0, 10)) if nominal is None
           else np.asarray(nominal(), dtype=np.float64).reshape(-1, 10))
    mass, trace = phi[:, 0], phi[:, 4] + phi[:, 6] + phi[:, 9]
    ok = (mass > 0) & (trace > 0)
    length = float(np.sqrt(np.median(trace[ok] / (2 * mass[ok])))) if ok.any() else 1.0
    power = np.full(p, 2.0)  # the rotor inertias after the links' columns
    power[:phi.size] = np.tile([0, 1, 1, 1, 2, 2, 2, 2, 2, 2], phi.shape[0])
    return length ** power


def _inertial_columns(chain, q, qd, qdd, armature: bool) -> np.ndarray:
    Y = chain.regressor(q, qd, qdd)
    if armature:
        B, m, _ = Y.shape
        A = np.zeros((B, m, m))
        A[:, np.arange(m), np.arange(m)] = qdd
        Y = np.concatenate([Y, A], axis=2)
    return Y


def friction_columns(qd, kinds) -> np.ndarray:
    """Friction regressor columns, shape (B, m, m·len(kinds)): for joint j and each kind, τ_j gains
    sign(q̇_j) ("coulomb", N·m), q̇_j ("viscous", N·m·s/rad) or 1 ("offset", N·m)."""
    B, m = qd.shape
    F = np.zeros((B, m, m * len(kinds)))
    for j in range(m):
        for c, kind in enumerate(kinds):
            col = j * len(kinds) + c
            F[:, j, col] = (np.sign(qd[:, j]) if kind == "coulomb" else qd[:, j]
                            if kind == "viscous" else 1.0)
    return F


@dataclass(frozen=True)
class Consistency:
    """Physical consistency of the estimate (:mod:`gripkit.sysid.rigid_body.dynamics_projection`).

    ``distance`` d (σ): the Mahalanobis distance, in the covariance of the identified parameters,
    from the estimate to the nearest physically consistent parameters ``theta`` (0: the estimate
    itself is consistent, ``inside``), reproduced by the consistent ``standard_parameters``.
    ``consistent``: d² ≤ χ²_dof(``level``), the test that some consistent parameters explain the
    data (``dof`` the number of constrained identified parameters, ``bound`` = √χ²_dof(level),
    ``p_value`` = P(χ²_dof > d²)). ``failing_links``: the parts held on the boundary (links,
    rotor inertias, friction coefficients). ``solver``, ``converged``, ``iterations``: how the
    projection was found."""

    consistent: bool
    distance: float
    failing_links: tuple
    standard_parameters: np.ndarray
    theta: np.ndarray
    dof: int = 0
    bound: float = float("nan")
    level: float = 0.95
    p_value: float = float("nan")
    inside: bool = False
    solver: str = ""
    converged: bool = True
    iterations: int = 0

    def message(self) -> str:
        if self.inside:
            return ("physically consistent: standard parameters with positive mass and "
                    "positive-definite pseudo-inertia reproduce the base parameters")
        where = (f"the nearest consistent parameters are {self.distance:.3g} σ away (Mahalanobis "
                 f"distance in the {self.dof} identified parameters; χ²({self.dof}) p = "
                 f"{self.p_value:.2g}, {100 * self.level:.0f} % bound {self.bound:.3g} σ)")
        if not self.converged:
            where += (f"; the optimiser did not converge, the distance is an upper bound "
                      f"({self.solver})")
        if self.consistent:
            return f"physically consistent within the noise: {where}"
        links = ", ".join(self.failing_links) or "(no single part)"
        return ("physically inconsistent: no standard parameters with positive-definite "
                "pseudo-inertia reproduce "
                f"the base parameters within the noise: {where}; on the boundary: {links}")

    def to_dict(self) -> dict:
        return dict(consistent=self.consistent, distance_sigma=self.distance,
                    failing_links=list(self.failing_links),
                    dof=self.dof, bound_sigma=self.bound, level=self.level, p_value=self.p_value,
                    estimate_consistent=self.inside, solver=self.solver, converged=self.converged,
                    iterations=self.iterations, message=self.message())


@dataclass(frozen=True)
class DynamicsResult:
    """Result of :func:`identify_dynamics`.

    ``base_parameters`` / ``base_parameters_std``: dicts, combination name → value (SI: kg, kg·m,
    kg·m²); ``friction``: joint name → {``coulomb``, ``coulomb_std``, ``viscous``, ``viscous_std``
    (, ``offset``, ``offset_std``)} in N·m, N·m·s/rad (N, N·s/m for prismatic joints);
    ``armature`` likewise when identified. ``theta``, ``covariance`` and ``names`` hold every
    estimated parameter in column order.
    """

    chain: object
    structure: BaseStructure
    friction_model: str
    armature_identified: bool
    names: tuple
    theta: np.ndarray
    covariance: np.ndarray
    residual_std: dict
    relative_error_percent: float
    condition_number: float
    n_samples: int
    consistency: Consistency | None
    constrained: bool
    unconstrained_theta: np.ndarray
    warnings: list = field(default_factory=list)
    urdf_text: str | None = None      # provenance for the model file (``save``): the URDF read,
    base_link: str | None = None      # the chain's end links in it (None: the URDF's defaults),
    tip_link: str | None = None
    data_file: str | None = None      # and the log's name and SHA-256
    data_hash: str | None = None

    def replace(self, **changes) -> DynamicsResult:
        """A copy with ``changes`` (e.g. the provenance fields ``urdf_text``, ``data_file``)."""
        return replace(self, **changes)

    def save(self, path) -> None:
        """Write the model as JSON (:mod:`gripkit.sysid.rigid_body.dynamics_file`, schema
        ``gripkit.dynamics-model``); read it back with :func:`gripkit.sysid.load_dynamics_model`."""
        save_dynamics_model(self, path)

    @property
    def std(self) -> np.ndarray:
        return np.sqrt(np.diag(self.covariance))

    @property
    def n_base(self) -> int:
        return self.structure.independent.size

    @property
    def base_parameters(self) -> dict:
        return dict(zip(self.structure.names, map(float, self.theta[:self.n_base])))

    @property
    def base_parameters_std(self) -> dict:
        return dict(zip(self.structure.names, map(float, self.std[:self.n_base])))

    def _per_joint(self, offset: int, kinds) -> dict:
        out = {}
        std = self.std
        for j, name in enumerate(self.chain.coordinate_names):
            d = {}
            for c, kind in enumerate(kinds):
                k = offset + j * len(kinds) + c
                d[kind] = float(self.theta[k])
                d[f"{kind}_std"] = float(std[k])
            out[name] = d
        return out

    @property
    def friction(self) -> dict:
        kinds = FRICTION_MODELS[self.friction_model]
        return (self._per_joint(len(self.names) - self.chain.dof * len(kinds),
                                kinds) if kinds else {})

    @property
    def armature(self) -> dict:
        """Rotor inertia per joint (identified with ``armature=True``; it appears in the base
        parameters, alone or combined)."""
        return {n: v for n, v in self.base_parameters.items() if "armature_" in n}

    def regressor(self, q, qd, qdd) -> np.ndarray:
        """The identified model's regressor X (B, m, n_params): τ = X θ."""
        q, qd, qdd = (np.atleast_2d(np.asarray(a, dtype=np.float64)) for a in (q, qd, qdd))
        Y = (_inertial_columns(self.chain, q, qd, qdd,
                               self.armature_identified)[:, :, self.structure.independent])
        kinds = FRICTION_MODELS[self.friction_model]
        return np.concatenate([Y, friction_columns(qd, kinds)], axis=2) if kinds else Y

    def predict(self, q, qd, qdd) -> np.ndarray:
        """τ (B, m) (or (m,) for one state) of the identified model."""
        single = np.asarray(q).ndim == 1
        tau = self.regressor(q, qd, qdd) @ self.theta
        return tau[0] if single else tau

    def to_dict(self) -> dict:
        d = dict(base_parameters=self.base_parameters, base_parameters_std=self.base_parameters_std,
                 friction=self.friction, friction_model=self.friction_model,
                 residual_std=self.residual_std, relative_error_percent=self.relative_error_percent,
                 condition_number=self.condition_number, n_samples=self.n_samples,
                 constrained=self.constrained,
                 joints=list(self.chain.coordinate_names),
                 n_standard_parameters=len(self.structure.standard_names),
                 n_base_parameters=self.n_base, warnings=list(self.warnings))
        if self.consistency is not None:
            d["consistency"] = self.consistency.to_dict()
        return d


def _joint_states(q, qd, qdd, tau, names):
    """q, q̇, q̈, τ as checked (N, m) arrays of one length N
    (:func:`~gripkit.sysid.checks.as_io_matrix`)."""
    q = as_io_matrix(q, "q", None, names, "joint")
    N = q.shape[0]
    return (q, as_io_matrix(qd, "qd", N, names, "joint"),
            as_io_matrix(qdd, "qdd", N, names, "joint"),
            as_io_matrix(tau, "tau", N, names, "joint"))


def _check_choices(friction: str, covariance: str) -> None:
    """DataError unless ``friction`` is a key of :data:`FRICTION_MODELS` and ``covariance`` is
    'ols' or 'hac'."""
    if friction not in FRICTION_MODELS:
        raise DataError(f"friction: expected one of {', '.join(FRICTION_MODELS)}, "
                        f"found {friction!r}")
    if covariance not in ("ols", "hac"):
        raise DataError(f"covariance: expected 'ols' or 'hac', found {covariance!r}")


def _row_weights(weights, N: int, m: int) -> np.ndarray:
    """The (N, m) row weights: ones, or ``weights`` ((N,) repeated over the joints, or (N, m)),
    finite and non-negative."""
    if weights is None:
        return np.ones((N, m))
    w = np.asarray(weights, dtype=np.float64)
    if w.ndim == 1:
        w = np.repeat(w[:, None], m, axis=1)
    if w.shape != (N, m) or not np.isfinite(w).all() or (w < 0).any():
        raise DataError(f"weights: expected (N,) or (N, {m}) finite non-negative values, found "
                        f"shape {np.shape(weights)}")
    return w


class _JointNormalEquations:
    """One pass over the data: each joint's weighted Gram matrix Gⱼ = XⱼᵀWⱼXⱼ, bⱼ = XⱼᵀWⱼτⱼ and
    τⱼᵀWⱼτⱼ of the regressor X3 (N, m, P) and the efforts τ (N, m) under the row weights (N, m);
    the per-joint reweighting, the solution, the residual sums and the covariance follow from
    them. The columns are scaled to unit RMS (``scale``) before solving."""

    def __init__(self, X3: np.ndarray, tau: np.ndarray, rows_w: np.ndarray, n_rows: int):
        self.X3, self.tau, self.rows_w, self.n_rows = X3, tau, rows_w, n_rows
        _, m, P = X3.shape
        self.Gj = np.empty((m, P, P))
        self.bj = np.empty((m, P))
        self.yy = np.empty(m)
        for j in range(m):
            sw = np.sqrt(rows_w[:, j])
            Xj = X3[:, j, :] * sw[:, None]
            yj = tau[:, j] * sw
            self.Gj[j] = Xj.T @ Xj
            self.bj[j] = Xj.T @ yj
            self.yy[j] = yj @ yj
        self.scale = np.sqrt(np.diagonal(self.Gj.sum(axis=0)) / n_rows)
        self.S = np.outer(self.scale, self.scale)

    def solve(self, jw):
        """θ for per-joint weights jw (normal equations on the scaled columns; their condition
        number is the square of the regressor's, so beyond 1e6 the orthogonal route is taken).
        Returns the scaled Gram matrix, θ, the regressor's condition number and the eigenvectors."""
        Gs = np.tensordot(jw, self.Gj, axes=1) / self.S
        ev, V = np.linalg.eigh(Gs)
        cnd = float(np.sqrt(ev[-1] / max(ev[0], 1e-300)))
        if cnd < 1e6:
            th = np.linalg.solve(Gs, (jw @ self.bj) / self.scale)
        else:
            th = np.linalg.lstsq(self._scaled_rows(jw),
                                 (self.tau * np.sqrt(self.rows_w * jw)).reshape(-1),
                                 rcond=None)[0]
        return Gs, th / self.scale, cnd, V

    def _scaled_rows(self, jw) -> np.ndarray:
        """The weighted stacked rows √w·X (N·m, P) with the columns scaled."""
        N, m, P = self.X3.shape
        sw = np.sqrt(self.rows_w * jw)
        return (self.X3 * sw[:, :, None]).reshape(N * m, P) / self.scale

    def rss(self, th):
        """Weighted residual sum of squares of each joint."""
        return (np.maximum(self.yy - 2 * self.bj @ th + np.einsum("i,jik,k->j", th, self.Gj, th),
                           0.0))

    def covariance(self, theta, jw, Gs, kind: str, r2) -> np.ndarray:
        """Cov(θ̂): σ̂² (XᵀWX)⁻¹ with σ̂² = rᵀWr/(N_rows − P) (``'ols'``), or the Newey-West
        covariance of the weighted rows (``'hac'``)."""
        P = self.X3.shape[2]
        if kind == "hac":
            sw = np.sqrt(self.rows_w * jw)
            rw = ((self.tau - self.X3 @ theta) * sw).reshape(-1)
            keep = sw.reshape(-1) > 0
            return hac_covariance(self._scaled_rows(jw)[keep], rw[keep]) / self.S
        s2 = float(jw @ r2 / max(self.n_rows - P, 1))
        return s2 * np.linalg.inv(Gs) / self.S


def _normal_equations(X3, tau, rows_w, names) -> _JointNormalEquations:
    """:class:`_JointNormalEquations`, refused with fewer than two weighted rows per parameter or a
    column the data never excite."""
    P = X3.shape[2]
    n_rows = int((rows_w > 0).sum())
    if n_rows < 2 * P:
        raise DataError(f"{n_rows} weighted rows are too few for {P} parameters (need "
                        f"at least {2 * P})",
                        hint="log a longer run")
    ne = _JointNormalEquations(X3, tau, rows_w, n_rows)
    weak = np.flatnonzero(ne.scale == 0)
    if weak.size:
        raise UnidentifiableError(f"the data never excite {', '.join(names[k] for k in weak[:3])}",
                                  hint="move every joint, in both directions, with accelerations")
    return ne


def _solve_joint_weighted(ne: _JointNormalEquations, names, joint_weighting: bool):
    """θ of the first pass (unit joint weights), refused beyond condition number 1e10 naming the
    weakest direction; then, with ``joint_weighting``, again with each joint weighted by 1/σ̂ⱼ²
    of the first pass (Gautier & Poignet 2001). Returns jw, the scaled Gram matrix, θ, the
    condition number."""
    m, P = ne.yy.size, ne.X3.shape[2]
    jw = np.ones(m)
    Gs, theta, cond, V = ne.solve(jw)
    if cond > 1e10:
        v = V[:, 0] / ne.scale
        top = np.argsort(-np.abs(v / np.max(np.abs(v))))[:3]
        raise UnidentifiableError("the data do not excite every base parameter (condition "
                                  f"number {cond:.3g}); "
                                  f"the weakest direction mixes {', '.join(names[k] for k in top)}",
                                  hint="use a richer excitation (gripkit.sysid.fourier_trajectory)")
    if joint_weighting and m > 1:
        n_j = (ne.rows_w > 0).sum(axis=0)
        s2_j = ne.rss(theta) / np.maximum(n_j - P / m, 1.0)
        s2_j[~(s2_j > 0)] = 1.0
        jw = 1.0 / s2_j
        Gs, theta, cond, _ = ne.solve(jw)
    return jw, Gs, theta, cond


@entry_point
def identify_dynamics(chain, q, qd, qdd, tau, *, friction: str = "coulomb-viscous", weights=None,
                      armature: bool = False, covariance: str = "ols", constrained: bool = False,
                      check_consistency: bool = True,
                      joint_weighting: bool = True) -> DynamicsResult:
    """Identify a chain's base inertial parameters and per-joint friction from joint states and
    efforts (module doc).

    Parameters
    ----------
    chain
        A gripkit chain (DH, coupled or URDF: ``gripkit.multibody.from_urdf``); its inertial
        values are only the starting point of the consistency check.
    q, qd, qdd, tau
        Positions (rad or m), velocities, accelerations and efforts (N·m or N) of the actuated
        joints, shape (N, m).
    friction
        ``'coulomb-viscous'``, ``'coulomb-viscous-offset'`` or ``'none'``.
    weights
        None, or (N,) or (N, m) non-negative row weights (0 drops a row: e.g. samples near a
        velocity reversal).
    joint_weighting
        Multiply the weights by each joint's 1/σ̂² from a first pass (module doc).
    armature
        Also identify a rotor inertia I_a per actuated joint (geared motors).
    covariance
        ``'ols'`` (white noise) or ``'hac'`` (filtered or decimated data).
    constrained
        Return the nearest physically consistent estimate (in the metric of the covariance) instead
        of the unconstrained one.
    """
    _check_choices(friction, covariance)
    m = chain.dof
    jn = chain.coordinate_names
    q, qd, qdd, tau = _joint_states(q, qd, qdd, tau, jn)
    N = q.shape[0]
    rows_w = _row_weights(weights, N, m)
    st = base_structure(chain, armature=armature)
    kinds = FRICTION_MODELS[friction]
    Y = _inertial_columns(chain, q, qd, qdd, armature)[:, :, st.independent]
    X3 = np.concatenate([Y, friction_columns(qd, kinds)], axis=2) if kinds else Y
    names = st.names + tuple(f"{k}_{j}" for j in jn for k in kinds)
    ne = _normal_equations(X3, tau, rows_w, names)
    jw, Gs, theta, cond = _solve_joint_weighted(ne, names, joint_weighting)
    r2 = ne.rss(theta)
    C = ne.covariance(theta, jw, Gs, covariance, r2)
    wsum = rows_w.sum(axis=0)
    res_std = ({j: float(np.sqrt(r2[k] / wsum[k])) if wsum[k] > 0 else float("nan")
                for k, j in enumerate(jn)})
    rel = float(100.0 * np.sqrt(r2.sum() / max(ne.yy.sum(), 1e-300)))
    notes = []
    if cond > 1e5:
        notes.append(f"regressor condition number {cond:.3g}: weak excitation, large σ")
    theta_u = theta.copy()
    cons = None
    if check_consistency or constrained:
        cons = _consistency(chain, st, theta, C, kinds, m, armature)
        if not cons.consistent:
            notes.append(cons.message())
        if constrained:
            theta = cons.theta
    return DynamicsResult(chain, st, friction, armature, names, theta, C, res_std, rel, cond, N,
                          cons,
                          constrained, theta_u, notes)


# --- physical consistency -------------------------------------------------------------------------

def _j_to_phi() -> np.ndarray:
    """The linear map vec(J) (16) → φ (10) of one link: m = J₃₃, h = J[:3, 3], I = tr(Σ)·1 − Σ
    with Σ = J[:3, :3] (the inverse of :func:`pseudo_inertia`)."""
    A = np.zeros((10, 16))
    for e in range(16):
        J = np.zeros(16)
        J[e] = 1.0
        J = J.reshape(4, 4)
        Sigma = J[:3, :3]
        Io = np.trace(Sigma) * np.eye(3) - Sigma
        A[:, e] = ([J[3, 3], J[0, 3], J[1, 3], J[2, 3], Io[0, 0], Io[0, 1], Io[1, 1], Io[0, 2],
                    Io[1, 2], Io[2, 2]])
    return A


_J_TO_PHI = _j_to_phi()


def pseudo_inertia(phi10) -> np.ndarray:
    """J = [[½tr(I_o)·1 − I_o, h], [hᵀ, m]] of one link's standard parameters."""
    m, hx, hy, hz, xx, xy, yy, xz, yz, zz = phi10
    Io = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    J = np.zeros((4, 4))
    J[:3, :3] = 0.5 * np.trace(Io) * np.eye(3) - Io
    J[:3, 3] = J[3, :3] = hx, hy, hz
    J[3, 3] = m
    return J


def _psd(J) -> bool:
    """J positive semidefinite (to 1e-9 of its largest eigenvalue)."""
    ev = np.linalg.eigvalsh(J)
    return ev[0] >= -1e-9 * max(ev[-1], 1e-300)


def _least_change_parameters(phi_nom, K, theta_b, n_links: int, p_std: int):
    """The standard parameters nearest to the chain's own φ₀ that reproduce the estimate (least
    change, each parameter relative to its own size s, so that a massless link stays massless):
    φ = φ₀ + S²Kᵀ(K S² Kᵀ)⁻¹(θ_b − K φ₀). The sizes are each parameter's own value plus 1e-3 of
    its link's scale of that kind (mass, first moment, inertia), so that zero off-diagonal
    products may move. Returns φ and whether K φ reproduces θ_b."""
    sz = np.abs(phi_nom)
    for k in range(n_links):
        f = phi_nom[10 * k:10 * k + 10]
        kind = (abs(f[0]), np.abs(f[1:4]).max(), np.abs(f[[4, 6, 9]]).max())
        sz[10 * k:10 * k + 10] += 1e-3 * np.array([kind[0]] + [kind[1]] * 3 + [kind[2]] * 6)
    if phi_nom.size > p_std:
        sz[p_std:] += 1e-3 * max(sz[:p_std].max(), 1e-300)
    KS = K * sz ** 2
    phi_p = phi_nom + KS.T @ np.linalg.lstsq(KS @ K.T, theta_b - K @ phi_nom, rcond=None)[0]
    reproduces = np.allclose(K @ phi_p, theta_b, rtol=1e-9, atol=1e-12 * np.abs(theta_b).max())
    return phi_p, reproduces


def _signed_indices(kinds, m: int, n_arm: int, fr0: int):
    """Indices of the projection's variables x = [φ, rotor inertias, friction] that must be ≥ 0
    (rotor inertias, Coulomb and viscous coefficients), and the rotor inertias alone."""
    arm = np.arange(fr0 - n_arm, fr0)
    fr = [fr0 + j * len(kinds) + c for j in range(m) for c, kind in enumerate(kinds)
          if kind in ("coulomb", "viscous")]
    return np.concatenate([arm, np.asarray(fr, dtype=np.intp)]).astype(np.intp), arm


def _projection_start(phi0, theta, std, signed, n_links: int, nb: int, fr0: int,
                      scale: float) -> np.ndarray:
    """A strictly consistent start for the projection: the chain's own links with each
    pseudo-inertia moved inside by 1 % of its scale, rotor inertias at 1 % of ``scale``, the
    estimated friction (Coulomb and viscous at |θ̂| + σ, strictly positive)."""
    x0 = np.concatenate([np.zeros(fr0), theta[nb:]])
    for k in range(n_links):
        J = pseudo_inertia(phi0[10 * k:10 * k + 10])
        ev, V = np.linalg.eigh(J)
        eps = 1e-2 * max(ev[-1], 1e-2 * scale)
        J_in = (V * np.maximum(ev, 0.0)) @ V.T + eps * np.eye(4)
        x0[10 * k:10 * k + 10] = _J_TO_PHI @ J_in.ravel()
    x0[10 * n_links:fr0] = 1e-2 * scale
    fr = signed[signed >= fr0]
    x0[fr] = np.abs(theta[fr - fr0 + nb]) + std[fr - fr0 + nb]
    return x0


def _failing_parts(chain, phi_p, x, theta, std, kinds, n_arm: int, nb: int,
                   scale: float) -> list[str]:
    """What has no consistent values: the links whose pseudo-inertia is indefinite in the
    least-change solution (if none, those on the boundary at the projection: smallest eigenvalue
    below 1e-6 of the largest), rotor inertias and Coulomb or viscous coefficients held at 0
    while the estimate is negative."""
    failing = []
    n_links = len(chain.link_names)
    for k, name in enumerate(chain.link_names):
        if not _psd(pseudo_inertia(phi_p[10 * k:10 * k + 10])):
            failing.append(f"link {name!r}")
    if not failing:
        for k, name in enumerate(chain.link_names):
            ev = np.linalg.eigvalsh(pseudo_inertia(x[10 * k:10 * k + 10]))
            if ev[0] <= 1e-6 * max(ev[-1], 1e-300):
                failing.append(f"link {name!r}")
    fr0 = 10 * n_links + n_arm
    failing += [f"armature of {j!r} (< 0)" for i, j in enumerate(chain.coordinate_names[:n_arm])
                if x[10 * n_links + i] <= 1e-6 * scale]
    for j, jn in enumerate(chain.coordinate_names):
        for c, kind in enumerate(kinds):
            k = j * len(kinds) + c
            held = theta[nb + k] < 0 and x[fr0 + k] <= 1e-3 * std[nb + k]
            if kind in ("coulomb", "viscous") and held:
                failing.append(f"{kind} friction of {jn!r} (< 0)")
    return failing


def _consistency(chain, st: BaseStructure, theta, C, kinds, m, armature,
                 level: float = 0.95) -> Consistency:
    """Physical consistency of the estimate θ̂ with covariance C
    (:mod:`gripkit.sysid.rigid_body.dynamics_projection`): first the least-change standard
    parameters,
    consistent there means consistent (d = 0, no search); else the projection of θ̂ onto the
    consistent set in the metric C⁻¹, its distance d and the χ² test of level 1 − ``level``
    with n = dim θ − (offsets) degrees of freedom."""
    from scipy.stats import chi2

    nb = st.independent.size
    p_std = len(chain.parameter_names)
    n_links = p_std // 10
    K = st.matrix
    phi0 = chain.standard_parameters()
    n_arm = m if armature else 0
    fr0 = p_std + n_arm
    dof = int(theta.size - sum(kind == "offset" for kind in kinds) * m)
    bound = float(np.sqrt(chi2.ppf(level, dof)))
    try:
        Ci = np.linalg.cholesky(np.linalg.inv(C))
    except np.linalg.LinAlgError:
        raise IdentificationError("the covariance of the estimate is not "
                                  "positive definite") from None
    std = np.sqrt(np.diag(C))
    phi_nom = np.concatenate([phi0, np.zeros(n_arm)]) if n_arm else phi0.copy()
    phi_p, reproduces = _least_change_parameters(phi_nom, K, theta[:nb], n_links, p_std)
    links_ok = all(_psd(pseudo_inertia(phi_p[10 * k:10 * k + 10])) for k in range(n_links))
    fr_ok = all(theta[nb + j * len(kinds) + c] >= 0 for j in range(m)
                for c, kind in enumerate(kinds)
                if kind in ("coulomb", "viscous"))
    if reproduces and links_ok and fr_ok and (not n_arm or (phi_p[p_std:] >= 0).all()):
        return Consistency(True, 0.0, (), phi_p, theta.copy(), dof=dof, bound=bound, level=level,
                           p_value=1.0, inside=True,
                           solver="none needed: the least-change standard parameters are "
                                  "consistent")
    typical = float(np.mean([np.trace(pseudo_inertia(phi0[10 * k:10 * k + 10]))
                             for k in range(n_links)]))
    scale = max(typical, float(np.abs(theta[:nb]).max()), 1e-12)
    A = np.zeros((theta.size, fr0 + theta.size - nb))
    A[:nb, :fr0] = K
    A[nb:, fr0:] = np.eye(theta.size - nb)
    signed, _ = _signed_indices(kinds, m, n_arm, fr0)
    x0 = _projection_start(phi0, theta, std, signed, n_links, nb, fr0, scale)
    sol = project_consistent(A, Ci, theta, x0, n_links, signed, np.arange(p_std, fr0), scale,
                             link_names=[repr(n) for n in chain.link_names])
    d = sol.distance
    inside = sol.converged and 0.5 * d * d <= sol.gap
    consistent = bool(d <= bound)
    failing = () if inside else tuple(_failing_parts(chain, phi_p, sol.x, theta, std, kinds, n_arm,
                                                     nb, scale))
    return Consistency(consistent, d, failing, sol.x[:fr0].copy(), sol.theta, dof=dof, bound=bound,
                       level=level, p_value=float(chi2.sf(d * d, dof)), inside=bool(inside),
                       solver=sol.message,
                       converged=sol.converged, iterations=sol.iterations)


def load_dynamics_model(path) -> DynamicsResult:
    """Read a model written by ``result.save(path)``
    (:mod:`gripkit.sysid.rigid_body.dynamics_file`): a
    :class:`DynamicsResult` with ``predict``, ``base_parameters``, ``base_parameters_std``,
    ``friction``, ``covariance``, ... as identified.

    Raises DataError for a missing file, a file that is not JSON, of another ``schema`` or of a
    newer
    ``schema_version``; ModelError for missing or malformed fields; warns (DataWarning) when
    the content digest does not match (the file was edited after it was saved).
    """
    doc = read_dynamics_document(path)
    where = repr(str(Path(path)))
    try:
        urdf = doc["urdf"]
        text = urdf["text"]
        if hashlib.sha256(text.encode()).hexdigest() != urdf.get("sha256"):
            emit_warning(f"dynamics model file {where}: the URDF text does not "
                         "match its sha256", AccuracyWarning)
        chain = from_urdf(text, base_link=urdf.get("base_link"), tip_link=urdf.get("tip_link"),
                          gravity=float_array(doc["gravity"], "gravity", where, (3,)))
        if list(chain.coordinate_names) != list(doc["joints"]):
            raise ModelError(f"dynamics model file {where}: the URDF's joints "
                             f"{list(chain.coordinate_names)} "
                             f"disagree with the file's {doc['joints']}")
        s = doc["structure"]
        ind = np.asarray(s["independent"], dtype=np.intp)
        dep = np.asarray(s["dependent"], dtype=np.intp)
        beta = float_array(s["beta"], "structure.beta", where).reshape(ind.size, dep.size)
        par = doc["parameters"]
        names = tuple(par["names"])
        n = len(names)
        theta = float_array(par["values"], "parameters.values", where, (n,))
        cov = float_array(par["covariance"], "parameters.covariance", where, (n, n))
        base_names = names[:ind.size]
        structure = BaseStructure(ind, dep, beta, base_names, tuple(s["standard_names"]))
        c = doc.get("consistency")
        consistency = None if c is None else Consistency(
            bool(c["consistent"]), float(c["distance_sigma"]), tuple(c["failing_links"]),
            float_array(c["standard_parameters"], "consistency.standard_parameters", where),
            float_array(c["values"], "consistency.values", where),
            dof=int(c.get("dof", 0)), bound=float(c.get("bound_sigma", float("nan"))),
            level=float(c.get("level", 0.95)), p_value=float(c.get("p_value", float("nan"))),
            inside=bool(c.get("estimate_consistent", c["distance_sigma"] == 0)),
            solver=str(c.get("solver", "")), converged=bool(c.get("converged", True)),
            iterations=int(c.get("iterations", 0)))
        data = doc.get("data") or {}
        return DynamicsResult(
            chain, structure, doc["friction_model"], bool(doc["armature"]), names, theta, cov,
            {k: float(v) for k, v in doc["residual_std"].items()},
            float(doc["relative_error_percent"]),
            float(doc["condition_number"]), int(doc["n_samples"]), consistency,
            bool(doc["constrained"]),
            float_array(doc["unconstrained_values"], "unconstrained_values", where, (n,)),
            list(doc.get("warnings", [])),
            urdf_text=text, base_link=urdf.get("base_link"), tip_link=urdf.get("tip_link"),
            data_file=data.get("file"), data_hash=data.get("sha256"))
    except (KeyError, TypeError, ValueError) as exc:
        raise ModelError(f"dynamics model file {where}: a required field is missing or "
                         f"malformed ({exc})",
                         hint="regenerate the file with gripkit identify dynamics --out") from None
