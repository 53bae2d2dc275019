"""``gripkit compare MODEL.json DATA [--json]``: the validation fit of a saved model on a record,
per output (``model.compare(data)``, by the model's ``fit_definition``); and ``gripkit simulate
MODEL.json --data DATA [--out FILE]`` (dispatched from :mod:`gripkit.cli.simulate`). Any model
file :func:`gripkit.sysid.load_model` reads, through the protocol of
:mod:`gripkit.sysid.model_protocol` only."""

from __future__ import annotations

import warnings
from pathlib import Path

import typer

from .app import app
from .common import FillOpt, FsOpt, JsonOpt, TimeOpt, emit_json, is_mcap, load_data, report_warnings

ModelArg = typer.Argument(..., help="Model file written by "
                                    "identify --out (.json).", show_default=False)


def _model_and_data(model_path: Path, data: Path, fs, time, fill, outputs: bool):
    from ..sysid import load_model

    model = load_model(model_path)
    cols = list(model.inputs) + (list(model.outputs) if outputs else [])
    from ..io import load

    # an MCAP log is read by the model's channel names (the /topic:field specs it was fitted on)
    tr = (load_data(data, cols, fs, time, fill) if is_mcap(data) else load(data, fs=fs, time=time,
                                                                           fill=fill))
    missing = [c for c in cols if c not in tr.names]
    if missing:
        from ..errors import DataError

        kind = "input" if any(c in model.inputs for c in missing) else "output"
        raise DataError(f"data {str(data)!r}: the model's {kind} column(s) "
                        f"{', '.join(map(repr, missing))} are "
                        f"missing; the file has {', '.join(map(repr, tr.names))}",
                        hint="rename the columns to the model's names or pick another record")
    return model, tr.select(*cols)


@app.command()
def compare(model: Path = ModelArg,
            data: Path = typer.Argument(..., help="Data file with the model's input and "
                                                  "output columns.",
                                        show_default=False),
            fs: float = FsOpt, time: str = TimeOpt, fill: str = FillOpt, json_out: bool = JsonOpt):
    """Free-run fit (%) of a saved model per output, by the model's fit definition."""
    from ..sysid.model_file import file_sha256

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        m, tr = _model_and_data(model, data, fs, time, fill, outputs=True)
        fitted = m.compare(tr)
    fit = fitted.fit_percent
    data_hash = getattr(m, "data_hash", None)
    same = data_hash is not None and data_hash == file_sha256(data)
    res = {"model": str(model), "data": str(data), "structure": m.structure,
           "outputs": list(m.outputs),
           "fit_percent": fit, "definition": fitted.definition, "estimation_data": same,
           "warnings": report_warnings(caught)}
    if hasattr(m, "initial_state"):  # the linear families and NARX say how the run starts
        res["initial_state"] = m.initial_state
    if json_out:
        emit_json(res)
        return
    which = " (the estimation data)" if same else ""
    typer.echo(f"{m.structure} on {data}{which}: {fitted.definition}")
    for n, f in zip(m.outputs, fit):
        typer.echo(f"  {n}: " + ("diverged" if f is None else f"{f:.2f} %"))


def simulate_model_file(model: Path, data: Path | None, out: Path | None, fs, time, fill,
                        json_out: bool) -> None:
    """``gripkit simulate MODEL.json --data DATA``: the model's outputs for DATA's input columns
    (:func:`gripkit.sysid.simulated_trajectory`: by name, offsets applied, from rest); writes
    the time column and one column per output, each in the output's display unit (the unit the
    estimation data's file wrote it in, ``force [mN]``) where the model file records one, else
    in SI. A diverged free run (non-finite samples) gives null extremes in the JSON."""
    import numpy as np

    from ..errors import DataError
    from ..io import save
    from ..sysid.model_protocol import simulated_trajectory
    from ..units import convert

    if data is None:
        raise DataError(f"simulate {str(model)!r}: a model file needs input data: --data DATA",
                        hint="give a record with the model's input columns")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        m, tr = _model_and_data(model, data, fs, time, fill, outputs=False)
        sim = simulated_trajectory(m, tr)
    sim.meta.update(model=str(model), data=str(data))
    units, shown = dict(sim.units), sim.meta["display_units"]
    ys = sim.as_array(*m.outputs)
    if out is not None:
        save(sim, out, units="display")
    ys = np.column_stack([convert(ys[:, i], units[n], shown[n]) if n in shown else ys[:, i]
                          for i, n in enumerate(m.outputs)])  # in the units the file shows
    units.update(shown)

    def extremes(y):
        finite = y[np.isfinite(y)]
        return {"min": float(finite.min()) if finite.size else None,
                "max": float(finite.max()) if finite.size else None,
                "final": float(y[-1]) if np.isfinite(y[-1]) else None}

    res = {"model": str(model), "data": str(data), "samples": sim.n,
           "out": None if out is None else str(out),
           "outputs": {n: {"unit": sim.display_unit(n), "si_unit": sim.unit(n),
                           **extremes(ys[:, i])} for i, n in enumerate(m.outputs)},
           "warnings": report_warnings(caught)}
    if json_out:
        emit_json(res)
        return
    if out is None:
        import sys

        cols = ["t [s]"] + [f"{n} [{units[n]}]" if n in units else n for n in m.outputs]
        sys.stdout.write(",".join(cols) + "\n")
        np.savetxt(sys.stdout, np.column_stack([tr.t, ys]), delimiter=",", fmt="%.10g")
        return
    typer.echo(f"{m.structure}: {sim.n} samples simulated, written to {out}")
