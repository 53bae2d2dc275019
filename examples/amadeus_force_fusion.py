"""Fuse redundant strain-gauge estimates of the AMADEUS fingertip force (000_8f66dcc7ab06470c.txt
§IV-A, eqs 16-19): three estimates of the same force with Table I's normalised variances,
signal-proportional noise (eq 19), fused by inverse-variance weighting."""

import numpy as np

from gripkit.estimation import fuse

force = 2.0  # N, a static applied force
var_n = np.array([0.01309, 0.00459, 0.00301])            # Table I, σ²_N of ε1, ε2, ε3
rng = np.random.default_rng(0)
e = force * (1.0 + np.sqrt(var_n)[:, None] * rng.standard_normal((3, 20000)))  # eq 19 noise
est, var = fuse(e, (e ** 2) * var_n[:, None])              # per sample, eq 19 variances
print("single estimates, normalised variance:", np.round((e / force).var(axis=1), 5))
print(f"fused: normalised variance {np.var(est / force):.5f} (theory, eq 18: "
      f"{1 / np.sum(1 / var_n):.5f})")
