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
  (least squares);
* the same with θ weighted to the recent rows (:func:`_narx_forgetting_rows`): gripkit
  ``narx(forgetting=0.98)`` (exponentially weighted least squares) beside sysidentpy ``FROLS``
  with ``RecursiveLeastSquares()`` (its default forgetting factor 0.98), degree 3 lags 2 and its
  own example's degree 2 lags 5, BIC on both sides; alone:
  ``python benchmarks/bench_measured.py dc_narx OUT_DIR``.

NARX rows (:func:`narx_rows`; alone: ``python benchmarks/bench_measured.py narx OUT_DIR``):

* speed: the same 20-term cubic NARX (lags 2, FROLS, least squares) on 41 000 synthetic samples
  (Billings' example ``y(t) = −0.605 y(t−1) − 0.163 y(t−2)² + 0.588 u(t−1) − 0.240 u(t−2)
  + e``, σ_e = 0.05), validated on 5000 more: gripkit ``narx(terms=20, prune=False)`` beside
  sysidentpy
  ``FROLS(n_terms=20, order_selection=False)``;
* the nonlinear benchmarks Silverbox and cascaded tanks (tests/fixtures, their READMEs): gripkit's
  cubic NARX (lags 2, BIC, θ refined on the simulation error) beside sysidentpy's FROLS on the
  same structure (BIC, least squares); both scored the same way: free run from the first 2
  measured outputs of the test record, fit and e_RMS over the samples after them.
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
                    gripkit_accuracy=_fit_text(fit_ours),
                    peer_accuracy=_fit_text(_ss_fit(*sippy_call(), uv, yv)),
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
                    gripkit_accuracy=_fit_text(fit_ours),
                    peer_accuracy=_fit_text(_ss_fit(*nfoursid_call(), uv, yv)),
                    notes="same order and block rows; free run, x0 estimated"))

    refined = lambda: pem(ours(), u=u0, y=y0, form="oe")  # noqa: E731
    t_refined = measure(refined)
    s = refined().system
    fit_refined = _ss_fit(s.A, s.B, s.C, s.D, uv, yv)
    rows.append(row("measured", "n4sid + PEM (output error), order "
                                f"{ORDER}, {DATA}", t_refined, "", None,
                    gripkit_accuracy=_fit_text(fit_refined), notes="the subspace model refined; "
                                                                   "free run, x0 estimated"))

    ours_arx = lambda: arx(u0, y0, LAGS, LAGS, 1, dt=1.0)  # noqa: E731
    fit_arx = _ss_fit(*_abcd(ours_arx()), uv, yv)
    linear = _sysidentpy(1, LAGS, False, ue, ye)
    m = linear()
    rows.append(row("measured", f"linear ARX, lags {LAGS}, {DATA}", measure(ours_arx),
                    "sysidentpy FROLS degree 1",
                    measure(linear), gripkit_accuracy=_fit_text(fit_arx),
                    peer_accuracy=_fit_text(_fit(yv, m.predict(X=uv[:, None], y=yv[:, None]))),
                    notes=f"same model class; sysidentpy keeps {m.final_model.shape[0]} of its "
                          f"{2 * LAGS} terms (BIC); "
                          "gripkit: x0 estimated, sysidentpy: its predict from the "
                          "first measured lags"))

    narx = _sysidentpy(2, 5, True, ue, ye)
    m = narx()
    rows.append(row("measured", f"best model of each tool, {DATA}", t_refined,
                    "sysidentpy FROLS degree-2 NARX (its own example)", measure(narx),
                    gripkit_accuracy=_fit_text(fit_refined) + " (linear, n4sid + PEM)",
                    peer_accuracy=_fit_text(_fit(yv,
                                                 m.predict(X=uv[:, None],
                                                               y=yv[:, None]))) + " (nonlinear)",
                    notes="different model classes: the motor speeds up and coasts down with "
                          "different time "
                          "constants, which a polynomial NARX captures and a linear model cannot"))
    rows.append(_narx_row(ue, ye, uv, yv))
    rows.extend(_narx_forgetting_rows(ue, ye, uv, yv))
    rows.extend(narx_rows())
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
               gripkit_accuracy=(_fit_text(g.compare(uv, yv).fit_percent[0])
                                 + f" ({len(g.terms)} terms)"),
               peer_accuracy=_fit_text(_fit(yv, m.predict(X=uv[:, None], y=yv[:, None])))
               + f" ({m.final_model.shape[0]} terms)",
               notes="same model class; gripkit: FROLS + BIC + pruning of |θ|/σ < 2, fit over the "
                     "samples after the first max_lag; sysidentpy: its predict, fit "
                     "over every sample")


def _narx_forgetting_rows(ue, ye, uv, yv) -> list[dict]:
    """Polynomial NARX with θ weighted to the recent rows, BIC on both sides: gripkit's
    exponentially weighted least squares (λ = 0.98) beside sysidentpy's recursive least squares
    (its default λ = 0.98), degree 3 lags 2 and sysidentpy's example (degree 2, lags 5)."""
    from gripkit.sysid import narx as gripkit_narx

    rows = []
    for degree, lags in ((3, 2), (2, 5)):
        ours = lambda: gripkit_narx(ue, ye, degree=degree, lags=lags, forgetting=0.98)  # noqa: E731
        g = ours()
        peer = _sysidentpy(degree, lags, True, ue, ye)
        m = peer()
        rows.append(row(
            "measured", f"polynomial NARX, degree {degree}, lags {lags}, BIC, θ weighted to the "
                        f"recent rows (forgetting 0.98), {DATA}", measure(ours),
            f"sysidentpy FROLS degree {degree}, RecursiveLeastSquares (λ = 0.98)", measure(peer),
            gripkit_accuracy=(_fit_text(g.compare(uv, yv).fit_percent[0])
                              + f" ({len(g.terms)} terms; estimation record "
                                f"{g.fit_percent:.1f} %)"),
            peer_accuracy=_fit_text(_fit(yv, m.predict(X=uv[:, None], y=yv[:, None])))
            + f" ({m.final_model.shape[0]} terms)",
            notes="same structure search (FROLS, BIC, unweighted) and the same forgetting "
                  "factor; gripkit: batch weighted least squares with the sandwich σ, pruning "
                  "of |θ|/σ < 2, fit over the samples after the first max_lag; sysidentpy: "
                  "its predict, fit over every sample"))
    return rows


# ------------------------------------------------------------------------------ NARX rows
def _billings(n: int, seed: int):
    rng = np.random.default_rng(seed)
    u = rng.uniform(-1.0, 1.0, n)
    e = rng.normal(0.0, 0.05, n)
    y = np.zeros(n)
    for t in range(2, n):
        y[t] = (-0.605 * y[t - 1] - 0.163 * y[t - 2] ** 2 + 0.588 * u[t - 1] - 0.240 * u[t - 2]
                + e[t])
    return u, y


def _free_run_scores(y, ys, k=2):
    """Fit (%) and e_RMS over the samples after the first ``k`` (None for a diverged run)."""
    if not np.all(np.isfinite(ys[k:])):
        return None, None
    return _fit(y[k:], ys[k:]), float(np.sqrt(np.mean((y[k:] - ys[k:]) ** 2)))


def _sysidentpy_narx(ue, ye, n_terms=None):
    """sysidentpy FROLS, cubic polynomial basis, lags 2, least squares; BIC over its candidates
    (35) or ``n_terms`` fixed."""
    from sysidentpy.basis_function import Polynomial
    from sysidentpy.model_structure_selection import FROLS
    from sysidentpy.parameter_estimation import LeastSquares

    def call():
        if n_terms is None:
            model = FROLS(order_selection=True, n_info_values=35, ylag=2, xlag=2,
                          info_criteria="bic", estimator=LeastSquares(),
                          basis_function=Polynomial(degree=3), err_tol=None)
        else:
            model = FROLS(order_selection=False, n_terms=n_terms, ylag=2, xlag=2,
                          estimator=LeastSquares(), basis_function=Polynomial(degree=3),
                          err_tol=None)
        model.fit(X=ue[:, None], y=ye[:, None])
        return model
    return _quiet(call)


def _narx_speed_row() -> dict:
    from gripkit.sysid import narx

    ue, ye = _billings(41_000, 0)
    uv, yv = _billings(5_000, 1)
    ours = lambda: narx(ue, ye, degree=3, lags=2, terms=20, prune=False)  # noqa: E731
    peer = _sysidentpy_narx(ue, ye, n_terms=20)
    g, m = ours(), peer()
    fg = _free_run_scores(yv, g.simulate(uv, yv[:2]))[0]
    fp = _free_run_scores(yv, _quiet(lambda: m.predict(X=uv[:, None], y=yv[:, None]))()[:, 0])[0]
    common = len(set(g.terms) & set(_sysidentpy_terms(m)))
    return row("measured", "polynomial NARX, degree 3, lags 2, 20 FROLS terms, least squares, "
               "41 000 synthetic samples (Billings' example, σ_e = 0.05)", measure(ours),
               "sysidentpy FROLS degree 3 (20 terms)", measure(peer), target="≥ 10× (issue 26)",
               gripkit_accuracy=f"validation fit {fg:.2f} %", peer_accuracy=f"{fp:.2f} %",
               notes=f"{common} of the 20 terms the same on both sides (the four true ones "
                     "among them; the rest explain noise); validation: 5000 new samples, free "
                     "run from the first 2 measured outputs")


def _sysidentpy_terms(m) -> list[str]:
    """sysidentpy's final_model codes as gripkit term names (1001+ = y lags, 2001+ = u lags)."""
    names = []
    for codes in m.final_model:
        parts = sorted(f"{'y' if c < 2000 else 'u'}(t-{c % 1000})" for c in codes if c)
        order = {"y": 0, "u": 1}
        parts.sort(key=lambda s: (order[s[0]], int(s.split("-")[1][:-1])))
        names.append("*".join(parts) if parts else "1")
    return names


#: the two nonlinear benchmarks: (name, fixture stem, input column, output column, unit, scale)
NONLINEAR = (("Silverbox", "silverbox/silverbox", 0, 1, "mV", 1e3),
             ("cascaded tanks", "cascaded_tanks/cascaded_tanks", 1, 2, "V", 1.0))


def _nonlinear_rows(name, stem, ci, co, unit, scale) -> list[dict]:
    from gripkit.sysid import hammerstein_wiener, narx

    de = np.loadtxt(FIXTURES / f"{stem}_est.csv", delimiter=",", skiprows=1)
    dv = np.loadtxt(FIXTURES / f"{stem}_val.csv", delimiter=",", skiprows=1)
    ue, ye, uv, yv = de[:, ci], de[:, co], dv[:, ci], dv[:, co]
    data = f"{name}, {len(ue)} + {len(uv)} samples"

    def text(fit, rms, terms):
        if fit is None:
            return "free run diverges"
        return f"validation fit {fit:.1f} %, e_RMS {rms * scale:.3g} {unit} ({terms} terms)"

    ours = _quiet(lambda: narx(ue, ye, degree=3, lags=2, refine="simulation"))
    g = ours()
    one = _quiet(lambda: narx(ue, ye, degree=3, lags=2))()
    peer = _sysidentpy_narx(ue, ye)
    m = peer()
    fg, rg = _free_run_scores(yv, _quiet(lambda: g.simulate(uv, yv[:2]))())
    f1, r1 = _free_run_scores(yv, _quiet(lambda: one.simulate(uv, yv[:2]))())
    fp, rp = _free_run_scores(yv, _quiet(lambda: m.predict(X=uv[:, None], y=yv[:, None]))()[:, 0])
    rows = [row("measured", f"polynomial NARX, degree 3, lags 2, BIC, {data}", measure(ours),
                "sysidentpy FROLS degree 3 (BIC, least squares)", measure(peer),
                gripkit_accuracy=text(fg, rg, len(g.terms))
                + ", θ refined on the simulation error",
                peer_accuracy=text(fp, rp, m.final_model.shape[0]),
                notes=f"gripkit without the refinement (one-step least squares): "
                      f"{text(f1, r1, len(one.terms))}; both free runs from the first 2 measured "
                      "outputs of the test record",
                extra=dict(record=stem.split("/")[0], gripkit_fit=fg, gripkit_rms=rg,
                           one_step_fit=f1, sysidentpy_fit=fp, sysidentpy_rms=rp))]
    hw_call = _quiet(lambda: hammerstein_wiener(ue, ye, dt=1.0))
    h = hw_call()
    fh = _quiet(lambda: h.compare(uv, yv))().fit_percent[0]
    spread = float(np.linalg.norm(yv - yv.mean())) / np.sqrt(len(yv))
    rh = None if fh is None else (1 - fh / 100) * spread
    rows.append(row("measured", f"Hammerstein–Wiener, structure and orders by BIC, {data}",
                    measure(hw_call, budget_s=30.0), "", None,
                    gripkit_accuracy="free run diverges" if fh is None else
                    f"validation fit {fh:.1f} %, e_RMS {rh * scale:.3g} {unit}",
                    notes="gripkit.sysid.hammerstein_wiener with no options; its own fit "
                          "definition (HWModel.fit_definition)",
                    extra=dict(record=stem.split("/")[0], hw_fit=fh)))
    return rows


def narx_rows() -> list[dict]:
    """The NARX speed row and the nonlinear-benchmark rows."""
    rows = [_narx_speed_row()]
    for rec in NONLINEAR:
        rows.extend(_nonlinear_rows(*rec))
    return rows


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
        fit_arx = _mimo_fit(*_abcd(ours_arx().linear_record()), dt, uv, yv, ue, ye)
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
    import sys

    if sys.argv[1:2] in (["narx"], ["dc_narx"]):  # NARX rows alone, written as run.py does
        import os

        if os.environ.get("OPENBLAS_NUM_THREADS") != "1":
            raise SystemExit("set OPENBLAS_NUM_THREADS=1 (as run.py does) before running this")
        import run as runner

        out = Path(sys.argv[2])
        out.mkdir(parents=True, exist_ok=True)
        rows = (narx_rows() if sys.argv[1] == "narx" else
                [_narx_row(*_halves()[0], *_halves()[1]),
                 *_narx_forgetting_rows(*_halves()[0], *_halves()[1])])
        results = {"machine": runner.machine(), "quick": False, "rows": rows, "errors": {}}
        (out / "results.json").write_text(json.dumps(results, indent=2, default=str))
        (out / "results.md").write_text(runner.to_markdown(results))
    else:
        for r in run(quick=True):
            print(json.dumps(r, default=str))
