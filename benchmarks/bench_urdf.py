"""URDF chains and multi-joint identification against Pinocchio, on the DLR/HIT finger written as a
URDF by ``gripkit.multibody.to_urdf`` (3 actuated joints, the distal joint a ``<mimic>``) and read
by both: ``gripkit.multibody.from_urdf`` and ``pinocchio.buildModelFromUrdf(..., mimic=True)``.

* one-state inverse dynamics: ``chain.rnea(q, qd, qdd)`` vs one ``pin.rnea`` call (target: gripkit
  ≤ 1.5× Pinocchio's time, i.e. ratio ≥ 0.67);
* batched inverse dynamics: gripkit's kernel over a batch vs ``pin.rnea`` in a Python loop
  (target: ≥ 2× faster);
* the inertial-parameter regressor, batched vs ``pin.computeJointTorqueRegressor`` in a loop
  (Pinocchio's regressor does not take mimic joints: the full model, then Γᵀ);
* identification of the finger's base parameters and friction from 1e5 samples (target: < 1 s):
  ``gripkit.sysid.identify_dynamics`` (without and with the physical-consistency check) vs what a
  Pinocchio user writes: the regressor in a loop, the base columns, friction columns and
  ``numpy.linalg.lstsq``.

Both sides get the same warm-up (1 call) and repeats; each row reports the median (the time
compared) and the minimum, and the accuracy beside the time (largest difference between the two
results). Numba compile time is excluded (warm-up call), as everywhere in the benchmarks.
"""

from __future__ import annotations

import tempfile
import warnings
from pathlib import Path

import numpy as np
from common import measure, row


def timed(fn, repeat: int, number: int = 1) -> tuple:
    """(Timing, min) per call through the shared harness :func:`common.measure` (same warm-up and
    runs for both sides; ``repeat`` is kept for the call sites and ignored)."""
    t = measure(fn, number)
    return t, t.min


def _setup():
    import pinocchio as pin

    from gripkit import zoo
    from gripkit.multibody import from_urdf, to_urdf

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ch = zoo.build("dlr-hit-finger").chain()
        path = to_urdf(ch, Path(tempfile.mkdtemp()) / "dlr_hit_finger.urdf")
    g = ch.chain.gravity_vector
    chain = from_urdf(path, gravity=g)
    model = pin.buildModelFromUrdf(str(path), mimic=True)
    model.gravity.linear = g
    full = pin.buildModelFromUrdf(str(path))
    full.gravity.linear = g
    return chain, model, model.createData(), full, full.createData()


def run(quick: bool = False) -> list[dict]:
    import pinocchio as pin

    from gripkit.sysid import identify_dynamics

    chain, model, data, full, fdata = _setup()
    rng = np.random.default_rng(0)
    rows = []
    R = 5 if quick else 9

    # one state
    q, qd, qdd = (rng.uniform(-1, 1, 3) for _ in range(3))
    n1 = 20_000 if quick else 100_000
    gk1 = timed(lambda: chain.rnea(q, qd, qdd), R, n1)
    pn1 = timed(lambda: pin.rnea(model, data, q, qd, qdd), R, n1)
    err = float(np.max(np.abs(chain.rnea(q, qd, qdd) - pin.rnea(model, data, q, qd, qdd))))
    rows.append(row("urdf", "RNEA, one state, URDF finger (3 "
                            "joints + mimic)", gk1[0], "one pin.rnea call", pn1[0],
                    target="ratio >= 0.67 (gripkit <= 1.5x pin)",
                    notes=f"per call, {n1} calls per run; min gripkit {gk1[1] * 1e6:.3f} µs, pin "
                          f"{pn1[1] * 1e6:.3f} µs; "
                          f"max |Δτ| {err:.1e} N·m",
                    extra=dict(gripkit_min_s=gk1[1], peer_min_s=pn1[1], max_abs_diff=err)))

    # batch
    B = 10_000 if quick else 100_000
    Q, QD, QDD = (rng.uniform(-1, 1, (B, 3)) for _ in range(3))
    gkb = timed(lambda: chain.rnea(Q, QD, QDD, parallel=False), R)

    def pin_loop():
        out = np.empty((B, 3))
        for i in range(B):
            out[i] = pin.rnea(model, data, Q[i], QD[i], QDD[i])
        return out

    pnb = timed(pin_loop, R)
    err = float(np.max(np.abs(chain.rnea(Q, QD, QDD, parallel=False) - pin_loop())))
    rows.append(row("urdf", f"RNEA, batch of {B} states (1 thread), per state", gkb[0] / B,
                    "pin.rnea in a Python loop", pnb[0] / B, target="ratio >= 2",
                    notes=f"min {gkb[1] / B * 1e9:.0f} vs {pnb[1] / B * 1e9:.0f} ns/state; "
                          f"max |Δτ| {err:.1e} N·m",
                          extra=dict(gripkit_min_s=gkb[1] / B, peer_min_s=pnb[1] / B,
                                                              max_abs_diff=err)))

    # regressor
    G = chain.coupling
    Br = min(B, 20_000)

    def pin_regressor():
        out = np.empty((Br, 3, G.shape[0] * 10))
        for i in range(Br):
            out[i] = (G.T @ pin.computeJointTorqueRegressor(full, fdata, G @ Q[i], G @ QD[i],
                                                            G @ QDD[i]))
        return out

    gkr = timed(lambda: chain.regressor(Q[:Br], QD[:Br], QDD[:Br]), R)
    pnr = timed(pin_regressor, R)
    err = float(np.max(np.abs(chain.regressor(Q[:Br], QD[:Br], QDD[:Br]) - pin_regressor())))
    rows.append(row("urdf", f"inertial-parameter regressor, batch of {Br}, per state", gkr[0] / Br,
                    "pin.computeJointTorqueRegressor "
                    "in a loop (+ Γᵀ)", pnr[0] / Br, target="ratio >= 1",
                    notes=f"min {gkr[1] / Br * 1e6:.2f} vs {pnr[1] / Br * 1e6:.2f} µs/state; "
                          f"max |ΔY| {err:.1e}",
                          extra=dict(gripkit_min_s=gkr[1] / Br, peer_min_s=pnr[1] / Br,
                                                         max_abs_diff=err)))

    # identification from 1e5 samples
    N = 20_000 if quick else 100_000
    t = np.arange(N) * 1e-3
    qs = np.zeros((N, 3))
    qds = np.zeros_like(qs)
    qdds = np.zeros_like(qs)
    for j in range(3):
        for k in range(1, 6):
            w = 2 * np.pi * 0.1 * k * (1 + 0.3 * j)
            a, b = rng.normal(size=2) * 0.3 / k
            qs[:, j] += a * np.sin(w * t) + b * np.cos(w * t)
            qds[:, j] += w * (a * np.cos(w * t) - b * np.sin(w * t))
            qdds[:, j] -= w * w * (a * np.sin(w * t) + b * np.cos(w * t))
    fc, fv = np.array([0.02, 0.015, 0.01]), np.array([0.005, 0.004, 0.003])
    tau = chain.rnea(qs, qds, qdds) + fc * np.sign(qds) + fv * qds + rng.normal(size=(N, 3)) * 1e-3
    Rid = 3 if quick else 5
    res = identify_dynamics(chain, qs, qds, qdds, tau, check_consistency=False)
    ind = res.structure.independent

    def pin_identify():
        Y = np.empty((N, 3, G.shape[0] * 10))
        for i in range(N):
            Y[i] = (G.T @ pin.computeJointTorqueRegressor(full, fdata, G @ qs[i], G @ qds[i],
                                                          G @ qdds[i]))
        F = np.zeros((N, 3, 6))
        for j in range(3):
            F[:, j, 2 * j] = np.sign(qds[:, j])
            F[:, j, 2 * j + 1] = qds[:, j]
        X = np.concatenate([Y[:, :, ind], F], axis=2).reshape(3 * N, -1)
        return np.linalg.lstsq(X, tau.reshape(-1), rcond=None)[0]

    gki = timed(lambda: identify_dynamics(chain, qs, qds, qdds, tau, check_consistency=False), Rid)
    gkc = timed(lambda: identify_dynamics(chain, qs, qds, qdds, tau), Rid)
    pni = timed(pin_identify, max(2, Rid - 2))
    th_pin = pin_identify()
    fr_err = float(np.max(np.abs(res.theta[-6:] - np.ravel(np.column_stack([fc, fv])))))
    rows.append(row("urdf", f"identify_dynamics, 3-joint finger, {N} samples (no "
                            "consistency check)", gki[0],
                    "pin regressor loop + numpy lstsq", pni[0], target="< 1 s",
                    notes=f"min {gki[1]:.3f} s vs {pni[1]:.3f} s; with the consistency check "
                          f"{gkc[0]:.3f} s; max |friction error| {fr_err:.1e} (σ "
                          f"{np.max(res.std[-6:]):.1e}); "
                          "max |Δθ| vs Pinocchio+lstsq (OLS, unweighted) "
                          f"{np.max(np.abs(res.theta - th_pin)):.1e}",
                    extra=dict(gripkit_min_s=gki[1], peer_min_s=pni[1], with_consistency_s=gkc[0],
                               friction_max_abs_error=fr_err)))
    return rows


if __name__ == "__main__":
    for r in run(quick=True):
        print(r["task"], r["gripkit_s"], r["peer_s"], r["ratio"], r["notes"])
