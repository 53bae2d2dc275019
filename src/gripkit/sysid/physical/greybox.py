"""Grey-box identification of any gripkit simulation model by nonlinear least squares on the
simulation (output) error.

Given a :class:`~gripkit.sim.Model`, measured inputs u and outputs y, find the free parameters

    θ̂ = argmin_θ  ½ Σ_k Σ_j ( (ŷ_j(k; θ) − y_j(k)) / w_j )²,   lo ≤ θ ≤ hi,

where ŷ is the model simulated from u (free run, not one-step prediction) and w_j scales output j
(its standard deviation by default, so outputs in different units weigh alike). The solver is
``scipy.optimize.least_squares`` (trust-region reflective with bounds, Levenberg-Marquardt without)
in scaled variables z = θ/s (s = |θ₀|, or the bound width when θ₀ = 0). The Jacobian is a finite
difference computed in one parallel call of the model's numba batch simulator (all perturbed
parameter vectors at once).

Uncertainty: with J the Jacobian of the weighted residuals in θ units at the optimum, N_r residuals
and n free parameters,

    σ̂² = Σ r² / (N_r − n),   Cov(θ̂) = σ̂² (JᵀJ)⁻¹  (via the SVD of J),

the usual asymptotic (Cramér-Rao for white Gaussian output noise) covariance. Identifiability:
singular values of J in scaled variables that are negligible against the largest, or along whose
directions the noise moves the parameters by more than 100 %, mark directions the experiment does
not determine; the parameters loading those directions are named,
their standard deviations are reported as infinite, and an :class:`AccuracyWarning` says which
parameters cannot be told apart.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares

from ...arguments import entry_point
from ...errors import AccuracyWarning, DataError, IdentificationError, ParameterError, emit_warning
from ...params import ParameterSet
from ...progress import track
from ...signals.trajectory import Trajectory

__all__ = ["GreyboxResult", "Identifiability", "fit"]


@dataclass(frozen=True)
class Identifiability:
    """Diagnosis of the Jacobian at the optimum (scaled variables)."""

    singular_values: np.ndarray
    condition_number: float
    unidentifiable: tuple[tuple[str, ...], ...]  # groups of parameters along near-null directions
    strongly_correlated: tuple[tuple[str, str, float], ...]  # |corr| > 0.99

    @property
    def ok(self) -> bool:
        return not self.unidentifiable

    def __str__(self) -> str:
        if self.ok and not self.strongly_correlated:
            return f"identifiable (condition number {self.condition_number:.3g})"
        parts = [f"cannot tell apart {{{', '.join(g)}}} from this experiment (only a "
                 "combination is "
                 f"determined)" if len(g) > 1 else f"{g[0]} is not determined by this experiment"
                 for g in self.unidentifiable]
        parts += [f"{a} and {b} correlated at {c:+.4f}" for a, b, c in self.strongly_correlated]
        return "; ".join(parts)


@dataclass(frozen=True)
class GreyboxResult:
    """Result of :func:`fit`.

    ``parameters`` is the model's whole ParameterSet with the free values replaced by the
    estimates (``std`` set); ``covariance``/``correlation`` are over ``free`` (SI units).
    """

    parameters: ParameterSet
    free: tuple[str, ...]
    theta: np.ndarray
    std: np.ndarray
    covariance: np.ndarray
    correlation: np.ndarray
    cost: float
    residual_std: np.ndarray
    fit_percent: np.ndarray
    outputs: tuple[str, ...]
    y_model: np.ndarray
    residuals: np.ndarray
    n_samples: int
    nfev: int
    success: bool
    message: str
    identifiability: Identifiability
    starts: tuple[tuple[float, np.ndarray], ...] = field(default=())

    def value(self, name: str) -> float:
        return self.parameters.value(name)

    def stdev(self, name: str) -> float:
        return float(self.std[self.free.index(name)])

    def table(self) -> list[dict]:
        return [r for r in self.parameters.table() if r["name"] in self.free]

    def summary(self) -> str:
        lines = [f"grey-box fit: {self.n_samples} samples, {len(self.free)} free parameters, "
                 f"{self.nfev} simulations, cost {self.cost:.6g}, "
                 "fit "
                 f"{', '.join(f'{o} {f:.2f} %' for o, f in zip(self.outputs, self.fit_percent))}"]
        for name in self.free:
            lines.append("  " + self.parameters[name].display())
        lines.append("  identifiability: " + str(self.identifiability))
        return "\n".join(lines)


def _scales(theta0: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    s = np.abs(theta0).astype(np.float64)
    width = hi - lo
    fallback = np.where(np.isfinite(width) & (width > 0), width, 1.0)
    return np.where(s > 0, s, fallback)


def _fit_percent(y: np.ndarray, yhat: np.ndarray) -> np.ndarray:
    num = np.linalg.norm(y - yhat, axis=0)
    den = np.linalg.norm(y - y.mean(axis=0), axis=0)
    return 100.0 * (1.0 - num / np.where(den > 0, den, np.nan))


def _random_starts(theta0, lo, hi, n, rng) -> list[np.ndarray]:
    starts = []
    for _ in range(n):
        th = np.empty_like(theta0)
        for i, (t0, a, b) in enumerate(zip(theta0, lo, hi)):
            if np.isfinite(a) and np.isfinite(b):
                if a > 0 and b / a > 100:
                    th[i] = math.exp(rng.uniform(math.log(a), math.log(b)))
                else:
                    th[i] = rng.uniform(a, b)
            else:
                th[i] = (np.clip(t0 * math.exp(rng.normal(0.0, 0.5)) if t0 != 0
                                 else rng.normal(0.0, 1.0), a, b))
        starts.append(th)
    return starts


@dataclass(frozen=True)
class _Columns:
    """The data a fit uses: the model's inputs ``u`` (N, n_u) and the measured outputs ``y``
    after the burn-in (N − burn_in, n_y) with their weights ``w`` (n_y,); ``out_map`` maps each
    fitted model output to its data column, ``out_idx`` is its index among the model's outputs."""

    u: np.ndarray
    y: np.ndarray
    w: np.ndarray
    out_map: dict
    out_idx: list
    burn_in: int


@dataclass(frozen=True)
class _SolverOptions:
    """How :func:`fit` runs ``scipy.optimize.least_squares``: ``method`` and ``loss``,
    ``max_nfev`` per start, ``multistart`` extra random starts drawn from ``seed``, and whether a
    progress bar shows the starts."""

    method: str
    loss: str
    max_nfev: int
    multistart: int
    seed: int
    progress: bool


def _parameters_to_fit(model, initial, free) -> tuple[ParameterSet, tuple[str, ...]]:
    """The model's parameters with the ``initial`` values in place, and the names to estimate
    (default: the non-fixed ones); unknown names raise a ParameterError naming them."""
    params = model.parameters
    if initial is not None:
        params = (params.replace(**({n: initial.value(n) for n in initial}
                                    if isinstance(initial, ParameterSet) else dict(initial))))
    free = tuple(params.free_names if free is None else free)
    for n in free:
        params[n]  # raises a clear ParameterError for unknown names
    if not free:
        raise ParameterError("no free parameters to identify", hint="pass free=[...] or unfix "
                                                                    "some parameters")
    return params, free


def _input_columns(model, data: Trajectory, inputs: Mapping[str, str] | None) -> np.ndarray:
    """The data columns of the model's inputs (``inputs`` maps a model input to a column name)."""
    in_map = {s.name: (inputs or {}).get(s.name, s.name) for s in model.inputs}
    missing = [c for c in in_map.values() if c not in data]
    if missing:
        raise DataError(f"data has no column {missing[0]!r} for the input of {model.name}",
                        hint=f"map it with inputs={{model_input: column}}; columns: "
                             f"{', '.join(data.names)}")
    return np.column_stack([data[c] for c in in_map.values()])


def _output_map(model, data: Trajectory, outputs) -> dict[str, str]:
    """``{model_output: data_column}`` of the outputs to fit (default: every model output that
    ``data`` holds under its own name)."""
    model_out = [s.name for s in model.outputs]
    if outputs is None:
        out_map = {o: o for o in model_out if o in data}
        if not out_map:
            raise DataError(f"data has none of the model outputs {model_out}",
                            hint="name the measured columns with outputs={model_output: column}")
    elif isinstance(outputs, Mapping):
        out_map = dict(outputs)
    else:
        out_map = {o: o for o in outputs}
    for o in out_map:
        if o not in model_out:
            raise DataError(f"{o!r} is not an output "
                            f"of {model.name}", hint=f"outputs: {', '.join(model_out)}")
    return out_map


def _fit_columns(model, data: Trajectory, *, inputs, outputs, n_free: int, burn_in,
                 output_scale) -> _Columns:
    """Read and check the inputs, the outputs and their weights w_j (default: the standard
    deviation of each measured output after the burn-in)."""
    u = _input_columns(model, data, inputs)
    out_map = _output_map(model, data, outputs)
    model_out = [s.name for s in model.outputs]
    out_idx = [model_out.index(o) for o in out_map]
    y = np.column_stack([data[c] for c in out_map.values()])
    burn_in = int(burn_in)
    if burn_in < 0:
        raise DataError(f"burn_in: expected a number of samples >= 0, found {burn_in}")
    data.require_samples(burn_in + 2 * n_free + 1, f"fitting {n_free} parameters after {burn_in} "
                                                   "burn-in samples")
    w = (np.asarray(output_scale, dtype=np.float64) if output_scale is not None
         else y[burn_in:].std(axis=0))
    if w.shape != (y.shape[1],) or not np.all(w > 0):
        raise DataError(f"output scale: expected {y.shape[1]} positive weights (a "
                        "measured output may be "
                        f"constant), found {w}", hint="pass output_scale=[...] explicitly")
    # the fitted samples (y_model, residuals and n_samples refer to these)
    return _Columns(u, y[burn_in:], w, out_map, out_idx, burn_in)


class _OutputError:
    """The weighted simulation-error residual r(z) = vec((ŷ(θ) − y) / w) of the free parameters,
    in the optimisation variables z = θ/s (s: :func:`_scales`; for 'lm', which has no bounds,
    positive parameters use z = log(θ/s)), and its forward-difference Jacobian dr/dz computed in
    one batch simulation of all perturbed parameter vectors. ``nfev`` counts the simulations."""

    def __init__(self, model, params: ParameterSet, free: tuple[str, ...], cols: _Columns,
                 dt: float,
                 x0, method: str):
        names = params.names
        self.model, self.cols, self.dt = model, cols, dt
        self.idx = np.array([names.index(n) for n in free])
        self.base = params.vector()
        lo_all, hi_all = params.bounds_arrays()
        self.lo, self.hi = lo_all[self.idx], hi_all[self.idx]
        self.theta0 = self.base[self.idx]
        self.s = _scales(self.theta0, self.lo, self.hi)
        self.logvar = (method == "lm") & (self.lo >= 0) & (self.theta0 > 0)
        self.bounds = (self.lo / self.s, self.hi / self.s) if method != "lm" else (-np.inf, np.inf)
        self.x0 = None if x0 is None else np.asarray(x0, dtype=np.float64)[None, :]
        self.nfev = 0
        self._substeps = 1  # only ever grows, so finite differences never straddle a change of step
        self._cache: dict = {}

    def to_theta(self, z):
        s, logvar = self.s, self.logvar
        return np.where(logvar, s * np.exp(np.where(logvar, z, 0.0)), s * z)

    def to_z(self, theta):
        s, logvar = self.s, self.logvar
        return np.where(logvar, np.log(np.where(logvar, theta, s) / s), theta / s)

    def simulate_rows(self, z_rows: np.ndarray) -> np.ndarray:
        """Fitted outputs ŷ (P, N − burn_in, n_y) for P rows of z."""
        T = np.repeat(self.base[None, :], z_rows.shape[0], axis=0)
        T[:, self.idx] = self.to_theta(z_rows)
        self.nfev += T.shape[0]
        self._substeps = max(self._substeps, self.model.substeps(self.dt, T))
        c = self.cols
        return (self.model.simulate_batch(T, c.u, self.dt, self.x0,
                                          substeps=self._substeps)[:, c.burn_in:, c.out_idx])

    def residual(self, z):
        key = z.tobytes()
        if key not in self._cache:
            self._cache.clear()
            self._cache[key] = ((self.simulate_rows(z[None,
                                                      :])[0] - self.cols.y) / self.cols.w).ravel()
        return self._cache[key]

    def jacobian(self, z):
        r0 = self.residual(z)
        n_free = z.size
        h = np.sqrt(np.finfo(float).eps) * np.maximum(np.abs(z), 1.0)
        # step away from an upper bound
        step = np.where(self.logvar | (z + h <= self.hi / self.s), h, -h)
        Z = np.repeat(z[None, :], n_free, axis=0) + np.diag(step)
        R = (self.simulate_rows(Z) - self.cols.y[None, :, :]) / self.cols.w
        return ((R.reshape(n_free, -1) - r0[None, :]) / step[:, None]).T

    def jacobian_theta(self, z, theta):
        """dr/dθ (chain rule through z)."""
        return self.jacobian(z) / np.where(self.logvar, theta, self.s)[None, :]


def _best_of_starts(problem: _OutputError, opts: _SolverOptions):
    """Run ``least_squares`` from θ₀ and ``opts.multistart`` random starts; returns the solution
    of least cost and every start's (cost, θ)."""
    rng = np.random.default_rng(opts.seed)
    starts = ([problem.theta0] + _random_starts(problem.theta0, problem.lo, problem.hi,
                                                opts.multistart, rng))
    best = None
    tried = []
    for th in track(starts, description="grey-box starts",
                    enabled=opts.progress and len(starts) > 1):
        z0 = np.clip(problem.to_z(th), problem.bounds[0], problem.bounds[1])
        try:
            sol = least_squares(problem.residual, z0, jac=problem.jacobian, bounds=problem.bounds,
                                method=opts.method, loss=opts.loss, max_nfev=opts.max_nfev,
                                x_scale="jac")
        except ParameterError as exc:
            raise IdentificationError(f"the fit left the parameters' physical range: {exc}",
                                      hint="use method='trf' to enforce the bounds, or better "
                                           "starting values") from None
        except ValueError as exc:
            raise IdentificationError(f"least squares failed to start: {exc}") from None
        tried.append((float(sol.cost), problem.to_theta(sol.x)))
        if best is None or sol.cost < best.cost:
            best = sol
    return best, tried


def _check_inside_bounds(theta, problem: _OutputError, free, method: str) -> None:
    """'lm' ignores the bounds: refuse an estimate outside them."""
    lo, hi = problem.lo, problem.hi
    if method == "lm" and ((theta < lo) | (theta > hi)).any():
        j = int(np.argmax((theta < lo) | (theta > hi)))
        raise IdentificationError("Levenberg-Marquardt converged outside the bounds: "
                                  f"{free[j]} = {theta[j]:g}",
                                  hint="use method='trf' to enforce the bounds")


def _weak_directions(sv, Vt, sigma2: float, rcond: float, max_rel_std: float, free):
    """The undetermined directions of the scaled Jacobian (module doc): a direction is weak when
    its singular value is negligible against the largest, or when the noise moves the (scaled,
    ~unit) parameters along it by more than ``max_rel_std``. Returns the weak mask, the free
    parameters loading a weak direction (> 0.1 of its largest component), and their name groups."""
    with np.errstate(divide="ignore"):
        rel_std_dir = np.sqrt(sigma2) / sv
    weak = ((sv <= rcond * sv[0]) | (rel_std_dir > max_rel_std) if sv[0] > 0
            else np.ones_like(sv, dtype=bool))
    groups = []
    bad_params = np.zeros(len(free), dtype=bool)
    for k in np.flatnonzero(weak):
        v = np.abs(Vt[k])
        members = np.flatnonzero(v > 0.1 * v.max())
        bad_params[members] = True
        groups.append(tuple(int(i) for i in members))
    return weak, bad_params, [tuple(free[i] for i in g) for g in sorted(set(groups))]


def _strongly_correlated(corr, free) -> list[tuple[str, str, float]]:
    """The pairs of free parameters correlated beyond |0.99|."""
    pairs = []
    for i in range(len(free)):
        for j in range(i + 1, len(free)):
            if np.isfinite(corr[i, j]) and abs(corr[i, j]) > 0.99:
                pairs.append((free[i], free[j], float(corr[i, j])))
    return pairs


def _uncertainty(J, r, s, free, rcond: float, max_rel_std: float):
    """σ̂² = Σ r² / (N_r − n) and Cov(θ̂) = σ̂² (JᵀJ)⁻¹ through the SVD of J·diag(s) (module
    doc), with the weak directions left out (their parameters' σ infinite, correlations NaN).
    Returns the covariance, σ, the correlation matrix and the :class:`Identifiability`."""
    dof = max(r.size - len(free), 1)
    sigma2 = float(r @ r) / dof
    Js = J * s[None, :]
    _, sv, Vt = np.linalg.svd(Js, full_matrices=False)
    cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else math.inf
    weak, bad_params, groups = _weak_directions(sv, Vt, sigma2, rcond, max_rel_std, free)
    inv_sv2 = np.where(weak, 0.0, 1.0 / np.where(sv > 0, sv, 1.0) ** 2)
    cov_z = (Vt.T * inv_sv2) @ Vt * sigma2
    cov = cov_z * np.outer(s, s)
    std = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    std[bad_params] = np.inf
    d = np.where(std > 0, std, 1.0)
    corr = cov / np.outer(d, d)
    corr[bad_params, :] = np.nan
    corr[:, bad_params] = np.nan
    np.fill_diagonal(corr, 1.0)
    ident = Identifiability(sv, cond, tuple(groups), tuple(_strongly_correlated(corr, free)))
    return cov, std, corr, ident


def _result(params: ParameterSet, free, theta, cov, std, corr, ident: Identifiability,
            problem: _OutputError,
            best, r, tried, *, source: str) -> GreyboxResult:
    """The :class:`GreyboxResult` of the best start: the modelled outputs ŷ = y + r·w, their
    residuals and fit percentages, and the parameters with their σ."""
    y, w = problem.cols.y, problem.cols.w
    yhat = y + (r.reshape(y.shape) * w)
    fitted = params.from_vector(theta, free, std=std, source=f"identified from {source}")
    return GreyboxResult(
        parameters=fitted, free=free, theta=theta, std=std, covariance=cov, correlation=corr,
        cost=float(best.cost), residual_std=(r.reshape(y.shape) * w).std(axis=0),
        fit_percent=_fit_percent(y, yhat), outputs=tuple(problem.cols.out_map), y_model=yhat,
        residuals=y - yhat, n_samples=y.shape[0], nfev=problem.nfev, success=bool(best.success),
        message=str(best.message), identifiability=ident, starts=tuple(tried))


@entry_point
def fit(model, data: Trajectory | Sequence[Trajectory], *,
        outputs: Sequence[str] | Mapping[str, str] | None = None,
        inputs: Mapping[str, str] | None = None, free: Sequence[str] | None = None,
        initial: ParameterSet | Mapping[str, float] | None = None, x0: np.ndarray | None = None,
        output_scale: Sequence[float] | None = None, multistart: int = 0, seed: int = 0,
        method: str = "trf", max_nfev: int = 200, rcond: float = 1e-8, max_rel_std: float = 1.0,
        loss: str = "linear", burn_in: int = 0,
        progress: bool = True) -> GreyboxResult:
    """Identify the free parameters of ``model`` from ``data`` (see the module docstring).

    Parameters
    ----------
    model
        A :class:`gripkit.sim.Model`.
    data
        Uniformly sampled measurements holding the model's inputs and the measured outputs.
    outputs
        Model outputs to fit: names (data columns of the same name) or a mapping
        ``{model_output: data_column}``. Default: every model output found in ``data``.
    inputs
        Mapping ``{model_input: data_column}`` when the data names differ.
    free
        Parameters to estimate (default: the non-fixed ones of ``model.parameters``).
    initial
        Starting values (default: the model's current values).
    x0
        Initial state (default: the model's ``initial_state``).
    output_scale
        Weight w_j per output (default: the standard deviation of each measured output).
    multistart
        Extra random starts within the bounds (log-uniform for positive bounds spanning > 100×);
        the best cost wins.
    method
        'trf' (bounds) or 'lm' (Levenberg-Marquardt; ignores bounds, checked afterwards).
    burn_in
        Samples simulated but left out of the cost (the transient of an unknown initial state,
        e.g. the hysteresis state of a record that starts mid-loop). Default 0.
    rcond, max_rel_std
        Identifiability diagnosis: a Jacobian direction (in parameters scaled to their starting
        values) is undetermined if its singular value is below ``rcond`` times the largest, or if
        the noise moves the parameters along it by more than ``max_rel_std`` (1.0 = 100 %).

    Several records (``data`` a list of trajectories with the same columns and sample interval):
    one set of parameters for all of them, every record simulated from its own initial state
    (``x0`` then a list with one per record, or None for the model's initial state in each), its
    own ``burn_in`` samples left out, the weights w_j from all records' outputs together; the
    residuals of all records form one least-squares problem and σ̂² = Σ r²/(Σ N_r − n).
    ``fit_percent``, ``y_model`` and ``residuals`` are then over the records one after another.
    """
    if isinstance(data, (list, tuple)):
        solver = _SolverOptions(method, loss, max_nfev, multistart, seed, progress)
        return _fit_records(model, data, outputs=outputs, inputs=inputs, free=free, initial=initial,
                            x0=x0, output_scale=output_scale, burn_in=burn_in, solver=solver,
                            rcond=rcond, max_rel_std=max_rel_std)
    if not isinstance(data, Trajectory):
        raise DataError(f"data: expected a Trajectory, found {type(data).__name__}")
    dt = data.require_uniform(why="grey-box identification")
    params, free = _parameters_to_fit(model, initial, free)
    cols = _fit_columns(model, data, inputs=inputs, outputs=outputs, n_free=len(free),
                        burn_in=burn_in,
                        output_scale=output_scale)
    problem = _OutputError(model, params, free, cols, dt, x0, method)
    best, tried = (_best_of_starts(problem, _SolverOptions(method, loss, max_nfev, multistart, seed,
                                                           progress)))
    z = best.x
    theta = problem.to_theta(z)
    _check_inside_bounds(theta, problem, free, method)
    r = problem.residual(z)
    cov, std, corr, ident = (_uncertainty(problem.jacobian_theta(z, theta), r, problem.s, free,
                                          rcond, max_rel_std))
    if not ident.ok:
        emit_warning(f"{model.name}: {ident}; their standard deviations are reported as infinite",
                     AccuracyWarning)
    return _result(params, free, theta, cov, std, corr, ident, problem, best, r, tried,
                   source=data.meta.get("source", "data"))


class _RecordsOutputError:
    """:class:`_OutputError` of several records sharing the free parameters: the residuals and
    Jacobians of the records stacked (each record simulated from its own initial state)."""

    def __init__(self, parts: list[_OutputError]):
        self.parts = parts
        first = parts[0]
        for name in ("lo", "hi", "s", "theta0", "bounds", "logvar", "to_z", "to_theta"):
            setattr(self, name, getattr(first, name))
        c = first.cols
        self.cols = _Columns(None, np.vstack([q.cols.y for q in parts]), c.w, c.out_map, c.out_idx,
                             c.burn_in)

    @property
    def nfev(self) -> int:
        return sum(q.nfev for q in self.parts)

    def residual(self, z):
        return np.concatenate([q.residual(z) for q in self.parts])

    def jacobian(self, z):
        return np.vstack([q.jacobian(z) for q in self.parts])

    def jacobian_theta(self, z, theta):
        return self.jacobian(z) / np.where(self.logvar, theta, self.s)[None, :]


def _fit_records(model, data, *, outputs, inputs, free, initial, x0, output_scale, burn_in,
                 solver: _SolverOptions, rcond: float, max_rel_std: float) -> GreyboxResult:
    """:func:`fit` of several records (see its docstring)."""
    if not data:
        raise DataError("data: expected a trajectory or a non-empty list of them, found an empty "
                        "list")
    for i, d in enumerate(data):
        if not isinstance(d, Trajectory):
            raise DataError(f"data[{i}]: expected a Trajectory, found {type(d).__name__}")
    dts = [d.require_uniform(why="grey-box identification") for d in data]
    for i, dt in enumerate(dts[1:], 1):
        if abs(dt - dts[0]) > 1e-9 * dts[0]:
            raise DataError(f"data[{i}] is sampled every {dt:g} s, data[0] every {dts[0]:g} s: the "
                            "records of one fit must share the sample interval",
                            hint="resample one of them")
    if x0 is not None and (not isinstance(x0, (list, tuple)) or len(x0) != len(data)):
        raise DataError(f"x0: with {len(data)} records expected a list of {len(data)} initial "
                        f"states (one per record) or None, found {type(x0).__name__}",
                        hint="x0=[x0_1, x0_2, ...], or None for the model's initial state")
    params, free = _parameters_to_fit(model, initial, free)
    cols = [_fit_columns(model, d, inputs=inputs, outputs=outputs, n_free=len(free),
                         burn_in=burn_in, output_scale=output_scale) for d in data]
    if output_scale is None:  # one weight per output, from all records
        w = np.vstack([c.y for c in cols]).std(axis=0)
        if not np.all(w > 0):
            raise DataError(f"output scale: a measured output is constant in every record ({w})",
                            hint="pass output_scale=[...] explicitly")
        cols = [_Columns(c.u, c.y, w, c.out_map, c.out_idx, c.burn_in) for c in cols]
    parts = [_OutputError(model, params, free, c, dts[0], None if x0 is None else x0[i],
                          solver.method) for i, c in enumerate(cols)]
    problem = _RecordsOutputError(parts)
    best, tried = _best_of_starts(problem, solver)
    theta = problem.to_theta(best.x)
    _check_inside_bounds(theta, problem, free, solver.method)
    r = problem.residual(best.x)
    cov, std, corr, ident = _uncertainty(problem.jacobian_theta(best.x, theta), r, problem.s, free,
                                         rcond, max_rel_std)
    if not ident.ok:
        emit_warning(f"{model.name}: {ident}; their standard deviations are reported as infinite",
                     AccuracyWarning)
    return _result(params, free, theta, cov, std, corr, ident, problem, best, r, tried,
                   source=f"{len(data)} records")
