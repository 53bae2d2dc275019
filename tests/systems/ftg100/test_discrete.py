"""Discrete FT-G100 models at 20 kHz (eqs 10, 17, 18) against the seed's printed matrices, scipy
and python-control; the eq 17 inconsistency and the readout unit reported as findings."""

import warnings

import numpy as np
import pytest
from scipy import signal

from gripkit.consistency import check
from gripkit.errors import ConsistencyWarning, ModelError
from gripkit.systems.ftg100.model import (SEED_EQ10, SEED_EQ17, FTG100Actuated, FTG100Coupled,
                                          FTG100Sensing, balancing_scale, controllable_form,
                                          seed_state_space)

FS = 20000.0


@pytest.fixture(scope="module")
def act():
    return FTG100Actuated()


@pytest.fixture(scope="module")
def sen():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConsistencyWarning)
        return FTG100Sensing()


def test_eq10_matrices_reproduced(act):
    """Eq 10 from D_a = 4.7, K_sa = 25.4 N/m, M_a = 1.37 mg, K_fa = 1.3 mN·s/m, k0 = 1043 N/m,
    k2 = 6.45 N/m: A_a = [[1.6621, -0.9536], [1, 0]], B_a = [0.25, 0], C_a = [0.1104, 0.1086] µm/V.
    Eigenvalues within 0.3 % (the printed parameters carry 2-3 digits)."""
    d = act.discrete(1 / FS)
    seed = np.array(SEED_EQ10["A"])
    ev, es = np.sort_complex(np.linalg.eigvals(d.A)), np.sort_complex(np.linalg.eigvals(seed))
    assert np.max(np.abs(ev - es) / np.abs(es)) < 0.003
    np.testing.assert_allclose(d.A, seed, rtol=2e-3, atol=1e-12)
    np.testing.assert_array_equal(d.B, [[0.25], [0.0]])
    np.testing.assert_allclose(d.C * 1e6, SEED_EQ10["C"], rtol=5e-3)  # metres -> µm


def test_dc_gain_0_1878_um_per_volt(act):
    """The seed's eq 10 matrices give C(I - A)^-1 B = 0.1878 µm/V (computed here from the printed
    numbers); the model's DC gain D_a N_a eps h V0/g / (K_sa + D_a² k_k) is within 1.5 % of it."""
    A, B, C = (np.array(SEED_EQ10[k]) for k in "ABC")
    seed_dc = (C @ np.linalg.solve(np.eye(2) - A, B)).item()
    assert seed_dc == pytest.approx(0.1878, abs=5e-5)
    assert act.dc_gain() * 1e6 == pytest.approx(0.1878, rel=0.015)
    assert float(act.discrete(1 / FS).dc_gain()[0, 0]) == pytest.approx(act.dc_gain(), rel=1e-10)


def test_canonical_form_matches_scipy_and_control(act):
    """The canonical form's transfer function equals scipy's ZOH of G_a(s) (eq 9), and
    python-control's
    c2d gives the same poles."""
    g = act.transfer_function()
    assert g.inputs == ("V_in",) and g.outputs == ("x_a",) and g.output_units == ("m",)
    assert float(g.dc_gain()[0, 0]) == pytest.approx(act.dc_gain(), rel=1e-12)
    num, den = g.numerator(), g.denominator()
    nd, dd, _ = signal.cont2discrete((num, den), 1 / FS, method="zoh")
    d = act.discrete(1 / FS)
    n2, d2 = signal.ss2tf(d.A, d.B, d.C, d.D)
    # Denominators: sums of products of the two eigenvalues, each route accurate to a few ε.
    # Numerators: ss2tf forms them as poly(A − BC) − poly(A), a difference of O(1) coefficients that
    # leaves O(1e-8) ones, so they carry a relative error of about ε·Σ|den|/|num| (≈ 3e-8 here);
    # 8 such roundings make the bound.
    eps = np.finfo(np.float64).eps
    np.testing.assert_allclose(d2, dd, rtol=8 * eps * np.abs(dd).sum())
    num_rtol = 8 * eps * np.abs(dd).sum() / np.abs(nd[np.nonzero(nd)]).min()
    np.testing.assert_allclose(n2[0], np.ravel(nd), rtol=num_rtol, atol=0)
    import control  # a dev dependency: the cross-check fails, never skips, without it
    sysd = control.c2d(control.tf(num, den), 1 / FS, "zoh")
    np.testing.assert_allclose(np.sort_complex(control.poles(sysd)), np.sort_complex(d.poles()),
                               rtol=1e-10)
    # physical-coordinate ZOH is similar: same poles and DC gain
    p = act.discrete(1 / FS, form="physical")
    np.testing.assert_allclose(np.sort_complex(p.poles()), np.sort_complex(d.poles()), rtol=1e-12)
    with pytest.raises(ModelError):
        act.discrete(1 / FS, form="jordan")


def test_balancing_scale_reproduces_both_printed_forms():
    """MATLAB's power-of-two input scale: B_a = 0.25 (eq 10, numerator 0.0276 + 0.0272 µm/V) and
    B_c = 0.5 (eq 17, numerator 0.0660 + 0.0648 µm/µN)."""
    assert balancing_scale(0.25 * np.array(SEED_EQ10["C"][0])) == 0.25
    assert balancing_scale(0.5 * np.array(SEED_EQ17["C"][0])) == 0.5
    seed = seed_state_space(SEED_EQ17)
    cf = controllable_form(seed, scale="balanced")  # in SI (m/N = µm/µN) the rule gives 0.5 again
    np.testing.assert_allclose(cf.A, SEED_EQ17["A"], rtol=1e-12)
    assert cf.B[0, 0] == 0.5
    np.testing.assert_allclose(cf.C, SEED_EQ17["C"], rtol=1e-9)


def test_eq17_inconsistency_detected(sen):
    """Eq 17 does not follow from M_b = 0.5 mg, K_fb = 0.71 mN·s/m, K_sb = 235.36 N/m, D_b = 6.05:
    those give 3.45 kHz (A_c entries 0.9026, -0.9315) while the printed A_c has 3.006 kHz; with K_sb
    and K_fb as stated the printed poles imply M_b = 0.660 mg (ω_n) and 0.659 mg (decay rate)."""
    rep = check(sen)
    poles = rep.find("eq17-poles")
    assert not poles.consistent and poles.rel_error > 0.1
    implied = rep.find("eq17-implied-M_b")
    assert not implied.consistent
    assert implied.computed == pytest.approx(0.660e-6, rel=2e-3)
    assert "0.6586 mg" in implied.message
    assert not rep.find("eq17-dc-gain").consistent
    d = sen.discrete(1 / FS)
    np.testing.assert_allclose(d.A, [[0.902582, -0.931462], [1, 0]], atol=1e-6)
    with pytest.warns(ConsistencyWarning) as rec:
        FTG100Sensing()
    assert any("eq17-implied-M_b" in str(w.message) for w in rec)
    # the actuated subsystem's checks all pass, including the damping-unit reading (mN·s/m)
    a = check(FTG100Actuated())
    assert a.ok and a.find("damping-unit").rel_error < 1e-4


def test_eq18_coupled():
    """Eq 18: block form from the canonical subsystems; its DC gains are exact:
    V_out/V = G_a(0) k_k (1/k2_b) k2/r with G_b(0) = D_b²/K_sb; the readout r = 50 µN/V (Fig. 10:
    140 µN -> 2.8 V) is reported against the printed '50 N/Volts'."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConsistencyWarning)
        cpl = FTG100Coupled()
    d = cpl.discrete(1 / FS)
    act = cpl.actuated()
    p = cpl.parameters
    kk = p.value("k0") * p.value("k2") / (p.value("k0") + p.value("k2"))
    xa = act.dc_gain()
    xb = xa * kk * p.value("D_b") ** 2 / p.value("K_sb")
    dc = d.dc_gain()[:, 0]
    np.testing.assert_allclose(dc, [xa, xb, kk * xa, p.value("k2") / 50e-6 * xb], rtol=1e-7)
    exact = cpl.discrete(1 / FS, form="physical")
    np.testing.assert_allclose(exact.dc_gain()[:, 0], dc, rtol=1e-7)
    np.testing.assert_allclose(np.sort_complex(exact.poles()), np.sort_complex(d.poles()),
                               rtol=1e-9)
    np.testing.assert_allclose(d.A[:2, :2], act.discrete(1 / FS).A)
    # simulate: the exact cascade settles at the DC gains
    u = np.full(4000, p.value("V0") + 1.0)
    y = cpl.simulate({"V_in": u}, dt=1 / FS)
    assert y["V_out"][-1] == pytest.approx(dc[3], rel=1e-3)
    f = check(cpl).find("readout-sensitivity-unit")
    assert (not f.consistent and f.stated == pytest.approx(2.8)
            and f.computed == pytest.approx(2.8e-6))
