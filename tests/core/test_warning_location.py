"""Warnings point at the user's line (issue 25, "rough edges": they pointed into gripkit):
gripkit.errors.emit_warning attributes a warning to the first frame outside the package, however
deep
the call inside it."""

import warnings
from pathlib import Path

import numpy as np

from gripkit.errors import AccuracyWarning, GripkitWarning, emit_warning


def test_warn_from_outside_gripkit_points_here():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        emit_warning("direct", AccuracyWarning)
    assert caught[0].filename == __file__ and caught[0].category is AccuracyWarning


def test_a_warning_deep_in_gripkit_points_at_the_calling_line():
    """The step-metrics warning of a record that has not settled is raised two calls deep in
    gripkit; it names this file and this line."""
    from gripkit.models.second_order import second_order_step
    from gripkit.sysid.physical.step_response import step_metrics

    t = np.linspace(0.0, 1.2, 600)
    y = second_order_step(t, 1.0, 2 * np.pi, 0.026)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        line = __import__("inspect").currentframe().f_lineno + 1
        step_metrics(t, y, y_initial=0.0)
    ours = [w for w in caught if issubclass(w.category, GripkitWarning)]
    assert ours, "expected the not-settled warning"
    assert all(Path(w.filename) == Path(__file__) and w.lineno == line for w in ours)


def test_every_warning_in_gripkit_goes_through_emit_warning():
    """No module of gripkit calls warnings.warn itself (only errors.emit_warning does)."""
    src = Path(__file__).resolve().parents[2] / "src" / "gripkit"
    calls = [f"{p.relative_to(src)}:{i}" for p in sorted(src.rglob("*.py")) if p.name != "errors.py"
             for i, line in enumerate(p.read_text().splitlines(), 1) if "warnings.warn(" in line]
    assert calls == [], "use gripkit.errors.emit_warning: " + ", ".join(calls)
