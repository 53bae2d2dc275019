"""Fusion of independent estimates of one quantity (``000_8f66dcc7ab06470c.txt`` §IV-A, eqs 16–19).

Two measurements ε₁, ε₂ of the same value with independent zero-mean Gaussian noise of variances
σ₁², σ₂² combine into (eq 16, eq 18)

    ε₁₂ = σ₂²/(σ₁² + σ₂²) · ε₁ + σ₁²/(σ₁² + σ₂²) · ε₂,       σ₁₂² = σ₁² σ₂² / (σ₁² + σ₂²).

For K estimates this is the inverse-variance weighted mean (the minimum-variance unbiased linear
combination, and the maximum-likelihood estimate under Gaussian noise):

    ε = Σ_i ε_i/σ_i² / Σ_i 1/σ_i²,        σ² = 1 / Σ_i 1/σ_i².

**Eq 17 as printed is wrong.** The extraction reads
``ε₁₂ = ε₁ + [σ₁² + σ₂²](ε₂ − ε₁)``: the gain lacks its numerator. Expanding eq 16,

    ε₁₂ = ε₁ + σ₁²/(σ₁² + σ₂²) · (ε₂ − ε₁),

i.e. the Kalman gain is K = σ₁²/(σ₁² + σ₂²) (dimensionless, between 0 and 1) and
σ₁₂² = (1 − K) σ₁². :func:`fuse_update` implements this corrected update form; applied
sequentially it gives the same answer as :func:`fuse` (tested).

**Signal-proportional noise (eq 19).** The seed assumes the noise variance of combination i grows
with the signal: σ²_εi = ε_i²(t) · σ²_Ni, where the *normalised* variance σ²_Ni comes from
calibration: repeated measurements at several known forces, each divided by the known force, have
mean 1 and variance σ²_Ni (:func:`normalised_variances`). Eq 19 gives zero variance — infinite
weight — to an estimate that happens to read exactly zero; :func:`proportional_variance` therefore
takes an optional absolute ``floor`` (the electronics noise that Fig. 16 shows at zero load).

**Table I.** Its "theoretical" column is :func:`fused_variance` of the measured normalised
variances (0.01309, 0.00459, 0.00301 → 0.00340, 0.00182, 0.00160; the printed 0.00181 for ε₂₃ lies
within the rounding of the printed inputs). Its "actual" column is 20–50 % higher: the seed
blames violated assumptions. One such violation is correlation between the combinations
(gauges sharing a beam and an amplifier); :func:`implied_correlation` gives the common
correlation coefficient that explains a measured fused variance, and :func:`fused_variance` with
``correlation=`` the variance the independent-noise weights really achieve.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import DataError

__all__ = [
    "fuse",
    "fuse_update",
    "fuse_proportional",
    "proportional_variance",
    "fused_variance",
    "implied_correlation",
    "normalised_variances",
    "NormalisedVariances",
]


def _stack(items, what: str) -> np.ndarray:
    """Stack K array-likes (broadcast together) along a new first axis: shape (K, ...)."""
    if isinstance(items, np.ndarray):
        arrs = list(items) if items.ndim >= 1 else [items]
    elif isinstance(items, Sequence) and not isinstance(items, (str, bytes)):
        arrs = [np.asarray(a, dtype=np.float64) for a in items]
    else:
        raise DataError(f"{what}: expected a sequence of K estimates (arrays broadcast over time), "
                        f"found {type(items).__name__}")
    if len(arrs) == 0:
        raise DataError(f"{what}: expected at least one estimate, found none")
    try:
        b = np.broadcast_arrays(*[np.asarray(a, dtype=np.float64) for a in arrs])
    except ValueError:
        shapes = [np.shape(a) for a in arrs]
        raise DataError(f"{what}: the estimates do not broadcast together, "
                        f"shapes {shapes}") from None
    return np.stack(b, axis=0)


def _first_bad(mask: np.ndarray) -> str:
    idx = np.argwhere(mask)[0]
    return (f"estimate {int(idx[0])}" + (f" at index {tuple(int(i) for i in idx[1:])}"
                                         if idx.size > 1 else ""))


def fuse(estimates, variances):
    """Fuse K independent estimates of one quantity (eqs 16 and 18, generalised to any K).

    Parameters
    ----------
    estimates
        K estimates: a sequence of K arrays (or an array with the K estimates along axis 0). Each
        may be a scalar or an array over time (shape (N,) or any shape); all broadcast together.
    variances
        Their noise variances, same structure (broadcast with ``estimates``). ``inf`` means "no
        information" (weight 0); ``0`` means exact (that estimate wins; several exact estimates
        must agree).

    Returns
    -------
    (estimate, variance)
        ``Σ ε_i/σ_i² / Σ 1/σ_i²`` and ``1/Σ 1/σ_i²``, with the broadcast shape (floats for scalar
        inputs).

    Examples
    --------
    >>> print(f"{fuse([1.0, 1.2], [0.01309, 0.00459])[1]:.7f}")  # Table I: theoretical var(ε_N12)
    0.0033984
    """
    x = _stack(estimates, "estimates")
    v = _stack(variances, "variances")
    if x.shape[0] != v.shape[0]:
        raise DataError(f"fuse: {x.shape[0]} estimates but {v.shape[0]} variances",
                        hint="give one variance (or variance array) per estimate")
    try:
        x, v = np.broadcast_arrays(x, v)
    except ValueError:
        raise DataError(f"fuse: estimates of shape {x.shape[1:]} and variances of "
                        f"shape {v.shape[1:]} "
                        "do not broadcast together") from None
    if not np.isfinite(x).all():
        raise DataError(f"fuse: non-finite estimate ({_first_bad(~np.isfinite(x))})",
                        hint="drop or interpolate NaN samples before fusing")
    if np.isnan(v).any() or (v < 0).any():
        raise DataError(f"fuse: variances must be >= 0 (inf allowed), found a bad value at "
                        f"{_first_bad(np.isnan(v) | (v < 0))}")
    exact = v == 0.0
    with np.errstate(divide="ignore"):
        w = np.where(exact, 0.0, 1.0 / np.where(exact, 1.0, v))
    wsum = w.sum(axis=0)
    n_exact = exact.sum(axis=0)
    none = (wsum == 0.0) & (n_exact == 0)
    if none.any():
        idx = np.argwhere(none)[0] if none.ndim else ()
        raise DataError("fuse: every estimate has infinite variance at index "
                        f"{tuple(int(i) for i in idx)}",
                        hint="at least one estimate must carry information")
    with np.errstate(invalid="ignore", divide="ignore"):
        est = (w * x).sum(axis=0) / wsum
        var = 1.0 / wsum
    if n_exact.any():
        xe = np.where(exact, x, 0.0)
        mean_exact = xe.sum(axis=0) / np.maximum(n_exact, 1)
        spread = np.where(exact, np.abs(x - mean_exact), 0.0).max(axis=0)
        tol = 1e-9 * np.maximum(1.0, np.abs(mean_exact))
        if (spread > tol).any():
            raise DataError("fuse: estimates with zero variance disagree (they "
                            "cannot all be exact)",
                            hint="give them their real (positive) variances")
        est = np.where(n_exact > 0, mean_exact, est)
        var = np.where(n_exact > 0, 0.0, var)
    if est.ndim == 0:
        return float(est), float(var)
    return est, var


def fuse_update(estimate, variance, new, new_variance):
    """The update form of eq 17, corrected: fold one more independent estimate into a fused one.

        K = σ₁²/(σ₁² + σ₂²),   ε₁₂ = ε₁ + K (ε₂ − ε₁),   σ₁₂² = (1 − K) σ₁²   (eq 18).

    (The printed eq 17 writes the gain as ``σ₁² + σ₂²``, without its numerator σ₁²/(·); that is not
    dimensionless and is a typesetting loss.) Arrays broadcast; returns ``(estimate, variance)``.
    """
    e1 = np.asarray(estimate, dtype=np.float64)
    v1 = np.asarray(variance, dtype=np.float64)
    e2 = np.asarray(new, dtype=np.float64)
    v2 = np.asarray(new_variance, dtype=np.float64)
    for name, a in (("variance", v1), ("new_variance", v2)):
        if np.isnan(a).any() or (a < 0).any():
            raise DataError(f"fuse_update: {name} must be >= 0, found "
                            f"{a[np.isnan(a) | (a < 0)].ravel()[0]!r}")
    if ((v1 + v2) == 0).any():
        raise DataError("fuse_update: both "
                        "variances are zero", hint="use fuse() for exact estimates")
    with np.errstate(invalid="ignore"):
        k = np.where(np.isinf(v1), 1.0, v1 / np.where(np.isinf(v1), 1.0, v1 + v2))
        k = np.where(np.isinf(v2) & ~np.isinf(v1), 0.0, k)
    e = e1 + k * (e2 - e1)
    v = np.where(np.isinf(v1), v2, (1.0 - k) * v1)
    if e.ndim == 0:
        return float(e), float(v)
    return e, v


def proportional_variance(estimate, normalised_variance, floor: float = 0.0):
    """Eq 19: the noise variance of an estimate whose noise grows with the signal,

        σ²_ε(t) = ε²(t) · σ²_N  (+ floor²),

    ``normalised_variance`` σ²_N (dimensionless, from :func:`normalised_variances`), ``floor`` an
    absolute noise standard deviation in the unit of ``estimate`` (default 0, as printed)."""
    e = np.asarray(estimate, dtype=np.float64)
    sn = np.asarray(normalised_variance, dtype=np.float64)
    if (sn < 0).any() or not np.isfinite(sn).all():
        raise DataError(f"normalised variance must be finite and >= 0, found {sn}")
    if not (np.isfinite(floor) and floor >= 0):
        raise DataError(f"floor: expected a noise standard deviation >= 0, found {floor!r}")
    out = e * e * sn + floor * floor
    return float(out) if out.ndim == 0 else out


def fuse_proportional(estimates, normalised_variances, floor=0.0):
    """Fuse estimates whose variances follow eq 19 (σ²_εi = ε_i² σ²_Ni + floor_i²).

    ``estimates`` as in :func:`fuse`; ``normalised_variances`` one σ²_Ni per estimate;
    ``floor`` a scalar or one absolute noise std per estimate. Returns ``(estimate, variance)``."""
    x = _stack(estimates, "estimates")
    sn = np.asarray(normalised_variances, dtype=np.float64).reshape(-1)
    if sn.size != x.shape[0]:
        raise DataError(f"fuse_proportional: {x.shape[0]} estimates but {sn.size} "
                        "normalised variances")
    fl = np.broadcast_to(np.asarray(floor, dtype=np.float64), (x.shape[0],))
    shape = (-1,) + (1,) * (x.ndim - 1)
    var = proportional_variance(x, sn.reshape(shape), 0.0) + (fl * fl).reshape(shape)
    return fuse(x, var)


def fused_variance(variances, correlation=None):
    """Variance of the inverse-variance-weighted fusion of K estimates (eq 18 generalised).

    Without ``correlation``: ``1/Σ 1/σ_i²`` (the theoretical column of Table I). With
    ``correlation`` (a scalar common coefficient ρ, or a K×K correlation matrix): the variance that
    the independent-noise weights w_i ∝ 1/σ_i² actually achieve, ``wᵀ Σ w`` with
    ``Σ = D C D``, D = diag(σ_i)."""
    v = np.asarray(variances, dtype=np.float64).reshape(-1)
    if v.size == 0 or (v <= 0).any() or not np.isfinite(v).all():
        raise DataError(f"fused_variance: expected positive finite variances, found {v.tolist()}")
    w = (1.0 / v) / np.sum(1.0 / v)
    if correlation is None:
        return float(1.0 / np.sum(1.0 / v))
    C = np.asarray(correlation, dtype=np.float64)
    if C.ndim == 0:
        C = np.full((v.size, v.size), float(C))
        np.fill_diagonal(C, 1.0)
    if C.shape != (v.size, v.size):
        raise DataError(f"correlation: expected a scalar or a {v.size}x{v.size} matrix, found "
                        f"shape {C.shape}")
    d = np.sqrt(v)
    return float(w @ (d[:, None] * C * d[None, :]) @ w)


def implied_correlation(variances, fused_actual: float) -> float:
    """The common correlation coefficient ρ between the K estimates that makes the
    inverse-variance-weighted fusion have variance ``fused_actual``.

    The fused variance is linear in ρ: ``V(ρ) = V₀ + ρ Σ_{i≠j} w_i w_j σ_i σ_j``; solved for ρ.
    Table I: ε_N1, ε_N2 (0.01309, 0.00459) fused to an actual 0.00440 imply ρ ≈ 0.34."""
    v = np.asarray(variances, dtype=np.float64).reshape(-1)
    if v.size < 2:
        raise DataError("implied_correlation needs at least two estimates")
    v0 = fused_variance(v)
    w = (1.0 / v) / np.sum(1.0 / v)
    d = np.sqrt(v)
    cross = float((w * d).sum() ** 2 - (w * w * v).sum())
    return (float(fused_actual) - v0) / cross


@dataclass(frozen=True)
class NormalisedVariances:
    """Normalised noise statistics of K estimate combinations from calibration data.

    Attributes
    ----------
    mean
        (K,) mean of estimate/known force (≈ 1 when the calibration is right; its deviation from 1
        is a gain error of that combination).
    variance
        (K,) σ²_Ni: variance of estimate/known force about ``mean`` (pooled over load levels).
    variance_std
        (K,) standard error of ``variance`` (Gaussian: σ² √(2/(n−1))).
    n
        Samples used per combination.
    levels
        Distinct known-force levels found.
    level_variance
        (n_levels, K) variance at each level; eq 19 assumes these are equal.
    homogeneity_p
        (K,) Bartlett-test p-value that the per-level variances are equal (small p: the noise is
        not proportional to the signal, eq 19's first assumption fails).
    """

    mean: np.ndarray
    variance: np.ndarray
    variance_std: np.ndarray
    n: int
    levels: np.ndarray
    level_variance: np.ndarray
    homogeneity_p: np.ndarray


def normalised_variances(estimates, known) -> NormalisedVariances:
    """σ²_Ni of eq 19 from calibration data (§IV-A: repeated measurements at several known forces,
    divided by the known force to give mean 1 and variance σ²_Ni).

    Parameters
    ----------
    estimates
        (n,) or (n, K): the estimates of K combinations for n calibration samples.
    known
        (n,): the known (applied) value for each sample; must be nonzero.
    """
    from scipy import stats

    e = np.asarray(estimates, dtype=np.float64)
    e = e[:, None] if e.ndim == 1 else e
    k = np.asarray(known, dtype=np.float64).reshape(-1)
    if e.ndim != 2 or e.shape[0] != k.size:
        raise DataError("normalised_variances: estimates of shape "
                        f"{np.shape(estimates)} do not match "
                        f"{k.size} known values")
    if k.size < 3:
        raise DataError("normalised_variances needs at least 3 calibration "
                        f"samples, found {k.size}")
    if not (np.isfinite(e).all() and np.isfinite(k).all()):
        raise DataError("normalised_variances: calibration data contain NaN or inf")
    if (k == 0).any():
        raise DataError("normalised_variances: known force is zero in "
                        f"{int((k == 0).sum())} samples",
                        hint="normalisation divides by the known force; drop the unloaded samples")
    r = e / k[:, None]
    levels, inv = np.unique(k, return_inverse=True)
    # pooled variance about each level's mean (a gain error per level would otherwise inflate it)
    lv = np.full((levels.size, e.shape[1]), np.nan)
    ss = np.zeros(e.shape[1])
    dof = 0
    groups = []
    for j in range(levels.size):
        g = r[inv == j]
        groups.append(g)
        if g.shape[0] >= 2:
            lv[j] = g.var(axis=0, ddof=1)
            ss += ((g - g.mean(axis=0)) ** 2).sum(axis=0)
            dof += g.shape[0] - 1
    if dof == 0:
        var = r.var(axis=0, ddof=1)
        dof = k.size - 1
    else:
        var = ss / dof
    pvals = np.full(e.shape[1], np.nan)
    big = [g for g in groups if g.shape[0] >= 2]
    if len(big) >= 2:
        for c in range(e.shape[1]):
            pvals[c] = stats.bartlett(*[g[:, c] for g in big]).pvalue
    return NormalisedVariances(mean=r.mean(axis=0), variance=var,
                               variance_std=var * np.sqrt(2.0 / dof),
                               n=int(k.size), levels=levels, level_variance=lv, homogeneity_p=pvals)
