"""No function in src/gripkit is longer than 100 lines (issue 12, "Inside the rooms": a long
function is split into named steps, one concept each, with a docstring; docs/DEVELOPING.md), and
no compiled kernel takes more than KERNEL_ARGUMENTS arguments (they take named records instead:
docs/ARCHITECTURE.md, "Kernels take named records").

A function's length is ``end_lineno − lineno + 1`` of its ``def`` as ``ast`` reports it: the
signature, the docstring and the body, not the decorators. Every function counts: module
functions, methods and nested functions, each named by its qualified name (``Class.method``,
``outer.inner``). Read from the source with ``ast``; nothing is imported."""

import ast
import textwrap
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "gripkit"
LIMIT = 100
#: the most arguments a compiled kernel takes (rnea_pass: sizes, the chain record, link
#: transforms, rates, gravity's three components, a flag, the torques and its scratch); the DLR/HIT
#: ``_forces`` took 46, the batched multibody simulation 41, the TSFM CUDA kernel 38 before they
#: took records, coupled_mass_bias 21 and the regressor 20 before the chain record reached them
KERNEL_ARGUMENTS = 12

#: Scalar numba kernels whose split would cost speed: (path under src/gripkit, name) → the
#: measurement that says so. None is left: systems/amadeus/pvdf.py ``contact_step`` (119 lines)
#: was split into per-substep helpers that numba's LLVM inlines (min of 40 runs of 2000 samples ×
#: 20 substeps: 2216 → 2221 µs for the grasp, 2063 → 2058 µs for the testbed); the TSFM
#: ``_grasp_core``, the DLR/HIT finger's ``_forces`` and ``multibody/kernels.py rnea_pass`` (its
#: outward step shared with the regressor) into pieces inlined at numba IR level
#: (docs/performance.md, "Named records in kernels"); outputs bit-identical. An entry here must be
#: a numba kernel, and its reason must give the measured slowdown of the split.
NUMBA_KERNELS: dict[tuple[str, str], str] = {}


def function_lengths(source: str) -> dict[str, tuple[int, int, ast.AST]]:
    """``{qualified name: (length, first line, node)}`` of every function in ``source``."""
    found = {}

    def visit(node, prefix):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                name = prefix + child.name
                found[name] = (child.end_lineno - child.lineno + 1, child.lineno, child)
                visit(child, name + ".")
            elif isinstance(child, ast.ClassDef):
                visit(child, prefix + child.name + ".")
            else:
                visit(child, prefix)

    visit(ast.parse(source), "")
    return found


def _numba_decorators(tree: ast.Module) -> set[str]:
    """Names bound at module level to a numba decorator (``hot = numba.njit(...)``)."""
    return {t.id for node in tree.body if isinstance(node, ast.Assign)
            and "jit" in ast.unparse(node.value)
            for t in node.targets if isinstance(t, ast.Name)}


def is_numba_kernel(node, aliases: set[str]) -> bool:
    return any("jit" in ast.unparse(d) or ast.unparse(d) in aliases for d in node.decorator_list)


def _all_lengths():
    """Every function's (length, first line, is a numba kernel, number of arguments). A decorator
    alias defined in one module (``hot`` in multibody/kernels.py) marks kernels in every module
    that imports it."""
    out = {}
    paths = sorted(SRC.rglob("*.py"))
    shared = set().union(*(_numba_decorators(ast.parse(p.read_text())) for p in paths))
    for path in paths:
        source = path.read_text()
        aliases = shared | _numba_decorators(ast.parse(source))
        rel = path.relative_to(SRC).as_posix()
        for name, (length, line, node) in function_lengths(source).items():
            out[(rel, name)] = (length, line, is_numba_kernel(node, aliases), _n_arguments(node))
    return out


def _n_arguments(node) -> int:
    a = node.args
    return len(a.posonlyargs) + len(a.args) + len(a.kwonlyargs)


LENGTHS = _all_lengths()


def test_no_function_is_longer_than_100_lines():
    allowed = set(NUMBA_KERNELS)
    too_long = sorted((length, f"src/gripkit/{rel}:{line} {name}")
                      for (rel, name), (length, line, _, _) in LENGTHS.items()
                      if length > LIMIT and (rel, name) not in allowed)
    assert not too_long, (
        f"{len(too_long)} function(s) longer than {LIMIT} lines: "
        + "; ".join(f"{where} ({length} lines)" for length, where in too_long[::-1])
        + ". Split each into named steps with docstrings (docs/DEVELOPING.md); a scalar "
          "numba kernel whose "
          "split measurably costs speed goes into NUMBA_KERNELS with that measurement.")


def test_no_compiled_kernel_takes_more_than_12_arguments():
    crowded = sorted((n, f"src/gripkit/{rel}:{line} {name}")
                     for (rel, name), (_, line, kernel, n) in LENGTHS.items() if kernel
                     and n > KERNEL_ARGUMENTS)
    assert not crowded, (
        f"{len(crowded)} compiled kernel(s) with more than {KERNEL_ARGUMENTS} arguments: "
        + "; ".join(f"{where} ({n})" for n, where in crowded[::-1])
        + ". Group the arrays into named records (namedtuples), as docs/ARCHITECTURE.md describes.")


def test_allow_list_entries_are_still_needed():
    """Every allowed function exists and is still too long (else its entry must go), and every
    entry is a numba kernel with a reason."""
    stale = [f"{rel} {name}: " + ("no such function" if (rel, name) not in LENGTHS else
                                  f"{LENGTHS[(rel, name)][0]} lines, within the limit")
             for rel, name in sorted(NUMBA_KERNELS)
             if (rel, name) not in LENGTHS or LENGTHS[(rel, name)][0] <= LIMIT]
    assert not stale, \
        "remove from the allow-list of tests/test_function_length.py: " + "; ".join(stale)
    for (rel, name), reason in NUMBA_KERNELS.items():
        assert LENGTHS[(rel, name)][2], \
            f"{rel} {name} is in NUMBA_KERNELS but is not a numba kernel"
        assert reason.strip(), f"{rel} {name}: give the measured slowdown of a split"


def test_the_measure():
    """Lengths on a made-up module: a 101-line function is over the limit, a 100-line one is not;
    decorators do not count, the docstring does; methods and nested functions are found under
    their qualified names; a numba kernel is recognised through a decorator alias."""
    body = "\n".join(f"    x{i} = {i}" for i in range(98))
    source = textwrap.dedent('''\
        import numba
        hot = numba.njit(cache=True)


        @hot
        def long_kernel():
            """Doc."""
        {body}
            return x0


        class Model:
            @staticmethod
            def method():
                def inner():
                    return 1
                return inner
        ''').replace("{body}", body)
    lengths = function_lengths(source)
    assert lengths["long_kernel"][0] == 101 and lengths["long_kernel"][1] == 6
    assert lengths["Model.method"][0] == 4 and lengths["Model.method.inner"][0] == 2
    tree = ast.parse(source)
    assert is_numba_kernel(lengths["long_kernel"][2], _numba_decorators(tree))
    assert not is_numba_kernel(lengths["Model.method"][2], _numba_decorators(tree))
    shorter = source.replace("    x97 = 97\n", "")
    assert function_lengths(shorter)["long_kernel"][0] == LIMIT
    assert _n_arguments(ast.parse("def f(a, /, b, *args, c, **kw): pass").body[0]) == 3


def test_kernels_decorated_through_an_imported_alias_are_counted():
    """``@hot`` imported from multibody/kernels.py marks a kernel in another module too: the
    regressor's kernels (decorated that way) are checked against KERNEL_ARGUMENTS, and so is a
    made-up kernel with 13 arguments."""
    assert LENGTHS[("multibody/regressor.py", "regressor_state")][2]
    assert LENGTHS[("multibody/kernels.py", "rnea_pass")][2]
    assert LENGTHS[("systems/dlr_hit/finger.py", "finger_loop")][2]
    assert not LENGTHS[("multibody/regressor.py", "regressor")][2]
    node = ast.parse("@hot\ndef k(a, b, c, d, e, f, g, h, i, j, k, l, m): pass").body[0]
    assert is_numba_kernel(node, {"hot"}) and _n_arguments(node) == KERNEL_ARGUMENTS + 1
