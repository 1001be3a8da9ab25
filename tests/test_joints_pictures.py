"""The pictures of a robot with a joint of several coordinates (its configuration block of
``q``, Pinocchio's layout): the link frames against a hand computation from the
quaternion, and against the numeric core's forward kinematics; the neutral and random
configurations of such joints."""

from __future__ import annotations

import numpy as np
from test_joints_refused import arm
from test_symbolic_spherical import quaternion_matrix

import armdyn
from armdyn.configuration import neutral, random_configuration
from armdyn.show import animate, draw, frame_poses, show
from armdyn.viewer import view


def rot_y(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def by_hand(q: np.ndarray) -> dict[str, np.ndarray]:
    """The leg's link poses: the hip at (0, 0, 0.8) turned by the quaternion q[:4], the
    knee at (0, 0, -0.5) in the thigh about y by q[4]."""
    R = quaternion_matrix(*q[:4])
    thigh, shin = np.eye(4), np.eye(4)
    thigh[:3, :3], thigh[:3, 3] = R, [0, 0, 0.8]
    shin[:3, :3], shin[:3, 3] = R @ rot_y(q[4]), np.array([0, 0, 0.8]) + R @ [0, 0, -0.5]
    return {"base": np.eye(4), "thigh": thigh, "shin": shin}


def test_frame_poses_by_hand_and_by_the_core():
    robot = arm()
    rng = np.random.default_rng(4)
    for _ in range(3):
        quat = rng.normal(size=4)
        q = np.array([*(quat / np.linalg.norm(quat)), rng.uniform(-3, 3)])
        poses = frame_poses(robot, q)
        expected = by_hand(q)
        core = np.asarray(armdyn.forward_kinematics(robot, q))
        for k, name in enumerate(robot.links):
            assert np.max(np.abs(poses[name] - expected[name])) <= 1e-12
            assert np.max(np.abs(core[k] - expected[name])) <= 1e-12


def test_pictures_of_a_ball_joint(tmp_path):
    robot = arm()
    q = np.array([0.0, np.sin(0.4), 0.0, np.cos(0.4), 0.3])  # a turn of 0.8 rad about y, then the knee
    draw(robot, q, out=str(tmp_path / "leg.png"))
    assert (tmp_path / "leg.png").stat().st_size > 0
    frames = animate(robot, np.stack([neutral(robot), q]), str(tmp_path / "leg.gif"))
    assert frames == 2
    scene = view(robot, q).scene
    at = scene["links"].index("shin")
    shin = np.array(scene["poses"]).reshape(1, len(scene["links"]), 7)[0, at, :3]
    assert np.max(np.abs(shin - by_hand(q)["shin"][:3, 3])) <= 1e-6  # the page rounds to 7 digits
    assert [j["link"] for j in scene["joints"]] == [scene["links"].index("shin")]  # no axis for the ball
    at_rest = view(robot).scene  # default: the neutral configuration
    assert np.allclose(np.array(at_rest["poses"]).reshape(-1, 7)[scene["links"].index("shin"), :3], [0, 0, 0.3])
    table = show(robot)
    hip = next(line for line in table.splitlines() if line.startswith("hip"))
    assert "spherical" in hip and "(0, 0, 1)" not in hip  # no axis shown for a ball joint


def test_a_floating_robot_with_a_ball_joint():
    """With the base at the origin, unturned, the joints place the links as on a fixed base."""
    robot = arm(root_joint="free-flyer")
    q = np.array([0.0, 0.0, np.sin(0.3), np.cos(0.3), -0.7])  # the hip turned 0.6 rad about z, the knee
    expected = by_hand(q)
    poses = frame_poses(robot, q)  # the joints' part of q
    scene = view(robot, np.concatenate([[0, 0, 0, 0, 0, 0, 1], q])).scene
    flat = np.array(scene["poses"]).reshape(len(scene["links"]), 7)
    for k, name in enumerate(scene["links"]):
        assert np.max(np.abs(poses[name] - expected[name])) <= 1e-12
        assert np.max(np.abs(flat[k, :3] - expected[name][:3, 3])) <= 1e-6


def test_a_quaternion_off_unit_length_is_refused():
    import pytest

    with pytest.raises(ValueError, match="'hip'"):
        frame_poses(arm(), [0.0, 0.0, 0.0, 1.1, 0.0])


def test_neutral_and_random_configurations():
    """Neutral: every joint unmoved (the poses of the same leg with a fixed hip and the knee
    at 0); random: unit quaternions and (cos, sin) pairs."""
    for kind, rest in (("spherical", [0, 0, 0, 1]), ("planar", [0, 0, 1, 0]), ("floating", [0, 0, 0, 0, 0, 0, 1])):
        robot = arm(kind)
        assert neutral(robot).tolist() == [*rest, 0.0]
        q = random_configuration(robot, np.random.default_rng(5))
        assert q.shape == (robot.nq,)
        block = q[: len(rest)]
        unit = np.hypot(block[2], block[3]) if kind == "planar" else np.linalg.norm(block[-4:])
        assert abs(unit - 1) <= 1e-12
    poses = np.asarray(armdyn.forward_kinematics(arm(), neutral(arm())))
    fixed = np.asarray(armdyn.forward_kinematics(arm("fixed"), np.zeros(1)))
    assert np.max(np.abs(poses - fixed)) <= 1e-12
