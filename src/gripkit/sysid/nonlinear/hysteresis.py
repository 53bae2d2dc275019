"""Hysteresis identified from the user's data: generic Bouc-Wen (actuator
form) and Prandtl–Ishlinskii with its analytic inverse, parameters with σ.

**Bouc-Wen, actuator form** (``001_0b92a7da96e7aa46.txt`` eq 3, generalised by the exponent n)::

    y = d u − h + c,     dh/dt = α d du/dt − β |du/dt| h |h|^(n−1) − γ du/dt |h|^n

u the input (a voltage, a force), y the output (a displacement), h the hysteresis term (unit of
y), c the output offset. With n = 1 and λ = α d this is eq 3 of the seed, the model of the
piezo reference system (:class:`gripkit.models.hysteresis.BoucWen`), and the free run uses its
exact per-sample step (:func:`gripkit.models.hysteresis.bouc_wen_advance`); for n ≠ 1 it is
integrated in the input by Runge-Kutta (:mod:`.hysteresis_kernels`). The model is rate
independent: only the path of u matters, the sample time does not. The record is simulated from
the virgin state, h = 0 at its first input sample. d, α, β, γ (and n with
``exponent='free'``, c with ``offset=True``) minimise ‖y − ŷ‖² of that free run
(``scipy.optimize.least_squares``, trust-region reflective, on signals scaled to unit half-range,
``multistart`` starting points from the data's slope and the gap between its branches);
cov θ = s² (JᵀJ)⁻¹ with s² = SSE/(N − p) and J the Jacobian of the free run at the optimum.

**Bouc-Wen, oscillator form** (Y.-K. Wen, "Method for random vibration of hysteretic
systems", *J. Eng. Mech. Div. ASCE* 102(2), 1976; :class:`BoucWenOscillatorModel`): a force u on a
mass with a hysteretic spring, ``m ẍ + c_v ẋ + k_e x + k_h z = u``,
``ż = ẋ − β |ẋ| z |z|^(n−1) − γ ẋ |z|^n`` (A = 1 fixes the scale of z), rate dependent,
simulated from rest with the input held over each sample (RK4 sub-steps) and fitted on the free
run like the actuator form, from the second-order ARX model nearest the data (the starting
points tried on the first :data:`WARM_SAMPLES` samples, shared out among the records, the best
then refined on the whole records). Several records: each run from its own first sample. A
record may start in motion: by default (``initial_state='estimate'``) each record's state
(x, ẋ, z) at its first sample (at sample ``burn_in``, the samples before it dropped, when one is
given) is estimated with θ, three nuisance parameters a record whose
Jacobian columns come from the same forward differences as θ's (a run of that record alone);
cov θ is the θ block of s² (JᵀJ)⁻¹ over θ and every initial state. ``initial_state='zero'``
runs every record from rest (x = ẋ = z = 0), right only for a record known to start at rest: a
record in motion at its first sample then biases θ.

**Prandtl–Ishlinskii**: ``y = c + Σ_i w_i F_{r_i}[u − a]`` with the play operators
``F_r[x](k) = max(x(k) − r, min(x(k) + r, F_r[x](k−1)))``, each relaxed at the first sample
(F = x(0)), thresholds ``r_0 = 0 < r_1 < …`` (by default ``r_i = i R / m``, R half the input's
range, m = ``operators``) and input offset a (0 for an identified model). The weights are the
least-squares solution with ``w_i ≥ 0`` (bounded-variable least squares, ``scipy.optimize
.lsq_linear``), cov = s² (AᵀA)⁻¹ over the play matrix A (the unconstrained covariance, honest
for the weights not on their bound). :meth:`PrandtlIshlinskiiModel.invert` gives the inverse
operator, again a PI model (Kuhnen, *Eur. J. Control* 9(4), 2003, eq 18)::

    r̂_i = Σ_{j≤i} w_j (r_i − r_j),   ŵ_0 = 1/w_0,   ŵ_i = −w_i / (W_i W_{i−1}),  W_i = Σ_{j≤i} w_j

with input offset c and output offset a, so that ``inverse(model(u)) = u`` sample by sample
(the inverse's plays relaxed at its first sample are the image of the model's relaxed state);
it needs w_0 > 0, and is the feed-forward compensator: voltage = inverse(desired displacement).

Both are scored by :data:`HYSTERESIS_FIT`. An input that never turns back does not excite the
hysteresis and is refused with a DataError that says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...errors import (AccuracyWarning, ArgumentError, DataError, IdentificationError, ModelError,
                       StabilityWarning, emit_warning)
from ...params import Parameter, ParameterSet
from ...progress import track
from ...signals.trajectory import Trajectory
from ..io_data import check_scale
from ..model_file import (SAMPLE_TIME, Domain, FamilyFile, check_family_fields, file_provenance,
                          read_family_document)
from ..model_protocol import ModelFit
from . import hysteresis_kernels as K
from .nonlinear_model import OutputErrorPrediction
from .single_channel import SingleChannel, fit_percent, not_constant, one_signal

__all__ = ["SCHEMA", "HYSTERESIS_FIT", "MODELS", "FORMS", "BoucWenModel",
           "BoucWenOscillatorModel", "PrandtlIshlinskiiModel", "hysteresis", "load_hysteresis",
           "pi_inverse"]

SCHEMA = "gripkit.hysteresis-model"
VERSION = 1
MODELS = ("bouc-wen", "prandtl-ishlinskii")
#: the forms of the Bouc-Wen model
FORMS = ("actuator", "oscillator")
#: how a hysteresis model's fit is taken (``gripkit compare`` prints it)
HYSTERESIS_FIT = ("free run from the relaxed state at the first input sample (Bouc-Wen: h = 0; "
                  "Prandtl-Ishlinskii: every play at the first input), "
                  "fit = 100 (1 − ‖y − ŷ‖/‖y − ȳ‖) over the record (at identification: the "
                  "samples after burn_in, the Bouc-Wen oscillator's estimation records from "
                  "their estimated initial states where initial_state='estimate')")
#: the hint of a rate-independent model given x0: the path of the input sets its state
_HISTORY_HINT = ("prepend the input's history to the record (the path of u sets the state), "
                 "or call simulate(data) from the relaxed state")
#: an input turning back by less than this fraction of its range is no reversal (noise)
REVERSAL_BAND = 0.01


# ---------------------------------------------------------------------------------------------
# helpers


def _unitless(u: str) -> bool:
    return u in ("", "1")


def _ratio(num: str, den: str) -> str:
    if _unitless(den):
        return num if not _unitless(num) else "1"
    return f"1/{den}" if _unitless(num) else f"{num}/{den}"


def _as_signal(x, name: str) -> np.ndarray:
    return one_signal(x, name, "hysteresis")


def _fit_percent(y: np.ndarray, yhat: np.ndarray) -> float | None:
    return fit_percent(y, yhat, "hysteresis") if np.all(np.isfinite(yhat)) else None


def _record(data, input, output, what: str, need_output: bool = True):
    """(u, y or None, dt, input name, output name, input unit, output unit) from a Trajectory or
    a pair (u, y) / an array u."""
    if isinstance(data, Trajectory):
        for role, col in (("input", input), ("output", output)):
            if col is None and (role == "input" or need_output):
                raise ArgumentError(f"{what}: give {role}= (a column of the data: "
                                    f"{', '.join(map(repr, data.names))})")
            if col is not None and col not in data.names and (role == "input" or need_output):
                raise DataError(f"{what}: no column {col!r} in the data; it has "
                                f"{', '.join(map(repr, data.names))}")
        u = _as_signal(data[input], f"column {input!r}")
        y = (_as_signal(data[output], f"column {output!r}")
             if need_output or (output is not None and output in data.names) else None)
        dt = data.dt if data.n > 1 else None
        return (u, y, dt, input, output, data.unit(input),
                data.unit(output) if output in data.names else "1")
    if isinstance(data, (tuple, list)) and len(data) == 2:
        u, y = _as_signal(data[0], "u"), _as_signal(data[1], "y")
        if len(u) != len(y):
            raise DataError(f"{what}: u has {len(u)} samples but y has {len(y)}; pass a pair of "
                            "equal length")
        return u, y, None, input or "u", output or "y", "1", "1"
    if need_output:
        raise ArgumentError(f"{what}: data must be a Trajectory or a pair (u, y), found "
                            f"{type(data).__name__}",
                            hint="give the record as a Trajectory, or its input and output "
                                 "arrays u, y (the record's values)")
    return _as_signal(data, "u"), None, None, input or "u", output or "y", "1", "1"


def _check_excited(u: np.ndarray, y: np.ndarray, input: str, output: str) -> None:
    if len(u) < 10:
        raise DataError(f"hysteresis: {len(u)} samples; a loop needs at least 10",
                        hint="more data are needed: record a longer sweep")
    check_scale((input,), u, "input", "hysteresis identification")
    check_scale((output,), y, "output", "hysteresis identification")
    not_constant(u, f"the input {input!r}", "hysteresis", "a hysteresis needs an input sweep")
    not_constant(y, f"the output {output!r}", "hysteresis", "check the output column")
    if K.count_reversals(u, REVERSAL_BAND * float(np.ptp(u))) < 1:
        raise DataError(f"hysteresis not excited: the input {input!r} never reverses (it "
                        f"never turns back by more than {100 * REVERSAL_BAND:g} % of its "
                        "range), so no loop is closed",
                        hint="record at least one rise and one fall of the input (a sine or "
                             "triangle sweep, ideally with loops of several amplitudes)")


def _parameter(name, value, unit, doc, std=None, fixed=False, bounds=(None, None)):
    return Parameter(name, float(value), unit, doc, bounds=bounds, fixed=fixed,
                     source="identified (gripkit.sysid.hysteresis)" if not fixed else "fixed",
                     std=None if std is None or not math.isfinite(std) else float(std))


def _output_std(G: np.ndarray, cov: np.ndarray) -> np.ndarray:
    """sqrt(diag(G cov Gᵀ)) row by row."""
    return np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", G, cov, G), 0.0))


@dataclass(kw_only=True)
class _HysteresisModel(OutputErrorPrediction, SingleChannel, FamilyFile):
    """What the hysteresis models share: the protocol's names, the fields below (keyword-only),
    compare, save and the common part of the model file."""

    covariance: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    input_name: str = "u"
    output_name: str = "y"
    input_unit: str = "1"
    output_unit: str = "1"
    fit_percent: float | None = None
    validation_fit_percent: float | None = None
    burn_in: int = 0
    criterion: str = ""

    structure = ""
    fit_definition = HYSTERESIS_FIT
    _file_what = "hysteresis model"
    #: with several estimation records: each one's ``n_samples`` and free-run ``fit_percent``
    records = ()

    def _input(self, data) -> np.ndarray:
        self._check_rate(data, f"{self.structure}.simulate")
        u = _record(data, self.input_name, None, f"{self.structure}.simulate",
                    need_output=False)[0]
        return self._column(data, "input") if isinstance(data, Trajectory) else u

    def _fd_std(self, u: np.ndarray, **run) -> np.ndarray:
        """σ of the free run (N,), the parameter covariance propagated through the Jacobian of
        the run by central differences (step 10⁻³ σ of each free parameter); ``run``: more
        arguments of ``_run`` (the oscillator's initial state, held)."""
        base, sd = self.values(), self.std
        G = np.zeros((len(u), len(self.free)))
        for j, k in enumerate(self.free):
            h = 1e-3 * sd[k] if sd[k] > 0 else 1e-8 * max(abs(base[k]), 1.0)
            hi, lo = dict(base), dict(base)
            hi[k] += h
            lo[k] -= h
            G[:, j] = (self._run(u, hi, **run)[0] - self._run(u, lo, **run)[0]) / (2 * h)
        return _output_std(G, self.covariance)

    def values(self) -> dict:
        """Every parameter of the Bouc-Wen forms by name (``_value_names``), as floats."""
        return {k: float(getattr(self, k)) for k in self._value_names}

    @property
    def std(self) -> dict:
        """1σ of each free parameter (from ``covariance``)."""
        sd = np.sqrt(np.maximum(np.diag(self.covariance), 0.0)) if len(self.free) else []
        return {k: float(s) for k, s in zip(self.free, sd)}

    def compare(self, data, y=None, *, warn: bool = True) -> ModelFit:
        """Free-run fit (%) on a record holding the model's input and output columns: a
        Trajectory, the arrays ``compare(u, y)`` or a pair ``(u, y)``, arrays in the record's
        values (no offset is removed); None (with a StabilityWarning) when the run diverges."""
        u, y, *_ = _record(data if y is None else (data, y), self.input_name, self.output_name,
                           f"{self.structure}.compare")
        if isinstance(data, Trajectory):  # the checks of a record: its rate, its units
            u, y = self._input(data), self._column(data, "output")
        yhat = self.simulate(u, warn=warn)
        return ModelFit(self.outputs, [_fit_percent(y, yhat[:, 0])], yhat, HYSTERESIS_FIT)

    def _measured(self, data, y) -> np.ndarray:
        """The record's output, as :meth:`compare` reads it (for ``residuals``)."""
        y_ = _record(data if y is None else (data, y), self.input_name, self.output_name,
                     f"{self.structure}.residuals")[1]
        return self._column(data, "output") if isinstance(data, Trajectory) else y_

    def _document(self, **own) -> dict:
        """The model file: the schema, the model's ``own`` entries, then what every hysteresis
        model writes."""
        return dict(schema=SCHEMA, version=VERSION, model=self.structure, **own, dt=self.dt,
                    **self.channel_document(),
                    fit_percent=self.fit_percent,
                    validation_fit_percent=self.validation_fit_percent, burn_in=self.burn_in,
                    criterion=self.criterion, fit_definition=HYSTERESIS_FIT,
                    **({"records": list(self.records)} if self.records else {}))

    def _parameter_set(self, docs: dict) -> ParameterSet:
        """The parameters ``docs`` names (name → (description, unit)), in its order, the ones
        not in ``free`` fixed, the free ones with their σ."""
        sd = self.std
        return ParameterSet([_parameter(k, getattr(self, k), unit, doc, sd.get(k),
                                        fixed=k not in self.free)
                             for k, (doc, unit) in docs.items()], self.structure)

    def _summary(self, head: str) -> str:
        """``head`` and a line per parameter: value ± σ (or fixed) and unit."""
        sd = self.std
        rows = [head]
        for p in self.parameters.values():
            s = f" ± {sd[p.name]:.3g}" if p.name in sd else " (fixed)"
            rows.append(f"  {p.name:<7s} {p.value: .6g}{s} {p.unit}")
        return "\n".join(rows)


# ---------------------------------------------------------------------------------------------
# Bouc-Wen


_BW_NAMES = ("d", "alpha", "beta", "gamma", "n", "offset")


@dataclass
class BoucWenModel(_HysteresisModel):
    """Generic Bouc-Wen hysteresis, actuator form (module docstring): y = d u − h + offset.

    ``free``: the names estimated, in the order of ``covariance``; the others are held (n = 1 by
    default, offset 0 with ``offset=False``)."""

    d: float
    alpha: float
    beta: float
    gamma: float
    n: float = 1.0
    offset: float = 0.0
    free: tuple = ("d", "alpha", "beta", "gamma", "offset")
    dt: float | None = None

    structure = "bouc-wen"
    _family = "a Bouc-Wen hysteresis model"
    _rate_dependent = False  # only the path of u matters (module docstring)
    _value_names = _BW_NAMES

    @property
    def lam(self) -> float:
        """λ = α d of the seed's eq 3 (unit of d)."""
        return self.alpha * self.d

    def saturation(self) -> float:
        """|h| a long monotone sweep tends to, (α d / (β + γ))^(1/n); inf when β + γ ≤ 0."""
        c = self.beta + self.gamma
        return (abs(self.lam) / c) ** (1.0 / self.n) if c > 0 else math.inf

    @property
    def parameters(self) -> ParameterSet:
        uu, yu = self.input_unit, self.output_unit
        shape = _ratio("1", uu) if self.n == 1.0 else f"1/({uu}*{yu}^{self.n - 1:g})"
        return self._parameter_set({
            "d": ("gain: output per unit input without hysteresis", _ratio(yu, uu)),
            "alpha": ("α: amplitude of the hysteresis (λ = α d in eq 3)", "1"),
            "beta": ("β: shape of the hysteresis (eq 3)", shape),
            "gamma": ("γ: shape of the hysteresis (eq 3)", shape),
            "n": ("exponent n of |h| (n = 1: eq 3)", "1"),
            "offset": ("output offset c", yu if not _unitless(yu) else "1")})

    def _run(self, u: np.ndarray, theta: dict | None = None) -> tuple[np.ndarray, int]:
        p = self.values() if theta is None else theta
        y = np.empty(len(u))
        at = K.bw_simulate(u, p["d"], p["alpha"], p["beta"], p["gamma"], p["n"], p["offset"],
                           0.0, float(u[0]), y)
        return y, at

    def simulate(self, data, x0=None, *, std: bool = False, warn: bool = True):
        """Free run (N, 1) on the input column of ``data`` (a Trajectory, or an array (N,) of the
        record's values), from h = 0 at the first sample (a given ``x0`` is refused: the model
        has no settable initial state). ``std=True`` also returns σ of ŷ (N, 1), propagated
        from the parameter covariance through the Jacobian of the run (central differences,
        step 10⁻³ σ)."""
        self._refuse_x0(x0, "the relaxed state h = 0 at the first input sample", _HISTORY_HINT)
        u = self._input(data)
        y, at = self._run(u)
        if at >= 0 and warn:
            emit_warning(f"bouc-wen: the free run diverges at sample {at} (β + γ = "
                         f"{self.beta + self.gamma:.4g} ≤ 0 lets h grow without bound?)",
                         StabilityWarning)
        if not std:
            return y[:, None]
        return y[:, None], self._fd_std(u)[:, None]

    def to_dict(self) -> dict:
        return self._document(**self.values(), free=list(self.free),
                              covariance=np.asarray(self.covariance).tolist(), std=self.std)

    def summary(self) -> str:
        how = " estimated" if "n" in self.free else ""
        return self._summary(f"Bouc-Wen (actuator form, n = {self.n:g}{how}): y = d u − h + c  "
                             f"({self.criterion})")


def _free_run_covariance(res, n_scored: int, family: str) -> np.ndarray:
    """``cov θ = s² (JᵀJ)⁺``, ``s² = SSE/(N − p)``, of a ``scipy.optimize.least_squares`` result
    on ``n_scored`` residuals (J of the free run at the optimum); an AccuracyWarning when JᵀJ is
    singular to working precision."""
    dof = max(n_scored - len(res.x), 1)
    s2 = 2.0 * res.cost / dof
    JtJ = res.jac.T @ res.jac
    if np.linalg.cond(JtJ) > 1e14:
        emit_warning(f"{family}: the parameters are nearly unidentifiable from this record (JᵀJ "
                     "singular to working precision); their σ are unreliable: excite loops of "
                     "several amplitudes", AccuracyWarning)
    return s2 * np.linalg.pinv(JtJ)


def _scaled_bw(theta_s, names, fixed, su, sy):
    """Physical Bouc-Wen parameters from the scaled ones (u/su, y/sy)."""
    p = dict(fixed)
    p.update(zip(names, theta_s))
    n = p["n"]
    k = 1.0 / (su * sy ** (n - 1.0))
    return {"d": p["d"] * sy / su, "alpha": p["alpha"], "beta": p["beta"] * k,
            "gamma": p["gamma"] * k, "n": n, "offset": p["offset"] * sy}


def _bw_transform_jacobian(theta_s, names, fixed, su, sy) -> np.ndarray:
    """∂(physical)/∂(scaled) over ``names`` (analytic: diagonal but for ∂β/∂n, ∂γ/∂n)."""
    phys = _scaled_bw(theta_s, names, fixed, su, sy)
    n = phys["n"]
    k = 1.0 / (su * sy ** (n - 1.0))
    diag = {"d": sy / su, "alpha": 1.0, "beta": k, "gamma": k, "n": 1.0, "offset": sy}
    T = np.diag([diag[x] for x in names])
    if "n" in names:
        j = names.index("n")
        for g in ("beta", "gamma"):
            if g in names:
                T[names.index(g), j] = -phys[g] * math.log(sy)
    return T


def _fit_bouc_wen(recs, *, exponent, offset, burn_in, multistart, progress):
    """Bouc-Wen (actuator form) on the records ``recs`` (a list of ``(u, y)``), each run from
    h = 0 at its own first sample, its first ``burn_in`` samples not scored; one least squares
    over all of them."""
    from scipy.optimize import least_squares

    u = np.concatenate([r[0] for r in recs])
    y = np.concatenate([r[1] for r in recs])
    su = 0.5 * float(np.ptp(u))
    sy = 0.5 * float(np.ptp(y))
    us, ys = u / su, y / sy
    bounds = np.cumsum([0] + [len(r[0]) for r in recs])
    n_free = exponent == "free"
    n0 = 1.0 if n_free else float(exponent)
    names = ["d", "alpha", "beta", "gamma"] + (["n"] if n_free else []) + (
        ["offset"] if offset else [])
    fixed = {"n": n0, "offset": 0.0}
    lo = {"d": -np.inf, "alpha": 0.0, "beta": 0.0, "gamma": -np.inf, "n": 1.0, "offset": -np.inf}
    hi = {"d": np.inf, "alpha": np.inf, "beta": np.inf, "gamma": np.inf, "n": 10.0,
          "offset": np.inf}
    # starting values: the straight line through the loop, and its half width as |h| reached
    A = np.column_stack([us, np.ones_like(us)])
    slope, icpt = np.linalg.lstsq(A, ys, rcond=None)[0]
    e = ys - A @ np.array([slope, icpt])
    hs = max(0.25 * float(np.ptp(e)), 1e-3)
    d0 = slope if abs(slope) > 1e-6 else 1.0
    starts = []
    for c0 in (2.0, 8.0, 0.5, 30.0):
        for ratio in (0.3, -0.3):
            beta0 = c0 / (1.0 + ratio)
            gamma0 = ratio * beta0
            alpha0 = hs ** n0 * c0 / abs(d0)
            p0 = {"d": d0, "alpha": alpha0, "beta": beta0, "gamma": gamma0, "n": n0,
                  "offset": float(ys[0] - d0 * us[0]) if offset else 0.0}
            starts.append(np.array([p0[k] for k in names]))
    starts = starts[:max(1, int(multistart))]
    scored = np.concatenate([np.arange(a + burn_in, b) for a, b in zip(bounds, bounds[1:])])
    target = ys[scored]
    buf = np.empty(len(us))

    def resid(th):
        p = dict(fixed)
        p.update(zip(names, th))
        for a, b in zip(bounds, bounds[1:]):  # every record from h = 0 at its first sample
            K.bw_simulate(us[a:b], p["d"], p["alpha"], p["beta"], p["gamma"], p["n"],
                          p["offset"], 0.0, float(us[a]), buf[a:b])
        r = buf[scored] - target
        return np.where(np.isfinite(r), r, 1e3)

    best = None
    for x0 in track(starts, description="bouc-wen fit", enabled=progress):
        x0 = np.clip(x0, [lo[k] + 1e-9 if np.isfinite(lo[k]) else -np.inf for k in names],
                     [hi[k] - 1e-9 if np.isfinite(hi[k]) else np.inf for k in names])
        res = least_squares(resid, x0, bounds=([lo[k] for k in names], [hi[k] for k in names]),
                            x_scale="jac", method="trf", xtol=1e-12, ftol=1e-12, gtol=1e-12,
                            max_nfev=400 * len(names))
        if best is None or res.cost < best.cost:
            best = res
    if best is None or not np.isfinite(best.cost):
        raise IdentificationError("bouc-wen: no starting point gave a finite free run; check that "
                                  "the output follows the input")
    cov_s = _free_run_covariance(best, len(target), "bouc-wen")
    T = _bw_transform_jacobian(best.x, names, fixed, su, sy)
    phys = _scaled_bw(best.x, names, fixed, su, sy)
    return phys, tuple(names), T @ cov_s @ T.T


# ---------------------------------------------------------------------------------------------
# Bouc-Wen, oscillator form


_BWO_NAMES = ("mass", "damping", "k_e", "k_h", "beta", "gamma", "n", "offset")
#: the oscillator's state at a record's first sample: x, ẋ, z (``initial_states`` entries)
STATE_NAMES = ("x0", "v0", "z0")
#: the oscillator's starting points are fitted on this many samples first (then the whole record)
WARM_SAMPLES = 5000


@dataclass
class BoucWenOscillatorModel(_HysteresisModel):
    """Bouc-Wen oscillator (Wen 1976, with A = 1, which fixes the scale of z)::

        mass ẍ + damping ẋ + k_e x + k_h z = u,   ż = ẋ − β |ẋ| z |z|^(n−1) − γ ẋ |z|^n

    output y = x + offset; u a force, x a displacement, z the hysteretic displacement (unit of
    x), k_e the elastic and k_h the hysteretic stiffness (k_e = a k, k_h = (1 − a) k of Wen's
    α-form). Rate dependent: simulated from rest (or from a given state ``x0``) with the input
    held over each sample of ``dt``, ``substeps`` Runge-Kutta steps per sample.

    ``initial_state_option``: how the estimation records started (``'zero'``: each from rest;
    ``'estimate'``: each record's (x, ẋ, z) at its first scored sample estimated with θ).
    ``initial_states``: with ``'estimate'``, one entry per estimation record, ``{"x0": x,
    "v0": ẋ, "z0": z, "std": {"x0": σ, …}, "sample": k}`` (x, z in the output's unit without the
    offset, ẋ in that unit per second; the state at sample k = ``burn_in`` of the record):
    nuisance parameters of those records, not in :attr:`parameters` and not used on other data
    (``simulate(record_input[k:], x0=m.initial_states[i])`` replays record i)."""

    mass: float
    damping: float
    k_e: float
    k_h: float
    beta: float
    gamma: float
    n: float = 1.0
    offset: float = 0.0
    dt: float = 1.0
    substeps: int = 4
    free: tuple = ("mass", "damping", "k_e", "k_h", "beta", "gamma", "offset")
    initial_state_option: str = "zero"
    initial_states: list = field(default_factory=list)

    structure = "bouc-wen-oscillator"
    _family = "a Bouc-Wen oscillator model"
    _value_names = _BWO_NAMES

    @property
    def parameters(self) -> ParameterSet:
        uu, yu = self.input_unit, self.output_unit
        k_unit = _ratio(uu, yu)
        shape = _ratio("1", yu) if self.n == 1.0 else f"1/{yu}^{self.n:g}"
        return self._parameter_set({
            "mass": ("mass: input per unit acceleration", f"{k_unit}*s^2"),
            "damping": ("viscous damping: input per unit velocity", f"{k_unit}*s"),
            "k_e": ("elastic stiffness k_e (a k of Wen's form)", k_unit),
            "k_h": ("hysteretic stiffness k_h ((1 − a) k of Wen's form)", k_unit),
            "beta": ("β: shape of the hysteresis (A = 1)", shape),
            "gamma": ("γ: shape of the hysteresis (A = 1)", shape),
            "n": ("exponent n of |z|", "1"),
            "offset": ("output offset", yu if not _unitless(yu) else "1")})

    def _run(self, u: np.ndarray, theta: dict | None = None,
             x0=(0.0, 0.0, 0.0)) -> tuple[np.ndarray, int]:
        p = self.values() if theta is None else theta
        y = np.empty(len(u))
        at = K.bwo_simulate(u, float(self.dt), int(self.substeps), _bwo_tuple(p), p["offset"],
                            (float(x0[0]), float(x0[1]), float(x0[2])), y)
        return y, at

    @staticmethod
    def _state(x0) -> tuple[float, float, float]:
        """``x0`` as (x, ẋ, z): rest for None; a sequence of three numbers, or a mapping with
        ``x0``, ``v0``, ``z0`` (an entry of ``initial_states``)."""
        if x0 is None:
            return 0.0, 0.0, 0.0
        try:
            v = [x0[k] for k in STATE_NAMES] if isinstance(x0, dict) else list(x0)
            v = [float(q) for q in v]
        except (KeyError, TypeError, ValueError):
            v = None
        if v is None or len(v) != 3 or not all(math.isfinite(q) for q in v):
            raise ArgumentError(f"bouc-wen-oscillator.simulate: x0 must be the state (x, ẋ, z) "
                                f"at the first sample, three finite numbers or a mapping with "
                                f"x0, v0, z0 (an entry of initial_states), found {x0!r}")
        return v[0], v[1], v[2]

    def simulate(self, data, x0=None, *, std: bool = False, warn: bool = True):
        """Free run (N, 1) on the input column of ``data`` (a Trajectory sampled at the model's
        dt, or an array (N,) of the record's values), from rest (what ``compare`` scores), or
        from ``x0`` = (x, ẋ, z) at the first sample (x and
        z in the output's unit without the offset, ẋ per second; or an entry of
        ``initial_states``). ``std=True`` also returns σ of ŷ (N, 1), propagated from the
        parameter covariance (central differences, step 10⁻³ σ; x0 held)."""
        u = self._input(data)
        x0 = self._state(x0)
        y, at = self._run(u, x0=x0)
        if at >= 0 and warn:
            emit_warning(f"bouc-wen-oscillator: the free run diverges at sample {at}; the model "
                         "is unstable on this input", StabilityWarning)
        if not std:
            return y[:, None]
        return y[:, None], self._fd_std(u, x0=x0)[:, None]

    def to_dict(self) -> dict:
        return self._document(**self.values(), substeps=int(self.substeps), free=list(self.free),
                              covariance=np.asarray(self.covariance).tolist(), std=self.std,
                              initial_state=self.initial_state_option,
                              initial_states=[dict(s, std=dict(s["std"]))
                                              for s in self.initial_states])

    def summary(self) -> str:
        text = self._summary(f"Bouc-Wen oscillator (n = {self.n:g}, A = 1): mass x'' + damping "
                             f"x' + k_e x + k_h z = u  ({self.criterion})")
        yu = "" if _unitless(self.output_unit) else f" {self.output_unit}"
        vu = _ratio(self.output_unit, "s")
        rows = []
        for i, s in enumerate(self.initial_states):
            at = f" at sample {s['sample']}" if s.get("sample") else ""
            sd = s["std"]
            rows.append(f"  record {i}{at}: x0 = {s['x0']:.6g} ± {sd['x0']:.3g}{yu}, "
                        f"x'0 = {s['v0']:.6g} ± {sd['v0']:.3g} {vu}, "
                        f"z0 = {s['z0']:.6g} ± {sd['z0']:.3g}{yu}")
        if rows:
            rows.insert(0, "initial state of each estimation record (nuisance, not parameters):")
        return "\n".join([text, *rows])


def _linear_start(recs, dt):
    """(mass, damping, k) of the second-order model nearest the records ``recs`` (a list of
    ``(u, y)``): a least-squares ARX [2 2 1] with a constant over every record's own rows (none
    spans two records), its poles mapped to s = ln z / dt and its static gain to 1/k."""
    A = np.vstack([np.column_stack([y[1:-1], y[:-2], u[1:-1], u[:-2], np.ones(len(y) - 2)])
                   for u, y in recs])
    a1, a2, b1, b2, _ = np.linalg.lstsq(A, np.concatenate([y[2:] for _, y in recs]),
                                        rcond=None)[0]
    roots = np.roots([1.0, -a1, -a2]).astype(complex)
    gain = (b1 + b2) / (1.0 - a1 - a2) if a1 + a2 != 1.0 else 0.0
    if np.all(np.abs(roots) < 1) and np.all(np.abs(roots) > 0) and gain > 0:
        s = np.log(roots) / dt
        w2 = float(np.real(s[0] * s[1]))
        two_zw = float(-np.real(s[0] + s[1]))
        if w2 > 0 and two_zw > 0:
            k = 1.0 / gain
            return k / w2, two_zw * k / w2, k
    u = np.concatenate([r[0] for r in recs])
    k = float(np.ptp(u) / np.ptp(np.concatenate([r[1] for r in recs])))
    w = 0.1 * math.pi / dt  # fallback: a tenth of Nyquist, ζ = 0.2
    return k / w**2, 0.4 * k / w, k


def _oscillator_starts(recs, dt, exponent, offset, multistart):
    """The oscillator's free names, held values, bounds and ``multistart`` starting points (each
    inside the bounds) on the scaled records ``recs``: the second-order model nearest the data
    split into elastic and hysteretic stiffness, z saturating at a fraction of the output's
    amplitude."""
    n_free = exponent == "free"
    n0 = 1.0 if n_free else float(exponent)
    names = ["mass", "damping", "k_e", "k_h", "beta", "gamma"] + (["n"] if n_free else []) + (
        ["offset"] if offset else [])
    fixed = {"n": n0, "offset": 0.0}
    lo = {"mass": 0.0, "damping": 0.0, "k_e": -np.inf, "k_h": -np.inf, "beta": 0.0,
          "gamma": -np.inf, "n": 1.0, "offset": -np.inf}
    hi = {k: np.inf for k in lo} | {"n": 10.0}
    m0, c0, k0 = _linear_start(recs, dt)
    y_amp = 0.5 * float(np.ptp(np.concatenate([y for _, y in recs])))
    starts = []
    for frac, q in ((0.5, 0.1), (0.8, 0.1), (0.5, 0.02), (0.8, 0.3), (0.3, 0.05)):
        bg = (1.0 / (q * y_amp)) ** n0  # z saturates at (1/(β+γ))^(1/n) = q × the amplitude
        p0 = {"mass": m0, "damping": c0, "k_e": frac * k0, "k_h": (1 - frac) * k0,
              "beta": bg / 1.3, "gamma": 0.3 * bg / 1.3, "n": n0,
              "offset": float(recs[0][1][0]) if offset else 0.0}
        starts.append(np.array([p0[k] for k in names]))
    lb = np.array([lo[k] for k in names])
    ub = np.array([hi[k] for k in names])
    starts = [np.clip(x0, np.where(np.isfinite(lb), lb + 1e-9, -np.inf),
                      np.where(np.isfinite(ub), ub - 1e-9, np.inf))
              for x0 in starts[:max(1, int(multistart))]]
    return names, fixed, (lb, ub), starts


def _oscillator_physical(theta_s, names, fixed, cov_s, su, sy):
    """The oscillator's physical parameters and the covariance of the whole vector from the
    scaled fit (u/su, y/sy): force-like parameters scale by sy/su, β and γ by sy^−n, the offset
    by sy; entries past ``names`` (the records' initial states x0, ẋ0, z0) by sy."""
    p = dict(fixed)
    p.update(zip(names, theta_s))
    n = p["n"]
    g = sy / su
    phys = {"mass": p["mass"] / g, "damping": p["damping"] / g, "k_e": p["k_e"] / g,
            "k_h": p["k_h"] / g, "beta": p["beta"] * sy ** -n, "gamma": p["gamma"] * sy ** -n,
            "n": n, "offset": p["offset"] * sy}
    diag = {"mass": 1 / g, "damping": 1 / g, "k_e": 1 / g, "k_h": 1 / g, "beta": sy ** -n,
            "gamma": sy ** -n, "n": 1.0, "offset": sy}
    T = np.diag([diag[k] for k in names] + [sy] * (len(cov_s) - len(names)))
    if "n" in names:
        for k in ("beta", "gamma"):
            T[names.index(k), names.index("n")] = -phys[k] * math.log(sy)
    return phys, T @ cov_s @ T.T


#: the options of the oscillator's initial state at each record's first sample
INITIAL_STATES = ("estimate", "zero")
#: the samples whose quadratic gives the start of a record's (x0, ẋ0) when they are estimated
X0_SAMPLES = 15


def _initial_state_start(u, y, dt, offset0):
    """(x0, ẋ0, z0) to start the estimate of a scaled record's initial state from: value and
    slope at the first sample of the quadratic through its first :data:`X0_SAMPLES` outputs,
    z0 = 0."""
    k = min(X0_SAMPLES, len(y))
    c = np.polyfit(np.arange(k) * dt, y[:k], 2)
    return np.array([c[2] - offset0, c[1], 0.0])


def _fd_step(x: float, lo: float, hi: float) -> float:
    """The forward-difference step of ``scipy.optimize.least_squares``' '2-point' Jacobian:
    √ε sign(x) max(1, |x|), turned back where it would leave [lo, hi]; the step as represented
    ((x + h) − x)."""
    h = math.sqrt(np.finfo(float).eps) * (1.0 if x >= 0 else -1.0) * max(1.0, abs(x))
    if not lo <= x + h <= hi:
        h = -h
    return (x + h) - x


def _fit_bouc_wen_oscillator(recs, dt, *, exponent, offset, burn_in, multistart, substeps,
                             progress, initial_state="zero"):
    """The Bouc-Wen oscillator on the records ``recs`` (a list of ``(u, y)``), each run from its
    own first sample, its first ``burn_in`` samples not scored; one least squares over all of
    them (σ from the Jacobian over all). ``initial_state='zero'``: every record from rest;
    ``'estimate'``: each record's (x0, ẋ0, z0) at its first sample estimated with θ (three
    nuisance parameters a record, their columns of the Jacobian by the same forward differences
    as θ's, each from a run of its own record only).

    Returns (physical θ, free names, cov θ, initial states): the last a list per record of
    ``{"x0", "v0", "z0", "std": {…}}`` (empty for ``'zero'``); cov θ is the θ block of the
    covariance of θ and the initial states together."""
    from scipy.optimize import least_squares

    u = np.concatenate([r[0] for r in recs])
    y = np.concatenate([r[1] for r in recs])
    su = 0.5 * float(np.ptp(u))
    sy = 0.5 * float(np.ptp(y))
    us, ys = u / su, y / sy
    first = np.cumsum([0] + [len(r[0]) for r in recs])[:-1]
    lengths = [len(r[0]) for r in recs]
    names, fixed, (lb, ub), starts = _oscillator_starts(
        [(us[a:a + n], ys[a:a + n]) for a, n in zip(first, lengths)], dt, exponent, offset,
        multistart)
    npar = len(names)
    est = initial_state == "estimate"
    s0 = np.zeros(0)
    if est:
        s0 = _initial_state_guesses(us, ys, first, lengths, dt, names, starts)
        lb = np.concatenate([lb, np.full(len(s0), -np.inf)])
        ub = np.concatenate([ub, np.full(len(s0), np.inf)])
    buf = np.empty(len(us))

    def params(th):
        p = dict(fixed)
        p.update(zip(names, th[:npar]))
        return p

    def run(i, p, th, e):  # record i from its initial state, its residual on burn_in … e − 1
        a = first[i]
        k = npar + 3 * i
        x0, v0, z0 = (th[k:k + 3] if len(th) > npar else s0[3 * i:3 * i + 3]) if est else (
            0.0, 0.0, 0.0)
        K.bwo_simulate(us[a:a + e], dt, substeps, _bwo_tuple(p), p["offset"],
                       (float(x0), float(v0), float(z0)), buf[a:a + e])
        r = buf[a + burn_in:a + e] - ys[a + burn_in:a + e]
        return np.clip(np.where(np.isfinite(r), r, 1e3), -1e3, 1e3)

    last = {}

    def resid(th, ends=lengths):
        key = (th.tobytes(), tuple(ends))
        if key not in last:
            p = params(th)
            last.clear()
            last[key] = np.concatenate([run(i, p, th, e) for i, e in enumerate(ends)])
        return last[key].copy()

    def jac(th, ends=lengths):
        return _oscillator_jacobian(resid(th, ends), th, ends, (run, params), (lb, ub), npar,
                                    burn_in)

    # the starts in order of their initial cost, each to convergence on the first
    # WARM_SAMPLES samples (shared out among the records), until one reproduces them to a fit of
    # 90 % (a free run of a rate-dependent model is costly, and a long record makes a poor start
    # crawl); then the best one refined on the whole records. With initial states estimated the
    # starts are tried with each record's state held at its start (the value and slope of its
    # first samples, z = 0), then θ and every state refined together
    ends = [min(n, burn_in + WARM_SAMPLES // len(recs)) for n in lengths]
    warm = (ends,)
    starts.sort(key=lambda x0: float(np.sum(resid(x0, *warm) ** 2)))
    short = np.concatenate([ys[a + burn_in:a + e] for a, e in zip(first, ends)])
    good = 0.01 * float(np.sum((short - short.mean()) ** 2))
    opts = dict(jac=jac, bounds=(lb[:npar], ub[:npar]), x_scale="jac", method="trf",
                xtol=1e-10, ftol=1e-10, gtol=1e-10, max_nfev=100 * npar)
    best = _first_good_fit(resid, starts, warm, opts, good, progress)
    if est:  # θ and every record's initial state together, on the whole records
        best = least_squares(resid, np.concatenate([best.x, s0]),
                             **(opts | dict(bounds=(lb, ub), max_nfev=100 * len(lb))))
    elif ends != lengths:
        best = least_squares(resid, best.x, **opts)
    cov_s = _free_run_covariance(best, len(y) - burn_in * len(recs), "bouc-wen-oscillator")
    phys, cov = _oscillator_physical(best.x, names, fixed, cov_s, su, sy)
    states = [_state_entry(best.x, cov, npar + 3 * i, sy) for i in range(len(recs) if est else 0)]
    return phys, tuple(names), cov[:npar, :npar], states


def _oscillator_jacobian(f0, th, ends, fns, bounds, npar: int, burn_in: int) -> np.ndarray:
    """Forward differences of the oscillator's residuals ``f0`` at ``th`` (scipy's '2-point'
    steps, :func:`_fd_step`): a θ column from a run of every record, a record's initial-state
    column from a run of that record alone (zero on the other records' rows). ``fns``: the fit's
    ``run(i, p, th, end)`` and ``params(th)``; ``bounds``: (lb, ub)."""
    run, params = fns
    lb, ub = bounds
    rows = np.cumsum([0] + [e - burn_in for e in ends])
    J = np.zeros((len(f0), len(th)))
    p0 = params(th)
    for j in range(len(th)):
        t = th.copy()
        h = _fd_step(th[j], lb[j], ub[j])
        t[j] += h
        if j < npar:
            p = params(t)
            J[:, j] = (np.concatenate([run(i, p, t, e) for i, e in enumerate(ends)]) - f0) / h
        else:
            i = (j - npar) // 3
            r = slice(rows[i], rows[i + 1])
            J[r, j] = (run(i, p0, t, ends[i]) - f0[r]) / h
    return J


def _initial_state_guesses(us, ys, first, lengths, dt, names, starts) -> np.ndarray:
    """The oscillator's scaled initial states to start from, three a record
    (:func:`_initial_state_start`), with the output offset of every start in ``starts`` set from
    the mean static line (in place) when the offset is free."""
    off0 = 0.0
    if "offset" in names:
        k0 = np.mean([x0[names.index("k_e")] + x0[names.index("k_h")] for x0 in starts])
        off0 = float(np.mean(ys) - np.mean(us) / k0)
        for x0 in starts:
            x0[names.index("offset")] = off0
    return np.concatenate([_initial_state_start(us[a:a + n], ys[a:a + n], dt, off0)
                           for a, n in zip(first, lengths)])


def _first_good_fit(resid, starts, warm, opts, good, progress):
    """``least_squares`` from each start in turn (on the ``warm`` samples) until one's cost is
    below ``good``/2; the best result."""
    from scipy.optimize import least_squares

    best = None
    for x0 in track(starts, description="bouc-wen oscillator fit", enabled=progress):
        res = least_squares(resid, x0, args=warm, **opts)
        if best is None or res.cost < best.cost:
            best = res
        if 2.0 * best.cost < good:
            break
    return best


def _state_entry(x, cov, k: int, sy: float) -> dict:
    """One record's initial state (x, ẋ, z) from the scaled estimate ``x[k:k + 3]`` with σ from
    the physical covariance ``cov``."""
    sd = np.sqrt(np.maximum(np.diag(cov)[k:k + 3], 0.0))
    return {**{q: float(sy * x[k + j]) for j, q in enumerate(STATE_NAMES)},
            "std": {q: float(sd[j]) for j, q in enumerate(STATE_NAMES)}}


def _bwo_tuple(p) -> tuple:
    """The oscillator's parameters as its kernels take them: (m, c, k_e, k_h, β, γ, n)."""
    return tuple(float(p[k]) for k in _BWO_NAMES[:7])


# ---------------------------------------------------------------------------------------------
# Prandtl–Ishlinskii


def pi_inverse(thresholds, weights) -> tuple[np.ndarray, np.ndarray]:
    """Thresholds and weights of the inverse PI operator (Kuhnen 2003, eq 18; module docstring).
    Needs r_0 = 0 < r_1 < … and every partial sum W_i = Σ_{j≤i} w_j > 0."""
    r = np.asarray(thresholds, dtype=np.float64)
    w = np.asarray(weights, dtype=np.float64)
    if r.ndim != 1 or r.shape != w.shape or len(r) == 0:
        raise ModelError(f"pi_inverse: thresholds {r.shape} and weights {w.shape} must be two "
                         "1-D arrays of equal length")
    if r[0] != 0.0 or np.any(np.diff(r) <= 0):
        raise ModelError("prandtl-ishlinskii invert: the thresholds must start at 0 and increase "
                         f"strictly, found {r.tolist()}")
    W = np.cumsum(w)
    if not (w[0] > 0 and np.all(W > 0)):
        bad = int(np.argmax(~(W > 0))) if w[0] > 0 else 0
        raise ModelError(f"prandtl-ishlinskii invert: the model is not invertible: the weight sum "
                         f"W_{bad} = Σ_(j≤{bad}) w_j = {W[bad]:.4g} must be > 0 (w_0 = {w[0]:.4g} "
                         "is the slope of the loop's branches at a reversal)",
                         hint="refit with more data near the reversals, or with fewer operators")
    rh = np.array([float(np.sum(w[:i + 1] * (r[i] - r[:i + 1]))) for i in range(len(r))])
    wh = np.empty_like(w)
    wh[0] = 1.0 / w[0]
    wh[1:] = -w[1:] / (W[1:] * W[:-1])
    return rh, wh


@dataclass
class PrandtlIshlinskiiModel(_HysteresisModel):
    """``y = offset + Σ_i weights[i] · play(thresholds[i])[u − input_offset]`` (module docstring).
    ``covariance`` is over the weights then the offset (when ``fit_offset``)."""

    thresholds: np.ndarray
    weights: np.ndarray
    offset: float = 0.0
    input_offset: float = 0.0
    fit_offset: bool = True
    dt: float | None = None

    structure = "prandtl-ishlinskii"
    _family = "a Prandtl–Ishlinskii model"
    _rate_dependent = False  # the play operators see the path of u only

    @property
    def weights_std(self) -> np.ndarray:
        """1σ of each weight; NaN (not determined) where the covariance's diagonal is not
        positive: with collinear play operators the pseudo-inverse leaves some variances at
        zero or below by rounding, which a "± 0" would report as exact (an all-zero covariance,
        a noiseless fit, gives 0)."""
        m = len(self.weights)
        if self.covariance.shape[0] < m:
            return np.full(m, np.nan)
        var = np.diag(self.covariance)[:m]
        if not np.any(self.covariance):
            return np.zeros(m)
        with np.errstate(invalid="ignore"):
            return np.where(var > 0.0, np.sqrt(np.abs(var)), np.nan)

    @property
    def parameters(self) -> ParameterSet:
        uu, yu = self.input_unit, self.output_unit
        sd = self.weights_std
        ps = [_parameter(f"w_{i}", w, _ratio(yu, uu), f"weight of the play of threshold r_{i}",
                         sd[i] if self.covariance.size else None, fixed=not self.covariance.size)
              for i, w in enumerate(self.weights)]
        ps += [_parameter(f"r_{i}", r, uu, f"threshold of play operator {i} (chosen, not fitted)",
                          fixed=True) for i, r in enumerate(self.thresholds)]
        osd = (math.sqrt(max(self.covariance[-1, -1], 0.0))
               if self.fit_offset and self.covariance.size else None)
        ps.append(_parameter("offset", self.offset, yu, "output offset c", osd,
                             fixed=osd is None))
        ps.append(_parameter("input_offset", self.input_offset, uu, "input offset a", fixed=True))
        return ParameterSet(ps, "prandtl-ishlinskii")

    @property
    def std(self) -> dict:
        """1σ of each fitted parameter by its name in :attr:`parameters` (``w_i``, ``offset``
        when fitted); empty for a model without covariance (an inverse)."""
        return {p.name: p.std for p in self.parameters.values() if p.std is not None}

    def _play_matrix(self, u: np.ndarray) -> np.ndarray:
        P = np.empty((len(u), len(self.thresholds)))
        K.play_matrix(u - self.input_offset, np.asarray(self.thresholds, dtype=np.float64), P)
        return P

    def simulate(self, data, x0=None, *, std: bool = False, warn: bool = True):
        """Output (N, 1) for the input column of ``data`` (a Trajectory or an array (N,) of the
        record's values), every play relaxed at the first sample (a given ``x0`` is refused).
        ``std=True`` also returns σ of ŷ (N, 1) from the covariance of the weights (and
        offset): the model is linear in them, so it is exact."""
        self._refuse_x0(x0, "every play relaxed at the first input sample (F_r = u(0) − a)",
                        _HISTORY_HINT)
        u = self._input(data)
        y = np.empty(len(u))
        K.pi_simulate(u - self.input_offset, np.asarray(self.thresholds, dtype=np.float64),
                      np.asarray(self.weights, dtype=np.float64), float(self.offset), y)
        if not std:
            return y[:, None]
        G = self._play_matrix(u)
        if self.fit_offset:
            G = np.column_stack([G, np.ones(len(u))])
        if self.covariance.shape != (G.shape[1], G.shape[1]):
            raise ModelError("prandtl-ishlinskii: this model has no parameter covariance (an "
                             "inverse, or read from a file without one); std=True needs one")
        return y[:, None], _output_std(G, self.covariance)[:, None]

    def invert(self) -> "PrandtlIshlinskiiModel":
        """The inverse operator, a PI model from the model's output column to its input column:
        ``inverse.simulate(model.simulate(u)) == u`` (to rounding) for every input record. It has
        no covariance (its parameters are exact functions of the model's)."""
        rh, wh = pi_inverse(self.thresholds, self.weights)
        return PrandtlIshlinskiiModel(rh, wh, offset=float(self.input_offset),
                                      input_offset=float(self.offset), fit_offset=False,
                                      dt=self.dt, input_name=self.output_name,
                                      output_name=self.input_name, input_unit=self.output_unit,
                                      output_unit=self.input_unit, data_file=self.data_file,
                                      data_hash=self.data_hash,
                                      criterion=f"inverse (Kuhnen 2003) of: {self.criterion}")

    def to_dict(self) -> dict:
        return self._document(thresholds=np.asarray(self.thresholds).tolist(),
                              weights=np.asarray(self.weights).tolist(),
                              weights_std=[None if not np.isfinite(s) else float(s)
                                           for s in self.weights_std],
                              offset=float(self.offset), input_offset=float(self.input_offset),
                              fit_offset=bool(self.fit_offset),
                              covariance=np.asarray(self.covariance).tolist())

    def summary(self) -> str:
        rows = [f"Prandtl-Ishlinskii, {len(self.weights)} play operators ({self.criterion})"]
        sd = self.weights_std
        undetermined = " ± — (not determined by this record)" if self.covariance.size else ""
        for i, (r, w) in enumerate(zip(self.thresholds, self.weights)):
            s = f" ± {sd[i]:.3g}" if np.isfinite(sd[i]) else undetermined
            rows.append(f"  r_{i:<3d} {r: .6g} {self.input_unit:<6s} w_{i:<3d} {w: .6g}{s}")
        osd = self.std.get("offset")
        rows.append(f"  offset {self.offset: .6g}" + (f" ± {osd:.3g}" if osd is not None else "")
                    + f" {self.output_unit}")
        return "\n".join(rows)


def default_thresholds(u: np.ndarray, operators: int) -> np.ndarray:
    """r_i = i R / m, i = 0 … m−1, R half the input's range: every play turns on the largest
    loop."""
    return np.arange(operators) * (0.5 * float(np.ptp(u)) / operators)


def _fit_pi(recs, thresholds, *, offset, burn_in):
    """Prandtl–Ishlinskii weights on the records ``recs`` (a list of ``(u, y)``), every play
    relaxed at each record's own first sample; one least squares over their rows after
    ``burn_in``."""
    from scipy.optimize import lsq_linear

    r = np.asarray(thresholds, dtype=np.float64)
    m = len(r)
    rows = []
    for u, _ in recs:
        P = np.empty((len(u), m))
        K.play_matrix(u, r, P)
        rows.append(P[burn_in:])
    A = np.vstack(rows)
    if offset:
        A = np.column_stack([A, np.ones(len(A))])
    b = np.concatenate([y[burn_in:] for _, y in recs])
    if len(b) < 2 * A.shape[1]:
        raise DataError(f"prandtl-ishlinskii: {len(b)} samples for {A.shape[1]} parameters; "
                        f"give at least {2 * A.shape[1]} or fewer operators")
    s = np.linalg.norm(A, axis=0)
    s[s == 0] = 1.0
    lb = np.r_[np.zeros(m), [-np.inf] if offset else []]
    res = lsq_linear(A / s, b, bounds=(lb, np.full(A.shape[1], np.inf)), method="bvls",
                     tol=1e-12)
    theta = res.x / s
    e = b - A @ theta
    s2 = float(e @ e) / max(len(b) - A.shape[1], 1)
    As = A / s
    G = As.T @ As
    if np.linalg.cond(G) > 1e14:
        emit_warning("prandtl-ishlinskii: the play operators are nearly collinear on this record; "
                     "the σ of the weights are unreliable: use fewer operators or loops of several "
                     "amplitudes", AccuracyWarning)
    cov = s2 * np.linalg.pinv(G) / np.outer(s, s)
    at_bound = int(np.sum(theta[:m] <= 0.0))
    w = theta[:m].copy()
    c = float(theta[m]) if offset else 0.0
    return w, c, cov, at_bound


# ---------------------------------------------------------------------------------------------
# entry point


def _check_int(v, name: str, lo: int) -> int:
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < lo:
        raise ArgumentError(f"hysteresis: {name} must be an integer ≥ {lo}, found {v!r}")
    return int(v)


def _is_records(data) -> bool:
    """``data`` is a list of records (Trajectories or pairs ``(u, y)``), not one pair."""
    if not isinstance(data, (list, tuple)):
        return False
    if any(isinstance(d, Trajectory) for d in data):
        return True
    return bool(data) and all(isinstance(d, (list, tuple)) and len(d) == 2 for d in data)


def _records(data, input, output):
    """Several records → ``(recs, dt, iname, oname, iunit, ounit)``, each record checked as one
    is, its errors naming ``data[i]``; every record sampled alike and in the same units."""
    if not data:
        raise DataError("hysteresis: data must be a Trajectory, a pair (u, y) or a non-empty list "
                        "of them, found an empty list")
    recs, first = [], None
    for i, d in enumerate(data):
        what = f"hysteresis data[{i}]"
        if not isinstance(d, Trajectory) and not (isinstance(d, (list, tuple)) and len(d) == 2):
            raise DataError(f"{what}: expected a Trajectory or a pair (u, y), found "
                            f"{type(d).__name__}")
        u, y, dt, iname, oname, iunit, ounit = _record(d, input, output, what)
        if first is None:
            first = (dt, iname, oname, iunit, ounit)
        else:
            dt0, _, _, iu0, ou0 = first
            if (dt is None) != (dt0 is None) or (dt is not None and abs(dt - dt0) > 1e-9 * dt0):
                rate = lambda h: "an unknown rate" if h is None else f"{1 / h:g} Hz"  # noqa: E731
                raise DataError(f"{what} is sampled at {rate(dt)}, data[0] at {rate(dt0)}: the "
                                "records of one fit must share the sample interval",
                                hint="resample one of them")
            for col, a, b in ((iname, iu0, iunit), (oname, ou0, ounit)):
                if a != b:
                    raise DataError(f"{what}: column {col!r} is in {b!r}, in data[0] in {a!r}: "
                                    "the records of one fit must use the same units",
                                    hint="convert one of them")
        try:
            _check_excited(u, y, iname, oname)
        except DataError as exc:
            raise DataError(exc.message.replace("hysteresis", what, 1), hint=exc.hint) from None
        recs.append((u, y))
    return (recs, *first)


def _check_burn_in(burn_in, recs) -> int:
    """``burn_in`` as an int ≥ 0 that leaves at least 10 samples of every record to fit."""
    burn_in = _check_int(burn_in, "burn_in", 0)
    for i, (ur, _) in enumerate(recs):
        if burn_in > len(ur) - 10:
            raise ArgumentError(f"hysteresis: burn_in = {burn_in} leaves fewer than 10 of the "
                                f"{len(ur)} samples{f' of data[{i}]' * (len(recs) > 1)} to fit; "
                                "lower it")
    return burn_in


def _bouc_wen_settings(form, exponent, multistart):
    """The Bouc-Wen arguments checked → (multistart, how the model is fitted)."""
    if form not in FORMS:
        raise ArgumentError(f"hysteresis: form must be one of {', '.join(FORMS)}, found "
                            f"{form!r}")
    if not (exponent == "free" or (isinstance(exponent, (int, float, np.floating))
                                   and not isinstance(exponent, bool)
                                   and 1.0 <= exponent <= 10.0)):
        raise ArgumentError(f"hysteresis: exponent must be a number in [1, 10] or 'free', "
                            f"found {exponent!r}")
    multistart = _check_int(multistart, "multistart", 1)
    how = (f"free-run least squares, {multistart} start(s), n "
           + ("estimated" if exponent == "free" else f"= {exponent:g}"))
    return multistart, how


def _check_initial_state(initial_state, oscillator: bool) -> str:
    """``initial_state`` checked; None → 'estimate' for the oscillator, 'zero' otherwise (the
    other models start from their relaxed state, which is not estimated)."""
    if initial_state is None:
        return "estimate" if oscillator else "zero"
    if not (isinstance(initial_state, str) and initial_state in INITIAL_STATES):
        raise ArgumentError(f"hysteresis: initial_state must be one of "
                            f"{', '.join(INITIAL_STATES)} (the oscillator's state at each "
                            f"record's first sample), found {initial_state!r}",
                            hint="'estimate' for records that may start in motion, 'zero' for "
                                 "records known to start at rest")
    if initial_state == "estimate" and not oscillator:
        raise ArgumentError("hysteresis: initial_state='estimate' is for the Bouc-Wen "
                            "oscillator (form='oscillator'); the actuator form and "
                            "Prandtl-Ishlinskii start from their relaxed state",
                            hint="drop initial_state, or give form='oscillator'")
    return initial_state


def _oscillator(recs, dt, exponent, offset, burn_in, multistart, substeps, progress, common,
                how, initial_state) -> BoucWenOscillatorModel:
    """The Bouc-Wen oscillator fitted to the records ``recs``, each from rest at its first
    sample or from its state estimated at its first scored sample (sample ``burn_in``: the
    samples before it are dropped, a state they alone would show is not identifiable) (``common``:
    the model's other fields)."""
    substeps = _check_int(substeps, "substeps", 1)
    if dt is None:
        raise ArgumentError("hysteresis: the Bouc-Wen oscillator is rate dependent: give the "
                            "sample time dt= (or a Trajectory, which has one)")
    est = initial_state == "estimate"
    phys, names, cov, states = _fit_bouc_wen_oscillator(
        [(u[burn_in:], y[burn_in:]) for u, y in recs] if est else recs, float(dt),
        exponent=exponent, offset=offset, burn_in=0 if est else burn_in, multistart=multistart,
        substeps=substeps, progress=progress, initial_state=initial_state)
    for st in states:
        st["sample"] = burn_in
    common["dt"] = float(dt)
    how += (", each record's initial state (x, x', z) estimated" if initial_state == "estimate"
            else ", each record from rest")
    return BoucWenOscillatorModel(**phys, substeps=substeps, free=names, covariance=cov,
                                  initial_state_option=initial_state, initial_states=states,
                                  **common, criterion=how)


def _prandtl_ishlinskii(recs, u, operators, thresholds, offset, burn_in, iname,
                        common) -> PrandtlIshlinskiiModel:
    """The Prandtl–Ishlinskii model of the records (``u`` all their inputs): ``thresholds``, or
    ``operators`` default ones, each below half the input's range; weights ≥ 0."""
    if thresholds is None:
        r = default_thresholds(u, _check_int(operators, "operators", 1))
    else:
        r = np.atleast_1d(np.asarray(thresholds, dtype=np.float64))
        if r.ndim != 1 or r[0] != 0.0 or np.any(np.diff(r) <= 0) or not np.all(np.isfinite(r)):
            raise ArgumentError("hysteresis: thresholds must start at 0 and increase strictly, "
                                f"found {r.tolist()}")
    half = 0.5 * float(np.ptp(u))
    if r[-1] >= half:
        raise DataError(f"hysteresis: the play of threshold {r[-1]:g} is not excited: the "
                        f"input {iname!r} spans only ±{half:g} about its middle, so plays of "
                        f"thresholds ≥ {half:g} never move on a loop",
                        hint="give thresholds below half the input's range, or record a "
                             "wider sweep")
    w, c, cov, at_bound = _fit_pi(recs, r, offset=offset, burn_in=burn_in)
    m = PrandtlIshlinskiiModel(r, w, offset=c, covariance=cov, fit_offset=bool(offset),
                               **common,
                               criterion=f"{len(r)} plays, weights ≥ 0 by bounded least "
                                         f"squares ({at_bound} on the bound 0)")
    if w[0] <= 0:
        emit_warning("prandtl-ishlinskii: w_0 (the play of threshold 0) came out 0, so the "
                     "model has no inverse (invert() will refuse it)", AccuracyWarning)
    return m


def _score_records(m, recs, burn_in: int) -> None:
    """``m.fit_percent`` of the free run over the scored samples; with several records each
    record from its own relaxed state (the oscillator's from its estimated initial state, where
    estimated), the fit over all of them together and each one's in ``m.records``."""
    states = getattr(m, "initial_states", None) or [None] * len(recs)
    runs = [m.simulate(ur)[burn_in:, 0] if s is None else  # a state at sample burn_in
            m.simulate(ur[s["sample"]:], x0=s)[burn_in - s["sample"]:, 0]
            for (ur, _), s in zip(recs, states)]
    if len(recs) == 1:
        m.fit_percent = _fit_percent(recs[0][1][burn_in:], runs[0])
        return
    m.records = [{"n_samples": len(ur), "fit_percent": _fit_percent(yr[burn_in:], s)}
                 for (ur, yr), s in zip(recs, runs)]
    m.fit_percent = _fit_percent(np.concatenate([yr[burn_in:] for _, yr in recs]),
                                 np.concatenate(runs))


def hysteresis(data, model: str = "bouc-wen", *, input: str | None = None,
               output: str | None = None, form: str = "actuator", exponent=1.0,
               operators: int = 10, thresholds=None, offset: bool = True, burn_in: int = 0,
               validate=None, multistart: int = 4, substeps: int = 4, dt: float | None = None,
               initial_state: str | None = None, progress: bool = True):
    """Identify a hysteresis model of ``output`` driven by ``input``.

    ``data``: a Trajectory (columns ``input``, ``output``) or a pair of arrays ``(u, y)``, or a
    list of them: several records fitted by one model (Bouc-Wen, either form, and
    Prandtl–Ishlinskii), each run from its own relaxed state (h = 0, every play at its first
    input, the oscillator at rest: x = ẋ = z = 0) with its own first ``burn_in`` samples
    unscored, all at one sample time, one least squares over all of them (σ from all);
    ``fit_percent`` over all scored samples together, each record's in ``records``.
    ``model``: ``"bouc-wen"`` (actuator form; ``exponent`` n ≥ 1, default 1 = the seed's eq 3, or
    ``"free"`` to estimate it; ``multistart`` starting points; ``form="oscillator"``: the
    rate-dependent Bouc-Wen oscillator :class:`BoucWenOscillatorModel`, from rest, ``substeps``
    RK4 steps per sample, its sample time that of the data or ``dt``) or ``"prandtl-ishlinskii"``
    (``operators`` plays with thresholds ``i R / operators``, or ``thresholds`` given, starting
    at 0 and increasing). ``offset``: fit an output offset c. ``burn_in``: samples simulated but
    not scored (a record that starts mid-loop). ``validate``: a second record (Trajectory or
    pair) scored by the free run, ``validation_fit_percent``. The model's ``fit_percent`` is on
    the estimation record (:data:`HYSTERESIS_FIT`).
    ``initial_state`` (the oscillator form; the other models start relaxed, ``"zero"``):
    ``"estimate"`` (the oscillator's default) estimates each record's
    state (x, ẋ, z) at its first sample jointly with θ (at sample ``burn_in`` when one is given:
    the samples before it are dropped), three nuisance parameters a record with
    σ (``model.initial_states``; θ's σ accounts for them), and the fit runs each record from
    its own; ``"zero"`` runs every record from rest (for records known to start at rest: a
    record that starts in motion biases θ). The validation record and new data are run from
    rest (``simulate(..., x0=...)`` for a known state), as ``compare`` does.

    Raises DataError when the input never reverses (the hysteresis is not excited).
    """
    if model not in MODELS:
        raise ArgumentError(f"hysteresis: model must be one of {', '.join(MODELS)}, found "
                            f"{model!r}")
    if _is_records(data):
        recs, dt0, iname, oname, iunit, ounit = _records(data, input, output)
    else:
        u, y, dt0, iname, oname, iunit, ounit = _record(data, input, output, "hysteresis")
        recs = [(u, y)]
    u = np.concatenate([r[0] for r in recs])
    dt = dt0 if dt is None else dt
    if dt is not None and not (isinstance(dt, (int, float, np.floating)) and math.isfinite(dt)
                               and dt > 0):
        raise ArgumentError(f"hysteresis: dt must be a positive sample interval in s, found {dt!r}")
    if len(recs) == 1:  # too few samples is the data's fault whatever burn_in is
        _check_excited(*recs[0], iname, oname)
    burn_in = _check_burn_in(burn_in, recs)
    if validate is not None:
        uv, yv, *_ = _record(validate, iname, oname, "hysteresis validate")
    common = dict(dt=dt, input_name=iname, output_name=oname, input_unit=iunit,
                  output_unit=ounit, burn_in=burn_in)
    initial_state = _check_initial_state(initial_state, model == "bouc-wen"
                                         and form == "oscillator")
    if model == "bouc-wen":
        multistart, how = _bouc_wen_settings(form, exponent, multistart)
    if model == "bouc-wen" and form == "oscillator":
        m = _oscillator(recs, dt, exponent, offset, burn_in, multistart, substeps, progress,
                        common, how, initial_state)
    elif model == "bouc-wen":
        phys, names, cov = _fit_bouc_wen(recs, exponent=exponent, offset=offset,
                                         burn_in=burn_in, multistart=multistart,
                                         progress=progress)
        m = BoucWenModel(**phys, free=names, covariance=cov, **common, criterion=how)
    else:
        m = _prandtl_ishlinskii(recs, u, operators, thresholds, offset, burn_in, iname, common)
    _score_records(m, recs, burn_in)
    if validate is not None:
        m.validation_fit_percent = m.compare((uv, yv)).fit_percent[0]
    return m


# ---------------------------------------------------------------------------------------------
# reading a model file


#: the numbers of each hysteresis model's file and their domains (the exponent n of the
#: Bouc-Wen forms: [1, 10], as :func:`hysteresis` fits it; the actuator form may have no dt)
_FINITE = Domain()
HYSTERESIS_NUMBERS = {
    "bouc-wen": {"dt": Domain(0.0, strict=True, optional=True), "n": Domain(1.0, 10.0),
                 **{k: _FINITE for k in ("d", "alpha", "beta", "gamma", "offset")}},
    "bouc-wen-oscillator": {"dt": SAMPLE_TIME, "n": Domain(1.0, 10.0),
                            "substeps": Domain(1, integer=True),
                            **{k: _FINITE for k in _BWO_NAMES if k != "n"}},
    "prandtl-ishlinskii": {"dt": Domain(0.0, strict=True, optional=True), "offset": _FINITE,
                           "input_offset": _FINITE}}


def _free_and_covariance(doc: dict, names: tuple) -> tuple[tuple, np.ndarray]:
    """The free parameters (each one of ``names``) and their covariance of a model file."""
    free = tuple(str(k) for k in doc["free"])
    if not set(free) <= set(names):
        raise ValueError(f"unknown free parameter in {free}")
    return free, np.array(doc["covariance"], dtype=np.float64).reshape(len(free), len(free))


def load_hysteresis(path):
    """Read a model written by ``save`` of :class:`BoucWenModel`,
    :class:`BoucWenOscillatorModel` or :class:`PrandtlIshlinskiiModel`; the same type comes
    back."""
    p = Path(path)
    writer = "model.save or `gripkit identify hysteresis --out`"
    doc = read_family_document(p, SCHEMA, VERSION, family="hysteresis", writer=writer)
    kind = doc.get("model")
    check_family_fields(doc, f"hysteresis model file {str(p)!r}", writer,
                        numbers=HYSTERESIS_NUMBERS.get(kind, {}),
                        finite=("thresholds", "weights"), units=("input_unit", "output_unit"))
    common = {k: doc.get(k) for k in ("dt", "fit_percent", "validation_fit_percent",
                                      "criterion")}
    try:
        common.update(input_name=str(doc["input_name"]), output_name=str(doc["output_name"]),
                      input_unit=str(doc["input_unit"]), output_unit=str(doc["output_unit"]),
                      burn_in=int(doc.get("burn_in", 0)), **file_provenance(doc))
        common["criterion"] = str(common["criterion"] or "")
        if kind == "bouc-wen":
            free, cov = _free_and_covariance(doc, _BW_NAMES)
            return BoucWenModel(**{k: float(doc[k]) for k in _BW_NAMES}, free=free,
                                covariance=cov, **common)
        if kind == "bouc-wen-oscillator":
            free, cov = _free_and_covariance(doc, _BWO_NAMES)
            common["dt"] = float(common["dt"])
            if not (common["dt"] > 0 and int(doc["substeps"]) >= 1):
                raise ValueError("dt must be > 0 and substeps ≥ 1")
            option = str(doc.get("initial_state", "zero"))
            if option not in INITIAL_STATES:
                raise ValueError(f"initial_state {option!r} is none of {INITIAL_STATES}")
            states = [{**{k: float(s[k]) for k in STATE_NAMES},
                       "std": {k: float(s["std"][k]) for k in STATE_NAMES},
                       "sample": int(s.get("sample", 0))}
                      for s in doc.get("initial_states", [])]
            return BoucWenOscillatorModel(**{k: float(doc[k]) for k in _BWO_NAMES},
                                          substeps=int(doc["substeps"]), free=free,
                                          covariance=cov, initial_state_option=option,
                                          initial_states=states, **common)
        if kind == "prandtl-ishlinskii":
            r = np.array(doc["thresholds"], dtype=np.float64)
            w = np.array(doc["weights"], dtype=np.float64)
            if r.ndim != 1 or r.shape != w.shape:
                raise ValueError("thresholds and weights differ in length")
            cov = np.array(doc["covariance"], dtype=np.float64)
            k = int(cov.size ** 0.5)
            return PrandtlIshlinskiiModel(r, w, offset=float(doc["offset"]),
                                          input_offset=float(doc["input_offset"]),
                                          covariance=cov.reshape(k, k),
                                          fit_offset=bool(doc["fit_offset"]), **common)
    except (KeyError, TypeError, ValueError) as exc:
        raise ModelError(f"{str(p)!r}: a malformed {SCHEMA} ({type(exc).__name__}: {exc}); "
                         "write it again with model.save") from None
    raise ModelError(f"{str(p)!r}: unknown hysteresis model {kind!r}; expected one of "
                     f"{', '.join(MODELS)}, bouc-wen-oscillator")
