"""Every member of a chain ``LHS = formula = value`` is checked, and a right value that does
not follow from the student's own earlier values is ``correct-but-unsupported``.

The second opinion is the mutation itself: each slip below is put by hand into a formula
member of a derivation checked outside armdyn (examples/grading/README.md), leaving the
value as it was; each changes what the member is worth (the comment says why), so the step
must be reported ``wrong`` at its line, and nothing else may change.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from armdyn.grading import grade

EXAMPLES = Path(__file__).resolve().parent.parent / "examples" / "grading"

#: file -> its documented wrong steps (README: "first wrong step"; none for the clean one)
DOCUMENTED_WRONG = {
    "rp-arm-dalembert.md": [],
    "planar-2r-craig.md": ["vc_dot_2"],
    "planar-3r-spong.md": ["N_3"],
    "planar-2r-lagrange.md": ["dL_dq_2"],
}

# (file, the line's start, text in a formula member, its slip, the step, why the member's worth changes)
MUTATIONS = [
    (
        "rp-arm-dalembert.md",
        "$$\\dot{v}_2^2 =",
        "+ \\omega_1^1 \\times (\\omega_1^1 \\times P_2^1) ",
        "",
        "v_dot_2",
        "dropped cross-product term: P_2^1 = (0, d2, 0), so the centripetal -d2 th1'^2 goes",
    ),
    (
        "rp-arm-dalembert.md",
        "$$\\dot{v}_2^2 =",
        "[\\dot{\\omega}_1^1 \\times P_2^1",
        "[\\omega_1^1 \\times P_2^1",
        "v_dot_2",
        "omega for omega-dot: th1' in place of th1'' times d2",
    ),
    (
        "rp-arm-dalembert.md",
        "$$f_1^1 =",
        "R_2^1 f_2^2",
        "R_1^2 f_2^2",
        "f_1",
        "the rotation the wrong way: f_2's z component lands in y with the opposite sign",
    ),
    (
        "rp-arm-dalembert.md",
        "$$n_1^1 =",
        "- P_1^1 \\times F_1^1",
        "+ P_1^1 \\times F_1^1",
        "n_1",
        "a sign: P_1^1 x F_1^1 = (0, 0, -l1 m1 (l1 th1'' + g cos th1)) is not zero",
    ),
    (
        "planar-2r-craig.md",
        "$${}^{2}\\dot{v}_{2} =",
        "({}^{1}\\dot{\\omega}_{1} \\times {}^{1}P_{2}",
        "({}^{1}\\omega_{1} \\times {}^{1}P_{2}",
        "v_dot_2",
        "omega for omega-dot: P_2 = (l1, 0, 0), so th1' l1 in place of th1'' l1",
    ),
    (
        "planar-2r-craig.md",
        "$${}^{1}f_{1} =",
        "{}^{1}_{2}R\\,{}^{2}f_{2}",
        "{}^{2}_{1}R\\,{}^{2}f_{2}",
        "f_1",
        "the rotation the wrong way (after the file's own slip: a new one, not inherited)",
    ),
    (
        "planar-3r-spong.md",
        "$$f_2^2 =",
        "R_3^2 f_3^3",
        "R_2^3 f_3^3",
        "f_2",
        "the rotation the wrong way: f_3 turned by -th3 instead of th3",
    ),
    (
        "planar-3r-spong.md",
        "$$f_3^3 =",
        "= F_3^3 =",
        "= -F_3^3 =",
        "f_3",
        "a sign: F_3 is not zero",
    ),
    (
        "planar-3r-spong.md",
        "$$\\dot{v}_{c,2}^2 =",
        "+ \\dot{\\omega}_2^2 \\times r_{2,c_2}",
        "+ \\omega_2^2 \\times r_{2,c_2}",
        "vc_dot_2",
        "omega for omega-dot: r_{2,c_2} = (l2/2, 0, 0), so (th1' + th2') in place of (th1'' + th2'')",
    ),
    (
        "planar-3r-spong.md",
        "$$n_2^2 =",
        "+ r_{2,c_2} \\times F_2^2 ",
        "",
        "n_2",
        "dropped cross-product term (after the file's own slip in N_3: a new one): l2/2 (F_2)_y in z",
    ),
    (
        "planar-2r-lagrange.md",
        "$$L =",
        "T - V",
        "T + V",
        "L",
        "a sign: V is not zero",
    ),
]


def _mutated(tmp_path, name, start, old, new):
    lines = (EXAMPLES / name).read_text().split("\n")
    k = next(i for i, t in enumerate(lines) if t.startswith(start))
    before = lines[k]
    assert before.count(old) == 1, (name, start, old)
    value_at = before.rindex("= ")
    assert before.index(old) < value_at, "the slip must be in a formula member, not in the value"
    lines[k] = before.replace(old, new)
    path = tmp_path / name
    path.write_text("\n".join(lines))
    return path, k + 1


@pytest.mark.parametrize("name", sorted(DOCUMENTED_WRONG))
def test_clean_chains_raise_no_false_alarm(name):
    r = grade(EXAMPLES / name)
    assert [v.name for v in r.steps if v.status == "wrong"] == DOCUMENTED_WRONG[name]
    assert not any(") differs from the value:" in v.message for v in r.steps)  # no formula member flagged


@pytest.mark.parametrize("name, start, old, new, step, why", MUTATIONS, ids=[f"{m[0]}:{m[4]}" for m in MUTATIONS])
def test_a_slip_in_a_formula_member_is_reported_at_its_line(tmp_path, name, start, old, new, step, why):
    path, line = _mutated(tmp_path, name, start, old, new)
    r = grade(path)
    v = next(v for v in r.steps if v.name == step and v.line == line)
    assert v.status == "wrong", why
    assert "formula member" in v.message and "differs from the value" in v.message
    assert [w.name for w in r.steps if w.status == "wrong"] == sorted(
        DOCUMENTED_WRONG[name] + [step], key=[s.name for s in r.steps].index
    )


def test_a_member_with_an_unknown_symbol_is_skipped_with_a_note():
    # the exercise's v_dot_1 chain uses \dot{\mathbf{V}}_1^0, which names nothing
    r = grade(EXAMPLES / "rp-arm-exercise.md")
    v = next(v for v in r.steps if v.name == "v_dot_1")
    assert v.status == "wrong" and "member 1 not checked: unknown symbol" in v.message and "V" in v.message


def test_exercise_keeps_its_documented_verdicts_and_says_the_members_are_right():
    r = grade(EXAMPLES / "rp-arm-exercise.md")
    status = {v.name: v.status for v in r.steps if v.key and v.key != "tau"}
    assert status["omega_2"] == "correct"  # its theta_2-dot of the prismatic joint is read as 0, said
    assert "prismatic" in next(v for v in r.steps if v.name == "omega_2").message
    n1 = next(v for v in r.steps if v.name == "n_1")
    assert n1.status == "wrong" and "factor l₁ missing" in n1.message
    assert "is right: the slip is in the value" in n1.message  # R_2^1 m_2^2 + P_1^1 x f_1^1 gives l1 (f_1)_y


def test_right_torque_after_a_wrong_moment_is_unsupported(tmp_path):
    """The clean d'Alembert derivation with n_1's value dropping m1 l1 (l1 th1'' + g cos th1)
    (P_1^1 x F_1^1's part): its tau_1 is still the true one, so it cannot follow from the
    student's own n_1 (tau_1 = z . n_1 = n_1's z component)."""
    text = (EXAMPLES / "rp-arm-dalembert.md").read_text()
    term = " + m_1 l_1 (l_1 \\ddot{\\theta}_1 + g \\cos\\theta_1) \\end{pmatrix}"
    assert text.count(term) == 1
    path = tmp_path / "n1-slip.md"
    path.write_text(text.replace(term, " \\end{pmatrix}"))
    r = grade(path)
    assert [v.name for v in r.steps if v.status == "wrong"] == ["n_1"]
    tau1 = next(v for v in r.steps if v.name == "tau_1")
    assert tau1.status == "correct-but-unsupported"
    assert "through earlier errors" in tau1.message  # its member n_1^{1T} Z_1^1, with their n_1
    assert next(v for v in r.steps if v.name == "tau_2").status == "correct"  # tau_2 uses f_2 only


def test_spongs_r_vectors_are_read_as_positions_and_said():
    r = grade(EXAMPLES / "planar-3r-spong.md")
    v = next(v for v in r.steps if v.name == "vc_dot_1")
    assert v.status == "correct" and "r_{1,c_1} read as P_C1^1" in v.message


def test_a_hostile_member_is_skipped_in_bounded_time(tmp_path):
    import time

    path = tmp_path / "hostile.md"
    member = " + ".join(["{}^{1}\\dot{\\omega}_{1}"] * 5000)
    path.write_text(f"---\nrobot: rp-arm\n---\n\n$$\\omega_1^1 = {member} = (0, 0, \\dot\\theta_1)^T$$\n")
    start = time.monotonic()
    v = grade(path).steps[0]
    assert time.monotonic() - start < 10
    assert v.status == "correct" and "member 1 not checked" in v.message and len(v.message) < 300


def test_a_member_naming_an_earlier_wrong_lagrange_step_is_inherited_not_wrong(tmp_path):
    # T drops I_2 (q1' + q2')^2 / 2; L = T - V is then written right: the member T - V, with
    # the student's T, differs from L only through T's error (the formula is right)
    text = (EXAMPLES / "planar-2r-lagrange.md").read_text().split("\n")
    k = next(i for i, t in enumerate(text) if t.startswith("$$T ="))
    tail = " + \\frac{1}{2} I_2 (\\dot{q}_1 + \\dot{q}_2)^2$$"
    assert text[k].endswith(tail)
    text[k] = text[k][: -len(tail)] + "$$"
    path = tmp_path / "t-slip.md"
    path.write_text("\n".join(text))
    r = grade(path)
    assert [v.name for v in r.steps if v.status == "wrong"] == ["T", "dL_dq_2"]
    v = next(v for v in r.steps if v.name == "L")
    assert v.status == "correct-but-unsupported" and "only through earlier errors" in v.message


def test_bold_zero_in_a_member_is_the_zero_vector(tmp_path):
    path = tmp_path / "zero.md"
    path.write_text(
        "---\nrobot: rp-arm\n---\n\n$$\\omega_1^1 = \\mathbf{0} + \\dot\\theta_1 \\hat{Z}_1^1 = (0, 0, \\dot\\theta_1)^T$$\n"
        "\n$$\\dot\\omega_1^1 = \\mathbf{0} + \\dot\\theta_1 \\hat{Z}_1^1 = (0, 0, \\ddot\\theta_1)^T$$\n"
    )
    r = grade(path)
    assert [(v.name, v.status) for v in r.steps] == [("omega_1", "correct"), ("omega_dot_1", "wrong")]
    assert "formula member" in r.steps[1].message and "not checked" not in r.steps[0].message


def test_members_of_a_chain_written_over_aligned_rows():
    from armdyn.grading.chains import members

    source = (
        "\\omega_2^2 &= R_1^2 \\omega_1^1 \\\\ &= \\begin{pmatrix} 0 & 1 \\\\ 0 & 1 \\end{pmatrix} x"
        " \\\\ &= \\begin{pmatrix} 0 \\\\ 0 \\\\ 1 \\end{pmatrix}"
    )
    got = members(source)
    assert [m.split() for m in got] == [
        ["R_1^2", "\\omega_1^1"],
        ["\\begin{pmatrix}", "0", "&", "1", "\\\\", "0", "&", "1", "\\end{pmatrix}", "x"],
    ]


def test_a_slip_carried_from_the_formula_member_into_the_value_is_placed_in_the_member(tmp_path):
    # L = T + V written out consistently: the value is wrong on its own and its formula member is where
    text = (EXAMPLES / "planar-2r-lagrange.md").read_text().split("\n")
    k = next(i for i, t in enumerate(text) if t.startswith("$$L ="))
    old = "- m_1 g l_{c1} \\sin q_1 - m_2 g (l_1"
    assert text[k].count(old) == 1 and text[k].count("T - V") == 1
    text[k] = text[k].replace(old, "+ m_1 g l_{c1} \\sin q_1 + m_2 g (l_1").replace("T - V", "T + V")
    path = tmp_path / "l-slip.md"
    path.write_text("\n".join(text))
    v = next(v for v in grade(path).steps if v.name == "L")
    assert v.status == "wrong" and "the slip is already in its formula member `T + V`" in v.message
