"""The DLR/HIT Hand II (``002_ddea254371185ad3.txt`` §3.1, §6.3): five identical fingers on a
palm, the thumb fixed in its orientation, each finger with its own friction factors; the zoo's
``dlr-hit-hand``."""

from __future__ import annotations

import numpy as np

from ...errors import ModelError, SimulationError
from ...params import Parameter, ParameterSet
from ...sim.model import Model, Signal
from .finger import (ACTUATORS, FINGER_PARAMETERS, FRICTION_MODES, INTEGRATORS, NTH, NX, DLRFinger,
                     run_jobs)
from .parameters import (FINGERS, SEED, DLRHITFinger, finger_consistency_checks, finger_tables,
                         thesis_finger_parameters)

__all__ = ["DLRHand", "hand", "palm_frames"]


def palm_frames() -> np.ndarray:
    """Finger base frames in the palm frame (5, 4, 4): thumb, index, middle, ring, little.

    Palm frame: x towards the fingertips, y towards the thumb, z out of the back of the hand.
    A finger's base frame has x along the straight finger and z on its abduction axis (the palm
    normal); positive flexion curls towards −z, the palm side. The four fingers sit side by side
    22 mm apart at the end of a 90 mm palm, the middle finger 5 mm further out. The thumb is fixed
    (§3.1: "the thumb is fixed in an appropriate orientation of the palm") at the palm's side,
    pointing forward, outward and down, its flexion curling towards the fingers (−z of its frame
    along −y of the palm). These distances and angles are assumed: the thesis does not give the
    palm geometry.
    """
    T = np.tile(np.eye(4), (5, 1, 1))
    for i, (y, x) in enumerate(((0.033, 0.090), (0.011, 0.095), (-0.011, 0.090), (-0.033, 0.082)),
                               start=1):
        T[i, :3, 3] = (x, y, 0.0)
    x0 = np.array([0.9, 0.3, -0.3])
    x0 /= np.linalg.norm(x0)
    z0 = np.array([0.0, 1.0, 0.0]) - x0[1] * x0
    z0 /= np.linalg.norm(z0)
    T[0, :3, :3] = np.column_stack([x0, np.cross(z0, x0), z0])
    T[0, :3, 3] = (0.030, 0.050, -0.020)
    return T


def _hand_parameters(finger_ps: ParameterSet, scales: dict | None) -> ParameterSet:
    ps = list(finger_ps.values())
    for i, n in enumerate(("g_x", "g_y", "g_z")):
        idx = finger_ps.names.index(n)
        p = ps[idx]
        ps[idx] = Parameter(p.name, p.value, p.unit, f"gravity in the palm frame, {'xyz'[i]}",
                            p.bounds, p.fixed, "assumed: palm horizontal, facing down")
    for f in FINGERS:
        for a in ACTUATORS:
            base = finger_ps.value(f"scale_{a}")
            val = (scales or {}).get(f, {}).get(a, 1.0) * base
            ps.append(Parameter(f"{f}_scale_{a}", val, "1", f"friction factor, {f} "
                                                            f"finger, {a} drive",
                                bounds=(0, None),
                                source=f"{SEED}, §6.3 (friction differs from finger to finger); "
                                       "default: the measured finger"))
    return ParameterSet(ps, "dlr-hit-hand")


class DLRHand(Model):
    """Five DLR/HIT II fingers on a palm (§3.1): four fingers and a thumb fixed in its
    orientation, each with its own friction factors (§6.3). Every finger is a
    :class:`~gripkit.systems.dlr_hit.finger.DLRFinger`; gravity is given in the palm frame and
    rotated into each finger's base frame (:func:`palm_frames`).

    Inputs: 15 PWM counts, finger-major (``thumb_pwm_base1``, ..., ``little_pwm_distal``);
    outputs: the 18 finger outputs per finger, prefixed with the finger name; states: 15 per finger.
    """

    name = "dlr-hit-hand"
    description = "DLR/HIT Hand II: five identical modular fingers (thumb fixed) on a palm"
    inputs = (tuple(Signal(f"{f}_{s.name}", s.unit,
                           s.doc) for f in FINGERS for s in DLRFinger.inputs))
    outputs = (tuple(Signal(f"{f}_{s.name}", s.unit,
                            s.doc) for f in FINGERS for s in DLRFinger.outputs))
    states = (tuple(Signal(f"{f}_{s.name}", s.unit,
                           s.doc) for f in FINGERS for s in DLRFinger.states))

    def __init__(self, parameters: ParameterSet | None = None, *, friction: str = "table",
                 integrator: str = "semi-implicit", thermal: bool = False, check: bool = True,
                 scales: dict | None = None):
        ps = (parameters if parameters is not None else _hand_parameters(thesis_finger_parameters(),
                                                                         scales))
        if ps.names[:NTH] != FINGER_PARAMETERS or len(ps) != NTH + 15:
            raise ModelError("DLRHand: expected the finger parameters followed by 15 "
                             "friction factors")
        self.frames = palm_frames()
        self._finger = DLRHITFinger(ParameterSet([ps[n] for n in FINGER_PARAMETERS],
                                                 "dlr-hit-finger"),
                                    finger_tables(), friction=friction, integrator=integrator,
                                    thermal=thermal, check=False)
        self.friction = friction
        self.integrator = integrator
        self.thermal = bool(thermal)
        super().__init__(ps, check=check)

    def finger_model(self, which: str) -> DLRHITFinger:
        """The finger ``which`` as a stand-alone model (its friction factors and gravity
        applied)."""
        i = FINGERS.index(which)
        p = self.parameters.value
        g = self.frames[i, :3, :3].T @ np.array([p("g_x"), p("g_y"), p("g_z")])
        ov = {f"scale_{a}": p(f"{which}_scale_{a}") for a in ACTUATORS}
        ov.update(g_x=g[0], g_y=g[1], g_z=g[2])
        fp = (ParameterSet([self.parameters[n] for n in FINGER_PARAMETERS],
                           "dlr-hit-finger").replace(**ov))
        return DLRHITFinger(fp, finger_tables(), friction=self.friction, integrator=self.integrator,
                            thermal=self.thermal, check=False, name=f"dlr-hit-{which}")

    def state(self, q=None, **kw) -> np.ndarray:
        """Initial state (75): ``q`` maps finger names to joint angles (abd, flex, prox)."""
        x = (np.concatenate([self._finger.state(q=(q or {}).get(f, (0.0, 0.0, 0.0)),
                                                **kw) for f in FINGERS]))
        return x

    def initial_state(self, theta):
        return self.state()

    #: run the fingers on parallel threads (compiles a parallel kernel on first use)
    parallel = False

    def finger_thetas(self, theta: np.ndarray) -> np.ndarray:
        """The five finger parameter vectors (5, 74) of a hand parameter vector: the shared
        parameters with each finger's friction factors and its gravity (Rᵀ g_palm)."""
        th = np.tile(theta[:NTH], (5, 1))
        i_s = FINGER_PARAMETERS.index("scale_base1")
        i_g = FINGER_PARAMETERS.index("g_x")
        g = theta[i_g:i_g + 3]
        for f in range(5):
            th[f, i_s:i_s + 3] = theta[NTH + 3 * f:NTH + 3 * f + 3]
            th[f, i_g:i_g + 3] = self.frames[f, :3, :3].T @ g
        return th

    def _simulate_batch(self, thetas, u, dt, substeps, x0, y):
        P = thetas.shape[0]
        ths = np.concatenate([self.finger_thetas(t) for t in thetas])
        x0f = np.ascontiguousarray(x0.reshape(P * 5, NX))
        jobs = np.arange(P * 5)
        fail = run_jobs(ths, u, 3 * (jobs % 5), dt, substeps, x0f, y, jobs // 5, 18 * (jobs % 5),
                        self._finger._tab, FRICTION_MODES[self.friction],
                        INTEGRATORS[self.integrator], self.thermal, self.parallel)
        if fail.any():
            raise SimulationError(f"{self.name}: a finger's mass matrix lost positive definiteness")

    def modes(self, theta):
        return self._finger.modes(theta[:NTH])

    def fingertips(self, trajectory) -> dict:
        """Fingertip positions in the palm frame, {finger: (N, 3)}, from a simulated trajectory."""
        out = {}
        for i, f in enumerate(FINGERS):
            ch = self._finger.chain(base=self.frames[i])
            q = np.column_stack([trajectory[f"{f}_{j}"] for j in ("abd", "flex", "prox")])
            p = np.linalg.solve(ch.coupling.matrix[:3], q.T).T
            out[f] = ch.tip_position(p)
        return out

    def consistency_checks(self):
        return finger_consistency_checks(self._finger)


def hand(*, friction: str = "table", integrator: str = "semi-implicit", thermal: bool = False,
         check: bool = True, scales: dict | None = None) -> DLRHand:
    """The five-finger DLR/HIT Hand II; ``scales`` = {finger: {actuator: factor}} sets per-finger
    friction relative to the measured finger."""
    return (DLRHand(friction=friction, integrator=integrator, thermal=thermal, check=check,
                    scales=scales))
