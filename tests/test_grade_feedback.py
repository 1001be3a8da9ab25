"""`armdyn grade` reads every equation of a hand derivation and says what to fix.

Expected values are worked out by hand from the frames documented in
examples/grading/README.md (rp-arm: frame 1's origin at l1 along the rotated x axis,
frame 2's origin at d2 along y1, point masses at the frame origins; planar-2r: frame 2 at
l1 along x1), never copied from armdyn's output. Hostile inputs run in a subprocess
with a generous timeout as a hang guard only; the real timings are in the report.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest
import sympy as sp
from cli_support import grade_cli

from armdyn.cli import main
from armdyn.grading import grade

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
EXAMPLES = ROOT / "examples" / "grading"
EXERCISE = EXAMPLES / "rp-arm-exercise.md"
HEADER = "---\nrobot: rp-arm\n---\n"
#: hang guard for hostile inputs (the real times are a few seconds, mostly start-up)
GUARD = 20


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def write(tmp_path, name, body, header=HEADER):
    path = tmp_path / name
    path.write_text(header + body)
    return path


def by_name(report, name):
    return next(v for v in report.steps if v.name == name)


def by_line(report, line):
    return [v for v in report.steps if v.line == line]


# ---------------------------------------------------------------- 1. every non-proof equation read


def test_position_vectors_and_rotations_are_kinematics_steps(tmp_path):
    # by hand: P_1^0 = l1 (cos θ1, sin θ1, 0); in frame 1 that is (l1, 0, 0); P_2^1 = (0, d2, 0);
    # point masses at the frame origins: P_{C_i}^i = 0; R_1^0 = Rz(θ1), R_0^1 its transpose
    path = write(
        tmp_path,
        "kin.md",
        r"""
$$\mathbf{P}_1^0 = \begin{pmatrix} l_1 \cos\theta_1 \\ l_1 \sin\theta_1 \\ 0 \end{pmatrix}$$
$$\mathbf{P}_1^1 = (l_1,\ 0,\ 0)^T, \mathbf{P}_{C_1}^1 = \mathbf{0},
\mathbf{P}_2^1 = \begin{pmatrix} 0 \\ d_2 \\ 0 \end{pmatrix}$$
$$\mathbf{P}_{C_2}^2 = \mathbf{0}$$
$$\mathbf{P}_2^1 = \begin{pmatrix} 0 \\ 0 \\ d_2 \end{pmatrix}$$
$$R_1^0 = \begin{pmatrix} \cos\theta_1 & -\sin\theta_1 & 0 \\ \sin\theta_1 & \cos\theta_1 & 0 \\
0 & 0 & 1 \end{pmatrix}$$
$$R_0^1 = \begin{pmatrix} \cos\theta_1 & -\sin\theta_1 & 0 \\ \sin\theta_1 & \cos\theta_1 & 0 \\
0 & 0 & 1 \end{pmatrix}$$
""",
    )
    r = grade(path)
    status = [(v.name, v.status) for v in r.steps]
    assert status[:5] == [
        ("P_1^0", "correct"),
        ("P_1^1", "correct"),
        ("P_C1^1", "correct"),
        ("P_2^1", "correct"),
        ("P_C2^2", "correct"),
    ]
    wrong = r.steps[5]
    assert (wrong.name, wrong.status, wrong.components) == ("P_2^1", "wrong", [1, 2])
    assert r.steps[6].status == "correct"  # R_1^0 maps frame-1 coordinates into frame 0: Rz(θ1)
    assert r.steps[7].status == "correct-by-convention" and "transposed" in r.steps[7].convention
    assert r.first_wrong == "P_2^1"


def test_lagrange_law_is_read_as_a_statement(tmp_path):
    laws = {
        r"\frac{d}{dt}\frac{\partial L}{\partial \dot{q}_i} - \frac{\partial L}{\partial q_i} = \tau_i": None,
        r"\frac{\partial L}{\partial \theta} - \frac{d}{dt}\frac{\partial L}{\partial \dot{\theta}} = \tau": "wrong order",
        r"\frac{d}{dt}\frac{\partial L}{\partial \dot{\theta}} + \frac{\partial L}{\partial \theta} = \tau": "wrong sign",
        r"\frac{\partial L}{\partial \dot{\theta}} - \frac{\partial L}{\partial \theta} = \tau": "d/dt missing",
    }
    body = "".join(f"$${law}$$\n\n" for law in laws) + "$$\\tau_2 = 0$$\n"
    r = grade(write(tmp_path, "law.md", body))
    verdicts = [v for v in r.steps if v.key == "law"]
    assert len(verdicts) == len(laws)
    for v, expect in zip(verdicts, laws.values()):
        if expect is None:
            assert v.status == "correct", v.message
        else:
            assert v.status == "wrong" and expect.split()[-1] in v.message, v.message


def test_exercise_every_non_proof_equation_read_and_parts_labelled(capsys):
    code, out, _ = run(capsys, "grade", EXERCISE, "--json")
    data = json.loads(out)
    steps = data["steps"]
    assert all("part" in s for s in steps)
    # the 7-4 verdicts as worked out by hand (examples/grading/README.md) are unchanged
    status = {s["name"]: s["status"] for s in steps if s["part"] == "7-4"}
    assert status["v_dot_1"] == status["F_2"] == status["n_1"] == "wrong"
    for name in ("vc_dot_1", "v_dot_2", "vc_dot_2", "F_1", "f_2", "n_2", "f_1"):
        assert status[name] == "follows-from-earlier-error", name
    assert status["tau_1"] == "correct-but-unsupported" and status["tau_2"] == "correct"
    assert status["R_0^1"] == status["R_1^2"] == "correct"  # as the README now says
    assert data["first_wrong"] == "v_dot_1" and code == 1
    # the parts: 7-3 and 7-4 by their number lines; the two unnumbered tasks null, with titles
    lines = EXERCISE.read_text().split("\n")
    lagrange_line = next(k for k, t in enumerate(lines, 1) if t.startswith("Check the answer in 7-4"))
    energy_line = next(k for k, t in enumerate(lines, 1) if t.startswith("Prove that the rotational"))
    seven_four = next(k for k, t in enumerate(lines, 1) if t.strip() == "# 7-4")
    for s in steps:
        if s["line"] > lagrange_line:
            assert s["part"] is None and s["task"].startswith("Check the answer in 7-4"), s
        elif s["line"] > energy_line:
            assert s["part"] is None and s["task"].startswith("Prove that the rotational energy"), s
        elif s["line"] > seven_four:
            assert s["part"] == "7-4", s
        else:
            assert s["part"] == "7-3", s
    # no equation outside the two proofs (graded by the proof checker) is left unread; the
    # Lagrange statement is checked
    unread = [s for s in steps if s["status"] == "unrecognised"]
    assert all(s["part"] == "7-3" or s["task"].startswith("Prove that the rotational") for s in unread), unread
    law = [s for s in steps if s["line"] > lagrange_line and s["name"] == "lagrange_equation"]
    assert len(law) == 1 and law[0]["status"] == "correct"
    assert next(s for s in steps if s["line"] > lagrange_line and s["name"] == "L")["status"] == "correct"


def test_free_end_condition_is_a_step_not_an_abort(tmp_path):
    path = write(
        tmp_path,
        "free.md",
        r"""
$$f_3^3 = \mathbf{0}, n_3^3 = 0$$
$$f_3^3 = \begin{pmatrix} m_2 g \\ 0 \\ 0 \end{pmatrix}$$
$$\tau_2 = m_2 l_1 \ddot{\theta}_1 + m_2 \ddot{d}_2 - m_2 d_2 \dot{\theta}_1^2 + m_2 g \cos\theta_1$$
""",
    )
    r = grade(path)
    assert [(v.name, v.status) for v in r.steps] == [
        ("f_3", "correct"),
        ("n_3", "correct"),
        ("f_3", "wrong"),
        ("tau_2", "correct"),
    ]
    assert r.steps[2].components == [0] and "free end" in r.steps[2].message


def test_reaction_convention_recognised_for_n(tmp_path):
    # planar-2r-craig.md's n_2 is right (README); written as the reaction -n_2 it is the same
    # statement in the other sign convention, as f_i already is
    text = (EXAMPLES / "planar-2r-craig.md").read_text().split("\n")
    k = next(i for i, t in enumerate(text) if t.startswith("$${}^{2}n_{2}"))
    lhs, _, rhs = text[k].rpartition("= ")
    assert rhs.startswith("\\begin{bmatrix}") and rhs.endswith("$$")
    text[k] = text[k].split(" = ")[0] + " = -" + rhs  # the value alone, its sign flipped
    path = tmp_path / "reaction.md"
    path.write_text("\n".join(text))
    v = by_name(grade(path), "n_2")
    assert v.status == "correct-by-convention" and "reaction" in v.convention
    # with the formula member N_2 + P_{C_2} x F_2 kept, the chain no longer holds: that member is the action
    text[k] = lhs + "= -" + rhs
    path.write_text("\n".join(text))
    v = by_name(grade(path), "n_2")
    assert v.status == "wrong" and "formula member" in v.message and v.line == k + 1


# ---------------------------------------------------------------- 2. messages


def test_exit_status_is_zero_only_when_every_equation_was_read(tmp_path, capsys):
    good = (EXAMPLES / "rp-arm-dalembert.md").read_text()
    code, _, _ = run(capsys, "grade", EXAMPLES / "rp-arm-dalembert.md")
    assert code == 0
    path = tmp_path / "unread.md"
    path.write_text(good + "\n$$\\tau_2 = m_2 \\ddot{d}_2 \\oint x$$\n")
    code, out, _ = run(capsys, "grade", path)
    assert code == 1 and "\\oint" in out


def test_unreadable_equation_names_line_column_and_the_open_brace(tmp_path):
    body = "$$\\tau_1 = 0$$\n\n$$\\tau_2 = m_2 \\ddot{d_2\n + g \\cos\\theta_1$$\n"
    path = write(tmp_path, "brace.md", body)
    lines = (HEADER + body).split("\n")
    k = next(i for i, t in enumerate(lines) if "ddot{d_2" in t)
    column = lines[k].index("{") + 1  # the brace that is never closed, 1-based
    v = by_name(grade(path), "tau_2")
    assert v.status == "unrecognised"
    assert f"line {k + 1}, column {column}" in v.message and "never closed" in v.message
    assert v.message.startswith(f"{path}:{k + 1}:")


def test_unreadable_value_reports_its_exact_column_and_a_hint(tmp_path):
    body = "$$\\tau_2 = m_2 \\ddot{d}_2 + (m_2 g, 0$$\n"
    path = write(tmp_path, "paren.md", body)
    v = by_name(grade(path), "tau_2")
    line = HEADER.count("\n") + 1
    column = body.index("$$", 2) + 1  # reading stops at the end: the '(' is never closed
    assert v.message.startswith(f"{path}:{line}:{column}: cannot read the value")
    assert "hint:" in v.message


def test_row_transposed_and_big_delimiters_are_read(tmp_path):
    path = write(
        tmp_path,
        "forms.md",
        r"""
$$\omega_1^1 = (0,\ 0,\ \dot{\theta}_1)^T$$
$$\dot{\omega}_1^1 = (0, 0, \ddot{\theta}_1)^{\mathrm{T}}$$
$$\tau_2 = m_2 \big( l_1 \ddot{\theta}_1 + \ddot{d}_2 \bigr) - m_2 \Big[ d_2 \dot{\theta}_1^2 - g \cos\theta_1 \Big]$$
""",
    )
    r = grade(path)
    assert [(v.name, v.status) for v in r.steps] == [
        ("omega_1", "correct"),
        ("omega_dot_1", "correct"),
        ("tau_2", "correct"),
    ]


@pytest.fixture(scope="module")
def craig_slip(tmp_path_factory):
    """planar-2r-craig.md with a sign slip in v̇_2's x component: +l1 θ̇1² c2 for -l1 θ̇1² c2."""
    text = (EXAMPLES / "planar-2r-craig.md").read_text().split("\n")
    k = next(i for i, t in enumerate(text) if t.startswith(r"$${}^{2}\dot{v}_{2} ="))
    j = text[k].rindex(r"- l_1 c_2 \dot{\theta}_1^2")
    text[k] = text[k][:j] + "+" + text[k][j + 1 :]
    path = tmp_path_factory.mktemp("slip") / "craig-slip.md"
    path.write_text("\n".join(text))
    return path


def test_difference_is_simplified_and_expected_in_the_students_shorthand(craig_slip, capsys):
    code, out, _ = run(capsys, "grade", craig_slip, "--json")
    step = next(s for s in json.loads(out)["steps"] if s["name"] == "v_dot_2")
    assert step["status"] == "wrong"
    q2, l1, q1d = sp.symbols("q2 l1 q1_dot")
    diff = sp.sympify(step["difference"][0])
    # by hand: (+l1 θ̇1² c2) - (-l1 θ̇1² c2); nothing else left, no angle sum to cancel
    assert diff == 2 * l1 * q1d**2 * sp.cos(q2)
    assert [sp.sympify(d) for d in step["difference"][1:]] == [0, 0]
    code, out, _ = run(capsys, "grade", craig_slip)
    line = next(t for t in out.split("\n") if "v̇_2" in t and "WRONG" in t)
    assert "wrong sign on the term −c₂ l₁ q̇₁²" in line
    expected = next(t for t in out.split("\n")[out.split("\n").index(line) :] if "expected:" in t)
    assert "g s₁₂" in expected and "c₁₂ g" in expected  # the student's s_{12}, c_{12}


def test_large_difference_falls_back_unsimplified_with_a_note(tmp_path):
    # 79 distinct monomials, exponents within the reader's limit for symbols (20)
    extra = " + ".join(f"{k} m_2 d_2^{{{k % 9 + 1}}} \\dot{{d}}_2^{{{k // 9 + 1}}}" for k in range(1, 80))
    path = write(tmp_path, "large.md", f"$$\\tau_2 = m_2 \\ddot{{d}}_2 + {extra}$$\n")
    v = by_name(grade(path), "tau_2")
    assert v.status == "wrong" and "not simplified" in v.message


def test_json_error_object_on_bad_input(tmp_path, capsys):
    # nothing can be graded (the front matter cannot be read); before, a link the robot
    # does not have (F_5^5 = 0) refused the whole file: it is one unrecognised step now
    text = "<!-- a comment -->\n---\nrobot: rp-arm\nmethod: [newton\n---\n$$\\tau_1 = 0$$\n"
    path = write(tmp_path, "bad.md", text, header="")
    code, out, err = run(capsys, "grade", path, "--json")
    assert code == 2 and err == ""
    data = json.loads(out)
    assert data["file"] == str(path) and data["line"] == 5 and "malformed YAML" in data["error"]
    assert set(data) == {"error", "file", "line", "column"}


def test_text_uses_derives_symbol_names(capsys):
    code, out, _ = run(capsys, "grade", EXERCISE)
    assert "missing term −l₁ θ̇₁² in the x component" in out
    assert "θ1" not in out and "l1·" not in out
    code, out, _ = run(capsys, "grade", EXERCISE, "--ascii")
    assert out.isascii() and "missing term -l1 theta1_dot**2" in out


# ---------------------------------------------------------------- 3. hostile input, bounded time


def _grade_subprocess(path, *extra):
    return grade_cli(path, *extra, timeout=GUARD)


HOSTILE_VALUES = {
    "tower": ("{{{{9}^{99}}^{99}}^{99}}^{99}", "digits"),
    "digits": ("7" * 5000, "5000 digits"),
    "fractions": ("\\frac{" * 400 + "1" + "}{2}" * 400, "nesting"),
    "accents": ("\\dot{" * 3000 + "x" + "}" * 3000, "nesting"),
    "functions": ("\\sin" * 3000 + " 1", "nesting"),
    "powers": ("d_2^{" * 3000 + "1" + "}" * 3000, "nesting"),
    "sqrt": ("\\sqrt{" * 3000 + "1" + "}" * 3000, "nesting"),
    # SymPy's real and imaginary parts: exponential in the nesting, cubic in the exponent
    "nested functions": ("\\sqrt{(" + "\\cos(" * 12 + "m_1" + ")" * 12 + ")^2}", "nesting of functions deeper than 4"),
    "symbolic power": ("\\sqrt{\\cos(m_1^{999})^2}", "an exponent of 999 (at most 20)"),
}


@pytest.mark.parametrize("name", sorted(HOSTILE_VALUES))
def test_hostile_value_is_one_clear_line_naming_file_and_line(tmp_path, name):
    value, words = HOSTILE_VALUES[name]
    path = write(tmp_path, f"{name}.md", f"$$\\tau_2 = 0$$\n$$\\tau_1 = {value}$$\n")
    done = _grade_subprocess(path)
    assert done.returncode == 1, done.stderr
    lines = [t for t in done.stdout.split("\n") if "τ_1" in t and "unrecognised" in t]
    assert len(lines) == 1 and f"{path}:5:" in lines[0] and words in lines[0], done.stdout
    for bad in ("Traceback", "RecursionError", "internal error", "Exceeds the limit"):
        assert bad not in done.stdout + done.stderr


def test_many_one_line_equations_end_in_an_error_naming_the_line(tmp_path):
    path = write(tmp_path, "many.md", "$$\\tau_2 = 0$$\n" * 130_000)
    done = _grade_subprocess(path)
    assert done.returncode == 2 and done.stderr.count("\n") == 1
    assert done.stderr.startswith(f"armdyn: error: {path}:") and "equations" in done.stderr


@pytest.mark.parametrize("shape", ["lines", "one-block", "prose", "unclosed"])
def test_a_file_just_under_the_size_limit_ends_in_bounded_time(tmp_path, shape):
    size = 4_900_000
    body = {
        "lines": "$$a = b$$\n",
        "one-block": "$$\\tau_1 = " + "1," * (size // 2) + "1$$\n",
        "prose": "7-4\n## Solution\nsome words\n",
        "unclosed": "\\[ x ",
    }[shape]
    text = body * max(1, size // len(body)) if shape != "one-block" else body
    path = write(tmp_path, f"{shape}.md", "$$\\tau_2 = 0$$\n" + text[:size])
    done = _grade_subprocess(path, "--json")
    assert done.returncode in (1, 2)
    data = json.loads(done.stdout)
    assert "error" in data or data["steps"]
    if "error" in data:
        assert data["file"] == str(path) and data["line"]


def test_hostile_yaml_values_in_sympy_syntax_are_refused_naming_the_line(tmp_path):
    digits = "1" + "0" * 5000
    path = tmp_path / "tower.yaml"
    path.write_text(
        f'robot: rp-arm\nsteps:\n  tau_2: "(((9**99)**99)**99)**99"\n  tau_1: "{digits}"\n'
        f'  T: "{"+".join(["m1"] * 3000)}+((9**99)**99)**99"\n'
        '  V: "((m1*9**99)**99)**99"\n'
    )  # a symbol's numeric coefficient grows too
    done = _grade_subprocess(path)
    assert done.returncode == 1, done.stderr
    for line, words in ((3, "digits"), (4, "5001 digits"), (5, "digits"), (6, "digits")):
        assert any(f"{path}:{line}: cannot read the value" in t and words in t for t in done.stdout.split("\n")), line
    assert "Exceeds the limit" not in done.stdout + done.stderr


def test_yaml_values_sympy_cannot_split_in_bounded_time_are_refused_naming_the_line(tmp_path):
    """Before: showing the difference turned the value into SymPy, which split
    cos(m1**999) into real and imaginary parts by expanding (a + i b)**999 (minutes), and
    nested functions in time exponential in the nesting (12 levels: 20 s)."""
    nested = "cos(" * 6 + "m1" + ")" * 6
    path = tmp_path / "slow.yaml"
    path.write_text(f'robot: rp-arm\nsteps:\n  tau_1: "sqrt(cos(m1**999)**2)"\n  tau_2: "sqrt(({nested})**2)"\n')
    start = time.monotonic()
    done = _grade_subprocess(path)
    assert done.returncode == 1 and time.monotonic() - start < GUARD, done.stderr
    for line, words in ((3, "an exponent of 999 (at most 20)"), (4, "nesting of functions deeper than 4 levels")):
        assert any(f"{path}:{line}: cannot read the value: {words}" in t for t in done.stdout.split("\n")), line


def test_deeply_nested_yaml_value_is_a_clear_error(tmp_path):
    path = tmp_path / "deep.yaml"
    path.write_text("robot: rp-arm\nsteps:\n  tau_1: '0'\n  tau_2: " + "[" * 5000 + "]" * 5000 + "\n")
    done = _grade_subprocess(path)
    assert done.returncode == 2 and done.stderr.count("\n") == 1
    # refused by the YAML screen (nesting) or by the step reader, at the value's line
    assert done.stderr.startswith(f"armdyn: error: {path}:4: ") and "internal error" not in done.stderr
    assert "step 'tau_2'" in done.stderr or "nesting deeper than" in done.stderr


def test_powers_print_as_superscripts_or_caret_never_as_dots():
    """Grade's one-line values: exponents 2..9 as superscripts, any other power with ^
    (m₁^999, not m₁··999, which reads as a product)."""
    from armdyn.grading.explain import pretty

    m1, x = sp.symbols("m1 x")
    assert pretty(m1**2 * x) in ("m₁² x", "x m₁²")
    assert pretty(m1**999) == "m₁^999"
    assert "·" not in pretty(2 * x * m1**999) and "^999" in pretty(2 * x * m1**999)
    assert pretty(x ** sp.Symbol("k")) == "x^k"
