"""The Bouc-Wen oscillator's initial state at each record's first sample (gripkit issue 26):
``initial_state='estimate'`` (the default) estimates (x0, ẋ0, z0) of every record with θ, σ
from the Jacobian over θ and the states together; ``'zero'`` runs every record from rest. A
record that starts in motion biases the from-rest fit; the estimate recovers θ and the states
within 3σ, agrees with an independent least squares over θ and the states, and on records that
do start at rest gives θ of the from-rest fit within a fraction of σ."""

import json
import warnings

import numpy as np
import pytest
from scipy.optimize import least_squares
from test_hysteresis_records import OSC, OSC_DT, OSC_NOISE, _osc_records, _write

from gripkit.errors import ArgumentError
from gripkit.sysid import BoucWenOscillatorModel, hysteresis, load_model
from gripkit.sysid.nonlinear.hysteresis_kernels import bwo_sample

STATES = ("x0", "v0", "z0")
#: the state (x [m], ẋ [m/s], z [m]) each record starts in: moving, away from rest (z saturates
#: at 2.5 mm)
MOVING = [{"x0": -5e-3, "v0": 0.13, "z0": 1.7e-3}, {"x0": 3e-3, "v0": -0.08, "z0": -1.2e-3}]


def _moving_forces(n):
    """Two force records (N) cut out of a longer drive: neither is 0 at its first sample."""
    t = np.arange(n) * OSC_DT
    return [15 * np.sin(2 * np.pi * 2 * t + 0.3) * (1 - 0.5 * t / t[-1])
            + 5 * np.sin(2 * np.pi * 5.3 * t),
            12 * np.sin(2 * np.pi * 3.1 * t + 1.0) + 4 * np.sin(2 * np.pi * 7.7 * t)]


def _moving_records(n, count, seed):
    """``count`` noisy records of ``n`` samples of the oscillator, each from its state of
    :data:`MOVING`."""
    truth = BoucWenOscillatorModel(**OSC, dt=OSC_DT)
    rng = np.random.default_rng(seed)
    return [(f, truth.simulate(f, x0=s)[:, 0] + rng.normal(0.0, OSC_NOISE, n))
            for f, s in zip(_moving_forces(n)[:count], MOVING)]


def _inside(m, states=MOVING):
    """(how many of θ and the records' initial states are within 3σ of the truth, how many)."""
    z = [abs(getattr(m, k) - OSC[k]) / m.std[k] for k in m.free]
    z += [abs(s[k] - t[k]) / s["std"][k] for s, t in zip(m.initial_states, states) for k in STATES]
    return sum(v < 3 for v in z), len(z)


def _floor(y):
    return 100 * (1 - OSC_NOISE * np.sqrt(len(y)) / np.linalg.norm(y - y.mean()))


def test_record_started_in_motion_recovered_where_the_from_rest_fit_is_biased():
    """One record (1.5 s) that starts at x = −5 mm, ẋ = 0.13 m/s, z = 1.7 mm: estimated (the
    default) the 7 parameters and the 3 initial states are within 3σ (0.03–1.4σ here) and the
    free run from them is at the noise floor (97.7 %); run from rest (the old path) the
    parameters are biased beyond 3σ of that fit's own σ (all but the offset, 3.4–17σ) and its
    free run is far worse (87.1 %); 600 samples of burn_in (the transient's 0.6 s) leave the
    mass 3.5σ off."""
    [(u, y)] = _moving_records(1500, 1, 0)
    m = hysteresis((u, y), form="oscillator", dt=OSC_DT, progress=False)
    assert m.initial_state_option == "estimate" and len(m.initial_states) == 1
    assert _inside(m) == (10, 10)
    assert m.fit_percent == pytest.approx(_floor(y), abs=0.3)
    for kw in ({}, {"burn_in": 600}):
        old = hysteresis((u, y), form="oscillator", dt=OSC_DT, initial_state="zero",
                         progress=False, **kw)
        assert old.initial_states == []
        bias = [abs(getattr(old, k) - OSC[k]) / old.std[k] for k in old.free]
        assert max(bias) > 3, (kw, bias)
        if not kw:
            assert sum(b > 3 for b in bias) >= 6 and old.fit_percent < m.fit_percent - 5


def test_initial_state_fit_equals_least_squares_over_theta_and_states():
    """Two records started in motion: θ and each record's (x0, ẋ0, z0) are the optimum (within
    10⁻⁴σ; 3·10⁻⁶σ here) of scipy's least squares on the stacked free runs of
    BoucWenOscillatorModel.simulate from x0 (central differences, 3-point), and their σ (θ's:
    the θ block of s² (JᵀJ)⁻¹ over θ and the states) agree within 0.1 % (4·10⁻⁵ here): the
    states' Jacobian columns of the fit (forward differences, each state's from a run of its
    own record) are right."""
    recs = _moving_records(1000, 2, 3)
    m = hysteresis(recs, form="oscillator", dt=OSC_DT, progress=False)
    names = list(m.free)
    scale = np.array([1.0, 10.0, 1e3, 1e3, 100.0, 100.0, 1e-3] + [1e-3, 0.1, 1e-3] * 2)
    nth = len(names)

    def resid(p):
        q = p * scale
        mm = BoucWenOscillatorModel(**dict(zip(names, q[:nth])), dt=OSC_DT)
        return np.concatenate([y - mm.simulate(u, x0=q[nth + 3 * i:nth + 3 * i + 3])[:, 0]
                               for i, (u, y) in enumerate(recs)]) / OSC_NOISE

    start = [OSC[k] for k in names] + [s[k] for s in MOVING for k in STATES]
    ref = least_squares(resid, np.array(start) / scale, jac="3-point", xtol=1e-12, ftol=1e-12,
                        gtol=1e-12)
    s2 = 2 * ref.cost / (len(ref.fun) - len(ref.x))
    ref_std = np.sqrt(np.diag(s2 * np.linalg.inv(ref.jac.T @ ref.jac))) * scale
    ours = [getattr(m, k) for k in names] + [s[k] for s in m.initial_states for k in STATES]
    sd = [m.std[k] for k in names] + [s["std"][k] for s in m.initial_states for k in STATES]
    for i, (v, r, s, rs) in enumerate(zip(ours, ref.x * scale, sd, ref_std)):
        assert abs(v - r) < 1e-4 * s, i
        assert s == pytest.approx(rs, rel=1e-3), i
    assert _inside(m) == (13, 13)


def test_burn_in_moves_the_estimated_state_to_the_first_scored_sample():
    """With burn_in = 300 the state is estimated at sample 300 (the samples before it dropped,
    as a state they alone show is not identifiable): θ within 3σ (0.2–1.2σ here), the state
    within 3σ of the truth's at sample 300 (stepped there by the oscillator's own RK4 sample
    step), no warning; the fit is the free run of the record's samples 300 … from that state."""
    [(u, y)] = _moving_records(1500, 1, 0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        m = hysteresis((u, y), form="oscillator", dt=OSC_DT, burn_in=300, progress=False)
    [s] = m.initial_states
    p = tuple(float(OSC[k]) for k in ("mass", "damping", "k_e", "k_h", "beta", "gamma")) + (1.0,)
    x = tuple(MOVING[0][k] for k in STATES)
    for k in range(300):
        x = bwo_sample(*x, u[k], OSC_DT / 4, 4, p)
    assert s["sample"] == 300
    assert _inside(m, [dict(zip(STATES, x))]) == (10, 10)
    run = m.simulate(u[300:], x0=s)[:, 0]
    fit = 100 * (1 - np.linalg.norm(y[300:] - run) / np.linalg.norm(y[300:] - y[300:].mean()))
    assert fit == pytest.approx(m.fit_percent, abs=1e-9)


def test_initial_state_small_monte_carlo():
    """Six seeded records started in motion: ≥ 90 % of the 60 (run, parameter or initial
    state) pairs within 3σ."""
    inside = sum(_inside(hysteresis(_moving_records(1500, 1, seed)[0], form="oscillator",
                                    dt=OSC_DT, progress=False))[0] for seed in range(6))
    assert inside >= 0.9 * 60


@pytest.mark.slow
def test_initial_state_monte_carlo():
    """30 seeded runs of two records (1.5 s each) started in motion: ≥ 90 % of the 390 (run,
    parameter or initial state) pairs within 3σ."""
    inside = sum(_inside(hysteresis(_moving_records(1500, 2, seed), form="oscillator",
                                    dt=OSC_DT, progress=False))[0] for seed in range(200, 230))
    assert inside >= 0.9 * 390


def test_records_at_rest_give_the_same_theta_either_way():
    """Three records that do start at rest (those of test_hysteresis_records): θ estimated with
    the initial states differs from the from-rest θ by < 0.25σ (0.04–0.13σ here), within 3 ×
    √(σ_est² − σ_rest²), the spread the difference of the two estimators has when both are
    right; the price is σ up to 15 % larger (3.5–12.5 % here); the states come out at 0 within
    3σ and the fit is the same within 0.01 %."""
    recs = _osc_records(1000, 3, 5)
    rest = hysteresis(recs, form="oscillator", dt=OSC_DT, initial_state="zero", progress=False)
    est = hysteresis(recs, form="oscillator", dt=OSC_DT, progress=False)
    for k in rest.free:
        d = abs(getattr(est, k) - getattr(rest, k))
        assert d < 0.25 * rest.std[k], k
        assert d < 3 * np.sqrt(est.std[k] ** 2 - rest.std[k] ** 2), k
        assert 1.0 < est.std[k] / rest.std[k] < 1.15, k
    assert all(abs(s[k]) < 3 * s["std"][k] for s in est.initial_states for k in STATES)
    assert est.fit_percent == pytest.approx(rest.fit_percent, abs=0.01)


def test_initial_states_kept_in_the_file_not_in_the_parameters(tmp_path):
    """Saved and read back the model keeps how it started its records and each record's state
    with σ; the states are no parameters; simulate(u, x0=state) replays the estimation record
    (its fit_percent), simulate(u) runs from rest; the summary lists them as nuisance."""
    [(u, y)] = _moving_records(1500, 1, 1)
    m = hysteresis((u, y), form="oscillator", dt=OSC_DT, progress=False)
    m2 = load_model(m.save(tmp_path / "osc.json"))
    assert m2.initial_state_option == "estimate" and m2.initial_states == m.initial_states
    assert m2.parameters == m.parameters and not set(STATES) & set(m.parameters)
    run = m2.simulate(u, x0=m2.initial_states[0])[:, 0]
    fit = 100 * (1 - np.linalg.norm(y - run) / np.linalg.norm(y - y.mean()))
    assert fit == pytest.approx(m.fit_percent, abs=1e-9)
    s = m.initial_states[0]
    np.testing.assert_array_equal(run, m.simulate(u, x0=(s["x0"], s["v0"], s["z0"]))[:, 0])
    assert m.simulate(u)[0, 0] == m.offset and run[0] == pytest.approx(s["x0"] + m.offset)
    assert "initial state of each estimation record (nuisance, not parameters)" in m.summary()
    assert "record 0: x0 = " in m.summary()
    zero = hysteresis((u, y), form="oscillator", dt=OSC_DT, initial_state="zero",
                      progress=False)
    doc = json.loads(zero.save(tmp_path / "z.json").read_text())
    assert doc["initial_state"] == "zero" and doc["initial_states"] == []


def test_bad_initial_state_option(tmp_path, capsys):
    """An unknown option, the estimate asked of a model that has no such state, a malformed x0:
    one-line ArgumentErrors naming the argument; the CLI's --initial-state likewise."""
    from gripkit.cli import main

    [(u, y)] = _moving_records(1000, 1, 2)
    with pytest.raises(ArgumentError, match="initial_state must be one of estimate, zero") as e:
        hysteresis((u, y), form="oscillator", dt=OSC_DT, initial_state="rest")
    assert "\n" not in str(e.value)
    with pytest.raises(ArgumentError, match="initial_state='estimate' is for the Bouc-Wen "
                                            "oscillator"):
        hysteresis((u, y), initial_state="estimate")
    m = BoucWenOscillatorModel(**OSC, dt=OSC_DT)
    with pytest.raises(ArgumentError, match=r"x0 must be the state \(x, ẋ, z\)"):
        m.simulate(u, x0=(1e-3, 0.0))
    a = _write(tmp_path / "A.csv", u, y)
    code = main([str(x) for x in ["identify", "hysteresis", a, "--input", "F", "--output", "x",
                                  "--form", "oscillator", "--initial-state", "rest", "--json"]])
    out, err = capsys.readouterr()
    assert code != 0 and out == ""
    assert err.startswith("error: DataError: --initial-state: expected one of estimate, zero")
    assert len(err.strip().splitlines()) == 1


def test_cli_initial_states_of_two_files(tmp_path, capsys):
    """`gripkit identify hysteresis A.csv B.csv --form oscillator --json`: the structure says
    the initial states were estimated, ``initial_states`` gives each file's (x0, ẋ0, z0) with σ
    as the Python call (within 10⁻³σ: the files' time column), the truth within 3σ;
    ``--initial-state zero`` gives none."""
    from gripkit.cli import main

    recs = _moving_records(1000, 2, 4)
    a, b = (_write(tmp_path / f"{k}.csv", *r) for k, r in zip("AB", recs))
    ref = hysteresis(recs, form="oscillator", dt=OSC_DT, progress=False)
    docs = {}
    for option in ("zero", "estimate"):
        code = main([str(x) for x in ["identify", "hysteresis", a, b, "--input", "F", "--output",
                                      "x", "--form", "oscillator", "--initial-state", option,
                                      "--json"]])
        out, err = capsys.readouterr()
        assert code == 0, err
        docs[option] = d = json.loads(out)
        assert d["structure"]["initial_state"] == option and d["warnings"] == []
    assert docs["zero"]["initial_states"] == []
    assert [s["data"] for s in d["initial_states"]] == [str(a), str(b)]
    for s, r, t in zip(d["initial_states"], ref.initial_states, MOVING):
        assert s["units"] == {"x0": "1", "v0": "1/s", "z0": "1"}  # the files have no units
        for k in STATES:
            assert s[k] == pytest.approx(r[k], abs=1e-3 * r["std"][k])  # the file's dt
            assert s["std"][k] == pytest.approx(r["std"][k], rel=1e-4)
            assert abs(s[k] - t[k]) < 3 * s["std"][k], k
