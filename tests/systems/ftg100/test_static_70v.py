"""FT-G100 at 70 V: the seed's 20 µm (``003_abd62b560633beaf.txt`` §III-A, after Fig. 4) read as
the free tip's travel (A: 43.5 µm from the printed numbers, the force factor that calibrates the
plant to it) and as the travel to the 80 µm ball (B: the default plant, 23.58 µm with the grip,
eq 10's gain within 0.82 %), the full close at 200 V, and the findings ``gripkit zoo check`` lists
(derivation in the docstring of :mod:`gripkit.systems.ftg100.model`)."""

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gripkit.cli import main
from gripkit.consistency import check
from gripkit.errors import ParameterError
from gripkit.systems.ftg100.model import (FTG100Plant, full_close_voltage, plant_parameters,
                                          static_force_factor)

# The printed constants (§III-A): eq 5, eq 4 (stated K_sa), eq 3 (stated D_a)
N_A, EPS, H, G = 1300.0, 8.85e-12, 50e-6, 6e-6
K_SA, D_A, W = 25.4, 4.7, 8e-6
C_EQ5 = N_A * EPS * H / (2 * G)                   # 47.94 nN/V²
K3_A = K_SA * (math.pi ** 4 / 128) / W ** 2       # clamped-clamped stretching (beams.py)


def _cardano(k1, k3, f):
    """The real root of k1 x + k3 x³ = f (one real root for k1, k3 > 0), in closed form."""
    p, q = k1 / k3, -f / k3
    r = math.sqrt(q * q / 4 + p ** 3 / 27)
    return math.cbrt(-q / 2 + r) + math.cbrt(-q / 2 - r)


def test_printed_numbers_give_43p5_um_free_not_20():
    """Reading (A), 20 µm = the free tip's travel: x_a = D_a c V²/K_sa = 43.46 µm (eqs 2-5, linear
    suspensions as in the default plant); with the π⁴/128 stretching law (Cardano's root of
    K_sa x + K3_a x³ = c V²) 29.56 µm; both reported with the κ the reading needs."""
    assert C_EQ5 * 70 ** 2 == pytest.approx(234.89e-6, rel=1e-4)
    x_lin = D_A * C_EQ5 * 70 ** 2 / K_SA
    x_nl = D_A * _cardano(K_SA, K3_A, C_EQ5 * 70 ** 2)
    assert x_lin == pytest.approx(43.46e-6, rel=1e-3)
    assert x_nl == pytest.approx(29.56e-6, rel=1e-3)
    free = FTG100Plant(check=False, k0=0.0)
    assert free.equilibrium(70.0)["x_a"] == pytest.approx(x_lin, rel=1e-12)
    stretch = FTG100Plant(plant_parameters(suspension="stretching"), check=False, k0=0.0)
    assert stretch.equilibrium(70.0)["x_a"] == pytest.approx(x_nl, rel=1e-10)
    rep = check(FTG100Plant(check=False))
    eq5, f70 = rep.find("static-70V-eq5"), rep.find("static-70V")
    assert not eq5.consistent and eq5.computed == pytest.approx(x_lin, rel=1e-12)
    assert eq5.rel_error == pytest.approx(x_lin / 20e-6 - 1, rel=1e-12)          # 117 %
    # the linearised gain of eq 8 (k_k = 0) against the gain 20 µm at 70 V implies for F ∝ V²
    assert "1.242 µm/V" in eq5.message and "0.571 µm/V" in eq5.message
    assert not f70.consistent and f70.computed == pytest.approx(x_lin, rel=1e-12)
    assert "force_factor = 0.4601" in f70.used                                   # how to adopt (A)


def _grasped_tip(k1, k3, c, V, gap, k0, k2, lever):
    """Tip position with the ball: c V² = k1 x_e + k3 x_e³ + D_a F_c, F_c = k_k (D_a x_e − gap),
    k_k = k0 k2/(k0 + k2) (eqs 2, 6-7), solved with scipy's brentq; returns (x_a, F_c)."""
    from scipy.optimize import brentq

    kk = k0 * k2 / (k0 + k2)
    def balance(x):
        return k1 * x + k3 * x ** 3 + lever * kk * (lever * x - gap) - c * V * V

    xe = brentq(balance, gap / lever, 1e-3,
                xtol=1e-22, rtol=1e-15)
    return lever * xe, kk * (lever * xe - gap)


def test_gap_reading_puts_the_grasped_tip_within_13_to_18_percent():
    """Reading (B), 20 µm = the 100 µm opening − 80 µm ball: with eq 5 and linear suspensions the
    static balance (K_sa/D_a²) x_a + k_k (x_a − gap) = F_x/D_a gives x_a = 23.58 µm (17.9 % beyond
    20 µm, F_c = 22.87 µN, the sensing arm pushed back F_c/k2 = 3.56 µm); with the stretching law
    22.63 µm (13.1 %); the plant, simulated from rest through a 0 → 70 V step, settles there."""
    k2 = 235.36 / 6.05 ** 2                     # the plant's sensing arm, K_sb/D_b² (eq 16)
    x_lin, f_lin = _grasped_tip(K_SA, 0.0, C_EQ5, 70.0, 20e-6, 1043.0, k2, D_A)
    kk = 1043.0 * k2 / (1043.0 + k2)
    closed_form = (C_EQ5 * 70 ** 2 / D_A + kk * 20e-6) / (K_SA / D_A ** 2 + kk)
    assert x_lin == pytest.approx(closed_form, rel=1e-12)
    assert x_lin == pytest.approx(23.578e-6, rel=1e-4)
    assert f_lin == pytest.approx(22.866e-6, rel=1e-4)
    x_nl, _ = _grasped_tip(K_SA, K3_A, C_EQ5, 70.0, 20e-6, 1043.0, k2, D_A)
    assert x_nl == pytest.approx(22.627e-6, rel=1e-4)
    plant = FTG100Plant(check=False)
    e = plant.equilibrium(70.0)
    assert e["x_a"] == pytest.approx(x_lin, rel=1e-9) and e["F_c"] == pytest.approx(f_lin, rel=1e-8)
    assert e["x_b"] == pytest.approx(f_lin / k2, rel=1e-9)
    y = plant.simulate({"V": np.full(int(0.05 * 20000), 70.0)}, dt=5e-5)
    assert y["x_a"][-1] == pytest.approx(x_lin, rel=1e-5)
    assert y["F_c"][-1] == pytest.approx(f_lin, rel=1e-4)
    g = check(plant).find("static-70V-grasp")
    assert g.consistent and g.rel_error == pytest.approx(x_lin / 20e-6 - 1, rel=1e-9)   # 17.9 %
    stretching = FTG100Plant(plant_parameters(suspension="stretching"), check=False)
    gs = check(stretching).find("static-70V-grasp")
    assert gs.rel_error == pytest.approx(x_nl / 20e-6 - 1, rel=1e-6)                     # 13.1 %


def test_default_plant_is_eq10_at_70V_the_calibrated_one_is_not():
    """Eq 10 is eq 9 at 70 V grasped. The default plant linearised there: ∂x_a/∂V =
    2 D_a c V₀/(K_sa + D_a² k_k) = 0.18936 µm/V, 0.82 % from eq 10's DC gain 0.18782 µm/V; the
    calibrated plant's is κ = 0.4601 times that (53.6 % below); the stretching law's 10.5 %
    below."""
    k2 = 235.36 / 6.05 ** 2
    kk = 1043.0 * k2 / (1043.0 + k2)
    g_lin = 2 * D_A * C_EQ5 * 70.0 / (K_SA + D_A ** 2 * kk)
    A = np.array([[1.6621, -0.9536], [1.0, 0.0]])
    g10 = float(np.array([0.1104, 0.1086]) @ np.linalg.solve(np.eye(2) - A, [0.25, 0.0])) * 1e-6
    assert g10 == pytest.approx(0.18782e-6, rel=1e-4)
    rep = check(FTG100Plant(check=False))
    f = rep.find("eq10-plant-gain")
    assert f.computed == pytest.approx(g_lin, rel=1e-9)
    assert f.stated == pytest.approx(g10, rel=1e-12)
    assert f.consistent and f.rel_error == pytest.approx(0.0082, abs=1e-4)
    assert rep.find("eq5-force-factor").consistent
    cal = check(FTG100Plant(plant_parameters(force_factor="static-70V"), check=False))
    fc = cal.find("eq10-plant-gain")
    assert not fc.consistent and fc.computed == pytest.approx(g_lin * 20e-6 / 43.4646e-6, rel=1e-5)
    assert fc.rel_error == pytest.approx(0.536, abs=1e-3)
    stretching = FTG100Plant(plant_parameters(suspension="stretching"), check=False)
    st = check(stretching).find("eq10-plant-gain")
    assert not st.consistent and st.rel_error == pytest.approx(0.105, abs=1e-3)


def test_full_close_voltage():
    """§II-A's full close of the 100 µm opening: linear suspensions reach it at 70·√(100/43.46) =
    106.2 V (≤ 200 V, consistent); the calibrated plant at 106.2/√κ = 156.5 V; the stretching law
    at 268.2 V (> 200 V: inconsistent, an artefact of the assumed law)."""
    v_lin = 70.0 * math.sqrt(100e-6 / (D_A * C_EQ5 * 70 ** 2 / K_SA))
    assert v_lin == pytest.approx(106.18, rel=1e-4)
    assert full_close_voltage() == pytest.approx(v_lin, rel=1e-12)
    cal = plant_parameters(force_factor="static-70V")
    assert full_close_voltage(cal) == pytest.approx(v_lin / math.sqrt(20e-6 / 43.4646e-6), rel=1e-5)
    xe = 100e-6 / D_A
    v_st = math.sqrt((K_SA * xe + K3_A * xe ** 3) / C_EQ5)
    assert v_st == pytest.approx(268.25, rel=1e-4)
    stretching = plant_parameters(suspension="stretching")
    assert full_close_voltage(stretching) == pytest.approx(v_st, rel=1e-12)
    free = FTG100Plant(check=False, k0=0.0)
    assert free.equilibrium(v_lin)["x_a"] == pytest.approx(100e-6, rel=1e-12)


def test_calibrated_force_factor_puts_the_tip_at_20_um():
    """κ = (K_sa x_e + K3_a x_e³)/(c V²) with x_e = 20 µm/D_a: 0.4601 with the linear suspensions
    (= 20/43.46), 0.5592 with the stretching law; the calibrated plant, simulated from rest through
    a 0 → 70 V step, settles at 20 µm."""
    xe = 20e-6 / D_A
    kappa = K_SA * xe / (C_EQ5 * 70 ** 2)
    assert kappa == pytest.approx(20e-6 / 43.4646e-6, rel=1e-5)
    assert static_force_factor() == pytest.approx(kappa, rel=1e-12)
    kappa_st = (K_SA * xe + K3_A * xe ** 3) / (C_EQ5 * 70 ** 2)
    assert kappa_st == pytest.approx(0.5592, abs=1e-4)
    stretching = plant_parameters(suspension="stretching")
    assert static_force_factor(stretching) == pytest.approx(kappa_st, rel=1e-12)
    ps = plant_parameters(force_factor="static-70V")
    assert ps.value("c_e") == pytest.approx(kappa * C_EQ5, rel=1e-12)
    assert "κ = 0.4601" in ps["c_e"].doc and "20 µm at 70 V" in ps["c_e"].source
    plant = FTG100Plant(ps, check=False, k0=0.0)
    assert plant.equilibrium(70.0)["x_a"] == pytest.approx(20e-6, rel=1e-10)
    fs = 20000.0
    x = plant.simulate({"V": np.full(int(0.04 * fs), 70.0)}, dt=1 / fs)["x_a"]
    assert x[-1] == pytest.approx(20e-6, rel=1e-6)     # 40 ms = 19 decay times 2 M_a/K_fa
    # it rang there (ζ ≈ 0.04), not a static solve
    assert x.max() > 20e-6
    # a number is also accepted, relative to eq 5
    assert plant_parameters(force_factor=0.5).value("c_e") == pytest.approx(0.5 * C_EQ5, rel=1e-12)


def test_calibrated_plant_reports_its_departure_from_eq5():
    """The calibrated plant meets 20 µm free but departs from eq 5 by 54 % (κ = 0.4601):
    reported."""
    rep = check(FTG100Plant(plant_parameters(force_factor="static-70V"), check=False))
    assert rep.find("static-70V").consistent
    assert not rep.find("static-70V-eq5").consistent             # the printed numbers do not change
    f5 = rep.find("eq5-force-factor")
    assert not f5.consistent and f5.computed / f5.stated == pytest.approx(0.4601, abs=1e-4)


@settings(max_examples=25, deadline=None)
@given(V=st.floats(20.0, 190.0), x=st.floats(2e-6, 90e-6), k3_scale=st.floats(0.0, 2.0))
def test_static_force_factor_solves_the_static_balance(V, x, k3_scale):
    """Property: for any target (V, x) and stiffening, the plant scaled by κ sits at x at V."""
    ps = plant_parameters(K3_a=K3_A * k3_scale)
    kappa = static_force_factor(ps, voltage=V, tip_displacement=x)
    plant = FTG100Plant(ps, check=False, k0=0.0, c_e=kappa * ps.value("c_e"))
    assert plant.equilibrium(V)["x_a"] == pytest.approx(x, rel=1e-9)


@pytest.mark.parametrize("kwargs, pattern", [
    (dict(force_factor=-1.0), "force_factor: expected a positive number or "
                              "'static-70V', found -1.0"),
    (dict(force_factor="static-80V"), "found 'static-80V'"),
    (dict(force_factor=None), "found None"),
    (dict(force_factor=float("nan")), "found nan"),
    (dict(force_factor=0.5, c_e=3e-8), "c_e and force_factor=0.5 both set"),
    (dict(force_factor="static-70V", c_e=3e-8), "both set the comb-drive coefficient"),
    (dict(suspension="cubic"), "suspension: expected 'linear' or 'stretching', found 'cubic'"),
])
def test_bad_force_factor(kwargs, pattern):
    with pytest.raises(ParameterError, match=pattern.replace("(", r"\(").replace(")", r"\)")):
        plant_parameters(**kwargs)


def test_bad_static_target():
    with pytest.raises(ParameterError, match="tip_displacement: expected a positive "
                                             "displacement in m"):
        static_force_factor(tip_displacement=-20e-6)
    with pytest.raises(ParameterError, match="voltage: expected a positive voltage"):
        static_force_factor(voltage=0.0)


def test_zoo_check_lists_the_70V_findings(capsys):
    """`gripkit zoo check ftg100-plant --json` exits 3 (reading A inconsistent) and lists
    static-70V-eq5 and static-70V (43.5 µm), static-70V-grasp (23.58 µm, ok) and eq10-plant-gain
    (ok); the calibrated entry meets 20 µm free and reports κ = 0.4601 and its eq 10 gap."""
    code = main(["zoo", "check", "ftg100-plant", "--json"])
    out, _ = capsys.readouterr()
    assert code == 3
    f = {x["check"]: x for x in json.loads(out)["findings"]}
    assert (not f["static-70V-eq5"]["consistent"]
            and f["static-70V-eq5"]["computed"] == pytest.approx(43.46e-6, rel=1e-3))
    assert not f["static-70V"]["consistent"]
    assert f["static-70V"]["computed"] == pytest.approx(43.46e-6, rel=1e-3)
    assert f["static-70V"]["stated"] == 20e-6
    assert f["static-70V-grasp"]["consistent"]
    assert f["static-70V-grasp"]["computed"] == pytest.approx(23.578e-6, rel=1e-4)
    assert f["eq10-plant-gain"]["consistent"] and f["full-close-200V"]["consistent"]
    code = main(["zoo", "check", "ftg100-plant-calibrated"])
    out, _ = capsys.readouterr()
    assert code == 3
    lines = {ln.split(": ")[1]: ln for ln in out.splitlines()}
    assert lines["static-70V"].startswith("[ok]") and "= 2e-05 m" in lines["static-70V"]
    assert lines["eq5-force-factor"].startswith("[INCONSISTENT]")
    assert "κ = 0.4601" in lines["eq5-force-factor"]
    assert lines["eq10-plant-gain"].startswith("[INCONSISTENT]")
    assert "53.6 % apart" in lines["eq10-plant-gain"]


def test_zoo_discretize_refuses_the_nonlinear_plant(capsys):
    """The plant has no linear form to discretise: one error line that lists the linear models
    only."""
    code = main(["zoo", "discretize", "ftg100-plant", "--fs", "20000"])
    out, err = capsys.readouterr()
    assert code == 1 and out == "" and len(err.strip().splitlines()) == 1
    assert err.startswith("error: ModelError: zoo model 'ftg100-plant' has no linear "
                          "continuous-time form")
    assert err.rstrip().endswith("discretize works on: ftg100-actuated, "
                                 "ftg100-sensing, ftg100-coupled")
