"""``gripkit identify modal|bouc-wen``: the identification procedures of the TSFM (§IV of
``001_0b92a7da96e7aa46.txt``) from a data file.

* ``gripkit identify modal DATA --signal COL [--fs HZ] [--json]``: natural frequency and damping
  ratio of a free vibration (Fig. 8); JSON keys ``natural_frequency_hz``, ``damping_ratio``,
  ``natural_frequency_std_hz``, ``damping_ratio_std`` and ``methods`` (each method's estimate).
* ``gripkit identify bouc-wen DATA --input COL --output COL [--json]``: static Bouc-Wen
  parameters from a quasi-static voltage (V) / displacement (m) sweep (Fig. 9); JSON ``params``
  and ``std``, each with ``d_p`` (m/V), ``lambda`` (m/V), ``beta`` (1/V), ``gamma`` (1/V), of
  y = d_p U − H, dH/dt = λ dU/dt − β|dU/dt|H − γ dU/dt|H|.

Warnings go to stderr as ``warning: ...`` lines and into the JSON ``warnings`` list.
"""

from __future__ import annotations

from pathlib import Path

import typer

from .app import identify_app
from .common import (FillOpt, FsOpt, JsonOpt, TimeOpt, check_data_options, check_number,
                     collected_warnings, emit_json, load_data, report_warnings)
from .identify_common import DataArg


@identify_app.command("modal")
def identify_modal(data: Path = DataArg,
                   signal: str = typer.Option(..., "--signal", help="Column holding the "
                                                                    "free vibration."),
                   fs: float = FsOpt, time: str = TimeOpt, fill: str = FillOpt,
                   start: float = typer.Option(None, "--start", help="Time (s) of the release "
                                                                     "(default: found)."),
                   json_out: bool = JsonOpt):
    """Natural frequency and damping ratio from a free vibration (FFT peak, half-power, log
    decrement, Hilbert envelope, damped-sine least squares)."""
    import math

    from ..errors import DataError
    from ..sysid.physical.modal import free_vibration

    check_data_options(fs, fill)
    if start is not None and not math.isfinite(start):
        raise DataError(f"--start: expected the release time in s (a finite number), found {start}")
    with collected_warnings() as caught:
        tr = load_data(data, [signal], fs, time, fill)
        dt = tr.require_uniform(why="free-vibration analysis")
        i0 = None if start is None else int(round((start - tr.t[0]) / dt))
        res = free_vibration(tr[signal], dt=dt, start=i0)
    out = res.to_dict()
    out.update(data=str(data), signal=signal, unit=tr.unit(signal),
               warnings=report_warnings(caught))
    if json_out:
        emit_json(out)
        return
    typer.echo(res.summary())


@identify_app.command("bouc-wen")
def identify_bouc_wen_cmd(data: Path = DataArg,
                          input: str = typer.Option(..., "--input", help="Voltage column (V)."),
                          output: str = typer.Option(..., "--output",
                                                     help="Displacement column (m)."),
                          fs: float = FsOpt, time: str = TimeOpt, fill: str = FillOpt,
                          delay: float = typer.Option(0.0, "--delay",
                                                      help="Lag (s) of the displacement "
                                                           "behind the static "
                                                           "hysteresis: b of D(s) plus "
                                                           "half a DAC sample."),
                          burn_in: int = typer.Option(0, "--burn-in", help="Samples left out of "
                                                                           "the fit (a record "
                                                                          "starting mid-loop)."),
                          json_out: bool = JsonOpt):
    """Static Bouc-Wen parameters (eq 3) from a quasi-static voltage/displacement sweep.
    The TSFM seed's step §IV-C1 (d_p, λ, β, γ of one sweep, --delay for the actuator's lag, no
    model file): use it to follow the seed's piezo procedure; for a hysteresis model to save,
    validate or simulate use identify hysteresis."""
    from ..sysid.physical.bouc_wen import identify_bouc_wen

    check_data_options(fs, fill)
    check_number(delay, "--delay", minimum=0)
    check_number(burn_in, "--burn-in", minimum=0, integer=True)
    with collected_warnings() as caught:
        tr = load_data(data, [input, output], fs, time, fill)
        res = (identify_bouc_wen(tr, input=input, output=output, delay=delay, burn_in=burn_in,
                                 progress=not json_out))
    out = res.to_dict()
    out.update(data=str(data), input=input, output=output, delay=delay,
               warnings=report_warnings(caught))
    if json_out:
        emit_json(out)
        return
    typer.echo(res.summary())
    typer.echo(f"  fit {res.fit.fit_percent[0]:.4g} % over {res.fit.n_samples} samples; "
               f"{res.fit.identifiability}")
