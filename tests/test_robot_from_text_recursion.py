"""Craig's outward recursion naming {}^{i}P_{C_i} and {}^{i}P_{i+1} only inside products: the
vectors are solved from the text's own accelerations (robot_text/recursion.py). The texts are
written by hand; the model expected is a YAML model written by hand, compared as dynamics
(M, C, g at random states)."""

from __future__ import annotations

from armdyn.errors import ModelError
from armdyn.grading import grade
from armdyn.grading.reader import read
from armdyn.grading.robot_text import robot_from_text
from armdyn.grading.robot_text.assigned import dynamics_differ
from armdyn.io.yaml import load_yaml_string

#: a planar 2R: mass centres at a and b on X_1, X_2, link 1 of length L, inertias J_k about z
RR = """
name: rr
parameters: [m1, m2, L, a, b, J1, J2, g]
gravity: [0, -g, 0]
joints:
  - {name: theta1, type: revolute, parent: base, child: link1, axis: [0, 0, 1]}
  - {name: theta2, type: revolute, parent: link1, child: link2, xyz: [L, 0, 0], axis: [0, 0, 1]}
links:
  - {name: link1, mass: m1, com: [a, 0, 0], inertia: {ixx: 0, iyy: J1, izz: J1}}
  - {name: link2, mass: m2, com: [b, 0, 0], inertia: {ixx: 0, iyy: J2, izz: J2}}
"""

# the accelerations below worked out by hand: v1 = R_0^1 (0, g, 0); v_C1 adds the tangential
# a th1'' and centripetal -a th1'^2 along X_1; v2 = Rz(th2)^T (v1 + th1'' L Y_1 - th1'^2 L X_1)
_TEXT = r"""---
method: newton-euler
---
Link 1 turns by $\theta_1$, link 2 by $\theta_2$; the base accelerates upwards by $g$.

$${}^{1}\omega_1 = \begin{bmatrix} 0 \\ 0 \\ \dot\theta_1 \end{bmatrix}, \quad
{}^{1}\dot\omega_1 = \begin{bmatrix} 0 \\ 0 \\ \ddot\theta_1 \end{bmatrix}$$

$${}^{1}\dot v_1 = \begin{bmatrix} g s_1 \\ g c_1 \\ 0 \end{bmatrix}$$

$${}^{1}\dot v_{C_1} = {}^{1}\dot\omega_1 \times {}^{1}P_{C_1} + {}^{1}\omega_1 \times ({}^{1}\omega_1 \times {}^{1}P_{C_1})
+ {}^{1}\dot v_1 = \begin{bmatrix} -a\dot\theta_1^2 + g s_1 \\ a\ddot\theta_1 + g c_1 \\ 0 \end{bmatrix}$$

$${}^{1}N_1 = \begin{bmatrix} 0 \\ 0 \\ J_1\ddot\theta_1 \end{bmatrix}$$

$${}^{2}\omega_2 = \begin{bmatrix} 0 \\ 0 \\ \dot\theta_1 + \dot\theta_2 \end{bmatrix}, \quad
{}^{2}\dot\omega_2 = \begin{bmatrix} 0 \\ 0 \\ \ddot\theta_1 + \ddot\theta_2 \end{bmatrix}$$

$${}^{2}\dot v_2 = {}^{2}_{1}R\left({}^{1}\dot\omega_1 \times {}^{1}P_2 + {}^{1}\omega_1 \times ({}^{1}\omega_1 \times {}^{1}P_2)
+ {}^{1}\dot v_1\right) = \begin{bmatrix} L s_2\ddot\theta_1 - L c_2\dot\theta_1^2 + g s_{12} \\
L c_2\ddot\theta_1 + L s_2\dot\theta_1^2 + g c_{12} \\ 0 \end{bmatrix}$$

$${}^{2}\dot v_{C_2} = \begin{bmatrix} L s_2\ddot\theta_1 - L c_2\dot\theta_1^2 + g s_{12} - b(\dot\theta_1 + \dot\theta_2)^2 \\
L c_2\ddot\theta_1 + L s_2\dot\theta_1^2 + g c_{12} + b(\ddot\theta_1 + \ddot\theta_2) \\ 0 \end{bmatrix}$$

$${}^{2}F_2 = m_2\,{}^{2}\dot v_{C_2}, \quad {}^{1}F_1 = m_1\,{}^{1}\dot v_{C_1}$$

$${}^{2}N_2 = \begin{bmatrix} 0 \\ 0 \\ J_2(\ddot\theta_1 + \ddot\theta_2) \end{bmatrix}$$
"""


def _write(tmp_path, text: str) -> str:
    path = tmp_path / "text.md"
    path.write_text(text, encoding="utf-8")
    return str(path)


def test_positions_and_inertias_solved_from_the_recursion(tmp_path):
    model = robot_from_text(read(_write(tmp_path, _TEXT)))
    written = load_yaml_string(RR, source="written by hand", strict=False)
    assert dynamics_differ(model.robot, written) is None
    notes = " ".join(model.assumptions)
    assert "{}^{1}P_{C_1} = [a, 0, 0]" in notes and "{}^{1}P_{2} = [L, 0, 0]" in notes
    assert "{}^{2}P_{C_2} = [b, 0, 0]" in notes and "diag(0, J2, J2)" in notes
    report = grade(_write(tmp_path, _TEXT))
    assert report.notes[0].startswith("model read from the text")
    assert all(v.status == "correct" for v in report.steps if v.name.startswith(("F_", "N_", "vc_dot", "v_dot")))


def test_no_constant_vector_gives_the_acceleration(tmp_path):
    # v_C1 with a term that grows with theta_1 itself: no constant P_C1 gives it, so link 1's
    # mass centre stays unplaced (and no other statement places it)
    text = _TEXT.replace(r"-a\dot\theta_1^2 + g s_1", r"-a\theta_1\dot\theta_1^2 + g s_1")
    try:
        notes = robot_from_text(read(_write(tmp_path, text))).assumptions
    except ModelError as err:  # read no further: the reason names what is missing
        notes = [str(err)]
    assert not any("{}^{1}P_{C_1} =" in n for n in notes)
    assert any("{}^{2}P_{C_2} = [b, 0, 0]" in n for n in notes) or "cannot read" in notes[0]
