"""One-state inverse dynamics and mass matrix with the least call overhead.

A controller or an estimator calls ``chain.rnea(q, qd, qdd)`` on one state at a time; there the
cost is the call, not the arithmetic. The batched path validates and stacks its inputs and
passes 17 arrays to the kernel (the figures: docs/performance.md, "One-state RNEA and CRBA").
This path packs the model and its scratch memory once into one float64 array
(:func:`pack`) kept with the chain, so a call is one ``np.empty`` and one call of a kernel compiled
for float64 arrays only, with three (mass matrix) or five (RNEA) arguments: unboxing an argument
is most of the cost of a call. Inside, the model's 2-D views are built in place
(:func:`_rows`) and the link transforms, CRBA and Γ projection are compiled inline
(:func:`_inline_twins`): one function without calls into numba's runtime or between kernels.
Other argument types raise TypeError at the call, and the kernel reports a state of the wrong
length, a strided state or one with NaN/inf: the caller then takes the validating path, which
converts it or raises the error. The scratch is shared by the calls on one
chain, which is safe because the kernels hold the GIL (compiled without ``nogil``): calls from
several threads run one after the other. The buffer is for these two kernels only; the batched
and ``prange`` kernels take their own scratch per state, never this buffer. The mass matrix
(:func:`mass_matrix_one`, CRBA) takes the same path. Measured in ``benchmarks/bench_urdf.py`` and
``benchmarks/bench_multibody.py`` against one ``pinocchio.rnea`` / ``pinocchio.crba`` call.
"""

from __future__ import annotations

import math
import types

import numba
import numpy as np
from numba.core import cgutils
from numba.core import types as nbtypes
from numba.core.imputils import impl_ret_borrowed
from numba.extending import intrinsic
from numba.np.arrayobj import make_array, populate_array

from . import kernels
from .kernels import WORK_PER_LINK, ChainArrays, hot_inline, links_of, rnea_pass

__all__ = ["mass_matrix_entry", "mass_matrix_one", "pack", "prepare", "rnea_one"]

#: header of the packed buffer: n, m, dh width, then the offsets of dh, mass, com, inertia,
#: arm_q, Γ, q₀, arm_p, gravity, joint types and the scratch
_HEADER = 14


def pack(arrays) -> np.ndarray:
    """One float64 buffer for :func:`rnea_one` and :func:`mass_matrix_one` from a system's
    ``kernel_arrays()``: a header of sizes and offsets (small integers, exact as floats), the
    model, and the scratch the kernels write. One array is one argument to unbox per call."""
    dh, jt, mass, com, inertia, arm_q, G, q0, arm_p, g = arrays
    n, w = dh.shape
    m = arm_p.shape[0]
    parts = [dh.ravel(), mass, com.ravel(), inertia.ravel(), arm_q, G.ravel(), q0, arm_p, g,
             np.asarray(jt, dtype=np.float64),
             np.zeros(12 * n + WORK_PER_LINK * n + 4 * n + n * n)]
    offsets = _HEADER + np.cumsum([0] + [p.size for p in parts])
    return np.concatenate([[n, m, w], offsets[:11], *parts]).astype(np.float64)


@intrinsic
def _rows(typingctx, a, start, rows, cols):  # pragma: no cover - compiled
    """``a[start:start + rows·cols]`` as a C-contiguous (rows, cols) array, built in place: numba's
    ``reshape`` calls a C helper of its runtime for each view, six per call here, most of the
    packed-model views' cost (docs/performance.md, CRBA). No bounds check: the offsets and sizes
    come from :func:`pack`, which sized the buffer for them."""
    ret = nbtypes.Array(a.dtype, 2, "C")

    def codegen(context, builder, sig, args):
        ary = make_array(sig.args[0])(context, builder, args[0])
        view = make_array(ret)(context, builder)
        start, r, c = (context.cast(builder, v, t, nbtypes.intp)
                       for v, t in zip(args[1:], sig.args[1:]))
        item = context.get_constant(nbtypes.intp, context.get_abi_sizeof(
            context.get_data_type(a.dtype)))
        populate_array(view, data=builder.gep(ary.data, [start]),
                       shape=cgutils.pack_array(builder, [r, c]),
                       strides=cgutils.pack_array(builder, [builder.mul(c, item), item]),
                       itemsize=ary.itemsize, meminfo=ary.meminfo, parent=ary.parent)
        return impl_ret_borrowed(context, builder, ret, view._getvalue())

    return ret(a, start, rows, cols), codegen


if numba.config.DISABLE_JIT:  # the kernels run as Python: the view the intrinsic builds
    def _rows(a, start, rows, cols):  # noqa: F811
        return a[start:start + rows * cols].reshape(rows, cols)


def _inline_twins(*names):
    """Twins of the named :mod:`~gripkit.multibody.kernels` functions: the same code object,
    compiled ``inline="always"`` into the one-state kernels, the calls among the named functions
    going to the twins too. The one-state mass matrix is then one function, without compiled
    calls that pass each array as its nine fields (docs/performance.md, CRBA); the batched
    kernels keep their compiled calls. Same operations in the same order: bit-identical.
    Returns {name: twin}."""
    ns = dict(vars(kernels))
    for name in names:
        fn = getattr(kernels, name)
        fn = getattr(fn, "py_func", fn)  # (a plain function under NUMBA_DISABLE_JIT)
        ns[name] = numba.njit(error_model="numpy", _nrt=False, inline="always")(
            types.FunctionType(fn.__code__, ns, name, fn.__defaults__, fn.__closure__))
    return {name: ns[name] for name in names}


_TWINS = _inline_twins("chain_links", "crba", "project_mass", "dh_link", "placement_links",
                       "_link_inertias", "_composite_inertias", "_mass_matrix_columns")
_chain_links, _crba, _project_mass = (_TWINS[k] for k in ("chain_links", "crba", "project_mass"))


@hot_inline
def _model(buf):  # pragma: no cover - compiled
    """Views of the packed buffer (no allocation): sizes, the model as a :data:`ChainArrays`
    record (joint types as floats) and the scratch."""
    n = int(buf[0])
    m = int(buf[1])
    w = int(buf[2])
    o = buf[3:_HEADER]
    dh = _rows(buf, int(o[0]), n, w)
    mass = buf[int(o[1]):int(o[1]) + n]
    com = _rows(buf, int(o[2]), n, 3)
    inertia = _rows(buf, int(o[3]), n, 6)
    arm_q = buf[int(o[4]):int(o[4]) + n]
    G = buf[int(o[5]):int(o[5]) + n * m]
    q0 = buf[int(o[6]):int(o[6]) + n]
    arm_p = buf[int(o[7]):int(o[7]) + m]
    g = buf[int(o[8]):int(o[8]) + 3]
    jtype = buf[int(o[9]):int(o[9]) + n]
    work = buf[int(o[10]):]
    return n, m, ChainArrays(dh, jtype, mass, com, inertia, arm_q, G, q0, arm_p, g), work


@hot_inline
def _finite(m, q):  # pragma: no cover - compiled
    """q has length m, stride 8 (numba's entry point reads a strided view as if contiguous)
    and no NaN or inf."""
    if q.shape[0] != m or q.strides[0] != 8:
        return False
    for i in range(m):
        if not math.isfinite(q[i]):
            return False
    return True


@hot_inline
def _links(n, m, ch, q, work):  # pragma: no cover - compiled
    """Joint positions Γ p + q₀ into the scratch and the link transforms R, P for them."""
    G, q0 = ch.G, ch.q0
    R = _rows(work, 0, n, 9)
    P = _rows(work, 9 * n, n, 3)
    qq = work[12 * n + WORK_PER_LINK * n:13 * n + WORK_PER_LINK * n]
    for k in range(n):
        s = q0[k]
        for a in range(m):
            s += G[k * m + a] * q[a]
        qq[k] = s
    _chain_links(n, ch.links, ch.jtype, qq, R, P)
    return R, P


@numba.njit("b1(f8[::1], f8[::1], f8[::1], "
            "f8[::1], f8[::1])", cache=True, error_model="numpy", _nrt=False)
def rnea_one(buf, q, qd, qdd, out):  # pragma: no cover - compiled
    """τ_p = Γᵀ RNEA(Γ p + q₀, Γ ṗ, Γ p̈) + armature_p·p̈ for one state; False when the state has
    NaN or inf or the wrong length, or ``out`` is not of length m (out untouched). Compiled for 1-D
    float64 arrays only
    (other types raise TypeError at the call)."""
    n, m, ch, work = _model(buf)
    if out.shape[0] != m or not (_finite(m, q) and _finite(m, qd) and _finite(m, qdd)):
        return False
    G, g, arm_p = ch.G, ch.g, ch.arm_p
    R, P = _links(n, m, ch, q, work)
    b = 12 * n + WORK_PER_LINK * n
    qqd = work[b + n:b + 2 * n]
    qqdd = work[b + 2 * n:b + 3 * n]
    tau = work[b + 3 * n:b + 4 * n]
    for k in range(n):
        sd = 0.0
        sdd = 0.0
        for a in range(m):
            gk = G[k * m + a]
            sd += gk * qd[a]
            sdd += gk * qdd[a]
        qqd[k] = sd
        qqdd[k] = sdd
    rnea_pass(n, links_of(ch), R, P, qqd, qqdd, g[0], g[1], g[2], True, tau, work[12 * n:b])
    for a in range(m):
        s = arm_p[a] * qdd[a]
        for k in range(n):
            s += G[k * m + a] * tau[k]
        out[a] = s
    return True


@numba.njit("b1(f8[::1], f8[::1], f8[:, ::1])", cache=True, error_model="numpy", _nrt=False)
def mass_matrix_one(buf, q, out):  # pragma: no cover - compiled
    """M_p = Γᵀ M(Γ p + q₀) Γ + diag(armature_p) (CRBA, thesis eqs 4.14–4.16) for one state into
    ``out`` (m×m); False when q has NaN or inf or the wrong length, or ``out`` is not m×m (out
    untouched)."""
    n, m, ch, work = _model(buf)
    if out.shape[0] != m or out.shape[1] != m or not _finite(m, q):
        return False
    R, P = _links(n, m, ch, q, work)
    b = 12 * n + WORK_PER_LINK * n
    Mq = _rows(work, b + 4 * n, n, n)
    _crba(n, links_of(ch), R, P, Mq, work[12 * n:b])
    _project_mass(n, m, Mq, ch.G, ch.arm_p, out)
    return True


def mass_matrix_entry():
    """The compiled :func:`mass_matrix_one`'s own CPython wrapper (numba's ``entry_point`` for its
    one signature): it unboxes its three arguments as the declared types without the
    dispatcher's type resolution (docs/performance.md, CRBA). It does not check them: numba reads
    any array with 8-byte items as float64 and writes an array of more dimensions past the
    declared ones, so only :meth:`~gripkit.multibody.dh.Dynamics.mass_matrix` calls it, with the
    chain's packed buffer, a fresh C-contiguous (m, m) float64 array, and a state with the
    native float64 dtype and one dimension (checked in Python first; an object that is not an
    ndarray raises TypeError here, and the kernel refuses a stride other than 8). The dispatcher
    where numba has no ``entry_point``."""
    overloads = getattr(mass_matrix_one, "overloads", {})  # (none under NUMBA_DISABLE_JIT)
    sig = next(iter(overloads), None)
    return getattr(overloads.get(sig), "entry_point", mass_matrix_one)


def prepare(system):
    """(packed buffer, m, (m, m), :func:`mass_matrix_entry`) of ``system`` for ``Dynamics.rnea``
    and ``Dynamics.mass_matrix`` (the shape tuple made once: building it per call is a
    measurable part of a call)."""
    m = system.dof
    return pack(system.kernel_arrays()), m, (m, m), mass_matrix_entry()
