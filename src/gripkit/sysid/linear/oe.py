"""Output-error identification by prediction-error minimisation.

Model: ``y(t) = B(q)/F(q) u(t) + e(t)``, θ = [b_nk..b_{nk+nb-1}, f_1..f_nf] (MATLAB ``oe`` orders
``[nb nf nk]``). The predictor is the free-run simulation ``w = B/F u``; its ``nf`` past outputs
``w(t0−1) … w(t0−nf)`` at the first predicted sample are estimated with the parameters (they
start from the measured outputs; never silently zero), so the start-up transient does not bias
the estimate. Gradients::

    ∂e/∂b_j = −u(t−j)/F(q),   ∂e/∂f_k = w(t−k)/F(q),   ∂e/∂w(t0−k) = −(free response)

Initialisation: an ARX ``[nf nb nk]`` estimate, refined by one instrumental-variable step whose
instruments are the ARX model's simulated output (Söderström & Stoica, *System Identification*,
§8), with F reflected into the unit circle if needed; then Levenberg–Marquardt
(:mod:`gripkit.sysid.linear._pem`) minimises eq (29) of ``000_8f66dcc7ab06470c.txt``.
"""

from __future__ import annotations

import warnings

import numpy as np

from ...errors import UnidentifiableError

from ._pem import covariance, is_stable_poly, levenberg_marquardt, stabilize
from ..scaling import in_user_units, unit_scale
from .arx import (_arx, arx_records, check_record_lengths, checked_records, records_summary,
                  scaled_records)
from ..checks import (channel_of, check_channels_vary, check_dt, check_identifiable, check_order,
                      check_persistent_excitation, checked_problem, require_samples,
                      warn_if_operating_point)
from .polynomial import PolynomialModel, check_meta
from .validation import fit_percent, loss_vn

__all__ = ["oe", "oe_records"]


def _iv_start(u, y, nb, nf, nk, t0) -> np.ndarray:
    """ARX [nf nb nk] then one instrumental-variable step; returns θ = [b, f]."""
    from scipy import signal as _sig

    m0 = _arx(u, y, nf, nb, nk, 1.0, warn=False, keep_residuals=False)
    F0 = stabilize(m0.A)
    theta = np.concatenate([m0.B[nk:], F0[1:]])
    if nf == 0:
        return theta
    x = _sig.lfilter(m0.B, F0, u)
    n = y.size
    phi = np.column_stack([u[t0 - nk - j:n - nk - j] for j in range(nb)] +
                          [-y[t0 - k:n - k] for k in range(1, nf + 1)])
    zeta = np.column_stack([u[t0 - nk - j:n - nk - j] for j in range(nb)] +
                           [-x[t0 - k:n - k] for k in range(1, nf + 1)])
    try:
        th_iv = np.linalg.solve(zeta.T @ phi, zeta.T @ y[t0:])
    except np.linalg.LinAlgError:
        return theta
    if np.all(np.isfinite(th_iv)) and is_stable_poly(np.concatenate([[1.0], th_iv[nb:]])):
        return th_iv
    return theta


def oe(u, y, nb: int, nf: int, nk: int = 1, *, dt: float | None = None,
       maxiter: int = 100, tol: float = 1e-10, progress: bool = False,
       **meta) -> PolynomialModel:
    """Output-error model ``y = B/F u + e`` by prediction-error minimisation.

    Parameters as :func:`gripkit.sysid.linear.arx` (``u``, ``y`` deviations with the operating
    point as ``u_offset=``/``y_offset=``; the model's methods take the record's own values) with
    ``nf`` (number of F coefficients after the
    leading 1) in place of ``na``. Returns a :class:`PolynomialModel` with ``structure='oe'``,
    ``A = [1]``, ``F`` and ``F_std``; its poles are the roots of F. ``progress``: a progress
    bar of the Levenberg–Marquardt iterations on stderr.
    """
    check_meta(meta, oe)
    u, y, step, nb, nf, nk = checked_problem(u, y, dt, nb=nb, nf=nf, nk=nk)
    check_channels_vary(u, y, meta)  # named in the user's units, before any scaling
    warn_if_operating_point(u, y, nf, nb, nk, f"oe [{nb} {nf} {nk}]")  # as ARX, na = nf
    cu, cy = unit_scale(u), unit_scale(y)
    model = in_user_units(_oe(u * cu, y * cy, nb, nf, nk, step, maxiter, tol, meta, progress),
                          cu, cy)
    return model.replace(estimation_data=(u, y))  # its simulation_fit_percent, on demand


def _oe(u, y, nb, nf, nk, step, maxiter, tol, meta, progress=False) -> PolynomialModel:
    """:func:`oe` on checked signals scaled to unit size."""
    from scipy import signal as _sig

    p = nb + nf
    t0 = max(nf, nk + nb - 1)
    label = f"OE [{nb} {nf} {nk}]"
    check_identifiable(u, y, t0 + 10 * p, f"{label} ({p} parameters)")
    check_persistent_excitation(u, nb, f"{label} ({nb} B coefficients)",
                                channel_of(meta, "input", "u")[0])
    try:
        start = _iv_start(u, y, nb, nf, nk, t0)
    except UnidentifiableError as exc:  # the start's ARX names its a1 … (our f1 …)
        raise UnidentifiableError(
            f"{label}: the data do not determine the start values: the ARX [{nf} {nb} {nk}] that "
            f"starts the fit is not determined ({exc.message.split(';')[0]}, its a_k standing "
            f"for F's f_k)", hint=exc.hint) from None
    theta0 = np.concatenate([start, y[t0 - nf:t0][::-1]])
    n = y.size
    ub = np.column_stack([u[t0 - nk - j:n - nk - j] for j in range(nb)])
    yt = y[t0:]
    u_past = u[:t0]
    zero_u = np.zeros(n - t0)

    def fun(theta):
        b, f, z = theta[:nb], theta[nb:p], theta[p:]  # z = w(t0-1), ..., w(t0-nf)
        B = np.concatenate([np.zeros(nk), b])
        F = np.concatenate([[1.0], f])
        zi = _sig.lfiltic(B, F, z, u_past[::-1][:B.size - 1])
        w = _sig.lfilter(B, F, u[t0:], zi=zi)[0] if zi.size else _sig.lfilter(B, F, u[t0:])
        e = yt - w
        wext = np.concatenate([z[::-1], w])
        cols = [-ub] + [wext[nf - k:nf - k + w.size, None] for k in range(1, nf + 1)]
        J = _sig.lfilter([1.0], F, np.hstack(cols), axis=0)
        free = np.empty((w.size, nf))
        for k in range(nf):  # ∂e/∂z_k = −(free response of the k-th past output)
            ek = np.zeros(nf)
            ek[k] = 1.0
            free[:, k] = (-_sig.lfilter(B, F, zero_u,
                                        zi=_sig.lfiltic(B, F, ek, np.zeros(B.size - 1)))[0])
        return e, np.hstack([J, free])

    def admissible(theta):
        return is_stable_poly(np.concatenate([[1.0], theta[nb:p]]))

    res = levenberg_marquardt(fun, theta0, admissible, maxiter=maxiter, tol=tol, label=label,
                              progress=progress)
    names = tuple(f"b{nk + j}" for j in range(nb)) + tuple(f"f{k}" for k in range(1, nf + 1)) + \
        tuple(f"w(t0-{k})" for k in range(1, nf + 1))
    cov, sigma2, cond = covariance(res, names)
    cov = cov[:p, :p]
    th = res.theta
    B = np.concatenate([np.zeros(nk), th[:nb]])
    F = np.concatenate([[1.0], th[nb:p]])
    e = res.e
    return PolynomialModel(np.ones(1), B, nk, F=F, dt=step, structure="oe", covariance=cov,
                           noise_variance=sigma2, loss=loss_vn(e),
                           fit_percent=fit_percent(yt, yt - e),
                           n_samples=int(n), n_used=int(e.size), estimation_residuals=e,
                           info={"method": "prediction-error minimisation (Levenberg-Marquardt), "
                                           "ARX + instrumental-variable start",
                                           "iterations": res.iterations,
                                 "converged": res.converged, "cond": cond,
                                 "initial_outputs": th[p:][::-1].tolist()}, **meta)


def oe_records(records, nb: int, nf: int, nk: int = 1, *, dt: float | None = None,
               maxiter: int = 100, tol: float = 1e-10, **meta) -> PolynomialModel:
    """:func:`oe` fitted to several records at once (one B and F, one σ).

    ``records``: a list of ``(u, y)`` pairs around one common operating point. Every record's
    simulation ``w_i = B/F u_i`` starts at its own first predicted sample ``start =
    max(nf, nk + nb − 1)`` from its own ``nf`` past outputs, estimated with the parameters (one
    set of initial outputs per record, started from that record's measured outputs), so no
    transient crosses from one record into the next. The errors and Jacobians of all records
    are stacked; Levenberg–Marquardt minimises ``Σ_i Σ_t e_i(t)²``; σ² = Σe²/(Σ M_i − p − R·nf)
    (R records: every estimated initial output counts, as for one record). The start is an ARX
    ``[nf nb nk]`` of all the records (:func:`~gripkit.sysid.arx_records`) and one pooled
    instrumental-variable step. ``info['records']``: each record's samples, one-step fit and
    estimated initial outputs.
    """
    check_meta(meta, oe)
    recs = checked_records(records, "oe_records")
    step = check_dt(dt)
    nb, nf, nk = check_order(nb, "nb", 1), check_order(nf, "nf"), check_order(nk, "nk")
    p = nb + nf
    t0 = max(nf, nk + nb - 1)
    label = f"OE [{nb} {nf} {nk}]"
    check_record_lengths(recs, t0, label)
    R = len(recs)
    require_samples(sum(y.size - t0 for _, y in recs) + t0, t0 + 10 * p + R * nf,
                    f"{label} ({p} parameters, {nf} initial outputs per record)")
    scaled, cu, cy = scaled_records(recs)
    z0 = [y[t0 - nf:t0][::-1] for _, y in scaled]
    theta0 = np.concatenate([_iv_start_records(scaled, nb, nf, nk, t0), *z0])

    def fun(theta):
        es, Js, frees = [], [], []
        for i, (u, y) in enumerate(scaled):
            e, J, free = _oe_errors(np.concatenate([theta[:p], theta[p + i * nf:p + (i + 1) * nf]]),
                                    u, y, nb, nf, nk, t0)
            es.append(e)
            Js.append(J)
            frees.append(free)
        # the parameters' columns for every record, each record's initial outputs its own block
        Jz = np.zeros((sum(e.size for e in es), R * nf))
        row = 0
        for i, free in enumerate(frees):
            Jz[row:row + free.shape[0], i * nf:(i + 1) * nf] = free
            row += free.shape[0]
        return np.concatenate(es), np.hstack([np.vstack(Js), Jz])

    def admissible(theta):
        return is_stable_poly(np.concatenate([[1.0], theta[nb:p]]))

    res = levenberg_marquardt(fun, theta0, admissible, maxiter=maxiter, tol=tol, label=label)
    names = tuple(f"b{nk + j}" for j in range(nb)) + tuple(f"f{k}" for k in range(1, nf + 1)) + \
        tuple(f"record {i}: w(t0-{k})" for i in range(R) for k in range(1, nf + 1))
    cov, sigma2, cond = covariance(res, names)
    th = res.theta
    ys = [y[t0:] for _, y in scaled]
    errs = np.split(res.e, np.cumsum([yt.size for yt in ys[:-1]]))
    fit, per_record, starts, e = records_summary(ys, errs, t0)
    for i, rec in enumerate(per_record):  # in the record's units
        rec["initial_outputs"] = (th[p + i * nf:p + (i + 1) * nf][::-1] / cy).tolist()
    info = {"method": "prediction-error minimisation over the records (Levenberg-Marquardt), "
                      "ARX + instrumental-variable start", "iterations": res.iterations,
            "converged": res.converged, "cond": cond, "n_records": R, "records": per_record,
            "record_starts": starts}
    model = PolynomialModel(np.ones(1), np.concatenate([np.zeros(nk), th[:nb]]), nk,
                            F=np.concatenate([[1.0], th[nb:p]]), dt=step, structure="oe",
                            covariance=cov[:p, :p], noise_variance=sigma2, loss=loss_vn(e),
                            fit_percent=fit, n_samples=int(sum(y.size for _, y in recs)),
                            n_used=int(e.size), estimation_residuals=e,
                            info=info, **meta)
    return in_user_units(model, cu, cy)


def _oe_errors(theta, u, y, nb, nf, nk, t0):
    """One record's simulation errors ``e = y − B/F u`` from its initial outputs ``theta[p:]``
    with their Jacobians: (e, ∂e/∂[b, f], ∂e/∂(initial outputs)) (the ``fun`` of :func:`_oe`)."""
    from scipy import signal as _sig

    p = nb + nf
    n = y.size
    b, f, z = theta[:nb], theta[nb:p], theta[p:]  # z = w(t0-1), ..., w(t0-nf)
    B = np.concatenate([np.zeros(nk), b])
    F = np.concatenate([[1.0], f])
    zi = _sig.lfiltic(B, F, z, u[:t0][::-1][:B.size - 1])
    w = _sig.lfilter(B, F, u[t0:], zi=zi)[0] if zi.size else _sig.lfilter(B, F, u[t0:])
    ub = np.column_stack([u[t0 - nk - j:n - nk - j] for j in range(nb)])
    wext = np.concatenate([z[::-1], w])
    cols = [-ub] + [wext[nf - k:nf - k + w.size, None] for k in range(1, nf + 1)]
    J = _sig.lfilter([1.0], F, np.hstack(cols), axis=0)
    free = np.empty((w.size, nf))
    zero_u = np.zeros(n - t0)
    for k in range(nf):  # ∂e/∂z_k = −(free response of the k-th past output)
        ek = np.zeros(nf)
        ek[k] = 1.0
        free[:, k] = -_sig.lfilter(B, F, zero_u, zi=_sig.lfiltic(B, F, ek, np.zeros(B.size - 1)))[0]
    return y[t0:] - w, J, free


def _iv_start_records(recs, nb, nf, nk, t0) -> np.ndarray:
    """:func:`_iv_start` on several records: one ARX [nf nb nk] of all of them, then one
    instrumental-variable step on the stacked rows of every record (each record's instruments
    simulated from rest)."""
    from scipy import signal as _sig

    with warnings.catch_warnings():  # an internal fit: the final model's diagnostics speak
        warnings.simplefilter("ignore")
        m0 = arx_records(recs, nf, nb, nk)
    F0 = stabilize(m0.A)
    theta = np.concatenate([m0.B[nk:], F0[1:]])
    if nf == 0:
        return theta
    phis, zetas, ys = [], [], []
    for u, y in recs:
        n = y.size
        x = _sig.lfilter(m0.B, F0, u)
        past_u = [u[t0 - nk - j:n - nk - j] for j in range(nb)]
        phis.append(np.column_stack(past_u + [-y[t0 - k:n - k] for k in range(1, nf + 1)]))
        zetas.append(np.column_stack(past_u + [-x[t0 - k:n - k] for k in range(1, nf + 1)]))
        ys.append(y[t0:])
    phi, zeta = np.vstack(phis), np.vstack(zetas)
    try:
        th_iv = np.linalg.solve(zeta.T @ phi, zeta.T @ np.concatenate(ys))
    except np.linalg.LinAlgError:
        return theta
    if np.all(np.isfinite(th_iv)) and is_stable_poly(np.concatenate([[1.0], th_iv[nb:]])):
        return th_iv
    return theta
