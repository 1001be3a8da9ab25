"""Joints of several coordinates (spherical, planar, floating) in the numeric core.

Second opinions: Pinocchio (JointModelSpherical / Planar / FreeFlyer, the same layouts) on
hand-built and random trees, fixed and floating bases; and physical identities on random
trees mixing every joint kind: ``aba(rnea(a)) = a``, M symmetric positive definite,
``M e_k = rnea(q, 0, e_k) - rnea(q, 0, 0)``, ``T = 1/2 v^T M v``,
``integrate(q, difference(q, q')) = q'``, batches equal to single calls bit for bit.
"""

from __future__ import annotations

import numpy as np
import pytest
from optional import needs_pinocchio, pin
from random_models import random_link, random_robot, random_rotation

import armdyn.centroidal as ac
import armdyn.numeric as an
from armdyn.model import Joint, Link, Robot


def random_configuration(robot: Robot, rng: np.random.Generator) -> np.ndarray:
    """A random q: joint coordinates in [-pi, pi], unit quaternions and (cos, sin) pairs
    drawn independently of armdyn."""
    q = np.empty(robot.nq)
    if robot.floating:
        q[:3] = rng.uniform(-1, 1, 3)
        quat = rng.normal(size=4)
        q[3:7] = quat / np.linalg.norm(quat)
    for _, kind, iq, _ in robot.configuration_layout:
        if kind in ("revolute", "prismatic"):
            q[iq] = rng.uniform(-np.pi, np.pi)
        elif kind == "planar":
            th = rng.uniform(-np.pi, np.pi)
            q[iq : iq + 4] = [*rng.uniform(-1, 1, 2), np.cos(th), np.sin(th)]
        else:
            quat = rng.normal(size=4)
            start = iq + (3 if kind == "floating" else 0)
            q[iq:start] = rng.uniform(-1, 1, start - iq)
            q[start : start + 4] = quat / np.linalg.norm(quat)
    return q


def mixed_tree(rng: np.random.Generator, n: int) -> Robot:
    """A random tree whose joints are drawn from every kind, at least one of several
    coordinates."""
    while True:
        robot = random_robot(rng, n_joints=n, tree=True, kinds="RPFSLX")
        if robot.multi_dof_joints:
            return robot


def test_random_trees_identities():
    rng = np.random.default_rng(7)
    worst = dict(aba=0.0, sym=0.0, col=0.0, energy=0.0, manifold=0.0)
    for _ in range(1000):
        robot = mixed_tree(rng, int(rng.integers(1, 6)))
        q = random_configuration(robot, rng)
        v, a = rng.normal(size=(2, robot.nv))
        tau = an.rnea(robot, q, v, a)
        M = an.crba(robot, q)
        worst["aba"] = max(worst["aba"], np.abs(an.aba(robot, q, v, tau) - a).max() / (1 + np.abs(a).max()))
        worst["sym"] = max(worst["sym"], np.abs(M - M.T).max())
        assert np.linalg.eigvalsh(M).min() > 0, robot
        g = an.rnea(robot, q, np.zeros(robot.nv), np.zeros(robot.nv))
        k = int(rng.integers(robot.nv))
        e = np.eye(robot.nv)[k]
        col = an.rnea(robot, q, np.zeros(robot.nv), e) - g
        worst["col"] = max(worst["col"], np.abs(col - M[:, k]).max())
        T = an.kinetic_energy(robot, q, v)
        worst["energy"] = max(worst["energy"], abs(T - 0.5 * v @ M @ v) / (1 + T))
        # integrate(q, difference(q, q')) = q': the same link poses (a quaternion and its
        # negative are one rotation)
        q2 = random_configuration(robot, rng)
        back = an.integrate(robot, q, an.difference(robot, q, q2))
        poses = an.forward_kinematics(robot, back) - an.forward_kinematics(robot, q2)
        worst["manifold"] = max(worst["manifold"], np.abs(poses).max())
    assert all(np.isfinite(x) for x in worst.values())
    assert worst["aba"] < 1e-8 and worst["sym"] < 1e-12 and worst["col"] < 1e-10 and worst["energy"] < 1e-12, worst
    assert worst["manifold"] < 1e-10, worst


def test_batches_equal_single_calls():
    rng = np.random.default_rng(3)
    robot = mixed_tree(rng, 6)
    Q = np.array([random_configuration(robot, rng) for _ in range(37)])
    V, A = rng.normal(size=(2, 37, robot.nv))
    for name, args in (("rnea", (Q, V, A)), ("crba", (Q,)), ("bias", (Q, V)), ("gravity", (Q,))):
        f = getattr(an, name)
        batch = f(robot, *args)
        single = np.array([f(robot, *row) for row in zip(*args)])
        assert np.array_equal(batch, single), name
    tau = an.rnea(robot, Q, V, A)
    assert np.array_equal(an.aba(robot, Q, V, tau), np.array([an.aba(robot, *r) for r in zip(Q, V, tau)]))


@needs_pinocchio
@pytest.mark.parametrize("seed", range(40))
def test_random_trees_against_pinocchio(seed):
    from pinocchio_bridge import PinocchioRobot

    rng = np.random.default_rng(100 + seed)
    robot = mixed_tree(rng, int(rng.integers(2, 7)))
    ref = PinocchioRobot(robot)
    for _ in range(3):
        q = random_configuration(robot, rng)
        v, a = rng.normal(size=(2, robot.nv))
        tau = ref.rnea(q, v, a)
        np.testing.assert_allclose(an.rnea(robot, q, v, a), tau, rtol=0, atol=1e-10)
        np.testing.assert_allclose(an.crba(robot, q), ref.crba(q), rtol=0, atol=1e-10)
        np.testing.assert_allclose(an.aba(robot, q, v, tau), a, rtol=0, atol=1e-9)
        np.testing.assert_allclose(an.kinetic_energy(robot, q, v), ref.kinetic_energy(q, v), rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(an.potential_energy(robot, q), ref.potential_energy(q), rtol=1e-12, atol=1e-10)
        np.testing.assert_allclose(an.forward_kinematics(robot, q), ref.forward_kinematics(q), rtol=0, atol=1e-12)
        link = list(robot.links)[-1]
        np.testing.assert_allclose(an.jacobian(robot, q, link), ref.jacobian(q, link), rtol=0, atol=1e-12)
        # the derivatives on the tangent space, against Pinocchio's analytical ones
        pin.computeRNEADerivatives(ref.model, ref.data, ref._p(q), ref._p(v), ref._p(a))
        dq, dv, _ = an.rnea_derivatives(robot, q, v, a)
        np.testing.assert_allclose(dq, ref._mat(ref.data.dtau_dq), rtol=0, atol=1e-9)
        np.testing.assert_allclose(dv, ref._mat(ref.data.dtau_dv), rtol=0, atol=1e-9)


def _hand_built(floating: bool):
    """The same tree in armdyn and in Pinocchio, by hand: a spherical joint, a prismatic
    one, a free joint in the middle of the tree and a revolute branch."""
    rng = np.random.default_rng(11)
    links = [random_link(rng, n) for n in ("base", "a", "b", "c", "d")]
    places = [(random_rotation(rng), rng.uniform(-0.5, 0.5, 3)) for _ in range(4)]
    spec = [("ball", "spherical", "base", "a"), ("slide", "prismatic", "a", "b"), ("free", "floating", "b", "c")]
    spec.append(("turn", "revolute", "base", "d"))
    joints = [
        Joint(n, t, p, c, xyz=x.tolist(), rotation=R.tolist(), axis=(0, 1, 0) if t == "prismatic" else (0, 0, 1))
        for (n, t, p, c), (R, x) in zip(spec, places)
    ]
    robot = Robot("mixed", links, joints, root_joint="free-flyer" if floating else None)
    model = pin.Model()
    model.gravity = pin.Motion(np.array([0, 0, -9.81, 0, 0, 0]))
    ids = {"base": 0}

    def inertia(link: Link):
        return pin.Inertia(
            float(link.mass), np.array(link.com, dtype=float).ravel(), np.array(link.inertia, dtype=float)
        )

    if floating:
        ids["base"] = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root")
        model.appendBodyToJoint(ids["base"], inertia(links[0]), pin.SE3.Identity())
    kinds = {
        "spherical": pin.JointModelSpherical(),
        "prismatic": pin.JointModelPY(),
        "floating": pin.JointModelFreeFlyer(),
    }
    kinds["revolute"] = pin.JointModelRZ()
    for (n, t, p, c), (R, x), link in zip(spec, places, links[1:]):
        ids[c] = model.addJoint(ids[p], kinds[t], pin.SE3(R, x), n)
        model.appendBodyToJoint(ids[c], inertia(link), pin.SE3.Identity())
    return robot, model


@needs_pinocchio
@pytest.mark.parametrize("floating", [False, True], ids=["fixed", "floating"])
def test_hand_built_tree_against_pinocchio(floating):
    robot, model = _hand_built(floating)
    data = model.createData()
    assert (robot.nq, robot.nv) == (model.nq, model.nv)
    rng = np.random.default_rng(5)

    def sym(A):
        return np.triu(A) + np.triu(A, 1).T

    for _ in range(20):
        q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
        v, a = rng.normal(size=(2, model.nv))
        tau = pin.rnea(model, data, q, v, a)
        np.testing.assert_allclose(an.rnea(robot, q, v, a), tau, rtol=0, atol=1e-10)
        np.testing.assert_allclose(an.crba(robot, q), sym(pin.crba(model, data, q)), rtol=0, atol=1e-10)
        np.testing.assert_allclose(an.aba(robot, q, v, tau), a, rtol=0, atol=1e-9)
        np.testing.assert_allclose(an.minverse(robot, q), sym(pin.computeMinverse(model, data, q)), rtol=0, atol=1e-9)
        np.testing.assert_allclose(an.bias(robot, q, v), pin.nonLinearEffects(model, data, q, v), rtol=0, atol=1e-10)
        np.testing.assert_allclose(an.gravity(robot, q), pin.computeGeneralizedGravity(model, data, q), atol=1e-10)
        Ag = pin.computeCentroidalMap(model, data, q)
        np.testing.assert_allclose(ac.centroidal_momentum_matrix(robot, q), Ag, rtol=0, atol=1e-10)
        np.testing.assert_allclose(ac.center_of_mass(robot, q), pin.centerOfMass(model, data, q), atol=1e-12)
        np.testing.assert_allclose(ac.com_jacobian(robot, q), pin.jacobianCenterOfMass(model, data, q), atol=1e-12)
        pin.computeRNEADerivatives(model, data, q, v, a)
        got = an.rnea_derivatives(robot, q, v, a)
        for x, want in zip(got, (data.dtau_dq, data.dtau_dv, sym(data.M))):
            np.testing.assert_allclose(x, want, rtol=0, atol=1e-9)
        pin.computeABADerivatives(model, data, q, v, tau)
        got = an.aba_derivatives(robot, q, v, tau)
        for x, want in zip(got, (data.ddq_dq, data.ddq_dv, sym(data.Minv))):
            np.testing.assert_allclose(x, want, rtol=0, atol=1e-8)
        dg = pin.computeGeneralizedGravityDerivatives(model, data, q)
        np.testing.assert_allclose(an.gravity_derivatives(robot, q), dg, rtol=0, atol=1e-9)
        # the momentum's rate, and A_G's (Pinocchio's dAg adds c' x the linear rows to the
        # angular ones: its moments about a centre of mass standing still)
        pin.computeCentroidalMomentumTimeVariation(model, data, q, v, a)
        np.testing.assert_allclose(ac.centroidal_momentum_rate(robot, q, v, a), data.dhg.vector, atol=1e-10)
        dA = ac.centroidal_momentum_matrix_rate(robot, q, v)
        cdot = ac.com_jacobian(robot, q) @ v
        dA[3:] += np.cross(cdot, ac.centroidal_momentum_matrix(robot, q)[:3].T).T
        np.testing.assert_allclose(
            dA, pin.computeCentroidalMapTimeVariation(model, model.createData(), q, v), atol=1e-10
        )


def _ball_pendulum() -> Robot:
    rod = Link("rod", 2.0, (0.0, 0.0, -0.6), [[0.1, 0, 0], [0, 0.12, 0], [0, 0, 0.02]])
    return Robot("ball", [Link("base"), rod], [Joint("ball", "spherical", "base", "rod")])


def test_ball_pendulum_closed_form():
    """tau = I_O w' + w x I_O w - m c x (R^T g), with I_O the inertia about the pivot,
    written here by hand."""
    robot = _ball_pendulum()
    rng = np.random.default_rng(2)
    m, c = 2.0, np.array([0.0, 0.0, -0.6])
    I_O = np.diag([0.1, 0.12, 0.02]) + m * (c @ c * np.eye(3) - np.outer(c, c))
    for _ in range(50):
        quat = rng.normal(size=4)
        x, y, z, w = quat / np.linalg.norm(quat)
        R = np.array(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
            ]
        )
        om, dom = rng.normal(size=(2, 3))
        want = I_O @ dom + np.cross(om, I_O @ om) - m * np.cross(c, R.T @ np.array([0, 0, -9.81]))
        got = an.rnea(robot, np.array([x, y, z, w]), om, dom)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)


def test_non_unit_quaternion_refused():
    robot = _ball_pendulum()
    with pytest.raises(ValueError, match=r"quaternion of joint 'ball' q\[0:4\].*normalise"):
        an.rnea(robot, np.array([0.0, 0.0, 0.0, 1.1]), np.zeros(3), np.zeros(3))
    with pytest.raises(ValueError, match=r"\(row 1\)"):
        an.crba(robot, np.array([[0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0, 2.0]]))
    with pytest.raises(ValueError, match=r"expected shape \(4,\)"):
        an.rnea(robot, np.zeros(3), np.zeros(3), np.zeros(3))


def test_planar_pair_refused():
    body = Link("body", 1.0, (0.1, 0, 0), [[0.01, 0, 0], [0, 0.01, 0], [0, 0, 0.01]])
    robot = Robot("puck", [Link("table"), body], [Joint("slide", "planar", "table", "body")])
    with pytest.raises(ValueError, match=r"\(cos, sin\) pair of joint 'slide' q\[2:4\]"):
        an.crba(robot, np.array([0.0, 0.0, 1.0, 0.5]))


@needs_pinocchio
@pytest.mark.parametrize("floating, frame", [(False, "local"), (False, "world"), (True, "local")])
def test_external_wrenches_against_pinocchio(floating, frame):
    """rnea and aba with a wrench on every link (link frames, or the world frame about
    its origin) and their derivatives against Pinocchio's with fext (joint frames). A
    floating base: the derivatives, wrenches in the link frames (rnea and aba refuse)."""
    robot, model = _hand_built(floating)
    data = model.createData()
    rng = np.random.default_rng(13)
    links = list(robot.links)
    joint_of = {j.child: j.name for j in robot.joints}
    joint_of[robot.base] = "root"

    def sym(A):
        return np.triu(A) + np.triu(A, 1).T

    for _ in range(5):
        q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
        v, a = rng.normal(size=(2, model.nv))
        W = rng.normal(size=(len(links), 6))
        if not floating:
            W[0] = 0.0  # the base carries none (Pinocchio's universe)
        pin.forwardKinematics(model, data, q)
        fext = [pin.Force.Zero() for _ in range(model.njoints)]
        for k, name in enumerate(links):
            if k == 0 and not floating:
                continue
            jid = model.getJointId(joint_of[name])
            wrench = pin.Force(W[k, :3], W[k, 3:])
            fext[jid] = wrench if frame == "local" else data.oMi[jid].actInv(wrench)
        tau = pin.rnea(model, data, q, v, a, fext)
        if not floating:
            np.testing.assert_allclose(an.rnea(robot, q, v, a, f_ext=W, frame=frame), tau, rtol=0, atol=1e-10)
            np.testing.assert_allclose(an.aba(robot, q, v, tau, f_ext=W, frame=frame), a, rtol=0, atol=1e-9)
        rnea_d = an.rnea_derivatives(robot, q, v, a, f_ext=W, frame=frame)
        aba_d = an.aba_derivatives(robot, q, v, tau, f_ext=W, frame=frame)
        # a batch of two states (the second with twice the wrenches) row by row
        twice = np.stack([W, 2 * W])
        batch = an.rnea_derivatives(
            robot, np.stack([q, q]), np.stack([v, v]), np.stack([a, a]), f_ext=twice, frame=frame
        )
        for x, single in zip(batch, rnea_d):
            np.testing.assert_array_equal(x[0], single)
        second = an.rnea_derivatives(robot, q, v, a, f_ext=2 * W, frame=frame)
        for x, single in zip(batch, second):
            np.testing.assert_array_equal(x[1], single)
        if frame == "world":  # fixed in space: Pinocchio's fext turn with the joints, so differences
            _check_by_differences(robot, q, v, a, tau, W, rnea_d, aba_d)
            continue
        pin.computeRNEADerivatives(model, data, q, v, a, fext)
        for x, want in zip(rnea_d, (data.dtau_dq, data.dtau_dv, sym(data.M))):
            np.testing.assert_allclose(x, want, rtol=0, atol=1e-9)
        pin.computeABADerivatives(model, data, q, v, tau, fext)
        for x, want in zip(aba_d, (data.ddq_dq, data.ddq_dv, sym(data.Minv))):
            np.testing.assert_allclose(x, want, rtol=0, atol=1e-8)


def _check_by_differences(robot, q, v, a, tau, W, rnea_d, aba_d):
    """The derivatives with wrenches fixed in the world against central differences on
    the tangent space (``q ⊕ h e_m``, armdyn's integrate, checked against Pinocchio's)."""
    from armdyn.configuration import integrate

    h = 1e-6

    def rnea(q, v):
        return an.rnea(robot, q, v, a, f_ext=W, frame="world")

    def aba(q, v):
        return an.aba(robot, q, v, tau, f_ext=W, frame="world")

    for f, (d_dq, d_dv, _) in ((rnea, rnea_d), (aba, aba_d)):
        for m, e in enumerate(np.eye(robot.nv)):
            by_q = (f(integrate(robot, q, h * e), v) - f(integrate(robot, q, -h * e), v)) / (2 * h)
            by_v = (f(q, v + h * e) - f(q, v - h * e)) / (2 * h)
            np.testing.assert_allclose(d_dq[:, m], by_q, rtol=0, atol=1e-6 * (1 + np.abs(by_q).max()))
            np.testing.assert_allclose(d_dv[:, m], by_v, rtol=0, atol=1e-6 * (1 + np.abs(by_v).max()))
