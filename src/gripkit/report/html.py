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

Everything a caller gives (titles, text, table cells, captions: often names read from files) is
text: the page template escapes all of it (jinja2 autoescaping), so a column named ``<script>``
shows as that name and never runs; a label whose mathtext does not parse is drawn as it is.

Narrow screens (a ``viewport`` meta tag; checked at 1400 px and 390 px in headless Chromium by
``scripts/screenshot_report.py``): each table scrolls sideways inside its own box (its prose
columns keep at least 8em, not a word per line), figures shrink
to the page width, and a word longer than the line (a long identifier in prose or a caption)
breaks instead of widening the page.
"""

from __future__ import annotations

import base64
import datetime as _dt
import functools
import io
import math
import numbers
import os
import re
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from markupsafe import Markup

from ..atomic import TEMP_SUFFIX, write_bytes, write_hint
from ..errors import PathError
from .plots import plain_math_fallback

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
        self.items.append(("table", _Table([str(h) for h in headers], [list(r) for r in rows],
                                           caption)))
        return self

    def figure(self, fig, caption: str = "", name: str | None = None, dpi: int = 110) -> "Section":
        """Add a matplotlib figure (closed after rendering)."""
        import matplotlib.pyplot as plt

        plain_math_fallback(fig)
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
        plt.close(fig)
        slug = _slug(name or f"{self.title}-{len(self.items)}")
        self.items.append(("figure", _Figure(buf.getvalue(), caption, slug)))
        return self

    def findings(self, report) -> "Section":
        """Add a consistency report (see :mod:`gripkit.consistency`) as a table."""
        rows = ([["ok" if f.consistent else "INCONSISTENT", f.check, f.message,
                  f.used] for f in report])
        return self.table(["status", "check", "finding", "gripkit uses"], rows,
                          caption=f"Consistency checks: {report.subject}")


def _slug(s: str) -> str:
    return re.sub(r"[^a-z0-9]+", "-", s.lower()).strip("-")[:60] or "figure"


def _cell(v) -> tuple[str, str]:
    """One cell as (CSS class, text): numbers right-aligned to 4 significant digits, prose
    left-aligned. Plain text: the page template escapes it."""
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "txt na", "not given"
    if isinstance(v, bool):
        return "txt", str(v)
    if isinstance(v, numbers.Real):
        return "", f"{v:.4g}" if isinstance(v, float) or not float(v).is_integer() else _text(v)
    text = _text(v)
    return ("txt" if _NUMBER.fullmatch(text.strip()) is None else ""), text


_NUMBER = re.compile(r"[-+±−]?\s*[0-9.]+([eE][-+]?[0-9]+)?\s*(%|[a-zA-Zµ°/*^·²³]+)?")


def _row(cells) -> dict:
    flagged = any(isinstance(c, str) and c.strip() == "INCONSISTENT" for c in cells)
    return {"bad": flagged, "cells": [_cell(c) for c in cells]}


_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;max-width:1100px;
margin:2em auto;
padding:0 1em;color:#222;line-height:1.45;overflow-wrap:break-word}
h1{border-bottom:2px solid #345;padding-bottom:.2em}
h2{color:#234;margin-top:2em;border-bottom:1px solid #ccd}
.tbl{overflow-x:auto}table{border-collapse:collapse;margin:1em 0;font-size:.92em}
th,td{border:1px solid #ccd;padding:.25em .6em;text-align:right;vertical-align:top}
th{background:#eef2f7}
td.txt,th:first-child,td:first-child{text-align:left}td.na{color:#888;font-style:italic}
tr.bad td{background:#fde8e6}tr.bad td:first-child{font-weight:600;color:#a31515}
figure{margin:1.2em 0}figure img{max-width:100%;height:auto;border:1px solid #dde}
figcaption,.cap{font-size:.9em;color:#555}nav ul{columns:2}.meta{color:#666;font-size:.9em}
@media (max-width:700px){body{margin:1em auto;font-size:.95em}nav ul{columns:1}
table{font-size:.85em}
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
        """The page. Every string in it that is not the template's own (titles, text, table cells,
        captions: names from files among them) goes through the template's autoescaping, so that
        a name such as ``<script>`` is shown as text, never run as markup."""
        sections = [{"title": _text(sec.title), "items": [_view(k, item) for k, item in sec.items]}
                    for sec in self.sections]
        return _page_template().render(
            title=_text(self.title), subtitle=_text(self.subtitle), css=Markup(_CSS),
            sections=sections, when=_dt.datetime.now().strftime("%Y-%m-%d %H:%M"))

    def write(self, out_dir) -> Path:
        """Write ``out_dir/index.html`` (and ``out_dir/figures/*.png``); returns the HTML path.

        The report is written whole into a temporary folder first and then moved into place: a
        new ``out_dir`` by one rename, into an existing one by a rename per figure and the page
        last. A failure while it is written (a full disk, Ctrl-C) raises
        :class:`~gripkit.errors.PathError` and leaves nothing behind (no figures without their
        page, no temporary folder, no folder made for it); what would stop the renames (a
        folder named index.html, a file named figures) is named before anything is written.
        Only a rename failing for another reason midway leaves new figures beside the old
        page."""
        out = Path(out_dir)
        figures = [item for sec in self.sections for kind, item in sec.items if kind == "figure"]
        _check_targets(out, [item.slug for item in figures])
        made = _first_missing(out)
        try:
            (out if made is None else out.parent).mkdir(parents=True, exist_ok=True)
            stage = Path(tempfile.mkdtemp(dir=out if made is None else out.parent,
                                          prefix=f".{out.name or 'report'}.", suffix=TEMP_SUFFIX))
            if made is not None:  # it becomes the report folder: a folder's usual permissions
                umask = os.umask(0)
                os.umask(umask)
                os.chmod(stage, 0o777 & ~umask)
        except OSError as exc:
            _remove_made(made)
            raise PathError(f"report folder {str(out)!r} cannot be made "
                            f"({exc.strerror or exc})", hint=write_hint(exc)) from None
        try:
            (stage / "figures").mkdir()
            for item in figures:
                write_bytes(stage / "figures" / f"{item.slug}.png", item.png,
                            what="report figure")
            write_bytes(stage / "index.html", self.render().encode(), what="report page")
            if made is not None:
                os.rename(stage, out)
                return out / "index.html"
            (out / "figures").mkdir(exist_ok=True)
            for item in figures:
                name = f"{item.slug}.png"
                os.replace(stage / "figures" / name, out / "figures" / name)
            os.replace(stage / "index.html", out / "index.html")
        except BaseException as exc:
            shutil.rmtree(stage, ignore_errors=True)
            _remove_made(made)
            if isinstance(exc, PathError):  # named by where it was going, not the temporary folder
                raise PathError(exc.message.replace(str(stage), str(out)),
                                hint=exc.hint) from exc
            if isinstance(exc, OSError):
                raise PathError(f"report {str(out / 'index.html')!r} could not be written "
                                f"({exc.strerror or exc}); no report was written",
                                hint=write_hint(exc)) from exc
            raise
        shutil.rmtree(stage, ignore_errors=True)
        return out / "index.html"


def _check_targets(out: Path, slugs) -> None:
    """A :class:`PathError` when something is in the way of the report in ``out``: a file named
    like the folder, a folder named index.html, a file named figures, a folder named like one of
    the figures ``slugs``."""
    index, figs = out / "index.html", out / "figures"
    if out.exists() and not out.is_dir():
        raise PathError(f"report folder {str(out)!r} is a file",
                        hint="choose a folder (it is created if missing)")
    if index.is_dir():
        raise PathError(f"report page {str(index)!r} is a folder",
                        hint="remove that folder, or choose another report folder")
    if figs.exists() and not figs.is_dir():
        raise PathError(f"report figures folder {str(figs)!r} is a file",
                        hint="remove that file, or choose another report folder")
    for slug in slugs:
        if (figs / f"{slug}.png").is_dir():
            raise PathError(f"report figure {str(figs / f'{slug}.png')!r} is a folder",
                            hint="remove that folder, or choose another report folder")


def _first_missing(out: Path) -> Path | None:
    """The outermost folder of ``out`` (itself included) that does not exist yet (the report
    makes it, and removes it again on failure), None when ``out`` exists."""
    missing = None
    for p in (out, *out.parents):
        if p.exists() or p.is_symlink():
            return missing
        missing = p
    return missing


def _remove_made(made: Path | None) -> None:
    if made is not None:
        shutil.rmtree(made, ignore_errors=True)


def _text(v) -> str:
    """``v`` as a plain ``str``: never markup marked safe (a ``markupsafe.Markup``, or an object
    whose ``__str__`` returns one), which the template would not escape."""
    return str(str(v))


def _view(kind: str, item) -> dict:
    """What the template needs of one item, as plain strings (escaped there)."""
    if kind == "text":
        return {"kind": "text", "text": _text(item)}
    if kind == "table":
        return {"kind": "table", "caption": _text(item.caption),
                "headers": [_text(h) for h in item.headers], "rows": [_row(r) for r in item.rows]}
    return {"kind": "figure", "caption": _text(item.caption), "slug": _slug(item.slug),
            "b64": base64.b64encode(item.png).decode()}


# The one place where the page's markup is written. Autoescaping is on for every value; the only
# value marked safe is the builder's own style sheet (_CSS), never anything from a caller.
_PAGE = (
    "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
    "<meta name='viewport' content='width=device-width, initial-scale=1'><title>{{ title }}</title>"
    "<style>{{ css }}</style></head><body><h1>{{ title }}</h1>"
    "{% if subtitle %}<p>{{ subtitle }}</p>{% endif %}"
    "<p class='meta'>Generated by gripkit on {{ when }}.</p>"
    "<nav><ul>{% for s in sections %}"
    "<li><a href='#s{{ loop.index0 }}'>{{ s.title }}</a></li>{% endfor %}</ul></nav>"
    "{% for s in sections %}{% set i = loop.index0 %}{% if not loop.first %}\n{% endif %}"
    "<h2 id=\"s{{ i }}\">{{ s.title }}</h2>"
    "{% for it in s['items'] %}\n"
    "{% if it.kind == 'text' %}<p>{{ it.text }}</p>"
    "{% elif it.kind == 'table' %}"
    "{% if it.caption %}<div class=\"cap\">{{ it.caption }}</div>{% endif %}"
    "<div class=\"tbl\"><table><tr>{% for h in it.headers %}<th>{{ h }}</th>{% endfor %}</tr>"
    "{% for r in it.rows %}<tr{% if r.bad %} class=\"bad\"{% endif %}>"
    "{% for cls, text in r.cells %}"
    "<td{% if cls %} class=\"{{ cls }}\"{% endif %}>{{ text }}</td>{% endfor %}"
    "</tr>{% endfor %}</table></div>"
    "{% else %}<figure><img alt=\"{{ it.caption }}\" src=\"data:image/png;base64,{{ it.b64 }}\"/>"
    "<figcaption>{{ it.caption }} (<a href=\"figures/{{ it.slug }}.png\">full size</a>)"
    "</figcaption></figure>"
    "{% endif %}{% endfor %}{% endfor %}</body></html>")


@functools.lru_cache(maxsize=1)
def _page_template():
    from jinja2 import Environment

    return Environment(autoescape=True).from_string(_PAGE)

