"""Imports go at the top of the module (issue 12), except where a lazy import is what keeps
``import gripkit`` and the CLI fast (issue 14) or where the dependency is optional. Every import
made inside a function must be one of these, and each exception says why:

* an optional dependency, or a heavy one measured below (``LAZY_PACKAGES``);
* a CLI command module's imports: ``gripkit --help`` and each command load only what that
  command runs (``cli/``, docs/performance.md "Start-up");
* a gripkit module whose import compiles or loads numba kernels or a heavy package
  (``LAZY_MODULES``: importer → imported, with the reason).

The test reads the source with ``ast`` (nothing is imported) and names each other in-function
import: move it to the top of its module."""

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "gripkit"

#: third-party packages imported on first use; import times measured on the CI machine (2 cores,
#: numpy and scipy already loaded): scipy.signal 0.85 s, scipy.stats 0.70 s, scipy.optimize 0.30 s,
#: scipy.spatial 0.21 s, scipy.linalg.blas 0.13 s, matplotlib.pyplot 0.34 s, pint 0.23 s,
#: pyarrow 0.08 s, h5py 0.07 s, numba.cuda 0.06 s, rich.console/table/progress 0.03–0.04 s each,
#: jinja2 0.02 s (the HTML report only)
LAZY_PACKAGES = {
    "scipy.signal": "0.85 s", "scipy.stats": "0.70 s", "scipy.optimize": "0.30 s",
    "scipy.spatial": "0.21 s",
    "scipy.linalg.blas": "0.13 s", "matplotlib": "0.34 s", "pint": "0.23 s", "pyarrow": "0.08 s",
    "h5py": "0.07 s", "scipy.io": "0.13-0.41 s (the .mat reader only)",
    "scipy.linalg": "0.2 s: a small ARX fit (`gripkit identify arx`) needs none",
    "rich": "0.04 s per module", "jinja2": "the HTML report only",
    "numba": "numba.cuda, the GPU path only",
    # optional extras of pyproject.toml: absent unless installed
    "control": "extra 'interop'", "pinocchio": "extra 'pinocchio'", "distributed": "extra 'dask'",
    "mcap": "extra 'mcap'", "mcap_ros2": "extra 'mcap'",
}

#: gripkit modules imported on first use: (importer, imported) → why
LAZY_MODULES = {
    ("sysid/linear/arx.py", ".lagged_sums"): "numba kernels: a small ARX is solved by QR without "
                                             "loading numba (0.45 s)",
    ("sysid/identify.py", ".linear.rls"): "numba (0.4 s): `gripkit identify arx` does not load it",
    ("sysid/identify.py", ".nonlinear.narx_entry"):
        "numba kernels: a nonlinear family's module loads with its first fit",
    ("sysid/identify.py", ".nonlinear.hammerstein_wiener"): "as the line above",
    ("sysid/identify.py", ".nonlinear.hysteresis"): "as the line above",
    ("sysid/identify.py", ".nonlinear.nlss"): "as the line above",
    ("sysid/identify.py", ".physical.step_response"):
        "the grey-box engine's scipy.optimize (0.3 s), loaded by the first step fit",
    ("sysid/linear/identify_mimo.py", ".pem_ss"): "numba kernels: only state-space "
                                                  "identification loads them",
    ("sysid/linear/identify_mimo.py", ".subspace"): "numba kernels: only state-space "
                                                    "identification loads them",
    ("sysid/linear/identify_mimo.py", ".tfest"): "scipy.signal (0.85 s): only "
                                                 "transfer-function fits load it",
    ("systems/tsfm/robustness.py", "...report.plots"):
        "matplotlib (0.34 s): only the robustness plot loads it",
    ("lti/_system.py", "._kernels"): "numba simulation kernel: lti loads without numba",
    ("sysid/linear/linear_model.py", "...lti"): "lti's numba simulation kernel, loaded on the "
                                                "first simulation",
    ("systems/tsfm/grasp_batch.py", ".grasp_gpu"): "numba.cuda: the GPU path only",
    ("io/formats.py", ".mcap_reader"): "the optional mcap extra",
    ("sysid/model_file.py", "..io.formats"):
        "the readers (pyarrow, h5py, scipy.io): every CLI command imports model_file for its JSON",
    ("control/robustness.py", "..report.plots"): "matplotlib (0.34 s): only the histograms load it",
    ("export/c_rls.py", "..sysid.linear.rls"): "numba (0.4 s): the RLS kernels, for --rls only",
    ("estimation/state_functions.py", "..sim.model"): "a filter on a model reads its family "
                                                     "on first use",
    ("estimation/state_functions.py", "..sysid.nonlinear.hammerstein_wiener"):
        "numba kernels of the nonlinear families: `import gripkit.estimation` loads none",
    ("estimation/state_functions.py", "..sysid.nonlinear.hysteresis"): "as the line above",
    ("estimation/state_functions.py", "..sysid.nonlinear.narx"): "as the line above",
    ("estimation/state_functions.py", "..sysid.nonlinear.narx_rational"): "as the line above",
    ("sysid/nonlinear/narx_entry.py", ".narx_rational"): "the rational NARX's numba kernels "
                                                         "load for basis='rational' only",
    ("estimation/state_functions.py", "..sysid.nonlinear.nlss"): "as the line above",
    ("estimation/state_functions.py", "..models.hysteresis"): "numba kernels of the grey-box "
                                                               "models, for their filters only",
    ("estimation/state_functions.py", "..models.mass_spring_damper"): "as the line above",
    ("estimation/state_functions.py", "..models.piezo"): "as the line above",
    ("estimation/state_functions.py", "..sim.integrators"): "as the line above",
    ("estimation/state_functions.py", "..sysid.nonlinear.hw_kernels"): "numba kernels of the "
                                                                         "nonlinear families",
    ("estimation/state_functions.py", "..sysid.nonlinear.hysteresis_kernels"): "as the line above",
    ("estimation/state_functions.py", "..sysid.nonlinear.nlss_kernels"): "as the line above",
}


def _in_function_imports():
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC).as_posix()
        for fn in ast.walk(ast.parse(path.read_text())):
            if not isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            for node in ast.walk(fn):
                if isinstance(node, ast.ImportFrom):
                    module = "." * node.level + (node.module or "")
                    if module == "scipy":  # `from scipy import signal`: the submodule is what loads
                        for a in node.names:
                            yield rel, node.lineno, f"scipy.{a.name}"
                    else:
                        yield rel, node.lineno, module
                elif isinstance(node, ast.Import):
                    for a in node.names:
                        yield rel, node.lineno, a.name


def _allowed(rel: str, module: str) -> bool:
    if rel.startswith("cli/"):
        return True
    if module.startswith("."):
        return (rel, module) in LAZY_MODULES
    parts = module.split(".")
    return any(".".join(parts[:k]) in LAZY_PACKAGES for k in range(1, len(parts) + 1))


def test_imports_inside_functions_have_a_reason():
    found = [f"{rel}:{line} imports {module}" for rel, line, module in _in_function_imports()
             if not _allowed(rel, module)]
    assert found == [], \
        "move to the top of the module (or give the reason here):\n" + "\n".join(found)


def test_every_exception_is_still_used():
    used = {(rel, module) for rel, _, module in _in_function_imports()}
    assert [k for k in LAZY_MODULES if k not in used] == []
