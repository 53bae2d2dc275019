"""Signals: the Trajectory data type, Butterworth filtering, detrending, resampling.

The names below are loaded on first use (PEP 562 ``__getattr__``): ``import gripkit`` needs only
:class:`Trajectory`, and the filter modules' ``scipy.signal`` costs more than the rest of gripkit.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from .trajectory import Trajectory as Trajectory

# public name -> the module of this package that defines it
_LAZY = {
    "apply_sos": "filters", "bandpass": "filters", "butter_ba": "filters", "butter_sos": "filters",
    "butter_zpk": "filters", "highpass": "filters", "lowpass": "filters",
    "ac_couple": "processing", "decimate": "processing", "detrend": "processing",
    "remove_mean": "processing", "resample": "processing", "segment_by": "processing",
    "split": "processing", "to_uniform": "processing",
}

__all__ = ["Trajectory", *sorted(_LAZY)]

if TYPE_CHECKING:  # for static readers: the same names, imported eagerly
    from .filters import apply_sos, bandpass, butter_ba, butter_sos, butter_zpk, highpass, lowpass
    from .processing import (ac_couple, decimate, detrend, remove_mean, resample, segment_by, split,
                             to_uniform)


def __getattr__(name: str):
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
