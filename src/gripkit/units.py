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
import importlib.util
import math
import re
import sys

from .errors import ParameterError

__all__ = ["to_si", "si_factor", "ratio_unit", "product_unit", "si_unit", "convert",
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


def _import_pint():
    """pint, imported without dask: ``pint.compat`` imports ``dask.base`` whenever dask is
    installed, for dask-array quantities gripkit never makes. While pint is first imported (and
    dask is not yet loaded), ``importlib.util.find_spec`` — which pint.compat binds at import to
    test ``find_spec("dask")`` — answers None for dask; pint then leaves its dask support out.
    Everything else, and dask itself when imported later (the sweep backend), is unaffected."""
    if "pint" in sys.modules or "dask" in sys.modules:
        import pint

        return pint
    real = importlib.util.find_spec

    def find_spec(name, package=None):
        return None if name == "dask" or name.startswith("dask.") else real(name, package)
    importlib.util.find_spec = find_spec
    try:
        import pint
    finally:
        importlib.util.find_spec = real
    return pint


@functools.lru_cache(maxsize=1)
def _registry():
    pint = _import_pint()

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


# SI spellings preferred over raw base units, tried in order (same dimension wins).
_PREFERRED = ("m", "s", "kg", "A", "K", "mol", "N", "Pa", "J", "W", "V", "C", "F", "ohm", "Hz",
              "N/m", "N*s/m", "N*m", "N*m*s", "kg*m**2", "m/s", "m/s**2", "m/V", "1/V", "N/V",
              "V/N", "m/N", "V/m", "Pa/s", "m**2", "m**3", "m**3/s", "W/K", "J/K", "1/K", "A/V")
_ANGLE = ("rad", "rad/s", "rad/s**2", "N*m/rad", "N*m*s/rad", "rad/V")


# Fast path: the common units, parsed without importing pint (0.3–1 s with its dependencies).
# Dimensions as exponents of (m, kg, s, A, K, mol); radian and degree are dimensionless, as in
# pint. Scales are 10^(prefix + unit exponent) for decimal units, so that they round as pint's.
_DIMS = ("m", "kg", "s", "A", "K", "mol")
_PREFIX = {"G": 9, "M": 6, "k": 3, "h": 2, "da": 1, "d": -1, "c": -2, "m": -3, "u": -6, "n": -9,
           "p": -12}
#: unit: (decimal exponent or None, factor when not decimal, dimension exponents, takes prefixes)
_FAST_UNITS = {
    "m": (0, 1.0, (1, 0, 0, 0, 0, 0), True), "g": (-3, 1.0, (0, 1, 0, 0, 0, 0), True),
    "s": (0, 1.0, (0, 0, 1, 0, 0, 0), True), "A": (0, 1.0, (0, 0, 0, 1, 0, 0), True),
    "K": (0, 1.0, (0, 0, 0, 0, 1, 0), True), "mol": (0, 1.0, (0, 0, 0, 0, 0, 1), True),
    "N": (0, 1.0, (1, 1, -2, 0, 0, 0), True), "Pa": (0, 1.0, (-1, 1, -2, 0, 0, 0), True),
    "bar": (5, 1.0, (-1, 1, -2, 0, 0, 0), True), "J": (0, 1.0, (2, 1, -2, 0, 0, 0), True),
    "W": (0, 1.0, (2, 1, -3, 0, 0, 0), True), "V": (0, 1.0, (2, 1, -3, -1, 0, 0), True),
    "C": (0, 1.0, (0, 0, 1, 1, 0, 0), True), "ohm": (0, 1.0, (2, 1, -3, -2, 0, 0), True),
    "F": (0, 1.0, (-2, -1, 4, 2, 0, 0), True),
    "Hz": (0, 1.0, (0, 0, -1, 0, 0, 0), True), "rad": (0, 1.0, (0, 0, 0, 0, 0, 0), True),
    "deg": (None, math.pi / 180.0, (0, 0, 0, 0, 0, 0), False),
    "min": (None, 60.0, (0, 0, 1, 0, 0, 0), False), "h": (None, 3600.0, (0, 0, 1, 0, 0, 0), False),
}
_FAST_TOKEN = re.compile(r"^([A-Za-z]+)(?:\^(-?[1-4]))?$")  # a unit and a power (** written ^)


def _fast_token(tok: str):
    """(decimal exponent or None, factor, dims) of one factor such as ``mm``, ``s^2``, or None."""
    m = _FAST_TOKEN.match(tok)
    if not m:
        return None
    name, power = m.group(1), int(m.group(2) or 1)
    if name in _FAST_UNITS:
        exp, fac, dims, _ = _FAST_UNITS[name]
        pre = 0
    else:
        for p in ("da",) + tuple(_PREFIX):
            base = name[len(p):]
            if name.startswith(p) and base in _FAST_UNITS and _FAST_UNITS[base][3]:
                exp, fac, dims, _ = _FAST_UNITS[base]
                pre = _PREFIX[p]
                break
        else:
            return None
    return ((exp + pre) * power if exp is not None else None, fac ** power * 10.0 ** (pre * power),
            tuple(d * power for d in dims))


@functools.lru_cache(maxsize=512)
def _fast_unit(unit: str):
    """(scale, dims, angular) of ``unit`` from the table above — products of its units with
    optional integer powers, over at most one ``/``, at most one of them scaled (a prefix, g,
    bar, deg, min, h) — or None for anything else (pint then)."""
    norm = _normalise(unit)
    if norm == "dimensionless":
        return 1.0, (0,) * len(_DIMS), False
    if any(c in norm for c in " ()") or norm.count("/") > 1:
        return None
    num, slash, den = norm.partition("/")
    if not num or (slash and not den):
        return None
    dec, fac, dims, scaled = 0, 1.0, [0] * len(_DIMS), 0
    for sign, part in ((1, num), (-1, den)):
        if not part or (sign == 1 and part == "1"):
            continue
        for tok in part.replace("**", "^").split("*"):
            got = _fast_token(tok)
            if got is None:
                return None
            e, f, d = got
            scaled += e != 0
            if scaled > 1:  # pint multiplies several scales in float: its rounding, not 10^Σ
                return None
            if e is None:
                dec = None
            elif dec is not None:
                dec += sign * e
            fac = fac * f if sign == 1 else fac / f
            dims = [a + sign * b for a, b in zip(dims, d)]
    scale = 10.0 ** dec if dec is not None else fac
    angular = any(a in norm for a in ("rad", "deg"))
    return scale, tuple(dims), angular


def _fast_si_factor(unit: str):
    """:func:`si_factor` from the fast table, or None (then pint)."""
    got = _fast_unit(unit)
    if got is None:
        return None
    scale, dims, angular = got
    for c in (_ANGLE if angular else ()) + _PREFERRED:
        if _fast_unit(c)[1] == dims:
            return scale, 0.0, c
    return (scale, 0.0, "1") if not any(dims) else None


@functools.lru_cache(maxsize=512)
def si_factor(unit: str) -> tuple[float, float, str]:
    """(scale, offset, si_unit_string) such that value_si = scale*value + offset.

    Common units (SI prefixes × m, g, s, A, K, mol, N, Pa, bar, J, W, V, C, ohm, F, Hz, rad,
    and deg, min, h; products, integer powers and one ``/``) are read from a table without
    importing pint (:func:`_fast_si_factor`, tested equal to pint's answer); the rest through
    pint (:func:`_pint_si_factor`)."""
    fast = _fast_si_factor(unit)
    return fast if fast is not None else _pint_si_factor(unit)


def _pint_si_factor(unit: str) -> tuple[float, float, str]:
    """:func:`si_factor` through pint."""
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


def product_unit(*factors: tuple[str, int]) -> str:
    """The unit of a product of integer powers of units: ``(('m', 1), ('V', -1))`` → ``'m/V'``,
    ``(('m', 1), ('m', -1), ('V', -1))`` → ``'1/V'``, ``(('V', -2),)`` → ``'1/V^2'``. Powers of
    the same spelling are added; dimensionless units ('1', '') and zero powers drop out; a
    compound unit raised to a power or multiplied is parenthesised (``'(N*m)^2'``); nothing left
    is '1'."""
    powers: dict[str, int] = {}
    for unit, power in factors:
        unit = (unit or "1").strip()
        if unit not in ("1", "") and power:
            powers[unit] = powers.get(unit, 0) + int(power)
    wrap = lambda u: u if all(c not in u for c in "*/ ") else f"({u})"  # noqa: E731

    def side(sign: int) -> str:
        got = [(u, p * sign) for u, p in powers.items() if p * sign > 0]
        return "*".join(u if p == 1 and len(got) == 1 else wrap(u) if p == 1 else f"{wrap(u)}^{p}"
                        for u, p in got)

    num, den = side(1), side(-1)
    return ratio_unit(num or "1", den or "1")


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
            hint=f"{from_unit!r} is {si_unit(from_unit)!r} in SI, {to_unit!r} is "
                 f"{si_unit(to_unit)!r}",
        )
    s1, o1, _ = si_factor(from_unit)
    s2, o2, _ = si_factor(to_unit)
    return ((s1 * value + o1) - o2) / s2


def same_dimension(a: str, b: str) -> bool:
    """True when ``a`` and ``b`` measure the same physical dimension (the fast table when it
    reads both, else pint)."""
    fa, fb = _fast_unit(a), _fast_unit(b)
    if fa is not None and fb is not None:
        return fa[1] == fb[1]
    return _parse_unit(a).dimensionality == _parse_unit(b).dimensionality


def dimension_of(unit: str) -> str:
    """The physical dimension of ``unit`` as pint writes it: ``'mA'`` → ``'[current]'``,
    ``'N'`` → ``'[length] * [mass] / [time] ** 2'``, ``'rad'`` → ``'dimensionless'``."""
    return str(_parse_unit(unit).dimensionality) or "dimensionless"


def format_quantity(value_si: float, unit_si: str, display_unit: str | None = None,
                    digits: int = 4, std: float | None = None) -> str:
    """Format an SI value for people, e.g. ``format_quantity(1.37e-6, 'kg', 'mg')`` → ``'1.37
    mg'``."""
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
