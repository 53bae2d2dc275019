"""Hostile names in every HTML report (issue 22, security item 1): names from files (CSV column
names, a model file's structure and units, a URDF's robot, link and joint names, a sweep table's
parameter names) are shown as text, never parsed as markup, and a ``$`` in them cannot stop a plot
(matplotlib mathtext).

Each page is parsed with :class:`html.parser.HTMLParser`: only the elements and attributes the
report builder itself writes may appear (no ``<script>``, no ``onerror``, one ``<img>`` per
figure, with a ``data:image/png`` source), and the hostile text is found, whole, in the text of
the page."""

from __future__ import annotations

import csv
import json
import math
from html.parser import HTMLParser
from xml.sax.saxutils import quoteattr

import matplotlib
import numpy as np
import pytest
from scipy import signal

matplotlib.use("Agg")

#: the pieces of the issue, in one string, so that every slot gets all of them
HOSTILE = '<script>alert(1)</script>"><img src=x onerror=alert(1)></title>&$\\frac{$'

#: what the builder writes itself (html.py's page template)
BUILDER_TAGS = {"html", "head", "meta", "title", "style", "body", "h1", "h2", "p", "nav", "ul",
                "li", "a", "div", "table", "tr", "th", "td", "figure", "img", "figcaption"}
BUILDER_ATTRS = {"lang", "charset", "name", "content", "href", "id", "class", "alt", "src"}


class _Page(HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.tags: list[tuple[str, dict]] = []
        self.text: list[str] = []
        self._in: list[str] = []
        self.title = ""

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))
        if tag not in ("meta", "img"):
            self._in.append(tag)

    def handle_endtag(self, tag):
        if self._in and self._in[-1] == tag:
            self._in.pop()

    def handle_data(self, data):
        self.text.append(data)
        if self._in and self._in[-1] == "title":
            self.title += data


def assert_no_markup_from_data(html: str, n_figures: int, title: str) -> _Page:
    page = _Page()
    page.feed(html)
    page.close()
    tags = [t for t, _ in page.tags]
    assert set(tags) <= BUILDER_TAGS, set(tags) - BUILDER_TAGS
    assert "script" not in tags
    for tag, attrs in page.tags:
        assert set(attrs) <= BUILDER_ATTRS, (tag, attrs)
        assert not any(a.startswith("on") for a in attrs), (tag, attrs)
        if tag == "img":
            assert attrs["src"].startswith("data:image/png;base64,")
        if tag == "a":
            assert attrs["href"].startswith(("#s", "figures/")), attrs
    assert tags.count("img") == n_figures
    assert tags.count("title") == 1 and page.title == title
    assert HOSTILE in "".join(page.text)  # shown, whole, as text
    return page


def _figures(rep) -> int:
    return sum(kind == "figure" for sec in rep.sections for kind, _ in sec.items)


def _slots_hostile(html: str, names) -> None:
    """Every name is on the page, as text (the parser decodes the escapes)."""
    page = _Page()
    page.feed(html)
    text = "".join(page.text)
    for n in names:
        assert n in text, n


# ---------------------------------------------------------------------------------------------
# the builder, as the demo sections use it: title, subtitle, section titles, text, table headers,
# cells and captions, figure captions, consistency findings


def test_builder_escapes_every_slot(tmp_path):
    from gripkit.consistency import ConsistencyReport, Finding
    from gripkit.report import Report
    from gripkit.report.plots import measured_vs_model

    rep = Report(HOSTILE, "sub " + HOSTILE)
    sec = rep.section("sec " + HOSTILE, "intro " + HOSTILE)
    sec.text("text " + HOSTILE)
    sec.table(["head " + HOSTILE, "value"], [["cell " + HOSTILE, 1.5], ["INCONSISTENT", HOSTILE]],
              caption="caption " + HOSTILE)
    t = np.linspace(0, 1, 50)
    fig = measured_vs_model(t, t, {"model " + HOSTILE: t}, ylabel="y " + HOSTILE, title=HOSTILE)
    sec.figure(fig, "figure " + HOSTILE, name=HOSTILE)
    finding = Finding(check="check " + HOSTILE, subject="s", consistent=False,
                      message="msg " + HOSTILE, used="used " + HOSTILE)
    sec.findings(ConsistencyReport([finding], "subject " + HOSTILE))
    html = rep.write(tmp_path).read_text()
    assert_no_markup_from_data(html, _figures(rep), HOSTILE)
    _slots_hostile(html, [f"{slot} {HOSTILE}" for slot in (
        "sub", "sec", "intro", "text", "head", "cell", "caption", "figure", "check", "msg",
        "subject")])
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in html and "&lt;/title&gt;" in html
    # the figure's file name is made of [a-z0-9-] only, inside figures/
    assert [p.name for p in (tmp_path / "figures").iterdir()] == [
        "script-alert-1-script-img-src-x-onerror-alert-1-title-frac.png"]


def test_builder_ignores_markup_marked_safe(tmp_path):
    """A caller cannot switch the escaping off: text marked as markup (markupsafe.Markup, or an
    object whose str() is one) is still shown as text."""
    from markupsafe import Markup

    from gripkit.report import Report

    class Sneaky:
        def __str__(self):
            return Markup(HOSTILE)

    rep = Report(Markup(HOSTILE))
    rep.section(Markup(HOSTILE)).text(Sneaky()).table([Sneaky()], [[Markup(HOSTILE), Sneaky()]],
                                                      caption=Sneaky())
    assert_no_markup_from_data(rep.render(), 0, HOSTILE)


def test_label_with_broken_mathtext_does_not_stop_a_figure():
    """A ``$...$`` from data that is not valid mathtext: the figure is still saved."""
    from gripkit.report import Report
    from gripkit.report.plots import pyplot

    fig, ax = pyplot().subplots()
    ax.set_title("$\\frac{$")  # outside the report's helpers: the builder's fallback shows it
    ax.plot([0, 1], [0, 1], label="$\\frac{$")
    ax.legend()
    sec = Report("t").section("s").figure(fig, "c")
    assert sec.items[0][1].png.startswith(b"\x89PNG")


def test_plot_helpers_draw_names_with_dollars_as_text():
    """Every figure helper of gripkit.report.plots takes a name with ``$\\frac{$`` (invalid
    mathtext) and shows it as written: the label's text is escaped, and the figure saves."""
    from gripkit.report import Report
    from gripkit.report import plots
    from gripkit.sysid.linear.validation import residual_tests

    name = "$\\frac{$"
    rng = np.random.default_rng(2)
    t = np.linspace(0.0, 1.0, 200)
    f = np.linspace(0.0, 50.0, 64)
    rt = residual_tests(rng.standard_normal(200), rng.standard_normal(200))
    figs = [plots.measured_vs_model(t, t, {name: t}, ylabel=name, title=name, extra={name: t}),
            plots.residual_correlation({name: rt}, title=name),
            plots.pole_zero_map({name: ([0.5 + 0.2j, 0.5 - 0.2j], [0.1])}, title=name),
            plots.bode({name: (f, 1.0 / (1.0 + 1j * f))}, title=name, magnitude_unit=name),
            plots.parameter_convergence(t, np.ones((200, 1)), np.full((200, 1), 0.1), [name],
                                        title=name)]
    sec = Report("t").section("s")
    for fig in figs:
        texts = [x.get_text() for x in fig.findobj(matplotlib.text.Text)]
        assert any("\\$\\frac{\\$" in x for x in texts), texts  # escaped: drawn as written
        sec.figure(fig, "c")
    assert all(item.png.startswith(b"\x89PNG") for _, item in sec.items)


# ---------------------------------------------------------------------------------------------
# identify tf/ss --report and gripkit report: CSV column names; the model file's structure, names
# and units


def _record(path, u_name, y_name, n=1200, dt=0.01):
    rng = np.random.default_rng(0)
    u = rng.standard_normal(n)
    b, a = signal.cont2discrete(([1.0], [1.0, 0.8, 4.0]), dt)[:2]
    y = signal.lfilter(np.ravel(b), a, u) + 1e-3 * rng.standard_normal(n)
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t", f"{u_name} [V]", f"{y_name} [N]"])
        w.writerows(zip(np.arange(n) * dt, u, y))
    return path


U, Y = "u" + HOSTILE, "y" + HOSTILE


def test_identify_report_and_gripkit_report(cli, tmp_path):
    file_name = 'd"><img src=x onerror=alert(1)>&.csv'  # the data file's name is shown too
    data = _record(tmp_path / file_name, U, Y)
    res = cli("identify", "tf", data, "--input", U, "--output", Y, "--poles", 2, "--zeros", 0,
              "--out", tmp_path / "m.json", "--report", tmp_path / "rep")
    assert res.code == 0, res.err
    html = (tmp_path / "rep" / "index.html").read_text()
    assert_no_markup_from_data(html, 4, "gripkit model report: tfest")
    _slots_hostile(html, [U, Y, file_name])

    # the model file's structure, names and units (a file someone sent)
    m = json.loads((tmp_path / "m.json").read_text())
    m["structure"] = HOSTILE
    m["outputs"][0]["unit"] = m["system"]["output_units"][0] = "unit" + HOSTILE
    (tmp_path / "m2.json").write_text(json.dumps(m))
    res = cli("report", tmp_path / "m2.json", data, "--out", tmp_path / "rep2")
    assert res.code == 0, res.err
    html = (tmp_path / "rep2" / "index.html").read_text()
    assert_no_markup_from_data(html, 4, "gripkit model report: " + HOSTILE)
    _slots_hostile(html, [U, Y, "unit" + HOSTILE, file_name])


# ---------------------------------------------------------------------------------------------
# identify dynamics --report: the URDF's robot, link and joint names and the log's column names

LINK = ('<link name={}><inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4"/>'
        '</inertial></link>')
JOINT = ('<joint name={} type="revolute"><parent link={}/><child link={}/><axis xyz="0 0 1"/>'
         '<limit lower="-1" upper="1" effort="1" velocity="2"/></joint>')


def test_identify_dynamics_report(cli, tmp_path):
    links = ["base" + HOSTILE, "l1" + HOSTILE, "l2" + HOSTILE]
    joints = ["j0" + HOSTILE, "j1" + HOSTILE]
    parts = [f"<robot name={quoteattr('arm' + HOSTILE)}>", f"<link name={quoteattr(links[0])}/>"]
    parts += [LINK.format(quoteattr(n)) for n in links[1:]]
    parts += [JOINT.format(quoteattr(joints[k]), quoteattr(links[k]), quoteattr(links[k + 1]))
              for k in range(2)]
    urdf = tmp_path / "arm.urdf"
    urdf.write_text("".join(parts) + "</robot>")
    n, fs = 4000, 1000.0
    t = np.arange(n) / fs
    cols = {"t": t}
    for j in range(2):
        cols[f"p{j}" + HOSTILE] = 0.5 * np.sin(2 * np.pi * 0.5 * (j + 1) * t)
        cols[f"e{j}" + HOSTILE] = np.cos(t * (j + 1))
    log = tmp_path / "log.csv"
    with open(log, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(list(cols))
        w.writerows(np.column_stack(list(cols.values())))
    names = list(cols)[1:]
    # the column lists are comma-separated: the hostile names hold no comma
    res = cli("identify", "dynamics", urdf, log, "--position", f"{names[0]},{names[2]}",
              "--effort", f"{names[1]},{names[3]}", "--report", tmp_path / "rep")
    assert res.code == 0, res.err
    html = (tmp_path / "rep" / "index.html").read_text()
    assert_no_markup_from_data(html, 3, "gripkit dynamics report: arm" + HOSTILE)
    _slots_hostile(html, joints + [links[1], links[2]])


# ---------------------------------------------------------------------------------------------
# the robustness section of the demo report on a sweep's table: the sweep's parameter names


def test_robustness_report_on_a_sweep_table_with_hostile_parameter_names(tmp_path):
    from gripkit.systems.tsfm.robustness import analyse
    from gripkit.report import Report

    rng = np.random.default_rng(1)
    n = 60
    k = np.geomspace(10.0, 1000.0, n)
    table = {"job_id": np.arange(n), "stiffness" + HOSTILE: k, "damage": rng.random(n) < 0.3,
             "lost": rng.random(n) < 0.1, "peak_force": 1e-4 * (1 + rng.random(n)),
             "settling_time": np.where(rng.random(n) < 0.9, 0.01 * rng.random(n), math.inf)}
    res = analyse(table, stiffness="stiffness" + HOSTILE)
    rep = Report("sweep " + HOSTILE)
    res.report(rep, "title " + HOSTILE, "intro " + HOSTILE, name=HOSTILE)
    html = rep.write(tmp_path).read_text()
    assert_no_markup_from_data(html, 1, "sweep " + HOSTILE)
    _slots_hostile(html, ["title " + HOSTILE, "intro " + HOSTILE])


@pytest.mark.parametrize("bad", ["<script>alert(1)</script>", '"><img src=x onerror=alert(1)>',
                                 "</title>", "&", "$\\frac{"])
def test_each_piece_alone_in_a_title(tmp_path, bad):
    from gripkit.report import Report

    rep = Report(bad)
    rep.section(bad).table([bad], [[bad]])
    page = _Page()
    page.feed(rep.render())
    assert page.title == bad
    assert [t for t, _ in page.tags if t not in BUILDER_TAGS] == []
    assert "".join(page.text).count(bad) >= 4  # title, h1, nav, h2 / th / td


# ---------------------------------------------------------------------------------------------
# the parameter table of a linear model's report: names and units from the model file


def test_step_model_parameter_table_from_a_hostile_file(cli, tmp_path):
    """A step model's file with a hostile gain unit and output unit: the parameter rows (K from
    ``info.step``, the coefficients from ``model.parameters``) show them as text."""
    from gripkit.lti import TransferFunction

    u = np.where(np.arange(600) >= 50, 2.0, 0.0)
    w = 2 * np.pi * 10.0
    y = TransferFunction([0.003 * w * w], [1.0, 2 * 0.2 * w, w * w]).c2d(1e-3).simulate(u)[:, 0]
    data = tmp_path / "step.csv"
    with open(data, "w", newline="") as f:
        csv.writer(f).writerows([["t", "v [V]", "x [m]"], *zip(np.arange(600) * 1e-3, u, y)])
    res = cli("identify", "step", data, "--input", "v", "--output", "x", "--out",
              tmp_path / "m.json")
    assert res.code == 0, res.err
    m = json.loads((tmp_path / "m.json").read_text())
    m["info"]["step"]["gain_unit"] = HOSTILE
    m["system"]["output_units"][0] = "unit" + HOSTILE
    m["outputs"][0]["unit"] = "unit" + HOSTILE  # both copies (a file whose copies differ: refused)
    (tmp_path / "m2.json").write_text(json.dumps(m))
    res = cli("report", tmp_path / "m2.json", data, "--out", tmp_path / "rep")
    assert res.code == 0, res.err
    html = (tmp_path / "rep" / "index.html").read_text()
    assert_no_markup_from_data(html, 4, "gripkit model report: step")
    from markupsafe import escape

    step = m["info"]["step"]
    # the rows: symbol, value, σ (4 significant digits), unit (escaped), meaning
    assert (f'<td class="txt">K</td><td>{step["gain"]:.4g}</td><td>{step["gain_std"]:.4g}</td>'
            f'<td class="txt">{escape(HOSTILE)}</td><td class="txt">static gain</td>') in html
    assert (f'<td class="txt">{escape("unit" + HOSTILE)}</td>'
            '<td class="txt">output offset (level before the step)</td>') in html
