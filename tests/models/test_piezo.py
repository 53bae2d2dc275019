"""Piezoelectric bending actuator (gripkit.models.piezo, eqs 2-4 of ``001_0b92a7da96e7aa46.txt``):
the static compliance block is an Euler-Bernoulli cantilever's, D(s) is exactly discretised, and
without hysteresis the DC gain from voltage to tip deflection is d_p."""

import numpy as np
import pytest
from scipy import signal

from gripkit.models import PiezoActuator
from gripkit.models.hysteresis import bouc_wen_response
from gripkit.models.piezo import actuator_state_space

#: Table II, left finger (λ read in µm/V, here in m/V)
BW = dict(d_p=0.77e-6, lam=0.43e-6, beta=0.108, gamma=7.5e-3)


def test_actuator_compliance_block_is_a_cantilever():
    """Eq 4 in statics: a tip force F bends by s_p F and turns by (3/2L_a) s_p F; a moment M bends
    by (3/2L_a) s_p M and turns by (3/L_a²) s_p M (Euler-Bernoulli cantilever, s_p = L³/3EI);
    free bending turns the tip by 2y/L_a (constant curvature)."""
    act = PiezoActuator()
    s_p, L_a = 9.1e-4, 15e-3
    n = 4000
    z0 = np.zeros(n)
    r = act.simulate({"U": z0, "F_A": np.full(n, 1e-4), "M_A": z0}, dt=5e-5)
    assert r["y_A"][-1] == pytest.approx(-s_p * 1e-4, rel=1e-6)
    assert r["alpha_A"][-1] == pytest.approx(-1.5 / L_a * s_p * 1e-4, rel=1e-6)
    r = act.simulate({"U": z0, "F_A": z0, "M_A": np.full(n, 1e-6)}, dt=5e-5)
    assert r["y_A"][-1] == pytest.approx(-1.5 / L_a * s_p * 1e-6, rel=1e-6)
    assert r["alpha_A"][-1] == pytest.approx(-3 / L_a**2 * s_p * 1e-6, rel=1e-6)
    r = act.simulate({"U": np.full(n, 30.0), "F_A": z0, "M_A": z0}, dt=5e-5)
    assert r["alpha_A"][-1] == pytest.approx(2 / L_a * r["y_A"][-1], rel=1e-9)


def test_d_s_step_response_matches_scipy():
    """D(s) = 1/(a s² + b s + 1) (eq 4, Table II a, b): the actuator's response to a held
    d_p U − H equals scipy.signal's ZOH step response of D."""
    act = PiezoActuator(loads=False)
    U = np.concatenate([[0.0], np.full(399, 50.0)])
    y = act.simulate(U, dt=5e-5)["y_A"]
    W = 0.77e-6 * 50 - bouc_wen_response(U, **BW)[1][-1]
    dsys = signal.cont2discrete(([1.0], [2.5e-8, 8e-5, 1.0]), 5e-5, method="zoh")
    _, ys = signal.dstep(dsys, n=399)
    np.testing.assert_allclose(y[1:], W * ys[0][:, 0], rtol=1e-9, atol=1e-15)


def test_dc_gain_without_hysteresis_is_d_p():
    """λ = 0 removes the hysteresis: the static gain −C A⁻¹ B of the linear part is [1, 2/L_a]
    from W = d_p U, so 20 V held gives y_A → 20 d_p and α_A → 40 d_p / L_a; the mode is
    ω_n = 1/√a, ζ = b ω_n/2."""
    a, b, L_a, d_p = 1e-6, 4e-4, 20e-3, 1.5e-6
    ss = actuator_state_space(2e-3, a, b, L_a)
    dc = -ss.C @ np.linalg.solve(ss.A, ss.B)
    np.testing.assert_allclose(dc[:, 0], [1.0, 2.0 / L_a], rtol=1e-12)
    act = PiezoActuator(loads=False, d_p=d_p, lam=0.0, a=a, b=b, L_a=L_a, s_p=2e-3)
    r = act.simulate(np.full(3000, 20.0), dt=1e-4)  # 0.3 s, e^{-ζ ω_n t} = e^{-60}
    assert r["y_A"][-1] == pytest.approx(20 * d_p, rel=1e-9)
    assert r["alpha_A"][-1] == pytest.approx(40 * d_p / L_a, rel=1e-9)
    (wn, zeta), = act.modes(act.theta())
    assert (wn, zeta) == pytest.approx((1e3, 0.2), rel=1e-12)
