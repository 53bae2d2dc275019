"""Scalar numba kernels shared by the multibody API and the finger simulation.

Everything here works on one state with caller-provided work arrays (no allocation inside), in
Craig's *modified* Denavit-Hartenberg convention (J. J. Craig, *Introduction to Robotics*, §3.4;
the convention of ``002_ddea254371185ad3.txt`` §4.3.1). Link ``i`` (1-based) is described by
``α_{i-1}, a_{i-1}, d_i, θ_i``; the transform from frame i to frame i−1 is

    ^{i-1}_i T = Rx(α_{i-1}) · Dx(a_{i-1}) · Rz(θ_i) · Dz(d_i),

so that, with c/s the cosine/sine,

    ^{i-1}_i R = [[ cθ,     −sθ,     0  ],         ^{i-1}P_i = [ a_{i-1},
                  [ cα·sθ,   cα·cθ,  −sα ],                       −sα·d_i,
                  [ sα·sθ,   sα·cθ,   cα ]]                        cα·d_i ].

Array layout (0-based ``k`` = link k+1): ``R[k, 0:9]`` is ^{k}_{k+1}R row-major, ``P[k, 0:3]``
is ^{k}P_{k+1}; link inertial data ``mass[k]``, ``com[k, :]`` (centre of mass in frame k+1) and
``inertia[k, :] = (Ixx, Iyy, Izz, Ixy, Ixz, Iyz)`` about the centre of mass in frame k+1;
``jtype[k]`` is REVOLUTE (0) or PRISMATIC (1).

Recursive Newton-Euler (thesis eqs 4.8–4.16 = Craig eqs 6.45–6.53), outward k = 0..n−1 with
R = (^{k}_{k+1}R)ᵀ and P = ^{k}P_{k+1}::

    ω_{k+1}  = R ω_k + θ̇ ẑ                                   (4.8)
    ω̇_{k+1}  = R ω̇_k + (R ω_k) × θ̇ ẑ + θ̈ ẑ                     (4.9)
    v̇_{k+1}  = R (ω̇_k × P + ω_k × (ω_k × P) + v̇_k)              (4.10)
    v̇_C      = ω̇ × p_C + ω × (ω × p_C) + v̇                      (4.11)
    F        = m v̇_C,   N = I_C ω̇ + ω × I_C ω                    (4.12, 4.13)

(prismatic joints: ω and ω̇ are only rotated, and v̇ gains 2 ω × ḋ ẑ + d̈ ẑ), then inward

    f_k = ^{k}_{k+1}R f_{k+1} + F_k                               (4.14)
    n_k = N_k + ^{k}_{k+1}R n_{k+1} + p_C × F_k + P × ^{k}_{k+1}R f_{k+1}   (4.15)
    τ_k = n_kᵀ ẑ  (revolute) or f_kᵀ ẑ (prismatic)                 (4.16)

Gravity enters as a base acceleration v̇_0 = −g (§4.4: "the base of the robot is accelerating
upward with 1 g"). Joint-space rotor inertia (``armature``) adds ``armature_k·θ̈_k``.

Coupled chains: joint coordinates q (n) are an affine function of actuator coordinates p (m),
q = Γ p + q₀. By virtual work the actuator forces are Γᵀ τ, so

    M_p(p) = Γᵀ M(q) Γ + diag(armature_p),   h_p = Γᵀ h(q, Γ ṗ),   τ_p = M_p p̈ + h_p.

``G`` is stored row-major as ``G[i*m + j]``.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numba
import numpy as np

#: a chain as the batched kernels take it (``system.kernel_arrays()``): link geometry (modified DH
#: table, or the joint placements of a URDF chain), joint types, masses, centres of mass,
#: inertias (layout above), joint armatures, the coupling Γ (n×m, row-major), joint offsets q₀,
#: actuator armatures and gravity (m/s²)
ChainArrays = namedtuple("ChainArrays", "links jtype mass com inertia arm_q G q0 arm_p g")
#: the links' part of a chain record, what :func:`rnea_pass`, :func:`crba` and
#: :func:`coupled_mass_bias` read (:func:`links_of` takes it out of a :data:`ChainArrays`-like
#: record): joint types, masses, centres of mass, inertias and joint armatures. A record passed to a
#: compiled call travels as all its arrays' fields, so these kernels take only the five they need
#: (the whole chain record slows the DLR/HIT finger's step: docs/performance.md)
LinkArrays = namedtuple("LinkArrays", "jtype mass com inertia arm_q")
#: scratch of the batched dynamics kernels (n links, m coordinates): link rotations and positions,
#: RNEA/CRBA work, joint positions, rates, accelerations, zeros, joint-space mass matrix and
#: torques, the coordinates' mass matrix, bias, Cholesky factor, right side and solution
DynamicsWork = namedtuple("DynamicsWork", "R P work q qd qdd zq Mq tau Mp hp L rhs a")

#: decorator of the allocation-free scalar kernels: compiled without numba's reference-counting
#: runtime (NRT), so passing arrays between them costs nothing (the finger step's figures:
#: docs/performance.md). Such kernels may not allocate.
hot = numba.njit(cache=True, error_model="numpy", _nrt=False)
#: the same for a small piece of such a kernel, inlined into its caller at numba IR level (where a
#: compiled call measured slower: docs/performance.md, "Named records in kernels")
hot_inline = numba.njit(cache=True, error_model="numpy", _nrt=False, inline="always")

#: joint type codes of ``jtype`` (a module-level int: numba folds it as a constant)
REVOLUTE = 0
PRISMATIC = 1

# work-array floats per link: RNEA stores F (3), N (3); CRBA a composite inertia (10)
WORK_PER_LINK = 10


@hot
def dh_link(ca, sa, a, d, theta, R, P, k):  # pragma: no cover - compiled
    """Fill R[k] = ^{k}_{k+1}R and P[k] = ^{k}P_{k+1} for one link (see module docstring);
    ``ca``, ``sa`` are cos/sin of the twist α_k."""
    ct = math.cos(theta)
    st = math.sin(theta)
    R[k, 0] = ct
    R[k, 1] = -st
    R[k, 2] = 0.0
    R[k, 3] = ca * st
    R[k, 4] = ca * ct
    R[k, 5] = -sa
    R[k, 6] = sa * st
    R[k, 7] = sa * ct
    R[k, 8] = ca
    P[k, 0] = a
    P[k, 1] = -sa * d
    P[k, 2] = ca * d


@hot
def placement_links(n, table, jtype, q, R, P):  # pragma: no cover - compiled
    """Link transforms of a chain described by joint placements (URDF, Pinocchio): ``table[k] =
    (F_R row-major (9), F_P (3))`` is the fixed transform F_k from frame k to joint k+1's frame,
    whose z axis is the joint axis, so ^{k}_{k+1}T = F_k · Rz(q_k) (revolute) or F_k · Dz(q_k)
    (prismatic): R = F_R·Rz(q), P = F_P, or R = F_R, P = F_P + q·F_R ẑ."""
    for k in range(n):
        if jtype[k] == REVOLUTE:
            c = math.cos(q[k])
            s = math.sin(q[k])
            for i in range(3):
                a = table[k, 3 * i]
                b = table[k, 3 * i + 1]
                R[k, 3 * i] = a * c + b * s
                R[k, 3 * i + 1] = b * c - a * s
                R[k, 3 * i + 2] = table[k, 3 * i + 2]
                P[k, i] = table[k, 9 + i]
        else:
            for i in range(3):
                R[k, 3 * i] = table[k, 3 * i]
                R[k, 3 * i + 1] = table[k, 3 * i + 1]
                R[k, 3 * i + 2] = table[k, 3 * i + 2]
                P[k, i] = table[k, 9 + i] + q[k] * table[k, 3 * i + 2]


#: width of a :func:`placement_links` table (a DH table, :func:`dh_table`, has 6 columns)
PLACEMENT_WIDTH = 12


@hot
def chain_links(n, dh, jtype, q, R, P):  # pragma: no cover - compiled
    """All link transforms for joint positions q. ``dh[k] = (α_{k}, a_{k}, d_{k+1}, θ0_{k+1},
    cos α_k, sin α_k)`` (see :func:`dh_table`); a revolute joint variable adds to θ0, a prismatic
    one to d. A table of :data:`PLACEMENT_WIDTH` columns holds joint placements instead
    (:func:`placement_links`): DH and URDF chains share every kernel below."""
    if dh.shape[1] == PLACEMENT_WIDTH:
        placement_links(n, dh, jtype, q, R, P)
        return
    for k in range(n):
        if jtype[k] == REVOLUTE:
            dh_link(dh[k, 4], dh[k, 5], dh[k, 1], dh[k, 2], dh[k, 3] + q[k], R, P, k)
        else:
            dh_link(dh[k, 4], dh[k, 5], dh[k, 1], dh[k, 2] + q[k], dh[k, 3], R, P, k)


def dh_table(alpha, a, d, offset) -> np.ndarray:
    """The (n, 6) kernel DH table: α, a, d, θ0 and the twist's cosine and sine (computed once)."""
    alpha = np.asarray(alpha, dtype=np.float64)
    return (np.ascontiguousarray(np.column_stack([alpha, a, d, offset, np.cos(alpha),
                                                  np.sin(alpha)])))


@hot_inline
def links_of(ch):  # pragma: no cover - compiled
    """The :data:`LinkArrays` of a chain record (no copy)."""
    return LinkArrays(ch.jtype, ch.mass, ch.com, ch.inertia, ch.arm_q)


@hot_inline
def centripetal(wx, wy, wz, px, py, pz):  # pragma: no cover - compiled
    """ω × (ω × p), the centripetal acceleration of a point p of a body turning at ω."""
    cx = wy * pz - wz * py
    cy = wz * px - wx * pz
    cz = wx * py - wy * px
    return wy * cz - wz * cy, wz * cx - wx * cz, wx * cy - wy * cx


@hot_inline
def rotation(R, k):  # pragma: no cover - compiled
    """The nine entries of ^{k}_{k+1}R (row-major ``R[k]``) as scalars."""
    return R[k, 0], R[k, 1], R[k, 2], R[k, 3], R[k, 4], R[k, 5], R[k, 6], R[k, 7], R[k, 8]


@hot_inline
def rotate(R, k, x, y, z):  # pragma: no cover - compiled
    """^{k}_{k+1}R (x, y, z): a vector of frame k+1 expressed in frame k."""
    return (R[k, 0] * x + R[k, 1] * y + R[k, 2] * z, R[k, 3] * x + R[k, 4] * y + R[k, 5] * z,
            R[k, 6] * x + R[k, 7] * y + R[k, 8] * z)


@hot_inline
def rotate_back(R, k, x, y, z):  # pragma: no cover - compiled
    """(^{k}_{k+1}R)ᵀ (x, y, z): a vector of frame k expressed in frame k+1."""
    return (R[k, 0] * x + R[k, 3] * y + R[k, 6] * z, R[k, 1] * x + R[k, 4] * y + R[k, 7] * z,
            R[k, 2] * x + R[k, 5] * y + R[k, 8] * z)


@hot_inline
def outward_step(k, R, P, jtype, qd, qdd, s, with_velocity):  # pragma: no cover - compiled
    """One link of the outward Newton-Euler pass (eqs 4.8–4.10): ω, ω̇ and the origin's
    acceleration v̇ of link k+1 in its own frame, as the 9-tuple (ω, ω̇, v̇), from those ``s`` of
    link k. ``with_velocity=False`` skips the velocity products."""
    wx, wy, wz, ax, ay, az, vx, vy, vz = s
    px = P[k, 0]; py = P[k, 1]; pz = P[k, 2]  # noqa: E702
    # linear acceleration of the new origin, in parent frame: ω̇×P + ω×(ω×P) + v̇
    tx = ay * pz - az * py + vx
    ty = az * px - ax * pz + vy
    tz = ax * py - ay * px + vz
    if with_velocity:
        cx, cy, cz = centripetal(wx, wy, wz, px, py, pz)
        tx += cx
        ty += cy
        tz += cz
    # rotate into the child frame (transpose of ^{k}_{k+1}R)
    nvx, nvy, nvz = rotate_back(R, k, tx, ty, tz)
    rwx, rwy, rwz = rotate_back(R, k, wx, wy, wz)
    rax, ray, raz = rotate_back(R, k, ax, ay, az)
    if jtype[k] == REVOLUTE:
        return (rwx, rwy, rwz + qd[k], rax + rwy * qd[k], ray - rwx * qd[k], raz + qdd[k], nvx, nvy,
                nvz)
    # prismatic: + 2 ω × (ḋ ẑ) + d̈ ẑ
    return (rwx, rwy, rwz, rax, ray, raz, nvx + 2.0 * rwy * qd[k], nvy - 2.0 * rwx * qd[k],
            nvz + qdd[k])


@hot
def rnea_pass(n, lk, R, P, qd, qdd, gx, gy, gz, with_velocity, tau,
              work):  # pragma: no cover - compiled
    """Joint forces τ (n) for velocities qd and accelerations qdd, base acceleration −g, of the
    chain whose links are ``lk`` (:data:`LinkArrays`, :func:`links_of` a chain record) and whose
    link transforms R, P are filled.

    ``with_velocity=False`` skips every velocity product (exact when qd = 0, e.g. gravity).
    ``work`` holds at least ``WORK_PER_LINK * n`` floats."""
    jtype, mass, com, inertia, armature = lk.jtype, lk.mass, lk.com, lk.inertia, lk.arm_q
    s = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -gx, -gy, -gz)  # base: ω = ω̇ = 0, v̇ = −g
    for k in range(n):
        s = outward_step(k, R, P, jtype, qd, qdd, s, with_velocity)
        wx, wy, wz, ax, ay, az, vx, vy, vz = s
        # centre-of-mass acceleration and link wrench
        cxm = com[k, 0]; cym = com[k, 1]; czm = com[k, 2]  # noqa: E702
        bx = ay * czm - az * cym + vx
        by = az * cxm - ax * czm + vy
        bz = ax * cym - ay * cxm + vz
        ixx = inertia[k, 0]; iyy = inertia[k, 1]; izz = inertia[k, 2]  # noqa: E702
        ixy = inertia[k, 3]; ixz = inertia[k, 4]; iyz = inertia[k, 5]  # noqa: E702
        nx = ixx * ax + ixy * ay + ixz * az
        ny = ixy * ax + iyy * ay + iyz * az
        nz = ixz * ax + iyz * ay + izz * az
        if with_velocity:
            dx, dy, dz = centripetal(wx, wy, wz, cxm, cym, czm)
            bx += dx
            by += dy
            bz += dz
            lx = ixx * wx + ixy * wy + ixz * wz
            ly = ixy * wx + iyy * wy + iyz * wz
            lz = ixz * wx + iyz * wy + izz * wz
            nx += wy * lz - wz * ly
            ny += wz * lx - wx * lz
            nz += wx * ly - wy * lx
        m = mass[k]
        o = WORK_PER_LINK * k
        work[o] = m * bx
        work[o + 1] = m * by
        work[o + 2] = m * bz
        work[o + 3] = nx
        work[o + 4] = ny
        work[o + 5] = nz
    # inward: f, n of link k+1 in its own frame
    fx = 0.0
    fy = 0.0
    fz = 0.0
    mx = 0.0
    my = 0.0
    mz = 0.0
    for k in range(n - 1, -1, -1):
        # rotate child's f, n into this frame: ^{k+1}_{k+2}R = R[k+1]
        if k < n - 1:
            rfx, rfy, rfz = rotate(R, k + 1, fx, fy, fz)
            rmx, rmy, rmz = rotate(R, k + 1, mx, my, mz)
            px = P[k + 1, 0]; py = P[k + 1, 1]; pz = P[k + 1, 2]  # noqa: E702
            # P × (R f)
            rmx += py * rfz - pz * rfy
            rmy += pz * rfx - px * rfz
            rmz += px * rfy - py * rfx
        else:
            rfx = 0.0
            rfy = 0.0
            rfz = 0.0
            rmx = 0.0
            rmy = 0.0
            rmz = 0.0
        o = WORK_PER_LINK * k
        Fx = work[o]; Fy = work[o + 1]; Fz = work[o + 2]  # noqa: E702
        cxm = com[k, 0]; cym = com[k, 1]; czm = com[k, 2]  # noqa: E702
        fx = rfx + Fx
        fy = rfy + Fy
        fz = rfz + Fz
        mx = work[o + 3] + rmx + (cym * Fz - czm * Fy)
        my = work[o + 4] + rmy + (czm * Fx - cxm * Fz)
        mz = work[o + 5] + rmz + (cxm * Fy - cym * Fx)
        if jtype[k] == REVOLUTE:
            tau[k] = mz + armature[k] * qdd[k]
        else:
            tau[k] = fz + armature[k] * qdd[k]


@hot
def crba(n, lk, R, P, M, work):  # pragma: no cover - compiled
    """Joint-space mass matrix M (n×n) of the chain whose links are ``lk`` (:data:`LinkArrays`) by
    the composite-rigid-body algorithm in the link frames.

    Composite body k (links k..n) in frame k about its origin: mass m, first moment h = Σ m·c,
    rotational inertia I_o. Moving a body's inertia from frame k+1 (origin offset P, rotation R)
    to frame k: h' = R h + m P and I' = R I Rᵀ + 2(P·h')1 − P h'ᵀ − h' Pᵀ − m(|P|²1 − P Pᵀ), with
    h' the rotated first moment before the shift (derivation in the tests). Unit acceleration of
    revolute joint k needs f = ẑ × h, n = I_o ẑ (prismatic: f = m ẑ, n = h × ẑ); M[k, k] is ẑ·n
    (ẑ·f), and M[i, k] for i < k follows by carrying (f, n) down the chain (eqs 4.14–4.16).
    ``work`` holds at least 10·n floats."""
    _link_inertias(n, lk.mass, lk.com, lk.inertia, work)
    _composite_inertias(n, R, P, work)
    _mass_matrix_columns(n, R, P, lk.jtype, lk.arm_q, M, work)


@hot
def _link_inertias(n, mass, com, inertia, work):  # pragma: no cover - compiled
    """work[10k:10k+10] = (m, h = m·c, I_o = I_c + m(|c|²1 − c cᵀ) as xx, yy, zz, xy, xz, yz) of
    each link about its own origin, in its frame: the composite bodies' starting values."""
    for k in range(n):
        o = 10 * k
        m = mass[k]
        cx = com[k, 0]
        cy = com[k, 1]
        cz = com[k, 2]
        c2 = cx * cx + cy * cy + cz * cz
        work[o] = m
        work[o + 1] = m * cx
        work[o + 2] = m * cy
        work[o + 3] = m * cz
        # I_o = I_c + m(|c|² 1 − c cᵀ): xx, yy, zz, xy, xz, yz
        work[o + 4] = inertia[k, 0] + m * (c2 - cx * cx)
        work[o + 5] = inertia[k, 1] + m * (c2 - cy * cy)
        work[o + 6] = inertia[k, 2] + m * (c2 - cz * cz)
        work[o + 7] = inertia[k, 3] - m * cx * cy
        work[o + 8] = inertia[k, 4] - m * cx * cz
        work[o + 9] = inertia[k, 5] - m * cy * cz


@hot
def _composite_inertias(n, R, P, work):  # pragma: no cover - compiled
    """Add each composite body k+1..n, moved into frame k, to body k, from the tip down (the
    transformation of :func:`crba`'s docstring)."""
    for k in range(n - 1, 0, -1):
        o = 10 * k
        m = work[o]
        r0, r1, r2, r3, r4, r5, r6, r7, r8 = rotation(R, k)
        hx0 = work[o + 1]; hy0 = work[o + 2]; hz0 = work[o + 3]  # noqa: E702
        hx = r0 * hx0 + r1 * hy0 + r2 * hz0
        hy = r3 * hx0 + r4 * hy0 + r5 * hz0
        hz = r6 * hx0 + r7 * hy0 + r8 * hz0
        a00 = work[o + 4]; a11 = work[o + 5]; a22 = work[o + 6]  # noqa: E702
        a01 = work[o + 7]; a02 = work[o + 8]; a12 = work[o + 9]  # noqa: E702
        # B = R A (A symmetric), then C = B Rᵀ (symmetric)
        b00 = r0 * a00 + r1 * a01 + r2 * a02
        b01 = r0 * a01 + r1 * a11 + r2 * a12
        b02 = r0 * a02 + r1 * a12 + r2 * a22
        b10 = r3 * a00 + r4 * a01 + r5 * a02
        b11 = r3 * a01 + r4 * a11 + r5 * a12
        b12 = r3 * a02 + r4 * a12 + r5 * a22
        b20 = r6 * a00 + r7 * a01 + r8 * a02
        b21 = r6 * a01 + r7 * a11 + r8 * a12
        b22 = r6 * a02 + r7 * a12 + r8 * a22
        c00 = b00 * r0 + b01 * r1 + b02 * r2
        c11 = b10 * r3 + b11 * r4 + b12 * r5
        c22 = b20 * r6 + b21 * r7 + b22 * r8
        c01 = b00 * r3 + b01 * r4 + b02 * r5
        c02 = b00 * r6 + b01 * r7 + b02 * r8
        c12 = b10 * r6 + b11 * r7 + b12 * r8
        px = P[k, 0]; py = P[k, 1]; pz = P[k, 2]  # noqa: E702
        ph = px * hx + py * hy + pz * hz
        p2 = px * px + py * py + pz * pz
        op = 10 * (k - 1)
        work[op] += m
        work[op + 1] += hx + m * px
        work[op + 2] += hy + m * py
        work[op + 3] += hz + m * pz
        work[op + 4] += c00 + 2.0 * ph - 2.0 * px * hx + m * (p2 - px * px)
        work[op + 5] += c11 + 2.0 * ph - 2.0 * py * hy + m * (p2 - py * py)
        work[op + 6] += c22 + 2.0 * ph - 2.0 * pz * hz + m * (p2 - pz * pz)
        work[op + 7] += c01 - px * hy - hx * py - m * px * py
        work[op + 8] += c02 - px * hz - hx * pz - m * px * pz
        work[op + 9] += c12 - py * hz - hy * pz - m * py * pz


@hot
def _mass_matrix_columns(n, R, P, jtype, armature, M, work):  # pragma: no cover - compiled
    """Column k of M from the wrench (f, n) a unit acceleration of joint k needs on composite body
    k, carried down the chain (eqs 4.14–4.16); the armature on the diagonal."""
    for k in range(n):
        o = 10 * k
        if jtype[k] == REVOLUTE:
            fx = -work[o + 2]  # ẑ × h = (−h_y, h_x, 0)
            fy = work[o + 1]
            fz = 0.0
            mx = work[o + 8]  # I_o ẑ = (I_xz, I_yz, I_zz)
            my = work[o + 9]
            mz = work[o + 6]
            M[k, k] = mz + armature[k]
        else:
            fx = 0.0
            fy = 0.0
            fz = work[o]
            mx = work[o + 2]  # h × ẑ = (h_y, −h_x, 0)
            my = -work[o + 1]
            mz = 0.0
            M[k, k] = fz + armature[k]
        for i in range(k, 0, -1):
            gx, gy, gz = rotate(R, i, fx, fy, fz)
            nx, ny, nz = rotate(R, i, mx, my, mz)
            px = P[i, 0]; py = P[i, 1]; pz = P[i, 2]  # noqa: E702
            nx += py * gz - pz * gy
            ny += pz * gx - px * gz
            nz += px * gy - py * gx
            fx = gx
            fy = gy
            fz = gz
            mx = nx
            my = ny
            mz = nz
            v = mz if jtype[i - 1] == REVOLUTE else fz
            M[i - 1, k] = v
            M[k, i - 1] = v


@hot
def coupled_mass_bias(n, m, lk, G, arm_p, cw, qd, gx, gy, gz, Mp, hp):  # pragma: no cover
    """Actuator-space mass matrix Mp (m×m) = Γᵀ M Γ + diag(arm_p) (M by :func:`crba`) and bias
    hp (m) = Γᵀ h(q, q̇) (one RNEA pass with q̈ = 0) for joint velocities qd (already Γ ṗ) of the
    chain with links ``lk`` (:data:`LinkArrays`) and coupling Γ. ``cw`` is the chain's scratch, a
    record with the fields ``R``, ``P`` (link transforms, filled for the current q), ``zq`` (n
    zeros), ``Mq`` (n×n), ``tau`` (n) and ``work`` (at least 10·n floats), as
    :data:`DynamicsWork`."""
    tau, work = cw.tau, cw.work
    rnea_pass(n, lk, cw.R, cw.P, qd, cw.zq, gx, gy, gz, True, tau, work)
    for i in range(m):
        s = 0.0
        for k in range(n):
            s += G[k * m + i] * tau[k]
        hp[i] = s
    crba(n, lk, cw.R, cw.P, cw.Mq, work)
    project_mass(n, m, cw.Mq, G, arm_p, Mp)


@hot
def project_mass(n, m, Mq, G, arm_p, Mp):  # pragma: no cover - compiled
    """Mp (m×m) = Γᵀ Mq Γ + diag(arm_p): a joint-space mass matrix seen by the actuators (Γ is
    n×m, row-major flat). The sizes are taken unsigned, and so the indices made from them:
    numba then adds no negative-index wraparound to each read of Mq and G (docs/performance.md,
    CRBA)."""
    n = np.uint64(n)
    m = np.uint64(m)
    for i in range(m):
        for j in range(i, m):
            s = 0.0
            for k in range(n):
                gk = G[k * m + i]
                if gk == 0.0:
                    continue
                t = 0.0
                for l in range(n):  # noqa: E741
                    t += Mq[k, l] * G[l * m + j]
                s += gk * t
            Mp[i, j] = s
            Mp[j, i] = s
        Mp[i, i] += arm_p[i]


@hot
def cholesky_solve(m, A, b, x, L):  # pragma: no cover - compiled
    """Solve A x = b for symmetric positive definite A (m×m) by Cholesky; L is scratch (m×m).
    Returns False when A is not positive definite."""
    for j in range(m):
        s = A[j, j]
        for k in range(j):
            s -= L[j, k] * L[j, k]
        if s <= 0.0:
            return False
        d = math.sqrt(s)
        L[j, j] = d
        for i in range(j + 1, m):
            s = A[i, j]
            for k in range(j):
                s -= L[i, k] * L[j, k]
            L[i, j] = s / d
    for i in range(m):
        s = b[i]
        for k in range(i):
            s -= L[i, k] * x[k]
        x[i] = s / L[i, i]
    for i in range(m - 1, -1, -1):
        s = x[i]
        for k in range(i + 1, m):
            s -= L[k, i] * x[k]
        x[i] = s / L[i, i]
    return True


@hot
def frames_into(n, R, P, T):  # pragma: no cover - compiled
    """Base-to-link transforms: T[k] (4×4 as 16 row-major) = ^{0}_{k+1}T for k = 0..n−1."""
    for k in range(n):
        if k == 0:
            for i in range(3):
                for j in range(3):
                    T[0, 4 * i + j] = R[0, 3 * i + j]
                T[0, 4 * i + 3] = P[0, i]
        else:
            for i in range(3):
                for j in range(3):
                    s = 0.0
                    for l in range(3):  # noqa: E741
                        s += T[k - 1, 4 * i + l] * R[k, 3 * l + j]
                    T[k, 4 * i + j] = s
                s = T[k - 1, 4 * i + 3]
                for l in range(3):  # noqa: E741
                    s += T[k - 1, 4 * i + l] * P[k, l]
                T[k, 4 * i + 3] = s
        T[k, 12] = 0.0
        T[k, 13] = 0.0
        T[k, 14] = 0.0
        T[k, 15] = 1.0


@hot
def point_jacobian(n, jtype, T, px, py, pz, J):  # pragma: no cover - compiled
    """Geometric Jacobian (6×n: linear rows 0–2, angular rows 3–5) of the point (px, py, pz)
    (base frame) rigidly attached to the last link, from the link frames T (see frames_into)."""
    for k in range(n):
        zx = T[k, 2]
        zy = T[k, 6]
        zz = T[k, 10]
        if jtype[k] == REVOLUTE:
            rx = px - T[k, 3]
            ry = py - T[k, 7]
            rz = pz - T[k, 11]
            J[0, k] = zy * rz - zz * ry
            J[1, k] = zz * rx - zx * rz
            J[2, k] = zx * ry - zy * rx
            J[3, k] = zx
            J[4, k] = zy
            J[5, k] = zz
        else:
            J[0, k] = zx
            J[1, k] = zy
            J[2, k] = zz
            J[3, k] = 0.0
            J[4, k] = 0.0
            J[5, k] = 0.0


@hot
def joints_from_actuators(n, m, G, q0, p, q):  # pragma: no cover - compiled
    """q = Γ p + q₀."""
    for k in range(n):
        s = q0[k]
        for j in range(m):
            s += G[k * m + j] * p[j]
        q[k] = s
