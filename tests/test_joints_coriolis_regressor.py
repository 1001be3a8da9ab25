"""The Coriolis matrix, the Jacobian's time derivative and the regressor on joints of
several coordinates (spherical, planar, free) and on a floating base.

Second opinions: Pinocchio's ``computeCoriolisMatrix``, ``getJointJacobianTimeVariation``
and ``computeJointTorqueRegressor`` (the same layouts; hand-built trees, fixed and
floating base, and random trees); and identities written here: ``C v = h - g``,
``Mdot = C + C^T`` along a path on the manifold (by central differences of M through
Pinocchio's ``integrate``), ``J qdd + Jdot v`` = the link's acceleration (by differences),
and ``Y pi = rnea`` with ``pi`` computed here from the links' masses and inertias.
"""

from __future__ import annotations

import numpy as np
import pytest
from optional import needs_pinocchio, pin
from random_models import random_link
from test_joints_numeric import _hand_built, mixed_tree, random_configuration

import armdyn.numeric as an
from armdyn.model import Joint, Link, Robot


def link_parameters(link: Link) -> np.ndarray:
    """``[m, m c, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`` about the link frame's origin (the
    parallel-axis theorem, by hand)."""
    m, c = float(link.mass), np.array(link.com, dtype=float).ravel()
    I_o = np.array(link.inertia, dtype=float) + m * (c @ c * np.eye(3) - np.outer(c, c))
    return np.array([m, *(m * c), I_o[0, 0], I_o[0, 1], I_o[1, 1], I_o[0, 2], I_o[1, 2], I_o[2, 2]])


def inertial_parameters(robot: Robot) -> np.ndarray:
    """The ten parameters of every link but a fixed base, in ``list(robot.links)`` order."""
    links = list(robot.links.values())
    return np.concatenate([link_parameters(k) for k in (links if robot.floating else links[1:])])


def model_parameters(robot: Robot) -> np.ndarray:
    """:func:`inertial_parameters`, then each velocity coordinate's joint terms that its
    joint states (a damping of 0 included), the columns of ``regressor(columns="model")``."""
    names = ("armature", "damping", "friction", "torque_offset")
    values = [getattr(j, k) for j in robot.movable_joints for _ in range(j.nv) for k in names]
    return np.concatenate([inertial_parameters(robot), [float(x) for x in values if x is not None]])


@needs_pinocchio
@pytest.mark.parametrize("floating", [False, True], ids=["fixed", "floating"])
def test_hand_built_tree_against_pinocchio(floating):
    robot, model = _hand_built(floating)
    data = model.createData()
    rng = np.random.default_rng(17)
    jid = model.getJointId("free")  # link 'c' hangs on the free joint, at its frame
    pi = inertial_parameters(robot)
    for _ in range(10):
        q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
        v, a = rng.normal(size=(2, model.nv))
        C = an.coriolis_matrix(robot, q, v)
        np.testing.assert_allclose(C, pin.computeCoriolisMatrix(model, data, q, v), rtol=0, atol=1e-10)
        np.testing.assert_allclose(C @ v, an.bias(robot, q, v) - an.gravity(robot, q), rtol=0, atol=1e-10)
        pin.computeJointJacobiansTimeVariation(model, data, q, v)
        dJ = pin.getJointJacobianTimeVariation(model, data, jid, pin.LOCAL_WORLD_ALIGNED)
        np.testing.assert_allclose(an.jacobian_dot(robot, q, v, "c"), dJ, rtol=0, atol=1e-10)
        Y = an.regressor(robot, q, v, a, columns="all")
        Y_pin = pin.computeJointTorqueRegressor(model, data, q, v, a)
        assert Y.shape == (model.nv, Y_pin.shape[1] + 4 * robot.dof)
        np.testing.assert_allclose(Y[:, : Y_pin.shape[1]], Y_pin, rtol=0, atol=1e-10)
        np.testing.assert_allclose(Y[:, : len(pi)] @ pi, an.rnea(robot, q, v, a), rtol=0, atol=1e-10)


@needs_pinocchio
@pytest.mark.parametrize("seed", range(12))
def test_random_trees_coriolis_against_pinocchio(seed):
    from pinocchio_bridge import PinocchioRobot

    rng = np.random.default_rng(300 + seed)
    robot = mixed_tree(rng, int(rng.integers(2, 7)))
    ref = PinocchioRobot(robot)
    for _ in range(3):
        q = random_configuration(robot, rng)
        v = rng.normal(size=robot.nv)
        np.testing.assert_allclose(an.coriolis_matrix(robot, q, v), ref.coriolis_matrix(q, v), rtol=0, atol=1e-10)


def test_mdot_is_c_plus_c_transpose_along_a_path():
    """dM/dt along q(t) = q ⊕ t v equals C + C^T (the Christoffel property), M by central
    differences on the manifold (armdyn's integrate, checked against Pinocchio's
    elsewhere)."""
    from armdyn.configuration import integrate

    rng = np.random.default_rng(23)
    for _ in range(20):
        robot = mixed_tree(rng, int(rng.integers(1, 5)))
        q = random_configuration(robot, rng)
        v = rng.normal(size=robot.nv)
        h = 1e-5
        Mdot = (an.crba(robot, integrate(robot, q, h * v)) - an.crba(robot, integrate(robot, q, -h * v))) / (2 * h)
        C = an.coriolis_matrix(robot, q, v)
        np.testing.assert_allclose(C + C.T, Mdot, rtol=0, atol=1e-6 * (1 + np.abs(Mdot).max()))


def test_jacobian_dot_is_the_rate_of_the_jacobian():
    """Jdot = dJ/dt along q(t) = q ⊕ t v, by central differences."""
    from armdyn.configuration import integrate

    rng = np.random.default_rng(29)
    for _ in range(20):
        robot = mixed_tree(rng, int(rng.integers(1, 5)))
        link = list(robot.links)[-1]
        q = random_configuration(robot, rng)
        v = rng.normal(size=robot.nv)
        h = 1e-5
        ahead, behind = integrate(robot, q, h * v), integrate(robot, q, -h * v)
        dJ = (an.jacobian(robot, ahead, link) - an.jacobian(robot, behind, link)) / (2 * h)
        np.testing.assert_allclose(an.jacobian_dot(robot, q, v, link), dJ, rtol=0, atol=1e-6)


def test_regressor_times_parameters_is_rnea_on_random_trees():
    rng = np.random.default_rng(31)
    for _ in range(50):
        robot = mixed_tree(rng, int(rng.integers(1, 6)))
        q = random_configuration(robot, rng)
        v, a = rng.normal(size=(2, robot.nv))
        Y = an.regressor(robot, q, v, a)  # no joint terms: the inertial columns only
        assert Y.shape == (robot.nv, 10 * len(robot.joints))
        np.testing.assert_allclose(Y @ inertial_parameters(robot), an.rnea(robot, q, v, a), rtol=0, atol=1e-9)


def test_regressor_joint_columns_per_velocity_coordinate():
    """A damped ball joint with rotor inertia: each of its three velocity coordinates has
    its own armature and damping columns, ``tau_k += Ia a_k + Fv v_k``."""
    rod = Link("rod", 2.0, (0.0, 0.1, -0.6), [[0.1, 0, 0], [0, 0.12, 0], [0, 0, 0.02]])
    joint = Joint("ball", "spherical", "base", "rod", armature=0.05, damping=0.3)
    robot = Robot("ball", [Link("base"), rod], [joint])
    rng = np.random.default_rng(37)
    quat = rng.normal(size=4)
    q, (v, a) = quat / np.linalg.norm(quat), rng.normal(size=(2, 3))
    Y = an.regressor(robot, q, v, a)
    assert Y.shape == (3, 10 + 3 * 2)
    for k in range(3):  # coordinate k: [qdd_k, qd_k] in its own pair of columns
        want = np.zeros((3, 2))
        want[k] = [a[k], v[k]]
        np.testing.assert_array_equal(Y[:, 10 + 2 * k : 12 + 2 * k], want)
    pi = np.concatenate([link_parameters(rod), [0.05, 0.3] * 3])
    np.testing.assert_allclose(Y @ pi, an.rnea(robot, q, v, a), rtol=0, atol=1e-12)


def test_floating_regressor_columns():
    """A floating base: the base link's ten columns come first and the base has no joint
    columns; ``Y pi = rnea`` with the base's parameters included."""
    rng = np.random.default_rng(41)
    links = [random_link(rng, n) for n in ("body", "leg")]
    joints = [Joint("hip", "revolute", "body", "leg", xyz=[0.1, 0, 0], axis=(0, 1, 0), damping=0.2)]
    robot = Robot("hopper", links, joints, root_joint="free-flyer")
    quat = rng.normal(size=4)
    q = np.concatenate([rng.normal(size=3), quat / np.linalg.norm(quat), [0.4]])
    v, a = rng.normal(size=(2, 7))
    Y = an.regressor(robot, q, v, a)
    assert Y.shape == (7, 20 + 1)
    np.testing.assert_array_equal(Y[:, 20], [0, 0, 0, 0, 0, 0, v[6]])
    pi = np.concatenate([inertial_parameters(robot), [0.2]])
    np.testing.assert_allclose(Y @ pi, an.rnea(robot, q, v, a), rtol=0, atol=1e-10)
