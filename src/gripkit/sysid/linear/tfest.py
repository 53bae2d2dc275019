"""Continuous-time transfer-function estimation (tfest-like), SISO::

    G(s) = (b_0 s^nz + … + b_nz) / (s^np + a_1 s^{np−1} + … + a_np),   θ = [a_1 … a_np, b_0 … b_nz].

* From an FRF (:class:`~gripkit.sysid.linear.frf.FRF` with σ per line): Sanathanan-Koerner
iterations
  (linear least squares of ``(A(jω)Ĥ − B(jω))/(A_prev(jω) σ)``, frequency scaled to 1 for
  conditioning) give the start; then weighted nonlinear least squares of
  ``(Ĥ_k − G(jω_k))/σ_k`` with the exact Jacobian ``∂G/∂b_i = s^{nz−i}/A``,
  ``∂G/∂a_i = −G s^{np−i}/A``. An FRF of sampled data whose input was held (``dt`` given) is
  compared with G's zero-order-hold equivalent ``G_d(e^{jωT})`` instead (the hold's half-sample
  delay would bias a continuous fit by several σ).
* From time-domain data (``tfest(u, y, ...)``): the model is sampled with a zero-order hold
  between samples (the assumption of MATLAB's iddata, ``InterSample='zoh'``) and the output error
  ``y − ŷ(θ, x0)`` is minimised, x0 the least-squares initial state for the current θ (variable
  projection, as :func:`tfest_records`; a record that starts away from rest, such as a step
  record with its means removed, is not forced to start from rest), starting from the FRF fit
  of an H1 estimate of the data (through the hold: from the better of the stabilised continuous
  fit and the d2c map of a discrete Sanathanan-Koerner fit in z = e^{jωT}, which is exact on
  noise-free data).

Covariance ``σ̂² (JᵀJ)⁻¹`` (σ̂² = residual sum of squares / (N − dim θ − n_poles), the
initial state counted); σ of each coefficient and, for every complex pole pair
p = −ζω_n ± jω_n√(1−ζ²), of the natural frequency ω_n = |p| and damping ζ = −Re p/|p|, by
linearisation (the roots' derivatives with respect to θ by the implicit function theorem:
``∂p/∂a_i = −p^{np−i}/A'(p)``).
"""

from __future__ import annotations

import numpy as np
from scipy import optimize
from scipy import signal as _signal

from ...errors import DataError, IdentificationError, ModelError
from ...lti import StateSpace, TransferFunction
from ..checks import (channel_of, check_dt, check_excitation, check_order, check_output_varies,
                      check_persistent_excitation, io_records, warn_if_operating_point)
from ..scaling import unit_scale
from .frf import FRF, frf
from .linear_model import (LinearModel, as_io_matrix, estimate_x0, fit_per_output, free_run,
                           x0_residual)
from .validation import records_fit

__all__ = ["tfest", "tfest_records", "tfest_frf", "modal_parameters"]


def _check_orders(n_poles, n_zeros):
    n_poles = check_order(n_poles, "poles", 1)
    n_zeros = check_order(n_zeros, "zeros", 0)
    if n_zeros > n_poles:
        raise DataError(f"zeros: expected at most as many zeros as poles ({n_poles}), "
                        f"found {n_zeros}",
                        hint="an improper transfer function cannot be simulated")
    return n_poles, n_zeros


def _check_channels_vary(recs: list, signals: dict, u_offset, y_offset) -> None:
    """An UnidentifiableError naming the channel (its value, the offset added back, in its unit;
    of several records, the record) for an input constant over all records of ``recs`` ((u, y)
    pairs of columns) or an output constant in one of them: a constant input cannot identify G,
    a constant output has nothing to fit and its fit % is undefined, and either one's FRF, the
    start, is zero or undefined (numpy's least squares then failed: 'SVD did not converge')."""
    meta = {**signals, "u_offset": u_offset, "y_offset": y_offset}
    label, offset, unit = channel_of(meta, "input", "u")
    u = recs[0][0][:, 0] if len(recs) == 1 else np.concatenate([u[:, 0] for u, _ in recs])
    check_excitation(u, label if len(recs) == 1 else f"{label} of all {len(recs)} records",
                     offset=offset, unit=unit)
    label, offset, unit = channel_of(meta, "output", "y")
    for i, (_, y) in enumerate(recs):
        check_output_varies(y[:, 0], label if len(recs) == 1 else f"records[{i}] {label}",
                            offset=offset, unit=unit)


def _eval(theta, s, npo, nz):
    a = np.concatenate([[1.0], theta[:npo]])
    b = theta[npo:]
    A = np.polyval(a, s)
    B = np.polyval(b, s)
    return A, B


def _sk(s, H, wgt, npo, nz, iterations=20):
    """Sanathanan-Koerner start on scaled frequencies s (|s| ≤ 1)."""
    Aprev = np.ones_like(s)
    theta = None
    for _ in range(iterations):
        # A(s) H − B(s) = 0 → Σ a_i s^{np−i} H − Σ b_i s^{nz−i} = −s^np H
        cols = ([s ** (npo - i) * H for i in range(1, npo + 1)]
                + [-s ** (nz - i) for i in range(nz + 1)])
        M = np.column_stack(cols) * (wgt / np.abs(Aprev))[:, None]
        rhs = -s ** npo * H * wgt / np.abs(Aprev)
        Mr = np.vstack([M.real, M.imag])
        rr = np.concatenate([rhs.real, rhs.imag])
        th = np.linalg.lstsq(Mr, rr, rcond=None)[0]
        Aprev = _eval(th, s, npo, nz)[0]
        if theta is not None and np.allclose(th, theta, rtol=1e-10, atol=1e-12):
            theta = th
            break
        theta = th
    return theta


def _unscale(theta, ws, npo, nz):
    """Coefficients for s' = s/ws back to s."""
    a = theta[:npo] * ws ** np.arange(1, npo + 1)
    b = theta[npo:] * ws ** (npo - nz + np.arange(nz + 1))
    return np.concatenate([a, b])


def _coefficient_scale(theta, npo):
    """The size of each coefficient for the optimiser's variables ``z = θ/scale``: ``|θ|`` floored
    at 1e-8 of the largest of its group (denominator, numerator), so that the scale follows the
    data's units (the numerator of an output in metres is tiny) and a coefficient near 0 keeps a
    usable one."""
    a = np.abs(np.asarray(theta, dtype=np.float64))
    den, num = a[:npo], a[npo:]
    return np.concatenate([den + 1e-8 * den.max(initial=0.0), num + 1e-8 * num.max(initial=0.0)])


def _stabilise(theta, npo):
    a = np.concatenate([[1.0], theta[:npo]])
    r = np.roots(a)
    if np.any(r.real >= 0):
        r = np.where(r.real >= 0, -np.abs(r.real) - 1e-6 + 1j * r.imag, r)
        theta = theta.copy()
        theta[:npo] = np.real(np.poly(r))[1:]
    return theta


def modal_parameters(den, cov_den=None):
    """Natural frequencies ω_n (rad/s) and damping ratios ζ of the complex pole pairs of a monic
    ``den`` (descending powers), with their σ when ``cov_den`` (covariance of den[1:]) is given."""
    den = np.asarray(den, dtype=np.float64)
    npo = den.size - 1
    r = np.roots(den)
    pairs = r[r.imag > 0]
    wn, zeta = np.abs(pairs), -pairs.real / np.abs(pairs)
    if cov_den is None:
        return wn, zeta, None, None
    dA = np.polyval(np.polyder(den), pairs)
    # ∂p/∂a_i = −p^{np−i}/A'(p)
    Jp = np.stack([-pairs ** (npo - i) / dA for i in range(1, npo + 1)], axis=1)   # (q, np)
    Jwn = np.real(pairs.conj()[:, None] * Jp) / wn[:, None]
    Jre = Jp.real
    Jz = -(Jre * wn[:, None] - pairs.real[:, None] * Jwn) / wn[:, None] ** 2
    s_wn = np.sqrt(np.einsum("qi,ij,qj->q", Jwn, cov_den, Jwn))
    s_z = np.sqrt(np.einsum("qi,ij,qj->q", Jz, cov_den, Jz))
    return wn, zeta, s_wn, s_z


def _covariance(J, s2, what, hint):
    """σ̂² (JᵀJ)⁻¹ from the SVD of J. Noise-free data give σ̂² ≈ 0 and a covariance ≈ 0 (not an
    error); a Jacobian that is singular to working precision (a flat direction) is refused."""
    _, sv, vt = np.linalg.svd(J, full_matrices=False)
    if sv[-1] <= max(J.shape) * np.finfo(float).eps * sv[0]:
        raise IdentificationError(f"tfest: {what} do not determine the coefficients "
                                  "(singular Jacobian, "
                                  f"condition number {sv[0] / max(sv[-1], 1e-300):.3g})", hint=hint)
    return s2 * (vt.T / sv ** 2) @ vt


def _model(theta, cov, npo, nz, *, fit, structure, info, signals, u_offset=None, y_offset=None,
           n=None):
    num = np.concatenate([np.zeros(npo - nz), theta[npo:]])
    den = np.concatenate([[1.0], theta[:npo]])
    names = ([f"den[{i}]" for i in range(1, npo + 1)]
             + [f"num[{npo - nz + i}]" for i in range(nz + 1)])
    g = TransferFunction(num, den, **signals).with_covariance(cov, names)
    wn, z, swn, sz = modal_parameters(den, cov[:npo, :npo])
    info = {**info, "natural_frequency_hz": wn / (2 * np.pi),
            "natural_frequency_hz_std": swn / (2 * np.pi),
            "damping_ratio": z, "damping_ratio_std": sz, "num_std": np.sqrt(np.diag(cov))[npo:],
            "den_std": np.concatenate([[0.0], np.sqrt(np.diag(cov))[:npo]])}
    return (LinearModel(g, structure, fit_percent=fit, u_offset=u_offset, y_offset=y_offset,
                        n_samples=n, info=info))


def tfest_frf(response: FRF, n_poles: int, n_zeros: int, *, dt: float | None = None,
              signals: dict | None = None) -> LinearModel:
    """Fit G(s) to an estimated frequency response (weighted by its σ); see the module docstring.

    ``dt``: the sample time of the data the FRF was estimated from, when their input was held
    between samples (zero-order hold): the model is then compared as its ZOH equivalent
    G_d(e^{jωT}) (the hold's half-sample delay and sinc would otherwise bias the fit), after the
    continuous fit has given the start."""
    npo, nz = _check_orders(n_poles, n_zeros)
    if response.H.shape[1:] != (1, 1):
        raise DataError("tfest: the FRF must be single-input single-output")
    H = response.H[:, 0, 0]
    sd = response.H_std[:, 0, 0]
    # σ = 0: noise-free lines (floor below)
    ok = np.isfinite(H) & np.isfinite(sd) & (response.frequency_hz > 0)
    w = response.w[ok]
    # weights 1/σ with a 0.1 % relative floor: noise-free data have σ ≈ 0 on some lines, and the
    # estimate's own systematic errors (leakage, the hold) are not in σ
    H, sd = H[ok], np.hypot(sd[ok], 1e-3 * np.abs(H[ok]))
    k = npo + nz + 1
    if 2 * w.size <= k:
        raise DataError(f"tfest: {w.size} usable FRF lines cannot determine {k} coefficients",
                        hint="use a finer FRF (more lines) or fewer poles/zeros")
    ws = float(w.max())
    s = 1j * w / ws
    th = _stabilise(_sk(s, H, 1.0 / sd, npo, nz), npo)

    def res(theta):
        A, B = _eval(theta, s, npo, nz)
        r = (H - B / A) / sd
        return np.concatenate([r.real, r.imag])

    def jac(theta):
        A, B = _eval(theta, s, npo, nz)
        G = B / A
        cols = ([G * s ** (npo - i) / A for i in range(1, npo + 1)]
                + [-s ** (nz - i) / A for i in range(nz + 1)])
        J = np.column_stack(cols) / sd[:, None]
        return np.vstack([J.real, J.imag])

    sol = optimize.least_squares(res, th, jac=jac, method="lm", xtol=1e-12, ftol=1e-12)
    T = np.diag(_unscale(np.ones(k), ws, npo, nz))
    # through the zero-order hold, in the scaled coordinates (finite differences)
    if dt is not None:
        z = np.exp(1j * w * float(dt))

        def res_zoh(theta):
            th_ = _unscale(theta, ws, npo, nz)
            if np.any(np.roots(np.concatenate([[1.0], th_[:npo]])).real >= 0):
                return np.full(2 * w.size, 1e6)
            Ad, Bd, Cd, Dd = _simulate_ct(th_, npo, nz, None, float(dt))
            G = (Cd @ np.linalg.solve(z[:, None, None] * np.eye(npo) - Ad,
                                      np.broadcast_to(Bd, (z.size,) + Bd.shape)))
            r = (H - (G[:, 0, 0] + Dd[0, 0])) / sd
            return np.concatenate([r.real, r.imag])

        # start from the better of the continuous fit (stabilised: without the hold's delay in the
        # model, high-σ-weight lines can pull it into the right half-plane) and the exact map of a
        # discrete fit; an unstable start has a flat penalty residual and a zero Jacobian
        starts = [_stabilise(sol.x, npo)]
        exact = _zoh_start(w, H, sd, npo, nz, float(dt))
        if exact is not None:
            starts.append(exact / _unscale(np.ones(k), ws, npo, nz))
        x0 = min(starts, key=lambda x: float(np.sum(res_zoh(x) ** 2)))
        sol = optimize.least_squares(res_zoh, x0, method="lm", xtol=1e-12, ftol=1e-12)
    dof = 2 * w.size - k
    J = sol.jac
    s2 = 2 * sol.cost / dof
    cov_s = _covariance(J, s2, "the FRF", "fewer poles/zeros or a wider frequency band")
    theta = _unscale(sol.x, ws, npo, nz)
    cov = T @ cov_s @ T
    sig = dict(signals or {})
    sig.setdefault("inputs", response.inputs)
    sig.setdefault("outputs", response.outputs)
    return _model(theta, 0.5 * (cov + cov.T), npo, nz, fit=None, structure="tfest",
                  info={"source": f"frf ({response.method}{', zero-order hold' if dt else ''})",
                        "chi2_per_dof": s2}, signals=sig)


def _zoh_start(w, H, sd, npo, nz, dt):
    """Continuous coefficients (unscaled) from a Sanathanan-Koerner fit of the zero-order-hold
    equivalent in z = e^{jωT}: G_d(z) has ``npo`` poles and at most npo − 1 zeros (npo when G is
    biproper), and d2c maps it back to G exactly. None when G_d has no continuous preimage (a
    pole on the negative real axis) or loses a pole to a cancellation."""
    nzd = npo if nz == npo else npo - 1
    thd = _sk(np.exp(1j * w * dt), H, 1.0 / sd, npo, nzd)
    try:
        g = TransferFunction(thd[npo:], np.concatenate([[1.0], thd[:npo]]), dt=dt).d2c()
    except ModelError:
        return None
    den, num = g.denominator(), g.numerator()
    if den.size != npo + 1 or not np.all(np.isfinite(den)):
        return None
    num = np.concatenate([np.zeros(nz + 1), num / den[0]])[-(nz + 1):]
    return _stabilise(np.concatenate([den[1:] / den[0], num]), npo)


def _simulate_ct(theta, npo, nz, u, dt, x0=None):
    a = np.concatenate([[1.0], theta[:npo]])
    d = StateSpace(*_signal.tf2ss(theta[npo:], a)).c2d(dt)
    return d.A, d.B, d.C, d.D


def _scaled_output_error(res, z0, cy):
    """``least_squares`` of the output error ``res(z)`` multiplied by ``cy`` (the power of two
    :func:`~gripkit.sysid.scaling.unit_scale` of the output: exact), its result (``fun``, ``jac``,
    ``cost``) given back for ``res`` itself. scipy's ``gtol`` is absolute (on ‖Jᵀr‖∞): on the
    raw residuals of an output of ~1e-8 (a tip in metres) it ended the fit at its start."""
    sol = optimize.least_squares(lambda z: cy * res(z), z0, method="trf", x_scale="jac",
                                 xtol=1e-10, ftol=1e-10)
    sol.fun, sol.jac, sol.cost = sol.fun / cy, sol.jac / cy, sol.cost / cy / cy
    return sol


def tfest(u, y, n_poles: int, n_zeros: int, *, dt: float | None = None,
          inputs=None, outputs=None, input_units=None, output_units=None, u_offset=None,
          y_offset=None) -> LinearModel:
    """Continuous-time G(s) with ``n_poles`` poles and ``n_zeros`` zeros from sampled data
    (deviation units), zero-order hold between samples; see the module docstring. ``u``, ``y``
    are deviations, the operating point given as ``u_offset``, ``y_offset``; the model's
    simulate/compare/validate then take the record's own values, never these deviations.

    Returns a :class:`LinearModel` whose ``system`` is a continuous
    :class:`gripkit.lti.TransferFunction` with the coefficient covariance, and whose ``info`` has
    ``num_std``, ``den_std``, ``natural_frequency_hz``(``_std``), ``damping_ratio``(``_std``).

    Examples
    --------
    >>> import numpy as np
    >>> from gripkit.lti import TransferFunction
    >>> from gripkit.sysid import tfest
    >>> g = TransferFunction([4.0], [1.0, 0.8, 4.0])
    >>> u = np.random.default_rng(0).standard_normal(4000)
    >>> y = g.c2d(0.05).simulate(u)[:, 0]          # noise-free: the exact answer
    >>> m = tfest(u, y, 2, 0, dt=0.05)
    >>> np.round(m.system.denominator(), 8).tolist()
    [1.0, 0.8, 4.0]
    >>> bool(m.info["den_std"].max() < 1e-10)
    True
    """
    npo, nz = _check_orders(n_poles, n_zeros)
    u = as_io_matrix(u, "input u")
    y = as_io_matrix(y, "output y", u.shape[0])
    if u.shape[1] != 1 or y.shape[1] != 1:
        raise DataError(f"tfest: expected one input and one output, found {u.shape[1]} "
                        f"and {y.shape[1]}",
                        hint="estimate one input-output pair at a time, or use gripkit identify ss")
    step = check_dt(dt)
    N = u.shape[0]
    k = npo + nz + 1
    if N < 10 * k + 64:
        raise DataError(f"tfest: {N} samples are too few for {k} coefficients (need at "
                        f"least {10 * k + 64})",
                        hint="use a longer record or fewer poles/zeros")
    signals = (dict(inputs=inputs, outputs=outputs, input_units=input_units,
                    output_units=output_units))
    _check_channels_vary([(u, y)], signals, u_offset, y_offset)
    check_persistent_excitation(u[:, 0], k, f"tfest ({npo} poles, {nz} zeros: {k} coefficients)")
    if npo > 0:  # its zero-order-hold equivalent is an ARX [npo npo 1] with a constant term
        warn_if_operating_point(u[:, 0], y[:, 0], npo, npo, 1, f"tfest ({npo} poles, {nz} zeros)")
    start = tfest_frf(frf(u, y, dt=step, nperseg=max(64, min(N // 4, 2048))), npo, nz, dt=step)
    th0 = (_stabilise(np.concatenate([start.system.denominator()[1:],
                                      start.system.numerator()[-(nz + 1):]]), npo))
    uu, yy = u, y[:, 0]
    scale = _coefficient_scale(th0, npo)
    cy = unit_scale(yy)  # residuals of unit size (see _scaled_output_error)

    def res(z):
        theta = z * scale
        if np.any(np.roots(np.concatenate([[1.0], theta[:npo]])).real >= 0):
            return np.full(N, 1e3 * (np.abs(yy).max() + 1.0))
        Ad, Bd, Cd, Dd = _simulate_ct(theta, npo, nz, uu, step)
        return x0_residual(Ad, Bd, Cd, Dd, uu, y)[:, 0]

    sol = _scaled_output_error(res, th0 / scale, cy)
    theta = sol.x * scale
    J = sol.jac / scale[None, :]
    dof = N - k - npo
    s2 = 2 * sol.cost / dof
    cov = _covariance(J, s2, "the data", "fewer poles/zeros or a richer input")
    Ad, Bd, Cd, Dd = _simulate_ct(theta, npo, nz, uu, step)
    x0 = estimate_x0(Ad, Bd, Cd, Dd, uu, y)
    fit = fit_per_output(y, free_run(Ad, Bd, Cd, Dd, uu, x0))
    return _model(theta, 0.5 * (cov + cov.T), npo, nz, fit=fit, structure="tfest",
                  info={"source": "time domain (zero-order hold, output error from the "
                                  "least-squares initial state)", "nfev": int(sol.nfev)},
                  signals=signals, u_offset=u_offset, y_offset=y_offset, n=N)


def tfest_records(records, n_poles: int, n_zeros: int, *, dt: float | None = None,
                  inputs=None, outputs=None, input_units=None, output_units=None, u_offset=None,
                  y_offset=None) -> LinearModel:
    """:func:`tfest` of several records at once: ``records`` a list of ``(u, y)`` pairs (one input,
    one output, deviation units around one common operating point). Every record's output error
    ``y_i − ŷ_i(θ, x0_i)`` is taken from its own initial state x0_i, the least-squares one for
    the current θ (variable projection: the output is linear in x0, so each x0_i is solved for
    inside the residual and the Jacobian of the projected residual gives θ's covariance); the
    errors of all records are minimised together, σ̂² = RSS/(Σ N_i − dim θ − R·n). Start: the
    FRF fit of the H1 estimate of the longest record. ``fit_percent``: the free run of all
    records (each from its own x0); ``info['records']``: each record's samples, fit and x0 (in
    the coordinates of the model's zero-order-hold state space, ``tf2ss``)."""
    npo, nz = _check_orders(n_poles, n_zeros)
    recs = io_records(records, siso=True)
    for i, (u, _) in enumerate(recs):
        if u.shape[0] <= npo:
            raise DataError(f"records[{i}]: {u.shape[0]} samples cannot determine its own "
                            f"{npo}-state initial condition", hint="drop the short record")
    step = check_dt(dt)
    N = sum(u.shape[0] for u, _ in recs)
    k = npo + nz + 1
    if N < 10 * k + 64 + len(recs) * npo:
        raise DataError(f"tfest: {N} samples in all are too few for {k} coefficients and "
                        f"{len(recs)} initial states",
                        hint="use longer records or fewer poles/zeros")
    signals = dict(inputs=inputs, outputs=outputs, input_units=input_units,
                   output_units=output_units)
    _check_channels_vary(recs, signals, u_offset, y_offset)
    check_persistent_excitation(np.concatenate([u[:, 0] for u, _ in recs]), k,
                                f"tfest ({npo} poles, {nz} zeros: {k} coefficients)")
    ul, yl = max(recs, key=lambda r: r[0].shape[0])
    start = tfest_frf(frf(ul, yl, dt=step, nperseg=max(64, min(ul.shape[0] // 4, 2048))), npo, nz,
                      dt=step)
    th0 = _stabilise(np.concatenate([start.system.denominator()[1:],
                                     start.system.numerator()[-(nz + 1):]]), npo)
    scale = _coefficient_scale(th0, npo)
    peak = max(float(np.abs(y).max()) for _, y in recs)
    cy = unit_scale(np.array([peak]))  # residuals of unit size (see _scaled_output_error)

    def runs(theta):
        Ad, Bd, Cd, Dd = _simulate_ct(theta, npo, nz, None, step)
        x0s = [estimate_x0(Ad, Bd, Cd, Dd, u, y) for u, y in recs]
        return [free_run(Ad, Bd, Cd, Dd, u, x0)[:, 0] for (u, _), x0 in zip(recs, x0s)], x0s

    def res(z):
        theta = z * scale
        if np.any(np.roots(np.concatenate([[1.0], theta[:npo]])).real >= 0):
            return np.full(N, 1e3 * (peak + 1.0))
        Ad, Bd, Cd, Dd = _simulate_ct(theta, npo, nz, None, step)
        return np.concatenate([x0_residual(Ad, Bd, Cd, Dd, u, y)[:, 0] for u, y in recs])

    sol = _scaled_output_error(res, th0 / scale, cy)
    theta = sol.x * scale
    J = sol.jac / scale[None, :]
    dof = N - k - len(recs) * npo
    cov = _covariance(J, 2 * sol.cost / dof, "the data", "fewer poles/zeros or a richer input")
    yh, x0s = runs(theta)
    ys = [y for _, y in recs]
    yhats = [h[:, None] for h in yh]
    info = {"source": "time domain (zero-order hold, output error from each record's least-squares "
                      "initial state)", "nfev": int(sol.nfev), "n_records": len(recs),
            "records": [{"n_samples": int(y.shape[0]), "fit_percent": fit_per_output(y, h),
                         "x0": x0} for y, h, x0 in zip(ys, yhats, x0s)]}
    return _model(theta, 0.5 * (cov + cov.T), npo, nz, fit=records_fit(ys, yhats).tolist(),
                  structure="tfest", info=info, signals=signals, u_offset=u_offset,
                  y_offset=y_offset, n=N)
