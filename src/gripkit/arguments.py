"""Argument checks of gripkit's public entry points.

A Python call with an unknown keyword, a missing argument or an argument of the wrong type raises
:class:`~gripkit.errors.ArgumentError` (a ``TypeError``) naming the argument and listing what is
accepted, instead of Python's bare ``TypeError`` or a failure deep inside the computation::

    >>> from gripkit.io import load
    >>> load("run.csv", colums=["force"])
    Traceback (most recent call last):
    ...
    gripkit.errors.ArgumentError: load(): unknown keyword 'colums'; load accepts path, columns, ...
"""

from __future__ import annotations

import functools
import inspect
import math
import numbers
import os
from collections.abc import Callable, Iterable, Mapping

import numpy as np

from .errors import ArgumentError, DataError

__all__ = ["entry_point", "check_keywords", "check_path", "keyword_names", "sample_interval",
           "real_array"]

_VARIADIC = (inspect.Parameter.VAR_POSITIONAL, inspect.Parameter.VAR_KEYWORD)


def sample_interval(dt, error: type = DataError) -> float:
    """``dt`` as a float after checking it is a positive, finite sample interval in seconds (the
    one name gripkit uses inside, docs/ARCHITECTURE.md); ``error`` (default DataError) otherwise.

    >>> sample_interval(5e-5)
    5e-05
    """
    if isinstance(dt, bool) or not isinstance(dt,
                                              numbers.Real) or not (math.isfinite(dt) and dt > 0):
        raise error(f"dt: expected a positive, finite sample interval in s, found {dt!r}")
    return float(dt)


def real_array(x, name: str, expected: str = "an array of numbers") -> np.ndarray:
    """``x`` as a float64 array (no copy when it is one), or a :class:`DataError` naming ``name``:
    for complex numbers (which numpy would cast with a ComplexWarning, dropping the imaginary
    part) and for anything that is not numbers (``expected`` says what was). The shared
    conversion of the identification's and the signal functions' arrays.

    >>> real_array([1, 2.5], "u").tolist()
    [1.0, 2.5]
    >>> real_array([1 + 2j], "u")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    gripkit.errors.DataError: u: expected real numbers, found complex (complex128); pass x.real...
    """
    if type(x) is np.ndarray and x.dtype == np.float64:
        return x
    try:
        a = np.asarray(x)
        complex_ = a.dtype.kind == "c" or (a.dtype == object and any(
            isinstance(v, complex) for v in a.ravel()))
        if not complex_:
            return np.asarray(a, dtype=np.float64)
    except (TypeError, ValueError):
        raise DataError(f"{name}: expected {expected}, found {type(x).__name__}") from None
    raise DataError(f"{name}: expected real numbers, found complex ({a.dtype})",
                    hint="pass x.real or abs(x) explicitly")


def keyword_names(fn: Callable, exclude: Iterable[str] = ()) -> list[str]:
    """The named parameters of ``fn`` (its ``*args``/``**kwargs`` left out), minus ``exclude``."""
    skip = set(exclude)
    return ([n for n, p in inspect.signature(fn).parameters.items() if p.kind not in _VARIADIC
             and n not in skip])


def check_keywords(given: Mapping | Iterable[str], accepted: Iterable[str], where: str,
                   hint: str | None = None) -> None:
    """Raise :class:`ArgumentError` naming each keyword of ``given`` that is not in ``accepted``
    (``hint``: the list of what is accepted, when it says more than ``accepted``)."""
    accepted = list(accepted)
    unknown = [k for k in given if k not in accepted]
    if unknown:
        s = "s" if len(unknown) > 1 else ""
        raise ArgumentError(f"{where}: unknown keyword{s} {', '.join(map(repr, unknown))}",
                            hint=hint or f"accepted: {', '.join(accepted) if accepted else 'none'}")


def check_path(value, name: str, where: str) -> None:
    """Raise :class:`ArgumentError` unless ``value`` is a path (``str`` or ``os.PathLike``)."""
    if not isinstance(value, (str, os.PathLike)):
        raise ArgumentError(f"{where}: {name} must be a file path (str or pathlib.Path), found "
                            f"{type(value).__name__} {value!r:.60}",
                            hint=f"pass the {name} as a string, e.g. \"run.csv\"")


def entry_point(fn: Callable) -> Callable:
    """Decorate a public function so that a call that does not fit its signature (unknown keyword,
    missing or surplus argument) raises :class:`ArgumentError` naming the problem and listing the
    accepted arguments. A call that fits costs nothing extra: the signature is consulted only when
    Python has refused the call."""
    sig = inspect.signature(fn)
    name = fn.__name__

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        try:
            return fn(*args, **kwargs)
        except TypeError:
            try:
                sig.bind(*args, **kwargs)
            except TypeError as refused:  # the call itself did not fit: nothing of fn has run
                accepted = ", ".join(n if p.kind not in _VARIADIC else f"*{n}"
                                     if p.kind is p.VAR_POSITIONAL
                                     else f"**{n}" for n, p in sig.parameters.items())
                unknown = [k for k in kwargs if k not in sig.parameters]
                if unknown and not any(p.kind is inspect.Parameter.VAR_KEYWORD
                                       for p in sig.parameters.values()):
                    s = "s" if len(unknown) > 1 else ""
                    what = f"unknown keyword{s} {', '.join(map(repr, unknown))}"
                else:
                    what = str(refused)
                raise ArgumentError(f"{name}(): {what}",
                                    hint=f"{name} accepts {accepted}") from None
            raise

    return wrapper
