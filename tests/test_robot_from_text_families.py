"""More notations the robot is read from (Craig's unit axes and generic link i, point masses
placed by x_k / y_k, a stated gravity vector, a theta that is a length, V's zero): each read
model is compared, as dynamics (M, C, g at random states), with the model the text was
written from, given here as YAML written by hand."""

from __future__ import annotations

import pytest

from armdyn.grading import grade
from armdyn.grading.reader import read
from armdyn.grading.robot_text import robot_from_text
from armdyn.grading.robot_text.assigned import dynamics_differ
from armdyn.io.yaml import load_yaml_string

#: Craig's example 6.6: point masses at the link tips, gravity along -y0
CRAIG_2R = """
name: craig-2r
parameters: [m1, m2, L1, L2, g]
gravity: [0, -g, 0]
joints:
  - {name: theta1, type: revolute, parent: base, child: link1, axis: [0, 0, 1]}
  - {name: theta2, type: revolute, parent: link1, child: link2, xyz: [L1, 0, 0], axis: [0, 0, 1]}
links:
  - {name: link1, mass: m1, com: [L1, 0, 0], inertia: 0}
  - {name: link2, mass: m2, com: [L2, 0, 0], inertia: 0}
"""


def _write(tmp_path, text: str, name: str = "text.md") -> str:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return str(path)


def _read(path: str):
    return robot_from_text(read(path))


def _same_dynamics(read_model, yaml_text: str) -> None:
    written = load_yaml_string(yaml_text, source="written by hand", strict=False)
    assert dynamics_differ(read_model.robot, written) is None


def test_craig_generic_link_unit_axes_and_base_acceleration(tmp_path):
    # frames from a generic link i, masses at the tips on \hat X_i, gravity by the base's
    # acceleration; a case shown in passing (gravity along -z) is outvoted
    text = r"""---
method: newton-euler
---
Frames: ${}^{i}_{i+1}R = \begin{bmatrix} c_{i+1} & -s_{i+1} & 0 \\ s_{i+1} & c_{i+1} & 0 \\ 0 & 0 & 1 \end{bmatrix}$,
${}^{i}P_{i+1} = L_i \hat X_i$ and ${}^{i}P_{C_i} = L_i \hat X_i$ (masses at the tips).
Were gravity along $-\hat Z_0$ we would set ${}^{0}\dot v_0 = g \hat Z_0$; here

$${}^{0}\dot v_0 = g \hat Y_0, \quad {}^{C_1}I_1 = 0$$

Outward from the base, ${}^{0}\dot v_0 = g \hat Y_0$:

$${}^{1}\omega_1 = \dot\theta_1 \hat Z_1, \quad {}^{2}\omega_2 = (\dot\theta_1 + \dot\theta_2) \hat Z_2$$

$${}^{1}F_1 = m_1 \, {}^{1}\dot v_{C_1}, \quad {}^{2}F_2 = m_2 \, {}^{2}\dot v_{C_2}$$
"""
    model = _read(_write(tmp_path, text))
    _same_dynamics(model, CRAIG_2R)
    assert any("another gravity" in c for c in model.conflicts)
    assert any(a.startswith("frame 1's origin at frame 0's") for a in model.assumptions)


def test_point_masses_placed_by_x_and_y_with_a_slip_in_one(tmp_path):
    # a double pendulum hanging down; y_1 has a sign slip: x_1 and the next mass agree
    text = r"""---
method: lagrange
---
$$x_1 = l_1 \sin\theta_1$$
$$y_1 = l_1 \cos\theta_1$$
$$x_2 = l_1 \sin\theta_1 + l_2 \sin(\theta_1 + \theta_2)$$
$$y_2 = -l_1 \cos\theta_1 - l_2 \cos(\theta_1 + \theta_2)$$
$$T_1 = \frac{1}{2} m_1 l_1^2 \dot\theta_1^2, \quad T_2 = \frac{1}{2} m_2 v_2^2$$
"""
    model = _read(_write(tmp_path, text))
    hanging = """
name: pendulum
parameters: [m1, m2, l1, l2, g]
gravity: [0, -g, 0]
joints:
  - {name: theta1, type: revolute, parent: base, child: link1, rpy: [0, 0, -pi/2], axis: [0, 0, 1]}
  - {name: theta2, type: revolute, parent: link1, child: link2, xyz: [l1, 0, 0], axis: [0, 0, 1]}
links:
  - {name: link1, mass: m1, com: [l1, 0, 0], inertia: 0}
  - {name: link2, mass: m2, com: [l2, 0, 0], inertia: 0}
"""
    _same_dynamics(model, hanging)
    assert any("x_1 and y_1 are not one point" in c and "x_1 used" in c for c in model.conflicts)


def test_a_theta_that_is_a_length_is_a_prismatic_joint(tmp_path):
    # an RP arm whose slide is written theta_2 (x_2 = theta_2 cos theta_1), rods' I about z
    text = r"""---
method: lagrange
---
$$x_1 = L_1\cos\theta_1, \qquad y_1 = L_1\sin\theta_1$$
$$x_2 = \theta_2\cos\theta_1, \qquad y_2 = \theta_2\sin\theta_1$$
$$\mathcal P_1 = m_1 g L_1 \sin\theta_1, \qquad \mathcal P_2 = m_2 g \theta_2 \sin\theta_1$$
$$T = \tfrac12 (I_1 + I_2 + m_1 L_1^2 + m_2\theta_2^2)\dot\theta_1^2 + \tfrac12 m_2 \dot\theta_2^2$$
"""
    model = _read(_write(tmp_path, text))
    rp = """
name: rp
parameters: [m1, m2, L1, I1, I2, g]
gravity: [0, -g, 0]
joints:
  - {name: theta1, type: revolute, parent: base, child: link1, axis: [0, 0, 1]}
  - {name: theta2, type: prismatic, parent: link1, child: link2, axis: [1, 0, 0]}
links:
  - {name: link1, mass: m1, com: [L1, 0, 0], inertia: {ixx: 0, iyy: I1, izz: I1}}
  - {name: link2, mass: m2, com: [0, 0, 0], inertia: {ixx: 0, iyy: I2, izz: I2}}
"""
    _same_dynamics(model, rp)
    assert any("joint 2 is prismatic" in a for a in model.assumptions)


_GRAVITY_TWICE = r"""---
method: lagrange
---
$$p_{c_1} = \begin{bmatrix} l_{c1} \cos q_1 \\ l_{c1} \sin q_1 \\ 0 \end{bmatrix}, \quad
p_{c_2} = \begin{bmatrix} l_1 \cos q_1 + l_{c2} \cos(q_1 + q_2) \\ l_1 \sin q_1 + l_{c2} \sin(q_1 + q_2) \\ 0 \end{bmatrix}$$

$$T = \frac{1}{2} m_1 l_{c1}^2 \dot q_1^2 + \frac{1}{2} m_2 (l_1^2 \dot q_1^2 + l_{c2}^2 (\dot q_1 + \dot q_2)^2
 + 2 l_1 l_{c2} \dot q_1 (\dot q_1 + \dot q_2) \cos q_2)$$

The figure has gravity along y:

$$g = \begin{bmatrix} 0 \\ -g \\ 0 \end{bmatrix}$$

but ours acts along x:

$$g = \begin{bmatrix} -g \\ 0 \\ 0 \end{bmatrix}$$

$$G_1 = -(m_1 l_{c1} + m_2 l_1) g s_1 - m_2 l_{c2} g s_{12}$$

$$G_2 = -m_2 l_{c2} g s_{12}$$
"""


def test_of_two_gravities_stated_the_one_the_steps_support_is_kept(tmp_path):
    path = _write(tmp_path, _GRAVITY_TWICE)
    model = _read(path)
    assert len(model.alternatives) == 1
    # G = dV/dq with V = m g x (gravity along -x): G_1 = -(m1 lc1 + m2 l1) g sin q1 - ...
    report = grade(path)
    statuses = {v.name: v.status for v in report.steps if v.name in ("G_1", "G_2")}
    assert statuses == {"G_1": "correct", "G_2": "correct"}
    assert "the reading kept is the one the text's steps agree with" in report.model_note
    assert "gravity (-g, 0, 0)" in report.model_note


def test_a_constant_in_a_height_is_the_zero_of_v(tmp_path):
    # Craig-style V with its reference added; the glued m2d_2 is m_2 d_2
    text = r"""---
method: lagrange
---
$$k_1 = \frac{1}{2} m_1 (l_1 \dot\theta_1)^2 + \frac{1}{2} I_{zz1} \dot\theta_1^2$$
$$k_2 = \frac{1}{2} m_2 ((d_2 \dot\theta_1)^2 + \dot d_2^2) + \frac{1}{2} I_{zz2} \dot\theta_1^2$$
$$u = (m_1 l_1 + m2d_2) g \sin\theta_1 + (m_1 l_1 + m_2 d_{max}) g$$
"""
    model = _read(_write(tmp_path, text))
    rp = """
name: rp
parameters: [m1, m2, l1, Izz1, Izz2, g]
gravity: [0, -g, 0]
joints:
  - {name: theta1, type: revolute, parent: base, child: link1, axis: [0, 0, 1]}
  - {name: d2, type: prismatic, parent: link1, child: link2, axis: [1, 0, 0]}
links:
  - {name: link1, mass: m1, com: [l1, 0, 0], inertia: {ixx: 0, iyy: Izz1, izz: Izz1}}
  - {name: link2, mass: m2, com: [0, 0, 0], inertia: {ixx: 0, iyy: Izz2, izz: Izz2}}
"""
    _same_dynamics(model, rp)
    assert any("read as where V is zero" in c for c in model.conflicts)


@pytest.mark.parametrize("wrong_sign", [False, True])
def test_a_slip_in_the_whole_t_is_named_when_each_t_k_agrees(tmp_path, wrong_sign):
    t12 = r"m_2 l_1 l_{c2} \cos\theta_2"
    whole = (
        r"\frac{1}{2}(m_1 l_{c1}^2 + m_2 (l_1^2 + l_{c2}^2 + 2 l_1 l_{c2}\cos\theta_2))\dot\theta_1^2"
        + rf" + (m_2 l_{{c2}}^2 + {t12})\dot\theta_1\dot\theta_2 + \frac{{1}}{{2}} m_2 l_{{c2}}^2 \dot\theta_2^2"
    )
    if wrong_sign:
        whole = whole.replace(r"+ (m_2 l_{c2}^2 + ", r"- (m_2 l_{c2}^2 + ")
    text = rf"""---
method: lagrange
---
$$T_1 = \frac{{1}}{{2}} m_1 l_{{c1}}^2 \dot\theta_1^2$$
$$T_2 = \frac{{1}}{{2}} m_2 (l_1^2 \dot\theta_1^2 + l_{{c2}}^2 (\dot\theta_1 + \dot\theta_2)^2
 + 2 l_1 l_{{c2}} \dot\theta_1 (\dot\theta_1 + \dot\theta_2) \cos\theta_2)$$
$$T = {whole}$$
$$V_1 = m_1 g l_{{c1}} \sin\theta_1$$
$$V_2 = m_2 g (l_1 \sin\theta_1 + l_{{c2}} \sin(\theta_1 + \theta_2))$$
"""
    model = _read(_write(tmp_path, text))
    rr = """
name: rr
parameters: [m1, m2, l1, lc1, lc2, g]
gravity: [0, -g, 0]
joints:
  - {name: theta1, type: revolute, parent: base, child: link1, axis: [0, 0, 1]}
  - {name: theta2, type: revolute, parent: link1, child: link2, xyz: [l1, 0, 0], axis: [0, 0, 1]}
links:
  - {name: link1, mass: m1, com: [lc1, 0, 0], inertia: 0}
  - {name: link2, mass: m2, com: [lc2, 0, 0], inertia: 0}
"""
    _same_dynamics(model, rr)
    named = any("T is not the sum of the links' T_k" in c for c in model.conflicts)
    assert named == wrong_sign


def test_a_mass_centre_named_with_c_wins_over_a_point_written_without(tmp_path):
    # x_2, y_2 (first) are the arm's tip here; x_{c2}, y_{c2} link 2's mass centre
    text = r"""---
method: lagrange
---
$$x_{c1} = l_{c1}\cos\theta_1, \quad y_{c1} = l_{c1}\sin\theta_1$$
$$x_2 = l_1\cos\theta_1 + l_2\cos(\theta_1 + \theta_2), \quad y_2 = l_1\sin\theta_1 + l_2\sin(\theta_1 + \theta_2)$$
$$x_{c2} = l_1\cos\theta_1 + l_{c2}\cos(\theta_1 + \theta_2), \quad y_{c2} = l_1\sin\theta_1 + l_{c2}\sin(\theta_1 + \theta_2)$$
$$V = m_1 g y_{c1} + m_2 g y_{c2}$$
$$T_1 = \frac{1}{2} m_1 l_{c1}^2 \dot\theta_1^2, \quad T_2 = \frac{1}{2} m_2 v_{c2}^2$$
"""
    model = _read(_write(tmp_path, text))
    rr = """
name: rr
parameters: [m1, m2, l1, lc1, lc2, g]
gravity: [0, -g, 0]
joints:
  - {name: theta1, type: revolute, parent: base, child: link1, axis: [0, 0, 1]}
  - {name: theta2, type: revolute, parent: link1, child: link2, xyz: [l1, 0, 0], axis: [0, 0, 1]}
links:
  - {name: link1, mass: m1, com: [lc1, 0, 0], inertia: 0}
  - {name: link2, mass: m2, com: [lc2, 0, 0], inertia: 0}
"""
    _same_dynamics(model, rr)


def test_of_an_x_and_a_y_that_disagree_the_one_the_steps_support_is_kept(tmp_path):
    # a hanging pendulum, x_1 with a sign slip: x_1 alone is the upright point (-l s, l c), y_1
    # alone the hanging one (l s, -l c); V and tau (worked out by hand for the hanging one) decide
    text = r"""---
method: lagrange
---
$$x_1 = -l_1 \sin\theta_1$$
$$y_1 = -l_1 \cos\theta_1$$
$$T = \frac{1}{2} m_1 l_1^2 \dot\theta_1^2$$
$$V = -m_1 g l_1 \cos\theta_1$$
$$L = T - V$$
$$\tau_1 = m_1 l_1^2 \ddot\theta_1 + m_1 g l_1 \sin\theta_1$$
"""
    path = _write(tmp_path, text)
    model = _read(path)
    assert any("x_1 used: the first written" in c for c in model.conflicts)
    assert len(model.alternatives) == 1
    report = grade(path)
    assert "the reading kept is the one the text's steps agree with" in report.model_note
    status = {v.name: v.status for v in report.steps}
    assert status["tau_1"] == "correct" and status["V"] == "correct"
