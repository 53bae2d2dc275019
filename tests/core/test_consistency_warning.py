"""ConsistencyWarning: points at the user's line and is shown once per distinct finding."""

import warnings

import pytest

from gripkit import zoo
from gripkit.consistency import check
from gripkit.errors import ConsistencyWarning


@pytest.mark.parametrize("name", ["dlr-hit-finger", "tsfm-left", "amadeus-hand"])
def test_three_builds_warn_once_per_distinct_finding_at_the_callers_line(name):
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        models = [zoo.build(name) for _ in range(3)]
    got = [w for w in rec if issubclass(w.category, ConsistencyWarning)]
    expected = {str(f) for f in check(models[0]).inconsistent}
    assert expected, f"{name} has no inconsistent finding to warn about"
    assert sorted(str(w.message) for w in got) == sorted(expected)  # each once, none missing
    assert {w.filename for w in got} == {__file__}


def test_a_new_warnings_context_shows_the_findings_again():
    with pytest.warns(ConsistencyWarning, match="fig5.7-temperature-coefficient"):
        zoo.build("dlr-hit-finger")
    with pytest.warns(ConsistencyWarning, match="fig5.7-temperature-coefficient"):
        zoo.build("dlr-hit-finger")


def test_a_changed_parameter_is_a_new_finding():
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        m = zoo.build("tsfm-left")
        n_first = len(rec)
        m.with_parameters(m_s=2.0e-6)
    assert n_first > 0 and len(rec) > n_first  # sensor-natural-frequency changes with m_s
    assert all(w.filename == __file__ for w in rec)
