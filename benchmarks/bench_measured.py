"""Measured data: gripkit beside SIPPY (sippy_unipi), nfoursid and sysidentpy on the DC
motor/generator record published with SysIdentPy (tests/fixtures/dc_motor: source, commit,
BSD-3 licence), in the same run, then on the measured corpus of tests/fixtures (:data:`CORPUS`:
CD player arm 2x2, evaporator 3x3, flexible robot arm, EMPS, cascaded tanks, Silverbox; each
folder's README and LICENSE give source and terms) and EMPS's IDIM-LS beside its published
estimates. Corpus rows: same order and horizon on every side, the free-run validation fit of
every side's model by gripkit's one definition (offsets of the estimation record, x0 by least
squares); `python benchmarks/run.py --only measured --out DIR`.

Split as SysIdentPy's own example: the first 500 samples estimate, the last 500 validate. Accuracy
beside every time: the free-run fit on the validation half, 100 (1 − ‖y − ŷ‖/‖y − ȳ‖), in %:

* state-space models (gripkit, SIPPY, nfoursid): the initial state estimated by least squares
  (the same :meth:`LinearModel.compare` for every model), operating point (mean) removed from each
  half;
* sysidentpy: its own ``predict(X, y)`` (free run started from the first ``max_lag`` measured
  outputs), on the raw data as its example does (its polynomial basis carries the constant).

Rows (both sides through ``common.measure``: same warm-up call and number of runs):

* order-3 subspace, horizon 8 on every side: gripkit ``n4sid`` beside SIPPY ``N4SID`` and nfoursid
  (``NFourSID(…, num_block_rows=8)``, ``system_identification(rank=3)``);
* gripkit ``n4sid`` + ``pem(form='oe')``: the refined model;
* linear ARX, lags 4: gripkit ``arx(u, y, 4, 4, 1)`` beside sysidentpy ``FROLS`` with a degree-1
  polynomial basis (ylag = xlag = 4, BIC order selection, least squares) — the same model class;
* sysidentpy's own example on these data (``FROLS``, degree-2 polynomial NARX, ylag = xlag = 5,
  BIC, recursive least squares) beside gripkit's refined linear model: different model classes;
  it shows what a nonlinear model gains on this system;
* polynomial NARX, degree 3, lags 2, BIC on both sides: gripkit ``narx`` beside sysidentpy ``FROLS``
  (least squares).
"""

from __future__ import annotations

import contextlib
import io
import warnings
from pathlib import Path

import numpy as np
from common import measure, row

FIXTURE = Path(__file__).resolve().parents[1] / "tests" / "fixtures" / "dc_motor" / "dc_motor.csv"
ORDER = 3
HORIZON = 8
LAGS = 4
DATA = "DC motor (SysIdentPy, measured), 500 + 500 samples"


def _halves():
    from gripkit.io import load

    tr = load(FIXTURE, fs=1.0)
    u, y = np.asarray(tr["voltage"]), np.asarray(tr["output"])
    return (u[:500], y[:500]), (u[500:], y[500:])


def _fit_text(fit):
    return "unstable model" if fit is None else f"validation fit {fit:.1f} %"


def _ss_fit(A, B, C, D, uv, yv):
    from gripkit.lti import StateSpace
    from gripkit.sysid.linear.linear_model import LinearModel

    m = LinearModel(StateSpace(A, B, C, D, dt=1.0), "peer")
    return None if not m.stable else float(m.compare(uv - uv.mean(), yv - yv.mean())[0][0])


def _fit(y, yhat):
    from gripkit.sysid.linear.linear_model import fit_per_output

    return float(fit_per_output(np.reshape(y, (-1, 1)), np.reshape(yhat, (-1, 1)))[0])


def _quiet(fn):
    def call():
        with contextlib.redirect_stdout(io.StringIO()), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return fn()
    return call


def _abcd(model):
    s = model.system.to_ss(minimal=False)
    return s.A, s.B, s.C, s.D


def _sysidentpy(degree: int, lag: int, recursive: bool, ue, ye):
    from sysidentpy.basis_function import Polynomial
    from sysidentpy.model_structure_selection import FROLS
    from sysidentpy.parameter_estimation import LeastSquares, RecursiveLeastSquares

    def call():
        model = FROLS(order_selection=True, n_info_values=100 if degree > 1 else 2 * lag + 1,
                      ylag=lag, xlag=lag, info_criteria="bic",
                      estimator=RecursiveLeastSquares() if recursive else LeastSquares(),
                      basis_function=Polynomial(degree=degree), err_tol=None)
        model.fit(X=ue[:, None], y=ye[:, None])
        return model
    return _quiet(call)


def run(quick: bool) -> list[dict]:
    """All rows; ``quick`` changes nothing (the record is small)."""
    from gripkit.sysid import arx, n4sid, pem
    from gripkit.sysid.linear.linear_model import from_polynomial

    (ue, ye), (uv, yv) = _halves()
    u0, y0 = ue - ue.mean(), ye - ye.mean()
    rows = []

    ours = lambda: n4sid(u0, y0, ORDER, horizon=HORIZON, dt=1.0)  # noqa: E731
    t_ours = measure(ours)
    s = ours().system
    fit_ours = _ss_fit(s.A, s.B, s.C, s.D, uv, yv)
    task = f"n4sid order {ORDER}, horizon {HORIZON}, {DATA}"

    import sippy_unipi as sippy

    def sippy_call():
        sm = sippy.system_identification(y0[None, :], u0[None, :], "N4SID", SS_fixed_order=ORDER,
                                         SS_f=HORIZON, SS_p=HORIZON)
        return tuple(np.asarray(a) for a in (sm.A, sm.B, sm.C, sm.D))
    sippy_call = _quiet(sippy_call)
    rows.append(row("measured", task, t_ours, "sippy_unipi N4SID", measure(sippy_call),
                    gripkit_accuracy=_fit_text(fit_ours), peer_accuracy=_fit_text(_ss_fit(*sippy_call(), uv, yv)),
                    notes="same order and horizon; free run, x0 estimated"))

    import pandas as pd
    from nfoursid.nfoursid import NFourSID

    df = pd.DataFrame({"u": u0, "y": y0})

    def nfoursid_call():
        nf = NFourSID(df, output_columns=["y"], input_columns=["u"], num_block_rows=HORIZON)
        nf.subspace_identification()
        ss, _ = nf.system_identification(rank=ORDER)
        return ss.a, ss.b, ss.c, ss.d
    rows.append(row("measured", task, t_ours, "nfoursid", measure(nfoursid_call),
                    gripkit_accuracy=_fit_text(fit_ours), peer_accuracy=_fit_text(_ss_fit(*nfoursid_call(), uv, yv)),
                    notes="same order and block rows; free run, x0 estimated"))

    refined = lambda: pem(ours(), u=u0, y=y0, form="oe")  # noqa: E731
    t_refined = measure(refined)
    s = refined().system
    fit_refined = _ss_fit(s.A, s.B, s.C, s.D, uv, yv)
    rows.append(row("measured", f"n4sid + PEM (output error), order {ORDER}, {DATA}", t_refined, "", None,
                    gripkit_accuracy=_fit_text(fit_refined), notes="the subspace model refined; free run, x0 estimated"))

    ours_arx = lambda: arx(u0, y0, LAGS, LAGS, 1, dt=1.0)  # noqa: E731
    fit_arx = _ss_fit(*_abcd(from_polynomial(ours_arx())), uv, yv)
    linear = _sysidentpy(1, LAGS, False, ue, ye)
    m = linear()
    rows.append(row("measured", f"linear ARX, lags {LAGS}, {DATA}", measure(ours_arx), "sysidentpy FROLS degree 1",
                    measure(linear), gripkit_accuracy=_fit_text(fit_arx),
                    peer_accuracy=_fit_text(_fit(yv, m.predict(X=uv[:, None], y=yv[:, None]))),
                    notes=f"same model class; sysidentpy keeps {m.final_model.shape[0]} of its {2 * LAGS} terms (BIC); "
                          "gripkit: x0 estimated, sysidentpy: its predict from the first measured lags"))

    narx = _sysidentpy(2, 5, True, ue, ye)
    m = narx()
    rows.append(row("measured", f"best model of each tool, {DATA}", t_refined,
                    "sysidentpy FROLS degree-2 NARX (its own example)", measure(narx),
                    gripkit_accuracy=_fit_text(fit_refined) + " (linear, n4sid + PEM)",
                    peer_accuracy=_fit_text(_fit(yv, m.predict(X=uv[:, None], y=yv[:, None]))) + " (nonlinear)",
                    notes="different model classes: the motor speeds up and coasts down with different time "
                          "constants, which a polynomial NARX captures and a linear model cannot"))
    rows.append(_narx_row(ue, ye, uv, yv))
    for rec in CORPUS:
        rows.extend(_corpus_rows(rec))
    rows.append(_emps_idim_row())
    return rows


def _narx_row(ue, ye, uv, yv) -> dict:
    """Polynomial NARX, degree 3, lags 2, BIC on both sides (sysidentpy: least squares)."""
    from gripkit.sysid import narx as gripkit_narx

    ours = lambda: gripkit_narx(ue, ye, degree=3, lags=2)  # noqa: E731
    g = ours()
    peer = _sysidentpy(3, 2, False, ue, ye)
    m = peer()
    return row("measured", f"polynomial NARX, degree 3, lags 2, BIC, {DATA}", measure(ours),
               "sysidentpy FROLS degree 3", measure(peer),
               gripkit_accuracy=_fit_text(g.compare(uv, yv)) + f" ({len(g.terms)} terms)",
               peer_accuracy=_fit_text(_fit(yv, m.predict(X=uv[:, None], y=yv[:, None])))
               + f" ({m.final_model.shape[0]} terms)",
               notes="same model class; gripkit: FROLS + BIC + pruning of |θ|/σ < 2, fit over the "
                     "samples after the first max_lag; sysidentpy: its predict, fit over every sample")


# ------------------------------------------------------------------------- the measured corpus
FIXTURES = Path(__file__).resolve().parents[1] / "tests" / "fixtures"

#: The public measured records of tests/fixtures (each folder's README: source, licence, what was
#: cut). ``split``: the estimation part of a single file (its first half) or the two files of the
#: benchmark's own estimation/validation pair; ``fs`` where the file has no time column (the
#: source states no sampling period: one sample per unit of time). Order: the same on every side;
#: horizon (block rows) ``max(8, 2 n)`` on every side.
CORPUS = (
    dict(name="CD player arm (DaISy, 2x2)", files=("cd_player_arm/cd_player_arm.csv",),
         inputs=("force1", "force2"), outputs=("tracking1", "tracking2"), fs=1.0, order=8),
    dict(name="evaporator (DaISy, 3x3)", files=("evaporator/evaporator.csv",),
         inputs=("feed_flow", "vapor_flow", "cooling_flow"),
         outputs=("dry_matter", "product_flow", "product_temp"), fs=1.0, order=6),
    dict(name="flexible robot arm (DaISy 96-009)", files=("flexible_arm/flexible_arm.csv",),
         inputs=("torque",), outputs=("acceleration",), fs=1.0, order=8),
    dict(name="EMPS prismatic joint, closed loop (reference to position)",
         files=("emps/emps_est.csv", "emps/emps_val.csv"), inputs=("reference",),
         outputs=("position",),
         fs=None, order=2),
    dict(name="cascaded tanks (nonlinear benchmark)",
         files=("cascaded_tanks/cascaded_tanks_est.csv", "cascaded_tanks/cascaded_tanks_val.csv"),
         inputs=("pump",), outputs=("level",), fs=None, order=3),
    dict(name="Silverbox (nonlinear benchmark)",
         files=("silverbox/silverbox_est.csv", "silverbox/silverbox_val.csv"),
         inputs=("input",), outputs=("output",), fs=1e7 / 2 ** 14, order=2),
)


def corpus_data(rec):
    """The estimation and validation trajectories, their (u, y) arrays and the sample interval,
    as gripkit loads them."""
    from gripkit.io import load
    from gripkit.signals import split

    parts = [load(FIXTURES / f, fs=rec["fs"]) for f in rec["files"]]
    est, val = split(parts[0], 2) if len(parts) == 1 else parts

    def cols(tr, names):
        return np.column_stack([np.asarray(tr[c]) for c in names])
    return (est, val), (cols(est, rec["inputs"]), cols(est, rec["outputs"])), \
        (cols(val, rec["inputs"]), cols(val, rec["outputs"])), float(est.dt)


def _fits_text(fit):
    if fit is None:
        return "unstable model"
    return "validation fit " + ", ".join(f"{f:.1f}" for f in fit) + " %"


def _mimo_fit(A, B, C, D, dt, uv, yv, ue, ye):
    """gripkit's one validation fit (``linear_model.VALIDATION_FIT``) of any side's model: free
    run from the estimation record's operating point (its means), x0 by least squares."""
    from gripkit.lti import StateSpace
    from gripkit.sysid.linear.linear_model import LinearModel

    m = LinearModel(StateSpace(A, B, C, D, dt=dt), "peer")
    if not m.stable:
        return None
    return [float(f) for f in m.compare(uv - ue.mean(0), yv - ye.mean(0))[0]]


def _corpus_rows(rec) -> list[dict]:
    """One record: gripkit's subspace model beside SIPPY's and nfoursid's (same order and
    horizon), gripkit's user route (`identify ss` with --validate: subspace, PEM, the better by
    the free-run fit kept), and for one-input one-output records linear ARX beside sysidentpy."""
    import pandas as pd
    import sippy_unipi as sippy
    from nfoursid.nfoursid import NFourSID

    from gripkit.sysid import arx, n4sid
    from gripkit.sysid.linear.identify_mimo import identify_ss
    from gripkit.sysid.linear.linear_model import from_polynomial

    (est, val), (ue, ye), (uv, yv), dt = corpus_data(rec)
    u0, y0 = ue - ue.mean(0), ye - ye.mean(0)
    n = rec["order"]
    k = max(8, 2 * n)
    data = f"{rec['name']}, {len(ue)} + {len(uv)} samples"
    task = f"subspace order {n}, horizon {k}, {data}"
    rows = []

    ours = lambda: n4sid(u0, y0, n, horizon=k, dt=dt)  # noqa: E731
    t_ours = measure(_quiet(ours))
    s = ours().system
    fit_ours = _mimo_fit(s.A, s.B, s.C, s.D, dt, uv, yv, ue, ye)

    def sippy_call():
        sm = sippy.system_identification(y0.T, u0.T, "N4SID", SS_fixed_order=n, SS_f=k, SS_p=k)
        return tuple(np.atleast_2d(np.asarray(a, dtype=float)) for a in (sm.A, sm.B, sm.C, sm.D))
    sippy_call = _quiet(sippy_call)
    rows.append(row("measured", task, t_ours, "sippy_unipi N4SID", measure(sippy_call),
                    gripkit_accuracy=_fits_text(fit_ours),
                    peer_accuracy=_fits_text(_mimo_fit(*sippy_call(), dt, uv, yv, ue, ye)),
                    notes="same order and horizon; free run, x0 estimated, per output",
                    extra=dict(record=rec["files"][0].split("/")[0], gripkit_fit=fit_ours)))

    ins = [f"u{i}" for i in range(u0.shape[1])]
    outs = [f"y{i}" for i in range(y0.shape[1])]
    df = pd.DataFrame(dict(zip(ins + outs, [*u0.T, *y0.T])))

    def nfoursid_call():
        nf = NFourSID(df, output_columns=outs, input_columns=ins, num_block_rows=k)
        nf.subspace_identification()
        ss, _ = nf.system_identification(rank=n)
        return ss.a, ss.b, ss.c, ss.d
    nfoursid_call = _quiet(nfoursid_call)
    rows.append(row("measured", task, t_ours, "nfoursid", measure(nfoursid_call),
                    gripkit_accuracy=_fits_text(fit_ours),
                    peer_accuracy=_fits_text(_mimo_fit(*nfoursid_call(), dt, uv, yv, ue, ye)),
                    notes="same order and block rows; free run, x0 estimated, per output"))

    def route():
        return identify_ss(est, input=list(rec["inputs"]), output=list(rec["outputs"]), order=n,
                           validate=val)
    t_route = measure(_quiet(route), budget_s=30.0)
    m, extras = _quiet(route)()
    fits = _fits_text(extras["validation_fit_percent"]) + f" ({m.structure})"
    rows.append(row("measured", f"identify ss (subspace + PEM, focus simulation), order {n}, "
                    f"{data}", t_route, "", None, gripkit_accuracy=fits,
                    notes="the user's route (`gripkit identify ss --order N --validate`): the "
                          "better of the subspace and PEM models by the free-run fit"))

    if u0.shape[1] == 1 and y0.shape[1] == 1:
        ours_arx = lambda: arx(u0[:, 0], y0[:, 0], LAGS, LAGS, 1, dt=dt)  # noqa: E731
        fit_arx = _mimo_fit(*_abcd(from_polynomial(ours_arx())), dt, uv, yv, ue, ye)
        linear = _sysidentpy(1, LAGS, False, ue[:, 0], ye[:, 0])
        mp = linear()
        rows.append(row("measured", f"linear ARX, lags {LAGS}, {data}", measure(ours_arx),
                        "sysidentpy FROLS degree 1", measure(linear),
                        gripkit_accuracy=_fits_text(fit_arx),
                        peer_accuracy=_fits_text([_fit(yv[:, 0], mp.predict(X=uv, y=yv))]),
                        notes="same model class; gripkit: x0 estimated, sysidentpy: its predict "
                              "from the first measured lags"))
    return rows


#: IDIM-LS of the EMPS description (Janot, Gautier, Brunot; tests/fixtures/emps/README.md), full
#: 1 kHz record: value and σ of M, Fv, Fc, offset.
EMPS_PUBLISHED = dict(inertia=(95.1089, 0.1085), viscous=(203.5034, 1.1460),
                      coulomb=(20.3935, 0.1012), offset=(-3.1648, 0.0444))


def _emps_idim_row() -> dict:
    """gripkit's IDIM-LS (``gripkit identify friction``) on the decimated EMPS record beside the
    description's published estimates (no peer library fits an inverse dynamic model)."""
    from gripkit.io import load
    from gripkit.sysid.rigid_body.friction import idim_ls

    tr = load(FIXTURES / "emps" / "emps_est.csv")
    q, f = np.asarray(tr["position"]), np.asarray(tr["force"])
    ours = lambda: idim_ls(q, f, dt=float(tr.dt))  # noqa: E731
    r = ours()
    text = ", ".join(f"{k} {r.params[k]:.4g} ± {r.std[k]:.2g}" for k in EMPS_PUBLISHED)
    ref = ", ".join(f"{k} {v:.4g} ± {s:.2g}" for k, (v, s) in EMPS_PUBLISHED.items())
    gap = max(abs(r.params[k] - v) / np.hypot(r.std[k], s) for k, (v, s) in EMPS_PUBLISHED.items())
    return row("measured", f"IDIM-LS friction (M, Fv, Fc, offset), EMPS identification record, "
               f"{len(q)} samples at 250 Hz", measure(ours),
               "published IDIM-LS (EMPS description, 1 kHz, MATLAB)", None,
               gripkit_accuracy=text + f"; relative force error {r.relative_error_percent:.2f} %",
               peer_accuracy=ref + "; relative force error 4.08 %",
               notes=f"largest gap {gap:.2f} σ (σ of both estimates combined)")


if __name__ == "__main__":
    import json

    for r in run(quick=True):
        print(json.dumps(r, default=str))
