"""``armdyn.jacobian(..., reference_frame=)`` in Pinocchio's three frames, against
Pinocchio's getFrameJacobian (every link frame) and getJointJacobian (joint frames), and
against central finite differences of forward kinematics (no Pinocchio needed)."""

from __future__ import annotations

import numpy as np
import pytest

import armdyn
from armdyn import numeric as num


def _skew_vee(W):
    return np.array([W[2, 1], W[0, 2], W[1, 0]])


@pytest.mark.parametrize("name", ["ur5", "panda", "iiwa14"])
def test_three_frames_against_finite_differences(name):
    robot = armdyn.load(name)
    rng = np.random.default_rng(5)
    q, qd = rng.uniform(-1, 1, (2, robot.dof))
    h = 1e-6
    plus, minus = num.forward_kinematics(robot, q + h * qd), num.forward_kinematics(robot, q - h * qd)
    pose = num.forward_kinematics(robot, q)
    for k, link in enumerate(robot.links):
        if k == 0:
            continue
        Tdot = (plus[k] - minus[k]) / (2 * h)
        R, p = pose[k, :3, :3], pose[k, :3, 3]
        v, w = Tdot[:3, 3], _skew_vee(Tdot[:3, :3] @ R.T)  # p-dot and w from R-dot R^T
        expect = {
            "local_world_aligned": np.r_[v, w],
            "local": np.r_[R.T @ v, R.T @ w],
            "world": np.r_[v - np.cross(w, p), w],
        }
        for frame, twist in expect.items():
            got = num.jacobian(robot, q, link, reference_frame=frame) @ qd
            np.testing.assert_allclose(got, twist, rtol=0, atol=1e-7, err_msg=f"{link} {frame}")
    # a batch gives the rows of single calls
    Q = rng.uniform(-1, 1, (3, robot.dof))
    last = list(robot.links)[-1]
    for frame in ("local", "world"):
        batch = num.jacobian(robot, Q, last, reference_frame=frame)
        np.testing.assert_allclose(batch, [num.jacobian(robot, x, last, reference_frame=frame) for x in Q], atol=1e-15)


@pytest.mark.parametrize("name", ["ur5", "panda", "puma560"])
def test_three_frames_against_pinocchio(name):
    pin = pytest.importorskip("pinocchio")
    import warnings

    from pinocchio_bridge import PinocchioRobot

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = armdyn.load(name).bind()
    P = PinocchioRobot(robot)
    frames = {"local": pin.LOCAL, "world": pin.WORLD, "local_world_aligned": pin.LOCAL_WORLD_ALIGNED}
    rng = np.random.default_rng(9)
    q = rng.uniform(-1, 1, robot.dof)
    qp = P._p(q)
    pin.computeJointJacobians(P.model, P.data, qp)
    pin.updateFramePlacements(P.model, P.data)
    for link in list(robot.links)[1:]:
        fid = P.frames[link]
        for frame, ref in frames.items():
            J = pin.getFrameJacobian(P.model, P.data, fid, ref)
            np.testing.assert_allclose(
                num.jacobian(robot, q, link, reference_frame=frame),
                _columns(P, J),
                rtol=0,
                atol=1e-10,
                err_msg=f"{link} {frame}",
            )
    # where a joint's frame is its child link's frame, getJointJacobian agrees too
    checked = 0
    for joint in robot.movable_joints:
        jid = P.model.getJointId(joint.name)
        if not P.model.frames[P.frames[joint.child]].placement.isIdentity():
            continue
        checked += 1
        for frame, ref in frames.items():
            J = pin.getJointJacobian(P.model, P.data, jid, ref)
            np.testing.assert_allclose(
                num.jacobian(robot, q, joint.child, reference_frame=frame),
                _columns(P, J),
                rtol=0,
                atol=1e-10,
                err_msg=f"{joint.name} {frame}",
            )
    assert checked >= 1


def _columns(P, J):
    """Pinocchio's Jacobian (6, nv) with its columns in armdyn's coordinate order."""
    return P._a(J.T).T


def test_bad_reference_frame():
    with pytest.raises(ValueError, match="reference_frame must be one of"):
        num.jacobian(armdyn.load("ur5"), np.zeros(6), "wrist_3_link", reference_frame="body")
