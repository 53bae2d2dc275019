"""Parameter consistency checks: find where a parameter set contradicts itself.

Seeds printed from PDFs contain numbers that disagree with each other (for example Table II of
``001_0b92a7da96e7aa46.txt`` gives k_s = 128 N/m and m_s = 1.8e-6 kg, whose sqrt(k_s/m_s)/2π is
1.34 kHz, while §IV-B measured 8.52 kHz). gripkit does not hide such contradictions: a model
lists its checks (a method ``consistency_checks() -> list[Finding]``), :func:`check` runs them,
and building a model with contradictory parameters emits a :class:`ConsistencyWarning` that says
which value gripkit uses.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterable, Sequence
from dataclasses import asdict, dataclass

from .errors import ConsistencyWarning, emit_warning

__all__ = ["Finding", "ConsistencyReport", "compare", "check", "warn_inconsistent"]


@dataclass(frozen=True)
class Finding:
    """The result of one consistency check.

    Attributes
    ----------
    check
        Short identifier, e.g. ``'sensor-natural-frequency'``.
    subject
        The model or parameter set checked.
    consistent
        True when the values agree within ``tolerance``.
    message
        What was compared and what was found, with numbers and units.
    used
        Which value gripkit uses, and why.
    computed, stated
        The value derived from other parameters and the value printed/stated.
    rel_error
        ``|computed - stated| / |stated|``.
    tolerance
        Relative tolerance of the check.
    source
        Where the stated value comes from (seed, table, equation).
    """

    check: str
    subject: str
    consistent: bool
    message: str
    used: str = ""
    computed: float = math.nan
    stated: float = math.nan
    rel_error: float = math.nan
    tolerance: float = math.nan
    source: str = ""

    def to_dict(self) -> dict:
        return asdict(self)

    def __str__(self) -> str:
        status = "ok" if self.consistent else "INCONSISTENT"
        text = f"[{status}] {self.subject}: {self.check}: {self.message}"
        if self.used and not self.consistent:
            text += f" -> {self.used}"
        return text


def compare(check: str, subject: str, *, computed: float, stated: float, rtol: float,
            what: str, unit: str = "", used: str = "", source: str = "") -> Finding:
    """Compare a derived value with a stated one.

    ``what`` describes the derivation, e.g. ``"sqrt(k_s/m_s)/2π from Table II"``.
    """
    rel = abs(computed - stated) / abs(stated) if stated != 0 else abs(computed - stated)
    ok = bool(rel <= rtol)
    u = f" {unit}" if unit else ""
    msg = (f"{what} = {computed:.6g}{u}, stated {stated:.6g}{u} "
           f"({100 * rel:.3g} % apart, tolerance {100 * rtol:.3g} %)")
    return Finding(check, subject, ok, msg, used, float(computed), float(stated), float(rel),
                   float(rtol), source)


class ConsistencyReport(Sequence[Finding]):
    """The findings of :func:`check` for one object."""

    def __init__(self, findings: Iterable[Finding], subject: str = ""):
        self._f = list(findings)
        self.subject = subject

    def __getitem__(self, i):
        return self._f[i]

    def __len__(self) -> int:
        return len(self._f)

    @property
    def ok(self) -> bool:
        return all(f.consistent for f in self._f)

    @property
    def inconsistent(self) -> list[Finding]:
        return [f for f in self._f if not f.consistent]

    def find(self, check: str) -> Finding:
        for f in self._f:
            if f.check == check:
                return f
        raise KeyError(f"no check {check!r} in report for {self.subject!r}")

    def to_dicts(self) -> list[dict]:
        return [f.to_dict() for f in self._f]

    def __str__(self) -> str:
        if not self._f:
            return f"{self.subject}: no consistency checks"
        return "\n".join(str(f) for f in self._f)


def check(obj) -> ConsistencyReport:
    """Run ``obj.consistency_checks()`` and return the report (empty if it has none)."""
    fn = getattr(obj, "consistency_checks", None)
    findings = fn() if fn is not None else []
    return ConsistencyReport(findings, getattr(obj, "name", type(obj).__name__))


#: texts already warned, valid while ``warnings.filters`` is the list object they were shown under
_shown: set[tuple[str, str, str]] = set()
_shown_under: list = []


def warn_inconsistent(findings: Iterable[Finding], stacklevel: int | None = None) -> None:
    """Emit one :class:`ConsistencyWarning` per inconsistent finding, pointing at the user's line.

    A finding is warned once: building the same model again (same subject, check and message)
    stays silent until the warning filters are reset (a new ``warnings.catch_warnings()`` context,
    e.g. ``pytest.warns``, shows them again). ``stacklevel`` (as for ``warnings.warn``) overrides
    the default, which is the first frame outside gripkit.
    """
    global _shown_under
    if warnings.filters is not _shown_under:  # catch_warnings() entered or left: a fresh context
        _shown.clear()
        _shown_under = warnings.filters
    for f in findings:
        key = (f.subject, f.check, f.message)
        if not f.consistent and key not in _shown:
            _shown.add(key)
            emit_warning(str(f), ConsistencyWarning,
                         stacklevel=None if stacklevel is None else stacklevel + 1)
