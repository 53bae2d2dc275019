"""Random draws inside numba kernels: a splitmix64 stream held in a one-element uint64 array,
deterministic per seed, allocation free and independent of thread scheduling (unlike numpy's
global state inside ``prange``). Seed the stream with ``rng[0] = seed * 0x2545F4914F6CDD1D + 1``.
"""

from __future__ import annotations

import math

import numba
import numpy as np

__all__ = ["uniform_draw", "normal_draw"]


@numba.njit(cache=True)
def uniform_draw(rng):  # pragma: no cover - compiled
    """Uniform in [0, 1) from a splitmix64 stream held in rng[0] (uint64): deterministic per seed,
    allocation free, independent of thread scheduling (unlike numpy's global state in prange)."""
    rng[0] += np.uint64(0x9E3779B97F4A7C15)
    z = rng[0]
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    z = z ^ (z >> np.uint64(31))
    return (z >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@numba.njit(cache=True)
def normal_draw(rng):  # pragma: no cover - compiled
    """Standard normal deviate (Box-Muller on two :func:`uniform_draw` draws)."""
    u1 = 1.0 - uniform_draw(rng)  # (0, 1]
    u2 = uniform_draw(rng)
    return math.sqrt(-2.0 * math.log(u1)) * math.cos(2.0 * math.pi * u2)
