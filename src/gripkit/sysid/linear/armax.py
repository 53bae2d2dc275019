"""ARMAX identification by prediction-error minimisation, eqs (24)–(27) of
``000_8f66dcc7ab06470c.txt``.

Model: ``A(q) y(t) = B(q) u(t) + C(q) e(t)``; θ = [a_1..a_na, b_nk..b_{nk+nb-1}, c_1..c_nc] (eq 27).
Predictor: ``C(q) e(t) = A(q) y(t) − B(q) u(t)``, so ``ŷ(t|t−1) = y(t) − e(t)``, with e(t) = 0
before the first predicted sample. Gradients (Ljung, §10.2)::

    ∂e/∂a_i = y(t−i)/C(q),   ∂e/∂b_j = −u(t−j)/C(q),   ∂e/∂c_k = −e(t−k)/C(q)

Initialisation (Hannan–Rissanen): a high-order ARX model gives estimates ê(t) of the innovations;
the linear regression of y(t) on −y(t−i), u(t−j), ê(t−k) gives A, B, C (C reflected into the
unit circle if needed). Then Levenberg–Marquardt (:mod:`gripkit.sysid.linear._pem`) minimises eq
(29).
"""

from __future__ import annotations

import warnings

import numpy as np

from ...errors import UnidentifiableError

from ._pem import covariance, is_stable_poly, levenberg_marquardt, stabilize
from ..scaling import in_user_units, unit_scale
from .arx import (_arx, arx, arx_records, check_record_lengths, checked_records, records_summary,
                  scaled_records)
from ..checks import (channel_of, check_channels_vary, check_dt, check_identifiable, check_order,
                      check_persistent_excitation, checked_problem, require_samples,
                      warn_if_operating_point)
from .polynomial import PolynomialModel, check_meta
from ..regression import qr_solve
from .validation import fit_percent, loss_vn

__all__ = ["armax", "armax_records"]



def _c_stable(theta, start: int) -> bool:
    """The predictor filter 1/C(q) of the ARMAX parameters ``theta`` (C's coefficients from
    ``start`` on) is stable: Levenberg-Marquardt's admissible set."""
    return is_stable_poly(np.concatenate([[1.0], theta[start:]]))


def _armax_names(na: int, nb: int, nc: int, nk: int) -> tuple[str, ...]:
    return (tuple(f"a{i}" for i in range(1, na + 1)) + tuple(f"b{nk + j}" for j in range(nb))
            + tuple(f"c{k}" for k in range(1, nc + 1)))


def _hannan_rissanen(u, y, na, nb, nc, nk) -> np.ndarray:
    n = y.size
    nh = int(min(max(3 * (na + nb + nc), 10), max((n - nk) // 10, nc + 1)))
    ehat = np.zeros(n)
    try:
        long = _arx(u, y, nh, nh, nk, 1.0, warn=False)
    except UnidentifiableError as exc:  # its message would name its parameters (b27 …), not ours
        raise UnidentifiableError(
            f"ARMAX [{na} {nb} {nc} {nk}]: the data do not determine the start values: the long "
            f"ARX [{nh} {nh} {nk}] that estimates the noise sequence e (Hannan-Rissanen) is not "
            f"determined ({exc.message.split(';')[0]}); the input excites too few frequencies",
            hint="excite the system more richly (multisine, PRBS, noise: gripkit.excitation), "
                 "or fit ARX or OE (no noise model to start)") from None
    ehat[max(nh, nk + nh - 1):] = long.estimation_residuals
    t0 = max(na, nk + nb - 1, nc) + max(nh, nk + nh - 1)
    X = _hr_rows(u, y, ehat, na, nb, nc, nk, t0)
    names = tuple(f"p{i}" for i in range(na + nb + nc))
    return qr_solve(X, names, overwrite=True, warn=False).theta


def _hr_rows(u, y, ehat, na, nb, nc, nk, t0) -> np.ndarray:
    """The Hannan-Rissanen regression ``[−y(t−i), u(t−nk−j), ê(t−k) | y(t)]`` for t = t0 … N−1,
    with ê the residuals of a long ARX fit (column-major, for the QR)."""
    n, p = y.size, na + nb + nc
    X = np.empty((n - t0, p + 1), order="F")
    for i in range(na):
        X[:, i] = -y[t0 - 1 - i:n - 1 - i]
    for j in range(nb):
        X[:, na + j] = u[t0 - nk - j:n - nk - j]
    for k in range(nc):
        X[:, na + nb + k] = ehat[t0 - 1 - k:n - 1 - k]
    X[:, p] = y[t0:]
    return X


def armax(u, y, na: int, nb: int, nc: int, nk: int = 1, *, dt: float | None = None,
          maxiter: int = 100, tol: float = 1e-10, progress: bool = False,
          **meta) -> PolynomialModel:
    """ARMAX model ``A y = B u + C e`` by prediction-error minimisation (MATLAB ``armax``
    orders ``[na nb nc nk]``).

    Parameters as :func:`gripkit.sysid.linear.arx` (``u``, ``y`` deviations with the operating
    point as ``u_offset=``/``y_offset=``; the model's methods take the record's own values), plus
    ``nc`` (number of C coefficients after the
    leading 1), ``maxiter`` and ``tol`` of the Levenberg–Marquardt iteration (``progress``: a
    progress bar of its iterations on stderr, as the command line shows it). Returns a
    :class:`PolynomialModel` with ``structure='armax'``, ``C`` and ``C_std``. Warns
    :class:`~gripkit.errors.AccuracyWarning` if the iteration does not converge.
    """
    check_meta(meta, armax)
    u, y, step, na, nb, nc, nk = checked_problem(u, y, dt, na=na, nb=nb, nc=nc, nk=nk)
    check_channels_vary(u, y, meta)  # named in the user's units, before any scaling
    if nc == 0:
        return arx(u, y, na, nb, nk, dt=step, **meta)
    warn_if_operating_point(u, y, na, nb, nk, f"armax [{na} {nb} {nc} {nk}]")
    cu, cy = unit_scale(u), unit_scale(y)
    model = in_user_units(_armax(u * cu, y * cy, na, nb, nc, nk, step, maxiter, tol, meta,
                                 progress), cu, cy)
    return model.replace(estimation_data=(u, y))  # its simulation_fit_percent, on demand


def _armax(u, y, na, nb, nc, nk, step, maxiter, tol, meta, progress=False) -> PolynomialModel:
    """:func:`armax` (nc >= 1) on checked signals scaled to unit size."""
    from scipy import signal as _sig

    p = na + nb + nc
    t0 = max(na, nk + nb - 1)
    label = f"ARMAX [{na} {nb} {nc} {nk}]"
    check_identifiable(u, y, t0 + 10 * p, f"{label} ({p} parameters)")
    check_persistent_excitation(u, nb, f"{label} ({nb} B coefficients)",
                                channel_of(meta, "input", "u")[0])
    theta0 = _hannan_rissanen(u, y, na, nb, nc, nk)
    theta0[na + nb:] = stabilize(np.concatenate([[1.0], theta0[na + nb:]]))[1:]

    ya = (np.column_stack([y[t0 - i:y.size - i] for i in range(1, na + 1)]) if na
          else np.zeros((y.size - t0, 0)))
    ub = np.column_stack([u[t0 - nk - j:u.size - nk - j] for j in range(nb)])
    yt = y[t0:]

    def fun(theta):
        a, b, c = theta[:na], theta[na:na + nb], theta[na + nb:]
        C = np.concatenate([[1.0], c])
        v = yt + ya @ a - ub @ b
        e = _sig.lfilter([1.0], C, v)
        es = np.zeros((e.size, nc))
        for k in range(1, nc + 1):
            es[k:, k - 1] = e[:-k]
        J = _sig.lfilter([1.0], C, np.hstack([ya, -ub, -es]), axis=0)
        return e, J

    res = levenberg_marquardt(fun, theta0, lambda theta: _c_stable(theta, na + nb), maxiter=maxiter,
                              tol=tol, label=label, progress=progress)
    cov, sigma2, cond = covariance(res, _armax_names(na, nb, nc, nk))
    th = res.theta
    A = np.concatenate([[1.0], th[:na]])
    B = np.concatenate([np.zeros(nk), th[na:na + nb]])
    C = np.concatenate([[1.0], th[na + nb:]])
    e = res.e
    return PolynomialModel(A, B, nk, C=C, dt=step, structure="armax", covariance=cov,
                           noise_variance=sigma2,
                           loss=loss_vn(e), fit_percent=fit_percent(yt, yt - e),
                           n_samples=int(y.size),
                           n_used=int(e.size), estimation_residuals=e,
                           info={"method": "prediction-error minimisation (Levenberg-Marquardt), "
                                           "Hannan-Rissanen start", "iterations": res.iterations,
                                 "converged": res.converged, "cond": cond}, **meta)


def armax_records(records, na: int, nb: int, nc: int, nk: int = 1, *, dt: float | None = None,
                  maxiter: int = 100, tol: float = 1e-10, **meta) -> PolynomialModel:
    """:func:`armax` fitted to several records at once (one model, one θ, one σ).

    ``records``: a list of ``(u, y)`` pairs around one common operating point. The prediction
    errors of every record are computed by its own filter, started at its own first predicted
    sample ``start = max(na, nk + nb − 1)`` from its own first samples (e = 0 before, as for one
    record), so nothing crosses from one record into the next; the errors and their Jacobians
    are stacked and Levenberg–Marquardt minimises ``Σ_i Σ_t e_i(t)²``; σ² = Σe²/(Σ M_i − p). The
    start is Hannan–Rissanen on all the records (:func:`~gripkit.sysid.arx_records` of high order
    for the innovations, then the stacked regression rows of every record). ``fit_percent``: the
    one-step fit of all records; ``info['records']``: each record's samples and one-step fit.
    """
    check_meta(meta, armax)
    recs = checked_records(records, "armax_records")
    step = check_dt(dt)
    na, nb, nc, nk = (check_order(na, "na"), check_order(nb, "nb", 1), check_order(nc, "nc"),
                      check_order(nk, "nk"))
    if nc == 0:
        return arx_records(recs, na, nb, nk, dt=step, **meta)
    p = na + nb + nc
    t0 = max(na, nk + nb - 1)
    label = f"ARMAX [{na} {nb} {nc} {nk}]"
    check_record_lengths(recs, t0, label)
    require_samples(sum(y.size - t0 for _, y in recs) + t0, t0 + 10 * p,
                    f"{label} ({p} parameters)")
    scaled, cu, cy = scaled_records(recs)
    theta0 = _hannan_rissanen_records(scaled, na, nb, nc, nk)
    theta0[na + nb:] = stabilize(np.concatenate([[1.0], theta0[na + nb:]]))[1:]
    parts = [_armax_part(u, y, na, nb, nk, t0) for u, y in scaled]

    def fun(theta):
        es, Js = zip(*(_armax_errors(theta, ya, ub, yt, na, nb, nc) for ya, ub, yt in parts))
        return np.concatenate(es), np.vstack(Js)

    res = levenberg_marquardt(fun, theta0, lambda theta: _c_stable(theta, na + nb), maxiter=maxiter,
                              tol=tol, label=label)
    cov, sigma2, cond = covariance(res, _armax_names(na, nb, nc, nk))
    th = res.theta
    ys = [yt for _, _, yt in parts]
    errs = np.split(res.e, np.cumsum([yt.size for yt in ys[:-1]]))
    fit, per_record, starts, e = records_summary(ys, errs, t0)
    info = {"method": "prediction-error minimisation over the records (Levenberg-Marquardt), "
                      "Hannan-Rissanen start", "iterations": res.iterations,
            "converged": res.converged, "cond": cond, "n_records": len(recs),
            "records": per_record, "record_starts": starts}
    model = PolynomialModel(np.concatenate([[1.0], th[:na]]),
                            np.concatenate([np.zeros(nk), th[na:na + nb]]), nk,
                            C=np.concatenate([[1.0], th[na + nb:]]), dt=step, structure="armax",
                            covariance=cov, noise_variance=sigma2, loss=loss_vn(e), fit_percent=fit,
                            n_samples=int(sum(y.size for _, y in recs)), n_used=int(e.size),
                            estimation_residuals=e, info=info, **meta)
    return in_user_units(model, cu, cy)


def _armax_part(u, y, na, nb, nk, t0):
    """One record's fixed regressors: past outputs (M, na), past inputs (M, nb), outputs (M,)."""
    n = y.size
    ya = (np.column_stack([y[t0 - i:n - i] for i in range(1, na + 1)]) if na
          else np.zeros((n - t0, 0)))
    ub = np.column_stack([u[t0 - nk - j:n - nk - j] for j in range(nb)])
    return ya, ub, y[t0:]


def _armax_errors(theta, ya, ub, yt, na, nb, nc):
    """One record's prediction errors ``C e = A y − B u`` (its filter at rest before its first
    predicted sample) and their Jacobian (the ``fun`` of :func:`_armax`, record by record)."""
    from scipy import signal as _sig

    a, b, c = theta[:na], theta[na:na + nb], theta[na + nb:]
    C = np.concatenate([[1.0], c])
    e = _sig.lfilter([1.0], C, yt + ya @ a - ub @ b)
    es = np.zeros((e.size, nc))
    for k in range(1, nc + 1):
        es[k:, k - 1] = e[:-k]
    return e, _sig.lfilter([1.0], C, np.hstack([ya, -ub, -es]), axis=0)


def _hannan_rissanen_records(recs, na, nb, nc, nk) -> np.ndarray:
    """:func:`_hannan_rissanen` on several records: the innovations of each record from one
    high-order ARX of all of them, then the regression rows of every record stacked."""
    nmin = min(y.size for _, y in recs)
    nh = int(min(max(3 * (na + nb + nc), 10), max((nmin - nk) // 10, nc + 1)))
    th = max(nh, nk + nh - 1)
    with warnings.catch_warnings():  # an internal fit: the final model's diagnostics speak
        warnings.simplefilter("ignore")
        high = arx_records(recs, nh, nh, nk)
    t0 = max(na, nk + nb - 1, nc) + th
    p = na + nb + nc
    rows = []
    for (u, y), start in zip(recs, high.info["record_starts"]):
        n = y.size
        if n <= t0:
            continue
        ehat = np.zeros(n)
        ehat[th:] = high.estimation_residuals[start:start + n - th]
        rows.append(_hr_rows(u, y, ehat, na, nb, nc, nk, t0))
    names = tuple(f"p{i}" for i in range(p))
    return qr_solve(np.asfortranarray(np.vstack(rows)), names, overwrite=True, warn=False).theta
