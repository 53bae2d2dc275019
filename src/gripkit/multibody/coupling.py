"""Joint coupling: chains whose joints are driven through a linear transmission.

Joint coordinates q (n) follow actuator coordinates p (m ≤ n) through a constant coupling matrix,

    q = Γ p + q₀,      q̇ = Γ ṗ,      τ_p = Γᵀ τ_q          (virtual work),

so the actuator-space equation of motion is

    τ_p = M_p(p) p̈ + Γᵀ (C(q, q̇) + G(q)),   M_p = Γᵀ M(q) Γ + diag(I_m·N²).

The last term is the motors' rotor inertia reflected through each actuator's reduction N
(thesis Appendix A: ``Im·N²``; "motor inertia can only be counted once", so a coupled joint carries
none of its own).

The DLR/HIT Hand II finger (``002_ddea254371185ad3.txt`` §3.1, §4.5, Fig. 7.2) has both kinds:

* **distal coupling** — the distal joint follows the proximal joint 1:1 through a steel wire:
  θ₄ = θ₃, and "the torque calculated for joint 4 has to be added to joint 3" (§4.5). That is
  the column ``[0, 0, 1, 1]ᵀ`` of Γ: Γᵀ adds τ₄ to τ₃.
* **bevel-gear differential** — the two base motors act at ±β (β = 45°) to the dynamics axes:
  the thesis maps the motor-side torques onto abduction (y1) and flexion (y2) as

      τ_abd  = sin(−β)·τ_res,1 + sin(β)·τ_res,2
      τ_flex = cos(−β)·τ_res,1 + cos(β)·τ_res,2          (Fig. 7.2)

  i.e. τ_q = A τ_p. Virtual work then requires τ_p = Γᵀ τ_q, so Γ = A⁻ᵀ; for β = 45° A is
  orthogonal and symmetric and Γ = A (driving one base motor moves the finger along a 45°
  diagonal of the abduction/flexion plane, driving both flexes it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from operator import attrgetter

import numpy as np

from ..errors import ModelError
from .dh import DHChain, Dynamics
from .kernels import ChainArrays

__all__ = ["Coupling", "CoupledChain", "differential_matrix", "finger_coupling"]


@dataclass(frozen=True, eq=False)
class Coupling:
    """q = Γ p + q₀ with reflected rotor inertia per actuator.

    Attributes
    ----------
    matrix
        Γ, shape (n_joints, n_actuators), full column rank.
    offset
        q₀ (n_joints,), joint positions at p = 0 (rad or m).
    armature
        Rotor inertia reflected to each actuator coordinate, I_m·N² (kg·m²), (n_actuators,).
    names
        Actuator names.
    """

    matrix: np.ndarray
    offset: np.ndarray
    armature: np.ndarray
    names: tuple[str, ...]

    def __post_init__(self):
        G = np.atleast_2d(np.asarray(self.matrix, dtype=np.float64))
        n, m = G.shape
        if not np.isfinite(G).all():
            raise ModelError("coupling matrix contains NaN or inf")
        if m > n or np.linalg.matrix_rank(G) < m:
            raise ModelError(f"coupling matrix {G.shape}: expected full column rank "
                             f"(every actuator must move some joint, independently)")
        off = np.zeros(n) if self.offset is None else np.asarray(self.offset, dtype=np.float64)
        arm = np.zeros(m) if self.armature is None else np.asarray(self.armature, dtype=np.float64)
        if off.shape != (n,) or arm.shape != (m,):
            raise ModelError(f"coupling: offset must have shape ({n},) and armature ({m},); "
                             f"found {off.shape} and {arm.shape}")
        if (arm < 0).any():
            raise ModelError(f"coupling armature must be >= 0, found {arm.tolist()}")
        names = (tuple(self.names) if self.names is not None
                 else tuple(f"p{j + 1}" for j in range(m)))
        if len(names) != m:
            raise ModelError(f"coupling: expected {m} actuator names, found {len(names)}")
        object.__setattr__(self, "matrix", G)
        object.__setattr__(self, "offset", off)
        object.__setattr__(self, "armature", arm)
        object.__setattr__(self, "names", names)

    @property
    def n_joints(self) -> int:
        return self.matrix.shape[0]

    @property
    def n_actuators(self) -> int:
        return self.matrix.shape[1]

    def joints(self, p) -> np.ndarray:
        """q = Γ p + q₀."""
        return np.asarray(p, dtype=np.float64) @ self.matrix.T + self.offset

    def joint_velocity(self, pd) -> np.ndarray:
        return np.asarray(pd, dtype=np.float64) @ self.matrix.T

    def actuator_force(self, tau_q) -> np.ndarray:
        """τ_p = Γᵀ τ_q."""
        return np.asarray(tau_q, dtype=np.float64) @ self.matrix

    def actuators(self, q) -> np.ndarray:
        """Least-squares inverse p = Γ⁺ (q − q₀) (exact when q is reachable)."""
        return (np.asarray(q, dtype=np.float64) - self.offset) @ np.linalg.pinv(self.matrix).T


def differential_matrix(beta: float = math.pi / 4) -> np.ndarray:
    """Γ of the base bevel-gear differential (Fig. 7.2): τ_q = A τ_p with
    A = [[sin(−β), sin β], [cos(−β), cos β]], Γ = A⁻ᵀ (rows: abduction, flexion)."""
    A = np.array([[math.sin(-beta), math.sin(beta)], [math.cos(-beta), math.cos(beta)]])
    if abs(np.linalg.det(A)) < 1e-9:
        raise ModelError(f"differential angle β = {math.degrees(beta):g}° makes the base singular")
    return np.linalg.inv(A).T


def finger_coupling(beta: float = math.pi / 4, armature=(0.0, 0.0, 0.0),
                    names=("base1", "base2", "distal")) -> Coupling:
    """The DLR/HIT II finger: actuators (base motor 1, base motor 2, proximal/distal motor) on
    joints (abduction θ₁, flexion θ₂, proximal θ₃, distal θ₄ = θ₃)."""
    G = np.zeros((4, 3))
    G[:2, :2] = differential_matrix(beta)
    G[2, 2] = 1.0
    G[3, 2] = 1.0
    return Coupling(G, np.zeros(4), np.asarray(armature, dtype=np.float64), tuple(names))


class CoupledChain(Dynamics):
    """A :class:`DHChain` driven through a :class:`Coupling`; every dynamics and kinematics method
    works in actuator coordinates p (positions, velocities, accelerations, forces)."""

    def __init__(self, chain: DHChain, coupling: Coupling, name: str | None = None):
        if not isinstance(chain, DHChain):
            raise ModelError(f"chain: expected a DHChain, found {type(chain).__name__}")
        if coupling.n_joints != chain.n:
            raise ModelError(f"coupling has {coupling.n_joints} joint rows but the chain has "
                             f"{chain.n} joints")
        self._chain = chain
        self.coupling = coupling
        self.name = name or f"{chain.name} (coupled)"
        self._arrays = None

    # the Dynamics interface, read through to the chain (DHChain) and the coupling
    chain = property(attrgetter("_chain"))
    dof = property(attrgetter("coupling.n_actuators"))
    coordinate_names = property(attrgetter("coupling.names"))
    base = property(attrgetter("_chain.base"))
    tool = property(attrgetter("_chain.tool"))

    def kernel_arrays(self):
        if self._arrays is None:
            dh, jt, mass, com, i6, arm, g = self._chain.link_arrays()
            c = self.coupling
            self._arrays = ChainArrays(dh, jt, mass, com, i6, arm,
                                       np.ascontiguousarray(c.matrix.ravel()),
                                       c.offset, c.armature, g)
        return self._arrays

    def joints(self, p) -> np.ndarray:
        return self.coupling.joints(p)

    def replace(self, **chain_changes) -> "CoupledChain":
        """A copy whose chain has some constructor arguments changed (``gravity=``, ``base=``)."""
        return CoupledChain(self._chain.replace(**chain_changes), self.coupling, self.name)

    def __repr__(self) -> str:
        return f"CoupledChain({self.name!r}, {self.chain.n} joints driven by {self.dof} actuators)"
