"""Reusable matplotlib figures for reports (Agg backend; add them with ``section.figure(fig,
...)``).

* :func:`measured_vs_model` — measured output against model outputs (seed Figs. 19–22 style);
* :func:`residual_correlation` — residual autocorrelation and input–residual cross-correlation with
  their confidence bands (:class:`gripkit.sysid.ResidualTests`);
* :func:`pole_zero_map` — z-plane poles (×) and zeros (○) with the unit circle (Figs. 20b, 21b);
* :func:`bode` — magnitude and phase of discrete-time models against frequency in Hz;
* :func:`parameter_convergence` — recursive estimates with ±2σ bands and optional true values;
* :func:`log_ticks` — labelled major ticks at 1, 2, 5 per decade on every log axis of an axes.

Labels, legends and titles are shown as given, never parsed as mathtext (:func:`plain`): they
often hold names read from files, and ``$`` in a column name must not stop a report.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

__all__ = ["measured_vs_model", "residual_correlation", "pole_zero_map", "bode",
           "parameter_convergence",
           "log_ticks", "plain", "plain_math_fallback"]


def plain(text) -> str:
    """``text`` (a name from a file: a column, unit, joint) as a matplotlib label shown as it
    is: each ``$`` escaped, so that no mathtext is parsed from data (``$\\frac{$`` would stop
    the plot)."""
    return str(text).replace("$", "\\$")


def plain_math_fallback(fig) -> None:
    """Show as plain text every text of ``fig`` whose mathtext does not parse (the report builder
    calls this before it saves a figure, so that a label from data cannot stop a report)."""
    from matplotlib import cbook
    from matplotlib.mathtext import MathTextParser
    from matplotlib.text import Text

    parser = MathTextParser("path")
    for t in fig.findobj(Text):
        s = t.get_text()
        if not (t.get_parse_math() and cbook.is_math_text(s)):
            continue
        try:
            parser.parse(s)
        except Exception:  # noqa: BLE001 - any parse failure: show the text as it is
            t.set_parse_math(False)


def pyplot():
    """matplotlib.pyplot on the Agg backend (imported on first use: matplotlib is heavy)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def subplots(*args, **kw):
    """``pyplot().subplots(...)``: a new figure and its axes."""
    return pyplot().subplots(*args, **kw)


def log_ticks(*axes) -> None:
    """Give every log-scaled axis of ``axes`` labelled ticks at 1, 2 and 5 × 10ⁿ (unlabelled minor
    ticks at the other integers), so that even a span under one decade shows at least three
    labels."""
    from matplotlib.ticker import LogFormatterSciNotation, LogLocator, NullFormatter

    for ax in axes:
        for axis, scale in ((ax.xaxis, ax.get_xscale()), (ax.yaxis, ax.get_yscale())):
            if scale != "log":
                continue
            lo, hi = sorted(axis.get_view_interval())
            decades = np.log10(hi / lo) if lo > 0 else np.inf
            subs = (1.0, 2.0, 5.0) if decades <= 4 else (1.0,)
            axis.set_major_locator(LogLocator(base=10.0, subs=subs, numticks=30))
            axis.set_major_formatter(LogFormatterSciNotation(labelOnlyBase=False,
                                                             minor_thresholds=(np.inf, np.inf))
                                     if decades <= 4 else LogFormatterSciNotation())
            axis.set_minor_locator(LogLocator(base=10.0, subs=np.arange(2, 10), numticks=30))
            axis.set_minor_formatter(NullFormatter())


def measured_vs_model(t: np.ndarray, measured: np.ndarray, models: Mapping[str, np.ndarray], *,
                      ylabel: str = "output", title: str = "", measured_label: str = "measured",
                      extra: Mapping[str, np.ndarray] | None = None):
    """Measured output (solid) and model outputs (dashed) against time ``t`` (s); labels and title
    are shown as given (no mathtext: they often hold names from data)."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(10, 3.6))
    ax.plot(t, measured, color="0.55", lw=0.9, label=plain(measured_label))
    for label, v in (extra or {}).items():
        ax.plot(t, v, lw=1.2, label=plain(label))
    for label, v in models.items():
        ax.plot(t, v, "--", lw=1.4, label=plain(label))
    ax.set_xlabel("time [s]")
    ax.set_ylabel(plain(ylabel))
    ax.set_title(plain(title))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
    return fig


def residual_correlation(tests: Mapping[str, object], *, title: str = ""):
    """Autocorrelation r_e(τ), τ ≥ 1, and cross-correlation r_eu(τ), τ ≥ 0, with ±bound bands.

    ``tests`` maps a label to a :class:`gripkit.sysid.ResidualTests`.
    """
    plt = pyplot()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 3.4))
    width = 0.8 / max(len(tests), 1)
    for k, (label, rt) in enumerate(tests.items()):
        off = (k - (len(tests) - 1) / 2) * width
        a1.bar(rt.lags[1:] + off, rt.autocorr[1:], width=width,
               label=plain(f"{label} (whiteness p = {rt.whiteness_p:.2g})"))
        a2.bar(rt.lags + off, rt.crosscorr, width=width,
               label=plain(f"{label} (independence p = {rt.independence_p:.2g})"))
        for ax in (a1, a2):
            ax.axhline(rt.bound, color=f"C{k}", ls=":", lw=1)
            ax.axhline(-rt.bound, color=f"C{k}", ls=":", lw=1)
    a1.set_title("residual autocorrelation")
    a2.set_title("cross-correlation residual / past input")
    a1.set_xlabel("lag τ [samples]")
    a2.set_xlabel("lag τ [samples]")
    for ax in (a1, a2):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    if title:
        fig.suptitle(plain(title))
    fig.tight_layout()
    return fig


def pole_zero_map(models: Mapping[str, tuple[Sequence[complex], Sequence[complex]]], *,
                  title: str = ""):
    """z-plane map: ``models`` maps a label to ``(poles, zeros)``."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(5.6, 5.2))
    th = np.linspace(0, 2 * np.pi, 400)
    ax.plot(np.cos(th), np.sin(th), color="0.4", lw=0.8)
    ax.axhline(0, color="0.8", lw=0.6)
    ax.axvline(0, color="0.8", lw=0.6)
    allz = [1.0]
    # models often share poles and zeros: each gets its own marker shape and a size that shrinks
    # with its order, drawn later on top, so coincident markers nest instead of hiding each other
    pole_marks, zero_marks = "x+1*", "osD^"
    for k, (label, (p, z)) in enumerate(models.items()):
        p = np.atleast_1d(np.asarray(p, dtype=complex))
        z = np.atleast_1d(np.asarray(z, dtype=complex))
        c, ms = f"C{k}", max(15.0 - 3.0 * k, 5.0)
        ax.plot(p.real, p.imag, pole_marks[k % 4], color=c, ms=ms, mew=2, zorder=3 + k,
                label=plain(f"{label} poles"))
        ax.plot(z.real, z.imag, zero_marks[k % 4], color=c, ms=ms, mfc="none", mew=1.6,
                zorder=3 + k,
                label=plain(f"{label} zeros"))
        allz += list(np.abs(p)) + list(np.abs(z))
    lim = 1.1 * max(allz)
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_aspect("equal")
    ax.set_xlabel("Re z")
    ax.set_ylabel("Im z")
    ax.set_title(plain(title))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    return fig


def bode(models: Mapping[str, object], *, n: int = 512, title: str = "", magnitude_unit: str = "",
         reference: str | None = None):
    """Magnitude (dB) and phase (deg) of models with ``frequency_response(n=...)`` giving
    ``(w [rad/s], H)`` (e.g. :class:`gripkit.sysid.PolynomialModel`), or of ``(f_Hz, H)`` pairs,
    up to Nyquist, drawn against the frequency in Hz.

    ``reference`` names the model the others are compared with (e.g. the true plant): it is drawn
    as a wide grey band under the others, so that an estimate lying on it shows as a line inside
    the band instead of hiding it."""
    plt = pyplot()
    fig, (am, ap) = plt.subplots(2, 1, figsize=(8, 5.6), sharex=True)
    k = 0
    for label, m in models.items():
        if isinstance(m, tuple):
            f, h = m
        else:
            w, h = m.frequency_response(n=n)
            f = w / (2.0 * np.pi)
        sel = f > 0
        if label == reference:
            style = dict(color="0.25", lw=6.0, alpha=0.35, zorder=1, solid_capstyle="butt")
        else:  # estimates often coincide: cycle the dash pattern as well as the colour
            style = dict(color=f"C{k}", lw=1.4, zorder=2, ls=("-", "--", "-.", ":")[k % 4])
            k += 1
        shown = plain(label)
        am.semilogx(f[sel], 20 * np.log10(np.maximum(np.abs(h[sel]), 1e-300)), label=shown, **style)
        ap.semilogx(f[sel], np.degrees(np.unwrap(np.angle(h[sel]))), label=shown, **style)
    am.set_ylabel(plain(f"magnitude [dB{' ' + magnitude_unit if magnitude_unit else ''}]"))
    ap.set_ylabel("phase [deg]")
    ap.set_xlabel("frequency [Hz]")
    for ax in (am, ap):
        ax.grid(alpha=0.3, which="both")
    log_ticks(am, ap)
    am.legend(fontsize=8)
    am.set_title(plain(title))
    fig.tight_layout()
    return fig


def parameter_convergence(t: np.ndarray, theta: np.ndarray, std: np.ndarray, names: Sequence[str],
                          *,
                          truth: Sequence[float] | None = None, title: str = ""):
    """One panel per parameter: estimate θ_i(t) with a ±2σ band and the true value (dashed)."""
    plt = pyplot()
    p = len(names)
    ncol = 2 if p > 1 else 1
    nrow = (p + ncol - 1) // ncol
    fig, axes = plt.subplots(nrow, ncol, figsize=(9, 2.3 * nrow), sharex=True, squeeze=False)
    for i, name in enumerate(names):
        ax = axes[i // ncol][i % ncol]
        ax.plot(t, theta[:, i], color="C0", lw=1.2, label="estimate")
        ok = np.isfinite(std[:, i])
        ax.fill_between(t[ok], theta[ok, i] - 2 * std[ok, i], theta[ok, i] + 2 * std[ok, i],
                        color="C0",
                        alpha=0.25, label="±2σ")
        if truth is not None:
            ax.axhline(truth[i], color="C3", ls="--", lw=1, label="true")
        fin = theta[ok, i]
        if fin.size:
            lo, hi = np.percentile(fin, [2, 100])
            if truth is not None:
                lo, hi = min(lo, truth[i]), max(hi, truth[i])
            pad = 0.3 * (hi - lo) + 1e-12
            ax.set_ylim(lo - pad, hi + pad)
        ax.set_ylabel(plain(name))
        ax.grid(alpha=0.3)
    for j in range(p, nrow * ncol):
        axes[j // ncol][j % ncol].set_visible(False)
    axes[0][0].legend(fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("time [s]")
    if title:
        fig.suptitle(plain(title))
    fig.tight_layout()
    return fig
