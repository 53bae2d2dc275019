"""URDF chains (``gripkit.multibody.from_urdf``) against Pinocchio (``pin``) on random states, to
1e-10: inverse dynamics, mass matrix, gravity, forward dynamics and the inertial-parameter
regressor (``pinocchio.computeJointTorqueRegressor``), for URDFs with mimic joints, rotated
inertials, rotated joint origins, arbitrary axes, fixed links (merged) and prismatic joints.

The same XML text goes to both parsers (Pinocchio's own URDF reader, ``mimic=True``)."""

import math

import numpy as np
import pinocchio as pin
import pytest

from gripkit.errors import ModelError
from gripkit.multibody import from_urdf

TOL = 1e-10


def _v(x):
    return " ".join(repr(float(a)) for a in x)


def random_inertial(rng, scale=1e-3):
    """xyz, rpy, mass and a physically valid (triangle inequality) principal inertia."""
    ev = rng.uniform(0.5, 1.0, 3) * scale
    return dict(xyz=rng.normal(size=3) * 0.05, rpy=rng.uniform(-math.pi, math.pi, 3),
                mass=rng.uniform(0.05, 1.0), I=ev)


def link_xml(name, inertial):
    if inertial is None:
        return f'<link name="{name}"/>'
    i = inertial
    ixx, iyy, izz = (float(x) for x in i["I"])
    return (f'<link name="{name}"><inertial><origin xyz="{_v(i["xyz"])}" rpy="{_v(i["rpy"])}"/>'
            f'<mass value="{float(i["mass"])!r}"/><inertia ixx="{ixx!r}" ixy="0" ixz="0" '
            f'iyy="{iyy!r}" iyz="0" '
            f'izz="{izz!r}"/></inertial></link>')


def joint_xml(name, jtype, parent, child, rng, axis=None, mimic=None, limit=True):
    xyz = rng.normal(size=3) * 0.1
    rpy = rng.uniform(-math.pi, math.pi, 3)
    s = f'<joint name="{name}" type="{jtype}"><origin xyz="{_v(xyz)}" rpy="{_v(rpy)}"/>'
    s += f'<parent link="{parent}"/><child link="{child}"/>'
    if jtype != "fixed":
        s += f'<axis xyz="{_v(axis)}"/>'
        if limit:
            s += '<limit lower="-2" upper="2" effort="10" velocity="3"/>'
    if mimic is not None:
        s += f'<mimic joint="{mimic[0]}" multiplier="{mimic[1]!r}" offset="{mimic[2]!r}"/>'
    return s + "</joint>"


def random_urdf(rng, spec):
    """A chain from a spec list of (type, axis or None, mimic or None); a fixed joint carries a
    link with an inertial (merged into its moving parent), and a fixed tip frame ends the chain."""
    parts = ['<robot name="rand">', link_xml("base", None)]
    parent = "base"
    for k, (jt, axis, mimic) in enumerate(spec):
        child = f"l{k}"
        parts.append(link_xml(child, random_inertial(rng)))
        parts.append(joint_xml(f"j{k}", jt, parent, child, rng, axis=axis, mimic=mimic))
        parent = child
    # a sensor link without inertial and a fixed tip frame
    parts.append(link_xml("sensor", None))
    parts.append(joint_xml("sensor_joint", "fixed", "l1", "sensor", rng))
    parts.append(link_xml("tip", None))
    parts.append(joint_xml("tip_joint", "fixed", parent, "tip", rng))
    return "".join(parts) + "</robot>"


SPECS = {
    "revolute-z": [("revolute", (0, 0, 1), None)] * 3,
    "mixed-axes": [("revolute", (1, 0, 0), None), ("revolute", (0, -1, 0), None),
                   ("prismatic", (0.3, -0.5, 0.8), None),
                   ("revolute", (0, 0, -1), None)],
    "mimic": [("revolute", (0, 0, 1), None), ("revolute", (0, 1, 0), None),
              ("revolute", (1, 0, 0), None),
              ("revolute", (0.6, 0, 0.8), ("j2", 0.7, 0.2))],
    "fixed-links": [("revolute", (0, 0, 1), None), ("fixed", None, None),
                    ("revolute", (0, 1, 0), None),
                    ("prismatic", (0, 0, 1), ("j0", -0.5, 0.0))],
}


def _pin(xml, gravity):
    model = pin.buildModelFromXML(xml, mimic=True)
    model.gravity.linear = np.asarray(gravity, dtype=float)
    return model, model.createData()


@pytest.fixture(scope="module", params=sorted(SPECS))
def pair(request):
    rng = np.random.default_rng(sorted(SPECS).index(request.param) + 3)
    xml = random_urdf(rng, SPECS[request.param])
    g = rng.normal(size=3) * 5
    chain = from_urdf(xml, gravity=g)
    chain.urdf_text = xml
    model, data = _pin(xml, g)
    return chain, model, data, rng


def test_names_and_size(pair):
    chain, model, data, _ = pair
    assert chain.dof == model.nq == model.nv
    # Pinocchio's joint 0 is the universe; mimic joints have nq = 0
    pin_names = [model.names[i] for i in range(1, model.njoints) if model.joints[i].nq > 0]
    assert list(chain.joint_names) == pin_names


def test_rnea_mass_gravity_fd(pair):
    chain, model, data, rng = pair
    m = chain.dof
    B = 20
    q, qd, qdd = (rng.uniform(-1.5, 1.5, size=(B, m)) for _ in range(3))
    tau = chain.rnea(q, qd, qdd)
    M = chain.mass_matrix(q)
    G = chain.gravity(q)
    for b in range(B):
        ref = pin.rnea(model, data, q[b], qd[b], qdd[b])
        np.testing.assert_allclose(tau[b], ref, atol=TOL, rtol=0)
        # one-state path
        np.testing.assert_allclose(chain.rnea(q[b], qd[b], qdd[b]), ref, atol=TOL, rtol=0)
        Mp = pin.crba(model, data, q[b])
        Mp = np.triu(Mp) + np.triu(Mp, 1).T
        np.testing.assert_allclose(M[b], Mp, atol=TOL, rtol=0)
        np.testing.assert_allclose(chain.mass_matrix(q[b]), Mp, atol=TOL, rtol=0)  # one-state path
        np.testing.assert_allclose(G[b], pin.computeGeneralizedGravity(model, data, q[b]), atol=TOL,
                                   rtol=0)
    qdd_fd = chain.forward_dynamics(q, qd, tau)
    np.testing.assert_allclose(qdd_fd, qdd, atol=1e-8, rtol=0)


def test_regressor_matches_pinocchio(pair):
    chain, model, data, rng = pair
    m = chain.dof
    q, qd, qdd = (rng.uniform(-1.5, 1.5, size=(8, m)) for _ in range(3))
    Y = chain.regressor(q, qd, qdd)
    phi = chain.standard_parameters()
    np.testing.assert_allclose(np.einsum("bij,j->bi", Y, phi), chain.rnea(q, qd, qdd), atol=TOL,
                               rtol=0)
    # Pinocchio's regressor does not take mimic joints: use the full model (every joint free) and
    # project, Y = Γᵀ Y_full(Γ q + q₀, Γ q̇, Γ q̈)
    full = pin.buildModelFromXML(chain.urdf_text, mimic=False)
    full.gravity.linear = chain.gravity_vector
    fdata = full.createData()
    Gm = chain.coupling
    moving = list(range(1, full.njoints))
    assert Y.shape[2] == 10 * len(moving)
    for b in range(len(q)):
        Yp = (Gm.T @ pin.computeJointTorqueRegressor(full, fdata, chain.joints(q[b]), Gm @ qd[b],
                                                     Gm @ qdd[b]))
        np.testing.assert_allclose(Y[b], Yp, atol=TOL, rtol=0)
    ref = np.concatenate([full.inertias[i].toDynamicParameters() for i in moving])
    np.testing.assert_allclose(phi, ref, atol=1e-14, rtol=0)


def test_fk_matches_pinocchio(pair):
    chain, model, data, rng = pair
    q = rng.uniform(-1.5, 1.5, size=chain.dof)
    pin.framesForwardKinematics(model, data, q)
    T = chain.fk(q)
    ref = data.oMf[model.getFrameId("tip")]
    np.testing.assert_allclose(T[:3, :3], ref.rotation, atol=TOL)
    np.testing.assert_allclose(T[:3, 3], ref.translation, atol=TOL)


def test_limits_kept(pair):
    chain, *_ = pair
    np.testing.assert_array_equal(chain.limits.lower, -2.0)
    np.testing.assert_array_equal(chain.limits.upper, 2.0)
    np.testing.assert_array_equal(chain.limits.velocity, 3.0)
    np.testing.assert_array_equal(chain.limits.effort, 10.0)


# --- errors name the element ----------------------------------------------------------------------

def _xml(body):
    return f'<robot name="r">{body}</robot>'


L = ('<link name="{}"><inertial><mass value="1"/><inertia ixx="1" iyy="1" '
     'izz="1"/></inertial></link>')
J = ('<joint name="{}" type="{}"><parent link="{}"/><child link="{}"/><axis xyz="0 0 1"/>'
     '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>')


@pytest.mark.parametrize("body, match", [
    (L.format("a") + L.format("b") + L.format("c") + J.format("j1", "revolute", "a", "b")
     + J.format("j2", "revolute", "c", "b"), "link 'b' is the child of joints 'j1' and "
                                             "'j2'.*closed loop"),
    (L.format("a") + L.format("b") + L.format("c") + L.format("d") + J.format("j1", "revolute", "a",
                                                                              "b")
     + J.format("j2", "revolute", "c", "d"), "several trees.*'a', 'c'"),
    (L.format("a") + '<link name="b"/>' + J.format("j1", "revolute", "a", "b"),
     "link 'b', moved by joint 'j1', has no <inertial>"),
    (L.format("a") + L.format("b") + J.format("j1", "floating", "a", "b"),
     "joint 'j1' has type 'floating'"),
    (L.format("a") + L.format("b") + J.format("j1", "planar", "a", "b"),
     "joint 'j1' has type 'planar'"),
    (L.format("a") + L.format("b") + J.format("j1", "revolute", "a", "b").replace("0 0 1", "0 x 1"),
     r"joint 'j1' <axis xyz>: expected 3 numbers, found '0 x 1'"),
    (L.format("a") + L.format("b").replace('value="1"',
                                           'value="heavy"') + J.format("j1", "revolute", "a", "b"),
     r"link 'b' <mass>: value='heavy' is not a number"),
    (L.format("a") + L.format("b") + L.format("c") + J.format("j1", "revolute", "a", "b")
     + J.format("j2", "revolute", "a", "c"), "link 'a' carries several chains"),
    (L.format("a") + L.format("b") + J.format("j1", "revolute", "a",
                                              "b").replace("</joint>",
                                                           '<mimic joint="zz"/></joint>'),
     "joint 'j1' mimics 'zz', which is not a moving joint"),
    (L.format("a") + L.format("b") + J.format("j1", "revolute", "a", "x"), "joint 'j1': child link "
                                                                           "'x' is not defined"),
])
def test_clear_errors(body, match):
    with pytest.raises(ModelError, match=match):
        from_urdf(_xml(body))


def test_branch_needs_tip_link_and_tip_link_selects():
    body = (L.format("a") + L.format("b") + L.format("c") + L.format("d")
            + J.format("j1", "revolute", "a", "b")
            + J.format("j2", "revolute", "b", "c") + J.format("j3", "revolute", "b", "d"))
    with pytest.raises(ModelError, match="the chain branches at link 'b'"):
        from_urdf(_xml(body))
    with pytest.raises(ModelError, match="joint 'j3' \\(revolute\\) branches off the "
                                         "chain at link 'b'"):
        from_urdf(_xml(body), tip_link="c")


def test_missing_file_and_bad_xml(tmp_path):
    with pytest.raises(ModelError, match="does not exist"):
        from_urdf(tmp_path / "none.urdf")
    with pytest.raises(ModelError, match="not well-formed"):
        from_urdf("<robot><link></robot>")
