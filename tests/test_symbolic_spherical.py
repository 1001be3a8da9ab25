"""The symbolic Newton-Euler derivation of spherical joints (newton_euler_spherical.py),
against three second opinions at random states:

* the ball pendulum's closed form, written here in NumPy: about the pivot O,
  ``tau = I_O wd + w x (I_O w) - m r x (R^T g)`` (I_O the inertia about the pivot, r the
  centre of mass from it, R the bob's rotation from its quaternion);
* armdyn.numeric.rnea (the Rust core), for the pendulum and a ball joint then a knee;
* Pinocchio's JointModelSpherical, the model built by hand here (no armdyn code).
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from optional import needs_pinocchio, pin

import armdyn
from armdyn.model import Joint, Link, Robot
from armdyn.symbolic.newton_euler_spherical import SphericalEquationsOfMotion, rotation_symbols, state_values
from armdyn.symbolic.report import derivation_report

TOL = 1e-10
G = np.array([0.0, 0.0, -9.81])
MASS, COM = 2.0, np.array([0.1, -0.05, -0.5])
I_COM = np.array([[0.15, 0.01, 0.0], [0.01, 0.2, 0.02], [0.0, 0.02, 0.25]])
KNEE_AXIS = np.array([0.6, 0.0, 0.8])


def rot_x(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_z(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


PLACEMENT = rot_x(0.3)
OFFSET_R, OFFSET_P = rot_z(0.7), np.array([0.05, 0.02, -0.1])


def quaternion_matrix(x, y, z, w) -> np.ndarray:
    """The rotation of the unit quaternion w + xi + yj + zk (written out independently)."""
    n = np.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array(
        [
            [w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z],
        ]
    )


def pendulum() -> Robot:
    links = [Link("base"), Link("bob", MASS, COM.tolist(), I_COM.tolist())]
    return Robot("ball", links, [Joint("ball", "spherical", "base", "bob", [0, 0, 1], PLACEMENT.tolist())])


def leg(offset: bool) -> Robot:
    """A ball joint (with a frame offset when ``offset``), then a knee about KNEE_AXIS."""
    extra = {"frame_xyz": OFFSET_P.tolist(), "frame_rotation": OFFSET_R.tolist()} if offset else {}
    links = [Link("base"), Link("thigh", MASS, COM.tolist(), I_COM.tolist())]
    links.append(Link("shin", 1.5, [0.0, 0.05, -0.2], np.diag([0.03, 0.02, 0.02]).tolist()))
    joints = [
        Joint("hip", "spherical", "base", "thigh", [0, 0, 1], PLACEMENT.tolist(), **extra),
        Joint("knee", "revolute", "thigh", "shin", [0, 0, -0.5], axis=KNEE_AXIS.tolist()),
    ]
    return Robot("leg", links, joints)


def states(robot: Robot, count: int, seed: int):
    """Random (q, v, a) in armdyn.numeric's layout: a spherical joint's q a random unit quaternion."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        q: list[float] = []
        for _, kind, _, _ in robot.configuration_layout:
            x = rng.normal(size=4)
            q += list(x / np.linalg.norm(x)) if kind == "spherical" else [rng.uniform(-np.pi, np.pi)]
        yield np.array(q), rng.normal(size=robot.nv), rng.normal(size=robot.nv)


def evaluate(eom, q, v, a) -> np.ndarray:
    values = state_values(eom.robot, q, v, a)
    out = np.array([float(t.xreplace(values)) for t in eom.tau])
    assert np.all(np.isfinite(out))
    return out


def test_ball_pendulum_closed_form():
    robot = pendulum()
    eom = armdyn.derive(robot)
    assert isinstance(eom, SphericalEquationsOfMotion)
    I_O = I_COM + MASS * (COM @ COM * np.eye(3) - np.outer(COM, COM))  # parallel axis theorem
    for q, w, wd in states(robot, 5, 1):
        R = PLACEMENT @ quaternion_matrix(*q)  # the bob's axes in the world
        expected = I_O @ wd + np.cross(w, I_O @ w) - MASS * np.cross(COM, R.T @ G)
        got = evaluate(eom, q, w, wd)
        assert np.max(np.abs(got - expected)) <= TOL * max(1.0, np.max(np.abs(expected)))


def test_terms_of_the_pendulum():
    """M is I_O (constant), g the gravity moment, bias = tau at zero acceleration; C refused."""
    eom = armdyn.derive(pendulum())
    I_O = I_COM + MASS * (COM @ COM * np.eye(3) - np.outer(COM, COM))
    assert np.max(np.abs(np.array(eom.M, dtype=float) - I_O)) <= TOL
    assert eom.g.free_symbols <= set(rotation_symbols(eom.robot.joints[0]))
    assert sp.expand(eom.bias - eom.g).free_symbols & set(eom.qd)  # velocity terms: w x I_O w
    with pytest.raises(armdyn.ModelError, match="quasi-velocity"):
        eom.C


def pinocchio_leg(offset: bool):
    """The leg built in Pinocchio by hand: a frame offset moves the thigh's inertia and the
    knee's placement into the moved joint frame."""
    model = pin.Model()
    hip = model.addJoint(0, pin.JointModelSpherical(), pin.SE3(PLACEMENT, np.array([0.0, 0.0, 1.0])), "hip")
    Xf = pin.SE3(OFFSET_R, OFFSET_P) if offset else pin.SE3.Identity()
    model.appendBodyToJoint(hip, Xf.act(pin.Inertia(MASS, COM, I_COM)), pin.SE3.Identity())
    knee_at = Xf * pin.SE3(np.eye(3), np.array([0.0, 0.0, -0.5]))
    knee = model.addJoint(hip, pin.JointModelRevoluteUnaligned(KNEE_AXIS), knee_at, "knee")
    inertia = pin.Inertia(1.5, np.array([0.0, 0.05, -0.2]), np.diag([0.03, 0.02, 0.02]))
    model.appendBodyToJoint(knee, inertia, pin.SE3.Identity())
    return model


@needs_pinocchio
@pytest.mark.parametrize("offset", [False, True])
def test_against_pinocchio(offset):
    robot = leg(offset)
    eom = armdyn.derive(robot)
    model = pinocchio_leg(offset)
    data = model.createData()
    assert (model.nq, model.nv) == (robot.nq, robot.nv)
    for q, v, a in states(robot, 4, 3):
        expected = pin.rnea(model, data, q, v, a)
        got = evaluate(eom, q, v, a)
        assert np.max(np.abs(got - expected)) <= TOL * max(1.0, np.max(np.abs(expected)))


def test_report_prints_the_steps():
    eom = armdyn.derive(leg(False))
    text = derivation_report([eom], "text", steps=True)
    assert "spherical joint 'hip'" in text  # the head says what the symbols are
    assert "τ₁..₃ = [" in text and "τ₄ = " in text  # the ball's moment, the knee's torque
    assert "ω⁽¹⁾x" in text and "r⁽¹⁾₃₃" in text and "ω̇⁽¹⁾z" in text
    latex = derivation_report([eom], "latex", steps=True)
    assert r"\dot{\omega}^{(1)}_{x}" in latex and r"r^{(1)}_{33}" in latex
    ascii_text = derivation_report([eom], "text", steps=True, ascii=True)
    assert ascii_text.isascii() and "tau1..3" in ascii_text and "hip.wx_dot" in ascii_text
    html = derivation_report([eom], "html", steps=True)
    assert "spherical joint" in html
