"""Measured data: gripkit beside SIPPY (sippy_unipi), nfoursid and sysidentpy on the DC
motor/generator record published with SysIdentPy (tests/fixtures/dc_motor: source, commit,
BSD-3 licence), in the same run.

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
    return None if not m.stable else float(m.compare(uv - uv.mean(), yv - yv.mean()).fit_percent[0])


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
        model = FROLS(order_selection=True, n_info_values=100 if degree > 1 else 2 * lag + 1, ylag=lag, xlag=lag,
                      info_criteria="bic", estimator=RecursiveLeastSquares() if recursive else LeastSquares(),
                      basis_function=Polynomial(degree=degree), err_tol=None)
        model.fit(X=ue[:, None], y=ye[:, None])
        return model
    return _quiet(call)


def run(quick: bool) -> list[dict]:
    """All rows; ``quick`` changes nothing (the record is small)."""
    from gripkit.sysid import arx, n4sid, pem

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
    fit_arx = _ss_fit(*_abcd(ours_arx()), uv, yv)
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
               gripkit_accuracy=(_fit_text(g.compare(uv, yv).fit_percent[0])
                                 + f" ({len(g.terms)} terms)"),
               peer_accuracy=_fit_text(_fit(yv, m.predict(X=uv[:, None], y=yv[:, None])))
               + f" ({m.final_model.shape[0]} terms)",
               notes="same model class; gripkit: FROLS + BIC + pruning of |θ|/σ < 2, fit over the "
                     "samples after the first max_lag; sysidentpy: its predict, fit over every sample")


if __name__ == "__main__":
    import json

    for r in run(quick=True):
        print(json.dumps(r, default=str))
