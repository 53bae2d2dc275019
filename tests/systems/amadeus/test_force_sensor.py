"""Six-bridge fingertip force sensor: eqs 9-14, calibration, WLS fusion, Kalman filter
(000_8f66dcc7ab06470c.txt §IV-A)."""

import math

import numpy as np
import pytest

from gripkit.errors import DataError, UnidentifiableError
from gripkit.estimation import fuse, fused_variance
from gripkit.systems.amadeus import (ForceDynamics, ForceKalmanFilter, calibrate_force_sensor,
                                     estimate_force)
from gripkit.systems.amadeus.parameters import force_plant
from gripkit.systems.amadeus.strain_gauge_sensor import StrainGaugeSensor, single_bridge_estimates

S = StrainGaugeSensor()


def test_readings_follow_eqs_9_to_14():
    K, (p1, p2), l = S.K, S.phi, S.beam_length
    fx, fy, fz = 0.7, -1.3, 2.1
    R = S.readings(np.array([fx, fy, fz]))
    c1, c2, s1, s2 = math.cos(p1), math.cos(p2), math.sin(p1), math.sin(p2)
    expect = [K[0] * l * fz, K[1] * l * (1 + math.cos(p2 - p1)) * fz, K[2] * l * (1 + c1 + c2) * fz,
              K[3] * l * (c2 * fy - s2 * fx), K[4] * l * ((c1 + c2) * fy - s1 * fx),
              K[5] * l * (1 + c1 + c2) * fy]
    np.testing.assert_allclose(R, expect, rtol=1e-14)


@pytest.fixture(scope="module")
def calibration():
    rng = np.random.default_rng(11)
    levels = np.array([-4.0, -2.0, -1.0, 1.0, 2.0, 4.0])
    loads = [np.eye(3)[ax] * lv for ax in range(3) for lv in levels for _ in range(40)]
    loads += list(rng.uniform(-4, 4, (500, 3)))
    F = np.array(loads)
    off = rng.normal(0, 0.01, 6)
    R = S.simulate(F, rng) + off
    return calibrate_force_sensor(F, R, beam_length=S.beam_length), off


def test_calibration_recovers_K_within_one_percent(calibration):
    """Recovery of K1..K6 (and φ1, φ2, offsets, eq-19 noise) from noisy known-load data
    (signal-proportional noise with Table I's σ²_N, 1 mV floor): within 1 %, with honest standard
    errors (|error| < 4 std) and χ²/dof ≈ 1."""
    cal, off = calibration
    err = cal.K / S.K - 1
    assert np.all(np.abs(err) < 0.01), err
    assert np.all(np.abs(cal.K - S.K) < 4 * cal.K_std)
    assert np.all(np.abs(np.degrees(np.array(cal.phi) - S.phi)) < 0.5)
    assert np.all(np.abs(np.array(cal.phi) - S.phi) < 4 * np.array(cal.phi_std))
    np.testing.assert_allclose(cal.offsets, off, atol=1e-3)
    assert abs(cal.chi2_dof - 1) < 0.1
    assert np.all(np.abs(cal.sigma_n2 - S.sigma_n2) < 4 * cal.sigma_n2_std)
    assert np.abs(cal.cross_talk_z).max() < 5


def test_calibration_refuses_uninformative_loads():
    rng = np.random.default_rng(0)
    F = np.column_stack([np.zeros(60), np.zeros(60), rng.uniform(1, 4, 60)])
    with pytest.raises(UnidentifiableError, match="three force axes"):
        calibrate_force_sensor(F, S.simulate(F, rng), beam_length=S.beam_length)
    F2 = np.column_stack([np.zeros(60), rng.uniform(-3, 3, 60), rng.uniform(-3, 3, 60)])
    with pytest.raises(UnidentifiableError):
        calibrate_force_sensor(F2, S.simulate(F2, rng), beam_length=S.beam_length, offsets=False)
    R = S.simulate(F, rng)
    R[3, 2] = np.nan
    with pytest.raises(DataError, match="NaN"):
        calibrate_force_sensor(F, R, beam_length=S.beam_length)


@pytest.fixture(scope="module")
def static_record():
    rng = np.random.default_rng(5)
    f0 = np.array([0.4, 2.0, 3.0])
    R = S.simulate(np.tile(f0, (30000, 1)), rng)
    return f0, R


def test_fused_force_variance_below_singles_and_near_theory(static_record):
    """Synthetic six-bridge data with signal-proportional noise (eq 19): the fused f_z variance is
    below every single combination's (R1, R2, R3 alone) and within 20 % of eq 18's theory
    1/Σ 1/σ_i² (σ_i² = f_z² σ²_Ni + floor² / sensitivity²)."""
    f0, R = static_record
    est = estimate_force(R, S)
    single = single_bridge_estimates(R, S.H)[:, :3]
    H = S.H
    sens = np.array([H[0, 2], H[1, 2], H[2, 2]])
    theory = fused_variance(f0[2] ** 2 * S.sigma_n2[:3] + (S.noise_floor / sens) ** 2)
    fused = est.force[:, 2].var()
    assert np.all(fused < single.var(0))
    assert abs(fused / theory - 1) < 0.2
    assert abs(fused / theory - 1) < 0.05  # in fact much closer
    # the WLS covariance predicts the scatter, and the estimate is unbiased
    np.testing.assert_allclose(est.covariance.mean(0).diagonal(), est.force.var(0), rtol=0.05)
    assert np.all(np.abs(est.force.mean(0) - f0) < 4 * est.std.mean(0) / math.sqrt(R.shape[0]))
    assert est.chi2.mean() == pytest.approx(3.0, rel=0.05)


def test_wls_is_fusion_for_one_component(static_record):
    """With given variances, the WLS f_z equals fuse() of the three single-bridge estimates (eq
    16-18
    for K = 3) — the z bridges see nothing else."""
    f0, R = static_record
    V = np.tile(np.array([1e-4, 2e-4, 3e-4, 1e-4, 1e-4, 1e-4]), (200, 1))
    est = estimate_force(R[:200], S, variances=V)
    single = single_bridge_estimates(R[:200], S.H)[:, :3]
    H = S.H
    sens = np.array([H[0, 2], H[1, 2], H[2, 2]])
    e, v = fuse(single.T, (V[0, :3] / sens ** 2)[:, None])
    np.testing.assert_allclose(est.force[:, 2], e, rtol=1e-10)
    np.testing.assert_allclose(est.covariance[:, 2, 2], v, rtol=1e-10)


def test_faulty_bridge_shows_in_chi2(static_record):
    """A bridge reading 0.5 V off (R1 ≈ 0.36 V) is flagged by the χ²(3) test at the 0.1 % level in
    every sample, while healthy samples pass at about that rate."""
    f0, R = static_record
    bad = R[:200].copy()
    bad[:, 0] += 0.5
    crit = 16.27  # χ²(3) 0.999 quantile
    assert (estimate_force(bad, S).chi2 > crit).mean() == 1.0
    assert (estimate_force(R[:2000], S).chi2 > crit).mean() < 0.01
    with pytest.raises(DataError, match="NaN"):
        estimate_force(np.full((2, 6), np.nan), S)


def _joint_kf(sensor, dyn, Z, U, x, P):
    """Reference: textbook Kalman filter with the joint 6-measurement update (numpy inverse)."""
    H = sensor.H @ dyn.C
    out = []
    for k in range(Z.shape[0]):
        r = H @ x
        Rm = np.diag(sensor.sigma_n2 * r * r + sensor.noise_floor ** 2)
        Sm = H @ P @ H.T + Rm
        K = P @ H.T @ np.linalg.inv(Sm)
        x = x + K @ (Z[k] - H @ x)
        P = (np.eye(len(x)) - K @ H) @ P
        out.append(dyn.C @ x)
        x = dyn.A @ x + dyn.B @ U[k]
        P = dyn.A @ P @ dyn.A.T + dyn.Q
    return np.array(out)


def test_kalman_sequential_update_equals_joint_update():
    """Independent measurement noise: the kernel's scalar sequential updates equal the joint
    update."""
    rng = np.random.default_rng(1)
    plant, _ = force_plant()
    dyn = ForceDynamics.from_plant(plant, axis=2, q_disturbance=5.0, q_other=2.0)
    u = 0.05 * np.sin(np.arange(300) * 0.05)[:, None]
    f = np.column_stack([np.full(300, 0.3), np.full(300, 0.8), 2.0 + plant.simulate(u[:, 0])])
    Z = S.simulate(f, rng)
    x0 = np.zeros(dyn.n_states)
    P0 = np.eye(dyn.n_states)
    kf = ForceKalmanFilter(S, dyn, x0=x0, P0=P0)
    got = kf.run(Z, u).force
    ref = _joint_kf(S, dyn, Z, u, x0.copy(), P0.copy())
    np.testing.assert_allclose(got, ref, rtol=1e-8, atol=1e-10)


def test_kalman_filter_is_honest_and_beats_per_sample_wls():
    """On a random-walk force: mean NEES ≈ 3 (the covariance is honest), mean NIS ≈ 6, and the
    RMS error is below the per-sample WLS's; step() equals run()."""
    rng = np.random.default_rng(4)
    dt, N = 0.005, 6000
    q = np.array([2.0, 2.0, 5.0])
    f = np.cumsum(rng.standard_normal((N, 3)) * np.sqrt(q * dt), axis=0) + [0.5, 1.0, 2.0]
    Z = S.simulate(f, rng)
    kf = (ForceKalmanFilter(S, ForceDynamics.random_walk(q, dt), x0=[0.5, 1.0, 2.0],
                            P0=np.eye(3) * 0.01))
    r = kf.run(Z)
    e = r.force - f
    nees = np.einsum("ni,nij,nj->n", e, np.linalg.inv(r.covariance), e)
    assert nees[100:].mean() == pytest.approx(3.0, rel=0.1)
    assert r.nis[100:].mean() == pytest.approx(6.0, rel=0.1)
    wls = estimate_force(Z, S)
    assert np.all(np.sqrt((e ** 2).mean(0)) < 0.7 * np.sqrt(((wls.force - f) ** 2).mean(0)))
    kf2 = (ForceKalmanFilter(S, ForceDynamics.random_walk(q, dt), x0=[0.5, 1.0, 2.0],
                             P0=np.eye(3) * 0.01))
    steps = np.array([kf2.step(Z[k])[0] for k in range(100)])
    np.testing.assert_array_equal(steps, r.force[:100])


def test_plant_model_kalman_filter_uses_the_valve_command():
    """In a control loop the identified force model (driven by the valve command) predicts the
    force:
    lower error than a random walk of the same disturbance intensity."""
    rng = np.random.default_rng(7)
    plant, _ = force_plant()
    N = 2000
    u = 0.08 * np.sign(np.sin(np.arange(N) * 2 * np.pi / 200))
    f = np.column_stack([np.zeros(N), np.full(N, 0.5), 3.0 + plant.simulate(u)])
    Z = S.simulate(f, rng)
    dyn = ForceDynamics.from_plant(plant, axis=2, q_disturbance=0.5, q_other=0.5)
    x0 = np.zeros(dyn.n_states)
    x0[-3] = 3.0
    x0[-1] = 0.5
    model = ForceKalmanFilter(S, dyn, x0=x0, P0=np.eye(dyn.n_states) * 0.01).run(Z, u[:, None])
    rw = ForceKalmanFilter(S, ForceDynamics.random_walk([0.5, 0.5, 0.5], plant.dt),
                           x0=[0.0, 0.5, 3.0], P0=np.eye(3) * 0.01).run(Z)
    err_m = np.sqrt(((model.force[:, 2] - f[:, 2]) ** 2).mean())
    err_r = np.sqrt(((rw.force[:, 2] - f[:, 2]) ** 2).mean())
    assert err_m < 0.5 * err_r
