"""The shell of every ``gripkit identify`` command that yields a model: read the data files into
trajectories, one call of :func:`gripkit.sysid.identify`, one call of
:func:`gripkit.sysid.identify_results.validate_model` for ``--validate``, then ``--out`` (the model
file: every model saves itself) and ``--report`` (``model.report``: every model writes its HTML
report). The commands only parse options and print."""

from __future__ import annotations

import functools
import inspect
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Optional

import typer

from .app import identify_app
from .common import (FillOpt, FsOpt, JsonOpt, ModelReportOpt, TimeOpt, check_data_options,
                     keyword_or_number, load_data, write_model_page)

DataArg = typer.Argument(..., help="Data file (.csv, .parquet, .h5).", show_default=False)
#: DATA of the commands that fit one model of several records
DataArgs = typer.Argument(..., help="Data file(s) (.csv, .parquet, .h5); several: one model of all "
                                    "the records, each with its own initial conditions.",
                          metavar="DATA", show_default=False)
ValidateOpt = typer.Option(None, "--validate", help="Second record (same columns): the one "
                                                    "validation fit, as gripkit compare gives it.")
ModelOutOpt = typer.Option(None, "--out", help="Write the identified model to this JSON file.")
ReportOpt = typer.Option(None, "--report", help="Write an HTML report of the model on the data "
                                                "to this folder.")


@dataclass(frozen=True)
class KeywordOrNumber:
    """An option that is a keyword or a number (``--terms auto|N``, ``--exponent free|N``),
    declared once: :meth:`option` is its typer option, :meth:`parse` its value, the keyword or a
    ``kind`` in [``low``, ``high``], else a DataError "FLAG: expected EXPECTED, found …" with
    ``hint``."""

    flag: str
    default: str
    keyword: str
    kind: type
    low: float
    high: float
    expected: str
    help: str
    hint: str

    def option(self):
        return typer.Option(self.default, self.flag, help=self.help)

    def parse(self, value: str):
        return keyword_or_number(value, self.flag, self.keyword, self.kind, self.low, self.high,
                                 self.expected, self.hint)


def columns(inputs, outputs) -> list[str]:
    """The columns to read: every input and output name (``'a,b'`` lists several)."""
    from ..sysid.io_data import parse_names

    return list(parse_names(inputs, "--input")) + list(parse_names(outputs, "--output"))


def check_outputs(out: Path | None, report: Path | None, inputs=()) -> None:
    """``--out`` (a model file) and ``--report`` (a report folder) checked before any work, both
    (:mod:`gripkit.cli.paths`: writable, and none of ``inputs``, the command's input files)."""
    from .paths import output_json, report_folder

    inputs = list(inputs)
    output_json(out, "--out", inputs)
    report_folder(report, "--report", inputs)


def run_identify(data: list[Path], method: str, input, output, *, fs, time, fill,
                 validate: Path | None = None, fit_validate: bool = False, **options):
    """Load ``data`` (one file: a trajectory; several: one model of all the records) and
    ``validate``, and call :func:`gripkit.sysid.identify` once (``fit_validate``: with the
    validation record as its ``validate`` option, for the methods that rank or select by it:
    ss, search, narx, hw, nlss, hysteresis); errors about ``data[i]`` name the file. Returns
    ``(model, trajectory or list of them, validation trajectory or None)``."""
    from ..errors import GripkitError
    from ..sysid import identify

    cols = columns(input, output)
    trs = [load_data(p, cols, fs, time, fill) for p in data]  # its errors name the file
    vtr = None if validate is None else load_data(validate, cols, fs, time, fill)
    tr = trs[0] if len(trs) == 1 else trs
    if fit_validate and vtr is not None:
        options["validate"] = vtr
    try:
        model = identify(tr, method, input=input, output=output, **options)
    except GripkitError as exc:
        if len(trs) == 1:
            raise
        msg = exc.message
        for i, path in reversed(list(enumerate(data))):  # data[10] before data[1]
            msg = msg.replace(f"data[{i}]", repr(str(path)))
        raise type(exc)(msg, hint=exc.hint) from None
    return model, tr, vtr


def validation(model, vtr, validate: Path | None, detrend: str = "mean"):
    """The :class:`~gripkit.sysid.identify_results.ValidationResult` of ``model`` on the
    ``--validate`` record (None without one), its ``data`` the path as given."""
    if vtr is None:
        return None
    import dataclasses

    from ..sysid.identify_results import validate_model

    return dataclasses.replace(validate_model(model, vtr, detrend=detrend), data_file=str(validate))


def save_and_report(model, tr, data: list[Path], out: Path | None, report: Path | None) -> None:
    """``--out``: the model file (outputs shown in the units of the data's file when there is one
    file); ``--report``: the HTML report of the model on that file, or with several files one
    report per file (each record with its own initial state) in ``report/<file stem>/``."""
    if out is None and report is None:
        return
    fm = model
    if len(data) == 1 and hasattr(fm, "with_display_units"):
        fm = fm.with_display_units(tr)
    if out is not None:
        fm.save(out)
    if report is None:
        return
    if len(data) == 1:
        fm.report(tr, report, data_name=Path(data[0]).name)
        return
    stems = [Path(p).stem for p in data]
    for i, (path, record) in enumerate(zip(data, tr)):
        folder = stems[i] if stems.count(stems[i]) == 1 else f"{i + 1}-{stems[i]}"
        fm.report(record, Path(report) / folder, data_name=Path(path).name)


def echo_written(out: Path | None, report: Path | None) -> None:
    """Say what ``--out`` and ``--report`` wrote (the text summary's last lines)."""
    if out is not None:
        typer.echo(f"model written to {out}")
    if report is not None:
        typer.echo(f"report written to {report}")


def save_and_page(model, out: Path | None, report: Path | None, record, vrecord,
                  data_path: Path, validate: Path | None):
    """``--out``: ``model.save(out)``; ``--report``: the model page (:func:`write_model_page`)
    on the validation record ``vrecord`` (file ``validate``) when given, else on ``record``
    (file ``data_path``). Returns the page, None without ``--report``."""
    if out is not None:
        model.save(out)
    if report is None:
        return None
    return write_model_page(model, record if vrecord is None else vrecord, report,
                            data_path if validate is None else validate)


def first_record(tr):
    """The record of the one file, or the first of several (what ``run_identify`` loaded)."""
    return tr if not isinstance(tr, list) else tr[0]


def data_field(data: list[Path]) -> str | list[str]:
    """The JSON ``data`` field: the file, or the list of files of a fit of several records."""
    return str(data[0]) if len(data) == 1 else [str(p) for p in data]


def records_field(data: list[Path], records: list[dict]) -> list[dict]:
    """The JSON ``records`` field: each file with its samples and fits (initial states left
    out)."""
    return [{"data": str(p), **{k: v for k, v in r.items() if k != "x0"}}
            for p, r in zip(data, records)]


@dataclass(frozen=True)
class RecordOptions:
    """The options every nonlinear identify command (hw, hysteresis, narx, nlss) shares, declared
    once by :func:`record_command`: ``--validate`` (a second record: the validation fit, and the
    record the report shows), ``--out`` (model JSON), ``--report`` (folder), ``--fs``,
    ``--time``, ``--fill`` and ``--json``."""

    validate: Optional[Path]
    out: Optional[Path]
    report: Optional[Path]
    fs: Optional[float]
    time: Optional[str]
    fill: Optional[str]
    json_out: bool

    def identify(self, data: list[Path], method: str, input, output, **options):
        """:func:`run_identify` with these options, the validation record passed to the fit
        (it ranks structures by it)."""
        return run_identify(data, method, input, output, fs=self.fs, time=self.time,
                            fill=self.fill, validate=self.validate, fit_validate=True, **options)

    def save(self, model, tr, vtr, data: list[Path]):
        """``--out`` and ``--report`` (:func:`save_and_page`) for what :meth:`identify` returned;
        the page's path, None without ``--report``."""
        return save_and_page(model, self.out, self.report, first_record(tr), vtr, data[0],
                             self.validate)


#: (parameter, type, typer option) of RecordOptions' fields, in its order
_RECORD_PARAMETERS = (
    ("validate", Optional[Path], typer.Option(None, "--validate",
                                              help="Validation record (same columns).")),
    ("out", Optional[Path], typer.Option(None, "--out", help="Write the model (JSON).")),
    ("report", Optional[Path], ModelReportOpt),
    ("fs", Optional[float], FsOpt),
    ("time", Optional[str], TimeOpt),
    ("fill", Optional[str], FillOpt),
    ("json_out", bool, JsonOpt),
)


def record_command(name: str):
    """Register the decorated function as ``gripkit identify NAME`` with the options of
    :class:`RecordOptions` after its own, checked (``--fs``, ``--fill``, ``--out``, ``--report``)
    before it runs; it receives them as its keyword ``opts``."""
    shared = [inspect.Parameter(n, inspect.Parameter.POSITIONAL_OR_KEYWORD, default=opt,
                                annotation=kind) for n, kind, opt in _RECORD_PARAMETERS]
    names = [f.name for f in fields(RecordOptions)]

    def register(func):
        signature = inspect.signature(func)
        own = [p for p in signature.parameters.values() if p.name != "opts"]

        @functools.wraps(func)
        def command(**kw):
            opts = RecordOptions(**{n: kw.pop(n) for n in names})
            check_data_options(opts.fs, opts.fill)
            data = kw.get("data")
            inputs = [*(data if isinstance(data, (list, tuple)) else [data]), opts.validate]
            check_outputs(opts.out, opts.report, inputs)
            return func(**kw, opts=opts)

        command.__signature__ = signature.replace(parameters=own + shared)
        return identify_app.command(name)(command)

    return register
