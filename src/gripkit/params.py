"""Parameters with units, bounds, a fixed flag and provenance; immutable parameter sets.

Values are stored in SI base units (``unit`` is the SI spelling: ``'kg'``, ``'N/m'``,
``'N*s/m'``, ``'m/V'``, ``'1'`` for dimensionless). ``display_unit`` says how people like to read
the value (``'mg'``, ``'um/V'``). Parameter sets are immutable: every change returns a new set.

>>> k = Parameter("k_s", 128.0, "N/m", "force-sensor stiffness", bounds=(0, None),
...               source="001_0b92a7da96e7aa46.txt, Table II, left finger")
>>> ps = ParameterSet([k], name="sensor")
>>> ps.replace(k_s="130.8 N/m")["k_s"].value
130.8
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass

import numpy as np

from .errors import ParameterError
from .units import convert, format_quantity, same_dimension, to_si

__all__ = ["Parameter", "ParameterSet"]


@dataclass(frozen=True)
class Parameter:
    """One physical parameter.

    Attributes
    ----------
    name
        Identifier (a valid Python name), e.g. ``'k_s'``.
    value
        Value in SI base units.
    unit
        SI unit string (``'1'`` when dimensionless). Required: gripkit has no unitless parameters.
    doc
        One line saying what the parameter means.
    bounds
        ``(lower, upper)`` in SI; ``None`` for unbounded. Values outside raise ``ParameterError``.
    fixed
        Held constant by identification.
    source
        Provenance: seed file, table/equation/page, or "identified from <file>".
    std
        One-sigma uncertainty in SI (from identification), or ``None``.
    display_unit
        Unit for reports and CLI output.
    """

    name: str
    value: float
    unit: str
    doc: str
    bounds: tuple[float | None, float | None] = (None, None)
    fixed: bool = False
    source: str = ""
    std: float | None = None
    display_unit: str | None = None

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise ParameterError(f"parameter name {self.name!r} is not a valid identifier")
        if not isinstance(self.unit, str) or not self.unit.strip():
            raise ParameterError(
                f"parameter {self.name!r} has no unit",
                hint="give its SI unit, or '1' if it is dimensionless",
            )
        if not self.doc or not self.doc.strip():
            raise ParameterError(f"parameter {self.name!r} has no one-line meaning (doc)")
        try:
            v = float(self.value)
        except (TypeError, ValueError):
            raise ParameterError(
                f"parameter {self.name!r}: expected a number, found {self.value!r}"
            ) from None
        if not math.isfinite(v):
            raise ParameterError(f"parameter {self.name!r} is {v} (must be finite)")
        object.__setattr__(self, "value", v)
        lo, hi = self.bounds
        lo = -math.inf if lo is None else float(lo)
        hi = math.inf if hi is None else float(hi)
        if lo > hi:
            raise ParameterError(f"parameter {self.name!r}: lower bound {lo:g} > "
                                 f"upper bound {hi:g}")
        object.__setattr__(self, "bounds", (lo, hi))
        if not lo <= v <= hi:
            raise ParameterError(
                f"parameter {self.name!r} = {v:g} {self.unit} is outside its bounds "
                f"[{lo:g}, {hi:g}] {self.unit}",
                hint="check the value and its unit",
            )
        if self.std is not None:
            s = float(self.std)
            if not (math.isfinite(s) or s == math.inf) or s < 0:
                raise ParameterError(f"parameter {self.name!r}: std must be >= 0, found {s}")
            object.__setattr__(self, "std", s)

    def with_value(self, value: float, std: float | None = None,
                   source: str | None = None) -> "Parameter":
        """A copy holding ``value`` (SI), optionally with its uncertainty and provenance."""
        return dataclasses.replace(
            self, value=value, std=std, source=self.source if source is None else source
        )

    def display(self, digits: int = 4) -> str:
        """``'k_s = 128 N/m'`` in the display unit, with ± std when known."""
        return f"{self.name} = " + format_quantity(
            self.value, self.unit, self.display_unit, digits=digits, std=self.std
        )

    def to_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d["bounds"] = [None if not math.isfinite(b) else b for b in self.bounds]
        return d


class ParameterSet(Mapping[str, Parameter]):
    """An ordered, immutable collection of :class:`Parameter`.

    ``ps["k_s"]`` is the Parameter, ``ps.value("k_s")`` its SI value, ``ps.vector()`` all values
    in order. ``replace``, ``fix``, ``free`` and ``with_estimates`` return new sets.
    """

    __slots__ = ("_params", "name")

    def __init__(self, params: Iterable[Parameter] = (), name: str = ""):
        d: dict[str, Parameter] = {}
        for p in params:
            if not isinstance(p, Parameter):
                raise ParameterError("ParameterSet takes Parameter objects, found "
                                     f"{type(p).__name__}")
            if p.name in d:
                raise ParameterError(f"parameter {p.name!r} appears twice in set {name!r}")
            d[p.name] = p
        self._params = d
        self.name = name

    # Mapping protocol
    def __getitem__(self, key: str) -> Parameter:
        try:
            return self._params[key]
        except KeyError:
            raise ParameterError(
                f"no parameter {key!r} in set {self.name!r}",
                hint=f"available: {', '.join(self._params)}",
            ) from None

    def __iter__(self) -> Iterator[str]:
        return iter(self._params)

    def __contains__(self, key) -> bool:  # Mapping's default would leak ParameterError
        return key in self._params

    def __len__(self) -> int:
        return len(self._params)

    def __repr__(self) -> str:
        inner = ", ".join(p.display() for p in self._params.values())
        return f"ParameterSet({self.name!r}: {inner})"

    def __eq__(self, other) -> bool:
        return isinstance(other, ParameterSet) and self._params == other._params

    __hash__ = None  # type: ignore[assignment]

    # Access
    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self._params)

    @property
    def free_names(self) -> tuple[str, ...]:
        return tuple(n for n, p in self._params.items() if not p.fixed)

    def value(self, name: str) -> float:
        return self[name].value

    def vector(self, names: Iterable[str] | None = None) -> np.ndarray:
        """SI values as a float64 array, in set order or in the order of ``names``."""
        names = self.names if names is None else tuple(names)
        return np.array([self[n].value for n in names], dtype=np.float64)

    def bounds_arrays(self, names: Iterable[str] | None = None) -> tuple[np.ndarray, np.ndarray]:
        names = self.names if names is None else tuple(names)
        lo = np.array([self[n].bounds[0] for n in names], dtype=np.float64)
        hi = np.array([self[n].bounds[1] for n in names], dtype=np.float64)
        return lo, hi

    # Changes (each returns a new set)
    def replace(self, **values: float | str) -> "ParameterSet":
        """New set with some values replaced. A string value is parsed with its unit
        (``replace(M_a="1.37 mg")``) and must have the parameter's dimension."""
        new = dict(self._params)
        for name, v in values.items():
            p = self[name]
            if isinstance(v, str):
                si, unit = to_si(v)
                if not same_dimension(unit, p.unit):
                    raise ParameterError(
                        f"parameter {name!r}: expected a value in {p.unit!r}, found {v!r} ({unit})"
                    )
                v = si
            elif isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)):
                raise ParameterError(f"parameter {name!r}: expected a number (in {p.unit!r}) "
                                     "or a string with "
                                     f"its unit, found {type(v).__name__} {v!r:.40}")
            new[name] = p.with_value(float(v))
        return ParameterSet(new.values(), self.name)

    def from_vector(self, vec: np.ndarray, names: Iterable[str] | None = None,
                    std: np.ndarray | None = None, source: str | None = None) -> "ParameterSet":
        """New set with the values of ``names`` (default: free parameters) taken from ``vec``."""
        names = self.free_names if names is None else tuple(names)
        vec = np.asarray(vec, dtype=np.float64)
        if vec.shape != (len(names),):
            raise ParameterError(f"expected a vector of {len(names)} values for {names}, found "
                                 f"shape {vec.shape}")
        new = dict(self._params)
        for i, n in enumerate(names):
            s = None if std is None else float(std[i])
            new[n] = self[n].with_value(float(vec[i]), std=s, source=source)
        return ParameterSet(new.values(), self.name)

    def fix(self, *names: str) -> "ParameterSet":
        return self._set_fixed(names, True)

    def free(self, *names: str) -> "ParameterSet":
        return self._set_fixed(names, False)

    def only_free(self, *names: str) -> "ParameterSet":
        """Fix every parameter except ``names``."""
        for n in names:
            self[n]
        return ParameterSet(
            (dataclasses.replace(p, fixed=p.name not in names) for p in self._params.values()),
            self.name,
        )

    def _set_fixed(self, names, fixed: bool) -> "ParameterSet":
        new = dict(self._params)
        for n in names:
            new[n] = dataclasses.replace(self[n], fixed=fixed)
        return ParameterSet(new.values(), self.name)

    def merged(self, other: "ParameterSet", name: str | None = None) -> "ParameterSet":
        return ParameterSet([*self._params.values(), *other._params.values()], name or self.name)

    # Export
    def to_dict(self) -> dict:
        return {"name": self.name, "parameters": [p.to_dict() for p in self._params.values()]}

    def to_json(self, **kw) -> str:
        return json.dumps(self.to_dict(), **kw)

    @classmethod
    def from_dict(cls, d: Mapping) -> "ParameterSet":
        params = []
        for pd in d["parameters"]:
            pd = dict(pd)
            pd["bounds"] = tuple(pd.get("bounds") or (None, None))
            params.append(Parameter(**pd))
        return cls(params, d.get("name", ""))

    def table(self) -> list[dict]:
        """Rows for reports: name, value (display unit), std, unit, fixed, doc, source."""
        rows = []
        for p in self._params.values():
            u = p.display_unit or p.unit
            val = convert(p.value, p.unit, u) if p.display_unit else p.value
            std = None
            if p.std is not None:
                std = (abs(convert(p.std, p.unit,
                                   u) - convert(0.0, p.unit, u)) if p.display_unit else p.std)
            rows.append(dict(name=p.name, value=val, std=std, unit=u, fixed=p.fixed,
                             doc=p.doc, source=p.source))
        return rows

