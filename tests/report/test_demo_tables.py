"""Demo tables a reader can scan: no nan cells, no repeated consistency rows; forces in N that
rest on the assumed AMADEUS force scale say so."""

import math
import warnings

import pytest

from gripkit.report import Report


def _run(module):
    rep = Report("test")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        module.run(rep, quick=True)
    return rep


def _tables(rep):
    return [(sec.title, item) for sec in rep.sections
            for kind, item in sec.items if kind == "table"]


def _assert_no_nan_cells(rep):
    for title, t in _tables(rep):
        for row in t.rows:
            for c in row:
                assert not (isinstance(c, float) and math.isnan(c)), (title, t.caption[:60], row)
                assert not (isinstance(c, str)
                            and c.strip().lower() == "nan"), (title, t.caption[:60], row)


def test_amadeus_demo_marks_forces_resting_on_the_force_scale():
    from gripkit.systems.amadeus import demo_hand
    from gripkit.systems.amadeus.force_dynamics import FORCE_SCALE_NOTE

    rep = _run(demo_hand)
    _assert_no_nan_cells(rep)
    captions = {"table": [], "figure": []}
    for sec in rep.sections:
        for kind, item in sec.items:
            if kind in captions:
                captions[kind].append(item.caption)
    grasp = [c for c in captions["table"] if c.startswith("Force-limited grasps")]
    assert grasp and all(FORCE_SCALE_NOTE in c for c in grasp)
    assert sum(FORCE_SCALE_NOTE in c for c in captions["figure"]) == 2  # force step, grasp


@pytest.mark.slow
@pytest.mark.parametrize("name", ["ftg100", "dlr_hit"])
def test_demo_tables_have_no_nan_and_no_repeated_consistency_rows(name):
    import importlib

    rep = _run(importlib.import_module(f"gripkit.systems.{name}.demo"))
    _assert_no_nan_cells(rep)
    seen = set()
    for _, t in _tables(rep):
        if t.headers[:2] == ["status", "check"]:
            keys = [(r[1], r[2]) for r in t.rows]
            assert len(keys) == len(set(keys)), t.caption
            assert not seen & set(keys), f"{t.caption}: rows repeated from an earlier table"
            seen |= set(keys)
