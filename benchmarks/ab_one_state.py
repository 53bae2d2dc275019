"""The one-state RNEA and mass matrix of two checkouts, for A/B comparisons in alternating
processes.

``python benchmarks/ab_one_state.py CHECKOUT [rounds]`` imports gripkit from ``CHECKOUT/src`` and
prints one JSON line: per call (thread CPU time, median of ``rounds`` rounds, 2·10⁴ states of the
DLR/HIT finger per round, each callable once per round in turn, garbage collection off, BLAS on
one thread) ``pin.crba``, ``chain.mass_matrix(p)`` (a new array per call, the caller's to keep),
``chain.mass_matrix(p, out=M)``, ``pin.rnea``, ``chain.rnea(p, ṗ, p̈)`` and with ``out=τ``, the
median over rounds of each per-round gripkit / Pinocchio ratio, and the URDF finger's one-state
``rnea`` and ``mass_matrix`` (no peer). ``pin.crba``/``pin.rnea`` fill Pinocchio's ``data`` and
return a new array copied from it (Pinocchio 4.1; the line says so, as checked). Run it
alternately on both checkouts (A B A B …)."""

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import gc  # noqa: E402
import json  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).parents[1])
                       / "src"))

from gripkit.errors import ConsistencyWarning, GripkitWarning  # noqa: E402
from gripkit.multibody import from_urdf, to_urdf  # noqa: E402
from gripkit.multibody.pinocchio import to_pinocchio  # noqa: E402
from gripkit.systems.dlr_hit.parameters import finger  # noqa: E402

from common import finger_crba_calls  # noqa: E402


def _rounds(fns: dict, n_rounds: int, per_call: int) -> dict:
    for fn in fns.values():
        fn()
    out = {k: [] for k in fns}
    gc.collect()
    gc.disable()
    try:
        for _ in range(n_rounds):
            for k, fn in fns.items():
                t0 = time.thread_time()
                fn()
                out[k].append((time.thread_time() - t0) / per_call)
    finally:
        gc.enable()
    return out


def main(n_rounds: int = 9, n: int = 20_000) -> dict:
    import pinocchio as pin

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConsistencyWarning)
        ch = finger().chain()
    with warnings.catch_warnings():  # the URDF has no place for the rotor inertia: said, known
        warnings.simplefilter("ignore", GripkitWarning)
        urdf = from_urdf(to_urdf(ch, Path(tempfile.mkdtemp()) / "finger.urdf"),
                         gravity=(0, 0, -9.81))
    model, data = to_pinocchio(ch.chain)
    G = ch.coupling.matrix
    rng = np.random.default_rng(0)
    ps, pds, pdds = ([np.ascontiguousarray(x) for x in rng.normal(size=(n, 3))] for _ in range(3))
    us = [[np.ascontiguousarray(x) for x in rng.normal(size=(n, urdf.dof))] for _ in range(3)]
    M, tau = np.empty((3, 3)), np.empty(3)
    qs, calls = finger_crba_calls(ch, (model, data), ps, M)
    qds, qdds = ([np.ascontiguousarray(G @ x) for x in a] for a in (pds, pdds))
    r = pin.crba(model, data, qs[0])
    pin_new = bool(r.flags.owndata and not np.shares_memory(r, data.M))

    def pin_rnea():
        for q, qd, qdd in zip(qs, qds, qdds):
            pin.rnea(model, data, q, qd, qdd)

    def rnea():
        for p, pd, pdd in zip(ps, pds, pdds):
            ch.rnea(p, pd, pdd)

    def rnea_out():
        for p, pd, pdd in zip(ps, pds, pdds):
            ch.rnea(p, pd, pdd, out=tau)

    def urdf_rnea():
        for a, b, c in zip(*us):
            urdf.rnea(a, b, c)

    def urdf_mass_matrix():
        for a in us[0]:
            urdf.mass_matrix(a)

    t = _rounds(dict(**calls, pin_rnea=pin_rnea, rnea=rnea, rnea_out=rnea_out, urdf_rnea=urdf_rnea,
                     urdf_mass_matrix=urdf_mass_matrix), n_rounds, n)
    ratio = {k: statistics.median(a / b for a, b in zip(t[k], t[ref]))
             for k, ref in (("mass_matrix", "pin_crba"), ("mass_matrix_out", "pin_crba"),
                            ("rnea", "pin_rnea"), ("rnea_out", "pin_rnea"))}
    return {"ns": {k: round(statistics.median(v) * 1e9) for k, v in t.items()},
            "gripkit_over_pin": {k: round(v, 3) for k, v in ratio.items()},
            "pin_returns_new_array": pin_new}


if __name__ == "__main__":
    print(json.dumps(main(int(sys.argv[2]) if len(sys.argv) > 2 else 9)))
