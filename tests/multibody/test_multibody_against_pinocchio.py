"""RNEA, mass matrix, Coriolis and gravity terms, forward dynamics, forward kinematics and
Jacobians agree with Pinocchio (``pin``) to 1e-10 on random states — for random modified-DH chains
(revolute and prismatic joints, armature) and for the coupled DLR/HIT finger.

The Pinocchio models are built here from the raw DH numbers (Craig's link transform
Rx(α)·Dx(a)·Rz(θ0)·Dz(d) as the joint placement), independently of gripkit's own exporter."""

import math

import numpy as np
import pytest

import pinocchio as pin  # a dev dependency: the cross-checks fail, never skip, without it

from gripkit.multibody import CoupledChain, Coupling, DHChain  # noqa: E402
from gripkit.multibody.pinocchio import to_pinocchio  # noqa: E402
from gripkit.systems.dlr_hit.parameters import finger

TOL = 1e-10


def _rx(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def _rz(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def pinocchio_model(alpha, a, d, off, types, mass, com, inertia, armature, gravity):
    """Pinocchio chain: joint i placed at Rx(α_{i-1}) Dx(a_{i-1}) Rz(θ0_i) Dz(d_i) in its parent."""
    model = pin.Model()
    parent = 0
    for k in range(len(alpha)):
        R = _rx(alpha[k]) @ _rz(off[k])
        p = np.array([a[k], 0.0, 0.0]) + _rx(alpha[k]) @ np.array([0.0, 0.0, d[k]])
        joint = pin.JointModelPZ() if types[k] == "P" else pin.JointModelRZ()
        parent = model.addJoint(parent, joint, pin.SE3(R, p), f"j{k}")
        model.appendBodyToJoint(parent, pin.Inertia(mass[k], np.asarray(com[k]),
                                                    np.asarray(inertia[k])),
                                pin.SE3.Identity())
    model.armature = np.asarray(armature, dtype=float)
    model.gravity.linear = np.asarray(gravity, dtype=float)
    return model, model.createData()


def random_inertia(rng, scale):
    """A physically valid inertia tensor (principal moments satisfying the triangle inequality)."""
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    ev = rng.uniform(0.5, 1.0, 3) * scale
    return Q @ np.diag(ev) @ Q.T


def random_chain(rng, types):
    n = len(types)
    kw = dict(alpha=rng.uniform(-math.pi, math.pi, n), a=rng.uniform(0, 0.3, n),
              d=rng.uniform(-0.2, 0.2, n),
              theta_offset=rng.uniform(-1, 1, n), joint_types=types, mass=rng.uniform(0.1, 2.0, n),
              com=rng.normal(size=(n, 3)) * 0.1,
              inertia=np.array([random_inertia(rng, 1e-3) for _ in range(n)]),
              armature=rng.uniform(0, 0.05, n), gravity=rng.normal(size=3) * 5)
    chain = DHChain(**kw)
    model, data = pinocchio_model(kw["alpha"], kw["a"], kw["d"], kw["theta_offset"], types,
                                  kw["mass"],
                                  kw["com"], kw["inertia"], kw["armature"], kw["gravity"])
    return chain, model, data


def full_crba(model, data, q):
    M = pin.crba(model, data, q)
    return np.triu(M) + np.triu(M, 1).T


@pytest.mark.parametrize("types", ["RRRRRR", "RRPRP", "PRR"])
def test_dh_chain_dynamics_match_pinocchio(types):
    rng = np.random.default_rng(len(types) * 7 + types.count("P"))
    chain, model, data = random_chain(rng, types)
    B = 40
    q, qd, qdd = (rng.normal(size=(B, chain.n)) for _ in range(3))
    tau = chain.rnea(q, qd, qdd)
    M = chain.mass_matrix(q)
    C = chain.coriolis(q, qd)
    G = chain.gravity(q)
    for b in range(B):
        np.testing.assert_allclose(tau[b], pin.rnea(model, data, q[b], qd[b], qdd[b]), atol=TOL,
                                   rtol=0)
        np.testing.assert_allclose(M[b], full_crba(model, data, q[b]), atol=TOL, rtol=0)
        g = pin.computeGeneralizedGravity(model, data, q[b])
        np.testing.assert_allclose(G[b], g, atol=TOL, rtol=0)
        np.testing.assert_allclose(C[b], pin.nonLinearEffects(model, data, q[b], qd[b]) - g,
                                   atol=TOL, rtol=0)
        np.testing.assert_allclose(chain.forward_dynamics(q[b], qd[b], tau[b]),
                                   pin.aba(model, data, q[b], qd[b], tau[b]), atol=1e-9, rtol=0)


@pytest.mark.parametrize("types", ["RRRRR", "RPRP"])
def test_kinematics_match_pinocchio(types):
    rng = np.random.default_rng(11)
    chain, model, data = random_chain(rng, types)
    tool = np.eye(4)
    tool[:3, 3] = [0.05, -0.02, 0.01]
    chain = chain.replace(tool=tool)
    for q in rng.normal(size=(10, chain.n)):
        pin.forwardKinematics(model, data, q)
        T = data.oMi[chain.n].homogeneous @ tool
        np.testing.assert_allclose(chain.fk(q), T, atol=TOL)
        frames = chain.frames(q)
        for k in range(chain.n):
            np.testing.assert_allclose(frames[k], data.oMi[k + 1].homogeneous, atol=TOL)
        # Jacobian of the tool point, world-aligned: Pinocchio's frame Jacobian at the tool frame
        fid = model.addFrame(pin.Frame("tool", chain.n, 0, pin.SE3(tool[:3, :3], tool[:3, 3]),
                                       pin.OP_FRAME)) \
            if not model.existFrame("tool") else model.getFrameId("tool")
        data = model.createData()
        J = pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL_WORLD_ALIGNED)
        np.testing.assert_allclose(chain.jacobian(q), J, atol=TOL)


def test_coupled_finger_matches_pinocchio_reduced_model():
    """The finger (4 DH joints, θ4 = θ3, bevel differential, rotor inertia Im·N²) in actuator
    coordinates: M_p = Γᵀ M Γ + diag(Im N²), h_p = Γᵀ h, G_p = Γᵀ G, with M, h, G from a Pinocchio
    model of the 4-joint chain built from the thesis's DH table (Appendix A/F)."""
    f = finger(check=False)
    ch = f.chain()
    c = ch.chain
    I = c.inertia  # noqa: E741
    model, data = pinocchio_model(c.dh[:, 0], c.dh[:, 1], c.dh[:, 2], c.dh[:, 3], "RRRR", c.mass,
                                  c.com, I,
                                  np.zeros(4), c.gravity_vector)
    Gm = ch.coupling.matrix
    arm = ch.coupling.armature
    # the coupling reproduces the thesis: θ4 = θ3, abduction/flexion from the ±45° motors
    np.testing.assert_allclose(Gm[3], Gm[2])
    s = math.sqrt(0.5)
    np.testing.assert_allclose(Gm[:2, :2], [[-s, s], [s, s]], atol=1e-15)
    np.testing.assert_allclose(arm, 5.1e-7 * np.array([234.3375, 234.3375, 208.3]) ** 2, rtol=1e-12)
    rng = np.random.default_rng(5)
    B = 30
    p, pd, pdd = (rng.normal(size=(B, 3)) for _ in range(3))
    tau = ch.rnea(p, pd, pdd)
    M = ch.mass_matrix(p)
    G = ch.gravity(p)
    C = ch.coriolis(p, pd)
    for b in range(B):
        q, qd, qdd = Gm @ p[b], Gm @ pd[b], Gm @ pdd[b]
        Mq = full_crba(model, data, q)
        g = pin.computeGeneralizedGravity(model, data, q)
        np.testing.assert_allclose(M[b], Gm.T @ Mq @ Gm + np.diag(arm), atol=TOL, rtol=0)
        np.testing.assert_allclose(G[b], Gm.T @ g, atol=TOL, rtol=0)
        np.testing.assert_allclose(C[b], Gm.T @ (pin.nonLinearEffects(model, data, q, qd) - g),
                                   atol=TOL, rtol=0)
        np.testing.assert_allclose(tau[b], Gm.T @ pin.rnea(model, data, q, qd, qdd) + arm * pdd[b],
                                   atol=TOL, rtol=0)


def test_exporter_matches_independent_model():
    rng = np.random.default_rng(3)
    chain, model, data = random_chain(rng, "RPRR")
    m2, d2 = to_pinocchio(chain)
    for q in rng.normal(size=(5, 4)):
        np.testing.assert_allclose(full_crba(m2, d2, q), full_crba(model, data, q), atol=TOL)
        np.testing.assert_allclose(pin.computeGeneralizedGravity(m2, d2, q),
                                   pin.computeGeneralizedGravity(model, data, q), atol=TOL)


def test_large_batches_run_in_parallel_with_the_same_result():
    rng = np.random.default_rng(9)
    chain, _, _ = random_chain(rng, "RRRR")
    q, qd, qdd = (rng.normal(size=(600, 4)) for _ in range(3))
    np.testing.assert_allclose(chain.rnea(q, qd, qdd, parallel=True),
                               chain.rnea(q, qd, qdd, parallel=False),
                               atol=1e-13, rtol=0)


def test_identity_coupling_equals_plain_chain():
    rng = np.random.default_rng(2)
    chain, _, _ = random_chain(rng, "RRR")
    cc = CoupledChain(chain, Coupling(np.eye(3), np.zeros(3), np.zeros(3), ("a", "b", "c")))
    q, qd = rng.normal(size=(2, 3))
    np.testing.assert_allclose(cc.mass_matrix(q), chain.mass_matrix(q), atol=1e-14)
    np.testing.assert_allclose(cc.bias(q, qd), chain.bias(q, qd), atol=1e-14)
