"""Lazy re-exports of a package's public names (PEP 562), so that importing a package does not
import every module below it, nor their third-party dependencies (scipy.signal, numba, ...).

A package lists its names in a table, ``{public name: (module of the package, name there)}``, and
installs the module-level ``__getattr__`` and ``__dir__`` made here::

    _LAZY = {"arx": ("arx", "arx"), ...}
    __getattr__, __dir__ = lazy_exports(__name__, _LAZY)

A name of the table that is also a submodule's name (``gripkit.sysid.linear.arx``, the function, in
the module ``gripkit/sysid/arx.py``) stays the public object: the import system's binding of the
submodule to the package, on its first import, is not kept.
"""

from __future__ import annotations

import importlib
import sys
import types


class _LazyPackage(types.ModuleType):
    _lazy_table: dict[str, tuple[str, str]]

    def __setattr__(self, name: str, value) -> None:
        if (isinstance(value, types.ModuleType) and name in self._lazy_table
                and value.__name__ == f"{self.__name__}.{name}"):
            # the import system binding a submodule over the public name of the same spelling
            return
        super().__setattr__(name, value)


def lazy_exports(package: str, table: dict[str, tuple[str, str]]):
    """The ``__getattr__`` and ``__dir__`` of ``package`` that load each name of ``table`` on first
    use."""
    module = sys.modules[package]

    def __getattr__(name: str):
        try:
            where, attr = table[name]
        except KeyError:
            raise AttributeError(f"module {package!r} has no attribute {name!r}") from None
        value = getattr(importlib.import_module(f".{where}", package), attr)
        module.__dict__[name] = value  # later lookups skip __getattr__
        return value

    def __dir__() -> list[str]:
        return sorted(set(module.__dict__) | set(table))

    module._lazy_table = table
    module.__class__ = _LazyPackage
    return __getattr__, __dir__
