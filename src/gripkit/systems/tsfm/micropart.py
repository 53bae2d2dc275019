"""Location, width and stiffness of a micropart held by the TSFM
(``001_0b92a7da96e7aa46.txt`` §V-C, §V-D, eq 16, Table III).

From the two fingers' estimated tip positions y₁, y₂ (eq 11, each positive when closing) and
measured forces F₁, F₂:

* **location** (§V-C): where each finger's force first exceeds the threshold (5 µN), its tip
  touches the part: the part's faces are at X = y₁c from finger 1's rest tip and at
  X = gap − y₂c;
* **width**: w = gap − (y₁c + y₂c) (the seed's 400 − (62.42 + 39.4) = 298.18 µm);
* **stiffness** (eq 16): k̂ = F_g / δ with F_g the gripping force from both sides, (F₁ + F₂)/2,
  and δ the total deformation from both sides, (y₁ − y₁c) + (y₂ − y₂c).

The threshold detection places each contact a little late (by the threshold over the contact
stiffness, and the detector's averaging delay): δ is then short by a constant. gripkit therefore
fits F̄ = k (s − s₀), s = y₁ + y₂, by least squares over the loading of the squeeze (on block
averages, so the force noise that also enters the position estimates hardly biases the slope; a
hold at constant force is left out: it adds no leverage): the slope is eq 16's
k̂ without the offset, and s₀ — where the loading line meets zero force — refines the width to
w = gap − s₀. Both come with standard deviations from the regression; the threshold-based width
and the single-ratio k̂ of eq 16 at the largest force are reported too. Under force control the
fingers move in response to the measured force's noise; ``instrument_lag`` replaces least squares
by instrumental variables that remove the resulting closed-loop bias (used by
:mod:`.stiffness_study`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from ...errors import DataError, IdentificationError
from ...estimation.contact_detection import ContactDetector

__all__ = ["MicropartEstimate", "estimate_micropart"]


@dataclass(frozen=True)
class MicropartEstimate:
    """Width (m) and stiffness (N/m) of a micropart, with standard deviations.

    ``width`` and ``stiffness`` are the loading-line estimates; ``width_threshold`` and
    ``stiffness_ratio`` the seed's (contact at the threshold; eq 16 at the largest force).
    ``faces`` are the part's faces (m from finger 1's rest tip); ``contacts`` the tip
    positions (m) of fingers 1 and 2 at contact, and ``contact_index`` the samples.
    """

    width: float
    width_std: float
    stiffness: float
    stiffness_std: float
    width_threshold: float
    stiffness_ratio: float
    faces: tuple[float, float]
    contacts: tuple[float, float]
    contact_index: tuple[int, int]
    n_blocks: int

    @property
    def centre(self) -> float:
        return 0.5 * (self.faces[0] + self.faces[1])

    def to_dict(self) -> dict:
        return asdict(self)


def estimate_micropart(y1, F1, y2, F2, gap: float, *, threshold: float = 5e-6, window: int = 8,
                       block: int = 20, min_force: float | None = None,
                       instrument_lag: int = 0) -> MicropartEstimate:
    """Estimate a grasped part's location, width and stiffness (see the module docstring).

    Parameters
    ----------
    y1, y2
        Estimated tip positions of fingers 1 and 2 (m, closing positive), shape (N,).
    F1, F2
        Forces measured by the two sensors (N), shape (N,).
    gap
        Distance between the tips at rest (m): 400 µm for the TSFM (§V-C).
    threshold, window
        Contact detection (§V-C: 5 µN above a noise below 2 µN); see :class:`ContactDetector`.
    block
        Samples averaged per point of the loading line (20 = 1 ms at 20 kHz).
    min_force
        Only squeeze samples whose mean force exceeds this enter the loading line (default:
        twice the threshold).
    instrument_lag
        0: ordinary least squares. L > 0: instrumental variables, the block sum s_{j−L} standing in
        for s_j. Under force control the fingers move in response to the measured force, noise
        included, so s_j is correlated with the force noise of its own block (a closed-loop bias,
        −3e-4 relative on a 12.1 N/m part, about −1σ); s_{j−L} is not (causality), and on a
        quasi-static squeeze it is nearly collinear with s_j, so the estimate stays as precise.
        The first L blocks of the loading line are lost.
    """
    arrs = [np.asarray(a, dtype=np.float64).ravel() for a in (y1, F1, y2, F2)]
    n = arrs[0].size
    if any(a.size != n for a in arrs):
        raise DataError(f"y1, F1, y2, F2 must have the same length, found {[a.size for a in arrs]}")
    if not all(np.isfinite(a).all() for a in arrs):
        raise DataError("positions or forces contain NaN or inf")
    y1, F1, y2, F2 = arrs
    c1, _ = ContactDetector(threshold, window=window).run(F1)
    c2, _ = ContactDetector(threshold, window=window).run(F2)
    if not c1.any() or not c2.any():
        which = "finger 1" if not c1.any() else "finger 2"
        raise DataError(f"{which} never touches the part: its force never exceeds "
                        f"{threshold * 1e6:g} µN",
                        hint="the record must include the contact of both fingers")
    i1, i2 = int(np.argmax(c1)), int(np.argmax(c2))
    y1c, y2c = float(y1[i1]), float(y2[i2])
    w_thr = gap - (y1c + y2c)
    both = c1 & c2
    both[: max(i1, i2)] = False
    Fm = 0.5 * (F1 + F2)
    s = y1 + y2
    fmin = 2.0 * threshold if min_force is None else float(min_force)
    idx = np.flatnonzero(both & (Fm > fmin))
    nb = idx.size // block
    if nb < 3:
        raise DataError(f"only {idx.size} samples squeeze the part with both fingers above "
                        f"{fmin * 1e6:g} µN; "
                        f"need at least {3 * block}", hint="squeeze longer or harder")
    idx = idx[: nb * block].reshape(nb, block)
    Fb = Fm[idx].mean(axis=1)
    sb = s[idx].mean(axis=1)
    # the loading line: blocks before the force levels off (a long hold at constant force adds no
    # leverage, only noise that the position estimates share with the force)
    load = np.flatnonzero(Fb < 0.97 * Fb.max())
    if load.size >= 3:
        idx, Fb, sb = idx[: load[-1] + 1], Fb[: load[-1] + 1], sb[: load[-1] + 1]
        nb = Fb.size
    lag = int(instrument_lag)
    if lag < 0 or nb - lag < 3:
        raise DataError(f"instrument_lag: expected 0 <= lag <= {max(nb - 3, 0)} (the loading line "
                        f"has {nb} blocks), "
                        f"found {instrument_lag!r}")
    if np.ptp(sb) <= 0:
        raise IdentificationError("the fingers did not move while squeezing: δ is constant, eq "
                                  "16 is undefined")
    M = np.column_stack([sb[lag:], np.ones(nb - lag)])
    Fb = Fb[lag:]
    Z = np.column_stack([sb[: nb - lag], np.ones(nb - lag)])
    # least squares (Z = M) or instrumental variables: β = (ZᵀM)⁻¹ZᵀF, cov = σ² (ZᵀM)⁻¹ ZᵀZ (MᵀZ)⁻¹
    ZM_inv = np.linalg.inv(Z.T @ M)
    coef = ZM_inv @ (Z.T @ Fb)
    r = Fb - M @ coef
    s2 = float(r @ r) / max(nb - lag - 2, 1)
    cov = s2 * ZM_inv @ (Z.T @ Z) @ ZM_inv.T
    k, c = float(coef[0]), float(coef[1])
    if k <= 0:
        raise IdentificationError(f"the force does not rise as the fingers close (slope {k:g} N/m)")
    s0 = -c / k
    g = np.array([c / k**2, -1.0 / k])   # ∂s0/∂(k, c)
    s0_std = math.sqrt(max(g @ cov @ g, 0.0))
    kmax = int(idx.ravel()[np.argmax(Fm[idx.ravel()])])
    delta = s[kmax] - (y1c + y2c)
    k_ratio = float(Fm[kmax] / delta) if delta > 0 else math.nan
    width = gap - s0
    # faces from the refined contact sum, split as the threshold contacts split it
    shift = (s0 - (y1c + y2c)) / 2.0
    faces = (y1c + shift, gap - (y2c + shift))
    return (MicropartEstimate(width, s0_std, k, math.sqrt(cov[0, 0]), w_thr, k_ratio, faces,
                              (y1c, y2c), (i1, i2), nb))
