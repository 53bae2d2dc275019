"""Identify a force sensor's mass, damping and stiffness from a noisy preload-release record.

The sensor is the TSFM's (001_0b92a7da96e7aa46.txt, Table II, left finger): m_s = 1.8 mg,
b_s = 0.7 mN·s/m, k_s = 128 N/m, sampled at 20 kHz as in §IV-B. gripkit simulates the record,
adds 1 % noise, and fits the three parameters back with their standard deviations.
"""

import numpy as np

from gripkit import Trajectory
from gripkit.models import MassSpringDamper
from gripkit.sysid.physical.greybox import fit

fs = 20000.0
force = np.where(np.arange(4000) < 2000, 150e-6, 0.0)  # 150 µN preload, released at 0.1 s
truth = MassSpringDamper(m=1.8e-6, b=7e-4, k=128.0)
x = truth.simulate(force, dt=1 / fs)["x"]
x = x + 0.01 * x.std() * np.random.default_rng(1).standard_normal(x.size)
data = Trajectory.uniform(dt=1 / fs, F=force, x=x, units={"F": "N", "x": "m"})

result = fit(MassSpringDamper(m=3e-6, b=1e-3, k=100.0), data, progress=False)
print(result.summary())
