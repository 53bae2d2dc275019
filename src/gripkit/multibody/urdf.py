"""URDF chains: read a serial chain from a URDF file (:func:`from_urdf`) and write any gripkit
chain as one (:func:`to_urdf`).

Reading (standard library ``xml.etree.ElementTree``; URDF as specified at wiki.ros.org/urdf/XML):

* the chain runs from ``base_link`` (default: the only root of the tree) to ``tip_link``
  (default: where the tree stops having moving joints; a branch of moving joints needs an
  explicit ``tip_link``);
* ``revolute``, ``continuous`` and ``prismatic`` joints move; ``fixed`` joints are merged: a
  link fixed to a moving link adds its inertia to it, the links fixed to the base are ignored
  (they do not move), and fixed joints between two moving joints fold into the placement;
* ``<origin xyz rpy>``: translation and R = Rz(yaw)·Ry(pitch)·Rx(roll); ``<axis>`` defaults to
  (1, 0, 0); inertials may be rotated (``<inertial><origin rpy>``): I_link = R I Rᵀ;
* ``<mimic joint multiplier offset>`` joints follow their leader: q_full = Γ q + q₀ and
  τ = Γᵀ τ_full (:mod:`gripkit.multibody.joints`); ``joint_names`` are the actuated joints;
* ``<limit lower upper velocity effort>`` of the actuated joints are kept (``chain.limits``);
  a ``velocity`` or ``effort`` of 0, which many URDF files write for "unspecified", reads as no
  limit, and a continuous joint has no position limits.

Errors name the element: a link with two parents (a closed loop), several roots without
``base_link``, a branching chain without ``tip_link``, a moving link without ``<inertial>``, an
unsupported joint type (floating, planar), malformed numbers, mimic joints off the chain. A
document that declares a DTD (``<!DOCTYPE``, where entities live) is refused before anything is
expanded or fetched: a URDF needs none, and a file must not reach outside itself.

Writing: each joint of a DH chain becomes a URDF joint whose origin is Craig's fixed transform
Rx(α)·Dx(a)·Rz(θ₀)·Dz(d) and whose axis is z, with the link's inertial in the DH frame; a coupled
chain's joints whose rows of Γ are multiples of an earlier joint's row become ``<mimic>`` joints
(the DLR/HIT finger's distal joint). What URDF cannot hold — a transmission that mixes actuators
(the finger's bevel-gear differential) and rotor inertia — is left out with a warning: the file's
coordinates are then the independent joints, not the actuators.
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from xml.parsers import expat
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..arguments import entry_point
from ..atomic import atomic_write
from ..errors import GripkitWarning, ModelError, PathError, emit_warning
from .coupling import CoupledChain
from .dh import DHChain
from .joints import JointChain, JointLimits

__all__ = ["from_urdf", "to_urdf"]

_MOVING = {"revolute": "R", "continuous": "R", "prismatic": "P"}
_SUPPORTED = set(_MOVING) | {"fixed"}


# --- reading --------------------------------------------------------------------------------------

def _numbers(text: str | None, count: int, where: str, default=None) -> np.ndarray:
    if text is None:
        if default is None:
            raise ModelError(f"{where}: missing, expected {count} numbers")
        return np.asarray(default, dtype=np.float64)
    parts = text.split()
    try:
        v = np.array([float(p) for p in parts], dtype=np.float64)
    except ValueError:
        raise ModelError(f"{where}: expected {count} numbers, found {text!r}") from None
    if v.size != count or not np.isfinite(v).all():
        raise ModelError(f"{where}: expected {count} finite numbers, found {text!r}")
    return v


def _number(el, attr: str, where: str, default: float | None = None) -> float:
    text = el.get(attr) if el is not None else None
    if text is None:
        if default is None:
            raise ModelError(f"{where}: attribute {attr!r} is missing")
        return float(default)
    try:
        v = float(text)
    except ValueError:
        raise ModelError(f"{where}: {attr}={text!r} is not a number") from None
    if math.isnan(v):
        raise ModelError(f"{where}: {attr} is NaN")
    return v


def rpy_matrix(rpy) -> np.ndarray:
    """R = Rz(yaw)·Ry(pitch)·Rx(roll) (URDF's fixed-axis roll-pitch-yaw)."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = (math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y),
                              math.sin(y))
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def matrix_rpy(R) -> tuple[float, float, float]:
    """Roll, pitch, yaw of a rotation (inverse of :func:`rpy_matrix`)."""
    sp = -R[2, 0]
    if abs(sp) < 1.0 - 1e-12:
        return (math.atan2(R[2, 1], R[2, 2]), math.asin(max(-1.0, min(1.0, sp))),
                math.atan2(R[1, 0], R[0, 0]))
    # gimbal lock: roll and yaw share one axis; put it all in yaw
    pitch = math.copysign(math.pi / 2, sp)
    return (0.0, pitch, math.atan2(-R[0, 1], R[1, 1]))


def _child(el, tag: str, where: str):
    """The child element ``<tag>`` of ``el``, or a ModelError saying it is missing."""
    child = el.find(tag)
    if child is None:
        raise ModelError(f"{where}: <{tag}> is missing")
    return child


def _origin(el, where: str) -> np.ndarray:
    T = np.eye(4)
    o = el.find("origin") if el is not None else None
    if o is not None:
        T[:3, 3] = _numbers(o.get("xyz"), 3, f"{where} <origin xyz>", default=(0, 0, 0))
        T[:3, :3] = (rpy_matrix(_numbers(o.get("rpy"), 3, f"{where} <origin rpy>",
                                         default=(0, 0, 0))))
    return T


def _inertial(link, where: str):
    """(mass, com, inertia about the COM) in the link frame, or None without <inertial>."""
    el = link.find("inertial")
    if el is None:
        return None
    mass = _number(_child(el, "mass", f"{where} <inertial>"), "value", f"{where} <mass>")
    i_el = _child(el, "inertia", f"{where} <inertial>")
    v = ({a: _number(i_el, a, f"{where} <inertia>",
                     default=0.0) for a in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")})
    Ic = (np.array([[v["ixx"], v["ixy"], v["ixz"]], [v["ixy"], v["iyy"], v["iyz"]],
                    [v["ixz"], v["iyz"], v["izz"]]]))
    T = _origin(el, f"{where} <inertial>")
    R = T[:3, :3]
    return mass, T[:3, 3].copy(), R @ Ic @ R.T


def _combine(a, b):
    """Inertial data of two rigid bodies welded together (same frame)."""
    m1, c1, I1 = a
    m2, c2, I2 = b
    m = m1 + m2
    if m == 0.0:
        return 0.0, np.zeros(3), I1 + I2
    c = (m1 * c1 + m2 * c2) / m

    def shift(mk, ck, Ik):
        d = ck - c
        return Ik + mk * (d @ d * np.eye(3) - np.outer(d, d))

    return m, c, shift(m1, c1, I1) + shift(m2, c2, I2)


def _transform_inertial(T, data):
    m, c, I = data  # noqa: E741
    R = T[:3, :3]
    return m, R @ c + T[:3, 3], R @ I @ R.T


def _named(robot, tag: str, seen: dict):
    """(name, element) of each ``<tag>`` of ``robot``; its name must be present and not yet in
    ``seen`` (which the caller fills as it goes)."""
    for el in robot.findall(tag):
        name = el.get("name")
        if not name:
            raise ModelError(f"<{tag}> without a name attribute")
        if name in seen:
            raise ModelError(f"{tag} {name!r} is defined twice")
        yield name, el


class _Tree:
    def __init__(self, robot):
        self.links = {}
        for name, el in _named(robot, "link", self.links):
            self.links[name] = el
        if not self.links:
            raise ModelError("the URDF has no <link>")
        self.joints = {}
        self.parent = {}      # child link -> joint name
        self.children = {name: [] for name in self.links}
        for name, el in _named(robot, "joint", self.joints):
            jtype = el.get("type")
            p_el, c_el = el.find("parent"), el.find("child")
            if p_el is None or c_el is None:
                raise ModelError(f"joint {name!r}: <parent link> and <child link> are required")
            parent, child = p_el.get("link"), c_el.get("link")
            for role, link in (("parent", parent), ("child", child)):
                if link not in self.links:
                    raise ModelError(f"joint {name!r}: {role} link {link!r} is not defined")
            if child in self.parent:
                raise ModelError(f"link {child!r} is the child of joints "
                                 f"{self.parent[child]!r} and {name!r}: "
                                 f"the URDF has a closed loop; gripkit needs a tree",
                                 hint="cut the loop (keep one parent joint) and model it as a "
                                      "mimic or a constraint")
            self.joints[name] = (el, jtype, parent, child)
            self.parent[child] = name
            self.children[parent].append(name)
        self.roots = [name for name in self.links if name not in self.parent]
        if not self.roots:
            raise ModelError("every link has a parent joint: the URDF's joints form a closed loop")
        reach = set()
        stack = list(self.roots)
        while stack:
            link = stack.pop()
            reach.add(link)
            stack.extend(self.joints[j][3] for j in self.children[link])
        self._moves = None  # see subtree_moves
        lost = [name for name in self.links if name not in reach]
        if lost:
            raise ModelError(f"links {lost[:3]} are not reachable from a root: their joints "
                             "form a closed loop")

    def subtree_moves(self, link) -> bool:
        """Whether a moving joint hangs anywhere below ``link`` (computed for every link at the
        first call, without recursion: chains of thousands of fixed joints are fine)."""
        moves = self._moves
        if moves is None:
            moves = self._moves = dict.fromkeys(self.links, False)
            order, stack = [], list(self.roots)
            while stack:  # pre-order; read backwards, children come before their parents
                link_ = stack.pop()
                order.append(link_)
                stack.extend(self.joints[j][3] for j in self.children[link_])
            for link_ in reversed(order):
                moves[link_] = any(self.joints[j][1] != "fixed" or moves[self.joints[j][3]]
                                   for j in self.children[link_])
        return moves[link]

    def check_type(self, joint):
        jtype = self.joints[joint][1]
        if jtype not in _SUPPORTED:
            raise ModelError(f"joint {joint!r} has type {jtype!r}, which gripkit does not support",
                             hint="gripkit builds serial chains of revolute, continuous, prismatic "
                                  "and fixed joints")


class _Declared(Exception):
    """Raised by the pre-scan at a DTD: what the document declares."""


class _RootReached(Exception):
    """Raised by the pre-scan at the root element: no DTD can follow."""


def _xml_text(source) -> str | bytes | None:
    """``source`` as XML to parse (bytes as given, decoded by the parser as XML says; a string
    without a leading byte-order mark), or None where it is a path."""
    if isinstance(source, (bytes, bytearray, memoryview)):
        return bytes(source)
    if isinstance(source, str):
        text = source.lstrip("\ufeff")
        if text.lstrip().startswith("<"):
            return text
    return None


def _path_like(text: str) -> bool:
    """Whether a string that is not XML may be a file name (the messages name it then)."""
    return not ("<" in text or "\n" in text or len(text) > 255)


def _refuse_dtd(xml, name: str | None) -> None:
    """A ModelError where the document declares a DTD (internal or external, with or without
    entities), read with expat up to the root element only: a URDF needs none, and refusing
    it keeps a file from reaching outside itself (external entities) or expanding without
    bound (nested entities)."""
    def doctype(doctype_name, system_id, public_id, has_internal_subset):
        raise _Declared("a DTD (<!DOCTYPE " + doctype_name[:40]
                        + (" SYSTEM ..." if system_id else "") + ">)")

    def root(*_):
        raise _RootReached()

    p = expat.ParserCreate()
    p.StartDoctypeDeclHandler = doctype  # entities are declared inside a DTD only
    p.StartElementHandler = root
    try:
        p.Parse(xml, True)
    except _RootReached:
        return
    except _Declared as d:
        where = f"URDF file {name!r}" if name else "the URDF"
        raise ModelError(f"{where} declares {d}: gripkit reads no DTDs or entities (a URDF needs "
                         "none, and a file must not reach outside itself)",
                         hint="remove the <!DOCTYPE ...> declaration and write the values out"
                         ) from None
    except expat.ExpatError as exc:  # in the prolog: fail closed, never parse it further
        raise ModelError(f"the URDF is not well-formed XML: {exc}") from None


def _read_root(source):
    xml = _xml_text(source)
    name = None
    if xml is None:
        text = os.fspath(source) if isinstance(source, os.PathLike) else str(source)
        try:
            found = Path(text).is_file()
        except (OSError, ValueError):  # a name too long, or with a NUL, is no file
            found = False
        if not found:
            if not _path_like(text):
                raise ModelError(f"source: neither an existing file nor XML text (which starts "
                                 f"with '<'): {text[:40]!r}…",
                                 hint="pass the path of a .urdf file or the XML itself")
            raise ModelError(f"URDF file {text!r} does not exist")
        try:
            name, xml = Path(text).name, Path(text).read_bytes()
        except OSError as exc:  # no read permission, an I/O error
            raise PathError(f"URDF file {text!r} cannot be read ({exc.strerror or exc})",
                            hint="give the path of a file you may read (check its permissions: "
                                 "ls -l, chmod u+r)") from None
    _refuse_dtd(xml, name)
    try:
        root = ET.fromstring(xml)
    except ET.ParseError as exc:
        raise ModelError(f"the URDF is not well-formed XML: {exc}") from None
    if root.tag != "robot":
        raise ModelError(f"expected a <robot> root element, found <{root.tag}>")
    return root


def _base_link(tree: _Tree, base_link: str | None) -> str:
    """``base_link``, checked, or the tree's only root."""
    if base_link is None:
        if len(tree.roots) > 1:
            raise ModelError("the URDF holds several trees (roots "
                             f"{', '.join(map(repr, tree.roots[:5]))})",
                             hint="choose one with base_link=")
        return tree.roots[0]
    if base_link not in tree.links:
        raise ModelError(f"base_link {base_link!r} is not a link of the URDF")
    return base_link


def _path_to_end(tree: _Tree, base_link: str) -> tuple[list[str], str]:
    """The joints from ``base_link`` down its only chain of moving joints, then along a single
    fixed path to a tip frame if there is one; and the link where it ends. A branch of moving
    joints is an error (the user must choose ``tip_link``)."""
    path = []
    link = base_link
    while True:
        moving = ([j for j in tree.children[link] if tree.subtree_moves(tree.joints[j][3])
                   or tree.joints[j][1] != "fixed"])
        if len(moving) > 1:
            if path and any(tree.joints[j][1] != "fixed" for j in path):
                raise ModelError(f"the chain branches at link {link!r} into joints "
                                 f"{', '.join(map(repr, moving))}",
                                 hint="choose the chain's end with tip_link=")
            raise ModelError(f"link {link!r} carries several chains (joints "
                             f"{', '.join(map(repr, moving))})",
                             hint="choose the chain's end with tip_link= (and base_link=)")
        if moving:
            path.append(moving[0])
            link = tree.joints[moving[0]][3]
            continue
        # no more moving joints: follow a single fixed path to a tip frame, if there is one
        fixed = tree.children[link]
        if len(fixed) == 1 and path:
            path.append(fixed[0])
            link = tree.joints[fixed[0]][3]
            continue
        return path, link


def _path_to_tip(tree: _Tree, base_link: str, tip_link: str) -> list[str]:
    """The joints from ``base_link`` to ``tip_link``, which must hang below it."""
    if tip_link not in tree.links:
        raise ModelError(f"tip_link {tip_link!r} is not a link of the URDF")
    path = []
    link = tip_link
    while link != base_link:
        if link not in tree.parent:
            raise ModelError(f"tip_link {tip_link!r} does not hang below base_link {base_link!r}")
        j = tree.parent[link]
        path.append(j)
        link = tree.joints[j][2]
    path.reverse()
    return path


@dataclass
class _MovingJoints:
    """The chain's moving joints in order, as read from the path: placement (fixed joints before a
    moving joint folded in), unit axis, type letter, name, moved link, inertial data (mass, com,
    inertia about the com), limits (lower, upper, velocity, effort) and ``<mimic>`` (leader,
    multiplier, offset) by joint name; ``tool``: the fixed joints after the last moving one."""

    placements: list = field(default_factory=list)
    axes: list = field(default_factory=list)
    types: list = field(default_factory=list)
    names: list = field(default_factory=list)
    links: list = field(default_factory=list)
    inertials: list = field(default_factory=list)
    limits: list = field(default_factory=list)
    mimic: dict = field(default_factory=dict)
    tool: np.ndarray | None = None


def _axis(el, j: str) -> np.ndarray:
    """The unit ``<axis xyz>`` of joint ``j`` (default (1, 0, 0))."""
    ax_el = el.find("axis")
    axis = (_numbers(ax_el.get("xyz") if ax_el is not None else None, 3, f"joint {j!r} <axis xyz>",
                     default=(1, 0, 0)))
    if np.linalg.norm(axis) < 1e-12:
        raise ModelError(f"joint {j!r}: <axis xyz> is the zero vector")
    return axis / np.linalg.norm(axis)


def _limits(el, jtype: str, j: str) -> tuple[float, float, float, float]:
    """(lower, upper, velocity, effort) of joint ``j``: no position limits for a continuous joint
    or without ``<limit>``; a velocity or effort of 0 (or none) reads as no limit (module doc)."""
    lim = el.find("limit")
    where = f"joint {j!r} <limit>"
    if jtype == "continuous" or lim is None:
        lo, hi = -np.inf, np.inf
    else:
        lo, hi = _number(lim, "lower", where, 0.0), _number(lim, "upper", where, 0.0)
        if lo > hi:
            raise ModelError(f"{where}: lower {lo:g} > upper {hi:g}")
    vel = _number(lim, "velocity", where, 0.0) if lim is not None else 0.0
    eff = _number(lim, "effort", where, 0.0) if lim is not None else 0.0
    return (lo, hi, vel if vel > 0 else np.inf, eff if eff > 0 else np.inf)


def _mimic(el, j: str) -> tuple[str, float, float] | None:
    """(leader, multiplier, offset) of joint ``j``'s ``<mimic>``, or None."""
    mm = el.find("mimic")
    if mm is None:
        return None
    leader = mm.get("joint")
    if leader is None:
        raise ModelError(f"joint {j!r} <mimic>: attribute 'joint' is missing")
    return (leader, _number(mm, "multiplier", f"joint {j!r} <mimic>", 1.0),
            _number(mm, "offset", f"joint {j!r} <mimic>", 0.0))


def _moving_joints(tree: _Tree, path: list[str]) -> _MovingJoints:
    """Read the moving joints along ``path``; fixed joints before a moving joint fold into its
    placement, those after the last one into the tool frame."""
    out = _MovingJoints()
    T_acc = np.eye(4)
    for j in path:
        el, jtype, _, child = tree.joints[j]
        T_acc = T_acc @ _origin(el, f"joint {j!r}")
        if jtype == "fixed":
            continue
        out.placements.append(T_acc)
        T_acc = np.eye(4)
        out.axes.append(_axis(el, j))
        out.types.append(_MOVING[jtype])
        out.names.append(j)
        out.links.append(child)
        out.limits.append(_limits(el, jtype, j))
        mimic = _mimic(el, j)
        if mimic is not None:
            out.mimic[j] = mimic
        # the moving link with everything fixed to it (off the path, or up to the next moving joint)
        data = _inertial(tree.links[child], f"link {child!r}")
        if data is None:
            raise ModelError(f"link {child!r}, moved by joint {j!r}, has no <inertial>",
                             hint="add one (<mass value='0'/> for a massless link)")
        out.inertials.append(data)
    out.tool = T_acc
    return out


def _merge_fixed(tree: _Tree, link: str, T: np.ndarray, k: int, joints: _MovingJoints,
                 on_path: set) -> None:
    """Merge every link fixed (directly or through other fixed links) to ``link``, at ``T`` in
    moving link ``k``'s frame, into that link's inertial data; a moving joint off the path is a
    branch, which a serial chain cannot hold. Depth first in document order, with a stack (no
    recursion: chains of thousands of fixed joints are fine)."""
    stack = [(j, T) for j in reversed(tree.children[link])]
    while stack:
        j, T = stack.pop()
        el, jtype, parent, child = tree.joints[j]
        if jtype == "fixed":
            Tc = T @ _origin(el, f"joint {j!r}")
            data = _inertial(tree.links[child], f"link {child!r}")
            if data is not None:
                joints.inertials[k] = _combine(joints.inertials[k], _transform_inertial(Tc, data))
            stack.extend((jc, Tc) for jc in reversed(tree.children[child]))
        elif j not in on_path:
            link = parent
            tree.check_type(j)
            raise ModelError(f"joint {j!r} ({jtype}) branches off the chain at link "
                             f"{link!r}: gripkit "
                             f"models serial chains", hint="choose base_link/tip_link so that "
                                                           "the chain does "
                             "not carry the branch, or make the joint fixed")


def _mimic_coupling(joints: _MovingJoints, base_link: str, tip_link: str):
    """Γ (n × m) and q₀ (n,) with q_full = Γ q + q₀ over the actuated joints (those that mimic
    none), following chains of mimics to their leader: q_k = (Π a) q_leader + Σ (Π a) b.
    Returns Γ, q₀ and the indices of the actuated joints."""
    names, mimic = joints.names, joints.mimic
    n = len(names)
    index = {name: k for k, name in enumerate(names)}
    actuated = [k for k, name in enumerate(names) if name not in mimic]
    col = {k: c for c, k in enumerate(actuated)}
    G = np.zeros((n, len(actuated)))
    q0 = np.zeros(n)
    for k, name in enumerate(names):
        mult, off, cur, seen = 1.0, 0.0, name, {name}
        while cur in mimic:
            leader, a, b = mimic[cur]
            if leader not in index:
                raise ModelError(f"joint {cur!r} mimics {leader!r}, which is not a moving "
                                 "joint of the chain "
                                 f"{base_link!r} → {tip_link!r}")
            if leader in seen:
                raise ModelError(f"mimic joints {sorted(seen)} follow each other in a circle")
            seen.add(leader)
            off = off + mult * b
            mult = mult * a
            cur = leader
        G[k, col[index[cur]]] = mult
        q0[k] = off
    return G, q0, actuated


@entry_point
def from_urdf(source, *, base_link: str | None = None, tip_link: str | None = None,
              gravity=(0.0, 0.0, -9.81)) -> JointChain:
    """The serial chain from ``base_link`` to ``tip_link`` of a URDF (module doc).

    Parameters
    ----------
    source
        Path of a ``.urdf`` file, or the XML text itself (a string starting with ``<`` after
        any byte-order mark and blanks, or bytes, decoded as their XML declaration says). A
        document that declares a DTD or entities is refused (ModelError): a URDF needs none.
    base_link, tip_link
        Link names; defaults: the tree's only root, and the end of its only chain of moving joints.
    gravity
        Gravity in the base link's frame (m/s²).

    Returns
    -------
    JointChain
        ``rnea``, ``mass_matrix``, ``forward_dynamics``, ``gravity``, ``regressor``, ...
        in the actuated joints' coordinates (``joint_names``), limits in ``limits``.

    Raises
    ------
    ModelError
        A file that is no URDF of a chain; the message starts with the file's name.
    """
    try:
        return _chain_of(source, base_link, tip_link, gravity)
    except ModelError as exc:  # name the file (XML text given as such has none)
        path = None if _xml_text(source) is not None else str(source)
        name = Path(path).name if path is not None and _path_like(path) else None
        if name is None or name in exc.message:
            raise
        raise type(exc)(f"URDF file {name!r}: {exc.message}", hint=exc.hint) from None


def _chain_of(source, base_link, tip_link, gravity) -> JointChain:
    """:func:`from_urdf`'s chain, its errors not yet naming the file."""
    robot = _read_root(source)
    tree = _Tree(robot)
    base_link = _base_link(tree, base_link)
    if tip_link is None:
        path, tip_link = _path_to_end(tree, base_link)
    else:
        path = _path_to_tip(tree, base_link, tip_link)
    for j in path:
        tree.check_type(j)
    if not any(tree.joints[j][1] != "fixed" for j in path):
        raise ModelError(f"no moving joint between {base_link!r} and {tip_link!r}")
    joints = _moving_joints(tree, path)
    # merge everything fixed to a moving link into it (fixed joints on or off the path)
    on_path = set(path)
    for k, link in enumerate(joints.links):
        _merge_fixed(tree, link, np.eye(4), k, joints, on_path)
    G, q0, actuated = _mimic_coupling(joints, base_link, tip_link)
    lim = np.array([joints.limits[k] for k in actuated]).reshape(-1, 4)
    limits = JointLimits(lim[:, 0].copy(), lim[:, 1].copy(), lim[:, 2].copy(), lim[:, 3].copy())
    inertials = joints.inertials
    return JointChain(np.array(joints.placements), np.array(joints.axes), "".join(joints.types),
                      [d[0] for d in inertials], [d[1] for d in inertials],
                      [d[2] for d in inertials],
                      coupling=G, offset=q0, names=joints.names, actuated=actuated,
                      link_names=joints.links,
                      limits=limits, gravity=gravity, tool=joints.tool,
                      name=robot.get("name") or "urdf")


# --- writing --------------------------------------------------------------------------------------

def _fmt(x: float) -> str:
    return repr(float(x))


def _vec(v) -> str:
    return " ".join(_fmt(x) for x in v)


def _origin_el(parent, T):
    ET.SubElement(parent, "origin", xyz=_vec(T[:3, 3]), rpy=_vec(matrix_rpy(T[:3, :3])))


def _describe(chain):
    """(placements, axes, types, mass, com, inertia, Γ, q₀, names, link names, tool, armature,
    limits or None) of a DH, coupled or joint chain, in joint coordinates."""
    if isinstance(chain, JointChain):
        return (chain.placements, chain.axes, chain.joint_types, chain.mass, chain.com,
                chain.inertia,
                chain.coupling, chain.offset, chain.names, chain.link_names, chain.tool,
                chain.armature,
                chain.limits)
    if isinstance(chain, CoupledChain):
        dh, c = chain.chain, chain.coupling
        G, q0, arm = c.matrix, c.offset, c.armature
    elif isinstance(chain, DHChain):
        dh = chain
        G, q0, arm = np.eye(dh.n), np.zeros(dh.n), np.zeros(dh.n)
    else:
        raise ModelError("chain: expected a DHChain, CoupledChain or JointChain, found "
                         f"{type(chain).__name__}")
    X = np.zeros((dh.n, 4, 4))
    for k in range(dh.n):
        alpha, a, d, off = dh.dh[k]
        ca, sa, co, so = math.cos(alpha), math.sin(alpha), math.cos(off), math.sin(off)
        Rx = np.array([[1, 0, 0], [0, ca, -sa], [0, sa, ca]])
        Rz = np.array([[co, -so, 0], [so, co, 0], [0, 0, 1]])
        X[k, :3, :3] = Rx @ Rz
        X[k, :3, 3] = np.array([a, 0.0, 0.0]) + Rx @ np.array([0.0, 0.0, d])
        X[k, 3, 3] = 1.0
    X[0] = dh.base @ X[0]
    arm_q = dh.armature
    arm_total = np.concatenate([arm, arm_q])
    return (X, np.tile([0.0, 0.0, 1.0], (dh.n, 1)), dh.joint_types, dh.mass, dh.com, dh.inertia, G,
            q0,
            dh.names, tuple(f"link{k + 1}" for k in range(dh.n)), dh.tool, arm_total, None)


@entry_point
def to_urdf(chain, path, *, name: str | None = None, base_link: str = "base",
            tip_link: str = "tip") -> Path:
    """Write ``chain`` (DH, coupled or URDF) as a URDF file (module doc) and return its path.

    The base link is ``base_link`` (the chain's frame 0, or the world frame when the DH chain has
    a ``base`` transform: then pass ``gravity = base_R · g`` to :func:`from_urdf`), the tip frame
    a massless link ``tip_link`` on a fixed joint. Joint positions without limits are written as
    revolute/prismatic joints with ``lower = -π, upper = π`` (revolute) or ±1 m (prismatic) and
    ``effort = velocity = 0`` (read back as unlimited), since Pinocchio reads ``continuous`` as a
    (cos, sin) joint.

    Warns (:class:`~gripkit.errors.GripkitWarning`) when the chain holds what URDF cannot: rotor
    inertia, or a coupling that mixes actuators (the file's coordinates are then its independent
    joints q_u = Γ_u p + q₀_u, and τ_p = Γ_uᵀ τ_u).
    """
    (X, axes, types, mass, com, inertia, G, q0, names, link_names, tool, arm,
     limits) = _describe(chain)
    n, m = G.shape
    left_out = []
    if np.any(np.asarray(arm) != 0):
        left_out.append("rotor inertia (armature) "
                        + ", ".join(f"{a:.4g}" for a in np.asarray(arm) if a != 0))
    # independent joints and mimic joints: row k = c·row j (j earlier, independent)
    leader, mult, mimic_off = {}, {}, {}
    independent = []
    for k in range(n):
        row = G[k]
        if not row.any():
            raise ModelError(f"joint {names[k]!r} is moved by no actuator: URDF has "
                             "no joint for it",
                             hint="fold it into a fixed transform first")
        for j in independent:
            rj = G[j]
            i = int(np.argmax(np.abs(rj)))
            c = row[i] / rj[i]
            if np.allclose(row, c * rj, rtol=0, atol=1e-14 * max(1.0, np.abs(row).max())):
                leader[k], mult[k], mimic_off[k] = j, c, q0[k] - c * q0[j]
                break
        else:
            independent.append(k)
    Gu = G[independent]
    if not np.array_equal(Gu, np.eye(m)) or np.any(q0[independent] != 0):
        left_out.append("the transmission from the actuators to the joints "
                        f"{[names[k] for k in independent]} "
                        f"(q_u = Γ_u p + q₀_u, Γ_u = {np.round(Gu, 6).tolist()}): the URDF's "
                        "coordinates are "
                        f"these joints")
    if left_out:
        emit_warning(f"to_urdf: URDF cannot hold {'; '.join(left_out)}; they are left out of "
                     f"{os.fspath(path)}",
                     GripkitWarning)
    robot = ET.Element("robot", name=name or getattr(chain, "name", "chain"))
    robot.append(ET.Comment(f" written by gripkit.multibody.to_urdf; gravity in {base_link!r}: "
                            f"{_vec(getattr(chain, 'chain', chain).gravity_vector)} m/s^2 "))
    ET.SubElement(robot, "link", name=base_link)
    parent = base_link
    actuated_rank = {k: r for r, k in enumerate(independent)}
    for k in range(n):
        link = ET.SubElement(robot, "link", name=link_names[k])
        inert = ET.SubElement(link, "inertial")
        ET.SubElement(inert, "origin", xyz=_vec(com[k]), rpy="0 0 0")
        ET.SubElement(inert, "mass", value=_fmt(mass[k]))
        I = inertia[k]  # noqa: E741
        ET.SubElement(inert, "inertia", ixx=_fmt(I[0, 0]), ixy=_fmt(I[0, 1]), ixz=_fmt(I[0, 2]),
                      iyy=_fmt(I[1, 1]), iyz=_fmt(I[1, 2]), izz=_fmt(I[2, 2]))
        joint = (ET.SubElement(robot, "joint", name=names[k],
                               type="revolute" if types[k] == "R" else "prismatic"))
        _origin_el(joint, X[k])
        ET.SubElement(joint, "parent", link=parent)
        ET.SubElement(joint, "child", link=link_names[k])
        ET.SubElement(joint, "axis", xyz=_vec(axes[k]))
        lo, hi, vel, eff = -math.pi, math.pi, 0.0, 0.0
        if types[k] == "P":
            lo, hi = -1.0, 1.0
        if limits is not None and k in actuated_rank:
            r = actuated_rank[k]
            vals = [limits.lower[r], limits.upper[r], limits.velocity[r], limits.effort[r]]
            lo = vals[0] if np.isfinite(vals[0]) else lo
            hi = vals[1] if np.isfinite(vals[1]) else hi
            vel = vals[2] if np.isfinite(vals[2]) else 0.0
            eff = vals[3] if np.isfinite(vals[3]) else 0.0
        ET.SubElement(joint, "limit", lower=_fmt(lo), upper=_fmt(hi), effort=_fmt(eff),
                      velocity=_fmt(vel))
        if k in leader:
            ET.SubElement(joint, "mimic", joint=names[leader[k]], multiplier=_fmt(mult[k]),
                          offset=_fmt(mimic_off[k]))
        parent = link_names[k]
    ET.SubElement(robot, "link", name=tip_link)
    tj = ET.SubElement(robot, "joint", name=f"{tip_link}_joint", type="fixed")
    _origin_el(tj, tool)
    ET.SubElement(tj, "parent", link=parent)
    ET.SubElement(tj, "child", link=tip_link)
    ET.indent(robot)
    path = Path(path)
    tree = ET.ElementTree(robot)
    atomic_write(path, lambda tmp: tree.write(tmp, encoding="unicode", xml_declaration=True),
                 what="URDF file")
    return path
