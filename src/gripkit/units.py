"""Units at the boundaries; plain SI floats inside.

gripkit stores every parameter and signal in SI base units. Units are parsed (with pint) only
where values enter or leave: parameter files, column headers, CLI options and reports.

>>> to_si("1.37 mg")
(1.37e-06, 'kg')
>>> round(convert(0.1878e-6, "m/V", "um/V"), 9)
0.1878
"""

from __future__ import annotations

import functools
import math
import re

from .errors import ParameterError

__all__ = ["to_si", "si_factor", "ratio_unit", "si_unit", "convert", "check_unit",
           "format_quantity", "same_dimension", "dimension_of"]

# Unit strings gripkit uses, spelled for pint; "1" is dimensionless.
_ALIASES = {
    "": "dimensionless",
    "1": "dimensionless",
    "-": "dimensionless",
    "%": "percent",
    "µ": "u",
    "μ": "u",
    "Ncm": "N*cm",
    "mNs/m": "mN*s/m",
}


@functools.lru_cache(maxsize=1)
def _registry():
    import pint

    ureg = pint.UnitRegistry(autoconvert_offset_to_baseunit=True)
    ureg.define("PWM = [] = pwm_count")  # motor-driver duty counts (DLR/HIT Hand II: 0..4096)
    return ureg


def _normalise(unit: str) -> str:
    unit = unit.strip()
    if unit in _ALIASES:
        return _ALIASES[unit]
    for k, v in (("µ", "u"), ("μ", "u"), ("·", "*"), ("°C", "degC"), ("°", "deg")):
        unit = unit.replace(k, v)
    return _ALIASES.get(unit, unit)


@functools.lru_cache(maxsize=512)
def _parse_unit(unit: str):
    ureg = _registry()
    try:
        return ureg.Unit(_normalise(unit))
    except Exception as exc:  # pint raises several types for bad strings
        raise ParameterError(
            f"unit {unit!r} is not a unit gripkit can read ({type(exc).__name__})",
            hint="use SI spellings such as 'm', 'N/m', 'N*s/m', 'kg', 'V', 'Hz', '1/V', 'bar'",
        ) from None


def check_unit(unit: str) -> str:
    """Return ``unit`` if pint can read it, else raise :class:`ParameterError`."""
    _parse_unit(unit)
    return unit


# SI spellings preferred over raw base units, tried in order (same dimension wins).
_PREFERRED = ("m", "s", "kg", "A", "K", "mol", "N", "Pa", "J", "W", "V", "C", "F", "ohm", "Hz",
              "N/m", "N*s/m", "N*m", "N*m*s", "kg*m**2", "m/s", "m/s**2", "m/V", "1/V", "N/V",
              "V/N", "m/N", "V/m", "Pa/s", "m**2", "m**3", "m**3/s", "W/K", "J/K", "1/K", "A/V")
_ANGLE = ("rad", "rad/s", "rad/s**2", "N*m/rad", "N*m*s/rad", "rad/V")


@functools.lru_cache(maxsize=512)
def si_factor(unit: str) -> tuple[float, float, str]:
    """(scale, offset, si_unit_string) such that value_si = scale*value + offset."""
    if unit == "s":  # a time column's default: the answer pint gives, without importing pint (0.3 s)
        return 1.0, 0.0, "s"
    ureg = _registry()
    u = _parse_unit(unit)
    q0 = ureg.Quantity(0.0, u).to_base_units()
    q1 = ureg.Quantity(1.0, u).to_base_units()
    offset = float(q0.magnitude)
    scale = float(q1.magnitude) - offset
    norm = _normalise(unit)
    angular = any(a in norm for a in ("rad", "deg", "rpm", "revolution", "turn"))
    candidates = (_ANGLE if angular else ()) + _PREFERRED
    si = None
    for c in candidates:
        if _parse_unit(c).dimensionality == u.dimensionality:
            si = c
            break
    if si is None:
        si = f"{q1.units:~C}"
        si = {"": "1", "dimensionless": "1"}.get(si, si)
    return scale, offset, si


def ratio_unit(num: str, den: str) -> str:
    """The unit of a ratio: 'm' over 'V' -> 'm/V'; compound units are parenthesised ('N*s' over
    'm' -> '(N*s)/m'); a dimensionless numerator gives '1/V', a dimensionless denominator the
    numerator itself."""
    if den in ("1", ""):
        return num or "1"
    wrap = lambda u: u if all(c not in u for c in "*/ ") else f"({u})"  # noqa: E731
    return f"{wrap(num or '1')}/{wrap(den)}"


def si_unit(unit: str) -> str:
    """The SI base-unit spelling of ``unit`` (``'mN*s/m'`` → ``'kg/s'``)."""
    return si_factor(unit)[2]


_QTY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*)$")


def to_si(quantity: str | float, unit: str | None = None) -> tuple[float, str]:
    """Parse ``"1.37 mg"`` (or a number and a unit) into ``(value_in_SI, si_unit)``."""
    if isinstance(quantity, str):
        m = _QTY.match(quantity)
        if not m:
            raise ParameterError(
                f"quantity {quantity!r} is not a number followed by a unit",
                hint="write it like '1.37 mg', '30 bar' or '25.4 N/m'",
            )
        value, unit = float(m.group(1)), (m.group(2) or (unit or "1"))
    else:
        value, unit = float(quantity), unit or "1"
    scale, offset, si = si_factor(unit)
    return scale * value + offset, si


def convert(value: float, from_unit: str, to_unit: str) -> float:
    """Convert ``value`` between two units of the same dimension."""
    if not same_dimension(from_unit, to_unit):
        raise ParameterError(
            f"cannot convert from {from_unit!r} to {to_unit!r}: different dimensions",
            hint=f"{from_unit!r} is {si_unit(from_unit)!r} in SI, {to_unit!r} is {si_unit(to_unit)!r}",
        )
    s1, o1, _ = si_factor(from_unit)
    s2, o2, _ = si_factor(to_unit)
    return ((s1 * value + o1) - o2) / s2


def same_dimension(a: str, b: str) -> bool:
    """True when ``a`` and ``b`` measure the same physical dimension."""
    return _parse_unit(a).dimensionality == _parse_unit(b).dimensionality


def dimension_of(unit: str) -> str:
    """The physical dimension of ``unit`` as pint writes it: ``'mA'`` → ``'[current]'``,
    ``'N'`` → ``'[length] * [mass] / [time] ** 2'``, ``'rad'`` → ``'dimensionless'``."""
    return str(_parse_unit(unit).dimensionality) or "dimensionless"


def format_quantity(value_si: float, unit_si: str, display_unit: str | None = None,
                    digits: int = 4, std: float | None = None) -> str:
    """Format an SI value for people, e.g. ``format_quantity(1.37e-6, 'kg', 'mg')`` → ``'1.37 mg'``."""
    unit = display_unit or unit_si
    v = convert(value_si, unit_si, unit) if display_unit else value_si
    text = _fmt(v, digits)
    if std is not None and math.isfinite(std):
        s = abs(convert(std, unit_si, unit) - convert(0.0, unit_si, unit)) if display_unit else std
        text += f" ± {_fmt(s, 2)}"
    return text if unit in ("1", "") else f"{text} {unit}"


def _fmt(v: float, digits: int) -> str:
    if v == 0 or not math.isfinite(v):
        return f"{v:g}"
    return f"{v:.{digits}g}"
