"""Every public function of gripkit.lti has a runnable example; they all pass."""

import doctest
import importlib
import inspect

import pytest

import gripkit.lti as lti

MODULES = ["gripkit.lti", "gripkit.lti._system", "gripkit.lti._interop", "gripkit.lti._uncertainty",
           "gripkit.lti._frequency", "gripkit.lti._discretize", "gripkit.lti._kernels"]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples_run(name):
    res = doctest.testmod(importlib.import_module(name), optionflags=doctest.NORMALIZE_WHITESPACE)
    assert res.failed == 0 and res.attempted > 0


def _public_callables():
    for name in lti.__all__:
        obj = getattr(lti, name)
        yield name, obj
        if inspect.isclass(obj):
            for attr, member in vars(obj).items():
                if not attr.startswith("_") and (inspect.isfunction(member)
                                                 or isinstance(member,
                                                               (classmethod, staticmethod))):
                    yield f"{name}.{attr}", member


@pytest.mark.parametrize("name, obj", list(_public_callables()))
def test_every_public_callable_has_an_example(name, obj):
    fn = obj.__func__ if isinstance(obj, (classmethod, staticmethod)) else obj
    doc = inspect.getdoc(fn) or ""
    assert ">>>" in doc, f"{name} has no runnable example"
