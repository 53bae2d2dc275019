"""Issue 26's speed target for the nonlinear state-space family: ``nlss`` on 40 000 samples in
under 60 s on the 2-core machine (wall clock, progress bar off), with the fit it reaches.

Rows (each one fit after a small warm-up fit that compiles the kernels; wall and CPU seconds and
the load average at the start are recorded, the machine being shared):

- the discrete Duffing oscillator of ``tests/sysid/test_nlss.py`` (40 000 samples, 1 % output
  noise, default options: orders 2 and 3 fitted, 2 kept by BIC), as its slow test;
- the Silverbox record (nonlinearbenchmark.org, ``SNLS80mV.csv``, 131 072 samples; not in the
  repository, only two 8192-sample cuts are: give its path in ``GRIPKIT_SILVERBOX_CSV``): its
  samples [40960, 81920) of the multisine part to estimate, ``order=4`` (239 parameters) and the
  default options with ``tests/fixtures/silverbox/silverbox_val.csv`` as the validation record,
  whose free-run fit is reported. Skipped, and said so, without the file.

``python benchmarks/bench_nlss.py`` prints the rows; ``run.py --only nlss`` records them.
"""

from __future__ import annotations

import hashlib
import os
import time
from pathlib import Path

import numpy as np
from common import row

HERE = Path(__file__).resolve().parent
VALIDATION = HERE.parent / "tests" / "fixtures" / "silverbox" / "silverbox_val.csv"
#: sha256 of the official SNLS80mV.csv (tests/fixtures/silverbox/README.md)
SILVERBOX_SHA256 = "ae62d5a91230c10f76e6dd02c8a4fac3c9d4d8a95fbf50e87cb0c4885003e0f1"
FS = 1e7 / 2 ** 14
TARGET = "< 60 s wall on 40 000 samples (issue 26)"


def _duffing(u):
    """tests/sysid/test_nlss.py's discrete Duffing oscillator (order 2, degree 3)."""
    x = v = 0.0
    y = np.empty(len(u))
    for t in range(len(u)):
        y[t] = x
        v = v + 0.2 * (-x - 0.3 * v - 2.0 * x ** 3 + u[t])
        x = x + 0.2 * v
    return y


def _timed(fit):
    """(model, wall s, CPU s, load average at the start) of one call."""
    load = os.getloadavg()[0]
    t, c = time.perf_counter(), time.process_time()
    model = fit()
    return model, time.perf_counter() - t, time.process_time() - c, load


def _silverbox():
    """(u, y) of samples [40960, 81920) of SNLS80mV.csv and the validation cut, or None."""
    path = os.environ.get("GRIPKIT_SILVERBOX_CSV")
    if not path or not Path(path).is_file():
        return None
    if hashlib.sha256(Path(path).read_bytes()).hexdigest() != SILVERBOX_SHA256:
        raise SystemExit(f"{path}: not the official SNLS80mV.csv (sha256 differs)")
    d = np.loadtxt(path, delimiter=",", skiprows=1, usecols=(0, 1))[40960:81920]
    v = np.loadtxt(VALIDATION, delimiter=",", skiprows=1)
    return (d[:, 0], d[:, 1]), (v[:, 0], v[:, 1])


def run(quick: bool) -> list[dict]:
    """One row per fit; ``quick``: the Duffing record only, 10 000 samples."""
    from gripkit.sysid import nlss

    from scipy.signal import lfilter

    rng = np.random.default_rng(1)  # the record of the test's slow case
    u = lfilter([0.3], [1.0, -0.7], rng.normal(0.0, 1.0, 10_000 if quick else 40_000))
    y0 = _duffing(u)
    y = y0 + rng.normal(0.0, 0.01 * y0.std(), u.size)
    nlss((u[:600], y[:600]), order=2, progress=False)  # compiles the kernels
    rows = []

    def add(task, fit, notes=""):
        m, wall, cpu, load = _timed(fit)
        val = m.validation_fit_percent
        acc = (f"order {m.order}, fit {m.fit_percent[0]:.2f} %"
               + ("" if val is None else ", validation "
                  + ("diverged" if val[0] is None else f"{val[0]:.2f} %"))
               + f", iterations {m.info['iterations_windows']} + {m.info['iterations_whole']}")
        rows.append(row("nlss", task, wall, "", None, target=TARGET, gripkit_accuracy=acc,
                        notes=f"CPU {cpu:.1f} s, load average {load:.1f} at the start; {notes}",
                        extra={"cpu_s": cpu, "load": load, "order": m.order,
                               "fit_percent": m.fit_percent, "validation_fit_percent": val,
                               "info": {k: v for k, v in m.info.items()
                                        if isinstance(v, (int, float, str, bool))}}))

    add(f"Duffing oscillator, N={u.size}, default options (orders 2, 3; BIC)",
        lambda: nlss((u, y), progress=False), "1 % output noise (fit limit ≈ 99.0 %)")
    sb = None if quick else _silverbox()
    if sb is None:
        rows.append(row("nlss", "Silverbox N=40960", None, "", None, target=TARGET,
                        notes="not run: set GRIPKIT_SILVERBOX_CSV to SNLS80mV.csv"
                        + (" (quick run)" if quick else "")))
        return rows
    (ue, ye), (uv, yv) = sb
    add("Silverbox N=40960, order=4 (239 parameters), validation record",
        lambda: nlss((ue, ye), order=4, dt=1 / FS, validate=(uv, yv), progress=False))
    add("Silverbox N=40960, default options, validation record (orders 1-3)",
        lambda: nlss((ue, ye), dt=1 / FS, validate=(uv, yv), progress=False))
    return rows


if __name__ == "__main__":
    for r in run(quick=False):
        t = "-" if r["gripkit_s"] is None else f"{r['gripkit_s']:.1f} s"
        print(f"| {r['task']} | {t} | {r['gripkit_accuracy']} | {r['notes']} |")
