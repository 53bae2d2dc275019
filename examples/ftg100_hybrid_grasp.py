"""Grasp an 80 µm glass ball with the FT-G100 MEMS microgripper (003_abd62b560633beaf.txt) under
hybrid force/position control — the paper's stated future work: position control while closing,
a bumpless switch to force control at contact, 20 µN commanded, 0-200 V actuation limits, 50 nN
sensor noise — for object stiffnesses from 520 to 1560 N/m (k0 = 1043 N/m ± 50 %)."""

import numpy as np

from gripkit.systems.ftg100.hybrid_control import HybridForcePosition, grasp_batch
from gripkit.systems.ftg100.model import FTG100Plant

plant = FTG100Plant()
ctrl = HybridForcePosition.for_plant(plant.parameters)
k0 = np.linspace(520.0, 1560.0, 5)
res = grasp_batch(ctrl, plant, force=20e-6, k0=k0, gap=20e-6, seed=np.arange(k0.size))
for k, ov, ts, peak in zip(k0, res["overshoot_percent"], res["settling_time"], res["peak_force"]):
    print(f"k0 = {k:6.0f} N/m: overshoot {ov:4.1f} %, settling {ts * 1e3:4.2f} ms, peak "
          f"{peak * 1e6:5.2f} µN")
