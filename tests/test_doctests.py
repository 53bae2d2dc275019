"""Every module's ``>>>`` examples run in the default test run (issue 12): one test per module of
gripkit that has examples. Collected here rather than with ``--doctest-modules`` so that the test
folders' several ``conftest.py`` are not imported as modules."""

import doctest
import importlib
import pkgutil

import pytest

import gripkit


def _modules_with_examples():
    names = ([gripkit.__name__] + [m.name for m in pkgutil.walk_packages(gripkit.__path__,
                                                                         "gripkit.")])
    found = []
    for name in names:
        module = importlib.import_module(name)
        if any(t.examples for t in doctest.DocTestFinder().find(module)):
            found.append(name)
    return found


MODULES = _modules_with_examples()


def test_modules_with_examples_are_found():
    assert "gripkit.units" in MODULES and len(MODULES) >= 16


@pytest.mark.parametrize("name", MODULES)
def test_module_examples_run(name):
    module = importlib.import_module(name)
    result = (doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE,
                              verbose=False))
    assert result.failed == 0, \
        f"{result.failed} of {result.attempted} examples in {name} failed (output above)"
