"""``gripkit demo --section … --quick`` tells its progress (audit of 27 Nov: a section ran for
tens of seconds without a word): each section announces its parts on stderr with
:func:`gripkit.progress.status` (``  SECTION: part``, the form of the tsfm section), the batch
section shows its grasp batches with :func:`gripkit.progress.track`; stdout keeps only the
command's result (``--json``: one JSON object), and ``--quiet`` silences the progress.

The fast tests replace each part of a section by a recorder of what stdout and stderr hold when
the part starts (the parts themselves are the demo's, run by ``make demo`` and the slow test)."""

from __future__ import annotations

import importlib
import json

import pytest

from gripkit.cli import main
from gripkit.demos import SECTIONS

#: section → its parts in run order, each with the progress lines printed just before it starts
PARTS = {
    "ftg100": [
        ("_model_section", ["  ftg100: model and printed numbers (eqs 3-18)"]),
        ("_static_section", ["  ftg100: static deflection at 70 V"]),
        ("_step_section", ["  ftg100: step responses"]),
        ("_resonance_section", ["  ftg100: resonance vs actuation voltage (Fig. 5)"]),
        ("_identification_section", ["  ftg100: identification (§III-B)"]),
        ("_hybrid_section", ["  ftg100: hybrid force/position control"]),
    ],
    "dlr-hit": [
        ("_motor_maps", ["  dlr-hit: consistency",
                         "  dlr-hit: motor maps and identification (§5.4)"]),
        ("_friction", ["  dlr-hit: friction tables (Appendix G)"]),
        ("_velocity_responses", ["  dlr-hit: velocity responses (Figs 7.3-7.5)"]),
        ("_stiction_and_idim", ["  dlr-hit: breakaway and IDIM-LS friction identification"]),
        ("_adaptation", ["  dlr-hit: friction adaptation"]),
        ("_loop_adaptation", []),
        ("_thermal_adaptation", []),
        ("_impedance", ["  dlr-hit: impedance control"]),
        ("_hand", ["  dlr-hit: five-finger hand"]),
    ],
}


def _recorded(section, monkeypatch, capsys) -> list:
    """Replace the parts of ``section`` by recorders; returns the list they fill with
    ``(part, stdout, stderr lines)`` as each starts."""
    module = importlib.import_module(SECTIONS[section])
    seen = []

    def recorder(name):
        def part(*args, **kwargs):
            out, err = capsys.readouterr()
            seen.append((name, out, err.splitlines()))
        return part

    for name, _ in PARTS[section]:
        monkeypatch.setattr(module, name, recorder(name))
    return seen


@pytest.mark.parametrize("section", list(PARTS))
def test_each_part_is_announced_on_stderr_before_it_runs(section, monkeypatch, capsys,
                                                         tmp_path):
    """``gripkit demo --section S --quick --json``: the section's line ``[1/1] S ...``, then
    each part's line just before the part starts, the section's closing line; stdout holds only
    the one JSON object of the result."""
    seen = _recorded(section, monkeypatch, capsys)
    code = main(["demo", "--section", section, "--quick", "--json", "--out", str(tmp_path)])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert [name for name, _, _ in seen] == [name for name, _ in PARTS[section]]
    assert all(o == "" for _, o, _ in seen)
    first = [f"[1/1] {section} ..."] + PARTS[section][0][1]
    assert seen[0][2] == first
    assert [lines for _, _, lines in seen[1:]] == [lines for _, lines in PARTS[section][1:]]
    assert err.splitlines()[0].startswith(f"[1/1] {section} done in ")
    doc = json.loads(out)
    assert doc["report"] == str(tmp_path / "index.html") and list(doc["sections"]) == [section]


def test_quiet_silences_the_progress(monkeypatch, capsys, tmp_path):
    """``gripkit --quiet demo …``: no progress line at all, the same one line on stdout."""
    seen = _recorded("ftg100", monkeypatch, capsys)
    code = main(["--quiet", "demo", "--section", "ftg100", "--quick", "--out", str(tmp_path)])
    out, err = capsys.readouterr()
    assert code == 0 and err == "" and all(lines == [] for _, _, lines in seen)
    assert out == f"report written to {tmp_path / 'index.html'}\n"


@pytest.mark.slow
def test_real_sections_show_progress_and_keep_stdout_clean(capsys, tmp_path):
    """The real amadeus-identification and batch-robustness sections (quick, about a minute):
    stderr has every part line of the first and the batch's grasp progress (gripkit.progress
    .track without a terminal: lines ``demo-hold (…): k/n (p %``), stdout only the JSON."""
    code = main(["demo", "--section", "amadeus-identification", "--section", "batch-robustness",
                 "--quick", "--json", "--out", str(tmp_path)])
    out, err = capsys.readouterr()
    assert code == 0, err
    doc = json.loads(out)
    assert list(doc["sections"]) == ["amadeus-identification", "batch-robustness"]
    lines = err.splitlines()
    parts = [ln for ln in lines if ln.startswith("  amadeus-identification: ")]
    assert len(parts) == 6 and parts[0].endswith("simulated records (§V-E)")
    for study in ("demo-hold", "demo-naive"):
        bar = [ln for ln in lines if ln.startswith(f"  {study} (in-process")]
        assert bar and "(100 %" in bar[-1]
