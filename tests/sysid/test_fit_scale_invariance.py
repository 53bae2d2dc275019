"""Scale invariance of the nonlinear least-squares fits tfest (one record and several), fit_motor
with a temperature column and fit_stribeck: the same record with its output multiplied by
K ∈ {1e-9, 1, 1e6} (a MEMS tip in metres, a micro-motor torque in N·m, a force in µN) gives the
K = 1 parameters scaled by K, and their σ likewise, after more than one evaluation of the
residual. scipy's ``least_squares`` ends when ‖Jᵀr‖∞ < gtol = 1e-8, an absolute test: on the raw
residuals of an output of ~1e-8 it ended each of these fits at its start values (tfest: one
evaluation, ζ 38σ off; fit_motor: α′ = 0 ± 0.0002 against 0.004; fit_stribeck: the start values).

Tolerances. K·y is rounded, so each K is a slightly different record, and each fit stops at its
own convergence test (relative ftol/xtol: 1e-10 in tfest, scipy's 1e-8 in the others); the
parameters then agree to about those tolerances (measured: ≤ 2e-10 for tfest, ≤ 1e-8 for the
others), checked at rtol 1e-6. σ comes from the optimiser's forward-difference Jacobian (step
√eps ≈ 1.5e-8 of each scaled parameter): the rounding of the residuals, ~eps/1.5e-8 ≈ 1e-8 of each
entry, is amplified by the conditioning of JᵀJ (measured: ≤ 6e-8 for fit_motor and fit_stribeck,
checked at 1e-6; ≤ 2.3e-6 for tfest's resonance, checked at 1e-5).

The base-parameter structure of a chain with 30 µm links keeps its L² regrouping terms."""

import numpy as np
import pytest

from gripkit import Trajectory
from gripkit.lti import TransferFunction
from gripkit.sysid import fit_motor, fit_stribeck, identify, tfest

SCALES = (1e-9, 1e6)  # each compared with K = 1

# a MEMS resonator: f_n = 2 kHz, ζ = 0.05, sampled at 50 kHz, 10 V random drive, 1 % noise
WN, ZETA, DT = 2 * np.pi * 2000.0, 0.05, 2e-5


def _resonator_record():
    g = TransferFunction([WN * WN], [1.0, 2 * ZETA * WN, WN * WN]).c2d(DT)
    rng = np.random.default_rng(42)
    u = 10 * rng.standard_normal(4000)
    y0 = g.simulate(u)[:, 0]
    return u, y0 + 0.01 * y0.std() * rng.standard_normal(u.size)


def _tf_values(m, K):
    """(den[1:], num/K) and their σ."""
    th = np.r_[m.system.denominator()[1:], m.system.numerator()[-1] / K]
    sd = np.r_[m.info["den_std"][1:], m.info["num_std"] / K]
    return th, sd


@pytest.fixture(scope="module")
def resonator():
    u, y = _resonator_record()
    return u, y, _tf_values(tfest(u, y, 2, 0, dt=DT), 1.0)


def test_tfest_is_scale_invariant(resonator):
    u, y, (th1, sd1) = resonator
    for K in SCALES:
        m = tfest(u, K * y, 2, 0, dt=DT)
        th, sd = _tf_values(m, K)
        assert m.info["nfev"] > 1
        np.testing.assert_allclose(th, th1, rtol=1e-6)
        np.testing.assert_allclose(sd, sd1, rtol=1e-5)


def test_tfest_records_through_identify_is_scale_invariant(resonator):
    """The several-records form, through ``identify(..., "tf")`` (means removed)."""
    u, y, _ = resonator

    def fit(k):
        trs = [Trajectory.uniform(dt=DT, u=u[a:a + 2000], y=k * y[a:a + 2000]) for a in (0, 2000)]
        return identify(trs, "tf", input="u", output="y", poles=2, zeros=0)

    th1, sd1 = _tf_values(fit(1.0), 1.0)
    for K in SCALES:
        m = fit(K)
        th, sd = _tf_values(m, K)
        assert m.info["nfev"] > 1
        np.testing.assert_allclose(th, th1, rtol=1e-6)
        np.testing.assert_allclose(sd, sd1, rtol=1e-5)


def test_tfest_recovers_a_resonance_measured_in_metres():
    """A tip of ~1e-8 m: f_n and ζ within 3σ of the truth (before: one evaluation, the FRF start
    returned, ζ = 0.0508 ± 0.00002 and f_n = 1999.54 ± 0.03 Hz)."""
    u, y = _resonator_record()
    m = tfest(u, 1e-8 * y, 2, 0, dt=DT)
    fn, sfn = m.info["natural_frequency_hz"][0], m.info["natural_frequency_hz_std"][0]
    z, sz = m.info["damping_ratio"][0], m.info["damping_ratio_std"][0]
    assert abs(fn - 2000.0) < 3 * sfn and abs(z - ZETA) < 3 * sz
    assert 0 < sz < 1e-4 and 0 < sfn < 0.1


def _motor_record():
    """eq 5.10 with eq 5.5's temperature factor: c = 2, b₁ = −0.01, b₀ = −0.002, α′ = 0.004/K
    (in units of K), 1 % noise."""
    rng = np.random.default_rng(42)
    n = 400
    u, w, T = rng.uniform(-1, 1, n), rng.uniform(-50, 50, n), np.linspace(20, 80, n)
    tau = (2.0 * u + (-0.01 * np.abs(u) - 0.002) * w) / (1 + 0.004 * (T - 50))
    return u, w, T, tau + 0.01 * tau.std() * rng.standard_normal(n)


def test_fit_motor_with_temperature_is_scale_invariant():
    u, w, T, tau = _motor_record()
    ref = fit_motor(u, w, tau, temperature=T)
    for K in SCALES:
        fit = fit_motor(u, w, K * tau, temperature=T)
        per = {"c_pwm": K, "b_pwm": K, "b_0": K, "alpha_ref": 1.0}
        for k, s in per.items():
            assert fit.values[k] / s == pytest.approx(ref.values[k], rel=1e-6), (K, k)
            assert fit.std[k] / s == pytest.approx(ref.std[k], rel=1e-6), (K, k)
        # and α′ is identified (truth 0.004), not left at its start 0
        assert abs(fit.values["alpha_ref"] - 0.004) < 3 * fit.std["alpha_ref"]
        assert fit.std["alpha_ref"] < 1e-4


def _stribeck_record():
    v = np.r_[-np.logspace(-3, 0, 30)[::-1], np.logspace(-3, 0, 30)]
    f = (np.sign(v) * (1 + 0.5 * np.exp(-(np.abs(v) / 0.02) ** 2)) + 0.5 * v)
    return v, f * (1 + 0.01 * np.random.default_rng(11).standard_normal(60))


@pytest.mark.parametrize("Kv", (1e-6, 1.0, 1e3))
def test_fit_stribeck_is_scale_invariant(Kv):
    """Friction times K and velocity times Kv: F_c, F_s scale by K, v_s by Kv, σ by K/Kv."""
    v, f = _stribeck_record()
    ref = fit_stribeck(v, f, fixed={"cubic": 0.0})
    truth = {"fc": 1.0, "fs": 1.5, "vs": 0.02, "delta": 2.0, "sigma": 0.5}
    for K in (1e-9, 1.0, 1e6) if Kv != 1.0 else SCALES:
        fit = fit_stribeck(Kv * v, K * f, fixed={"cubic": 0.0})
        per = {"fc": K, "fs": K, "vs": Kv, "delta": 1.0, "sigma": K / Kv}
        for k, s in per.items():
            assert fit.values[k] / s == pytest.approx(ref.values[k], rel=1e-6), (K, k)
            assert fit.std[k] / s == pytest.approx(ref.std[k], rel=1e-6), (K, k)
            # the truth (in units of K and Kv) within 3σ: the fit left its start values
            assert abs(fit.values[k] / s - truth[k]) < 3 * fit.std[k] / s, (K, k)


def _micro_chain_base_error(L):
    """max |Y₁ (K φ) − Y φ| / max |Y φ| of a planar three-link chain (horizontal: inertial
    torques only) with links of length L, and the smallest regrouping coefficient."""
    from gripkit.multibody import DHChain
    from gripkit.sysid.rigid_body.dynamics import base_structure

    m = np.full(3, 2.3e3 * L ** 3)  # silicon cubes of side L
    inertia = np.array([np.diag([0.2, 1.0, 1.0]) * mk * L * L / 6 for mk in m])
    chain = DHChain([0, 0, 0], [0, L, L], [0, 0, 0], mass=m, com=np.tile([L / 2, 0, 0], (3, 1)),
                    inertia=inertia, gravity=(0, 0, -9.81))
    st = base_structure(chain)
    rng = np.random.default_rng(1)
    q, qd, qdd = rng.uniform(-3, 3, (50, 3)), rng.normal(size=(50, 3)), rng.normal(size=(50, 3))
    Y = chain.regressor(q, qd, qdd)
    phi = chain.standard_parameters()
    full = Y @ phi
    base = Y[:, :, st.independent] @ (st.matrix @ phi)
    return np.abs(base - full).max() / np.abs(full).max(), np.abs(st.beta[st.beta != 0]).min()


def test_base_structure_of_a_micro_chain_reproduces_the_regressor():
    """Base parameters: Y φ = Y₁ (K φ) exactly (module doc of rigid_body.dynamics), for links of
    10 cm and of 30 µm (a MEMS gripper). The regrouping coefficients are L and L²
    (``Izz_link1 + L²·m_link2 + …``); for 30 µm links L² = 9e-10 used to be zeroed as rounding
    (an absolute threshold of 1e-8 on β), and Y₁ K φ missed 36 % of the torque; at 10 µm the
    rank tests, comparing columns of different units, lost 13 % (now they run on columns scaled
    by the chain's radius of gyration: 1 µm and 10 m links as well)."""
    for L in (10.0, 0.1, 3e-5, 1e-5, 1e-6):
        err, smallest = _micro_chain_base_error(L)
        assert err < 1e-12, L
        assert smallest == pytest.approx(min(L, L * L), rel=1e-9), L  # L² below 1 m, L above
