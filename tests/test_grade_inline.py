"""`armdyn grade` reads equations written as inline ``$ ... $`` math, as notes and
generated solutions write them: one equation per list item, after a short lead
(``where``, ``So,``, ``Label:``), two on one line, and ``$+ ...$`` lines continuing the
equation above. Inline math in a sentence is prose and is not read.

The texts are the RP arm's (examples/grading/README.md's frames); the expected values are
the hand closed forms TAU_1, TAU_2 of tests/test_grade_reading.py, checked there by a plain
SymPy Lagrangian. A slip (a term dropped or doubled) must be found where it is written.
"""

from __future__ import annotations

import time

from test_grade_reading import TAU_1, TAU_2, statuses, write

from armdyn.grading import grade
from armdyn.grading.reader import read_markdown

# TAU_2 = m_2 (l_1 θ̈_1 - d_2 θ̇_1² + d̈_2 + g cos θ_1), written out in three pieces
TAU_2_HEAD = r"m_2 l_1 \ddot{\theta}_1 - m_2 d_2 \dot{\theta}_1^2"
TAU_2_TAIL = (r"+ m_2 \ddot{d}_2", r"+ m_2 g \cos\theta_1")


def equations(tmp_path, body):
    return [(e.lhs, e.line) for e in read_markdown(str(write(tmp_path, "i.md", body))).equations]


def test_one_equation_a_list_item_after_any_marker_or_short_lead(tmp_path):
    body = (
        "1.  **Torques**\n"  # line 4
        f"    *   $\\tau_1 = {TAU_1}$\n"
        f"    -   where $\\tau_2 = {TAU_2}$\n"
        f"a)  $\\tau_2 = {TAU_2}$\n"
        f"(b) Torque at joint 1: $\\tau_1 = {TAU_1}$.\n"
        f"2.  So $\\tau_2 = {TAU_2}$\n"
        f"+ Then, $\\tau_1 = {TAU_1}$;\n"
    )
    assert equations(tmp_path, body) == [
        ("\\tau_1", 5),
        ("\\tau_2", 6),
        ("\\tau_2", 7),
        ("\\tau_1", 8),
        ("\\tau_2", 9),
        ("\\tau_1", 10),
    ]
    assert {s for _, s in statuses(grade(write(tmp_path, "i.md", body)))} == {"correct"}


def test_two_equations_on_one_line_are_each_read(tmp_path):
    body = f"- $\\tau_2 = {TAU_2}$, and $\\tau_1 = {TAU_1}$.\n- $\\tau_1 = {TAU_1}$; $\\tau_2 = {TAU_2}$\n"
    report = grade(write(tmp_path, "two.md", body))
    assert statuses(report) == [("tau_2", "correct"), ("tau_1", "correct"), ("tau_1", "correct"), ("tau_2", "correct")]
    assert [v.line for v in report.steps] == [4, 4, 5, 5]


def test_plus_lines_continue_the_equation_above(tmp_path):
    body = (
        "Total torque on the slider.\n\n"
        "So,\n"
        f"$\\tau_2 = {TAU_2_HEAD}$\n"  # line 7
        f"  ${TAU_2_TAIL[0]}$\n"
        f"  ${TAU_2_TAIL[1]}$\n"
        "\n"
        f"- $\\tau_2 = {TAU_2_HEAD}$\n"  # line 11: the last row dropped
        f"  - ${TAU_2_TAIL[0]}$\n"
    )
    report = grade(write(tmp_path, "plus.md", body))
    assert statuses(report) == [("tau_2", "correct"), ("tau_2", "wrong")]
    assert [v.line for v in report.steps] == [7, 11]
    sub = read_markdown(str(tmp_path / "plus.md"))
    assert [e.rows for e in sub.equations] == [3, 2]


def test_a_continuation_never_jumps_over_a_line_not_read(tmp_path):
    # the torque on the slider is in a sentence (not read): its "+" row must not grow tau_1
    body = (
        f"- $\\tau_1 = {TAU_1}$\n"
        f"- and the force the joint exerts on the slider is $\\tau_2 = {TAU_2_HEAD}$\n"
        f"  ${TAU_2_TAIL[0]} {TAU_2_TAIL[1]}$\n"
    )
    report = grade(write(tmp_path, "jump.md", body))
    assert statuses(report) == [("tau_1", "correct")]
    assert read_markdown(str(tmp_path / "jump.md")).equations[0].rows == 1
    # a "+" line with nothing read just before it (a blank line between) is not read either
    body = f"$$\\tau_2 = {TAU_2_HEAD}$$\n\n${TAU_2_TAIL[0]} {TAU_2_TAIL[1]}$\n"
    assert statuses(grade(write(tmp_path, "gap.md", body))) == [("tau_2", "wrong")]


def test_inline_math_in_prose_is_not_read(tmp_path):
    body = (
        "where $m_1$ is the mass of link 1 and $\\tau_1 = 0$ at rest.\n"
        "In this case we see that $\\tau_1 = 0$ holds.\n"
        "- the slider force is found as $\\tau_2 = 0$ when the arm hangs still\n"
        "Since the slider does not move at all we have: $\\tau_2 = 0$\n"
        "- $m_2$\n"
        "- $\\tau_2 + \\tau_1$\n"
        "The torque at the base is\n"
        "$\\tau_1 = 0$\n"
        "when the arm rests on its stop.\n"
    )
    assert equations(tmp_path, body) == []


def test_a_lone_line_after_a_short_intro_is_read_but_not_in_mid_sentence(tmp_path):
    body = (
        "The torques follow from the Lagrangian.\n"
        f"$\\tau_1 = {TAU_1}$\n"  # line 5: after a sentence's end
        "\n"
        "Torque at joint 2, thus\n"
        f"$\\tau_2 = {TAU_2}$\n"  # line 8: after a short connective line
        "\n"
        "Writing the slider's equation of motion out in full with every force and\n"
        f"$\\tau_2 = {TAU_2}$\n"  # mid-sentence: prose
    )
    assert equations(tmp_path, body) == [("\\tau_1", 5), ("\\tau_2", 8)]


def test_many_inline_lines_read_in_bounded_time(tmp_path):
    line = "- where " + "$x$, " * 2000 + "and no equation\n"
    body = line * 50 + "$" + "+ x " * 20000 + "$\n" + ("a: " * 3000 + "$y$\n") * 20
    # long runs of spaces where the math line's pattern allows spaces (before, between, after)
    body += " " * 200_000 + "y\n" + "- $x$" + " " * 200_000 + "$y$ z\n" + "$x$" + " " * 200_000 + "y\n"
    start = time.perf_counter()
    assert equations(tmp_path, body) == []
    assert time.perf_counter() - start < 5


def test_an_entry_written_as_a_function_of_a_joint_is_the_entry(tmp_path):
    # by hand: |v_2|^2 = (l_1^2 + d_2^2) θ̇_1^2 + 2 l_1 θ̇_1 ḋ_2 + ḋ_2^2, so M_11 = m_1 l_1^2 + m_2 (l_1^2 + d_2^2)
    body = (
        "- $M_{11}(d_2) = (m_1 + m_2) l_1^2 + m_2 d_2^2$\n"
        "- $M_{12}(d_2) = m_2 l_1$\n"
        "- $M_{22}(\\theta_1, d_2) = 2 m_2$\n"  # a slip: m_2
    )
    report = grade(write(tmp_path, "m.md", body))
    assert statuses(report) == [("M_11", "correct"), ("M_12", "correct"), ("M_22", "wrong")]
