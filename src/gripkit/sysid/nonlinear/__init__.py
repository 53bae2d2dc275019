"""Nonlinear system identification (issue 26): polynomial NARX by forward regression with the
error reduction ratio (:func:`narx`, :mod:`.narx`); polynomial nonlinear state space
(:func:`nlss`, :mod:`.nlss`).

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
    "nlss": ("nlss", "nlss"),
    "NLSSModel": ("nlss", "NLSSModel"),
    "load_nlss": ("nlss", "load_nlss"),
}
__getattr__, __dir__ = lazy_exports(__name__, _LAZY)
__all__ = [*_LAZY]

if TYPE_CHECKING:  # static readers see the same names, imported eagerly
    from .narx import NARXModel as NARXModel
    from .narx import load_narx as load_narx
    from .narx import narx as narx
    from .nlss import NLSSModel as NLSSModel
    from .nlss import load_nlss as load_nlss
    from .nlss import nlss as nlss
