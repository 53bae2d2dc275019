"""The parameter table of a linear model's HTML report (``model.report`` of ARX/ARMAX/OE/tf/ss/step
models, :func:`gripkit.sysid.model_report.parameters_section`): every parameter of
``model.parameters`` (the model protocol) with its value and 1σ to the page's 4 significant digits
and its unit; a step model first shows its own K, f_n, ζ and offset with σ and units. The
identified values are checked against the systems the records were made from (recovery of known
parameters), so the rows shown are the fit's, not any numbers."""

from html.parser import HTMLParser

import numpy as np
import pytest
from scipy.signal import lfilter

from gripkit import Trajectory
from gripkit.lti import TransferFunction
from gripkit.sysid import identify


class _Tables(HTMLParser):
    """The text of every table row of a page: a list of rows, each the list of its cells."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.rows: list[list[str]] = []
        self._cell: list[str] | None = None

    def handle_starttag(self, tag, attrs):
        if tag == "tr":
            self.rows.append([])
        elif tag in ("td", "th"):
            self._cell = []

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._cell is not None:
            self.rows[-1].append("".join(self._cell))
            self._cell = None

    def handle_data(self, data):
        if self._cell is not None:
            self._cell.append(data)


def page_rows(index) -> dict[str, list[str]]:
    """The rows of the page ``index`` by their first cell."""
    parser = _Tables()
    parser.feed(index.read_text(encoding="utf-8"))
    return {r[0]: r[1:] for r in parser.rows if r}


def shown(x: float) -> str:
    """A number as the report's tables show it (4 significant digits)."""
    return f"{x:.4g}"


@pytest.fixture(scope="module")
def arx_report(tmp_path_factory):
    """ARX [2 2 1] of y = (0.5 q⁻¹ + 0.3 q⁻²)/(1 − 1.5 q⁻¹ + 0.7 q⁻²) u + e, e ~ N(0, 0.02²),
    u ~ N(0, 1) A, y in N, 100 Hz, 1000 samples."""
    rng = np.random.default_rng(4)
    u = rng.standard_normal(1000)
    e = 0.02 * rng.standard_normal(1000)
    y = lfilter([0.0, 0.5, 0.3], [1.0, -1.5, 0.7], u) + lfilter([1.0], [1.0, -1.5, 0.7], e)
    tr = Trajectory.uniform(dt=0.01, current=u, force=y, units={"current": "A", "force": "N"})
    m = identify(tr, "arx", input="current", output="force", na=2, nb=2, nk=1)
    return m, m.report(tr, tmp_path_factory.mktemp("arx") / "rep")


@pytest.fixture(scope="module")
def step_report(tmp_path_factory):
    """Step of 0 → 2 V at sample 50 of 1000 (1 kHz) into K ω_n²/(s² + 2ζω_n s + ω_n²) with
    K = 0.003 m/V, f_n = 10 Hz, ζ = 0.2, offset 1 mm, noise σ = 10 µm."""
    u = np.where(np.arange(1000) >= 50, 2.0, 0.0)
    w = 2 * np.pi * 10.0
    y = TransferFunction([0.003 * w * w], [1.0, 2 * 0.2 * w, w * w]).c2d(1e-3).simulate(u)[:, 0]
    y = 1e-3 + y + 1e-5 * np.random.default_rng(5).standard_normal(1000)
    tr = Trajectory.uniform(dt=1e-3, voltage=u, position=y,
                            units={"voltage": "V", "position": "m"})
    m = identify(tr, "step", input="voltage", output="position")
    return m, m.report(tr, tmp_path_factory.mktemp("step") / "rep")


def test_arx_report_shows_every_parameter_with_sigma_and_unit(arx_report):
    m, index = arx_report
    rows = page_rows(index)
    table = {r["name"]: r for r in m.parameters.table()}
    assert list(table) == ["a1", "a2", "b1", "b2"]
    truth = {"a1": -1.5, "a2": 0.7, "b1": 0.5, "b2": 0.3}
    for name, r in table.items():
        assert abs(r["value"] - truth[name]) < 5 * r["std"] + 0.01, (name, r)  # recovered
        assert rows[name][:3] == [shown(r["value"]), shown(r["std"]), r["unit"]], rows[name]
    # units: A(q) coefficients are ratios of the output to itself, B(q)'s output per input
    assert rows["a1"][2] == "1" and rows["b1"][2] == "N/A"


def test_step_report_shows_gain_frequency_damping_and_offset(step_report):
    m, index = step_report
    rows = page_rows(index)
    step = m.info["step"]
    expected = {"K": ("gain", "m/V", 0.003), "f_n": ("natural_frequency_hz", "Hz", 10.0),
                "ζ": ("damping_ratio", "1", 0.2), "y₀": ("offset", "m", 1e-3)}
    for symbol, (key, unit, truth) in expected.items():
        value, sd = step[key], step[f"{key}_std"]
        assert abs(value - truth) < 5 * sd + 1e-3 * abs(truth), (symbol, value, sd)  # recovered
        assert rows[symbol][:3] == [shown(value), shown(sd), unit], rows[symbol]
    # and the transfer function's coefficients of model.parameters, each with σ and unit
    for r in m.parameters.table():
        assert rows[r["name"]][:3] == [shown(r["value"]), shown(r["std"]), r["unit"]]
