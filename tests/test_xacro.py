"""``.xacro`` models, trusted (untrusted ones are refused: test_security_probe_io.py):
expanded by the ``xacro`` package and read as URDF. The expanded robot equals the same
robot written out by hand (its rnea and M); without the package the error names the
file and the package."""

from __future__ import annotations

import builtins

import numpy as np
import pytest

import armdyn
from armdyn import numeric as num
from armdyn.errors import ModelError

XACRO = """<?xml version="1.0"?>
<robot name="two" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="len" value="0.4"/>
  <xacro:macro name="arm_link" params="name mass">
    <link name="${name}">
      <inertial><origin xyz="0 0 ${len/2}" rpy="0 0 0"/><mass value="${mass}"/>
        <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.002"/></inertial>
    </link>
  </xacro:macro>
  <link name="base"/>
  <xacro:arm_link name="l1" mass="1.5"/>
  <xacro:arm_link name="l2" mass="0.5"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="5" velocity="3"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0 ${len}" rpy="0 0 0"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="5" velocity="3"/></joint>
</robot>
"""

EXPANDED = """<robot name="two">
  <link name="base"/>
  <link name="l1"><inertial><origin xyz="0 0 0.2" rpy="0 0 0"/><mass value="1.5"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.002"/></inertial></link>
  <link name="l2"><inertial><origin xyz="0 0 0.2" rpy="0 0 0"/><mass value="0.5"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.002"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="5" velocity="3"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0 0.4" rpy="0 0 0"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="5" velocity="3"/></joint>
</robot>
"""


def test_xacro_equals_hand_expanded_urdf(tmp_path):
    pytest.importorskip("xacro")
    path = tmp_path / "two.urdf.xacro"
    path.write_text(XACRO)
    robot = armdyn.load(path, trusted=True)
    hand = armdyn.Robot.from_urdf(EXPANDED)
    assert robot.coordinate_names == hand.coordinate_names == ["j1", "j2"]
    rng = np.random.default_rng(2)
    for _ in range(3):
        q, qd, qdd = rng.uniform(-1, 1, (3, 2))
        np.testing.assert_allclose(num.rnea(robot, q, qd, qdd), num.rnea(hand, q, qd, qdd), rtol=0, atol=1e-13)
        np.testing.assert_allclose(num.crba(robot, q), num.crba(hand, q), rtol=0, atol=1e-13)


def test_bad_xacro_names_the_file(tmp_path):
    pytest.importorskip("xacro")
    path = tmp_path / "bad.xacro"
    path.write_text(XACRO.replace("${len/2}", "${nosuch}"))
    with pytest.raises(ModelError, match="bad.xacro.*xacro could not expand it"):
        armdyn.load(path, trusted=True)


def test_without_the_package_the_error_names_it(tmp_path, monkeypatch):
    path = tmp_path / "two.xacro"
    path.write_text(XACRO)
    real = builtins.__import__

    def no_xacro(name, globals=None, locals=None, fromlist=(), level=0):
        if name == "xacro" and level == 0:  # the package, not armdyn.io.xacro
            raise ImportError("No module named 'xacro'")
        return real(name, globals, locals, fromlist, level)

    monkeypatch.setattr(builtins, "__import__", no_xacro)
    with pytest.raises(ModelError, match=r"two.xacro.*needs the 'xacro' package: pip install xacro"):
        armdyn.load(path, trusted=True)
