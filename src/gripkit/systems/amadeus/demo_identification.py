"""Demo section: the AMADEUS finger-force identification study (``000_8f66dcc7ab06470c.txt`` §V)
repeated on simulated data.

The "true finger" is the zoo plant (Table II ``[2 2 2]``, SI units, see
:mod:`gripkit.systems.amadeus.force_dynamics`), driven by the paper's excitations S1 (multisine
1–10 Hz, 400 samples) and S2 (band-limited noise 0.3–10 Hz, 4000 samples) between 600 and 1100 mA,
with white measurement noise on the force. Three ways of processing the data are compared:

* ``raw``: no filter;
* ``filtered y`` (the paper's §V-E): the 9 Hz Butterworth on the force only, not part of the
  model structure;
* ``prefiltered u, y``: the same filter on input and output (Ljung, §14.4), which keeps the
  input-output relation and removes noise above the finger's bandwidth.

LS over Table II's structures and RLS over Table III's, validation on the other record, the zeros
of ``[2 2 2]`` (non-minimum phase) and ``[2 2 10]``, and an output-error fit that removes the ARX
noise bias.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass

import numpy as np

from ...consistency import ConsistencyReport, check
from ...excitation import bandlimited_noise, multisine
from ...progress import status
from ...report import plots
from ...signals.filters import apply_sos
from ...sysid import arx, oe, rls
from .force_dynamics import (FORCE_SCALE, FORCE_SCALE_NOTE, DT, TABLE_II, TABLE_III,
                             finger_force_model as build_plant, reference, stepped_sine_experiment)

__all__ = ["run", "NOISE_UNITS"]

NOISE_UNITS = 20.0  # force-sensor units: white measurement noise (≈ 7 % of the S1 force RMS)
STRUCT_II = [(1, 1, 2), (2, 2, 2), (3, 2, 2), (4, 4, 2), (2, 2, 10)]
VARIANTS = ("raw", "filtered y", "prefiltered u, y")


def _zero_and_std(model) -> tuple[float, float]:
    """The single zero −b_{nk+1}/b_nk of an nb = 2 model and its σ (first-order propagation)."""
    b0, b1 = model.B[model.nk], model.B[model.nk + 1]
    z = -b1 / b0
    i = model.parameter_names.index(f"b{model.nk}")
    g = np.zeros(model.n_params)
    g[i] = b1 / b0 ** 2
    g[i + 1] = -1.0 / b0
    return float(z), float(np.sqrt(g @ model.covariance @ g))


def _fmt_pm(v, s) -> str:
    return f"{v:.4g} ± {s:.2g}"


@dataclass(frozen=True)
class _Study:
    """The simulated experiment: the true finger ``plant`` (its ``truth`` model and 9 Hz
    prefilter ``sos``), the excitations S1 and S2, the noisy records ``rec`` and the noise level."""

    plant: object
    truth: object
    sos: np.ndarray
    s1: object
    rec: dict
    noise_std: float

    def signals(self, name: str, variant: str):
        """(u, y) of record ``name`` ("S1", "S2"): the current's deviation from the operating point
        and the force, processed as ``variant`` (one of :data:`VARIANTS`)."""
        tr = self.rec[name]
        u = tr["current"] - self.plant.operating_point
        y = tr["force"]
        if variant == "filtered y":
            y = apply_sos(self.sos, y)
        elif variant == "prefiltered u, y":
            u, y = apply_sos(self.sos, u), apply_sos(self.sos, y)
        return u, y


def _simulate_study() -> _Study:
    """The paper's excitations (§V-E) between 600 and 1100 mA on the zoo plant, with white
    measurement noise of :data:`NOISE_UNITS` sensor units on the force."""
    plant = build_plant()
    s1 = multisine(range(1, 11), 2.0, dt=DT, operating_point=0.850, limits=(0.600, 1.100), unit="A")
    s2 = (bandlimited_noise(0.3, 10.0, 20.0, dt=DT, operating_point=0.850, limits=(0.600, 1.100),
                            seed=7, unit="A"))
    noise_std = NOISE_UNITS * FORCE_SCALE  # N
    rec = {"S1": plant.simulate(s1.u, noise_std=noise_std, seed=1),
           "S2": plant.simulate(s2.u, noise_std=noise_std, seed=2)}
    return _Study(plant, plant.model, plant.prefilter_sos(), s1, rec, noise_std)


def _intro(report, study: _Study):
    """The section and its opening paragraph: the true finger, the excitations, the processings."""
    return report.section(
        "AMADEUS finger force identification (§V)",
        "The study of §V of 000_8f66dcc7ab06470c.txt on simulated data. True finger: the Table II "
        "[2 2 2] model (valve current deviation from 850 mA in A → force in N; the seed "
        "prints B in sensor "
        f"units per mA and gives no force unit: gripkit assumes {FORCE_SCALE:.4f} N per "
        "unit, from the "
        "15.45 N peak force of Fig. 2(c) over the 500 mA valve span). Excitations as "
        "in §V-E: S1, a "
        "1–10 Hz multisine, 400 samples at 200 Hz (crest factor "
        f"{study.s1.crest_factor:.2f}); S2, band-limited noise 0.3–10 Hz, 4000 samples; both "
        "between 600 and "
        f"1100 mA. White measurement noise of {study.noise_std:.3g} N ({NOISE_UNITS:g} sensor "
        "units) on the force. Three processings: raw; "
        "'filtered y', the paper's 9 Hz Butterworth on the force only (§V-E, not part of "
        "the model); and "
        "'prefiltered u, y', the same filter on input and output, which keeps the "
        "input-output relation.")


def _ls_table(sec, study: _Study) -> dict:
    """LS (QR) fits of Table II's structures on S1 and S2 under every processing, in a table with
    the loss V_N of eq (29), the free-run fit on the other record and Table II's V_N. Returns
    the fits, keyed (record, structure, variant)."""
    other = {"S1": "S2", "S2": "S1"}
    fits: dict[tuple, object] = {}
    rows = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # validation of poor raw models is reported in the table
        for name in ("S1", "S2"):
            for st in STRUCT_II:
                row = [f"[{st[0]} {st[1]} {st[2]}]", name]
                for var in VARIANTS:
                    u, y = study.signals(name, var)
                    m = arx(u, y, *st, dt=DT, input_name="current", output_name="force",
                            input_unit="A", output_unit="N")
                    fits[(name, st, var)] = m
                    row.append(m.loss / FORCE_SCALE**2)
                uv, yv = study.signals(other[name], "prefiltered u, y")
                val = fits[(name, st, "prefiltered u, y")].validate(uv, yv)
                row.append("—" if val.fit_percent is None else f"{val.fit_percent:.1f}")
                paper = [r for r in TABLE_II if (r.na, r.nb, r.nk, r.data) == (*st, name)]
                row.append(paper[0].loss if paper else "—")
                rows.append(row)
    sec.table(["structure", "data", "V_N raw", "V_N filtered y (§V-E)", "V_N prefiltered u, y",
               "free-run fit % on the other record (prefiltered)", "Table II V_N"], rows,
              caption="LS (QR) over the structures of Table II. Loss V_N of eq (29) on the "
                      "estimation record, "
                      "in the seed's force-sensor units² (V_N in N² divided by force_scale²).")
    return fits


def _winners(sec, fits: dict) -> dict:
    """Which structure wins on S1, on loss and on AIC, per processing, with the text that explains
    why. Returns ``{variant: (best on loss, best on AIC)}``."""
    winners = {}
    for var in VARIANTS:
        best = min(STRUCT_II, key=lambda st: fits[("S1", st, var)].loss)
        best_aic = min(STRUCT_II, key=lambda st: fits[("S1", st, var)].aic)
        winners[var] = (best, best_aic)
    ratio = {v: fits[("S1", (2, 2, 2), v)].loss / fits[("S1", (4, 4, 2), v)].loss for v in VARIANTS}
    sec.text(
        "Which structure wins (S1): on loss, "
        + ", ".join(f"{v} {list(w[0])}" for v, w in winners.items()) + "; on AIC, "
        + ", ".join(f"{v} {list(w[1])}" for v, w in winners.items())
        + ". As in Table II, more coefficients always lower the loss. The loss ratio [2 "
          "2 2]/[4 4 2] is "
        + ", ".join(f"{ratio[v]:.3g} ({v})" for v in VARIANTS)
        + ": with the force filtered but not the input (the paper's procedure) the model must also "
        "describe the filter's two poles, which only the higher orders can. That the "
        "largest structure "
        "also wins on AIC does not make the finger fourth order: the true plant here is "
        "[2 2 2], but an "
        "ARX model's noise model 1/A cannot describe measurement noise, so extra "
        "coefficients absorb its "
        "colour. The [2 2 2] model on prefiltered data and the output-error model "
        "below recover the "
        "true coefficients.")
    return winners


def _zeros(sec, study: _Study, fits: dict) -> dict:
    """§V-F: the zeros of [2 2 2] (non-minimum phase) and [2 2 10] (prefiltered u, y) with σ, next
    to Table II's and the true plant's, and the pole-zero map (cf. Figs. 20b and 21b). Returns
    ``{(record, structure): (z, σ_z)}``."""
    zrows = []
    zsum = {}
    for name in ("S1", "S2"):
        for st in [(2, 2, 2), (2, 2, 10)]:
            m = fits[(name, st, "prefiltered u, y")]
            z, zs = _zero_and_std(m)
            zsum[(name, st)] = (z, zs)
            zrows.append([f"[{st[0]} {st[1]} {st[2]}]", name, _fmt_pm(z, zs),
                          "minimum phase" if abs(z) < 1 else "NON-minimum phase"])
    for r in (reference("II", 2, 2, 2), reference("II", 2, 2, 10)):
        z = float(r.model().zeros()[0].real)
        zrows.append([r.label, "Table II (paper, S1)", f"{z:.4g}",
                      "minimum phase" if abs(z) < 1 else "NON-minimum phase"])
    zrows.append(["[2 2 2]", "true plant", f"{study.truth.zeros()[0].real:.4g}",
                  "NON-minimum phase"])
    sec.table(["structure", "estimated on", "zero z (±σ)", "phase"], zrows,
              caption="Zeros of B(z) (prefiltered u, y). σ by first-order propagation of the "
                      "parameter covariance.")
    sec.text("§V-F: the [2 2 2] model is non-minimum phase (zero outside the unit "
             "circle, so pole-zero "
             "cancelling controllers are risky), while the model with a ten-sample "
             "delay has its zero "
             "inside. On the simulated finger the [2 2 2] estimate recovers the true "
             "zero at z = 1.167 "
             "within its σ; the [2 2 10] model, which has the wrong delay for this plant, "
             "again puts its "
             "zero inside the unit circle.")
    m222 = fits[("S2", (2, 2, 2), "prefiltered u, y")]
    m2210 = fits[("S2", (2, 2, 10), "prefiltered u, y")]
    r222, r2210 = reference("II", 2, 2, 2).model(), reference("II", 2, 2, 10).model()
    sec.figure(plots.pole_zero_map({"[2 2 2] estimated (S2)": (m222.poles(), m222.zeros()),
                                    "[2 2 10] estimated (S2)": (m2210.poles(), m2210.zeros()),
                                    "[2 2 2] Table II": (r222.poles(), r222.zeros()),
                                    "[2 2 10] Table II": (r2210.poles(), r2210.zeros())},
                                   title="Pole-zero map (cf. Figs. 20b and 21b)"),
               "Poles (×, +, ⋎, ✱) and zeros (open ○, □, ◇, △), one shape and size per "
               "model so coincident "
               "markers nest: the [2 2 2] zero lies outside the unit circle, the [2 2 "
               "10] zero inside.",
               name="amadeus-pole-zero")
    return zsum


def _output_error(sec, study: _Study, fits: dict):
    """The output-error [2 2 2] fit on raw S2 that removes the ARX noise bias: its estimates next to
    ARX's, the residual tests, the free runs on S1 and the Bode plot. Returns the validations of
    the raw ARX and the OE models on S1."""
    u2, y2 = study.signals("S2", "raw")
    moe = (oe(u2, y2, 2, 2, 2, dt=DT, input_name="current", output_name="force", input_unit="A",
              output_unit="N"))
    marx = fits[("S2", (2, 2, 2), "raw")]
    m222 = fits[("S2", (2, 2, 2), "prefiltered u, y")]
    names = ["a1 / f1", "a2 / f2", "b2 [N/mA]", "b3 [N/mA]"]
    scale = np.array([1, 1, 1e-3, 1e-3])
    tr_theta = study.truth.theta * scale
    prow = []
    for i, n in enumerate(names):
        prow.append([n, f"{tr_theta[i]:.4g}",
                     _fmt_pm(marx.theta[i] * scale[i], marx.theta_std[i] * scale[i]),
                     _fmt_pm(m222.theta[i] * scale[i], m222.theta_std[i] * scale[i]),
                     _fmt_pm(moe.theta[[2, 3, 0, 1][i]] * scale[i],
                             moe.theta_std[[2, 3, 0, 1][i]] * scale[i])])
    sec.table(["parameter", "true", "ARX raw (S2)", "ARX prefiltered (S2)", "OE raw (S2)"], prow,
              caption="[2 2 2] estimates ± σ. Output (measurement) noise biases ARX; "
                      "the output-error "
                      "model is consistent for it. b2, b3 in N/mA: " + FORCE_SCALE_NOTE)
    u1r, y1r = study.signals("S1", "raw")
    val_arx = marx.validate(u1r, y1r)
    val_oe = moe.validate(u1r, y1r)
    _validation_figures(sec, study, fits, moe, val_arx, val_oe, y1r)
    return val_arx, val_oe


def _validation_figures(sec, study: _Study, fits: dict, moe, val_arx, val_oe, y1r) -> None:
    """Residual tests, measured vs modelled force on S1 (cf. Figs. 19–22) and the Bode plot of the
    true plant and the estimated models."""
    marx = fits[("S2", (2, 2, 2), "raw")]
    sec.figure(plots.residual_correlation({"ARX [2 2 2]": val_arx.tests,
                                           "OE [2 2 2]": val_oe.tests},
                                          title="Residual tests on the S1 record (models estimated "
                                                "on S2, raw data)"),
               "Residual autocorrelation and input-residual cross-correlation with 99 % "
               "bands: the ARX "
               "residuals (equation error under output noise) are coloured and correlated "
               "with the input; "
               "the OE residuals pass.", name="amadeus-residuals")
    t = study.rec["S1"].t
    sec.figure(plots.measured_vs_model(
        t, y1r, {f"OE [2 2 2] free run (fit {val_oe.fit_percent:.1f} %)":
                 val_oe.simulation.simulated[:, 0],
                 "ARX [2 2 2] free run (fit "
                 f"{val_arx.fit_percent:.1f} %)": val_arx.simulation.simulated[:, 0]},
        extra={"noise-free force": study.rec["S1"]["force_true"]}, ylabel="force deviation [N]",
        title="Measured and modelled force on S1 (models estimated on S2; initial "
              "conditions estimated)"),
        "Measured (grey) and modelled (dashed) force, cf. Figs. 19–22. " + FORCE_SCALE_NOTE,
        name="amadeus-measured-vs-model")
    sec.figure(plots.bode({"true plant [2 2 2]": study.truth, "OE [2 2 2] raw": moe,
                           "ARX [2 2 2] raw": marx,
                           "ARX [2 2 2] prefiltered": fits[("S2", (2, 2, 2), "prefiltered u, y")],
                           "ARX [4 4 2] filtered y": fits[("S2", (4, 4, 2), "filtered y")],
                           "9 Hz prefilter (×1000)": _scaled_filter(study.plant, 1000.0)},
                          title="Frequency responses (current → force)", magnitude_unit="re 1 N/A",
                          reference="true plant [2 2 2]"),
               "Bode plot (true plant: wide grey band): the [4 4 2] model of the force-only "
               "filtered data contains "
               "the filter's roll-off. " + FORCE_SCALE_NOTE,
               name="amadeus-bode")


def _rls(sec, study: _Study) -> None:
    """RLS (λ = 1, P0 = 10⁶·I) over Table III's structures on S1, and the convergence of the
    [2 2 2] estimates on prefiltered S2 with ±2σ bands."""
    rrows = []
    for ref in TABLE_III:
        var = "prefiltered u, y" if ref.filtered else "raw"
        u, y = study.signals("S1", var)
        res = rls(u, y, ref.na, ref.nb, ref.nk, forgetting=1.0, p0=1e6, dt=DT)
        bscale = 1e-3 / FORCE_SCALE  # N/A -> sensor units per mA, the seed's scale
        th = ", ".join(_fmt_pm(v * (1 if n[0] == "a" else bscale),
                               s * (1 if n[0] == "a" else bscale))
                       for n, v, s in zip(res.names, res.theta_final, res.theta_std_final))
        rrows.append([ref.label, "9 Hz" if ref.filtered else "no", th, res.loss / FORCE_SCALE**2,
                      ref.loss])
    sec.table(["structure", "filter", "final θ ± σ (b in sensor units/mA, as Table III)",
               "V_N (a-priori errors, units²)", "Table III V_N"],
              rrows, caption="RLS (λ = 1, P0 = 10⁶·I) over the structures of Table III on "
                             "S1 (400 samples).")
    u, y = study.signals("S2", "prefiltered u, y")
    res = rls(u, y, 2, 2, 2, forgetting=1.0, p0=1e6, dt=DT)
    sc = np.array([1, 1, 1e-3, 1e-3])
    sec.figure(plots.parameter_convergence(study.rec["S2"].t, res.theta * sc, res.theta_std * sc,
                                           ["a1", "a2", "b2 [N/mA]", "b3 [N/mA]"],
                                           truth=study.truth.theta * sc,
                                           title="RLS [2 2 2] on S2 (prefiltered): "
                                                 "convergence with ±2σ"),
               "Recursive estimates with ±2σ bands and the true "
               "values (dashed).", name="amadeus-rls-convergence")


def _fig14(sec, study):
    """Fig. 14 simulated: the stepped sine through the Table II [2 2 2] plant."""
    ss = stepped_sine_experiment(study.plant)
    f_pk, db_pk = ss.peak
    sec.table(["frequency (Hz)", *[f"{f:g}" for f in ss.frequency]],
              [["gain over static (dB)", *[f"{g:+.2f}" for g in ss.gain_db]],
               ["phase (deg)", *[f"{p:.0f}" for p in ss.phase]]],
              caption=("Fig. 14's stepped-sine experiment (§V-C: sinusoids 0.5–10.6 Hz, gain and "
                       "phase from "
                       "the waveforms) simulated with Table II's [2 2 2] model, ±100 mA at 850 "
                       "mA: the amplitude "
                       f"peaks at {db_pk:+.2f} dB at {f_pk:g} Hz, where the seed measured a "
                       "first-order-like "
                       "amplitude (cut-off between 1 and 10 Hz, no peak); the selected model "
                       "contradicts the "
                       f"measurement it was chosen to match (finding fig14-first-order-amplitude)"))


def run(report, *, quick: bool = False) -> dict:
    """Add the section to ``report``; returns the summary numbers. The records are the paper's
    (400 and 4000 samples), so the section takes a few seconds once numba's RLS kernel is compiled
    (about 10 s the first time); ``quick`` changes nothing."""
    t_start = time.perf_counter()
    status("  amadeus-identification: simulated records (§V-E)")
    study = _simulate_study()
    sec = _intro(report, study)
    status("  amadeus-identification: least squares over Table II's structures")
    fits = _ls_table(sec, study)        # LS over Table II's structures
    winners = _winners(sec, fits)
    status("  amadeus-identification: zeros (§V-F)")
    zsum = _zeros(sec, study, fits)     # non-minimum-phase [2 2 2], minimum-phase [2 2 10]
    status("  amadeus-identification: output error and residual tests")
    val_arx, val_oe = _output_error(sec, study, fits)  # OE removes the ARX bias; residual tests
    status("  amadeus-identification: RLS over Table III's structures")
    _rls(sec, study)                    # RLS over Table III's structures
    status("  amadeus-identification: stepped sine (Fig. 14)")
    _fig14(sec, study)                  # the stepped-sine experiment against Table II [2 2 2]
    # `gripkit zoo check amadeus-finger-force`: the plant's numbers, Fig. 14 and the §V-F statements
    sec.findings(ConsistencyReport(check(study.plant), "amadeus-finger-force (zoo check), with the "
                                                       "AMADEUS Tables II/III statements of §V-F"))
    z222, z222s = zsum[("S2", (2, 2, 2))]
    z2210, _ = zsum[("S2", (2, 2, 10))]
    return {"winner_on_loss_filtered_y": list(winners["filtered y"][0]),
            "winner_on_aic_prefiltered": list(winners["prefiltered u, y"][1]),
            "zero_222": z222, "zero_222_std": z222s, "non_minimum_phase_222": bool(abs(z222) > 1),
            "zero_2210": z2210, "minimum_phase_2210": bool(abs(z2210) < 1),
            "oe_validation_fit_percent": val_oe.fit_percent,
            "arx_validation_fit_percent": val_arx.fit_percent,
            "seconds": round(time.perf_counter() - t_start, 2)}


def _scaled_filter(plant, gain: float):
    from scipy import signal as sig

    b, a = sig.sos2tf(plant.prefilter_sos())
    f, h = sig.freqz(b, a, worN=512, fs=1.0 / plant.dt)
    return f, gain * h
