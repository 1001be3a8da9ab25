"""Conventions decided right: Craig's pre-superscript on a position names where the vector
starts, a rotation written transposed is a convention only if it is used as one, and the
report opens with the model it was graded against when that was read from the text.

The second opinion is plain SymPy by hand: the planar two-link arm's kinematics written
out from its geometry (frame 1 turns by q1 about z0, frame 2 by q2 about z1 at l1 along
x1, link 2's mass centre at lc2 along x2), never armdyn's output.
"""

from __future__ import annotations

import sympy as sp

from armdyn.grading import grade

q1, q2 = sp.symbols(r"\theta_{1} \theta_{2}")
qd1, qdd1 = sp.symbols(r"\dot{\theta}_{1} \ddot{\theta}_{1}")
l1, lc2, g = sp.symbols(r"l_{1} l_{c2} g")
c1, s1, c2, s2 = sp.cos(q1), sp.sin(q1), sp.cos(q2), sp.sin(q2)


def rz(q):
    """Frame-k coordinates to its parent's, for a turn q about z."""
    return sp.Matrix([[sp.cos(q), -sp.sin(q), 0], [sp.sin(q), sp.cos(q), 0], [0, 0, 1]])


def column(v) -> str:
    return r"\begin{bmatrix} " + r" \\ ".join(sp.latex(sp.expand(x)) for x in v) + r" \end{bmatrix}"


def matrix(m) -> str:
    rows = [" & ".join(sp.latex(m[r, c]) for c in range(3)) for r in range(3)]
    return r"\begin{bmatrix} " + r" \\ ".join(rows) + r" \end{bmatrix}"


def graded(tmp_path, body: str, robot: str = "planar-2r", method: str = "newton-euler"):
    head = f"---\nrobot: {robot}\nmethod: {method}\n---\n\n" if robot else ""
    path = tmp_path / "d.md"
    path.write_text(head + body)
    return grade(path)


def by_line(report):
    """The verdicts by line: the front matter takes lines 1-5, so the first equation is line 6."""
    return {v.line: v for v in report.steps}


# -- positions: Craig's {}^{j}P_X is X's position from frame j's origin, in frame j

#: link 2's mass centre from the base origin, in frame 0: l1 (c1, s1) + lc2 (c12, s12)
PC2_IN_0 = rz(q1) * sp.Matrix([l1, 0, 0]) + rz(q1) * rz(q2) * sp.Matrix([lc2, 0, 0])


def test_craig_pre_superscript_base_position_is_from_the_base_origin(tmp_path):
    r = graded(tmp_path, f"$$ {{}}^{{0}}P_{{C_2}} = {column(PC2_IN_0)} $$\n")
    assert by_line(r)[6].status == "correct", by_line(r)[6].message


def test_craig_pre_superscript_does_not_mean_from_the_links_own_frame(tmp_path):
    # lc2 (c12, s12): the vector from frame 2's origin, not from frame 0's as {}^{0} says
    own = rz(q1) * rz(q2) * sp.Matrix([lc2, 0, 0])
    r = graded(tmp_path, f"$$ {{}}^{{0}}P_{{C_2}} = {column(own)} $$\n")
    v = by_line(r)[6]
    assert v.status == "wrong" and "from frame 0's origin" in v.message


def test_craig_pre_superscript_intermediate_frame(tmp_path):
    # from frame 1's origin, in frame 1: (l1 + lc2 c2, lc2 s2, 0)
    r = graded(tmp_path, f"$$ {{}}^{{1}}P_{{C_2}} = {column(sp.Matrix([l1 + lc2 * c2, lc2 * s2, 0]))} $$\n")
    assert by_line(r)[6].status == "correct"


def test_right_superscript_base_position_is_read_as_craigs_and_said(tmp_path):
    # P_{C_2}^0 names only the frame; a value that is the base-frame position is read so, said
    r = graded(tmp_path, f"$$ P_{{C_2}}^0 = {column(PC2_IN_0)} $$\n")
    v = by_line(r)[6]
    assert v.status == "correct" and "read as Craig's" in v.message and "frame 0's origin" in v.message


def test_right_superscript_keeps_its_documented_meaning(tmp_path):
    # P_{C_2}^0: from frame 2's origin, written in frame 0 (docs/grading.md)
    own = rz(q1) * rz(q2) * sp.Matrix([lc2, 0, 0])
    r = graded(tmp_path, f"$$ P_{{C_2}}^0 = {column(own)} $$\n$$ {{}}^{{2}}P_{{C_2}} = {column([lc2, 0, 0])} $$\n")
    assert [v.status for v in r.steps] == ["correct", "correct"]


# -- a rotation written transposed: a convention only when used as one

#: frame-1 coordinates to frame 2: the transpose of Rz(q2)
R12 = rz(q2).T
#: the elbow's acceleration in frame 1 (gravity as the base accelerating by (0, g, 0)):
#: v̇_1 = Rz(q1)ᵀ (0, g, 0), plus ω̇ × (l1, 0, 0) + ω × (ω × (l1, 0, 0)) with ω = (0, 0, q̇1)
W, WD, P2 = sp.Matrix([0, 0, qd1]), sp.Matrix([0, 0, qdd1]), sp.Matrix([l1, 0, 0])
ELBOW_IN_1 = rz(q1).T * sp.Matrix([0, g, 0]) + WD.cross(P2) + W.cross(W.cross(P2))


def _rotation_then_elbow(tmp_path, rotation, elbow):
    body = f"$$ {{}}^{{2}}_{{1}}R = {matrix(rotation)} $$\n\n$$ {{}}^{{2}}\\dot v_2 = {column(elbow)} $$\n"
    return by_line(graded(tmp_path, body))


def test_transposed_rotation_used_as_written_is_the_slip(tmp_path):
    v = _rotation_then_elbow(tmp_path, R12.T, R12.T * ELBOW_IN_1)
    assert v[6].status == "wrong" and "used as written" in v[6].message and "line 8" in v[6].message
    assert v[8].status == "follows-from-earlier-error" and v[8].caused_by == v[6].name


def test_transposed_rotation_used_consistently_is_a_convention(tmp_path):
    v = _rotation_then_elbow(tmp_path, R12.T, R12 * ELBOW_IN_1)
    assert v[6].status == "correct-by-convention" and v[8].status == "correct"


def test_right_rotation_then_a_transposed_product_is_the_later_steps_slip(tmp_path):
    v = _rotation_then_elbow(tmp_path, R12, R12.T * ELBOW_IN_1)
    assert v[6].status == "correct" and v[8].status == "wrong"


def test_transposed_rotation_with_an_unrelated_later_slip_stays_a_convention(tmp_path):
    # the elbow's centripetal term dropped: neither rotation gives it
    slip = R12 * (ELBOW_IN_1 - W.cross(W.cross(P2)))
    v = _rotation_then_elbow(tmp_path, R12.T, slip)
    assert v[6].status == "correct-by-convention" and v[8].status == "wrong"
    assert "R_" not in v[8].message


def test_wrong_rotation_is_carried_forward(tmp_path):
    bad = sp.Matrix(R12)
    bad[1, 0] = -bad[1, 0]  # a sign slip in entry (2, 1): -s2 written s2
    v = _rotation_then_elbow(tmp_path, bad, bad * ELBOW_IN_1)
    assert v[6].status == "wrong"
    assert v[8].status == "follows-from-earlier-error" and v[8].caused_by == v[6].name


# -- the model read from the text: said first


def test_model_read_from_text_is_the_reports_first_line(tmp_path):
    from armdyn.grading.html import report_body

    body = (
        "A planar arm: $\\theta_1$ turns link 1 about $z_0$, $m_1$ at $p_{c1} = (l_{c1} \\cos\\theta_1,"
        " l_{c1} \\sin\\theta_1)$, gravity $-g$ along $y_0$.\n\n"
        "$$ V = m_1 g l_{c1} \\sin\\theta_1 $$\n"
    )
    r = graded(tmp_path, body, robot="")
    assert r.model_note.startswith("model read from the text")
    first = r.text().splitlines()[0]
    assert first == f"note: {r.model_note}"
    assert r.text().count(r.model_note) == 1  # not repeated among the notes at the bottom
    html = report_body(r)
    assert html.index("model read from the text") < html.index("<h1>")
    assert html.count("model read from the text") == 1


def test_named_model_has_no_model_note(tmp_path):
    r = graded(tmp_path, f"$$ {{}}^{{2}}P_{{C_2}} = {column([lc2, 0, 0])} $$\n")
    assert r.model_note == "" and r.text().startswith("armdyn grade")


def test_model_read_from_text_takes_craigs_base_position_as_the_mass_centre(tmp_path):
    # Craig's {}^{0}P_{C_2} (link 2's mass centre from the base origin, by hand above) agrees
    # with the example's {}^{2}P_{C_2} = (lc2, 0, 0): no disagreement, and it grades right
    from pathlib import Path

    example = Path(__file__).resolve().parent.parent / "examples" / "grading" / "planar-2r-craig.md"
    text = "".join(line for line in example.read_text().splitlines(True) if not line.startswith("robot:"))
    path = tmp_path / "d.md"
    path.write_text(text + f"\n$$ {{}}^{{0}}P_{{C_2}} = {column(PC2_IN_0)} $$\n")
    r = grade(path)
    assert r.model_note.startswith("model read from the text") and "disagree" not in r.model_note
    assert r.steps[-1].name == "P_C2^0" and r.steps[-1].status == "correct"


# -- a wrong step says the convention it was compared in


def test_wrong_step_names_the_convention_it_is_read_in(tmp_path):
    # link 1's mass centre with gravity kept as a force: ω̇ × (lc1, 0, 0) + ω × (ω × (lc1, 0, 0))
    # = (-lc1 q̇1², lc1 q̈1, 0); the centripetal term dropped. Closest reading: gravity as a force
    lc1 = sp.Symbol("l_{c1}")
    slip = sp.Matrix([0, lc1 * qdd1, 0])
    r = graded(tmp_path, f"$$ \\dot{{v}}_{{C_1}}^1 = {column(slip)} $$\n")
    v = by_line(r)[6]
    assert v.status == "wrong" and "in the convention: gravity as a force" in v.message
    assert v.components == [0]
    # shown in that convention, simplified: -lc1 q̇1² (no gravity terms left to cancel)
    x = v.expected[0]
    assert {s.name for s in x.free_symbols} == {"lc1", "q1_dot"}
    at = {s: {"lc1": 0.3, "q1_dot": 1.7}[s.name] for s in x.free_symbols}
    assert abs(float(x.subs(at)) + 0.3 * 1.7**2) < 1e-12
