"""A report made of sections, written as one self-contained HTML file.

>>> rep = Report("AMADEUS finger identification")
>>> sec = rep.section("Least squares", "ARX models of Table II ...")
>>> sec = sec.table(["model", "loss"], [["[2 2 2]", 27.6]])  # sec.figure(fig, "caption") likewise
>>> import tempfile
>>> with tempfile.TemporaryDirectory() as out:
...     print(rep.write(out).name)
index.html

Figures are embedded as PNG (base64), so the page is one self-contained file; each is also saved
under ``<out>/figures/`` and linked from its caption, for a full-size view or to cite elsewhere.

Tables: numbers are right-aligned and shown to 4 significant digits, prose is left-aligned, a
missing value (None or NaN) reads "not given", and a row that reports ``INCONSISTENT`` is
highlighted.

Narrow screens (a ``viewport`` meta tag; checked at 1400 px and 390 px in headless Chromium by
``scripts/screenshot_report.py``): each table scrolls sideways inside its own box (its prose
columns keep at least 8em, not a word per line), figures shrink
to the page width, and a word longer than the line (a long identifier in prose or a caption)
breaks instead of widening the page.
"""

from __future__ import annotations

import base64
import datetime as _dt
import html
import io
import math
import numbers
import re
from dataclasses import dataclass, field
from pathlib import Path

from ..atomic import write_bytes
from ..errors import PathError

__all__ = ["Report", "Section"]


@dataclass
class _Figure:
    png: bytes
    caption: str
    slug: str


@dataclass
class _Table:
    headers: list[str]
    rows: list[list]
    caption: str


@dataclass
class Section:
    """One section: paragraphs, tables and figures, shown in the order they were added."""

    title: str
    items: list = field(default_factory=list)

    def text(self, paragraph: str) -> "Section":
        self.items.append(("text", paragraph))
        return self

    def table(self, headers, rows, caption: str = "") -> "Section":
        self.items.append(("table", _Table([str(h) for h in headers], [list(r) for r in rows], caption)))
        return self

    def figure(self, fig, caption: str = "", name: str | None = None, dpi: int = 110) -> "Section":
        """Add a matplotlib figure (closed after rendering)."""
        import matplotlib.pyplot as plt

        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
        plt.close(fig)
        slug = _slug(name or f"{self.title}-{len(self.items)}")
        self.items.append(("figure", _Figure(buf.getvalue(), caption, slug)))
        return self

    def findings(self, report) -> "Section":
        """Add a consistency report (see :mod:`gripkit.consistency`) as a table."""
        rows = [["ok" if f.consistent else "INCONSISTENT", f.check, f.message, f.used] for f in report]
        return self.table(["status", "check", "finding", "gripkit uses"], rows,
                          caption=f"Consistency checks: {report.subject}")


def _slug(s: str) -> str:
    return re.sub(r"[^a-z0-9]+", "-", s.lower()).strip("-")[:60] or "figure"


def _cell(v) -> str:
    """One ``<td>``: numbers right-aligned to 4 significant digits, prose left-aligned."""
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return '<td class="txt na">not given</td>'
    if isinstance(v, bool):
        return f'<td class="txt">{v}</td>'
    if isinstance(v, numbers.Real):
        text = f"{v:.4g}" if isinstance(v, float) or not float(v).is_integer() else str(v)
        return f"<td>{html.escape(text)}</td>"
    text = str(v)
    cls = "txt" if _NUMBER.fullmatch(text.strip()) is None else ""
    return f'<td class="{cls}">{html.escape(text)}</td>' if cls else f"<td>{html.escape(text)}</td>"


_NUMBER = re.compile(r"[-+±−]?\s*[0-9.]+([eE][-+]?[0-9]+)?\s*(%|[a-zA-Zµ°/*^·²³]+)?")


def _row(cells) -> str:
    flagged = any(isinstance(c, str) and c.strip() == "INCONSISTENT" for c in cells)
    tds = "".join(_cell(c) for c in cells)
    return f'<tr class="bad">{tds}</tr>' if flagged else f"<tr>{tds}</tr>"


_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;max-width:1100px;margin:2em auto;
padding:0 1em;color:#222;line-height:1.45;overflow-wrap:break-word}
h1{border-bottom:2px solid #345;padding-bottom:.2em}h2{color:#234;margin-top:2em;border-bottom:1px solid #ccd}
.tbl{overflow-x:auto}table{border-collapse:collapse;margin:1em 0;font-size:.92em}
th,td{border:1px solid #ccd;padding:.25em .6em;text-align:right;vertical-align:top}th{background:#eef2f7}
td.txt,th:first-child,td:first-child{text-align:left}td.na{color:#888;font-style:italic}
tr.bad td{background:#fde8e6}tr.bad td:first-child{font-weight:600;color:#a31515}
figure{margin:1.2em 0}figure img{max-width:100%;height:auto;border:1px solid #dde}
figcaption,.cap{font-size:.9em;color:#555}nav ul{columns:2}.meta{color:#666;font-size:.9em}
@media (max-width:700px){body{margin:1em auto;font-size:.95em}nav ul{columns:1}table{font-size:.85em}
td.txt{min-width:8em}}
"""


class Report:
    """An HTML report made of :class:`Section` objects."""

    def __init__(self, title: str, subtitle: str = ""):
        self.title = title
        self.subtitle = subtitle
        self.sections: list[Section] = []

    def section(self, title: str, intro: str = "") -> Section:
        sec = Section(title)
        if intro:
            sec.text(intro)
        self.sections.append(sec)
        return sec

    def render(self) -> str:
        from jinja2 import Template

        body = []
        for i, sec in enumerate(self.sections):
            parts = [f'<h2 id="s{i}">{html.escape(sec.title)}</h2>']
            for kind, item in sec.items:
                if kind == "text":
                    parts.append(f"<p>{html.escape(item)}</p>")
                elif kind == "table":
                    head = "".join(f"<th>{html.escape(h)}</th>" for h in item.headers)
                    rows = "".join(_row(r) for r in item.rows)
                    cap = f'<div class="cap">{html.escape(item.caption)}</div>' if item.caption else ""
                    parts.append(f'{cap}<div class="tbl"><table><tr>{head}</tr>{rows}</table></div>')
                else:
                    b64 = base64.b64encode(item.png).decode()
                    parts.append(f'<figure><img alt="{html.escape(item.caption)}" '
                                 f'src="data:image/png;base64,{b64}"/>'
                                 f"<figcaption>{html.escape(item.caption)} "
                                 f'(<a href="figures/{item.slug}.png">full size</a>)</figcaption></figure>')
            body.append("\n".join(parts))
        tmpl = Template(
            "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
            "<meta name='viewport' content='width=device-width, initial-scale=1'><title>{{title}}</title>"
            "<style>{{css}}</style></head><body><h1>{{title}}</h1>"
            "{% if subtitle %}<p>{{subtitle}}</p>{% endif %}"
            "<p class='meta'>Generated by gripkit on {{when}}.</p>"
            "<nav><ul>{% for s in sections %}<li><a href='#s{{loop.index0}}'>{{s.title}}</a></li>{% endfor %}</ul></nav>"
            "{{body}}</body></html>")
        return tmpl.render(title=self.title, subtitle=self.subtitle, css=_CSS, sections=self.sections,
                           when=_dt.datetime.now().strftime("%Y-%m-%d %H:%M"), body="\n".join(body))

    def write(self, out_dir) -> Path:
        """Write ``out_dir/index.html`` (and ``out_dir/figures/*.png``); returns the HTML path.
        Each file is written atomically (:func:`gripkit.atomic.write_bytes`): a failure leaves the
        previous file as it was and raises :class:`~gripkit.errors.PathError`."""
        out = Path(out_dir)
        figs = out / "figures"
        try:
            figs.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise PathError(f"report folder {str(figs)!r} cannot be made ({exc.strerror or exc})",
                            hint="choose a folder you may write to") from None
        for sec in self.sections:
            for kind, item in sec.items:
                if kind == "figure":
                    write_bytes(figs / f"{item.slug}.png", item.png, what="report figure")
        index = out / "index.html"
        write_bytes(index, self.render().encode(), what="report page")
        return index
