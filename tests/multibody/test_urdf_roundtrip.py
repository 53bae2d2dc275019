"""``to_urdf`` / ``from_urdf`` round trips: the DLR/HIT Hand II finger (``002_ddea254371185ad3.txt``
§4.5: θ₄ = θ₃ through the distal steel wire, a ``<mimic>`` joint) written as a URDF and read back —
by gripkit and by Pinocchio — has the same dynamics to 1e-12; random DH chains and URDF chains
survive the round trip; the regressor reproduces RNEA with the rotor-inertia term."""

import math
import warnings

import numpy as np
import pytest

from gripkit.errors import ConsistencyWarning, GripkitWarning, ModelError
from gripkit.multibody import CoupledChain, Coupling, DHChain, from_urdf, to_urdf

TOL = 1e-12


@pytest.fixture(scope="module")
def finger_chain():
    """The DLR/HIT finger's coupled chain, through the zoo registry (one place to update)."""
    from gripkit import zoo

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConsistencyWarning)
        return zoo.build("dlr-hit-finger").chain()


@pytest.fixture(scope="module")
def finger_urdf(finger_chain, tmp_path_factory):
    path = tmp_path_factory.mktemp("urdf") / "dlr_hit_finger.urdf"
    with pytest.warns(GripkitWarning, match="rotor inertia.*transmission from the actuators"):
        to_urdf(finger_chain, path)
    return path


def _joint_space(ch):
    """The finger's links with only the distal coupling θ₄ = θ₃ (what URDF can hold)."""
    G = np.zeros((4, 3))
    G[0, 0] = G[1, 1] = G[2, 2] = G[3, 2] = 1.0
    return (CoupledChain(ch.chain.replace(armature=np.zeros(4)),
                         Coupling(G, np.zeros(4), np.zeros(3), ch.chain.names[:3])))


def _states(rng, m, B=25):
    return tuple(rng.uniform(-1.2, 1.2, size=(B, m)) for _ in range(3))


def test_finger_urdf_structure(finger_urdf, finger_chain):
    u = from_urdf(finger_urdf, gravity=finger_chain.chain.gravity_vector)
    assert u.joint_names == ("theta1", "theta2", "theta3")
    assert u.names == ("theta1", "theta2", "theta3", "theta4")
    np.testing.assert_array_equal(u.coupling, [[1, 0, 0], [0, 1, 0], [0, 0, 1], [0, 0, 1]])
    text = finger_urdf.read_text()
    assert '<mimic joint="theta3" multiplier="1.0" offset="0.0"' in text


def test_finger_round_trip_dynamics(finger_urdf, finger_chain):
    u = from_urdf(finger_urdf, gravity=finger_chain.chain.gravity_vector)
    ref = _joint_space(finger_chain)
    q, qd, qdd = _states(np.random.default_rng(1), 3)
    np.testing.assert_allclose(u.rnea(q, qd, qdd), ref.rnea(q, qd, qdd), atol=TOL, rtol=0)
    np.testing.assert_allclose(u.mass_matrix(q), ref.mass_matrix(q), atol=TOL, rtol=0)
    np.testing.assert_allclose(u.gravity(q), ref.gravity(q), atol=TOL, rtol=0)
    np.testing.assert_allclose(u.regressor(q, qd, qdd), ref.regressor(q, qd, qdd), atol=TOL, rtol=0)
    np.testing.assert_allclose(u.standard_parameters(), ref.standard_parameters(), atol=1e-15,
                               rtol=0)
    np.testing.assert_allclose(u.fk(q), ref.fk(q), atol=TOL, rtol=0)
    np.testing.assert_allclose(u.jacobian(q), ref.jacobian(q), atol=TOL, rtol=0)


def test_finger_actuator_space_from_urdf(finger_urdf, finger_chain):
    """The motors' dynamics follow from the URDF's by the differential u = T p and the rotor
    inertia that the URDF cannot hold: τ_p = Tᵀ τ_u(T p, T ṗ, T p̈) + diag(I_m N²) p̈."""
    u = from_urdf(finger_urdf, gravity=finger_chain.chain.gravity_vector)
    T = finger_chain.coupling.matrix[:3]
    p, pd, pdd = _states(np.random.default_rng(2), 3)
    tau_p = (u.rnea(p @ T.T, pd @ T.T, pdd @ T.T)) @ T + pdd * finger_chain.coupling.armature
    np.testing.assert_allclose(tau_p, finger_chain.rnea(p, pd, pdd), atol=TOL, rtol=0)


def test_finger_urdf_in_pinocchio(finger_urdf, finger_chain):
    import pinocchio as pin
    model = pin.buildModelFromUrdf(str(finger_urdf), mimic=True)
    model.gravity.linear = finger_chain.chain.gravity_vector
    data = model.createData()
    assert model.nq == 3
    ref = _joint_space(finger_chain)
    q, qd, qdd = _states(np.random.default_rng(3), 3, B=10)
    for b in range(10):
        np.testing.assert_allclose(pin.rnea(model, data, q[b], qd[b], qdd[b]),
                                   ref.rnea(q[b], qd[b], qdd[b]),
                                   atol=TOL, rtol=0)
        M = pin.crba(model, data, q[b])
        np.testing.assert_allclose(np.triu(M) + np.triu(M, 1).T, ref.mass_matrix(q[b]), atol=TOL,
                                   rtol=0)


def test_regressor_with_rotor_inertia(finger_chain):
    """τ = Y φ + A q̈ on the coupled finger (A = Γᵀ diag(arm_q) Γ + diag(I_m N²))."""
    p, pd, pdd = _states(np.random.default_rng(4), 3)
    Y = finger_chain.regressor(p, pd, pdd)
    tau = Y @ finger_chain.standard_parameters() + pdd @ finger_chain.armature_matrix().T
    np.testing.assert_allclose(tau, finger_chain.rnea(p, pd, pdd), atol=TOL, rtol=0)
    assert len(finger_chain.parameter_names) == Y.shape[-1] == 40


def _random_dh(rng, types, base=None):
    n = len(types)
    Q = [np.linalg.qr(rng.normal(size=(3, 3)))[0] for _ in range(n)]
    inertia = np.array([q @ np.diag(rng.uniform(0.5, 1.0, 3) * 1e-3) @ q.T for q in Q])
    tool = np.eye(4)
    tool[:3, 3] = rng.normal(size=3) * 0.05
    return DHChain(alpha=rng.uniform(-math.pi, math.pi, n), a=rng.uniform(0, 0.3, n),
                   d=rng.uniform(-0.2, 0.2, n),
                   theta_offset=rng.uniform(-1, 1, n), joint_types=types,
                   mass=rng.uniform(0.1, 2.0, n),
                   com=rng.normal(size=(n, 3)) * 0.1, inertia=inertia,
                   gravity=rng.normal(size=3) * 5,
                   tool=tool, base=base)


@pytest.mark.parametrize("types", ["RRR", "RPRR", "PRP"])
def test_dh_round_trip(types, tmp_path):
    rng = np.random.default_rng(len(types))
    base = np.eye(4)
    base[:3, :3] = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    if np.linalg.det(base[:3, :3]) < 0:
        base[:3, 0] *= -1
    base[:3, 3] = rng.normal(size=3)
    ch = _random_dh(rng, types, base=base)
    path = to_urdf(ch, tmp_path / "c.urdf")
    # URDF's root is the world frame: gravity rotates with the base
    u = from_urdf(path, gravity=base[:3, :3] @ ch.gravity_vector)
    q, qd, qdd = _states(rng, len(types))
    np.testing.assert_allclose(u.rnea(q, qd, qdd), ch.rnea(q, qd, qdd), atol=TOL, rtol=0)
    np.testing.assert_allclose(u.mass_matrix(q), ch.mass_matrix(q), atol=TOL, rtol=0)
    np.testing.assert_allclose(u.fk(q), ch.fk(q), atol=TOL, rtol=0)
    # and once more through the URDF chain itself
    u2 = from_urdf(to_urdf(u, tmp_path / "c2.urdf"), gravity=u.gravity_vector)
    np.testing.assert_allclose(u2.rnea(q, qd, qdd), u.rnea(q, qd, qdd), atol=TOL, rtol=0)
    np.testing.assert_array_equal(u2.limits.lower, u.limits.lower)


def test_to_urdf_refuses_unknown_objects(tmp_path):
    with pytest.raises(ModelError, match="expected a DHChain, CoupledChain or "
                                         "JointChain, found str"):
        to_urdf("arm", tmp_path / "x.urdf")
