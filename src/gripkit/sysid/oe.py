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
(:mod:`gripkit.sysid._pem`) minimises eq (29) of ``000_8f66dcc7ab06470c.txt``.
"""

from __future__ import annotations

import numpy as np

from ._pem import covariance, is_stable_poly, levenberg_marquardt, stabilize
from ._scaling import in_user_units, unit_scale
from .arx import _arx
from .checks import check_identifiable, checked_problem
from .polynomial import PolynomialModel, check_meta
from .validation import fit_percent, loss_vn

__all__ = ["oe"]


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
       maxiter: int = 100, tol: float = 1e-10, **meta) -> PolynomialModel:
    """Output-error model ``y = B/F u + e`` by prediction-error minimisation.

    Parameters as :func:`gripkit.sysid.arx` with ``nf`` (number of F coefficients after the
    leading 1) in place of ``na``. Returns a :class:`PolynomialModel` with ``structure='oe'``,
    ``A = [1]``, ``F`` and ``F_std``; its poles are the roots of F.
    """
    check_meta(meta, oe)
    u, y, step, nb, nf, nk = checked_problem(u, y, dt, nb=nb, nf=nf, nk=nk)
    cu, cy = unit_scale(u), unit_scale(y)
    return in_user_units(_oe(u * cu, y * cy, nb, nf, nk, step, maxiter, tol, meta), cu, cy)


def _oe(u, y, nb, nf, nk, step, maxiter, tol, meta) -> PolynomialModel:
    """:func:`oe` on checked signals scaled to unit size."""
    from scipy import signal as _sig

    p = nb + nf
    t0 = max(nf, nk + nb - 1)
    label = f"OE [{nb} {nf} {nk}]"
    check_identifiable(u, y, t0 + 10 * p, f"{label} ({p} parameters)")
    theta0 = np.concatenate([_iv_start(u, y, nb, nf, nk, t0), y[t0 - nf:t0][::-1]])
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
            free[:, k] = -_sig.lfilter(B, F, zero_u, zi=_sig.lfiltic(B, F, ek, np.zeros(B.size - 1)))[0]
        return e, np.hstack([J, free])

    def admissible(theta):
        return is_stable_poly(np.concatenate([[1.0], theta[nb:p]]))

    res = levenberg_marquardt(fun, theta0, admissible, maxiter=maxiter, tol=tol, label=label)
    names = tuple(f"b{nk + j}" for j in range(nb)) + tuple(f"f{k}" for k in range(1, nf + 1)) + \
        tuple(f"w(t0-{k})" for k in range(1, nf + 1))
    cov, sigma2, cond = covariance(res, names)
    cov = cov[:p, :p]
    th = res.theta
    B = np.concatenate([np.zeros(nk), th[:nb]])
    F = np.concatenate([[1.0], th[nb:p]])
    e = res.e
    return PolynomialModel(np.ones(1), B, nk, F=F, dt=step, structure="oe", covariance=cov,
                           noise_variance=sigma2, loss=loss_vn(e), fit_percent=fit_percent(yt, yt - e),
                           n_samples=int(n), n_used=int(e.size), residuals=e,
                           info={"method": "prediction-error minimisation (Levenberg-Marquardt), "
                                           "ARX + instrumental-variable start", "iterations": res.iterations,
                                 "converged": res.converged, "cond": cond,
                                 "initial_outputs": th[p:][::-1].tolist()}, **meta)
