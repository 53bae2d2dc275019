"""One self-contained HTML report of an identified linear model on a data record
(``gripkit report MODEL.json DATA --out DIR``, ``gripkit identify … --report DIR``).

Sections: measured against simulated output per output (free run, x0 estimated); residual
auto-correlation per output and cross-correlation with each input, with the ±1.96/√N band of
white, independent residuals (Ljung 2nd ed. §16.6); pole-zero map with the 1σ ellipse of each
pole (from the parameter covariance); Bode magnitude and phase with ±2σ bands, and the data's
Welch H1 estimate (with its ±2σ) beside them when the data allow; the subspace singular values
with the chosen order; the warnings raised on the way.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from ..report.html import Report
from ..report.plots import measured_vs_model, plain, pyplot
from .frf import frf
from .linear_model import VALIDATION_FIT
from .pem_ss import predict_errors

__all__ = ["write_model_report", "model_report"]


def _xcorr(a, b, lags):
    a = a - a.mean()
    b = b - b.mean()
    den = np.sqrt((a @ a) * (b @ b)) or 1.0
    return np.array([(a[k:] @ b[:a.size - k]) / den for k in lags])


def _residual_figure(e, u, outputs, inputs):
    plt = pyplot()
    p, m = e.shape[1], u.shape[1]
    L = min(25, e.shape[0] // 4)
    lags = np.arange(0, L + 1)
    bound = 1.96 / np.sqrt(e.shape[0])
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


def bode_figure(system, dt, estimate):
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
                am.fill_between(f, np.maximum(mag[:, i, j] - 2 * ms[:, i, j], 1e-300), mag[:, i, j] + 2 * ms[:, i, j],
                                alpha=0.25, label="±2σ")
                ap.fill_between(f, ph[:, i, j] - 2 * ps[:, i, j], ph[:, i, j] + 2 * ps[:, i, j], alpha=0.25)
            if estimate is not None:
                fe, He, Se = estimate.frequency_hz, estimate.H[:, i, j], estimate.H_std[:, i, j]
                ok = np.isfinite(He) & (fe > 0)
                am.errorbar(fe[ok], np.abs(He[ok]), yerr=2 * Se[ok], fmt=".", ms=2, lw=0.5, color="0.45",
                            label="H1 estimate ±2σ")
                # phase of the estimate, aligned to the model's branch
                php = np.degrees(np.angle(He[ok]))
                ref = np.interp(fe[ok], f, ph[:, i, j])
                php = php + 360 * np.round((ref - php) / 360)
                ap.plot(fe[ok], php, ".", ms=2, color="0.45")
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
    ax.semilogy([order], [sv[order - 1]], "o", ms=10, mfc="none", color="C3", label=f"order {order}")
    ax.set_xlabel("index")
    ax.set_ylabel("singular value")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def model_report(model, data, *, data_name: str = "data", warnings_list=()) -> Report:
    """Build the :class:`~gripkit.report.html.Report` of ``model`` on the trajectory ``data``."""
    ss = model.system.to_ss(minimal=False)
    dt = data.require_uniform(why="a model report")
    caught_lines = list(warnings_list)
    rep = Report(f"gripkit model report: {model.structure}",
                 f"{', '.join(model.inputs)} → {', '.join(model.outputs)}, order {ss.n_states}, "
                 f"data {data_name}")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        u = model._columns(data, model.inputs, model.u_offset, "input")
        y = model._columns(data, model.outputs, model.y_offset, "output")
        fit, ys, _ = model.compare(u, y, dt=dt)
        sec = rep.section("Measured and simulated outputs",
                          f"Validation fit on the record: {VALIDATION_FIT}.")
        sec.table(["output", "unit", "fit %"], [[n, u_ or "—", f] for n, u_, f in
                                                zip(model.outputs, model.system.output_units, fit)])
        t = data.t - data.t[0]
        for i, name in enumerate(model.outputs):
            sec.figure(measured_vs_model(t, y[:, i] + model.y_offset[i], {"model": ys[:, i] + model.y_offset[i]},
                                         ylabel=name, title=f"{name}: fit {fit[i]:.2f} %"), f"{name}", name=f"out-{i}")
        dss = model.discrete(dt)
        K = model.K if model.K is not None else np.zeros((dss.n_states, dss.n_outputs))
        e = np.empty_like(y)
        x0 = np.zeros(dss.n_states)
        predict_errors(dss.A, dss.B, dss.C, dss.D, K, x0, u, y, e)
        rep.section("Residual analysis",
                    f"{'One-step prediction errors of the innovation form' if model.K is not None else 'Output errors'}"
                    "; the dotted lines are ±1.96/√N, the 95 % band of white residuals independent of past inputs."
                    ).figure(_residual_figure(e[min(50, e.shape[0] // 10):], u[min(50, e.shape[0] // 10):],
                                              model.outputs, model.inputs), "residual correlations", name="residuals")
        rep.section("Poles and zeros", "Poles (×), transmission zeros (○) and the 1σ ellipse of each pole, "
                    "by linearisation of the parameter covariance.").figure(_pz_figure(model.system), "pole-zero map",
                                                                            name="pz")
        est = None
        if u.shape[0] >= 256 * (u.shape[1] + 1):
            try:
                est = frf(u, y, dt=dt, nperseg=int(min(4096, max(256, u.shape[0] // 16))))
            except Exception as exc:  # the report goes on without the estimate
                caught_lines.append(f"FRF estimate skipped: {exc}")
        rep.section("Frequency response", "Model magnitude and phase with ±2σ bands (from the parameter "
                    "covariance) and the data's Welch H1 estimate with ±2σ where the data allow."
                    ).figure(bode_figure(model.system, dt, est), "Bode",
                             name="bode")
        if model.singular_values is not None:
            rep.section("Subspace singular values", "Singular values of the weighted subspace matrix; the order is "
                        "where they drop.").figure(singular_value_figure(np.asarray(model.singular_values), ss.n_states),
                                                   "singular values", name="sv")
    lines = caught_lines + [f"{w.category.__name__}: {w.message}" for w in caught]
    sec = rep.section("Warnings")
    sec.text("none" if not lines else "")
    if lines:
        sec.table(["warning"], [[ln] for ln in dict.fromkeys(lines)])
    info = {k: v for k, v in model.info.items() if isinstance(v, (str, int, float))}
    if info:
        rep.section("Identification details").table(["item", "value"], [[k, v] for k, v in info.items()])
    return rep


def write_model_report(model, data, out_dir, *, data_name: str = "data", warnings_list=()) -> Path:
    """Write ``out_dir/index.html`` (self-contained: figures inline); returns its path."""
    return model_report(model, data, data_name=data_name, warnings_list=warnings_list).write(Path(out_dir))
