"""Parameter and ParameterSet: units required, bounds enforced, immutable updates."""

import math

import numpy as np
import pytest

from gripkit import Parameter, ParameterError, ParameterSet


def k_s(**kw):
    d = dict(name="k_s", value=128.0, unit="N/m", doc="force-sensor stiffness", bounds=(0, None),
             source="001_0b92a7da96e7aa46.txt, Table II")
    d.update(kw)
    return Parameter(**d)


def test_unit_is_required():
    with pytest.raises(ParameterError, match="has no unit"):
        k_s(unit="")


def test_doc_is_required():
    with pytest.raises(ParameterError, match="meaning"):
        k_s(doc=" ")


def test_bounds_are_enforced_with_message():
    with pytest.raises(ParameterError, match=r"'k_s' = -1 N/m is outside its bounds \[0, inf\]"):
        k_s(value=-1.0)


def test_non_finite_rejected():
    with pytest.raises(ParameterError, match="must be finite"):
        k_s(value=math.nan)


def test_replace_parses_units_and_checks_dimension():
    ps = (ParameterSet([k_s(), Parameter("m_s", 1.8e-6, "kg", "sensor mass", display_unit="mg")],
                       "sensor"))
    ps2 = ps.replace(m_s="1.79 mg", k_s=130.8)
    assert ps2["m_s"].value == pytest.approx(1.79e-6)
    assert ps2["k_s"].value == 130.8
    assert ps["m_s"].value == 1.8e-6  # original unchanged
    with pytest.raises(ParameterError, match="expected a value in 'kg'"):
        ps.replace(m_s="3 N")


def test_vector_roundtrip_and_free_names():
    ps = ParameterSet([k_s(), Parameter("b_s", 7e-4, "N*s/m", "sensor damping", fixed=True)])
    assert ps.free_names == ("k_s",)
    ps2 = ps.from_vector(np.array([200.0]), std=np.array([2.0]), source="identified")
    assert ps2["k_s"].value == 200.0 and ps2["k_s"].std == 2.0 and ps2["k_s"].source == "identified"
    assert ParameterSet.from_dict(ps2.to_dict()) == ps2


def test_display_in_display_unit():
    p = Parameter("M_a", 1.37e-6, "kg", "actuated mass", display_unit="mg", std=0.02e-6)
    assert p.display() == "M_a = 1.37 ± 0.02 mg"


def test_duplicate_and_missing_names():
    with pytest.raises(ParameterError, match="appears twice"):
        ParameterSet([k_s(), k_s()])
    with pytest.raises(ParameterError, match="available: k_s"):
        ParameterSet([k_s()])["nope"]
