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


#: serial chains: (joint name, type, xyz, placement rotation, axis, (mass, com, inertia about it))
UPPER = (1.2, np.array([0.15, 0.0, 0.0]), np.diag([0.01, 0.02, 0.02]))
SHIN = (1.5, np.array([0.0, 0.05, -0.2]), np.diag([0.03, 0.02, 0.02]))
HAND = (0.5, np.array([0.0, 0.02, -0.05]), np.diag([0.002, 0.003, 0.002]))
BOB = (MASS, COM, I_COM)
CHAINS = {
    "leg": [  # a ball joint at the root, then a knee
        ("hip", "spherical", [0, 0, 1], PLACEMENT, None, BOB),
        ("knee", "revolute", [0, 0, -0.5], np.eye(3), KNEE_AXIS, SHIN),
    ],
    "arm": [  # a ball joint on a turning link: its parent's w and wd enter
        ("shoulder", "revolute", [0, 0, 0.4], np.eye(3), np.array([0.0, 0.0, 1.0]), UPPER),
        ("elbow", "spherical", [0.3, 0, 0.1], rot_x(0.3) @ rot_z(-0.4), None, BOB),
        ("wrist", "revolute", [0, 0, -0.25], np.eye(3), KNEE_AXIS, HAND),
    ],
    "two-balls": [
        ("ball1", "spherical", [0, 0, 1], PLACEMENT, None, BOB),
        ("ball2", "spherical", [0, 0.1, -0.5], rot_z(0.5), None, SHIN),
    ],
}


def chain(name: str, offset: bool) -> Robot:
    """The chain ``name`` in armdyn; ``offset``: each ball joint's child frame placed at
    (OFFSET_R, OFFSET_P) in its moved joint frame."""
    links, joints, parent = [Link("base")], [], "base"
    for k, (joint, kind, xyz, R, axis, (m, c, inertia)) in enumerate(CHAINS[name]):
        child = f"link{k + 1}"
        links.append(Link(child, m, c.tolist(), inertia.tolist()))
        extra = {"axis": axis.tolist()} if axis is not None else {}
        if offset and kind == "spherical":
            extra.update(frame_xyz=OFFSET_P.tolist(), frame_rotation=OFFSET_R.tolist())
        joints.append(Joint(joint, kind, parent, child, xyz, R.tolist(), **extra))
        parent = child
    return Robot(name, links, joints)


def pinocchio_chain(name: str, offset: bool):
    """The chain ``name`` built in Pinocchio by hand: a frame offset ``Xf`` moves the body's
    inertia and the next joint's placement into the moved joint frame."""
    model, parent, Xf = pin.Model(), 0, pin.SE3.Identity()
    for joint, kind, xyz, R, axis, (m, c, inertia) in CHAINS[name]:
        jmodel = pin.JointModelSpherical() if kind == "spherical" else pin.JointModelRevoluteUnaligned(axis)
        parent = model.addJoint(parent, jmodel, Xf * pin.SE3(R, np.array(xyz, dtype=float)), joint)
        Xf = pin.SE3(OFFSET_R, OFFSET_P) if offset and kind == "spherical" else pin.SE3.Identity()
        model.appendBodyToJoint(parent, Xf.act(pin.Inertia(m, c, inertia)), pin.SE3.Identity())
    return model


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


@pytest.mark.parametrize(
    "name, offset", [("pendulum", False), *((n, o) for n in CHAINS for o in (False, True))], ids=str
)
def test_symbolic_equals_numeric(name, offset):
    robot = pendulum() if name == "pendulum" else chain(name, offset)
    eom = armdyn.derive(robot)
    for q, v, a in states(robot, 4, 2):
        expected = np.asarray(armdyn.rnea(robot, q, v, a), dtype=float)
        got = evaluate(eom, q, v, a)
        assert np.max(np.abs(got - expected)) <= TOL * max(1.0, np.max(np.abs(expected)))


@needs_pinocchio
@pytest.mark.parametrize("offset", [False, True], ids=["on-joint", "frame-offset"])
@pytest.mark.parametrize("name", list(CHAINS))
def test_against_pinocchio(name, offset):
    robot = chain(name, offset)
    eom = armdyn.derive(robot)
    model = pinocchio_chain(name, offset)
    data = model.createData()
    assert (model.nq, model.nv) == (robot.nq, robot.nv)
    for q, v, a in states(robot, 4, 3):
        expected = pin.rnea(model, data, q, v, a)
        got = evaluate(eom, q, v, a)
        assert np.max(np.abs(got - expected)) <= TOL * max(1.0, np.max(np.abs(expected)))


def test_report_prints_the_steps():
    eom = armdyn.derive(chain("leg", False))
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


@pytest.mark.parametrize("seed", range(4))
def test_random_trees_symbolic_equals_numeric(seed):
    """Branched random trees of revolute, prismatic, fixed and ball joints, child frames off
    their joints, gravity in any direction: the derivation equals the core's rnea."""
    from random_models import random_robot

    from armdyn.configuration import random_configuration

    rng = np.random.default_rng(100 + seed)
    robot = random_robot(rng, n_joints=5, tree=True, kinds="RPFSS", frame_offsets=True)
    assert robot.multi_dof_joints, "this seed draws no ball joint: the test would check nothing new"
    eom = armdyn.derive(robot)
    for _ in range(2):
        q = random_configuration(robot, rng)
        v, a = rng.normal(size=robot.nv), rng.normal(size=robot.nv)
        expected = np.asarray(armdyn.rnea(robot, q, v, a), dtype=float)
        got = evaluate(eom, q, v, a)
        assert np.max(np.abs(got - expected)) <= 1e-9 * max(1.0, np.max(np.abs(expected)))


def test_joint_terms_beside_a_ball_joint():
    """Damping, Coulomb friction, rotor inertia and offsets on the revolute joints around a
    ball joint land on their own rows (the ball's three rows carry none): the derivation
    equals the core's rnea, and the friction rows are the revolute joints'."""
    from dataclasses import replace

    robot = chain("arm", True)
    terms = dict(damping=0.3, armature=0.05, friction=0.2, torque_offset=0.1)
    joints = [replace(j, **terms) if j.type == "revolute" else j for j in robot.joints]
    robot = Robot(robot.name, robot.links.values(), joints)
    eom = armdyn.derive(robot)
    shoulder, wrist = sp.Symbol("shoulder_dot"), sp.Symbol("wrist_dot")
    friction = [0.3 * shoulder + 0.2 * sp.sign(shoulder), 0, 0, 0, 0.3 * wrist + 0.2 * sp.sign(wrist)]
    assert list(eom.friction) == friction
    for q, v, a in states(robot, 3, 7):
        expected = np.asarray(armdyn.rnea(robot, q, v, a), dtype=float)
        got = evaluate(eom, q, v, a)
        assert np.max(np.abs(got - expected)) <= TOL * max(1.0, np.max(np.abs(expected)))


def test_joint_terms_on_a_ball_joint():
    """Damping, Coulomb friction, rotor inertia and an offset on a ball joint apply to each
    of its three coordinates (as MuJoCo's on a ball joint): the derivation equals the
    core's rnea, whose terms are checked against MuJoCo in tests/test_joints_readers.py."""
    from dataclasses import replace

    robot = chain("arm", True)
    terms = dict(damping=0.3, armature=0.05, friction=0.2, torque_offset=0.1)
    joints = [replace(j, **terms) for j in robot.joints if j.movable] + [j for j in robot.joints if not j.movable]
    robot = Robot(robot.name, robot.links.values(), joints)
    eom = armdyn.derive(robot)
    for q, v, a in states(robot, 3, 11):
        expected = np.asarray(armdyn.rnea(robot, q, v, a), dtype=float)
        got = evaluate(eom, q, v, a)
        assert np.max(np.abs(got - expected)) <= TOL * max(1.0, np.max(np.abs(expected)))
