"""List the public names defined in src/gripkit that nothing uses (issue 23, "Habits").

A *public name* is a module-level function, class or assigned name without a leading
underscore, or such a method of a public class. It is *used* when its word occurs anywhere in
the project's source and text files (src, tests, docs, examples, benchmarks, scripts,
README.md, pyproject.toml, Makefile) outside the statement that defines it, outside ``__all__``
lists and outside the re-exports of package ``__init__`` files (their imports and lazy tables:
a re-export is not a use). It is *documented public API*, and so never reported, when a package
``__init__`` of its module lists it in ``__all__`` (a method: when it lists the method's class).
Functions with a decorator that registers them (``@app.command()``, ``@record_command("hw")``
and the like: a decorator called with arguments, other than numba's and the standard library's
wrappers) are used by that registration.

The search is by words in text, so a name quoted in a string, a docstring or a document counts
as used: the list errs towards keeping a name. Nothing is imported; files are read with ``ast``.

Usage: ``python scripts/unused_names.py [ROOT]`` prints ``path:line name`` for each unused name
and exits 1 when there is any (ROOT: the repository, default the parent of this script's folder).
"""

from __future__ import annotations

import ast
import re
import sys
from collections import Counter
from pathlib import Path

#: folders and files whose words count as uses
PLACES = ("src", "tests", "docs", "examples", "benchmarks", "scripts")
FILES = ("README.md", "pyproject.toml", "Makefile")
SUFFIXES = {".py", ".md", ".rst", ".txt", ".toml", ".json", ".cfg", ".ini", ".yaml", ".yml"}
#: decorators that wrap a function without registering it anywhere
WRAPPERS = {"njit", "jit", "hot", "vectorize", "guvectorize", "cfunc", "stencil", "dataclass",
            "staticmethod", "classmethod", "property", "contextmanager", "cache", "lru_cache",
            "wraps", "overload", "register_jitable", "generated_jit", "jitclass"}

WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def _text_files(root: Path):
    for place in PLACES:
        base = root / place
        if base.is_dir():
            for p in sorted(base.rglob("*")):
                if p.is_file() and p.suffix in SUFFIXES and "__pycache__" not in p.parts:
                    yield p
    for name in FILES:
        if (root / name).is_file():
            yield root / name


def _decorator_name(d: ast.expr) -> str:
    f = d.func if isinstance(d, ast.Call) else d
    return f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", "")


def _registers(node) -> bool:
    """A decorator like ``@app.command()`` or ``@record_command("hw")``: called, not a known
    wrapper."""
    return any(isinstance(d, ast.Call) and _decorator_name(d) not in WRAPPERS
               for d in node.decorator_list)


def _targets(node) -> list[str]:
    out = []
    targets = node.targets if isinstance(node, ast.Assign) else [node.target]
    for t in targets:
        for n in ast.walk(t):
            if isinstance(n, ast.Name):
                out.append(n.id)
    return out


def definitions(tree: ast.Module) -> list[tuple[str, ast.stmt]]:
    """(name, statement) of the public module-level names a module defines."""
    out = []
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            if not _registers(node):
                out.append((node.name, node))
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            out.extend((n, node) for n in _targets(node))
    return [(n, s) for n, s in out if not n.startswith("_")]


def methods(tree: ast.Module) -> list[tuple[str, str, ast.stmt]]:
    """(class, method, statement) of the public methods of the module's public classes."""
    return [(c.name, m.name, m) for c in tree.body
            if isinstance(c, ast.ClassDef) and not c.name.startswith("_")
            for m in c.body if isinstance(m, (ast.FunctionDef, ast.AsyncFunctionDef))
            and not m.name.startswith("_") and not _registers(m)]


def _assigns(node, name: str) -> bool:
    if isinstance(node, ast.AugAssign):
        return isinstance(node.target, ast.Name) and node.target.id == name
    return isinstance(node, (ast.Assign, ast.AnnAssign)) and name in _targets(node)


def _all_names(tree: ast.Module) -> set[str]:
    """The names ``__all__`` lists, ``*_LAZY`` (the lazy table of :mod:`gripkit.exports`)
    resolved to the table's keys."""
    lazy = {c.value for node in tree.body
            if _assigns(node, "_LAZY") and isinstance(node.value, ast.Dict)
            for c in node.value.keys if isinstance(c, ast.Constant)}
    names: set[str] = set()
    for node in tree.body:
        if _assigns(node, "__all__"):
            for c in ast.walk(node.value):
                if isinstance(c, ast.Constant) and isinstance(c.value, str):
                    names.add(c.value)
                elif isinstance(c, ast.Starred) and getattr(c.value, "id", "") == "_LAZY":
                    names |= lazy
    return names


def _masked_lines(tree: ast.Module, is_package: bool) -> set[int]:
    """Lines whose words are not uses: ``__all__`` lists and, in a package ``__init__``, its
    re-exports (imports, also under ``if TYPE_CHECKING:``, and the lazy table ``_LAZY``)."""
    lines: set[int] = set()
    nodes = [n for n in tree.body if _assigns(n, "__all__")]
    if is_package:
        nodes += [n for n in tree.body if _assigns(n, "_LAZY")]
        nodes += [n for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)]
    for node in nodes:
        lines.update(range(node.lineno, node.end_lineno + 1))
    return lines


def _def_lines(name: str, node: ast.stmt) -> set[int]:
    """The lines of the defining statement that carry ``name`` itself (its ``def``/``class``
    line, or the assignment's target lines)."""
    if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
        return {node.lineno}
    targets = node.targets if isinstance(node, ast.Assign) else [node.target]
    return {n.lineno for t in targets for n in ast.walk(t)
            if isinstance(n, ast.Name) and n.id == name}


def unused_names(root: Path) -> list[tuple[str, int, str]]:
    """``[(path relative to root, line, name)]`` of the public names that nothing uses."""
    root = Path(root)
    src = root / "src" / "gripkit"
    trees = {p: ast.parse(p.read_text(encoding="utf-8")) for p in sorted(src.rglob("*.py"))}
    exported: dict[Path, set[str]] = {p.parent: _all_names(t) for p, t in trees.items()
                                      if p.name == "__init__.py"}
    counts: Counter = Counter()
    for f in _text_files(root):
        text = f.read_text(encoding="utf-8", errors="replace")
        tree = trees.get(f)
        masked = _masked_lines(tree, f.name == "__init__.py") if tree is not None else set()
        if masked:
            text = "\n".join(line for i, line in enumerate(text.splitlines(), 1) if i not in masked)
        counts.update(WORD.findall(text))
    out = []
    for p, tree in trees.items():
        public = {d for folder, names in exported.items() if folder in p.parents for d in names}
        seen: set[str] = set()
        lines = p.read_text(encoding="utf-8").splitlines()
        for name, node in definitions(tree):
            if name in seen or name in public:
                continue
            seen.add(name)
            own = sum(len(re.findall(rf"\b{re.escape(name)}\b", lines[i - 1]))
                      for i in _def_lines(name, node))
            if counts[name] <= own:
                out.append((str(p.relative_to(root)), node.lineno, name))
        for cls, name, node in methods(tree):
            if cls not in public and counts[name] <= 1:  # only its own ``def`` line
                out.append((str(p.relative_to(root)), node.lineno, f"{cls}.{name}"))
    return out


def main(argv: list[str]) -> int:
    root = Path(argv[1]) if len(argv) > 1 else Path(__file__).resolve().parents[1]
    found = unused_names(root)
    for path, line, name in found:
        print(f"{path}:{line} {name}")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
