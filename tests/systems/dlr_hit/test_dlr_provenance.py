"""Provenance of the DLR/HIT finger (issue 28 item 6): IDIM-LS, the online friction adaptation,
the motor's thermal model and LuGre friction are gripkit's additions, not the content of
``002_ddea254371185ad3.txt``; the README's seed table, docs/dlr_hit.md and the modules that
implement them say so, and none of them cites the seed as their source."""

import importlib
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
ADDITIONS = ("IDIM-LS", "online friction adaptation", "thermal model", "LuGre")


def _dlr_row() -> str:
    rows = [r for r in (ROOT / "README.md").read_text(encoding="utf-8").splitlines()
            if r.startswith("| `dlr-hit-finger`")]
    assert len(rows) == 1
    return rows[0]


def test_readme_seed_row_names_the_additions():
    row = _dlr_row()
    head, _, tail = row.partition("gripkit's additions, not the thesis's content:")
    assert tail, row
    for name in ADDITIONS:
        assert name in tail and name not in head, name


def test_docs_state_the_provenance():
    text = (ROOT / "docs" / "dlr_hit.md").read_text(encoding="utf-8")
    para = re.search(r"\*\*Provenance:.*?\n\n", text, re.S).group(0)
    assert "gripkit's additions, not the thesis's content" in para
    for name in ("IDIM-LS", "online\nfriction adaptation", "thermal model", "LuGre"):
        assert name.replace("\n", " ") in para.replace("\n", " "), name


@pytest.mark.parametrize("module", ["gripkit.sysid.rigid_body.friction",
                                    "gripkit.estimation.friction_adaptation",
                                    "gripkit.systems.dlr_hit.friction_adaptation",
                                    "gripkit.models.bldc", "gripkit.models.friction",
                                    "gripkit.systems.dlr_hit.impedance"])
def test_module_docstrings_mark_the_addition(module):
    doc = " ".join(importlib.import_module(module).__doc__.split())
    assert "gripkit's addition" in doc, module
