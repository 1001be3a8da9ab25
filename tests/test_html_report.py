"""HTML reports: the grade report and ``armdyn derive --format html``.

The structure of the pages is checked by parsing them (xml.etree for the MathML, the
standard library's HTML parser for the page), and the pages are rendered in headless
Chromium (tests/browser.py): every <math> element must have a non-zero box, none an
<merror>, none raw LaTeX, and the wrong rows must be painted. The browser tests skip
alone when no Chromium is installed.

The grade report here is built by hand, shaped like the verdict on the RP-arm
exercise (docs/exercise.md, part 2): the student's values are the exercise's own lines,
the expected values are worked out by hand from the exercise's frames (point masses
m1 at l1 along x1 and m2 at the slider's tip, gravity g along -y0).
"""

from __future__ import annotations

import os
import re
from html.parser import HTMLParser
from pathlib import Path

import pytest
import sympy as sp
from browser import assert_math_rendered, assert_parentheses_stretch, render, require_chromium

from armdyn.grading.html import report_html, repr_html
from armdyn.grading.verdict import STATUSES, GradeReport, StepVerdict

ROOT = Path(__file__).resolve().parents[1]
SHOTS = Path(os.environ.get("ARMDYN_SCREENSHOTS", ROOT / "target" / "screenshots"))

th, thd, thdd, d, dd, ddd, l1, m1, m2, g = sp.symbols("theta1 theta1_dot theta1_ddot d2 d2_dot d2_ddot l1 m1 m2 g")
s1, c1 = sp.sin(th), sp.cos(th)
V = sp.Matrix

STUDENT_LATEX = {
    th: r"\theta_1",
    thd: r"\dot{\theta}_1",
    thdd: r"\ddot{\theta}_1",
    d: "d_2",
    dd: r"\dot{d}_2",
    ddd: r"\ddot{d}_2",
    l1: "l_1",
    m1: "m_1",
    m2: "m_2",
    g: "g",
}

HOSTILE = r"m_2^2 = \mathbf{P}_2^2 \times f_2^2 </pre><script>alert('x')</script> & <b>bold</b>"


def _step(name, key, status, label, expected, got, components=(), **kw):
    diff = None
    if (
        expected is not None
        and got is not None
        and status not in ("correct", "correct-by-convention", "correct-but-unsupported")
    ):
        diff = (got - expected).applyfunc(sp.expand) if isinstance(got, sp.MatrixBase) else sp.expand(got - expected)
    return StepVerdict(
        name=name,
        key=key,
        link=kw.pop("link", ""),
        status=status,
        label=label,
        source=kw.pop("source", f"{label} = ..."),
        line=kw.pop("line", 0),
        expected=expected,
        got=got,
        difference=diff,
        components=list(components),
        **kw,
    )


def exercise_like_report() -> GradeReport:
    """A GradeReport with every status, a wrong vector component, a convention, an
    unrecognised line with hostile text and a scalar tau."""
    vd1_true = V([-l1 * thd**2 + g * s1, l1 * thdd + g * c1, 0])
    vd1_student = V([g * s1, l1 * thdd + g * c1, 0])  # drops -l1*theta1_dot^2 in x
    vc2_true = V([-d * thdd - l1 * thd**2 - 2 * dd * thd + g * s1, 0, l1 * thdd + ddd - d * thd**2 + g * c1])
    vc2_student = V([-d * thdd - 2 * dd * thd + g * s1, 0, l1 * thdd + ddd - d * thd**2 + g * c1])
    F2_student = V([-m2 * (-thd * d - 2 * thd * dd + g * s1), 0, -m2 * (l1 * thdd - thd**2 * d + ddd + g * c1)])
    tau1 = (
        (m1 + m2) * l1**2 * thdd
        + m2 * l1 * ddd
        + 2 * m2 * d * thd * dd
        + m2 * thdd * d**2
        + (m1 + m2) * g * l1 * c1
        - m2 * g * d * s1
    )
    tau2 = m2 * (l1 * thdd - thd**2 * d + ddd + g * c1)
    steps = [
        _step(
            "omega_1",
            "omega",
            "correct",
            r"\boldsymbol{\omega}_1^1",
            V([0, 0, thd]),
            V([0, 0, thd]),
            link="link1",
            line=14,
            frame="1",
        ),
        _step(
            "v_dot_1",
            "v_dot",
            "wrong",
            r"\dot{\boldsymbol{v}}_1^1",
            vd1_true,
            vd1_student,
            [0],
            link="link1",
            line=16,
            frame="1",
            message="missing term \u2212l1\u00b7\u03b8\u03071\u00b2 in the x component",
        ),
        _step(
            "v_dot_C2",
            "vc_dot",
            "follows-from-earlier-error",
            r"\dot{v}_{C_2}^2",
            vc2_true,
            vc2_student,
            [0],
            link="link2",
            line=22,
            frame="2",
            caused_by="v_dot_1",
            message="what your v\u03071 gives: carried forward",
        ),
        _step(
            "F_2",
            "F",
            "wrong",
            r"F_2^2",
            -m2 * vc2_true,
            F2_student,
            [0],
            link="link2",
            line=26,
            frame="2",
            convention="d'Alembert sign F = \u2212m v\u0307_C",
            message="\u03b8\u03071 where \u03b8\u03081 belongs in the x component",
        ),
        _step(
            "N_2",
            "N",
            "correct-by-convention",
            r"N_2^2",
            V([0, 0, 0]),
            V([0, 0, 0]),
            link="link2",
            line=30,
            frame="2",
            convention="d'Alembert sign N = \u2212I \u03c9\u0307 \u2212 \u03c9 \u00d7 I\u03c9",
        ),
        _step(
            "m_2",
            "",
            "unrecognised",
            r"m_2^2",
            None,
            None,
            line=40,
            source=HOSTILE,
            message="m_2^2 is not a step name (the moment n_2 about frame 1's origin?): skipped",
        ),
        _step("tau_2", "tau", "correct", r"\tau_2", tau2, tau2, link="d2", line=52),
        _step(
            "tau_1",
            "tau",
            "correct-but-unsupported",
            r"\tau_1",
            tau1,
            tau1,
            link="theta1",
            line=50,
            message="right, but your n_1 gives a different value",
        ),
    ]
    return GradeReport(
        robot="rp-arm",
        method="newton-euler",
        submission="assignment-7.md",
        steps=steps,
        first_wrong="v_dot_1",
        tau_correct=[True, True],
        symbol_latex=STUDENT_LATEX,
        notes=["symbols mapped: \u03b8_1 \u2194 theta1, d_2 \u2194 d2, l_1 \u2194 l1"],
    )


# ------------------------------------------------------------------ static structure


class _Collect(HTMLParser):
    def __init__(self):
        super().__init__()
        self.tags, self.classes, self.text = [], [], []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        self.classes.append((tag, dict(attrs).get("class", ""), dict(attrs).get("id", "")))

    def handle_data(self, data):
        self.text.append(data)


def _parse(page: str) -> _Collect:
    p = _Collect()
    p.feed(page)
    return p


def test_grade_page_is_self_contained_and_escapes_source():
    page = report_html(exercise_like_report())
    assert page.startswith("<!DOCTYPE html>")
    # nothing to fetch: no script, no stylesheet link, no image or font from anywhere
    for bad in ("<script", "<link", "src=", "url(", "@import", "@font-face"):
        assert bad not in page.lower(), bad
    p = _parse(page)
    assert "script" not in p.tags and "<b>bold</b>" not in page  # the hostile source stayed text
    assert "&lt;script&gt;" in page
    assert HOSTILE in "".join(p.text)


def test_grade_page_cards_badges_and_highlights():
    report = exercise_like_report()
    page = report_html(report)
    p = _parse(page)
    # every step has an anchor, in the student's order; each recognised one its card
    ids = [i for _, _, i in p.classes if i.startswith("step-")]
    assert ids == [f"step-{k}" for k in range(len(report.steps))]
    cards = {i: c for t, c, i in p.classes if t == "li" and "step" in c.split()}
    for k, step in enumerate(report.steps):
        if step.status != "unrecognised":
            assert f"st-{step.status}" in cards[f"step-{k}"].split()
    assert sum("st-unrecognised" in c.split() for t, c, _ in p.classes if t == "li") == 1
    # one count chip per status present, with the right number
    for status in STATUSES:
        n = sum(s.status == status for s in report.steps)
        chip = re.search(rf'<span class="badge s-{status}"><span class="n">(\d+)</span>', page)
        assert (chip is None) if n == 0 else (chip and int(chip.group(1)) == n), status
    # the first wrong step is linked from the summary, its card marked
    assert '<a href="#step-1">' in page and 'class="step st-wrong first"' in page
    # highlighted cells: v_dot_1, v_dot_C2, F_2 each show yours, expected, difference with row 0 marked
    assert page.count('<mtd class="hl">') == 3 * 3
    # the unrecognised step shows its source and no comparison
    unrec = page[page.index('id="step-5"') : page.index('id="step-6"')]
    assert "<pre>" in unrec and 'class="compare"' not in unrec


def test_grade_page_math_is_wellformed_and_in_students_notation():
    import xml.etree.ElementTree as ET

    page = report_html(exercise_like_report())
    maths = re.findall(r"<math\b.*?</math>", page, re.S)
    assert len(maths) > 20
    ns = "{http://www.w3.org/1998/Math/MathML}"
    accents = 0
    for m in maths:
        root = ET.fromstring(m)  # every formula is well-formed XML
        for mover in root.iter(ns + "mover"):
            accents += mover.get("accent") == "true"
    assert accents > 10  # theta-dots are accents on the letter
    # the difference of v_dot_1 is l1*theta1_dot^2 in x: shown as l_1 θ̇_1^2 in the highlighted row
    start = page.index('id="step-1"')
    card = page[start : page.index('id="step-2"')]
    diff = card[card.index("difference") :]
    row = re.search(r'<mtd class="hl">(.*?)</mtd>', diff, re.S).group(1)
    root = ET.fromstring(f'<mrow xmlns="http://www.w3.org/1998/Math/MathML">{row}</mrow>')
    texts = [e.text for e in root.iter() if e.text]
    assert "l" in texts and "\u03b8" in texts and "2" in texts and "\u2212" not in texts


def test_repr_html_is_a_fragment():
    frag = repr_html(exercise_like_report())
    assert frag.startswith('<div class="armdyn') and "<html" not in frag and "<math" in frag


# ------------------------------------------------------------------ in the browser


def test_grade_page_renders_in_chromium(tmp_path):
    chromium = require_chromium()
    page = tmp_path / "grade.html"
    page.write_text(report_html(exercise_like_report()), encoding="utf-8")
    shot = render(page, chromium, screenshot=SHOTS / "grade-exercise-like.png")
    assert_math_rendered(shot, min_count=20)
    assert_parentheses_stretch(shot, min_count=10)
    assert "alert('x')" in shot.body_text  # the hostile source shows as text
    # highlighted rows are painted (not transparent) and have a size
    assert len(shot.hl) == 9
    for cell in shot.hl:
        assert cell["w"] > 0 and cell["h"] > 0
        assert cell["background"] not in ("rgba(0, 0, 0, 0)", "transparent"), cell
    # fits a 1000 px window: nothing forces horizontal scrolling of the page
    assert shot.width <= 1000, shot.width


def test_derive_html_renders_in_chromium(tmp_path, capsys):
    chromium = require_chromium()
    from armdyn.cli import main

    assert main(["derive", "rp-arm", "--steps", "--format", "html"]) == 0
    html_text = capsys.readouterr().out
    for bad in ("<script", "<link", "src=", "url(", "@import"):
        assert bad not in html_text.lower(), bad
    page = tmp_path / "derive.html"
    page.write_text(html_text, encoding="utf-8")
    shot = render(page, chromium, screenshot=SHOTS / "derive-rp-arm.png")
    assert_math_rendered(shot, min_count=30)
    assert_parentheses_stretch(shot, min_count=20)
    assert shot.width <= 1000, shot.width


# ------------------------------------------------------------------ derive --format html, Jupyter


def _maths(markup: str) -> list:
    import xml.etree.ElementTree as ET

    return [ET.fromstring(m) for m in re.findall(r"<math\b.*?</math>", markup, re.S)]


@pytest.fixture(scope="module")
def rp_arm():
    from armdyn.io import load
    from armdyn.symbolic import check, derive

    robot = load("rp-arm")
    ne, la = derive(robot, "newton-euler"), derive(robot, "lagrange")
    return robot, ne, la, check(ne, la, structure=False)


def test_derive_html_page_structure(rp_arm):
    from armdyn.symbolic.report import derivation_report

    robot, ne, la, agreement = rp_arm
    page = derivation_report([ne, la], "html", steps=True, agreement=agreement)
    assert page.startswith("<!DOCTYPE html>") and "<script" not in page.lower()
    maths = _maths(page)  # every formula is well-formed XML
    # one equation per step and per tau of each method, plus M, C, g and the model tables
    eqs = page.count('<div class="eq">')
    assert eqs == len(ne.steps) + len(la.steps) + 2 * robot.dof + 3
    assert len(maths) > eqs
    # steps grouped per link: one group per (stage, link) run of the derivation
    runs = sum(
        1
        for eom in (ne, la)
        for k, s in enumerate(eom.steps)
        if k == 0 or (s.stage, s.link) != (eom.steps[k - 1].stage, eom.steps[k - 1].link)
    )
    assert page.count('<div class="group">') == runs
    assert "all passed" in page


def test_jupyter_reprs(rp_arm):
    robot, ne, la, agreement = rp_arm
    html_robot = robot._repr_html_()
    assert html_robot.startswith('<div class="armdyn')
    for j in robot.joints:
        assert f"<td>{j.name}</td>" in html_robot
    assert len(_maths(html_robot)) >= 2 * robot.dof
    html_eom = la._repr_html_()
    assert len(re.findall(r'<div class="eq">', html_eom)) == robot.dof
    _maths(html_eom)
    latex = ne._repr_latex_()
    assert latex.startswith("$$\\begin{aligned}") and latex.endswith("\\end{aligned}$$")
    assert latex.count("&=") == robot.dof and "%" not in latex
    html_check = agreement._repr_html_()
    assert html_check.count('<span class="ok">OK</span>') == len(agreement.results) >= 1


def test_jupyter_reprs_render_in_chromium(rp_arm, tmp_path):
    chromium = require_chromium()
    robot, ne, la, agreement = rp_arm
    from armdyn.htmlpage import page as html_page

    body = robot._repr_html_() + ne._repr_html_() + agreement._repr_html_() + repr_html(exercise_like_report())
    path = tmp_path / "jupyter.html"
    path.write_text(html_page("reprs", body), encoding="utf-8")
    shot = render(path, chromium, screenshot=SHOTS / "jupyter-reprs.png")
    assert_math_rendered(shot, min_count=20)


def test_browser_check_can_fail(tmp_path):
    """The browser check catches what it is meant to: an <merror>, a math element of
    zero size, LaTeX left unconverted, parentheses that do not stretch."""
    chromium = require_chromium()
    cases = {
        "merror": "<math><merror><mtext>bad</mtext></merror></math>",
        "zero size": '<math style="display:none"><mi>x</mi></math><math><mi>y</mi></math>',
        "latex": "<math><mtext>\\dot{\\theta}_1</mtext></math>",
    }
    for what, body in cases.items():
        path = tmp_path / "bad.html"
        path.write_text(f"<!DOCTYPE html><html><body>{body}</body></html>", encoding="utf-8")
        with pytest.raises(AssertionError):
            assert_math_rendered(render(path, chromium))
    # a vector in a text font: its parentheses keep the height of one line
    vec = (
        '<mrow><mo stretchy="true">(</mo><mtable>'
        + "<mtr><mtd><mi>x</mi></mtd></mtr>" * 3
        + '</mtable><mo stretchy="true">)</mo></mrow>'
    )
    path.write_text(
        f"<!DOCTYPE html><html><body><math style=\"font-family:'Liberation Serif',serif\">{vec}</math></body></html>",
        encoding="utf-8",
    )
    with pytest.raises(AssertionError, match="do not stretch"):
        assert_parentheses_stretch(render(path, chromium))


def test_huge_values_are_not_printed_and_the_page_stays_fast():
    """A value of a generated 6-dof derivation can have 10^4+ nodes: the page says so
    instead of printing it (SymPy's MathML printer takes ~1 ms a node)."""
    import time

    from armdyn.grading import html as grade_html

    x = sp.symbols("x0:60")
    huge = sp.Add(*[sp.Mul(*[x[(k + j) % 60] for j in range(20)]) * sp.sin(x[k]) for k in range(60)])
    assert sum(1 for _ in sp.preorder_traversal(huge)) > grade_html.PRINT_NODE_LIMIT
    small = x[0] * x[1]
    steps = [
        StepVerdict(
            name="tau_1",
            key="tau",
            link="q1",
            status="wrong",
            label=r"\tau_1",
            source="",
            line=3,
            expected=huge,
            got=huge + small,
            difference=small,
        )
    ]
    report = GradeReport("big", "newton-euler", "big.md", steps, "tau_1", [False])
    t0 = time.perf_counter()
    page = report_html(report)
    assert time.perf_counter() - t0 < 10
    assert page.count("too long to print") == 2  # yours and expected; the difference is shown
    diff = page[page.index("difference") :]
    assert "<msub><mi>x</mi><mn>0</mn></msub>" in diff


@pytest.mark.parametrize(
    "statuses, verdict",
    [
        (["correct", "correct-by-convention"], "Every step is right"),
        (["correct", "correct-but-unsupported"], "No step is wrong"),
        (["unrecognised"], "No step was recognised"),
    ],
)
def test_summary_verdict_without_a_wrong_step(statuses, verdict):
    x = sp.Symbol("theta1_dot")
    steps = [
        StepVerdict(
            name=f"s{k}",
            key="omega" if st != "unrecognised" else "",
            link="",
            status=st,
            label=r"\omega_1",
            source=r"\omega_1 = x",
            line=k + 1,
            expected=None if st == "unrecognised" else x,
            got=None if st == "unrecognised" else x,
        )
        for k, st in enumerate(statuses)
    ]
    page = report_html(GradeReport("r", "newton-euler", "s.md", steps, None, []))
    head = page[page.index('<section class="summary">') : page.index("</section>")]
    assert verdict in head
    assert ("verdict pass" in head) == (verdict == "Every step is right")


def test_write_report_html_writes_whole_page_or_nothing(tmp_path, monkeypatch):
    from armdyn.grading import html as grade_html

    out = tmp_path / "r.html"
    grade_html.write_report_html(exercise_like_report(), out)
    assert out.read_text(encoding="utf-8") == report_html(exercise_like_report())

    def boom(report):
        raise ValueError("bad report")

    monkeypatch.setattr(grade_html, "report_html", boom)
    other = tmp_path / "s.html"
    with pytest.raises(ValueError):
        grade_html.write_report_html(exercise_like_report(), other)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.html"]


def test_grouped_unrecognised_and_inherited_rows():
    """Consecutive unrecognised equations share one card, each with its line and source;
    an inherited error with no components named is highlighted where it differs from
    the expected value; a difference taken against the student's own earlier values
    (not the expected one) is captioned so."""
    x, y = sp.symbols("theta1_dot l1")
    un = [
        StepVerdict(
            name=f"u{k}",
            key="",
            link="",
            status="unrecognised",
            label=r"I_P",
            line=10 + k,
            source=f"I_P = {k} <x>",
            message="not a step",
        )
        for k in range(3)
    ]
    carried = StepVerdict(
        name="F_1",
        key="F",
        link="link1",
        status="follows-from-earlier-error",
        label="F_1^1",
        source="",
        line=20,
        expected=V([x, y, 0]),
        got=V([x, 0, 0]),
        difference=V([0, -y, 0]),
        caused_by="u0",
    )
    own = StepVerdict(
        name="F_2",
        key="F",
        link="link2",
        status="wrong",
        label="F_2^2",
        source="",
        line=21,
        expected=V([x, y, 0]),
        got=V([2 * x, 0, 0]),
        difference=V([x, 0, 0]),
        components=[0],
        message="x wrong (compared with what your own earlier steps give)",
    )
    report = GradeReport("r", "newton-euler+lagrange", "s.md", un + [carried, own], "F_2", [])
    page = report_html(report)
    assert "3 equations not recognised as steps" in page and "lines 10\u201312" in page
    assert page.count('<div class="skip"') == 3 and "I_P = 2 &lt;x&gt;" in page
    assert "Newton\u2013Euler and Lagrange" in page
    card = page[page.index('id="step-3"') : page.index('id="step-4"')]
    assert card.count('<mtd class="hl">') == 3  # row 1 (y) on yours, expected and the difference
    assert "difference: yours \u2212 expected" in card
    card = page[page.index('id="step-4"') :]
    # the expected value shown and the difference name one reference: the student's own
    # chain gives 2x - x = x in the first row; the exercise's value is shown apart, named
    assert "difference: yours \u2212 expected from your own earlier steps" in card
    assert "expected from your own earlier steps</span>" in card and "from the exercise&#x27;s model" in card
    from armdyn.grading.html import OWN_REFERENCE, reference

    value, name = reference(own)
    assert name == OWN_REFERENCE and value == V([x, 0, 0])
    assert reference(carried)[0] == V([x, y, 0])


def test_exercise_grade_report_renders_in_chromium(tmp_path):
    """The real exercise (examples/grading/rp-arm-exercise.md) through the grader:
    the page renders, its first wrong step is v̇_1 with the x row highlighted."""
    chromium = require_chromium()
    from armdyn.grading import grade

    report = grade(ROOT / "examples" / "grading" / "rp-arm-exercise.md")
    page = tmp_path / "grade-exercise.html"
    page.write_text(report_html(report), encoding="utf-8")
    shot = render(page, chromium, screenshot=SHOTS / "grade-exercise.png")
    assert_math_rendered(shot, min_count=40)
    assert_parentheses_stretch(shot, min_count=10)
    k = next(i for i, s in enumerate(report.steps) if s.name == report.first_wrong)
    text = page.read_text(encoding="utf-8")
    assert f'<a href="#step-{k}">' in text
    card = text[text.index(f'id="step-{k}"') :]
    card = card[: card.index("</li>")]
    assert card.count('<mtr class="hl">') == 3  # x row of yours, expected and the difference
    assert card.count('<mtable><mtr class="hl">') == 3  # ... and it is the first row, x
