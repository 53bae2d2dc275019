"""``gripkit identify arx|armax|oe|rls|search``: linear identification from a data file.

Every command reads DATA (CSV, Parquet or HDF5) with ``--input COL --output COL``, removes the
operating point (``--detrend mean`` by default), and prints a summary table, or one JSON object
(a list for ``search``) with ``--json``. ``identify arx`` also takes several columns
(``--input a,b --output c,d``): a matrix-polynomial ARX whose fit figures (``fit_percent``,
``one_step_fit_percent``, ``validation.fit_percent``) are lists per output in ``--output`` order;
with one input and one output its JSON is the SISO one (``validation.fit_percent`` a number).
Warnings (an unstable model in validation, a
non-converged iteration) go to stderr as ``warning: ...`` lines and into the JSON ``warnings``.
``identify arx|armax|oe DATA1 DATA2 ...`` fit one model of several records (each with its own
initial conditions, one operating point): ``data`` is then the list of files and ``records`` each
file's samples and fit.
"""

from __future__ import annotations

import math
from pathlib import Path

import typer

from .app import identify_app
from ..errors import emit_warning
from ..sysid.checks import LINEAR_ORDERS
from ..units import product_unit
from .common import (FillOpt, FsOpt, JsonOpt, TimeOpt, check_choice, check_data_options,
                     check_number, collected_warnings, emit_json, finish_json, report_warnings,
                     table_console)
from .identify_common import (DataArg, DataArgs, ModelOutOpt, ReportOpt, ValidateOpt, check_outputs,
                              data_field, echo_written, records_field, run_identify,
                              save_and_report, validation)

InputOpt = typer.Option(..., "--input", help="Input column (e.g. the valve current).")
OutputOpt = typer.Option(..., "--output", help="Output column (e.g. the force).")
DetrendOpt = typer.Option("mean", "--detrend",
                          help="Operating-point removal before fitting: mean, linear or none.")
# the orders not given are gripkit.sysid.identify's (its table LINEAR_ORDERS), so a command and
# its Python call give one model; typer's help shows each default
_LIBRARY = "the default of gripkit.sysid.identify"
NaOpt = typer.Option(LINEAR_ORDERS["na"], "--na",
                     help=f"Number of A coefficients (after the leading 1); {_LIBRARY}.")
NbOpt = typer.Option(LINEAR_ORDERS["nb"], "--nb", help=f"Number of B coefficients; {_LIBRARY}.")
NkOpt = typer.Option(LINEAR_ORDERS["nk"], "--nk",
                     help=f"Input delay in samples (B's leading zeros); {_LIBRARY}.")
NcOpt = typer.Option(LINEAR_ORDERS["nc"], "--nc", help=f"Number of C coefficients; {_LIBRARY}.")
NfOpt = typer.Option(LINEAR_ORDERS["na"], "--nf", "--na",
                     help=f"Number of F (denominator) coefficients; {_LIBRARY} (nf = na).")
InputsOpt = typer.Option(..., "--input", help="Input column, or several comma-separated "
                                              "(a,b: MIMO ARX).")
OutputsOpt = typer.Option(..., "--output", help="Output column, or several comma-separated "
                                                "(c,d: MIMO ARX).")


DETREND_CHOICES = ("mean", "linear", "none")


def _check_options(fs, fill, detrend: str, validate: Path | None = None, **orders) -> None:
    """Every option of a linear identification command, checked before the data are read."""
    from ..sysid.checks import check_order

    check_data_options(fs, fill)
    check_choice(detrend, "--detrend", DETREND_CHOICES)
    for name, value in orders.items():
        check_order(value, f"--{name}", 1 if name == "nb" else 0)
    if validate is not None and not validate.is_file():  # the same words as gripkit.io.load
        from ..errors import DataError

        if validate.is_dir():
            raise DataError(f"--validate: {str(validate)!r} is a folder, expected a data file")
        raise DataError(f"--validate: data file {str(validate)!r} not found")


def _several_files_detrend(data: list[Path], detrend: str) -> None:
    from ..errors import DataError

    if len(data) > 1 and detrend == "linear":
        raise DataError("--detrend: with several data files expected mean (the mean of all "
                        "records) or none, found 'linear'",
                        hint="a line per file would give every record its own operating point")


def _siso(method: str, data: list[Path], input: str, output: str, fs, time, fill, detrend: str,
          validate: Path | None, json_out: bool, out_file: Path | None, report: Path | None,
          **orders) -> None:
    """ARX, ARMAX or OE of one input and one output, of one file or of several (one model of
    all the records: ``data`` the list of files, ``fit_percent`` the one-step fit of all records
    and ``records`` each file's): one call of gripkit.sysid.identify, one validation, print."""
    check_outputs(out_file, report, [*data, validate])
    _several_files_detrend(data, detrend)
    if method in ("armax", "oe") and len(data) == 1:  # PEM: its iterations on stderr
        orders["progress"] = True
    with collected_warnings() as caught:
        model, tr, vtr = run_identify(data, method, input, output, fs=fs, time=time, fill=fill,
                                      validate=validate, detrend=detrend, **orders)
        save_and_report(model, tr, data, out_file, report)
        out = model.to_dict()
        out.update(data=data_field(data), detrend=detrend)
        if len(data) > 1:
            out["records"] = records_field(data, model.info["records"])
        elif method != "arx":  # the fit of `gripkit compare` (fit_percent: the one-step fit);
            # not for ARX, whose command loads no numba (its start-up: docs/performance.md)
            out["free_run_fit_percent"] = _compare_fit(model, tr)
        val = _validation_fields(out, model, vtr, validate, detrend)
    if finish_json(out, caught, json_out):
        return
    _print_model(model, None if val is None else val.one_step, out.get("validation_fit_percent"),
                 out.get("free_run_fit_percent", False))
    _echo_records(out.get("records"))
    echo_written(out_file, report)


def _compare_fit(model, tr) -> float | None:
    """The free-run fit of ``gripkit compare`` of the SISO ``model`` on its estimation record
    ``tr`` (:func:`~gripkit.sysid.linear.identify_mimo.compare_score`, loaded already by the
    fit); None for the JSON where compare has none (its −inf for ranking: an unstable model; a
    record whose ‖y − ȳ‖ underflows to 0)."""
    from ..sysid.linear.identify_mimo import compare_score

    fit = compare_score(model, tr)
    return None if fit == -math.inf else fit


def _validation_fields(res: dict, model, vtr, validate: Path | None, detrend: str = "mean"):
    """``--validate``: the validation of ``model`` on the record ``vtr`` (None without one), its
    JSON fields ``validation_fit_percent`` and ``validation`` put into ``res``."""
    val = validation(model, vtr, validate, detrend)
    if val is not None:
        res["validation_fit_percent"] = val.fit_percent
        res["validation"] = val.to_dict()
    return val


def _unit_suffix(unit: str | None) -> str:
    """``' N^2'`` after a printed value, nothing for a dimensionless one."""
    return "" if unit in (None, "", "1") else f" {unit}"


def _print_model(model, val, vfit: float | None = None, free: float | None | bool = False) -> None:
    from rich.table import Table

    con = table_console()
    t = Table("parameter", "value", "σ", "unit", title=f"{model.label}  ({model.input_name} → "
                                                       f"{model.output_name}, "
                                                       f"fs = {1.0 / model.dt:g} Hz, N = "
                                                       f"{model.n_samples})")
    std = model.theta_std
    units = {n: p.unit for n, p in model.parameters.items()}  # SI, as the values are
    for i, (n, v) in enumerate(zip(model.parameter_names, model.theta)):
        t.add_row(n, f"{v:.6g}", "—" if std is None else f"{std[i]:.3g}", units.get(n, ""))
    con.print(t)
    squared = _unit_suffix(product_unit((model.output_unit, 2)))  # mean squared errors
    con.print(f"loss V_N (eq 29) = {model.loss:.6g}{squared}   fit (1-step) = "
              f"{model.fit_percent:.2f} %   AIC = {model.aic:.6g}   FPE = {model.fpe:.6g}{squared}")
    if free is not False:  # one record: the fit `gripkit compare` reports on it
        con.print("free-run fit (estimation data, as gripkit compare) = "
                  + (f"{free:.2f} %" if free is not None else "— (unstable model)"
                     if not model.stable else "— (undefined: ‖y − ȳ‖ underflows)"))
    fmt = lambda z: ", ".join(f"{v.real:.4g}{v.imag:+.4g}j" for v in z) or "none"  # noqa: E731
    con.print(f"poles: {fmt(model.poles())}   ({'stable' if model.stable else 'UNSTABLE'})")
    con.print(f"zeros: {fmt(model.zeros())}   ({model.phase_note})")
    if val is not None:
        fit = "— (unstable model)" if vfit is None else f"{vfit:.2f} %"
        tt = val.tests
        if tt is None:
            con.print(f"validation: free-run fit {fit}; the one-step predictor diverges "
                      "(unstable model)")
            return
        con.print(f"validation: free-run fit {fit}, 1-step fit {val.prediction_fit_percent:.2f} %, "
                  f"residuals {'white' if tt.white else 'NOT white'} (p = {tt.whiteness_p:.3g}), "
                  f"{'independent of' if tt.independent else 'CORRELATED with'} past input "
                  f"(p = {tt.independence_p:.3g})")


def _mimo_arx(data: list[Path], input: str, output: str, na: int, nb: int, nk: int, fs, time, fill,
              detrend: str, validate: Path | None, json_out: bool, out_file: Path | None,
              report: Path | None) -> None:
    """Matrix-polynomial ARX of several columns (a PolynomialModel of matrix polynomials): every
    fit figure is a list per output, in ``--output`` order (``fit_percent`` the free run with
    estimated x0, ``one_step_fit_percent``, and the free run on ``--validate``).
    Several DATA files: one model of all the records (``records``: each file's fits)."""
    from ..errors import DataError, StabilityWarning

    if detrend == "linear":
        raise DataError("--detrend: 'linear' is for one input and one output; with several "
                        "columns expected "
                        "mean or none", hint="use --detrend mean, or detrend the columns before")
    check_outputs(out_file, report, [*data, validate])
    with collected_warnings() as caught:
        model, tr, vtr = run_identify(data, "arx", input, output, fs=fs, time=time, fill=fill,
                                      validate=validate, detrend=detrend, na=na, nb=nb, nk=nk)
        save_and_report(model, tr, data, out_file, report)
        res = model.to_dict()
        info = model.info
        res.update(na=na, nb=nb, nk=nk, data=data_field(data), detrend=detrend,
                   n_samples=model.n_samples, fit_percent=info["free_run_fit_percent"],
                   one_step_fit_percent=model.fit_percent,
                   A_poly=res["A"][1:], A_poly_std=res["A_std"][1:], B_poly=res["B"][nk:],
                   B_poly_std=res["B_std"][nk:], out=None if out_file is None else str(out_file))
        if "records" in info:
            res["records"] = records_field(data, info["records"])
        if not model.stable:
            emit_warning("arx: the identified model is unstable (a pole on or outside "
                         "the unit circle): "
                         "no free-run fit is reported", StabilityWarning)
        _validation_fields(res, model, vtr, validate)
    if finish_json(res, caught, json_out):
        return
    typer.echo(f"ARX [{na} {nb} {nk}]: {len(model.inputs)} input(s) {list(model.inputs)} → "
               f"{len(model.outputs)} "
               f"output(s) {list(model.outputs)}, dt = {model.dt:g} s, N = {model.n_samples}, "
               f"{'stable' if model.stable else 'UNSTABLE'}")
    for what, polys, stds in (("A", res["A_poly"], res["A_poly_std"]),
                              ("B", res["B_poly"], res["B_poly_std"])):
        first = 1 if what == "A" else nk
        for i, (c, sd) in enumerate(zip(polys, stds)):
            rows = ("; ".join(" ".join(f"{v:.4g}±{s:.2g}" for v, s in zip(r, rs))
                              for r, rs in zip(c, sd)))
            typer.echo(f"  {what}{first + i} = [{rows}]")
    for i, name in enumerate(model.outputs):
        free = "—" if res["fit_percent"] is None else f"{res['fit_percent'][i]:.2f} %"
        line = f"  {name}: fit free run {free}, 1-step {res['one_step_fit_percent'][i]:.2f} %"
        if res.get("validation_fit_percent") is not None:
            line += f", validation free run {res['validation_fit_percent'][i]:.2f} %"
        typer.echo(line)
    _echo_records(res.get("records"))
    echo_written(out_file, report)


def _echo_records(records: list[dict] | None, free_run: bool = False) -> None:
    """One line per record of a fit of several files (``free_run``: a single fit per record is
    the free run, as for the nonlinear families, not the one-step fit of ARX/ARMAX/OE)."""
    if not records:
        return
    typer.echo(f"{len(records)} records, each with its own initial conditions:")
    for r in records:
        fit = r["fit_percent"]
        free = "—" if fit is None else (f"{fit:.2f} %" if isinstance(fit, float) else
                                        "[" + ", ".join("—" if v is None else f"{v:.2f}"
                                                        for v in fit) + "] %")
        kind = "1-step" if isinstance(fit, float) and not free_run else "free run"
        line = f"  {r['data']}: N = {r['n_samples']}, fit ({kind}) {free}"
        if "one_step_fit_percent" in r:
            line += ", 1-step [" + ", ".join(f"{v:.2f}" for v in r["one_step_fit_percent"]) + "] %"
        typer.echo(line)


@identify_app.command("arx")
def identify_arx(data: list[Path] = DataArgs, input: str = InputsOpt, output: str = OutputsOpt,
                 na: int = NaOpt, nb: int = NbOpt, nk: int = NkOpt,
                 fs: float = FsOpt, time: str = TimeOpt, fill: str = FillOpt,
                 detrend: str = DetrendOpt,
                 validate: Path = ValidateOpt, json_out: bool = JsonOpt, out: Path = ModelOutOpt,
                 report: Path = ReportOpt):
    """ARX (orders na, nb, nk) by least squares (QR), with σ, loss (eq 29), fit, AIC, poles and
    zeros.
    With several columns (``--input a,b --output c,d``) a matrix-polynomial ARX: fit figures are
    lists per output, in ``--output`` order. With several DATA files one model of all the records
    (each with its own initial conditions; --detrend mean removes the mean of all of them)."""
    from ..sysid.linear.identify_mimo import several

    _check_options(fs, fill, detrend, validate, na=na, nb=nb, nk=nk)
    if several(input, output):
        _mimo_arx(data, input, output, na, nb, nk, fs, time, fill, detrend, validate, json_out, out,
                  report)
        return
    _siso("arx", data, input, output, fs, time, fill, detrend, validate, json_out, out, report,
          na=na, nb=nb, nk=nk)


@identify_app.command("armax")
def identify_armax(data: list[Path] = DataArgs, input: str = InputOpt, output: str = OutputOpt,
                   na: int = NaOpt,
                   nb: int = NbOpt,
                   nc: int = NcOpt,
                   nk: int = NkOpt,
                   fs: float = FsOpt, time: str = TimeOpt, fill: str = FillOpt,
                   detrend: str = DetrendOpt,
                   validate: Path = ValidateOpt, json_out: bool = JsonOpt, out: Path = ModelOutOpt,
                   report: Path = ReportOpt):
    """ARMAX (orders na, nb, nc, nk) by prediction-error minimisation. With several DATA files one
    model of all the records (each with its own initial conditions)."""
    _check_options(fs, fill, detrend, validate, na=na, nb=nb, nc=nc, nk=nk)
    _siso("armax", data, input, output, fs, time, fill, detrend, validate, json_out, out, report,
          na=na, nb=nb, nc=nc, nk=nk)


@identify_app.command("oe")
def identify_oe(data: list[Path] = DataArgs, input: str = InputOpt, output: str = OutputOpt,
                nb: int = NbOpt,
                nf: int = NfOpt,
                nk: int = NkOpt,
                fs: float = FsOpt, time: str = TimeOpt, fill: str = FillOpt,
                detrend: str = DetrendOpt,
                validate: Path = ValidateOpt, json_out: bool = JsonOpt, out: Path = ModelOutOpt,
                report: Path = ReportOpt):
    """Output-error (orders nb, nf, nk) by prediction-error minimisation. With several DATA files
    one model of all the records (each with its own initial outputs, estimated)."""
    _check_options(fs, fill, detrend, validate, nb=nb, nf=nf, nk=nk)
    _siso("oe", data, input, output, fs, time, fill, detrend, validate, json_out, out, report,
          nb=nb, nf=nf, nk=nk)


@identify_app.command("rls")
def identify_rls(data: Path = DataArg, input: str = InputOpt, output: str = OutputOpt,
                 na: int = NaOpt, nb: int = NbOpt, nk: int = NkOpt,
                 forgetting: float = typer.Option(1.0, "--forgetting",
                                                  help="Forgetting factor λ in (0, 1]."),
                 p0: float = typer.Option(1e4, "--p0", help="Initial covariance P0 = p0·I."),
                 windup: str = typer.Option("trace", "--windup", help="Anti-windup: trace, "
                                                                      "directional or none."),
                 trajectory: Path = typer.Option(None, "--trajectory",
                                                 help="Write θ(t), σ(t), prediction and "
                                                      "error to this file."),
                 fs: float = FsOpt, time: str = TimeOpt, fill: str = FillOpt,
                 detrend: str = DetrendOpt,
                 json_out: bool = JsonOpt):
    """Recursive least squares ARX (orders na, nb, nk) with forgetting; θ and σ at every sample.
    No --out, --report or --validate: the result is a parameter trajectory θ(t), not one model
    (with forgetting, θ at the end describes the end of the record only); write θ(t) with
    --trajectory, or fit one model of the record with identify arx."""
    from ..io import save
    from ..sysid import RLS
    from .paths import output_file

    _check_options(fs, fill, detrend)
    # checks the orders and the options
    RLS(na, nb, nk, forgetting=forgetting, p0=p0, windup=windup)
    output_file(trajectory, "--trajectory", [data])
    with collected_warnings() as caught:
        res = run_identify([data], "rls", input, output, fs=fs, time=time, fill=fill,
                           detrend=detrend, na=na, nb=nb, nk=nk, forgetting=forgetting, p0=p0,
                           windup=windup)[0]
        if trajectory is not None:
            save(res.to_trajectory(), trajectory)
    out = res.to_dict()
    out.update(data=str(data), detrend=detrend, input=input, output=output,
               trajectory=None if trajectory is None else str(trajectory),
               warnings=report_warnings(caught))
    if res.theta_std_final is None:
        out["theta_std_note"] = _no_sigma_reason(res, forgetting)
    if json_out:
        emit_json(out)
        return
    from rich.table import Table

    t = Table("parameter", "final value", "σ", "unit", title=f"RLS ARX [{na} {nb} {nk}], λ = "
                                                             f"{forgetting:g}, "
                                                             f"N = {res.n_samples}")
    std = res.theta_std_final
    units = {n: p.unit for n, p in res.model.parameters.items()}
    for i, n in enumerate(res.names):
        t.add_row(n, f"{res.theta_final[i]:.6g}", "—" if std is None else f"{std[i]:.3g}",
                  units.get(n, ""))
    con = table_console()
    con.print(t)
    squared = _unit_suffix(product_unit((res.model.output_unit, 2)))
    con.print(f"loss V_N of the a-priori errors (eq 29) = {res.loss:.6g}{squared}")
    if std is None:
        con.print(out["theta_std_note"], markup=False, highlight=False)
    if trajectory is not None:
        con.print(f"parameter trajectory written to {trajectory}")


def _no_sigma_reason(res, forgetting: float) -> str:
    """Why an RLS result has no σ: σ̂² divides the weighted squared errors by w₁ − p, w₁ the
    effective sample count (λ^k-weighted updates, 1/(1 − λ) in the limit), so it needs w₁ > p."""
    p = len(res.names)
    updates = res.n_samples - res.first_update
    lam = float(forgetting)
    w1 = updates if lam == 1.0 else (1.0 - lam ** updates) / (1.0 - lam)
    text = (f"σ —: the forgetting factor λ = {lam:g} keeps about {w1:.3g} effective samples "
            f"(1/(1 − λ)), not more than the {p} parameters: too few to estimate the noise "
            f"variance that σ rests on")
    if lam < 1.0 and 1.0 / (1.0 - lam) <= p:
        return f"{text}; choose --forgetting above {1.0 - 1.0 / p:.4g} for σ"
    return (f"σ —: {updates} update(s), about {w1:.3g} effective samples, not more than the {p} "
            f"parameters: too few to estimate the noise variance that σ rests on")


@identify_app.command("search")
def identify_search(data: Path = DataArg, input: str = InputOpt, output: str = OutputOpt,
                    na: str = typer.Option("1:4", "--na", help="Range of na, e.g. 1:4."),
                    nb: str = typer.Option("1:4", "--nb", help="Range of nb, e.g. 1:4."),
                    nk: str = typer.Option("1:10", "--nk", help="Range of nk, e.g. 1:10."),
                    criterion: str = typer.Option("aic", "--criterion",
                                                  help="Ranking: aic, fpe or loss."),
                    top: int = typer.Option(10, "--top", help="Rows shown in the table "
                                                              "(JSON lists all)."),
                    fs: float = FsOpt, time: str = TimeOpt, fill: str = FillOpt,
                    detrend: str = DetrendOpt,
                    validate: Path = ValidateOpt, json_out: bool = JsonOpt, out: Path = ModelOutOpt,
                    report: Path = ReportOpt):
    """Fit every ARX structure of the ranges and rank them (best first; by free-run fit on
    --validate). --out and --report: the best structure, fitted by identify arx on the whole
    record (the ranking fits every structure on the samples they have in common)."""
    from ..sysid.linear.search import CRITERIA, parse_range

    _check_options(fs, fill, detrend, validate)
    check_choice(criterion, "--criterion", CRITERIA)
    check_number(top, "--top", minimum=1, integer=True)
    for name, text in (("--na", na), ("--nb", nb), ("--nk", nk)):
        parse_range(text, name)
    check_outputs(out, report, [data, validate])
    with collected_warnings() as caught:
        res, tr, vtr = run_identify([data], "search", input, output, fs=fs, time=time, fill=fill,
                                    validate=validate, fit_validate=True, detrend=detrend,
                                    na=na, nb=nb, nk=nk, criterion=criterion)
        if out is not None or report is not None:
            from ..sysid import identify

            b = res.best
            best = identify(tr, "arx", input=input, output=output, na=b.na, nb=b.nb, nk=b.nk,
                            detrend=detrend)
            save_and_report(best, tr, [data], out, report)
    report_warnings(caught)
    criterion = res.criterion
    if json_out:
        emit_json(res.to_list())
        return
    from rich.table import Table

    t = Table("rank", "na", "nb", "nk", "loss V_N", "AIC", "FPE", "1-step fit %",
              "validation fit %",
              title=f"ARX structures ranked by {criterion.upper()} ({res.n_used} common samples)")
    for i, c in enumerate(res.candidates[:top], 1):
        v = c.validation_fit_percent
        t.add_row(str(i), str(c.na), str(c.nb), str(c.nk), f"{c.loss:.5g}", f"{c.aic:.6g}",
                  f"{c.fpe:.5g}",
                  f"{c.fit_percent:.2f}", "—" if v is None else f"{v:.2f}")
    table_console().print(t)
    if res.skipped:
        typer.echo(f"{len(res.skipped)} structure(s) skipped (not identifiable "
                   "from these data)", err=True)
