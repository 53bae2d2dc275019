"""The offsets convention (review of poly_t.py): the estimators take u, y as deviations with
u_offset=/y_offset= as metadata; a model's simulate/compare/validate on arrays take the record's
own values and subtract the offsets. Arrays that look like deviations (means within 5 % of their
spans of 0) given to a model whose offsets lie outside their range warn (DataWarning, once per
call, naming the rule); the record's own values do not."""

import warnings

import numpy as np
import pytest
from scipy.signal import lfilter

from gripkit.errors import DataError, DataWarning
from gripkit.sysid import arx, n4sid, oe, validate
from gripkit.sysid.linear.validation import OFFSETS_RULE

U0, Y0 = 2.0, 5.0


def _deviations(n=500, seed=0):
    """The review's plant y = 0.3 q⁻¹/(1 − 1.2 q⁻¹ + 0.5 q⁻²) u (static gain 1), white u, noise
    0.01: deviations from the operating point (U0, Y0), means ≈ 0."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    return u, lfilter([0.0, 0.3], [1.0, -1.2, 0.5], u) + 0.01 * rng.standard_normal(n)


def _deviation_warnings(fn):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = fn()
    return out, [str(w.message) for w in caught
                 if issubclass(w.category, DataWarning) and "look like deviations" in
                 str(w.message)]


@pytest.mark.parametrize("fit", [
    lambda u, y: arx(u, y, 2, 1, 1, dt=0.1, u_offset=U0, y_offset=Y0),
    lambda u, y: oe(u, y, 1, 2, 1, dt=0.1, u_offset=U0, y_offset=Y0),
    lambda u, y: n4sid(u, y, 2, dt=0.1, u_offset=(U0,), y_offset=(Y0,)),
], ids=["arx", "oe", "n4sid"])
def test_deviations_given_to_the_model_warn_once_the_record_does_not(fit):
    """compare on the deviations subtracts the offsets a second time: its fit falls from 96.7 %
    (the record's values) to below 0, and it warns, once, naming the rule; validate (which calls
    compare and residuals) warns once too; the record's values u + U0, y + Y0 give the
    96.7 % fit without a warning."""
    u, y = _deviations()
    m = fit(u, y)
    good, caught = _deviation_warnings(lambda: m.compare(u + U0, y + Y0))
    assert not caught and good.fit_percent[0] > 95.0
    bad, caught = _deviation_warnings(lambda: m.compare(u, y))
    assert len(caught) == 1 and bad.fit_percent[0] < 0.0
    assert OFFSETS_RULE in caught[0]
    assert "u_offset = 2, y_offset = 5" in caught[0] and "pass the record's values" in caught[0]
    for call in (lambda: m.validate(u, y), lambda: validate(m, u, y)):
        _, caught = _deviation_warnings(call)
        assert len(caught) == 1 and ".validate: the arrays look like deviations" in caught[0]
    _, caught = _deviation_warnings(lambda: m.validate(u + U0, y + Y0))
    assert not caught


def test_simulate_warns_on_an_input_far_from_its_offset():
    """simulate takes u alone: an input around 0 with u_offset = 10 (outside its range of about
    ±3) warns; u_offset = 2 (inside that range) cannot be told from a record and does not; the
    record's own values (u + 10) do not."""
    u, y = _deviations()
    far = arx(u, y, 2, 1, 1, dt=0.1, u_offset=10.0, y_offset=Y0)
    _, caught = _deviation_warnings(lambda: far.simulate(u))
    assert len(caught) == 1 and ".simulate: the arrays look like deviations" in caught[0]
    for call in (lambda: far.simulate(u + 10.0),
                 lambda: arx(u, y, 2, 1, 1, dt=0.1, u_offset=U0, y_offset=Y0).simulate(u)):
        _, caught = _deviation_warnings(call)
        assert not caught


def test_no_offsets_or_a_record_around_zero_do_not_warn():
    """A model fitted without offsets takes deviations as its record: no warning; nor does a
    record whose own operating point is 0 when the model's offset lies within its range."""
    u, y = _deviations()
    plain = arx(u, y, 2, 1, 1, dt=0.1)
    _, caught = _deviation_warnings(lambda: plain.compare(u, y))
    assert not caught
    near = arx(u, y, 2, 1, 1, dt=0.1, u_offset=0.5, y_offset=0.3)
    _, caught = _deviation_warnings(lambda: near.compare(u + 0.5, y + 0.3))
    assert not caught


def test_keyword_calls_empty_arrays_and_every_array_method():
    """The deviation check binds arguments as the wrapped signature does: ``validate(model=m,
    u=…, y=…)`` and ``validate(m, u=…, y=…)`` give the positional call's fit (they raised
    TypeError); empty arrays reach the method's own DataError (a bare ValueError came first);
    ``predict`` and ``residuals`` warn on deviations as ``simulate``, ``compare`` and
    ``validate`` do, once each."""
    from gripkit.sysid import arx, validate

    rng = np.random.default_rng(0)
    u = rng.standard_normal(800)
    y = np.convolve(u, [0.0, 1.0, 0.5])[:800] + 0.01 * rng.standard_normal(800)
    m = arx(u, y, 1, 2, 1, u_offset=50.0, y_offset=100.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fits = [validate(m, u + 50, y + 100).fit_percent,
                validate(model=m, u=u + 50, y=y + 100).fit_percent,
                validate(m, u=u + 50, y=y + 100).fit_percent]
    assert fits[0] > 99.0 and fits[1] == fits[0] and fits[2] == fits[0]
    with pytest.raises(DataError):
        m.compare(np.empty(0), np.empty(0))
    for method in ("predict", "residuals"):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            getattr(m, method)(u, y)
        hits = [w for w in caught if "look like deviations" in str(w.message)]
        assert len(hits) == 1 and f".{method}:" in str(hits[0].message)


def test_text_is_no_operating_point():
    """A state-space model's ``u_offset="2.0"`` is refused (numpy would have read the text as a
    number)."""
    from gripkit.errors import ModelError

    rng = np.random.default_rng(1)
    u = rng.standard_normal(300)
    with pytest.raises(ModelError, match="found text"):
        n4sid(u, np.convolve(u, [0.0, 1.0, 0.5])[:300], 2, u_offset="2.0")
