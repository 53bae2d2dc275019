"""Helpers of the bad-input corpus (issue 11): every case runs the CLI in-process (or the Python
API) and asserts the error class and a key phrase of the one-line message, or the warning.

Imported as ``from corpus import ...``: pytest puts this folder on ``sys.path`` for its test
modules, and the name is unique where ``conftest`` is not (tests/ holds several)."""

from __future__ import annotations

import json


class CliResult:
    """Exit code, stdout and stderr of one in-process ``gripkit`` call."""

    def __init__(self, code: int, out: str, err: str):
        self.code, self.out, self.err = code, out, err

    @property
    def error_lines(self) -> list[str]:
        return [ln for ln in self.err.splitlines() if ln.startswith("error:")]

    def json(self) -> dict:
        return json.loads(self.out)


def assert_user_error(res: CliResult, error_class: str, phrase: str) -> None:
    """A user error: non-zero exit, exactly one ``error:`` line on stderr naming ``error_class`` and
    containing ``phrase`` (case-insensitive), no traceback and never the word 'unexpected'."""
    assert res.code != 0, (res.out, res.err)
    assert "Traceback" not in res.err, res.err
    assert len(res.error_lines) == 1, res.err
    line = res.error_lines[0]
    assert "unexpected" not in line, line
    assert error_class in line, line
    assert phrase.lower() in line.lower(), line


def assert_warned(res: CliResult, phrase: str) -> None:
    """A warning: the phrase on stderr and, for ``--json`` output, in the JSON ``warnings`` list."""
    assert phrase.lower() in res.err.lower(), res.err
    if res.out.lstrip().startswith("{"):
        assert any(phrase.lower() in w.lower() for w in res.json().get("warnings", [])), res.out


def clipped_arx_record(n: int = 400, seed: int = 0):
    """(u, y) of y(t) = 1.2 y(t−1) − 0.5 y(t−2) + 0.8 w(t−1) + 0.3 w(t−2), w = u clipped to ±0.8,
    with 0.01 output noise: a record every model family fits (the files of the model-file tests)."""
    import numpy as np

    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    w = np.clip(u, -0.8, 0.8)
    y = np.zeros(n)
    for t in range(2, n):
        y[t] = 1.2 * y[t - 1] - 0.5 * y[t - 2] + 0.8 * w[t - 1] + 0.3 * w[t - 2]
    return u, y + 0.01 * rng.standard_normal(n)


def loaded_with_data_warnings(load, path):
    """``load(path)`` and the DataWarnings it gave."""
    import warnings

    from gripkit.errors import DataWarning

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        obj = load(path)
    return obj, [w for w in caught if issubclass(w.category, DataWarning)]


def documented_digest(doc: dict) -> str:
    """The ``content_sha256`` of a model or controller file's document as the file format
    specifies it, recomputed here with hashlib (not with gripkit's function): the SHA-256 of all
    other entries serialised with sorted keys, no spaces and ASCII escapes."""
    import hashlib

    body = {k: v for k, v in doc.items() if k != "content_sha256"}
    text = json.dumps(body, sort_keys=True, separators=(",", ":"), ensure_ascii=True)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()
