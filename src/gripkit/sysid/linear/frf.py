"""Frequency-response estimation, every line with its one-sigma σ (of the complex H:
``σ² = E|Ĥ − H|²``).

* **Periodic excitation** (``method='periodic'``, P periods of L samples; the first dropped as
  transient unless ``keep_transient``): DFT of each period, means Ū(k), Ȳ(k) over the P' kept
  periods, ``Ĥ = Ȳ/Ū`` on the excited lines, and the noise from the period-to-period spread
  (Pintelon & Schoukens, *System Identification: A Frequency Domain Approach*, 2nd ed., §2.5)::

      σ²_Y = Σ|Y_p − Ȳ|² / (P'(P' − 1)),  σ²_U, σ_YU likewise,
      σ²_Ĥ = |Ĥ|² (σ²_Y/|Ȳ|² + σ²_U/|Ū|² − 2 Re(σ_YU/(Ȳ Ū*))).

* **Arbitrary excitation, Welch H1** (``method='h1'``): K Hann-windowed segments with 50 %
  overlap, ``Ĥ = S_yu S_uu⁻¹`` (MIMO: m inputs at once), multiple coherence
  ``γ²_i = Ĥ_i S_uu Ĥ_iᴴ / S_yy,ii`` and ``σ²(Ĥ_ij) = c S_vv,i [S_uu⁻¹]_jj / (K − m)`` with
  ``S_vv,i = S_yy,ii − Ĥ_i S_uu Ĥ_iᴴ`` the residual power (SISO: ``σ² = |Ĥ|²(1 − γ²)/((K − 1)γ²)``,
  Bendat & Piersol, *Random Data*, eq 9.90) and c = 1.056 the variance inflation of 50 %-overlapped
  Hann segments (Welch 1967).
* **Smoothed ETFE / SPA** (``method='spa'``, SISO; Ljung, *System Identification*, 2nd ed., §6.4):
  covariances ``R̂_yu(τ)``, ``R̂_u(τ)`` with a Hann lag window of width M,
  ``Ĝ = Φ̂_yu/Φ̂_u`` and ``σ² = (Σ_τ W_M²(τ)/N) Φ̂_v/Φ̂_u`` (Ljung eq 6.64).

A line whose input carries no power cannot give H: its σ is infinite and a warning says which
lines (:class:`~gripkit.errors.AccuracyWarning`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from ...errors import AccuracyWarning, ArgumentError, DataError, emit_warning
from ...units import ratio_unit
from ..checks import check_columns_vary, check_dt
from .linear_model import as_io_matrix

__all__ = ["FRF", "frf", "FRF_METHODS"]

FRF_METHODS = ("periodic", "h1", "spa", "etfe")
_HANN_OVERLAP_INFLATION = 1.056  # Welch (1967): 1 + 2ρ², ρ = 0.167 for Hann at 50 % overlap
_NO_POWER = 1e-10                 # a line with less than this fraction of the peak input power


@dataclass(frozen=True, eq=False)
class FRF:
    """An estimated frequency response.

    Attributes
    ----------
    frequency_hz
        Lines (Hz), shape (F,).
    H
        Complex response (F, p, m); NaN where a line has no excitation.
    H_std
        One-sigma of the complex H per line (F, p, m); inf where a line has no excitation.
    coherence
        Multiple coherence per output (F, p) (H1, SPA), or None (periodic).
    input_units, output_units
        The channels' units ('' where unknown: arrays given without them); H is in output unit
        per input unit (:attr:`H_units`), σ too.
    """

    frequency_hz: np.ndarray
    H: np.ndarray
    H_std: np.ndarray
    coherence: np.ndarray | None
    method: str
    inputs: tuple[str, ...] = ("u",)
    outputs: tuple[str, ...] = ("y",)
    info: dict = field(default_factory=dict)
    input_units: tuple[str, ...] = ()
    output_units: tuple[str, ...] = ()

    @property
    def w(self) -> np.ndarray:
        return 2 * np.pi * self.frequency_hz

    @property
    def H_units(self) -> list[list[str]]:
        """The unit of each H[:, i, j]: output i's unit per input j's ('m/V'); '' where either
        is unknown."""
        m, p = len(self.inputs), len(self.outputs)
        ins = self.input_units if len(self.input_units) == m else ("",) * m
        outs = self.output_units if len(self.output_units) == p else ("",) * p
        return [[ratio_unit(o or "1", i or "1") if (o and i) else "" for i in ins] for o in outs]

    def __repr__(self) -> str:
        f = self.frequency_hz
        band = f" {f[0]:.4g} … {f[-1]:.4g} Hz" if f.size else ""
        units = {u for row in self.H_units for u in row}
        shown = (f", H in {units.pop()}" if len(units) == 1 and "" not in units else
                 f", H in {self.H_units}" if units - {""} else "")
        return (f"FRF({self.method}: {f.size} lines{band}, {list(self.inputs)} → "
                f"{list(self.outputs)}{shown})")

    def to_dict(self) -> dict:
        """JSON fields: ``frequency_hz``, ``H_real``, ``H_imag``, ``H_std`` and ``coherence``;
        (F,) lists for SISO, else (F, p, m) / (F, p) nested lists."""
        siso = self.H.shape[1:] == (1, 1)
        sq = (lambda a: a[:, 0, 0]) if siso else (lambda a: a)
        out = {"method": self.method, "inputs": list(self.inputs), "outputs": list(self.outputs),
               "H_unit": self.H_units[0][0] if siso else self.H_units,
               "frequency_hz": self.frequency_hz, "H_real": sq(self.H.real),
               "H_imag": sq(self.H.imag),
               "H_std": sq(self.H_std)}
        if self.coherence is not None:
            out["coherence"] = self.coherence[:, 0] if siso else self.coherence
        out["info"] = self.info
        return out


def _no_power_warning(f, bad, what):
    if bad.any():
        lines = ", ".join(f"{x:.4g}" for x in f[bad][:5]) + (" …" if bad.sum() > 5 else "")
        emit_warning(f"frf: {int(bad.sum())} line(s) have no {what} power ({lines} Hz): H is "
                     "undefined there "
                     f"and its σ is infinite", AccuracyWarning)


def _periodic(u, y, dt, periods, keep_transient):
    N, m = u.shape
    p = y.shape[1]
    P = int(periods)
    if P < 2 or N % P:
        raise DataError(f"periods: {N} samples do not split into {P} whole periods" if P >= 2 else
                        f"periods: expected an integer >= 2, found {periods!r}",
                        hint="give the number of periods the record holds (N must be a "
                             "multiple of it)")
    L = N // P
    U = u.reshape(P, L, m)
    span = float(np.max(np.abs(u - u.mean(axis=0)))) or 1.0
    dev = np.max(np.abs(U - U[-1:]), axis=(1, 2)) / span
    if np.max(dev) > 1e-3:
        i = int(np.argmax(dev))
        raise DataError(f"periods: the input is not periodic with {P} periods of {L} samples "
                        f"(period {i + 1} differs "
                        f"from the last by {100 * dev[i]:.3g} % of the input range)",
                        hint="check --periods, or use a method for arbitrary excitation (h1, spa)")
    if m != 1:
        raise DataError("periods: periodic FRF estimation takes one input per "
                        f"experiment, found {m}",
                        hint="use the h1 method for several simultaneous inputs")
    first = 0 if keep_transient else 1
    if P - first < 2:
        raise DataError(f"periods: {P} period(s) leave {P - first} after dropping the "
                        "transient; the "
                        f"noise estimate needs at least 2", hint="record more periods or pass "
                                                                 "--keep-transient")
    Uk = np.fft.rfft(U[first:, :, 0], axis=1)[:, 1:]                       # (P', F)
    Yk = np.fft.rfft(y.reshape(P, L, p)[first:], axis=1)[:, 1:]            # (P', F, p)
    f = np.fft.rfftfreq(L, dt)[1:]
    Pk = Uk.shape[0]
    Ub, Yb = Uk.mean(axis=0), Yk.mean(axis=0)
    excited = np.abs(Ub) ** 2 > _NO_POWER * np.max(np.abs(Ub) ** 2)
    if not excited.any():
        raise DataError("input: no frequency line carries power (constant input)")
    dU, dY = Uk - Ub, Yk - Yb
    vU = np.sum(np.abs(dU) ** 2, axis=0) / (Pk * (Pk - 1))
    vY = np.sum(np.abs(dY) ** 2, axis=0) / (Pk * (Pk - 1))
    cYU = np.sum(dY * dU.conj()[:, :, None], axis=0) / (Pk * (Pk - 1))
    f, Ub, Yb, vU, vY, cYU = (f[excited], Ub[excited], Yb[excited], vU[excited], vY[excited],
                              cYU[excited])
    H = Yb / Ub[:, None]
    var = ((vY + np.abs(H) ** 2 * vU[:, None] - 2 * np.real(H.conj() * cYU / Ub[:, None]))
           / np.abs(Ub[:, None]) ** 2)
    std = np.sqrt(np.maximum(var, 0.0))
    return f, H[:, :, None], std[:, :, None], None, {"periods": P, "periods_used": Pk,
                                                     "period_samples": L,
                                                     "transient_dropped": not keep_transient}


def _h1_min_samples(m: int) -> int:
    """The shortest record whose default segments (N // 8 within 16 … 4096 samples, half
    overlapping) number more than ``m``: 16 + 8 m for m < 14."""
    N = 16
    while 1 + (N - (L := max(min(N // 8, 4096), 16))) // (L // 2) <= m:
        N += 1
    return N


def _h1(u, y, dt, nperseg):
    N, m = u.shape
    p = y.shape[1]
    L = int(nperseg) if nperseg else max(min(N // 8, 4096), 16)
    if not nperseg and (L > N or 1 + (N - L) // (L // 2) <= m):
        raise DataError(f"data: a record of {N} sample(s) is too short for an H1 FRF with "
                        f"{m} input(s): it needs at least {_h1_min_samples(m)} (Hann "
                        f"segments of at least 16 samples, half overlapping, more than {m})",
                        hint="use a longer record")
    if L < 8 or L > N:
        raise DataError(f"nperseg: expected 8 … {N} samples per segment, found {L}")
    step = L // 2
    K = 1 + (N - L) // step
    if K <= m:
        raise DataError(f"data: {N} samples give {K} segment(s) of {L}; H1 with {m} input(s) "
                        f"needs more than {m}",
                        hint="use a longer record or a shorter --nperseg")
    win = np.hanning(L + 1)[:-1]
    Uk = _segment_spectra(u, L, step, K, win)                               # (m, K, F)
    Yk = _segment_spectra(y, L, step, K, win)                               # (p, K, F)
    f = np.fft.rfftfreq(L, dt)
    Suu = _cross_spectra(Uk, Uk)
    Syu = _cross_spectra(Yk, Uk)
    Syy = np.stack([_power(Yk[i]) for i in range(p)], axis=1)
    pu = np.real(np.einsum("fii->fi", Suu))
    bad = np.any(pu <= _NO_POWER * pu.max(axis=0), axis=1)
    good = ~bad
    H = np.full((f.size, p, m), np.nan, dtype=complex)
    std = np.full((f.size, p, m), np.inf)
    coh = np.full((f.size, p), np.nan)
    Sinv = np.linalg.inv(Suu[good])
    Hg = Syu[good] @ Sinv
    Sfit = np.einsum("fij,fjk,fik->fi", Hg, Suu[good], Hg.conj()).real
    Svv = np.maximum(Syy[good] - Sfit, 0.0)
    var = (_HANN_OVERLAP_INFLATION * Svv[:, :, None]
           * np.real(np.einsum("fjj->fj", Sinv))[:, None, :] / (K - m))
    H[good], std[good] = Hg, np.sqrt(var)
    coh[good] = np.clip(Sfit / np.maximum(Syy[good], 1e-300), 0.0, 1.0)
    _no_power_warning(f, bad, "input")
    return f, H, std, coh, {"segments": K, "nperseg": L, "window": "hann", "overlap": 0.5}


def _segment_spectra(x, L: int, step: int, K: int, win):
    """rfft (c, K, F) of the K Hann-windowed, 50 %-overlapping segments of each column of x (N, c):
    segments as a strided view (no copy), one windowed temporary per column, the FFT along its
    last (contiguous) axis into one complex array."""
    c = x.shape[1]
    X = np.empty((c, K, L // 2 + 1), dtype=complex)
    for j in range(c):
        seg = sliding_window_view(x[:, j], L)[::step][:K]
        np.fft.rfft(seg * win, axis=-1, out=X[j])
    return X


def _sum_products(a, b):
    """Σ_k a[k, f]·b[k, f] per column f (a, b: (K, F) real arrays or views)."""
    return np.einsum("kf,kf->f", a, b)


def _real_part_sum(A, B):
    """Σ_k Re(A[k, f] conj(B[k, f])) = Σ(ar·br) + Σ(ai·bi), from one product over the
    interleaved (contiguous) real and imaginary parts."""
    d = _sum_products(A.view(np.float64), B.view(np.float64))
    return d[0::2] + d[1::2]


def _power(A):
    """Σ_k |A[k, f]|² per line f."""
    return _real_part_sum(A, A)


def _cross_spectra(A, B):
    """S[f, i, j] = Σ_k A_i[k, f] conj(B_j[k, f]) (A: (a, K, F), B: (b, K, F)) without conjugated
    copies: Re from :func:`_real_part_sum`, Im = Σ(ai·br) − Σ(ar·bi); a spectrum of a channel with
    itself (A is B, i = j) is real."""
    S = np.empty((A.shape[2], A.shape[0], B.shape[0]), dtype=complex)
    for i in range(A.shape[0]):
        for j in range(B.shape[0]):
            S[:, i, j].real = _real_part_sum(A[i], B[j])
            if A is B and i == j:
                S[:, i, j].imag = 0.0
            else:
                S[:, i, j].imag = (_sum_products(A[i].imag, B[j].real)
                                   - _sum_products(A[i].real, B[j].imag))
    return S


def _spa(u, y, dt, lag_window, n_lines):
    N = u.shape[0]
    if u.shape[1] != 1 or y.shape[1] != 1:
        raise DataError("spa: the smoothed ETFE is single-input; found "
                        f"{u.shape[1]} input(s)", hint="use the h1 method for several inputs")
    M = int(lag_window) if lag_window else int(min(30, N // 10))
    if not lag_window and M < 2:
        raise DataError(f"data: a record of {N} sample(s) is too short for an SPA FRF: it needs "
                        "at least 20 (a lag window of N/10 ≥ 2 lags)", hint="use a longer record")
    if M < 2 or M >= N // 2:
        raise DataError(f"lag_window: expected 2 … {N // 2 - 1}, found {M}")
    uu, yy = u[:, 0], y[:, 0]
    nf = 1 << int(np.ceil(np.log2(2 * N)))
    Fu, Fy = np.fft.rfft(uu, nf), np.fft.rfft(yy, nf)

    def xcorr(a, b):  # R̂_ab(τ) = (1/N) Σ a(t+τ) b(t), τ = −M … M
        r = np.fft.irfft(a * b.conj(), nf) / N
        return np.concatenate([r[-M:], r[:M + 1]])

    tau = np.arange(-M, M + 1)
    W = 0.5 * (1 + np.cos(np.pi * tau / M))
    Ru, Ryu, Ry = xcorr(Fu, Fu), xcorr(Fy, Fu), xcorr(Fy, Fy)
    w = np.pi * np.arange(1, n_lines + 1) / n_lines * (1 - 1e-9)
    E = np.exp(-1j * np.outer(w, tau))
    Pu, Pyu, Py = (E @ (W * Ru)).real, E @ (W * Ryu), (E @ (W * Ry)).real
    bad = Pu <= _NO_POWER * Pu.max()
    G = np.where(bad, np.nan, Pyu / np.where(bad, 1.0, Pu))
    Pv = np.maximum(Py - np.abs(Pyu) ** 2 / np.where(bad, 1.0, Pu), 0.0)
    var = np.where(bad, np.inf, np.sum(W ** 2) / N * Pv / np.where(bad, 1.0, Pu))
    coh = np.where(bad, np.nan, np.clip(np.abs(Pyu) ** 2 / np.maximum(Pu * Py, 1e-300), 0, 1))
    f = w / (2 * np.pi * dt)
    _no_power_warning(f, bad, "input")
    return (f, G[:, None, None], np.sqrt(var)[:, None, None], coh[:, None],
            {"lag_window": M, "window": "hann"})


def frf(u, y, *, dt: float | None = None, method: str = "auto", periods: int | None = None,
        keep_transient: bool = False, nperseg: int | None = None, lag_window: int | None = None,
        n_lines: int = 128, inputs=None, outputs=None, input_units=None,
        output_units=None) -> FRF:
    """Estimate the frequency response from input ``u`` (N, m) to output ``y`` (N, p);
    ``inputs``/``outputs`` name the channels, ``input_units``/``output_units`` give their units
    (H is then labelled output unit per input unit: :attr:`FRF.H_units`).

    ``method='auto'``: ``'periodic'`` when ``periods`` is given, else ``'h1'``. See the module
    docstring for the estimators and their σ.

    Examples
    --------
    >>> import numpy as np
    >>> from gripkit.sysid import frf
    >>> u = np.random.default_rng(0).standard_normal(20000)
    >>> y = 0.5 * np.concatenate([[0.0], u[:-1]])            # y[t] = 0.5 u[t-1]
    >>> r = frf(u, y, dt=0.01, nperseg=256)
    >>> bool(np.allclose(np.abs(r.H[1:, 0, 0]), 0.5, atol=0.01))
    True
    """
    u = as_io_matrix(u, "input u")
    y = as_io_matrix(y, "output y", u.shape[0])
    check_columns_vary(u, y, dict(inputs=inputs, outputs=outputs, input_units=input_units,
                                  output_units=output_units))
    step = check_dt(dt)
    if method == "auto":
        method = "periodic" if periods is not None else "h1"
    if method not in FRF_METHODS:
        raise DataError(f"method: expected one of auto, {', '.join(FRF_METHODS)}, found {method!r}")
    if method == "periodic":
        if periods is None:
            raise DataError("periods: the periodic method needs the number of "
                            "periods in the record")
        f, H, std, coh, info = _periodic(u, y, step, periods, keep_transient)
    elif method == "h1":
        f, H, std, coh, info = _h1(u, y, step, nperseg)
    else:
        f, H, std, coh, info = _spa(u, y, step, lag_window, int(n_lines))
    m, p = u.shape[1], y.shape[1]
    ins = tuple(inputs) if inputs else tuple(f"u{i}" if m > 1 else "u" for i in range(m))
    outs = tuple(outputs) if outputs else tuple(f"y{i}" if p > 1 else "y" for i in range(p))
    return FRF(f, H, std, coh, "spa" if method == "etfe" else method, ins, outs, info,
               _units(input_units, m, "input_units"), _units(output_units, p, "output_units"))


def _units(units, k: int, name: str) -> tuple[str, ...]:
    """``units`` (None, one string for one channel, or one per channel) as a k-tuple."""
    if units is None:
        return ("",) * k
    units = (units,) if isinstance(units, str) else tuple(units)
    if len(units) != k or not all(u is None or isinstance(u, str) for u in units):
        raise ArgumentError(f"{name}: expected {k} unit string(s), one per channel, found "
                            f"{units!r:.80}")
    return tuple(u or "" for u in units)
