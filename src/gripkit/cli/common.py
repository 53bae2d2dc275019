"""Helpers shared by CLI commands: data loading options, JSON output, result printing."""

from __future__ import annotations

import json
import math
import sys
import warnings
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import typer

from ..signals.trajectory import MAX_FILL_FRACTION
from ..sysid.model_file import plain

__all__ = ["emit_json", "is_mcap", "load_data", "collected_warnings", "report_warnings",
           "finish_json", "check_data_options", "check_choice", "check_number", "complex_pairs",
           "FsOpt", "TimeOpt", "FillOpt", "JsonOpt", "ModelReportOpt", "write_model_page"]

FsOpt = typer.Option(None, "--fs", help="Sampling rate in Hz, when the file has no time column "
                                         "(with one, it must agree with the time stamps).")
TimeOpt = typer.Option(None, "--time", help="Name of the time column (default: t/time/timestamp).")
FillOpt = typer.Option(None, "--fill", help="Missing values: 'drop' rows or 'interpolate' "
                                            f"(at most {100 * MAX_FILL_FRACTION:g} % of a channel, "
                                            "with a warning; default: error).")
JsonOpt = typer.Option(False, "--json", help="Print one JSON object on stdout.")
ModelReportOpt = typer.Option(None, "--report", help="Write an HTML report of the model on the "
                                                     "--validate record (else on the record) "
                                                     "to this folder.")


def is_mcap(path: Path) -> bool:
    from ..io import FORMATS

    return FORMATS.get(Path(path).suffix.lower()) == "mcap"


def load_data(path: Path, columns: list[str], fs: float | None, time: str | None, fill: str | None):
    """The record's ``columns`` as a Trajectory. An MCAP log's channels keep the names given on
    the command line (``/topic:field`` or ``alias=/topic:field``, as :func:`gripkit.io.load`
    takes them in Python), so the commands find them by those names and a model identified from
    the log names them so in its file (``gripkit compare MODEL.json LOG.mcap`` reads them again)."""
    from ..io import load

    tr = load(path, columns=columns, fs=fs, time=time, fill=fill)
    if is_mcap(path):
        from ..io.mcap_reader import parse_column

        tr = tr.rename(**{parse_column(c)[0]: c for c in dict.fromkeys(columns)})
    return tr


def check_data_options(fs: float | None, fill: str | None) -> None:
    """``--fs`` and ``--fill``, checked before any file is read (commands call this first, with
    their own option checks, so that a bad option is reported before a long load)."""
    from ..io.table import check_fill, check_fs

    check_fill(fill)
    check_fs(fs)


def check_choice(value: str, option: str, choices: tuple[str, ...]) -> None:
    """A :class:`~gripkit.errors.DataError` unless ``value`` is one of ``choices``."""
    from ..errors import DataError

    if value not in choices:
        raise DataError(f"{option}: expected one of {', '.join(choices)}, found {value!r}")


def check_number(value, option: str, *, minimum: float | None = None, above: float | None = None,
                 integer: bool = False, nonzero: bool = False) -> None:
    """A :class:`~gripkit.errors.DataError` unless ``value`` (when given) is a finite number
    ``>= minimum`` / ``> above`` (an integer if ``integer``, non-zero if ``nonzero``)."""
    from ..errors import DataError

    if value is None:
        return
    want = ("an integer" if integer else "a finite number") + (
        f" >= {minimum:g}" if minimum is not None else f" > {above:g}" if above is not None
        else "") + (
        ", not zero" if nonzero else "")
    ok = (math.isfinite(value) and (minimum is None or value >= minimum)
          and (above is None or value > above)
          and (not integer or float(value).is_integer()) and not (nonzero and value == 0))
    if not ok:
        raise DataError(f"{option}: expected {want}, found {value!r}")


def check_effort_scale(value: float) -> None:
    """``--effort-scale``: :func:`gripkit.sysid.rigid_body.friction.check_effort_scale`, before
    the data are read."""
    from ..sysid.rigid_body.friction import check_effort_scale as check

    check(value, "--effort-scale")


def keyword_or_number(value: str, option: str, keyword: str, kind, low: float, high: float,
                      expected: str, hint: str):
    """``keyword`` itself, or ``value`` as ``kind`` (int or float) in ``[low, high]``; else a
    :class:`~gripkit.errors.DataError` "OPTION: expected EXPECTED, found VALUE" with ``hint``."""
    from ..errors import DataError

    if value == keyword:
        return keyword
    try:
        n = kind(value)
    except ValueError:
        n = None
    if n is None or not low <= n <= high:
        raise DataError(f"{option}: expected {expected}, found {value!r}", hint=hint)
    return n


#: columns of a printed table when stdout is a pipe or a file (rich would take 80 and cut numbers)
PIPE_WIDTH = 120


def table_console():
    """A rich Console for the commands' tables: the terminal's width, or :data:`PIPE_WIDTH`
    columns when stdout is no terminal (a pipe, a file), where rich's default of 80 cut values
    to ``4.8232e…``."""
    from rich.console import Console

    return Console() if sys.stdout.isatty() else Console(width=PIPE_WIDTH)


def emit_json(obj) -> None:
    """Write ``obj`` as one JSON object on stdout (NaN/inf become null)."""
    sys.stdout.write(json.dumps(plain(obj), allow_nan=False) + "\n")
    sys.stdout.flush()


def complex_pairs(values) -> list[list[float]]:
    """Complex numbers as ``[[re, im], ...]``."""
    return [[float(np.real(v)), float(np.imag(v))] for v in np.atleast_1d(values)]


@contextmanager
def collected_warnings():
    """Record every warning raised inside the block (``with collected_warnings() as caught``);
    if the block fails, print them (:func:`report_warnings`) before the error propagates, so that a
    warning that explains the error (a corrupt sample, a truncated file) is not lost."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            yield caught
        except Exception:
            report_warnings(caught)
            raise


def report_warnings(caught) -> list[str]:
    """Print each distinct recorded warning as one ``warning: …`` line on stderr; return the lines
    (for the JSON output)."""
    lines = list(dict.fromkeys(f"{w.category.__name__}: {w.message}" for w in caught))
    for line in lines:
        print(f"warning: {line}", file=sys.stderr)
    return lines


def finish_json(result: dict, caught, json_out: bool) -> bool:
    """The end of a command with a JSON result: the recorded warnings printed
    (:func:`report_warnings`) and listed in ``result['warnings']``; with ``--json``
    (``json_out``) ``result`` printed as one JSON object. Returns ``json_out``: True when the
    command has printed its result."""
    result["warnings"] = report_warnings(caught)
    if json_out:
        emit_json(result)
    return json_out


def write_model_page(model, record, folder: Path, data_path: Path) -> str:
    """``identify narx|hw|nlss|hysteresis --report DIR``: the report of ``model`` on ``record`` (the
    validation record when one is given, else the estimation record) through the model protocol
    (:mod:`gripkit.sysid.protocol_report`), the page ``gripkit report MODEL DATA --out DIR``
    writes; returns the page's path."""
    from ..sysid.protocol_report import write_protocol_report

    return str(write_protocol_report(model, record, folder, data_name=Path(data_path).name)[0])
