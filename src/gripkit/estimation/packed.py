"""Packed vectors: the parameter and state vectors that the compiled Kalman filter and LQG steps
read in flat row-major indexing (no views: making array views inside a kernel costs more than a
small filter's arithmetic). Each layout is written once, as the tuple of its block sizes (a
compiled function of n, m, p); Python reads it as ``{name: offset}`` (:func:`block_offsets`) and
the kernels as a tuple of offsets (:func:`block_starts`), so the two cannot drift apart."""

from __future__ import annotations

from itertools import accumulate

from numba.core import types
from numba.extending import overload

__all__ = ["block_starts", "block_offsets"]


def block_starts(sizes: tuple) -> tuple[tuple, int]:
    """``(starts, total)``: the offset of each block of a vector whose blocks of ``sizes`` (a
    tuple of ints) lie one after another, as a tuple of the same length, and the vector's size.
    Compiled code gets the same sums written out for the tuple's length (no loop, no
    allocation: the offsets fold into the caller's indexing).

    Examples
    --------
    >>> block_starts((4, 2, 3))
    ((0, 4, 6), 9)
    """
    ends = tuple(accumulate(sizes))
    return (0,) + ends[:-1], (ends[-1] if ends else 0)


@overload(block_starts, inline="always")
def _block_starts_compiled(sizes):
    """The compiled :func:`block_starts` for a tuple of ``len(sizes)`` ints: ``o0 = 0``,
    ``o(i+1) = o(i) + sizes[i]``, one line per block (the source is built from the length
    alone)."""
    if not isinstance(sizes, types.BaseTuple):
        return None
    k = len(sizes)
    lines = ["def block_starts(sizes):", "    o0 = 0"]
    lines += [f"    o{i + 1} = o{i} + sizes[{i}]" for i in range(k)]
    lines.append(f"    return ({''.join(f'o{i}, ' for i in range(k))}), o{k}")
    scope = {}
    exec("\n".join(lines), scope)
    return scope["block_starts"]


def block_offsets(names, sizes) -> tuple[dict, int]:
    """``({name: offset}, size)`` of the vector whose blocks ``names`` have ``sizes`` (the
    Python view of :func:`block_starts`).

    Examples
    --------
    >>> block_offsets(("A", "b"), (4, 2))
    ({'A': 0, 'b': 4}, 6)
    """
    starts, total = block_starts(tuple(int(s) for s in sizes))
    return dict(zip(names, starts)), total
