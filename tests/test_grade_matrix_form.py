"""`armdyn grade` reads the equations of motion in matrix form with ``τ`` first
(``τ = M(q) q̈ + C(q, q̇) q̇ + G(q)``, ``τ = [M]q̈ + [C]q̇ + [G]``, Craig's ``V(Θ, Θ̇)``,
Lynch & Park's ``c(θ, θ̇)``) as the statement of the law, like the form with ``τ`` last.

The inertia matrix of the planar elbow arm is derived here by hand in plain SymPy (mass
centres written out, kinetic energy's Hessian in the joint rates), never taken from
armdyn's output.
"""

from __future__ import annotations

import pytest
import sympy as sp

from armdyn.grading import grade

q1, q2, qd1, qd2 = sp.symbols("q1 q2 q1_dot q2_dot")
m1, m2, l1, lc1, lc2, I1, I2 = sp.symbols("m1 m2 l1 lc1 lc2 I1 I2")
Q, QD = [q1, q2], [qd1, qd2]
NAMES = {q1: "q_1", q2: "q_2", m1: "m_1", m2: "m_2", l1: "l_1", lc1: "l_{c1}", lc2: "l_{c2}", I1: "I_1", I2: "I_2"}
HEAD = "---\nrobot: planar-2r\nmethod: lagrange\nsymbols:\n  'l_{c1}': lc1\n  'l_{c2}': lc2\n---\n\n"

PC1 = sp.Matrix([lc1 * sp.cos(q1), lc1 * sp.sin(q1)])
PC2 = sp.Matrix([l1 * sp.cos(q1) + lc2 * sp.cos(q1 + q2), l1 * sp.sin(q1) + lc2 * sp.sin(q1 + q2)])
V1, V2 = PC1.jacobian(Q) * sp.Matrix(QD), PC2.jacobian(Q) * sp.Matrix(QD)
T = (m1 * V1.dot(V1) + m2 * V2.dot(V2) + I1 * qd1**2 + I2 * (qd1 + qd2) ** 2) / 2
D = sp.hessian(T, QD).applyfunc(sp.simplify)


def _pmatrix(m) -> str:
    rows = [" & ".join(sp.latex(m[i, j], symbol_names=NAMES) for j in range(m.cols)) for i in range(m.rows)]
    return r"\begin{pmatrix}" + r" \\ ".join(rows) + r"\end{pmatrix}"


def _grade(tmp_path, body):
    path = tmp_path / "d.md"
    path.write_text(HEAD + body)
    return grade(path)


def _status(report):
    return [(v.name, v.status) for v in report.steps]


def test_the_hand_inertia_matrix_is_the_textbooks():
    assert sp.simplify(D[1, 1] - (m2 * lc2**2 + I2)) == 0
    assert sp.simplify(D[0, 1] - (m2 * (lc2**2 + l1 * lc2 * sp.cos(q2)) + I2)) == 0


@pytest.mark.parametrize(
    "law",
    [
        r"\tau = M(q)\ddot{q} + C(q,\dot{q})\dot{q} + G(q)",
        r"\tau = [M]\ddot{q} + [C]\dot{q} + [G]",
        r"\tau = M(\Theta)\ddot\Theta + V(\Theta,\dot\Theta) + G(\Theta)",
        r"\tau = M(\theta)\ddot\theta + c(\theta,\dot\theta) + g(\theta)",
        r"D(q)\ddot q + C\dot q + g = \tau",
    ],
)
def test_the_matrix_form_with_tau_first_is_the_law(tmp_path, law):
    report = _grade(tmp_path, f"$${law}$$\n")
    assert _status(report) == [("matrix_form", "correct")]
    assert "no matrix given before it" in report.steps[0].message


def test_the_matrix_form_follows_the_matrix_given_before_it(tmp_path):
    law = r"$$\tau = D(q)\ddot{q} + C(q,\dot{q})\dot{q} + g(q)$$" + "\n"
    right = _grade(tmp_path, f"$$D(q) = {_pmatrix(D)}$$\n\n" + law)
    assert _status(right)[-1] == ("matrix_form", "correct")
    assert "with the matrices given earlier" in right.steps[-1].message
    slip = D.copy()
    slip[1, 1] = m2 * lc2**2  # I_2 dropped
    wrong = _grade(tmp_path, f"$$D(q) = {_pmatrix(slip)}$$\n\n" + law)
    assert _status(wrong)[0][1] == "wrong"
    assert _status(wrong)[-1] == ("matrix_form", "follows-from-earlier-error")


def test_one_joints_torque_with_entries_stays_a_step(tmp_path):
    # τ_1 written with matrix entries is the first row, not the vector law
    report = _grade(tmp_path, r"$$\tau_1 = M_{11}\ddot{q}_1 + M_{12}\ddot{q}_2 + G_1$$" + "\n")
    assert all(v.name != "matrix_form" for v in report.steps)
