"""``gripkit compare MODEL.json DATA [--json]``: free-run fit of a saved model on a record, per
output, with the initial state estimated by least squares; and ``gripkit simulate MODEL.json
--data DATA [--out FILE]`` (dispatched from :mod:`gripkit.cli.simulate`)."""

from __future__ import annotations

import warnings
from pathlib import Path

import typer

from .app import app
from .common import FillOpt, FsOpt, JsonOpt, TimeOpt, emit_json, is_mcap, load_data, report_warnings

ModelArg = typer.Argument(..., help="Model file written by identify --out (.json).", show_default=False)


def _model_and_data(model_path: Path, data: Path, fs, time, fill, outputs: bool):
    from ..sysid import load_model

    model = load_model(model_path)
    cols = list(model.inputs) + (list(model.outputs) if outputs else [])
    from ..io import load

    # an MCAP log is read by the model's channel names (the /topic:field specs it was fitted on)
    tr = load_data(data, cols, fs, time, fill) if is_mcap(data) else load(data, fs=fs, time=time, fill=fill)
    missing = [c for c in cols if c not in tr.names]
    if missing:
        from ..errors import DataError

        kind = "input" if any(c in model.inputs for c in missing) else "output"
        raise DataError(f"data {str(data)!r}: the model's {kind} column(s) {', '.join(map(repr, missing))} are "
                        f"missing; the file has {', '.join(map(repr, tr.names))}",
                        hint="rename the columns to the model's names or pick another record")
    return model, tr.select(*cols)


@app.command()
def compare(model: Path = ModelArg,
            data: Path = typer.Argument(..., help="Data file with the model's input and output columns.",
                                        show_default=False),
            fs: float = FsOpt, time: str = TimeOpt, fill: str = FillOpt, json_out: bool = JsonOpt):
    """Free-run fit (%) of a saved model per output, initial state estimated."""
    from ..sysid.linear.linear_model import VALIDATION_FIT
    from ..sysid.nonlinear.narx import SCHEMA, file_schema

    if file_schema(model) == SCHEMA:
        return _compare_narx(model, data, fs, time, fill, json_out)
    if _other_family(model):
        return _compare_protocol(model, data, fs, time, fill, json_out)
    from ..sysid.model_file import file_sha256

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        m, tr = _model_and_data(model, data, fs, time, fill, outputs=True)
        fit, _ = m.compare_data(tr)
    same = m.data_hash is not None and m.data_hash == file_sha256(data)
    res = {"model": str(model), "data": str(data), "structure": m.structure, "outputs": list(m.outputs),
           "fit_percent": fit, "initial_state": "estimated", "definition": VALIDATION_FIT,
           "estimation_data": same, "warnings": report_warnings(caught)}
    if json_out:
        emit_json(res)
        return
    typer.echo(f"{m.structure} on {data}{' (the estimation data)' if same else ''}: {VALIDATION_FIT}")
    for n, f in zip(m.outputs, fit):
        typer.echo(f"  {n}: {f:.2f} %")


def _other_family(model: Path) -> bool:
    """A model file of a family other than the linear and NARX ones (which have their own
    branches): it is compared and simulated through the model protocol alone."""
    from ..sysid.model_protocol import MODEL_FILES, file_schema

    return file_schema(model) in set(MODEL_FILES) - {"gripkit.linear-model", "gripkit.narx-model"}


def _compare_protocol(model: Path, data: Path, fs, time, fill, json_out: bool) -> None:
    """``gripkit compare`` of any model that :func:`~gripkit.sysid.load_model` reads other than
    the linear and NARX ones: ``m.compare(record)``, the fit by ``m.fit_definition``."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        m, tr = _model_and_data(model, data, fs, time, fill, outputs=True)
        fit = m.compare(tr)
    res = {"model": str(model), "data": str(data), "structure": m.structure,
           "outputs": list(m.outputs), "fit_percent": list(fit.fit_percent),
           "definition": fit.definition, "warnings": report_warnings(caught)}
    if json_out:
        emit_json(res)
        return
    typer.echo(f"{m.structure} on {data}: {fit.definition}")
    for n, f in zip(m.outputs, fit.fit_percent):
        typer.echo(f"  {n}: " + ("diverged" if f is None else f"{f:.2f} %"))


def _simulate_protocol(model: Path, data: Path, out: Path | None, fs, time, fill,
                       json_out: bool) -> None:
    """``gripkit simulate`` of any model that :func:`~gripkit.sysid.load_model` reads other than
    the linear and NARX ones: ``m.simulate(record)``, written as CSV on stdout or to ``--out``."""
    import sys

    import numpy as np

    from ..io import save
    from ..signals.trajectory import Trajectory

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        m, tr = _model_and_data(model, data, fs, time, fill, outputs=False)
        ys = np.asarray(m.simulate(tr), dtype=np.float64).reshape(tr.n, len(m.outputs))
    sim = Trajectory(tr.t, {n: ys[:, i] for i, n in enumerate(m.outputs)})
    if out is not None:
        save(sim, out)

    def stat(v, f):
        v = v[np.isfinite(v)]
        return float(f(v)) if v.size else None

    res = {"model": str(model), "data": str(data), "samples": sim.n,
           "out": None if out is None else str(out),
           "outputs": {n: {"min": stat(ys[:, i], np.min), "max": stat(ys[:, i], np.max),
                           "final": float(ys[-1, i]) if np.isfinite(ys[-1, i]) else None}
                       for i, n in enumerate(m.outputs)},
           "warnings": report_warnings(caught)}
    if json_out:
        emit_json(res)
    elif out is None:
        sys.stdout.write(",".join(["t [s]", *m.outputs]) + "\n")
        np.savetxt(sys.stdout, np.column_stack([tr.t, ys]), delimiter=",", fmt="%.10g")
    else:
        typer.echo(f"{m.structure}: {sim.n} samples simulated, written to {out}")


def _compare_narx(model: Path, data: Path, fs, time, fill, json_out: bool) -> None:
    """``gripkit compare`` of a NARX model file: its free-run fit on DATA's columns (the number
    ``gripkit identify narx --validate`` reports)."""
    import numpy as np

    from ..sysid.nonlinear.narx import NARX_FIT, load_narx

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        m = load_narx(model)
        tr = load_data(data, [m.input_name, m.output_name], fs, time, fill)
        fit = m.compare(np.asarray(tr[m.input_name]), np.asarray(tr[m.output_name]))
    res = {"model": str(model), "data": str(data), "structure": "narx", "outputs": [m.output_name],
           "fit_percent": [fit], "initial_state": "measured", "definition": NARX_FIT,
           "warnings": report_warnings(caught)}
    if json_out:
        emit_json(res)
        return
    typer.echo(f"narx on {data}: {NARX_FIT}")
    typer.echo(f"  {m.output_name}: " + ("diverged" if fit is None else f"{fit:.2f} %"))


def _simulate_narx(model: Path, data: Path, out: Path | None, fs, time, fill, json_out: bool) -> None:
    """``gripkit simulate`` of a NARX model file: its free run on DATA's input column, from rest
    (the first max_lag outputs zero), written as CSV on stdout or to ``--out``."""
    import sys

    import numpy as np

    from ..io import save
    from ..signals.trajectory import Trajectory
    from ..sysid.nonlinear.narx import load_narx

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        m = load_narx(model)
        tr = load_data(data, [m.input_name], fs, time, fill)
        y = m.simulate(np.asarray(tr[m.input_name]))
    sim = Trajectory(tr.t, {m.output_name: y})
    if out is not None:
        save(sim, out)
    finite = y[np.isfinite(y)]
    res = {"model": str(model), "data": str(data), "samples": sim.n, "out": None if out is None else str(out),
           "outputs": {m.output_name: {"min": float(finite.min()) if finite.size else None,
                                       "max": float(finite.max()) if finite.size else None,
                                       "final": float(y[-1]) if np.isfinite(y[-1]) else None}},
           "warnings": report_warnings(caught)}
    if json_out:
        emit_json(res)
    elif out is None:
        sys.stdout.write(f"t [s],{m.output_name}\n")
        np.savetxt(sys.stdout, np.column_stack([tr.t, y]), delimiter=",", fmt="%.10g")
    else:
        typer.echo(f"narx: {sim.n} samples simulated, written to {out}")


def simulate_model_file(model: Path, data: Path | None, out: Path | None, fs, time, fill, json_out: bool) -> None:
    """``gripkit simulate MODEL.json --data DATA``: the model's outputs for DATA's input columns
    (by name, offsets applied, from rest); writes the time column and one column per output, each
    in the output's display unit (the unit the estimation data's file wrote it in, ``force [mN]``)
    where the model file records one, else in SI."""
    import numpy as np

    from ..errors import DataError
    from ..io import save
    from ..units import convert

    if data is None:
        raise DataError(f"simulate {str(model)!r}: a model file needs input data: --data DATA",
                        hint="give a record with the model's input columns")
    from ..sysid.nonlinear.narx import SCHEMA, file_schema

    if file_schema(model) == SCHEMA:
        return _simulate_narx(model, data, out, fs, time, fill, json_out)
    if _other_family(model):
        return _simulate_protocol(model, data, out, fs, time, fill, json_out)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        m, tr = _model_and_data(model, data, fs, time, fill, outputs=False)
        sim = m.simulate_trajectory(tr)
    sim.meta.update(model=str(model), data=str(data))
    units, shown = dict(sim.units), sim.meta["display_units"]
    ys = sim.as_array(*m.outputs)
    if out is not None:
        save(sim, out, units="display")
    ys = np.column_stack([convert(ys[:, i], units[n], shown[n]) if n in shown else ys[:, i]
                          for i, n in enumerate(m.outputs)])  # in the units the file shows
    units.update(shown)
    res = {"model": str(model), "data": str(data), "samples": sim.n, "out": None if out is None else str(out),
           "outputs": {n: {"unit": sim.display_unit(n), "si_unit": sim.unit(n),
                           "min": float(np.min(ys[:, i])), "max": float(np.max(ys[:, i])),
                           "final": float(ys[-1, i])} for i, n in enumerate(m.outputs)},
           "warnings": report_warnings(caught)}
    if json_out:
        emit_json(res)
        return
    if out is None:
        import sys

        import numpy as np

        cols = ["t [s]"] + [f"{n} [{units[n]}]" if n in units else n for n in m.outputs]
        sys.stdout.write(",".join(cols) + "\n")
        np.savetxt(sys.stdout, np.column_stack([tr.t, ys]), delimiter=",", fmt="%.10g")
        return
    typer.echo(f"{m.structure}: {sim.n} samples simulated, written to {out}")
