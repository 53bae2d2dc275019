"""Online friction adaptation on a DLR/HIT II finger log (``002_ddea254371185ad3.txt`` §6.3): the
generic :class:`~gripkit.estimation.friction_adaptation.FrictionAdapter` fed with the finger's
motor torques (eq 5.10), multibody bias torques and drive inertias."""

from __future__ import annotations

import numpy as np

from ...estimation.friction_adaptation import FrictionAdapter
from .finger import ACTUATORS

__all__ = ["adapt_finger_friction"]


def adapt_finger_friction(finger, trajectory, *, forgetting: float = 0.999, filter_hz: float = 10.0,
                          v_min: float = 0.05, tables=None, adapter: FrictionAdapter | None = None):
    """Run a :class:`FrictionAdapter` on a DLR/HIT finger log (a Trajectory with the finger's
    PWM inputs and joint angle/velocity outputs, as :meth:`DLRFinger.simulate` returns or a real
    log with the same channel names). The motor torque comes from eq 5.10 at the logged speed, the
    bias torque from the multibody model, the inertia from the diagonal of M_p at the log's
    median configuration. Returns ``(adapter, result)``."""
    fs = trajectory.require_uniform(why="friction adaptation")
    ch = finger.chain()
    G = ch.coupling.matrix[:3]
    q = np.column_stack([trajectory[j] for j in ("abd", "flex", "prox")])
    qd = np.column_stack([trajectory[f"{j}_vel"] for j in ("abd", "flex", "prox")])
    p = np.linalg.solve(G, q.T).T
    pd = np.linalg.solve(G, qd.T).T
    pwm = np.column_stack([trajectory[f"pwm_{a}"] for a in ACTUATORS])
    tau = np.column_stack([finger.motor_torque(a, pwm[:, k], pd[:, k]) for k, a in enumerate(ACTUATORS)])
    h = ch.bias(p, pd)
    if adapter is None:
        J = np.diag(ch.mass_matrix(np.median(p, axis=0)))
        tabs = tables if tables is not None else tuple(
            t.scaled(finger.parameters.value(f"scale_{a}")) for t, a in zip(finger.tables, ACTUATORS))
        adapter = FrictionAdapter(tabs, J, 1.0 / fs, forgetting=forgetting, filter_hz=filter_hz,
                                  v_min=v_min, names=ACTUATORS)
    return adapter, adapter.update(tau, h, pd)
