"""Export a :class:`~gripkit.multibody.DHChain` to Pinocchio (optional extra ``pin``).

Each DH link becomes a revolute (``JointModelRZ``) or prismatic (``JointModelPZ``) joint whose
placement in its parent is ``Rx(α_{i-1})·Dx(a_{i-1})·Rz(θ0_i)·Dz(d_i)`` (the constant offsets are
folded into the placement, so Pinocchio's q equals gripkit's joint variable), with the link's
spatial inertia in the joint frame, ``armature`` as Pinocchio's rotor inertia and ``gravity`` as
``model.gravity``. Used by the benchmarks; the tests build their reference models independently.
"""

from __future__ import annotations

import numpy as np

from ..errors import ConfigError

__all__ = ["to_pinocchio"]


def to_pinocchio(chain):
    """``(model, data)`` of a Pinocchio model equivalent to ``chain`` (joint coordinates)."""
    try:
        import pinocchio as pin
    except ImportError:  # pragma: no cover - optional dependency
        raise ConfigError("Pinocchio is not installed",
                          hint="pip install 'gripkit[pinocchio]'") from None
    model = pin.Model()
    parent = 0
    for k in range(chain.n):
        alpha, a, d, off = chain.dh[k]
        prismatic = chain.joint_types[k] == "P"
        Rx = pin.utils.rotate("x", alpha)
        Rz = pin.utils.rotate("z", off)
        placement = pin.SE3(Rx @ Rz, np.array([a, 0.0, 0.0]) + Rx @ np.array([0.0, 0.0, d]))
        joint = pin.JointModelPZ() if prismatic else pin.JointModelRZ()
        jid = model.addJoint(parent, joint, placement, chain.names[k])
        model.appendBodyToJoint(jid, pin.Inertia(chain.mass[k], chain.com[k], chain.inertia[k]),
                                pin.SE3.Identity())
        parent = jid
    model.armature = np.asarray(chain.armature, dtype=np.float64).copy()
    model.gravity.linear = np.asarray(chain.gravity_vector, dtype=np.float64)
    return model, model.createData()
