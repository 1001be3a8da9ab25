"""Render armdyn's HTML reports in a real browser (headless Chromium) and measure the math.

Used by tests/test_html_report.py; a new test of a report is a few lines::

    from browser import require_chromium, render, assert_math_rendered

    def test_my_report(tmp_path):
        chromium = require_chromium()               # skips this test alone if absent
        page = tmp_path / "report.html"
        page.write_text(report_html(report), encoding="utf-8")
        shot = render(page, chromium, screenshot=tmp_path / "report.png")
        assert_math_rendered(shot, min_count=10)

How: the page is copied with a small measuring script appended (the report itself has
no script, and its Content-Security-Policy, which would block the script, is taken out
of the copy) and loaded from a file with ``--dump-dom``; the script writes, as JSON, the
bounding box of every ``<math>`` element, the number of ``<merror>`` elements, any
math whose text still looks like LaTeX source (a backslash: a conversion that did not
happen), and the box and background of each highlighted table cell (``mtd.hl``).
A second run of the original page (policy and all) takes a screenshot of the full page height.
Chromium runs headless, with a fresh profile, no first-run, sync, component updates
or background networking; the pages load nothing from the network.

CI needs a Chromium binary and a math font: ``apt-get install -y chromium-headless-shell
fonts-dejavu-extra`` (Debian; ``chromium`` works too). ``ARMDYN_CHROMIUM`` may name
the binary.
"""

from __future__ import annotations

import html
import json
import os
import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import pytest

INSTALL_HINT = (
    "no Chromium binary found: install one with "
    "`apt-get install -y chromium-headless-shell fonts-dejavu-extra` "
    "(or `apt-get install -y chromium`), or set ARMDYN_CHROMIUM=/path/to/chromium"
)
CANDIDATES = ("chromium-headless-shell", "chromium", "chromium-browser", "google-chrome", "headless_shell")
FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
    "--mute-audio",
    # the reports are self-contained: any host lookup is a bug, so make it fail
    "--host-resolver-rules=MAP * ~NOTFOUND",
)

_MEASURE = """
<script>
(function () {
  function box(e) { var r = e.getBoundingClientRect(); return {w: r.width, h: r.height, x: r.left, y: r.top + window.scrollY}; }
  var maths = Array.prototype.map.call(document.querySelectorAll("math"), function (m) {
    var b = box(m); b.text = m.textContent.slice(0, 80); return b; });
  var hl = Array.prototype.map.call(document.querySelectorAll("mtd.hl"), function (c) {
    var b = box(c); b.background = getComputedStyle(c).backgroundColor; return b; });
  // a column vector: stretchy parentheses around an mtable of 3 rows or more
  var fences = [];
  Array.prototype.forEach.call(document.querySelectorAll("mrow > mtable"), function (t) {
    var open = t.previousElementSibling;
    if (open && open.tagName.toLowerCase() === "mo" && open.getAttribute("stretchy") === "true"
        && t.querySelectorAll(":scope > mtr").length >= 3) {
      fences.push({paren: open.getBoundingClientRect().height, table: t.getBoundingClientRect().height});
    }
  });
  var out = {
    fences: fences,
    math: maths,
    merror: document.querySelectorAll("merror").length,
    latex: maths.filter(function (m) { return m.text.indexOf("\\\\") >= 0; }).map(function (m) { return m.text; }),
    hl: hl,
    height: Math.ceil(document.documentElement.scrollHeight),
    width: Math.ceil(document.documentElement.scrollWidth),
    title: document.title,
    bodyText: document.body ? document.body.innerText.slice(0, 20000) : ""
  };
  var pre = document.createElement("pre");
  pre.id = "armdyn-measure";
  pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
})();
</script>
"""


@dataclass
class Rendered:
    """What the browser made of a page.

    math:       one dict per ``<math>``: w, h (CSS px), x, y, text (first 80 characters)
    merror:     number of ``<merror>`` elements
    latex:      texts of math elements that still contain a backslash (unconverted LaTeX)
    hl:         one dict per highlighted cell (``mtd.hl``): w, h, x, y, background
    fences:     one dict per column vector of 3+ rows in stretchy parentheses: the
                heights (CSS px) of its opening parenthesis and of its table
    height, width: the page's scroll size in CSS px
    body_text:  the page's visible text (first 20000 characters)
    screenshot: the PNG written, or None
    """

    math: list = field(default_factory=list)
    merror: int = 0
    latex: list = field(default_factory=list)
    hl: list = field(default_factory=list)
    fences: list = field(default_factory=list)
    height: int = 0
    width: int = 0
    title: str = ""
    body_text: str = ""
    screenshot: Path | None = None


_CSP_META = re.compile(r'<meta http-equiv="Content-Security-Policy"[^>]*>\n?', re.IGNORECASE)


def without_csp(source: str) -> str:
    """The page without its Content-Security-Policy ``<meta>`` (so that a test's own
    script may run in it)."""
    return _CSP_META.sub("", source)


def find_chromium() -> str | None:
    """Path of a Chromium binary (``ARMDYN_CHROMIUM`` first), or None."""
    env = os.environ.get("ARMDYN_CHROMIUM")
    if env:
        return env if (os.path.isfile(env) and os.access(env, os.X_OK)) or shutil.which(env) else None
    for name in CANDIDATES:
        path = shutil.which(name)
        if path:
            return path
    return None


def require_chromium() -> str:
    """The Chromium binary, or skip the calling test (alone) saying how to install one."""
    path = find_chromium()
    if path is None:
        pytest.skip(INSTALL_HINT)
    return path


def _run(chromium: str, args: list[str], timeout: float) -> subprocess.CompletedProcess:
    with tempfile.TemporaryDirectory(prefix="armdyn-chromium-") as profile:
        cmd = [chromium, *FLAGS, f"--user-data-dir={profile}", *args]
        try:
            return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, check=False)
        except subprocess.TimeoutExpired:
            raise AssertionError(f"Chromium did not finish within {timeout} s: {' '.join(cmd)}") from None


def render(
    page: str | Path,
    chromium: str,
    screenshot: str | Path | None = None,
    width: int = 1000,
    timeout: float = 90.0,
    max_height: int = 30000,
) -> Rendered:
    """Load the HTML file ``page`` in headless Chromium at ``width`` CSS px, measure its
    math (see :class:`Rendered`) and, when ``screenshot`` is given, save a PNG of the
    whole page there."""
    page = Path(page).resolve()
    source = without_csp(page.read_text(encoding="utf-8"))
    with tempfile.TemporaryDirectory(prefix="armdyn-page-") as tmp:
        probe = Path(tmp) / page.name
        at = source.rfind("</body>")
        probe.write_text(source[:at] + _MEASURE + source[at:] if at >= 0 else source + _MEASURE, encoding="utf-8")
        done = _run(chromium, [f"--window-size={width},900", "--dump-dom", probe.as_uri()], timeout)
    m = re.search(r'<pre id="armdyn-measure">(.*?)</pre>', done.stdout, re.S)
    if m is None:
        raise AssertionError(
            f"Chromium produced no measurement (exit {done.returncode}); stderr:\n{done.stderr[-2000:]}"
        )
    data = json.loads(html.unescape(m.group(1)))
    out = Rendered(
        math=data["math"],
        merror=data["merror"],
        latex=data["latex"],
        hl=data["hl"],
        fences=data["fences"],
        height=data["height"],
        width=data["width"],
        title=data["title"],
        body_text=data["bodyText"],
    )
    if screenshot is not None:
        shot = Path(screenshot).resolve()
        shot.parent.mkdir(parents=True, exist_ok=True)
        if shot.exists():
            shot.unlink()
        height = max(200, min(out.height, max_height))
        done = _run(chromium, [f"--window-size={width},{height}", f"--screenshot={shot}", page.as_uri()], timeout)
        if not shot.exists() or shot.stat().st_size == 0:
            raise AssertionError(
                f"Chromium wrote no screenshot (exit {done.returncode}); stderr:\n{done.stderr[-2000:]}"
            )
        out.screenshot = shot
    return out


def dump_dom(page: str | Path, chromium: str, timeout: float = 90.0, budget_ms: int = 3000) -> str:
    """The DOM of the HTML file ``page`` as Chromium serializes it after loading it as
    it is (no script added, its own policy in force) and letting ``budget_ms`` of
    virtual time pass (timers, image errors, load events run)."""
    done = _run(chromium, [f"--virtual-time-budget={budget_ms}", "--dump-dom", Path(page).resolve().as_uri()], timeout)
    if "<html" not in done.stdout:
        raise AssertionError(f"Chromium dumped no document (exit {done.returncode}); stderr:\n{done.stderr[-2000:]}")
    return done.stdout


def assert_math_rendered(r: Rendered, min_count: int = 1) -> None:
    """Every ``<math>`` element has a non-zero box, none is an ``<merror>``, none shows
    LaTeX source; and there are at least ``min_count`` of them."""
    assert len(r.math) >= min_count, f"expected at least {min_count} math elements, the page has {len(r.math)}"
    empty = [m for m in r.math if not (m["w"] > 0 and m["h"] > 0)]
    assert not empty, f"{len(empty)} math elements rendered with zero size, e.g. {empty[:3]}"
    assert r.merror == 0, f"{r.merror} <merror> elements in the page"
    assert not r.latex, f"math showing LaTeX source (not converted): {r.latex[:3]}"


def assert_parentheses_stretch(r: Rendered, min_count: int = 1) -> None:
    """The parentheses of column vectors grow to the vector's height (this needs a font
    with an OpenType MATH table: Debian's fonts-dejavu-extra has DejaVu Math TeX Gyre)."""
    assert len(r.fences) >= min_count, f"expected at least {min_count} column vectors, found {len(r.fences)}"
    short = [f for f in r.fences if not f["paren"] >= 0.8 * f["table"] > 0]
    assert not short, (
        f"{len(short)} parentheses do not stretch around their vector, e.g. {short[:3]}: "
        "is a math font installed? (apt-get install -y fonts-dejavu-extra)"
    )
