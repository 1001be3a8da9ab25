"""Quantities used by name across a derivation: totals written before their parts, a link's
energy under another textbook name, a speed through its square, entries with their arguments
(``M_{11}(\\theta_2)``), time derivatives of entries (``\\dot M_{11}``), a corrected restatement.

Each derivation's values are transcribed by hand into SymPy beside the LaTeX and checked
against the planar elbow derived from first principles here (plain SymPy), never against
armdyn's output; the grader's verdicts are then checked against that truth."""

from __future__ import annotations

import time

import pytest
import sympy as sp

from armdyn.grading import grade

HEADER = r"""---
robot: planar-2r
method: lagrange
symbols:
  '\theta_1': q1
  '\theta_2': q2
  'l_1': l1
  'l_{c1}': lc1
  'l_{c2}': lc2
  'm_1': m1
  'm_2': m2
  'I_1': I1
  'I_2': I2
  'g': g
---

"""

q1, q2, qd1, qd2, qdd1, qdd2 = sp.symbols("q1 q2 qd1 qd2 qdd1 qdd2")
l1, lc1, lc2, m1, m2, I1, I2, g = sp.symbols("l1 lc1 lc2 m1 m2 I1 I2 g")
half = sp.Rational(1, 2)


def _elbow() -> dict:
    """The planar elbow from its mass centres (gravity along -y): energies, D(q), Lagrange's terms."""
    t = sp.Symbol("t")
    a1, a2 = sp.Function("a1")(t), sp.Function("a2")(t)
    pc1 = sp.Matrix([lc1 * sp.cos(a1), lc1 * sp.sin(a1)])
    pc2 = sp.Matrix([l1 * sp.cos(a1) + lc2 * sp.cos(a1 + a2), l1 * sp.sin(a1) + lc2 * sp.sin(a1 + a2)])
    v1, v2 = pc1.diff(t), pc2.diff(t)
    K1 = (m1 * v1.dot(v1) + I1 * a1.diff(t) ** 2) / 2
    K2 = (m2 * v2.dot(v2) + I2 * (a1.diff(t) + a2.diff(t)) ** 2) / 2
    P1, P2 = g * m1 * pc1[1], g * m2 * pc2[1]
    L = K1 + K2 - P1 - P2
    subs = {a1.diff(t, 2): qdd1, a2.diff(t, 2): qdd2, a1.diff(t): qd1, a2.diff(t): qd2}
    plain = lambda e: e.subs(subs).subs({a1: q1, a2: q2})  # noqa: E731
    out = {"K1": plain(K1), "K2": plain(K2), "P1": plain(P1), "P2": plain(P2), "L": plain(L)}
    out["vc2_sq"] = plain(v2.dot(v2))
    out["K"], out["P"] = out["K1"] + out["K2"], out["P1"] + out["P2"]
    D = sp.hessian(out["K"], [qd1, qd2])
    for i in range(2):
        for j in range(2):
            out[f"M{i + 1}{j + 1}"] = D[i, j]
            out[f"M{i + 1}{j + 1}dot"] = sp.diff(D[i, j], q1) * qd1 + sp.diff(D[i, j], q2) * qd2
    for k, (q, qd) in enumerate(((q1, qd1), (q2, qd2)), start=1):
        p = sp.diff(out["L"], qd)
        out[f"dL_dqd{k}"] = p
        out[f"ddt{k}"] = sum(sp.diff(p, a) * b for a, b in ((q1, qd1), (q2, qd2), (qd1, qdd1), (qd2, qdd2)))
        out[f"dL_dq{k}"] = sp.diff(out["L"], q)
        out[f"tau{k}"] = out[f"ddt{k}"] - out[f"dL_dq{k}"]
    return out


TRUE = _elbow()
c2, s2 = sp.cos(q2), sp.sin(q2)
M11 = m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2) + I1 + I2
M12 = m2 * (lc2**2 + l1 * lc2 * c2) + I2
M22 = m2 * lc2**2 + I2
K1 = half * (m1 * lc1**2 + I1) * qd1**2
V2SQ = l1**2 * qd1**2 + lc2**2 * (qd1 + qd2) ** 2 + 2 * l1 * lc2 * c2 * qd1 * (qd1 + qd2)
K2 = half * m2 * V2SQ + half * I2 * (qd1 + qd2) ** 2
P1 = m1 * g * lc1 * sp.sin(q1)
P2 = m2 * g * (l1 * sp.sin(q1) + lc2 * sp.sin(q1 + q2))

# LaTeX of the values above, as the texts below write them
TEX = {
    "K1": r"\frac{1}{2} (m_1 l_{c1}^2 + I_1) \dot\theta_1^2",
    "V2SQ": r"l_1^2 \dot\theta_1^2 + l_{c2}^2 (\dot\theta_1 + \dot\theta_2)^2 "
    r"+ 2 l_1 l_{c2} \cos\theta_2 \dot\theta_1 (\dot\theta_1 + \dot\theta_2)",
    "K2": r"\frac{1}{2} m_2 (l_1^2 \dot\theta_1^2 + l_{c2}^2 (\dot\theta_1 + \dot\theta_2)^2 "
    r"+ 2 l_1 l_{c2} \cos\theta_2 \dot\theta_1 (\dot\theta_1 + \dot\theta_2)) + \frac{1}{2} I_2 (\dot\theta_1 + \dot\theta_2)^2",
    "P1": r"m_1 g l_{c1} \sin\theta_1",
    "P2": r"m_2 g (l_1 \sin\theta_1 + l_{c2} \sin(\theta_1 + \theta_2))",
    "M11": r"m_1 l_{c1}^2 + m_2 (l_1^2 + l_{c2}^2 + 2 l_1 l_{c2} \cos\theta_2) + I_1 + I_2",
    "M12": r"m_2 (l_{c2}^2 + l_1 l_{c2} \cos\theta_2) + I_2",
    "M22": r"m_2 l_{c2}^2 + I_2",
}


def _same(a, b) -> bool:
    return sp.simplify(sp.expand_trig(sp.expand(a - b))) == 0


def test_the_transcriptions_are_the_elbow():
    # the independent check every verdict below relies on
    for name, value in (("K1", K1), ("K2", K2), ("P1", P1), ("P2", P2), ("vc2_sq", V2SQ)):
        assert _same(value, TRUE[name]), name
    for name, value in (("M11", M11), ("M12", M12), ("M22", M22)):
        assert _same(value, TRUE[name]), name
    assert _same(TRUE["M11dot"], -2 * m2 * l1 * lc2 * s2 * qd2)
    assert _same(TRUE["M12dot"], -m2 * l1 * lc2 * s2 * qd2)
    assert _same(TRUE["ddt1"], M11 * qdd1 + TRUE["M11dot"] * qd1 + M12 * qdd2 + TRUE["M12dot"] * qd2)
    assert _same(TRUE["dL_dqd1"], M11 * qd1 + M12 * qd2)
    assert not _same(M12, m2 * (lc2**2 + 2 * l1 * lc2 * c2) + I2)  # the slip used below is one


def _grade(tmp_path, body: str):
    path = tmp_path / "names.md"
    path.write_text(HEADER + body, encoding="utf-8")
    report = grade(path)
    lines = (HEADER + body).split("\n")
    return report, {s.line: s for s in report.steps}, lines


def _line(lines, text: str) -> int:
    return next(k + 1 for k, ln in enumerate(lines) if text in ln)


def test_a_total_written_before_its_parts_is_graded_at_its_own_line(tmp_path):
    body = f"$$T = T_1 + T_2$$\n\n$$T_1 = {TEX['K1']}$$\n\n$$T_2 = {TEX['K2']}$$\n"
    report, at, lines = _grade(tmp_path, body)
    total = at[_line(lines, "T = T_1")]
    assert total.name == "T" and total.status == "correct"
    assert [s.line for s in report.steps] == sorted(s.line for s in report.steps)  # in the text's order


def test_a_total_above_a_wrong_part_is_right_in_its_names(tmp_path):
    # the slip is the part's, further on; written above it, the total is right as a formula
    wrong_k2 = TEX["K2"].replace(r"\frac{1}{2} I_2", "I_2")  # the rotation term without its 1/2
    assert not _same(K2 - half * I2 * (qd1 + qd2) ** 2 + I2 * (qd1 + qd2) ** 2, TRUE["K2"])
    body = f"$$K = K_1 + K_2$$\n\n$$K_1 = {TEX['K1']}$$\n\n$$K_2 = {wrong_k2}$$\n\n$$L = K - P_1$$\n"
    _, at, lines = _grade(tmp_path, body)
    assert at[_line(lines, "K_2 =")].status == "wrong"
    total = at[_line(lines, "K = K_1")]
    assert total.status == "correct" and "wrong further on" in total.message


def test_a_total_below_a_wrong_part_follows_from_it(tmp_path):
    wrong_k2 = TEX["K2"].replace(r"\frac{1}{2} I_2", "I_2")
    body = f"$$K_1 = {TEX['K1']}$$\n\n$$K_2 = {wrong_k2}$$\n\n$$K = K_1 + K_2$$\n"
    _, at, lines = _grade(tmp_path, body)
    total = at[_line(lines, "K = K_1")]
    assert total.status == "follows-from-earlier-error" and total.caused_by == "T_2"


def test_a_name_never_given_is_said_so(tmp_path):
    body = f"$$K_1 = {TEX['K1']}$$\n\n$$L = K_1 + K_2 - P_1 - P_2$$\n\n$$P_1 = {TEX['P1']}$$\n"
    _, at, lines = _grade(tmp_path, body)
    lagrangian = at[_line(lines, "L = K_1")]
    assert lagrangian.status == "unrecognised"
    assert "K_{2} is used but never given" in lagrangian.message


def test_a_link_energy_under_another_textbook_name(tmp_path):
    # Lynch & Park name the energies E_{K_i} and P_i, and write the Lagrangian with K_i
    body = (
        f"$$\\mathcal E_{{K_1}} = {TEX['K1']}$$\n\n$$\\mathcal E_{{K_2}} = {TEX['K2']}$$\n\n"
        f"$$\\mathcal P_1 = {TEX['P1']}$$\n\n$$\\mathcal P_2 = {TEX['P2']}$$\n\n"
        "$$\\mathcal L = \\mathcal K_1 + \\mathcal K_2 - \\mathcal P_1 - \\mathcal P_2$$\n\n"
        "$$L = KE_1 + KE_2 - U_1 - U_2$$\n"
    )
    _, at, lines = _grade(tmp_path, body)
    assert at[_line(lines, "\\mathcal L =")].status == "correct"
    assert at[_line(lines, "L = KE_1")].status == "correct"


def test_a_speed_given_through_its_square(tmp_path):
    body = f"$$v_{{c2}}^2 = {TEX['V2SQ']}$$\n\n$$K_2 = \\frac{{1}}{{2}} m_2 v_{{c2}}^2 + \\frac{{1}}{{2}} I_2 (\\dot\\theta_1 + \\dot\\theta_2)^2$$\n"
    _, at, lines = _grade(tmp_path, body)
    assert at[_line(lines, "K_2 =")].status == "correct"


def _entries(m12: str) -> str:
    return (
        f"$$M_{{11}}(\\theta_2) = {TEX['M11']}$$\n\n$$M_{{12}}(\\theta_2) = {m12}$$\n\n$$M_{{22}} = {TEX['M22']}$$\n\n"
    )


def test_an_entry_with_its_arguments_is_the_entry(tmp_path):
    body = _entries(TEX["M12"]) + (
        f"$$P_1 = {TEX['P1']}$$\n\n$$P_2 = {TEX['P2']}$$\n\n"
        "$$L = \\frac{1}{2} M_{11}(\\theta_2)\\dot\\theta_1^2 + M_{12}(\\theta_2)\\dot\\theta_1\\dot\\theta_2"
        " + \\frac{1}{2} M_{22}\\dot\\theta_2^2 - P_1 - P_2$$\n"
    )
    report, at, lines = _grade(tmp_path, body)
    assert at[_line(lines, "L = ")].status == "correct"
    assert any("M_{11}(\\theta_2) read as the quantity M_{11}" in n for n in report.notes)


def test_a_bracket_after_a_parameter_stays_a_product(tmp_path):
    # I_1(\dot\theta_1)\dot\theta_1: a model symbol is no function of the joint rate
    body = "$$K_1 = \\frac{1}{2} m_1 l_{c1}^2 \\dot\\theta_1^2 + \\frac{1}{2} I_1(\\dot\\theta_1)\\dot\\theta_1$$\n"
    _, at, lines = _grade(tmp_path, body)
    assert at[_line(lines, "K_1 =")].status == "correct"


DDT1 = (
    "$$\\frac{d}{dt}\\frac{\\partial L}{\\partial\\dot\\theta_1} = M_{11}\\ddot\\theta_1 + \\dot M_{11}\\dot\\theta_1"
    " + M_{12}\\ddot\\theta_2 + \\dot M_{12}\\dot\\theta_2$$\n\n"
)


def test_time_derivatives_of_entries(tmp_path):
    body = (
        _entries(TEX["M12"])
        + DDT1
        + (
            "$$\\dot M_{11} = -2 m_2 l_1 l_{c2} \\sin\\theta_2 \\dot\\theta_2$$\n\n"
            "$$\\dot{M}_{12} = -m_2 l_1 l_{c2} \\sin\\theta_2 \\dot\\theta_1$$\n"
        )
    )
    assert not _same(-m2 * l1 * lc2 * s2 * qd1, TRUE["M12dot"])
    _, at, lines = _grade(tmp_path, body)
    assert at[_line(lines, "\\frac{d}{dt}")].status == "correct"
    assert at[_line(lines, "\\dot M_{11} =")].status == "correct"
    wrong = at[_line(lines, "\\dot{M}_{12} =")]
    assert wrong.status == "wrong" and "time derivative of M_{12}" in wrong.message


def test_the_derivative_of_a_wrong_entry_follows_from_it(tmp_path):
    slip = r"m_2 (l_{c2}^2 + 2 l_1 l_{c2} \cos\theta_2) + I_2"
    body = _entries(slip) + "$$\\dot M_{12} = -2 m_2 l_1 l_{c2} \\sin\\theta_2 \\dot\\theta_2$$\n"
    _, at, lines = _grade(tmp_path, body)
    assert at[_line(lines, "M_{12}(\\theta_2) =")].status == "wrong"
    carried = at[_line(lines, "\\dot M_{12} =")]
    assert carried.status == "follows-from-earlier-error" and carried.caused_by == "M_12"


@pytest.mark.parametrize("restated", [False, True])
def test_a_corrected_restatement_is_what_later_steps_use(tmp_path, restated):
    slip = r"m_2 (l_{c2}^2 + 2 l_1 l_{c2} \cos\theta_2) + I_2"
    body = _entries(slip)
    if restated:
        body += f"Correcting: $M_{{12}}(\\theta_2) = {TEX['M12']}$\n\n"
    body += "$$\\frac{\\partial L}{\\partial\\dot\\theta_1} = M_{11}\\dot\\theta_1 + M_{12}\\dot\\theta_2$$\n"
    _, at, lines = _grade(tmp_path, body)
    step = at[_line(lines, "\\frac{\\partial L}")]
    assert step.status == ("correct" if restated else "follows-from-earlier-error")


def test_many_brackets_are_read_in_bounded_time(tmp_path):
    value = " + ".join(["M_{11}(\\theta_2)(\\theta_1)\\dot\\theta_1"] * 400)
    body = _entries(TEX["M12"]) + f"$$\\frac{{\\partial L}}{{\\partial\\dot\\theta_1}} = {value}$$\n"
    start = time.perf_counter()
    _grade(tmp_path, body)
    assert time.perf_counter() - start < 60


def test_partials_of_entries(tmp_path):
    # dM_11/dtheta_2 = -2 m_2 l_1 l_c2 sin(theta_2); dM_12/dtheta_2 is half that (written with the l_c2^2 term's slip)
    assert _same(sp.diff(M11, q2), -2 * m2 * l1 * lc2 * s2)
    assert not _same(sp.diff(M12, q2), -m2 * (lc2**2 + l1 * lc2) * s2)
    body = _entries(TEX["M12"]) + (
        "$$\\frac{\\partial M_{11}}{\\partial \\theta_2} = -2 m_2 l_1 l_{c2} \\sin\\theta_2$$\n\n"
        "$$\\frac{\\partial M_{12}}{\\partial \\theta_2} = -m_2 (l_{c2}^2 + l_1 l_{c2}) \\sin\\theta_2$$\n"
    )
    _, at, lines = _grade(tmp_path, body)
    assert at[_line(lines, "\\partial M_{11}")].status == "correct"
    assert at[_line(lines, "\\partial M_{12}")].status == "wrong"


def test_a_partial_of_an_entry_inside_a_value(tmp_path):
    # dL/dtheta_2 = 1/2 dM11/dtheta_2 thd1^2 + dM12/dtheta_2 thd1 thd2 - dP/dtheta_2 (M_22 is constant)
    dL_dq2 = half * sp.diff(M11, q2) * qd1**2 + sp.diff(M12, q2) * qd1 * qd2 - sp.diff(P2, q2)
    assert _same(dL_dq2, TRUE["dL_dq2"])
    body = _entries(TEX["M12"]) + (
        "$$\\frac{\\partial L}{\\partial\\theta_2} = \\frac{1}{2}\\frac{\\partial M_{11}}{\\partial\\theta_2}\\dot\\theta_1^2"
        " + \\frac{\\partial M_{12}}{\\partial \\theta_2}\\dot\\theta_1\\dot\\theta_2"
        " - m_2 g l_{c2}\\cos(\\theta_1 + \\theta_2)$$\n"
    )
    _, at, lines = _grade(tmp_path, body)
    assert at[_line(lines, "\\frac{\\partial L}")].status == "correct"


def test_a_point_mass_speed_is_checked_and_used(tmp_path):
    # v_1 = l_c1 thd1 is link 1's speed; a v_2 without the elbow's cross term is not link 2's
    speed2_slip = sp.sqrt(l1**2 * qd1**2 + lc2**2 * (qd1 + qd2) ** 2)
    assert not _same(speed2_slip**2, TRUE["vc2_sq"])
    body = (
        "$$v_1 = l_{c1}\\dot\\theta_1$$\n\n"
        "$$v_2 = \\sqrt{l_1^2\\dot\\theta_1^2 + l_{c2}^2(\\dot\\theta_1 + \\dot\\theta_2)^2}$$\n\n"
        "$$K_1 = \\frac{1}{2} m_1 v_1^2 + \\frac{1}{2} I_1\\dot\\theta_1^2$$\n"
    )
    _, at, lines = _grade(tmp_path, body)
    assert at[_line(lines, "v_1 =")].status == "correct"
    assert at[_line(lines, "v_2 =")].status == "wrong"
    assert at[_line(lines, "K_1 =")].status == "correct"


def test_the_joint_vector_in_a_quadratic_form(tmp_path):
    # K = 1/2 qdot^T D(q) qdot with the D(q) given: the total kinetic energy (checked by hand above)
    assert _same(half * (M11 * qd1**2 + 2 * M12 * qd1 * qd2 + M22 * qd2**2), TRUE["K"])
    body = (
        f"$$D(q) = \\begin{{bmatrix}} {TEX['M11']} & {TEX['M12']} \\\\ {TEX['M12']} & {TEX['M22']} \\end{{bmatrix}}$$\n\n"
        "$$K = \\frac{1}{2}\\dot\\theta^T D(\\theta)\\dot\\theta$$\n\n"
        "$$\\tau = D(\\theta)\\ddot\\theta$$\n"
    )
    _, at, lines = _grade(tmp_path, body)
    assert at[_line(lines, "K =")].status == "correct"
    form = at[_line(lines, "\\tau =")]  # written to say what D does: not the equations of motion
    assert form.status == "unrecognised" and "names of whole quantities only" in form.message


@pytest.mark.parametrize("restated", [False, True])
def test_a_symmetric_entry_given_by_name(tmp_path, restated):
    # M_21 = M_12 states the symmetry; M_21 then stands for the student's latest M_12
    assert _same(TRUE["dL_dqd2"], M12 * qd1 + M22 * qd2)
    slip = r"m_2 (l_{c2}^2 + 2 l_1 l_{c2} \cos\theta_2) + I_2"
    body = _entries(slip) + "$$M_{21} = M_{12}$$\n\n"
    if restated:
        body += f"$$M_{{12}} = {TEX['M12']}$$\n\n"
    body += "$$\\frac{\\partial L}{\\partial\\dot\\theta_2} = M_{21}\\dot\\theta_1 + M_{22}\\dot\\theta_2$$\n"
    _, at, lines = _grade(tmp_path, body)
    symmetry = at[_line(lines, "M_{21} = M_{12}")]
    assert symmetry.status == "correct" and "symmetric" in symmetry.message
    step = at[_line(lines, "\\frac{\\partial L}")]
    assert step.status == ("correct" if restated else "follows-from-earlier-error")


def test_many_names_never_given_end_in_bounded_time(tmp_path):
    body = "".join(f"$$L = X_{{{k}}} + \\dot\\theta_1$$\n\n" for k in range(300))
    start = time.perf_counter()
    report, _, _ = _grade(tmp_path, body + f"$$K_1 = {TEX['K1']}$$\n")
    assert time.perf_counter() - start < 60
    assert sum(s.status == "unrecognised" for s in report.steps) == 300


def test_a_speed_of_a_joint_is_said_so(tmp_path):
    # the elbow joint (frame 2's origin) moves at l_1 |thd1|: not link 2's mass centre, right for that point
    body = "$$v_2 = l_1\\dot\\theta_1$$\n"
    _, at, lines = _grade(tmp_path, body)
    step = at[_line(lines, "v_2 =")]
    assert step.status == "correct" and "frame 2's origin" in step.message


def test_a_chain_member_with_arguments(tmp_path):
    # K = K(theta, thetadot) = 1/2 thetadot^T D thetadot: every member is the total kinetic energy
    body = (
        f"$$D(\\theta) = \\begin{{bmatrix}} {TEX['M11']} & {TEX['M12']} \\\\ {TEX['M12']} & {TEX['M22']} \\end{{bmatrix}}$$\n\n"
        f"$$K_1 = {TEX['K1']}$$\n\n$$K_2 = {TEX['K2']}$$\n\n"
        "$$K = K_1(\\theta, \\dot\\theta) + K_2(\\theta, \\dot\\theta) = \\frac{1}{2}\\dot\\theta^T D(\\theta)\\dot\\theta$$\n"
    )
    _, at, lines = _grade(tmp_path, body)
    assert at[_line(lines, "K = K_1")].status == "correct"
