"""Positions written component by component as ``P_{k,x}``, ``P_{k,y}`` (a column equation
of the mass centres), a potential energy written with those names, and a closed form whose
gravity vector ``g(q)`` shares its letter with the constant ``g``. The texts are written by
hand; the model expected is a YAML model written by hand (compared as dynamics M, C, g at
random states), the torques by plain SymPy."""

from __future__ import annotations

import sympy as sp

from armdyn.grading import grade
from armdyn.grading.reader import read
from armdyn.grading.robot_text import robot_from_text
from armdyn.grading.robot_text.assigned import dynamics_differ
from armdyn.io.yaml import load_yaml_string

#: a planar 2R with mass centres at a_1 and a_2 from the joints, rods' inertias I_k about z
RR = """
name: rr
parameters: [m1, m2, l1, a1, a2, I1, I2, g]
gravity: [0, -g, 0]
joints:
  - {name: q1, type: revolute, parent: base, child: link1, axis: [0, 0, 1]}
  - {name: q2, type: revolute, parent: link1, child: link2, xyz: [l1, 0, 0], axis: [0, 0, 1]}
links:
  - {name: link1, mass: m1, com: [a1, 0, 0], inertia: {ixx: 0, iyy: I1, izz: I1}}
  - {name: link2, mass: m2, com: [a2, 0, 0], inertia: {ixx: 0, iyy: I2, izz: I2}}
"""

_COLUMNS = r"""---
method: lagrange
---
Where the mass centres are:

$$ \left[ \begin{array}{c} P_{1,x} \\ P_{1,y} \end{array} \right] =
\left[ \begin{array}{c} a_1 \cos q_1 \\ a_1 \sin q_1 \end{array} \right] $$

$$ \left[ \begin{array}{c} P_{2,x} \\ P_{2,y} \end{array} \right] =
\left[ \begin{array}{c} l_1 \cos q_1 + a_2 \cos(q_1 + q_2) \\ l_1 \sin q_1 + a_2 \sin(q_1 + q_2) \end{array} \right] $$

$$ T = \frac{1}{2} m_1 a_1^2 \dot q_1^2 + \frac{1}{2} I_1 \dot q_1^2 + \frac{1}{2} m_2 \left( l_1^2 \dot q_1^2
+ a_2^2 (\dot q_1 + \dot q_2)^2 + 2 l_1 a_2 \cos q_2 \dot q_1 (\dot q_1 + \dot q_2) \right)
+ \frac{1}{2} I_2 (\dot q_1 + \dot q_2)^2 $$

$$ V = m_1 g P_{1,y} + m_2 g P_{2,y} $$
"""


def _write(tmp_path, text: str) -> str:
    path = tmp_path / "text.md"
    path.write_text(text, encoding="utf-8")
    return str(path)


def test_mass_centres_as_column_components_place_the_arm(tmp_path):
    path = _write(tmp_path, _COLUMNS)
    model = robot_from_text(read(path))
    written = load_yaml_string(RR, source="written by hand", strict=False)
    assert dynamics_differ(model.robot, written) is None
    # V written with the names P_{k,y} is the heights stated: no conflict with them
    assert not model.conflicts
    report = grade(path)
    assert report.notes[0].startswith("model read from the text")
    assert {v.name: v.status for v in report.steps if v.name in ("T", "V")} == {"T": "correct", "V": "correct"}


def test_a_slip_in_a_component_stays_a_conflict_with_v(tmp_path):
    # P_{1,y} with a cos for the sin: V, whose heights are those names, is still read as stated,
    # and the x and y of link 1 are named as not one point
    text = _COLUMNS.replace(r"a_1 \sin q_1 \end{array}", r"a_1 \cos q_1 \end{array}")
    model = robot_from_text(read(_write(tmp_path, text)))
    assert any("x_1 and y_1 are not one point" in c for c in model.conflicts)


q1, q2, qd1, qd2, qdd1, qdd2 = sp.symbols("q1 q2 qd1 qd2 qdd1 qdd2")
m, g, b, c = sp.symbols("m g b c")

_CLOSED = r"""---
method: lagrange
---
The closed form (the geometry is in the figure):

$$M(q) = \begin{bmatrix} b + 2 c \cos q_2 & c \cos q_2 \\ c \cos q_2 & b \end{bmatrix}$$

$$h(q, \dot q) = \begin{bmatrix} -c \sin q_2 (2 \dot q_1 \dot q_2 + \dot q_2^2) \\ c \sin q_2 \dot q_1^2 \end{bmatrix}$$

$$g(q) = \begin{bmatrix} m g \cos q_1 \\ 0 \end{bmatrix}$$

$$\tau_1 = (b + 2 c \cos q_2) \ddot q_1 + c \cos q_2 \ddot q_2 - c \sin q_2 (2 \dot q_1 \dot q_2 + \dot q_2^2) + m g \cos q_1$$

$$\tau_2 = c \cos q_2 \ddot q_1 + b \ddot q_2 + c \sin q_2 \dot q_1^2 + m g \cos q_1$$
"""


def test_a_gravity_vector_named_g_beside_the_constant_g(tmp_path):
    # tau = M qdd + h + g(q) by hand: tau_1 is right, tau_2 has a gravity term g(q) has not
    M = sp.Matrix([[b + 2 * c * sp.cos(q2), c * sp.cos(q2)], [c * sp.cos(q2), b]])
    h = sp.Matrix([-c * sp.sin(q2) * (2 * qd1 * qd2 + qd2**2), c * sp.sin(q2) * qd1**2])
    G = sp.Matrix([m * g * sp.cos(q1), 0])
    tau = M * sp.Matrix([qdd1, qdd2]) + h + G
    written_1 = (b + 2 * c * sp.cos(q2)) * qdd1 + c * sp.cos(q2) * qdd2 + h[0] + m * g * sp.cos(q1)
    written_2 = c * sp.cos(q2) * qdd1 + b * qdd2 + c * sp.sin(q2) * qd1**2 + m * g * sp.cos(q1)
    assert sp.simplify(written_1 - tau[0]) == 0 and sp.simplify(written_2 - tau[1]) != 0
    report = grade(_write(tmp_path, _CLOSED))
    assert report.model_note.startswith("no model:")
    status = {v.name: v.status for v in report.steps}
    assert status["tau_1"] == "consistent"
    assert status["tau_2"] == "wrong"


_CRAIG_ROTATIONS = r"""---
method: newton-euler
---
Frame 2 sits at the elbow (its place is in the figure). The rotations between the frames:

$${}^{1}_{0}R = \begin{bmatrix} c_1 & s_1 & 0 \\ -s_1 & c_1 & 0 \\ 0 & 0 & 1 \end{bmatrix}$$

$${}^{2}_{1}R = \begin{bmatrix} c_2 & -s_2 & 0 \\ s_2 & c_2 & 0 \\ 0 & 0 & 1 \end{bmatrix}$$

$${}^{1}_{2}R = \begin{bmatrix} c_2 & -s_2 & 0 \\ s_2 & c_2 & 0 \\ 0 & 0 & 1 \end{bmatrix}$$

$${}^{2}F_2 = m_2 \begin{bmatrix} a \ddot\theta_2 \\ b \dot\theta_1 \\ 0 \end{bmatrix}$$
"""


def test_a_rotation_between_successive_frames_is_checked_against_its_joint(tmp_path):
    # {}^{b}_{a}R maps frame-a coordinates to frame b; joint k turns theta_k about z, so frame k's
    # axes in frame k-1 are the columns of Rz(theta_k) and {}^{k}_{k-1}R is its transpose
    t1, t2 = sp.symbols("theta1 theta2")

    def rz(t):
        return sp.Matrix([[sp.cos(t), -sp.sin(t), 0], [sp.sin(t), sp.cos(t), 0], [0, 0, 1]])

    written = rz(t2)  # lines 8 and 10 write the same matrix
    assert sp.simplify(
        rz(t1).T - sp.Matrix([[sp.cos(t1), sp.sin(t1), 0], [-sp.sin(t1), sp.cos(t1), 0], [0, 0, 1]])
    ) == sp.zeros(3)
    assert sp.simplify(written - rz(t2).T) != sp.zeros(3)  # {}^{2}_{1}R written transposed
    report = grade(_write(tmp_path, _CRAIG_ROTATIONS))
    assert report.model_note.startswith("no model:")
    by_line = {v.line: v for v in report.steps}
    assert by_line[6].status == "correct"  # {}^{1}_{0}R = Rz(theta_1)^T
    assert by_line[8].status == "wrong" and "Rz(" in by_line[8].message  # {}^{2}_{1}R = Rz(theta_2): transposed
    assert by_line[10].status == "correct"  # {}^{1}_{2}R = Rz(theta_2)
