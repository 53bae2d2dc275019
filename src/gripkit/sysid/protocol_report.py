"""One self-contained HTML report of any identified model on a data record, built on the model
protocol alone (:mod:`gripkit.sysid.model_protocol`): ``model.report(data, out)`` of the families
without a linear system to draw (NARX, Hammerstein–Wiener, nonlinear state space, hysteresis),
which ``gripkit report MODEL.json DATA --out DIR`` and ``gripkit identify narx|hw|nlss|hysteresis …
--report DIR`` call.

Sections:

* measured against simulated output per output: the free run of ``model.compare(data)`` (the
  run whose fit is quoted, by ``model.fit_definition``) with its ±2σ band where the family gives
  σ of its free run (``model.simulate(data, std=True)``: the parameter covariance propagated to
  the output; drawn about the compared run);
* the residuals ``e = y − ŷ`` of that free run: their auto-correlation (lags ≥ 1) and their
  cross-correlation with each input (lags ≥ 0), with the ±2.576/√N band that white residuals
  independent of past inputs stay inside 99 % of the time, and the portmanteau p-values of
  :func:`gripkit.sysid.linear.validation.residual_tests` (α = 0.01; Ljung 2nd ed. §16.6);
* the parameter table (``model.parameters``: value, 1σ, unit, meaning);
* the warnings raised on the way.

The linear models have their own report (:mod:`gripkit.sysid.model_report`: poles, Bode with σ,
innovation residuals); this module shares its residual figure.
"""

from __future__ import annotations

import inspect
import warnings
from pathlib import Path

import numpy as np

from ..errors import DataError, ModelError
from ..report.html import Report
from ..report.plots import measured_vs_model
from .linear.validation import residual_tests
from .model_protocol import ModelFit
from .model_report import _residual_figure, parameters_section

__all__ = ["protocol_report", "write_protocol_report", "write_protocol_page", "RESIDUAL_ALPHA"]

#: significance of the residual tests and of the bands drawn (99 %)
RESIDUAL_ALPHA = 0.01
#: the band factor z_{1−α/2} of RESIDUAL_ALPHA (scipy.stats.norm.ppf(0.995))
_Z99 = 2.5758293035489004
#: lags of the residual correlations
RESIDUAL_LAGS = 25


def _columns(data, names) -> np.ndarray:
    """The columns ``names`` of the trajectory ``data`` as an array (N, len(names))."""
    return np.column_stack([np.asarray(data[n], dtype=np.float64) for n in names])


def _output_std(model, data):
    """(σ of the free run (N, ny) or None, a sentence on where it comes from)."""
    if "std" not in inspect.signature(model.simulate).parameters:
        return None, (f"The {model.structure} family gives no σ of its free run (only of its "
                      "parameters), so no band is drawn.")
    try:
        _, sd = model.simulate(data, std=True)
    except ModelError as exc:  # e.g. a model read without its covariance
        return None, f"No ±2σ band: {exc}"
    sd = np.asarray(sd, dtype=np.float64).reshape(data.n, -1)
    return sd, ("The band is ±2σ of the free run: the parameter covariance propagated to the "
                "simulated output (model.simulate(data, std=True)), drawn about the compared run; "
                "where σ is infinite (a parameter the data do not determine) no band is drawn.")


def _fit_text(f) -> str:
    return "diverged" if f is None else f"{f:.2f} %"


def _outputs_section(rep: Report, model, data, fit: ModelFit, y: np.ndarray) -> None:
    """Measured against simulated output per output, the fit table and the ±2σ band."""
    sd, band_note = _output_std(model, data)
    sec = rep.section("Measured and simulated outputs",
                      f"Validation fit on the record: {fit.definition}. {band_note}")
    sec.table(["output", "unit", "fit %"],
              [[n, _unit(data, n), _fit_text(f)] for n, f in zip(model.outputs, fit.fit_percent)])
    t = data.t - data.t[0]
    ys = np.asarray(fit.simulated, dtype=np.float64).reshape(len(t), -1)
    for i, name in enumerate(model.outputs):
        unit = _unit(data, name)
        fig = measured_vs_model(t, y[:, i], {"model (free run)": ys[:, i]},
                                ylabel=name if unit == "—" else f"{name} [{unit}]",
                                title=f"{name}: fit {_fit_text(fit.fit_percent[i])}")
        if sd is not None:
            s = np.where(np.isfinite(sd[:, i]), sd[:, i], np.nan)
            ax = fig.axes[0]
            ax.fill_between(t, ys[:, i] - 2 * s, ys[:, i] + 2 * s, color="C0", alpha=0.25,
                            lw=0, label="±2σ")
            ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
        sec.figure(fig, name, name=f"out-{i}")


def _unit(data, name: str) -> str:
    """The SI unit of column ``name`` (the values the model sees and the page draws)."""
    return data.units.get(name) or "—"


def _residuals_section(rep: Report, model, data, fit: ModelFit, y: np.ndarray) -> None:
    """Residuals of the free run: correlations with the 99 % band and the portmanteau tests."""
    ys = np.asarray(fit.simulated, dtype=np.float64).reshape(y.shape)
    u = _columns(data, model.inputs)
    keep = [i for i, f in enumerate(fit.fit_percent) if f is not None]
    sec = rep.section("Residual analysis",
                      "Residuals e = measured − simulated (the free run above). Auto-correlation "
                      "at lags ≥ 1 and cross-correlation with each input at lags ≥ 0; the dotted "
                      f"lines are ±{_Z99:.3f}/√N, the 99 % band of white residuals independent "
                      "of past inputs. p-values: the portmanteau tests of whiteness (χ² of the "
                      "auto-correlations) and of independence from the input (α = "
                      f"{RESIDUAL_ALPHA:g}).")
    if len(keep) < len(model.outputs):
        sec.text("No residuals for " + ", ".join(n for i, n in enumerate(model.outputs)
                                                  if i not in keep) + ": the free run diverged.")
    if not keep:
        return
    e = y[:, keep] - ys[:, keep]
    rows = []
    for k, i in enumerate(keep):
        rms = float(np.sqrt(np.mean(e[:, k] ** 2)))
        for j, inp in enumerate(model.inputs):
            try:
                rt = residual_tests(e[:, k], u[:, j], lags=RESIDUAL_LAGS, alpha=RESIDUAL_ALPHA)
            except DataError as exc:  # constant residuals or input: named in the table
                rows.append([model.outputs[i], inp, rms, None, None, f"not tested: {exc}"])
                continue
            rows.append([model.outputs[i], inp, rms, rt.whiteness_p, rt.independence_p,
                         "yes" if rt.white and rt.independent else "no"])
    sec.table(["output", "input", "RMS residual", "whiteness p", "independence p",
               "passes both at 99 %"], rows)
    outs = [model.outputs[i] for i in keep]
    sec.figure(_residual_figure(e, u, outs, list(model.inputs), z=_Z99), "residual correlations",
               name="residuals")


def protocol_report(model, data, *, data_name: str = "data",
                    warnings_list=()) -> tuple[Report, ModelFit]:
    """The :class:`~gripkit.report.html.Report` of ``model`` (any object of the model protocol)
    on the trajectory ``data`` (with the model's input and output columns), and the
    :class:`~gripkit.sysid.ModelFit` it shows (``model.compare(data)``: the number ``gripkit
    compare`` prints). ``warnings_list``: lines raised before (listed on the page)."""
    rep = Report(f"gripkit model report: {model.structure}",
                 f"{', '.join(model.inputs)} → {', '.join(model.outputs)}, data {data_name}")
    lines = list(warnings_list)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fit = model.compare(data)
        y = _columns(data, model.outputs)
        _outputs_section(rep, model, data, fit, y)
        _residuals_section(rep, model, data, fit, y)
        parameters_section(rep, model)
    for w in caught:  # the caller sees them too (the CLI prints them and lists them in --json)
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    lines += [f"{w.category.__name__}: {w.message}" for w in caught]
    sec = rep.section("Warnings")
    sec.text("none" if not lines else "")
    if lines:
        sec.table(["warning"], [[ln] for ln in dict.fromkeys(lines)])
    dt = getattr(model, "dt", None)
    rep.section("Model").table(["item", "value"], [
        ["structure", model.structure], ["inputs", ", ".join(model.inputs)],
        ["outputs", ", ".join(model.outputs)], ["sample time [s]", dt],
        ["fit definition", model.fit_definition]])
    return rep, fit


def write_protocol_report(model, data, out_dir, *, data_name: str = "data",
                          warnings_list=()) -> tuple[Path, ModelFit]:
    """Write ``out_dir/index.html`` (self-contained: figures inline); returns its path and the
    fit it shows."""
    rep, fit = protocol_report(model, data, data_name=data_name, warnings_list=warnings_list)
    return rep.write(Path(out_dir)), fit


def write_protocol_page(model, data, out_dir, *, data_name: str = "data",
                        warnings_list=()) -> Path:
    """The page of :func:`write_protocol_report`, its path only: the writer of
    ``model.report(data, out_dir)`` for every family but the linear ones
    (:data:`gripkit.sysid.model_protocol.MODEL_REPORTS`)."""
    return write_protocol_report(model, data, out_dir, data_name=data_name,
                                 warnings_list=warnings_list)[0]
