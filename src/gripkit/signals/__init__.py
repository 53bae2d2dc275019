"""Signals: the Trajectory data type, Butterworth filtering, detrending, resampling.

The public names are loaded on first use (the table ``_LAZY``, :mod:`gripkit.exports`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..exports import lazy_exports
from .trajectory import Trajectory as Trajectory

# public name -> (module of this package, name in that module)
_LAZY = {
    "apply_sos": ("filters", "apply_sos"),
    "bandpass": ("filters", "bandpass"),
    "butter_ba": ("filters", "butter_ba"),
    "butter_sos": ("filters", "butter_sos"),
    "butter_zpk": ("filters", "butter_zpk"),
    "highpass": ("filters", "highpass"),
    "lowpass": ("filters", "lowpass"),
    "ac_couple": ("processing", "ac_couple"),
    "decimate": ("processing", "decimate"),
    "detrend": ("processing", "detrend"),
    "remove_mean": ("processing", "remove_mean"),
    "resample": ("processing", "resample"),
    "segment_by": ("processing", "segment_by"),
    "split": ("processing", "split"),
    "to_uniform": ("processing", "to_uniform"),
}
__getattr__, __dir__ = lazy_exports(__name__, _LAZY)
__all__ = ["Trajectory", *_LAZY]

if TYPE_CHECKING:  # static readers see the same names, imported eagerly
    from .filters import apply_sos as apply_sos
    from .filters import bandpass as bandpass
    from .filters import butter_ba as butter_ba
    from .filters import butter_sos as butter_sos
    from .filters import butter_zpk as butter_zpk
    from .filters import highpass as highpass
    from .filters import lowpass as lowpass
    from .processing import ac_couple as ac_couple
    from .processing import decimate as decimate
    from .processing import detrend as detrend
    from .processing import remove_mean as remove_mean
    from .processing import resample as resample
    from .processing import segment_by as segment_by
    from .processing import split as split
    from .processing import to_uniform as to_uniform
