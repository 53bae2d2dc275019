"""Every ```python block of the docs runs as pasted (issue 25): the blocks of one page run in page
order in one namespace (a later block may use what an earlier one made), in a fresh temporary
folder, so every file a block reads must be created by the page itself. Slow pages (a demo-length
study) are marked in ``SLOW`` and run with ``-m slow``; the README's blocks are
tests/test_readme.py."""

import re
import warnings
from pathlib import Path

import matplotlib
import pytest

DOCS = Path(__file__).resolve().parents[1] / "docs"
PAGES = sorted(p for p in DOCS.glob("*.md")
               if re.search(r"^```python\n", p.read_text(encoding="utf-8"), re.M))
# pages whose blocks are a demo-length study (none today: every page runs in seconds once numba's
# cache is warm); they run with ``pytest -m slow`` / ``make test-all``
SLOW: set[str] = set()


def blocks(page: Path) -> list[str]:
    return re.findall(r"^```python\n(.*?)^```", page.read_text(encoding="utf-8"), re.S | re.M)


@pytest.mark.parametrize("page", [pytest.param(p, marks=pytest.mark.slow) if p.name in SLOW else p
                                  for p in PAGES], ids=lambda p: p.name)
def test_page_blocks_run_in_order(page, tmp_path, monkeypatch):
    matplotlib.use("Agg")
    monkeypatch.chdir(tmp_path)
    namespace = {"__name__": "__docs__"}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the seeds' ConsistencyWarnings are expected here
        for i, code in enumerate(blocks(page), 1):
            exec(compile(code, f"{page.name} block {i}", "exec"), namespace)


def test_the_docs_have_python_blocks():
    assert sum(len(blocks(p)) for p in PAGES) >= 30
