"""Rational NARX models: ``y(t) = N(φ(t)) / D(φ(t)) + e(t)`` with ``N`` and ``D`` polynomials
in the lagged signals ``φ(t) = (y(t−1) … y(t−ly), u(t−1) … u(t−lu))`` and the constant of
``D`` fixed to 1 (``D = 1 + Σ_j d_j q_j(φ)``) for identifiability.

Identification (S. A. Billings and Q. M. Zhu, "Rational model identification using an extended
least-squares algorithm", *Int. J. Control* 54(3), 1991; S. A. Billings, *Nonlinear System
Identification: NARMAX Methods*, Wiley 2013, §3.7):

1. *Structure* by FROLS on the linear-in-parameters form ``y(t) D = N + D e``, i.e.
   ``y(t) = Σ n_k p_k(φ) − Σ d_j y(t) q_j(φ) + D e(t)``: the candidates are the numerator
   monomials ``p_k`` (degree ``degree``) and the products ``−y(t) q_j`` of the output with the
   denominator monomials (degree ``den_degree``, no constant). Those products hold
   ``−e(t) q_j``: their Gram block carries ``σ² QᵀQ`` and their product with ``y`` ``−σ² Qᵀ1``
   that noise-free columns would not; FROLS and the least-squares start are run on the Gram
   matrix with that share removed (the extended least squares of Billings & Zhu), σ² from the
   one-step error of the previous pass's model (the first pass uncorrected), until the chosen
   terms repeat (at most :data:`PASSES` passes). The number of terms is the BIC minimum of the
   one-step error ``y − N/D`` of the refined models (or ``terms=``, or the validation free-run
   fit).
2. The least-squares estimate of the linear form is biased even so (the noise ``D e`` is not
   white, and σ² is estimated), so θ = (n, d) is then refined by Levenberg–Marquardt on the
   one-step prediction error ``e(t) = y(t) − N(φ)/D(φ)`` on the measured φ (the nonlinear least
   squares, maximum likelihood for white Gaussian ``e``), Jacobian ``∂(N/D)/∂n_k = p_k/D``,
   ``∂(N/D)/∂d_j = −(N/D) q_j / D``; ``cov θ = σ² (JᵀJ)⁻¹``, ``σ² = SSE/(N − k)``. With
   ``prune`` the weakest term with ``|θ|/σ < 2`` on that σ is dropped and θ refined again, one
   at a time. These are the σ reported with ``refine=None``.
3. With ``refine="simulation"`` θ is refined instead on the free-run error (the noise on the
   measured output), the free run and its sensitivities ``∂ŷ/∂θ`` from one numba kernel
   (:func:`_sensitivity_kernel`), σ from that Gauss–Newton Hessian, pruning on that σ.

The free run (:func:`_simulate_kernel`) stops where ``D`` falls to :data:`DEN_FLOOR` or below
(``D`` is 1 at φ = 0, so it crossed zero on the way): a StabilityWarning naming the
denominator and the sample, NaN from there on, a fit of None. The one-step refinement refuses a
step whose ``D`` crosses zero on the estimation rows; a least-squares start whose ``D`` does is
an :class:`~gripkit.errors.IdentificationError` naming it.
"""

from __future__ import annotations

import dataclasses
from collections import namedtuple
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numba import njit

from ...errors import DataError, IdentificationError, ModelError, StabilityWarning, emit_warning
from ...params import Parameter, ParameterSet
from ...progress import status, track
from ..model_file import read_family_document
from .levenberg_marquardt import fit_residuals
from .narx import (_DAMPING, NARX_FIT, NARXModel, _better_on_validation, _fit, _fit_records,
                   _frols_gram, _max_terms, _model_fields, _positive_int, _Regression,
                   _refine_and_prune, _regression_matrix, _regressors, _row_index, _term_name,
                   _validation_records, candidate_terms, check_narx_fields, narx_output)
from .single_channel import DIVERGENCE_FACTOR

__all__ = ["RationalNARXModel", "rational_narx", "rational_output", "load_rational_narx",
           "DEN_FLOOR", "SCHEMA"]

#: a rational NARX model's file: a schema of its own, so that a reader of polynomial NARX files
#: refuses it instead of reading its numerator alone
SCHEMA = "gripkit.rational-narx-model"
VERSION = 1
#: what the rational kernels read of a model's structure: each base's kind (0 output, 1 input) and
#: lag, and the numerator's and denominator's terms (indices into the bases, −1 padded)
RationalTerms = namedtuple("RationalTerms", "kinds lags rows den_rows")
#: scratch of the sensitivity kernel: the bases' values ``z`` and ∂N/∂y, ∂D/∂y per base, and
#: ``why`` (one int: why a free run stopped)
RationalWork = namedtuple("RationalWork", "z dndy dddy why")

#: a denominator at or below this on the data is taken as crossing zero (D = 1 at φ = 0)
DEN_FLOOR = 1e-6


@njit(cache=True)
def rational_output(rows, den_rows, theta, z, u0):  # pragma: no cover - compiled
    """``(N, D)`` at time t: ``N = Σ_k θ_k p_k(z)`` over the ``rows`` (the first
    ``len(rows)`` entries of θ), ``D = 1 + Σ_j θ_{nN+j} q_j(z)`` over ``den_rows``; ``z`` and
    ``u0`` as in :func:`~gripkit.sysid.nonlinear.narx.narx_output`."""
    nn = rows.shape[0]
    return (narx_output(rows, theta[:nn], z, u0),
            1.0 + narx_output(den_rows, theta[nn:], z, u0))


@njit(cache=True)
def _fill(kinds, lags, u, y, t, z):  # pragma: no cover - compiled
    for b in range(kinds.shape[0]):
        z[b] = y[t - lags[b]] if kinds[b] == 0 else u[t - lags[b]]


@njit(cache=True)
def _stop(y, J, t):  # pragma: no cover - compiled
    for s in range(t, y.shape[0]):
        y[s] = np.nan
        for j in range(J.shape[1]):
            J[s, j] = 0.0


@njit(cache=True)
def _simulate_kernel(terms, theta, u, y, start, limits, z, why):  # pragma: no cover - compiled
    """Free run in place: ``y[start:]`` from ``y[:start]`` and ``u`` (``terms``:
    :data:`RationalTerms`; ``limits``: ``(limit_lo, limit_hi, floor)``); ``z`` scratch of one
    entry per base. Returns the first sample where ``D ≤ floor`` (``why[0] = 1``; that sample
    and the rest NaN) or the output left [limit_lo, limit_hi] or became non-finite
    (``why[0] = 2``; the rest NaN), −1 if none."""
    kinds, lags, rows, den_rows = terms
    limit_lo, limit_hi, floor = limits
    n = y.shape[0]
    why[0] = 0
    for t in range(start, n):
        _fill(kinds, lags, u, y, t, z)
        num, den = rational_output(rows, den_rows, theta, z, u[t])
        if not den > floor:
            why[0] = 1
            for s in range(t, n):
                y[s] = np.nan
            return t
        acc = num / den
        y[t] = acc
        if not (acc >= limit_lo and acc <= limit_hi):
            why[0] = 2
            for s in range(t + 1, n):
                y[s] = np.nan
            return t
    return -1


@njit(cache=True)
def _monomial(rows, k, z):  # pragma: no cover - compiled
    m = 1.0
    for d in range(rows.shape[1]):
        b = rows[k, d]
        if b < 0:
            break
        m *= z[b]
    return m


@njit(cache=True)
def _add_dy(rows, k, coef, kinds, z, out):  # pragma: no cover - compiled
    """``out[b] += ∂(coef · Π z[rows[k]])/∂z[b]`` for the output bases ``b`` of term k."""
    deg = rows.shape[1]
    for d in range(deg):
        b = rows[k, d]
        if b < 0:
            break
        if kinds[b] != 0:
            continue
        p = coef
        for e in range(deg):
            c = rows[k, e]
            if c < 0:
                break
            if e != d:
                p *= z[c]
        out[b] += p


@njit(cache=True)
def _sensitivity_kernel(terms, theta, u, y, start, limits, J,
                        work):  # pragma: no cover - compiled
    """Free run in place (as :func:`_simulate_kernel`) and in the same pass
    ``J[t, j] = ∂ŷ(t)/∂θ_j``: with ``ŷ = N/D``, ``J[t] = ∂ŷ/∂θ|_φ + Σ_b g_b J[t − lag_b]`` over
    the output bases ``b``, ``g_b = (∂N/∂y_b − ŷ ∂D/∂y_b)/D``, ``∂ŷ/∂n_k = p_k/D`` and
    ``∂ŷ/∂d_j = −ŷ q_j/D``; ``J[t] = 0`` for the given outputs. ``work``:
    :data:`RationalWork` (``z``, ``dndy``, ``dddy``: one entry per base). Returns as
    :func:`_simulate_kernel` (J zero from the stop)."""
    kinds, lags, rows, den_rows = terms
    limit_lo, limit_hi, floor = limits
    z, dndy, dddy, why = work
    n = y.shape[0]
    nn = rows.shape[0]
    nd = den_rows.shape[0]
    nb = kinds.shape[0]
    why[0] = 0
    for t in range(start):
        for j in range(nn + nd):
            J[t, j] = 0.0
    for t in range(start, n):
        _fill(kinds, lags, u, y, t, z)
        num, den = rational_output(rows, den_rows, theta, z, u[t])
        if not den > floor:
            why[0] = 1
            _stop(y, J, t)
            return t
        yt = num / den
        y[t] = yt
        for b in range(nb):
            dndy[b] = 0.0
            dddy[b] = 0.0
        for k in range(nn):
            J[t, k] = _monomial(rows, k, z) / den
            _add_dy(rows, k, theta[k], kinds, z, dndy)
        for j in range(nd):
            J[t, nn + j] = -yt * _monomial(den_rows, j, z) / den
            _add_dy(den_rows, j, theta[nn + j], kinds, z, dddy)
        for b in range(nb):
            if kinds[b] != 0:
                continue
            g = (dndy[b] - yt * dddy[b]) / den
            if g != 0.0:
                s = t - lags[b]
                for j in range(nn + nd):
                    J[t, j] += g * J[s, j]
        if not (yt >= limit_lo and yt <= limit_hi):
            why[0] = 2
            _stop(y, J, t + 1)
            return t
    return -1


RATIONAL_FIT = NARX_FIT + ("; the run stops (fit None) where the denominator D falls to "
                           f"{DEN_FLOOR:g} or below")


@dataclass
class RationalNARXModel(NARXModel):
    """A rational NARX model ``y(t) = N(φ)/D(φ)``, ``N = Σ n_k p_k(φ)`` (the terms ``rows``),
    ``D = 1 + Σ d_j q_j(φ)`` (the terms ``den_rows``, degree ``den_degree``).

    ``theta`` is ``(n_1 … n_K, d_1 … d_J)``, ``theta_std`` and ``covariance`` over all of them;
    ``numerator_terms`` and ``denominator_terms`` name them, ``terms`` is both with the prefix
    ``"num: "`` or ``"den: "``; ``parameters`` names them ``num_k`` and ``den_j``. Every other
    attribute and method as :class:`~gripkit.sysid.nonlinear.narx.NARXModel`; the free run stops
    with a StabilityWarning where D falls to :data:`DEN_FLOOR` or below."""

    structure = "rational-narx"
    basis = "rational"
    fit_definition = RATIONAL_FIT
    _file_what = "rational NARX model"
    _family = "a rational NARX model"

    den_degree: int = 1
    den_rows: np.ndarray = field(default_factory=lambda: np.zeros((0, 1), dtype=np.int64))

    @property
    def numerator_terms(self) -> list[str]:
        return [_term_name(r, self.bases) for r in self.rows]

    @property
    def denominator_terms(self) -> list[str]:
        return [_term_name(r, self.bases) for r in self.den_rows]

    @property
    def terms(self) -> list[str]:
        return ([f"num: {t}" for t in self.numerator_terms]
                + [f"den: {t}" for t in self.denominator_terms])

    @property
    def parameters(self) -> ParameterSet:
        """θ as a :class:`~gripkit.params.ParameterSet`: ``num_0`` … (the numerator's
        coefficients, in the output unit over their term's unit) then ``den_1`` … (the
        denominator's, D dimensionless: one over their term's unit; its constant is 1), each
        documented by its term, with its 1σ (units: :meth:`~.narx.NARXModel.term_unit`)."""
        nn = len(self.rows)
        names = [f"num_{k}" for k in range(nn)] + [f"den_{j + 1}"
                                                   for j in range(len(self.den_rows))]
        docs = ([f"coefficient of {t} in the numerator N" for t in self.numerator_terms]
                + [f"coefficient of {t} in the denominator D = 1 + …"
                   for t in self.denominator_terms])
        units = ([self.term_unit(r, 1) for r in self.rows]
                 + [self.term_unit(r, 0) for r in self.den_rows])
        src = f"identified (rational narx, {self.criterion or 'FROLS'})"
        return ParameterSet([Parameter(nm, float(v), unit, doc, source=src, std=float(s))
                             for nm, v, s, doc, unit in zip(names, self.theta, self.theta_std,
                                                            docs, units)],
                            name="rational-narx")

    def _terms(self) -> "RationalTerms":
        return RationalTerms(self.bases[:, 0].copy(), self.bases[:, 1].copy(),
                             np.ascontiguousarray(self.rows, dtype=np.int64),
                             np.ascontiguousarray(self.den_rows, dtype=np.int64))

    def _run(self, u, y, lo: float, hi: float) -> int:
        why = np.zeros(1, dtype=np.int64)
        at = _simulate_kernel(self._terms(), self.theta, u, y, self.max_lag,
                              (float(lo), float(hi), DEN_FLOOR), np.empty(len(self.bases)), why)
        self._why = int(why[0])
        return at

    def _sensitivities(self, u, y, theta):
        lo, hi = self._limits()
        J = np.empty((len(u), len(theta)))
        nb = len(self.bases)
        work = RationalWork(np.empty(nb), np.empty(nb), np.empty(nb), np.zeros(1, dtype=np.int64))
        at = _sensitivity_kernel(self._terms(), np.ascontiguousarray(theta, dtype=np.float64),
                                 u, y, self.max_lag, (float(lo), float(hi), DEN_FLOOR), J, work)
        self._why = int(work.why[0])
        return at, J

    def _stop_message(self, at: int) -> str:
        if getattr(self, "_why", 0) == 1:
            return (f"narx: the rational model's denominator D crosses zero at sample {at} of "
                    f"the free run (D ≤ {DEN_FLOOR:g}, D = 1 at rest); the output is undefined "
                    "from there: the model is not valid on this input's range")
        return (f"narx: the free run diverges at sample {at} (beyond {DIVERGENCE_FACTOR:g}× the "
                "estimation output's range); the model is unstable on this input")

    def _one_step(self, u: np.ndarray, y: np.ndarray) -> np.ndarray:
        """The one-step prediction ``N/D`` on checked measured signals (:meth:`NARXModel.predict`);
        NaN, with a StabilityWarning, where D ≤ :data:`DEN_FLOOR`."""
        m, nn = self.max_lag, len(self.rows)
        num = _regressors(self.bases, self.rows, u, y, m) @ self.theta[:nn]
        den = 1.0 + _regressors(self.bases, self.den_rows, u, y, m) @ self.theta[nn:]
        bad = ~(den > DEN_FLOOR)
        if bad.any():
            emit_warning(f"narx.predict: the rational model's denominator D crosses zero at "
                         f"{int(bad.sum())} of {len(den)} samples (first at sample "
                         f"{m + int(np.argmax(bad))}); the prediction there is NaN",
                         StabilityWarning)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.concatenate([y[:m], np.where(bad, np.nan, num / den)])

    def _structure_state(self) -> tuple:
        return self.rows, self.den_rows, self.theta, self.covariance, self.theta_std

    def _restore_structure(self, state: tuple) -> None:
        self.rows, self.den_rows, self.theta, self.covariance, self.theta_std = state

    def _drop_term(self, j: int) -> None:
        nn = len(self.rows)
        keep = np.arange(len(self.theta)) != j
        self.rows, self.den_rows = self.rows[keep[:nn]], self.den_rows[keep[nn:]]
        self.theta = self.theta[keep]

    def to_dict(self) -> dict:
        doc = super().to_dict()
        doc.update(schema=SCHEMA, version=VERSION, basis="rational", den_degree=self.den_degree,
                   den_rows=self.den_rows.tolist(), numerator_terms=self.numerator_terms,
                   denominator_terms=self.denominator_terms)
        return doc


def load_rational_narx(path) -> RationalNARXModel:
    """Read a model written by :meth:`RationalNARXModel.save`; any other schema is refused."""
    p = Path(path)
    writer = "RationalNARXModel.save or `gripkit identify narx --basis rational --out`"
    doc = read_family_document(p, SCHEMA, VERSION, family="rational-narx", writer=writer)
    check_narx_fields(doc, f"rational-narx model file {str(p)!r}", writer)
    if doc.get("basis") != "rational":
        raise ModelError(f"{str(p)!r}: a {SCHEMA} must have basis 'rational', found "
                         f"{doc.get('basis')!r}; write it again with RationalNARXModel.save")
    try:
        fields = _model_fields(doc)
        dd = int(doc["den_degree"])
        den_rows = np.array(doc["den_rows"], dtype=np.int64).reshape(len(doc["den_rows"]), dd)
        m = RationalNARXModel(**fields, den_degree=dd, den_rows=den_rows)
    except (KeyError, TypeError, ValueError) as exc:
        raise ModelError(f"{str(p)!r}: a malformed rational {SCHEMA} ({type(exc).__name__}: "
                         f"{exc}); write it again with RationalNARXModel.save") from None
    if (len(m.rows) + len(den_rows) != len(m.theta) or (m.rows >= len(m.bases)).any()
            or (den_rows >= len(m.bases)).any()):
        raise ModelError(f"{str(p)!r}: {len(m.rows)} numerator and {len(den_rows)} denominator "
                         f"terms but {len(m.theta)} parameters, or a term naming a missing lagged "
                         "signal; write it again with RationalNARXModel.save")
    return m


def _prediction_refine(theta, A, B, target, max_iter: int, tol: float = 1e-10):
    """Levenberg–Marquardt on the one-step prediction error ``target − (A θ_N)/(1 + B θ_D)``
    (``A``: the numerator terms on the measured rows, ``B``: the denominator's), from ``theta``;
    a step whose D crosses zero (≤ :data:`DEN_FLOOR`) on a row is refused. → (θ, cov θ =
    σ² (JᵀJ)⁻¹ with σ² = SSE/(N − k), SSE, iterations), or (None, row, min D) when D of the
    start crosses zero."""
    nn = A.shape[1]

    def run(th):
        D = 1.0 + B @ th[nn:]
        if not np.all(D > DEN_FLOOR):
            return None
        yh = (A @ th[:nn]) / D
        J = np.empty((len(D), len(th)))
        J[:, :nn] = A / D[:, None]
        J[:, nn:] = B * (-(yh / D))[:, None]
        return target - yh, J

    res = fit_residuals(run, theta, tol=tol, max_iter=max_iter, damping=_DAMPING)
    if res is None:
        D = 1.0 + B @ theta[nn:]
        return None, int(np.argmin(D)), float(np.min(D))
    return res


def rational_narx(records, *, ylags: int, ulags: int, degree: int, den_degree, direct: bool,
                  terms, dt, validate, prune: bool, refine, max_iter: int,
                  progress: bool) -> RationalNARXModel:
    """The rational NARX model of the records (checked pairs) — the module docstring; called
    by :func:`gripkit.sysid.narx` with ``basis="rational"``, whose arguments these are."""
    say = status if progress else (lambda message: None)
    dd = degree if den_degree is None else _positive_int(den_degree, "den_degree")
    ly, lu, start = ylags, ulags, max(ylags, ulags, 1)
    bases, rows, drows, Pn, Q, X, target = _linear_form(records, ly, lu, (degree, dd), direct,
                                                        start)
    M, L, n = len(rows), len(drows), len(target)
    val = _validation_records(validate, start)
    kmax = _max_terms(terms, M + L)
    say(f"narx: FROLS over {M} numerator and {L} denominator candidates, {n} rows")
    reg = _Regression(X, target)
    QQ, Q1 = Q.T @ Q, Q.sum(axis=0)
    y_range = (min(float(r[1].min()) for r in records), max(float(r[1].max()) for r in records))
    names = ([f"num: {_term_name(r, bases)}" for r in rows]
             + [f"den: {_term_name(r, bases)}" for r in drows])
    prune_pe = prune and refine is None

    def select(s2: float):
        """FROLS on the Gram matrix with the noise's share removed for the noise variance
        ``s2`` (:func:`_corrected_gram`) → (G, g, order, ERR, SSE)."""
        G, g = _corrected_gram(reg.G, reg.g, M, QQ, Q1, s2)
        order, errs, sse = _frols_gram(G, g, reg.yy, kmax)
        if not order:
            raise IdentificationError("narx: no candidate term explains the output (all columns "
                                      "zero)")
        return G, g, order, errs, sse

    def build(k, prune_now=True):
        """The model of the first k FROLS terms, θ refined on the one-step error (and, with
        ``prune_now`` and ``prune``, pruned on its σ) → (model, SSE, iterations, terms pruned),
        or (None, row, min D, 0) when the least-squares start's denominator crosses zero on the
        estimation rows."""
        cols = order[:k]
        theta_ls = _solve(G, g, cols) if s2 > 0.0 else reg.fit(cols)[0]
        nc = [c for c in cols if c < M]
        dc = [c - M for c in cols if c >= M]
        theta = np.concatenate([theta_ls[[i for i, c in enumerate(cols) if c < M]],
                                theta_ls[[i for i, c in enumerate(cols) if c >= M]]])
        last, iters = _refine_pruning(theta, nc, dc, (Pn, Q, target), max_iter,
                                      prune_pe and prune_now)
        if last[0] is None:
            return last
        nc, dc, theta, cov, cost, _, dropped = last
        mod = RationalNARXModel(
            ylags=ly, ulags=lu, degree=degree, direct=direct, bases=bases, rows=rows[nc],
            theta=theta, theta_std=np.sqrt(np.maximum(np.diag(cov), 0.0)), covariance=cov,
            dt=1.0 if dt is None else float(dt), y_range=y_range, err=list(errs[:k]),
            frols_terms=[names[c] for c in cols], den_degree=dd, den_rows=drows[dc])
        return mod, cost, iters, dropped

    def bic_terms():
        return _bic_terms(build, len(order), n)

    # extended least squares (Billings & Zhu 1991): the columns −y q_j hold −e q_j (σ² QᵀQ in
    # their Gram block, −σ² Qᵀ1 in their product with y); FROLS and least squares run again with
    # that removed, σ² from the last one-step error, until the terms repeat (≤ PASSES times)
    s2, passes, chosen, k_bic = 0.0, 0, None, None
    for passes in range(1, PASSES + 1):
        G, g, order, errs, sse = select(s2)
        if terms != "auto":
            k, cost = len(order), build(len(order), prune_now=False)[1]
            cost = cost if isinstance(cost, float) else None
        else:
            k, cost = bic_terms()
        if k is None or cost is None or sorted(order[:k]) == chosen:
            break
        chosen, k_bic = sorted(order[:k]), k
        new = cost / max(n - k, 1)
        if passes > 1 and abs(new - s2) <= 0.01 * s2:
            break
        s2 = new
    G, g, order, errs, sse = select(s2)
    els = (f"FROLS and least squares with the noise share σ² = {s2:.3g} removed (extended "
           f"least squares, {passes} passes)")
    if terms != "auto":
        k, how = len(order), f"terms={len(order)}, {els}"
    elif val is None:
        k = k_bic if k_bic is not None and sorted(order[:k_bic]) == chosen else bic_terms()[0]
        k = len(order) if k is None else k
        how = f"BIC of the one-step error y − N/D minimal at {k} FROLS terms, {els}"
    else:
        best = _validation_best(build, len(order), val, progress)
        k = len(order) if best is None else best[1]
        how = ("validation fit (every candidate diverged)" if best is None else
               f"validation free-run fit best at {k} FROLS terms") + f", {els}"
    model = _final_model(build(k), k, how)
    model.prediction_fit_percent = _fit(target, target - _residual(model, rows, drows, Pn, Q,
                                                                   target))
    if refine == "simulation":
        say(f"narx: refining {len(model.theta)} parameters on the free-run error")
        model = _refined_on_free_run(model, records, (rows, drows, Pn, Q, target), prune,
                                     max_iter, val)
    model.fit_percent = _fit_records(model, records)
    if val is not None:
        model.validation_fit_percent = _fit_records(model, val)
    return model


def _linear_form(records, ly: int, lu: int, degrees, direct: bool, start: int):
    """The candidates and the regression of the linear form ``y·D = N``: the bases, the
    numerator's and the denominator's candidate terms (``degrees``: theirs; D's constant fixed
    to 1), the numerator regressors ``Pn``, the denominator monomials ``Q``, ``X = [Pn, −y·Q]``
    and the target y, over every record's rows from ``start`` on; a DataError when there are
    fewer than twice as many rows as candidates."""
    bases, rows = candidate_terms(ly, lu, degrees[0], direct)
    drows = candidate_terms(ly, lu, degrees[1], direct)[1][1:]
    M, L = len(rows), len(drows)
    total = sum(len(yr) - start for _, yr in records)
    if total < 2 * (M + L):
        raise DataError(f"narx: {total} regression rows for {M} numerator and {L} denominator "
                        f"candidate terms; need at least {2 * (M + L)}: lower degree, den_degree "
                        "or lags, or give more data")
    Pn, target = _regression_matrix(bases, rows, records, start)
    Q = np.concatenate([_regressors(bases, drows, ur, yr, start) for ur, yr in records])
    X = np.empty((len(target), M + L), order="F")
    X[:, :M] = Pn
    np.multiply(Q, -target[:, None], out=X[:, M:])            # the columns −y(t) q_j(φ)
    return bases, rows, drows, Pn, Q, X, target


def _refined_on_free_run(model, records, problem, prune: bool, max_iter: int, val):
    """``model`` refined on the free-run error (:func:`~.narx._refine_and_prune`, its one-step
    fit from ``problem`` = (numerator terms, denominator terms, Pn, Q, target)); with the
    validation records ``val`` the one-step model instead when it validates better."""
    rows, drows, Pn, Q, target = problem
    one_step = dataclasses.replace(model)

    def one_step_fit(m):
        return _fit(target, target - _residual(m, rows, drows, Pn, Q, target))

    _refine_and_prune(model, records, None, None, None, prune, max_iter, one_step_fit)
    if val is not None and "not refined" not in model.criterion:
        model = _better_on_validation(model, one_step, val)
    return model


def _refine_pruning(theta, nc, dc, problem, max_iter: int, prune: bool):
    """θ of the numerator terms ``nc`` and denominator terms ``dc`` refined on the one-step
    error (:func:`_prediction_refine`; ``problem``: the numerator and denominator regressors and
    the target), then with ``prune`` the weakest term with |θ|/σ < 2 dropped and θ refined
    again, one at a time → ((terms, θ, cov, cost, iterations, terms pruned), total iterations),
    or ((None, row, min D, 0), 0) when the start's denominator crosses zero on the estimation
    rows. A term whose removal makes D cross zero stays, and the pruning stops there."""
    Pn, Q, target = problem
    nc, dc = list(nc), list(dc)
    iters, dropped, last = 0, 0, None
    while True:
        res = _prediction_refine(theta, Pn[:, nc], Q[:, dc], target, max_iter)
        if res[0] is None:
            if last is None:
                return (None, res[1], res[2], 0), 0
            break          # without the term dropped last D crosses zero: keep it, stop
        last = (list(nc), list(dc), *res, dropped)
        theta, cov, _, it = res
        iters += it
        if not prune or len(theta) == 1:
            break
        std = np.sqrt(np.maximum(np.diag(cov), 0.0))
        t = np.abs(theta) / np.where(std > 0, std, np.inf)
        w = int(np.argmin(t))
        if not t[w] < 2.0:
            break
        if w < len(nc):
            del nc[w]
        else:
            del dc[w - len(nc)]
        theta = np.delete(theta, w)
        dropped += 1
    return last, iters


def _bic_terms(build, n_order: int, n: int):
    """The number of FROLS terms whose one-step-error model (``build(k, prune_now=False)``,
    unpruned) has the lowest ``BIC = N ln(SSE/N) + k ln N``, the search stopped
    :data:`BIC_PATIENCE` numbers past the best → (k, its model's SSE), or (None, None) when every
    start's D crosses zero."""
    best, since = None, 0
    for k in range(1, n_order + 1):
        cand = build(k, prune_now=False)
        since += 1
        if cand[0] is not None:
            b = n * np.log(max(cand[1], 1e-300) / n) + k * np.log(n)
            if best is None or b < best[0]:
                best, since = (b, k, cand[1]), 0
        if since >= BIC_PATIENCE:
            break
    return (None, None) if best is None else best[1:]


def _validation_best(build, n_order: int, val, progress: bool):
    """(free-run validation fit, k) of the best of the models of the first k FROLS terms, None
    when every one diverges or its denominator crosses zero."""
    best = None
    for j in track(range(1, n_order + 1), description="narx: validation free runs",
                   enabled=progress):
        cand = build(j)
        if cand[0] is None:
            continue
        f = _fit_records(cand[0], val, warn=False)
        if f is not None and (best is None or f > best[0] + 1e-9):
            best = (f, j)
    return best


def _final_model(built, k: int, how: str) -> RationalNARXModel:
    """The chosen model of ``build(k)`` with its criterion, or the named error when its
    least-squares start's denominator crosses zero on the estimation data."""
    model, *rest = built
    if model is None:
        raise IdentificationError(
            f"narx: the rational model's least-squares start of {k} FROLS terms has a "
            f"denominator D that crosses zero on the estimation data (D = {rest[1]:.3g} at "
            f"regression row {rest[0]}); θ is undefined there",
            hint="give fewer terms, a lower den_degree, or basis='polynomial'")
    _, iters, dropped = rest
    model.criterion = (how + "; θ refined on the one-step prediction error y − N/D "
                       f"(Levenberg–Marquardt, {iters} iterations, σ from its Gauss–Newton "
                       "Hessian" + (f", {dropped} term(s) with |θ|/σ < 2 pruned one by one)"
                                    if dropped else ")"))
    return model


#: most passes of the extended least squares (FROLS with the noise share removed)
PASSES = 4
#: the BIC search over the number of terms stops this many numbers past the best
BIC_PATIENCE = 5


def _corrected_gram(G, g, M: int, QQ, Q1, s2: float):
    """``G`` and ``g`` of the regression ``[P_N, −y·Q]`` with the noise's share removed: the
    denominator block ``G[M:, M:] − σ² QᵀQ``, ``g[M:] + σ² Qᵀ1`` (the expectation of the Gram
    matrix of the noise-free columns −(y − e) q_j, for white ``e`` of variance ``s2``)."""
    if s2 <= 0.0:
        return G, g
    G = G.copy()
    g = g.copy()
    G[M:, M:] -= s2 * QQ
    g[M:] += s2 * Q1
    return G, g


def _solve(G, g, cols):
    """θ of the normal equations ``G[cols, cols] θ = g[cols]`` (column-scaled; a pseudo-inverse
    where the corrected matrix is not positive definite)."""
    A = G[np.ix_(cols, cols)]
    d = np.sqrt(np.maximum(np.abs(np.diag(A)), 1e-300))
    return np.linalg.pinv(A / np.outer(d, d), rcond=1e-12) @ (g[cols] / d) / d


def _residual(model, rows, drows, Pn, Q, target):
    """The one-step error ``y − N/D`` of ``model`` on the estimation rows (NaN where D ≤
    :data:`DEN_FLOOR`)."""
    nc = [_row_index(rows, r) for r in model.rows]
    nn = len(nc)
    num = Pn[:, nc] @ model.theta[:nn]
    # denominator rows are padded to den_degree like drows
    dc = [_row_index(drows, r) for r in model.den_rows]
    den = 1.0 + Q[:, dc] @ model.theta[nn:]
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(den > DEN_FLOOR, target - num / den, np.nan)
