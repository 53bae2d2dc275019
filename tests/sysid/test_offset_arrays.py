"""Arrays, offsets and fit figures of the linear models (audit of the Python API).

* A linear model's arrays are in the units of the data it was fitted on: its ``u_offset`` and
  ``y_offset`` apply to them as to a trajectory (``validate``, ``compare``, ``simulate``,
  ``predict``, ``residuals``), so the two doors give one number.
* ``fit_percent`` of ARX/ARMAX is the one-step prediction fit and says so
  (``fit_percent_definition``); ``simulation_fit_percent`` is the free-run fit of every family.
* An array-level fit of data around an operating point warns (DataWarning).
* ``validate`` and ``sysid.compare`` take a trajectory; a nonlinear model's ``validate`` is a
  ModelError that names ``compare``.

Fits are recomputed by the formula of issue 2: fit % = 100 (1 − ‖y − ŷ‖/‖y − ȳ‖)."""

import json
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.signal import lfilter

from gripkit.cli import main
from gripkit.errors import ArgumentError, DataError, DataWarning, ModelError
from gripkit.io import load
from gripkit.sysid import armax, arx, compare, identify, n4sid, oe, tfest, validate

FIX = Path(__file__).resolve().parents[1] / "fixtures" / "cascaded_tanks"

#: the operating-point record of the audit: ARX truth A = [1, −1.5, 0.7], B = [0, 0.5, 0.3]
#: (static gain 0.8/0.2 = 4), u around 2, y offset 3 (mean ≈ 4·2 + 3 = 11)
TRUTH_A, TRUTH_B = [1.0, -1.5, 0.7], [0.0, 0.5, 0.3]


def _fit(y, yhat):
    y, yhat = np.ravel(y), np.ravel(yhat)
    return 100.0 * (1.0 - np.linalg.norm(y - yhat) / np.linalg.norm(y - y.mean()))


@pytest.fixture(scope="module")
def tanks():
    return (load(FIX / "cascaded_tanks_est.csv"), load(FIX / "cascaded_tanks_val.csv"))


def _record(offset_u=2.0, offset_y=3.0, n=2000, seed=0):
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n) + offset_u
    y = lfilter(TRUTH_B, TRUTH_A, u) + 0.1 * rng.standard_normal(n) + offset_y
    return u, y


# ---------------------------------------------------------------------------------------- A
def test_validate_on_the_record_columns_is_compare_on_the_record(tanks):
    """The audit's case: ARX [2 2 1] of the cascaded tanks (identify removes the means, the
    model keeps them as offsets, u_offset 2.8, y_offset 5.58). validate on the validation
    record's raw columns gave −273.8 % (the arrays taken as deviations) against compare's
    66.9 %; now both are 66.94 %, the formula's fit of compare's free run, and the −273.8 %
    is what a model at a zero operating point gives on those columns."""
    est, val = tanks
    m = identify(est, "arx", input="pump", output="level", na=2, nb=2, nk=1)
    assert (m.u_offset, m.y_offset) == pytest.approx((2.8, 5.5827), abs=1e-4)
    u, y = np.asarray(val["pump"]), np.asarray(val["level"])
    fitted = m.compare(val)
    assert fitted.fit_percent[0] == pytest.approx(_fit(y, fitted.simulated), rel=1e-12)
    assert fitted.fit_percent[0] == pytest.approx(66.94, abs=0.01)
    v = m.validate(u, y)
    assert v.fit_percent == fitted.fit_percent[0]
    assert validate(m, u, y).fit_percent == fitted.fit_percent[0]
    assert compare(m, u, y).fit_percent == fitted.fit_percent
    at_zero = m.replace(u_offset=0.0, y_offset=0.0)
    assert at_zero.validate(u, y).fit_percent == pytest.approx(-273.8, abs=0.1)
    # the one-step fit of validate, by the formula, on the samples after the predictor's start
    t0 = m.start
    assert v.prediction_fit_percent == pytest.approx(_fit(y[t0:], v.y_pred[t0:]), rel=1e-12)
    assert v.prediction_fit_percent == pytest.approx(97.38, abs=0.01)


@pytest.mark.parametrize("method, orders", [
    ("arx", dict(na=2, nb=2, nk=1)), ("oe", dict(nb=2, nf=2, nk=1)), ("ss", dict(order=2)),
])
def test_arrays_and_trajectory_give_the_same_results(tanks, method, orders):
    """simulate, predict, residuals and compare of a record's columns are those of the record
    (to the rounding of the offsets removed and added back)."""
    est, val = tanks
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # ss: the stabilised-estimate warning
        m = identify(est, method, input="pump", output="level", **orders)
    u, y = np.asarray(val["pump"]), np.asarray(val["level"])
    np.testing.assert_allclose(np.ravel(m.simulate(u)), np.ravel(m.simulate(val)), atol=1e-12)
    np.testing.assert_allclose(np.ravel(m.predict(u, y)), np.ravel(m.predict(val)), atol=1e-12)
    np.testing.assert_allclose(np.ravel(m.residuals(u, y)), np.ravel(m.residuals(val)),
                               atol=1e-12)
    assert m.compare(u, y).fit_percent == pytest.approx(m.compare(val).fit_percent, rel=1e-12)
    assert m.validate(u, y).fit_percent == pytest.approx(m.compare(val).fit_percent[0],
                                                         rel=1e-12)


def test_a_model_fitted_on_arrays_has_no_offset_to_apply():
    """arx of arrays: zero offsets, so compare on the same arrays scores them as they are (the
    free run plus nothing: the formula on compare's own simulated output)."""
    u, y = _record(0.0, 0.0)
    m = arx(u, y, 2, 2, 1)
    assert (m.u_offset, m.y_offset) == (0.0, 0.0)
    fitted = m.compare(u, y)
    assert fitted.fit_percent[0] == pytest.approx(_fit(y, fitted.simulated), rel=1e-12)
    np.testing.assert_array_equal(m.simulate(u), m.system.simulate(u)[:, 0])


# ---------------------------------------------------------------------------------------- B
def test_fit_percent_says_what_it_is_and_simulation_fit_ranks_like_with_like(tanks):
    """On the cascaded tanks estimation record ARX's fit_percent (97.79 %) is its one-step fit
    (the formula on predict's ŷ(t|t−1)), OE's (75.66 %) its free run: ranking by fit_percent
    puts ARX first. simulation_fit_percent is compare's free-run fit for every family (ARX
    71.48 %, OE 75.66 %, ss 72.78 %, NARX 66.14 %), so it ranks OE first."""
    est, _ = tanks
    y = np.asarray(est["level"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ms = {"arx": identify(est, "arx", input="pump", output="level", na=2, nb=2, nk=1),
              "oe": identify(est, "oe", input="pump", output="level", nb=2, nf=2, nk=1),
              "ss": identify(est, "ss", input="pump", output="level", order=2)}
    a = ms["arx"]
    t0 = a.start
    assert a.fit_percent == pytest.approx(_fit(y[t0:], a.predict(est)[t0:]), rel=1e-9)
    assert a.prediction_fit_percent == a.fit_percent == pytest.approx(97.79, abs=0.01)
    assert a.fit_percent_definition.startswith("one-step-ahead prediction")
    assert ms["ss"].fit_percent_definition.startswith(ms["ss"].fit_definition)
    for name, m in ms.items():
        want = m.compare(est).fit_percent
        assert m.simulation_fit_percent == pytest.approx(want, rel=1e-9), name
    assert a.simulation_fit_percent[0] == pytest.approx(71.48, abs=0.01)
    assert ms["oe"].simulation_fit_percent[0] == pytest.approx(75.66, abs=0.01)
    assert a.fit_percent > ms["oe"].fit_percent  # the one-step figure: ARX looks better
    best = max(ms, key=lambda k: ms[k].simulation_fit_percent[0])
    assert best == "oe"


def test_cli_json_keeps_fit_percent_and_states_its_definition(capsys):
    """gripkit identify arx --json keeps issue 2's keys (fit_percent the one-step fit, 97.79 %
    on the cascaded tanks) and states which fit it is."""
    code = main(["identify", "arx", str(FIX / "cascaded_tanks_est.csv"), "--input", "pump",
                 "--output", "level", "--na", "2", "--nb", "2", "--nk", "1", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert code == 0
    assert {"structure", "na", "nb", "nk", "A", "B", "A_std", "B_std", "loss", "fit_percent",
            "poles", "zeros", "minimum_phase", "n_samples"} <= set(out)
    assert out["fit_percent"] == pytest.approx(97.79, abs=0.01)
    assert out["fit_percent_definition"].startswith("one-step-ahead prediction")


def test_narx_simulation_fit_is_its_free_run_fit(tanks):
    est, val = tanks
    m = identify(est, "narx", input="pump", output="level")
    assert m.simulation_fit_percent == [m.fit_percent]
    assert m.simulation_fit_percent == pytest.approx(m.compare(est).fit_percent, rel=1e-12)


# ---------------------------------------------------------------------------------------- C
@pytest.mark.parametrize("fit", [
    lambda u, y: arx(u, y, 2, 2, 1), lambda u, y: oe(u, y, 2, 2, 1),
    lambda u, y: armax(u, y, 2, 2, 1, 1, maxiter=5), lambda u, y: n4sid(u, y, 2),
    lambda u, y: tfest(u, y, 2, 1, dt=1.0),
], ids=["arx", "oe", "armax", "n4sid", "tfest"])
def test_arrays_around_an_operating_point_warn(fit):
    """u around 2, y with an offset of 3: the model has no constant term, so the fit is biased
    (the audit: OE static gain 5.47 against the truth 4.0). The ARX check with a constant finds
    c = 3 (1 − 1.5 + 0.7) = 0.6 (0.58 estimated) and a static gain of 4.06 against 5.46
    without it; the warning names the means and the fix."""
    u, y = _record()
    with pytest.warns(DataWarning, match=r"operating point \(mean u = 1\.972, mean y = 10\.89\)"
                                         r".*static gain of 4\.059 against 5\.463.*subtract the "
                                         r"means"):
        warnings.simplefilter("ignore", category=UserWarning)
        warnings.simplefilter("always", category=DataWarning)
        fit(u, y)


def _operating_point_warnings(fn):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = fn()
    return out, [w for w in caught if "operating point" in str(w.message)]


def test_centred_data_and_a_step_from_rest_do_not_warn():
    """The same record with its means removed fits without the warning (and OE's static gain is
    then the truth's 4.0 within 5 %, where the raw record gave 5.47); a step from rest (u 0 → 1,
    y from 0: no constant, c ≈ 0) does not warn either."""
    u, y = _record()
    m, caught = _operating_point_warnings(lambda: oe(u - u.mean(), y - y.mean(), 2, 2, 1))
    assert not caught
    assert m.dc_gain == pytest.approx(4.0, rel=0.05)
    rng = np.random.default_rng(3)
    step = np.where(np.arange(1500) >= 100, 1.0, 0.0)
    ys = lfilter(TRUTH_B, TRUTH_A, step) + 0.01 * rng.standard_normal(step.size)
    for fn in (lambda: arx(step, ys, 2, 2, 1), lambda: oe(step, ys, 2, 2, 1),
               lambda: n4sid(step, ys, 2)):
        _, caught = _operating_point_warnings(fn)
        assert not caught
    # the same step with the output 3 above rest: c = 3·0.2 = 0.6 (0.67), and the fix named is
    # the steady state before the step, not the mean of a step record
    with pytest.warns(DataWarning, match=r"subtract the steady state before the step "
                                         r"\(u = 0, y = 3\.02\)"):
        arx(step, ys + 3.0, 2, 2, 1)


@pytest.mark.parametrize("method, orders", [
    ("arx", dict(na=2, nb=2, nk=1)), ("armax", dict(na=2, nb=2, nc=1, nk=1)),
    ("oe", dict(nb=2, nf=2, nk=1)), ("ss", dict(order=2)), ("tf", dict(poles=2, zeros=1)),
])
def test_identify_of_the_measured_fixture_does_not_warn(tanks, method, orders):
    """identify removes the means first (its default detrend): no operating-point warning."""
    est, _ = tanks
    _, caught = _operating_point_warnings(
        lambda: identify(est, method, input="pump", output="level", **orders))
    assert not caught


# ---------------------------------------------------------------------------------------- D
def test_validate_and_sysid_compare_take_a_trajectory(tanks):
    est, val = tanks
    m = identify(est, "arx", input="pump", output="level", na=2, nb=2, nk=1)
    u, y = np.asarray(val["pump"]), np.asarray(val["level"])
    v = m.validate(val)
    assert v.fit_percent == m.validate(u, y).fit_percent == m.compare(val).fit_percent[0]
    assert v.prediction_fit_percent == m.validate(u, y).prediction_fit_percent
    assert compare(m, val).fit_percent == m.compare(val).fit_percent
    assert validate(m, val).fit_percent == v.fit_percent
    with pytest.raises(ArgumentError, match="a trajectory carries its outputs and sample time"):
        compare(m, val, dt=1.0)
    with pytest.raises(ArgumentError, match="a trajectory carries its outputs and sample time"):
        m.validate(val, y)
    with pytest.raises(ArgumentError, match="give a trajectory with the model's columns, or "
                                            "the arrays u and y"):
        m.validate(u)
    with pytest.raises(DataError, match=r"output column\(s\) 'level' are missing"):
        m.validate(val.select("pump"))


def test_a_nonlinear_model_validate_names_compare(tanks):
    est, val = tanks
    m = identify(est, "narx", input="pump", output="level")
    with pytest.raises(ModelError, match=r"a NARX model is not a linear model.*use "
                                         r"model\.compare\(data\)"):
        m.validate(val)
    assert compare(m, val).fit_percent == m.compare(val).fit_percent


def test_one_number_is_the_operating_point_of_a_single_channel():
    """``u_offset=2.0`` on a one-input model is ``(2.0,)`` (it raised TypeError: 'float' object is
    not iterable); on several channels one number is refused rather than copied to each."""
    from gripkit.lti import StateSpace
    from gripkit.sysid import LinearModel

    rng = np.random.default_rng(0)
    u = rng.standard_normal(500)
    y = np.convolve(u, [0.0, 1.0, 0.5])[:500] + 0.01 * rng.standard_normal(500)
    m = n4sid(u, y, 2, u_offset=2.0, y_offset=3.0)
    assert (m.u_offset, m.y_offset) == ((2.0,), (3.0,))
    two = StateSpace(np.eye(1) * 0.5, np.ones((1, 2)), np.ones((1, 1)), np.zeros((1, 2)), dt=1.0)
    with pytest.raises(ModelError, match="one number given for 2 channels"):
        LinearModel(two, "n4sid", u_offset=1.0)
