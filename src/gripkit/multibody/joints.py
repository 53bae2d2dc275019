"""Serial chains described by joint placements and axes (the URDF and Pinocchio description),
with mimic joints folded into the actuated coordinates.

Joint k (0-based) sits at the fixed placement X_k (4×4) in the frame of the link before it (the
base frame for k = 0) and moves its child link about (revolute) or along (prismatic) the unit
axis a_k of its own frame:

    ^{k-1}T_k(q_k) = X_k · Rot(a_k, q_k)      or      X_k · Trans(q_k a_k).

Link k's inertial data (mass, centre of mass, inertia about the centre of mass) are in that joint
frame (the URDF child link frame). The kernels of :mod:`gripkit.multibody.kernels` move along z:
with a constant rotation A_k taking ẑ to a_k (A_k = 1 when a_k = ẑ), Rot(a_k, q) =
A_k Rz(q) A_kᵀ, so the kernel frame K_k = (joint frame)·A_k has the placement
F_k = A_{k-1}ᵀ X_k A_k and link data c_K = A_kᵀ c, I_K = A_kᵀ I A_k. DH and URDF chains therefore
run the same RNEA, CRBA, forward-dynamics and regressor kernels.

Mimic joints: the full joint vector follows the actuated one, q_full = Γ q + q₀ (URDF ``<mimic
joint=... multiplier=... offset=...>``), and the actuated forces are τ = Γᵀ τ_full (virtual
work), exactly the :class:`~gripkit.multibody.Coupling` of the DLR/HIT finger's distal joint.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from .dh import Dynamics, _as_transform
from .kernels import PLACEMENT_WIDTH, PRISMATIC, REVOLUTE, ChainArrays
from .regressor import kernel_parameters
from .rnea import OP_JACOBIAN, _states, run_op

__all__ = ["JointChain", "JointLimits", "axis_frame"]


@dataclass(frozen=True)
class JointLimits:
    """Limits of the actuated joints (SI; ±inf where the URDF gives none): ``lower``, ``upper``
    (rad or m), ``velocity`` (rad/s or m/s), ``effort`` (N·m or N), each shape (m,)."""

    lower: np.ndarray
    upper: np.ndarray
    velocity: np.ndarray
    effort: np.ndarray

    @classmethod
    def unbounded(cls, m: int) -> "JointLimits":
        inf = np.full(m, np.inf)
        return cls(-inf, inf.copy(), inf.copy(), inf.copy())


def axis_frame(axis) -> np.ndarray:
    """A rotation A with A ẑ = axis (unit). Exact (entries 0, ±1) for the coordinate axes."""
    a = np.asarray(axis, dtype=np.float64)
    for k in range(3):
        for sgn in (1.0, -1.0):
            e = np.zeros(3)
            e[k] = sgn
            if np.array_equal(a, e):
                # a permutation (with signs) mapping z to e, det +1
                cols = ({0: ([0, 0, 1], [0, 1, 0]), 1: ([0, 0, 1], [1, 0, 0]),
                         2: ([1, 0, 0], [0, 1, 0])}[k])
                x = np.array(cols[0], dtype=np.float64)
                y = np.cross(e, x)
                return np.column_stack([x, y, e])
    z = a / np.linalg.norm(a)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def _parameter_map(A: np.ndarray) -> np.ndarray:
    """L (10×10) with φ_K = L φ for a link whose kernel frame is (link frame)·A: c_K = Aᵀ c,
    I_K = Aᵀ I A (about the origin)."""
    L = np.zeros((10, 10))
    for c in range(10):
        e = np.zeros(10)
        e[c] = 1.0
        I = np.array([[e[4], e[5], e[7]], [e[5], e[6], e[8]], [e[7], e[8], e[9]]])  # noqa: E741
        IK = A.T @ I @ A
        L[:, c] = ([e[0], *(A.T @ e[1:4]), IK[0, 0], IK[0, 1], IK[1, 1], IK[0, 2], IK[1, 2],
                    IK[2, 2]])
    return L


def check_inertia(mass: float, inertia: np.ndarray, what: str) -> None:
    """ModelError unless mass ≥ 0 and the inertia about the COM is symmetric, positive
    semidefinite and satisfies the triangle inequality (a rigid body can have it)."""
    if not (math.isfinite(mass) and mass >= 0):
        raise ModelError(f"{what}: mass must be a finite number >= 0 kg, found {mass!r}")
    if not np.isfinite(inertia).all() or not np.allclose(inertia, inertia.T,
                                                         atol=1e-15 + 1e-9 * np.abs(inertia).max()):
        raise ModelError(f"{what}: the inertia tensor is not a finite symmetric matrix")
    ev = np.linalg.eigvalsh(inertia)
    tol = 1e-12 * max(1e-30, ev.max(initial=0.0)) + 1e-300
    if ev.min() < -tol:
        raise ModelError(f"{what}: the inertia tensor has a negative principal moment "
                         f"({ev.min():.3g} kg·m²)")
    if ev[0] + ev[1] < ev[2] - 1e-9 * max(ev[2], 0.0) - tol:
        raise ModelError(f"{what}: principal moments {ev[0]:.3g} + {ev[1]:.3g} < {ev[2]:.3g} kg·m² "
                         f"violate the triangle inequality: no rigid body has them")


class JointChain(Dynamics):
    """A serial chain of joints at fixed placements (module doc), with mimic coupling.

    Parameters
    ----------
    placements
        X_k, shape (n, 4, 4): joint k's frame in the previous link's frame at q = 0.
    axes
        Unit joint axes in their own frames, (n, 3).
    joint_types
        ``'R'`` (revolute) / ``'P'`` (prismatic) per joint, length n.
    mass, com, inertia
        Link masses (kg, (n,)), centres of mass (m, (n, 3)) and inertia tensors about them
        (kg·m², (n, 3, 3)), in the joint frames.
    coupling, offset
        Γ (n × m) and q₀ (n,): q_full = Γ q + q₀. Default: every joint actuated.
    names
        The n joint names; ``coordinate_names`` are the actuated ones (columns of Γ).
    actuated
        Indices of the actuated joints (one per column of Γ), default ``range(n)``.
    link_names
        The n moving link names (regressor parameter names).
    limits
        :class:`JointLimits` of the actuated joints.
    gravity
        In the base frame (m/s²).
    tool
        The tip frame in the last link's frame (4×4).
    """

    def __init__(self, placements, axes, joint_types, mass, com, inertia, *, coupling=None,
                 offset=None, names, actuated=None, link_names=None,
                 limits: JointLimits | None = None,
                 gravity=(0.0, 0.0, -9.81), tool=None, armature=None, name: str = "chain"):
        X = np.asarray(placements, dtype=np.float64)
        n = X.shape[0]
        if X.shape != (n, 4, 4) or n < 1:
            raise ModelError(f"placements: expected shape (n, 4, 4) with n >= 1, found {X.shape}")
        for k in range(n):
            _as_transform(X[k], f"placement of joint {k}")
        axes = np.asarray(axes, dtype=np.float64).reshape(n, 3)
        norms = np.linalg.norm(axes, axis=1)
        if not np.isfinite(norms).all() or (norms < 1e-12).any():
            raise ModelError("axes: every joint axis must be a finite non-zero vector")
        axes = axes / norms[:, None]
        jt = str(joint_types).upper()
        if len(jt) != n or set(jt) - {"R", "P"}:
            raise ModelError(f"joint_types: expected {n} letters R or P, found {joint_types!r}")
        mass = np.asarray(mass, dtype=np.float64).reshape(n)
        com = np.asarray(com, dtype=np.float64).reshape(n, 3)
        inertia = np.asarray(inertia, dtype=np.float64).reshape(n, 3, 3)
        names = tuple(names)
        link_names = (tuple(link_names) if link_names is not None
                      else tuple(f"link{k + 1}" for k in range(n)))
        if len(names) != n or len(link_names) != n:
            raise ModelError(f"names and link_names: expected {n} each, found {len(names)} and "
                             f"{len(link_names)}")
        for k in range(n):
            check_inertia(float(mass[k]), inertia[k], f"link {link_names[k]!r}")
        G = np.eye(n) if coupling is None else np.asarray(coupling, dtype=np.float64)
        if (G.ndim != 2 or G.shape[0] != n or G.shape[1] > n
                or np.linalg.matrix_rank(G) < G.shape[1]):
            raise ModelError(f"coupling: expected a full-column-rank ({n}, m) matrix, found "
                             f"shape {G.shape}")
        m = G.shape[1]
        q0 = np.zeros(n) if offset is None else np.asarray(offset, dtype=np.float64).reshape(n)
        actuated = tuple(range(n)) if actuated is None else tuple(int(a) for a in actuated)
        if len(actuated) != m:
            raise ModelError(f"actuated: expected {m} joint indices (columns of the coupling), "
                             f"found {len(actuated)}")
        arm = np.zeros(m) if armature is None else np.asarray(armature, dtype=np.float64).reshape(m)
        self.placements = X.copy()
        self.axes = axes
        self.joint_types = jt
        self.mass = mass.copy()
        self.com = com.copy()
        self.inertia = inertia.copy()
        self.coupling = G.copy()
        self.offset = q0.copy()
        self.names = names
        self.actuated = actuated
        self._link_names = link_names
        self.limits = limits if limits is not None else JointLimits.unbounded(m)
        self.gravity_vector = np.asarray(gravity, dtype=np.float64).reshape(3).copy()
        self.tool = _as_transform(tool, "tool")
        self.base = np.eye(4)
        self.armature = arm
        self.name = name
        self._A = np.array([axis_frame(a) for a in axes])
        self._arrays = None

    # --- the Dynamics interface -----------------------------------------------------------------
    @property
    def n(self) -> int:
        return self.placements.shape[0]

    @property
    def dof(self) -> int:
        return self.coupling.shape[1]

    @property
    def chain(self) -> "JointChain":
        return self

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The actuated (non-mimic) joints, in tree order."""
        return tuple(self.names[k] for k in self.actuated)

    @property
    def coordinate_names(self) -> tuple[str, ...]:
        return self.joint_names

    @property
    def link_names(self) -> tuple[str, ...]:
        return self._link_names

    def kernel_arrays(self):
        if self._arrays is None:
            n = self.n
            A = self._A
            table = np.empty((n, PLACEMENT_WIDTH))
            com = np.empty((n, 3))
            i6 = np.empty((n, 6))
            prev = np.eye(3)
            for k in range(n):
                X = self.placements[k]
                table[k, :9] = (prev.T @ X[:3, :3] @ A[k]).ravel()
                table[k, 9:] = prev.T @ X[:3, 3]
                com[k] = A[k].T @ self.com[k]
                I = A[k].T @ self.inertia[k] @ A[k]  # noqa: E741
                i6[k] = I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]
                prev = A[k]
            jt = np.array([REVOLUTE if c == "R" else PRISMATIC for c in self.joint_types],
                          dtype=np.int64)
            self._arrays = ChainArrays(np.ascontiguousarray(table), jt, self.mass,
                                       np.ascontiguousarray(com),
                                       i6, np.zeros(n), np.ascontiguousarray(self.coupling.ravel()),
                                       self.offset, self.armature, self.gravity_vector)
            self._kernel_tool = self.tool.copy()
            self._kernel_tool[:3] = A[-1].T @ self.tool[:3]
        return self._arrays

    def frames(self, q) -> np.ndarray:
        """World transforms of the moving links' (URDF) frames, (n, 4, 4) or (B, n, 4, 4)."""
        T = super().frames(q)
        Ak = np.zeros((self.n, 4, 4))
        Ak[:, :3, :3] = np.transpose(self._A, (0, 2, 1))
        Ak[:, 3, 3] = 1.0
        return T @ Ak

    def jacobian(self, q) -> np.ndarray:
        """Geometric Jacobian of the tip, rows (v, ω) in the base frame, (6, m) or (B, 6, m)."""
        (qq,), single = _states(self, q)
        self.kernel_arrays()
        J = np.empty((qq.shape[0], 6, self.dof))
        run_op(self, OP_JACOBIAN, qq, tool=self._kernel_tool[:3, 3], fout=J)
        return J[0] if single else J

    def parameter_map(self):
        """Block-diagonal L with φ_kernel = L φ (identity blocks where the axis is z)."""
        if all(np.array_equal(A, np.eye(3)) for A in self._A):
            return None
        n = self.n
        L = np.zeros((10 * n, 10 * n))
        for k in range(n):
            L[10 * k:10 * k + 10, 10 * k:10 * k + 10] = _parameter_map(self._A[k])
        return L

    def standard_parameters(self) -> np.ndarray:
        """φ in the URDF link frames (inertia about each link frame's origin)."""
        i6 = np.stack([self.inertia[:, 0, 0], self.inertia[:, 1, 1], self.inertia[:, 2, 2],
                       self.inertia[:, 0, 1], self.inertia[:, 0, 2], self.inertia[:, 1, 2]], axis=1)
        return kernel_parameters(self.mass, self.com, i6)

    def joints(self, q) -> np.ndarray:
        """q_full = Γ q + q₀."""
        return np.asarray(q, dtype=np.float64) @ self.coupling.T + self.offset

    def replace(self, **changes) -> "JointChain":
        """A copy with some constructor arguments changed (``gravity=``, ``mass=``, ...)."""
        kw = dict(placements=self.placements, axes=self.axes, joint_types=self.joint_types,
                  mass=self.mass, com=self.com, inertia=self.inertia, coupling=self.coupling,
                  offset=self.offset, names=self.names, actuated=self.actuated,
                  link_names=self._link_names, limits=self.limits, gravity=self.gravity_vector,
                  tool=self.tool, armature=self.armature, name=self.name)
        unknown = set(changes) - set(kw)
        if unknown:
            raise ModelError(f"JointChain.replace: unknown arguments {sorted(unknown)}")
        kw.update(changes)
        return JointChain(**kw)

    def __repr__(self) -> str:
        return (f"JointChain({self.name!r}, {self.n} joints {self.joint_types}, "
                f"{self.dof} actuated, "
                f"mass {self.mass.sum():.4g} kg)")

