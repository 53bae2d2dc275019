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
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares

from ..arguments import entry_point
from ..errors import AccuracyWarning, DataError, IdentificationError, ParameterError
from ..params import ParameterSet
from ..progress import track
from ..signals.trajectory import Trajectory

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
        parts = [f"cannot tell apart {{{', '.join(g)}}} from this experiment (only a combination is "
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
                 f"fit {', '.join(f'{o} {f:.2f} %' for o, f in zip(self.outputs, self.fit_percent))}"]
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
                th[i] = np.clip(t0 * math.exp(rng.normal(0.0, 0.5)) if t0 != 0 else rng.normal(0.0, 1.0), a, b)
        starts.append(th)
    return starts


@entry_point
def fit(model, data: Trajectory, *, outputs: Sequence[str] | Mapping[str, str] | None = None,
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
    """
    if not isinstance(data, Trajectory):
        raise DataError(f"data: expected a Trajectory, found {type(data).__name__}")
    fs = data.require_uniform(why="grey-box identification")
    dt = 1.0 / fs
    params = model.parameters
    if initial is not None:
        params = params.replace(**({n: initial.value(n) for n in initial} if isinstance(initial, ParameterSet) else dict(initial)))
    free = tuple(params.free_names if free is None else free)
    for n in free:
        params[n]  # raises a clear ParameterError for unknown names
    if not free:
        raise ParameterError("no free parameters to identify", hint="pass free=[...] or unfix some parameters")

    in_map = {s.name: (inputs or {}).get(s.name, s.name) for s in model.inputs}
    missing = [c for c in in_map.values() if c not in data]
    if missing:
        raise DataError(f"data has no column {missing[0]!r} for the input of {model.name}",
                        hint=f"map it with inputs={{model_input: column}}; columns: {', '.join(data.names)}")
    u = np.column_stack([data[c] for c in in_map.values()])
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
            raise DataError(f"{o!r} is not an output of {model.name}", hint=f"outputs: {', '.join(model_out)}")
    out_idx = [model_out.index(o) for o in out_map]
    y = np.column_stack([data[c] for c in out_map.values()])
    n_free = len(free)
    burn_in = int(burn_in)
    if burn_in < 0:
        raise DataError(f"burn_in: expected a number of samples >= 0, found {burn_in}")
    data.require_samples(burn_in + 2 * n_free + 1, f"fitting {n_free} parameters after {burn_in} burn-in samples")
    w = np.asarray(output_scale, dtype=np.float64) if output_scale is not None else y[burn_in:].std(axis=0)
    if w.shape != (y.shape[1],) or not np.all(w > 0):
        raise DataError(f"output scale: expected {y.shape[1]} positive weights (a measured output may be "
                        f"constant), found {w}", hint="pass output_scale=[...] explicitly")
    y = y[burn_in:]  # the fitted samples (y_model, residuals and n_samples refer to these)

    names = params.names
    idx = np.array([names.index(n) for n in free])
    base = params.vector()
    lo_all, hi_all = params.bounds_arrays()
    lo, hi = lo_all[idx], hi_all[idx]
    theta0 = base[idx]
    s = _scales(theta0, lo, hi)
    # optimisation variables: z = θ/s; for 'lm' (no bounds) positive parameters use z = log(θ/s)
    logvar = (method == "lm") & (lo >= 0) & (theta0 > 0)

    def to_theta(z):
        return np.where(logvar, s * np.exp(np.where(logvar, z, 0.0)), s * z)

    def to_z(theta):
        return np.where(logvar, np.log(np.where(logvar, theta, s) / s), theta / s)

    x0_arr = None if x0 is None else np.asarray(x0, dtype=np.float64)[None, :]
    nfev = [0]
    substeps = [1]  # only ever grows, so finite differences never straddle a change of step

    def simulate_rows(z_rows: np.ndarray) -> np.ndarray:
        T = np.repeat(base[None, :], z_rows.shape[0], axis=0)
        T[:, idx] = to_theta(z_rows)
        nfev[0] += T.shape[0]
        substeps[0] = max(substeps[0], model.substeps(dt, T))
        return model.simulate_batch(T, u, dt, x0_arr, substeps=substeps[0])[:, burn_in:, out_idx]

    cache: dict = {}

    def residual(z):
        key = z.tobytes()
        if key not in cache:
            cache.clear()
            cache[key] = ((simulate_rows(z[None, :])[0] - y) / w).ravel()
        return cache[key]

    def jacobian(z):
        r0 = residual(z)
        h = np.sqrt(np.finfo(float).eps) * np.maximum(np.abs(z), 1.0)
        step = np.where(logvar | (z + h <= hi / s), h, -h)  # step away from an upper bound
        Z = np.repeat(z[None, :], n_free, axis=0) + np.diag(step)
        R = (simulate_rows(Z) - y[None, :, :]) / w
        return ((R.reshape(n_free, -1) - r0[None, :]) / step[:, None]).T

    bounds = (lo / s, hi / s) if method != "lm" else (-np.inf, np.inf)
    rng = np.random.default_rng(seed)
    starts = [theta0] + _random_starts(theta0, lo, hi, multistart, rng)
    best = None
    tried = []
    for th in track(starts, description="grey-box starts", enabled=progress and len(starts) > 1):
        z0 = np.clip(to_z(th), bounds[0], bounds[1])
        try:
            sol = least_squares(residual, z0, jac=jacobian, bounds=bounds, method=method, loss=loss,
                                max_nfev=max_nfev, x_scale="jac")
        except ParameterError as exc:
            raise IdentificationError(f"the fit left the parameters' physical range: {exc}",
                                      hint="use method='trf' to enforce the bounds, or better starting values") from None
        except ValueError as exc:
            raise IdentificationError(f"least squares failed to start: {exc}") from None
        tried.append((float(sol.cost), to_theta(sol.x)))
        if best is None or sol.cost < best.cost:
            best = sol
    z = best.x
    theta = to_theta(z)
    if method == "lm" and ((theta < lo) | (theta > hi)).any():
        j = int(np.argmax((theta < lo) | (theta > hi)))
        raise IdentificationError(f"Levenberg-Marquardt converged outside the bounds: {free[j]} = {theta[j]:g}",
                                  hint="use method='trf' to enforce the bounds")
    r = residual(z)
    J = jacobian(z) / np.where(logvar, theta, s)[None, :]  # d r / d theta (chain rule through z)
    n_res = r.size
    dof = max(n_res - n_free, 1)
    sigma2 = float(r @ r) / dof
    Js = J * s[None, :]
    U, sv, Vt = np.linalg.svd(Js, full_matrices=False)
    cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else math.inf
    # a direction is undetermined when its singular value is negligible against the largest, or
    # when the noise moves the (scaled, ~unit) parameters along it by more than max_rel_std
    with np.errstate(divide="ignore"):
        rel_std_dir = np.sqrt(sigma2) / sv
    weak = (sv <= rcond * sv[0]) | (rel_std_dir > max_rel_std) if sv[0] > 0 else np.ones_like(sv, dtype=bool)
    groups = []
    bad_params = np.zeros(n_free, dtype=bool)
    for k in np.flatnonzero(weak):
        v = np.abs(Vt[k])
        members = np.flatnonzero(v > 0.1 * v.max())
        bad_params[members] = True
        groups.append(tuple(int(i) for i in members))
    groups = [tuple(free[i] for i in g) for g in sorted(set(groups))]
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
    pairs = []
    for i in range(n_free):
        for j in range(i + 1, n_free):
            if np.isfinite(corr[i, j]) and abs(corr[i, j]) > 0.99:
                pairs.append((free[i], free[j], float(corr[i, j])))
    ident = Identifiability(sv, cond, tuple(groups), tuple(pairs))
    if not ident.ok:
        warnings.warn(f"{model.name}: {ident}; their standard deviations are reported as infinite",
                      AccuracyWarning, stacklevel=2)
    yhat = y + (r.reshape(y.shape) * w)
    fitted = params.from_vector(theta, free, std=std, source=f"identified from {data.meta.get('source', 'data')}")
    return GreyboxResult(
        parameters=fitted, free=free, theta=theta, std=std, covariance=cov, correlation=corr,
        cost=float(best.cost), residual_std=(r.reshape(y.shape) * w).std(axis=0),
        fit_percent=_fit_percent(y, yhat), outputs=tuple(out_map), y_model=yhat,
        residuals=y - yhat, n_samples=y.shape[0], nfev=nfev[0], success=bool(best.success),
        message=str(best.message), identifiability=ident, starts=tuple(tried))
