"""Synthetic data for the identification tests (imported as ``from arx_cases import ...``; a
unique name, where ``conftest`` is not): the Table II [2 2 2] model of
000_8f66dcc7ab06470c.txt (S1, filtered data) with known noise, so the truth is known."""

import numpy as np
from scipy.signal import lfilter

# Table II, [2 2 2], S1, 9 Hz-filtered data (paper units: u in mA, force in sensor units)
A222 = np.array([1.0, -1.8732, 0.8996])
B222 = np.array([0.0, 0.0, 0.1950, -0.2276])
THETA222 = np.array([-1.8732, 0.8996, 0.1950, -0.2276])


def simulate_arx(n, *, noise=1.0, seed=0, A=A222, B=B222, C=(1.0,), F=(1.0,), kind="arx", u=None):
    """u: white noise (std 100, like ±250 mA excitation) unless given.
    kind='arx': A y = B u + C e;  kind='oe': y = B/F u + e."""
    rng = np.random.default_rng(seed)
    if u is None:
        u = 100.0 * rng.standard_normal(n)
    e = noise * rng.standard_normal(n)
    if kind == "arx":
        y = lfilter(B, A, u) + lfilter(C, A, e)
    else:
        y = lfilter(B, F, u) + e
    return u, y
