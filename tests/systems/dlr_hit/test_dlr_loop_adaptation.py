"""Online friction adaptation inside the DLR/HIT impedance loop (``002_ddea254371185ad3.txt``
abstract, eq 3.1, §6.3; the drift after Fig. 5.7): the in-loop estimator is the offline one run
at every control step, it follows a drifting plant friction, and the adapted compensation
reduces the tracking error without harming the nominal case."""

import math
import warnings

import numpy as np
import pytest

from gripkit.errors import ConsistencyWarning, ModelError, SimulationError
from gripkit.estimation.friction_adaptation import FrictionAdapter
from gripkit.systems.dlr_hit.finger import ACTUATORS, JOINTS
from gripkit.systems.dlr_hit.friction_adaptation import compare_adaptation, tracking_reference
from gripkit.systems.dlr_hit.friction_drift import (STICTION_STEP, FrictionDrift, stiction_step,
                                                    warmup_drift)
from gripkit.systems.dlr_hit.impedance import (LOOP_ADAPTATION, ImpedanceController,
                                               model_friction_tables, simulate_impedance)
from gripkit.systems.dlr_hit.parameters import finger

DEG = math.pi / 180
T = 120.0  # the duration of Fig. 5.7
T_STEP = 60.0
CTRL = ImpedanceController("joint", (8, 8, 8), (0.6, 0.6, 0.6))


def _finger(**kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConsistencyWarning)
        return finger(**kw)


@pytest.fixture(scope="module")
def study():
    """Fig. 5.7's 120 s warm-up (friction 1.5× at room temperature, τ = 39.6 s) plus a stiction
    step of 0.09 N·m on every drive at 60 s."""
    f = _finger(check=False)
    drift = warmup_drift(T).combine(stiction_step(T_STEP))
    return f, compare_adaptation(f, CTRL, tracking_reference(T), drift)


def test_in_loop_estimator_is_the_offline_adapter_run_each_step(study):
    """Reference implementation: the FrictionAdapter run after the fact on the loop's own log
    (motor torque by eq 5.10 from the logged PWM and speed, bias torque by the multibody model in
    Python, the same inertias and settings) gives the in-loop estimates to 1e-9. The actuator
    velocities are recovered from the joint velocities; a stuck drive's exact 0 comes back as
    ~1e-17 and is set to 0 again (sign(v) would differ)."""
    f, cmp = study
    tr = cmp.runs["adaptive", "drift"]
    ch = f.chain()
    G = ch.coupling.matrix[:3]
    p = np.linalg.solve(G, np.column_stack([tr[j] for j in JOINTS]).T).T
    pd = np.linalg.solve(G, np.column_stack([tr[f"{j}_vel"] for j in JOINTS]).T).T
    pd[np.abs(pd) < 1e-12] = 0.0
    tau = (np.column_stack([f.motor_torque(a, tr[f"pwm_{a}"],
                                           pd[:, k]) for k, a in enumerate(ACTUATORS)]))
    J = np.diag(ch.mass_matrix(p[0]))
    ad = (FrictionAdapter(model_friction_tables(f), J, 1e-3, settings=LOOP_ADAPTATION,
                          names=ACTUATORS))
    off = ad.update(tau, ch.bias(p, pd), pd)
    for k, a in enumerate(ACTUATORS):
        np.testing.assert_allclose(tr[f"scale_hat_{a}"], off.scale[:, k], rtol=0, atol=1e-9)
        np.testing.assert_allclose(tr[f"offset_hat_{a}"], off.offset[:, k], rtol=0, atol=1e-9)
        np.testing.assert_array_equal(tr[f"adapt_status_{a}"] == 1.0, off.active[:, k])


def test_adaptation_reduces_the_tracking_error_under_drift(study):
    """The drift adds tracking error to the fixed compensation (at least 20 % more RMS than the
    nominal plant: the test is meaningful); adaptation removes at least half of that added error
    (margin derived from the run) and lowers the largest error."""
    _, cmp = study
    fixed, nominal, adaptive = (cmp.rms["fixed", "drift"], cmp.rms["fixed", "nominal"],
                                cmp.rms["adaptive", "drift"])
    assert fixed > 1.2 * nominal, (fixed, nominal)
    assert adaptive <= nominal + 0.5 * (fixed - nominal), (adaptive, nominal, fixed)
    assert cmp.recovered >= 0.5
    assert cmp.rms_ratio == pytest.approx(fixed / adaptive)
    assert cmp.max["adaptive", "drift"] < cmp.max["fixed", "drift"]
    assert cmp.max_ratio > 1.0


def test_adaptation_does_no_harm_without_drift(study):
    """Nominal plant (the controller's tables are exact): adaptation changes the RMS error by at
    most +2 % and the largest error by at most +5 %, and its estimates stay at (1, 0) within 3 %
    and 0.02 N·m after the first 5 s."""
    _, cmp = study
    assert cmp.rms["adaptive", "nominal"] <= 1.02 * cmp.rms["fixed", "nominal"]
    assert cmp.max["adaptive", "nominal"] <= 1.05 * cmp.max["fixed", "nominal"]
    tr = cmp.runs["adaptive", "nominal"]
    late = tr.t > 5.0
    for a in ACTUATORS:
        assert np.all(np.abs(tr[f"scale_hat_{a}"][late] - 1.0) < 0.03)
        assert np.all(np.abs(tr[f"offset_hat_{a}"][late]) < 0.02)
    fixed = cmp.runs["fixed", "nominal"]
    for a in ACTUATORS:  # without adaptation the estimate is never touched
        assert np.all(fixed[f"scale_hat_{a}"] == 1.0) and np.all(fixed[f"offset_hat_{a}"] == 0.0)
        assert np.all(fixed[f"adapt_status_{a}"] == 0.0)


def test_adapted_friction_follows_the_plant(study):
    """The adapted friction ŝ·F(v) + ô matches the plant's s(t)·F(v) + Δ(t) within 4 % at 0.5, 1
    and 2 rad/s just before the stiction step and at the end of the run."""
    f, cmp = study
    tr = cmp.runs["adaptive", "drift"]
    tabs = model_friction_tables(f)
    v = np.array([0.5, 1.0, 2.0])
    for t_check in (T_STEP - 0.5, T - 0.01):
        n = int(t_check * 1000)
        for k, a in enumerate(ACTUATORS):
            true = tr[f"drift_scale_{a}"][n] * tabs[k](v) + tr[f"drift_offset_{a}"][n]
            est = tr[f"scale_hat_{a}"][n] * tabs[k](v) + tr[f"offset_hat_{a}"][n]
            np.testing.assert_allclose(est, true, rtol=0.04, err_msg=f"{a} at {t_check} s")


def test_plant_drift_is_a_rescaled_friction():
    """A constant drift s = 1.3 is the finger with its friction scales and stiction ×1.3; a
    stiction step Δ on a Stribeck finger is F_c and F_s raised by Δ: the closed-loop runs agree."""
    ref = tracking_reference(3.0)
    f = _finger(check=False)
    ctrl = (ImpedanceController("joint", (8, 8, 8), (0.6, 0.6, 0.6),
                                friction_tables=model_friction_tables(f)))
    v = f.parameters.value
    scaled = _finger(check=False, **{f"scale_{a}": 1.3 * v(f"scale_{a}") for a in ACTUATORS},
                     **{f"fs_{a}": 1.3 * v(f"fs_{a}") for a in ACTUATORS})
    a = simulate_impedance(f, ctrl, ref, friction_drift=FrictionDrift([0.0], [1.3]))
    b = simulate_impedance(scaled, ctrl, ref)
    for ch in ("abd", "flex", "prox", "fric_distal", "fric_base1"):
        np.testing.assert_allclose(a[ch], b[ch], rtol=1e-6, atol=1e-9)
    fs = _finger(check=False, friction="stribeck")
    vs = fs.parameters.value
    d = 0.05
    raised = _finger(check=False, friction="stribeck",
                     **{f"fc_{x}": vs(f"fc_{x}") + d for x in ACTUATORS},
                     **{f"fs_{x}": vs(f"fs_{x}") + d for x in ACTUATORS})
    ctrl = (ImpedanceController("joint", (8, 8, 8), (0.6, 0.6, 0.6),
                                friction_tables=model_friction_tables(fs)))
    a = simulate_impedance(fs, ctrl, ref, friction_drift=stiction_step(0.0, d))
    b = simulate_impedance(raised, ctrl, ref)
    for ch in ("abd", "flex", "prox", "fric_distal"):
        np.testing.assert_allclose(a[ch], b[ch], rtol=1e-6, atol=1e-9)


def test_drift_schedules():
    """Fig. 5.7 warm-up: s(t) = 1 + 0.5·e^(−t/39.6 s); a step is right-continuous; combined
    drifts multiply scales and add offsets."""
    w = warmup_drift(120.0)
    assert w.at(0.0)[0] == pytest.approx(1.5)
    assert w.at(39.6)[0] == pytest.approx(1 + 0.5 / math.e, rel=1e-4)
    s = stiction_step(60.0, actuators=("distal",))
    np.testing.assert_array_equal(s.at([59.999, 60.0]),
                                  [[1, 1, 1, 0, 0, 0], [1, 1, 1, 0, 0, STICTION_STEP]])
    assert STICTION_STEP == pytest.approx(0.09)
    c = w.combine(s)
    t = np.array([10.0, 59.9, 60.0, 100.0])
    expect = w.at(t) * [1, 1, 1, 0, 0, 0] + s.at(t) * [0, 0, 0, 1, 1, 1]
    # w is piecewise linear between 200 points
    np.testing.assert_allclose(c.at(t), expect, rtol=2e-5)
    assert c.at(120.0)[0] == pytest.approx(1 + 0.5 * math.exp(-120 / 39.6))


@pytest.mark.parametrize("build, match", [
    (lambda: FrictionDrift([0.0, 1.0], [1.0, -0.1]), "scale"),
    (lambda: FrictionDrift([1.0, 0.0], [1.0, 1.0]), "times"),
    (lambda: FrictionDrift([0.0, 1.0, 1.0, 1.0], [1.0] * 4), "at most twice"),
    (lambda: FrictionDrift([0.0, 1.0], np.ones((2, 2))), r"\(2, 3\)"),
    (lambda: warmup_drift(-1.0), "duration"),
    (lambda: stiction_step(1.0, actuators=("thumb",)), "actuators"),
    (lambda: ImpedanceController(adaptation="fast"), "adaptation"),
    (lambda: ImpedanceController(adaptation=LOOP_ADAPTATION, friction_compensation=False),
     "friction_compensation"),
])
def test_bad_drift_and_adaptation_settings_are_refused(build, match):
    with pytest.raises(ModelError, match=match):
        build()


def test_drift_needs_a_finger_with_friction():
    with pytest.raises(SimulationError, match="no friction"):
        simulate_impedance(_finger(check=False, friction="none"), CTRL, tracking_reference(0.1),
                           friction_drift=warmup_drift(1.0))
    with pytest.raises(SimulationError, match="FrictionDrift"):
        simulate_impedance(_finger(check=False), CTRL, tracking_reference(0.1), friction_drift=1.3)
