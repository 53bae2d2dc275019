"""PVDF slip sensing and slip detection (000_8f66dcc7ab06470c.txt §IV-B, Figs 12-13)."""


import numpy as np
import pytest

from gripkit.errors import DataError
from gripkit.systems.amadeus import (SlipDetector, SlipReflex, calibrate_speed, false_alarm_rate,
                                     stick_slip_rate)
from gripkit.systems.amadeus.pvdf import (PVDFFilm, SlipTestbed, StickSlipContact,
                                          nonslip_grasp_inputs, pvdf_noise, slip_onset_inputs)

FS = 2000.0
C = StickSlipContact()


def test_pvdf_charge_decays():
    """§IV-B: a step of deformation gives a jump g·Δd that decays as e^{-t/τ}; no steady output."""
    f = PVDFFilm()
    g, tau = f.parameters.value("gain"), f.parameters.value("tau")
    d = np.r_[np.zeros(10), np.full(200, 1e-5)]
    v = f.simulate(d, dt=1e-4)["v"]
    t = (np.arange(200)) * 1e-4
    np.testing.assert_allclose(v[10:], g * 1e-5 * np.exp(-t / tau), rtol=1e-12)
    assert np.all(v[:10] == 0)


def test_slip_starts_at_the_static_friction_limit():
    """Coulomb: the object starts to slip when the tangential load reaches μ_s F_n."""
    u = slip_onset_inputs(1.5, dt=1 / FS, normal_force=2.0, load0=0.6, start=0.2, rate=2.0)
    tr = C.simulate(u, dt=1 / FS, x0=C.equilibrium_state(0.6))
    k = int(np.argmax(tr["slipping"] > 0))
    assert u[k, 1] == pytest.approx(0.6 * 2.0, abs=0.01)
    assert np.all(tr["slipping"][:k] == 0)


@pytest.fixture(scope="module")
def detector():
    rng = np.random.default_rng(1)
    u = nonslip_grasp_inputs(30.0, dt=1 / FS, rng=rng)
    x = (C.simulate(u, dt=1 / FS, x0=C.equilibrium_state(u[0, 1]))["v_pvdf"]
         + pvdf_noise(u.shape[0], dt=1 / FS, rng=rng))
    return SlipDetector(dt=1 / FS).calibrate(x)


def test_ten_minute_nonslip_record_and_onsets(detector):
    """Under 1 % false alarms over a 10-minute synthetic record of non-slip grasping (load wander,
    taps, grip steps, pump ripple; ground truth: no slip), and 12 slip onsets (different grips and
    load rates) detected within 20 ms."""
    rng = np.random.default_rng(2)
    u = nonslip_grasp_inputs(600.0, dt=1 / FS, rng=rng)
    tr = C.simulate(u, dt=1 / FS, x0=C.equilibrium_state(u[0, 1]))
    assert tr["slipping"].max() == 0.0
    x = tr["v_pvdf"] + pvdf_noise(u.shape[0], dt=1 / FS, rng=rng)
    d = detector.detect(x)
    fa = false_alarm_rate(d.slipping, tr["slipping"], dt=1 / FS)
    assert fa["n_frames"] == 60000
    assert fa["rate"] < 0.01
    for trial in range(12):
        fn = rng.uniform(1.0, 3.0)
        uu = (slip_onset_inputs(1.0, dt=1 / FS, normal_force=fn, load0=0.3 * fn, start=0.2,
                                rate=rng.uniform(0.5, 8.0)))
        t = C.simulate(uu, dt=1 / FS, x0=C.equilibrium_state(uu[0, 1]))
        onset = np.argmax(t["slipping"] > 0) / FS
        dd = detector.detect(t["v_pvdf"] + pvdf_noise(uu.shape[0], dt=1 / FS, rng=rng))
        assert dd.events, f"trial {trial}: slip not detected"
        assert 0.0 <= dd.events[0].alarm - onset <= 0.020
        assert abs(dd.events[0].onset - onset) <= 0.020


def test_stream_equals_batch(detector):
    rng = np.random.default_rng(3)
    u = slip_onset_inputs(1.0, dt=1 / FS, start=0.3)
    x = (C.simulate(u, dt=1 / FS, x0=C.equilibrium_state(u[0, 1]))["v_pvdf"]
         + pvdf_noise(u.shape[0], dt=1 / FS, rng=rng))
    batch = detector.detect(x)
    s = detector.stream()
    alarms = []
    for k in range(0, x.size, 10):
        alarms += s.update(x[k:k + 10])[1]
    assert alarms == [e.alarm for e in batch.events]
    assert [e[0] for e in s.events] == [e.onset for e in batch.events]


def test_slip_speed_indication():
    """Fig. 12(b): the film signal depends on slip speed. Calibrated on the test rig at 4-20 mm/s
    and
    two normal forces, the stick-slip rate × F_n indicates held-out speeds within 20 %, and the
    indication increases with the true speed."""
    rng = np.random.default_rng(4)
    tb = SlipTestbed()

    def rec(v, F):
        n = int(0.6 * FS)
        u = np.column_stack([np.full(n, F), np.full(n, v)])
        return tb.simulate(u, dt=1 / FS)["v_pvdf"] + pvdf_noise(n, dt=1 / FS, rng=rng)

    sp, fn, recs = [], [], []
    for v in (0.004, 0.008, 0.012, 0.016, 0.020):
        for F in (1.5, 2.5):
            sp.append(v)
            fn.append(F)
            recs.append(rec(v, F))
    cal = calibrate_speed(recs, sp, dt=1 / FS, normal_forces=fn)
    preds = []
    for v in (0.006, 0.010, 0.014):
        r = stick_slip_rate(rec(v, 2.0)[100:], dt=1 / FS)
        p, s = cal.predict(r, 2.0)
        assert abs(p / v - 1) < 0.2
        assert abs(p - v) < 3 * s
        preds.append(p)
    assert preds == sorted(preds)


def test_reflex_ratchets_and_caps():
    r = SlipReflex(step=0.5, rate=2.0, max_force=3.0)
    assert r.demand(2.0) == 2.0
    r.on_slip()
    assert r.demand(2.0) == 2.5
    r.while_slipping(0.1)
    assert r.demand(2.0) == pytest.approx(2.7)
    r.on_slip()
    assert r.demand(2.0) == 3.0


def test_detector_errors():
    with pytest.raises(DataError, match="no threshold"):
        SlipDetector(dt=1 / FS).detect(np.zeros(100))
    with pytest.raises(DataError, match="NaN"):
        SlipDetector(dt=1 / FS, threshold=1.0).detect(np.array([0.0, np.nan, 1.0]))
