"""`armdyn grade` reads derivations as people write them, and grades what it can read.

The derivations here are written in the layouts of public course notes, tutorial
solutions and notebooks (align* with rows continuing an equation, ```math fences, bare
environments, lone $...$ lines, colours, SymPy's own LaTeX). The expected values are the
RP arm's closed forms worked out by hand (examples/grading/README.md's frames: m1 at
l1 along the rotated x axis, m2 at d2 further along y1, gravity along -y0), checked
once more below by a plain SymPy Lagrangian: never armdyn's output.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest
import sympy as sp
from cli_support import grade_cli

from armdyn.grading import grade
from armdyn.grading.latex import Name, UnknownSymbol, parse
from armdyn.grading.reader import read_markdown

ROOT = Path(__file__).resolve().parent.parent
HEADER = "---\nrobot: rp-arm\n---\n"
#: hang guard for the subprocess runs (the real times are a few seconds, mostly start-up)
GUARD = 60

# the RP arm's torques by hand (Lagrange on the two point masses)
TAU_1 = (
    r"(m_1 + m_2) l_1^2 \ddot{\theta}_1 + m_2 l_1 \ddot{d}_2 + 2 m_2 d_2 \dot{\theta}_1 \dot{d}_2"
    r" + m_2 d_2^2 \ddot{\theta}_1 + (m_1 + m_2) g l_1 \cos\theta_1 - m_2 g d_2 \sin\theta_1"
)
TAU_2 = r"m_2 (l_1 \ddot{\theta}_1 - d_2 \dot{\theta}_1^2 + \ddot{d}_2 + g \cos\theta_1)"


def test_the_closed_forms_are_the_lagrangian_of_the_two_point_masses():
    """The second opinion on TAU_1, TAU_2: plain SymPy, no armdyn."""
    t = sp.Symbol("t")
    m1, m2, l1, g = sp.symbols("m_1 m_2 l_1 g")
    th, d = sp.Function("theta")(t), sp.Function("d")(t)
    p1 = sp.Matrix([l1 * sp.cos(th), l1 * sp.sin(th)])
    p2 = p1 + d * sp.Matrix([-sp.sin(th), sp.cos(th)])  # along y1
    kinetic = (m1 * p1.diff(t).dot(p1.diff(t)) + m2 * p2.diff(t).dot(p2.diff(t))) / 2
    potential = g * (m1 * p1[1] + m2 * p2[1])
    lag = kinetic - potential
    taus = [sp.diff(lag.diff(q.diff(t)), t) - lag.diff(q) for q in (th, d)]
    names = {
        "theta_1": th,
        "d_2": d,
        "m_1": m1,
        "m_2": m2,
        "l_1": l1,
        "g": g,
    }

    def resolve(name: Name):
        value = names[name.base + ("_" + name.sub if name.sub else "")]
        return value.diff(t, name.dots) if name.dots else value

    for text, tau in zip((TAU_1, TAU_2), taus):
        assert sp.simplify(parse(text, resolve) - tau) == 0


def write(tmp_path, name, body, header=HEADER):
    path = tmp_path / name
    path.write_text(header + body)
    return path


def statuses(report):
    return [(v.name, v.status) for v in report.steps]


# ---------------------------------------------------------------- 1. grade what can be read


MIXED = (
    "# 7-4\n"  # line 4
    "$$\\omega_1^1 = (0, 0, \\dot{\\theta}_1)^T$$\n"  # 5: right
    "$$\\tau_2 = k_7 \\ddot{d}_2$$\n"  # 6: an unknown symbol
    "$$F_5^5 = \\mathbf{0}$$\n"  # 7: a link the arm does not have
    "$$\\dot{\\omega}_1^1 = \\ddot{\\theta}_1$$\n"  # 8: a scalar for a vector
    "$$\\tau_3 = 0$$\n"  # 9: a joint the arm does not have
    "$$\\tau_1 = (m_1 + 2$$\n"  # 10: unreadable
    f"$$\\tau_1 = {TAU_1}$$\n"  # 11: right
)


def test_each_equation_that_cannot_be_graded_is_one_line_and_the_rest_is_graded(tmp_path):
    path = write(tmp_path, "mixed.md", MIXED)
    done = grade_cli(path)
    assert done.returncode == 1 and done.stderr == "", done.stderr
    assert "Traceback" not in done.stdout
    bad = [t for t in done.stdout.split("\n") if "unrecognised:" in t]
    assert len(bad) == 5, done.stdout
    expected = [
        f"{path}:6:12: tau_2: unknown symbol k_{{7}}",
        f"{path}:7: F_5 names link 5, but 'rp-arm' has links 1..2",
        f"{path}:8:22: omega_dot_1 is a vector, but the value is a scalar",
        f"{path}:9: tau_3 names joint 3, but 'rp-arm' has joints 1..2",
        f"{path}:10:",
    ]
    for line, words in zip(bad, expected):
        assert words in line, (words, line)
    assert "cannot read the value" in bad[-1] and "hint:" in bad[-1]
    report = grade(path)
    assert ("omega_1", "correct") in statuses(report) and ("tau_1", "correct") in statuses(report)


def test_json_keeps_its_documented_shape_when_some_equations_are_unrecognised(tmp_path):
    path = write(tmp_path, "mixed.md", MIXED)
    done = grade_cli(path, "--json")
    assert done.returncode == 1, done.stderr
    data = json.loads(done.stdout)
    steps = data["steps"]
    assert [s["status"] for s in steps].count("unrecognised") == 5
    assert {s["line"] for s in steps if s["status"] == "correct"} == {5, 11}


def test_a_file_whose_only_equations_name_no_step_is_still_refused(tmp_path):
    path = write(tmp_path, "none.md", "$$x = (1, 2$$\n$$y = 3$$\n")
    done = grade_cli(path)
    assert done.returncode == 2 and done.stderr.count("\n") == 1
    assert done.stderr.startswith(f"armdyn: error: {path}: no step") and "Traceback" not in done.stderr


# ---------------------------------------------------------------- 2. front matter after a comment


@pytest.mark.parametrize("lead", ["<!-- graded by armdyn -->\n", "\n\n", "<!--\n a note\n-->\n\n<!-- x -->\n"])
def test_a_comment_or_blank_lines_before_the_front_matter_do_not_hide_it(tmp_path, lead):
    path = write(tmp_path, "lead.md", f"$$\\tau_2 = {TAU_2}$$\n", header=lead + HEADER)
    report = grade(path)
    assert statuses(report) == [("tau_2", "correct")]
    assert report.steps[0].line == lead.count("\n") + 4


# ---------------------------------------------------------------- 3. every display-math form


def test_align_star_rows_continue_the_equation_and_the_last_side_is_graded(tmp_path):
    body = (
        "\\begin{align*}\n"
        "\\tau_2 &= m_2 \\ddot{d}_2 + m_2 l_1 \\ddot{\\theta}_1 \\\\\n"  # alone this row is wrong
        "       &\\quad - m_2 d_2 \\dot{\\theta}_1^2 + m_2 g \\cos\\theta_1 \\nonumber \\\\\n"
        f"       &= {TAU_2} \\label{{eq:tau2}}\n"
        "\\end{align*}\n"
    )
    report = grade(write(tmp_path, "align.md", body))
    assert statuses(report) == [("tau_2", "correct")]
    assert report.steps[0].line == 5


def test_a_plus_row_is_joined_to_the_value_before_it(tmp_path):
    body = (
        "$$\n\\begin{aligned}\n"
        "\\tau_2 &= m_2 \\ddot{d}_2 + m_2 l_1 \\ddot{\\theta}_1 \\\\\n"
        "&\\qquad - m_2 d_2 \\dot{\\theta}_1^2 + m_2 g \\cos\\theta_1\n"
        "\\end{aligned}\n$$\n"
    )
    assert statuses(grade(write(tmp_path, "aligned.md", body))) == [("tau_2", "correct")]


def test_the_last_row_decides_even_when_the_first_is_right(tmp_path):
    body = f"\\begin{{align}}\n\\tau_2 &= {TAU_2} \\\\\n&= m_2 \\ddot{{d}}_2\n\\end{{align}}\n"
    assert statuses(grade(write(tmp_path, "last.md", body))) == [("tau_2", "wrong")]


def test_continuation_blocks_join_the_equation_before(tmp_path):
    body = (
        "$$\\tau_2 = m_2 (\\ddot{d}_2 + l_1 \\ddot{\\theta}_1)$$\n"  # line 4
        "and the velocity and gravity terms\n"
        "$$- m_2 d_2 \\dot{\\theta}_1^2 + m_2 g \\cos\\theta_1$$\n"
        "$$\\tau_1 = \\frac{d}{dt}\\frac{\\partial L}{\\partial \\dot\\theta_1} - \\frac{\\partial L}{\\partial \\theta_1}$$\n"
        "$$= (m_1 + m_2) l_1^2 \\ddot{\\theta}_1 + m_2 l_1 \\ddot{d}_2 + 2 m_2 d_2 \\dot{\\theta}_1 \\dot{d}_2$$\n"
        "$$+ m_2 d_2^2 \\ddot{\\theta}_1 + (m_1 + m_2) g l_1 \\cos\\theta_1 - m_2 g d_2 \\sin\\theta_1$$\n"
    )
    report = grade(write(tmp_path, "blocks.md", body))
    assert statuses(report) == [("tau_2", "correct"), ("tau_1", "correct")]
    # a chain split over blocks is reported where its value is written (tau_1's: line 8)
    assert [v.line for v in report.steps] == [4, 8]


def test_a_continued_value_reports_the_column_of_its_second_piece(tmp_path):
    body = "$$\\tau_2 = m_2 \\ddot{d}_2$$\n$$+ m_2 q_9$$\n"
    v = grade(write(tmp_path, "col.md", body)).steps[0]
    assert v.status == "unrecognised" and f":5:{len('$$+ m_2 ') + 1}: tau_2: unknown symbol q_{{9}}" in v.message


def test_math_fences_environments_and_lone_dollar_lines_are_display_math(tmp_path):
    body = (
        "```math\n"
        f"\\tau_2 = {TAU_2} \\quad \\tau_1 = {TAU_1} \\tag{{7.4}}\n"
        "```\n"
        "```python\n"
        "print('$$\\tau_1 = 0$$')  # code, not math\n"
        "```\n"
        "\\begin{equation*}\n"
        "\\omega_1^1 = \\begin{pmatrix} 0 \\\\ 0 \\\\ \\dot{\\theta}_1 \\end{pmatrix} \\label{eq:w}\n"
        "\\end{equation*}\n"
        "\n"
        "$\\omega_2^2 = (0, -\\dot{\\theta}_1, 0)^T$\n"  # y2 = -z1
        "\n"
        "In the text $\\tau_1 = 0$ is not an equation of the derivation.\n"
        "\\[ \\dot{\\omega}_1^1 = (0, 0, \\ddot{\\theta}_1)^T \\]\n"
    )
    report = grade(write(tmp_path, "forms.md", body))
    assert statuses(report) == [
        ("tau_2", "correct"),
        ("tau_1", "correct"),
        ("omega_1", "correct"),
        ("omega_2", "correct"),
        ("omega_dot_1", "correct"),
    ]


def test_a_latex_fence_is_math_only_when_its_body_is(tmp_path):
    sub = read_markdown(
        str(write(tmp_path, "f.md", "```latex\n\\documentclass{article}\n\\tau_1 = 0\n```\n```tex\n\\tau_2 = 0\n```\n"))
    )
    assert [(e.lhs, e.value) for e in sub.equations] == [("\\tau_2", "0")]


def test_separators_between_equations_of_one_block(tmp_path):
    body = (
        f"$$\\tau_2 = {TAU_2}; \\qquad \\tau_1 = {TAU_1}$$\n"
        f"$$\\tau_2 = {TAU_2} \\text{{ and }} \\tau_1 = {TAU_1}$$\n"
        f"$$\\tau_2 = {TAU_2} \\quad \\text{{for all }} t \\geq 0, \\; d_2 = 0$$\n"
        f"$$\\tau_1 = {TAU_1} \\qquad (\\text{{by Lagrange}})$$\n"
    )
    assert statuses(grade(write(tmp_path, "sep.md", body))) == [("tau_2", "correct"), ("tau_1", "correct")] * 3


# ---------------------------------------------------------------- 4. syntax inside values


VALUES = {
    "colour": r"\color{grey}{m_2} \left( l_1 \ddot{\theta}_1 {\color{red} - d_2 \dot{\theta}_1^2} + \textcolor{blue}{\ddot{d}_2} + g \cos\theta_1 \right)",
    "power before subscript": r"m_2 (l_1 \ddot{\theta}_1 - d_2 \dot{\theta}^2_1 + \ddot{d}_2 + g \cos\theta_1)",
    "accent without braces": r"m_2 (l_1 \ddot\theta_1 - d_2 \dot\theta_1^2 + \ddot d_2 + g \cos\theta_1)",
    "sympy latex": r"m_{2} \left(g \cos{\left(\theta_{1} \right)} + l_{1} \ddot{\theta_1} - d_{2} \dot{\theta_1}^{2} + \ddot{d_2}\right)",
    "operatorname": r"m_2 \cdot (l_1 \ddot{\theta}_1 - d_2 \dot{\theta}_1^2 + \ddot{d}_2 + g \operatorname{cos}\theta_1)",
    "spacing": r"m_2\,\Big(l_1\ddot{\theta}_1 \;-\; d_2\,\dot{\theta}_1^2 \!+\ \ddot{d}_2~+ g\cos\theta_1\Big).",
    "fractions": r"\frac12 m_2 \cdot 2 (l_1 \ddot{\theta}_1 - d_2 \dot{\theta}_1^2) + \dfrac{m_2}{1} \ddot{d}_2 + \tfrac{2}{2} m_2 g \cos\theta_1",
    "times": r"m_2 \times (l_1 \ddot{\theta}_1 - d_2 \dot{\theta}_1^2 + \ddot{d}_2 + g \cos\theta_1),",
    "primes": r"m_2 (l_1 \theta_1'' - d_2 (\theta_1')^2 + d_2'' + g \cos\theta_1)",
}


@pytest.mark.parametrize("name", sorted(VALUES))
def test_values_written_as_the_field_writes_them(tmp_path, name):
    report = grade(write(tmp_path, "v.md", f"$$\\tau_2 = {VALUES[name]}$$\n"))
    assert statuses(report) == [("tau_2", "correct")], report.steps[0].message
    if name == "primes":  # the assumption is said
        assert any("prime" in n and "time derivative" in n for n in report.notes)


def test_a_wrong_coloured_value_is_still_wrong(tmp_path):
    body = (
        r"$$\tau_2 = m_2 (l_1 \ddot{\theta}_1 {\color{red} + d_2 \dot{\theta}^2_1} + \ddot{d}_2 + g \cos\theta_1)$$"
        + "\n"
    )
    assert statuses(grade(write(tmp_path, "w.md", body))) == [("tau_2", "wrong")]


def test_a_value_of_step_names_only_is_read_through_them(tmp_path):
    # f_1 = R f_2 + F_1 is the law itself: read through the (unwritten, so the method's) steps it is right
    body = r"$$f_1^1 = {}^{1}_{2}R \cdot f_2^2 + F_1^1$$" + "\n" + f"$$\\tau_2 = {TAU_2}$$\n"
    report = grade(write(tmp_path, "step.md", body))
    assert [v.status for v in report.steps] == ["correct", "correct"]


def test_prescripts_reach_the_resolver():
    seen = []

    def resolve(name: Name):
        seen.append(name)
        return sp.Symbol(name.base)

    parse(r"{}^{2}_{1}R + {}^{1}\dot{v}_1", resolve)
    assert seen == [Name("R", pre_sup="2", pre_sub="1"), Name("v", 1, "1", pre_sup="1")]
    with pytest.raises(UnknownSymbol, match="names a step"):
        parse(r"{}^{0}P", lambda n: (_ for _ in ()).throw(UnknownSymbol("unknown")))


# ---------------------------------------------------------------- 5. hostile input stays one line


def test_hostile_layout_is_bounded_and_one_equation_at_most(tmp_path):
    body = (
        f"$$\\tau_2 = {TAU_2}$$\n"
        "\\begin{align*}\n"  # never closed
        + "\\text{and}" * 20_000
        + "\n$$\\tau_1 = "
        + "\\color{red}" * 20_000
        + "(1$$\n"
        + "$" * 5000
        + "\n```math\n"  # never closed: the rest is its body
        + "\\tau_1 = 0 \\\\ = " * 2000
        + "\n"
    )
    path = write(tmp_path, "hostile.md", body)
    start = time.monotonic()
    done = grade_cli(path)
    assert time.monotonic() - start < GUARD and done.returncode == 1, done.stderr
    assert "Traceback" not in done.stdout + done.stderr
    assert any("τ_2" in t and "correct" in t for t in done.stdout.split("\n")), done.stdout


def test_code_fences_are_neither_math_nor_headings(tmp_path):
    body = "# 7-3\n```python\n# 7-4\nprint('$$\\tau_2 = 0$$')\n```\n" + f"$$\\tau_2 = {TAU_2}$$\n"
    report = grade(write(tmp_path, "code.md", body))
    assert [(v.name, v.status, v.part) for v in report.steps] == [("tau_2", "correct", "7-3")]


def test_an_equation_continued_without_end_is_one_unrecognised_line(tmp_path):
    from armdyn.grading.reader import MAX_ROWS

    body = f"$$\\tau_2 = {TAU_2}$$\n$$\\tau_1 = 0$$\n" + "$$+ 0$$\n" * (MAX_ROWS + 5)
    start = time.monotonic()
    report = grade(write(tmp_path, "rows.md", body))
    assert time.monotonic() - start < GUARD
    assert statuses(report) == [("tau_2", "correct"), ("tau_1", "unrecognised")]
    assert f"more than {MAX_ROWS} rows" in report.steps[1].message and ":5:" in report.steps[1].message


def test_eqnarray_rows_underbraces_and_a_boxed_answer(tmp_path):
    body = (
        "\\begin{eqnarray}\n"
        "\\tau_1 &=& (m_1 + m_2) l_1^2 \\ddot{\\theta}_1 + m_2 l_1 \\ddot{d}_2"
        " + \\underbrace{2 m_2 d_2 \\dot{\\theta}_1 \\dot{d}_2}_{\\text{Coriolis}} \\nonumber \\\\\n"
        "& & + m_2 d_2^2 \\ddot{\\theta}_1 + \\overbrace{(m_1 + m_2) g l_1 \\cos\\theta_1 - m_2 g d_2 \\sin\\theta_1}^{G_1}\n"
        "\\end{eqnarray}\n"
        f"$$\\boxed{{\\tau_2 = {TAU_2}}}$$\n"
    )
    report = grade(write(tmp_path, "eqnarray.md", body))
    assert statuses(report) == [("tau_1", "correct"), ("tau_2", "correct")]
    assert [v.line for v in report.steps] == [5, 8]


def test_an_unworked_derivative_is_refused_with_its_reason_and_mathrm_d_is_a_name(tmp_path):
    body = (
        "$$\\tau_1 = \\frac{\\mathrm{d}}{\\mathrm{d}t} \\frac{\\partial L}{\\partial \\dot\\theta_1}"
        " - \\frac{\\partial L}{\\partial \\theta_1}$$\n"
        "$$\\tau_2 = m_2 (l_1 \\ddot{\\theta}_1 - \\mathrm{d}_2 \\dot{\\theta}_1^2 + \\ddot{\\mathrm{d}}_2"
        " + g \\cos\\theta_1)$$\n"
    )
    report = grade(write(tmp_path, "d.md", body))
    assert statuses(report) == [("tau_1", "unrecognised"), ("tau_2", "correct")]
    assert ":4:12: cannot read the value: a derivative written as a fraction" in report.steps[0].message
