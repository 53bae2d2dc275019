"""Identify the AMADEUS finger-force dynamics as §V of 000_8f66dcc7ab06470c.txt does: excite the
finger with S2 (band-limited noise, 0.3-10 Hz), fit ARX [2 2 2], validate on S1 (a 1-10 Hz
multisine), and look at the non-minimum-phase zero the seed reports (z ≈ 1.167)."""

import numpy as np

from gripkit import sysid
from gripkit.excitation import bandlimited_noise, multisine
from gripkit.systems.amadeus.force_dynamics import finger_force_model

plant = finger_force_model()  # Table II [2 2 2] at 200 Hz, valve current (A) -> force (N)
s2 = (bandlimited_noise(0.3, 10.0, 20.0, dt=0.005, operating_point=0.850, limits=(0.600, 1.100),
                        unit="A", seed=7))
s1 = multisine(range(1, 11), 2.0, dt=0.005, operating_point=0.850, limits=(0.600, 1.100), unit="A")
est = plant.simulate(s2.u, noise_std=0.02, seed=1)
val = plant.simulate(np.tile(s1.u, 2), noise_std=0.02, seed=2)

model = sysid.identify(est, "arx", input="current", output="force", na=2, nb=2, nk=2)
print("A =", np.round(model.A, 4), "±", np.round(model.A_std, 4))
print("B =", np.round(model.B, 3), "±", np.round(model.B_std, 3), "N/A")
print("zeros:", np.round(model.zeros(), 3), "-> minimum phase:", model.minimum_phase)
check = model.validate(val)  # the record as it is: the model removes its own operating point
print(f"free-run fit on S1: {check.fit_percent:.1f} %")
