"""Guards of the online friction estimator (gripkit.estimation.friction_adaptation) against its
own failure modes: no excitation (freeze), covariance windup (bounded trace), velocity reversals
(left out) and non-finite samples (one-line DataError, or skipped with a DataWarning); plus the
projection on the bounds of scale and offset. The friction tables are synthetic (Stribeck-like),
the truth is known."""

import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gripkit.errors import DataError, DataWarning, ModelError
from gripkit.estimation.friction_adaptation import AdaptationSettings, FrictionAdapter
from gripkit.models.friction import FrictionTable

DT = 1e-3
J = 0.02
V = np.r_[-np.geomspace(4.0, 0.05, 30), np.geomspace(0.05, 4.0, 30)]
TABLE = (FrictionTable(V, np.sign(V) * (0.3 + 0.1 * np.exp(-(V / 0.2) ** 2)) + 0.05 * V,
                       name="synthetic"))


def drive(v, scale=1.0, offset=0.0, noise=0.0, seed=0):
    """Motor torque of a drive J·v̇ = τ − F(v) with F = scale·F_table + offset·sign(v), the
    acceleration as the backward difference a semi-implicit Euler step gives."""
    rng = np.random.default_rng(seed)
    acc = np.r_[0.0, np.diff(v)] / DT
    tau = J * acc + scale * TABLE(v) + offset * np.sign(v) + rng.normal(0, noise, v.size)
    return tau[:, None], np.zeros((v.size, 1)), v[:, None]


def sine(n, amp=2.0, hz=1.3):
    return amp * np.sin(2 * np.pi * hz * np.arange(n) * DT)


def test_recovers_scale_and_offset_on_synthetic_data():
    """Truth s = 1.3, o = 0.08 N·m with 2 mN·m torque noise: recovered within 2 % / 5 mN·m, and
    the reported std covers the error."""
    a = FrictionAdapter([TABLE], [J], DT)
    r = a.update(*drive(sine(20_000), 1.3, 0.08, noise=2e-3))
    assert r.scale[-1, 0] == pytest.approx(1.3, rel=0.02)
    assert r.offset[-1, 0] == pytest.approx(0.08, abs=5e-3)
    assert abs(r.scale[-1, 0] - 1.3) < 4 * r.std[-1, 0, 0] + 1e-3


@settings(max_examples=30, deadline=None)
@given(st.lists(st.floats(-0.05, 0.05), min_size=50, max_size=400),
       st.lists(st.floats(-5.0, 5.0), min_size=50, max_size=400))
def test_no_excitation_freezes_the_estimator(vel, torque):
    """Property: whatever the torques, samples with |v| ≤ v_min never change θ, P or σ̂² (an
    actuator at rest neither drifts nor winds up its covariance)."""
    n = min(len(vel), len(torque))
    a = FrictionAdapter([TABLE], [J], DT, v_min=0.05)
    a.update(*drive(sine(3000), 1.2, 0.05))  # a converged, non-trivial state
    before = (a.theta.copy(), a.P.copy(), a.sig2.copy())
    r = a.update(np.array(torque[:n])[:, None], np.zeros((n, 1)), np.array(vel[:n])[:, None])
    assert not r.active.any()
    np.testing.assert_array_equal(a.theta, before[0])
    np.testing.assert_array_equal(a.P, before[1])
    np.testing.assert_array_equal(a.sig2, before[2])


def test_covariance_stays_bounded_while_sliding_without_excitation():
    """At a constant speed the regressor keeps one direction: the division by λ alone would grow
    P along the other one like λ⁻ⁿ (e^10 ≈ 2·10⁴ after 10 000 samples at λ = 0.999); the trace
    bound keeps trace P ≤ 2·p0."""
    v = np.full(10_000, 1.5)
    bounded = FrictionAdapter([TABLE], [J], DT, p0=100.0)
    free = FrictionAdapter([TABLE], [J], DT, settings=AdaptationSettings(p0=100.0, trace_max=1e300))
    traces = []
    for chunk in np.split(v, 20):
        for a in (bounded, free):
            a.update(*drive(chunk))
        traces.append(np.trace(bounded.P[0]))
    assert max(traces) <= 200.0 * (1 + 1e-12)
    assert np.trace(free.P[0]) > 1e3 * 200.0  # what the guard prevents


@settings(max_examples=25, deadline=None)
@given(st.lists(st.floats(-4.0, 4.0), min_size=200, max_size=2000), st.floats(10.0, 1e4))
def test_trace_never_exceeds_its_bound(vel, p0):
    """Property: for any velocity sequence, trace P ≤ max(trace_max, initial trace) = 2·p0."""
    v = np.repeat(np.array(vel), 5)
    a = FrictionAdapter([TABLE], [J], DT, p0=p0)
    for chunk in np.array_split(v, 7):
        a.update(*drive(chunk, 1.1, 0.02))
        assert np.trace(a.P[0]) <= 2 * p0 * (1 + 1e-9)
        assert np.all(np.isfinite(a.theta))


def test_samples_near_reversals_and_slow_samples_never_update():
    """The Coulomb step at v = 0 lingers in the filtered signals: after every sign change (and
    every sample with |v| ≤ v_min) the first ⌈3/(a·T_s)⌉ = 48 sliding samples (10 Hz filter) are
    left out. The update mask equals that rule computed independently."""
    v = sine(6000, amp=1.0, hz=2.1)
    a = FrictionAdapter([TABLE], [J], DT, v_min=0.05, filter_hz=10.0)
    r = a.update(*drive(v, 1.2))
    hold = math.ceil(3.0 / (2 * math.pi * 10.0 * DT))
    assert hold == 48
    expect = np.zeros(v.size, bool)
    run = 0
    for n, x in enumerate(v):
        if abs(x) > 0.05 and (run == 0 or np.sign(x) == np.sign(v[n - 1])):
            run += 1
        else:
            run = 1 if abs(x) > 0.05 else 0
        expect[n] = run > hold
    np.testing.assert_array_equal(r.active[:, 0], expect)
    # the estimate converges although every reversal is a Coulomb discontinuity
    assert r.scale[-1, 0] == pytest.approx(1.2, rel=0.01)


def test_nonfinite_torque_is_one_line_error_or_skipped_with_a_warning():
    tau, h, v = drive(sine(4000), 1.25, 0.03)
    tau[1500, 0] = np.nan
    tau[2200, 0] = np.inf
    a = FrictionAdapter([TABLE], [J], DT, names=("distal",))
    with pytest.raises(DataError) as err:
        a.update(tau, h, v)
    msg = str(err.value)
    assert "\n" not in msg
    assert ("tau_motor: 2 non-finite value(s), the first at sample 1500 (t = 1.5 s) "
            "of actuator distal") in msg
    assert "nonfinite='skip'" in msg
    np.testing.assert_array_equal(a.theta, [[1.0, 0.0]])  # nothing was consumed
    with pytest.warns(DataWarning, match="left out"):
        r = a.update(tau, h, v, nonfinite="skip")
    assert np.flatnonzero(r.skipped[:, 0]).tolist() == [1500, 2200]
    assert r.scale[1500, 0] == r.scale[1499, 0] and r.offset[1500, 0] == r.offset[1499, 0]
    clean = FrictionAdapter([TABLE], [J], DT).update(*drive(sine(4000), 1.25, 0.03))
    assert r.scale[-1, 0] == pytest.approx(clean.scale[-1, 0], rel=1e-3)
    assert r.scale[-1, 0] == pytest.approx(1.25, rel=0.01)
    with pytest.raises(ModelError, match="nonfinite"):
        a.update(tau, h, v, nonfinite="ignore")


def test_estimates_are_projected_on_their_bounds():
    """Truth s = 3, o = 0.2 N·m outside scale_bounds (0, 2): the estimate never leaves the bounds
    and stays on the upper one, and the free offset takes up the rest (projection in the metric
    of P⁻¹): the adapted friction at 1 rad/s is within 3 % of the truth. With the offset bounded
    too, both sit on their bounds (plain clipping made the pair bang between the bounds)."""
    a = FrictionAdapter([TABLE], [J], DT, settings=AdaptationSettings(scale_bounds=(0.0, 2.0)))
    r = a.update(*drive(sine(5000), 3.0, 0.2))
    assert r.scale.max() <= 2.0 and r.scale.min() >= 0.0
    assert np.all(r.scale[1000:, 0] == 2.0)
    truth = 3.0 * TABLE(1.0) + 0.2
    assert 2.0 * TABLE(1.0) + r.offset[-1, 0] == pytest.approx(truth, rel=0.03)
    both = AdaptationSettings(scale_bounds=(0.0, 2.0), offset_bounds=(-0.01, 0.01))
    r = FrictionAdapter([TABLE], [J], DT, settings=both).update(*drive(sine(5000), 3.0, 0.2))
    assert np.abs(r.offset).max() <= 0.01
    assert np.all(r.scale[1000:, 0] == 2.0) and np.all(r.offset[1000:, 0] == 0.01)


@pytest.mark.parametrize("kw, match", [
    (dict(forgetting=0.0), "forgetting"),
    (dict(scale_bounds=(1.5, 3.0)), "scale_bounds: must contain the nominal scale 1"),
    (dict(offset_bounds=(0.1, 0.2)), "offset_bounds"),
    (dict(scale_bounds=(2.0, 1.0)), "low < high"),
    (dict(trace_max=-1.0), "trace_max"),
    (dict(p0=float("nan")), "p0"),
])
def test_settings_refuse_bad_values(kw, match):
    with pytest.raises(ModelError, match=match):
        AdaptationSettings(**kw)


def test_nyquist_is_checked_against_the_sample_period():
    with pytest.raises(ModelError, match="Nyquist"):
        AdaptationSettings(filter_hz=600).vector(1e-3)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert AdaptationSettings(filter_hz=400).vector(1e-3).shape == (10,)
