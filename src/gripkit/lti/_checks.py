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
        raise ModelError(f"{name} has non-finite entries (first at [{bad[0]}, {bad[1]}] = "
                         f"{a[tuple(bad)]})",
                         hint="a linear system needs finite matrices")
    a.flags.writeable = False
    return a


def as_dt(dt) -> float | None:
    """``None`` or 0 → continuous (None); a finite positive number → discrete sample time (s)."""
    if dt is None or (not isinstance(dt, bool) and isinstance(dt,
                                                              (int, float, np.number)) and dt == 0):
        return None
    if isinstance(dt, bool) or not isinstance(dt,
                                              (int, float,
                                                   np.number)) or not math.isfinite(dt) or dt < 0:
        raise ModelError("dt: expected None or 0 (continuous) or a positive sample time in "
                         f"s, found {dt!r}")
    return float(dt)


def require_discrete(dt, what: str) -> float:
    """A positive, finite sample time for an operation that needs one."""
    if dt is None or isinstance(dt, bool) or not isinstance(dt, (int, float, np.number)) \
            or not math.isfinite(dt) or dt <= 0:
        raise ModelError(f"{what}: expected a positive sample time dt in s, found {dt!r}")
    return float(dt)


def _labels(values, n: int, what: str, kind: str):
    """``values`` (one string or a sequence of n) as a tuple of n strings, or None when absent."""
    if values is None or (not isinstance(values, str) and len(values) == 0):
        return None
    values = (values,) if isinstance(values, str) else tuple(values)
    if len(values) != n:
        raise ModelError(f"{what}: expected {n} {kind}, found {len(values)} "
                         f"({', '.join(map(str, values))})")
    for s in values:
        if not isinstance(s, str) or (kind == "names" and not s):
            raise ModelError(f"{what}: {kind} must be "
                             f"{'non-empty ' if kind == 'names' else ''}strings, "
                             f"found {s!r}")
    return values


def as_names(names, n: int, what: str, default: str) -> tuple[str, ...]:
    """``n`` distinct signal names; None/empty gives ``default0 .. default{n-1}`` (or ``default``
    alone when n == 1)."""
    names = _labels(names, n, what, "names")
    if names is None:
        return (default,) if n == 1 else tuple(f"{default}{i}" for i in range(n))
    if len(set(names)) != n:
        dup = sorted({s for s in names if names.count(s) > 1})
        raise ModelError(f"{what}: names must be distinct, found {', '.join(dup)} more than once")
    return names


def as_units(units, n: int, what: str) -> tuple[str, ...]:
    """``n`` unit strings (SI spelling, ``''`` = not declared)."""
    units = _labels(units, n, what, "units")
    return ("",) * n if units is None else units


def same_dt(a, b, what: str) -> float | None:
    """The common sample time of two systems, or a ModelError naming both."""
    if a is None and b is None:
        return None
    if a is None or b is None or not math.isclose(a, b, rel_tol=1e-12):
        fmt = lambda d: "continuous" if d is None else f"dt = {d:g} s"  # noqa: E731
        raise ModelError(f"{what}: both systems must share one time base, found "
                         f"{fmt(a)} and {fmt(b)}",
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
        raise DataError(f"{what} has non-finite values "
                        f"(first at sample {k})", hint="drop or interpolate them")
    return np.ascontiguousarray(a)
