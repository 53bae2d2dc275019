"""C99 code of an identified linear model's step (``gripkit export c``).

The model's discrete state-space realisation (``model.to_ss(dt)``: the system's
``to_ss(minimal=False)``, ZOH-sampled at ``dt`` for a continuous model) runs from rest, with the
model's offsets applied exactly as ``model.simulate(data)`` applies them to a trajectory::

    du = u - u_offset;   y = C x + D du + y_offset;   x <- A x + B du

in that order of summation (each row: Σ_j M[i, j] x[j], then Σ_j N[i, j] du[j]), and carried
state entries below 1e-280 in magnitude set to zero as :func:`gripkit.lti.flush_tiny` does. Inputs
and outputs are SI values (the model's ``input_units``/``output_units``), in the model's input and
output order: not the display units ``gripkit simulate`` writes its file in (``force [mN]``);
multiply by the display unit's factor in the glue code where those are wanted.

With ``float32=True`` the state, the coefficients and the arithmetic are single precision (the
offsets stay double, applied in double before and after); :func:`float32_error_bound` states how
far its outputs may be from the double ones.

Nothing read from the model file enters the C code except in comments, and there only after
:func:`_comment` has kept a safe subset of ASCII (no ``*/``, no backslash, no ``?``).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

from ..atomic import write_text
from ..errors import ArgumentError, ModelError

__all__ = ["c_harness", "c_sources", "check_c_name", "export_c", "float32_bound_on",
           "float32_error_bound"]

#: state entries below this magnitude are carried as zero (as gripkit.lti.FLUSH_BELOW)
FLUSH_DOUBLE = "1e-280"
#: the same for the float32 variant (above FLT_MIN = 1.2e-38, so never subnormal)
FLUSH_FLOAT = "1e-30f"

_C_KEYWORDS = frozenset("""auto break case char const continue default do double else enum extern
float for goto if inline int long register restrict return short signed sizeof static struct switch
typedef union unsigned void volatile while _Bool _Complex _Imaginary main""".split())
_IDENT = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,39}\Z")
_SAFE = re.compile(r"[^A-Za-z0-9 _.,:;=+\-\[\]()%#@<>|]")


def check_c_name(name: str) -> str:
    """``name`` if it can prefix the generated C identifiers (a letter, then letters, digits and
    ``_``, at most 40 characters, not a C keyword), else ArgumentError."""
    if not isinstance(name, str) or not _IDENT.match(name) or name in _C_KEYWORDS:
        raise ArgumentError(f"--name: expected a C identifier (a letter, then letters, digits "
                            f"or '_', at most 40 characters, not a C keyword), found {name!r}",
                            hint="pick a name such as gripper_model")
    return name


def _comment(text) -> str:
    """``text`` reduced to characters that are harmless inside a C block comment."""
    return _SAFE.sub("_", str(text))[:80]


def _realisation(model, dt: float | None):
    """The model's discrete state-space realisation (at ``dt`` for a continuous one) and its
    arrays, through the protocol's ``to_ss`` (a nonlinear model refuses it: ModelError)."""
    try:
        ss = model.to_ss(model.dt if dt is None else float(dt))
    except ModelError as exc:
        raise ModelError(f"export c: {exc.message}", hint=exc.hint) from None
    if ss.dt is None:
        raise ArgumentError("dt: the model is continuous (a tfest model); the C step needs a "
                            "sample time",
                            hint="give the loop's period: --dt 0.001")
    A, B, C, D = (np.asarray(M, dtype=np.float64) for M in (ss.A, ss.B, ss.C, ss.D))
    off = np.concatenate([np.atleast_1d(model.u_offset), np.atleast_1d(model.y_offset)])
    if not all(np.all(np.isfinite(M)) for M in (A, B, C, D, off)):
        raise ModelError("export c: the model's matrices or offsets hold NaN or inf; no C code "
                         "is written",
                         hint="re-identify the model")
    return ss, A, B, C, D


def _num(v: float, float32: bool) -> str:
    if float32:
        return f"{float(np.float32(v))!r}f"
    return repr(float(v))


def _array(name: str, M: np.ndarray, float32: bool, ctype: str) -> str:
    if M.ndim == 1:
        body = ", ".join(_num(v, float32) for v in M)
        return f"static const {ctype} {name}[{M.size}] = {{{body}}};\n"
    rows = ",\n    ".join("{" + ", ".join(_num(v, float32) for v in r) + "}" for r in M)
    return f"static const {ctype} {name}[{M.shape[0]}][{M.shape[1]}] = {{\n    {rows}}};\n"


def _describe(model, ss) -> str:
    s = model.system
    lines = [f"model structure: {_comment(model.structure)}, {ss.n_states} states, "
             f"dt = {ss.dt!r} s"]
    u_off, y_off = np.atleast_1d(model.u_offset), np.atleast_1d(model.y_offset)
    lines += [f"u[{i}]: {_comment(n)} [{_comment(u or '-')}], offset {o!r}"
              for i, (n, u, o) in enumerate(zip(s.inputs, s.input_units, u_off))]
    lines += [f"y[{i}]: {_comment(n)} [{_comment(u or '-')}], offset {o!r}"
              for i, (n, u, o) in enumerate(zip(s.outputs, s.output_units, y_off))]
    return "".join(f" * {ln}\n" for ln in lines)


def _header(name: str, model, ss, float32: bool) -> str:
    N = name.upper()
    nx, nu, ny = ss.n_states, ss.n_inputs, ss.n_outputs
    t = "float" if float32 else "double"
    bound = ""
    if float32:
        b = float32_error_bound(model)
        rule = (f"{b['gain']!r} * max_k (|A||x_k| + |B||du_k|)_inf"
                f" + {b['gamma']!r} * max_k (|C||x_k| + |D||du_k|)_inf" if b["gain"] is not None
                else "no bound: the model is not stable")
        bound = f" * float32: |y - y_double| <= {rule}\n * (gripkit.export.float32_error_bound)\n"
    return (f"/* {name}.h: generated by gripkit export c. Inputs and outputs in SI units.\n"
            f"{_describe(model, ss)}{bound} */\n"
            f"#ifndef {N}_GRIPKIT_H\n#define {N}_GRIPKIT_H\n\n"
            "#ifdef __cplusplus\nextern \"C\" {\n#endif\n\n"
            f"#define {N}_NU {nu}   /* inputs */\n#define {N}_NY {ny}   /* outputs */\n"
            f"#define {N}_NX {nx}   /* states */\n\n"
            f"typedef struct {{\n    {t} x[{max(nx, 1)}];   /* the state"
            f"{' (unused: static model)' if not nx else ''} */\n"
            f"}} {name}_state;\n\n"
            f"/* rest, as `gripkit simulate` starts */\nvoid {name}_init({name}_state *s);\n"
            f"/* one sample: outputs y for inputs u, then the state advances */\n"
            f"void {name}_step({name}_state *s, const double u[{N}_NU], double y[{N}_NY]);\n\n"
            "#ifdef __cplusplus\n}\n#endif\n\n"
            f"#endif /* {N}_GRIPKIT_H */\n")


def _source(name: str, ss, A, B, C, D, model, float32: bool) -> str:
    N = name.upper()
    nx = ss.n_states
    t = "float" if float32 else "double"
    flush = FLUSH_FLOAT if float32 else FLUSH_DOUBLE
    fabs = "fabsf" if float32 else "fabs"
    out = [f"/* {name}.c: generated by gripkit export c (see {name}.h). */\n",
           "#include <math.h>\n#include <string.h>\n", f'#include "{name}.h"\n\n',
           _array("U_OFF", np.atleast_1d(model.u_offset), False, "double"),
           _array("Y_OFF", np.atleast_1d(model.y_offset), False, "double"),
           _array("Cm", C, float32, t), _array("Dm", D, float32, t)]
    if nx:
        out += [_array("Am", A, float32, t), _array("Bm", B, float32, t)]
    out.append(f"\nvoid {name}_init({name}_state *s)\n{{\n    memset(s, 0, sizeof *s);\n}}\n\n")
    cast = f"({t})" if float32 else ""
    body = [f"void {name}_step({name}_state *s, const double u[{N}_NU], double y[{N}_NY])\n{{\n",
            f"    {t} du[{N}_NU];\n"]
    if nx:
        body.append(f"    {t} xn[{N}_NX];\n")
    else:
        body.append("    (void)s;\n")
    body += ["    int i, j;\n",
             f"    for (j = 0; j < {N}_NU; ++j) du[j] = {cast}(u[j] - U_OFF[j]);\n",
             f"    for (i = 0; i < {N}_NY; ++i) {{\n        {t} acc = 0;\n"]
    if nx:
        body.append(f"        for (j = 0; j < {N}_NX; ++j) acc += Cm[i][j] * s->x[j];\n")
    body += [f"        for (j = 0; j < {N}_NU; ++j) acc += Dm[i][j] * du[j];\n",
             "        y[i] = (double)acc + Y_OFF[i];\n    }\n"]
    if nx:
        body += [f"    for (i = 0; i < {N}_NX; ++i) {{\n        {t} acc = 0;\n",
                 f"        for (j = 0; j < {N}_NX; ++j) acc += Am[i][j] * s->x[j];\n",
                 f"        for (j = 0; j < {N}_NU; ++j) acc += Bm[i][j] * du[j];\n",
                 "        xn[i] = acc;\n    }\n",
                 f"    for (i = 0; i < {N}_NX; ++i)\n"
                 f"        s->x[i] = {fabs}(xn[i]) < {flush} ? 0 : xn[i];\n"]
    else:
        body.append("    (void)Cm;\n")
    body.append("}\n")
    return "".join(out + body)


def c_sources(model, name: str = "model", *, float32: bool = False,
              dt: float | None = None) -> dict:
    """``{"NAME.h": text, "NAME.c": text}`` for ``model`` (a :class:`~gripkit.sysid.LinearModel`).

    ``dt`` samples a continuous model (ZOH); a discrete model keeps its own (a different ``dt``
    is refused by ``model.to_ss(dt)``)."""
    check_c_name(name)
    ss, A, B, C, D = _realisation(model, dt)
    return {f"{name}.h": _header(name, model, ss, float32),
            f"{name}.c": _source(name, ss, A, B, C, D, model, float32)}


def _write_sources(files: dict, out_dir) -> list:
    """Write each ``{file name: text}`` of ``files`` into ``out_dir`` (created if missing),
    atomically; returns the paths in the dict's order."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = []
    for fname, text in files.items():
        write_text(out_dir / fname, text)
        paths.append(out_dir / fname)
    return paths


def export_c(model, out_dir, name: str = "model", *, float32: bool = False,
             dt: float | None = None) -> list:
    """Write ``NAME.h`` and ``NAME.c`` of ``model`` into ``out_dir`` (created if missing);
    returns the two paths. See the module docstring for what the step computes."""
    files = c_sources(model, name, float32=float32, dt=dt)
    return _write_sources(files, out_dir)


def c_harness(name: str) -> str:
    """A C99 program that reads ``NAME_NU`` numbers per line from the file named by its first
    argument (SI inputs, the model's order), steps the model from rest on each line and prints
    the ``NAME_NY`` outputs, ``%.17g``, comma-separated, one line per sample."""
    check_c_name(name)
    N = name.upper()
    return (f'#include <stdio.h>\n#include "{name}.h"\n\n'
            "int main(int argc, char **argv)\n{\n"
            f"    {name}_state s;\n    double u[{N}_NU], y[{N}_NY];\n    int i;\n    FILE *f;\n"
            '    if (argc < 2 || !(f = fopen(argv[1], "r"))) return 2;\n'
            f"    {name}_init(&s);\n    for (;;) {{\n"
            f"        for (i = 0; i < {N}_NU; ++i)\n"
            '            if (fscanf(f, " %lf%*[ ,]", &u[i]) != 1) { fclose(f); return 0; }\n'
            f"        {name}_step(&s, u, y);\n"
            f'        for (i = 0; i < {N}_NY; ++i) printf(i ? ",%.17g" : "%.17g", y[i]);\n'
            '        printf("\\n");\n    }\n}\n')


def float32_error_bound(model, dt: float | None = None) -> dict:
    """First-order bound of the ``float32`` step's deviation from the double one.

    Each float32 row sum of ``k`` products (``k = n + m``) from coefficients rounded to float32
    is within ``γ = (k + 2) ε / (1 − (k + 2) ε)``, ``ε = 2⁻²⁴``, of the exact one times the sum of
    absolute terms (Higham, *Accuracy and Stability of Numerical Algorithms*, eq. 3.5, plus one
    rounding of each coefficient and of ``du``). The state error e obeys ``e ← A e + δ``,
    ``|δ| ≤ γ (|A||x| + |B||du|)``, so the output error is at most
    ``gain · max_k ‖|A||x_k| + |B||du_k|‖_∞ + γ · max_k ‖|C||x_k| + |D||du_k|‖_∞`` with
    ``gain = γ Σ_j ‖C A^j‖_∞`` (second-order terms neglected). Returns ``{"gamma", "gain"}``;
    ``gain`` is None for a model that is not stable (no bound). :func:`float32_bound_on` evaluates
    it on a trajectory of states and inputs."""
    ss, A, B, C, D = _realisation(model, dt)
    k = ss.n_states + ss.n_inputs
    eps = 2.0 ** -24
    gamma = (k + 2) * eps / (1 - (k + 2) * eps)
    if ss.n_states == 0:
        return {"gamma": gamma, "gain": 0.0}
    if np.max(np.abs(np.linalg.eigvals(A))) >= 1.0:
        return {"gamma": gamma, "gain": None}
    total = _power_norm_sum(C, A)
    return {"gamma": gamma, "gain": gamma * total if math.isfinite(total) else None}


def _power_norm_sum(C: np.ndarray, A: np.ndarray, block: int = 256,
                    most: int = 1_000_000) -> float:
    """``Σ_j ‖C A^j‖_∞`` for a stable A, up to the first term below 1e-17 of the sum (at most
    ``most`` terms), ``block`` terms per numpy call: ``C A^(kb) · A^i`` for i < b. One product per
    term made a lightly damped model take seconds (docs/performance.md, the float32
    bound)."""
    n = A.shape[0]
    powers = np.empty((block, n, n))
    powers[0] = np.eye(n)
    for i in range(1, block):
        powers[i] = powers[i - 1] @ A
    step = powers[-1] @ A
    total, M = 0.0, np.array(C, dtype=np.float64)
    for _ in range(0, most, block):
        for term in np.abs(M @ powers).sum(axis=2).max(axis=1):
            total += float(term)
            if term <= 1e-17 * total:
                return total
        M = M @ step
    return total


def float32_bound_on(model, u, dt: float | None = None) -> np.ndarray:
    """:func:`float32_error_bound` evaluated on the inputs ``u`` (N, m), SI, offsets not yet
    removed: the bound per output (p,) on ``|y_float32 − y_double|`` over the run from rest.
    ``inf`` for a model that is not stable."""
    ss, A, B, C, D = _realisation(model, dt)
    b = float32_error_bound(model, dt)
    du = np.atleast_2d(np.asarray(u, dtype=np.float64)) - np.asarray(model.u_offset)
    if b["gain"] is None:
        return np.full(ss.n_outputs, np.inf)
    x = np.zeros(ss.n_states)
    drive, direct = 0.0, 0.0
    aA, aB, aC, aD = (np.abs(M) for M in (A, B, C, D))
    for row in du:
        direct = max(direct, float(np.max(aC @ np.abs(x) + aD @ np.abs(row))))
        if ss.n_states:
            drive = max(drive, float(np.max(aA @ np.abs(x) + aB @ np.abs(row))))
            x = A @ x + B @ row
    return np.full(ss.n_outputs, b["gain"] * drive + b["gamma"] * direct)
