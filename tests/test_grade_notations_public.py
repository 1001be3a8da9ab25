"""Notations learnt from public course material (tests/corpus/README.md): each reader
added for one is checked here on a short derivation of its own.

The expected verdicts are worked out by hand: the right values are the planar 2R arm's
textbook formulas (Spong's D(q), phi_k), the wrong ones carry a slip put in by hand.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from armdyn.grading import grade
from armdyn.grading.equations import split_equations

HEAD = """---
robot: planar-2r
method: lagrange
symbols:
{symbols}---

"""
SYMS_2R = {"l_1": "l1", "l_{c1}": "lc1", "l_{c2}": "lc2", "m_1": "m1", "m_2": "m2", "I_1": "I1", "I_2": "I2", "g": "g"}


def graded(tmp_path: Path, body: str, **symbols) -> dict:
    """Grade ``body`` on the planar 2R arm; {step name: status}."""
    table = {**SYMS_2R, **symbols}
    lines = "".join(f"  '{k}': {v}\n" for k, v in table.items())
    path = tmp_path / "derivation.md"
    path.write_text(HEAD.format(symbols=lines) + body, encoding="utf-8")
    report = grade(path)
    return {s.name: s.status for s in report.steps}


# --- SymPy's printed functions of time (a notebook's output cells) -----------------------

TH1 = r"\theta_{1}{\left(t \right)}"
TH2 = r"\theta_{2}{\left(t \right)}"
D1 = r"\frac{d}{d t} " + TH1
D2 = r"\frac{d}{d t} " + TH2
DD1 = r"\frac{d^{2}}{d t^{2}} " + TH1
DD2 = r"\frac{d^{2}}{d t^{2}} " + TH2
SYMPY = {r"\theta_{1}": "q1", r"\theta_{2}": "q2", "l_{1}": "l1", "l_{c2}": "lc2", "m_{2}": "m2", "I_{2}": "I2"}


def test_sympy_printed_time_functions_are_read_as_rates_and_accelerations(tmp_path):
    # tau_2 = (I2 + m2 lc2^2 + m2 l1 lc2 c2) q1'' + (I2 + m2 lc2^2) q2'' + m2 l1 lc2 s2 q1'^2 + m2 g lc2 c12
    tau2 = (
        rf"\left(I_{{2}} + l_{{1}} l_{{c2}} m_{{2}} \cos{{\left({TH2} \right)}} + l_{{c2}}^{{2}} m_{{2}}\right) {DD1}"
        rf" + \left(I_{{2}} + l_{{c2}}^{{2}} m_{{2}}\right) {DD2}"
        rf" + l_{{1}} l_{{c2}} m_{{2}} \sin{{\left({TH2} \right)}} \left({D1}\right)^{{2}}"
        rf" + g l_{{c2}} m_{{2}} \cos{{\left({TH1} + {TH2} \right)}}"
    )
    right = graded(tmp_path, f"$\\displaystyle \\tau_{{2}} = {tau2}$\n", **SYMPY)
    assert right == {"tau_2": "correct"}
    # the centrifugal term with the rate of joint 2 instead of joint 1: a slip
    slip = tau2.replace(rf"\left({D1}\right)^{{2}}", rf"\left({D2}\right)^{{2}}")
    assert graded(tmp_path, f"$\\displaystyle \\tau_{{2}} = {slip}$\n", **SYMPY) == {"tau_2": "wrong"}


def test_time_functions_keep_offsets_and_leave_other_fractions():
    block = r"x = \frac{d}{d t} \theta_{1}{\left(t \right)} + y, \quad z = \frac{d}{dt} L"
    (off1, eq1), (off2, eq2) = split_equations(block)
    assert eq1.split() == ["x", "=", r"\dot{\theta_{1}}", "+", "y"]
    assert block[off2:].startswith("z =") and eq2 == r"z = \frac{d}{dt} L"


# --- a system of equations with a brace: \begin{cases}, \left\{\begin{array} ------------


def test_a_system_of_equations_splits_at_its_rows():
    for block in (
        "\\begin{cases}\nx_1=a\\\\\ny_1=b\\\\\n\\end{cases}",
        "\\left\\{ \\begin{array}{l}\nx_1=a\\\\\ny_1=b\n\\end{array} \\right.",
    ):
        rows = split_equations(block)
        assert [t for _, t in rows] == ["x_1=a", "y_1=b"], block
        assert all(block[off:].startswith(t) for off, t in rows)
    # a brace that is a value (a piecewise function) is not a system: one equation
    assert len(split_equations(r"f = \begin{cases} a & x > 0 \\ b & x \le 0 \end{cases}")) == 1


def test_cases_rows_are_graded_each(tmp_path):
    body = "\\[\n\\begin{cases}\nx_2=l_1\\cos \\theta _1+l_{c2}\\cos \\left( \\theta _1+\\theta _2 \\right)\\\\\n"
    body += "y_2=l_1\\sin \\theta _1+l_{c2}\\cos \\left( \\theta _1+\\theta _2 \\right)\\\\\n\\end{cases}\n\\]\n"
    got = graded(tmp_path, body, **{r"\theta_1": "q1", r"\theta_2": "q2"})
    assert got == {"x_c2": "correct", "y_c2": "wrong"}  # y_2 holds cos for sin: a slip


# --- Murray, Li & Sastry's N(theta, theta-dot) ----------------------------------------


@pytest.mark.parametrize("lhs", [r"N(\theta,\dot\theta)", r"N(\theta)"])
def test_mls_N_is_the_gravity_vector(tmp_path, lhs):
    # phi_1 = (m1 lc1 + m2 l1) g c1 + m2 lc2 g c12, phi_2 = m2 lc2 g c12 (gravity along -y)
    value = (
        r"\begin{bmatrix} (m_1 l_{c1} + m_2 l_1) g\cos\theta_1 + m_2 l_{c2} g\cos(\theta_1+\theta_2) \\"
        r" m_2 l_{c2} g\cos(\theta_1+\theta_2) \end{bmatrix}"
    )
    syms = {r"\theta_1": "q1", r"\theta_2": "q2"}
    assert list(graded(tmp_path, f"$${lhs} = {value}$$\n", **syms).values()) == ["correct"]
    slip = value.replace(r"m_2 l_{c2} g\cos(\theta_1+\theta_2) \end", r"m_2 l_1 g\cos(\theta_1+\theta_2) \end")
    assert list(graded(tmp_path, f"$${lhs} = {slip}$$\n", **syms).values()) == ["wrong"]


# --- Asada & Slotine's H_{ij} ----------------------------------------------------------


def test_asada_H_entries_are_the_inertia_matrix(tmp_path):
    # d_12 = m2 (lc2^2 + l1 lc2 c2) + I2 (Spong's D(q) of the 2R arm); d_22 has no cos term
    syms = {"q_1": "q1", "q_2": "q2"}
    h12 = r"$$H_{12} = m_2(l_{c2}^2 + l_1 l_{c2}\cos q_2) + I_2$$" + "\n"
    h22 = r"$$H_{22} = m_2(l_{c2}^2 + l_1 l_{c2}\cos q_2) + I_2$$" + "\n"
    assert graded(tmp_path, h12, **syms) == {"M_12": "correct"}
    assert graded(tmp_path, h22, **syms) == {"M_22": "wrong"}


# --- the Rome course's u_i: the input torque, not an energy -----------------------------


def test_u_with_accelerations_is_the_torque_and_without_an_energy(tmp_path):
    syms = {r"\theta_1": "q1", r"\theta_2": "q2"}
    # tau_2 of the 2R arm (Spong): d21 q1'' + d22 q2'' + m2 l1 lc2 s2 q1'^2 + m2 g lc2 c12
    tau2 = (
        r"(I_2 + m_2(l_{c2}^2 + l_1 l_{c2}\cos\theta_2))\ddot\theta_1 + (I_2 + m_2 l_{c2}^2)\ddot\theta_2"
        r" + m_2 l_1 l_{c2}\sin\theta_2\dot\theta_1^2 + m_2 g l_{c2}\cos(\theta_1+\theta_2)"
    )
    assert graded(tmp_path, f"$$u_2 = {tau2}$$\n", **syms) == {"tau_2": "correct"}
    assert graded(tmp_path, f"$$u_2 = {tau2.replace('^2 + m_2 g', '^2 - m_2 g')}$$\n", **syms) == {"tau_2": "wrong"}
    # no acceleration in the value: link 1's potential energy m1 g lc1 sin(theta1), as before
    assert graded(tmp_path, r"$$u_1 = m_1 g l_{c1}\sin\theta_1$$" + "\n", **syms) == {"V_1": "correct"}


# --- a column equal to a column, trigonometric functions typed as letters ---------------


def test_column_equations_split_into_their_rows():
    block = r"\left[ \begin{array}{c} P_{1,x} \\ P_{1,y} \end{array} \right] = \left[ \begin{array}{c} a \\ b \end{array} \right]"
    rows = split_equations(block)
    assert [t for _, t in rows] == ["P_{1,x} = a", "P_{1,y} = b"]
    assert [block[o : o + 7] for o, _ in rows] == ["P_{1,x}", "P_{1,y}"]
    bm = r"\begin{bmatrix} x_1 \\ y_1 \end{bmatrix} = \begin{bmatrix} c \\ d \end{bmatrix}"
    assert [t for _, t in split_equations(bm)] == ["x_1 = c", "y_1 = d"]
    # a matrix times a column, or columns of different lengths: one equation, not split
    for block in (
        r"\begin{bmatrix} x \\ y \end{bmatrix} = \begin{bmatrix} a & b \\ c & d \end{bmatrix}\begin{bmatrix} e \\ f \end{bmatrix}",
        r"\begin{bmatrix} x \\ y \end{bmatrix} = \begin{bmatrix} a \\ b \\ c \end{bmatrix}",
    ):
        assert len(split_equations(block)) == 1


def test_bare_trig_letters_are_the_functions():
    ((_, eq),) = split_equations(r"x = r_1 cos(\theta_1) + sin (\theta_2)")
    assert eq == r"x = r_1\cos(\theta_1) +\sin (\theta_2)"
    ((_, eq),) = split_equations(r"x = cost(a) + \cos(b)")  # a word ending in cos is not cos
    assert eq == r"x = cost(a) + \cos(b)"


def test_point_components_with_a_comma_and_bare_trig(tmp_path):
    syms = {r"\theta_1": "q1", r"\theta_2": "q2", "r_2": "lc2"}
    body = (
        "$$ \\left[ \\begin{array}{c} P_{2,x} \\\\\nP_{2,y} \\end{array} \\right] = \\left[ \\begin{array}{c} "
        "l_1 cos(\\theta_1) + r_2 cos(\\theta_1 + \\theta_2) \\\\\nl_1 sin(\\theta_1) + r_2 cos(\\theta_1 + \\theta_2)"
        " \\end{array} \\right] $$\n"
    )
    assert graded(tmp_path, body, **syms) == {"x_c2": "correct", "y_c2": "wrong"}  # cos for sin in y
