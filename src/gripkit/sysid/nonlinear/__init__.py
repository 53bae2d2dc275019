"""Nonlinear system identification: polynomial NARX by forward regression with the
error reduction ratio (:func:`narx`, :mod:`.narx`); Hammerstein, Wiener and Hammerstein–Wiener
models (:func:`hammerstein_wiener`, :mod:`.hammerstein_wiener`); hysteresis, generic Bouc-Wen
and Prandtl–Ishlinskii with its inverse (:func:`hysteresis`, :mod:`.hysteresis`); polynomial
nonlinear state space (:func:`nlss`, :mod:`.nlss`).

The public names are loaded on first use (the table ``_LAZY``, :mod:`gripkit.exports`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...exports import lazy_exports

# public name -> (module of this package, name in that module)
_LAZY = {
    "narx": ("narx", "narx"),
    "NARXModel": ("narx", "NARXModel"),
    "load_narx": ("narx", "load_narx"),
    "hammerstein_wiener": ("hammerstein_wiener", "hammerstein_wiener"),
    "HWModel": ("hammerstein_wiener", "HWModel"),
    "load_hw": ("hammerstein_wiener", "load_hw"),
    "hysteresis": ("hysteresis", "hysteresis"),
    "BoucWenModel": ("hysteresis", "BoucWenModel"),
    "BoucWenOscillatorModel": ("hysteresis", "BoucWenOscillatorModel"),
    "PrandtlIshlinskiiModel": ("hysteresis", "PrandtlIshlinskiiModel"),
    "load_hysteresis": ("hysteresis", "load_hysteresis"),
    "nlss": ("nlss", "nlss"),
    "NLSSModel": ("nlss", "NLSSModel"),
    "load_nlss": ("nlss", "load_nlss"),
}
__getattr__, __dir__ = lazy_exports(__name__, _LAZY)
__all__ = [*_LAZY]

if TYPE_CHECKING:  # static readers see the same names, imported eagerly
    from .hammerstein_wiener import HWModel as HWModel
    from .hammerstein_wiener import hammerstein_wiener as hammerstein_wiener
    from .hammerstein_wiener import load_hw as load_hw
    from .narx import NARXModel as NARXModel
    from .narx import load_narx as load_narx
    from .narx import narx as narx
    from .hysteresis import BoucWenModel as BoucWenModel
    from .hysteresis import BoucWenOscillatorModel as BoucWenOscillatorModel
    from .hysteresis import PrandtlIshlinskiiModel as PrandtlIshlinskiiModel
    from .hysteresis import hysteresis as hysteresis
    from .hysteresis import load_hysteresis as load_hysteresis
    from .nlss import NLSSModel as NLSSModel
    from .nlss import load_nlss as load_nlss
    from .nlss import nlss as nlss
