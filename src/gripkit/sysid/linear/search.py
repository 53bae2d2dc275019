"""ARX structure search over ranges of ``na``, ``nb``, ``nk`` (like MATLAB's ``arxstruc``).

Every candidate is fitted by least squares (QR) on the *same* samples ``t ≥ t0``,
``t0 = max(na_max, nk_max + nb_max − 1)``, so that losses are comparable, and ranked by a
criterion: ``'aic'`` (default: ``M ln(2π V) + M + 2p``, penalises parameters), ``'fpe'``, or
``'loss'`` (eq 29 of ``000_8f66dcc7ab06470c.txt``; always prefers more parameters — §V-E:
"models estimating more coefficients clearly give better performance"). Candidates the data
cannot determine (rank-deficient regressor) are listed as skipped, with the reason.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np

from ...arguments import entry_point
from ...errors import DataError, GripkitWarning, UnidentifiableError, emit_warning
from ...progress import track
from ..scaling import unit_scale
from ..checks import check_dt, check_identifiable, check_io, check_order
from .polynomial import PolynomialModel
from ..regression import arx_regression, qr_solve
from .validation import compare

__all__ = ["Candidate", "SearchResult", "structure_search", "parse_range"]

CRITERIA = ("aic", "fpe", "loss", "validation")


@dataclass(frozen=True)
class Candidate:
    """One ARX structure of the search, fitted on the common samples."""

    na: int
    nb: int
    nk: int
    n_params: int
    loss: float
    aic: float
    fpe: float
    fit_percent: float
    validation_fit_percent: float | None = None

    def to_dict(self) -> dict:
        d = dict(na=self.na, nb=self.nb, nk=self.nk, n_params=self.n_params, loss=self.loss,
                 aic=self.aic, fpe=self.fpe, fit_percent=self.fit_percent)
        if self.validation_fit_percent is not None:
            d["validation_fit_percent"] = self.validation_fit_percent
        return d


@dataclass(frozen=True)
class SearchResult:
    """Candidates ranked best first by ``criterion``; ``skipped`` lists (na, nb, nk, reason)."""

    candidates: tuple[Candidate, ...]
    criterion: str
    n_used: int
    skipped: tuple[tuple[int, int, int, str], ...] = field(default_factory=tuple)

    @property
    def best(self) -> Candidate:
        return self.candidates[0]

    def __len__(self) -> int:
        return len(self.candidates)

    def __iter__(self):
        return iter(self.candidates)

    def to_list(self) -> list[dict]:
        return [c.to_dict() for c in self.candidates]


def parse_range(text: str | int | Iterable[int], name: str) -> list[int]:
    """``'1:4'`` → [1, 2, 3, 4] (inclusive, MATLAB style), ``'2'`` → [2], ``'1,3,5'`` → [1, 3,
    5]."""
    if isinstance(text, (int, np.integer)):
        return [int(text)]
    if not isinstance(text, str):
        vals = [int(v) for v in text]
        if not vals:
            raise DataError(f"{name}: the range is empty")
        return vals
    t = text.strip()
    try:
        if ":" in t:
            parts = [int(x) for x in t.split(":")]
            if len(parts) == 2:
                lo, hi, step = parts[0], parts[1], 1
            elif len(parts) == 3:
                lo, step, hi = parts
            else:
                raise ValueError
            if step <= 0 or hi < lo:
                raise ValueError
            return list(range(lo, hi + 1, step))
        return [int(x) for x in t.split(",")]
    except ValueError:
        raise DataError(f"{name}: expected a range like '1:4', '1:2:9' or "
                        f"'1,3,5', found {text!r}") from None


@entry_point
def structure_search(u, y, na=range(1, 5), nb=range(1, 5), nk=range(1, 11), *,
                     criterion: str = "aic", dt: float | None = None,
                     progress: bool = True, validate=None) -> SearchResult:
    """Fit every ARX ``[na nb nk]`` of the given ranges and rank them.

    Parameters
    ----------
    u, y
        Input and output, shape (N,), deviation units.
    na, nb, nk
        Iterables of orders (or ``'1:4'`` strings, see :func:`parse_range`).
    criterion
        ``'aic'``, ``'fpe'`` or ``'loss'``; ``'validation'`` (the default when ``validate`` is
        given): free-run fit on the validation record, best first.
    validate
        ``(u2, y2)``: a second record (deviation units) for free-run validation of every candidate.
    progress
        Show a progress bar on stderr (:func:`gripkit.progress.track`) when the search is long
        (more than 2·10⁶ candidate-samples).
    """
    u, y = check_io(u, y)
    step = check_dt(dt)
    if validate is not None:
        uv, yv = check_io(*validate)
        criterion = "validation"
    elif criterion == "validation":
        raise DataError("criterion 'validation' needs a validation record (validate=(u2, y2); "
                        "CLI: --validate)")
    if criterion not in CRITERIA:
        raise DataError(f"criterion: expected one of {', '.join(CRITERIA)}, found {criterion!r}")
    nas = [check_order(v, "na", 0) for v in parse_range(na, "na")]
    nbs = [check_order(v, "nb", 1) for v in parse_range(nb, "nb")]
    nks = [check_order(v, "nk", 0) for v in parse_range(nk, "nk")]
    t0 = max(max(nas), max(nks) + max(nbs) - 1)
    pmax = max(nas) + max(nbs)
    check_identifiable(u, y, t0 + pmax + 1, f"structure search up to na={max(nas)}, "
                                            f"nb={max(nbs)}, nk={max(nks)}")
    cu, cy = unit_scale(u), unit_scale(y)  # exact powers of two (see scaling): any data scale
    u, y = u * cu, y * cy
    yt = y[t0:]
    sst = float(np.sum((yt - yt.mean()) ** 2))
    m = y.size - t0
    grid = [(a, b, k) for a in nas for b in nbs for k in nks]
    found, skipped = [], []
    for a, b, k in track(grid, description="ARX structure search",
                         enabled=progress and len(grid) * y.size > 2e6):
        names = tuple(f"a{i}" for i in range(1, a + 1)) + tuple(f"b{k + j}" for j in range(b))
        try:
            sol = qr_solve(arx_regression(u, y, a, b, k, t0=t0), names, overwrite=True, warn=False)
        except UnidentifiableError as exc:
            skipped.append((a, b, k, str(exc)))
            continue
        p = a + b
        v = sol.rss / m  # in the scaled units: V_user = V / cy²
        aic = m * (math.log(2 * math.pi * v) - 2 * math.log(cy)) + m + 2 * p if v > 0 else -math.inf
        fpe = v * (1 + p / m) / (1 - p / m) / cy / cy
        fit = 100.0 * (1.0 - math.sqrt(sol.rss / sst))
        vfit = (_validation_fit(sol.theta, a, b, k, step, uv * cu,
                                yv * cy) if validate is not None else None)
        found.append(Candidate(a, b, k, p, 0.5 * v / cy / cy, aic, fpe, fit, vfit))
    if not found:
        raise UnidentifiableError("no structure of the search could be identified: "
                                  + (skipped[0][3] if skipped else "empty grid"))
    key = {"aic": lambda c: c.aic, "fpe": lambda c: c.fpe, "loss": lambda c: c.loss,
           "validation": lambda c: (math.inf if c.validation_fit_percent is None
                                    else -c.validation_fit_percent)}[criterion]
    found.sort(key=lambda c: (key(c), c.n_params))
    _warn_edge(found[0], {"na": nas, "nb": nbs, "nk": nks})
    return SearchResult(tuple(found), criterion, m, tuple(skipped))


def _validation_fit(theta, na, nb, nk, dt, u, y) -> float | None:
    """Free-run fit (%) of the ARX [na nb nk] with coefficients θ on (u, y); None if unstable."""
    model = PolynomialModel(np.concatenate([[1.0], theta[:na]]),
                            np.concatenate([np.zeros(nk), theta[na:]]), nk,
                            dt=dt, structure="arx")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # an unstable candidate simply ranks last
        return compare(model, u, y).fit_percent[0]


def _warn_edge(best: Candidate, ranges: dict) -> None:
    edges = [f"{name} = {getattr(best, name)} (searched "
             f"{min(r)}:{max(r)})" for name, r in ranges.items()
             if len(set(r)) >= 3 and getattr(best, name) in (min(r), max(r))]
    if edges:
        emit_warning("structure search: the best structure lies on the edge of the "
                     "searched range: "
                     f"{', '.join(edges)}; the best may lie outside it, "
                     "widen the range", GripkitWarning)
