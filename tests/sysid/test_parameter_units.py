"""Units on every identified parameter (issue 23): identified from a CSV whose headers are
``u [V]`` and ``y [mm]`` (loaded in V and m), each family's parameters carry the unit their
place in the model equation gives them (the output unit over the unit of what they multiply),
not '1'."""

import warnings

import numpy as np
import pytest

from gripkit.io import load
from gripkit.lti import StateSpace, TransferFunction
from gripkit.sysid import identify
from gripkit.sysid.linear.linear_model import LinearModel
from gripkit.sysid.nonlinear.narx import NARXModel, candidate_terms
from gripkit.units import product_unit, si_unit

#: the coefficient unit of every candidate term of degree ≤ 2 in y(t-1), y(t-2), u(t-1), u(t-2):
#: output unit (m) over the product of the factors' units (y in m, u in V)
NARX_UNITS = {"1": "m", "y(t-1)": "1", "y(t-2)": "1", "u(t-1)": "m/V", "u(t-2)": "m/V",
              "y(t-1)*y(t-1)": "1/m", "y(t-1)*y(t-2)": "1/m", "y(t-2)*y(t-2)": "1/m",
              "y(t-1)*u(t-1)": "1/V", "y(t-1)*u(t-2)": "1/V", "y(t-2)*u(t-1)": "1/V",
              "y(t-2)*u(t-2)": "1/V", "u(t-1)*u(t-1)": "m/V^2", "u(t-1)*u(t-2)": "m/V^2",
              "u(t-2)*u(t-2)": "m/V^2"}
#: a rational model's denominator D is dimensionless: one over the term's unit
DEN_UNITS = {"y(t-1)": "1/m", "y(t-2)": "1/m", "u(t-1)": "1/V", "u(t-2)": "1/V",
             "y(t-1)*y(t-1)": "1/m^2", "y(t-1)*u(t-1)": "1/(m*V)", "u(t-1)*u(t-2)": "1/V^2"}


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    """A second-order system with a quadratic input term, y in metres written in mm."""
    rng = np.random.default_rng(3)
    n, dt = 800, 0.01
    u = np.repeat(rng.uniform(-1.0, 1.0, n // 8), 8)
    y = np.zeros(n)
    for t in range(2, n):
        y[t] = 1.5 * y[t - 1] - 0.7 * y[t - 2] + 0.4 * u[t - 1] + 0.05 * u[t - 1] ** 2
    y = 1e-3 * y + 1e-6 * rng.normal(size=n)
    path = tmp_path_factory.mktemp("units") / "record.csv"
    np.savetxt(path, np.column_stack([np.arange(n) * dt, u, 1e3 * y]), delimiter=",",
               header="time [s],u [V],y [mm]", comments="")
    tr = load(path)
    assert (tr.unit("u"), tr.unit("y"), tr.display_unit("y")) == ("V", "m", "mm")
    return tr


def _identify(tr, method, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return identify(tr, method, input="u", output="y", **options)


def _units(model) -> dict:
    return {k: p.unit for k, p in model.parameters.items()}


def test_product_unit_cancels_and_spells_powers():
    assert product_unit(("m", 1), ("V", -1)) == "m/V"
    assert product_unit(("m", 1), ("m", -1), ("V", -1)) == "1/V"
    assert product_unit(("m", -1), ("V", -1)) == "1/(m*V)"
    assert product_unit(("V", -2)) == "1/V^2"
    assert product_unit(("1", 3), ("m", 0)) == "1"
    assert si_unit(product_unit(("m", 1), ("V", -1), ("s", -2))) == si_unit("m/V/s**2")


def test_narx_coefficients_carry_output_over_term_units(record):
    """Every candidate term's coefficient (a model built on all 15), and the terms FROLS chose
    on the record."""
    bases, rows = candidate_terms(2, 2, 2)
    k = len(rows)
    full = NARXModel(2, 2, 2, False, bases, rows, np.zeros(k), np.zeros(k), np.zeros((k, k)),
                     input_unit="V", output_unit="m")
    assert {t: p.unit for t, p in zip(full.terms, full.parameters.values())} == NARX_UNITS
    m = _identify(record, "narx", degree=2, lags=2)
    assert (m.input_unit, m.output_unit) == ("V", "m")
    assert [p.unit for p in m.parameters.values()] == [NARX_UNITS[t] for t in m.terms]
    assert "u(t-1)" in m.terms and m.parameters[f"theta_{m.terms.index('u(t-1)')}"].unit == "m/V"


def test_rational_narx_numerator_and_denominator_units(record):
    m = _identify(record, "narx", degree=2, lags=2, basis="rational", den_degree=1)
    units = _units(m)
    for k, t in enumerate(m.numerator_terms):
        assert units[f"num_{k}"] == NARX_UNITS[t]
    for j, t in enumerate(m.denominator_terms):
        assert units[f"den_{j + 1}"] == DEN_UNITS[t]
    assert [m.term_unit(r, 0) for r in ([0, 0], [0, 2], [2, 3])] == \
        ["1/m^2", "1/(m*V)", "1/V^2"]
    assert m.term_unit([-1, -1], 0) == "1" and m.term_unit([-1, -1], 1) == "m"


def test_hammerstein_wiener_units_follow_the_gain_normalisation(record):
    """w = f(u) in V, x in m: b in m/V, f dimensionless, a poly coefficient c_k in V^(1−k),
    saturation limits of the output block and y0 in m."""
    m = _identify(record, "hw", nb=2, nf=2, nk=1, input_nonlinearity="poly:3",
                  output_nonlinearity="saturation")
    assert _units(m) == {"in_c2": "1/V", "in_c3": "1/V^2", "b1": "m/V", "b2": "m/V", "f1": "1",
                         "f2": "1", "out_lo": "m", "out_hi": "m", "y0": "m"}
    m = _identify(record, "hw", nk=0, linear="ss", order=2, input_nonlinearity="sigmoid:2",
                  output_nonlinearity="pwl:2")
    assert _units(m) == {"in_a1": "V", "in_a2": "V", "a1": "1", "a2": "1", "b1": "m/V",
                         "b2": "m/V", "d": "m/V", "out_d1": "1", "out_d2": "1", "y0": "m"}
    m = _identify(record, "hw", nb=2, nf=2, nk=1, input_nonlinearity="deadzone",
                  output_nonlinearity="poly:2")
    assert {k: v for k, v in _units(m).items() if "_" in k} == \
        {"in_lo": "V", "in_hi": "V", "out_c2": "1/m"}


def test_transfer_function_coefficients_make_the_dc_gain_m_per_v(record):
    """Continuous tf (tfest) and step: a_k of s^n + a_1 s^(n−1) + … in 1/s^k, the numerator's
    coefficient of s^k in (m/V)/s^(n−k); the DC gain b_n/a_n comes out in m/V."""
    for method, opts in (("tf", dict(poles=2, zeros=1)), ("step", {})):
        units = _units(_identify(record, method, **opts))
        assert units["den_0_0_1"] == "1/s" and units["den_0_0_2"] == "1/s^2"
        assert units["num_0_0_2"] == "m/(V*s^2)"
        assert si_unit(units["num_0_0_2"] + "*s^2") == "m/V"
    assert _units(_identify(record, "tf", poles=2, zeros=1))["num_0_0_1"] == "m/(V*s)"


def test_discrete_transfer_function_and_state_space_units():
    """A discrete tf: denominator dimensionless, numerator in m/V. State space with no state
    units (an identified basis): A dimensionless (discrete) or 1/s (continuous), D m/V, and B,
    C with the state dimensionless, said in their description; with declared state units each
    entry is the ratio of its row's and column's units."""
    tf = TransferFunction([0.2, 0.1], [1.0, -0.5, 0.06], dt=0.01, inputs="u", outputs="y",
                          input_units="V", output_units="m")
    units = _units(LinearModel(tf, "tfest"))
    assert units == {"num_0_0_1": "m/V", "num_0_0_2": "m/V", "den_0_0_0": "1", "den_0_0_1": "1",
                     "den_0_0_2": "1", "num_0_0_0": "m/V"}
    A, B, C, D = [[-1.0, 0.5], [0.0, -2.0]], [[1.0], [0.5]], [[1.0, 0.0]], [[0.1]]
    kw = dict(inputs="u", outputs="y", input_units="V", output_units="m")
    cont = LinearModel(StateSpace(A, B, C, D, **kw), "n4sid").parameters
    assert cont["A_0_1"].unit == "1/s" and cont["B_1_0"].unit == "1/(V*s)"
    assert cont["C_0_0"].unit == "m" and cont["D_0_0"].unit == "m/V"
    assert "carries no unit" in cont["B_1_0"].doc and "carries no unit" not in cont["D_0_0"].doc
    disc = LinearModel(StateSpace(A, B, C, D, dt=0.01, **kw), "n4sid").parameters
    assert (disc["A_0_1"].unit, disc["B_1_0"].unit) == ("1", "1/V")
    phys = LinearModel(StateSpace(A, B, C, D, state_units=("m", "m/s"), **kw), "n4sid").parameters
    assert (phys["A_0_1"].unit, phys["B_1_0"].unit, phys["C_0_1"].unit) == \
        ("m/((m/s)*s)", "(m/s)/(V*s)", "m/(m/s)")
    assert [si_unit(phys[k].unit) for k in ("A_0_1", "A_1_0", "B_1_0", "C_0_1")] == \
        ["1", si_unit("1/s^2"), si_unit("m/(V*s^2)"), "s"]
    assert "carries no unit" not in phys["B_1_0"].doc


def test_identified_state_space_units(record):
    """A discrete PEM model on the record: its free entries (A, B; C, D where estimated) in the
    units of a dimensionless state."""
    ps = _identify(record, "ss", order=2).parameters
    expected = {"A": "1", "B": "1/V", "C": "m", "D": "m/V"}
    assert {k[0] for k in ps} >= {"A", "B"}
    assert {k: p.unit for k, p in ps.items()} == {k: expected[k[0]] for k in ps}
