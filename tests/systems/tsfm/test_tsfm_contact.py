"""Free ↔ constrained motion of a TSFM finger (Fig. 5, Fig. 13; 001_0b92a7da96e7aa46.txt §III-A,
§V-B): exact ZOH with in-step events against a fine RK4 reference, conservation at the contact."""


import numpy as np
import pytest

from gripkit.models.hysteresis import bouc_wen_response
from gripkit.systems.tsfm import parameters as z

FS = 20000.0


@pytest.fixture(scope="module")
def fig13(left):
    return z.contact_experiment(left, 72.5, noise=0.0)


def test_contact_starts_at_44_V_and_no_force_before(fig13):
    """Fig. 13: the contact starts at U = 44 V (part face placed there); no force at all while
    free."""
    c = fig13["contact"] > 0.5
    on = int(np.argmax(c))
    assert fig13["U"][on] == pytest.approx(44.0, abs=0.05)
    assert np.all(fig13["F_g"][~c] == 0.0)
    assert fig13["F_g"][c].min() >= 0.0
    # separation on the falling branch below 44 V (hysteresis: the tip is further out there)
    off = on + int(np.argmax(~c[on:]))
    assert 30.0 < fig13["U"][off] < 44.0


def test_force_is_continuous_through_a_quasi_static_contact(fig13):
    """A 0.1 Hz approach meets the part at ≈ zero velocity: the force starts from 0 — the first
    contact sample holds less than two samples' worth of the loading rate, no jump."""
    F = fig13["F_g"]
    on = int(np.argmax(fig13["contact"] > 0.5))
    rate = np.max(np.diff(F[on:on + 200]))
    assert F[on] <= 2 * rate
    assert np.max(np.abs(np.diff(F))) < 1e-6  # 1 µN per sample at most, everywhere


def test_static_force_is_the_series_compliance(left):
    """Held voltage, part face 5 µm short of the free tip position: F = 5 µm / (c_finger + 1/k_e)
    with c_finger = 1/k_s + α_f s_p (eq 11 at s = 0)."""
    v = left.values()
    x_free = z.contact_voltage(left, 30.0)
    m = left.contact(x_w=x_free - 5e-6, k_e=72.5)
    U = np.concatenate([np.linspace(0, 30, 2000), np.full(18000, 30.0)])
    F = m.simulate(U, dt=1 / FS)["F_g"][-1]
    L = v["L_r"] + v["L_s"]
    cf = 1 / v["k_s"] + (1 + 3 * L / v["L_a"] + 3 * L**2 / v["L_a"] ** 2) * v["s_p"]
    assert F == pytest.approx(5e-6 / (cf + 1 / 72.5), rel=1e-6)


@pytest.mark.parametrize("realisation", ["component", "minimal"])
def test_exact_hybrid_scheme_against_fine_rk4_reference(left, realisation):
    """A fast 20 Hz stroke hits a stiff part (469 N/m, Table III) and rings: the exact scheme
    (events inside the step) agrees with RK4 at 1000 substeps per sample, whose own switching
    happens only at the end of a 50 ns substep (≈ 3e-10 m at 6 mm/s), to 1e-6 of the stroke in
    position and 1e-4 of the peak in force."""
    x_w = z.contact_voltage(left, 20.0)
    m = left.contact(x_w=x_w, k_e=469.0, c_e=2e-3, realisation=realisation)
    t = np.arange(4000) / FS
    U = 30.0 * np.sin(2 * np.pi * 20 * t)
    exact = m.simulate(U, dt=1 / FS)
    v = dict(zip(m.parameters.names, m.theta()))
    W = v["d_p"] * U - bouc_wen_response(U, v["d_p"], v["lam"], v["beta"], v["gamma"])[1]
    hs = m.hybrid_system()
    u = np.column_stack([W, np.full_like(W, x_w)])
    ref = hs.simulate_reference(u, 1 / FS, substeps=1000)
    yr, Fr = ref.trajectory["y_C"], ref.trajectory["F_g"]
    assert np.sum(np.diff(exact["contact"]) != 0) >= 2
    np.testing.assert_allclose(exact["y_C"], yr, atol=1e-6 * np.ptp(yr))
    np.testing.assert_allclose(exact["F_g"], Fr, atol=1e-4 * np.max(np.abs(Fr)))


def test_pull_off_holds_the_contact_until_the_adhesion_breaks(left):
    """With a pull-off force the contact outlives zero force: it ends when the tension reaches
    −F_po (penetration −F_po/k_e), later than without adhesion."""
    x_w = z.contact_voltage(left, 44.0)
    t = np.arange(int(10 * FS)) / FS
    U = 25 * (1 - np.cos(2 * np.pi * 0.1 * t))
    r0 = left.contact(x_w=x_w, k_e=72.5).simulate(U, dt=1 / FS)
    r1 = left.contact(x_w=x_w, k_e=72.5, F_po=20e-6).simulate(U, dt=1 / FS)
    off0 = np.flatnonzero(np.diff(r0["contact"]) < 0)[0]
    off1 = np.flatnonzero(np.diff(r1["contact"]) < 0)[0]
    assert off1 > off0
    assert r1["F_g"][off1] == pytest.approx(-20e-6, abs=0.2e-6)
