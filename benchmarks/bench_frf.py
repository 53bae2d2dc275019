"""Welch H1 frequency response of 10⁶ samples (4096-sample Hann segments, 50 % overlap) with its
σ and coherence: gripkit's ``frf`` beside the numpy route an expert would write (strided segment
view, window, rfft along the last axis, cross-spectra summed from real and imaginary parts) and
beside ``scipy.signal.csd``/``welch`` (H1 only). Issue 24 target: ≤ 1.1× the numpy route's time
(ratio peer/gripkit ≥ 0.91). All runs alternate, BLAS on one thread, median and min of 7."""

from __future__ import annotations

import numpy as np
from common import measure_alternating, row
from numpy.lib.stride_tricks import sliding_window_view

N = 1_000_000
L = 4096
INFLATION = 1.056  # Welch (1967) for Hann at 50 % overlap, as gripkit


def numpy_h1(u, y, nperseg=L, dt=0.001):
    """SISO Welch H1, σ and coherence in plain numpy: segments as a strided view, one windowed
    copy each, rfft along the last axis, spectra as sums over segments."""
    step = nperseg // 2
    win = np.hanning(nperseg + 1)[:-1]
    U = np.fft.rfft(sliding_window_view(u, nperseg)[::step] * win, axis=-1)
    Y = np.fft.rfft(sliding_window_view(y, nperseg)[::step] * win, axis=-1)
    K = U.shape[0]
    Ur, Ui, Yr, Yi = U.real, U.imag, Y.real, Y.imag
    Suu = np.einsum("kf,kf->f", Ur, Ur) + np.einsum("kf,kf->f", Ui, Ui)
    Syy = np.einsum("kf,kf->f", Yr, Yr) + np.einsum("kf,kf->f", Yi, Yi)
    Syu = (np.einsum("kf,kf->f", Yr, Ur) + np.einsum("kf,kf->f", Yi, Ui)
           + 1j * (np.einsum("kf,kf->f", Yi, Ur) - np.einsum("kf,kf->f", Yr, Ui)))
    H = Syu / Suu
    fit = (Syu.real ** 2 + Syu.imag ** 2) / Suu
    coh = np.clip(fit / Syy, 0.0, 1.0)
    std = np.sqrt(INFLATION * np.maximum(Syy - fit, 0.0) / Suu / (K - 1))
    return np.fft.rfftfreq(nperseg, dt), H, std, coh


def run(quick: bool) -> list[dict]:
    """gripkit frf against the numpy route and scipy; ``quick`` changes nothing."""
    from scipy import signal

    from gripkit.sysid import frf

    rng = np.random.default_rng(3)
    u = rng.standard_normal(N)
    y = signal.lfilter([0.2, 0.1], [1.0, -1.2, 0.5], u) + 0.1 * rng.standard_normal(N)
    r = frf(u, y, dt=0.001, nperseg=L)
    f, H, std, coh = numpy_h1(u, y)
    Hg = r.H[:, 0, 0]
    acc = (f"max |H − H_numpy|/|H| = {np.max(np.abs(Hg - H) / np.abs(H)):.1e}, "
           f"max |σ/σ_numpy − 1| = {np.max(np.abs(r.H_std[:, 0, 0] / std - 1)):.1e}, "
           f"max |coh − coh_numpy| = {np.max(np.abs(r.coherence[:, 0] - coh)):.1e}")

    def scipy_h1():
        _, pyu = signal.csd(u, y, fs=1000.0, nperseg=L)
        _, puu = signal.welch(u, fs=1000.0, nperseg=L)
        return pyu / puu
    t_g, t_np, t_sp = measure_alternating(
        [lambda: frf(u, y, dt=0.001, nperseg=L), lambda: numpy_h1(u, y), scipy_h1])
    lab = "FRF (Welch H1 with σ and coherence), 1e6 samples, 4096-sample Hann segments"
    return [row("frf", lab, t_g, "numpy strided rfft route (H1, σ, coherence)", t_np,
                target="≤ 1.1× the numpy route", gripkit_accuracy=acc,
                notes="frf(): checks, MIMO-general spectra, no-power lines, result object"),
            row("frf", lab, t_g, "scipy.signal csd/welch", t_sp, target="—",
                notes="scipy gives H1 only (no σ, no coherence)")]


if __name__ == "__main__":
    import json

    for r in run(quick=True):
        print(json.dumps(r, default=str))
