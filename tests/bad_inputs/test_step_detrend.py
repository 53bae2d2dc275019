"""Mean detrending of a step record (a silent wrong answer of the audit): a step input is never
at its mean, so removing the means moves a record that starts at rest away from rest. ``identify``
with the default ``detrend='mean'`` then refits without detrending and keeps the model of the
higher free-run fit (the fit of ``gripkit compare``), with an AccuracyWarning when that is the
refit (docs/reliability.md, "No silent wrong answers").

Record: G(s) = K ω²/(s² + 2ζω s + ω²), K = 3 mm/V, f_n = 10 Hz, ζ = 0.2, sampled at 1 kHz
with a zero-order hold (scipy.signal.cont2discrete, exact for the held input), a 2 V step at
0.1 s, 1 s in all, white measurement noise σ = 5 µm (0.25 % of the 6 mm step)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy import signal

from gripkit.errors import AccuracyWarning
from gripkit.signals.trajectory import Trajectory
from gripkit.sysid import identify
from gripkit.sysid.linear.identify_mimo import step_like
from corpus import assert_warned

K, FN, ZETA, DT = 3.0, 10.0, 0.2, 1e-3
STEP_WARNING = "the input is a step (piecewise constant, at most 4 level changes)"


def step_record(n: int = 1000, seed: int = 0, u=None) -> Trajectory:
    w = 2 * np.pi * FN
    ct = signal.tf2ss([K * w * w], [1.0, 2 * ZETA * w, w * w])
    A, B, C, D, _ = signal.cont2discrete(ct, DT, "zoh")
    if u is None:
        u = np.where(np.arange(n) >= 100, 2.0, 0.0)
    _, y, _ = signal.dlsim((A, B, C, D, DT), u)
    y = y[:, 0] + 0.005 * np.random.default_rng(seed).standard_normal(n)
    return Trajectory(np.arange(n) * DT, {"voltage": u, "position": y},
                      {"voltage": "V", "position": "mm"}, {"dt": DT})


def test_step_like_tells_a_step_from_a_random_input():
    rng = np.random.default_rng(1)
    assert step_like(np.where(np.arange(500) >= 100, 2.0, 0.0))
    assert step_like(np.column_stack([np.repeat([0.0, 1.0, 0.0, 1.0, 0.0], 100), np.ones(500)]))
    assert not step_like(np.sign(rng.standard_normal(50)).repeat(10))  # a PRBS, ~25 switches
    assert not step_like(rng.standard_normal(500))
    assert not step_like(np.full(500, 2.0))  # no step at all


def test_tf_default_on_a_step_recovers_zeta_and_fn_within_3_sigma():
    """With the means removed the fit was 82 % and ζ = 0.34 ± 0.016 (8.7 σ off on the audit's
    record); the refit without detrending is kept, with the warning."""
    with pytest.warns(AccuracyWarning, match=r"identify tf: the input is a step") as rec:
        m = identify(step_record(), "tf", input="voltage", output="position", poles=2, zeros=0)
    assert "the model fitted without detrending is returned" in str(rec[0].message)
    info = m.info
    assert abs(info["damping_ratio"][0] - ZETA) < 3 * info["damping_ratio_std"][0]
    assert abs(info["natural_frequency_hz"][0] - FN) < 3 * info["natural_frequency_hz_std"][0]
    num, den = m.system.numerator(), m.system.denominator()
    assert num[-1] / den[-1] == pytest.approx(K, rel=1e-3)  # DC gain, mm/V
    assert m.fit_percent[0] > 99.0


@pytest.mark.parametrize("method, orders", [("oe", dict(nb=1, nf=2, nk=1)),
                                            ("armax", dict(na=2, nb=1, nc=1, nk=1))])
def test_polynomial_default_on_a_step_keeps_the_model_without_detrending(method, orders):
    """oe and armax of the same record: 98 % with the means removed, 99.5 % without; the kept
    model's DC gain is K (the ZOH sampling keeps it) within 0.5 %."""
    with pytest.warns(AccuracyWarning, match=rf"identify {method}: the input is a step"):
        m = identify(step_record(), method, input="voltage", output="position", **orders)
    g = m.to_tf()  # discrete: the DC gain is G(z = 1)
    assert np.sum(g.numerator()) / np.sum(g.denominator()) == pytest.approx(K, rel=5e-3)


def test_a_random_input_is_still_detrended_without_refit():
    """The same system driven by a PRBS around 1 V: not step-like, the means removed, no
    warning (the rule of a step record stays out of the way)."""
    u = 1.0 + np.sign(np.random.default_rng(2).standard_normal(100)).repeat(10)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        m = identify(step_record(u=u), "tf", input="voltage", output="position", poles=2,
                     zeros=0)
    assert abs(m.info["damping_ratio"][0] - ZETA) < 3 * m.info["damping_ratio_std"][0]


def test_cli_tf_on_a_step_warns_in_the_json_warnings(cli, tmp_path):
    from gripkit.io import save

    p = tmp_path / "step.csv"
    save(step_record(), p)
    res = cli("identify", "tf", p, "--input", "voltage", "--output", "position", "--poles", 2,
              "--zeros", 0, "--json")
    assert res.code == 0, res.err
    assert_warned(res, f"AccuracyWarning: identify tf: {STEP_WARNING}")
    assert_warned(res, "the model fitted without detrending is returned")
    assert res.json()["damping_ratio"][0] == pytest.approx(ZETA, abs=0.005)


def test_mimo_arx_default_on_two_steps_keeps_the_model_without_detrending():
    """Matrix-polynomial ARX of two step inputs (2 V at 0.1 s into the record's system; 1 V at
    0.4 s into y2(t) = 0.9 y2(t−1) + 0.1 u2(t−1)): the returned model is the one fitted without
    detrending, and its mean compare fit beats that of the model fitted with the means removed
    (arx_mimo on the same columns, the means as its offsets)."""
    from gripkit.sysid.linear.arx_mimo import arx_mimo
    from gripkit.sysid.linear.identify_mimo import compare_score, mimo_data

    n = 1000
    base = step_record(n)
    u2 = np.where(np.arange(n) >= 400, 1.0, 0.0)
    y2 = signal.lfilter([0.0, 0.1], [1.0, -0.9], u2)
    y2 = y2 + 0.002 * np.random.default_rng(3).standard_normal(n)
    tr = Trajectory(base.t, {"voltage": base["voltage"], "position": base["position"], "u2": u2,
                             "y2": y2},
                    {"voltage": "V", "position": "mm", "u2": "V", "y2": "mm"}, {"dt": DT})
    cols = dict(input="voltage,u2", output="position,y2")
    with pytest.warns(AccuracyWarning, match=r"identify arx: the input is a step"):
        m = identify(tr, "arx", **cols, na=2, nb=2, nk=1)
    none = identify(tr, "arx", **cols, na=2, nb=2, nk=1, detrend="none")
    np.testing.assert_array_equal(m.theta, none.theta)
    d = mimo_data(tr, cols["input"], cols["output"], "mean")
    mean = arx_mimo(d.u, d.y, 2, 2, 1, dt=d.dt, u_offset=d.u_offset, y_offset=d.y_offset,
                    **d.signals)
    assert compare_score(m, tr) > compare_score(mean, tr)


def test_tfest_of_a_step_with_the_means_removed_starts_from_its_own_initial_state():
    """tfest itself (no refit): the step record with its means removed sits at (−ū, −ȳ) before
    the step, not at rest; the output error from the least-squares initial state recovers ζ and
    f_n within 3 σ (from rest it gave ζ = 0.34 ± 0.016, f_n = 11.6 Hz on the audit's record)."""
    from gripkit.sysid.linear.tfest import tfest

    tr = step_record()
    u, y = tr["voltage"], tr["position"]
    m = tfest(u - u.mean(), y - y.mean(), 2, 0, dt=DT)
    info = m.info
    assert abs(info["damping_ratio"][0] - ZETA) < 3 * info["damping_ratio_std"][0]
    assert abs(info["natural_frequency_hz"][0] - FN) < 3 * info["natural_frequency_hz_std"][0]
