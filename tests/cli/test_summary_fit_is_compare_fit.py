"""One fit definition (issue 23): the free-run fit that ``gripkit identify`` prints for the
estimation record is the number ``gripkit compare MODEL.json RECORD`` prints for the saved model.
Record: DaISy 96-009, the flexible robot arm (tests/fixtures/flexible_arm, its README), where the
ss summary printed 96.46 % (the free run from the innovation predictor's x0) and compare 97.03 %
(the free run from its own least-squares x0). armax/oe print their one-step fit, labelled
"fit (1-step)", and beside it the free-run fit of compare (JSON ``free_run_fit_percent``); arx
prints its labelled one-step fit alone (its command loads no numba: the free run would cost the
start-up, tests/core/test_import_cost.py)."""

import json
import re
from pathlib import Path

import pytest

from gripkit.cli import main

ARM = Path(__file__).parents[1] / "fixtures" / "flexible_arm" / "flexible_arm.csv"
IO = ["--input", "torque", "--output", "acceleration", "--fs", "1"]


def _run(capsys, *args):
    code = main([*map(str, args)])
    out = capsys.readouterr()
    assert code == 0, out.err
    return out.out


@pytest.mark.parametrize("command, key", [
    (["ss", "--order", "4"], "fit_percent"),
    (["tf", "--poles", "4", "--zeros", "2"], "fit_percent"),
    (["oe", "--nb", "2", "--nf", "2", "--nk", "1"], "free_run_fit_percent"),
])
def test_identify_summary_fit_is_the_compare_fit(tmp_path, capsys, command, key):
    model = tmp_path / f"{command[0]}.json"
    text = _run(capsys, "identify", command[0], ARM, *command[1:], *IO, "--out", model)
    res = json.loads(_run(capsys, "identify", command[0], ARM, *command[1:], *IO, "--json"))
    cmp = json.loads(_run(capsys, "compare", model, ARM, "--fs", "1", "--json"))
    summary = res[key][0] if isinstance(res[key], list) else res[key]
    assert summary == pytest.approx(cmp["fit_percent"][0], abs=1e-6)
    if command[0] == "ss":  # the text line, as the audit read it
        shown = re.search(r"acceleration: free-run fit (-?[\d.]+) %", text).group(1)
    elif command[0] == "tf":
        shown = re.search(r"free-run fit (-?[\d.]+) %", text).group(1)
    else:
        assert re.search(r"fit \(1-step\) = [\d.]+ %", text)
        shown = re.search(r"as gripkit compare\) = (-?[\d.]+) %", text).group(1)
    assert shown == f"{cmp['fit_percent'][0]:.2f}"
