"""``gripkit identify hysteresis DATA --input U --output Y [--model bouc-wen|prandtl-ishlinskii]
[--form actuator|oscillator] [--exponent N|free] [--operators M]
[--initial-state estimate|zero] [--validate DATA2] [--out MODEL.json] [--json]``: a generic
Bouc-Wen (actuator or oscillator form) or Prandtl–Ishlinskii hysteresis from a record, through
``gripkit.sysid.identify(data, "hysteresis", ...)`` (:func:`gripkit.sysid.hysteresis`). The
oscillator's JSON has ``initial_states``: each file's state (x0, ẋ0, z0) at its first sample
with σ (none with ``--initial-state zero``)."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from .common import check_choice, collected_warnings, emit_json, report_warnings
from .identify_common import (KeywordOrNumber, RecordOptions, data_field, record_command,
                              records_field)
from .identify_linear import DataArgs, _echo_records


EXPONENT = KeywordOrNumber("--exponent", "1", "free", float, 1.0, 10.0,
                           "'free' or a number in [1, 10]", "Bouc-Wen exponent n (1 = eq 3 of "
                           "the seed), or free.", "--exponent 1 is the seed's Bouc-Wen (eq 3); "
                           "free estimates it")


@record_command("hysteresis")
def identify_hysteresis(data: list[Path] = DataArgs,
                        input_col: str = typer.Option(..., "--input", help="Input column "
                                                                           "(voltage, force)."),
                        output_col: str = typer.Option(..., "--output",
                                                       help="Output column (displacement)."),
                        model: str = typer.Option("bouc-wen", "--model",
                                                  help="bouc-wen or prandtl-ishlinskii."),
                        form: str = typer.Option("actuator", "--form",
                                                 help="Bouc-Wen form: actuator (y = d u − h) "
                                                      "or oscillator (force on a mass)."),
                        exponent: str = EXPONENT.option(),
                        operators: int = typer.Option(10, "--operators",
                                                      help="Prandtl-Ishlinskii: number of plays."),
                        burn_in: int = typer.Option(0, "--burn-in",
                                                    help="Samples simulated but not scored."),
                        initial_state: Optional[str] = typer.Option(
                            None, "--initial-state",
                            help="Oscillator form: estimate each record's state (x, x', z) at "
                                 "its first sample with the parameters (estimate, the default), "
                                 "or start every record at rest (zero)."),
                        *, opts: RecordOptions):
    """Hysteresis (Bouc-Wen or Prandtl-Ishlinskii): parameters with σ, free-run fit.
    The generic family through gripkit.sysid.identify (several records, the oscillator form,
    Prandtl-Ishlinskii, --validate, --out, --report): use it for a model to save, validate or
    simulate; identify bouc-wen is the TSFM seed's static step (§IV-C1) of one quasi-static sweep.

    Several DATA files: one model of all the records, each from its own relaxed state
    (``records``: each file's fit)."""
    from ..sysid.nonlinear.hysteresis import FORMS, INITIAL_STATES, MODELS

    check_choice(model, "--model", MODELS)
    check_choice(form, "--form", FORMS)
    if initial_state is not None:
        check_choice(initial_state, "--initial-state", INITIAL_STATES)
    n = EXPONENT.parse(exponent)
    with collected_warnings() as caught:
        # several files: one model of every file's record, each from its own relaxed state
        m, tr, val = opts.identify(data, "hysteresis", input_col, output_col, detrend="none",
                                   model=model, form=form, exponent=n, operators=operators,
                                   burn_in=burn_in, progress=not opts.json_out,
                                   **({} if initial_state is None
                                      else {"initial_state": initial_state}))
        page = opts.save(m, tr, val, data)
    lines = report_warnings(caught)
    if opts.json_out:
        structure = ({"model": model, "form": form, "exponent": m.n,
                      "exponent_estimated": "n" in m.free}
                     if model == "bouc-wen" else
                     {"model": m.structure, "operators": len(m.thresholds),
                      "thresholds": [float(r) for r in m.thresholds]})
        structure["criterion"] = m.criterion
        oscillator = m.structure == "bouc-wen-oscillator"
        if oscillator:
            structure["initial_state"] = m.initial_state_option
        emit_json({"data": data_field(data),
                   "input": input_col, "output": output_col,
                   "input_unit": m.input_unit, "output_unit": m.output_unit,
                   "structure": structure,
                   "parameters": [{"name": p.name, "value": p.value, "std": p.std,
                                   "unit": p.unit, "fixed": p.fixed}
                                  for p in m.parameters.values()],
                   "fit_percent": m.fit_percent, "definition": m.fit_definition,
                   "validation": None if opts.validate is None else
                   {"data": str(opts.validate), "fit_percent": m.validation_fit_percent},
                   **({"records": records_field(data, m.records)} if len(data) > 1 else {}),
                   **({"initial_states": _initial_states(data, m)} if oscillator else {}),
                   "model": None if opts.out is None else str(opts.out), "report": page,
                   "warnings": lines})
    else:
        typer.echo(m.summary())
        fmt = lambda v: "diverged" if v is None else f"{v:.2f} %"  # noqa: E731
        typer.echo(f"free-run fit (estimation): {fmt(m.fit_percent)}")
        if opts.validate is not None:
            typer.echo(f"free-run fit (validation): {fmt(m.validation_fit_percent)}")
        if len(data) > 1:
            _echo_records(records_field(data, m.records), free_run=True)


def _initial_states(data: list[Path], m) -> list[dict]:
    """The JSON ``initial_states`` of an oscillator: each estimation file's state (x, x', z) at
    its first scored sample (``sample``: --burn-in) with σ and units (empty when every record
    started at rest)."""
    yu = m.output_unit
    units = {"x0": yu, "v0": f"{yu}/s" if yu not in ("", "1") else "1/s", "z0": yu}
    return [{"data": str(p), **{k: s[k] for k in ("x0", "v0", "z0")}, "std": dict(s["std"]),
             "units": units, "sample": s["sample"]} for p, s in zip(data, m.initial_states)]
