"""No unused public names (issue 23, habits): scripts/unused_names.py finds no public name in
src/gripkit that nothing uses, and on a small made-up tree it reports exactly the names that
nothing uses (so the check can fail). Files are read, nothing is imported."""

import importlib.util
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "scripts" / "unused_names.py"


def _script():
    spec = importlib.util.spec_from_file_location("unused_names", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_src_has_no_unused_public_names():
    assert _script().unused_names(ROOT) == []


def _write(root: Path, files: dict) -> None:
    for rel, text in files.items():
        p = root / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)


def test_the_script_reports_what_nothing_uses(tmp_path):
    """Reported: a function only re-exported by an ``__init__`` without listing it in __all__, a
    constant named only in its module's __all__, a method of a class no package exports.
    A class under a wrapping decorator (``@dataclass(...)``) is reported too.
    Not reported: names in a package's __all__ (with their class's methods), names used in
    tests or docs, private names, a function registered by a decorator (``@app.command()``,
    ``@register("x")``), names in _LAZY."""
    _write(tmp_path, {
        "src/gripkit/__init__.py": '__all__ = ["Public"]\n',
        "src/gripkit/pkg/__init__.py": (
            'from .mod import dead as dead\nfrom .mod import Public as Public\n'
            '_LAZY = {"lazy": ("mod", "lazy")}\n__all__ = [*_LAZY, "exported"]\n'),
        "src/gripkit/pkg/mod.py": (
            '__all__ = ["dead", "LIMIT", "exported"]\n'
            'LIMIT = 3\n\n'
            'def dead(x):\n    return _private(x)\n\n'
            'def _private(x):\n    return x\n\n'
            'def exported():\n    pass\n\n'
            'def lazy():\n    pass\n\n'
            'def in_tests():\n    pass\n\n'
            'def in_docs():\n    pass\n\n'
            '@app.command()\ndef cli_command():\n    pass\n\n'
            '@register("x")\ndef registered():\n    pass\n\n'
            '@dataclass(frozen=True)\nclass Frozen:\n    pass\n\n'
            'class Public:\n    def method(self):\n        pass\n\n'
            'class Hidden:\n    def unused_method(self):\n        pass\n\n'
            '    def used_method(self):\n        pass\n\n'
            'Hidden().used_method()\n'),
        "tests/test_mod.py": "from gripkit.pkg.mod import in_tests\n",
        "docs/guide.md": "Call `in_docs()`.\n",
    })
    found = _script().unused_names(tmp_path)
    assert [(Path(p).name, n) for p, _, n in found] == [
        ("mod.py", "LIMIT"), ("mod.py", "dead"), ("mod.py", "Frozen"),
        ("mod.py", "Hidden.unused_method")]
    run = subprocess.run([sys.executable, str(SCRIPT), str(tmp_path)], capture_output=True,
                         text=True)
    assert run.returncode == 1 and "mod.py:2 LIMIT" in run.stdout
