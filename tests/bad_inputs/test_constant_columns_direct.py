"""Constant columns given straight to the estimators (audit of 27 Nov): ``tfest`` with a constant
output failed with numpy's raw ``LinAlgError`` ("SVD did not converge"), its FRF start being
zero; it now gives the UnidentifiableError of the other estimators
(:func:`gripkit.sysid.checks.check_output_varies`), naming the channel, its value (the offset
added back) and its unit, also for ``tfest_records`` (naming the record) and
``identify(..., "tf")``.

The data: a white-noise input (seeded) through G(s) = 4/(s² + 0.8 s + 4), sampled with a
zero-order hold at dt = 0.05 s (the example of ``tfest``'s docstring)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from gripkit import Trajectory
from gripkit.errors import UnidentifiableError
from gripkit.lti import TransferFunction
from gripkit.sysid import identify, tfest
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
