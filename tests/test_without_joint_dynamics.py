"""Dropping joint damping/friction/armature: ``Robot.without_joint_dynamics()``.

Pinocchio's ``rnea``/``aba`` are rigid-body only (its URDF parser reads ``<dynamics>``
but the algorithms ignore it), so the stripped model must equal Pinocchio's, read by
Pinocchio's own URDF parser from the same text, and the full model must differ from it
by exactly the closed form ``damping qd + friction sign(qd)``.
"""

from __future__ import annotations

import numpy as np
import pytest

from armdyn import numeric as num
from armdyn.io.urdf import load_urdf

URDF = """<robot name="two_link">
  <link name="base"/>
  <link name="l1">
    <inertial><origin xyz="0.1 0.02 0.3" rpy="0 0 0"/><mass value="1.3"/>
      <inertia ixx="0.05" ixy="0.001" ixz="0.002" iyy="0.04" iyz="0.003" izz="0.02"/></inertial>
  </link>
  <link name="l2">
    <inertial><origin xyz="0.05 0.0 0.25" rpy="0 0 0"/><mass value="0.8"/>
      <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.025" iyz="0" izz="0.01"/></inertial>
  </link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-3" upper="3" effort="10" velocity="5"/><dynamics damping="0.7" friction="0.3"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0.1 0.6" rpy="0.2 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="10" velocity="5"/><dynamics damping="0.4" friction="0.1"/></joint>
</robot>
"""


def test_joint_dynamics_reported_and_dropped():
    robot = load_urdf(URDF)
    assert robot.joint_dynamics == ("damping", "friction")
    assert "joint_dynamics=['damping', 'friction']" in repr(robot)
    rigid = robot.without_joint_dynamics()
    assert rigid.joint_dynamics == ()
    assert "joint_dynamics" not in repr(rigid)
    assert robot.joint_dynamics == ("damping", "friction")  # the original is unchanged
    assert rigid.without_joint_dynamics() is rigid


def test_rigid_rnea_aba_equal_pinocchio():
    pin = pytest.importorskip("pinocchio")
    model = pin.buildModelFromXML(URDF)
    data = model.createData()
    robot = load_urdf(URDF)
    rigid = robot.without_joint_dynamics()
    damping, friction = np.array([0.7, 0.4]), np.array([0.3, 0.1])
    rng = np.random.default_rng(3)
    for _ in range(5):
        q, qd, qdd = rng.uniform(-2, 2, (3, 2))
        expect = pin.rnea(model, data, q, qd, qdd).copy()
        np.testing.assert_allclose(num.rnea(rigid, q, qd, qdd), expect, rtol=0, atol=1e-12)
        # the full model adds the URDF's joint terms, and Pinocchio has none of them
        np.testing.assert_allclose(
            num.rnea(robot, q, qd, qdd), expect + damping * qd + friction * np.sign(qd), rtol=0, atol=1e-12
        )
        tau = rng.uniform(-5, 5, 2)
        np.testing.assert_allclose(num.aba(rigid, q, qd, tau), pin.aba(model, data, q, qd, tau), rtol=0, atol=1e-10)
