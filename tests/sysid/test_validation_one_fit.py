"""One validation fit (issue 23): :func:`gripkit.sysid.compare` and :func:`gripkit.sysid.validate`
report exactly ``model.compare(u, y).fit_percent`` (free run from the least-squares initial
state, every sample scored) for ARX, ARMAX, OE and state-space models, on noisy records of the
Table II [2 2 2] plant; ``validate`` works on a state-space model too."""

import numpy as np
import pytest
from arx_cases import A222, B222, simulate_arx
from scipy.signal import lfilter

from gripkit.errors import ArgumentError, ModelError
from gripkit.sysid import (ModelFit, PolynomialModel, armax, arx, compare, fit_percent, n4sid, oe,
                           residual_tests, validate)

DT = 0.005
C1 = (1.0, 0.5)  # ARMAX noise polynomial C = 1 + 0.5 q⁻¹


def _records(kind: str, **kw):
    """An estimation and a validation record of the same plant (noise σ = 2, seeds fixed)."""
    return (simulate_arx(3000, noise=2.0, seed=230, kind=kind, **kw),
            simulate_arx(2000, noise=2.0, seed=231, kind=kind, **kw))


FAMILIES = {  # name: (records, fit on (u, y), the true model)
    "arx": (lambda: _records("arx"), lambda u, y: arx(u, y, 2, 2, 2, dt=DT),
            PolynomialModel.from_coefficients(A222, B222, dt=DT)),
    "armax": (lambda: _records("arx", C=C1), lambda u, y: armax(u, y, 2, 2, 1, 2, dt=DT),
              PolynomialModel.from_coefficients(A222, B222, C=C1, dt=DT)),
    "oe": (lambda: _records("oe", F=A222), lambda u, y: oe(u, y, 2, 2, 2, dt=DT),
           PolynomialModel.from_coefficients([1.0], B222, F=A222, dt=DT)),
    # B/F with a delay of 2 samples: 3 states, (b2 z + b3)/(z³ + f1 z² + f2 z)
    "ss": (lambda: _records("oe", F=A222), lambda u, y: n4sid(u, y, 3, dt=DT),
           PolynomialModel.from_coefficients([1.0], B222, F=A222, dt=DT)),
}


@pytest.mark.parametrize("family", sorted(FAMILIES))
def test_sysid_compare_and_validate_give_model_compare_fit(family):
    """The same number, bit for bit, from the three doors; and it is the right number: the fitted
    model scores within 0.5 % of the true model's fit on the same noisy record."""
    records, fit, true = FAMILIES[family]
    (ue, ye), (uv, yv) = records()
    m = fit(ue, ye)
    one = m.compare(uv, yv)
    got = compare(m, uv, yv)
    assert isinstance(got, ModelFit) and got.fit_percent == one.fit_percent
    np.testing.assert_array_equal(got.simulated, one.simulated)
    v = validate(m, uv, yv)
    assert v.fit_percent == one.fit_percent[0] and v.simulation.fit_percent == one.fit_percent
    assert v.to_dict()["fit_percent"] == one.fit_percent[0]
    assert abs(one.fit_percent[0] - true.compare(uv, yv).fit_percent[0]) < 0.5


def test_validate_state_space_model():
    """A SISO state-space model: the one-step errors are model.residuals, the prediction fit that
    of model.predict, the residual tests those of residual_tests on those errors; on output-error
    data (white output noise σ = 2, the true predictor's loss σ²/2 = 2 by eq 29) the errors are
    independent of the input and the loss is no lower than σ²/2 − 8 % and within 50 % of it."""
    (ue, ye), (uv, yv) = _records("oe", F=A222)
    m = n4sid(ue, ye, 3, dt=DT)
    v = validate(m, uv, yv)
    e = m.residuals(uv, yv)[:, 0]
    np.testing.assert_array_equal(v.residuals, e)
    assert v.prediction_fit_percent == pytest.approx(fit_percent(yv, m.predict(uv, yv)[:, 0]),
                                                     abs=1e-9)
    assert v.tests.to_dict() == residual_tests(e, uv).to_dict()
    assert v.stable and v.tests.independent
    assert 0.92 * 2.0 < v.loss < 1.5 * 2.0


def test_compare_two_by_two_state_space():
    """y1 = 0.4 q⁻¹/(1 − 0.7 q⁻¹) u1 + 0.2 q⁻¹ u2, y2 = 0.3 q⁻¹/(1 − 0.5 q⁻¹) u2 (3 states) with
    output noise σ = 0.02: compare() is model.compare() per output, and each output fits within
    0.1 % of the noise-free true output's fit (the ceiling the noise leaves); validate() takes
    one input and one output only."""
    rng = np.random.default_rng(232)
    u = rng.standard_normal((4000, 2))
    y0 = np.column_stack([lfilter([0, 0.4], [1, -0.7], u[:, 0])
                          + lfilter([0, 0.2], [1], u[:, 1]),
                          lfilter([0, 0.3], [1, -0.5], u[:, 1])])
    y = y0 + 0.02 * rng.standard_normal(y0.shape)
    m = n4sid(u[:2000], y[:2000], 3, dt=DT)
    got = compare(m, u[2000:], y[2000:])
    assert got.fit_percent == m.compare(u[2000:], y[2000:]).fit_percent
    ceiling = [fit_percent(y[2000:, i], y0[2000:, i]) for i in range(2)]
    np.testing.assert_allclose(got.fit_percent, ceiling, atol=0.1)
    with pytest.raises(ModelError, match="validate takes one of each"):
        validate(m, u[2000:, 0], y[2000:, 0])


def test_compare_refuses_what_is_not_a_model():
    """An array where the model belongs: ArgumentError naming the argument and what it expects."""
    u, y = simulate_arx(100, seed=233)
    with pytest.raises(ArgumentError, match="model: expected an identified model, found ndarray"):
        compare(np.array([1.0, -0.5]), u, y)


def test_a_continuous_model_validates_with_the_arrays_sample_time():
    """A continuous transfer function (tfest) of 25/(s² + 4 s + 25), sampled at 100 Hz with
    output noise: ``validate(..., dt=)`` and ``model.validate(..., dt=)`` give exactly
    ``model.compare(u, y, dt=)``'s fit, its residuals are ``model.residuals``; without ``dt``
    the arrays carry no sample time and the call is refused in one line."""
    from scipy import signal

    from gripkit import Trajectory
    from gripkit.sysid import identify

    rng = np.random.default_rng(1)
    N, dt = 1500, 0.01
    t = np.arange(N) * dt
    u = rng.standard_normal(N)
    y = signal.lsim(signal.TransferFunction([25.0], [1.0, 4.0, 25.0]), u, t)[1]
    y = y + 0.01 * rng.standard_normal(N)
    m = identify(Trajectory(t, {"u": u, "y": y}), "tf", inputs="u", outputs="y", poles=2,
                 zeros=0)
    uu, yy = u - np.ravel(m.u_offset)[0], y - np.ravel(m.y_offset)[0]
    fit = m.compare(uu, yy, dt=dt).fit_percent[0]
    v = validate(m, uu, yy, dt=dt)
    assert v.fit_percent == fit == m.validate(uu, yy, dt=dt).fit_percent and fit > 90.0
    np.testing.assert_array_equal(v.residuals, m.residuals(uu, yy, dt=dt)[:, 0])
    with pytest.raises(ArgumentError, match="the model is continuous"):
        validate(m, uu, yy)
