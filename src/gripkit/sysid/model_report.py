"""One self-contained HTML report of an identified linear model on a data record
(``model.report(data, out)`` of a linear model, which ``gripkit report MODEL.json DATA --out DIR``
and ``gripkit identify … --report DIR`` call).

Sections: measured against simulated output per output (free run, x0 estimated); residual
auto-correlation per output and cross-correlation with each input, with the ±1.96/√N band of
white, independent residuals (Ljung 2nd ed. §16.6); pole-zero map with the 1σ ellipse of each
pole (from the parameter covariance); Bode magnitude and phase with ±2σ bands, and the data's
Welch H1 estimate (with its ±2σ) beside them when the data allow; the subspace singular values
with the chosen order; the parameter table (:func:`parameters_section`: ``model.parameters``
with value, 1σ and unit, a step model's K, f_n, ζ and offset first); the warnings raised on the
way.

Measured records: the residuals are those of the model's predictor from the initial
state estimated by least squares over the record (:func:`residual_analysis`; innovation models:
``x̂⁺ = (A − KC) x̂ + (B − KD) u + K y``, whose prediction errors are affine in x0), as the free-run
comparison does, never from x0 = 0 — a predictor pole near the unit circle would carry a wrong
start through the whole record — and a predictor pole whose memory outlasts half the record is
warned about. The Bode magnitude axis is set by the model's |G| and the estimate lines that mean
something (:func:`meaningful_lines`: input power, σ below |H|), at most
:data:`ESTIMATE_MARGIN_DECADES` beyond the model's range.
"""

from __future__ import annotations

import math
import numbers
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import AccuracyWarning, ModelError, emit_warning
from ..report.html import Report
from ..report.plots import measured_vs_model, plain, pyplot
from .linear.frf import frf
from .linear.linear_model import VALIDATION_FIT, fit_per_output
from .linear.pem_ss import predictor_x0
from .linear.ss_bootstrap import bootstrapped, covariance_method

__all__ = ["write_model_report", "model_report", "parameters_section", "residual_analysis",
           "predictor_x0",
           "meaningful_lines", "bode_figure", "Residuals", "ESTIMATE_MARGIN_DECADES",
           "MIN_INPUT_POWER"]

#: an estimate line is drawn only where each input's Welch power is at least this fraction of
#: that input's largest line (−40 dB): below it H1 divides noise by leakage
MIN_INPUT_POWER = 1e-4
#: the Bode magnitude axis reaches at most this many decades beyond the model's |G| range to show
#: estimate lines; the model's own range counts at most MODEL_DECADES below its peak
ESTIMATE_MARGIN_DECADES = 2.0
MODEL_DECADES = 8.0
#: a predictor whose initial-state error needs more than this fraction of the record to decay to
#: 1 % is warned about (its residuals hang on the estimated x0)
SLOW_PREDICTOR_FRACTION = 0.5


def _xcorr(a, b, lags):
    a = a - a.mean()
    b = b - b.mean()
    den = np.sqrt((a @ a) * (b @ b)) or 1.0
    return np.array([(a[k:] @ b[:a.size - k]) / den for k in lags])


@dataclass(frozen=True, eq=False)
class Residuals:
    """The residuals the report analyses.

    ``e`` (N, p): one-step prediction errors of the innovation predictor (``kind='one-step'``)
    or free-run output errors (``kind='output error'``: no K, or an unstable predictor), from
    ``x0`` estimated by least squares; ``fit_percent`` per output (the one-step fit for
    ``'one-step'``); ``predictor_pole``: the slowest pole of A − KC (None without K);
    ``memory_samples``: samples an initial-state error takes to decay to 1 % through it;
    ``notes``: what the report states (first what the residuals are, then the warnings)."""

    e: np.ndarray
    x0: np.ndarray
    kind: str
    fit_percent: list[float]
    predictor_pole: complex | None
    memory_samples: float
    notes: tuple[str, ...]


def _fmt_pole(z: complex) -> str:
    return f"{z.real:.6g}" if abs(z.imag) < 1e-12 else f"{z.real:.6g}{z.imag:+.6g}j"


def _warn(msg: str, notes: list) -> None:
    emit_warning(msg, AccuracyWarning)
    notes.append(msg)


def _predictor(model, A, C, notes):
    """(kind, K, slowest pole, memory in samples) of the predictor the residuals come from."""
    n, p = A.shape[0], C.shape[0]
    if getattr(model, "K", None) is None or n == 0:
        return "output error", np.zeros((n, p)), None, 0.0
    K = np.asarray(model.K, dtype=np.float64)
    poles = np.linalg.eigvals(A - K @ C)
    pole = complex(poles[np.argmax(np.abs(poles))])
    rho = abs(pole)
    if rho >= 1.0:
        _warn(f"residual analysis: the innovation model's one-step predictor (A − KC) is "
              f"unstable (pole {_fmt_pole(pole)}, |p| = {rho:.6g}): its prediction errors grow "
              f"without bound, so the free-run output errors (x0 estimated) are analysed instead",
              notes)
        return "output error", np.zeros((n, p)), pole, math.inf
    memory = 0.0 if rho == 0.0 else math.log(100.0) / -math.log(rho)
    return "one-step", K, pole, memory


def residual_analysis(model, u, y, dt: float, free_run_fit=None) -> Residuals:
    """Residuals of ``model`` on deviation data ``u`` (N, m), ``y`` (N, p), initial state
    estimated by least squares (:func:`predictor_x0`). Warns
    (:class:`~gripkit.errors.AccuracyWarning`) when the innovation predictor is unstable (the
    free-run output errors are analysed instead), when its slowest pole keeps an initial-state
    error beyond :data:`SLOW_PREDICTOR_FRACTION` of the record, and when its one-step fit falls
    more than 10 points below ``free_run_fit`` (the free-run fit per output)."""
    ss = model.to_ss(dt)
    N = y.shape[0]
    notes: list[str] = []
    kind, K, pole, memory = _predictor(model, ss.A, ss.C, notes)
    x0, e = predictor_x0(ss.A, ss.B, ss.C, ss.D, K, u, y)
    fit = fit_per_output(y, y - e)
    if kind != "one-step":
        notes.insert(0, "Free-run output errors from the initial state estimated by least "
                        "squares (as the comparison above).")
        return Residuals(e, x0, kind, fit, pole, memory, tuple(notes))
    notes.insert(0, f"One-step prediction errors of the innovation predictor "
                 f"x̂⁺ = (A − KC) x̂ + (B − KD) u + K y from the initial state estimated by least "
                 f"squares over the record; its slowest pole {_fmt_pole(pole)} "
                 f"(|p| = {abs(pole):.6g}) forgets an initial-state error to 1 % in "
                 f"{memory:.4g} samples.")
    if memory > SLOW_PREDICTOR_FRACTION * N:
        fits = ", ".join(f"{f:.2f} %" for f in fit)
        f_zero = abs(np.angle(pole)) / (2 * np.pi * dt)
        _warn(f"residual analysis: the innovation model's one-step predictor (A − KC) has a pole "
              f"at {_fmt_pole(pole)} (|p| = {abs(pole):.6g}): an initial-state error decays to "
              f"1 % only after {memory:.4g} samples, more than half of this record ({N}); the "
              f"residuals and the one-step fit ({fits}) hang on the initial state estimated by "
              f"least squares, and the noise model has a zero near the unit circle (it claims "
              f"almost no noise near {f_zero:.4g} Hz)", notes)
    for name, f1, ff in zip(model.outputs, fit, free_run_fit or ()):
        if f1 < ff - 10.0:
            _warn(f"residual analysis: the one-step predictor fits output {name!r} worse than "
                  f"the free run ({f1:.2f} % against {ff:.2f} %): the innovation gain K does not "
                  f"describe this record's noise; judge the model by the free-run fit", notes)
    return Residuals(e, x0, kind, fit, pole, memory, tuple(notes))


def _residual_figure(e, u, outputs, inputs, z: float = 1.96):
    """Auto-correlation of each residual column of ``e`` (N, p) and its cross-correlation with
    each input column of ``u`` (N, m), lags 0…25, with the band ±z/√N of white residuals
    independent of past inputs (z = 1.96: 95 %; the protocol report draws 99 %, z = 2.576)."""
    plt = pyplot()
    p, m = e.shape[1], u.shape[1]
    L = min(25, e.shape[0] // 4)
    lags = np.arange(0, L + 1)
    bound = z / np.sqrt(e.shape[0])
    fig, axes = plt.subplots(p, 1 + m, figsize=(3.4 * (1 + m), 2.4 * p), squeeze=False)
    for i in range(p):
        ax = axes[i, 0]
        ax.bar(lags[1:], _xcorr(e[:, i], e[:, i], lags)[1:], width=0.7)
        ax.set_title(plain(f"auto-corr. of {outputs[i]} residual"), fontsize=8)
        for j in range(m):
            ax2 = axes[i, 1 + j]
            ax2.bar(lags, _xcorr(e[:, i], u[:, j], lags), width=0.7, color="C1")
            ax2.set_title(plain(f"{outputs[i]} residual × past {inputs[j]}"), fontsize=8)
        for a in axes[i]:
            a.axhline(bound, color="k", ls=":", lw=0.8)
            a.axhline(-bound, color="k", ls=":", lw=0.8)
            a.grid(alpha=0.3)
    for a in axes[-1]:
        a.set_xlabel("lag [samples]")
    fig.tight_layout()
    return fig


def _pz_figure(system):
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(5.4, 5.0))
    discrete = system.is_discrete
    if discrete:
        th = np.linspace(0, 2 * np.pi, 400)
        ax.plot(np.cos(th), np.sin(th), color="0.4", lw=0.8)
    p = system.poles()
    cov = None
    if system.uncertainty is not None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            p, cov = system.pole_covariance()
    z = system.zeros()
    ax.plot(p.real, p.imag, "x", ms=9, mew=2, label="poles")
    if z.size:
        ax.plot(z.real, z.imag, "o", mfc="none", ms=8, label="zeros")
    if cov is not None:
        t = np.linspace(0, 2 * np.pi, 100)
        for k in range(p.size):
            c = cov[k]
            if not np.isfinite(c).all():
                continue
            w, V = np.linalg.eigh(c)
            pts = V @ (np.sqrt(np.maximum(w, 0))[:, None] * np.vstack([np.cos(t), np.sin(t)]))
            ax.plot(p[k].real + pts[0], p[k].imag + pts[1], color="C3", lw=1)
        ax.plot([], [], color="C3", label="1σ ellipse")
    ax.set_xlabel("Re z" if discrete else "Re s")
    ax.set_ylabel("Im z" if discrete else "Im s")
    if discrete:
        ax.set_aspect("equal")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def meaningful_lines(estimate, u) -> np.ndarray:
    """Mask (F, p, m) of the H1 estimate lines worth drawing: f > 0, H and σ finite, σ < |H| (the
    estimate tells the response from zero: for SISO H1 that is coherence γ² > 1/K of K segments,
    Bendat & Piersol eq 9.90), and every input carrying at least :data:`MIN_INPUT_POWER` of its
    largest line's Welch power (the estimate's own segments and window) — a line without input
    power gives H = noise / leakage, anything from 1e-300 to 1e15."""
    from scipy.signal import welch

    H, S = estimate.H, estimate.H_std
    ok = np.isfinite(H) & np.isfinite(S) & (S < np.abs(H))
    ok &= (estimate.frequency_hz > 0)[:, None, None]
    L = estimate.info.get("nperseg")
    if L:
        _, P = welch(np.asarray(u, dtype=np.float64), nperseg=int(L), noverlap=int(L) // 2,
                     window="hann", detrend=False, axis=0)
        P = np.asarray(P).reshape(P.shape[0], -1)
        if P.shape[0] == H.shape[0]:
            powered = np.all(P >= MIN_INPUT_POWER * np.maximum(P.max(axis=0), 1e-300), axis=1)
            ok &= powered[:, None, None]
    return ok


def _magnitude_limits(model_mag, est_mag):
    """(lo, hi) of the magnitude axis: the model's |G| range (at most MODEL_DECADES below its peak),
    widened to the kept estimates by at most ESTIMATE_MARGIN_DECADES, and a 0.2-decade margin."""
    g = model_mag[np.isfinite(model_mag) & (model_mag > 0)]
    if not g.size:
        g = est_mag[np.isfinite(est_mag) & (est_mag > 0)]
    if not g.size:
        return None
    hi_m = np.log10(g.max())
    lo_m = max(np.log10(g.min()), hi_m - MODEL_DECADES)
    lo, hi = lo_m, hi_m
    e = est_mag[np.isfinite(est_mag) & (est_mag > 0)]
    if e.size:
        lo = max(min(lo, np.log10(e.min())), lo_m - ESTIMATE_MARGIN_DECADES)
        hi = min(max(hi, np.log10(e.max())), hi_m + ESTIMATE_MARGIN_DECADES)
    return 10 ** (lo - 0.2), 10 ** (hi + 0.2)


def bode_figure(system, dt, estimate, keep=None):
    """Bode magnitude and phase of ``system`` with its ±2σ bands; the estimate's lines where
    ``keep`` (F, p, m) allows (default: every finite line at f > 0; the report passes
    :func:`meaningful_lines`). The magnitude axis is set by :func:`_magnitude_limits`; the
    estimate's points carry the gid ``'frf-estimate'``."""
    plt = pyplot()
    p, m = system.n_outputs, system.n_inputs
    nyq = np.pi / dt
    w = np.logspace(np.log10(nyq) - 3.5, np.log10(nyq * 0.999), 400)
    b = system.bode(w)
    mag, ph = b.magnitude, np.degrees(b.phase)
    ms, ps = b.magnitude_std, (None if b.phase_std is None else np.degrees(b.phase_std))
    fig, axes = plt.subplots(2 * p, m, figsize=(4.2 * m, 2.6 * 2 * p), squeeze=False, sharex=True)
    f = w / (2 * np.pi)
    for i in range(p):
        for j in range(m):
            am, ap = axes[2 * i, j], axes[2 * i + 1, j]
            am.loglog(f, mag[:, i, j], label="model")
            ap.semilogx(f, ph[:, i, j])
            if ms is not None:
                am.fill_between(f, np.maximum(mag[:, i, j] - 2 * ms[:, i, j], 1e-300),
                                mag[:, i, j] + 2 * ms[:, i, j],
                                alpha=0.25, label="±2σ")
                ap.fill_between(f, ph[:, i, j] - 2 * ps[:, i, j], ph[:, i, j] + 2 * ps[:, i, j],
                                alpha=0.25)
            kept = np.zeros(0)
            if estimate is not None:
                fe, He, Se = estimate.frequency_hz, estimate.H[:, i, j], estimate.H_std[:, i, j]
                ok = np.isfinite(He) & (fe > 0) if keep is None else keep[:, i, j]
                kept = np.abs(He[ok])
                am.errorbar(fe[ok], kept, yerr=2 * Se[ok], fmt=".", ms=2, lw=0.5, color="0.45",
                            label="H1 estimate ±2σ")[0].set_gid("frf-estimate")
                # phase of the estimate, aligned to the model's branch
                php = np.degrees(np.angle(He[ok]))
                ref = np.interp(fe[ok], f, ph[:, i, j])
                php = php + 360 * np.round((ref - php) / 360)
                ap.plot(fe[ok], php, ".", ms=2, color="0.45", gid="frf-estimate-phase")
            lim = _magnitude_limits(mag[:, i, j], kept)
            if lim is not None:
                am.set_ylim(*lim)
            am.set_title(plain(f"{system.inputs[j]} → {system.outputs[i]}"), fontsize=9)
            am.grid(alpha=0.3, which="both")
            ap.grid(alpha=0.3, which="both")
            am.set_ylabel("|H|")
            ap.set_ylabel("phase [deg]")
    for a in axes[-1]:
        a.set_xlabel("frequency [Hz]")
    axes[0, 0].legend(fontsize=7)
    fig.tight_layout()
    return fig


def singular_value_figure(sv, order):
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6, 3.2))
    k = np.arange(1, sv.size + 1)
    ax.semilogy(k, sv, "o-", ms=4)
    ax.semilogy([order], [sv[order - 1]], "o", ms=10, mfc="none", color="C3",
                label=f"order {order}")
    ax.set_xlabel("index")
    ax.set_ylabel("singular value")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def _sigma(sd):
    """A σ cell: the number, "inf (…)" where the data do not determine it, None (shown "not
    given") where the model has no covariance."""
    if isinstance(sd, numbers.Real) and not math.isfinite(sd):
        return "inf (not determined by the data)"
    return sd


#: the step fit's own parameters (``info["step"]`` of a step model): symbol, key, meaning, unit
#: (None: the key ``gain_unit``; "output": the output's SI unit)
_STEP_PARAMETERS = (("K", "gain", "static gain", None),
                    ("f_n", "natural_frequency_hz", "natural frequency", "Hz"),
                    ("ζ", "damping_ratio", "damping ratio", "1"),
                    ("y₀", "offset", "output offset (level before the step)", "output"))


def _step_rows(model, step: dict) -> list[list]:
    """The rows of the step fit K ω_n²/(s² + 2ζω_n s + ω_n²): K, f_n, ζ and y₀ with their σ (a
    None value in the file is infinite, as the model file writes it)."""
    rows = []
    for symbol, key, meaning, unit in _STEP_PARAMETERS:
        unit = (step.get("gain_unit") if unit is None else
                (list(model.output_units) or ["—"])[0] if unit == "output" else unit)
        value, sd = step.get(key), step.get(f"{key}_std")
        rows.append([symbol, math.inf if value is None else value,
                     _sigma(math.inf if sd is None else sd), unit or "—", meaning])
    return rows


def parameters_section(rep: Report, model) -> None:
    """The section "Parameters": every parameter of ``model.parameters`` (the model protocol)
    with its value, 1σ, unit and meaning; for a second-order step model first its own
    parameters K, f_n, ζ and the offset (``info["step"]``)."""
    sec = rep.section("Parameters", "Identified parameters with their 1σ (from the parameter "
                      "covariance of the fit), in SI units or '1' for coefficients of the "
                      "record's own units.")
    headers = ["parameter", "value", "σ", "unit", "meaning"]
    info = getattr(model, "info", None)
    step = info.get("step") if isinstance(info, dict) else None
    if isinstance(step, dict):
        sec.table(headers, _step_rows(model, step),
                  caption="The step fit K ω_n²/(s² + 2ζω_n s + ω_n²) + y₀ (ω_n = 2π f_n):")
    rows = [[r["name"], r["value"], _sigma(r["std"]), r["unit"], r["doc"]]
            for r in model.parameters.table()]
    sec.table(headers, rows, caption="The coefficients of the model (model.parameters):"
              if isinstance(step, dict) else "")


def model_report(model, data, *, data_name: str = "data", warnings_list=(),
                 sections=()) -> Report:
    """Build the :class:`~gripkit.report.html.Report` of ``model`` (any identified linear
    model: an ARX/ARMAX/OE model is reported through its state-space record,
    :meth:`~gripkit.sysid.PolynomialModel.linear_record`) on the trajectory ``data``;
    ``sections``: callables ``f(report)`` that add sections after the frequency response (e.g.
    ``lambda rep: gripkit.control.robustness_section(rep, result)``, the robustness of a loop
    closed around the model)."""
    original = model  # its parameters: an ARX model's a1, b1, … rather than its record's
    if hasattr(model, "linear_record"):
        model = model.linear_record()
    if not hasattr(model, "system"):
        raise ModelError(f"report: the {model.structure} model has no linear system to show "
                         f"(poles, Bode); the HTML report covers linear models",
                         hint="judge it with gripkit compare MODEL DATA")
    ss = model.system.to_ss(minimal=False)
    dt = data.require_uniform(why="a model report")
    caught_lines = list(warnings_list)
    rep = Report(f"gripkit model report: {model.structure}",
                 f"{', '.join(model.inputs)} → {', '.join(model.outputs)}, order {ss.n_states}, "
                 f"data {data_name}")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        u, y, _, y_offset = model._io(data, None, "a model report")
        fitted = model.compare(data)
        fit, ys = fitted.fit_percent, fitted.simulated - y_offset
        if None in fit:
            raise ModelError("compare: the model is unstable (a pole outside the unit circle): "
                             "its free run diverges, so no fit is reported")
        sec = rep.section("Measured and simulated outputs",
                          f"Validation fit on the record: {VALIDATION_FIT}.")
        sec.table(["output", "unit", "fit %"], [[n, u_ or "—", f] for n, u_, f in
                                                zip(model.outputs, model.system.output_units, fit)])
        t = data.t - data.t[0]
        for i, name in enumerate(model.outputs):
            yo = y_offset[i]
            sec.figure(measured_vs_model(t, y[:, i] + yo, {"model": ys[:, i] + yo},
                                         ylabel=name, title=f"{name}: fit {fit[i]:.2f} %"),
                                         f"{name}", name=f"out-{i}")
        res = residual_analysis(model, u, y, dt, free_run_fit=fit)
        sec = rep.section("Residual analysis", res.notes[0] + " The dotted lines are ±1.96/√N, "
                          "the 95 % band of white residuals independent of past inputs.")
        for note in res.notes[1:]:  # the warnings, beside the figure they concern
            sec.text(note)
        if res.kind == "one-step":
            sec.table(["output", "free-run fit %", "one-step fit %"],
                      [[n, ff, f1] for n, ff, f1 in zip(model.outputs, fit, res.fit_percent)])
        sec.figure(_residual_figure(res.e, u, model.outputs, model.inputs), "residual correlations",
                   name="residuals")
        how = ("" if not bootstrapped(model) else
               f" The covariance is that of a {covariance_method(model)}: the subspace model "
               + ("was not refined (PEM skipped, --no-refine)" if model.info.get("refined") is False
                  else "was kept in place of the PEM refinement")
               + ", and this is no PEM covariance.")
        rep.section("Poles and zeros", "Poles (×), transmission zeros (○) and the 1σ "
                                       "ellipse of each pole, "
                    "by linearisation of the "
                    "parameter covariance." + how).figure(_pz_figure(model.system),
                                                          "pole-zero map", name="pz")
        est, keep, shown = None, None, ""
        if u.shape[0] >= 256 * (u.shape[1] + 1):
            try:
                with warnings.catch_warnings():
                    # lines without input power are left out below, and the page says how many
                    warnings.simplefilter("ignore", AccuracyWarning)
                    est = frf(u, y, dt=dt, nperseg=int(min(4096, max(256, u.shape[0] // 16))))
                keep = meaningful_lines(est, u)
                shown = (f" {int(keep.sum())} of the estimate's {keep.size} lines are drawn: "
                         f"those with input power (at least {MIN_INPUT_POWER:g} of the largest "
                         f"line's) and σ below |H|; the magnitude axis follows the model, widened "
                         f"for the estimate by at most {ESTIMATE_MARGIN_DECADES:g} decades.")
            except Exception as exc:  # the report goes on without the estimate
                caught_lines.append(f"FRF estimate skipped: {exc}")
        rep.section("Frequency response", "Model magnitude and phase with ±2σ bands (from the "
                    "parameter covariance) and the data's Welch H1 estimate with ±2σ where the "
                    "data allow." + shown).figure(bode_figure(model.system, dt, est, keep), "Bode",
                                                  name="bode")
        for add_section in sections:
            add_section(rep)
        if getattr(model, "singular_values", None) is not None:
            rep.section("Subspace singular values",
                        "Singular values of the weighted subspace matrix; the order is "
                        "where they drop.").figure(
                singular_value_figure(np.asarray(model.singular_values), ss.n_states),
                "singular values", name="sv")
        parameters_section(rep, original)
    for w in caught:  # the caller sees them too (the CLI prints them and lists them in --json)
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    lines = caught_lines + [f"{w.category.__name__}: {w.message}" for w in caught]
    sec = rep.section("Warnings")
    sec.text("none" if not lines else "")
    if lines:
        sec.table(["warning"], [[ln] for ln in dict.fromkeys(lines)])
    info = {k: v for k, v in model.info.items() if isinstance(v, (str, int, float))}
    if info:
        rep.section("Identification details").table(["item", "value"],
                                                    [[k, v] for k, v in info.items()])
    return rep


def write_model_report(model, data, out_dir, *, data_name: str = "data", warnings_list=(),
                       sections=()) -> Path:
    """Write ``out_dir/index.html`` (self-contained: figures inline); returns its path."""
    return model_report(model, data, data_name=data_name, warnings_list=warnings_list,
                        sections=sections).write(Path(out_dir))
