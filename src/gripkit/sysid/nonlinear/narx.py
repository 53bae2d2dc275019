"""Polynomial NARX models: structure by forward regression with the error
reduction ratio, parameters by least squares with σ, free-run simulation.

The model is ``y(t) = Σ_k θ_k m_k(t) + e(t)`` where every term ``m_k`` is a constant or a product
of at most ``degree`` lagged signals from ``y(t−1) … y(t−ly)`` and ``u(t−1) … u(t−lu)`` (from
``u(t)`` with ``direct=True``).

Structure selection is the forward regression orthogonal least squares of Billings (FROLS;
S. A. Billings, *Nonlinear System Identification: NARMAX Methods*, Wiley 2013, §3.2): at each
step the candidate whose part orthogonal to the terms already chosen explains most of the output
energy (the largest error reduction ratio ``ERR = (wᵀy)² / (wᵀw · yᵀy)``) is taken, and the
remaining candidates are orthogonalised against it (Gram-Schmidt carried out on the Gram matrix
``PᵀP``: one pass over the ``N × M`` candidate block, then ``O(M²)`` per step). The
number of terms is where the Bayesian information criterion ``BIC = N ln(SSE/N) + k ln N``
is lowest, or ``terms=N``, or, with ``validate=``, the number whose pruned model has the best
free-run fit on the validation record.

After selection the parameters are the least-squares solution on the chosen terms, with
``cov θ = σ² (ΦᵀΦ)⁻¹`` and ``σ² = SSE/(N − k)`` (Cholesky of the scaled Gram matrix and one step
of iterative refinement on the residual); terms with ``|θ|/σ_θ < 2`` are removed one at a time
(the weakest first) and the model is refitted.

With ``forgetting=λ < 1`` θ is the exponentially weighted least squares ``min Σ λ^age e²`` (the
batch form of recursive least squares with a forgetting factor, for a slowly drifting system; the
terms still chosen by FROLS on every row), σ from the sandwich covariance
(:meth:`_Regression._fit_weighted`).

With ``refine="simulation"`` θ is then refined by Levenberg–Marquardt on the free-run error, the
free run and its sensitivities ``∂ŷ/∂θ`` from one numba kernel (:func:`_sensitivity_kernel`),
``cov θ`` from the Gauss–Newton Hessian, and the pruning done on that σ. The same sensitivities
give the σ of a simulated output (``simulate(..., std=True)``). Several records
(``narx([(u1, y1), (u2, y2)])``) share one regression, each with its own first ``max_lag``
samples as past.

The free run feeds the simulated output back into the lagged terms (numba kernel
:func:`_simulate_kernel`). The fit is ``100 (1 − ‖y − ŷ‖/‖y − ȳ‖)`` over the samples after the
``max_lag`` initial ones, which are taken from the measured output. A free run that grows beyond
any sensible range or becomes non-finite is reported with a :class:`StabilityWarning` and a fit
of None.
"""

from __future__ import annotations

import dataclasses
import itertools
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numba import njit

from ...errors import (ArgumentError, DataError, IdentificationError, ModelError, StabilityWarning,
                       emit_warning)
from ...params import Parameter, ParameterSet
from ...signals.trajectory import Trajectory
from ...units import product_unit
from ..io_data import check_scale
from ..model_file import (SAMPLE_TIME, Domain, FamilyFile, check_family_fields, file_provenance,
                          read_family_document)
from ..model_protocol import ModelFit
from .levenberg_marquardt import Damping, fit_residuals
from .single_channel import (DIVERGENCE_FACTOR, FreeRunModel, channel_fields, fit_percent,
                             not_constant, one_signal)
from ...progress import status, track

__all__ = ["SCHEMA", "NARX_FIT", "NARXModel", "polynomial_narx", "load_narx", "candidate_terms",
           "frols", "REFINE", "checked_arguments"]

SCHEMA = "gripkit.narx-model"
VERSION = 1
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


def _regressors(bases, rows, u, y, start: int, out=None) -> np.ndarray:
    """The candidate matrix (N − start, M): every monomial evaluated on the measured data
    (written into ``out``, a Fortran-order block of that shape, when given)."""
    n = len(y) - start
    cols = np.empty((len(bases), n))
    for i, (kind, lag) in enumerate(bases):
        s = y if kind == 0 else u
        cols[i] = s[start - lag:len(s) - lag]
    P = np.empty((n, len(rows)), order="F") if out is None else out
    for j, row in enumerate(rows):
        used = [b for b in row if b >= 0]
        if not used:
            P[:, j] = 1.0
        elif len(used) == 1:
            P[:, j] = cols[used[0]]
        else:
            np.multiply(cols[used[0]], cols[used[1]], out=P[:, j])
            for b in used[2:]:
                P[:, j] *= cols[b]
    return P


def _gram(P: np.ndarray, y: np.ndarray):
    """``PᵀP`` (numpy hands ``Aᵀ A`` to BLAS ``syrk``: one pass over ``P``), ``Pᵀy``, ``yᵀy``."""
    return P.T @ P, P.T @ y, float(y @ y)


def frols(P: np.ndarray, y: np.ndarray, max_terms: int):
    """Forward regression orthogonal least squares: the order in which columns of ``P`` are
    chosen, their error reduction ratios, and the residual sum of squares after each step.

    Modified Gram-Schmidt carried out on the Gram matrix: with ``C = WᵀW`` and ``g = Wᵀy`` of the
    candidates orthogonalised so far, choosing column ``j`` (``q = w_j/‖w_j‖``, ``c = qᵀW =
    C[j]/√C_jj``) turns ``W`` into ``W − q cᵀ``, whose Gram matrix is ``C − c cᵀ`` and whose
    ``Wᵀy`` is ``g − c qᵀy``. One pass over the data (``PᵀP``, ``Pᵀy``), then ``O(M²)`` per step:
    the same choices and ERRs as the Gram-Schmidt on the columns, in exact arithmetic."""
    P = np.asarray(P, dtype=np.float64)
    if not P.flags.f_contiguous:
        P = np.asfortranarray(P)
    G, g, yy = _gram(P, np.ascontiguousarray(y, dtype=np.float64))
    return _frols_gram(G, g, yy, max_terms)


def _frols_gram(G: np.ndarray, g: np.ndarray, yy: float, max_terms: int):
    """:func:`frols` from ``G = PᵀP``, ``g = Pᵀy`` and ``yy = yᵀy``."""
    C = np.array(G, dtype=np.float64)
    g = np.array(g, dtype=np.float64)
    norms = np.diag(C).copy()
    active = np.ones(len(g), dtype=bool)
    floor = 1e-10 * np.maximum(norms, 1e-300)
    sse_now = yy
    chosen, errs, sse = [], [], []
    for _ in range(min(max_terms, len(g))):
        ok = active & (norms > floor)
        if not ok.any():
            break
        err = np.where(ok, g * g / np.where(ok, norms, 1.0), -1.0) / yy
        j = int(np.argmax(err))
        r = np.sqrt(norms[j])
        c = C[j] / r
        qy = g[j] / r
        chosen.append(j)
        errs.append(float(err[j]))
        active[j] = False
        sse_now -= qy * qy
        sse.append(max(sse_now, 0.0))
        C -= np.outer(c, c)
        norms = np.maximum(norms - c * c, 0.0)  # ‖w − q qᵀw‖² = ‖w‖² − (qᵀw)²
        g = g - c * qy
    return chosen, errs, sse


class _Regression:
    """The stacked candidate matrix ``P`` (every record's rows after its first ``max_lag``
    samples), the target, and their Gram matrix, from which every least-squares fit on a subset
    of the columns is taken (:meth:`fit`)."""

    def __init__(self, P, target, weights=None):
        self.P, self.target = P, target
        self.G, self.g, self.yy = _gram(P, target)
        self.weights = weights
        if weights is not None:  # ΦᵀWΦ, ΦᵀWy and ΦᵀW²Φ of every candidate, one pass each
            r = np.sqrt(weights)
            Pw = np.asfortranarray(P * r[:, None])
            self.Gw, self.gw, _ = _gram(Pw, target * r)
            Pw *= r[:, None]
            self.Bw = Pw.T @ Pw

    def fit(self, cols):
        """θ, cov θ = σ² (ΦᵀΦ)⁻¹ and SSE of the least squares on ``cols``: Cholesky of the
        column-scaled Gram matrix (the semi-normal equations) and one step of iterative
        refinement on the actual residual, which brings θ to the accuracy of a QR solution for
        any ``cond(Φ)`` below about 1e7; beyond that (or a failed Cholesky) a QR of ``Φ``.
        With row weights (``forgetting``): :func:`_weighted_lstsq_cov`."""
        cols = list(cols)
        if self.weights is not None:
            return self._fit_weighted(cols)
        G = self.G[np.ix_(cols, cols)]
        d = np.sqrt(np.diag(G))
        d[d == 0] = 1.0
        Gs = G / np.outer(d, d)
        try:
            L = np.linalg.cholesky(Gs)
            ok = np.min(np.diag(L)) ** 2 > 1e-14 * len(cols)
        except np.linalg.LinAlgError:
            ok = False
        if not ok:
            return _lstsq_cov(self.P[:, cols], self.target)
        from scipy.linalg import cho_solve

        Phi = self.P[:, cols]
        z = cho_solve((L, True), self.g[cols] / d)
        e = self.target - Phi @ (z / d)
        z += cho_solve((L, True), (Phi.T @ e) / d)  # one refinement step on the residual
        theta = z / d
        e = self.target - Phi @ theta
        sse = float(e @ e)
        n, k = Phi.shape
        Linv = np.linalg.solve(L, np.eye(k))
        cov = sse / max(n - k, 1) * (Linv.T @ Linv) / np.outer(d, d)
        return theta, cov, sse

    def _fit_weighted(self, cols):
        """The exponentially weighted least squares ``min Σ w_i e_i²`` on ``cols`` (Cholesky of
        the column-scaled ``A = ΦᵀWΦ`` and one refinement step on the residual, as :meth:`fit`)
        → θ, its covariance for white noise of one variance σ², and the unweighted SSE. The
        weights are a forgetting profile, not the inverse noise variance, so the covariance is
        the sandwich ``σ² A⁻¹ (ΦᵀW²Φ) A⁻¹`` with ``σ² = Σ w e² / (Σ w − tr(A⁻¹ ΦᵀW²Φ))``,
        unbiased (``E[eᵀWe] = σ² (tr W − tr(A⁻¹ΦᵀW²Φ))``; for ``W = I``: ``SSE/(N − k)``)."""
        from scipy.linalg import cho_solve

        w = self.weights
        G = self.Gw[np.ix_(cols, cols)]
        d = np.sqrt(np.diag(G))
        d[d == 0] = 1.0
        try:
            L = np.linalg.cholesky(G / np.outer(d, d))
        except np.linalg.LinAlgError:
            L = None
        if L is None or np.min(np.diag(L)) ** 2 <= 1e-14 * len(cols):
            raise IdentificationError(
                f"narx: the weighted regressors of {len(cols)} terms are singular (the rows "
                "the forgetting factor keeps do not excite them); give a forgetting factor "
                "closer to 1 or fewer terms")
        Phi = self.P[:, cols]
        z = cho_solve((L, True), self.gw[cols] / d)
        e = self.target - Phi @ (z / d)
        z += cho_solve((L, True), (Phi.T @ (w * e)) / d)  # one refinement step
        theta = z / d
        e = self.target - Phi @ theta
        Ainv = cho_solve((L, True), np.eye(len(cols)))
        AB = Ainv @ (self.Bw[np.ix_(cols, cols)] / np.outer(d, d))
        dof = float(w.sum() - np.trace(AB))
        sigma2 = float(w @ (e * e)) / max(dof, 1e-300)
        cov = sigma2 * (AB @ Ainv) / np.outer(d, d)
        return theta, 0.5 * (cov + cov.T), float(e @ e)


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


def _fit_pruned(reg: _Regression, cols: list[int], threshold: float = 2.0):
    """Least squares on ``cols``, removing the weakest term while ``|θ|/σ < threshold``."""
    cols = list(cols)
    while True:
        theta, cov, sse = reg.fit(cols)
        std = np.sqrt(np.maximum(np.diag(cov), 0.0))
        t = np.abs(theta) / np.where(std > 0, std, np.inf)
        weakest = int(np.argmin(np.where(std > 0, t, np.inf)))
        if len(cols) == 1 or not (t[weakest] < threshold):
            return cols, theta, std, cov, sse
        del cols[weakest]


@njit(cache=True)
def narx_output(rows, theta, z, u0):  # pragma: no cover - compiled
    """``Σ_k θ_k Π_d z[rows[k, d]]``: a polynomial NARX model's output at time t from ``z``, the
    values there of the lagged signals its terms multiply (``rows[k]``: term ``k``'s indices into
    ``z``, −1 padded); an index past the end of ``z`` stands for ``u0``, the input u(t). The one
    evaluation of the model: the free run (:func:`_simulate_kernel`, ``z`` one value per base)
    and the NARX state model of :func:`gripkit.estimation.state_functions` (``z`` the state
    ``[y(t−1) … y(t−ly), u(t−1) … u(t−lu)]``)."""
    nz = z.shape[0]
    acc = 0.0
    for k in range(rows.shape[0]):
        v = theta[k]
        for d in range(rows.shape[1]):
            b = rows[k, d]
            if b < 0:
                break
            v *= z[b] if b < nz else u0
        acc += v
    return acc


@njit(cache=True)
def _simulate_kernel(kinds, lags, rows, theta, u, y, start, limit_lo, limit_hi):
    """Free run in place: ``y[start:]`` from ``y[:start]`` and ``u``. Returns the first sample
    where the run left [limit_lo, limit_hi] or became non-finite, −1 if none."""
    n = y.shape[0]
    z = np.empty(kinds.shape[0])  # the bases' values at t
    for t in range(start, n):
        for b in range(kinds.shape[0]):
            z[b] = y[t - lags[b]] if kinds[b] == 0 else u[t - lags[b]]
        acc = narx_output(rows, theta, z, u[t])
        y[t] = acc
        if not (acc >= limit_lo and acc <= limit_hi):
            for s in range(t + 1, n):
                y[s] = np.nan
            return t
    return -1


@njit(cache=True)
def _sensitivity_kernel(kinds, lags, rows, theta, u, y, start, limit_lo, limit_hi, J, dfdy):
    """Free run in place (as :func:`_simulate_kernel`) and, in the same pass, its derivative
    ``J[t, j] = ∂ŷ(t)/∂θ_j``: ``J[t] = m(t) + Σ_b ∂f/∂y(t−lag_b) · J[t − lag_b]`` over the
    output bases ``b``, with ``J[t] = 0`` for the ``start`` given outputs. ``dfdy`` is scratch of
    one entry per base. Returns the first sample where the run left the limits, −1 if none."""
    n = y.shape[0]
    nt = rows.shape[0]
    deg = rows.shape[1]
    nb = kinds.shape[0]
    for t in range(start):
        for j in range(nt):
            J[t, j] = 0.0
    for t in range(start, n):
        for b in range(nb):
            dfdy[b] = 0.0
        acc = 0.0
        for k in range(nt):
            m = 1.0
            v = theta[k]  # the same order of products as narx_output: the same run
            for d in range(deg):
                b = rows[k, d]
                if b < 0:
                    break
                f = y[t - lags[b]] if kinds[b] == 0 else u[t - lags[b]]
                m *= f
                v *= f
            J[t, k] = m
            acc += v
            for d in range(deg):  # ∂(θ_k m_k)/∂y(t − lag_b): the product of the other factors
                b = rows[k, d]
                if b < 0:
                    break
                if kinds[b] != 0:
                    continue
                p = theta[k]
                for e in range(deg):
                    c = rows[k, e]
                    if c < 0:
                        break
                    if e != d:
                        p *= y[t - lags[c]] if kinds[c] == 0 else u[t - lags[c]]
                dfdy[b] += p
        y[t] = acc
        for b in range(nb):
            if kinds[b] == 0 and dfdy[b] != 0.0:
                s = t - lags[b]
                for j in range(nt):
                    J[t, j] += dfdy[b] * J[s, j]
        if not (acc >= limit_lo and acc <= limit_hi):
            for s in range(t + 1, n):
                y[s] = np.nan
            return t
    return -1


def _as_signal(x, name: str) -> np.ndarray:
    return one_signal(x, name, "narx")


def _fit(y, yhat) -> float:
    return fit_percent(y, yhat, "narx")


@dataclass
class NARXModel(FreeRunModel, FamilyFile):
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
    #: the basis of the terms (:class:`~.narx_rational.RationalNARXModel`: 'rational')
    basis = "polynomial"
    fit_definition = NARX_FIT
    _file_what = "NARX model"
    _family = "a NARX model"
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
    prediction_fit_percent: float | None = None
    err: list = field(default_factory=list)
    frols_terms: list = field(default_factory=list)

    @property
    def parameters(self) -> ParameterSet:
        """θ as a :class:`~gripkit.params.ParameterSet` (``theta_0`` … in term order, each
        documented by its term, with its 1σ); each in the output unit over its term's unit
        (:meth:`term_unit`: 'm/V' for ``u(t-1)``, '1' for ``y(t-1)``, 'm' for the constant),
        in the units of the record the model was fitted on (``input_unit``, ``output_unit``)."""
        return ParameterSet([Parameter(f"theta_{k}", float(v), self.term_unit(r, 1),
                                       f"coefficient of {t}",
                                       source=f"identified (narx, {self.criterion or 'FROLS'})",
                                       std=float(s))
                             for k, (v, s, t, r) in enumerate(zip(self.theta, self.theta_std,
                                                                  self.terms, self.rows))],
                            name="narx")

    def term_unit(self, row, output_power: int) -> str:
        """The unit of the coefficient of the monomial ``row`` (base indices, −1 padded) in a sum
        of unit ``output_unit^output_power``: that unit over the product of the factors' units
        (``y`` in ``output_unit``, ``u`` in ``input_unit``); ``output_power`` 1 for a term of
        the output (or of a rational model's numerator), 0 for one of a dimensionless sum (a
        rational model's denominator)."""
        kinds = [int(self.bases[b, 0]) for b in row if b >= 0]
        return product_unit((self.output_unit, output_power - kinds.count(0)),
                            (self.input_unit, -kinds.count(1)))

    def _signals(self, data, y, why: str, outputs: bool = True):
        """``(u, y)`` of a trajectory's columns by name, or of the signals given."""
        if isinstance(data, Trajectory):
            self._check_rate(data, f"narx.{why}")
            cols = [self.input_name] + ([self.output_name] if outputs else [])
            missing = [c for c in cols if c not in data.names]
            if missing:
                raise DataError(f"data: the model's column(s) {', '.join(map(repr, missing))} "
                                f"are missing; the data have {', '.join(map(repr, data.names))}",
                                hint="rename the columns or identify the model from matching "
                                     "data")
            return (self._column(data, "input"),
                    self._column(data, "output") if outputs else None)
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

    def simulate(self, data, x0=None, *, y0=None, warn: bool = True, std: bool = False):
        """Free run on the input of ``data`` (a trajectory: (N, 1)) or on the input ``u`` (N,),
        the record's values: the first ``max_lag`` outputs are the initial state ``x0`` (zeros
        by default; ``y0=`` is the same, its older name), the rest simulated. A diverging run
        ends in NaN after a StabilityWarning.

        ``std=True``: also the 1σ of the simulated output from the parameter covariance,
        ``σ_ŷ(t)² = J(t) cov θ J(t)ᵀ`` with ``J(t) = ∂ŷ(t)/∂θ`` propagated through the free run
        (linearised; 0 for the given first outputs); returns ``(y, σ_y)``."""
        if y0 is not None:
            if x0 is not None:
                raise ArgumentError("narx.simulate: x0 and y0 both given; they are the same "
                                    "first max_lag outputs", hint="give x0=… only")
            x0 = y0
        if isinstance(data, Trajectory):
            u, _ = self._signals(data, None, "simulate", outputs=False)
            out = self.simulate(u, x0, warn=warn, std=std)
            if std:
                return out[0].reshape(-1, 1), out[1].reshape(-1, 1)
            return out.reshape(-1, 1)
        u = _as_signal(data, "u")
        m = self.max_lag
        if len(u) <= m:
            raise DataError(f"narx.simulate: u has {len(u)} samples, needs more than max_lag = {m}")
        y = np.zeros(len(u))
        if x0 is not None:
            x0 = np.atleast_1d(np.asarray(x0, dtype=np.float64))
            if x0.shape != (m,):
                raise ArgumentError(f"narx.simulate: x0 must hold the first max_lag = {m} outputs, "
                                    f"found shape {x0.shape}")
            y[:m] = x0
        lo, hi = self._limits()
        if std:
            at, J = self._sensitivities(u, y, self.theta)
            if at >= 0:  # the kernel stopped there: no sensitivities beyond
                J[at:] = 0.0
            sy = np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", J, self.covariance, J), 0.0))
            if at >= 0:
                sy[at:] = np.nan
        else:
            at = self._run(u, y, lo, hi)
        if at >= 0 and warn:
            emit_warning(self._stop_message(at), StabilityWarning)
        return (y, sy) if std else y

    def _run(self, u, y, lo: float, hi: float) -> int:
        """Free run into ``y`` (its first ``max_lag`` entries given) → the sample where it
        left [lo, hi], −1 if none."""
        return _simulate_kernel(self.bases[:, 0].copy(), self.bases[:, 1].copy(), self.rows,
                                self.theta, u, y, self.max_lag, lo, hi)

    def _stop_message(self, at: int) -> str:
        """The StabilityWarning of a free run that stopped at sample ``at``."""
        return (f"narx: the free run diverges at sample {at} (beyond {DIVERGENCE_FACTOR:g}× the "
                "estimation output's range); the model is unstable on this input")

    def _structure_state(self) -> tuple:
        """The terms and θ with its σ, to put back with :meth:`_restore_structure`."""
        return self.rows, self.theta, self.covariance, self.theta_std

    def _restore_structure(self, state: tuple) -> None:
        self.rows, self.theta, self.covariance, self.theta_std = state

    def _drop_term(self, j: int) -> None:
        """Remove term ``j`` (index into :attr:`theta`) and its parameter."""
        keep = np.arange(len(self.theta)) != j
        self.rows, self.theta = self.rows[keep], self.theta[keep]

    def _sensitivities(self, u, y, theta):
        """Free run into ``y`` (its first ``max_lag`` entries given) with parameters ``theta``,
        and ``J = ∂ŷ/∂θ`` (N, k); returns (diverged sample or −1, J)."""
        lo, hi = self._limits()
        J = np.empty((len(u), len(theta)))
        at = _sensitivity_kernel(self.bases[:, 0].copy(), self.bases[:, 1].copy(), self.rows,
                                 np.ascontiguousarray(theta, dtype=np.float64), u, y,
                                 self.max_lag, lo, hi, J, np.empty(len(self.bases)))
        return at, J

    def predict(self, data, y=None, horizon: int = 1) -> np.ndarray:
        """One-step-ahead prediction from measured ``u`` and ``y`` (or a trajectory: (N, 1));
        the first ``max_lag`` samples are the measured ones. ``horizon`` must be 1 (a NARX
        k-step predictor is a free run of k steps; use :meth:`simulate` with ``x0``)."""
        if horizon != 1:
            raise ArgumentError(f"narx.predict: horizon must be 1 for a NARX model, found "
                                f"{horizon!r}", hint="simulate(u, x0) runs the model freely")
        if isinstance(data, Trajectory):
            return self.predict(*self._signals(data, y, "predict")).reshape(-1, 1)
        u, y = _as_signal(data, "u"), _as_signal(y, "y")
        if len(u) != len(y):
            raise DataError(f"narx.predict: u has {len(u)} samples but y has {len(y)}; pass a pair "
                            "of equal length")
        return self._one_step(u, y)

    def _one_step(self, u: np.ndarray, y: np.ndarray) -> np.ndarray:
        """``Σ θ_k terms_k(t)`` on checked measured signals, the first ``max_lag`` samples the
        measured ones."""
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
        """The free-run fit (:data:`NARX_FIT`) on a trajectory or on the arrays ``u``, ``y`` (the
        record's values, no offset removed): the run started from the first ``max_lag``
        measured outputs and scored on the samples after them; ``fit_percent`` [None] (with a
        warning) if it diverges; ``simulated`` (N, 1)."""
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
                    **self.channel_document())


def load_narx(path) -> NARXModel:
    """Read a model written by :meth:`NARXModel.save`; any other schema is refused."""
    p = Path(path)
    writer = "NARXModel.save or `gripkit identify narx --out`"
    doc = read_family_document(p, SCHEMA, VERSION, family="narx", writer=writer)
    check_narx_fields(doc, f"narx model file {str(p)!r}", writer)
    try:
        m = NARXModel(**_model_fields(doc))
        bases, rows, theta = m.bases, m.rows, m.theta
    except (KeyError, TypeError, ValueError) as exc:
        raise ModelError(f"{str(p)!r}: a malformed {SCHEMA} ({type(exc).__name__}: {exc}); "
                         "write it again with NARXModel.save") from None
    if len(rows) != len(theta) or (rows >= len(bases)).any():
        raise ModelError(f"{str(p)!r}: {len(rows)} terms but {len(theta)} parameters, or a term "
                         "naming a missing lagged signal; write it again with NARXModel.save")
    return m


#: the numbers of a NARX model file and their domains (:func:`check_narx_fields`)
NARX_NUMBERS = {"dt": SAMPLE_TIME, "degree": Domain(1, integer=True),
                "ylags": Domain(0, integer=True), "ulags": Domain(0, integer=True)}


def check_narx_fields(doc: dict, what: str, writer: str) -> None:
    """The fields of a (polynomial or rational) NARX model file checked on load
    (:func:`~gripkit.sysid.model_file.check_family_fields`): sample time, degree and lags in
    their domains, θ finite, the units readable."""
    check_family_fields(doc, what, writer, numbers=NARX_NUMBERS, finite=("theta",),
                        units=("input_unit", "output_unit"))


def _model_fields(doc: dict) -> dict:
    """The fields of a NARX model file's document (both bases); raises KeyError, TypeError or
    ValueError for a malformed one."""
    bases = np.array(doc["bases"], dtype=np.int64).reshape(-1, 2)
    rows = np.array(doc["rows"], dtype=np.int64).reshape(len(doc["rows"]), int(doc["degree"]))
    theta = np.array(doc["theta"], dtype=np.float64)
    return dict(ylags=int(doc["ylags"]), ulags=int(doc["ulags"]), degree=int(doc["degree"]),
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
                **channel_fields(doc), **file_provenance(doc))


def _positive_int(v, name: str, lo: int = 1) -> int:
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < lo:
        raise ArgumentError(f"narx: {name} must be an integer ≥ {lo}, found {v!r}")
    return int(v)


def _is_signal(a) -> bool:
    """``a`` reads as one 1-D numeric signal (not a pair of records)."""
    try:
        return np.asarray(a, dtype=np.float64).ndim == 1
    except (TypeError, ValueError):
        return False


def _pairs(x, what: str) -> list[tuple[np.ndarray, np.ndarray]]:
    """One record ``(u, y)`` or a list of them -> a list of checked pairs of equal length."""
    if isinstance(x, (list, tuple)) and len(x) == 2 and _is_signal(x[0]) and _is_signal(x[1]):
        x = [x]
    if not isinstance(x, (list, tuple)) or not x:
        raise ArgumentError(f"narx: {what} must be a pair (u, y) of 1-D arrays or a non-empty list "
                            f"of such pairs, found {type(x).__name__}")
    out = []
    for i, pair in enumerate(x):
        name = what if len(x) == 1 else f"{what}[{i}]"
        try:
            u, y = pair
        except (TypeError, ValueError):
            raise ArgumentError(f"narx: {name} must be a pair (u, y) of 1-D arrays, found "
                                f"{type(pair).__name__}") from None
        u, y = _as_signal(u, f"{name} u"), _as_signal(y, f"{name} y")
        if len(u) != len(y):
            raise DataError(f"narx: {name}: u has {len(u)} samples but y has {len(y)}; pass a pair "
                            "of equal length")
        out.append((u, y))
    return out


def _fit_records(model: NARXModel, records, warn: bool = True) -> float | None:
    """Free-run fit (%) over several records, each run from its own first ``max_lag`` measured
    outputs; the fit over all the samples after them together (None if a run diverges)."""
    if len(records) == 1:
        return model._free_run_fit(*records[0], warn=warn)[0]
    m = model.max_lag
    ys, yh = [], []
    for u, y in records:
        s = model.simulate(u, y[:m], warn=warn)
        if not np.all(np.isfinite(s)):
            return None
        ys.append(y[m:])
        yh.append(s[m:])
    return _fit(np.concatenate(ys), np.concatenate(yh))


#: choices of ``refine``
REFINE = (None, "simulation")
#: choices of ``basis``
#: λ ÷ 3 after a step taken, × 4 after one refused, tried below 1e12
_DAMPING = Damping(shrink=3.0, grow=4.0, ceiling=float(np.nextafter(1e12, 0.0)))


def _refine_simulation(model: NARXModel, records, max_iter: int, tol: float = 1e-9):
    """Levenberg–Marquardt on the free-run error ``Σ_records ‖y − ŷ(θ)‖²`` (the samples after
    each record's first ``max_lag``), started from the least-squares θ; the Jacobian from
    :func:`_sensitivity_kernel` (the free run and ``∂ŷ/∂θ`` in one pass). ``cov θ = σ² (JᵀJ)⁻¹``
    at the optimum (the Gauss–Newton Hessian), ``σ² = SSE/(N − k)``. Returns the number of
    iterations, or None when the least-squares start itself diverges."""
    m = model.max_lag

    def run(theta):
        es, Js = [], []
        for u, y in records:
            ys = np.empty(len(u))
            ys[:m] = y[:m]
            at, J = model._sensitivities(u, ys, theta)
            if at >= 0:
                return None
            es.append(y[m:] - ys[m:])
            Js.append(J[m:])
        return np.concatenate(es), np.concatenate(Js)

    res = fit_residuals(run, model.theta, tol=tol, max_iter=max_iter, damping=_DAMPING)
    if res is None:
        return None
    theta, cov, _, it = res
    model.theta = theta
    model.covariance = cov
    model.theta_std = np.sqrt(np.maximum(np.diag(cov), 0.0))
    return it


def _narx_records(u, y) -> list:
    """The estimation records [(u, y)]: ``u`` a list of pairs when ``y`` is None."""
    if y is None:
        return _pairs(u, "records")
    u, y = _as_signal(u, "u"), _as_signal(y, "y")
    if len(u) != len(y):
        raise DataError(f"narx: u has {len(u)} samples but y has {len(y)}; pass a pair of "
                        "equal length")
    return [(u, y)]


def _regression_matrix(bases, rows, records, start: int):
    """The candidate regressors of every record's samples from ``start`` on, stacked in one
    Fortran-ordered matrix, and the targets → (P, target); raises for records too short."""
    for i, (_, yr) in enumerate(records):
        if len(yr) <= start + 1:
            raise DataError(f"narx: record {i} has {len(yr)} samples; each record needs more than "
                            f"max_lag + 1 = {start + 1}")
    n = sum(len(yr) - start for _, yr in records)
    if n < 2 * len(rows):
        raise DataError(f"narx: {n + start * len(records)} samples for {len(rows)} candidate "
                        f"terms; need at least {2 * len(rows) + start * len(records)}: lower "
                        "degree or lags, or give more data")
    P = np.empty((n, len(rows)), order="F")
    at = 0
    for ur, yr in records:
        k = len(yr) - start
        _regressors(bases, rows, ur, yr, start, out=P[at:at + k])
        at += k
    return P, np.concatenate([yr[start:] for _, yr in records])


def _validation_records(validate, start: int):
    """The validation records [(u, y)], or None; each must be longer than max_lag + 2."""
    if validate is None:
        return None
    val = _pairs(validate, "validate")
    for uv, yv in val:
        if len(uv) <= start + 2:
            raise DataError(f"narx: a validation record has {len(uv)} samples; need more "
                            f"than max_lag + 2 = {start + 2}")
    return val


def _max_terms(terms, n_candidates: int) -> int:
    """The most FROLS terms to select: ``terms``, or up to :data:`MAX_AUTO_TERMS` for 'auto'."""
    if terms == "auto":
        return min(n_candidates, MAX_AUTO_TERMS)
    if isinstance(terms, str):
        raise ArgumentError(f"narx: terms must be 'auto' or an integer ≥ 1, found {terms!r}")
    kmax = _positive_int(terms, "terms")
    if kmax > n_candidates:
        raise ArgumentError(f"narx: terms = {kmax} but only {n_candidates} candidates; give at "
                            f"most {n_candidates} or raise degree/lags")
    return kmax


def _choose_terms(build, terms, n_selected: int, sse, n: int, val, progress: bool):
    """The model of the number of FROLS terms chosen: all ``n_selected`` for a given ``terms``,
    else the BIC minimum, or with ``val`` the best validation free-run fit; ``build(k)`` makes
    the model of the first k terms → (model, its SSE, how the number was chosen)."""
    if terms != "auto":
        return (*build(n_selected), f"terms={n_selected}")
    if val is None:
        bic = [n * np.log(max(s, 1e-300) / n) + (k + 1) * np.log(n) for k, s in enumerate(sse)]
        k = int(np.argmin(bic)) + 1
        return (*build(k), f"BIC minimum at {k} FROLS terms")
    best = None
    for k in track(range(1, n_selected + 1), description="narx: validation free runs",
                   enabled=progress):
        cand, sse_c = build(k)
        f = _fit_records(cand, val, warn=False)
        if f is not None and (best is None or f > best[0] + 1e-9):
            best = (f, k, cand, sse_c)
    if best is None:
        return (*build(n_selected), "validation fit (every candidate diverged)")
    return best[2], best[3], f"validation free-run fit best at {best[1]} FROLS terms"


def _refine_and_prune(model, records, rows, P, target, prune: bool, max_iter: int,
                      one_step=None) -> None:
    """θ refined on the free-run error (:func:`_refine_simulation`), then with ``prune`` the
    weakest term with |θ|/σ < 2 dropped and θ refined again, one at a time; the criterion and
    the one-step fit of the refined θ updated. A term whose removal makes the free run
    diverge (the start of the next refinement) stays, and the pruning stops there.
    ``one_step(model)``: the one-step fit (%) of the refined model, when not that of the
    polynomial terms on the columns of ``P``."""
    iters = _refine_simulation(model, records, max_iter)
    dropped, kept = 0, ""
    while prune and iters is not None and len(model.theta) > 1:
        t = np.abs(model.theta) / np.where(model.theta_std > 0, model.theta_std, np.inf)
        weakest = int(np.argmin(t))
        if not t[weakest] < 2.0:
            break
        before, name = model._structure_state(), model.terms[weakest]
        model._drop_term(weakest)
        more = _refine_simulation(model, records, max_iter)
        if more is None:  # without it the free run diverges: keep it, stop pruning
            model._restore_structure(before)
            kept = (f"; {name} kept (|θ|/σ = {t[weakest]:.2g}): without it the free run "
                    "diverges")
            break
        dropped += 1
        iters += more
    model.criterion += ("; θ refined on the free-run error (Levenberg–Marquardt, "
                        f"{iters} iterations, σ from its Gauss–Newton Hessian"
                        + (f", then {dropped} term(s) with |θ|/σ < 2 pruned one by one)"
                           if dropped else ")") + kept
                        if iters is not None else
                        "; not refined: the least-squares model's free run diverges")
    if iters is not None and one_step is not None:
        model.prediction_fit_percent = one_step(model)
    elif iters is not None:  # the one-step fit of the refined θ
        cols = [_row_index(rows, r) for r in model.rows]
        e = target - P[:, cols] @ model.theta
        model.prediction_fit_percent = _fit(target, target - e)


def checked_arguments(u, y, *, degree, lags, ylags, ulags, dt, direct, refine, max_iter):
    """The checks every NARX basis makes of its data and structure: ``(records, all outputs,
    degree, ylags, ulags, max_iter)``, or the one-line error naming the argument."""
    records = _narx_records(u, y)
    if refine not in REFINE:
        raise ArgumentError(f"narx: refine must be None or 'simulation', found {refine!r}")
    max_iter = _positive_int(max_iter, "max_iter")
    yall = np.concatenate([r[1] for r in records])
    check_scale(("u",), np.concatenate([r[0] for r in records]), "input", "NARX identification")
    check_scale(("y",), yall, "output", "NARX identification")
    not_constant(yall, "the output", "narx",
                 "there is nothing to identify: check the output column")
    degree = _positive_int(degree, "degree")
    ly = _positive_int(ylags if ylags is not None else lags, "ylags", 0)
    lu = _positive_int(ulags if ulags is not None else lags, "ulags", 0)
    if dt is not None and not (isinstance(dt, (int, float, np.floating)) and np.isfinite(dt)
                               and dt > 0):
        raise ArgumentError(f"narx: dt must be a positive sample interval in s, found {dt!r}")
    if ly + lu == 0 and not direct:
        raise ArgumentError("narx: no lagged signal (ylags = ulags = 0); give lags ≥ 1")
    return records, yall, degree, ly, lu, max_iter


def polynomial_narx(u, y=None, *, degree: int = 2, lags: int | None = 2,
                    ylags: int | None = None, ulags: int | None = None, terms="auto",
                    dt: float | None = None, validate=None, direct: bool = False,
                    prune: bool = True, refine: str | None = None, forgetting: float = 1.0,
                    max_iter: int = 50, progress: bool = False) -> NARXModel:
    """Polynomial NARX model of ``y`` driven by ``u`` (1-D arrays of equal length), or of
    several records: ``narx([(u1, y1), (u2, y2), …])`` (each record's first ``max_lag``
    samples are its own past; one regression over all of them, σ from all). The public entry
    is :func:`gripkit.sysid.narx` (:mod:`.narx_entry`), whose ``basis`` chooses this or the
    rational NARX.

    ``degree``: highest total degree of a term. ``lags``: output and input lags (``ylags`` /
    ``ulags`` set them apart). ``terms``: ``"auto"`` (BIC, or the validation fit with
    ``validate=(u2, y2)`` or a list of such pairs; at most 40 FROLS terms are tried) or a number
    of FROLS terms. ``direct``: include ``u(t)``. ``dt``: sample interval (s), default 1.
    ``prune``: remove terms with ``|θ|/σ < 2`` and refit.
    ``refine``: None (default: θ and σ of the one-step least squares, the maximum-likelihood
    estimate when the noise enters the equation) or ``"simulation"``: after the structure is
    chosen, θ refined by Levenberg–Marquardt on the free-run (simulation) error, at most
    ``max_iter`` iterations, σ from its Gauss–Newton Hessian (the estimate to use when the
    noise is measurement noise on the output, which biases the one-step estimate). With
    ``validate=`` the refined θ is kept only when its free-run validation fit is at least the
    least-squares one (the criterion says both fits otherwise).
    ``forgetting``: λ in (0, 1]; below 1, θ is the exponentially weighted least squares
    ``min Σ λ^age(t) e(t)²`` (age: rows before the last row of the last record, records taken
    in time order; the batch form of recursive least squares with forgetting factor λ), for a
    system that drifts slowly: the terms are still chosen by FROLS on every row unweighted,
    θ and σ (the sandwich covariance for white noise) weight the recent rows, the memory
    ``Σ λ^age ≈ 1/(1 − λ)`` rows; at most half the memory in terms; not with ``refine``.
    ``progress``: each stage on stderr, a bar over the validation candidates.
    """
    say = status if progress else (lambda message: None)
    records, yall, degree, ly, lu, max_iter = checked_arguments(
        u, y, degree=degree, lags=lags, ylags=ylags, ulags=ulags, dt=dt, direct=direct,
        refine=refine, max_iter=max_iter)
    forgetting = _forgetting(forgetting, refine)
    bases, rows = candidate_terms(ly, lu, degree, direct)
    start = max(ly, lu, 1)
    P, target = _regression_matrix(bases, rows, records, start)
    n = P.shape[0]
    val = _validation_records(validate, start)
    kmax = _max_terms(terms, len(rows))
    weights = None
    if forgetting < 1.0:
        weights = forgetting ** np.arange(n - 1, -1, -1, dtype=np.float64)
        kmax = _memory_terms(terms, kmax, float(weights.sum()), forgetting)
    say(f"narx: FROLS over {len(rows)} candidate terms, {n} rows")
    reg = _Regression(P, target, weights)
    order, errs, sse = _frols_gram(reg.G, reg.g, reg.yy, kmax)
    if not order:
        raise IdentificationError("narx: no candidate term explains the output (all columns zero)")
    y_range = (float(yall.min()), float(yall.max()))

    # with refine, terms are pruned by the σ of the simulation-error criterion, after refinement
    # (the one-step σ of a biased estimate would remove true terms)
    prune_ls = prune and refine is None

    def build(k):
        cols = order[:k]
        if prune_ls:
            cols, theta, std, cov, sse_k = _fit_pruned(reg, cols)
        else:
            theta, cov, sse_k = reg.fit(cols)
            std = np.sqrt(np.maximum(np.diag(cov), 0.0))
        mod = NARXModel(ylags=ly, ulags=lu, degree=degree, direct=direct, bases=bases,
                        rows=rows[cols], theta=theta, theta_std=std, covariance=cov,
                        dt=1.0 if dt is None else float(dt), y_range=y_range,
                        err=list(errs[:k]),
                        frols_terms=[_term_name(rows[c], bases) for c in order[:k]])
        return mod, sse_k

    model, sse_k, how = _choose_terms(build, terms, len(order), sse, n, val, progress)
    model.criterion = how + (", terms with |θ|/σ < 2 pruned" if prune_ls else "")
    if weights is not None:
        model.criterion += (f"; θ by exponentially weighted least squares (forgetting "
                            f"{forgetting:g}, memory {weights.sum():.0f} rows)")
    spread = float(np.linalg.norm(target - target.mean()))
    if spread == 0.0:
        raise DataError("narx: the fit is undefined for a constant output (‖y − ȳ‖ = 0)")
    model.prediction_fit_percent = 100.0 * (1.0 - np.sqrt(sse_k) / spread)
    if refine == "simulation":
        say(f"narx: refining {len(model.theta)} parameters on the free-run error")
        least_squares = dataclasses.replace(model)
        _refine_and_prune(model, records, rows, P, target, prune, max_iter)
        if val is not None and "not refined" not in model.criterion:
            model = _better_on_validation(model, least_squares, val)
    model.fit_percent = _fit_records(model, records)
    if val is not None:
        model.validation_fit_percent = _fit_records(model, val)
    return model


def _better_on_validation(refined: NARXModel, least_squares: NARXModel, val) -> NARXModel:
    """With a validation record the refinement is one more candidate of the structure search:
    the refined model is kept when its free-run validation fit is at least the least-squares
    model's (the one whose number of terms that fit chose), else the least-squares model is
    returned, the criterion saying both fits."""
    f_ref = _fit_records(refined, val, warn=False)
    f_ls = _fit_records(least_squares, val, warn=False)
    if f_ls is None or (f_ref is not None and f_ref >= f_ls):
        return refined
    least_squares.criterion += (
        "; the θ refined on the free-run error was not kept: its validation free-run fit "
        + ("diverges" if f_ref is None else f"is {f_ref:.2f} %") + f" against {f_ls:.2f} % "
        "for least squares")
    return least_squares


def _forgetting(forgetting, refine) -> float:
    """The checked forgetting factor λ in (0, 1]."""
    if isinstance(forgetting, bool) or not isinstance(forgetting, (int, float, np.floating)) \
            or not 0.0 < forgetting <= 1.0:
        raise ArgumentError(f"narx: forgetting must be a number in (0, 1], found {forgetting!r}",
                            hint="1 (default) weighs every row alike; 0.98 remembers about 50 "
                                 "rows")
    if forgetting < 1.0 and refine is not None:
        raise ArgumentError(f"narx: forgetting = {forgetting!r} applies to the least-squares "
                            f"estimate, not to refine={refine!r}; give one of them",
                            hint="refine=None with forgetting < 1, or forgetting=1 with refine")
    return float(forgetting)


def _memory_terms(terms, kmax: int, memory: float, forgetting: float) -> int:
    """The most terms a forgetting memory of ``memory`` rows carries: half of it."""
    most = int(round(memory, 6) // 2)
    if most < 1:
        raise ArgumentError(f"narx: forgetting = {forgetting:g} remembers {memory:.1f} rows, "
                            "too few for one term; give a forgetting factor closer to 1")
    if terms != "auto" and kmax > most:
        raise ArgumentError(f"narx: terms = {kmax} but forgetting = {forgetting:g} remembers "
                            f"{memory:.0f} rows, enough for at most {most} terms; give fewer "
                            "terms or a forgetting factor closer to 1")
    return min(kmax, most)


def _row_index(rows, row) -> int:
    return int(np.flatnonzero((rows == row).all(axis=1))[0])
