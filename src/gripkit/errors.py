"""gripkit's error and warning hierarchy.

Every message names the argument or column, what was expected and what was found, and, where it
can, says how to fix it::

    DataError: column 'force' has 3 NaN values (first at t=1.205 s); drop or interpolate them
    with fill='interpolate' (CLI: --fill interpolate)

The CLI prints ``str(error)`` on one line and exits non-zero; ``--debug`` shows the traceback.
"""

from __future__ import annotations

import os
import sys
import warnings

__all__ = [
    "GripkitError",
    "DataError",
    "ModelError",
    "ParameterError",
    "IdentificationError",
    "UnidentifiableError",
    "SimulationError",
    "ConfigError",
    "ArgumentError",
    "PathError",
    "GripkitWarning",
    "ConsistencyWarning",
    "StabilityWarning",
    "AccuracyWarning",
    "DataWarning",
    "emit_warning",
]


class GripkitError(Exception):
    """Base class of every error gripkit raises on purpose.

    Parameters
    ----------
    message
        What went wrong: the argument/column, what was expected and what was found.
    hint
        How to fix it (optional); appended after a semicolon.
    """

    def __init__(self, message: str, *, hint: str | None = None):
        self.message = message
        self.hint = hint
        super().__init__(message)

    def __str__(self) -> str:
        return f"{self.message}; {self.hint}" if self.hint else self.message


class DataError(GripkitError, ValueError):
    """Bad experiment data: NaN/inf, non-monotonic or non-uniform time, too few samples, missing
    or mistyped columns, unreadable files, signals that cannot identify the requested model."""


class ModelError(GripkitError, ValueError):
    """A model or parameter set that cannot be built as asked."""


class ParameterError(ModelError):
    """A parameter value outside its bounds, without a unit, or otherwise invalid."""


class IdentificationError(GripkitError):
    """An identification that cannot return trustworthy numbers."""


class UnidentifiableError(IdentificationError):
    """The experiment does not determine the requested parameters (rank-deficient or
    ill-conditioned regressor or Jacobian)."""


class SimulationError(GripkitError):
    """A simulation that would return garbage (step too coarse, divergence, bad inputs)."""


class ConfigError(GripkitError, ValueError):
    """A model/sweep description file (TOML) that is malformed or incomplete."""


class ArgumentError(GripkitError, TypeError):
    """A Python call with an unknown keyword or an argument of the wrong type; the message names
    the argument and lists what is accepted. A ``TypeError``, as Python raises for such calls."""


class PathError(GripkitError, OSError):
    """A file or folder that cannot be used as asked: missing, a folder where a file is expected
    (or the reverse), not readable or not writable. An ``OSError``, as Python raises for such
    paths."""


class GripkitWarning(UserWarning):
    """Base class of gripkit's warnings."""


class ConsistencyWarning(GripkitWarning):
    """A parameter set contradicts itself (for example a stated natural frequency that its own
    mass and stiffness do not give)."""


class StabilityWarning(GripkitWarning):
    """An identified or simulated model is unstable where stability was expected."""


class AccuracyWarning(GripkitWarning):
    """A result is computed but may be inaccurate (poor excitation, coarse step, few samples)."""


class DataWarning(GripkitWarning):
    """Data that could be read but look damaged: a file whose last line is cut short, a sample far
    outside the rest of its channel (a corrupt value). The data are used as read; check them."""


def emit_warning(message: str | Warning, category: type[Warning] = GripkitWarning,
                 stacklevel: int | None = None) -> None:
    """Issue ``category(message)`` attributed to the first stack frame outside gripkit: the user's
    line that called into gripkit, whatever the depth of the call inside (what Python 3.12's
    ``warnings.warn(skip_file_prefixes=...)`` does), so the printed location and ``-W`` filters by
    module point at the user's code, never into gripkit. ``stacklevel`` (counted from the caller,
    as for ``warnings.warn``) overrides the search. Every warning of gripkit goes through here.
    ``message`` may be a warning instance (its class is then the category, as for
    ``warnings.warn``)."""
    if stacklevel is not None:
        warnings.warn(message, category, stacklevel=stacklevel + 1)
        return
    package = os.path.dirname(os.path.abspath(__file__)) + os.sep
    frame, level = sys._getframe(1), 2  # stacklevel 2: the caller of emit_warning()
    while frame is not None and os.path.abspath(frame.f_code.co_filename).startswith(package):
        frame, level = frame.f_back, level + 1
    warnings.warn(message, category, stacklevel=level)
