"""One name for the sample interval (issue 12, "One name per thing"): inside gripkit it is ``dt``
in seconds; a sampling rate ``fs`` in Hz appears only at the boundaries, where it is converted
once: the file readers (``gripkit.io``: ``load(..., fs=)``) and the command line (``--fs``).
No function parameter and no property elsewhere is named ``fs``, and nothing (parameter,
property or dataclass field) anywhere is named ``ts``, the old spelling of the interval (issue 23:
``PID(dt=)``).

One exception, another quantity: :mod:`gripkit.models.friction`'s ``fs`` is the friction
literature's F_s, the static friction level of the Stribeck and LuGre models (N·m; the DLR/HIT
tables' ``fs_base1`` …, Appendix F of ``002_ddea254371185ad3.txt``), not a rate. Read from the
source with ``ast``; nothing is imported."""

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "gripkit"
BOUNDARIES = ("io/", "cli/")
#: modules where ``fs`` names another quantity (the module docstring says which)
OTHER_QUANTITY = ("models/friction.py",)


def _named_fs():
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC).as_posix()
        if rel.startswith(BOUNDARIES) or rel in OTHER_QUANTITY:
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            a = node.args
            params = [p.arg for p in a.posonlyargs + a.args + a.kwonlyargs]
            if "fs" in params:
                yield f"{rel}:{node.lineno} {node.name}() takes a parameter fs"
            if node.name == "fs" and any(getattr(d, "id",
                                                 None) == "property" for d in node.decorator_list):
                yield f"{rel}:{node.lineno} property fs"


def _named_ts():
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC).as_posix()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                a = node.args
                if "ts" in [p.arg for p in a.posonlyargs + a.args + a.kwonlyargs]:
                    yield f"{rel}:{node.lineno} {node.name}() takes a parameter ts"
            if isinstance(node, ast.ClassDef):
                for item in node.body:
                    if isinstance(item, ast.AnnAssign) and getattr(item.target, "id", None) == "ts":
                        yield f"{rel}:{item.lineno} {node.name}.ts field"
                    if isinstance(item, ast.Assign) and any(getattr(t, "id", None) == "ts"
                                                            for t in item.targets):
                        yield f"{rel}:{item.lineno} {node.name}.ts attribute"


def test_no_parameter_or_property_is_named_fs_inside():
    assert list(_named_fs()) == []


def test_no_parameter_field_or_property_is_named_ts():
    assert list(_named_ts()) == []


def test_the_ts_check_finds_what_it_forbids(tmp_path, monkeypatch):
    (tmp_path / "control").mkdir()
    (tmp_path / "control" / "c.py").write_text("class P:\n    ts: float = 1.0\n    ts = "
                                               "property(lambda s: 1)\n\n\n"
                                                "def f(u, *, ts):\n    pass\n")
    monkeypatch.setattr(__import__(__name__), "SRC", tmp_path)
    assert [x.split(" ", 1)[1] for x in _named_ts()] == ["P.ts field", "P.ts attribute",
                                                         "f() takes a parameter ts"]


def test_the_check_finds_what_it_forbids(tmp_path, monkeypatch):
    (tmp_path / "sysid").mkdir()
    (tmp_path / "sysid" / "m.py").write_text("def f(u, fs):\n    pass\n\n\nclass "
                                             "C:\n    @property\n"
                                             "    def fs(self):\n        return 1.0\n")
    (tmp_path / "io").mkdir()
    (tmp_path / "io" / "r.py").write_text("def load(path, fs=None):\n    pass\n")
    monkeypatch.setattr(__import__(__name__), "SRC", tmp_path)
    assert [x.split(" ", 1)[1] for x in _named_fs()] == ["f() takes a parameter fs", "property fs"]
