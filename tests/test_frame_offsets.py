"""Link frames off their joint's axis (``Joint.frame_xyz`` / ``frame_rotation``), as in the
exercise's RP arm, whose frame 1 sits at the point mass, l1 from joint 1's axis.

Second opinions: the NumPy reference handles the offset natively (motion subspace of an
off-axis frame); the Rust core computes on ``Robot.canonical()`` (frames moved onto the
joints); the symbolic engine by Newton-Euler (moving frame origin) and by Lagrange; and
the rp-arm's kinematics against the exercise's geometry, written out by hand.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from random_models import random_robot, random_state

import armdyn
from armdyn import reference

SEEDS = [11, 12, 13, 14, 15, 16]


def _robot(seed, tree=False, n=4):
    rng = np.random.default_rng(seed)
    robot = random_robot(rng, n_joints=n, tree=tree, frame_offsets=True)
    assert any(j.has_frame_offset for j in robot.joints), "the case must exercise offsets"
    return robot, rng


def _close(a, b, tol=1e-10):
    a, b = np.asarray(a, float), np.asarray(b, float)
    assert np.all(np.isfinite(a)) and np.all(np.isfinite(b))
    np.testing.assert_allclose(a, b, rtol=tol, atol=tol)


@pytest.mark.parametrize("seed", SEEDS)
def test_rust_core_on_canonical_frames_equals_reference_with_offsets(seed):
    robot, rng = _robot(seed, tree=seed % 2 == 0)
    for _ in range(2):
        q, qd, qdd = (random_state(rng, robot.dof) for _ in range(3))
        _close(armdyn.rnea(robot, q, qd, qdd), reference.rnea(robot, q, qd, qdd))
        _close(armdyn.crba(robot, q), reference.crba(robot, q))
        tau = random_state(rng, robot.dof)
        _close(armdyn.aba(robot, q, qd, tau), reference.aba(robot, q, qd, tau), 1e-8)
        _close(armdyn.kinetic_energy(robot, q, qd), reference.kinetic_energy(robot, q, qd))
        _close(armdyn.forward_kinematics(robot, q), reference.forward_kinematics(robot, q))
        for link in list(robot.links)[1:]:
            _close(armdyn.jacobian(robot, q, link), reference.jacobian(robot, q, link))


@pytest.mark.parametrize("seed", SEEDS[:3])
def test_jacobian_of_an_offset_frame_is_the_derivative_of_its_position(seed):
    """Independent of both engines' Jacobians: finite differences of the pose."""
    robot, rng = _robot(seed)
    q = random_state(rng, robot.dof)
    link = list(robot.links)[-1]
    k = list(robot.links).index(link)
    J = armdyn.jacobian(robot, q, link)
    h = 1e-6
    for j in range(robot.dof):
        dq = np.zeros(robot.dof)
        dq[j] = h
        dp = (
            armdyn.forward_kinematics(robot, q + dq)[k, :3, 3] - armdyn.forward_kinematics(robot, q - dq)[k, :3, 3]
        ) / (2 * h)
        np.testing.assert_allclose(J[:3, j], dp, atol=1e-7)


@pytest.mark.parametrize("seed", SEEDS[:3])
def test_symbolic_newton_euler_and_lagrange_agree_with_offsets(seed):
    robot, rng = _robot(seed, n=3)
    ne = armdyn.derive(robot, "newton-euler")
    la = armdyn.derive(robot, "lagrange")
    symbols = list(robot.q) + list(robot.qd) + list(robot.qdd)
    f_ne = sp.lambdify(symbols, ne.tau, "numpy")
    f_la = sp.lambdify(symbols, la.tau, "numpy")
    for _ in range(3):
        q, qd, qdd = (random_state(rng, robot.dof) for _ in range(3))
        args = [*q, *qd, *qdd]
        a, b = np.ravel(f_ne(*args)), np.ravel(f_la(*args))
        _close(a, b, 1e-9)
        _close(a, reference.rnea(robot, q, qd, qdd), 1e-9)


def test_rp_arm_frames_are_the_exercises():
    """Frame 1 at the point mass, l1 along the turned x axis; frame 2 at the slider's tip,
    d2 further along y1; R_1^2 as the exercise writes it (frame-1 -> frame-2 coordinates)."""
    robot = armdyn.load("rp-arm")
    th, d2, l1 = robot.q[0], robot.q[1], robot.parameters["l1"]
    R1, p1 = robot.joints[0].transform(th)
    assert sp.simplify(p1 - sp.Matrix([l1 * sp.cos(th), l1 * sp.sin(th), 0])) == sp.zeros(3, 1)
    R2, p2 = robot.joints[1].transform(d2)
    assert p2 == sp.Matrix([0, d2, 0])
    assert R2.T == sp.Matrix([[1, 0, 0], [0, 0, -1], [0, 1, 0]])
    steps = {(s.name, s.link): s.value for s in armdyn.derive(robot, "newton-euler").steps}
    # the exercise's v̇_1 formula with the term it drops: the centripetal -l1 θ̇1² in x
    theta1_dot, theta1_ddot, g = robot.qd[0], robot.qdd[0], robot.parameters["g"]
    expected = sp.Matrix([g * sp.sin(th) - l1 * theta1_dot**2, g * sp.cos(th) + l1 * theta1_ddot, 0])
    assert sp.simplify(steps[("v_dot", "link1")] - expected) == sp.zeros(3, 1)


def test_canonical_form_moves_inertia_and_children_exactly():
    robot = armdyn.load("rp-arm")
    canon = robot.canonical()
    assert not any(j.has_frame_offset for j in canon.joints)
    assert canon.links["link1"].com == sp.Matrix([robot.parameters["l1"], 0, 0])
    assert sp.simplify(armdyn.derive(canon).tau - armdyn.derive(robot).tau) == sp.zeros(2, 1)


def test_yaml_reads_frame_offsets_and_rejects_bad_ones(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(
        "name: x\nparameters: [l1]\njoints:\n  - {name: j1, type: revolute, parent: base, child: a,"
        " frame_xyz: [l1, 0, 0], frame_rotation: [[1, 0, 0], [0, 1, 0], [0, 0, 2]]}\nlinks:\n"
        "  - {name: a, mass: 1, inertia: 0}\n"
    )
    with pytest.raises(armdyn.ModelError, match="frame_rotation"):
        armdyn.load(str(bad))
