"""Margins and closed-loop poles with σ (issue 27): the nominal gain and phase margins equal
python-control's ``stability_margins`` (polynomial roots on the unit circle, an independent
method from gripkit's grid and Brent refinement), and the Monte Carlo probability that the loop
is stable equals the analytic one for a first-order plant whose pole is uncertain."""

import math

import control
import numpy as np
import pytest
from scipy.stats import norm

from gripkit.control import PID, design_rst, loop_margins, robustness, tune_pid
from gripkit.control.robustness import controller_transfer_function, robustness_section
from gripkit.errors import ModelError
from gripkit.lti import StateSpace, TransferFunction
from gripkit.sysid import LinearModel, PolynomialModel



def _plant():
    return TransferFunction.from_polynomials([1.0, -1.5, 0.56], [0.0, 0.0, 0.2, 0.1], dt=0.01)


@pytest.mark.parametrize("make", [
    lambda g: tune_pid(g, tau_c=0.05),
    lambda g: PID(0.5, 4.0, 0.02, dt=0.01),
    lambda g: design_rst(g, wn=10.0, zeta=0.7),
])
def test_nominal_margins_equal_python_control(make):
    g = _plant()
    c = make(g)
    num, den, _ = controller_transfer_function(c)
    L = control.tf(num, den, 0.01) * control.tf(g.num[0, 0], g.den[0, 0], 0.01)
    gm, pm, _, wg, wp, _ = control.stability_margins(L, method="poly")
    m = robustness(g, c, n=0).nominal
    # python-control roots a polynomial of twice the loop's degree; near the loop's double pole
    # at z = 1 (RST: R's integrator and the plant's slow poles) its crossover lands 7e-6 off in
    # |L| (gripkit's Brent refinement: 1e-12), so the two agree to 1e-5 and gripkit's are
    # checked to be true crossings
    assert m["gain_margin"] == pytest.approx(gm, rel=1e-9)
    assert m["phase_margin_deg"] == pytest.approx(pm, rel=1e-5)
    assert m["w_gain_margin"] == pytest.approx(wg, rel=1e-9)
    assert m["w_phase_margin"] == pytest.approx(wp, rel=1e-5)
    Lz = L(np.exp(1j * np.array([m["w_gain_margin"], m["w_phase_margin"]]) * 0.01))
    assert abs(Lz[0].imag) < 1e-10 * abs(Lz[0]) and Lz[0].real < 0
    assert abs(abs(Lz[1]) - 1.0) < 1e-10
    assert 1.2 < m["gain_margin"] < 20 and 10 < m["phase_margin_deg"] < 90


def test_probability_of_stability_equals_the_analytic_one():
    """G = b/(z − a), a ~ N(0.9, 0.05²), P control K: the closed-loop pole a − K b is inside the
    unit circle with probability Φ((1 + Kb − a)/σ) − Φ((−1 + Kb − a)/σ); K b = 1.85 puts the
    nominal pole at −0.95, one σ inside z = −1, so about 16 % of the draws are unstable. The mean
    pole radius is the folded normal's mean."""
    a, b, s, K = 0.9, 0.5, 0.05, 3.7
    m = PolynomialModel.from_coefficients([1.0, -a], [0.0, b], dt=0.01, std={"A": [0.0, s]})
    r = robustness(m, ([K], [1.0], 0.01), n=4000, seed=27)
    exact = norm.cdf((1 + K * b - a) / s) - norm.cdf((-1 + K * b - a) / s)
    assert r.stable and abs(r.poles[0] - (a - K * b)) < 1e-12
    assert 0.1 < exact < 0.9
    assert r.probability_stable == pytest.approx(exact, abs=3 * r.probability_stable_se)
    # the pole radius of each draw is |a_i − K b|: its mean over the draws
    assert np.mean(r.pole_radius) == pytest.approx(
        s * math.sqrt(2 / math.pi) * math.exp(-((a - K * b) / s) ** 2 / 2)
        + abs(a - K * b) * (1 - 2 * norm.cdf(-abs(a - K * b) / s)), rel=0.03)


def test_each_draws_margins_are_python_controls():
    g = _plant()
    m = PolynomialModel.from_coefficients(g.den_zinv(), g.num_zinv(), dt=0.01,
                                          std={"A": [0, 0.004, 0.004], "B": [0, 0, 0.01, 0.01]})
    pid = tune_pid(g, tau_c=0.05)
    r = robustness(m, pid, n=40, seed=1)
    assert r.probability_stable == 1.0
    num, den, _ = controller_transfer_function(pid)
    for i, gi in enumerate(m.system.sample(40, seed=1)[:5]):
        L = control.tf(num, den, 0.01) * control.tf(gi.num[0, 0], gi.den[0, 0], 0.01)
        gm, pm = control.stability_margins(L, method="poly")[:2]
        assert r.gain_margin_db[i] == pytest.approx(20 * math.log10(gm), rel=1e-8)
        assert r.phase_margin_deg[i] == pytest.approx(pm, rel=1e-8)
    st = r.statistics()
    assert st["gain_margin_db"]["std"] > 0 and st["gain_margin_db"]["count"] == 40
    assert st["phase_margin_deg"]["p05"] <= st["phase_margin_deg"]["p50"] \
        <= st["phase_margin_deg"]["p95"]


def test_a_model_without_covariance_gives_the_nominal_figures_only():
    ss = StateSpace([[0.9]], [[1.0]], [[0.5]], dt=0.01)
    m = LinearModel(ss, "n4sid")
    pid = PID(0.5, 2.0, dt=0.01)
    assert math.isnan(robustness(m, pid, n=0).probability_stable)
    with pytest.raises(ModelError, match="carries no parameter covariance"):
        robustness(m, pid, n=10)
    with pytest.raises(ModelError, match="the controller runs at dt"):
        robustness(m, PID(0.5, 2.0, dt=0.02), n=0)


def test_loop_without_crossovers_has_infinite_margins():
    """0.1 z/(z − 0.5): |L| ≤ 0.2 everywhere, L(1) = 0.2 and L(−1) = 1/15 are positive and Im L
    ≠ 0 inside (0, π/h): no crossover of either kind."""
    res = loop_margins([0.1, 0.0], [1.0, -0.5], 0.01)
    assert res["gain_margin"] == math.inf and res["phase_margin_deg"] == math.inf


def test_a_phase_crossover_at_z_minus_one_is_the_gain_margin():
    """0.1/(z − 0.5): L is real and negative only at z = −1 (L = −1/15), so the gain margin is
    15 at ω = π/h, the gain k at which the closed-loop pole 0.5 − 0.1 k reaches −1 (it was
    inf: the crossover at the Nyquist frequency was missed); no gain crossover (|L| < 1)."""
    res = loop_margins([0.1], [1.0, -0.5], 0.01)
    assert res["gain_margin"] == pytest.approx(15.0, rel=1e-12)
    assert res["w_gain_margin"] == pytest.approx(math.pi / 0.01, rel=1e-15)
    assert res["phase_margin_deg"] == math.inf


def test_the_robustness_section_in_the_model_report(tmp_path):
    """The model report of a first-order model with a parameter covariance, with the section
    of a PI loop: the table's nominal gain margin is the result's, P(stable) is printed, and a
    controller label from outside is escaped, never markup."""
    from html import unescape

    from gripkit.signals import Trajectory
    from gripkit.sysid.model_report import write_model_report

    ss = StateSpace([[0.9]], [[0.1]], [[1.0]], dt=0.01, inputs=["u"], outputs=["y"])
    ss = ss.with_covariance([[1e-4]], ["A[0,0]"])
    m = LinearModel(ss, "n4sid")
    rng = np.random.default_rng(0)
    u = rng.standard_normal(300)
    y = m.simulate(u[:, None])[:, 0] + 1e-3 * rng.standard_normal(300)
    data = Trajectory(np.arange(300) * 0.01, {"u": u, "y": y})
    pid = tune_pid(m, tau_c=0.05)
    r = robustness(m, pid, n=200, seed=3)
    assert r.n == 200 and 0.0 <= r.probability_stable <= 1.0
    label = "PI <script>alert(1)</script>"
    index = write_model_report(m, data, tmp_path / "rep",
                               sections=[lambda rep: robustness_section(rep, r, controller=label)])
    html = index.read_text()
    assert "Robustness of the loop" in html and "<script>alert" not in html
    assert "PI <script>alert(1)</script> in the loop" in unescape(html)
    assert f"Probability that the loop is stable: {r.probability_stable:.4f}" in html
    assert f"{r.nominal['gain_margin_db']:.4g}" in html


def test_lqr_state_feedback_margins():
    """Single-input LQR on a 2-state plant, loop broken at the input, L(z) = K (zI − A)⁻¹ B:
    the margins equal python-control's on ss(A, B, K, 0), the closed-loop poles are those of
    A − B K, and the discrete return-difference inequality |1 + L| ≥ ρ = √(R/(R + BᵀSB))
    (Shaked 1986) guarantees a phase margin of at least 2 asin(ρ/2)."""
    from gripkit.control import lqr, lqr_controller

    A = np.array([[1.0, 0.01], [-0.5, 0.97]])
    B = np.array([[0.0], [0.01]])
    g = StateSpace(A, B, [[1.0, 0.0]], [[0.0]], dt=0.01)
    g = g.with_covariance(np.diag([1e-4, 1e-4]), ["A[1,0]", "A[1,1]"])
    Q, R = np.diag([10.0, 1.0]), np.array([[0.01]])
    sf = lqr_controller(g, Q, R)
    K, S, E = lqr(g, Q, R)
    res = robustness(g, sf, n=200, seed=4)
    np.testing.assert_allclose(np.sort_complex(res.poles), np.sort_complex(E), atol=1e-12)
    L = control.ss(A, B, K, 0, 0.01)
    gm, pm = control.stability_margins(L, method="poly")[:2]
    assert res.nominal["phase_margin_deg"] == pytest.approx(pm, rel=1e-6)
    # L crosses the negative real axis only at z = −1 (python-control's poly method, which
    # leaves z = −1 out, says inf): the gain margin is the k at which A − k B K has a pole at −1
    gmr = res.nominal["gain_margin"]
    assert gm == math.inf and res.nominal["w_gain_margin"] == pytest.approx(math.pi / 0.01)
    assert np.min(np.abs(np.linalg.eigvals(A - gmr * B @ K) + 1.0)) < 1e-9
    assert np.max(np.abs(np.linalg.eigvals(A - 0.999 * gmr * B @ K))) < 1.0
    rho = math.sqrt(R[0, 0] / (R[0, 0] + float((B.T @ S @ B)[0, 0])))
    assert res.nominal["phase_margin_deg"] >= math.degrees(2 * math.asin(rho / 2))
    assert res.probability_stable == 1.0 and np.std(res.phase_margin_deg) > 0
