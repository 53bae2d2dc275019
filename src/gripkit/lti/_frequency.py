"""Bode data (magnitude and phase with their linearised one-sigma) and default frequency grids."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Bode", "default_grid"]


@dataclass(frozen=True, eq=False)
class Bode:
    """Frequency response H(jω) on a grid, with its covariance when the system carries one.

    Attributes
    ----------
    w
        Angular frequencies (rad/s), shape (N,).
    H
        Complex response, shape (N, p, m).
    H_cov
        Covariance of (Re H, Im H) per entry, shape (N, p, m, 2, 2), or None.

    Magnitude and phase σ are linearised: with g_|H| = (Re H, Im H)/|H| and
    g_∠H = (−Im H, Re H)/|H|², ``σ² = gᵀ H_cov g``.

    Examples
    --------
    >>> import numpy as np
    >>> from gripkit.lti import TransferFunction
    >>> b = TransferFunction([1.0], [1.0, 1.0]).bode([1.0])
    >>> round(float(b.magnitude_db[0, 0, 0]), 3), round(float(np.degrees(b.phase[0, 0, 0])), 1)
    (-3.01, -45.0)
    """

    w: np.ndarray
    H: np.ndarray
    H_cov: np.ndarray | None = None

    @property
    def f_hz(self) -> np.ndarray:
        """Frequencies in Hz, ω/2π."""
        return self.w / (2 * np.pi)

    @property
    def magnitude(self) -> np.ndarray:
        return np.abs(self.H)

    @property
    def magnitude_db(self) -> np.ndarray:
        return 20 * np.log10(np.abs(self.H))

    @property
    def phase(self) -> np.ndarray:
        """Phase (rad), unwrapped along the frequency axis."""
        return np.unwrap(np.angle(self.H), axis=0)

    def _std(self, g) -> np.ndarray | None:
        if self.H_cov is None:
            return None
        return np.sqrt(np.clip(np.einsum("...a,...ab,...b->...", g, self.H_cov, g), 0.0, None))

    @property
    def magnitude_std(self) -> np.ndarray | None:
        """One-sigma of |H| (linearised), or None without covariance."""
        a = np.abs(self.H)
        return self._std(np.stack([self.H.real, self.H.imag], -1) / a[..., None])

    @property
    def phase_std(self) -> np.ndarray | None:
        """One-sigma of the phase (rad, linearised), or None without covariance."""
        a2 = np.abs(self.H) ** 2
        return self._std(np.stack([-self.H.imag, self.H.real], -1) / a2[..., None])


def default_grid(dt, poles, zeros, n: int) -> np.ndarray:
    """Discrete: ``n`` points 0 … π/dt (Nyquist excluded, as ``scipy.signal.freqz``).
    Continuous: ``n`` log-spaced points two decades around the poles' and zeros' magnitudes."""
    if dt is not None:
        return np.pi / dt * np.arange(n) / n
    mags = np.abs(np.concatenate([poles, zeros]))
    mags = mags[mags > 0]
    lo, hi = (mags.min(), mags.max()) if mags.size else (1.0, 1.0)
    return np.logspace(np.log10(lo) - 2, np.log10(hi) + 2, n)
