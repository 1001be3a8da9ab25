"""`armdyn grade`: a student's own derivation checked step by step.

The expected verdicts are not armdyn's output: they are the ones worked out by hand in
examples/grading/README.md (the exercise's slips are the student's own; every other file's
slips were put in by hand and checked with an independent NumPy script of point positions
and momentum balances).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import sympy as sp
import yaml

import armdyn
from armdyn.cli import main
from armdyn.grading import grade
from armdyn.grading.latex import LatexError, parse, split_equations
from armdyn.grading.sympy_syntax import parse_sympy_syntax

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parent / "examples" / "grading"
EXERCISE = EXAMPLES / "rp-arm-exercise.md"


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def first_status(report, name):
    return next(v for v in report.steps if v.name == name)


@pytest.fixture(scope="module")
def exercise():
    return grade(EXERCISE)


def test_exercise_verdict_is_the_one_worked_out_by_hand(exercise):
    r = exercise
    assert r.first_wrong == "v_dot_1"
    v1 = first_status(r, "v_dot_1")
    assert v1.status == "wrong" and v1.components == [0]
    assert "missing term −l₁ θ̇₁²" in v1.message  # derive's symbol names and "x component" in v1.message
    for name in ("vc_dot_1", "v_dot_2", "vc_dot_2", "F_1", "f_2", "n_2", "f_1"):
        v = first_status(r, name)
        assert v.status == "follows-from-earlier-error", name
        assert v.caused_by == "v_dot_1", name
    assert "d'Alembert" in first_status(r, "F_1").convention
    f2 = first_status(r, "F_2")
    assert f2.status == "wrong" and f2.components == [0]
    assert "θ̇₁ written where θ̈₁ belongs" in f2.message
    n1 = first_status(r, "n_1")
    assert n1.status == "wrong" and "factor l₁ missing" in n1.message and n1.components == [2]
    tau = [v for v in r.steps if v.key == "tau"]
    assert [(v.name, v.status) for v in tau[:2]] == [("tau_1", "correct-but-unsupported"), ("tau_2", "correct")]
    assert "−d₂ l₁ m₂ θ̇₁²" in tau[0].message  # what the first slip would leave, carried through
    for name in (
        "omega_0",
        "omega_dot_0",
        "v_dot_0",
        "omega_1",
        "omega_dot_1",
        "omega_2",
        "omega_dot_2",
        "N_1",
        "N_2",
        "R_0^1",
        "R_1^2",
        "T",
        "V",
        "L",
    ):
        assert first_status(r, name).status == "correct", name
    assert [v.status for v in tau[2:]] == ["correct", "correct"]  # the Lagrange check
    assert r.tau_correct == [True, True]
    assert r.method == "newton-euler+lagrange"
    # the parallel-axis and rotational-energy proofs are graded link by link (tests/test_grade_proofs.py),
    # never as dynamics steps; what is left unrecognised is shown and skipped
    proofs = [v for v in r.steps if v.key == "proof"]
    assert len(proofs) >= 10 and all(v.line < 85 or v.line > 130 for v in proofs)
    skipped = [v for v in r.steps if v.status == "unrecognised"]
    assert all(v.line > 0 for v in skipped)


# (file, first wrong, the steps that follow from it, tau_correct): examples/grading/README.md
EXAMPLE_TABLE = [
    ("rp-arm-dalembert.md", None, [], [True, True]),
    ("planar-2r-craig.md", "vc_dot_2", ["F_2", "f_2", "f_1", "n_1", "tau_1"], [False, True]),
    ("planar-3r-spong.md", "N_3", ["n_3", "tau_3", "n_2", "tau_2", "n_1", "tau_1"], [False, False, False]),
    ("planar-2r-lagrange.md", "dL_dq_2", ["tau_2"], [True, False]),
    ("scara-lagrange.md", "V", ["L", "dL_dq_3", "tau_3"], [True, True, False, True]),
]


@pytest.mark.parametrize("name, first, follows, taus", EXAMPLE_TABLE)
def test_hand_written_examples_give_their_known_first_wrong_step(name, first, follows, taus):
    r = grade(EXAMPLES / name)
    assert r.first_wrong == first
    got_follows = sorted(v.name for v in r.steps if v.status == "follows-from-earlier-error")
    assert got_follows == sorted(follows)
    assert all(v.caused_by == first for v in r.steps if v.status == "follows-from-earlier-error")
    wrong = [v.name for v in r.steps if v.status == "wrong"]
    assert wrong == ([first] if first else [])
    assert r.tau_correct == taus


def test_correct_derivation_in_dalembert_convention_names_the_convention():
    r = grade(EXAMPLES / "rp-arm-dalembert.md")
    assert r.passed and r.first_wrong is None
    for name in ("F_1", "F_2"):
        v = first_status(r, name)
        assert v.status == "correct-by-convention" and "d'Alembert" in v.convention


def test_cli_text_json_and_exit_status(capsys):
    code, out, err = run(capsys, "grade", EXERCISE)
    assert code == 1 and err == ""
    assert "first wrong step: v̇_1" in out and "missing term −l₁ θ̇₁² in the x component" in out
    code, out, _ = run(capsys, "grade", EXERCISE, "--json")
    data = json.loads(out)
    assert {"robot", "method", "steps", "first_wrong", "tau_correct"} <= set(data)
    assert data["first_wrong"] == "v_dot_1" and data["tau_correct"] == [True, True]
    step = next(s for s in data["steps"] if s["name"] == "v_dot_1")
    assert {"name", "link", "status", "expected", "got", "difference", "convention", "caused_by"} <= set(step)
    assert step["link"] == "link1" and step["status"] == "wrong"
    # the difference is a SymPy string that parses back to +l1*theta1_dot**2 in x
    diff = sp.sympify(step["difference"][0])
    assert sp.simplify(diff - sp.Symbol("l1") * sp.Symbol("theta1_dot") ** 2) == 0
    code, _, _ = run(capsys, "grade", EXAMPLES / "rp-arm-dalembert.md")
    assert code == 0
    code, out, _ = run(capsys, "grade", EXERCISE, "--ascii")
    assert out.isascii() and "missing term -l1 theta1_dot**2" in out


def test_markdown_read_back_as_yaml_grades_the_same(tmp_path, capsys):
    code, out, _ = run(capsys, "grade", EXERCISE, "--to-yaml")
    assert code == 0
    path = tmp_path / "exercise.yaml"
    path.write_text(out)
    a, b = grade(EXERCISE), grade(path)
    proof_lines = {v.line for v in a.steps if v.key == "proof"}  # proofs need the prose: Markdown only
    assert proof_lines
    assert [(v.name, v.status) for v in a.steps if v.key != "proof"] == [
        (v.name, v.status) for v in b.steps if v.line not in proof_lines
    ]


def test_yaml_in_sympy_syntax(tmp_path):
    path = tmp_path / "planar.yaml"
    path.write_text(
        "robot: planar-2r\nmethod: lagrange\nsteps:\n"
        "  T: 'm1*lc1**2*q1_dot**2/2 + I1*q1_dot**2/2'\n"  # link 2's kinetic energy forgotten
        "  V: 'm1*g*lc1*sin(q1) + m2*g*(l1*sin(q1) + lc2*sin(q1 + q2))'\n"
    )
    r = grade(path)
    assert r.first_wrong == "T"
    assert first_status(r, "V").status == "correct"
    assert first_status(r, "T").line == 4


def test_generated_derivation_with_one_term_altered(tmp_path):
    """Steps written out from armdyn's Newton-Euler for the SCARA (4 dof, published
    numbers), one term added to one step: that step is the first and only wrong one."""
    robot = armdyn.load("scara").bind()
    steps = []
    for s in armdyn.derive(robot, "newton-euler").steps:
        i = robot.link_index(s.link)
        key = f"tau_{robot.coordinate_index(robot.parent_joint(s.link)) + 1}" if s.name == "tau" else f"{s.name}_{i}"
        value = s.value
        if key == "f_3":
            value = value + sp.Matrix([0, robot.qd[0] * robot.qd[1], 0])
        steps.append(
            {"step": key, "value": [str(x) for x in value] if isinstance(value, sp.MatrixBase) else str(value)}
        )
    path = tmp_path / "scara.yaml"
    path.write_text(yaml.safe_dump({"robot": "scara", "values": "published", "steps": steps}, width=10**6))
    r = grade(path)
    assert r.first_wrong == "f_3"
    v = first_status(r, "f_3")
    assert v.components == [1] and "extra term" in v.message
    assert [x.name for x in r.steps if x.status == "wrong"] == ["f_3"]
    # f_2 = R_3^2 f_3 + F_2 and n_2 (P_3 x R_3^2 f_3) are written right, so they do not follow
    # from the student's own f_3: right but unsupported; everything after them follows from theirs
    unsupported = [x.name for x in r.steps if x.status == "correct-but-unsupported"]
    assert unsupported == ["f_2", "n_2"]
    assert [x.name for x in r.steps if x.status not in ("correct", "correct-but-unsupported")] == ["f_3"]


BAD = {
    "no-equation.md": ("---\nrobot: rp-arm\n---\nJust prose, $x$ inline.\n", "no step"),
    "front.md": ("---\nrobot: [rp-arm\n---\n$$\\tau_1 = 0$$\n", "malformed YAML"),
    "robot.md": ("---\nrobot: no-such-arm\n---\n$$\\tau_1 = 0$$\n", "no-such-arm"),
    "alias.yaml": ("robot: rp-arm\nx: &a [1, 2]\ny: *a\nsteps: {T: '0'}\n", "aliases"),
}


#: an equation that names a step but cannot be graded: one unrecognised line, the rest graded
#: (before, each of these refused the whole file)
UNGRADABLE = {
    "unknown-symbol.md": ("\n$$\\tau_2 = k_7 \\ddot{d}_2$$\n", ":5:12: tau_2: unknown symbol k_{7}"),
    "short-vector.md": (
        "$$\\omega_1^1 = \\begin{pmatrix} 0 \\\\ 0 \\end{pmatrix}$$\n",
        ":4:16: omega_1 must be a vector of 3 components",
    ),
    "no-link.md": ("$$F_5^5 = \\mathbf{0}$$\n", ":4: F_5 names link 5"),
}


@pytest.mark.parametrize("name", sorted(UNGRADABLE))
def test_an_equation_that_cannot_be_graded_is_one_unrecognised_line(tmp_path, capsys, name):
    text, expected = UNGRADABLE[name]
    path = tmp_path / name
    path.write_text("---\nrobot: rp-arm\n---\n" + text + "\n$$\\tau_1 = 0$$\n")
    code, out, err = run(capsys, "grade", path)
    assert code == 1 and err == ""
    bad = [t for t in out.split("\n") if "unrecognised:" in t]
    assert len(bad) == 1 and f"{path}{expected}" in bad[0], out
    assert any("τ_1" in t and "wrong" in t for t in out.split("\n")), out  # the other equation graded


@pytest.mark.parametrize("name", sorted(BAD))
def test_bad_input_is_one_line_and_exit_2(tmp_path, capsys, name):
    text, expected = BAD[name]
    path = tmp_path / name
    path.write_text(text)
    code, out, err = run(capsys, "grade", path)
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("armdyn: error: ") and "Traceback" not in err
    assert str(path) in err and expected in err, err


def test_a_huge_file_and_a_missing_file_are_refused(tmp_path, capsys):
    big = tmp_path / "big.md"
    big.write_text("x" * 6_000_000)
    code, _, err = run(capsys, "grade", big)
    assert code == 2 and "bytes" in err
    code, _, err = run(capsys, "grade", tmp_path / "none.md")
    assert code == 2 and "none.md" in err


def test_unreadable_single_equations_are_skipped_not_fatal(tmp_path):
    nested = "(" * 500 + "x" + ")" * 500
    path = tmp_path / "mixed.md"
    path.write_text(
        "---\nrobot: rp-arm\n---\n$$\\omega_1^1 = \\begin{pmatrix} 0 \\\\ 0 \\\\ \\dot\\theta_1 \\end{pmatrix}$$\n"
        "$$\\omega_2^2 = \\frac{1}{$$\n"
        f"$$\\tau_2 = {nested}$$\n"
        "$$\\tau_1 = \\frac{0}{0}$$\n"
    )
    r = grade(path)
    status = {v.line: v.status for v in r.steps}
    assert status == {4: "correct", 5: "unrecognised", 6: "unrecognised", 7: "unrecognised"} or (
        status[4] == "correct"
        and status[5] == "unrecognised"
        and status[6] == "unrecognised"
        and status[7] != "correct"
    )  # 0/0 is never equal to anything


def test_nan_never_passes(tmp_path):
    path = tmp_path / "nan.yaml"
    path.write_text("robot: rp-arm\nsteps:\n  tau_2: 'm2*(d2_ddot + g*cos(theta1)) * 0 + log(-1 - theta1**2)'\n")
    r = grade(path)
    assert first_status(r, "tau_2").status != "correct"


def test_latex_reader_pieces():
    def resolve(n):
        return sp.Symbol(n.base + n.sub + "_dot" * n.dots)

    assert (
        parse(r"\frac{1}{2} m_1 (l_1 \dot{\theta}_1)^2", resolve)
        == sp.Rational(1, 2) * sp.Symbol("m1") * (sp.Symbol("l1") * sp.Symbol("theta1_dot")) ** 2
    )
    assert parse(r"\sin^2\theta_1 + \cos(\theta_1)", resolve) == sp.sin(sp.Symbol("theta1")) ** 2 + sp.cos(
        sp.Symbol("theta1")
    )
    with pytest.raises(LatexError):
        parse("(" * 100 + "x" + ")" * 100, resolve)
    eqs = split_equations(r"a &= 0, b = \begin{pmatrix} 1, 2 \\ 3 \end{pmatrix} \\ c = 1")
    assert [e for _, e in eqs] == ["a  = 0", r"b = \begin{pmatrix} 1, 2 \\ 3 \end{pmatrix}", "c = 1"]
    with pytest.raises(LatexError, match="huge"):
        parse_sympy_syntax("10**10**10", {})
    with pytest.raises(LatexError):
        parse_sympy_syntax("__import__('os')", {})


def test_armdyn_grade_is_callable():
    assert armdyn.grade(EXAMPLES / "rp-arm-dalembert.md").passed


def test_hostile_values_are_refused_in_bounded_time(tmp_path):
    import time

    path = tmp_path / "hostile.md"
    path.write_text(
        "---\nrobot: rp-arm\n---\n"
        "$$\\tau_1 = 10^{10^{10}}$$\n"
        "$$\\tau_2 = " + "\\dot{" * 3000 + "x" + "}" * 3000 + "$$\n"
        "$$T = " + "{" * 5000 + "m_1" + "}" * 5000 + "$$\n"
    )
    t0 = time.perf_counter()
    r = grade(path)
    assert time.perf_counter() - t0 < 20
    assert [v.status for v in r.steps] == ["unrecognised"] * 3
    assert "exponent" in r.steps[0].message
