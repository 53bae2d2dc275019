"""The one identification data class (gripkit.sysid.io_data.IOData): SISO and MIMO from one
constructor, its SISO view, the checks of state-space estimation, the validation record around
the estimation operating point."""

import numpy as np
import pytest

from gripkit import Trajectory
from gripkit.errors import ArgumentError, DataError, UnidentifiableError
from gripkit.sysid import IOData, arx, identify, io_data
from gripkit.sysid.io_data import validation_data
from gripkit.sysid.linear.identify_mimo import mimo_data


def _record(seed: int = 0, n: int = 400) -> Trajectory:
    rng = np.random.default_rng(seed)
    a = 2.0 + rng.standard_normal(n)
    b = -1.0 + rng.standard_normal(n)
    c = np.zeros(n)
    for t in range(1, n):
        c[t] = 0.8 * c[t - 1] + 0.5 * (a[t - 1] - 2.0)
    return Trajectory.uniform(dt=0.01, a=a, b=b, c=c + 3.0, units={"a": "A", "b": "V", "c": "N"})


def test_siso_and_mimo_from_one_constructor():
    tr = _record()
    mimo = IOData.from_trajectory(tr, "a,b", ["c"])
    siso = IOData.from_trajectory(tr, "a", "c")
    assert mimo.u.shape == (400, 2) and mimo.y.shape == (400, 1) and siso.u.shape == (400, 1)
    assert mimo.inputs == ("a", "b") and mimo.input_units == ("A", "V") and mimo.dt == 0.01
    # the offsets are the columns' means, the arrays the deviations from them
    assert mimo.u_offset == pytest.approx((tr["a"].mean(), tr["b"].mean()), rel=1e-15)
    np.testing.assert_array_equal(siso.u1, tr["a"] - tr["a"].mean())
    np.testing.assert_array_equal(siso.u1, mimo.u[:, 0])
    assert (siso.input, siso.output, siso.input_unit, siso.output_unit) == ("a", "c", "A", "N")
    assert siso.keywords["y_offset"] == pytest.approx(tr["c"].mean(), rel=1e-15)
    with pytest.raises(ArgumentError, match=r"IOData.u1: the SISO view needs one input and one "
                                            r"output, found 2 input\(s\) \['a', 'b'\]"):
        mimo.u1
    np.testing.assert_array_equal(siso.y1, tr["c"] - tr["c"].mean())
    for name in ("y1", "input", "output", "input_unit", "output_unit"):  # each names itself
        with pytest.raises(ArgumentError, match=rf"IOData.{name}: the SISO view needs one input"):
            getattr(mimo, name)


def test_siso_identify_is_the_array_fit_of_the_deviations():
    """identify(tr, 'arx') is arx() of the mean-removed columns, bit for bit."""
    tr = _record(1)
    m = identify(tr, "arx", input="a", output="c", na=1, nb=1, nk=1)
    ref = arx(tr["a"] - tr["a"].mean(), tr["c"] - tr["c"].mean(), 1, 1, 1, dt=0.01)
    np.testing.assert_array_equal(m.theta, ref.theta)
    # the noise-free system, up to the edge effects of the sample means (N = 400)
    assert m.theta == pytest.approx([-0.8, 0.5], abs=1e-5)


def test_linear_detrend_removes_a_line_exactly():
    t = np.arange(200) * 0.1
    rng = np.random.default_rng(3)
    tr = Trajectory.uniform(dt=0.1, u=1.0 + 0.5 * t + rng.standard_normal(200) * 0.0,
                            y=rng.standard_normal(200))
    d = io_data(tr, input="u", output="y", detrend="linear")
    assert np.max(np.abs(d.u1)) < 1e-12
    assert d.u_offset[0] == pytest.approx(1.0 + 0.5 * t.mean(), rel=1e-12)


def test_none_keeps_the_data_and_zero_offsets():
    tr = _record(2)
    d = IOData.from_trajectory(tr, "a", "c", detrend="none")
    np.testing.assert_array_equal(d.y1, tr["c"])
    assert d.u_offset == (0.0,) and d.y_offset == (0.0,)


def test_checks_of_state_space_data():
    tr = _record().with_channels(b=np.full(400, 4.5))
    # the estimators' own check and message (checks.check_excitation): the value in its unit
    with pytest.raises(UnidentifiableError,
                       match=r"^input column 'b' is constant \(4.5 V for all 400 samples\): a "
                             r"constant input cannot identify B"):
        IOData.from_trajectory(tr, "a,b", "c")
    big = _record().with_channels(a=_record()["a"] * 1e120)
    with pytest.raises(DataError, match=r"input column 'a' has values up to .*accepts peak values "
                                        r"between 1e-100 and 1e\+100"):
        IOData.from_trajectory(big, "a", "c", why="state-space identification")
    # the SISO polynomial estimators scale internally: no scale check there
    assert io_data(big, input="a", output="c").u_offset[0] > 1e119
    with pytest.raises(DataError, match="detrend: expected 'mean' or 'none', found 'linear'"):
        mimo_data(tr, "a", "c", "linear")
    with pytest.raises(DataError, match="input and output must be different columns, both are 'a'"):
        io_data(tr, input="a", output="a")
    with pytest.raises(DataError, match="column 'x' not found"):
        IOData.from_trajectory(tr, "a,x", "c")


def test_validation_data_sit_around_the_estimation_operating_point():
    est, val = _record(4), _record(5)
    d = IOData.from_trajectory(est, "a", "c")
    vd = validation_data(val, d)
    assert vd.u_offset == d.u_offset
    np.testing.assert_array_equal(vd.y1, val["c"] - d.y_offset[0])
    slow = Trajectory.uniform(dt=0.02, a=val["a"], c=val["c"])
    with pytest.raises(DataError, match="validation data are sampled at 50 Hz, the estimation "
                                        "data at 100 Hz"):
        validation_data(slow, d)


def test_memory_data_have_no_provenance():
    assert IOData.from_trajectory(_record(), "a", "c").provenance == {"data_file": None,
                                                                       "data_hash": None}
