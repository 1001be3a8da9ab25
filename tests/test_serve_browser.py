"""``armdyn serve`` in a real browser: headless Chromium (Debian's chromium-headless-shell)
driven over the DevTools protocol (tests/cdp.py), against a real server process.

- a student pastes the exercise, sees the live preview, presses Grade and gets the
  report with the first wrong step highlighted (the step and line found here from the
  text itself, the hand-checked verdict of examples/grading/README.md: v_dot_1);
- script in a submission (raw HTML, LaTeX \\text and \\href, the student's name) never
  runs: no dialog, no global set, no live element, on every page that shows it;
- the instructor logs in with the token and downloads the gradebook.

With ``ARMDYN_SERVE_SCREENSHOT=path.png`` the student's page is also saved there
(tests/test_serve_pages.py makes the screenshots of docs/img).
"""

from __future__ import annotations

import csv
import io
import json
import os
import time
import urllib.parse

import pytest
from browser import require_chromium
from cdp import Browser
from serve_support import EXERCISE, http, start_server

pytest.importorskip("starlette")
pytest.importorskip("uvicorn")
pytest.importorskip("websocket")

TOKEN = "browser-test-instructor-token"
PAYLOADS = (
    "---\nrobot: rp-arm\n---\n"
    "<script>window.__xss = 1; alert('raw script')</script>\n"
    "<img src=x onerror=\"window.__xss = 2; alert('img')\">\n"
    "$$\\omega_1^1 = \\begin{pmatrix} 0 \\\\ 0 \\\\ \\dot{\\theta}_1 \\end{pmatrix}$$\n"
    "$$\\tau_1 = \\text{<img src=x onerror=alert('text')>} + \\href{javascript:alert('href')}{x}$$\n"
    "$$\\dot{v}_1^1 = \\begin{pmatrix} \\text{</math><script>alert('close')</script>} \\\\ 0 \\\\ 0 \\end{pmatrix}$$\n"
)
NO_SCRIPT = """(function () {
  var bad = [];
  document.querySelectorAll('script').forEach(function (s) {
    if (!s.src || new URL(s.src).pathname !== '/static/app.js') bad.push('script:' + s.outerHTML.slice(0, 80)); });
  document.querySelectorAll('*').forEach(function (e) {
    for (var i = 0; i < e.attributes.length; i++) {
      var a = e.attributes[i];
      if (/^on/i.test(a.name) || /^\\s*javascript:/i.test(a.value)) bad.push(e.tagName + '[' + a.name + ']');
    }
  });
  document.querySelectorAll('img, iframe, object, embed').forEach(function (e) { bad.push(e.tagName); });
  return JSON.stringify({bad: bad, xss: typeof window.__xss === 'undefined' ? null : window.__xss});
})()"""


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    require_chromium()
    tmp = tmp_path_factory.mktemp("serve-browser")
    srv = start_server(tmp, f"sqlite:///{tmp / 'serve.db'}", workers=1, token=TOKEN)
    yield srv
    # uvicorn re-raises SIGTERM after its graceful shutdown: -15 is a clean stop
    assert srv.stop() in (0, -15), srv.log.read_text()[-2000:]


@pytest.fixture
def browser(tmp_path):
    b = Browser(require_chromium(), downloads=str(tmp_path / "downloads"))
    yield b
    b.close()


def expected_first_wrong_line(text: str) -> int:
    """The line of the $$ block holding the student's v_dot_1 (the hand-checked first slip)."""
    lines = text.splitlines()
    return next(
        i + 1
        for i, line in enumerate(lines)
        if "\\dot{\\boldsymbol{v}}_1^1 &=" in line and line.lstrip().startswith("$$")
    )


def test_student_submits_and_sees_first_wrong_step(server, browser, tmp_path):
    text = EXERCISE.read_text(encoding="utf-8")
    page = browser.page()
    page.goto(server.base + "/")
    page.eval(f"""(function () {{ var t = document.getElementById('markdown'); t.value = {json.dumps(text)};
        t.dispatchEvent(new Event('input')); document.getElementById('student').value = 'Ada Lovelace';
        return true; }})()""")
    n = page.wait_for("document.querySelectorAll('#preview math').length", 60, "the live preview")
    steps = page.eval("Array.from(document.querySelectorAll('#preview .step:not(.none)')).map(e => e.textContent)")
    assert n >= 10 and "v_dot_1" in steps and "tau_1" in steps, steps
    shot = os.environ.get("ARMDYN_SERVE_SCREENSHOT")
    if shot:
        page.eval(
            "var t = document.getElementById('markdown'); document.getElementById('preview').scrollTop = 1400;"
            "t.scrollTop = t.scrollHeight * t.value.indexOf('\\\\begin{split}') / t.value.length - 60"
        )
        page.screenshot(shot, full=False)
    page.eval("document.getElementById('grade-button').click()")
    page.wait_for(
        "location.pathname.startsWith('/submissions/') && document.readyState === 'complete'", 90, "the submission page"
    )
    page.wait_for("!!document.querySelector('.report .step.first')", 90, "the report")
    got = json.loads(
        page.eval("""JSON.stringify((function () {
        var first = document.querySelector('.report .step.first');
        var link = document.querySelector('.report .verdict.fail a');
        var hl = Array.from(first.querySelectorAll('mtd.hl')).map(c => getComputedStyle(c).backgroundColor);
        return {cls: first.className, id: first.id, href: link && link.getAttribute('href'),
                verdict: document.querySelector('.report .verdict').textContent, hl: hl,
                shadow: getComputedStyle(first).boxShadow};
    })())""")
    )
    assert "st-wrong" in got["cls"] and got["href"] == "#" + got["id"]
    assert f"(line {expected_first_wrong_line(text)})" in got["verdict"]
    assert got["hl"] and all(bg not in ("rgba(0, 0, 0, 0)", "transparent") for bg in got["hl"]), got
    assert got["shadow"] != "none"
    # the earlier submission is listed on the student's page (same browser, its key cookie)
    page.goto(server.base + "/")
    assert page.wait_for("document.querySelector('#mine') && document.querySelector('#mine').textContent")
    assert not browser.dialogs


def test_script_in_a_submission_never_runs(server, browser):
    q = urllib.parse.urlencode({"student": "<script>alert('name')</script><img src=x onerror=alert(5)>"})
    status, body = http("POST", f"{server.base}/api/grade?{q}", PAYLOADS.encode(), {"content-type": "text/markdown"})
    assert status == 200 and body["status"] == "done", body
    page = browser.page()
    pages = [server.base + body["url"], f"{server.base}/submissions/{body['id']}/report.html?t={body['token']}"]
    for url in pages:
        page.goto(url)
        time.sleep(0.5)
        found = json.loads(page.eval(NO_SCRIPT))
        assert found == {"bad": [], "xss": None}, (url, found)
    shown = page.eval("document.body.innerText")
    assert "report" in shown.lower()
    # the student's raw text is shown as text on the submission page
    page.goto(pages[0])
    assert "window.__xss = 1" in page.eval("document.querySelector('pre.source').textContent")
    # the live preview of the same text
    page.goto(server.base + "/")
    page.eval(f"""(function () {{ var t = document.getElementById('markdown'); t.value = {json.dumps(PAYLOADS)};
        t.dispatchEvent(new Event('input')); return true; }})()""")
    page.wait_for("document.querySelectorAll('#preview li').length >= 3", 60, "the preview")
    time.sleep(0.5)
    assert json.loads(page.eval(NO_SCRIPT)) == {"bad": [], "xss": None}
    # the instructor's table shows the name
    login(page, server)
    assert json.loads(page.eval(NO_SCRIPT)) == {"bad": [], "xss": None}
    assert "<script>alert('name')</script>" in page.eval("document.getElementById('class').textContent")
    assert browser.dialogs == []


def login(page, server):
    page.goto(server.base + "/instructor")
    page.eval(
        f"document.getElementById('token').value = {json.dumps(TOKEN)}; "
        "document.querySelector('#login button').click(); true"
    )
    page.wait_for("!!document.getElementById('gradebook-link')", 30, "the instructor page")


def test_instructor_downloads_gradebook(server, browser, tmp_path):
    text = EXERCISE.read_text(encoding="utf-8")
    status, body = http(
        "POST", f"{server.base}/api/grade?student=Grace", text.encode(), {"content-type": "text/markdown"}
    )
    assert status == 200 and body["first_wrong"] == "v_dot_1"
    page = browser.page()
    login(page, server)
    page.eval("document.getElementById('gradebook-link').click(); true")
    target = tmp_path / "downloads" / "gradebook.csv"
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline and not target.exists():
        time.sleep(0.2)
    assert target.exists(), f"no download; files: {list((tmp_path / 'downloads').glob('*'))}"
    rows = list(csv.DictReader(io.StringIO(target.read_text(encoding="utf-8"))))
    grace = [r for r in rows if r["student"] == "Grace"]
    assert grace and grace[0]["first_wrong"] == "v_dot_1" and grace[0]["variant"] == "rp-arm"
