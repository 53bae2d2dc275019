"""The check of kernel results against recordings (tests/conftest.py) passes what agrees to
RECORD_RTOL and fails what does not."""

import numpy as np
import pytest


def test_a_result_agrees_with_its_own_record_and_its_rows_are_spread(assert_matches_record,
                                                                     record_tools):
    record_of, RECORD_RTOL = record_tools.record_of, record_tools.rtol
    result = np.column_stack([np.linspace(0.0, 1.0, 300), np.full(300, np.inf), np.zeros(300)])
    record = record_of(result)
    assert record["rows"][0] == 0 and record["rows"][-1] == 299 and 12 <= len(record["rows"]) <= 14
    assert_matches_record("same", result * (1.0 + 0.1 * RECORD_RTOL), record)


@pytest.mark.parametrize("change", ["relative", "inf", "nan", "shape"])
def test_a_result_beyond_the_tolerance_fails(assert_matches_record, record_tools, change):
    record_of, RECORD_RTOL = record_tools.record_of, record_tools.rtol
    result = np.column_stack([np.linspace(1.0, 2.0, 50), np.full(50, np.inf)])
    record = record_of(result)
    bad = result.copy()
    if change == "relative":
        bad[49, 0] *= 1.0 + 10 * RECORD_RTOL
    elif change == "inf":
        bad[0, 1] = 1.0
    elif change == "nan":
        bad[24, 0] = np.nan
    else:
        bad = bad[:-1]
    with pytest.raises(AssertionError):
        assert_matches_record("changed", bad, record)
