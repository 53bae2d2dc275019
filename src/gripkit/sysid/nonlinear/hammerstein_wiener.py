"""Hammerstein, Wiener and Hammerstein–Wiener models: static nonlinearities
around an output-error or a state-space linear block, refined by prediction-error minimisation of
the simulation error, with σ of every parameter.

The model (one input ``u``, one output ``y``)::

    w(t) = f(u(t))                                   input nonlinearity (static)
    x(t) = B(q)/F(q) w(t)                            linear block, output-error form
    ŷ(t) = g(x(t)) + y0                              output nonlinearity (static) and offset
    B(q) = b1 q^-nk + … + b_nb q^-(nk+nb-1),   F(q) = 1 + f1 q^-1 + … + f_nf q^-nf

**State-space linear block** (``linear='ss'``, ``order = n``): in place of B/F ::

    ξ(t+1) = A ξ(t) + b w(t − m),   x(t) = C ξ(t) + d w(t),   m = max(nk − 1, 0)
    A = [[−a1, 1, 0, …, 0], [−a2, 0, 1, …, 0], …, [−a_n, 0, …, 0]],   C = [1, 0, …, 0]

(observer canonical form; ``d`` is estimated only when ``nk = 0``, else 0). A full ``(A, b, C,
d)`` would not be identifiable: ``(T A T⁻¹, T b, C T⁻¹, d)`` gives the same output for every
invertible ``T``, a null space of ``n²`` directions in which σ is infinite. The canonical form
keeps ``2n (+1)`` parameters, one per coefficient of the transfer function ::

    G(q) = d + (b1 q⁻¹ + … + b_n q⁻ⁿ)/(1 + a1 q⁻¹ + … + a_n q⁻ⁿ)  (times q^-m)

so the parameters are determined as long as that fraction has no common factor (the same
condition as for B/F); the poles are the roots of ``zⁿ + a1 zⁿ⁻¹ + … + a_n`` (the eigenvalues
of A). The gain normalisation below puts the chain's gain in ``b`` (and ``d``). Its start is
gripkit's subspace estimate of the best linear approximation
(:func:`gripkit.sysid.linear.subspace.n4sid`, order ``n``, the input delayed by ``m``, with
``D`` when ``nk = 0``), brought to this form through its transfer function, its poles pulled
inside ``|z| = 0.98``; then everything below is the same as for B/F: the linear PEM, the
nonlinear fits from it, the order ``n`` chosen in 1, 2, 3 (and ``nk`` in 0, 1, 2) as ``(nb,
nf)`` are, the free run from the steady state ``ξ(0) = (I − A)⁻¹ b w₋``, a step that puts an
eigenvalue of A on or outside the unit circle refused. The forward sensitivities
``∂ξ(t+1)/∂θ = A ∂ξ(t)/∂θ + b ∂w(t−m)/∂θ + (∂A/∂θ) ξ(t) + (∂b/∂θ) w(t−m)`` run beside the
free run in one numba kernel (:func:`.hw_kernels.ss_run`). The state-space block represents
exactly the transfer functions of B/F with ``nf = n`` and ``nb = n`` (``nk ≥ 1``) or
``nb = n + 1`` (``nk = 0``); the two reach the same fit on such data.

``f = none`` gives a Wiener model, ``g = none`` a Hammerstein model, both ``none`` the linear
output-error model with an offset. The nonlinearities (``KIND[:N]``):

* ``none``: ``v``
* ``saturation``: ``min(max(v, lo), hi)`` (parameters ``lo < hi``)
* ``deadzone``: ``v − hi`` for ``v > hi``, ``v − lo`` for ``v < lo``, 0 between (``lo ≤ hi``)
* ``poly:N``: ``v + c2 v² + … + cN v^N`` (default N = 3)
* ``pwl:N``: ``v + Σ_{k ≤ N/2} d_k min(0, v − β_k) + Σ_{k > N/2} d_k max(0, v − β_k)``, the N
  breakpoints ``β_1 < … < β_N`` fixed at the ``k/(N+1)`` quantiles of the signal entering the
  block (the measured ``u``, or ``x`` of the initial linear model); the slope changes ``d_k``
  away from the middle segment (between ``β_⌊N/2⌋`` and the next, slope 1) are estimated
  (default N = 4)
* ``sigmoid:N``: ``v + Σ_k a_k tanh((v − c_k)/h)``, the N centres ``c_k`` fixed at the same
  quantiles and ``h`` at their spacing; the weights ``a_k`` are estimated (default N = 4)

**Gain normalisation.** ``c·f``, ``B/c`` and ``g(c·)``, ``B·c`` give the same output for every
``c ≠ 0``. gripkit fixes the ambiguity by giving every nonlinearity **unit slope in its linear
part** (the coefficient of ``v`` is 1 for poly and sigmoid; slope 1 on the middle segment of pwl,
between the limits of a saturation and outside the thresholds of a dead zone): the gain of the
whole chain is in ``B``, and thresholds and limits are in the units of the signal entering the
block (``u`` for the input block; ``x``, the output's unit before ``g``, for the output block).

**Estimation.** (1) Orders: ``(nb, nf)`` in (1, 1), (2, 2), (3, 3) and ``nk`` in 0, 1, 2
unless given, each by a linear output-error fit (the best linear approximation: least-squares
ARX, unstable poles reflected into the unit circle, then the PEM of (3) with both blocks
``none``; at most 30 iterations per candidate while screening, the chosen one to convergence).
**Periodic excitation** (``periods=P``, ``--periods P``: the record is P ≥ 3 whole periods of a
periodic input such as a random-phase multisine; one record): the linear block starts instead
from the nonparametric best linear approximation ``G_BLA(e^{jω})`` and its σ on the excited
lines (:func:`gripkit.sysid.linear.frf.frf`, ``periods=P``, the first period dropped as
transient; it refuses a record that is not P periods of one input), σ² averaged over
:data:`BLA_SMOOTH` neighbouring lines (from P − 1 periods alone it scatters like χ² with few
degrees of freedom). ``B/F`` (or, for ``linear='ss'``, the same transfer function, then ``a``,
``b``, ``d``) is fitted to it with weights ``1/σ_G``: Sanathanan–Koerner iterations (linear
least squares of ``(F G_BLA − B)/(F_prev σ_G)``) then Levenberg–Marquardt on
``(G_BLA − B/F)/σ_G``, F stabilised as the ARX start's; the PEM of (3) with both blocks
``none`` follows as above (orders chosen the same way). For a Wiener system under a Gaussian-like
input ``G_BLA = E[g'(x)] B/F`` (Bussgang): the start has the true poles, the gain scaled.
(2) Nonlinear fits from that linear model with the nonlinearities at identity (``c = d = a = 0``)
and, for saturation and dead zone, limits started at quantiles of the signal entering the block
(a few starts, the best kept). When the orders were searched and the best structure is
nonlinear, it is fitted again at the other ``(nb, nf)`` with the same ``nk``: a linear
approximation of a nonlinear system often asks for extra poles. (3) Levenberg–Marquardt on
``V(θ) = ½ Σ (y − ŷ(θ))²`` with Marquardt's diagonal scaling, until a step lowers the SSE by
less than ``1e-4 SSE/N``. The Jacobian is exact: the forward sensitivities
``∂x/∂b_i = q^-(nk+i-1) w − Σ f_j ∂x/∂b_i(t−j)``, ``∂x/∂f_j = −x(t−j) − Σ f_l ∂x/∂f_j(t−l)``,
``∂x/∂p_f = B/F ∂f/∂p_f`` and ``∂ŷ/∂θ = g'(x) ∂x/∂θ`` (``∂ŷ/∂p_g = ∂g/∂p_g``) run beside the
free run in one numba kernel. A step that makes ``F`` unstable (a root with ``|z| ≥ 1``) or
reverses the limits is refused (more damping), so the returned ``F`` is stable.

The free run starts from a steady state of the linear block under a constant input ``w₋``
(``w(t<0) = w₋``, ``x(t<0) = B(1)/F(1) w₋``): a record that starts at rest has ``w₋ = 0``, one
that starts settled at the first input ``w₋ = f(u(0))``. ``w₋`` is estimated with ``θ`` on the
estimation record (a nuisance parameter: its uncertainty is in every σ), fitted alone by
Gauss–Newton on a validation record (:meth:`HWModel.compare`), and ``f(u(0))`` in
:meth:`HWModel.simulate` unless given.

**σ.** ``cov θ = σ² (JᵀJ)⁻¹`` (Gauss–Newton), ``σ² = SSE/(N − P)``, from the eigen-decomposition
of the column-scaled ``JᵀJ``: a direction with eigenvalue below ``1e-10`` of the largest is not
determined by the data, and every parameter that moves along it has σ = inf (for example a
saturation limit that the data never reach; an AccuracyWarning names them).
``simulate(data, std=True)`` propagates ``cov θ`` to the free run linearly:
``σ_ŷ(t)² = J(t) cov θ J(t)ᵀ`` (inf where ŷ(t) depends on an undetermined parameter).

**Structure.** Without ``input_nonlinearity``/``output_nonlinearity`` the candidates are the
linear model, the Hammerstein models with saturation, dead zone, poly:3 and pwl:4, the Wiener
models with saturation, poly:3 and pwl:4, and the Hammerstein–Wiener models that join the two
best of those input blocks to the two best of those output blocks. They (and the orders) are
ranked by the free-run fit on ``validate=`` when given (among those within 0.1 point of the
best: one whose parameters the data all determine, then the fewest parameters), else by
``BIC = N ln(SSE/N) + P ln N`` on the estimation record.

The fit is ``100 (1 − ‖y − ŷ‖/‖y − ȳ‖)`` over all samples of the free run. A run that leaves
``1000×`` the estimation output's range (about its middle) or is not finite counts as diverged:
fit None with a :class:`StabilityWarning`.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from operator import attrgetter
from pathlib import Path

import numpy as np

from ...errors import (AccuracyWarning, ArgumentError, DataError, GripkitError,
                       IdentificationError, ModelError, StabilityWarning, emit_warning)
from ...params import Parameter, ParameterSet
from ...progress import track
from ...signals.trajectory import Trajectory
from ...units import product_unit
from ..linear.frf import frf
from ..linear.subspace import n4sid, n4sid_records
from ..io_data import check_scale
from ..model_file import (SAMPLE_TIME, Domain, FamilyFile, check_family_fields, file_provenance,
                          read_family_document)
from ..model_protocol import ModelFit
from . import hw_kernels as K
from .levenberg_marquardt import levenberg_marquardt
from .nonlinear_model import OutputErrorPrediction
from .single_channel import (DIVERGENCE_FACTOR, FreeRunModel, channel_fields, fit_percent,
                             not_constant, one_signal)

__all__ = ["SCHEMA", "HW_FIT", "HWModel", "Nonlinearity", "hammerstein_wiener", "load_hw",
           "parse_nonlinearity"]

SCHEMA = "gripkit.hw-model"
#: the file version of a model with the output-error block (the files written before the
#: state-space block, read as they are)
VERSION = 1
#: the file version of a model with the state-space block (``linear``, ``order``): a reader of
#: version 1 alone refuses it instead of reading its a, b as B/F
SS_VERSION = 2
#: the linear blocks
LINEAR = ("oe", "ss")
HW_FIT = ("free run from a steady state of the linear block whose constant input w₋ is fitted "
          "to the record (least squares), fit = 100 (1 − ‖y − ŷ‖/‖y − ȳ‖) over all samples")
KINDS = {"none": K.NONE, "saturation": K.SATURATION, "deadzone": K.DEADZONE, "poly": K.POLY,
         "pwl": K.PWL, "sigmoid": K.SIGMOID}
DEFAULT_N = {"poly": 3, "pwl": 4, "sigmoid": 4}
#: the structures tried when no nonlinearity is given: (input, output)
AUTO_STRUCTURES = (("none", "none"), ("saturation", "none"), ("deadzone", "none"),
                   ("poly:3", "none"), ("pwl:4", "none"), ("none", "saturation"),
                   ("none", "poly:3"), ("none", "pwl:4"))
#: with ``validate=``, the simplest candidate within this many fit points of the best is taken
PARSIMONY_POINTS = 0.1
#: input and output blocks joined into Hammerstein–Wiener candidates (the best of each side)
N_JOINED = 2
AUTO_ORDERS = ((1, 1), (2, 2), (3, 3))
AUTO_NK = (0, 1, 2)
_EIG_FLOOR = 1e-10
#: LM iterations of each linear fit while the orders are screened (the chosen one then converges)
SCREEN_ITERATIONS = 30
#: lines over which the FRF's σ² is averaged for the weights of the BLA fit (a σ² from a few
#: periods scatters like χ² with 2(P − 2) degrees of freedom; the noise spectrum is smooth)
BLA_SMOOTH = 9


@dataclass(frozen=True)
class Nonlinearity:
    """A static nonlinearity: ``kind`` (``none``, ``saturation``, ``deadzone``, ``poly``,
    ``pwl``, ``sigmoid``), ``n`` (degree or number of breakpoints/units; 0 where none) and the
    fixed ``consts`` (breakpoints, or centres followed by the width ``h``)."""

    kind: str = "none"
    n: int = 0
    consts: tuple = ()

    @property
    def code(self) -> int:
        return KINDS[self.kind]

    @property
    def n_params(self) -> int:
        return {"none": 0, "saturation": 2, "deadzone": 2, "poly": max(self.n - 1, 0)}.get(
            self.kind, self.n)

    @property
    def label(self) -> str:
        return self.kind + (f":{self.n}" if self.kind in DEFAULT_N else "")

    def param_names(self, prefix: str) -> list[str]:
        if self.kind in ("saturation", "deadzone"):
            return [f"{prefix}_lo", f"{prefix}_hi"]
        letter = {"poly": "c", "pwl": "d", "sigmoid": "a"}.get(self.kind)
        if letter is None:
            return []
        first = 2 if self.kind == "poly" else 1
        return [f"{prefix}_{letter}{k}" for k in range(first, first + self.n_params)]

    def evaluate(self, v, p) -> np.ndarray:
        """``f(v)`` for an array ``v`` with parameters ``p``."""
        v = np.asarray(v, dtype=np.float64)
        p = np.asarray(p, dtype=np.float64)
        c = np.asarray(self.consts, dtype=np.float64) if self.consts else np.zeros(1)
        g = np.zeros(max(len(p), 1))
        return np.array([K.nl_eval(self.code, p, c, float(x), g)[0] for x in v.ravel()]
                        ).reshape(v.shape)


def parse_nonlinearity(spec, where: str = "nonlinearity") -> Nonlinearity:
    """``'KIND[:N]'`` (or None / ``'none'``) → a :class:`Nonlinearity` without its constants."""
    if spec is None:
        return Nonlinearity()
    if isinstance(spec, Nonlinearity):
        return spec
    if not isinstance(spec, str):
        raise ArgumentError(f"hammerstein_wiener: {where} must be a string KIND[:N], found "
                            f"{type(spec).__name__} {spec!r:.40}")
    kind, _, num = spec.strip().lower().partition(":")
    if kind not in KINDS:
        raise ArgumentError(f"hammerstein_wiener: {where} {spec!r}: unknown kind {kind!r}; "
                            f"expected one of {', '.join(KINDS)} (with :N for poly, pwl, sigmoid)")
    if num and kind not in DEFAULT_N:
        raise ArgumentError(f"hammerstein_wiener: {where} {spec!r}: {kind} takes no :N (only "
                            "poly, pwl and sigmoid do)")
    if not num:
        return Nonlinearity(kind, DEFAULT_N.get(kind, 0))
    try:
        n = int(num)
    except ValueError:
        n = -1
    lo = 2 if kind == "poly" else 1
    if not lo <= n <= 20:
        raise ArgumentError(f"hammerstein_wiener: {where} {spec!r}: N must be an integer from {lo} "
                            f"to 20 (the {'degree' if kind == 'poly' else 'number of units'}), "
                            f"found {num!r}")
    return Nonlinearity(kind, n)


def _with_consts(nl: Nonlinearity, v: np.ndarray) -> Nonlinearity:
    """Fix the breakpoints/centres of pwl and sigmoid at the quantiles of ``v``."""
    if nl.kind not in ("pwl", "sigmoid"):
        return nl
    q = np.quantile(v, np.arange(1, nl.n + 1) / (nl.n + 1))
    if nl.kind == "pwl":
        return Nonlinearity(nl.kind, nl.n, tuple(float(a) for a in q))
    span = float(np.quantile(v, 0.95) - np.quantile(v, 0.05))
    h = max(span / (nl.n + 1), 1e-12 * max(abs(float(np.mean(v))), 1.0), 1e-300)
    return Nonlinearity(nl.kind, nl.n, tuple(float(a) for a in q) + (h,))


def _limit_starts(nl: Nonlinearity, v: np.ndarray) -> list[np.ndarray]:
    """Start values of the nonlinearity's parameters: identity for poly/pwl/sigmoid; limits at a
    few quantile pairs of ``v`` for saturation and dead zone."""
    if nl.kind == "saturation":
        return [np.quantile(v, [q, 1.0 - q]) for q in (0.03, 0.1, 0.25)]
    if nl.kind == "deadzone":
        return [np.quantile(v, [0.5 - m / 2, 0.5 + m / 2]) for m in (0.1, 0.3, 0.5)]
    return [np.zeros(nl.n_params)]


def _fit_value(y, yhat) -> float:
    return fit_percent(y, yhat, "hammerstein_wiener")


class _RunOutput:
    """``yhat`` and ``jac``: the last run's ŷ and J, views of ``self.out`` (a ``K.HWOut``)."""

    yhat = property(attrgetter("out.yhat"))
    jac = property(attrgetter("out.jac"))


class _Problem(_RunOutput):
    """One structure on one record: work arrays for the kernel, ŷ and J."""

    linear = "oe"

    def __init__(self, u, fin: Nonlinearity, fout: Nonlinearity, nb, nf, nk):
        self.u, self.fin, self.fout = u, fin, fout
        self.nb, self.nf, self.nk = nb, nf, nk
        self.ni, self.no = fin.n_params, fout.n_params
        self.L = nb + nf  # parameters of the linear block
        self.P = self.ni + nb + nf + self.no + 1
        n, m = len(u), nk + nb + nf
        self.work = K.HWWork(np.empty(n + m), np.empty(n + m), np.zeros((n + m, self.ni + 1)),
                             np.zeros((n + m, self.ni + nb + nf + 1)))
        self.gin, self.gout = np.zeros(max(self.ni, 2)), np.zeros(max(self.no, 2))
        self.cin = np.asarray(fin.consts or (0.0,), dtype=np.float64)
        self.cout = np.asarray(fout.consts or (0.0,), dtype=np.float64)
        self.out = K.HWOut(np.empty(n), np.empty((n, self.P + 1)))  # jac's last column: ∂ŷ/∂w₋

    @property
    def x(self) -> np.ndarray:
        """The linear block's output of the last run (its first ``nk + nb + nf`` rows: before the
        record)."""
        return self.work.x

    @property
    def inner(self) -> np.ndarray:
        """The linear block's output of the last run on the record's samples."""
        return self.work.x[self.nk + self.nb + self.nf:]

    def split(self, th):
        ni, nb, nf, no = self.ni, self.nb, self.nf, self.no
        return (th[:ni], th[ni:ni + nb], th[ni + nb:ni + nb + nf],
                th[ni + nb + nf:ni + nb + nf + no], th[-1])

    def run(self, the, want_j: bool):
        """Free run (and J) for ``the = [θ, w₋]``."""
        the = np.ascontiguousarray(the, dtype=np.float64)
        pin, b, f, pout, y0 = self.split(the[:-1])
        return K.hw_run(self.u, K.HWBlock(self.fin.code, pin, self.cin, self.gin),
                        K.HWLinear(b, f, self.nk), K.HWBlock(self.fout.code, pout, self.cout,
                                                             self.gout),
                        float(y0), float(the[-1]), want_j, self.work, self.out)

    def admissible(self, the) -> bool:
        pin, _, f, pout, _ = self.split(the[:self.P])
        if len(f) and np.max(np.abs(np.roots(np.r_[1.0, f]))) >= 1.0 - 1e-9:
            return False
        return _limits_ordered(self.fin, pin) and _limits_ordered(self.fout, pout)


class _SSProblem(_RunOutput):
    """:class:`_Problem` with the state-space linear block of order ``n`` in observer canonical
    form (module docstring; :func:`.hw_kernels.ss_run`): ``the = [θ, w₋]`` with
    ``θ = [input block, a1…a_n, b1…b_n, d (nk = 0 only), output block, y0]``."""

    linear = "ss"

    def __init__(self, u, fin: Nonlinearity, fout: Nonlinearity, n, nk):
        self.u, self.fin, self.fout = u, fin, fout
        self.nb = self.nf = n
        self.nk = nk
        self.ni, self.no = fin.n_params, fout.n_params
        self.L = 2 * n + (nk == 0)
        self.P = self.ni + self.L + self.no + 1
        N, m = len(u), max(nk - 1, 0)
        self.work = K.SSWork(np.empty(N + m), np.empty(N), np.zeros((N + m, self.ni + 1)),
                             np.zeros(n), np.zeros((n, self.ni + self.L + 1)))
        self.gin, self.gout = np.zeros(max(self.ni, 2)), np.zeros(max(self.no, 2))
        self.cin = np.asarray(fin.consts or (0.0,), dtype=np.float64)
        self.cout = np.asarray(fout.consts or (0.0,), dtype=np.float64)
        self.out = K.HWOut(np.empty(N), np.empty((N, self.P + 1)))

    @property
    def inner(self) -> np.ndarray:
        """The linear block's output of the last run."""
        return self.work.x

    def split(self, th):
        """``(input block, a, b, d, output block, y0)`` of θ."""
        ni, n, L, no = self.ni, self.nb, self.L, self.no
        return (th[:ni], th[ni:ni + n], th[ni + n:ni + 2 * n], th[ni + 2 * n:ni + L],
                th[ni + L:ni + L + no], th[ni + L + no])

    def run(self, the, want_j: bool):
        """Free run (and J) for ``the = [θ, w₋]``."""
        the = np.ascontiguousarray(the, dtype=np.float64)
        pin, a, b, d, pout, y0 = self.split(the[:-1])
        return K.ss_run(self.u, K.HWBlock(self.fin.code, pin, self.cin, self.gin),
                        K.SSLinear(a, b, d, self.nk), K.HWBlock(self.fout.code, pout, self.cout,
                                                                self.gout),
                        float(y0), float(the[-1]), want_j, self.work, self.out)

    def admissible(self, the) -> bool:
        pin, a, _, _, pout, _ = self.split(the[:self.P])
        if np.max(np.abs(np.roots(np.r_[1.0, a]))) >= 1.0 - 1e-9:
            return False
        return _limits_ordered(self.fin, pin) and _limits_ordered(self.fout, pout)


def _limits_ordered(nl: Nonlinearity, p) -> bool:
    """The limits of a saturation ordered (``lo < hi``), of a dead zone ``lo ≤ hi``."""
    if nl.kind == "saturation":
        return bool(p[0] < p[1])
    if nl.kind == "deadzone":
        return bool(p[0] <= p[1])
    return True


class _Records(_RunOutput):
    """One structure on several records (the interface of :class:`_Problem`): each record runs
    from its own steady state, ``the = [θ, w₋ of record 1, …, w₋ of record R]``; ŷ and J are the
    records' stacked (a record's rows are zero in the other records' w₋ columns)."""

    def __init__(self, us, fin: Nonlinearity, fout: Nonlinearity, nb, nf, nk, linear="oe"):
        self.parts = [_problem([u], fin, fout, nb, nf, nk, linear) for u in us]
        p = self.parts[0]
        self.fin, self.fout, self.nb, self.nf, self.nk = fin, fout, nb, nf, nk
        self.linear, self.L = linear, p.L
        self.ni, self.no, self.P, self.R = p.ni, p.no, p.P, len(us)
        self.bounds = np.cumsum([0] + [len(u) for u in us])
        n = int(self.bounds[-1])
        self.out = K.HWOut(np.empty(n), np.zeros((n, self.P + self.R)))
        self._inner = np.empty(n)

    @property
    def inner(self) -> np.ndarray:
        return self._inner

    def split(self, th):
        return self.parts[0].split(th)

    def run(self, the, want_j: bool):
        """Every record's free run (and J) for ``the = [θ, w₋ …]``; the first code ≥ 0 of a
        record that diverged (offset to the stacked rows), else −1."""
        P = self.P
        for r, prob in enumerate(self.parts):
            a, b = self.bounds[r], self.bounds[r + 1]
            code = prob.run(np.r_[the[:P], the[P + r]], want_j)
            if code >= 0:
                return int(a + code)
            self.out.yhat[a:b] = prob.yhat
            self._inner[a:b] = prob.inner
            if want_j:
                self.out.jac[a:b, :P] = prob.jac[:, :P]
                self.out.jac[a:b, P + r] = prob.jac[:, P]
        return -1

    def admissible(self, the) -> bool:
        return self.parts[0].admissible(the)


def _problem(us, fin: Nonlinearity, fout: Nonlinearity, nb, nf, nk, linear="oe"):
    """:class:`_Problem` (``linear='oe'``) or :class:`_SSProblem` (``'ss'``, order ``nb = nf``)
    for one record, :class:`_Records` for several (``us``: their inputs)."""
    if len(us) > 1:
        return _Records(us, fin, fout, nb, nf, nk, linear)
    if linear == "ss":
        return _SSProblem(us[0], fin, fout, nb, nk)
    return _Problem(us[0], fin, fout, nb, nf, nk)


def _lm(prob: _Problem, y, th0, maxiter: int = 200):
    """Levenberg–Marquardt on the simulation error over ``[θ, w₋]``; returns them, SSE, J there,
    iterations.

    Stops when a step lowers the SSE by less than ``1e-4 σ̂²`` (``σ̂² = SSE/N``): a move of one
    standard deviation in any parameter changes the SSE by about ``σ²``, so the parameters are
    then within about 0.01σ of the minimum."""
    th = np.array(th0, dtype=np.float64)
    if prob.run(th, True) >= 0:
        return th, math.inf, None, 0
    r, rc = np.empty(len(y)), np.empty(len(y))
    n = len(y)
    H, g = np.empty((len(th), len(th))), np.empty(len(th))
    stale = False  # J is of an earlier θ: the run of the θ accepted last was without J

    def normal_equations():
        nonlocal stale
        if stale:
            prob.run(th, True)
            stale = False
        K.gram(prob.jac, r, H, g)
        return H, g

    def trial(cand):
        if prob.admissible(cand) and prob.run(cand, False) < 0:
            return K.residual(y, prob.yhat, rc)
        return None

    def accept(cand):
        nonlocal th, r, rc, stale
        th, (r, rc), stale = cand, (rc, r), True

    _, _, it = levenberg_marquardt(th, K.residual(y, prob.yhat, r),
                                   normal_equations=normal_equations, trial=trial,
                                   accept=accept, max_iter=maxiter,
                                   converged=lambda old, new: old - new < 1e-4 * new / n)
    prob.run(th, True)
    return th, K.residual(y, prob.yhat, r), prob.jac.copy(), it


def _covariance(J: np.ndarray, sse: float):
    """Gauss–Newton covariance σ²(JᵀJ)⁻¹ on the directions the data determine; σ = inf for every
    parameter along an undetermined direction."""
    n, P = J.shape
    H, g = np.empty((P, P)), np.empty(P)
    K.gram(J, np.zeros(n), H, g)
    d = np.sqrt(np.maximum(np.diag(H), 0.0))
    ok = d > 0
    ds = np.where(ok, d, 1.0)
    lam, V = np.linalg.eigh(H / np.outer(ds, ds))
    keep = lam > _EIG_FLOOR * max(lam.max(), 1e-300)
    inv = (V[:, keep] / lam[keep]) @ V[:, keep].T
    sigma2 = sse / max(n - P, 1)
    cov = sigma2 * inv / np.outer(ds, ds)
    loose = ~ok | (np.abs(V[:, ~keep]) > 1e-3).any(axis=1) if (~keep).any() else ~ok
    cov[loose, :] = np.nan
    cov[:, loose] = np.nan
    std = np.sqrt(np.maximum(np.diag(cov), 0.0))
    std[loose] = np.inf
    return cov, std


def _check_length(recs, nb, nf, nk, what=None):
    """A DataError when a record has fewer than ``nk + nb + nf + 4 (nb + nf + 1)`` samples (too
    few for the least-squares start of B/F; ``what`` names the orders, default nb, nf, nk)."""
    m = nk + nb + nf
    for u, y in recs:
        n = len(y)
        if n - m < 4 * (nb + nf + 1):
            raise DataError(f"hammerstein_wiener: {n} samples{' in a record' * (len(recs) > 1)} "
                            f"for {what or f'orders nb={nb}, nf={nf}, nk={nk}'}; need at least "
                            f"{m + 4 * (nb + nf + 1)}: lower the orders or give more data")


def _arx_start(recs, nb, nf, nk):
    """Least-squares ARX ``F y = B q^-nk u + c`` on demeaned signals (``recs``: the records
    ``(u, y)``, each one's regressors from its own samples only), F stabilised; θ = [b, f]."""
    _check_length(recs, nb, nf, nk)
    m = nk + nb + nf
    rows, target = [], []
    for u, y in recs:
        n = len(y)
        cols = [-y[m - j:n - j] for j in range(1, nf + 1)]
        cols += [u[m - nk - i:n - nk - i] for i in range(nb)]
        rows.append(np.column_stack(cols + [np.ones(n - m)]))
        target.append(y[m:])
    th = np.linalg.lstsq(np.vstack(rows), np.concatenate(target), rcond=None)[0]
    f, b = th[:nf], th[nf:nf + nb]
    return b, _stabilised(f)


def _stabilised(f: np.ndarray) -> np.ndarray:
    """``F = [1, f]`` with every root of modulus ≥ 0.98 pulled onto the circle of radius 0.98
    (same angle); returns the new ``f``."""
    if not len(f):
        return f
    z = np.roots(np.r_[1.0, f])
    z = np.where(np.abs(z) >= 0.98, 0.98 * z / np.maximum(np.abs(z), 1e-300), z)
    return np.real(np.poly(z))[1:]


def check_periods(periods, n_records: int, flag: str = "") -> int:
    """``periods`` as an integer ≥ 3 on one record (the first period is dropped as transient and
    the FRF's σ needs two more), or an ArgumentError naming ``flag + 'periods'``."""
    name = f"{flag}periods"
    if (isinstance(periods, bool) or not isinstance(periods, (int, np.integer))
            or periods < 3):
        raise ArgumentError(f"hammerstein_wiener: {name} must be an integer ≥ 3 (the whole "
                            "periods of a periodic input in the record: the first is dropped as "
                            f"transient, the FRF's σ needs two more), found {periods!r:.20}")
    if n_records != 1:
        raise ArgumentError(f"hammerstein_wiener: {name} takes one record (its FRF gives the "
                            f"linear start), found {n_records}; fit one periodic record, or "
                            f"leave out {name}")
    return int(periods)


def _bla(u, y, periods: int):
    """The nonparametric best linear approximation of a periodic record (``periods`` whole
    periods, the first dropped as transient: :func:`gripkit.sysid.linear.frf.frf`, which refuses
    a record that is not ``periods`` periods of one input) → ``(z⁻¹ = e^{−jω}, G, σ_G)`` on the
    excited lines (ω in rad/sample). σ is floored at ``1e-6 max|G|`` (noise-free data)."""
    try:
        r = frf(u, y, periods=periods, method="periodic")
    except DataError as exc:
        raise DataError(f"hammerstein_wiener: {exc.message}", hint=exc.hint) from None
    G, var = r.H[:, 0, 0], r.H_std[:, 0, 0] ** 2
    k = min(BLA_SMOOTH, len(G))
    sd = np.sqrt(np.convolve(var, np.ones(k), "same") / np.convolve(np.ones(len(G)), np.ones(k),
                                                                    "same"))
    sd = np.maximum(sd, 1e-6 * float(np.max(np.abs(G))))
    return np.exp(-2j * np.pi * r.frequency_hz), G, sd


def _bla_fit(bla, nb, nf, nk):
    """``(b, f)`` of ``B(q)/F(q)`` fitted to the best linear approximation ``bla`` (from
    :func:`_bla`) with weights ``1/σ_G``: Sanathanan–Koerner iterations (linear least squares of
    ``(F G − B)/(F_prev σ_G)``), then Levenberg–Marquardt on ``(G − B/F)/σ_G``; F stabilised
    like the ARX start (:func:`_stabilised`)."""
    from scipy.optimize import least_squares

    zi, G, sd = bla
    if 2 * len(G) < nb + nf:
        raise DataError(f"hammerstein_wiener: the periodic input excites {len(G)} frequency "
                        f"lines, too few for the {nb + nf} coefficients of B/F (nb={nb}, "
                        f"nf={nf}); excite more lines or lower the orders")
    Bz = np.column_stack([zi ** (nk + i) for i in range(nb)])
    Fz = np.column_stack([zi ** j for j in range(1, nf + 1)]) if nf else np.zeros((len(G), 0))
    M = np.column_stack([Bz, -Fz * G[:, None]])
    den, th = np.ones_like(G), None
    for _ in range(30):
        s = 1.0 / (sd * np.abs(den))
        Ms, rs = M * s[:, None], G * s
        new = np.linalg.lstsq(np.vstack([Ms.real, Ms.imag]), np.r_[rs.real, rs.imag],
                              rcond=None)[0]
        den = 1.0 + Fz @ new[nb:]
        done = th is not None and np.allclose(new, th, rtol=1e-10, atol=1e-12)
        th = new
        if done or not nf:
            break

    def res(t):
        e = (G - (Bz @ t[:nb]) / (1.0 + Fz @ t[nb:])) / sd
        return np.r_[e.real, e.imag]

    if nf:
        with np.errstate(all="ignore"):
            ref = least_squares(res, th, method="lm")
        if np.all(np.isfinite(ref.x)) and ref.cost <= 0.5 * float(res(th) @ res(th)):
            th = ref.x
    return th[:nb], _stabilised(th[nb:])


def _bla_ss_start(bla, n, nk):
    """``[a, b, d]`` of the state-space block (``d`` when ``nk = 0``) from the B/F fit of the best
    linear approximation with the same transfer function (``nb = n``, or ``n + 1`` with
    ``nk = 0``; module docstring)."""
    bo, a = _bla_fit(bla, n + (nk == 0), n, nk)
    num = np.r_[0.0, bo] if nk else bo
    d = num[0] if nk == 0 else 0.0
    return np.r_[a, num[1:] - d * a, [d] if nk == 0 else []]


def _ss_start(recs, n, nk):
    """The observer canonical ``[a, b, d]`` (``d`` when ``nk = 0``) of the order-``n`` subspace
    estimate (:func:`gripkit.sysid.linear.subspace.n4sid`, N4SID weighting; several records:
    ``n4sid_records``) of the best linear approximation on demeaned signals (``recs``: the
    records ``(u, y)``), the input delayed by ``nk − 1`` samples, with a feedthrough when
    ``nk = 0``; the characteristic polynomial stabilised. The transfer function ``C(zI − A)⁻¹B +
    D = (d + (b1 + d a1) z⁻¹ + … + (b_n + d a_n) z⁻ⁿ)/(1 + a1 z⁻¹ + … + a_n z⁻ⁿ)`` gives ``a``
    (the coefficients of ``det(zI − A)``) and ``b``. When the subspace step fails (too short a
    record for its horizon) the least-squares ARX start of the same transfer function is
    used."""
    from scipy.signal import ss2tf

    m = max(nk - 1, 0)
    shifted = [(u[:len(u) - m], y[m:]) for u, y in recs]
    try:
        with warnings.catch_warnings():  # a start only: the final model's diagnostics speak
            warnings.simplefilter("ignore")
            if len(recs) == 1:
                lm = n4sid(*shifted[0], n, feedthrough=nk == 0)
            else:
                lm = n4sid_records(shifted, n, feedthrough=nk == 0)
        sysm = lm.system
        num, den = ss2tf(sysm.A, sysm.B, sysm.C, sysm.D)
        num, a = np.real(num[0]), np.real(den[1:])
    except (GripkitError, np.linalg.LinAlgError, ValueError):
        bo, a = _arx_start(recs, n + (nk == 0), n, nk)
        num = np.r_[0.0, bo] if nk else bo
    a = _stabilised(a)
    d = num[0] if nk == 0 else 0.0
    return np.r_[a, num[1:] - d * a, [d] if nk == 0 else []]


@dataclass
class HWModel(OutputErrorPrediction, FreeRunModel, FamilyFile):
    """A Hammerstein–Wiener model ``ŷ = g(B/F f(u)) + y0`` (see the module docstring).

    ``linear``: ``'oe'`` (the linear block B/F) or ``'ss'`` (the observer canonical state-space
    block of order ``order``; ``nb = nf = order`` count its ``b`` and ``a``, ``nk = 0`` gives it
    the feedthrough ``d``). ``theta`` = [input-nonlinearity parameters, b1…b_nb, f1…f_nf (for
    ``'ss'``: a1…a_n, b1…b_n, d when nk = 0), output-nonlinearity parameters, y0] (names in
    ``names``), ``theta_std`` (1σ, inf where the data do not determine
    it), ``covariance``; ``fit_percent`` (free run, estimation record), ``validation_fit_percent``
    (free run on ``validate=``, None when diverged or none given), ``criterion`` (how structure
    and orders were chosen), ``candidates`` (every structure tried with its score),
    ``initial_input`` (w₋ of the estimation record's initial steady state; of the first record
    when fitted on several), ``records`` (with several records: each one's ``n_samples``, its own
    ``initial_input`` w₋ and free-run ``fit_percent``; empty for one record)."""

    input_nl: Nonlinearity
    output_nl: Nonlinearity
    nb: int
    nf: int
    nk: int
    theta: np.ndarray
    theta_std: np.ndarray
    covariance: np.ndarray
    candidates: list = field(default_factory=list)
    initial_input: float | None = None
    records: list = field(default_factory=list)
    linear: str = "oe"
    structure: str = "hw"
    fit_definition: str = HW_FIT
    _file_what = "Hammerstein-Wiener model"
    _file_allow_nan = False  # to_dict writes non-finite σ as null
    _family = "a Hammerstein–Wiener model"
    _linear_hint = ("its linear block B(q)/F(q) is model.B, model.F: "
                    "lti.TransferFunction.from_polynomials([1.0], model.B, F=model.F, "
                    "dt=model.dt) gives it as a system")

    # -- names and blocks -------------------------------------------------------------------
    @property
    def kind(self) -> str:
        """``'linear'``, ``'hammerstein'``, ``'wiener'`` or ``'hammerstein-wiener'``."""
        i, o = self.input_nl.kind != "none", self.output_nl.kind != "none"
        return {(0, 0): "linear", (1, 0): "hammerstein", (0, 1): "wiener"}.get(
            (i, o), "hammerstein-wiener")

    @property
    def order(self) -> int | None:
        """The state dimension of the state-space linear block (None for ``linear='oe'``)."""
        return self.nf if self.linear == "ss" else None

    @property
    def _n_linear(self) -> int:
        """Parameters of the linear block."""
        return self.nb + self.nf + (self.linear == "ss" and self.nk == 0)

    @property
    def names(self) -> list[str]:
        if self.linear == "ss":
            lin = ([f"a{i}" for i in range(1, self.nf + 1)]
                   + [f"b{i}" for i in range(1, self.nb + 1)] + ["d"] * (self.nk == 0))
        else:
            lin = ([f"b{i}" for i in range(1, self.nb + 1)]
                   + [f"f{j}" for j in range(1, self.nf + 1)])
        return (self.input_nl.param_names("in") + lin + self.output_nl.param_names("out")
                + ["y0"])

    def _part(self, which: str) -> np.ndarray:
        """``'in'``, ``'out'``: the nonlinearities' parameters; ``'b'``, ``'f'``: B/F's (for
        ``linear='ss'``: ``'b'`` the input vector b, ``'f'`` (or ``'a'``) the coefficients a of
        ``det(zI − A)`` and ``'d'`` the feedthrough, empty when ``nk ≥ 1``)."""
        ni, no, L = self.input_nl.n_params, self.output_nl.n_params, self._n_linear
        if self.linear == "ss":
            n = self.nf
            lin = {"f": slice(ni, ni + n), "a": slice(ni, ni + n),
                   "b": slice(ni + n, ni + 2 * n), "d": slice(ni + 2 * n, ni + L)}
        else:
            lin = {"b": slice(ni, ni + self.nb), "f": slice(ni + self.nb, ni + L)}
        s = {"in": slice(0, ni), "out": slice(ni + L, ni + L + no), **lin}[which]
        return self.theta[s]

    @property
    def B(self) -> np.ndarray:
        """B(q) coefficients from q⁰ (``nk`` leading zeros), as in gripkit's polynomial models;
        for ``linear='ss'`` the numerator of its transfer function ``d + C(qI − A)⁻¹b q^-m``
        (``nk = 0``: ``[d, b1 + d a1, …, b_n + d a_n]``; else ``nk`` zeros then ``b``)."""
        if self.linear == "ss" and self.nk == 0:
            d = self._part("d")[0]
            return np.r_[d, self._part("b") + d * self._part("a")]
        return np.r_[np.zeros(self.nk), self._part("b")]

    @property
    def F(self) -> np.ndarray:
        """F(q) coefficients from q⁰ (for ``linear='ss'``: ``det(qI − A)/qⁿ``)."""
        return np.r_[1.0, self._part("f")]

    @property
    def state_space(self):
        """``(A, b, C, d)`` of the state-space linear block (observer canonical form, module
        docstring; the input delayed by ``max(nk − 1, 0)`` samples before it); None for
        ``linear='oe'``."""
        if self.linear != "ss":
            return None
        n = self.nf
        A = np.eye(n, k=1)
        A[:, 0] = -self._part("a")
        C = np.zeros((1, n))
        C[0, 0] = 1.0
        d = self._part("d")
        return A, self._part("b")[:, None].copy(), C, np.array([[d[0] if d.size else 0.0]])

    @property
    def poles(self) -> np.ndarray:
        return np.roots(self.F) if self.nf else np.zeros(0)

    def input_nonlinearity(self, u) -> np.ndarray:
        """``f(u)`` of the identified input block."""
        return self.input_nl.evaluate(u, self._part("in"))

    def output_nonlinearity(self, x) -> np.ndarray:
        """``g(x)`` of the identified output block (without ``y0``)."""
        return self.output_nl.evaluate(x, self._part("out"))

    @property
    def parameters(self):
        """Every parameter with its unit and 1σ (:class:`gripkit.params.ParameterSet`)."""
        docs = {"b": "numerator coefficient of B(q) (carries the chain's gain)",
                "f": "denominator coefficient of F(q)",
                "y0": "output offset, in the output's unit"}
        if self.linear == "ss":
            docs.update(a="coefficient of det(zI − A), A in observer canonical form",
                        b="entry of the input vector b (carries the chain's gain)",
                        d="feedthrough of the linear block")
        ps = []
        for name, v, s in zip(self.names, self.theta, self.theta_std):
            if name.startswith(("in_", "out_")):
                blk, sub = name.split("_", 1)
                sig = "u, in the input's unit" if blk == "in" else "x, in the output's unit"
                doc = f"{'input' if blk == 'in' else 'output'} nonlinearity parameter {sub} " \
                      f"(signal {sig})"
            else:
                doc = docs["y0" if name == "y0" else name[0]]
            ps.append(Parameter(name, float(v), self._unit(name), doc, std=float(s),
                                source="identified (hammerstein_wiener)"))
        return ParameterSet(ps, name=f"hw {self.input_nl.label}/{self.output_nl.label}")

    def _unit(self, name: str) -> str:
        """The unit of parameter ``name`` under the gain normalisation (module docstring): ``w``
        carries the input's unit and ``x`` the output's, so B/F's ``b`` (and the state-space
        block's ``b``, ``d``) are in output unit per input unit and ``f``, ``a`` dimensionless;
        a nonlinearity's limits and thresholds (``lo``, ``hi``) and sigmoid weights ``a_k`` are
        in the unit of the signal entering it (u, or x), a polynomial's ``c_k`` in that unit to
        the power 1 − k, the slope changes ``d_k`` of pwl dimensionless; ``y0`` in the output's
        unit."""
        y, u = self.output_unit, self.input_unit
        if name == "y0":
            return product_unit((y, 1))
        blk, _, sub = name.partition("_")
        if blk not in ("in", "out"):
            return product_unit((y, 1), (u, -1)) if name[0] in "bd" else "1"
        sig = u if blk == "in" else y
        kind = (self.input_nl if blk == "in" else self.output_nl).kind
        if kind == "poly":
            return product_unit((sig, 1 - int(sub[1:])))
        return "1" if kind == "pwl" else product_unit((sig, 1))

    # -- simulation -------------------------------------------------------------------------
    def _problem(self, u) -> _Problem:
        return _problem([u], self.input_nl, self.output_nl, self.nb, self.nf, self.nk,
                        self.linear)

    def _columns(self, data, need_output: bool):
        if isinstance(data, Trajectory):
            self._check_rate(data, "hw.compare" if need_output else "hw.simulate")
            cols = [self.input_name] + ([self.output_name] if need_output else [])
            missing = [c for c in cols if c not in data.names]
            if missing:
                raise DataError(f"hw: the data have no column {missing[0]!r} (the model's "
                                f"{'input' if missing[0] == self.input_name else 'output'}); "
                                f"they have {', '.join(map(repr, data.names))}")
            return [_signal(self._column(data, r), c) for c, r in zip(cols, ("input", "output"))]
        a = np.asarray(data, dtype=np.float64)
        if a.ndim == 2 and a.shape[1] == (2 if need_output else 1) and a.shape[0] > 2:
            return [_signal(a[:, i], n) for i, n in enumerate(("u", "y")[:a.shape[1]])]
        if need_output:
            raise DataError(f"hw.compare: expected a Trajectory with columns {self.input_name!r}, "
                            f"{self.output_name!r} or an array (N, 2) of [u, y], found shape "
                            f"{a.shape}")
        return [_signal(a, "u")]

    def simulate(self, data, x0=None, *, std: bool = False, warn: bool = True,
                 initial_input=None):
        """Free run on ``data``'s input (a Trajectory with the model's input column, or an array
        (N,) of the record's values) → (N, 1), from the linear block's steady state under the
        constant input ``initial_input`` (w₋; default ``f(u(0))``, the steady state at the first
        input sample); a given ``x0`` is refused (the start is set by ``initial_input``).
        With ``std=True`` also its 1σ (N, 1) from the parameter covariance (linearised, module
        docstring). A diverging run is NaN from where it left the range, after a
        StabilityWarning."""
        self._refuse_x0(x0, "the steady state of its linear block under the constant input "
                            "initial_input (default f(u(0)), its first input sample)",
                        "give initial_input=… (the input level before the record; "
                        "model.fit_initial_input(u, y) fits it to a record)")
        u = self._columns(data, False)[0]
        if initial_input is None:
            initial_input = float(self.input_nonlinearity(u[:1])[0])
        prob = self._problem(u)
        prob.run(np.r_[self.theta, float(initial_input)], std)
        y = prob.yhat.copy()
        lo, hi = self._limits()
        out = np.flatnonzero(~((y >= lo) & (y <= hi)))
        if out.size:
            y[out[0]:] = np.nan
            if warn:
                emit_warning(f"hw: the free run diverges at sample {int(out[0])} (beyond "
                             f"{DIVERGENCE_FACTOR:g}× the estimation output's range); the model "
                             "does not hold on this input", StabilityWarning)
        if not std:
            return y[:, None]
        J = prob.jac[:, :-1]
        C = np.where(np.isfinite(self.covariance), self.covariance, 0.0)
        sd = np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", J, C, J), 0.0))
        loose = ~np.isfinite(self.theta_std)
        if loose.any():
            sd = np.where(np.any(np.abs(J[:, loose]) > 0, axis=1), np.inf, sd)
        return y[:, None], sd[:, None]

    def fit_initial_input(self, u, y) -> float:
        """The constant input w₋ whose steady state best starts the free run on ``(u, y)`` (Gauss–
        Newton on that one number, from ``f(u(0))``)."""
        u, y = _signal(u, "u"), _signal(y, "y")
        prob = self._problem(u)
        wm = float(self.input_nonlinearity(u[:1])[0])
        best = None
        for _ in range(20):
            if prob.run(np.r_[self.theta, wm], True) >= 0:
                break
            r = y - prob.yhat
            sse = float(r @ r)
            if best is not None and sse >= best[1]:
                break
            best = (wm, sse)
            j = prob.jac[:, -1]
            jj = float(j @ j)
            if jj == 0.0:
                break
            step = float(j @ r) / jj
            wm += step
            if abs(step) <= 1e-10 * (abs(wm) + 1e-10):
                break
        return float(u[0]) if best is None else best[0]

    def compare(self, data, y=None, *, warn: bool = True) -> ModelFit:
        """Free-run fit (%) on a record (:data:`HW_FIT`): a Trajectory with the input and output
        columns, an array (N, 2) of [u, y], or ``compare(u, y)`` (arrays in the record's values,
        no offset removed); the initial steady state is
        fitted to the record (:meth:`fit_initial_input`). None (with a StabilityWarning) when the
        run diverges."""
        if y is not None:
            u, yv = _signal(data, "u"), _signal(y, "y")
            if len(u) != len(yv):
                raise DataError(f"hw.compare: u has {len(u)} samples but y has {len(yv)}; pass a "
                                "pair of equal length")
        else:
            u, yv = self._columns(data, True)
        ys = self.simulate(u, warn=warn, initial_input=self.fit_initial_input(u, yv))
        fit = _fit_value(yv, ys[:, 0]) if np.all(np.isfinite(ys)) else None
        return ModelFit(self.outputs, [fit], ys, HW_FIT)

    def _measured(self, data, y) -> np.ndarray:
        """The record's output, as :meth:`compare` reads it (for ``residuals``)."""
        return _signal(y, "y") if y is not None else self._columns(data, True)[1]

    # -- files ------------------------------------------------------------------------------
    def to_dict(self) -> dict:
        fin = lambda v: float(v) if np.isfinite(v) else None  # noqa: E731
        nl = lambda n: {"kind": n.kind, "n": n.n, "consts": list(n.consts)}  # noqa: E731
        ss = {"linear": "ss", "order": self.order} if self.linear == "ss" else {}
        return dict(schema=SCHEMA, schema_version=SS_VERSION if ss else VERSION, kind=self.kind,
            input_nonlinearity=nl(self.input_nl), output_nonlinearity=nl(self.output_nl),
            **ss, nb=self.nb, nf=self.nf, nk=self.nk, dt=self.dt,
            y_range=[float(v) for v in self.y_range], names=self.names,
            theta=[float(v) for v in self.theta], theta_std=[fin(v) for v in self.theta_std],
            covariance=[[fin(v) for v in row] for row in self.covariance],
            fit_percent=self.fit_percent, validation_fit_percent=self.validation_fit_percent,
            criterion=self.criterion, **self.channel_document(), fit_definition=HW_FIT,
            initial_input=self.initial_input,
            candidates=[{k: (fin(v) if isinstance(v, float) else v) for k, v in c.items()}
                        for c in self.candidates],
            **({"records": self.records} if self.records else {}))


def _signal(x, name: str) -> np.ndarray:
    return np.ascontiguousarray(one_signal(x, name, "hw"))


def load_hw(path) -> HWModel:
    """Read a model written by :meth:`HWModel.save`; any other schema is refused."""
    p = Path(path)
    writer = "HWModel.save or `gripkit identify hw --out`"
    doc = read_family_document(p, SCHEMA, (VERSION, SS_VERSION), family="hw", writer=writer,
                               version_key="schema_version")
    order = Domain(0, integer=True)
    check_family_fields(doc, f"hw model file {str(p)!r}", writer,
                        numbers={"dt": SAMPLE_TIME, "nb": Domain(1, integer=True), "nf": order,
                                 "nk": order, "initial_input": Domain(optional=True)},
                        finite=("theta",), units=("input_unit", "output_unit"))
    try:
        nls = []
        for key in ("input_nonlinearity", "output_nonlinearity"):
            d = doc[key]
            base = parse_nonlinearity(d["kind"] + (f":{int(d['n'])}" if d["kind"] in DEFAULT_N
                                                   else ""), key)
            nls.append(Nonlinearity(base.kind, base.n, tuple(float(c) for c in d["consts"])))
        theta = np.array(doc["theta"], dtype=np.float64)
        P = len(theta)
        nan = lambda v: np.nan if v is None else v  # noqa: E731
        std = np.array([np.inf if v is None else v for v in doc["theta_std"]], dtype=np.float64)
        cov = np.array([[nan(v) for v in row] for row in doc["covariance"]], dtype=np.float64)
        linear = doc.get("linear", "oe")
        if (linear == "ss") != (doc["schema_version"] == SS_VERSION) or linear not in LINEAR:
            raise ValueError(f"linear block {linear!r} in a file of schema_version "
                             f"{doc['schema_version']}")
        if linear == "ss" and not int(doc["nb"]) == int(doc["nf"]) == int(doc["order"]):
            raise ValueError(f"a state-space block of order {doc['order']!r} with nb = "
                             f"{doc['nb']!r}, nf = {doc['nf']!r}")
        m = HWModel(nls[0], nls[1], int(doc["nb"]), int(doc["nf"]), int(doc["nk"]), theta, std,
                    cov.reshape(P, P), linear=linear, dt=float(doc["dt"]),
                    y_range=tuple(doc["y_range"]),
                    fit_percent=doc.get("fit_percent"),
                    validation_fit_percent=doc.get("validation_fit_percent"),
                    criterion=str(doc.get("criterion", "")),
                    **channel_fields(doc), **file_provenance(doc),
                    initial_input=(None if doc.get("initial_input") is None
                                   else float(doc["initial_input"])),
                    candidates=[dict(c) for c in doc.get("candidates", [])],
                    records=[dict(r) for r in doc.get("records", [])])
    except (KeyError, TypeError, ValueError, ArgumentError) as exc:
        raise ModelError(f"{str(p)!r}: a malformed {SCHEMA} ({type(exc).__name__}: {exc}); write "
                         "it again with HWModel.save") from None
    if len(m.names) != P or len(std) != P or min(m.nb, m.nf + 1, m.nk + 1) < 1:
        raise ModelError(f"{str(p)!r}: {P} parameters but the structure needs {len(m.names)}; "
                         "write it again with HWModel.save")
    if (m.input_nl.kind in ("pwl", "sigmoid") and len(m.input_nl.consts) < m.input_nl.n) or (
            m.output_nl.kind in ("pwl", "sigmoid") and len(m.output_nl.consts) < m.output_nl.n):
        raise ModelError(f"{str(p)!r}: a pwl/sigmoid block without its breakpoints; write it "
                         "again with HWModel.save")
    return m


def linear_orders(linear, order, nb, nf, nk, flag: str = "") -> tuple:
    """``linear`` and its orders checked → ``(nb, nf, nk)`` (each None where searched; for
    ``'ss'`` ``nb = nf = order``). ``flag``: ``'--'`` names them as the CLI's options."""
    nm = {k: flag + k for k in ("linear", "order", "nb", "nf", "nk")}
    if not isinstance(linear, str) or linear not in LINEAR:
        raise ArgumentError(f"hammerstein_wiener: {nm['linear']} must be 'oe' (the output-error "
                            f"block B/F) or 'ss' (the state-space block), found {linear!r:.40}")
    nk = None if nk is None else _order(nk, nm["nk"], 0)
    if linear == "oe":
        if order is not None:
            raise ArgumentError(f"hammerstein_wiener: {nm['order']} {order!r:.20} is the state "
                                f"dimension of the state-space block; with {nm['linear']} oe "
                                f"give {nm['nb']} and {nm['nf']}, or choose {nm['linear']} ss")
        return (None if nb is None else _order(nb, nm["nb"], 1),
                None if nf is None else _order(nf, nm["nf"], 0), nk)
    if nb is not None or nf is not None:
        raise ArgumentError(f"hammerstein_wiener: {nm['nb']}/{nm['nf']} (found {nb!r:.20}/"
                            f"{nf!r:.20}) are the orders of the output-error block; with "
                            f"{nm['linear']} ss give {nm['order']} (the state dimension), or "
                            f"choose {nm['linear']} oe")
    n = None if order is None else _order(order, nm["order"], 1)
    return n, n, nk


def _order(v, name: str, lo: int) -> int:
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not lo <= v <= 20:
        raise ArgumentError(f"hammerstein_wiener: {name} must be an integer from {lo} to 20, "
                            f"found {v!r}")
    return int(v)


def _linear_start(demeaned, nb, nf, nk, linear, bla=None):
    """The linear block's start ``(parameters, static gain)`` on the demeaned records: the ARX
    (``'oe'``) or subspace (``'ss'``) start, or with ``bla`` (:func:`_bla`, a periodic record)
    the weighted frequency-domain fit of the best linear approximation."""
    if linear == "ss":
        _check_length(demeaned, nb + (nk == 0), nf, nk, f"order={nb}, nk={nk}")
        lin0 = _ss_start(demeaned, nb, nk) if bla is None else _bla_ss_start(bla, nb, nk)
        a, bd = lin0[:nb], lin0[nb:]
        gain = (bd[:nb].sum() + (bd[nb] * (1 + a.sum()) if nk == 0 else 0.0)) / (1 + a.sum())
        return lin0, gain
    if bla is None:
        b, f = _arx_start(demeaned, nb, nf, nk)
    else:
        _check_length(demeaned, nb, nf, nk)
        b, f = _bla_fit(bla, nb, nf, nk)
    return np.r_[b, f], b.sum() / (1 + f.sum())


def _fit_structure(recs, fin, fout, nb, nf, nk, lin_start=None, maxiter=200, linear="oe",
                   bla=None):
    """Fit one structure (orders given; ``linear='ss'``: the state-space block of order
    ``nb = nf``) to the records ``recs`` (a list of ``(u, y)``) from the linear start
    ``[linear block, y0, w₋ of each record]`` (without one: the linear model from the ARX or,
    for ``'ss'``, the subspace start, or with ``bla`` from the best linear approximation's
    frequency-domain fit: :func:`_linear_start`); several limit starts, the best kept. Returns
    (``[θ, w₋ …]``, SSE, J, problem)."""
    us = [r[0] for r in recs]
    u, y = np.concatenate(us), np.concatenate([r[1] for r in recs])
    if lin_start is None:
        demeaned = [(ur - u.mean(), yr - y.mean()) for ur, yr in recs]
        lin0, gain = _linear_start(demeaned, nb, nf, nk, linear, bla)
        prob = _problem(us, Nonlinearity(), Nonlinearity(), nb, nf, nk, linear)
        th0 = np.r_[lin0, y.mean() - gain * u.mean(), [ur[0] for ur in us]]
        th, sse, J, _ = _lm(prob, y, th0, maxiter)
        if fin.kind == "none" and fout.kind == "none":
            return th, sse, J, prob
        lin_start = th
    # the signal entering each block under the linear start
    lin = _problem(us, Nonlinearity(), Nonlinearity(), nb, nf, nk, linear)
    L = lin.L
    lpar, y0, wpre = lin_start[:L], lin_start[L], lin_start[L + 1:]
    lin.run(lin_start, False)
    xlin = lin.inner.copy()
    fin = _with_consts(fin, u)
    fout = _with_consts(fout, xlin)
    prob = _problem(us, fin, fout, nb, nf, nk, linear)
    best = None
    for pin in _limit_starts(fin, u):
        for pout in _limit_starts(fout, xlin):
            th0 = np.r_[pin, lpar, pout, y0, wpre]
            if not prob.admissible(th0):
                continue
            th, sse, J, _ = _lm(prob, y, th0, maxiter)
            if J is not None and (best is None or sse < best[1]):
                best = (th, sse, J)
    if best is None:
        raise IdentificationError(f"hammerstein_wiener: no start of the {fin.label}/{fout.label} "
                                  "structure gave a finite free run; check the data's scale")
    return best[0], best[1], best[2], prob


def _excitation_check(model: HWModel, us: list):
    """Name a saturation limit or dead-zone threshold that the data (the records' inputs ``us``)
    never cross."""
    for where, nl, sig in (("input", model.input_nl, None), ("output", model.output_nl, None)):
        if nl.kind not in ("saturation", "deadzone"):
            continue
        if where == "input":
            v = np.concatenate(us)
        else:
            prob = _problem(us, model.input_nl, model.output_nl, model.nb, model.nf, model.nk,
                            model.linear)
            w0 = ([r["initial_input"] for r in model.records] if model.records
                  else [model.initial_input])
            prob.run(np.r_[model.theta, w0], False)
            v = prob.inner.copy()
        lo, hi = model._part("in" if where == "input" else "out")
        below, above = int(np.sum(v < lo)), int(np.sum(v > hi))
        inside = len(v) - below - above
        sname = "u" if where == "input" else "x (the linear block's output)"
        if nl.kind == "deadzone" and below + above == 0:
            raise IdentificationError(
                f"hammerstein_wiener: the {where} dead zone [{lo:.6g}, {hi:.6g}] is never left: "
                f"all {len(v)} samples of {sname} lie inside it, so the output does not depend on "
                "the input; excite beyond the dead zone or choose another nonlinearity")
        few = max(3, math.ceil(0.005 * len(v)))
        if nl.kind == "deadzone" and min(below, above, inside) < few:
            where_ = ("below the lower threshold" if below < few else
                      "above the upper threshold" if above < few else "inside it")
            k = min(below, above, inside)
            emit_warning(f"hammerstein_wiener: the data never cross the {where} dead zone "
                         f"[{lo:.6g}, {hi:.6g}]: only {k} of {len(v)} samples of {sname} lie "
                         f"{where_}, so its thresholds are not identified (σ = inf, or "
                         "confounded with the offset y0); excite both sides of the dead zone",
                         AccuracyWarning)
        if nl.kind == "saturation" and min(below, above) < few:
            side = "lower" if below < few else "upper"
            k = min(below, above)
            emit_warning(f"hammerstein_wiener: the {where} saturation's {side} limit "
                         f"{lo if below < few else hi:.6g} is never reached by the data (only {k} "
                         f"of {len(v)} samples of {sname} beyond it), so it is not identified "
                         "(σ = inf or meaningless); excite beyond the limit or choose another "
                         "nonlinearity", AccuracyWarning)


def _check_data(u, y, dt, maxiter):
    """The estimation record as two finite signals of equal length, neither constant; ``dt`` and
    ``maxiter`` checked. Returns ``(u, y)``."""
    u, y = _signal(u, "u"), _signal(y, "y")
    if len(u) != len(y):
        raise DataError(f"hammerstein_wiener: u has {len(u)} samples but y has {len(y)}; pass a "
                        "pair of equal length")
    check_scale(("u",), u, "input", "Hammerstein-Wiener identification")
    check_scale(("y",), y, "output", "Hammerstein-Wiener identification")
    not_constant(y, "the output", "hammerstein_wiener",
                 "there is nothing to identify: check the output column")
    not_constant(u, "the input", "hammerstein_wiener", "it excites nothing: check the input column")
    if dt is not None and not (isinstance(dt, (int, float, np.floating)) and np.isfinite(dt)
                               and dt > 0):
        raise ArgumentError(f"hammerstein_wiener: dt must be a positive sample interval in s, "
                            f"found {dt!r}")
    if isinstance(maxiter, bool) or not isinstance(maxiter, (int, np.integer)) or maxiter < 1:
        raise ArgumentError(f"hammerstein_wiener: maxiter must be an integer ≥ 1, found "
                            f"{maxiter!r}")
    return u, y


def _check_validation(validate):
    """``validate=(u2, y2)`` as two finite signals of equal length (≥ 10 samples), or None."""
    if validate is None:
        return None
    try:
        uv, yv = validate
    except (TypeError, ValueError):
        raise ArgumentError("hammerstein_wiener: validate must be a pair (u, y) of validation "
                            "data") from None
    uv, yv = _signal(uv, "validate u"), _signal(yv, "validate y")
    if len(uv) != len(yv) or len(uv) < 10:
        raise DataError(f"hammerstein_wiener: validation u has {len(uv)} and y {len(yv)} "
                        "samples; need a pair of equal length (≥ 10 samples)")
    return uv, yv


def _order_candidates(nb, nf, nk) -> list:
    """The ``(nb, nf, nk)`` tried in step (1): :data:`AUTO_ORDERS` × :data:`AUTO_NK` with each
    given order in place of its candidates, without repeats."""
    orders = [(b_, f_, k_) for b_, f_ in AUTO_ORDERS for k_ in AUTO_NK]
    orders = [(nb if nb is not None else b_, nf if nf is not None else f_,
               nk if nk is not None else k_) for b_, f_, k_ in orders]
    return list(dict.fromkeys(orders))


class _Search:
    """What the steps of :func:`hammerstein_wiener` share: the estimation record, the validation
    record (or None), the linear fits at each order (``lin_fits``: orders → ``([θ, w₋], SSE, J)``)
    and the progress bar; builds candidate models and scores them (validation free-run fit, or
    −BIC)."""

    def __init__(self, recs, validation, dt, maxiter, bar, linear="oe", bla=None):
        self.recs, self.linear, self.bla = recs, linear, bla
        self.us = [r[0] for r in recs]
        self.u, self.y = np.concatenate(self.us), np.concatenate([r[1] for r in recs])
        y = self.y
        self.uv, self.yv = validation if validation is not None else (None, None)
        self.n = len(y)
        self.R = len(recs)
        self.dt = 1.0 if dt is None else float(dt)
        self.maxiter = maxiter
        self.y_range = (float(y.min()), float(y.max()))
        self.lin_fits = {}
        self.bar = bar

    @property
    def chosen_by(self) -> str:
        return "validation free-run fit" if self.uv is not None else "BIC"

    def step(self):
        """One step of the progress bar."""
        next(self.bar, None)

    def make(self, fin, fout, o, the, sse, J) -> HWModel:
        """The model of structure ``fin``/``fout`` at orders ``o`` from ``[θ, w₋]``, its SSE and
        Jacobian (σ with w₋: its uncertainty is in every other σ)."""
        cov, std = _covariance(J, sse)
        P = len(the) - self.R
        m = HWModel(fin, fout, o[0], o[1], o[2], the[:P], std[:P], cov[:P, :P], dt=self.dt,
                    y_range=self.y_range, linear=self.linear)
        m.initial_input = float(the[P])
        if self.R > 1:
            m.records = [{"n_samples": len(ur), "initial_input": float(w)}
                         for ur, w in zip(self.us, the[P:])]
        return m

    def score(self, m: HWModel, sse: float) -> float:
        """Higher is better: the validation free-run fit (−inf when the run diverges), or −BIC."""
        n = self.n
        if self.uv is None:
            return -(n * math.log(max(sse, 1e-300) / n) + len(m.theta) * math.log(n))
        f = m.compare(self.uv, self.yv, warn=False).fit_percent[0]
        return -math.inf if f is None else f

    def fit_at(self, fin, fout, o):
        """Fit structure ``fin``/``fout`` at orders ``o`` from the linear fit there → ``(score,
        model, (fin, fout))``."""
        if fin.kind == "none" and fout.kind == "none":
            th, sse, J = self.lin_fits[o]
            fin_c, fout_c = fin, fout
        else:
            th, sse, J, prob = _fit_structure(self.recs, fin, fout, *o,
                                              lin_start=self.lin_fits[o][0], maxiter=self.maxiter,
                                              linear=self.linear)
            fin_c, fout_c = prob.fin, prob.fout
        m = self.make(fin_c, fout_c, o, th, sse, J)
        return self.score(m, sse), m, (fin, fout)


def _choose_orders(search: _Search, orders: list) -> tuple:
    """Step (1): the linear output-error model at every candidate order (at most
    :data:`SCREEN_ITERATIONS` iterations each when there are several), ranked by score; the best
    one's fit then runs to convergence. Returns its orders ``(nb, nf, nk)``."""
    lin_fits, maxiter = search.lin_fits, search.maxiter
    screen = maxiter if len(orders) == 1 else min(maxiter, SCREEN_ITERATIONS)
    for o in orders:
        search.step()
        th, sse, J, _ = _fit_structure(search.recs, Nonlinearity(), Nonlinearity(), *o,
                                       maxiter=screen, linear=search.linear, bla=search.bla)
        if J is None:
            continue
        lin_fits[o] = (th, sse, J)
    if not lin_fits:
        raise IdentificationError("hammerstein_wiener: no linear start gave a finite free run; "
                                  "check the data's scale")
    ranked = sorted(lin_fits, key=lambda o: -search.score(
        search.make(Nonlinearity(), Nonlinearity(), o, *lin_fits[o]), lin_fits[o][1]))
    o = ranked[0]
    if screen < maxiter:  # the chosen orders' linear model to convergence
        th, sse, J, _ = _lm(_problem(search.us, Nonlinearity(), Nonlinearity(), *o,
                                     search.linear), search.y, lin_fits[o][0], maxiter)
        lin_fits[o] = (th, sse, J)
    return o


def _fit_candidates(search: _Search, structures: list, o: tuple, auto: bool) -> list:
    """Step (2): every structure at orders ``o`` and, when the structure is searched, the
    Hammerstein–Wiener candidates that join the :data:`N_JOINED` best input blocks to the
    :data:`N_JOINED` best output blocks. Returns ``(score, model, (fin, fout))``, best first."""
    cands = []
    for fin, fout in structures:
        search.step()
        cands.append(search.fit_at(fin, fout, o))
    ins = sorted((c for c in cands if c[2][0].kind != "none" and c[2][1].kind == "none"),
                 key=lambda c: -c[0])[:N_JOINED]
    outs = sorted((c for c in cands if c[2][0].kind == "none" and c[2][1].kind != "none"),
                  key=lambda c: -c[0])[:N_JOINED]
    for ci in ins if auto else ():
        for co in outs:
            search.step()
            cands.append(search.fit_at(ci[2][0], co[2][1], o))
    cands.sort(key=lambda c: -c[0])
    return cands


def _refit_dynamics(search: _Search, cands: list, o: tuple, dyn: list, searched: bool) -> list:
    """Step (3): a nonlinear structure may need fewer poles than the linear approximation, so
    when ``(nb, nf)`` were searched and the best candidate is nonlinear, it is fitted again at
    the other ``(nb, nf)`` of ``dyn`` with the delay of step (1). Returns those candidates."""
    refit = []
    if searched and cands[0][1].kind != "linear":
        for b_, f_ in dyn:
            if (b_, f_, o[2]) != o and (b_, f_, o[2]) in search.lin_fits:
                search.step()
                refit.append(search.fit_at(*cands[0][2], (b_, f_, o[2])))
    return refit


def _pick(cands: list, validated: bool) -> HWModel:
    """The best candidate (``cands`` best first), with every candidate's score in
    ``candidates``. With validation data, parsimony: among those within
    :data:`PARSIMONY_POINTS` of the best, one whose parameters the data all determine (finite σ)
    before one that is not, then the fewest parameters."""
    best = cands[0][1]
    if validated:
        best = min((c for c in cands if c[0] >= cands[0][0] - PARSIMONY_POINTS),
                   key=lambda c: (not np.all(np.isfinite(c[1].theta_std)), len(c[1].theta)))[1]
    best.candidates = [{"input": c[1].input_nl.label, "output": c[1].output_nl.label,
                        **({"linear": "ss", "order": c[1].order} if c[1].linear == "ss" else
                           {"nb": c[1].nb, "nf": c[1].nf}), "nk": c[1].nk,
                        ("validation_fit_percent" if validated else "bic"):
                        (c[0] if validated else -c[0])} for c in cands]
    return best


def _criterion(best: HWModel, orders_chosen: bool, auto: bool, chosen_by: str,
               n_structures: int, n_joined: int, refit: bool) -> str:
    """One line on how the orders and the structure of ``best`` were chosen."""
    what = []
    if orders_chosen and best.linear == "ss":
        what.append(f"state-space order {best.order}, nk = {best.nk} by {chosen_by} (the delay "
                    f"on the linear model{'; the order again for the structure' * refit})")
    elif orders_chosen:
        what.append(f"orders [nb nf nk] = [{best.nb} {best.nf} {best.nk}] by {chosen_by} (the "
                    f"delay on the linear model"
                    f"{'; nb and nf again for the structure' if refit else ''})")
    if auto:
        what.append(f"structure {best.input_nl.label}/{best.output_nl.label} by {chosen_by} "
                    f"among {n_structures} and {n_joined} joined")
    return "; ".join(what) if what else "structure and orders given"


def _finish(best: HWModel, search: _Search) -> HWModel:
    """Name what the data do not excite or determine (:func:`_excitation_check`, an
    AccuracyWarning for parameters with σ = inf) and set the free-run fits of ``best``."""
    _excitation_check(best, search.us)
    loose = [n for n, sd in zip(best.names, best.theta_std) if not np.isfinite(sd)]
    if loose:
        emit_warning(f"hammerstein_wiener: the data do not determine {', '.join(loose)} of the "
                     f"{best.input_nl.label}/{best.output_nl.label} model (σ = inf: they trade "
                     "off against other parameters without changing the output); excite more "
                     "amplitudes, or choose a simpler block", AccuracyWarning)
    if search.R == 1:
        best.fit_percent = best.compare(search.u, search.y).fit_percent[0]
    else:  # each record from its own steady state; the fit over all their samples together
        fits = [best.compare(ur, yr) for ur, yr in search.recs]
        for rec, f in zip(best.records, fits):
            rec["fit_percent"] = f.fit_percent[0]
        ys = np.concatenate([f.simulated[:, 0] for f in fits])
        best.fit_percent = _fit_value(search.y, ys) if np.all(np.isfinite(ys)) else None
    if search.uv is not None:
        best.validation_fit_percent = best.compare(search.uv, search.yv).fit_percent[0]
    return best


def _records(u, y) -> list:
    """``(u, y)``, or ``u`` a list of records ``(u_i, y_i)`` when ``y`` is None → a list of
    checked pairs (names ``records[i]``)."""
    if y is not None:
        return [(u, y)]
    if not isinstance(u, (list, tuple)) or not u:
        raise ArgumentError(f"hammerstein_wiener: without y, the data must be a non-empty list of "
                            f"records (u, y), found {type(u).__name__}",
                            hint="call hammerstein_wiener(u, y) or "
                                 "hammerstein_wiener([(u1, y1), (u2, y2)])")
    out = []
    for i, pair in enumerate(u):
        try:
            ui, yi = pair
        except (TypeError, ValueError):
            raise ArgumentError(f"hammerstein_wiener: records[{i}] must be a pair (u, y) of 1-D "
                                f"arrays, found {type(pair).__name__}") from None
        out.append((ui, yi))
    return out


def hammerstein_wiener(u, y=None, *, input_nonlinearity=None, output_nonlinearity=None,
                       nb: int | None = None, nf: int | None = None, nk: int | None = None,
                       linear: str = "oe", order: int | None = None,
                       dt: float | None = None, validate=None, maxiter: int = 200,
                       periods: int | None = None, progress: bool = False) -> HWModel:
    """Hammerstein, Wiener or Hammerstein–Wiener model of ``y`` driven by ``u`` (see the module
    docstring), or of several records: ``hammerstein_wiener([(u1, y1), (u2, y2), …])`` (each
    record's free run from its own steady state, its own ``w₋`` estimated with θ; one SSE over
    all of them, σ from all; ``fit_percent`` over all samples together and each record's in
    ``records``).

    ``input_nonlinearity`` / ``output_nonlinearity``: ``'none'``, ``'saturation'``,
    ``'deadzone'``, ``'poly[:N]'``, ``'pwl[:N]'``, ``'sigmoid[:N]'``; when both are None the
    structure is chosen among :data:`AUTO_STRUCTURES` (one None with the other given means
    ``'none'``). ``nb``, ``nf``, ``nk``: orders of B/F; each None is chosen (``(nb, nf)`` in
    (1,1), (2,2), (3,3); ``nk`` in 0, 1, 2) on the linear model. ``linear``: ``'oe'`` (B/F,
    default) or ``'ss'`` (the state-space block in observer canonical form, module docstring;
    ``order`` its state dimension, None: chosen in 1, 2, 3 as ``(nb, nf)`` are; ``nk`` its
    delay, 0 with a feedthrough ``d``; ``nb``, ``nf`` are not taken). Choice by free-run fit on
    ``validate=(u2, y2)`` when given, else by BIC. ``dt``: sample interval (s), default 1.
    ``periods``: the record is that many (≥ 3) whole periods of a periodic input (a multisine):
    the linear block starts from the weighted fit of its best linear approximation, the FRF with
    σ (module docstring, "Estimation"), in place of the ARX / subspace start; one record only.
    ``progress``: a progress bar on stderr (one step per structure and start).
    """
    recs = _records(u, y)
    for i, (ui, yi) in enumerate(recs):
        try:
            recs[i] = _check_data(ui, yi, dt, maxiter)
        except (DataError, ArgumentError) as exc:
            if len(recs) == 1:
                raise
            raise type(exc)(exc.message.replace("hammerstein_wiener: ", f"records[{i}]: ", 1)
                            .replace("hw: ", f"records[{i}]: ", 1), hint=exc.hint) from None
    auto = input_nonlinearity is None and output_nonlinearity is None
    structures = ([(parse_nonlinearity(a), parse_nonlinearity(b)) for a, b in AUTO_STRUCTURES]
                  if auto else [(parse_nonlinearity(input_nonlinearity, "input_nonlinearity"),
                                 parse_nonlinearity(output_nonlinearity, "output_nonlinearity"))])
    nb, nf, nk = linear_orders(linear, order, nb, nf, nk)
    validation = _check_validation(validate)
    bla = None if periods is None else _bla(*recs[0], check_periods(periods, len(recs)))
    orders = _order_candidates(nb, nf, nk)
    searched = nb is None or nf is None
    dyn = list(dict.fromkeys((nb if nb is not None else b_, nf if nf is not None else f_)
                             for b_, f_ in AUTO_ORDERS))
    steps = (len(orders) + len(structures) + (N_JOINED**2 if auto else 0)
             + (len(dyn) - 1 if searched else 0))
    bar = iter(track(range(steps), total=steps, description="hw fit", enabled=progress))
    search = _Search(recs, validation, dt, maxiter, bar, linear, bla)
    o = _choose_orders(search, orders)
    cands = _fit_candidates(search, structures, o, auto)
    refit = _refit_dynamics(search, cands, o, dyn, searched)
    for _ in bar:  # the bar's remaining steps (orders not searched), so that it ends at 100 %
        continue
    cands = sorted(cands + refit, key=lambda c: -c[0])
    best = _pick(cands, validation is not None)
    best.criterion = _criterion(best, nb is None or nf is None or nk is None, auto,
                                search.chosen_by, len(structures),
                                len(cands) - len(structures) - len(refit), bool(refit))
    if bla is not None:
        best.criterion += (f"; linear start from the best linear approximation (FRF of "
                           f"{periods} periods, the first dropped)")
    return _finish(best, search)
