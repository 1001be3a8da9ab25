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
