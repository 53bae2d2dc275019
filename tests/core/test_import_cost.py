"""Start-up structure (issue 14): ``import gripkit`` leaves the heavy third-party packages unloaded,
and the lazy re-exports of the packages (:mod:`gripkit.exports`) give the same objects as eager
imports.
Structural checks in a fresh interpreter, not timings."""

import json
import subprocess
import sys

import pytest

HEAVY = ("scipy.signal", "scipy.stats", "scipy.optimize", "matplotlib", "pyarrow", "pint", "h5py",
         "numba")


def _loaded_after(code: str) -> list[str]:
    probe = f"import json, sys\n{code}\nprint(json.dumps(sorted(sys.modules)))"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_import_gripkit_does_not_import_heavy_packages():
    loaded = set(_loaded_after("import gripkit"))
    assert [m for m in HEAVY if m in loaded] == []


@pytest.mark.parametrize("package", ["gripkit.signals", "gripkit.sysid"])
def test_lazy_package_import_does_not_import_heavy_packages(package):
    loaded = set(_loaded_after(f"import {package}"))
    assert [m for m in HEAVY if m in loaded] == []


def test_lazy_names_are_the_defining_modules_objects_and_listed():
    import gripkit.signals
    import gripkit.sysid
    # a submodule spelled like a public function: the function stays public
    import gripkit.sysid.linear.arx
    import gripkit.sysid.linear.rls
    from gripkit.signals.filters import lowpass
    from gripkit.sysid import arx, rls
    from gripkit.sysid.linear.arx import arx as arx_defined
    from gripkit.sysid.linear.rls import rls as rls_defined

    assert arx is arx_defined and rls is rls_defined and gripkit.sysid.arx is arx_defined
    assert gripkit.signals.lowpass is lowpass
    for pkg in (gripkit.signals, gripkit.sysid):
        assert set(pkg.__all__) <= set(dir(pkg))
        for name in pkg.__all__:
            assert getattr(pkg, name) is not None
    with pytest.raises(AttributeError, match="no_such_name"):
        gripkit.sysid.no_such_name  # noqa: B018


def test_small_arx_from_a_csv_file_stays_light(tmp_path):
    """The path of `gripkit identify arx` on a small log (read the CSV, fit ARX by QR, one-step
    residuals by np.convolve) needs neither pandas (pyarrow's to_numpy imports it), nor numba, nor
    scipy.signal/scipy.stats: together 1.2 s of a 1.7 s fresh process before this was checked."""
    import numpy as np

    rng = np.random.default_rng(1)
    u = rng.standard_normal(500)
    y = np.convolve(u, [0.0, 0.5, 0.25])[:500]
    path = tmp_path / "log.csv"
    np.savetxt(path, np.column_stack([np.arange(500) * 1e-3, u, y]), delimiter=",",
               header="time,u,y", comments="")
    loaded = set(_loaded_after(f"from gripkit.io import load\nfrom gripkit.sysid import arx\n"
                               f"d = load({str(path)!r})\nm = arx(d['u'], d['y'], "
                               "1, 2, 1, dt=d.dt)"))
    assert [m for m in ("pandas", "numba", "scipy.signal", "scipy.stats") if m in loaded] == []


def test_lti_simulate_ss_loads_on_first_use():
    loaded = set(_loaded_after("import gripkit.lti"))
    assert "numba" not in loaded
    loaded = set(_loaded_after("from gripkit.lti import simulate_ss"))
    assert "numba" in loaded


def test_cli_identify_arx_with_unit_headers_leaves_scipy_linalg_out(tmp_path):
    """`gripkit identify arx` on a small log with the README's unit headers (`force [N]`), in a
    fresh interpreter: the QR route, its triangular solves and the report need no scipy.linalg
    (~0.2 s of the start-up, issue 24), nor pint/dask for the units, nor numba or pandas; a float64
    CSV column needs no pyarrow.compute cast, the interval median no numpy.ma."""
    import numpy as np

    rng = np.random.default_rng(2)
    u = rng.standard_normal(2000)
    y = np.convolve(u, [0.0, 0.0, 1.0, 0.5])[:2000] + 0.01 * rng.standard_normal(2000)
    path = tmp_path / "log.csv"
    np.savetxt(path, np.column_stack([np.arange(2000) * 1e-3, u, y]), delimiter=",",
               header="time [s],current [A],force [N]", comments="")
    argv = ["gripkit", "identify", "arx", str(path), "--input", "current", "--output", "force",
            "--na", "2", "--nb", "2", "--nk", "2", "--json"]
    loaded = set(_loaded_after(f"import contextlib, io\nsys.argv = {argv!r}\n"
                               "from gripkit.cli import main\n"
                               "with contextlib.redirect_stdout(io.StringIO()) as out:\n"
                               "    try:\n        main()\n    except SystemExit as e:\n"
                               "        assert not e.code, e.code\n"
                               "assert json.loads(out.getvalue())['A'][0] == 1.0\n"))
    heavy = ("scipy.linalg", "pint", "dask", "numba", "pandas", "scipy.signal", "scipy.stats",
             "pyarrow.compute", "numpy.ma")
    assert [m for m in heavy if m in loaded] == []
