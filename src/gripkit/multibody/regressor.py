"""Inverse-dynamics regressor: joint forces linear in the standard inertial parameters.

For a rigid chain, τ = M(q) q̈ + C(q, q̇) + G(q) is linear in the ten standard inertial parameters
of every link (Atkeson, An & Hollerbach 1986; Khalil & Dombre §9.3),

    τ = Y(q, q̇, q̈) φ + diag(armature) q̈,      φ_j = (m, m·c_x, m·c_y, m·c_z,
                                                      I_xx, I_xy, I_yy, I_xz, I_yz, I_zz)_j,

with c the centre of mass and I the inertia tensor about the link frame's *origin*
(I_o = I_C + m(|c|²1 − c cᵀ)), both in the link frame — Pinocchio's ``Inertia.toDynamicParameters``
order, so Y equals ``pinocchio.computeJointTorqueRegressor``. The link's wrench at its origin, in
its frame, is linear in φ_j:

    f = m v̇ + ω̇ × h + ω × (ω × h),      n = I_o ω̇ + ω × (I_o ω) + h × v̇      (h = m·c),

where ω, ω̇, v̇ come from the outward Newton-Euler pass (thesis eqs 4.8–4.10, gravity as the base
acceleration −g). Column (j, c) of Y is then the projection on each joint axis i ≤ j of the wrench
of parameter c carried down the chain (eqs 4.14–4.16). Coupled chains (q = Γ p + q₀) give
Y_p = Γᵀ Y. Rotor inertia (``armature``) is not part of φ: add ``armature_i·q̈_i`` (or identify
it as an extra column, :func:`gripkit.sysid.identify_dynamics`).
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from .kernels import REVOLUTE, chain_links, hot, hot_inline, outward_step, rotation
from .rnea import _states

__all__ = ["regressor", "standard_parameters", "parameter_names", "PARAMETERS_PER_LINK",
           "LINK_PARAMETERS"]

PARAMETERS_PER_LINK = 10
#: names of a link's standard parameters, in φ order (hx = m·c_x, ...; I about the link origin)
LINK_PARAMETERS = ("m", "mx", "my", "mz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")
#: scratch of the regressor kernels (n links): link rotations (n, 9) and positions (n, 3), the
#: outward kinematics (n, 9), one link's parameter wrenches (6, 10), the joint-space regressor
#: (n, 10n) and the joint positions, rates and accelerations (n each)
RegressorWork = namedtuple("RegressorWork", "R P kin W Yq q qd qdd")


@hot
def outward_kinematics(n, R, P, jtype, qd, qdd, gx, gy, gz, kin):  # pragma: no cover - compiled
    """ω, ω̇ and the origin's acceleration v̇ (gravity as −g) of every link in its own frame:
    ``kin[k] = (ω, ω̇, v̇)`` (9 floats), eqs 4.8–4.10."""
    s = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -gx, -gy, -gz)  # base: ω = ω̇ = 0, v̇ = −g
    for k in range(n):
        s = outward_step(k, R, P, jtype, qd, qdd, s, True)
        wx, wy, wz, ax, ay, az, vx, vy, vz = s
        kin[k, 0] = wx
        kin[k, 1] = wy
        kin[k, 2] = wz
        kin[k, 3] = ax
        kin[k, 4] = ay
        kin[k, 5] = az
        kin[k, 6] = vx
        kin[k, 7] = vy
        kin[k, 8] = vz


@hot
def _parameter_wrench(c, wx, wy, wz, ax, ay, az, vx, vy, vz):  # pragma: no cover - compiled
    """Wrench (f, n) at the link origin produced by a unit value of standard parameter c."""
    if c == 0:
        return vx, vy, vz, 0.0, 0.0, 0.0
    if c <= 3:
        ex = 1.0 if c == 1 else 0.0
        ey = 1.0 if c == 2 else 0.0
        ez = 1.0 if c == 3 else 0.0
        we = wx * ex + wy * ey + wz * ez
        w2 = wx * wx + wy * wy + wz * wz
        fx = ay * ez - az * ey + wx * we - ex * w2
        fy = az * ex - ax * ez + wy * we - ey * w2
        fz = ax * ey - ay * ex + wz * we - ez * w2
        return fx, fy, fz, ey * vz - ez * vy, ez * vx - ex * vz, ex * vy - ey * vx
    # E ω̇ and E ω for the unit symmetric matrix E of (xx, xy, yy, xz, yz, zz)
    if c == 4:
        ea = (ax, 0.0, 0.0)
        ew = (wx, 0.0, 0.0)
    elif c == 5:
        ea = (ay, ax, 0.0)
        ew = (wy, wx, 0.0)
    elif c == 6:
        ea = (0.0, ay, 0.0)
        ew = (0.0, wy, 0.0)
    elif c == 7:
        ea = (az, 0.0, ax)
        ew = (wz, 0.0, wx)
    elif c == 8:
        ea = (0.0, az, ay)
        ew = (0.0, wz, wy)
    else:
        ea = (0.0, 0.0, az)
        ew = (0.0, 0.0, wz)
    nx = ea[0] + wy * ew[2] - wz * ew[1]
    ny = ea[1] + wz * ew[0] - wx * ew[2]
    nz = ea[2] + wx * ew[1] - wy * ew[0]
    return 0.0, 0.0, 0.0, nx, ny, nz


@hot_inline
def regressor_state(n, m, ch, w, qd, qdd, gx, gy, gz, Y, b):  # pragma: no cover - compiled
    """Joint-space regressor Yq = ``w.Yq`` (n × 10n) of one state of the chain ``ch`` (joint types
    and Γ of :data:`~gripkit.multibody.kernels.ChainArrays`; link transforms ``w.R``, ``w.P``
    already filled, ``w`` a :data:`RegressorWork`) and its actuator-space projection
    Y[b] = Γᵀ Yq (m × 10n).

    Link j's ten parameter wrenches (f, n) at its origin, in its frame, are kept in ``W`` (6 × 10)
    and projected on each joint i ≤ j: with u the axis of joint i and d the vector from joint i's
    origin to link j's, both in frame j, τ_i = u·n + (u × d)·f (revolute) or u·f (prismatic).
    u and d come from carrying frame j down to frame i (R_{i←j} = R_{i+1}·R_{i+1←j},
    p_i = R_{i+1} p_{i+1} + P_{i+1}): u = R_{i←j}ᵀ ẑ, u × d = R_{i←j}ᵀ (ẑ × p_i)."""
    R, P, jtype, G, kin, W, Yq = w.R, w.P, ch.jtype, ch.G, w.kin, w.W, w.Yq
    outward_kinematics(n, R, P, jtype, qd, qdd, gx, gy, gz, kin)
    for i in range(n):
        for col in range(10 * n):
            Yq[i, col] = 0.0
    for j in range(n):
        wx = kin[j, 0]; wy = kin[j, 1]; wz = kin[j, 2]  # noqa: E702
        ax = kin[j, 3]; ay = kin[j, 4]; az = kin[j, 5]  # noqa: E702
        vx = kin[j, 6]; vy = kin[j, 7]; vz = kin[j, 8]  # noqa: E702
        for c in range(10):
            fx, fy, fz, nx, ny, nz = _parameter_wrench(c, wx, wy, wz, ax, ay, az, vx, vy, vz)
            W[0, c] = fx
            W[1, c] = fy
            W[2, c] = fz
            W[3, c] = nx
            W[4, c] = ny
            W[5, c] = nz
        # R_{i←j} row-major in a0..a8, p = origin of frame j in frame i
        a0 = 1.0; a1 = 0.0; a2 = 0.0  # noqa: E702
        a3 = 0.0; a4 = 1.0; a5 = 0.0  # noqa: E702
        a6 = 0.0; a7 = 0.0; a8 = 1.0  # noqa: E702
        px = 0.0; py = 0.0; pz = 0.0  # noqa: E702
        for i in range(j, -1, -1):
            if i < j:
                k = i + 1
                r0, r1, r2, r3, r4, r5, r6, r7, r8 = rotation(R, k)
                b0 = r0 * a0 + r1 * a3 + r2 * a6
                b1 = r0 * a1 + r1 * a4 + r2 * a7
                b2 = r0 * a2 + r1 * a5 + r2 * a8
                b3 = r3 * a0 + r4 * a3 + r5 * a6
                b4 = r3 * a1 + r4 * a4 + r5 * a7
                b5 = r3 * a2 + r4 * a5 + r5 * a8
                b6 = r6 * a0 + r7 * a3 + r8 * a6
                b7 = r6 * a1 + r7 * a4 + r8 * a7
                b8 = r6 * a2 + r7 * a5 + r8 * a8
                a0 = b0; a1 = b1; a2 = b2; a3 = b3; a4 = b4; a5 = b5; a6 = b6; a7 = b7; a8 = b8  # noqa: E702
                qx = r0 * px + r1 * py + r2 * pz + P[k, 0]
                qy = r3 * px + r4 * py + r5 * pz + P[k, 1]
                qz = r6 * px + r7 * py + r8 * pz + P[k, 2]
                px = qx
                py = qy
                pz = qz
            ux = a6
            uy = a7
            uz = a8
            col = 10 * j
            if jtype[i] == REVOLUTE:
                ex = -py * a0 + px * a3
                ey = -py * a1 + px * a4
                ez = -py * a2 + px * a5
                for c in range(4):
                    Yq[i, col + c] = (ux * W[3, c] + uy * W[4, c] + uz * W[5, c]
                                      + ex * W[0, c] + ey * W[1, c] + ez * W[2, c])
                for c in range(4, 10):
                    Yq[i, col + c] = ux * W[3, c] + uy * W[4, c] + uz * W[5, c]
            else:
                for c in range(4):
                    Yq[i, col + c] = ux * W[0, c] + uy * W[1, c] + uz * W[2, c]
    for a in range(m):
        for col in range(10 * n):
            s = 0.0
            for k in range(n):
                gk = G[k * m + a]
                if gk != 0.0:
                    s += gk * Yq[k, col]
            Y[b, a, col] = s


@hot
def _regressor_range(b0, b1, ch, gscale, pos, vel, acc, Y, w):  # pragma: no cover - compiled
    """Regressors Y[b] of states b0..b1−1 of the chain ``ch`` (:data:`ChainArrays`), gravity
    scaled by ``gscale``; scratch ``w`` (:data:`RegressorWork`)."""
    n = ch.links.shape[0]
    m = pos.shape[1]
    G, q0, g, q, qd, qdd = ch.G, ch.q0, ch.g, w.q, w.qd, w.qdd
    for b in range(b0, b1):
        for k in range(n):
            s = q0[k]
            sd = 0.0
            sdd = 0.0
            for a in range(m):
                gk = G[k * m + a]
                s += gk * pos[b, a]
                sd += gk * vel[b, a]
                sdd += gk * acc[b, a]
            q[k] = s
            qd[k] = sd
            qdd[k] = sdd
        chain_links(n, ch.links, ch.jtype, q, w.R, w.P)
        regressor_state(n, m, ch, w, qd, qdd, gscale * g[0], gscale * g[1], gscale * g[2], Y, b)


@hot
def _regressor_batch(ch, gscale, pos, vel, acc, Y, w):  # pragma: no cover - compiled
    _regressor_range(0, pos.shape[0], ch, gscale, pos, vel, acc, Y, w)


def regressor(system, q, qd, qdd, *, gravity: bool = True) -> np.ndarray:
    """Y(q, q̇, q̈) such that τ = Y φ + diag(armature) q̈ (module doc).

    Parameters
    ----------
    system
        A chain (DH, coupled or URDF); states in its coordinates, shape (m,) or (B, m).

    Returns
    -------
    Y
        Shape (m, p) or (B, m, p) with p = 10 × number of moving links, columns in
        :func:`parameter_names` order.
    """
    (q, qd, qdd), single = _states(system, q, qd, qdd, names=("q", "qd", "qdd"))
    ch = system.kernel_arrays()
    n = ch.links.shape[0]
    B, m = q.shape
    Y = np.empty((B, m, PARAMETERS_PER_LINK * n))
    w = RegressorWork(np.empty((n, 9)), np.empty((n, 3)), np.empty((n, 9)), np.empty((6, 10)),
                      np.empty((n, PARAMETERS_PER_LINK * n)), np.empty(n), np.empty(n), np.empty(n))
    _regressor_batch(ch, 1.0 if gravity else 0.0, q, qd, qdd, Y, w)
    L = system.parameter_map()
    if L is not None:
        Y = Y @ L
    return Y[0] if single else Y


def kernel_parameters(mass, com, inertia6) -> np.ndarray:
    """φ of every link from the kernel arrays (mass (n,), com (n, 3), inertia about the COM as
    (xx, yy, zz, xy, xz, yz) (n, 6)), shape (10n,)."""
    n = mass.shape[0]
    phi = np.empty((n, PARAMETERS_PER_LINK))
    for k in range(n):
        m = mass[k]
        c = com[k]
        xx, yy, zz, xy, xz, yz = inertia6[k]
        Ic = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
        Io = Ic + m * (c @ c * np.eye(3) - np.outer(c, c))
        phi[k] = [m, *(m * c), Io[0, 0], Io[0, 1], Io[1, 1], Io[0, 2], Io[1, 2], Io[2, 2]]
    return phi.ravel()


def standard_parameters(system) -> np.ndarray:
    """φ (10 per moving link, :func:`parameter_names` order) with which ``regressor`` reproduces
    the system's inverse dynamics (apart from the rotor inertia)."""
    return system.standard_parameters()


def parameter_names(system) -> tuple[str, ...]:
    """``'<parameter>_<link>'`` for every column of the regressor."""
    return tuple(f"{p}_{link}" for link in system.link_names for p in LINK_PARAMETERS)
