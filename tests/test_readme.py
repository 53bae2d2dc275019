"""The README's ```python blocks are self-contained and run (issue 16): each in a fresh namespace,
in a temporary directory. Shell blocks are not run."""

import re
import warnings
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"
BLOCKS = re.findall(r"^```python\n(.*?)^```", README.read_text(encoding="utf-8"), re.S | re.M)


def test_readme_has_python_blocks():
    assert len(BLOCKS) >= 4


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_readme_block_runs(index, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")       # the seeds' ConsistencyWarnings are expected here
        exec(compile(BLOCKS[index], f"README.md block {index + 1}", "exec"),
             {"__name__": "__readme__"})
