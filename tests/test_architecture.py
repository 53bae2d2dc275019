"""The import rules of docs/ARCHITECTURE.md, read from the source with ``ast`` (nothing is
imported):
no circles between modules, generic layers never import a reference system (nor the TOML front
end, the demo or the CLI), a system never imports another one, the zoo imports no system,
``signals`` never imports ``io``, ``atomic`` imports only ``errors``, no module imports another
package's private names.

Every import counts, also the ones made inside functions."""

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "gripkit"

#: the generic layers (a package or a top-level module of gripkit)
GENERIC = ("errors", "atomic", "progress", "arguments", "units", "params", "consistency", "signals",
           "io", "excitation", "report", "lti", "sim", "multibody", "models", "sysid", "estimation",
           "control", "batch", "export")
#: what sits above the systems: the TOML front end, the demo, the CLI
ABOVE_SYSTEMS = ("description", "demos", "cli")
SYSTEMS = ("amadeus", "tsfm", "dlr_hit", "ftg100")


def _module(path: Path) -> str:
    parts = ("gripkit",) + path.relative_to(SRC).with_suffix("").parts
    return ".".join(parts[:-1]) if parts[-1] == "__init__" else ".".join(parts)


def _imports():
    """(importer, imported module, names, line) for every gripkit-internal import."""
    modules = {_module(p): p for p in SRC.rglob("*.py")}
    out = []
    for mod, path in modules.items():
        is_pkg = path.name == "__init__.py"
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    base = mod.split(".") if is_pkg else mod.split(".")[:-1]
                    base = base[:len(base) - (node.level - 1)]
                    target = ".".join(base + ([node.module] if node.module else []))
                else:
                    target = node.module or ""
                if not target.startswith("gripkit"):
                    continue
                plain = []
                for a in node.names:
                    if f"{target}.{a.name}" in modules:  # a submodule
                        out.append((mod, f"{target}.{a.name}", (), node.lineno))
                    else:
                        plain.append(a.name)
                if plain:
                    out.append((mod, target, tuple(plain), node.lineno))
            elif isinstance(node, ast.Import):
                out.extend((mod, a.name, (), node.lineno) for a in node.names
                           if a.name.startswith("gripkit"))
    return modules, out


MODULES, IMPORTS = _imports()


def _layer(mod: str) -> str:
    parts = mod.split(".")
    return parts[1] if len(parts) > 1 else ""


def _system(mod: str) -> str | None:
    parts = mod.split(".")
    return parts[2] if len(parts) > 2 and parts[1] == "systems" else None


def test_the_import_graph_has_no_circles():
    """Tarjan's strongly connected components of the module graph: each must be a single module."""
    graph = {m: set() for m in MODULES}
    for a, b, _, _ in IMPORTS:
        while b not in MODULES and "." in b:  # ``from pkg.mod import name`` where mod is a module
            b = b.rsplit(".", 1)[0]
        if b in MODULES and b != a:
            graph[a].add(b)
    index, low, stack, on, circles = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            # a package face importing its own modules is no circle of code
            if len(comp) > 1 and not all(m == comp[0] or m.startswith(comp[0] + ".") for m in comp):
                circles.append(sorted(comp))

    for v in graph:
        if v not in index:
            visit(v)
    assert circles == []


@pytest.mark.parametrize("rule", ["generic layers name no system", "systems stay apart",
                                  "systems sit below description, demos and cli",
                                  "the zoo names its "
                                  "factories by string", "signals never imports io",
                                  "atomic writes import only errors"])
def test_layering(rule):
    bad = []
    for a, b, names, line in IMPORTS:
        la, lb = _layer(a), _layer(b)
        if (rule == "generic layers name no system" and la in GENERIC
                and lb in ("systems", *ABOVE_SYSTEMS)):
            bad.append((a, b, line))
        elif (rule == "systems stay apart" and _system(a) and _system(b)
              and _system(a) != _system(b)):
            bad.append((a, b, line))
        elif (rule == "systems sit below description, demos and cli" and la == "systems"
              and lb in ABOVE_SYSTEMS):
            bad.append((a, b, line))
        elif (rule == "the zoo names its factories by string" and la == "zoo"
              and lb not in ("zoo", *GENERIC)):
            bad.append((a, b, line))
        elif rule == "signals never imports io" and la == "signals" and lb == "io":
            bad.append((a, b, line))
        elif rule == "atomic writes import only errors" and la == "atomic" and lb != "errors":
            bad.append((a, b, line))
    assert bad == []


def test_no_module_imports_another_packages_private_names():
    bad = []
    for a, b, names, line in IMPORTS:
        pkg_a = a if MODULES[a].name == "__init__.py" else a.rsplit(".", 1)[0]
        pkg_b = b if b in MODULES and MODULES[b].name == "__init__.py" else b.rsplit(".", 1)[0]
        private = [n for n in names if n.startswith("_") and not n.startswith("__")]
        private_module = any(p.startswith("_") and not p.startswith("__") for p in b.split("."))
        if pkg_a != pkg_b and (private or private_module):
            bad.append((a, b, names, line))
    assert bad == []


def test_the_rules_catch_what_they_forbid():
    """The checks above are not vacuous: the graph holds the imports they judge."""
    layers = {(_layer(a), _layer(b)) for a, b, _, _ in IMPORTS}
    assert ("systems", "sim") in layers and ("systems",
                                             "batch") in layers and ("batch", "zoo") in layers
    assert ("cli", "description") in layers and ("demos", "systems") in layers
    assert ("atomic", "errors") in layers and ("report", "atomic") in layers
