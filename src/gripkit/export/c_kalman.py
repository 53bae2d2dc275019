"""C99 code of an identified model's steady-state Kalman filter (``gripkit export c --kind
kalman``).

The filter is :class:`~gripkit.estimation.KalmanFilter` with ``steady_state=True``: fixed gains
``K_f``, ``K_p`` (the model's own innovation gain K by default, or those of the noise
covariances Q, R, S), on the model's discrete realisation with its offsets::

    du = u − u_offset;   e = y − y_offset − C x_p − D du;   x_hat = x_p + K_f e;
    x_p ← A x_p + B du + K_p e

``NAME_kf_step(s, u, y, x_hat)`` computes that, in the order of summation of the numba
kernel :func:`gripkit.estimation.kalman.kf_step_packed` (each row: the constant term, then its
sums over the index ascending), so that in double precision its ``x_hat`` is the Python filter's
``x[t|t]`` to rounding (1e-12 relative in the tests). No allocation, nothing beyond the C99
language beyond ``fabs`` and ``isnan``: the state is the prediction ``x_p`` (``NAME_kf_init``
sets it to 0, rest), its entries below 1e-280 carried as zero as the Python filter carries them
(:func:`gripkit.lti.flush_tiny`).

A NaN ``y[i]`` is a missing measurement, as in the Python filter: its ``e_i`` is 0 and the
sample's gains are those of the steady prediction covariance with the measured outputs only
(:meth:`~gripkit.estimation.KalmanFilter.gains_measuring`; all missing: zero gains, the time
update alone). Up to :data:`MAX_PATTERN_OUTPUTS` outputs the C code carries the gains of every
pattern of missing outputs (``KFX``, ``KPX``, 2^p each, indexed by the mask of missing
outputs), computed by the Python filter at export time, so the C step equals the Python one on
records with dropouts too; with more outputs a sample with any missing output gets the time
update only (x_hat = x_p), where the Python filter still updates with the measured outputs.

As in :mod:`gripkit.export.c_code`, nothing read from the model file enters the C code except
as a sanitized identifier (``--name``, checked) or in comments reduced to a safe subset of ASCII.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..errors import DataError, ModelError, PathError
from ..estimation import KalmanFilter
from ..estimation.kalman import without_innovation_gain
from .c_code import (FLUSH_DOUBLE, _array, _describe, _num, _realisation, _write_sources,
                     check_c_name)

__all__ = ["export_kalman_c", "kalman_c_harness", "kalman_c_sources", "kalman_filter_of",
           "load_noise"]

#: up to this many outputs the C step carries the gains of every pattern of missing outputs
#: (2^p of them); beyond, a sample with a missing output gets the time update only
MAX_PATTERN_OUTPUTS = 4


def load_noise(path, n: int, p: int) -> tuple:
    """``(Q, R, S)`` from a JSON file ``{"Q": …, "R": …, "S": …}`` (``S`` optional): each a
    matrix (nested lists), or a number q meaning q·I (S: q everywhere). ``n``, ``p``: the model's
    order and number of outputs."""
    path = Path(path)
    try:
        obj = json.loads(path.read_text())
    except OSError as exc:
        raise PathError(f"--noise: cannot read {str(path)!r} ({exc.strerror or exc})",
                        hint="give a JSON file with the keys Q and R") from None
    except ValueError as exc:
        raise DataError(f"--noise: {str(path)!r} is not valid JSON ({exc})") from None
    if not isinstance(obj, dict) or "Q" not in obj or "R" not in obj:
        raise DataError(f"--noise: {str(path)!r} must hold an object with the keys Q and R "
                        f"(and optionally S), found {type(obj).__name__}"
                        + (f" with keys {sorted(map(str, obj))}" if isinstance(obj, dict) else ""))
    out = []
    for key, shape in (("Q", (n, n)), ("R", (p, p)), ("S", (n, p))):
        v = obj.get(key, 0.0 if key == "S" else None)
        try:
            M = np.asarray(v, dtype=np.float64)
        except (TypeError, ValueError):
            raise DataError(f"--noise: {key} in {str(path)!r} must be a number or a matrix of "
                            "numbers") from None
        if M.ndim == 0:
            M = np.full(shape, float(M)) if key == "S" else float(M) * np.eye(shape[0])
        if M.shape != shape or not np.all(np.isfinite(M)):
            raise DataError(f"--noise: {key} in {str(path)!r} must be a finite {shape[0]}×"
                            f"{shape[1]} matrix (or a number) for this model, found shape "
                            f"{M.shape}")
        out.append(M)
    return tuple(out)


def kalman_filter_of(model, Q=None, R=None, S=None, *, dt: float | None = None):
    """The steady-state :class:`~gripkit.estimation.KalmanFilter` that the C code implements."""
    return KalmanFilter(model, Q=Q, R=R, S=S, steady_state=True, dt=dt)


def _header(name: str, model, ss, source: str, patterns: bool) -> str:
    N = name.upper()
    nx, nu, ny = ss.n_states, ss.n_inputs, ss.n_outputs
    missing = (" * a NaN y[i] is a missing measurement: the update uses the measured outputs\n"
               " * only (the Python filter's gains for that pattern; none: time update only)\n"
               if patterns else
               " * a NaN y[i] is a missing measurement: that sample gets the time update only\n"
               f" * (more than {MAX_PATTERN_OUTPUTS} outputs: the Python filter uses the measured"
               " ones)\n")
    return (f"/* {name}.h: generated by gripkit export c --kind kalman. Inputs, outputs and\n"
            " * states in SI units; x_hat is the filtered state x[t|t] of the model's\n"
            " * discrete realisation (its own coordinates).\n"
            f" * gains: {source}\n{missing}"
            f"{_describe(model, ss)} */\n"
            f"#ifndef {N}_KF_GRIPKIT_H\n#define {N}_KF_GRIPKIT_H\n\n"
            "#ifdef __cplusplus\nextern \"C\" {\n#endif\n\n"
            f"#define {N}_NU {nu}   /* inputs */\n#define {N}_NY {ny}   /* outputs */\n"
            f"#define {N}_NX {nx}   /* states */\n\n"
            f"typedef struct {{\n    double x[{nx}];   /* the prediction x[t|t-1] */\n"
            f"}} {name}_kf_state;\n\n"
            f"/* rest: the prediction at the model's operating point */\n"
            f"void {name}_kf_init({name}_kf_state *s);\n"
            "/* one sample: the filtered state x_hat = x[t|t] from u[t], y[t]; then the\n"
            "   prediction advances */\n"
            f"void {name}_kf_step({name}_kf_state *s, const double u[{N}_NU], "
            f"const double y[{N}_NY],\n"
            f"    double x_hat[{N}_NX]);\n\n"
            "#ifdef __cplusplus\n}\n#endif\n\n"
            f"#endif /* {N}_KF_GRIPKIT_H */\n")


def _body(name: str, patterns: bool) -> str:
    """The step, row sums in the numba kernel's order. ``patterns``: the gains of each missing
    pattern are in KFX/KPX (indexed by the mask of missing outputs); without, a sample with a
    missing output gets the time update only."""
    N = name.upper()
    gf, gp = ("KFX[miss]", "KPX[miss]") if patterns else ("KFm", "KPm")
    return (f"void {name}_kf_step({name}_kf_state *s, const double u[{N}_NU], "
            f"const double y[{N}_NY],\n    double x_hat[{N}_NX])\n{{\n"
            f"    double du[{N}_NU], e[{N}_NY], xn[{N}_NX];\n    int i, j;\n"
            "    unsigned miss = 0;   /* y[i] NaN (a missing measurement): bit i, or 1 */\n"
            f"    for (j = 0; j < {N}_NU; ++j) du[j] = u[j] - U_OFF[j];\n"
            f"    for (i = 0; i < {N}_NY; ++i) {{   /* e = y - y0 - C x_p - D du; 0 if missing */\n"
            "        double acc = y[i] - Y_OFF[i];\n"
            f"        for (j = 0; j < {N}_NX; ++j) acc -= Cm[i][j] * s->x[j];\n"
            f"        for (j = 0; j < {N}_NU; ++j) acc -= Dm[i][j] * du[j];\n"
            f"        if (isnan(y[i])) {{ miss {'|= 1u << i' if patterns else '= 1'}; acc = 0; }}\n"
            "        e[i] = acc;\n    }\n"
            + ("" if patterns else
               f"    if (miss) for (i = 0; i < {N}_NY; ++i) e[i] = 0;   /* time update only */\n")
            + f"    for (i = 0; i < {N}_NX; ++i) {{   /* x_hat = x_p + K_f e */\n"
            "        double acc = s->x[i];\n"
            f"        for (j = 0; j < {N}_NY; ++j) acc += {gf}[i][j] * e[j];\n"
            "        x_hat[i] = acc;\n    }\n"
            f"    for (i = 0; i < {N}_NX; ++i) {{   /* x_p <- A x_p + B du + K_p e */\n"
            "        double acc = 0;\n"
            f"        for (j = 0; j < {N}_NX; ++j) acc += Am[i][j] * s->x[j];\n"
            f"        for (j = 0; j < {N}_NU; ++j) acc += Bm[i][j] * du[j];\n"
            f"        for (j = 0; j < {N}_NY; ++j) acc += {gp}[i][j] * e[j];\n"
            "        xn[i] = acc;\n    }\n"
            f"    for (i = 0; i < {N}_NX; ++i)   /* tiny entries carried as 0 (no subnormals) */\n"
            f"        s->x[i] = fabs(xn[i]) < {FLUSH_DOUBLE} ? 0 : xn[i];\n}}\n")


def _pattern_gains(kf, p: int) -> str:
    """KFX, KPX: the gains (n×p) of each pattern of missing outputs, indexed by its mask (bit i:
    y[i] missing; 0: none, the steady gains), as the Python filter computes them."""
    Kf, Kp = [], []
    for mask in range(1 << p):
        if mask == 0:
            f, g = np.asarray(kf.filter_gain), np.asarray(kf.predictor_gain)
        else:
            f, g = kf.gains_measuring([not (mask >> i) & 1 for i in range(p)])
        Kf.append(f)
        Kp.append(g)
    if not (np.all(np.isfinite(Kf)) and np.all(np.isfinite(Kp))):
        raise ModelError("export c --kind kalman: the gains of a pattern of missing outputs "
                         "hold NaN or inf; no C code is written", hint="check the noise "
                         "covariances")
    out = []
    for label, Ks in (("KFX", Kf), ("KPX", Kp)):
        n = Ks[0].shape[0]
        blocks = ",\n    ".join(
            "{" + ", ".join("{" + ", ".join(_num(v, False) for v in row) + "}" for row in K) + "}"
            for K in Ks)
        out.append(f"static const double {label}[{1 << p}][{n}][{p}] = {{\n    {blocks}}};\n")
    return "".join(out)


def kalman_c_sources(model, name: str = "model", Q=None, R=None, S=None, *,
                     dt: float | None = None) -> dict:
    """``{"NAME.h": text, "NAME.c": text}`` of ``model``'s steady-state Kalman filter (module
    docstring): the model's innovation form (its K and Λ) without ``Q``, ``R``, else the gains of
    those noise covariances (n×n, p×p; ``S`` n×p, default 0)."""
    check_c_name(name)
    ss = _realisation(model, dt)[0]
    if ss.n_states == 0 or ss.n_inputs == 0:
        raise ModelError(f"export c --kind kalman: the C filter needs states and inputs; the "
                         f"model has {ss.n_states} state(s) and {ss.n_inputs} input(s)",
                         hint="export the model itself: --kind model")
    if Q is None and R is None and getattr(model, "K", None) is None:
        raise ModelError(f"export c --kind kalman: {without_innovation_gain(model)}; the filter "
                         f"needs the noise covariances Q ({ss.n_states}×{ss.n_states}) and R "
                         f"({ss.n_outputs}×{ss.n_outputs})",
                         hint='give them in a JSON file: --noise NOISE.json, with '
                              '{"Q": …, "R": …} (matrices, or numbers meaning q·I)')
    kf = kalman_filter_of(model, Q, R, S, dt=dt)
    Kf, Kp = np.asarray(kf.filter_gain), np.asarray(kf.predictor_gain)
    if not (np.all(np.isfinite(Kf)) and np.all(np.isfinite(Kp))):
        raise ModelError("export c --kind kalman: the filter's gains hold NaN or inf; no C code "
                         "is written", hint="check the noise covariances")
    patterns = ss.n_outputs <= MAX_PATTERN_OUTPUTS
    source = ("the model's innovation gain K (its own steady-state predictor)"
              if kf.innovation_form else "the steady-state Riccati solution of the given Q, R")
    src = [f"/* {name}.c: generated by gripkit export c --kind kalman (see {name}.h). */\n",
           f'#include <math.h>\n#include "{name}.h"\n\n',
           _array("U_OFF", np.atleast_1d(model.u_offset), False, "double"),
           _array("Y_OFF", np.atleast_1d(model.y_offset), False, "double"),
           _array("Am", np.asarray(kf.A), False, "double"),
           _array("Bm", np.asarray(kf.B), False, "double"),
           _array("Cm", np.asarray(kf.C), False, "double"),
           _array("Dm", np.asarray(kf.D), False, "double"),
           (_pattern_gains(kf, ss.n_outputs) if patterns else
            _array("KFm", Kf, False, "double") + _array("KPm", Kp, False, "double")),
           f"\nvoid {name}_kf_init({name}_kf_state *s)\n{{\n    int i;\n"
           f"    for (i = 0; i < {name.upper()}_NX; ++i) s->x[i] = 0.0;\n}}\n\n",
           _body(name, patterns)]
    return {f"{name}.h": _header(name, model, ss, source, patterns),
            f"{name}.c": "".join(src)}


def export_kalman_c(model, out_dir, name: str = "model", Q=None, R=None, S=None, *,
                    dt: float | None = None) -> list:
    """Write :func:`kalman_c_sources` into ``out_dir`` (created if missing); returns the two
    paths."""
    files = kalman_c_sources(model, name, Q, R, S, dt=dt)
    return _write_sources(files, out_dir)


def kalman_c_harness(name: str) -> str:
    """A C99 program that reads ``NAME_NU`` inputs then ``NAME_NY`` outputs per line (SI, the
    model's order) from the file named by its first argument, runs the filter from rest and
    prints ``x_hat`` (``%.17g``, comma-separated), one line per sample."""
    check_c_name(name)
    N = name.upper()
    return (f'#include <stdio.h>\n#include "{name}.h"\n\n'
            "int main(int argc, char **argv)\n{\n"
            f"    {name}_kf_state s;\n    double u[{N}_NU], y[{N}_NY], x[{N}_NX];\n"
            "    int i;\n    FILE *f;\n"
            '    if (argc < 2 || !(f = fopen(argv[1], "r"))) return 2;\n'
            f"    {name}_kf_init(&s);\n    for (;;) {{\n"
            f"        for (i = 0; i < {N}_NU; ++i)\n"
            '            if (fscanf(f, " %lf%*[ ,]", &u[i]) != 1) { fclose(f); return 0; }\n'
            f"        for (i = 0; i < {N}_NY; ++i)\n"
            '            if (fscanf(f, " %lf%*[ ,]", &y[i]) != 1) { fclose(f); return 3; }\n'
            f"        {name}_kf_step(&s, u, y, x);\n"
            f'        for (i = 0; i < {N}_NX; ++i) printf(i ? ",%.17g" : "%.17g", x[i]);\n'
            '        printf("\\n");\n    }\n}\n')
