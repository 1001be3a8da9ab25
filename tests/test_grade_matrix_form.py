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


def _grade(tmp_path, body, head=HEAD):
    path = tmp_path / "d.md"
    path.write_text(head + body)
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
        r"\tau = M(\Theta)\ddot\Theta + B(\Theta)[\dot\Theta\dot\Theta] + C(\Theta)[\dot\Theta^2] + G(\Theta)",
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


# ------------------------------------------------------------ unit vectors in values
CRAIG = (
    "---\nrobot: planar-2r\nmethod: newton-euler\nsymbols:\n  '\\theta_1': q1\n  '\\theta_2': q2\n"
    "  'l_1': l1\n  'l_{c1}': lc1\n  'l_{c2}': lc2\n---\n\n"
)


def _unit_axis_text(vec, frame: int, letters=("X", "Y", "Z")) -> str:
    names = {q1: r"\theta_1", q2: r"\theta_2", qd1: r"\dot{\theta}_1", qd2: r"\dot{\theta}_2"}
    terms = [
        rf"\left({sp.latex(c, symbol_names=names)}\right) \hat{{{ax}}}_{{{frame}}}"
        for c, ax in zip(vec, letters)
        if c != 0
    ]
    return " + ".join(terms)


def test_the_parser_keeps_the_hat_of_a_unit_axis():
    from armdyn.grading.latex import parse
    from armdyn.grading.notation import SymbolMap
    from armdyn.io import load

    symbols = SymbolMap(load("planar-2r"), {"l_1": "l1"})
    ex, ey, ez = (sp.eye(3)[:, k] for k in range(3))
    assert parse(r"l_1\hat X_1", symbols) == l1 * ex
    assert parse(r"\hat{Z}_1", symbols) == ez
    assert parse(r"\hat z", symbols) == ez
    assert parse(r"{}^{1}\hat{X}_{1}", symbols) == ex
    assert parse(r"\hat{j}", symbols) == ey
    assert parse(r"l_1 \hat{\theta}_1", symbols) == l1 * q1  # any other letter: \hat is a typeface


def test_a_vector_written_with_unit_axes_is_graded(tmp_path):
    g = sp.Symbol("g")
    rot = sp.Matrix([[sp.cos(q1), -sp.sin(q1), 0], [sp.sin(q1), sp.cos(q1), 0], [0, 0, 1]])
    base = sp.Matrix([0, g, 0])  # the base accelerates upwards: gravity along -Y_0
    in_1 = rot.T * base  # by hand: (g sin q1, g cos q1, 0)
    assert sp.simplify(in_1 - sp.Matrix([g * sp.sin(q1), g * sp.cos(q1), 0])) == sp.zeros(3, 1)
    swapped = sp.Matrix([in_1[1], in_1[0], 0])  # a slip: sine and cosine exchanged
    body = (
        r"$${}^{0}\dot{v}_{0} = g \hat{Y}_0$$" + "\n\n"
        rf"$${{}}^{{1}}\dot{{v}}_{{1}} = {_unit_axis_text(in_1, 1)}$$" + "\n\n"
        rf"$${{}}^{{1}}\dot{{v}}_{{1}} = {_unit_axis_text(swapped, 1)}$$" + "\n\n"
        r"$${}^{1}\omega_{1} = \dot{\theta}_1 \hat{Z}_1$$" + "\n"
    )
    report = _grade(tmp_path, body, head=CRAIG)
    assert [v.status for v in report.steps] == ["correct", "correct", "wrong", "correct"]
    note = next(n for n in report.notes if "unit axes" in n)  # the reading is said, not silent
    assert r"\hat Y_{0}" in note and r"\hat Z_{1}" in note


# ------------------------------------------------------------ Coriolis entries, Lynch & Park's energies
def _coriolis():
    """C(q, q̇) from the Christoffel symbols of the hand inertia matrix D."""
    c = sp.zeros(2, 2)
    for k in range(2):
        for j in range(2):
            c[k, j] = sum(
                (sp.diff(D[k, j], Q[i]) + sp.diff(D[k, i], Q[j]) - sp.diff(D[i, j], Q[k])) / 2 * QD[i] for i in range(2)
            )
    return c.applyfunc(sp.simplify)


def test_coriolis_entries_and_lynch_parks_energies(tmp_path):
    c = _coriolis()
    assert sp.simplify(c[1, 0] - m2 * l1 * lc2 * sp.sin(q2) * qd1) == 0  # the textbook's C_21
    names = {**NAMES, qd1: r"\dot{q}_1", qd2: r"\dot{q}_2"}
    t1 = (m1 * V1.dot(V1) + I1 * qd1**2) / 2
    p1 = sp.Symbol("g") * m1 * PC1[1]  # gravity along -y
    body = "\n\n".join(
        [
            rf"$$C_{{12}} = {sp.latex(c[0, 1], symbol_names=names)}$$",
            rf"$$c_{{12}} = {sp.latex(c[0, 1], symbol_names=names)}$$",
            rf"$$C_{{21}} = {sp.latex(c[1, 0], symbol_names=names)}$$",
            rf"$$C_{{21}} = {sp.latex(-c[1, 0], symbol_names=names)}$$",
            rf"$$\mathcal E_{{K_1}} = {sp.latex(sp.simplify(t1), symbol_names=names)}$$",
            rf"$$\mathcal{{E}}_{{K_1}} = {sp.latex(sp.simplify(2 * t1), symbol_names=names)}$$",
            rf"$$\mathcal{{P}}_1 = {sp.latex(p1, symbol_names=names)}$$",
        ]
    )
    report = _grade(tmp_path, body + "\n")
    assert [(v.name, v.status) for v in report.steps] == [
        ("C_12", "correct"),
        ("C_12", "correct"),
        ("C_21", "correct"),
        ("C_21", "wrong"),
        ("T_1", "correct"),
        ("T_1", "wrong"),
        ("V_1", "correct"),
    ]


# ------------------------------------------------------------ partials as a row
def test_a_partial_by_the_joint_vector_as_a_row(tmp_path):
    dv = [sp.diff(sp.Symbol("g") * (m1 * PC1[1] + m2 * PC2[1]), x) for x in Q]
    cells = [sp.latex(e, symbol_names=NAMES) for e in dv]
    lhs = r"\frac{\partial V}{\partial q}"
    body = "\n\n".join(
        [
            rf"$${lhs} = \begin{{bmatrix}} {cells[0]} & {cells[1]} \end{{bmatrix}}$$",
            rf"$${lhs} = \left( {cells[0]}, {cells[1]} \right)$$",
            rf"$${lhs} = ( {cells[0]}, {cells[1]} )$$",
            rf"$${lhs} = \left( {cells[1]}, {cells[0]} \right)$$",  # the entries exchanged: a slip
        ]
    )
    report = _grade(tmp_path, body + "\n")
    assert [v.status for v in report.steps] == ["correct"] * 6 + ["wrong", "wrong"]


def test_an_unreadable_matrix_before_the_matrix_form_is_not_an_error(tmp_path):
    """A G that could not be read (here a 2x3 product), then the right G: the matrix form
    stated after them is the law with a right G, not a consequence of an error."""
    g = r"\begin{bmatrix} (m_1 l_{c1} + m_2 l_1) g\cos q_1 + m_2 l_{c2} g\cos(q_1 + q_2) \\ m_2 l_{c2} g\cos(q_1 + q_2) \end{bmatrix}"
    body = (
        r"$$G = \begin{bmatrix} 1 & 0 & 0 \\ 0 & 1 & 0 \end{bmatrix}$$" + "\n\n"
        f"$$G = {g}$$\n\n"
        r"$$\tau = M(q)\ddot{q} + C(q,\dot{q})\dot{q} + G(q)$$" + "\n"
    )
    path = tmp_path / "g.md"
    path.write_text(
        "---\nrobot: planar-2r\nsymbols: {'l_{c1}': lc1, 'l_{c2}': lc2, 'l_1': l1}\n---\n" + body, encoding="utf-8"
    )
    steps = grade(str(path)).steps
    assert [v.status for v in steps] == ["unrecognised", "correct", "correct"], [(v.status, v.message) for v in steps]
