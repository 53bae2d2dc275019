"""python-control and scipy.signal objects from arrays (python-control is imported lazily: it is
an optional dependency, ``pip install 'gripkit[interop]'``)."""

from __future__ import annotations

from ..errors import ModelError

__all__ = ["control_module"]


def control_module():
    """The ``control`` package, or a ModelError saying how to install it."""
    try:
        import control
    except ImportError:
        raise ModelError("python-control is not installed, and this conversion needs it",
                         hint="pip install 'gripkit[interop]' (or pip install control)") from None
    return control
