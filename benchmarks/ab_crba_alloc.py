"""Where the time of a one-state mass matrix without ``out=`` goes, beside ``pin.crba`` (issue 24:
≤ 1.1× ``pin.crba``).

``python benchmarks/ab_crba_alloc.py`` times, per call from a Python loop over 2·10⁴ states of
the DLR/HIT finger (4 joints, 3 actuators), in thread CPU time (steady on a loaded machine),
alternating, min and median of 15 runs:

* ``pin.crba(model, data, q)`` (fills ``data.M`` and returns a new array copied from it, in
  Pinocchio 4.1: printed below as checked);
* ``chain.mass_matrix(p)`` (a new 3×3 array per call) and ``chain.mass_matrix(p, out=M)``;
* the compiled kernel ``mass_matrix_one(buf, p, M)`` alone, into one array and into a new
  ``np.empty`` per call: the difference of the last two is the price of a fresh result array,
  the difference to ``chain.mass_matrix`` the Python method's;
* the same through the kernel's numba entry point (``onestate.mass_matrix_entry``, no
  dispatcher), which ``chain.mass_matrix(p)`` calls for an exact 1-D float64 state;
* the entry point into one array after an unused ``np.empty``: the allocation alone slows the
  kernel that follows it.
"""

import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parents[1] / "src"))

from common import finger_crba_calls  # noqa: E402

from gripkit.errors import ConsistencyWarning  # noqa: E402
from gripkit.multibody.onestate import mass_matrix_one  # noqa: E402
from gripkit.multibody.pinocchio import to_pinocchio  # noqa: E402
from gripkit.systems.dlr_hit.parameters import finger  # noqa: E402


def main(n: int = 20_000, runs: int = 15) -> dict:
    import pinocchio as pin

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConsistencyWarning)
        ch = finger().chain()
    model, data = to_pinocchio(ch.chain)
    rng = np.random.default_rng(0)
    ps = [np.ascontiguousarray(x) for x in rng.normal(size=(n, 3))]
    M = np.empty((3, 3))
    qs, calls = finger_crba_calls(ch, (model, data), ps, M)
    buf, _, shape, entry = ch._one or ch._one_state()

    def kernel_into_one_array():
        for p in ps:
            mass_matrix_one(buf, p, M)

    def kernel_into_new_array():
        for p in ps:
            mass_matrix_one(buf, p, np.empty(shape))

    def entry_into_one_array():
        for p in ps:
            entry(buf, p, M)

    def entry_into_new_array():
        for p in ps:
            entry(buf, p, np.empty(shape))

    def entry_after_unused_empty():
        for p in ps:
            np.empty(shape)
            entry(buf, p, M)

    r = pin.crba(model, data, qs[0])
    print("pin.crba returns " + ("a new array (owns its data, shares no memory with data.M)"
                                 if r.flags.owndata and not np.shares_memory(r, data.M)
                                 else "a view of data.M"))
    fns = {"pin.crba": calls["pin_crba"], "mass_matrix(p)": calls["mass_matrix"],
           "mass_matrix(p, out=M)": calls["mass_matrix_out"],
           "kernel, one array": kernel_into_one_array,
           "kernel, np.empty per call": kernel_into_new_array,
           "entry point, one array": entry_into_one_array,
           "entry point, np.empty per call": entry_into_new_array,
           "entry point, unused np.empty": entry_after_unused_empty}
    for fn in fns.values():
        fn()
    times = {k: [] for k in fns}
    for _ in range(runs):
        for k, fn in fns.items():
            t0 = time.thread_time()
            fn()
            times[k].append((time.thread_time() - t0) / n)
    ref = min(times["pin.crba"])
    out = {}
    for k, v in times.items():
        out[k] = (min(v), float(np.median(v)))
        print(f"{k:31s} min {min(v) * 1e9:6.0f} ns  median {np.median(v) * 1e9:6.0f} ns  "
              f"min / pin.crba min {min(v) / ref:.2f}")
    return out


if __name__ == "__main__":
    main()
