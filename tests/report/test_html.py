"""The HTML report: tables a reader can scan (issue 16) and a page that works on a phone."""

import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from gripkit.report import Report  # noqa: E402


def _page(tmp_path, rows, headers=("status", "check", "value")):
    rep = Report("t")
    sec = rep.section("s")
    sec.table(list(headers), rows)
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    sec.figure(fig, "a line", name="line")
    return rep.write(tmp_path).read_text(), tmp_path


def test_cells_prose_left_numbers_right_missing_said(tmp_path):
    html, _ = _page(tmp_path, [["ok", "eq 10 poles", 0.123456789], ["ok", "M_b", math.nan],
                               ["ok", "gain", None], ["ok", "width", "3.5 µm"]])
    assert '<td class="txt">eq 10 poles</td>' in html
    assert "<td>0.1235</td>" in html  # 4 significant digits
    assert html.count('<td class="txt na">not given</td>') == 2
    assert "nan" not in html.replace("name", "")
    assert "<td>3.5 µm</td>" in html  # a number with its unit stays right-aligned


def test_inconsistent_rows_are_highlighted(tmp_path):
    html, _ = _page(tmp_path, [["ok", "a", 1.0], ["INCONSISTENT", "b", 2.0], ["ok", "c", 3.0]])
    assert html.count('<tr class="bad">') == 1
    bad = html.split('<tr class="bad">')[1].split("</tr>")[0]
    assert "INCONSISTENT" in bad and "<td>2</td>" in bad


def test_viewport_and_figures_linked(tmp_path):
    html, out = _page(tmp_path, [["ok", "a", 1.0]])
    assert "name='viewport'" in html and "width=device-width" in html
    assert 'href="figures/line.png"' in html and (out / "figures" / "line.png").is_file()
    assert "@media (max-width:700px)" in html
    # phone width (measured in a browser by tests/report/test_report_browser.py): tables scroll in
    # their own box, figures shrink, long words break
    assert '<div class="tbl"><table>' in html and ".tbl{overflow-x:auto}" in html
    assert "figure img{max-width:100%" in html and "overflow-wrap:break-word" in html
