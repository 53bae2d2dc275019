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


#: units read by the fast table (no pint import): its answers must equal pint's, bit for bit
FAST_UNITS = [
    "N", "mN", "kN", "m", "mm", "um", "µm", "μm", "nm", "km", "cm", "s", "ms", "us", "min", "h",
    "g", "kg", "mg", "ug", "V", "mV", "kV", "A", "mA", "uA", "W", "mW", "kW", "Pa", "kPa", "MPa",
    "hPa", "bar", "mbar", "rad", "mrad", "deg", "°", "Hz", "kHz", "mHz", "J", "mJ", "C", "ohm",
    "kohm", "F", "uF", "K", "mol", "mmol", "N*m", "N·m", "mN*m", "Ncm", "N/m", "N*s/m", "mNs/m",
    "m/s", "mm/s", "m/s**2", "m/s^2", "rad/s", "deg/s", "rad/s**2", "1/s", "1/V", "m/V", "um/V",
    "N/V", "V/N", "kg*m**2", "m**2", "mm**2", "m**3/s", "Pa/s", "bar/s", "W/K", "A/V", "N*m/rad",
    "N*m*s/rad", "C/V", "1", "", "-", "s**-1", "kg*m/s**2"]
#: left to pint: other units, several scaled factors (pint's float rounding), offsets, and
#: spellings pint reads in its own way ('Nm' is not newton-metre there)
PINT_ONLY = ["g*cm**2", "km/h", "Nm", "degC", "°C", "%", "rpm", "T", "ft", "lbf", "m/s/s",
             "(N*s)/m"]


@pytest.mark.parametrize("unit", FAST_UNITS)
def test_fast_table_equals_pint(unit):
    """si_factor's table path gives pint's (scale, offset, SI spelling) exactly."""
    from gripkit.units import _fast_si_factor, _pint_si_factor

    fast = _fast_si_factor(unit)
    assert fast is not None, f"{unit!r} should be read from the fast table, not by pint"
    assert fast == _pint_si_factor(unit)


@pytest.mark.parametrize("unit", PINT_ONLY)
def test_units_outside_the_table_go_to_pint(unit):
    from gripkit.units import _fast_si_factor, si_factor

    assert _fast_si_factor(unit) is None
    si_factor(unit)  # pint reads them


def test_fast_same_dimension_equals_pint():
    """same_dimension from the table agrees with pint's dimensionality for every pair of a
    sample of table units (radian and degree dimensionless, as in pint)."""
    from gripkit.units import _parse_unit

    sample = ["N", "mN*m", "N*m", "J", "rad", "deg", "1", "Hz", "1/s", "rad/s", "kPa", "bar",
              "m/s", "mm/s", "W", "F", "C/V"]
    for a in sample:
        for b in sample:
            same = _parse_unit(a).dimensionality == _parse_unit(b).dimensionality
            assert same_dimension(a, b) == same, (a, b)


def test_unit_headers_do_not_import_pint(tmp_path):
    """A CSV with the README's header style (`force [N]`) loads without importing pint (nor dask,
    which pint.compat imports when installed): 0.3–0.4 s of `gripkit identify arx`."""
    import json
    import subprocess
    import sys

    path = tmp_path / "log.csv"
    path.write_text("time [s],voltage [V],force [mN],angle [deg]\n" + "".join(
        f"{k * 1e-3},{(k * 7) % 5 - 2.0},{k % 3 * 0.5},{k * 0.1}\n" for k in range(50)))
    probe = (f"import json, sys\nfrom gripkit.io import load\nd = load({str(path)!r})\n"
             "heavy = sorted(m for m in sys.modules if m.split('.')[0] in ('pint', 'dask'))\n"
             "print(json.dumps([heavy, float(d['force'][1]), float(d['angle'][1])]))")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    loaded, force, angle = json.loads(out.stdout.strip().splitlines()[-1])
    assert loaded == []
    assert force == 0.5e-3 and angle == pytest.approx(0.1 * 3.141592653589793 / 180, rel=1e-15)


def test_pint_fallback_leaves_dask_out():
    """A unit outside the table (°C) is read by pint, imported without dask (pint.compat would
    import dask.base, 0.1 s); dask itself still imports afterwards (the sweep backend)."""
    import json
    import subprocess
    import sys

    probe = ("import json, sys\nfrom gripkit.units import si_factor\nf = si_factor('degC')\n"
             "loaded = [m for m in ('pint', 'dask') if m in sys.modules]\nimport dask\n"
             "print(json.dumps([loaded, f, dask.__name__]))")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    loaded, factor, name = json.loads(out.stdout.strip().splitlines()[-1])
    assert loaded == ["pint"] and factor == [1.0, 273.15, "K"] and name == "dask"
