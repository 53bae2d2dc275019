"""One re-export style (issue 23, habits): every package of gripkit declares ``__all__``, lists in
it exactly the names it re-exports (``from .m import x as x``, or its lazy table ``_LAZY``, see
:mod:`gripkit.exports`) and the functions and classes it defines, and every listed name resolves.
Read with ``ast``; the packages are imported only to resolve the names."""

import ast
import importlib
import importlib.util
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "gripkit"
PACKAGES = sorted(p.parent for p in SRC.rglob("__init__.py"))


def _package(path: Path) -> str:
    return ".".join(("gripkit",) + path.relative_to(SRC).parts)


def declared_and_exported(init: Path) -> tuple[list | None, set]:
    """(``__all__`` as written or None, the names the package re-exports or defines)."""
    tree = ast.parse(init.read_text())
    declared, exported = None, set()
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id",
                                                        None) == "__all__" for t in node.targets):
            declared = ([ast.literal_eval(e) for e in node.value.elts
                         if not isinstance(e, ast.Starred)])
            if any(isinstance(e, ast.Starred) for e in node.value.elts):  # __all__ = [*_LAZY, ...]
                lazy = next(n for n in tree.body if isinstance(n, ast.Assign)
                            and any(getattr(t, "id", None) == "_LAZY" for t in n.targets))
                declared += [ast.literal_eval(k) for k in lazy.value.keys]
        elif isinstance(node, ast.ImportFrom) and node.level:
            exported |= {a.asname for a in node.names if a.asname and not a.asname.startswith("_")}
        elif isinstance(node, (ast.FunctionDef, ast.ClassDef)) and not node.name.startswith("_"):
            exported.add(node.name)
        elif isinstance(node, ast.Assign) and any(getattr(t, "id",
                                                          None) == "_LAZY" for t in node.targets):
            exported |= {ast.literal_eval(k) for k in node.value.keys}
    return declared, exported


@pytest.mark.parametrize("pkg", PACKAGES, ids=lambda p: _package(p))
def test_every_package_declares_what_it_exports(pkg):
    declared, exported = declared_and_exported(pkg / "__init__.py")
    assert declared is not None, f"{_package(pkg)} has no __all__"
    assert len(declared) == len(set(declared)), f"{_package(pkg)}: a name twice in __all__"
    missing = exported - set(declared)
    assert not missing, \
        f"{_package(pkg)} re-exports {sorted(missing)} without listing them in __all__"
    module = importlib.import_module(_package(pkg))
    unresolved = [n for n in declared if not hasattr(module, n)  # or a subpackage (gripkit.systems)
                  and importlib.util.find_spec(f"{module.__name__}.{n}") is None]
    assert not unresolved, f"{_package(pkg)}.__all__ lists names that do not resolve: {unresolved}"


def test_the_check_finds_an_unlisted_export(tmp_path):
    init = tmp_path / "__init__.py"
    init.write_text("from .a import f as f\nfrom .b import g as g\n\n__all__ = ['f']\n")
    declared, exported = declared_and_exported(init)
    assert exported - set(declared) == {"g"}
    init.write_text("from .a import f as f\n")
    assert declared_and_exported(init)[0] is None


def test_every_model_component_is_exported():
    """``gripkit.models`` exports each module's components (issue 23: it exported 3 of 9)."""
    import gripkit.models as models

    for mod in sorted((SRC / "models").glob("[!_]*.py")):
        assert any(getattr(getattr(models, n), "__module__", "") == f"gripkit.models.{mod.stem}"
                   for n in models.__all__), f"nothing of gripkit.models.{mod.stem} is exported"
