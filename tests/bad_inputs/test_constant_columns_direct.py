"""Constant columns given straight to the estimators (audit of 27 Nov): ``tfest`` with a constant
output failed with numpy's raw ``LinAlgError`` ("SVD did not converge"), its FRF start being
zero; it now gives the UnidentifiableError of the other estimators
(:func:`gripkit.sysid.checks.check_output_varies`), naming the channel, its value (the offset
added back) and its unit, also for ``tfest_records`` (naming the record) and
``identify(..., "tf")``.

Direct calls of ``n4sid``, ``frf``, ``tfest`` and ``arx_mimo`` had no constant-column check of
their own (only ``identify`` checked; n4sid refused only an all-zero column): an input held at
0.7 V was fitted by n4sid and arx_mimo and went into an FRF without a word. They now run the
same checks (:func:`gripkit.sysid.checks.check_columns_vary`, ``check_excitation`` /
``check_output_varies``) on each column: an exactly constant one (span ≤ 1e-12 of its peak) is
an UnidentifiableError naming the channel; the data are deviation units (n4sid's documented
contract), so a constant input is no offset input but a channel that carries nothing.

The SISO data: a white-noise input (seeded) through G(s) = 4/(s² + 0.8 s + 4), sampled with a
zero-order hold at dt = 0.05 s (the example of ``tfest``'s docstring); the MIMO data: two
white-noise inputs through the 2 × 2 first-order ARX y(t) = [[0.5, 0.1], [0, 0.7]] y(t−1) +
u(t−1) (the example of ``arx_mimo``'s docstring), noise-free."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from gripkit import Trajectory
from gripkit.errors import UnidentifiableError
from gripkit.lti import TransferFunction
from gripkit.sysid import frf, identify, n4sid, tfest
from gripkit.sysid.linear.arx_mimo import arx_mimo
from gripkit.sysid.linear.tfest import tfest_records

DT = 0.05
N = 1000
U = np.random.default_rng(0).standard_normal(N)
Y = TransferFunction([4.0], [1.0, 0.8, 4.0]).c2d(DT).simulate(U)[:, 0]
NO_DYNAMICS = "there are no dynamics to identify; no estimate returned"


def _refused(fn, phrase):
    """The UnidentifiableError of ``fn()``, its message holding ``phrase``, no numpy warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(UnidentifiableError) as e:
            fn()
    assert phrase in str(e.value), str(e.value)
    return str(e.value)


@pytest.mark.parametrize("level", [0.0, 3.0])
def test_tfest_constant_output(level):
    """Zero and a constant level: the estimators' message, the level in it."""
    y = np.full(N, level)
    _refused(lambda: tfest(U, y, 2, 0, dt=DT),
             f"output y is constant ({level:g} for all {N} samples): {NO_DYNAMICS}")


def test_tfest_constant_output_names_the_channel_its_level_and_unit():
    """Named as identify names it: the column, the offset added back, the unit."""
    _refused(lambda: tfest(U, np.zeros(N), 2, 0, dt=DT, outputs=["force"], output_units=["N"],
                           y_offset=[1.5]),
             "output column 'force' is constant (1.5 N for all 1000 samples)")


@pytest.mark.parametrize("which", [0, 1])
def test_tfest_records_a_constant_output_names_the_record(which):
    """One record's output constant (a record at rest, the first or the longer second one): the
    record named (its fit % would be undefined; as the longest one its zero FRF was the start
    that failed in numpy's SVD)."""
    recs = [(U[:600], Y[:600]), (U, Y)]
    recs[which] = (recs[which][0], np.full(recs[which][0].shape[0], 2.0))
    n = recs[which][0].shape[0]
    _refused(lambda: tfest_records(recs, 2, 0, dt=DT),
             f"records[{which}] output y is constant (2 for all {n} samples): {NO_DYNAMICS}")


def test_tfest_records_varying_outputs_still_fit():
    """The same records, both varying and noise-free: G's denominator [1, 0.8, 4] to 1e-6 (the
    check refuses nothing that fits)."""
    m = tfest_records([(U[:600], Y[:600]), (U, Y)], 2, 0, dt=DT)
    np.testing.assert_allclose(m.system.denominator(), [1.0, 0.8, 4.0], rtol=1e-6, atol=1e-6)


@pytest.mark.parametrize("level", [0.0, 3.0])
def test_identify_tf_constant_output(level):
    """``identify(..., "tf")`` on a trajectory built from the arrays (its unit 'N'): the column
    named, the level and the unit given."""
    tr = Trajectory.uniform(dt=DT, u=U, y=np.full(N, level), units={"u": "A", "y": "N"})
    _refused(lambda: identify(tr, "tf", input="u", output="y", poles=2, zeros=0),
             f"output column 'y' is constant ({level:g} N for all {N} samples)")


def _mimo(n: int = 2000):
    u = np.random.default_rng(1).standard_normal((n, 2))
    y = np.zeros((n, 2))
    for t in range(1, n):
        y[t] = np.array([[0.5, 0.1], [0.0, 0.7]]) @ y[t - 1] + u[t - 1]
    return u, y


UM, YM = _mimo()
NAMES = dict(inputs=["current", "voltage"], outputs=["force", "position"],
             input_units=["A", "V"], output_units=["N", "m"])
#: each entry point on (u, y) of two columns (tfest, SISO: the second input, the first output)
DIRECT = {
    "n4sid": lambda u, y, **kw: n4sid(u, y, 2, dt=DT, **kw),
    "frf": lambda u, y, **kw: frf(u, y, dt=DT, **kw),
    "arx_mimo": lambda u, y, **kw: arx_mimo(u, y, 1, 1, 1, dt=DT, **kw),
    "tfest": lambda u, y, **kw: tfest(u[:, 1], y[:, 0], 2, 0, dt=DT,
                                      **{k: v[1:] if k.startswith("input") else v[:1]
                                         for k, v in kw.items()}),
}
INPUT = "a constant input cannot identify B"


@pytest.mark.parametrize("fn", list(DIRECT))
def test_a_constant_input_channel_is_refused_by_its_index(fn):
    """Input channel 1 held at 0.7 (n4sid and arx_mimo fitted it, frf estimated with it): the
    estimators' message, the channel by its index (tfest, SISO: 'input u')."""
    u = UM.copy()
    u[:, 1] = 0.7
    label = "input u" if fn == "tfest" else "input channel 1"
    _refused(lambda: DIRECT[fn](u, YM), f"{label} is constant (0.7 for all 2000 samples): {INPUT}")


@pytest.mark.parametrize("fn", list(DIRECT))
def test_a_constant_output_channel_is_refused_by_its_index(fn):
    """Output channel 0 held at 2 (n4sid and arx_mimo failed in the fit %'s DataError, frf gave
    H = 0)."""
    y = YM.copy()
    y[:, 0] = 2.0
    label = "output y" if fn == "tfest" else "output channel 0"
    _refused(lambda: DIRECT[fn](UM, y), f"{label} is constant (2 for all 2000 samples): "
                                        f"{NO_DYNAMICS}")


@pytest.mark.parametrize("fn", list(DIRECT))
def test_named_channels_are_named_with_their_unit(fn):
    """Given names and units, the column is named and its value given in its unit."""
    u = UM.copy()
    u[:, 1] = 0.7
    _refused(lambda: DIRECT[fn](u, YM, **NAMES),
             "input column 'voltage' is constant (0.7 V for all 2000 samples)")
    y = YM.copy()
    y[:, 0] = -3.0
    _refused(lambda: DIRECT[fn](UM, y, **NAMES),
             "output column 'force' is constant (-3 N for all 2000 samples)")


def test_the_offset_is_added_back_as_identify_does():
    """arx_mimo and n4sid of deviation data with u_offset: the level in the user's terms (the
    column was 0 after the operating point 1.5 was removed)."""
    u = UM.copy()
    u[:, 1] = 0.0
    for fit in (lambda: arx_mimo(u, YM, 1, 1, 1, u_offset=[0.0, 1.5], **NAMES),
                lambda: n4sid(u, YM, 2, u_offset=[0.0, 1.5], **NAMES)):
        _refused(fit, "input column 'voltage' is constant (1.5 V for all 2000 samples)")


def test_only_an_exactly_constant_column_is_refused():
    """The check refuses an exactly constant column only (span ≤ 1e-12 of its peak): the input
    0.7 V with a dither of 1e-9 V passes and arx_mimo fits the other input's gain to 1e-6 (the
    held channel's own gain is then poorly determined: the data's business, not the check's);
    the output check likewise lets a small but varying output through (the data scaled by 1e-6:
    A recovered to 1e-9)."""
    u = UM.copy()
    u[:, 1] = 0.7 + 1e-9 * np.random.default_rng(2).standard_normal(UM.shape[0])
    y = np.zeros_like(YM)
    for t in range(1, y.shape[0]):
        y[t] = np.array([[0.5, 0.1], [0.0, 0.7]]) @ y[t - 1] + u[t - 1]
    m = arx_mimo(u, y, 1, 1, 1)
    np.testing.assert_allclose(m.B[1][:, 0], [1.0, 0.0], atol=1e-6)
    small = arx_mimo(UM, 1e-6 * YM, 1, 1, 1)
    np.testing.assert_allclose(-small.A[1], [[0.5, 0.1], [0.0, 0.7]], atol=1e-9)


def test_tfest_records_an_input_constant_over_all_records():
    """Every record's input at 0.7: refused, the records joined (before: the persistent-excitation
    message, which did not say the input was constant)."""
    recs = [(np.full(600, 0.7), Y[:600]), (np.full(N, 0.7), Y)]
    _refused(lambda: tfest_records(recs, 2, 0, dt=DT),
             f"input u of all 2 records is constant (0.7 for all {600 + N} samples): {INPUT}")
