"""``gripkit identify ss|frf|tf``: MIMO state space (subspace + PEM), frequency response and
continuous-time transfer function from a data file, with ``--out MODEL.json`` and ``--json``.

JSON fields (exact, other tools read them):

* ``ss``: ``A``, ``B``, ``C``, ``D``, ``K``, ``dt``, ``order``, ``singular_values``, ``stable``,
  ``fit_percent`` (list per output, in ``--output`` order), ``poles`` and ``poles_std`` ((Re, Im)
  of each), ``covariance_method`` (how σ was obtained: PEM's covariance, or for a subspace model,
  kept in place of PEM's or with ``--no-refine`` (``info.refined`` false), a parametric
  bootstrap, detailed in ``info.covariance``; null without σ) and, with
  ``--validate``, ``validation.fit_percent`` (list per output, free run, estimated initial state);
* ``frf``: ``frequency_hz``, ``H_real``, ``H_imag``, ``H_std``, ``coherence`` (where defined);
* ``tf``: ``num``, ``den`` (continuous time, descending powers of s), ``num_std``, ``den_std``,
  ``natural_frequency_hz``, ``damping_ratio`` (complex poles), ``fit_percent``.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import typer

from .app import identify_app
from .common import (FillOpt, FsOpt, JsonOpt, TimeOpt, emit_json, finish_json, load_data,
                     report_warnings)
from .identify_common import (DataArg, DataArgs, ModelOutOpt, ReportOpt, ValidateOpt, check_outputs,
                              data_field, echo_written, run_identify, save_and_report, validation)

InputsOpt = typer.Option(..., "--input", help="Input column(s), comma-separated (e.g. a,b).")
OutputsOpt = typer.Option(..., "--output", help="Output column(s), comma-separated (e.g. c,d).")
DetrendOpt = typer.Option("mean", "--detrend", help="Operating-point removal before "
                                                    "fitting: mean or none.")


def _load(path: Path, inputs: str, outputs: str, fs, time, fill):
    from .identify_common import columns

    return load_data(path, columns(inputs, outputs), fs, time, fill)


@identify_app.command("ss")
def identify_ss_cmd(data: list[Path] = DataArgs, input: str = InputsOpt, output: str = OutputsOpt,
                    order: str = typer.Option(None, "--order", help="Order N, or a range "
                                                                    "LO:HI to search "
                                                                     "(default: from the "
                                                                     "singular values)."),
                    method: str = typer.Option("n4sid", "--method", help="Subspace weighting: "
                                                                         "n4sid, moesp or cva."),
                    form: str = typer.Option("innovation", "--form",
                                             help="PEM refinement: oe or innovation."),
                    no_refine: bool = typer.Option(False, "--no-refine", help="Keep the subspace "
                                                                              "model (no PEM; σ "
                                                                              "by a parametric "
                                                                              "bootstrap of it)."),
                    focus: str = typer.Option("simulation", "--focus",
                                              help="Criterion the returned model never "
                                              "loses by (subspace start against PEM "
                                              "result): simulation "
                                              "(free-run fit, default) or prediction "
                                              "(one-step fit)."),
                    max_iterations: int = typer.Option(50, "--max-iterations",
                                                       help="PEM iterations at most "
                                                       "(a warning says when they "
                                                       "did not converge)."),
                    validate: Path = typer.Option(None, "--validate",
                                                  help="Second record: free-run validation "
                                                       "(and order ranking for a range)."),
                    out: Path = ModelOutOpt, report: Path = ReportOpt,
                    fs: float = FsOpt, time: str = TimeOpt, fill: str = FillOpt,
                    detrend: str = DetrendOpt,
                    json_out: bool = JsonOpt):
    """MIMO state space: subspace (N4SID/MOESP/CVA, order from the singular values), then PEM.
    Several DATA files: one model of all the records (subspace, then PEM), one initial state per
    record (``records``: each file's free-run fit), with the order search, --focus and --report
    (one page per file) as for one file; --validate then checks the model, the search ranks by
    Akaike's criterion over the records."""
    _check_ss_options(form, focus, max_iterations)
    several = len(data) > 1
    check_outputs(out, report, [*data, validate])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        options = dict(order=order, refine=not no_refine, form=form, max_iterations=max_iterations,
                       weighting=method, progress=True, focus=focus)
        model, tr, vtr = run_identify(data, "ss", input, output, fs=fs, time=time, fill=fill,
                                      validate=validate, fit_validate=not several,
                                      detrend=detrend, **options)
        save_and_report(model, tr, data, out, report)
        val = validation(model, vtr, validate)
    res = _ss_result(model, val, data, method, no_refine, out)
    if finish_json(res, caught, json_out):
        return
    _echo_ss(model, val, res, focus, out, report)


def _check_ss_options(form: str, focus: str, max_iterations: int) -> None:
    """Validate the options that the identification itself does not check (--form, --focus,
    --max-iterations); a DataError names the option, what it expects and what it found."""
    from ..errors import DataError

    if form not in ("oe", "innovation"):
        raise DataError(f"--form: expected oe or innovation, found {form!r}")
    if focus not in ("simulation", "prediction"):
        raise DataError(f"--focus: expected simulation or prediction, found {focus!r}")
    if max_iterations < 1:
        raise DataError(f"--max-iterations: expected a positive integer, found {max_iterations}")


def _ss_result(model, val, data: list[Path], method: str, no_refine: bool, out: Path) -> dict:
    """The JSON result of ``identify ss`` (without ``warnings``): the model's fields, the data
    files, the per-record fits (several files), the validation, order search and focus."""
    from ..sysid.linear.ss_bootstrap import covariance_method

    several = len(data) > 1
    res = model.to_dict()
    res["info"] = {k: v for k, v in res["info"].items()  # the search is given at the top level
                   if k not in ("search", "search_criterion", "validation_fit_percent")}
    res.update(data=data_field(data), method=method, refined=not no_refine,
               out=None if out is None else str(out))
    if several:
        res["records"] = [{"data": str(p), "n_samples": r["n_samples"],
                           "fit_percent": r["fit_percent"]}
                          for p, r in zip(data, model.info["records"])]
        res["info"]["records"] = res["records"]  # without the initial states' arrays
    if val is not None:
        res["validation"] = val.to_dict()
    search = model.info.get("search")
    if search is not None:
        res["search"] = search
        res["search_criterion"] = model.info["search_criterion"]
    if "focus" in model.info:
        res["focus"] = model.info["focus"]
    res["covariance_method"] = covariance_method(model)
    return res


def _echo_ss(model, val, res: dict, focus: str, out: Path | None,
             report: Path | None = None) -> None:
    """The text output of ``identify ss``: structure, singular values, free-run fits (per
    record for several files), focus decision, order search, validation, how σ was obtained and
    the poles (± σ)."""
    ss = model.system
    typer.echo(f"{model.structure}: order {ss.n_states}, {ss.n_inputs} input(s) "
               f"{list(ss.inputs)} → "
               f"{ss.n_outputs} output(s) {list(ss.outputs)}, dt = {ss.dt:g} s, "
               f"{'stable' if model.stable else 'UNSTABLE'}")
    sv = model.singular_values
    if sv is not None:
        typer.echo("singular values: " + " ".join(f"{v:.3g}" for v in sv[:min(sv.size, 12)]))
    for name, f in zip(ss.outputs, model.fit_percent):
        typer.echo(f"  {name}: free-run fit {f:.2f} %")
    for r in res.get("records", []):
        typer.echo(f"  record {r['data']}: N = {r['n_samples']}, free-run fit "
                   + ", ".join(f"{v:.2f}" for v in r["fit_percent"]) + " % (its own initial state)")
    if "focus" in model.info:
        fo = model.info["focus"]
        typer.echo(f"focus {fo['criterion']} ({fo['data']} data): subspace "
                   f"{fo['subspace_percent']:.2f} %, "
                   f"PEM {fo['refined_percent']:.2f} %; kept the {fo['kept']} model")
    search = res.get("search")
    if search is not None:
        _echo_search(search, res["search_criterion"], focus)
    if val is not None and val.fit_percent is not None:
        typer.echo("validation free-run fit: " + ", ".join(f"{n} {f:.2f} %" for n, f in
                                                           zip(ss.outputs, val.fit_percent)))
        typer.echo(f"  ({val.definition})")
    p, cov = (ss.pole_covariance() if ss.uncertainty is not None else (ss.poles(), None))
    if res["covariance_method"] is not None:
        typer.echo(f"σ: {res['covariance_method']}")
    for i, z in enumerate(p):
        sd = "" if cov is None else f" ± ({np.sqrt(cov[i, 0, 0]):.2g}, {np.sqrt(cov[i, 1, 1]):.2g})"
        typer.echo(f"  pole {z.real:.6g}{z.imag:+.6g}j{sd}")
    echo_written(out, report)


def _echo_search(rows: list[dict], criterion: str, focus: str) -> None:
    """The order search as a table, best first (the JSON ``search`` list): the refined orders
    first, ranked by their ``focus`` fit, then the other subspace models by ``criterion``."""
    val = any("validation_fit_percent" in r for r in rows)
    ref = any("refined_percent" in r for r in rows)
    typer.echo(f"order search, subspace models ranked by {criterion}"
               + (f"; the best refined by PEM and ranked first by their {focus} fit "
                  "(refined %)" if ref else "") + ":")
    typer.echo("  order  " + ("refined %  " if ref else "")
               + ("validation fit % (per output)  " if val else "") + "fit % (per output)  AIC")
    for r in rows:
        vf = r.get("validation_fit_percent")
        vtxt = ("—" if vf is None else ", ".join(f"{v:.2f}" for v in vf)) if val else ""
        fit = ", ".join(f"{v:.2f}" for v in r["fit_percent"]) if r.get("fit_percent") else "—"
        rtxt = ("—" if "refined_percent" not in r else f"{r['refined_percent']:.2f}") if ref else ""
        typer.echo(f"  {r['order']:>5}  " + (f"{rtxt:<9}  " if ref else "")
                   + (f"{vtxt:<30}  " if val else "") + f"{fit:<18}  {r['aic']:.6g}")


@identify_app.command("frf")
def identify_frf_cmd(data: Path = DataArg, input: str = InputsOpt, output: str = OutputsOpt,
                     periods: int = typer.Option(None, "--periods",
                                                 help="Number of periods of a periodic input "
                                                      "(averaging; the first is dropped)."),
                     keep_transient: bool = typer.Option(False, "--keep-transient",
                                                         help="Keep the first period "
                                                              "with --periods."),
                     method: str = typer.Option("auto", "--method",
                                                help="auto, periodic, h1 or spa."),
                     nperseg: int = typer.Option(None, "--nperseg",
                                                 help="Samples per Welch segment (h1)."),
                     fs: float = FsOpt, time: str = TimeOpt, fill: str = FillOpt,
                     detrend: str = DetrendOpt,
                     json_out: bool = JsonOpt):
    """Frequency response with σ on every line (periodic averaging, Welch H1 with coherence,
    SPA)."""
    from ..sysid.linear.identify_mimo import identify_frf

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        tr = _load(data, input, output, fs, time, fill)
        r = identify_frf(tr, input=input, output=output, detrend=detrend, method=method,
                         periods=periods,
                         keep_transient=keep_transient, nperseg=nperseg)
    res = r.to_dict()
    res.update(data=str(data), warnings=report_warnings(caught))
    if json_out:
        emit_json(res)
        return
    unit = r.H_units[0][0]
    typer.echo(f"FRF ({r.method}): {r.frequency_hz.size} lines, {list(r.inputs)} → "
               f"{list(r.outputs)}" + (f", H in {unit}" if unit else ""))
    step = max(1, r.frequency_hz.size // 20)
    unit = f" {unit}" if unit else ""
    for k in range(0, r.frequency_hz.size, step):
        h, s = r.H[k, 0, 0], r.H_std[k, 0, 0]
        typer.echo(f"  {r.frequency_hz[k]:10.4g} Hz  |H| {abs(h):.4g}{unit}  "
                   f"phase {np.degrees(np.angle(h)):7.1f}°  σ {s:.2g}{unit}")


def _coefficients(model, which: str, values, stds, poles: int) -> str:
    """``'9.25±0.28 N/(A*s), …'``: the coefficients of ``which`` (``'num'``/``'den'``, highest
    power of s first; the numerator's leading zeros left out) with their σ and SI unit, from the
    model's parameters (``num_0_0_k``: the coefficient of s^(poles−k)); none on a dimensionless
    one (the monic denominator's 1)."""
    units = {n: p.unit for n, p in model.parameters.items()}
    first = poles + 1 - len(values)
    out = []
    for i, (v, s) in enumerate(zip(values, stds)):
        unit = units.get(f"{which}_0_0_{first + i}", "1")
        out.append(f"{v:.6g}±{s:.2g}" + ("" if unit in ("", "1") else f" {unit}"))
    return ", ".join(out)


@identify_app.command("tf")
def identify_tf_cmd(data: list[Path] = DataArgs, input: str = InputsOpt, output: str = OutputsOpt,
                    poles: int = typer.Option(..., "--poles", help="Number of poles."),
                    zeros: int = typer.Option(..., "--zeros", help="Number of zeros."),
                    out: Path = ModelOutOpt, report: Path = ReportOpt,
                    validate: Path = ValidateOpt,
                    fs: float = FsOpt, time: str = TimeOpt, fill: str = FillOpt,
                    detrend: str = DetrendOpt,
                    json_out: bool = JsonOpt):
    """Continuous-time transfer function (zero-order hold between samples) with σ. Several DATA
    files: one model of all the records, each from its own initial state."""
    several = len(data) > 1
    check_outputs(out, report, [*data, validate])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        model, tr, vtr = run_identify(data, "tf", input, output, fs=fs, time=time, fill=fill,
                                      validate=validate, detrend=detrend, poles=poles,
                                      zeros=zeros)
        save_and_report(model, tr, data, out, report)
        val = validation(model, vtr, validate)
    g, info = model.system, model.info
    res = {"num": g.numerator(), "den": g.denominator(), "num_std": info["num_std"][-(zeros + 1):],
           "den_std": info["den_std"], "natural_frequency_hz": info["natural_frequency_hz"],
           "natural_frequency_hz_std": info["natural_frequency_hz_std"],
           "damping_ratio": info["damping_ratio"],
           "damping_ratio_std": info["damping_ratio_std"], "fit_percent": model.fit_percent,
           "poles": [[float(z.real), float(z.imag)] for z in g.poles()], "inputs": list(g.inputs),
           "outputs": list(g.outputs), "data": data_field(data),
           "out": None if out is None else str(out), "warnings": report_warnings(caught)}
    if val is not None:
        res["validation"] = val.to_dict()
    if several:
        res["records"] = [{"data": str(p), "n_samples": r["n_samples"],
                           "fit_percent": r["fit_percent"]}
                          for p, r in zip(data, model.info["records"])]
    if json_out:
        emit_json(res)
        return
    typer.echo(f"G(s) = num/den, {poles} pole(s), {zeros} zero(s); free-run fit "
               f"{model.fit_percent[0]:.2f} %")
    typer.echo(f"  num: {_coefficients(model, 'num', res['num'], res['num_std'], poles)}")
    typer.echo(f"  den: {_coefficients(model, 'den', res['den'], res['den_std'], poles)}")
    for f, sf, z, sz in zip(res["natural_frequency_hz"], res["natural_frequency_hz_std"],
                            res["damping_ratio"],
                            res["damping_ratio_std"]):
        typer.echo(f"  mode: f_n = {f:.6g} ± {sf:.2g} Hz, ζ = {z:.4g} ± {sz:.2g}")
    if val is not None:
        fit = "—" if val.fit_percent is None else ", ".join(f"{v:.2f}" for v in val.fit_percent)
        typer.echo(f"validation free-run fit: {fit} % ({val.definition})")
    echo_written(out, report)
