"""Serial chains in Craig's modified Denavit-Hartenberg convention: description, forward
kinematics, Jacobians, and the dynamics API.

A link i (1-based) is described by ``α_{i-1}`` (twist of the previous link), ``a_{i-1}`` (its
length), ``d_i`` (offset) and the joint variable θ_i (revolute) or d_i (prismatic), exactly as in
Craig's *Introduction to Robotics* §3.4 and ``002_ddea254371185ad3.txt`` §4.3.1 / Fig. 4.1. The
frame of link i sits on joint i's axis (ẑ_i along the axis, x̂_i along the common normal towards
joint i+1); the link's centre of mass and inertia tensor are given in that frame.

>>> import numpy as np
>>> arm = DHChain(alpha=[0, 0], a=[0, 1.0], d=[0, 0], mass=[1.0, 1.0],
...               com=[[0.5, 0, 0], [0.5, 0, 0]], inertia=np.zeros((2, 3, 3)),
...               tool=np.array([[1, 0, 0, 1.0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]))
>>> np.round(arm.fk([0.0, np.pi / 2])[:3, 3], 12)
array([1., 1., 0.])
"""

from __future__ import annotations

import numpy as np

from ..errors import ArgumentError, ModelError
from . import rnea as _dyn
from .kernels import PRISMATIC, REVOLUTE, ChainArrays, dh_table
from .onestate import mass_matrix_one, rnea_one
from .onestate import prepare as prepare_one_state
from .regressor import kernel_parameters, parameter_names, regressor

__all__ = ["DHChain", "Dynamics"]

# the one-state mass matrix's test for its unchecked entry point, and np.empty without the
# module lookup (per call: docs/performance.md, "One-state RNEA and CRBA")
_F8 = np.dtype(np.float64)
_empty = np.empty


def _as_transform(T, what: str) -> np.ndarray:
    if T is None:
        return np.eye(4)
    T = np.asarray(T, dtype=np.float64)
    if T.shape != (4, 4) or not np.isfinite(T).all():
        raise ModelError(f"{what}: expected a finite 4×4 homogeneous transform, found "
                         f"shape {T.shape}")
    R = T[:3, :3]
    if not np.allclose(R @ R.T, np.eye(3), atol=1e-9) or abs(np.linalg.det(R) - 1) > 1e-9 \
            or not np.allclose(T[3], [0, 0, 0, 1]):
        raise ModelError(f"{what}: the rotation part is not a proper rotation (RᵀR ≠ I or det ≠ 1)")
    return T


def _into(out, value: np.ndarray) -> np.ndarray:
    """``value``, or ``value`` copied into the caller's ``out`` after checking it fits."""
    if out is None:
        return value
    if not (isinstance(out, np.ndarray) and out.dtype == np.float64 and out.shape == value.shape
            and out.flags.writeable):
        found = (f"{out.dtype} array of shape "
                 f"{out.shape}{'' if out.flags.writeable else ', read-only'}"
                 if isinstance(out, np.ndarray) else type(out).__name__)
        raise ArgumentError("out: expected a writable float64 array of shape "
                            f"{value.shape}, found {found}")
    out[...] = value
    return out


class Dynamics:
    """Kinematics and dynamics methods shared by :class:`DHChain` and
    :class:`~gripkit.multibody.CoupledChain` (coordinates: joints of a chain, actuators of a
    coupled chain). Subclasses provide ``dof``, ``coordinate_names``, ``name``, ``chain``,
    ``base``, ``tool`` and ``kernel_arrays()``."""

    _one = None  # the packed model of the one-state path (gripkit.multibody.onestate)

    # --- dynamics (thesis eq 4.17) ---
    def rnea(self, q, qd, qdd, *, gravity: bool = True, parallel: bool | None = None,
             out: np.ndarray | None = None) -> np.ndarray:
        """τ = M q̈ + C + G (RNEA, eqs 4.8–4.16); one float64 state takes the low-overhead path
        of :mod:`gripkit.multibody.onestate`. ``out``: a float64 array of τ's shape to write
        into (a controller loop's workspace, as Pinocchio's ``data``); returned."""
        if gravity:
            buf, m = (self._one or self._one_state())[:2]
            res = np.empty(m) if out is None else out
            try:  # try/except costs nothing on this hot path, unlike a context manager
                done = rnea_one(buf, q, qd, qdd, res)
            except TypeError:  # not 1-D float64 arrays: the validating way below
                done = False
            if done:
                return res
        return _into(out, _dyn.rnea(self, q, qd, qdd, gravity=gravity, parallel=parallel))

    def regressor(self, q, qd, qdd, *, gravity: bool = True) -> np.ndarray:
        """Y(q, q̇, q̈), (m, p) or (B, m, p): τ = Y φ + diag(armature) q̈ with φ the standard
        inertial parameters (:mod:`gripkit.multibody.regressor`)."""
        return regressor(self, q, qd, qdd, gravity=gravity)

    @property
    def link_names(self) -> tuple[str, ...]:
        """Names of the moving links, one per regressor block of 10 parameters."""
        return tuple(f"link{k + 1}" for k in range(self.chain.n))

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """``'<parameter>_<link>'`` per regressor column (m, mx, my, mz, Ixx, Ixy, Iyy, Ixz, Iyz,
        Izz)."""
        return parameter_names(self)

    def standard_parameters(self) -> np.ndarray:
        """φ, the standard inertial parameters of the moving links (kg, kg·m, kg·m²; inertia about
        each link frame's origin), in :attr:`parameter_names` order."""
        _, _, mass, com, i6, *_ = self.kernel_arrays()
        return kernel_parameters(mass, com, i6)

    def parameter_map(self):
        """None: the regressor's link frames are the kernel's (a URDF chain maps them)."""
        return None

    def armature_matrix(self) -> np.ndarray:
        """A = Γᵀ diag(armature_q) Γ + diag(armature_p) (m×m): the rotor-inertia term outside φ,
        τ = Y φ + A q̈."""
        dh, _, _, _, _, arm_q, G, _, arm_p, _ = self.kernel_arrays()
        Gm = G.reshape(dh.shape[0], -1)
        return Gm.T @ (arm_q[:, None] * Gm) + np.diag(arm_p)

    def mass_matrix(self, q, out: np.ndarray | None = None) -> np.ndarray:
        """M(q), including reflected rotor inertia (CRBA, eqs 4.14–4.16); one float64 state takes
        the low-overhead path of :mod:`gripkit.multibody.onestate`. ``out``: a float64 array of
        M's shape to write into (a controller loop's workspace, as Pinocchio's ``data``);
        returned. (``out`` may be given by position: a keyword-only parameter takes CPython's
        slower call path; docs/performance.md, CRBA.)"""
        one = self._one or self._one_state()
        if out is None:
            # a 1-D float64 array: the kernel's unchecked entry point (onestate
            # .mass_matrix_entry) into a fresh array; False (wrong length, stride, NaN): the
            # checks below. TypeError (an object with a float64 dtype that is not an ndarray) or
            # AttributeError (no dtype: a list): the validating way at once
            try:
                if q.dtype is _F8 and q.ndim == 1:
                    res = _empty(one[2])
                    if one[3](one[0], q, res):
                        return res
            except (AttributeError, TypeError):
                return _dyn.mass_matrix(self, q)
        res = _empty(one[2]) if out is None else out
        try:
            done = mass_matrix_one(one[0], q, res)
        # not a 1-D float64 state or a C-contiguous float64 out: the validating way
        except TypeError:
            done = False
        return res if done else _into(out, _dyn.mass_matrix(self, q))

    def _one_state(self):
        """The packed model of the one-state path, made on first use."""
        self._one = prepare_one_state(self)
        return self._one

    def coriolis(self, q, qd) -> np.ndarray:
        """Coriolis/centrifugal vector C(q, q̇)."""
        return _dyn.coriolis(self, q, qd)

    def gravity(self, q) -> np.ndarray:
        """Gravity torques G(q) (N·m or N per joint) for the gravity vector ``gravity_vector``."""
        return _dyn.gravity(self, q)

    def bias(self, q, qd) -> np.ndarray:
        """C(q, q̇) + G(q)."""
        return _dyn.bias(self, q, qd)

    def forward_dynamics(self, q, qd, tau) -> np.ndarray:
        """q̈ = M⁻¹(τ − C − G)."""
        return _dyn.forward_dynamics(self, q, qd, tau)

    def kinetic_energy(self, q, qd) -> np.ndarray:
        return _dyn.kinetic_energy(self, q, qd)

    def potential_energy(self, q) -> np.ndarray:
        return _dyn.potential_energy(self, q)

    def energy(self, q, qd) -> np.ndarray:
        """Total mechanical energy T + U (J)."""
        return self.kinetic_energy(q, qd) + self.potential_energy(q)

    def simulate_free(self, q0, qd0, torque, dt, *, substeps=1, method="rk4"):
        """See :func:`gripkit.multibody.rnea.simulate_free`."""
        return _dyn.simulate_free(self, q0, qd0, torque, dt, substeps=substeps, method=method)

    # --- kinematics ---
    def frames(self, q) -> np.ndarray:
        """World transforms of every link frame, shape (n, 4, 4) or (B, n, 4, 4)."""
        (q,), single = _dyn._states(self, q)
        n = self.chain.n
        T = np.empty((q.shape[0], n, 16))
        _dyn.run_op(self, _dyn.OP_FRAMES, q, fout=T)
        T = self.base @ T.reshape(q.shape[0], n, 4, 4)
        return T[0] if single else T

    def fk(self, q) -> np.ndarray:
        """World pose of the tip (last link frame composed with ``tool``), (4, 4) or (B, 4, 4)."""
        T = self.frames(q)
        return T[..., -1, :, :] @ self.tool

    def tip_position(self, q) -> np.ndarray:
        """Tip position in the world frame, (3,) or (B, 3)."""
        return self.fk(q)[..., :3, 3]

    def jacobian(self, q) -> np.ndarray:
        """Geometric Jacobian of the tip in the world frame, rows (v_x, v_y, v_z, ω_x, ω_y, ω_z),
        shape (6, dof) or (B, 6, dof): tip twist = J q̇."""
        (q,), single = _dyn._states(self, q)
        J = np.empty((q.shape[0], 6, self.dof))
        _dyn.run_op(self, _dyn.OP_JACOBIAN, q, tool=self.tool[:3, 3], fout=J)
        Rb = self.base[:3, :3]
        J[:, :3] = Rb @ J[:, :3]
        J[:, 3:] = Rb @ J[:, 3:]
        return J[0] if single else J


class DHChain(Dynamics):
    """A serial chain of rigid links described by modified (Craig) DH parameters.

    Parameters
    ----------
    alpha, a, d, theta_offset
        Per joint i = 1..n, shape (n,): ``alpha[i-1] = α_{i-1}`` (rad), ``a[i-1] = a_{i-1}`` (m),
        ``d[i-1] = d_i`` (m) and ``theta_offset[i-1]`` (rad). A revolute joint's variable adds to
        ``theta_offset`` (θ_i = θ0_i + q_i), a prismatic joint's to ``d`` (d_i = d0_i + q_i).
    joint_types
        String of ``'R'`` (revolute) and ``'P'`` (prismatic), default all revolute.
    mass, com, inertia
        Link masses (kg, (n,)), centres of mass in the link frames (m, (n, 3)), and inertia
        tensors about the centres of mass in the link frames (kg·m², (n, 3, 3)); default zero.
    armature
        Rotor inertia reflected to each joint (kg·m² or kg, (n,)): ``I_m·N²``, added to
        the diagonal of M (thesis Appendix A, ``Im·N²``).
    gravity
        Gravity vector in frame 0 (m/s², default (0, 0, −9.81)); enters as base acceleration −g.
    tool
        Transform from the last link frame to the tip (4×4), default identity.
    base
        Transform from frame 0 to the world frame (4×4), default identity. ``gravity`` stays in
        frame 0.
    """

    def __init__(self, alpha, a, d, theta_offset=None, *, joint_types: str | None = None,
                 mass=None, com=None, inertia=None, armature=None, gravity=(0.0, 0.0, -9.81),
                 tool=None, base=None, names=None, name: str = "chain"):
        alpha = np.atleast_1d(np.asarray(alpha, dtype=np.float64))
        n = alpha.shape[0]
        if alpha.ndim != 1 or n < 1:
            raise ModelError("alpha: expected a 1-D array of link twists, found "
                             f"shape {alpha.shape}")

        def vec(x, what, default=0.0, shape=(n,)):
            if x is None:
                return np.full(shape, default, dtype=np.float64)
            v = np.asarray(x, dtype=np.float64)
            if v.shape != shape:
                raise ModelError(f"{what}: expected shape {shape} for {n} joints, found {v.shape}")
            if not np.isfinite(v).all():
                raise ModelError(f"{what}: contains NaN or inf")
            return v.copy()

        a = vec(a, "a")
        d = vec(d, "d")
        off = vec(theta_offset, "theta_offset")
        jt = "R" * n if joint_types is None else str(joint_types).upper()
        if len(jt) != n or set(jt) - {"R", "P"}:
            raise ModelError(f"joint_types: expected {n} letters R (revolute) or P (prismatic), "
                             f"found {joint_types!r}")
        mass = vec(mass, "mass")
        if (mass < 0).any():
            raise ModelError(f"mass: link masses must be >= 0 kg, found {mass.tolist()}")
        com = vec(com, "com", shape=(n, 3))
        inertia = vec(inertia, "inertia", shape=(n, 3, 3))
        for k in range(n):
            Ik = inertia[k]
            if not np.allclose(Ik, Ik.T, atol=1e-15 + 1e-9 * np.abs(Ik).max()):
                raise ModelError(f"inertia of link {k + 1} is not symmetric")
            ev = np.linalg.eigvalsh(Ik)
            tol = 1e-12 * max(1.0, ev.max(initial=0.0))
            if ev.min() < -tol:
                raise ModelError(f"inertia of link {k + 1} has a negative principal moment "
                                 f"({ev.min():.3g} kg·m²)")
            if ev[0] + ev[1] < ev[2] - tol:
                raise ModelError(f"inertia of link {k + 1} violates the triangle inequality "
                                 f"(principal moments {ev[0]:.3g} + {ev[1]:.3g} < "
                                 f"{ev[2]:.3g} kg·m²): "
                                 f"no rigid body has it")
        armature = vec(armature, "armature")
        if (armature < 0).any():
            raise ModelError(f"armature: rotor inertias must be >= 0, found {armature.tolist()}")
        g = vec(gravity, "gravity", shape=(3,))
        self.name = name
        self.dh = np.ascontiguousarray(np.column_stack([alpha, a, d, off]))
        self.joint_types = jt
        self.mass = mass
        self.com = np.ascontiguousarray(com)
        self.inertia = inertia
        self.armature = armature
        self.gravity_vector = g
        self.tool = _as_transform(tool, "tool")
        self.base = _as_transform(base, "base")
        self.names = tuple(names) if names is not None else tuple(f"q{k + 1}" for k in range(n))
        if len(self.names) != n:
            raise ModelError(f"names: expected {n} joint names, found {len(self.names)}")
        self._arrays = None

    @property
    def n(self) -> int:
        return self.dh.shape[0]

    @property
    def dof(self) -> int:
        return self.n

    @property
    def coordinate_names(self) -> tuple[str, ...]:
        return self.names

    @property
    def chain(self) -> "DHChain":
        return self

    def link_arrays(self):
        """(dh, jtype, mass, com, inertia6, armature, gravity) as the kernels take them."""
        I = self.inertia  # noqa: E741
        i6 = np.ascontiguousarray(np.stack([I[:, 0, 0], I[:, 1, 1], I[:, 2, 2], I[:, 0, 1],
                                            I[:, 0, 2], I[:, 1, 2]], axis=1))
        jt = np.array([REVOLUTE if c == "R" else PRISMATIC for c in self.joint_types],
                      dtype=np.int64)
        return dh_table(*self.dh.T), jt, self.mass, self.com, i6, self.armature, self.gravity_vector

    def kernel_arrays(self):
        if self._arrays is None:
            dh, jt, mass, com, i6, arm, g = self.link_arrays()
            n = self.n
            self._arrays = ChainArrays(dh, jt, mass, com, i6, arm, np.eye(n).ravel(), np.zeros(n),
                                       np.zeros(n), g)
        return self._arrays

    def replace(self, **changes) -> "DHChain":
        """A copy with some constructor arguments changed (``gravity=``, ``base=``, ...)."""
        kw = dict(alpha=self.dh[:, 0], a=self.dh[:, 1], d=self.dh[:, 2], theta_offset=self.dh[:, 3],
                  joint_types=self.joint_types, mass=self.mass, com=self.com, inertia=self.inertia,
                  armature=self.armature, gravity=self.gravity_vector, tool=self.tool,
                  base=self.base,
                  names=self.names, name=self.name)
        unknown = set(changes) - set(kw)
        if unknown:
            raise ModelError(f"DHChain.replace: unknown arguments {sorted(unknown)}")
        kw.update(changes)
        return DHChain(**kw)

    def __repr__(self) -> str:
        return (f"DHChain({self.name!r}, {self.n} joints {self.joint_types}, mass "
                f"{self.mass.sum():.4g} kg)")
