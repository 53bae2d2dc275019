"""Subspace identification, PEM refinement and FRF estimation: gripkit beside SIPPY
(sippy_unipi) and nfoursid, on the same data, in the same run.

Problem: a 2-input 2-output discrete system of order 8 (four pole pairs, |z| = 0.95, 0.9, 0.8,
0.7, in a random basis), N = 10⁵ samples of white inputs, 10 % white output noise; a second record
for validation. Every tool gets order 8 and the same horizon (past = future = k = 9 block rows,
gripkit's default for order 8 and two outputs).

Fairness notes (also in each row):

* gripkit ``n4sid(u, y, 8, horizon=9)`` is the full user call: checks, scaling, factorisation, A and
  C, B and x0 by least squares, Kalman gain, free-run fit.
* SIPPY: ``system_identification(y.T, u.T, 'N4SID' | 'MOESP', SS_fixed_order=8, SS_f=9, SS_p=9)``.
* nfoursid 1.0.2: ``NFourSID(df, output_columns, input_columns, num_block_rows=9)``,
  ``subspace_identification()``, ``system_identification(rank=8)`` (its documented use; a pandas
  DataFrame is its input format, built outside the timing). Its ``system_identification`` takes a
  full SVD (``np.linalg.svd``, ``full_matrices=True``) of a p·k × (N − k + 1) matrix, whose
  right factor alone is (N − k + 1)² float64: 74.5 GiB at N = 10⁵. It is called at N = 10⁵ only
  when that fits in
  half the available memory (else the row says so, with the figures); a second pair of rows
  compares gripkit and nfoursid at N = 10⁴ (0.75 GiB), where nfoursid runs.
* Both sides of every row go through ``common.measure`` (same warm-up call and number of runs,
  median and min); accuracy beside the time is the free-run validation fit.
* Validation fit: free run on the second record with the initial state estimated by least squares
  (the same :meth:`LinearModel.compare` for every model), mean over the two outputs.
* PEM: ``pem(model, u, y, form)`` from the subspace model, innovation and output-error forms.
* FRF: ``frf`` (Welch H1, 4096-sample Hann segments, σ and coherence) of 10⁶ samples beside
  ``scipy.signal.csd``/``welch`` (H1 only, no σ).
"""

from __future__ import annotations

import contextlib
import io
import warnings
from pathlib import Path

import numpy as np
from common import measure, row

N_FULL = 100_000
N_SMALL = 10_000
ORDER = 8
HORIZON = 9
TARGET = "≥ 5× faster at equal or better validation fit"


def _system():
    from gripkit.lti import StateSpace

    rng = np.random.default_rng(2)
    poles = ([0.95 * np.exp(1j * 0.1), 0.9 * np.exp(1j * 0.4), 0.8 * np.exp(1j * 0.9),
              0.7 * np.exp(1j * 1.8)])
    A = np.zeros((8, 8))
    for i, z in enumerate(poles):
        A[2 * i:2 * i + 2, 2 * i:2 * i + 2] = [[z.real, z.imag], [-z.imag, z.real]]
    T = rng.standard_normal((8, 8))
    return (StateSpace(T @ A @ np.linalg.inv(T), rng.standard_normal((8, 2)),
                       rng.standard_normal((2, 8)), dt=1.0))


def _record(g, n, seed):
    rng = np.random.default_rng(seed)
    u = rng.standard_normal((n, 2))
    y0 = g.simulate(u)
    return u, y0 + 0.1 * y0.std(axis=0) * rng.standard_normal(y0.shape)


def _val_fit(A, B, C, D, uv, yv):
    from gripkit.lti import StateSpace
    from gripkit.sysid.linear.linear_model import LinearModel

    m = LinearModel(StateSpace(A, B, C, D, dt=1.0), "peer")
    if not m.stable:
        return None
    return float(np.mean(m.compare(uv, yv).fit_percent))


def _fit_text(fit):
    return "unstable model" if fit is None else f"validation fit {fit:.2f} %"


def _available_bytes() -> float:
    with contextlib.suppress(OSError, ValueError, IndexError):
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return float(line.split()[1]) * 1024.0
    return 0.0  # unknown: do not attempt a huge allocation


def _nfoursid(u, y):
    """nfoursid's documented call; returns a function that identifies order 8 and the model's
    (A, B, C, D)."""
    import pandas as pd
    from nfoursid.nfoursid import NFourSID

    df = pd.DataFrame(np.hstack([u, y]), columns=["u0", "u1", "y0", "y1"])

    def call():
        nf = (NFourSID(df, output_columns=["y0", "y1"], input_columns=["u0", "u1"],
                       num_block_rows=HORIZON))
        nf.subspace_identification()
        ss, _ = nf.system_identification(rank=ORDER)
        return ss.a, ss.b, ss.c, ss.d
    return call


def _gripkit_n4sid(u, y, method="n4sid"):
    from gripkit.sysid import n4sid

    return lambda: n4sid(u, y, ORDER, method=method, horizon=HORIZON)


def _abcd(model):
    s = model.system
    return s.A, s.B, s.C, s.D


def _nfoursid_rows(g, uv, yv, u, y, ours, model) -> list[dict]:
    """nfoursid beside gripkit at N = 1e5 (when its N² SVD fits in memory) and at N = 1e4."""
    try:
        import nfoursid  # noqa: F401
    except ImportError:  # pragma: no cover - in the lock file and the bench extra
        return [row("subspace", "n4sid 2×2, N=1e5, order 8", ours, "nfoursid", None,
                    notes="nfoursid not installed: not timed")]
    rows = []
    need = 8.0 * (u.shape[0] - HORIZON + 1) ** 2
    avail = _available_bytes()
    g_fit = _val_fit(*_abcd(model), uv, yv)
    task = "n4sid 2×2, N=1e5, order 8 (median)"
    if need <= 0.5 * avail:  # pragma: no cover - needs ~150 GiB of free memory
        t = measure(_nfoursid(u, y))
        fit = _val_fit(*_nfoursid(u, y)(), uv, yv)
        rows.append(row("subspace", task, ours, "nfoursid", t, target=TARGET,
                        gripkit_accuracy=_fit_text(g_fit),
                        peer_accuracy=_fit_text(fit), notes="same order and horizon; free "
                                                            "run, x0 estimated"))
    else:
        rows.append(row("subspace", task, ours, "nfoursid", None, target=TARGET,
                        gripkit_accuracy=_fit_text(g_fit),
                        notes="nfoursid not run at N=1e5: its system_identification "
                              "takes a full SVD "
                              "(np.linalg.svd, full_matrices=True) whose right factor needs "
                              f"{need / 2**30:.1f} GiB; "
                              f"{avail / 2**30:.1f} GiB available (MemoryError). "
                              "See the N=1e4 row."))
    us, ys = _record(g, N_SMALL, 1)
    t_g = measure(_gripkit_n4sid(us, ys))
    t_p = measure(_nfoursid(us, ys))
    rows.append(row("subspace", "n4sid 2×2, N=1e4, "
                                "order 8 (median)", t_g, "nfoursid", t_p, target=TARGET,
                    gripkit_accuracy=_fit_text(_val_fit(*_abcd(_gripkit_n4sid(us, ys)()), uv, yv)),
                    peer_accuracy=_fit_text(_val_fit(*_nfoursid(us, ys)(), uv, yv)),
                    notes="same order and horizon; free run on the N=2e4 validation "
                          "record, x0 estimated; "
                          "nfoursid's time is mostly its N×N SVD factor (0.75 GiB)"))
    return rows


def _scaling_rows(g, quick: bool) -> list[dict]:
    """N4SID 2×2 order 8 at N = 1e4, 1e5 and 1e6 (issue 24: linear in N): the time per 10⁴
    samples of each size beside that of N = 1e4 (the peer column; ratio ≈ 1 means linear).
    ``quick``: 1e4 and 1e5 only."""
    sizes = (10_000, 100_000) if quick else (10_000, 100_000, 1_000_000)
    per = {}
    for n in sizes:
        u, y = _record(g, n, 1)
        per[n] = measure(_gripkit_n4sid(u, y), budget_s=30.0)
        del u, y
    unit = {n: per[n] * (1e4 / n) for n in sizes}
    return [row("subspace", f"n4sid 2×2, order 8, N={n:.0e}, time per 1e4 samples", unit[n],
                "the same at N=1e4", unit[sizes[0]],
                target="linear in N from 1e4 to 1e6 (ratio ≈ 1)",
                notes=f"whole call {float(per[n]):.3g} s (min {per[n].min:.3g} s, "
                      f"{per[n].runs} runs); N=1e4: {float(per[sizes[0]]) * 1e3:.3g} ms")
            for n in sizes[1:]]


def run(quick: bool) -> list[dict]:
    """All rows; ``quick`` changes nothing (the problem sizes are the issue's targets) except
    the scaling rows (:func:`_scaling_rows`)."""
    from gripkit.sysid import frf, pem

    g = _system()
    u, y = _record(g, N_FULL, 1)
    uv, yv = _record(g, 20_000, 2)
    rows = []
    ours = {}
    for method in ("n4sid", "moesp"):
        call = _gripkit_n4sid(u, y, method)
        ours[method] = (measure(call), call())
    try:
        import sippy_unipi as sippy
    except ImportError:  # pragma: no cover - in the lock file and the bench extra
        sippy = None
    for method, sip in (("n4sid", "N4SID"), ("moesp", "MOESP")):
        t, model = ours[method]
        g_fit = _val_fit(*_abcd(model), uv, yv)
        task = f"{method} 2×2, N=1e5, order 8 (median)"
        if sippy is None:  # pragma: no cover
            rows.append(row("subspace", task, t, f"sippy_unipi {sip}", None,
                            notes="sippy_unipi not installed"))
            continue

        def call():
            with contextlib.redirect_stdout(io.StringIO()), warnings.catch_warnings():
                warnings.simplefilter("ignore")
                sm = (sippy.system_identification(y.T, u.T, sip, SS_fixed_order=ORDER, SS_f=HORIZON,
                                                  SS_p=HORIZON))
            return np.asarray(sm.A), np.asarray(sm.B), np.asarray(sm.C), np.asarray(sm.D)
        t_p = measure(call)
        rows.append(row("subspace", task, t, f"sippy_unipi {sip}", t_p, target=TARGET,
                        gripkit_accuracy=_fit_text(g_fit),
                        peer_accuracy=_fit_text(_val_fit(*call(), uv, yv)),
                        notes="same order and horizon; validation = free run, x0 estimated"))
    rows += _nfoursid_rows(g, uv, yv, u, y, *ours["n4sid"])
    rows += _scaling_rows(g, quick)
    start = ours["n4sid"][1]
    for form in ("innovation", "oe"):
        call = lambda: pem(start, u=u, y=y, form=form)  # noqa: E731
        t = measure(call)
        r = call()
        rows.append(row("subspace", f"PEM refinement ({form}) of the "
                                    "order-8 model, N=1e5", t, "", None,
                        target="< 2 s", gripkit_accuracy=_fit_text(_val_fit(*_abcd(r), uv, yv)),
                        notes="from the N4SID model; exact sensitivity Jacobians",
                        extra={"iterations": r.info["pem"]["iterations"]}))
    # FRF of 1e6 samples
    from scipy import signal

    rng = np.random.default_rng(3)
    uf = rng.standard_normal(1_000_000)
    yf = signal.lfilter([0.2, 0.1], [1.0, -1.2, 0.5], uf) + 0.1 * rng.standard_normal(uf.size)
    t = measure(lambda: frf(uf, yf, dt=0.001, nperseg=4096))

    def scipy_h1():
        f, pyu = signal.csd(uf, yf, fs=1000.0, nperseg=4096)
        _, puu = signal.welch(uf, fs=1000.0, nperseg=4096)
        return pyu / puu
    rows.append(row("subspace", "FRF (Welch H1 with σ and "
                                "coherence) of 1e6 samples", t, "scipy.signal csd/welch",
                    measure(scipy_h1), target="< 0.5 s", notes="scipy gives H1 only (no "
                                                               "σ, no coherence)"))
    return rows


if __name__ == "__main__":
    import json

    for r in run(quick=True):
        print(json.dumps(r, default=str))
