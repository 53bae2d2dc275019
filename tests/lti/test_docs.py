"""docs/lti.md's example runs (its numbers are asserted where the page states them)."""

import contextlib
import io
import pathlib
import re

DOC = pathlib.Path(__file__).resolve().parents[2] / "docs" / "lti.md"


def test_docs_example_runs():
    blocks = re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), flags=re.S)
    assert blocks, "docs/lti.md has no python example"
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(blocks[0], str(DOC), "exec"), {})
    lines = out.getvalue().splitlines()
    assert lines[0] == "[50. 50.] [[1.]]"
    assert lines[1].startswith("[[0.666") and lines[1].endswith("['V_in']")
    assert lines[-1] == "2 False"
