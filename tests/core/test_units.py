"""Unit parsing at the boundaries (pint)."""

import pytest

from gripkit.errors import ParameterError
from gripkit.units import convert, format_quantity, same_dimension, to_si


@pytest.mark.parametrize("text, value, unit_dim", [
    ("1.37 mg", 1.37e-6, "kg"),
    ("30 bar", 3.0e6, "Pa"),
    ("1.3 mN*s/m", 1.3e-3, "N*s/m"),
    ("0.77 µm/V", 0.77e-6, "m/V"),
    ("1 Ncm", 0.01, "N*m"),
    ("8.52 kHz", 8520.0, "Hz"),
    ("850 mA", 0.85, "A"),
])
def test_to_si(text, value, unit_dim):
    v, u = to_si(text)
    assert v == pytest.approx(value, rel=1e-12)
    assert same_dimension(u, unit_dim)


def test_temperature_offset():
    assert to_si("80 degC")[0] == pytest.approx(353.15)


def test_convert_and_format():
    assert convert(0.1878e-6, "m/V", "um/V") == pytest.approx(0.1878)
    assert format_quantity(1.37e-6, "kg", "mg") == "1.37 mg"
    with pytest.raises(ParameterError, match="different dimensions"):
        convert(1.0, "m", "s")


def test_bad_unit():
    with pytest.raises(ParameterError, match="not a unit"):
        to_si("3 furlongz")
