#!/usr/bin/env python3
"""Check that an HTML report (``make demo`` -> ``report/index.html``) reads at desktop and phone
width.

For each window size (default 1400×900 and 390×844, an iPhone-sized portrait) headless Chromium

1. takes a screenshot of the page (``OUT/screenshot-<W>x<H>.png``), and
2. loads a copy of the page into a frame of that size with a small script that measures, after
   layout, the document's width (``scrollWidth``) against the viewport (``innerWidth``) and lists
   the elements that stick out of the viewport (or whose text does) and are not inside a
   horizontally scrollable box (the report wraps its tables in one); ``--dump-dom`` returns it.

The page overflows when the document is wider than the viewport: the reader must scroll the whole
page sideways. Exit status 0: no overflow at any size; 1: overflow (one line per size and element on
stderr); 2: no browser or the browser failed. ``--json`` prints the measurements as one JSON object.

    python scripts/screenshot_report.py report/                 # or report/index.html
    python scripts/screenshot_report.py report/ --out shots --size 1400x900 --size 390x844 --json

The browser: ``--browser PATH``, else ``$GRIPKIT_BROWSER``, else ``chromium``, ``chromium-browser``,
``google-chrome`` on the PATH (Debian: ``apt-get install chromium``). The report's tests run this
script (``tests/report/test_report_browser.py``; see docs/DEVELOPING.md).
"""

from __future__ import annotations

import argparse
import html
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
from pathlib import Path

BROWSERS = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
DEFAULT_SIZES = ((1400, 900), (390, 844))
_MARK = "gripkit-layout-check"

# The page is laid out in an iframe of the window's size (headless Chromium keeps its own window at
# least 500 px wide for --dump-dom, so the window alone cannot show a phone width); after layout the
# probe compares the page's width with the frame's viewport and lists the elements whose right edge,
# or whose content's, lies beyond it outside any box that scrolls horizontally (those make the page
# itself scroll).
_PROBE = """<!DOCTYPE html><html><head><meta charset="utf-8"></head><body style="margin:0">
<iframe id="page" src="page.html" style="border:0;width:%(w)dpx;height:%(h)dpx"></iframe>
<script>
document.getElementById('page').addEventListener('load', function () {
  var win = this.contentWindow, doc = win.document, vw = win.innerWidth, out = [];
  function scrollsX(el) {
    for (var p = el.parentElement; p; p = p.parentElement) {
      var ox = win.getComputedStyle(p).overflowX;
      if (ox === 'auto' || ox === 'scroll' || ox === 'hidden') return true;
    }
    return false;
  }
  var all = doc.body.getElementsByTagName('*');
  for (var i = 0; i < all.length; i++) {
    var el = all[i], r = el.getBoundingClientRect(), right = r.right;
    // content (a long word) spilling out of its box
    if (win.getComputedStyle(el).overflowX === 'visible')
      right = Math.max(right, r.left + el.scrollWidth);
    if (r.width > 0 && right > vw + 1 && !scrollsX(el)) {
      out.push({tag: el.tagName.toLowerCase(), cls: String(el.className || ''),
                right: Math.round(right),
                text: (el.textContent || '').trim().slice(0, 60)});
    }
  }
  var pre = document.createElement('pre');
  pre.id = '%(mark)s';
  pre.textContent = JSON.stringify({viewport: vw, scroll_width: doc.documentElement.scrollWidth,
                                    offenders: out.slice(0, 20), n_offenders: out.length});
  document.body.appendChild(pre);
});
</script></body></html>"""


class BrowserError(RuntimeError):
    """No browser, or the browser did not produce its output."""


def find_browser(explicit: str | None = None) -> str:
    """The browser to run: ``explicit``, ``$GRIPKIT_BROWSER``, or the first of :data:`BROWSERS` on
    the PATH."""
    for name in (explicit, os.environ.get("GRIPKIT_BROWSER"), *BROWSERS):
        if name and shutil.which(name):
            return shutil.which(name)
    raise BrowserError(f"no headless browser found (tried {', '.join(BROWSERS)}); install one "
                       "(Debian: apt-get install chromium) or pass --browser PATH / set "
                       "GRIPKIT_BROWSER")


def _run(browser: str, profile: str, size: tuple[int, int], url: str, *args: str,
         timeout: float = 120.0) -> str:
    cmd = [browser, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
           "--no-first-run",
           f"--user-data-dir={profile}", f"--window-size={size[0]},{size[1]}",
           "--run-all-compositor-stages-before-draw", "--virtual-time-budget=5000", *args, url]
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired as exc:
        raise BrowserError(f"{Path(browser).name} did not finish in {timeout:.0f} s") from exc
    if done.returncode != 0:
        last = (done.stderr.strip().splitlines() or ["no message"])[-1]
        raise BrowserError(f"{Path(browser).name} exited with {done.returncode}: {last}")
    return done.stdout


def png_size(path: Path) -> tuple[int, int]:
    """(width, height) in pixels from a PNG's IHDR chunk."""
    head = Path(path).read_bytes()[:24]
    if head[:8] != b"\x89PNG\r\n\x1a\n":
        raise BrowserError(f"{path} is not a PNG file")
    return struct.unpack(">II", head[16:24])


def parse_probe(dom: str) -> dict:
    """The measurement the probe script left in the dumped DOM."""
    m = re.search(r'<pre id="%s">(.*?)</pre>' % _MARK, dom, re.S)
    if m is None:
        raise BrowserError("the layout probe left no result in the page (did the page load?)")
    return json.loads(html.unescape(m.group(1)))


def check_report(page: Path, out: Path, sizes=DEFAULT_SIZES,
                 browser: str | None = None) -> list[dict]:
    """Screenshot ``page`` at each size into ``out`` and measure its layout; one dict per size:
    ``size``, ``screenshot``, ``screenshot_size``, ``viewport``, ``scroll_width``, ``overflow``
    (px the page is wider than the viewport), ``offenders``, ``n_offenders``."""
    exe = find_browser(browser)
    page = Path(page).resolve()
    out.mkdir(parents=True, exist_ok=True)
    results = []
    with tempfile.TemporaryDirectory(prefix="gripkit-browser-") as tmp:
        shutil.copyfile(page, Path(tmp) / "page.html")  # the probe reads it from the same folder
        profile = str(Path(tmp) / "profile")
        for w, h in sizes:
            shot = out / f"screenshot-{w}x{h}.png"
            _run(exe, profile, (w, h), page.as_uri(), f"--screenshot={shot}")
            if not shot.is_file():
                raise BrowserError(f"no screenshot written to {shot}")
            probed = Path(tmp) / f"probe-{w}x{h}.html"
            probed.write_text(_PROBE % dict(w=w, h=h, mark=_MARK), encoding="utf-8")
            probe = parse_probe(_run(exe, profile, (w + 40, h + 40), probed.as_uri(), "--dump-dom",
                                     "--allow-file-access-from-files"))
            results.append(dict(size=[w, h], screenshot=str(shot),
                                screenshot_size=list(png_size(shot)), **probe,
                                overflow=max(0, probe["scroll_width"] - probe["viewport"])))
    return results


def _parse_size(text: str) -> tuple[int, int]:
    m = re.fullmatch(r"\s*(\d+)\s*[xX×]\s*(\d+)\s*", text)
    if m is None or int(m.group(1)) < 200 or int(m.group(2)) < 200:
        raise argparse.ArgumentTypeError("expected WIDTHxHEIGHT in pixels (each ≥ 200), e.g. "
                                         f"390x844, found {text!r}")
    return int(m.group(1)), int(m.group(2))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("report", type=Path, help="report folder (with index.html) or an HTML file")
    ap.add_argument("--out", type=Path, help="folder for the screenshots (default: "
                                             "REPORT/screenshots)")
    ap.add_argument("--size", type=_parse_size, action="append",
                    help="window WIDTHxHEIGHT (repeatable; "
                    "default 1400x900 and 390x844)")
    ap.add_argument("--browser", help="browser executable (default: $GRIPKIT_BROWSER or "
                                      "chromium on the PATH)")
    ap.add_argument("--json", action="store_true", help="print the measurements as one JSON object")
    a = ap.parse_args(argv)
    page = a.report / "index.html" if a.report.is_dir() else a.report
    if not page.is_file():
        print("error: report: expected a report folder with index.html or an HTML file, "
              f"found {a.report}",
              file=sys.stderr)
        return 2
    out = a.out or page.parent / "screenshots"
    try:
        results = check_report(page, out, tuple(a.size or DEFAULT_SIZES), a.browser)
    except (BrowserError, OSError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    bad = [r for r in results if r["overflow"] > 0]
    if a.json:
        print(json.dumps({"page": str(page), "ok": not bad, "sizes": results}))
    for r in results:
        w, h = r["size"]
        line = (f"{w}x{h}: page {r['scroll_width']} px wide in a {r['viewport']} px viewport"
                f"{' (overflows by %d px)' % r['overflow'] if r['overflow'] else ''}; screenshot "
                f"{r['screenshot']}")
        print(line, file=sys.stderr if r["overflow"] else sys.stdout) if not a.json else None
        if r["overflow"]:
            for o in r["offenders"]:
                print(f"  {w}x{h}: <{o['tag']} class='{o['cls']}'> reaches {o['right']} "
                      f"px: {o['text']!r}",
                      file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
