"""Polynomial NARX models (issue 26, family 1): structure by forward regression with the error
reduction ratio, parameters by least squares with σ, free-run simulation.

The model is ``y(t) = Σ_k θ_k m_k(t) + e(t)`` where every term ``m_k`` is a constant or a product
of at most ``degree`` lagged signals from ``y(t−1) … y(t−ly)`` and ``u(t−1) … u(t−lu)`` (from
``u(t)`` with ``direct=True``).

Structure selection is the forward regression orthogonal least squares of Billings (FROLS;
S. A. Billings, *Nonlinear System Identification: NARMAX Methods*, Wiley 2013, §3.2): at each
step the candidate whose part orthogonal to the terms already chosen explains most of the output
energy (the largest error reduction ratio ``ERR = (wᵀy)² / (wᵀw · yᵀy)``) is taken, and the
remaining candidates are orthogonalised against it (modified Gram-Schmidt, one rank-one update
of the candidate block per step, so ``k`` steps cost ``O(k N M)`` for ``M`` candidates). The
number of terms is where the Bayesian information criterion ``BIC = N ln(SSE/N) + k ln N``
is lowest, or ``terms=N``, or, with ``validate=``, the number whose pruned model has the best
free-run fit on the validation record.

After selection the parameters are the least-squares solution on the chosen terms, with
``cov θ = σ² (ΦᵀΦ)⁻¹`` and ``σ² = SSE/(N − k)``; terms with ``|θ|/σ_θ < 2`` are removed one at a
time (the weakest first) and the model is refitted.

The free run feeds the simulated output back into the lagged terms (numba kernel
:func:`_simulate_kernel`). The fit is ``100 (1 − ‖y − ŷ‖/‖y − ȳ‖)`` over the samples after the
``max_lag`` initial ones, which are taken from the measured output. A free run that grows beyond
any sensible range or becomes non-finite is reported with a :class:`StabilityWarning` and a fit
of None.
"""

from __future__ import annotations

import itertools
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numba import njit

from ...atomic import write_text
from ...errors import (ArgumentError, DataError, IdentificationError, ModelError, PathError,
                       StabilityWarning, emit_warning)
from ...params import Parameter, ParameterSet
from ...signals.trajectory import Trajectory
from ..model_protocol import ModelFit

__all__ = ["SCHEMA", "NARX_FIT", "NARXModel", "narx", "load_narx", "file_schema", "candidate_terms",
           "frols"]

SCHEMA = "gripkit.narx-model"
VERSION = 1
#: a free run beyond this many times the data's range (about its mean) counts as diverged
DIVERGENCE_FACTOR = 1e3
#: how a NARX model's free-run fit is taken (``gripkit compare`` prints it)
NARX_FIT = ("free run started from the first max_lag measured outputs, "
            "fit = 100 (1 − ‖y − ŷ‖/‖y − ȳ‖) over the samples after them")
#: most terms FROLS selects when ``terms='auto'``
MAX_AUTO_TERMS = 40


def candidate_terms(ylags: int, ulags: int, degree: int, direct: bool = False):
    """The bases ``(kind, lag)`` (kind 0 = y, 1 = u) and the candidate monomials: an int array
    (M, degree) of base indices, −1 where unused (row 0 is the constant)."""
    bases = [(0, k) for k in range(1, ylags + 1)]
    bases += [(1, k) for k in range(0 if direct else 1, ulags + 1)]
    rows = [[-1] * degree]
    for d in range(1, degree + 1):
        for combo in itertools.combinations_with_replacement(range(len(bases)), d):
            rows.append(list(combo) + [-1] * (degree - d))
    return np.array(bases, dtype=np.int64).reshape(-1, 2), np.array(rows, dtype=np.int64)


def _term_name(row, bases) -> str:
    parts = [f"{'yu'[bases[b, 0]]}(t-{bases[b, 1]})" if bases[b, 1] else f"{'yu'[bases[b, 0]]}(t)"
             for b in row if b >= 0]
    return "*".join(parts) if parts else "1"


def _regressors(bases, rows, u, y, start: int) -> np.ndarray:
    """The candidate matrix (N − start, M): every monomial evaluated on the measured data."""
    n = len(y) - start
    cols = np.empty((len(bases), n))
    for i, (kind, lag) in enumerate(bases):
        s = y if kind == 0 else u
        cols[i] = s[start - lag:len(s) - lag]
    P = np.ones((n, len(rows)), order="F")  # column by column
    for j, row in enumerate(rows):
        for b in row:
            if b >= 0:
                P[:, j] *= cols[b]
    return P


def frols(P: np.ndarray, y: np.ndarray, max_terms: int):
    """Forward regression orthogonal least squares: the order in which columns of ``P`` are
    chosen, their error reduction ratios, and the residual sum of squares after each step.

    Modified Gram-Schmidt on the candidate block ``W`` (Fortran order): after a column is chosen
    (unit vector ``q``), ``c = qᵀW`` and the rank-one update ``W ← W − q cᵀ`` runs in place
    (BLAS ``dger``); the squared norms and ``Wᵀy`` are downdated (``‖w‖² − c²``, ``Wᵀy − c qᵀy``)
    rather than recomputed, so each step is two passes over ``W``."""
    from scipy.linalg.blas import dger

    W = np.array(P, dtype=np.float64, order="F")
    y = np.ascontiguousarray(y, dtype=np.float64)
    yy = float(y @ y)
    active = np.ones(W.shape[1], dtype=bool)
    norms = np.einsum("ij,ij->j", W, W)
    floor = 1e-10 * np.maximum(norms, 1e-300)
    g = W.T @ y
    sse_now = yy
    chosen, errs, sse = [], [], []
    for _ in range(min(max_terms, W.shape[1])):
        ok = active & (norms > floor)
        if not ok.any():
            break
        err = np.where(ok, g * g / np.where(ok, norms, 1.0), -1.0) / yy
        j = int(np.argmax(err))
        q = W[:, j] / np.sqrt(norms[j])
        qy = float(q @ y)
        chosen.append(j)
        errs.append(float(err[j]))
        active[j] = False
        sse_now -= qy * qy
        sse.append(max(sse_now, 0.0))
        c = q @ W
        W = dger(-1.0, q, c, a=W, overwrite_a=True)
        norms = np.maximum(norms - c * c, 0.0)  # ‖w − q qᵀw‖² = ‖w‖² − (qᵀw)²
        g = g - c * qy
    return chosen, errs, sse


def _lstsq_cov(Phi: np.ndarray, y: np.ndarray):
    """θ, cov θ = σ² (ΦᵀΦ)⁻¹ (from the QR of the column-scaled Φ), SSE."""
    n, k = Phi.shape
    s = np.linalg.norm(Phi, axis=0)
    s[s == 0] = 1.0
    Q, R = np.linalg.qr(Phi / s)
    z = np.linalg.solve(R, Q.T @ y)
    theta = z / s
    e = y - Phi @ theta
    sse = float(e @ e)
    sigma2 = sse / max(n - k, 1)
    Rinv = np.linalg.solve(R, np.eye(k))
    cov = sigma2 * (Rinv @ Rinv.T) / np.outer(s, s)
    return theta, cov, sse


def _fit_pruned(P, y, cols: list[int], threshold: float = 2.0):
    """Least squares on ``cols``, removing the weakest term while ``|θ|/σ < threshold``."""
    cols = list(cols)
    while True:
        theta, cov, sse = _lstsq_cov(P[:, cols], y)
        std = np.sqrt(np.maximum(np.diag(cov), 0.0))
        t = np.abs(theta) / np.where(std > 0, std, np.inf)
        weakest = int(np.argmin(np.where(std > 0, t, np.inf)))
        if len(cols) == 1 or not (t[weakest] < threshold):
            return cols, theta, std, cov, sse
        del cols[weakest]


@njit(cache=True)
def _simulate_kernel(kinds, lags, rows, theta, u, y, start, limit_lo, limit_hi):
    """Free run in place: ``y[start:]`` from ``y[:start]`` and ``u``. Returns the first sample
    where the run left [limit_lo, limit_hi] or became non-finite, −1 if none."""
    n = y.shape[0]
    nt = rows.shape[0]
    deg = rows.shape[1]
    for t in range(start, n):
        acc = 0.0
        for k in range(nt):
            v = theta[k]
            for d in range(deg):
                b = rows[k, d]
                if b < 0:
                    break
                if kinds[b] == 0:
                    v *= y[t - lags[b]]
                else:
                    v *= u[t - lags[b]]
            acc += v
        y[t] = acc
        if not (acc >= limit_lo and acc <= limit_hi):
            for s in range(t + 1, n):
                y[s] = np.nan
            return t
    return -1


def _as_signal(x, name: str) -> np.ndarray:
    a = np.asarray(x, dtype=np.float64)
    if a.ndim == 2 and 1 in a.shape:
        a = a.ravel()
    if a.ndim != 1:
        raise DataError(f"narx: {name} must be one signal (shape (N,)), found shape {a.shape}; "
                        "pass one column")
    if not np.all(np.isfinite(a)):
        raise DataError(f"narx: {name} has {int(np.sum(~np.isfinite(a)))} non-finite samples; "
                        "remove or interpolate them first")
    return a


def _fit(y, yhat) -> float:
    den = float(np.linalg.norm(y - y.mean()))
    if den == 0.0:
        raise DataError("narx: the fit is undefined for a constant output (‖y − ȳ‖ = 0)")
    return 100.0 * (1.0 - float(np.linalg.norm(y - yhat)) / den)


@dataclass
class NARXModel:
    """A polynomial NARX model: ``y(t) = Σ θ_k · terms[k](t)``.

    ``terms`` (readable names such as ``"y(t-1)*u(t-2)"``), ``theta``, ``theta_std`` (1σ from
    ``σ² (ΦᵀΦ)⁻¹``), ``fit_percent`` (free-run fit on the estimation record),
    ``prediction_fit_percent`` (one step ahead), ``validation_fit_percent`` (free run on the
    ``validate=`` record; None when the run diverged or no record was given), ``criterion``
    (how the number of terms was chosen), ``err`` (error reduction ratio of each selected term,
    in FROLS order, before pruning).

    The protocol of :mod:`gripkit.sysid.model_protocol`: ``structure`` ('narx'),
    ``fit_definition`` (:data:`NARX_FIT`: the free run starts from the measured past outputs,
    ``initial_state = 'measured'``), ``inputs``, ``outputs``, ``parameters``, ``simulate``,
    ``predict``, ``compare`` → :class:`~gripkit.sysid.ModelFit`, ``residuals``, ``save``. Data
    are a :class:`~gripkit.signals.Trajectory` (the columns ``input_name``, ``output_name``;
    results (N, 1)) or the signals ``u``, ``y`` (N,)."""

    structure = "narx"
    fit_definition = NARX_FIT
    #: how :meth:`compare` starts the free run: from the first ``max_lag`` measured outputs
    initial_state = "measured"

    ylags: int
    ulags: int
    degree: int
    direct: bool
    bases: np.ndarray
    rows: np.ndarray
    theta: np.ndarray
    theta_std: np.ndarray
    covariance: np.ndarray
    dt: float = 1.0
    y_range: tuple = (-np.inf, np.inf)
    fit_percent: float | None = None
    prediction_fit_percent: float | None = None
    validation_fit_percent: float | None = None
    criterion: str = ""
    err: list = field(default_factory=list)
    frols_terms: list = field(default_factory=list)
    input_name: str = "u"
    output_name: str = "y"

    @property
    def inputs(self) -> tuple[str, ...]:
        return (self.input_name,)

    @property
    def outputs(self) -> tuple[str, ...]:
        return (self.output_name,)

    @property
    def parameters(self) -> ParameterSet:
        """θ as a :class:`~gripkit.params.ParameterSet` (``theta_0`` … in term order, each
        documented by its term, with its 1σ); in the units of the record the model was fitted
        on ('1': a NARX model keeps no units)."""
        return ParameterSet([Parameter(f"theta_{k}", float(v), "1", f"coefficient of {t}",
                                       source=f"identified (narx, {self.criterion or 'FROLS'})",
                                       std=float(s))
                             for k, (v, s, t) in enumerate(zip(self.theta, self.theta_std,
                                                               self.terms))], name="narx")

    def _signals(self, data, y, why: str, outputs: bool = True):
        """``(u, y)`` of a trajectory's columns by name, or of the signals given."""
        if isinstance(data, Trajectory):
            cols = [self.input_name] + ([self.output_name] if outputs else [])
            missing = [c for c in cols if c not in data.names]
            if missing:
                raise DataError(f"data: the model's column(s) {', '.join(map(repr, missing))} "
                                f"are missing; the data have {', '.join(map(repr, data.names))}",
                                hint="rename the columns or identify the model from matching "
                                     "data")
            return (np.asarray(data[self.input_name], dtype=np.float64),
                    np.asarray(data[self.output_name], dtype=np.float64) if outputs else None)
        if outputs and y is None:
            raise ArgumentError(f"narx.{why}: give a trajectory, or the signals u and y",
                                hint=f"model.{why}(data) or model.{why}(u, y)")
        return data, y

    @property
    def terms(self) -> list[str]:
        return [_term_name(r, self.bases) for r in self.rows]

    @property
    def max_lag(self) -> int:
        return int(max(self.ylags, self.ulags, 1))

    def _limits(self):
        lo, hi = self.y_range
        span = max(hi - lo, 1e-12)
        mid = 0.5 * (hi + lo)
        return mid - DIVERGENCE_FACTOR * span, mid + DIVERGENCE_FACTOR * span

    def simulate(self, data, y0=None, *, warn: bool = True) -> np.ndarray:
        """Free run on the input of ``data`` (a trajectory: (N, 1)) or on the input ``u`` (N,):
        the first ``max_lag`` outputs are ``y0`` (zeros by default), the rest simulated. A
        diverging run ends in NaN after a StabilityWarning."""
        if isinstance(data, Trajectory):
            u, _ = self._signals(data, None, "simulate", outputs=False)
            return self.simulate(u, y0, warn=warn).reshape(-1, 1)
        u = _as_signal(data, "u")
        m = self.max_lag
        if len(u) <= m:
            raise DataError(f"narx.simulate: u has {len(u)} samples, needs more than max_lag = {m}")
        y = np.zeros(len(u))
        if y0 is not None:
            y0 = np.atleast_1d(np.asarray(y0, dtype=np.float64))
            if y0.shape != (m,):
                raise ArgumentError(f"narx.simulate: y0 must hold the first max_lag = {m} outputs, "
                                    f"found shape {y0.shape}")
            y[:m] = y0
        lo, hi = self._limits()
        at = _simulate_kernel(self.bases[:, 0].copy(), self.bases[:, 1].copy(), self.rows,
                              self.theta, u, y, m, lo, hi)
        if at >= 0 and warn:
            emit_warning(f"narx: the free run diverges at sample {at} (beyond "
                         f"{DIVERGENCE_FACTOR:g}× the estimation output's range); the model is "
                         "unstable on this input",
                         StabilityWarning)
        return y

    def predict(self, data, y=None, horizon: int = 1) -> np.ndarray:
        """One-step-ahead prediction from measured ``u`` and ``y`` (or a trajectory: (N, 1));
        the first ``max_lag`` samples are the measured ones. ``horizon`` must be 1 (a NARX
        k-step predictor is a free run of k steps; use :meth:`simulate` with ``y0``)."""
        if horizon != 1:
            raise ArgumentError(f"narx.predict: horizon must be 1 for a NARX model, found "
                                f"{horizon!r}", hint="simulate(u, y0) runs the model freely")
        if isinstance(data, Trajectory):
            return self.predict(*self._signals(data, y, "predict")).reshape(-1, 1)
        u, y = _as_signal(data, "u"), _as_signal(y, "y")
        if len(u) != len(y):
            raise DataError(f"narx.predict: u has {len(u)} samples but y has {len(y)}; pass a pair "
                            "of equal length")
        m = self.max_lag
        P = _regressors(self.bases, self.rows, u, y, m)
        return np.concatenate([y[:m], P @ self.theta])

    def residuals(self, data, y=None) -> np.ndarray:
        """One-step prediction errors after the first ``max_lag`` samples: (N − max_lag,) for
        signals, (N − max_lag, 1) for a trajectory."""
        u, yy = self._signals(data, y, "residuals")
        yy = _as_signal(yy, "y")
        e = (yy - self.predict(u, yy))[self.max_lag:]
        return e.reshape(-1, 1) if isinstance(data, Trajectory) else e

    def compare(self, data, y=None, *, warn: bool = True) -> ModelFit:
        """The free-run fit (:data:`NARX_FIT`) on a trajectory or on ``(u, y)``: the run started
        from the first ``max_lag`` measured outputs and scored on the samples after them;
        ``fit_percent`` [None] (with a warning) if it diverges; ``simulated`` (N, 1)."""
        u, yy = self._signals(data, y, "compare")
        fit, ys = self._free_run_fit(u, yy, warn)
        return ModelFit(self.outputs, [fit], ys.reshape(-1, 1), self.fit_definition)

    def _free_run_fit(self, u, y, warn: bool = True) -> tuple[float | None, np.ndarray]:
        u, y = _as_signal(u, "u"), _as_signal(y, "y")
        m = self.max_lag
        ys = self.simulate(u, y[:m], warn=warn)
        if not np.all(np.isfinite(ys)):
            return None, ys
        return _fit(y[m:], ys[m:]), ys

    def to_dict(self) -> dict:
        return dict(schema=SCHEMA, version=VERSION, ylags=self.ylags, ulags=self.ulags,
                    degree=self.degree, direct=self.direct, dt=self.dt,
                    y_range=[float(v) for v in self.y_range],
                    bases=self.bases.tolist(), rows=self.rows.tolist(), terms=self.terms,
                    theta=self.theta.tolist(), theta_std=self.theta_std.tolist(),
                    covariance=self.covariance.tolist(), fit_percent=self.fit_percent,
                    prediction_fit_percent=self.prediction_fit_percent,
                    validation_fit_percent=self.validation_fit_percent, criterion=self.criterion,
                    err=[float(v) for v in self.err], frols_terms=list(self.frols_terms),
                    input_name=self.input_name, output_name=self.output_name)

    def save(self, path) -> Path:
        """Write the model as JSON (schema ``gripkit.narx-model``), atomically."""
        return write_text(path, json.dumps(self.to_dict(), indent=1) + "\n", what="NARX model")


def file_schema(path) -> str | None:
    """The ``schema`` field of a JSON model file, None when it has none or cannot be read."""
    try:
        doc = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):  # the model file readers name what is wrong
        return None
    return doc.get("schema") if isinstance(doc, dict) else None


def load_narx(path) -> NARXModel:
    """Read a model written by :meth:`NARXModel.save`; any other schema is refused."""
    p = Path(path)
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise PathError(f"narx model file {str(p)!r} does not exist; give the path of a file "
                        "written by NARXModel.save or `gripkit identify narx --out`") from None
    except OSError as exc:
        raise PathError(f"narx model file {str(p)!r} cannot be read ({exc.strerror or exc}); give "
                        "the path of a readable file") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise ModelError(f"narx model file {str(p)!r} is not JSON ({exc}); expected a file of "
                         f"schema {SCHEMA!r}") from None
    except RecursionError:
        raise ModelError(f"narx model file {str(p)!r} cannot be read: its JSON nests lists or "
                         f"objects deeper than Python's recursion limit; a model file nests a few "
                         f"levels") from None
    except ValueError as exc:  # an integer beyond Python's limit on digits read from text
        raise ModelError(f"narx model file {str(p)!r} cannot be read: {str(exc).split(';')[0]}") from None
    schema = doc.get("schema") if isinstance(doc, dict) else None
    if schema != SCHEMA:
        raise ModelError(f"{str(p)!r} has schema {schema!r}, expected {SCHEMA!r}; load other model "
                         "files with gripkit.sysid.load_model")
    if doc.get("version") != VERSION:
        raise ModelError(f"{str(p)!r} is a {SCHEMA} of version {doc.get('version')!r}; this "
                         f"gripkit reads version {VERSION}")
    try:
        bases = np.array(doc["bases"], dtype=np.int64).reshape(-1, 2)
        rows = np.array(doc["rows"], dtype=np.int64).reshape(len(doc["rows"]), int(doc["degree"]))
        theta = np.array(doc["theta"], dtype=np.float64)
        m = NARXModel(ylags=int(doc["ylags"]), ulags=int(doc["ulags"]), degree=int(doc["degree"]),
                      direct=bool(doc["direct"]), bases=bases, rows=rows, theta=theta,
                      theta_std=np.array(doc["theta_std"], dtype=np.float64),
                      covariance=np.array(doc["covariance"], dtype=np.float64).reshape(
                          len(theta), len(theta)),
                      dt=float(doc["dt"]), y_range=tuple(doc["y_range"]),
                      fit_percent=doc.get("fit_percent"),
                      prediction_fit_percent=doc.get("prediction_fit_percent"),
                      validation_fit_percent=doc.get("validation_fit_percent"),
                      criterion=str(doc.get("criterion", "")),
                      err=[float(v) for v in doc.get("err", [])],
                      frols_terms=[str(t) for t in doc.get("frols_terms", [])],
                      input_name=str(doc.get("input_name", "u")),
                      output_name=str(doc.get("output_name", "y")))
    except (KeyError, TypeError, ValueError) as exc:
        raise ModelError(f"{str(p)!r}: a malformed {SCHEMA} ({type(exc).__name__}: {exc}); "
                         "write it again with NARXModel.save") from None
    if len(rows) != len(theta) or (rows >= len(bases)).any():
        raise ModelError(f"{str(p)!r}: {len(rows)} terms but {len(theta)} parameters, or a term "
                         "naming a missing lagged signal; write it again with NARXModel.save")
    return m


def _positive_int(v, name: str, lo: int = 1) -> int:
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < lo:
        raise ArgumentError(f"narx: {name} must be an integer ≥ {lo}, found {v!r}")
    return int(v)


def narx(u, y, *, degree: int = 2, lags: int | None = 2, ylags: int | None = None,
         ulags: int | None = None, terms="auto", dt: float | None = None, validate=None,
         direct: bool = False, prune: bool = True) -> NARXModel:
    """Polynomial NARX model of ``y`` driven by ``u`` (1-D arrays of equal length).

    ``degree``: highest total degree of a term. ``lags``: output and input lags (``ylags`` /
    ``ulags`` set them apart). ``terms``: ``"auto"`` (BIC, or the validation fit with
    ``validate=(u2, y2)``; at most 40 FROLS terms are tried) or a number of FROLS terms.
    ``direct``: include ``u(t)``. ``dt``: sample interval (s), default 1.
    ``prune``: remove terms with ``|θ|/σ < 2`` and refit.
    """
    u, y = _as_signal(u, "u"), _as_signal(y, "y")
    if len(u) != len(y):
        raise DataError(f"narx: u has {len(u)} samples but y has {len(y)}; pass a pair of equal "
                        "length")
    if np.ptp(y) == 0.0:
        raise DataError(f"narx: the output is constant ({y[0]:g} in all {len(y)} samples); there "
                        "is nothing to identify: check the output column")
    degree = _positive_int(degree, "degree")
    ly = _positive_int(ylags if ylags is not None else lags, "ylags", 0)
    lu = _positive_int(ulags if ulags is not None else lags, "ulags", 0)
    if dt is not None and not (isinstance(dt, (int, float, np.floating)) and np.isfinite(dt)
                               and dt > 0):
        raise ArgumentError(f"narx: dt must be a positive sample interval in s, found {dt!r}")
    if ly + lu == 0 and not direct:
        raise ArgumentError("narx: no lagged signal (ylags = ulags = 0); give lags ≥ 1")
    bases, rows = candidate_terms(ly, lu, degree, direct)
    start = max(ly, lu, 1)
    if len(y) - start < 2 * len(rows):
        raise DataError(f"narx: {len(y)} samples for {len(rows)} candidate terms; need at least "
                        f"{2 * len(rows) + start}: lower degree or lags, or give more data")
    P = _regressors(bases, rows, u, y, start)
    target = y[start:]
    if validate is not None:
        try:
            uv, yv = validate
        except (TypeError, ValueError):
            raise ArgumentError("narx: validate must be a pair (u, y) of validation data") from None
        uv, yv = _as_signal(uv, "validate u"), _as_signal(yv, "validate y")
        if len(uv) != len(yv) or len(uv) <= start + 2:
            raise DataError(f"narx: validation u has {len(uv)} and y {len(yv)} samples; need equal "
                            f"lengths beyond max_lag = {start}")
    if terms == "auto":
        kmax = min(len(rows), MAX_AUTO_TERMS)
    else:
        if isinstance(terms, str):
            raise ArgumentError(f"narx: terms must be 'auto' or an integer ≥ 1, found {terms!r}")
        kmax = _positive_int(terms, "terms")
        if kmax > len(rows):
            raise ArgumentError(f"narx: terms = {kmax} but only {len(rows)} candidates; give at "
                                f"most {len(rows)} or raise degree/lags")
    order, errs, sse = frols(P, target, kmax)
    if not order:
        raise IdentificationError("narx: no candidate term explains the output (all columns zero)")
    n = len(target)
    y_range = (float(y.min()), float(y.max()))

    def build(k):
        cols = order[:k]
        if prune:
            cols, theta, std, cov, _ = _fit_pruned(P, target, cols)
        else:
            theta, cov, _ = _lstsq_cov(P[:, cols], target)
            std = np.sqrt(np.maximum(np.diag(cov), 0.0))
        return NARXModel(ylags=ly, ulags=lu, degree=degree, direct=direct, bases=bases,
                         rows=rows[cols], theta=theta, theta_std=std, covariance=cov,
                         dt=1.0 if dt is None else float(dt), y_range=y_range,
                         err=list(errs[:k]),
                         frols_terms=[_term_name(rows[c], bases) for c in order[:k]])

    if terms != "auto":
        model, how = build(len(order)), f"terms={len(order)}"
    elif validate is None:
        bic = [n * np.log(max(s, 1e-300) / n) + (k + 1) * np.log(n) for k, s in enumerate(sse)]
        k = int(np.argmin(bic)) + 1
        model, how = build(k), f"BIC minimum at {k} FROLS terms"
    else:
        best = None
        for k in range(1, len(order) + 1):
            cand = build(k)
            f = cand._free_run_fit(uv, yv, warn=False)[0]
            if f is not None and (best is None or f > best[0] + 1e-9):
                best = (f, k, cand)
        if best is None:
            model = build(len(order))
            how = "validation fit (every candidate diverged)"
        else:
            model, how = best[2], f"validation free-run fit best at {best[1]} FROLS terms"
    model.criterion = how + (", terms with |θ|/σ < 2 pruned" if prune else "")
    model.prediction_fit_percent = _fit(target, P[:, [_row_index(rows, r) for r in model.rows]]
                                        @ model.theta)
    model.fit_percent = model._free_run_fit(u, y)[0]
    if validate is not None:
        model.validation_fit_percent = model._free_run_fit(uv, yv)[0]
    return model


def _row_index(rows, row) -> int:
    return int(np.flatnonzero((rows == row).all(axis=1))[0])
