"""The DLR/HIT finger's time loops, for A/B comparisons of two checkouts in alternating processes.

``python benchmarks/ab_finger_loops.py CHECKOUT`` prints µs per simulated second at 1 kHz: the open
loop (10 s of sign-changing PWM from near the proximal end stop, median of 9 runs) and the joint
impedance loop (2 s of tracking_reference, median of 15 runs), each after a warm-up call. Run it
alternately on both checkouts (A B A B …) on an idle machine; docs/performance.md reports pairs."""

import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).parents[1])
                       / "src"))

from gripkit.errors import ConsistencyWarning  # noqa: E402
from gripkit.systems.dlr_hit.friction_adaptation import tracking_reference  # noqa: E402
from gripkit.systems.dlr_hit.impedance import ImpedanceController, simulate_impedance  # noqa: E402
from gripkit.systems.dlr_hit.parameters import finger  # noqa: E402


def _median_seconds(call, runs):
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        call()
        times.append(time.perf_counter() - t0)
    return float(np.median(times))


def main():
    warnings.simplefilter("ignore", ConsistencyWarning)
    f = finger(check=False)
    t = np.arange(10_000) * 1e-3
    u = np.column_stack([2500 * np.sin(2 * math.pi * 3 * t),
                         -3000 * np.sin(2 * math.pi * 2 * t + 0.4),
                         2000 * np.sin(2 * math.pi * t)])
    x0 = f.state(q=(10 * math.pi / 180, 20 * math.pi / 180, 80 * math.pi / 180))
    f.simulate(u[:100], dt=1e-3, x0=x0)
    open_loop = _median_seconds(lambda: f.simulate(u, dt=1e-3, x0=x0), 9) / 10.0
    controller = ImpedanceController("joint", (8, 8, 8), (0.6, 0.6, 0.6))
    ref = tracking_reference(2.0)
    simulate_impedance(f, controller, ref[:50])
    closed_loop = _median_seconds(lambda: simulate_impedance(f, controller, ref), 15) / 2.0
    print(f"open loop {open_loop * 1e6:.0f} µs per simulated second; "
          f"joint impedance {closed_loop * 1e6:.0f} µs per simulated second")


if __name__ == "__main__":
    main()
