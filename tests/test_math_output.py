"""Output that looks like the math: text without ``*`` between factors, LaTeX with the
field's accents (``\\dot{\\theta}_{1}``), derive HTML whose wide rows stay on the page, a
joint table with the frames off the joint axis, captions and grader messages as math.

Each check has its own expectation: printed text is parsed back with SymPy (juxtaposition
read as a product, Unicode names spelled out by a table written here) and compared with
the expression or the exercise's hand-derived torques; LaTeX names with a table written
by hand; frame offsets with the model file read by PyYAML; the page's layout with what
a real browser measures.
"""

from __future__ import annotations

import html
import json
import re
import unicodedata
import xml.etree.ElementTree as ET
from html.parser import HTMLParser
from pathlib import Path

import pytest
import sympy as sp
import yaml
from sympy.parsing.sympy_parser import implicit_multiplication, parse_expr, standard_transformations

import armdyn
from armdyn.mathml import latex_to_mathml, text_with_math
from armdyn.symbolic.names import latex_symbol_names
from armdyn.symbolic.report import derivation_report, steps_lines, tau_lines

IMPLICIT = standard_transformations + (implicit_multiplication,)
# the exercise's symbols spelled in ASCII, written out here (not taken from the printer)
SPELLED = {
    "θ̈₁": "theta1_ddot",
    "θ̇₁": "theta1_dot",
    "θ₁": "theta1",
    "d̈₂": "d2_ddot",
    "ḋ₂": "d2_dot",
    "d₂": "d2",
    "m₁": "m1",
    "m₂": "m2",
    "l₁": "l1",
    "²": "**2",
    "³": "**3",
    "·": "*",
    "−": "-",
}
M1, M2, L1, G, TH, D, THD, DD, THDD, DDD = sp.symbols("m1 m2 l1 g theta1 d2 theta1_dot d2_dot theta1_ddot d2_ddot")
# the exercise's result (assignment 7, by hand)
TAU1 = (
    (M1 + M2) * L1**2 * THDD
    + M2 * L1 * DDD
    + 2 * M2 * D * THD * DD
    + M2 * THDD * D**2
    + (M1 + M2) * G * L1 * sp.cos(TH)
    - M2 * G * D * sp.sin(TH)
)
TAU2 = M2 * (L1 * THDD - THD**2 * D + DDD + G * sp.cos(TH))
LOCALS = {str(s): s for s in (M1, M2, L1, G, TH, D, THD, DD, THDD, DDD)}


def _read_back(text: str):
    """Unicode report text -> SymPy, juxtaposed factors read as products."""
    text = unicodedata.normalize("NFC", text)
    for uni, asc in sorted(SPELLED.items(), key=lambda kv: -len(kv[0])):
        text = text.replace(unicodedata.normalize("NFC", uni), f" {asc} " if asc[0].isalpha() else asc)
    assert text.isascii(), text
    return parse_expr(text, local_dict=LOCALS, transformations=IMPLICIT)


@pytest.fixture(scope="module")
def rp():
    robot = armdyn.load("rp-arm")
    return robot, armdyn.derive(robot, "newton-euler"), armdyn.derive(robot, "lagrange")


# ---------------------------------------------------------------- text
def test_text_tau_has_no_star_and_reads_back_as_the_exercise(rp):
    _, ne, la = rp
    for eom in (ne, la):
        lines = tau_lines(eom, "text")
        assert len(lines) == 2
        for line in lines:
            assert "*" not in line.split(" = ", 1)[1], line
        nfc = unicodedata.normalize
        assert nfc("NFC", "(d₂² m₂ + l₁² m₁ + l₁² m₂) θ̈₁ + l₁ m₂ d̈₂") in nfc("NFC", lines[0])
        for line, expected in zip(lines, (TAU1, TAU2)):
            rhs = line.split(" = ", 1)[1].rsplit("    (", 1)[0]
            assert sp.expand(_read_back(rhs) - expected) == 0, line


def test_every_text_step_reads_back_as_its_value(rp):
    """The printer is faithful: each printed step component, parsed back, is the step's
    value (a scalar or a 3-vector)."""
    _, ne, la = rp
    for eom in (ne, la):
        values = [s.value for s in eom.steps]
        body = [ln for ln in steps_lines(eom, "text") if ln.startswith("  ")]  # not the stage titles
        assert len(body) == len(values)
        for line, value in zip(body, values):
            rhs = line.split(" = ", 1)[1].rsplit("    # ", 1)[0]
            assert "*" not in rhs, line
            if isinstance(value, sp.MatrixBase):
                parts = [_read_back(p) for p in _split_vector(rhs)]
                assert len(parts) == len(value), line
                for got, want in zip(parts, value):
                    assert sp.simplify(got - want) == 0, line
            else:
                assert sp.simplify(_read_back(rhs) - value) == 0, line


def _split_vector(text: str) -> list[str]:
    assert text[0] == "[" and text[-1] == "]", text
    parts, depth, cur = [], 0, ""
    for ch in text[1:-1]:
        depth += ch == "("
        depth -= ch == ")"
        if ch == "," and depth == 0:
            parts.append(cur)
            cur = ""
        else:
            cur += ch
    return parts + [cur]


def test_two_numbers_keep_a_visible_separator():
    from armdyn.symbolic.names import UnicodeTextPrinter

    x = sp.Symbol("x")
    out = UnicodeTextPrinter({}).doprint(sp.Mul(2, sp.Pow(3, x, evaluate=False), evaluate=False))
    assert "2 3" not in out and "·" in out
    assert sp.sympify(out.replace("·", "*")) == 2 * 3**x


def test_ascii_keeps_a_plain_parseable_form(rp):
    _, ne, _ = rp
    text = derivation_report([ne], "text", ascii=True)
    assert text.isascii()
    tau1 = next(ln for ln in text.splitlines() if ln.startswith("  tau1 = "))
    rhs = tau1.split(" = ", 1)[1].rsplit("    (", 1)[0]
    assert "*" in rhs  # plain form: explicit products
    assert sp.expand(sp.sympify(rhs, locals=LOCALS) - TAU1) == 0


# ---------------------------------------------------------------- LaTeX
def test_latex_symbol_names_as_written_by_hand(rp):
    robot, ne, _ = rp
    names = {str(k): v for k, v in latex_symbol_names(robot).items()}
    expected = {
        "theta1": r"\theta_{1}",
        "theta1_dot": r"\dot{\theta}_{1}",
        "theta1_ddot": r"\ddot{\theta}_{1}",
        "d2": "d_{2}",
        "d2_dot": r"\dot{d}_{2}",
        "d2_ddot": r"\ddot{d}_{2}",
        "l1": "l_{1}",
        "m1": "m_{1}",
        "m2": "m_{2}",
        "g": "g",
    }
    assert names == expected
    assert latex_symbol_names(robot) is latex_symbol_names(robot)  # built once per robot
    planar = armdyn.load("planar-2r")  # the field's l_{c1}: distance to the centre of mass
    names = {str(k): v for k, v in latex_symbol_names(planar).items()}
    assert names["lc1"] == "l_{c1}" and names["q1_dot"] == r"\dot{q}_{1}" and names["I2"] == "I_{2}"


@pytest.mark.parametrize("where", ["report", "repr_latex", "sympy"])
def test_latex_puts_the_accent_on_the_letter(rp, where):
    robot, ne, _ = rp
    if where == "report":
        tex = derivation_report([ne], "latex", steps=True)
    elif where == "repr_latex":
        tex = ne._repr_latex_()
    else:  # Jupyter display of a SymPy result with the robot's names
        tex = sp.latex(ne.tau, symbol_names=latex_symbol_names(robot))
    assert r"\dot{\theta}_{1}" in tex and r"\ddot{d}_{2}" in tex
    for wrong in ("theta_{1 \\dot", "theta_{1 dot", "d_{2 dot", r"\dot{\theta_{1}}", r"\ddot{d_{2}}"):
        assert wrong not in tex, wrong


def test_mathml_from_the_latex_has_the_dot_on_theta_and_the_index_outside(rp):
    robot, _, _ = rp
    name = latex_symbol_names(robot)[robot.qd[0]]
    root = ET.fromstring(f"<mrow>{latex_to_mathml(name)}</mrow>")
    msub = root.find(".//msub")
    assert msub is not None
    base, index = list(msub)
    assert base.tag == "mover" and base.find(".//mi").text == "θ" and "".join(index.itertext()) == "1"


# ---------------------------------------------------------------- derive HTML
class _Table(HTMLParser):
    """Rows of the first <table> (cells' text, MathML flattened)."""

    def __init__(self):
        super().__init__()
        self.rows, self.depth, self.cell, self.done = [], 0, None, False

    def handle_starttag(self, tag, attrs):
        if self.done:
            return
        if tag == "table":
            self.depth += 1
        elif tag == "tr" and self.depth:
            self.rows.append([])
        elif tag in ("td", "th") and self.depth:
            self.cell = ""

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self.cell is not None and self.rows:
            self.rows[-1].append(self.cell)
            self.cell = None
        elif tag == "table" and self.depth:
            self.done = True

    def handle_data(self, data):
        if self.cell is not None:
            self.cell += data.strip()


def test_joint_table_lists_frame_offsets(rp):
    robot, ne, la = rp
    page = derivation_report([ne, la], "html", steps=True)
    parser = _Table()
    parser.feed(page)
    head, *rows = parser.rows
    col = head.index("frame_xyz (joint frame)")
    source = yaml.safe_load((Path(armdyn.__file__).parent / "robots" / "rp-arm.yaml").read_text())
    for joint in source["joints"]:
        row = next(r for r in rows if r[0] == joint["name"])
        xyz = joint.get("frame_xyz")
        if xyz is None:
            assert row[col] == ""
        else:  # the cell's math, flattened: (l1 0 0)
            assert row[col] == "(" + "".join(str(v) for v in xyz) + ")", row


def test_captions_are_math(rp):
    _, ne, la = rp
    page = derivation_report([ne, la], "html", steps=True)
    notes = re.findall(r'<span class="note">(.*?)</span></div>', page)
    inertial = [n for n in notes if n.startswith("inertial force")]
    assert inertial and all("<math" in n and "vcd" not in n for n in inertial)
    assert all("<math" in n for n in notes if "kinetic energy" in n and "total" not in n)
    assert not any(ascii_form in n for n in notes for ascii_form in ("w x I w", "1/2 w^T I w", "1/2 m vc.vc"))


_PROBE = """<script>(function () {
  var rows = Array.prototype.map.call(document.querySelectorAll(".eq"), function (eq) {
    var m = eq.querySelector(":scope > math"), n = eq.querySelector(":scope > .note");
    function box(e) { if (!e) return null; var r = e.getBoundingClientRect();
      return {l: r.left, r: r.right, t: r.top, b: r.bottom, sw: e.scrollWidth, cw: e.clientWidth}; }
    return {math: box(m), note: box(n), text: m ? m.textContent.slice(0, 12) : "",
            caption: n ? n.textContent : "", eq: box(eq)};
  });
  var pre = document.createElement("pre"); pre.id = "probe";
  pre.textContent = JSON.stringify({rows: rows, width: document.documentElement.scrollWidth,
                                    view: window.innerWidth});
  document.body.appendChild(pre);
})();</script>"""


def test_browser_long_row_and_its_caption_stay_on_the_page(rp, tmp_path):
    import sys

    sys.path.insert(0, str(Path(__file__).parent))
    from browser import _run, render, require_chromium, without_csp

    chromium = require_chromium()
    _, ne, la = rp
    page = tmp_path / "rp-arm.html"
    page.write_text(derivation_report([ne, la], "html", steps=True), encoding="utf-8")
    probe = tmp_path / "probe.html"
    src = without_csp(page.read_text(encoding="utf-8"))
    probe.write_text(src.replace("</body>", _PROBE + "</body>"), encoding="utf-8")
    done = _run(chromium, ["--window-size=1200,900", "--dump-dom", probe.as_uri()], 90.0)
    data = json.loads(html.unescape(re.search(r'<pre id="probe">(.*?)</pre>', done.stdout, re.S).group(1)))
    view = data["view"]
    assert view == 1200 and data["width"] <= view
    n1 = [r for r in data["rows"] if r["text"].startswith("1n1") and r["caption"].startswith("moment exerted")]
    assert n1, [r["text"] for r in data["rows"]]
    for row in n1:
        m, n = row["math"], row["note"]
        assert 0 <= m["l"] and m["r"] <= view and m["sw"] <= m["cw"] + 1  # drawn whole, no scrolling
        assert 0 <= n["l"] and n["r"] <= view and n["r"] - n["l"] > 50  # the caption is on the page
        assert n["sw"] <= n["cw"] + 1  # and not cut
        assert n["l"] >= m["r"] or n["t"] >= m["b"]  # beside or under the formula, not over it
        assert n["r"] <= row["eq"]["r"] + 1 and n["b"] <= row["eq"]["b"] + 1  # inside its row (not clipped)
    shot = render(page, chromium, screenshot=tmp_path / "rp-arm.png", width=1200)
    assert shot.merror == 0 and not shot.latex


# ---------------------------------------------------------------- grade HTML
def test_text_with_math_renders_delimited_math_through_the_sanitizer():
    out = text_with_math(r"expected $\dot{\theta}_1$ here, 5 \$ not math")
    root = ET.fromstring(f"<p>{out}</p>")
    maths = root.findall("{http://www.w3.org/1998/Math/MathML}math")
    assert len(maths) == 1 and maths[0].find(".//{http://www.w3.org/1998/Math/MathML}mover") is not None
    assert root.text.startswith("expected ") and "not math" in ET.tostring(root, encoding="unicode")
    hostile = text_with_math(r"$\text{<img src=x onerror=alert(1)>}$ and <script>alert(1)</script>")
    assert "<img" not in hostile and "<script" not in hostile and "onerror=alert(1)>" not in hostile.replace("&", "")


def test_grade_html_shows_skipped_equations_as_math(tmp_path):
    from armdyn.grading.html import report_html

    sub = tmp_path / "sub.md"
    sub.write_text(
        "---\nrobot: rp-arm\nmethod: newton-euler\n---\n"
        "$$\\mathbf{r}_P = \\mathbf{r}_C + \\mathbf{d}$$\n\n"
        "$$\\text{<script>alert(1)</script>} = 1$$\n\n"
        "$$\\omega_1 = \\begin{pmatrix} 0 \\\\ 0 \\\\ \\dot{\\theta}_1 \\end{pmatrix}$$\n",
        encoding="utf-8",
    )
    report = armdyn.grade(sub)
    skipped = [s for s in report.steps if s.status == "unrecognised"]
    assert len(skipped) == 2
    page = report_html(report)
    cards = re.findall(r'<div class="skip" id="step-\d+">(.*?)</div></div>', page, re.S)
    assert len(cards) == 2
    assert '<div class="written"><math' in cards[0] and "<pre>" in cards[0]  # math, source under "as written"
    assert "<script" not in page.split("</style>", 1)[1]
    assert "&lt;script&gt;" in cards[1]


def test_grade_and_derive_html_print_model_symbols_alike():
    """The grade report names the model's symbols as the derivation report does: the
    field's l_{c1} (l with the subscript c1) in both, never l times c_1."""
    example = Path(__file__).parent.parent / "examples" / "grading" / "planar-2r-craig.md"
    graded = armdyn.grade(example)._repr_html_()
    derived = derivation_report([armdyn.derive(armdyn.load("planar-2r"))], "html")
    l_c1 = "<msub><mi>l</mi><mrow><mi>c</mi><mn>1</mn></mrow></msub>"
    l_times_c1 = "<mi>l</mi><msub><mi>c</mi>"
    for page in (graded, derived):
        assert l_c1 in page and l_times_c1 not in page
    assert latex_symbol_names(armdyn.load("planar-2r"))  # the names both take
