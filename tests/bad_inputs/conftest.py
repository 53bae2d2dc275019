"""The ``cli`` fixture of the bad-input corpus; the assertions live in ``corpus.py``."""

from __future__ import annotations

import pytest
from corpus import CliResult

from gripkit.cli import main


@pytest.fixture
def cli(capsys):
    """``cli(*args)`` runs ``gripkit ARGS`` and returns a :class:`CliResult`."""

    def run(*args) -> CliResult:
        code = main([str(a) for a in args])
        out, err = capsys.readouterr()
        return CliResult(code, out, err)

    return run
