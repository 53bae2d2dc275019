"""σ of a subspace (N4SID, MOESP, CVA) state-space model by parametric bootstrap.

The subspace estimator has no simple closed-form covariance, and PEM's ``σ² (JᵀJ)⁻¹`` belongs to
PEM's optimum, not to the subspace model (a kept subspace model is one that scores better than
that optimum by the focus criterion, so it is no stationary point of PEM's criterion, and the
Gauss–Newton covariance evaluated there would describe a different estimator; where PEM failed,
its Jacobian was singular and has no inverse at all). The bootstrap
measures the spread of the estimator itself:

1. the model's free run from its ``x0`` on the record's input, ``ŷ``, and the residuals
   ``v = y − ŷ``, the disturbance as the model sees it;
2. B records ``y_b = ŷ + v_b``, each refitted by the same subspace estimation (same order,
   weighting, horizon, feedthrough, detrending). ``v_b`` is drawn like ``v`` by a sieve
   bootstrap: per output an AR model of ``v`` (Yule–Walker, order by Akaike's criterion, at most
   20; order 0 for a white disturbance), its whitened residuals drawn with replacement by rows
   (the outputs' cross correlation kept) and filtered by it again. The model's own noise model
   (innovation form, ``K``) is not used: on a short record the subspace ``K`` is poor (K ≈ −0.24
   for a white output disturbance, whose K is 0, at N = 500), and the innovations resampled
   through a wrong noise filter do not have the spectrum of the disturbance (σ of the poles 1.5 to
   3.3 times the Monte Carlo spread of 100 records in that case; the sieve: 0.75 to 1.3 times,
   with white output noise as in tests/sysid/test_ss_bootstrap.py and with MA(1) noise alike);
3. each refit brought to the model's state coordinates by the similarity ``T`` that maps its
   extended observability matrix onto the model's, ``O_b T ≈ O`` (least squares over n + 1 block
   rows, each output scaled by its record's σ): ``(T⁻¹ A_b T, T⁻¹ B_b, C_b T, D_b)``;
4. Σ = the sample covariance of those entries over the replicates, carried as the system's
   :class:`~gripkit.lti.Uncertainty` of its entries ``A[i,j]``, ``B[i,j]``, ``C[i,j]``
   (``D[i,j]`` with feedthrough): poles, natural frequencies, damping and frequency responses
   then get their σ by the same first-order propagation as a PEM model's
   (:meth:`~gripkit.lti.StateSpace.pole_covariance`, ``damping()``, ``bode()``).

The number of replicates follows the record's length, so that a result never depends on the
machine's speed: :data:`MAX_REPLICATES` up to ``SAMPLE_BUDGET / MAX_REPLICATES`` samples, fewer
beyond (``SAMPLE_BUDGET // N``), never below :data:`MIN_REPLICATES` (the relative error of a
bootstrap σ is about ``1/√(2(B − 1))``: 7 % at B = 100, 13 % at B = 30). The draws come from
``numpy.random.default_rng(seed)``, :data:`BOOTSTRAP_SEED` by default: the same record and seed
give the same σ.

Several records (:func:`bootstrap_covariance_records`, the model of
:func:`~gripkit.sysid.linear.subspace.n4sid_records`): each replicate is every record's free run
from its own initial state plus a disturbance drawn like that record's own residuals (its own
sieve), the records refitted jointly by the same several-record estimation; the replicate count
follows the samples of all records together, and ``demean`` removes the mean of all their
samples, the one operating point of such a model.
"""

from __future__ import annotations

import warnings

import numpy as np

from ...errors import AccuracyWarning, ArgumentError, GripkitError, emit_warning
from ...lti import StateSpace
from ...progress import status, track

__all__ = ["BOOTSTRAP_SEED", "MAX_REPLICATES", "MIN_REPLICATES", "bootstrap_replicates",
           "bootstrap_covariance", "bootstrap_covariance_records", "bootstrapped",
           "covariance_method", "check_bootstrap"]

#: the default seed of the bootstrap's draws (numpy.random.default_rng)
BOOTSTRAP_SEED = 0
#: replicates of a record of at most SAMPLE_BUDGET / MAX_REPLICATES samples
MAX_REPLICATES = 100
#: replicates of a long record at least
MIN_REPLICATES = 30
#: replicates × samples of a long record (N = 1e5: 30 replicates; measured 4 s at horizon 6, 9 s at
#: horizon 22, on 2 shared cores)
SAMPLE_BUDGET = 2_000_000
#: failed replicates (an error of the refit, a refit whose states do not map onto the model's)
#: above this fraction are warned about: the σ of the others may be too small
FAILED_FRACTION = 0.1


def bootstrap_replicates(n_samples: int) -> int:
    """The number of replicates for a record of ``n_samples`` samples (module docstring).

    Examples
    --------
    >>> bootstrap_replicates(5_000), bootstrap_replicates(40_000), bootstrap_replicates(10**6)
    (100, 50, 30)
    """
    return int(min(MAX_REPLICATES, max(MIN_REPLICATES, SAMPLE_BUDGET // max(int(n_samples), 1))))


def check_bootstrap(value, seed, name: str) -> int | None:
    """The replicates asked for by ``value`` (``n4sid``'s ``bootstrap``, ``identify_ss``'s
    ``bootstrap_replicates``; ``name``: which): ``None`` (replicates by the record's length) for
    None or True, ``0`` (no bootstrap) for 0 or False, else an integer >= ``MIN_REPLICATES / 3``
    (fewer give no σ worth reporting); ``seed`` a non-negative integer (numpy's default_rng).
    An :class:`~gripkit.errors.ArgumentError` otherwise."""
    lo = MIN_REPLICATES // 3
    if value is None or value is True:
        replicates = None
    elif value is False:
        replicates = 0
    elif isinstance(value, (int, np.integer)) and (value == 0 or value >= lo):
        replicates = int(value)
    else:
        raise ArgumentError(f"{name}: expected None or True (replicates by the record's length), "
                            f"0 or False (no bootstrap, no σ) or an integer >= {lo} "
                            f"(replicates), found {value!r:.40}",
                            hint=f"pass {name}={lo} or more, or {name}=0")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ArgumentError(f"bootstrap_seed: expected a non-negative integer, found {seed!r:.40}",
                            hint="pass bootstrap_seed=0 (the default) or another integer >= 0")
    return replicates


def _levinson(r: np.ndarray, n_samples: int) -> np.ndarray:
    """The coefficients a (y[t] ≈ Σ_i a_i y[t−i]) of the AR model of the autocovariances
    ``r[0..q_max]`` whose order minimises Akaike's ``N log σ²_q + 2q`` (Levinson–Durbin on the
    Yule–Walker equations: with biased autocovariances the filter is stable)."""
    a, err = np.zeros(0), float(r[0])
    best, best_aic = a, n_samples * np.log(err) if err > 0 else -np.inf
    for q in range(1, r.size):
        if err <= 0:
            break
        kq = (r[q] - a @ r[q - 1:0:-1]) / err
        a = np.concatenate([a - kq * a[::-1], [kq]])
        err *= 1.0 - kq * kq
        aic = n_samples * np.log(err) + 2 * q if err > 0 else -np.inf
        if aic < best_aic:
            best, best_aic = a, aic
    return best


def _noise_model(v: np.ndarray) -> tuple[list[np.ndarray], np.ndarray]:
    """Per output, the AR coefficients of the free-run residuals ``v`` (N, p) (order by Akaike's
    criterion, at most min(20, N/20)), and the whitened residuals (N, p), centred."""
    from scipy.signal import lfilter

    N, p = v.shape
    q_max = int(min(20, N // 20))
    coefs, eps = [], np.empty_like(v)
    for i in range(p):
        x = v[:, i] - v[:, i].mean()
        r = np.array([x[:N - k] @ x[k:] / N for k in range(q_max + 1)])
        a = _levinson(r, N)
        coefs.append(a)
        eps[:, i] = lfilter(np.concatenate([[1.0], -a]), [1.0], x)
    return coefs, eps - eps.mean(axis=0)


def _disturbance(coefs: list, eps: np.ndarray, rng) -> np.ndarray:
    """A disturbance record like the residuals: rows of ``eps`` drawn with replacement (the
    outputs' cross correlation kept), each output filtered by its AR model, after a burn-in of
    100 + q samples (the filter's start-up transient dropped)."""
    from scipy.signal import lfilter

    N, p = eps.shape
    burn = 100 + max(a.size for a in coefs)
    draw = eps[rng.integers(0, N, N + burn)]
    out = np.empty((N, p))
    for i, a in enumerate(coefs):
        out[:, i] = lfilter([1.0], np.concatenate([[1.0], -a]), draw[:, i])[burn:]
    return out


def _observability(A: np.ndarray, C: np.ndarray, w: np.ndarray) -> np.ndarray:
    """``[C; CA; …; CAⁿ]`` with each output row scaled by ``w`` (n + 1 block rows)."""
    rows, M = [], C * w[:, None]
    for _ in range(A.shape[0] + 1):
        rows.append(M)
        M = M @ A
    return np.vstack(rows)


def _aligned(refit: StateSpace, O: np.ndarray, w: np.ndarray, feedthrough: bool):
    """The entries (vec A, vec B, vec C[, vec D], row-major) of ``refit`` in the model's state
    coordinates (``O_b T ≈ O``, module docstring), or None when T is (nearly) singular or the
    linear algebra fails on a degenerate replicate (numpy's LinAlgError: a failed replicate)."""
    try:
        Ob = _observability(refit.A, refit.C, w)
        T = np.linalg.lstsq(Ob, O, rcond=None)[0]
        if not np.all(np.isfinite(T)) or np.linalg.cond(T) > 1e8:
            return None
        A = np.linalg.solve(T, refit.A @ T)
        B = np.linalg.solve(T, refit.B)
    except np.linalg.LinAlgError:
        return None
    C = refit.C @ T
    parts = [A.ravel(), B.ravel(), C.ravel()] + ([refit.D.ravel()] if feedthrough else [])
    return np.concatenate(parts)


def _replicates(model, records, x0s, refit, replicates: int, seed: int, detrend: str,
                feedthrough: bool, progress: bool):
    """The aligned entries of each replicate that refits (rows), the number that failed and the
    number tried: all of ``replicates``, unless more than half of those tried (after
    :data:`MIN_REPLICATES` / 3 at least) have failed, which stops the loop (no σ comes of it).
    ``records``: (u, y) pairs, each simulated from its own initial state of ``x0s`` and given
    its own disturbance, then detrended as the estimate's data were (``detrend``: 'mean', the
    mean of all records' samples; 'linear', each record's least-squares line against time;
    'none'); ``refit(us, ys)`` fits them all at once: an error of it (a GripkitError, or
    numpy's LinAlgError on a degenerate replicate) counts the replicate as failed."""
    ss = model.system
    us = [u for u, _ in records]
    y_dets = [ss.simulate(u, x0) for u, x0 in zip(us, x0s)]
    noises = [_noise_model(y - y_det) for (_, y), y_det in zip(records, y_dets)]
    sy = np.vstack([y for _, y in records]).std(axis=0)
    w = 1.0 / np.where(sy > 0, sy, 1.0)
    O = _observability(ss.A, ss.C, w)
    rng = np.random.default_rng(seed)
    rows, failed, tried = [], 0, 0
    for _ in track(range(replicates), description="bootstrap σ", enabled=progress):
        if tried >= MIN_REPLICATES // 3 and 2 * failed > tried:
            break
        tried += 1
        ybs = [y_det + _disturbance(coefs, eps, rng) for y_det, (coefs, eps) in zip(y_dets, noises)]
        ybs = _detrended(ybs, detrend)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                fitted = refit(us, [np.ascontiguousarray(yb) for yb in ybs])
        except (GripkitError, np.linalg.LinAlgError):
            failed += 1
            continue
        theta = _aligned(fitted.system, O, w, feedthrough)
        if theta is None:
            failed += 1
            continue
        rows.append(theta)
    return rows, failed, tried


def _detrended(ys: list, detrend: str) -> list:
    """The simulated outputs ``ys`` (one (N, p) array per record) detrended as the estimation's
    data were (:func:`_replicates`)."""
    if detrend == "mean":  # the mean of all records' samples, as the estimation removed it
        mean = np.vstack(ys).mean(axis=0)
        return [y - mean for y in ys]
    if detrend == "linear":  # each record's own line (io_data's 'linear', uniform sampling)
        from scipy.signal import detrend as line_off

        return [line_off(y, axis=0, type="linear") for y in ys]
    return ys


def bootstrap_covariance(model, u, y, refit, *, estimator: str, replicates: int | None = None,
                         seed: int = BOOTSTRAP_SEED, demean: bool = False,
                         feedthrough: bool = False, progress: bool = False,
                         detrend: str | None = None):
    """``model`` (a subspace :class:`~gripkit.sysid.LinearModel` of the deviation data ``u``
    (N, m), ``y`` (N, p)) with the covariance of its entries from a parametric bootstrap (module
    docstring) in ``system.uncertainty`` and ``info['covariance']`` saying how it was obtained
    (``method``, ``replicates`` used, ``failed``, ``seed``, ``estimator``). ``progress``: a
    line on stderr saying what runs, then a progress bar of the replicates.

    ``refit(u, y)`` is the subspace estimation that gave ``model`` (same order and options);
    ``estimator`` names it in ``info``; ``replicates`` default :func:`bootstrap_replicates`;
    ``demean``: remove each simulated output's mean as the estimation removed the record's
    (detrend 'mean'); ``detrend``: 'mean' (``demean``), 'linear' (each simulated output's
    least-squares line removed, as ``detrend='linear'`` removed the record's) or 'none'
    (default: ``demean``'s); ``feedthrough``: D is estimated, and carries σ. When more than half
    of the
    replicates fail (a refit error, such as an order the replicate's data do not support, or a
    refit whose states do not map onto the model's: an order above what the data determine),
    the model is returned without covariance, with an :class:`AccuracyWarning` (the loop stops
    as soon as more than half of those tried have failed, after :data:`MIN_REPLICATES` / 3
    tried at least); more than :data:`FAILED_FRACTION` failed is warned about too.
    """
    u = np.ascontiguousarray(u, dtype=np.float64)
    y = np.ascontiguousarray(y, dtype=np.float64)
    ss = model.system
    x0 = np.zeros(ss.n_states) if model.x0 is None else np.asarray(model.x0, dtype=np.float64)
    how = detrend if detrend is not None else ("mean" if demean else "none")
    if how not in ("mean", "linear", "none"):
        raise ArgumentError(f"detrend: expected 'mean', 'linear' or 'none', found {how!r:.40}",
                            hint="detrend the replicates as the estimate's data were")
    return _covariance(model, [(u, y)], [x0], lambda us, ys: refit(us[0], ys[0]),
                       (estimator, replicates, seed, how, feedthrough, progress))


def bootstrap_covariance_records(model, records, refit, *, estimator: str,
                                 replicates: int | None = None, seed: int = BOOTSTRAP_SEED,
                                 demean: bool = False, feedthrough: bool = False,
                                 progress: bool = False):
    """:func:`bootstrap_covariance` of a subspace model of several records
    (:func:`~gripkit.sysid.linear.subspace.n4sid_records`): ``records`` the (u, y) deviation
    pairs it was fitted to, each replicate every record's free run from its own initial state
    (``model.info['records'][i]['x0']``) plus its own disturbance drawn like that record's
    residuals (its own AR sieve), all refitted at once by ``refit(us, ys)`` (lists, one array
    per record); ``replicates`` default :func:`bootstrap_replicates` of all records' samples
    together; ``demean``: the mean of all records' samples removed (one operating point), as
    the estimation removed it. The same ``info['covariance']`` fields and warnings."""
    recs = [(np.ascontiguousarray(u, dtype=np.float64).reshape(len(u), -1),
             np.ascontiguousarray(y, dtype=np.float64).reshape(len(y), -1)) for u, y in records]
    x0s = [np.asarray(r["x0"], dtype=np.float64) for r in model.info["records"]]
    return _covariance(model, recs, x0s, refit,
                       (estimator, replicates, seed, "mean" if demean else "none", feedthrough,
                        progress))


def _covariance(model, records, x0s, refit, options: tuple):
    """The body of :func:`bootstrap_covariance` and :func:`bootstrap_covariance_records`;
    ``options``: (estimator, replicates, seed, detrend, feedthrough, progress)."""
    estimator, replicates, seed, detrend, feedthrough, progress = options
    n_samples = sum(u.shape[0] for u, _ in records)
    B = bootstrap_replicates(n_samples) if replicates is None else int(replicates)
    if progress:
        status(f"σ of the {estimator} model: parametric bootstrap, {B} replicates (seed {seed})")
    rows, failed, tried = _replicates(model, records, x0s, refit, B, seed, detrend, feedthrough,
                                      progress)
    info = {"method": "parametric bootstrap", "replicates": len(rows), "failed": failed,
            "seed": int(seed), "estimator": estimator}
    if 2 * failed > tried or len(rows) < 2:
        emit_warning(f"bootstrap σ of the {estimator} model: {failed} of the {tried} replicates "
                     f"tried (of {B}) could not be refitted or brought to the model's states; "
                     "the model is returned without covariance (lower the order)",
                     AccuracyWarning)
        return model
    if failed > FAILED_FRACTION * B:
        emit_warning(f"bootstrap σ of the {estimator} model: {failed} of {B} replicates could not "
                     "be refitted or brought to the model's states; the σ of the other "
                     f"{len(rows)} may be too small (lower the order)", AccuracyWarning)
    ss = model.system
    names = [f"{k}[{i},{j}]" for k, a in zip("ABCD", (ss.A, ss.B, ss.C, ss.D))
             if k != "D" or feedthrough for i in range(a.shape[0]) for j in range(a.shape[1])]
    cov = np.cov(np.asarray(rows), rowvar=False).reshape(len(names), len(names))
    return model.replace(system=ss.with_covariance(0.5 * (cov + cov.T), names),
                         info={**model.info, "covariance": info})


def bootstrapped(model) -> bool:
    """Whether the σ that ``model.system`` carries comes from :func:`bootstrap_covariance`
    (its ``info['covariance']``; any model with ``info`` and ``system``)."""
    cov = (getattr(model, "info", None) or {}).get("covariance")
    return (model.system.uncertainty is not None and isinstance(cov, dict)
            and cov.get("method") == "parametric bootstrap")


def covariance_method(model) -> str | None:
    """How the σ that the state-space ``model.system`` carries was obtained, in words: the
    bootstrap of :func:`bootstrap_covariance` or PEM's (None without σ)."""
    if model.system.uncertainty is None:
        return None
    if bootstrapped(model):
        cov = model.info["covariance"]
        return (f"parametric bootstrap of the {cov['estimator']} estimate, B = "
                f"{cov['replicates']} replicates, seed {cov['seed']}")
    return "PEM: σ² (JᵀJ)⁻¹ at its optimum"
