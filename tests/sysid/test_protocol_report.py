"""`gripkit report MODEL DATA` and `identify narx|hw|hysteresis --report DIR` for the model
families without a linear system (issue 26: "the saved model works with gripkit simulate, gripkit
compare and gripkit report"): the page is built on the model protocol alone
(:mod:`gripkit.sysid.protocol_report`). Each family's model file is identified from a synthetic
record whose input column is named ``valve<script>``; the page must show the fit `gripkit compare`
prints (the same digits), every parameter with its σ, the residual tests that scipy's reference
computation gives, and the hostile name as text."""

import contextlib
import io
import json
import re
import warnings

import numpy as np
import pytest
from scipy.signal import lfilter
from scipy.stats import norm

from gripkit.cli import main
from gripkit.io import load
from gripkit.sysid import BoucWenModel, load_model
from gripkit.sysid.linear.validation import residual_tests
from gripkit.sysid.protocol_report import RESIDUAL_ALPHA, protocol_report

HOSTILE = "valve<script>"


def _cli(*args):
    """``gripkit ARGS`` in this process: (exit code, stdout, stderr)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([str(a) for a in args])
    return code, out.getvalue(), err.getvalue()


def _hammerstein(rng, n):
    """u ~ U(−2, 2) through a saturation [−1, 0.8], B = 0.5 q⁻¹ + 0.3 q⁻², F = 1 − 1.2 q⁻¹ +
    0.5 q⁻² (the system of tests/sysid/test_hammerstein_wiener.py), noise σ = 0.05."""
    u = rng.uniform(-2.0, 2.0, n)
    y = lfilter([0.0, 0.5, 0.3], [1.0, -1.2, 0.5], np.clip(u, -1.0, 0.8)) + 0.3
    return u, y + 0.05 * rng.normal(size=n)


def _bouc_wen(rng, n):
    """The piezo Bouc-Wen of tests/sysid/test_hysteresis.py (seed values), a decaying 4 Hz sine
    of 0…100 V, noise σ = 0.2 µm."""
    t = np.linspace(0.0, 1.0, n)
    u = 50.0 + 50.0 * np.sin(2 * np.pi * 4 * t - np.pi / 2) * (1 - 0.7 * t) * rng.uniform(0.9, 1.0)
    truth = BoucWenModel(d=0.77e-6, alpha=0.43 / 0.77, beta=0.108, gamma=7.5e-3, offset=0.0)
    return u, truth.simulate(u)[:, 0] + rng.normal(0.0, 0.2e-6, n)


FAMILIES = {  # family -> (record maker, samples, identify arguments)
    "hw": (_hammerstein, 600, ["--input-nonlinearity", "saturation", "--nb", 2, "--nf", 2,
                               "--nk", 1]),
    "narx": (_hammerstein, 600, ["--degree", 2, "--lags", 2]),
    "hysteresis": (_bouc_wen, 1000, []),
}


@pytest.fixture(scope="module", params=sorted(FAMILIES))
def identified(request, tmp_path_factory):
    """Estimation and validation records (CSV, 100 Hz), the model file written by `identify
    FAMILY … --validate VAL --out M --report R --json` and its JSON answer."""
    family = request.param
    make, n, args = FAMILIES[family]
    folder = tmp_path_factory.mktemp(family)
    paths = {}
    for name, seed in (("est", 1), ("val", 2)):
        u, y = make(np.random.default_rng(seed), n)
        paths[name] = folder / f"{name}.csv"
        np.savetxt(paths[name], np.column_stack([u, y]), delimiter=",",
                   header=f"{HOSTILE},force", comments="", fmt="%.12g")
    model = folder / "model.json"
    code, out, err = _cli("identify", family, paths["est"], "--input", HOSTILE,
                          "--output", "force", "--fs", 100, *args, "--validate", paths["val"],
                          "--out", model, "--report", folder / "identify-report", "--json")
    assert code == 0, err
    return family, paths, model, json.loads(out), folder


def _compare(model, data):
    code, out, err = _cli("compare", model, data, "--fs", 100, "--json")
    assert code == 0, err
    code, text, err = _cli("compare", model, data, "--fs", 100)
    assert code == 0, err
    return json.loads(out), text


def test_report_shows_the_fit_compare_prints(identified):
    """`gripkit report --json` gives the fit `gripkit compare --json` gives, and the page shows
    the digits `gripkit compare` prints ("force: 95.85 %") in its fit table."""
    family, paths, model, ident, folder = identified
    compared, text = _compare(model, paths["val"])
    code, out, err = _cli("report", model, paths["val"], "--fs", 100,
                          "--out", folder / "rep", "--json")
    assert code == 0, err
    rep = json.loads(out)
    assert rep["fit_percent"] == pytest.approx(compared["fit_percent"], abs=1e-9)
    assert rep["fit_percent"][0] == pytest.approx(ident["validation"]["fit_percent"], abs=1e-6)
    assert rep["definition"] == compared["definition"] == load_model(model).fit_definition
    assert rep["outputs"] == ["force"] and rep["structure"] == load_model(model).structure
    assert rep["warnings"] == [] and rep["report"] == str(folder / "rep" / "index.html")
    printed = re.search(r"force: ([0-9.]+ %)", text).group(1)
    html = (folder / "rep" / "index.html").read_text(encoding="utf-8")
    assert f"<td class=\"txt\">force</td><td>1</td><td>{printed}</td>" in html  # unit 1: none given
    assert (folder / "rep" / "figures" / "out-0.png").stat().st_size > 1000


def test_identify_report_is_the_same_page_on_the_validation_record(identified):
    """`identify … --validate VAL --report DIR` reports on VAL: its page shows the validation
    fit the JSON answer gives (the number `gripkit compare` prints on VAL)."""
    family, paths, model, ident, folder = identified
    page = folder / "identify-report" / "index.html"
    assert ident["report"] == str(page)
    html = page.read_text(encoding="utf-8")
    assert f"<td>{ident['validation']['fit_percent']:.2f} %</td>" in html
    assert "data val.csv" in html


def test_parameters_with_sigma_and_the_band(identified):
    """Every parameter of ``model.parameters`` is a row of the page with its value and 1σ (to the
    table's 4 significant digits); HW and Bouc-Wen give σ of the free run (the ±2σ band), NARX
    says it gives none."""
    family, paths, model, ident, folder = identified
    m = load_model(model)
    rows = m.parameters.table()
    assert len(rows) >= 3
    html = (folder / "identify-report" / "index.html").read_text(encoding="utf-8")
    for r in rows:
        sd = "not given" if r["std"] is None else f"{r['std']:.4g}"
        cls = ' class="txt na"' if r["std"] is None else ""
        assert (f'<td class="txt">{r["name"]}</td><td>{r["value"]:.4g}</td><td{cls}>{sd}</td>'
                in html), r["name"]
    assert "The band is ±2σ of the free run" in html  # every family gives σ of its free run


def test_hostile_column_name_is_text(identified):
    """The input column ``valve<script>`` is shown escaped, never as markup."""
    *_, folder = identified
    html = (folder / "identify-report" / "index.html").read_text(encoding="utf-8")
    assert "valve&lt;script&gt;" in html and "<script" not in html


def test_residual_tests_are_scipys_on_the_free_run_errors(identified):
    """The page's whiteness and independence p-values are those of the portmanteau tests on
    e = y − ŷ (ŷ: the compared free run) at α = 0.01, and the band is z₀.₉₉₅/√N with z from
    scipy (2.576)."""
    family, paths, model, ident, folder = identified
    m, tr = load_model(model), load(paths["val"], fs=100.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rep, fit = protocol_report(m, tr, data_name="val.csv")
    e = np.asarray(tr["force"]) - fit.simulated[:, 0]
    rt = residual_tests(e, np.asarray(tr[HOSTILE]), lags=25, alpha=RESIDUAL_ALPHA)
    html = rep.render()
    assert f"<td>{rt.whiteness_p:.4g}</td><td>{rt.independence_p:.4g}</td>" in html
    assert f"±{norm.ppf(1 - RESIDUAL_ALPHA / 2):.3f}/√N" in html


def test_diverging_free_run_is_named_not_analysed(tmp_path):
    """A NARX model whose quadratic feedback runs away on a large step (the case of
    tests/sysid/test_narx.py): the page says 'diverged' and draws no residuals."""
    from gripkit import Trajectory
    from gripkit.errors import StabilityWarning
    from gripkit.sysid import narx

    rng = np.random.default_rng(3)
    u, e = rng.uniform(-1.0, 1.0, 1000), rng.normal(0.0, 0.01, 1000)
    y = np.zeros(1000)
    for t in range(2, 1000):
        y[t] = (-0.605 * y[t - 1] - 0.163 * y[t - 2] ** 2 + 0.588 * u[t - 1] - 0.240 * u[t - 2]
                + e[t])
    m = narx(u, y, degree=2, lags=2)
    n = 500
    tr = Trajectory(np.arange(n) * 1.0, {"u": np.full(n, -6.0),
                                         "y": -3.0 * (1.0 - 0.5 ** np.arange(float(n)))})
    with pytest.warns(StabilityWarning, match="diverges"):
        rep, fit = protocol_report(m, tr)
    assert fit.fit_percent == [None]
    html = rep.render()
    assert '<td class="txt">diverged</td>' in html
    assert "No residuals for y: the free run diverged." in html
    assert "residual correlations" not in html


def test_identify_report_without_validation_uses_the_estimation_record(tmp_path):
    """Without --validate the page is of the estimation record and shows the estimation fit;
    a --report path that is a file is one PathError line naming the option, before any fit."""
    u, y = _hammerstein(np.random.default_rng(4), 600)
    est = tmp_path / "est.csv"
    np.savetxt(est, np.column_stack([u, y]), delimiter=",", header=f"{HOSTILE},force",
               comments="", fmt="%.12g")
    args = ["identify", "hw", est, "--input", HOSTILE, "--output", "force", "--fs", 100,
            "--input-nonlinearity", "saturation", "--nb", 2, "--nf", 2, "--nk", 1]
    code, out, err = _cli(*args, "--report", tmp_path / "rep", "--json")
    assert code == 0, err
    d = json.loads(out)
    html = (tmp_path / "rep" / "index.html").read_text(encoding="utf-8")
    assert "data est.csv" in html and f"<td>{d['fit_percent']:.2f} %</td>" in html
    code, out, err = _cli(*args, "--report", est)  # the data file itself: named as the input
    assert code != 0 and err.startswith("error: PathError: --report") and "is the input" in err
    assert len(err.strip().splitlines()) == 1
    (tmp_path / "notes.txt").write_text("x")
    code, out, err = _cli(*args, "--report", tmp_path / "notes.txt")
    assert code != 0 and err.startswith("error: PathError: --report") and "is a file" in err
    assert len(err.strip().splitlines()) == 1


def test_model_without_covariance_has_no_band_and_says_why():
    """A Prandtl–Ishlinskii model built from its weights (no covariance, as an inverse is): the
    page draws no band and gives the model's reason; its fit on its own noise-free output is
    100 %, and residuals that are all 0 are named in the residual table, not tested."""
    from gripkit import Trajectory
    from gripkit.sysid import PrandtlIshlinskiiModel

    m = PrandtlIshlinskiiModel(np.arange(8) * 0.1,
                               np.array([0.5, 0.3, 0.2, 0.15, 0.1, 0.08, 0.05, 0.03]), offset=0.2)
    t = np.linspace(0.0, 1.0, 400)
    u = 0.4 + 0.4 * np.sin(2 * np.pi * 3 * t)
    tr = Trajectory(t, {"u": u, "y": m.simulate(u)[:, 0]})
    rep, fit = protocol_report(m, tr)
    html = rep.render()
    assert fit.fit_percent[0] == pytest.approx(100.0, abs=1e-9)
    assert "No ±2σ band: prandtl-ishlinskii: this model has no parameter covariance" in html
    assert ('<td>0</td><td class="txt na">not given</td><td class="txt na">not given</td>'
            '<td class="txt">not tested: residual tests need non-constant residuals and input</td>'
            in html)
