"""The pages of ``armdyn serve`` as students and an instructor use them: headless
Chromium over the DevTools protocol (tests/cdp.py) against a real server, and axe-core
(tests/axe.py) for accessibility.

- the editor keeps its size whatever is pasted (a 5000-character line, wide math in
  the preview), and no page scrolls sideways, on a desktop and a phone;
- the problem statement is beside the editor: the variant's own ``problem.md`` (its
  first heading) with its drawing, switched with the exercise menu;
- every page (student, with and without a preview, submission, report, instructor
  login, the class, the class summary) has no critical, serious or moderate axe
  violation; the controls are reached with
  Tab in reading order; grading progress and the preview's state are live regions;
- every instructor page has a way back to the class;
- explanations show math as MathML, never LaTeX source; a step's expected value and
  its difference name the same reference (the hand-checked slips of
  examples/grading/README.md: F_2 has θ̇1 for θ̈1 in x against the student's own chain).

Screenshots go to the test's tmp directory; with ``ARMDYN_SERVE_SCREENSHOTS=DIR`` also
to DIR (docs/img is made this way).
"""

from __future__ import annotations

import json
import os
import re
import shutil
import time
from pathlib import Path

import pytest
from browser import require_chromium
from serve_support import EXERCISE, http, start_server

from armdyn.mathml import text_with_math

TOKEN = "pages-test-instructor-token"
LATEX_SOURCE = re.compile(r"\\[A-Za-z]{2,}")  # a TeX command left as text


# -- without a browser: the pieces the pages are made of


def visible_text(html: str) -> str:
    """The text a reader sees of ``html`` outside <math> (tags dropped, entities kept)."""
    return re.sub(r"<[^>]+>", "", re.sub(r"<math\b.*?</math>", "[math]", html, flags=re.S))


@pytest.mark.parametrize(
    "message, math_count, kept",
    [
        ("member 1 not checked: unknown symbol \\dot{V}_{1}", 1, "unknown symbol"),
        ("its formula member `-m_2 \\dot{v}_{C_2}^2` (member 1) is right", 1, "(member 1) is right"),
        ("uses \\int r_C dm = 0: C is the center of mass", 1, ": C is the center of mass"),
        ("\\mathbf{I} (bold, no subscript) read as the identity", 1, "(bold, no subscript)"),
        ("the slip is in \\frac{1}{2}\\omega_i^T \\mathbf{R}^{c\\...; the two sides differ", 1, "…; the two"),
        ("in 7-25 is  $E_{rot} = \\frac{1…", 1, "in 7-25 is"),
        ("compare v_dot_1 with F_2 and $\\tau_1$", 1, "compare v_dot_1 with F_2 and"),
    ],
)
def test_explanations_show_math_not_latex(message, math_count, kept):
    html = text_with_math(message)
    assert html.count("<math") == math_count, html
    shown = visible_text(html)
    assert not LATEX_SOURCE.search(shown), shown
    assert kept in shown.replace("&#x27;", "'"), shown


def test_plain_text_stays_text():
    for text in ("a factor l₁ missing in the z component", "left side = 10, right side = 50", "(copied, or not?)"):
        assert text_with_math(text) == text.replace("'", "&#x27;")


def test_statement_markdown_round_trip(tmp_path):
    """A variant's problem.md read back gives the blocks it was written from."""
    from armdyn.course.exercise import make_exercise
    from armdyn.course.statement import markdown_blocks, statement_markdown

    make_exercise("rp", tmp_path, seed=11, count=1)
    text = (tmp_path / "v001" / "problem.md").read_text(encoding="utf-8")
    blocks = markdown_blocks(text)
    assert statement_markdown(blocks) == text
    assert blocks[0] == ("h1", text.splitlines()[0][2:]) and any(b[0] == "table" or b[0] == "list" for b in blocks)


def test_nav_bar_in_a_self_contained_page():
    from armdyn.htmlpage import page
    from armdyn.serve.pages import INSTRUCTOR_LINKS, report_links, with_nav

    html = with_nav(page("t", "<p>x</p>"), INSTRUCTOR_LINKS)
    body = html[html.index("<body>") :]
    assert body.index('href="/instructor"') < body.index("<main")
    token = "A" * 43
    assert report_links("sid1", token, False)[0][0] == f"/submissions/sid1?t={token}"
    assert report_links("sid1", '"><script>', False)[0][0] == "/submissions/sid1"  # not a token: dropped


def test_statement_route_names_exercises_only(tmp_path, variants):
    """The statement of an exercise by its id from the whitelist; nothing else."""
    from starlette.testclient import TestClient

    from armdyn.serve.app import Settings, build_app
    from armdyn.serve.exercises import catalogue

    app = build_app(Settings(db=f"sqlite:///{tmp_path / 's.db'}", exercises=catalogue(str(variants)), workers=1))
    c = TestClient(app)  # no lifespan: no worker is needed to show a statement
    first = (variants / "v001" / "problem.md").read_text(encoding="utf-8").splitlines()[0][2:]
    r = c.get("/exercises/v001/statement")
    assert r.status_code == 200 and f"<h3>{first}</h3>" in r.text and "<script" not in r.text
    assert "content-security-policy" in r.headers
    for bad in ("/exercises/nope/statement", "/exercises/..%2Fv001/statement", "/exercises/model.yaml/statement"):
        assert c.get(bad).status_code == 404, bad


# -- in a browser


@pytest.fixture(scope="module")
def variants(tmp_path_factory):
    from armdyn.course.exercise import make_exercise

    out = tmp_path_factory.mktemp("variants")
    make_exercise("rp", out, seed=5, count=1)
    return out


@pytest.fixture(scope="module")
def server(tmp_path_factory, variants):
    require_chromium()
    pytest.importorskip("websocket")
    tmp = tmp_path_factory.mktemp("serve-pages")
    srv = start_server(
        tmp, f"sqlite:///{tmp / 'serve.db'}", workers=1, token=TOKEN, extra=("--exercises", str(variants))
    )
    yield srv
    assert srv.stop() in (0, -15), srv.log.read_text()[-2000:]


@pytest.fixture
def browser(tmp_path):
    from cdp import Browser

    b = Browser(require_chromium())
    yield b
    b.close()


@pytest.fixture(scope="module")
def graded(server):
    """The exercise graded through the API (the hand-checked slips): its id and token."""
    status, body = http(
        "POST", f"{server.base}/api/grade?student=Ada", EXERCISE.read_bytes(), {"content-type": "text/markdown"}
    )
    assert status == 200 and body["first_wrong"] == "v_dot_1", body
    return body


def shoot(page, name: str, tmp_path: Path, full: bool = True) -> Path:
    shot = tmp_path / name
    page.screenshot(shot, full=full)
    keep = os.environ.get("ARMDYN_SERVE_SCREENSHOTS")
    if keep:
        Path(keep).mkdir(parents=True, exist_ok=True)
        shutil.copy(shot, Path(keep) / name)
    return shot


def viewport(page, width: int, height: int, mobile: bool = False) -> None:
    page.b.call(
        "Emulation.setDeviceMetricsOverride",
        {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": mobile},
        page.session,
    )


def paste(page, text: str) -> None:
    page.eval(
        f"(function () {{ var t = document.getElementById('markdown'); t.focus(); t.value = {json.dumps(text)};"
        " t.dispatchEvent(new Event('input')); return true; })()"
    )


BOXES = """JSON.stringify((function () {
  function r(id) { var b = document.getElementById(id).getBoundingClientRect();
    return {x: b.left, y: b.top, w: b.width, h: b.height}; }
  return {editor: r('markdown'), preview: r('preview'), statement: r('statement'),
          scroll: document.documentElement.scrollWidth, inner: window.innerWidth};
})())"""


def test_editor_keeps_its_size_whatever_is_pasted(server, browser, tmp_path, variants):
    page = browser.page()
    # (width, a phone?, the editor's least share of the width, screenshot)
    layouts = (
        (1280, False, 0.25, "serve-student.png"),
        (1000, False, 0.4, None),
        (390, True, 0.8, "serve-student-phone.png"),
    )
    for width, mobile, share, name in layouts:
        viewport(page, width, 900, mobile)
        page.goto(server.base + "/")
        if width > 1000:  # the variant (an RP arm too): its statement has a drawing
            page.eval(
                "var s = document.getElementById('exercise'); s.value = 'v001';"
                " s.dispatchEvent(new Event('change')); true"
            )
            page.wait_for("!!document.querySelector('#statement img')", 30, "the variant's statement")
        before = json.loads(page.eval(BOXES))
        long_line = "$$\\tau_1 = " + " + ".join(f"m_{{{k}}} l_{{{k}}}^2 \\ddot{{\\theta}}_1" for k in range(200)) + "$$"
        text = (variants / "v001" / "solution.md") if width > 1000 else EXERCISE
        paste(page, text.read_text(encoding="utf-8") + "\n" + long_line + "\n" + "x" * 5000 + "\n")
        page.wait_for("document.querySelectorAll('#preview math').length > 10", 60, "the preview")
        after = json.loads(page.eval(BOXES))
        for key in ("w", "h"):
            assert abs(after["editor"][key] - before["editor"][key]) <= 1, (width, before, after)
        assert after["editor"]["w"] >= share * width, after
        assert after["editor"]["h"] >= 240, after
        assert after["scroll"] <= after["inner"], f"the page scrolls sideways at {width} px: {after}"
        if width > 1000:  # the statement, the editor and the preview side by side
            assert after["statement"]["x"] + after["statement"]["w"] <= after["editor"]["x"] + 1
            assert after["editor"]["x"] + after["editor"]["w"] <= after["preview"]["x"] + 1
            assert abs(after["statement"]["y"] - after["editor"]["y"]) < 40
        elif width == 1000:  # the statement above, the editor and the preview side by side
            assert after["statement"]["y"] + after["statement"]["h"] <= after["editor"]["y"]
            assert after["editor"]["x"] + after["editor"]["w"] <= after["preview"]["x"] + 1
        if name:
            page.eval("document.getElementById('preview').scrollTop = 900; true")
            shoot(page, name, tmp_path, full=False)
        hint = page.eval("document.getElementById('hint').textContent")
        assert "on the right" not in hint and "How each equation is read" in hint


def test_statement_follows_the_exercise_menu(server, browser, variants):
    page = browser.page()
    page.goto(server.base + "/")
    first_line = (variants / "v001" / "problem.md").read_text(encoding="utf-8").splitlines()[0][2:]
    assert "rp-arm" in page.eval("document.getElementById('statement').textContent")
    page.eval(
        "var s = document.getElementById('exercise'); s.value = 'v001'; s.dispatchEvent(new Event('change')); true"
    )
    page.wait_for(
        "(document.querySelector('#statement h3') || {}).textContent === " + json.dumps(first_line),
        30,
        "the variant's statement",
    )
    drawing = json.loads(
        page.eval(
            "JSON.stringify((function () { var i = document.querySelector('#statement img');"
            " return i ? {w: i.naturalWidth, alt: i.alt, src: i.src.slice(0, 26)} : null; })())"
        )
    )
    assert drawing and drawing["w"] > 100 and drawing["alt"] and drawing["src"] == "data:image/svg+xml;base64,"
    assert page.eval("document.querySelectorAll('#statement math').length") > 3
    prose = page.eval(  # what to type is shown as code on purpose; the rest has no LaTeX source
        "(function () { var c = document.getElementById('statement').cloneNode(true);"
        " c.querySelectorAll('code, pre, math').forEach(e => e.remove()); return c.textContent; })()"
    )
    assert not LATEX_SOURCE.search(prose), prose


def test_keyboard_reaches_every_control_in_order(server, browser):
    page = browser.page()
    page.goto(server.base + "/")
    seen = []
    for _ in range(16):
        for kind in ("keyDown", "keyUp"):
            page.b.call(
                "Input.dispatchKeyEvent",
                {"type": kind, "key": "Tab", "code": "Tab", "windowsVirtualKeyCode": 9},
                page.session,
            )
        seen.append(page.eval("document.activeElement.id || document.activeElement.tagName"))
    want = ["exercise", "student", "upload", "statement", "markdown", "preview", "grade-button"]
    at = [seen.index(w) for w in want]  # ValueError: a control Tab never reached
    assert at == sorted(at), seen
    assert seen[0] != "markdown" and "BODY" not in seen[: at[-1]], seen


def test_live_regions_say_what_happens(server, browser):
    page = browser.page()
    page.goto(server.base + "/")
    live = json.loads(page.eval("JSON.stringify(Array.from(document.querySelectorAll('[aria-live]')).map(e => e.id))"))
    assert {"preview-state", "grade-state"} <= set(live), live
    paste(page, EXERCISE.read_text(encoding="utf-8"))
    said = page.wait_for(
        "/steps? read/.test(document.getElementById('preview-state').textContent)"
        " && document.getElementById('preview-state').textContent",
        60,
        "the preview's state",
    )
    n = page.eval("document.querySelectorAll('#preview .step:not(.none)').length")
    assert said == f"({n} steps read)" and n >= 10
    page.eval("document.getElementById('grade-button').click(); true")
    page.wait_for("location.pathname.startsWith('/submissions/')", 90, "the submission page")


def axe_clean(page, script, what: str) -> list:
    from axe import run_axe

    found = run_axe(page, script)
    bad = [v for v in found if v[0] in ("serious", "critical", "moderate")]
    assert not bad, f"{what}: {bad}"
    return found


def login(page, server) -> None:
    page.goto(server.base + "/instructor")
    page.eval(
        f"document.getElementById('token').value = {json.dumps(TOKEN)}; "
        "document.querySelector('#login button').click(); true"
    )
    page.wait_for("!!document.getElementById('gradebook-link')", 30, "the instructor page")


def test_every_page_is_accessible_and_leads_back(server, browser, graded, tmp_path):
    from axe import require_axe

    script = require_axe()
    page = browser.page()
    page.b.call("Page.setBypassCSP", {"enabled": True}, page.session)  # for axe's script alone
    sub = f"{server.base}/submissions/{graded['id']}?t={graded['token']}"
    report = f"{server.base}/submissions/{graded['id']}/report.html?t={graded['token']}"
    pages = [
        ("student page", server.base + "/", "serve-student-full.png"),
        ("submission", sub, "serve-submission.png"),
        ("one-page report", report, None),
        ("instructor login", server.base + "/instructor", "serve-login.png"),
    ]
    for what, url, shot in pages:
        page.goto(url)
        axe_clean(page, script, what)
        links = page.eval("Array.from(document.querySelectorAll('nav a')).map(a => a.getAttribute('href'))")
        assert "/" in links or any(h.startswith("/submissions/") for h in links), (what, links)
        if shot:
            shoot(page, shot, tmp_path)
    page.goto(server.base + "/")  # the student page again, its preview full of math
    paste(page, EXERCISE.read_text(encoding="utf-8"))
    page.wait_for("document.querySelectorAll('#preview math').length > 10", 60, "the preview")
    axe_clean(page, script, "student page with its preview")
    login(page, server)
    for what, path, shot in (
        ("the class", "/instructor", "serve-class.png"),
        ("class summary", "/instructor/summary", "serve-summary.png"),
        ("submission (instructor)", sub[len(server.base) :], None),
        ("report (instructor)", report[len(server.base) :], None),
    ):
        page.goto(server.base + path)
        axe_clean(page, script, what)
        back = page.eval("Array.from(document.querySelectorAll('nav a, .back a')).map(a => a.getAttribute('href'))")
        assert "/instructor" in back, (what, back)
        if shot:
            shoot(page, shot, tmp_path)


def test_report_explains_in_math_and_names_its_reference(server, browser, graded, tmp_path):
    page = browser.page()
    page.goto(f"{server.base}/submissions/{graded['id']}?t={graded['token']}")
    page.wait_for("!!document.querySelector('.report .step.first')", 60, "the report")
    said = page.eval(
        "Array.from(document.querySelectorAll('.report .message, .report .verdict .sub, .report .where'))"
        ".map(e => { var c = e.cloneNode(true); c.querySelectorAll('math').forEach(m => m.remove());"
        " return c.textContent; }).join('\\n')"
    )
    assert not LATEX_SOURCE.search(said), LATEX_SOURCE.findall(said)[:5]
    # the unnumbered task's title in full (the text's line under which its equations sit)
    title = next(line.strip() for line in EXERCISE.read_text(encoding="utf-8").splitlines() if "by Lagrangian" in line)
    assert len(title) > 40 and title in page.eval("document.querySelector('.report').textContent")
    # F_2: the student's line "$$F_2^2 = -m_2 ..." (θ̇1 for θ̈1, against their own chain)
    lines = EXERCISE.read_text(encoding="utf-8").splitlines()
    f2 = next(i + 1 for i, line in enumerate(lines) if line.startswith("$$F_2^2"))
    card = json.loads(
        page.eval(
            "JSON.stringify((function () { var li = Array.from(document.querySelectorAll('.report li.step')).find("
            f"li => /\\bline {f2}\\b/.test((li.querySelector('.where') || {{}}).textContent || ''));"
            " return li ? {caps: Array.from(li.querySelectorAll('.side .cap')).map(c => c.textContent),"
            " status: li.className, id: li.id} : null; })())"
        )
    )
    assert card is not None and "st-wrong" in card["status"], card
    caps = card["caps"]
    assert "expected from your own earlier steps" in caps, caps
    assert "difference: yours \u2212 expected from your own earlier steps" in caps, caps
    assert "expected (from the exercise's model)" in caps, caps
    page.eval(f"document.getElementById({json.dumps(card['id'])}).scrollIntoView(); true")
    time.sleep(0.3)
    shoot(page, "serve-report-step.png", tmp_path, full=False)


def test_reference_of_a_slip_against_the_students_own_chain():
    """F_2 of the exercise (hand-checked, examples/grading/README.md): its x component
    has -θ̇1 d2 where the student's own v̇_C2 gives -θ̈1 d2. The reference shown is
    the student's own chain, and it is F_2 = -m2 v̇_C2 with that one term put right,
    worked out here by hand from the student's line."""
    import sympy as sp

    from armdyn.grading import grade
    from armdyn.grading.html import OWN_REFERENCE, reference
    from armdyn.grading.reader import read_markdown

    report = grade(read_markdown(str(EXERCISE)))
    step = next(s for s in report.steps if s.name == "F_2")
    value, name = reference(step)
    assert name == OWN_REFERENCE
    t, td, tdd, d, dd, m2, g = sp.symbols("theta1 theta1_dot theta1_ddot d2 d2_dot m2 g")
    by_hand_x = -m2 * (-tdd * d - 2 * td * dd + g * sp.sin(t))
    names = {s.name: s for s in sp.Matrix(value).free_symbols}
    x = sp.Matrix(value)[0].subs({names[k.name]: k for k in (t, td, tdd, d, dd, m2, g) if k.name in names})
    assert sp.simplify(x - by_hand_x) == 0, x
    assert sp.simplify(sp.Matrix(step.expected)[0] - by_hand_x) != 0  # the exercise's value differs
