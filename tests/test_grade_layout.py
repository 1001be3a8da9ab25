"""Equations as real texts lay them out, and the LaTeX they are written in.

1. A chain split over display blocks (``$$ LHS = formula $$``, prose, ``$$ = value $$``,
   ``$$ + ... $$``, ``$$ \\Rightarrow ... $$``, ``$$ \\tau_1 = $$`` then its value) is one
   equation: each member is checked as a chain member, and the step is reported where its
   slip is written (a value block, or the formula block holding it).
2. What the LaTeX parser reads (a resolver mapping names to plain SymPy symbols; the values
   expected are worked out by hand), and where it stops, with why, for what it cannot read.

The RP arm's torques (TAU_1, TAU_2) are the closed forms of test_grade_reading, checked there
against a plain SymPy Lagrangian.
"""

from __future__ import annotations

import pytest
import sympy as sp
from test_grade_reading import TAU_2, write

from armdyn.grading import grade
from armdyn.grading.equations import split_equations
from armdyn.grading.latex import LatexError, Name, parse
from armdyn.grading.reader import read_markdown

# TAU_2 by hand, written out term by term, and the same with one sign slipped (+ d_2 θ̇₁²)
TAU_2_OUT = r"m_2 l_1 \ddot{\theta}_1 - m_2 d_2 \dot{\theta}_1^2 + m_2 \ddot{d}_2 + m_2 g \cos\theta_1"
TAU_2_SLIP = r"m_2 l_1 \ddot{\theta}_1 + m_2 d_2 \dot{\theta}_1^2 + m_2 \ddot{d}_2 + m_2 g \cos\theta_1"


def only(report):
    (v,) = report.steps
    return v


# ---------------------------------------------------------------- 1. chains split over blocks


def test_a_slip_in_the_value_block_is_reported_at_that_block(tmp_path):
    body = (
        f"$$\\tau_2 = {TAU_2}$$\n"  # line 4: the formula, right
        "which, multiplied out, gives\n"
        "\n"
        f"$$= {TAU_2_SLIP}$$\n"  # line 7: the value, with the slip
    )
    v = only(grade(write(tmp_path, "value.md", body)))
    assert (v.name, v.status) == ("tau_2", "wrong")
    assert v.line == 7
    assert "(member 1 at line 4) is right: the slip is in the value" in v.message


def test_a_slip_in_the_formula_block_is_reported_there(tmp_path):
    body = (
        f"$$\\tau_2 = m_2 (l_1 \\ddot{{\\theta}}_1 + d_2 \\dot{{\\theta}}_1^2 + \\ddot{{d}}_2 + g \\cos\\theta_1)$$\n"
        "$$\n"
        f"= {TAU_2_SLIP}\n"  # line 6: the slip carried on from line 4
        "$$\n"
    )
    v = only(grade(write(tmp_path, "formula.md", body)))
    assert (v.status, v.line) == ("wrong", 4)
    assert "the slip is already in its formula member" in v.message and "member 1 at line 4" in v.message


def test_a_chain_of_three_blocks_right_throughout_is_correct_at_its_value(tmp_path):
    body = f"$$\\tau_2 = {TAU_2}$$\n\n$$= {TAU_2_OUT}$$\n\n$$= {TAU_2_OUT.replace('m_2 g', 'g m_2')}$$\n"
    v = only(grade(write(tmp_path, "three.md", body)))
    assert (v.status, v.line) == ("correct", 8)


def test_a_lone_lhs_block_takes_the_next_block_as_its_value(tmp_path):
    # "\tau_2 =" closes its block; the value follows in two blocks, the second one adding
    body = "$$\\tau_2 =$$\n$$m_2 l_1 \\ddot{\\theta}_1 - m_2 d_2 \\dot{\\theta}_1^2$$\n$$+ m_2 \\ddot{d}_2 + m_2 g \\cos\\theta_1$$\n"
    sub = read_markdown(str(write(tmp_path, "lone.md", body)))
    (eq,) = sub.equations
    assert eq.value.startswith("m_2 l_1") and eq.blocks == 3
    v = only(grade(write(tmp_path, "lone.md", body)))
    assert (v.status, v.line) == ("correct", 5)


def test_a_lone_lhs_block_with_a_wrong_value_is_wrong(tmp_path):
    body = f"$$\\tau_2 =$$\n$${TAU_2_SLIP}$$\n"
    assert (only(grade(write(tmp_path, "lone-slip.md", body))).status) == "wrong"


def test_a_rightarrow_block_continues_the_chain(tmp_path):
    body = f"$$\\tau_2 = {TAU_2}$$\n$$\\Rightarrow {TAU_2_SLIP}$$\n"
    v = only(grade(write(tmp_path, "arrow.md", body)))
    assert (v.status, v.line) == ("wrong", 5)
    body = f"$$\\tau_2 = {TAU_2}$$\n$$\\implies = {TAU_2_OUT}$$\n"
    assert only(grade(write(tmp_path, "implies.md", body))).status == "correct"


def test_a_rightarrow_before_a_new_left_hand_side_starts_a_new_equation(tmp_path):
    body = f"$$\\tau_2 = {TAU_2}$$\n$$\\Rightarrow \\tau_2 = {TAU_2_SLIP}$$\n"
    report = grade(write(tmp_path, "arrow-new.md", body))
    assert [(v.name, v.status, v.line) for v in report.steps] == [("tau_2", "correct", 4), ("tau_2", "wrong", 5)]
    assert report.steps[1].label == "\\tau_2"  # the arrow set aside


def test_a_plus_row_then_a_minus_row_reads_as_a_difference():
    # rows "+" and "-x" of a ```math block (a GitHub README's layout): + -x is - x
    text = "```math\nf =\n a\n\\\\\n+\n-b\n\\\\\n+\n- -c\n```\n"
    (eq,) = read_markdown("rows.md", text).equations
    a, b, c = sp.symbols("a b c")
    assert parse(eq.value, lambda n: sp.Symbol(n.base)) == a - b + c


def test_a_boxed_result_ending_in_thin_spaces_is_read(tmp_path):
    body = f"$$\\boxed{{\\;\\tau_2 = {TAU_2_OUT}.\\;}}$$\n"
    assert only(grade(write(tmp_path, "boxed.md", body))).status == "correct"


@pytest.mark.parametrize("sep", ["\\quad", "\\qquad", "\\;\\;", ",\\;\\;", "\\cr"])
def test_separators_between_two_equations(sep):
    assert [t for _, t in split_equations(f"a = b {sep} c = d")] == ["a = b", "c = d"]


@pytest.mark.parametrize("text", ["E \\;=\\; m v \\;+\\; c", "F = m\\; v = w", "y = \\;\\;L_1 c_1"])
def test_single_thin_spaces_do_not_split(text):
    assert [t for _, t in split_equations(text)] == [text]


# ---------------------------------------------------------------- 2. what the parser reads

T = sp.Symbol("t")
_FUNCS = {b: sp.Function(b)(T) for b in ("theta1", "theta2", "q1", "x")}


def _resolve(name: Name):
    """theta_1 -> theta1(t) (its dots: time derivatives), every other name a plain symbol."""
    key = name.base + name.sub.replace("{", "").replace("}", "")
    if key in _FUNCS:
        return _FUNCS[key].diff(T, name.dots) if name.dots else _FUNCS[key]
    return sp.Symbol(key + "'" * name.dots)


def read(text):
    return parse(text, _resolve)


a, b, c, d, m, v = sp.symbols("a b c d m v")
th1 = _FUNCS["theta1"]

READS = [
    (r"\boxed{a + b}", a + b),
    (r"\underbrace{a + b}_{\text{gravity}} + c", a + b + c),
    (r"\overbrace{a b}^{\text{Coriolis}} - c", a * b - c),
    (r"{\color{red} a} + \textcolor{blue}{b}", a + b),
    (r"a + \cancel{b} - \cancel{b}", a),
    (r"\bcancel{a} + \xcancel{b}", a + b),
    (r"\bigg( a + b \bigg) c", (a + b) * c),
    (r"\Big[ a - b \Big] c", (a - b) * c),
    (r"\left. a + b \right| + c", a + b + c),
    (r"\left| a - b \right|", sp.Abs(a - b)),
    (r"a\;b\!c\,d\quad", a * b * c * d),
    (r"\tfrac{1}{2} m v^2", m * v**2 / 2),
    (r"\dfrac{a}{b}", a / b),
    (r"\tfrac12 m", m / 2),
    (r"\operatorname{sin}\theta_1 + \operatorname{cos}(\theta_1)", sp.sin(th1) + sp.cos(th1)),
    (r"\frac{\mathrm{d}\theta_1}{\mathrm{d}t}", th1.diff(T)),
    (r"\frac{d^2 \theta_1}{dt^2}", th1.diff(T, 2)),
    (r"\dfrac{d x}{dt}", _FUNCS["x"].diff(T)),
    (r"\mathcal{P}_1 + \mathbb{a}", sp.Symbol("P1") + a),
    (r"\theta_1' + \theta_1''", th1.diff(T) + th1.diff(T, 2)),
    (r"a + - b", a - b),
    (r"a - - b", a + b),
]


@pytest.mark.parametrize("text,expected", READS, ids=[t for t, _ in READS])
def test_the_parser_reads(text, expected):
    assert sp.simplify(read(text) - expected) == 0


VECTORS = [
    r"\begin{bmatrix} a & b \end{bmatrix}^\intercal",
    r"\begin{bmatrix} a & b \end{bmatrix}^\top",
    r"\begin{bmatrix} a & b \end{bmatrix}^{\mathsf T}",
    r"\begin{bmatrix} a & b \end{bmatrix}^{\mathsf{T}}",
    r"\begin{bmatrix} a & b \end{bmatrix}^\mathsf{T}",
    r"\begin{bmatrix} a & b \end{bmatrix}^{\mathrm T}",
    r"\left[\begin{array}{c} a \\ b \end{array}\right]",
    r"\begin{pmatrix} a \cr b \end{pmatrix}",
    r"\pmatrix{a \cr b}",
]


@pytest.mark.parametrize("text", VECTORS)
def test_column_vectors_and_transposes(text):
    assert read(text) == sp.Matrix([a, b])


REFUSED = [
    (r"\begin{bmatrix} a & \cdots & b \\ \vdots & \ddots & \vdots \end{bmatrix}", "a general matrix", r"\cdots"),
    (r"a + \ldots + b", "elided terms", r"\ldots"),
    (r"\sum_{i=1}^{n} m_i", "a sum over an index", r"\sum"),
    (r"\int_0^t a \, \mathrm{d}t", "an integral", r"\int"),
    (r"\cancelto{0}{a} + b", "struck out towards a value", r"\cancelto"),
    (r"\left. a + b \right|_{t=0}", "an evaluation bar", r"\right"),
    (r"\operatorname{diag}(a, b)", r"\operatorname{diag}", r"\operatorname"),
    (r"\frac{d^2 \theta_1}{dt}", "a derivative written as a fraction", r"\frac"),
]


@pytest.mark.parametrize("text,why,at", REFUSED, ids=[t for t, _, _ in REFUSED])
def test_what_is_not_read_says_why_and_where(text, why, at):
    with pytest.raises(LatexError) as err:
        read(text)
    assert why in str(err.value)
    assert err.value.pos == text.index(at)


def test_a_general_matrix_in_a_step_is_refused_at_its_line_and_column(tmp_path):
    body = "Text.\n\n$$\\tau_2 = \\begin{bmatrix} m_2 & \\cdots \\end{bmatrix}$$\n"
    v = only(grade(write(tmp_path, "general.md", body)))
    col = body.split("\n")[2].index("\\cdots") + 1
    assert v.status == "unrecognised"
    assert f"general.md:6:{col}:" in v.message and "a general matrix" in v.message


# ---------------------------------------------------------------- 3. relations between steps

CRAIG_2R = (
    "---\nrobot: planar-2r\nmethod: newton-euler\nsymbols:\n  '\\theta_1': q1\n  '\\theta_2': q2\n"
    "  'l_1': l1\n  'l_{c2}': lc2\n  'm_2': m2\n  'I_2': I2\n  'g': g\n---\n"
)
# {}^2\dot v_{C_2} of the planar 2R (Craig's frames, gravity as a base acceleration g Y_0), by
# hand: the elbow's acceleration rotated into frame 2 plus the centre's tangential and
# centripetal parts; SLIP is the same with the sign of the centripetal part flipped
VC2 = (
    r"\begin{bmatrix} l_1 s_2\ddot\theta_1 - l_1 c_2\dot\theta_1^2 + g s_{12} - l_{c2}(\dot\theta_1 + \dot\theta_2)^2 \\ "
    r"l_1 c_2\ddot\theta_1 + l_1 s_2\dot\theta_1^2 + g c_{12} + l_{c2}(\ddot\theta_1 + \ddot\theta_2) \\ 0 \end{bmatrix}"
)
VC2_SLIP = VC2.replace(r"- l_{c2}(\dot", r"+ l_{c2}(\dot")


def test_a_step_written_as_another_step_alone_is_an_identity_that_holds(tmp_path):
    body = (
        f"$${{}}^{{2}}\\dot v_{{C_2}} = {VC2_SLIP}$$\n"
        "$${}^{2}F_{2} = {}^{2}f_{2}$$\n"  # tip free: the same quantity, whatever its value
        "$${}^{2}f_{2} = m_2\\,{}^{2}\\dot v_{C_2}$$\n"  # a formula in names: its value carries the slip
        f"$${{}}^{{2}}F_{{2}} = m_2 {VC2_SLIP}$$\n"  # a worked value: carries the slip
    )
    report = grade(write(tmp_path, "relation.md", body, header=CRAIG_2R))
    assert [(v.name, v.status) for v in report.steps] == [
        ("vc_dot_2", "wrong"),
        ("F_2", "correct"),
        ("f_2", "follows-from-earlier-error"),
        ("F_2", "follows-from-earlier-error"),
    ]
    assert "right as a relation between steps" in report.steps[1].message
    assert "follows from the error in vc_dot_2" in report.steps[1].message


def test_the_right_value_is_not_called_a_relation(tmp_path):
    body = f"$${{}}^{{2}}\\dot v_{{C_2}} = {VC2}$$\n$${{}}^{{2}}F_{{2}} = m_2\\,{{}}^{{2}}\\dot v_{{C_2}}$$\n"
    report = grade(write(tmp_path, "relation-right.md", body, header=CRAIG_2R))
    assert [(v.name, v.status, v.message) for v in report.steps] == [
        ("vc_dot_2", "correct", ""),
        ("F_2", "correct", ""),
    ]


@pytest.mark.parametrize(
    "text",
    ["\\frac{d" * 3000, "\\frac{d}{dt}" * 3000 + "x", "a" + "\\;\\;" * 20000 + "= b", "\\pmatrix{" * 3000],
    ids=["open-d-fractions", "d-dt-operators", "thin-space-runs", "plain-tex-matrices"],
)
def test_hostile_layouts_end_in_bounded_time(text):
    import time

    start = time.perf_counter()
    try:
        read(text)
    except LatexError:
        pass
    split_equations(text)
    assert time.perf_counter() - start < 2.0


def test_digits_typed_after_a_letter_are_its_subscript_and_said(tmp_path):
    body = f"$$\\tau_2 = {TAU_2_OUT.replace('m_2', 'm2')}$$\n"
    report = grade(write(tmp_path, "glued.md", body))
    assert only(report).status == "correct"
    assert "m2 read as m_{2} (digits typed after a letter)" in report.notes


def test_a_letter_then_a_space_then_digits_stays_a_product(tmp_path):
    body = f"$$\\tau_2 = {TAU_2_OUT.replace('m_2', 'm 2')}$$\n"
    v = only(grade(write(tmp_path, "spaced.md", body)))
    assert v.status == "unrecognised" and "unknown symbol m " in v.message


def test_the_last_of_a_run_of_math_lines_is_read_though_prose_follows(tmp_path):
    body = (
        "The torques, written out:\n"
        f"$\\tau_2 = {TAU_2}$\n"  # line 5: the line after is math
        f"$\\tau_2 = {TAU_2_OUT}$\n"  # line 6: the line before is math, prose after
        "This matches the matrix form.\n"
        "\n"
        "A sentence, then\n"
        f"$\\tau_2 = {TAU_2_OUT}$\n"  # line 10: alone between prose lines: prose
        "which we keep.\n"
    )
    report = grade(write(tmp_path, "run.md", body))
    assert [(v.name, v.status, v.line) for v in report.steps] == [("tau_2", "correct", 5), ("tau_2", "correct", 6)]
