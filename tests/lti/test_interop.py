"""python-control and scipy.signal round trips keep the system, its names and time base."""

import control  # a dev dependency: the cross-checks fail, not skip, without it
import numpy as np
import pytest
from scipy import signal

from gripkit.errors import ModelError
from gripkit.lti import StateSpace, TransferFunction, as_system, from_control, from_scipy


def test_state_space_names_survive_control_round_trip():
    s = StateSpace([[0.0, 1.0], [-4.0, -0.4]], [[0.0, 0.0], [1.0, 0.5]], [[1.0, 0.0], [0.0, 1.0]],
                   dt=0.01,
                   inputs=("V", "F"), outputs=("x", "v"), states=("pos", "vel"),
                   input_units=("V", "N"),
                   output_units=("m", "m/s"))
    c = s.to_control()
    assert (c.input_labels == ["V", "F"] and c.output_labels == ["x", "v"]
            and c.state_labels == ["pos", "vel"])
    assert c.dt == 0.01
    back = from_control(c, input_units=("V", "N"), output_units=("m", "m/s"))
    assert isinstance(back, StateSpace)
    assert (back.inputs, back.outputs, back.states,
            back.dt) == (s.inputs, s.outputs, s.states, s.dt)
    assert back.output_units == ("m", "m/s")
    for X, Y in zip(back._arrays(), s._arrays()):
        np.testing.assert_array_equal(X, Y)


def test_transfer_function_names_survive_control_round_trip_mimo():
    g = (TransferFunction([[[1.0], [2.0, 1.0]]], [[[1.0, 1.0], [1.0, 3.0, 2.0]]], inputs=("a", "b"),
                          outputs="y"))
    c = g.to_control()
    assert c.input_labels == ["a", "b"] and c.output_labels == ["y"] and c.dt == 0
    back = from_control(c)
    assert isinstance(back, TransferFunction) and back.dt is None
    assert back.inputs == ("a", "b") and back.outputs == ("y",)
    np.testing.assert_array_equal(back.num, g.num)
    np.testing.assert_array_equal(back.den, g.den)


def test_from_control_refuses_an_unspecified_time_base():
    with pytest.raises(ModelError, match="unspecified time base"):
        from_control(control.tf([1.0], [1.0, 1.0], True))


def test_scipy_round_trip():
    g = TransferFunction([0.5], [1.0, -0.5], dt=0.1)
    sg = g.to_scipy()
    assert isinstance(sg, signal.TransferFunction) and sg.dt == 0.1
    back = from_scipy(sg, inputs="u1")
    assert back.inputs == ("u1",) and back.denominator().tolist() == [1.0, -0.5]
    s = StateSpace([[-1.0]], [[1.0]], [[2.0]])
    ss = s.to_scipy()
    assert isinstance(ss, signal.StateSpace) and ss.dt is None
    np.testing.assert_array_equal(from_scipy(ss).A, s.A)


def test_as_system_reads_tuples_and_polynomial_like_objects():
    class Poly:  # the attributes a gripkit.sysid polynomial model exposes
        A = np.array([1.0, -0.5])
        B = np.array([0.0, 2.0])
        F = np.ones(1)
        dt = 0.01
        input_name, output_name, input_unit, output_unit = "i", "F", "A", "N"
        covariance = None

    g = as_system(Poly())
    assert (g.inputs == ("i",) and g.outputs == ("F",) and g.input_units == ("A",)
            and g.output_units == ("N",))
    assert g.dc_gain()[0, 0] == pytest.approx(4.0)
    assert as_system(g) is g
    with pytest.raises(ModelError, match="cannot read a linear system from int"):
        as_system(3)


def test_dict_round_trip_through_json_is_exact():
    """to_dict → JSON → from_dict returns the same arrays, names, units and covariance (JSON keeps
    floats by their shortest repr, which round-trips exactly)."""
    import json

    s = StateSpace([[0.0, 1.0], [-4.0, -0.4]], [[0.0], [1.0 / 3.0]], [[1.0, 0.0]], dt=0.01,
                   inputs="V",
                   outputs="x", states=("p", "v"), input_units="V", output_units="m",
                   meta={"source": "test"})
    s = s.with_covariance(np.diag([1e-4, 2e-4]), ["A[1,0]", "A[1,1]"])
    g = TransferFunction.from_polynomials([1.0, -1.8732, 0.8996], [0, 0, 0.1950, -0.2276], dt=0.005,
                                          covariance=np.diag([1e-6, 1e-6, 4e-6, 4e-6]), outputs="F")
    for sys in (s, g, g.to_ss(minimal=False)):
        back = type(sys).from_dict(json.loads(json.dumps(sys.to_dict())))
        assert type(back) is type(sys)
        for X, Y in zip(back._arrays(), sys._arrays()):
            np.testing.assert_array_equal(X, Y)
        assert (back.dt, back.inputs, back.outputs, back.input_units, back.output_units,
                back.meta) == \
            (sys.dt, sys.inputs, sys.outputs, sys.input_units, sys.output_units, sys.meta)
        np.testing.assert_array_equal(back.uncertainty.covariance, sys.uncertainty.covariance)
        assert back.uncertainty.names == sys.uncertainty.names
    with pytest.raises(ModelError, match="expected a dict with type"):
        StateSpace.from_dict({"type": "Polynomial"})
    with pytest.raises(ModelError, match="lacks 'C'"):
        StateSpace.from_dict({"type": "StateSpace", "A": [[1.0]], "B": [[1.0]]})
