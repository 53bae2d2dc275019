"""Stability margins and closed-loop poles of a controller on an identified model, **with σ**:
a Monte Carlo over the model's parameter covariance.

The loop is broken at the plant input: ``L(z) = C(z) G(z)`` with G the discrete SISO plant
(:func:`gripkit.control.as_plant`) and C the controller's feedback path — a
:class:`~gripkit.control.PID`'s ``U/E`` (:meth:`PID.transfer_function`, linear region), an
:class:`~gripkit.control.RSTController`'s ``S/R`` — or a discrete ``(num, den)`` pair in powers of
z; for a single-input :class:`~gripkit.control.StateFeedback` ``L(z) = K (zI − A)⁻¹ B`` on the
model's state space. For L:

* **gain margin** (:func:`loop_margins`): 1/|L| at the phase crossovers (Im L = 0, Re L < 0) on
  0 < ω ≤ π/dt (the Nyquist frequency counts where Im L vanishes there to
  :data:`NYQUIST_IM_TOL` relative: a real discrete loop at z = −1 with Re L < 0, such as a PI
  on b q⁻¹/(1 − a q⁻¹), whose phase reaches −180° exactly there), the one closest to 1 in log
  scale; **phase margin**: arg L + 180° (wrapped to (−180°, 180°]) at the gain crossovers
  (|L| = 1), the smallest in magnitude: the selection of python-control's
  ``stability_margins`` (whose version 0.10 leaves z = −1 out: inf there). Found on a grid of
  ``n_grid`` frequencies (log-spaced from 1e-5·π/dt and linear up to π/dt, π/dt included) by
  sign changes, refined by Brent's method to 1e-14 relative in ω;
* **closed-loop poles**: the roots of ``den_C den_G + num_C num_G``; the loop is stable when all
  lie inside the unit circle.

:func:`robustness` draws ``n`` plants θ ~ N(θ̂, Σ) from the model's parameter covariance
(:meth:`gripkit.lti.LinearSystem.sample`: a first-order propagation of the covariance into the
plant's coefficients, as the identified model carries it) and returns the distributions of the
margins, the largest closed-loop pole radius and the probability that the loop is stable.
A model without covariance (a state-space model from ``n4sid``/PEM that kept none, a model built
from known coefficients) gives the nominal figures only (``n = 0``), and asking for samples from
it is a ModelError that says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

from ..errors import ArgumentError, ModelError
from .linear_quadratic import _discrete
from .pid import PID
from .rst import RSTController, as_plant
from .state_feedback import StateFeedback

__all__ = ["Robustness", "controller_transfer_function", "frequency_margins", "loop_margins",
           "robustness"]

#: Im L at ω = π/dt within this of |L| counts as zero there (a real loop's L(−1), rounded)
NYQUIST_IM_TOL = 1e-9


def controller_transfer_function(controller) -> tuple[np.ndarray, np.ndarray, float | None]:
    """(num, den, dt) of the controller's feedback path C(z) in descending powers of z."""

    if isinstance(controller, PID):
        num, den = _tf_z(controller.transfer_function())
        return num, den, controller.dt
    if isinstance(controller, RSTController):
        n = max(controller.R.size, controller.S.size)
        num = np.pad(np.asarray(controller.S, float), (0, n - controller.S.size))
        den = np.pad(np.asarray(controller.R, float), (0, n - controller.R.size))
        return num, den, controller.dt
    if isinstance(controller, tuple) and len(controller) in (2, 3):
        num = np.atleast_1d(np.asarray(controller[0], dtype=float))
        den = np.atleast_1d(np.asarray(controller[1], dtype=float))
        if num.ndim != 1 or den.ndim != 1 or not (np.isfinite(num).all()
                                                  and np.isfinite(den).all()):
            raise ArgumentError("controller: expected (num, den) of finite coefficients in powers "
                                "of z")
        return num, den, (float(controller[2]) if len(controller) == 3 else None)
    raise ArgumentError(f"controller: expected a gripkit.control.PID, RSTController, "
                        f"StateFeedback or a (num, den[, dt]) pair in powers of z, found "
                        f"{type(controller).__name__}")


def _tf_z(g) -> tuple[np.ndarray, np.ndarray]:
    return np.asarray(g.num, float)[0, 0], np.asarray(g.den, float)[0, 0]


def _grid(dt: float, n_grid: int) -> np.ndarray:
    wn = math.pi / dt
    w = np.unique(np.concatenate([np.geomspace(1e-5 * wn, wn, n_grid // 2),
                                  np.linspace(0.0, wn, n_grid // 2 + 1)[1:]]))
    return np.r_[w[w < wn], wn]


def loop_margins(num, den, dt: float, *, n_grid: int = 4000) -> dict:
    """Gain margin (ratio and dB), phase margin (deg) and their frequencies (rad/s) of the
    discrete loop ``L = num/den`` (powers of z) by the rules of the module docstring; ``inf``
    (and NaN frequency) where L has no such crossover."""
    num, den = np.asarray(num, float), np.asarray(den, float)

    def L(w):
        z = np.exp(1j * np.asarray(w) * dt)
        return np.polyval(num, z) / np.polyval(den, z)

    return frequency_margins(L, dt, n_grid=n_grid)


def frequency_margins(L, dt: float, *, n_grid: int = 4000) -> dict:
    """:func:`loop_margins` of a loop given by its frequency response ``L(ω)`` (a function of
    ω in rad/s, an array or a scalar, returning complex values) on 0 < ω ≤ π/dt: a sampled
    controller on a continuous plant with delay (:func:`gripkit.control.tune_pid` on a
    :class:`~gripkit.control.LowOrderModel`)."""
    w = _grid(dt, n_grid)
    with np.errstate(divide="ignore", invalid="ignore"):
        Lw = L(w)
    fin = np.isfinite(Lw)

    def roots(f, vals):
        out = []
        s = np.sign(vals)
        for i in np.flatnonzero((s[:-1] * s[1:] < 0) & fin[:-1] & fin[1:]):
            out.append(brentq(f, w[i], w[i + 1], xtol=1e-300, rtol=1e-14, maxiter=200))
        for i in np.flatnonzero((vals == 0) & fin):
            out.append(float(w[i]))
        return out

    im = np.imag(Lw)
    if abs(im[-1]) <= NYQUIST_IM_TOL * abs(Lw[-1]):  # z = −1: L real there (up to rounding)
        im[-1] = 0.0
    w180 = [x for x in roots(lambda x: float(np.imag(L(x))), im) if np.real(L(x)) <= 0]
    wc = roots(lambda x: float(abs(L(x)) - 1.0), np.abs(Lw) - 1.0)
    gm, wg = math.inf, math.nan
    if w180:
        with np.errstate(divide="ignore"):
            g = np.array([1.0 / abs(L(x)) for x in w180])
        i = int(np.argmin(np.abs(np.log(g))))
        gm, wg = float(g[i]), float(w180[i])
    pm, wp = math.inf, math.nan
    if wc:
        p = np.array([np.remainder(np.angle(L(x), deg=True), 360.0) - 180.0 for x in wc])
        i = int(np.argmin(np.abs(p)))
        pm, wp = float(p[i]), float(wc[i])
    return dict(gain_margin=gm, gain_margin_db=20 * math.log10(gm) if gm not in (0.0, math.inf)
                else (math.inf if gm == math.inf else -math.inf),
                phase_margin_deg=pm, w_gain_margin=wg, w_phase_margin=wp)


def _loop(cnum, cden, g):
    gn, gd = _tf_z(g)
    ln, ld = np.polymul(cnum, gn), np.polymul(cden, gd)
    poles = np.roots(np.trim_zeros(np.polyadd(ld, ln), "f"))
    return ln, ld, poles


@dataclass(frozen=True)
class Robustness:
    """What :func:`robustness` returns. ``nominal``: the margins of :func:`loop_margins` on the
    identified model, its closed-loop ``poles`` and ``stable``. Per Monte Carlo sample (arrays of
    length ``n``; empty without covariance): ``gain_margin_db``, ``phase_margin_deg``,
    ``pole_radius`` (largest closed-loop |pole|), ``stable``; ``probability_stable`` (NaN when
    n = 0) and its binomial standard error."""

    nominal: dict
    poles: np.ndarray
    stable: bool
    gain_margin_db: np.ndarray
    phase_margin_deg: np.ndarray
    pole_radius: np.ndarray
    stable_samples: np.ndarray
    n: int
    seed: int | None
    dt: float
    notes: tuple = field(default_factory=tuple)

    @property
    def probability_stable(self) -> float:
        return float(np.mean(self.stable_samples)) if self.n else math.nan

    @property
    def probability_stable_se(self) -> float:
        p = self.probability_stable
        return math.sqrt(p * (1 - p) / self.n) if self.n else math.nan

    def statistics(self) -> dict:
        """``{quantity: {nominal, mean, std, p05, p50, p95}}`` over the stable samples' finite
        margins (an unstable sample's margins describe no working loop)."""
        rows = {}
        nom = dict(gain_margin_db=self.nominal["gain_margin_db"],
                   phase_margin_deg=self.nominal["phase_margin_deg"],
                   pole_radius=float(np.max(np.abs(self.poles))) if self.poles.size else 0.0)
        for k in ("gain_margin_db", "phase_margin_deg", "pole_radius"):
            v = getattr(self, k)
            if k != "pole_radius":
                v = v[self.stable_samples]
            v = v[np.isfinite(v)]
            q = np.percentile(v, [5, 50, 95]) if v.size else [math.nan] * 3
            rows[k] = dict(nominal=nom[k], mean=float(np.mean(v)) if v.size else math.nan,
                           std=float(np.std(v, ddof=1)) if v.size > 1 else math.nan,
                           p05=float(q[0]), p50=float(q[1]), p95=float(q[2]), count=int(v.size))
        return rows

    def to_dict(self) -> dict:
        def num(x):
            return None if not math.isfinite(x) else float(x)
        return dict(nominal={k: num(v) for k, v in self.nominal.items()}, stable=self.stable,
                    poles=[[float(p.real), float(p.imag)] for p in self.poles],
                    n=self.n, seed=self.seed, dt=self.dt,
                    probability_stable=num(self.probability_stable),
                    probability_stable_se=num(self.probability_stable_se),
                    statistics={k: {kk: (num(vv) if isinstance(vv, float) else vv)
                                    for kk, vv in r.items()}
                                for k, r in self.statistics().items()},
                    notes=list(self.notes))


def _state_feedback_loop(sf, ss):
    """(num, den, closed-loop poles) of L(z) = K (zI − A)⁻¹ B for a single-input state feedback
    on the discrete state space ``ss`` (the loop broken at the plant input)."""
    from scipy.signal import ss2tf

    A, B = np.asarray(ss.A, float), np.asarray(ss.B, float)
    num, den = ss2tf(A, B, np.asarray(sf.K, float), np.zeros((1, 1)))
    return num[0], den, np.linalg.eigvals(A - B @ np.asarray(sf.K, float))


def robustness(model, controller, n: int = 1000, seed: int | None = None, *,
               n_grid: int = 4000) -> Robustness:
    """Nominal margins and closed-loop poles of ``controller`` on ``model``, and their
    distributions over ``n`` plants drawn from the model's parameter covariance (module
    docstring). ``seed`` makes the draw reproducible.

    A single-input :class:`~gripkit.control.StateFeedback` (an LQR gain) is analysed on the
    model's own discrete state space, broken at the plant input: ``L(z) = K (zI − A)⁻¹ B`` and
    the closed-loop poles eig(A − B K); the samples are drawn in the same coordinates."""
    if not isinstance(n, (int, np.integer)) or isinstance(n, bool) or n < 0:
        raise ArgumentError(f"n: expected a number of Monte Carlo samples >= 0, found {n!r}")
    if isinstance(controller, StateFeedback):
        g = _discrete(model, controller.dt)
        if controller.n_inputs != 1 or controller.n_states != g.n_states:
            raise ArgumentError(
                f"robustness: a state feedback with {controller.n_inputs} inputs and "
                f"{controller.n_states} states on a model with {g.n_inputs} inputs and "
                f"{g.n_states} states: margins need one input and the model's own states",
                hint="break one loop yourself and pass (num, den) of it")
        cdt = controller.dt

        def loop(plant):
            return _state_feedback_loop(controller, plant)
    else:
        g = as_plant(model)
        cnum, cden, cdt = controller_transfer_function(controller)

        def loop(plant):
            return _loop(cnum, cden, plant)
    if cdt is not None and not math.isclose(cdt, g.dt, rel_tol=1e-9):
        raise ModelError(f"robustness: the controller runs at dt = {cdt:g} s but the model's "
                         f"sample time is {g.dt:g} s",
                         hint="design the controller for the model's dt (tune_pid does)")
    ln, ld, poles = loop(g)
    nominal = loop_margins(ln, ld, g.dt, n_grid=n_grid)
    stable = bool(np.all(np.abs(poles) < 1.0))
    notes = []
    gm = np.empty(n)
    pm = np.empty(n)
    rad = np.empty(n)
    st = np.zeros(n, dtype=bool)
    if n:
        if g.uncertainty is None:
            raise ModelError(
                f"robustness: the model ({type(model).__name__}) carries no parameter covariance, "
                f"so there is nothing to sample",
                hint="use n=0 for the nominal margins, or a model identified with its "
                     "covariance (arx/armax/oe, or a state-space model that kept one)")
        for i, gi in enumerate(g.sample(int(n), seed=seed)):
            a, b, p = loop(gi)
            r = float(np.max(np.abs(p))) if p.size else 0.0
            rad[i] = r
            st[i] = r < 1.0
            m = loop_margins(a, b, g.dt, n_grid=n_grid)
            gm[i], pm[i] = m["gain_margin_db"], m["phase_margin_deg"]
    else:
        notes.append("nominal only (n = 0)")
    return Robustness(nominal=nominal, poles=poles, stable=stable, gain_margin_db=gm,
                      phase_margin_deg=pm, pole_radius=rad, stable_samples=st, n=int(n),
                      seed=seed, dt=float(g.dt), notes=tuple(notes))

def _histograms(result: Robustness):
    from ..report.plots import pyplot

    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(8, 3.0))
    st = result.stable_samples
    for ax, key, label in ((axes[0], "gain_margin_db", "gain margin (dB)"),
                           (axes[1], "phase_margin_deg", "phase margin (deg)")):
        v = getattr(result, key)[st]
        v = v[np.isfinite(v)]
        if v.size:
            ax.hist(v, bins=min(40, max(5, v.size // 10)), color="C0", alpha=0.8)
        nom = result.nominal[key]
        if math.isfinite(nom):
            ax.axvline(nom, color="C3", lw=1.5, label="nominal")
            ax.legend(fontsize=8)
        ax.set_xlabel(label)
        ax.set_ylabel("draws")
        ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def robustness_section(report, result: Robustness, *, controller: str = "controller"):
    """Add the section "Robustness of the loop" to a :class:`gripkit.report.html.Report`: the
    nominal margins and poles, the Monte Carlo statistics and P(stable), and histograms of the
    margins (all text escaped by the report). Returns the section."""
    intro = (f"{controller} in the loop with the identified model, broken at the plant input. "
             "Gain margin: the phase crossover closest to 1 in log scale; phase margin: the "
             "smallest at a gain crossover (python-control's selection).")
    if result.n:
        intro += (f" {result.n} plants drawn from the parameter covariance (seed {result.seed}); "
                  "margin statistics over the stable draws.")
    else:
        intro += " The model carries no parameter covariance: nominal figures only."
    sec = report.section("Robustness of the loop", intro)
    rows = []
    names = {"gain_margin_db": "gain margin (dB)", "phase_margin_deg": "phase margin (deg)",
             "pole_radius": "largest closed-loop |pole|"}
    for key, r in result.statistics().items():
        rows.append([names[key], r["nominal"], r["mean"], r["std"], r["p05"], r["p50"], r["p95"]])
    sec.table(["quantity", "nominal", "mean", "σ", "5 %", "median", "95 %"], rows)
    if result.n:
        sec.text(f"Probability that the loop is stable: {result.probability_stable:.4f} "
                 f"± {result.probability_stable_se:.4f} (binomial standard error, {result.n} "
                 f"draws); the nominal loop is {'stable' if result.stable else 'UNSTABLE'}.")
        sec.figure(_histograms(result), "distribution of the margins over the stable draws",
                   name="robustness")
    else:
        sec.text(f"The nominal loop is {'stable' if result.stable else 'UNSTABLE'}.")
    return sec
