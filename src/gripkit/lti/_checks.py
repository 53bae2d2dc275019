"""Argument checks shared by the linear-system types: matrices, sample times, signal names."""

from __future__ import annotations

import math

import numpy as np

from ..errors import DataError, ModelError

__all__ = ["as_matrix", "as_dt", "as_names", "as_units", "same_dt", "require_discrete"]


def as_matrix(x, name: str, shape: tuple[int | None, int | None] | None = None) -> np.ndarray:
    """A finite, read-only float64 2-D copy of ``x``; ``shape`` entries of None are free."""
    try:
        a = np.array(x, dtype=np.float64, copy=True)
    except (TypeError, ValueError):
        raise ModelError(f"{name}: expected a real matrix, found {type(x).__name__}") from None
    if a.ndim == 0:
        a = a.reshape(1, 1)
    if a.ndim != 2:
        raise ModelError(f"{name}: expected a 2-D matrix, found shape {a.shape}")
    if shape is not None:
        want = tuple(a.shape[k] if s is None else s for k, s in enumerate(shape))
        if a.shape != want:
            raise ModelError(f"{name}: expected shape {want}, found {a.shape}")
    if not np.isfinite(a).all():
        bad = np.argwhere(~np.isfinite(a))[0]
        raise ModelError(f"{name} has non-finite entries (first at [{bad[0]}, {bad[1]}] = {a[tuple(bad)]})",
                         hint="a linear system needs finite matrices")
    a.flags.writeable = False
    return a


def as_dt(dt) -> float | None:
    """``None`` or 0 → continuous (None); a finite positive number → discrete sample time (s)."""
    if dt is None or (not isinstance(dt, bool) and isinstance(dt, (int, float, np.number)) and dt == 0):
        return None
    if isinstance(dt, bool) or not isinstance(dt, (int, float, np.number)) or not math.isfinite(dt) or dt < 0:
        raise ModelError(f"dt: expected None or 0 (continuous) or a positive sample time in s, found {dt!r}")
    return float(dt)


def require_discrete(dt, what: str) -> float:
    """A positive, finite sample time for an operation that needs one."""
    if dt is None or isinstance(dt, bool) or not isinstance(dt, (int, float, np.number)) \
            or not math.isfinite(dt) or dt <= 0:
        raise ModelError(f"{what}: expected a positive sample time dt in s, found {dt!r}")
    return float(dt)


def as_names(names, n: int, what: str, default: str) -> tuple[str, ...]:
    """``n`` distinct signal names; None/empty gives ``default0 .. default{n-1}`` (or ``default``
    alone when n == 1)."""
    if names is None or (not isinstance(names, str) and len(names) == 0):
        return (default,) if n == 1 else tuple(f"{default}{i}" for i in range(n))
    if isinstance(names, str):
        names = (names,)
    names = tuple(names)
    if len(names) != n:
        raise ModelError(f"{what}: expected {n} names, found {len(names)} ({', '.join(map(str, names))})")
    for s in names:
        if not isinstance(s, str) or not s:
            raise ModelError(f"{what}: names must be non-empty strings, found {s!r}")
    if len(set(names)) != n:
        dup = sorted({s for s in names if names.count(s) > 1})
        raise ModelError(f"{what}: names must be distinct, found {', '.join(dup)} more than once")
    return names


def as_units(units, n: int, what: str) -> tuple[str, ...]:
    """``n`` unit strings (SI spelling, ``''`` = not declared)."""
    if units is None or (not isinstance(units, str) and len(units) == 0):
        return ("",) * n
    if isinstance(units, str):
        units = (units,)
    units = tuple(units)
    if len(units) != n:
        raise ModelError(f"{what}: expected {n} units, found {len(units)} ({', '.join(map(str, units))})")
    for s in units:
        if not isinstance(s, str):
            raise ModelError(f"{what}: units must be strings, found {s!r}")
    return units


def same_dt(a, b, what: str) -> float | None:
    """The common sample time of two systems, or a ModelError naming both."""
    if a is None and b is None:
        return None
    if a is None or b is None or not math.isclose(a, b, rel_tol=1e-12):
        fmt = lambda d: "continuous" if d is None else f"dt = {d:g} s"  # noqa: E731
        raise ModelError(f"{what}: both systems must share one time base, found {fmt(a)} and {fmt(b)}",
                         hint="discretise the continuous one with c2d(dt) first")
    return a


def as_input_array(u, m: int, what: str = "u") -> np.ndarray:
    """Inputs as a C-contiguous float64 array (N, m); (N,) is accepted when m == 1."""
    a = np.asarray(u, dtype=np.float64)
    if a.ndim == 1 and m == 1:
        a = a.reshape(-1, 1)
    if a.ndim != 2 or a.shape[1] != m:
        raise DataError(f"{what}: expected shape (N, {m}) (one column per input), found {a.shape}")
    if not np.isfinite(a).all():
        k = int(np.argwhere(~np.isfinite(a))[0, 0])
        raise DataError(f"{what} has non-finite values (first at sample {k})", hint="drop or interpolate them")
    return np.ascontiguousarray(a)
