"""integrate, difference, neutral and random_configuration on joints of several
coordinates (spherical, planar, floating), against Pinocchio's on a hand-built model
with the same joints in the same order, and against identities of the Lie groups."""

from __future__ import annotations

import mpmath as mp
import numpy as np
import pytest
from optional import needs_pinocchio, pin

from armdyn.configuration import QUATERNION_TOL, difference, integrate, neutral, random_configuration
from armdyn.model import Joint, Link, Robot

#: (name, type, axis) of the test chain's joints, base to tip
CHAIN = (
    ("shoulder", "revolute", (0.0, 0.0, 1.0)),
    ("ball", "spherical", None),
    ("slider", "prismatic", (0.6, 0.0, 0.8)),
    ("table", "planar", None),
    ("free", "floating", None),
    ("wrist", "revolute", (0.0, 0.6, -0.8)),
    ("ball2", "spherical", None),
)


def chain_robot(floating: bool, kinds=CHAIN) -> Robot:
    """A chain of unit-mass links on the joints ``kinds`` (placements off the origin)."""
    links = [Link(f"l{k}", 1, [0.1, 0, 0], np.diag([0.1, 0.2, 0.3]).tolist()) for k in range(len(kinds) + 1)]
    joints = []
    for k, (name, kind, axis) in enumerate(kinds):
        extra = {"axis": list(axis)} if axis is not None else {}
        joints.append(Joint(name, kind, f"l{k}", f"l{k + 1}", xyz=[0.2, 0.1 * k, 0.0], **extra))
    return Robot("chain", links, joints, root_joint="free-flyer" if floating else None)


def pinocchio_model(robot: Robot):
    """A Pinocchio model with the robot's joints in its order (placements and inertias
    do not matter to the configuration space)."""
    model, parent = pin.Model(), 0
    if robot.floating:
        parent = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root")
    for joint in robot.movable_joints:
        axis = None if joint.type in ("spherical", "planar", "floating") else joint.floats("axis")
        jmodel = {
            "spherical": pin.JointModelSpherical,
            "planar": pin.JointModelPlanar,
            "floating": pin.JointModelFreeFlyer,
            "revolute": lambda: pin.JointModelRevoluteUnaligned(axis),
            "prismatic": lambda: pin.JointModelPrismaticUnaligned(axis),
        }[joint.type]()
        parent = model.addJoint(parent, jmodel, pin.SE3.Identity(), joint.name)
    return model


def states(robot: Robot, count: int, seed: int):
    """``count`` pairs ``(q, v)``: random configurations, velocities of all sizes (turns
    past pi, and tiny ones that take the series branches)."""
    rng = np.random.default_rng(seed)
    for k in range(count):
        q = random_configuration(robot, rng)
        scale = [1e-7, 1e-3, 0.3, 1.5, 4.0][k % 5]
        yield q, scale * rng.standard_normal(robot.nv)


def same_up_to_quaternion_sign(robot: Robot, a: np.ndarray, b: np.ndarray) -> float:
    """Largest difference of configurations, each quaternion compared up to its sign."""
    worst = 0.0
    slots = [(3, 7)] if robot.floating else []
    for _, kind, iq, _ in robot.configuration_layout:
        if kind == "spherical":
            slots.append((iq, iq + 4))
        elif kind == "floating":
            slots.append((iq + 3, iq + 7))
    quat = np.zeros(robot.nq, dtype=bool)
    for lo, hi in slots:
        quat[lo:hi] = True
        worst = max(worst, min(np.abs(a[lo:hi] - b[lo:hi]).max(), np.abs(a[lo:hi] + b[lo:hi]).max()))
    return max(worst, np.abs(a[~quat] - b[~quat]).max())


def test_layout_of_the_chain():
    """The sizes the joints' layouts add up to (written out: 1 + 4 + 1 + 4 + 7 + 1 + 4)."""
    robot = chain_robot(floating=True)
    assert (robot.nq, robot.nv) == (7 + 22, 6 + 18)
    assert [(t, iq, iv) for _, t, iq, iv in robot.configuration_layout][:3] == [
        ("revolute", 7, 6),
        ("spherical", 8, 7),
        ("prismatic", 12, 10),
    ]


@needs_pinocchio
@pytest.mark.parametrize("floating", [False, True])
def test_neutral_matches_pinocchio(floating):
    robot = chain_robot(floating)
    expected = pin.neutral(pinocchio_model(robot))
    assert np.array_equal(neutral(robot), expected)


def planar_log(q0, q1) -> np.ndarray:
    """``log(M0^-1 M1)`` of two planar poses (x, y, cos, sin) in 50-digit arithmetic
    (SE(2)'s closed form, ``V(th)^-1 = [[e, th/2], [-th/2, e]]``, ``e = (th/2) cot(th/2)``)."""
    mp.mp.dps = 50
    x0, y0, c0, s0 = (mp.mpf(float(x)) for x in q0)
    x1, y1, c1, s1 = (mp.mpf(float(x)) for x in q1)
    th = mp.atan2(c0 * s1 - s0 * c1, c0 * c1 + s0 * s1)
    tx, ty = c0 * (x1 - x0) + s0 * (y1 - y0), c0 * (y1 - y0) - s0 * (x1 - x0)
    e = 1 if th == 0 else th / 2 / mp.tan(th / 2)
    return np.array([float(e * tx + th / 2 * ty), float(e * ty - th / 2 * tx), float(th)])


def check_difference(robot: Robot, model, q0, q1) -> int:
    """``difference`` against Pinocchio's to 1e-12. Pinocchio's planar log divides by
    ``1 - cos th``, which loses digits for small turns (3e-12 at th = 4e-3): there the
    planar part is checked against the 50-digit closed form (1e-14) and Pinocchio's
    against its own rounding. Returns how many planar parts were checked that way."""
    mine, theirs = difference(robot, q0, q1), pin.difference(model, q0, q1)
    near = 0
    for _, kind, iq, iv in robot.configuration_layout:
        if kind != "planar":
            continue
        th = mine[iv + 2]
        if 1e-4 <= abs(th) < 0.05:
            near += 1
            exact = planar_log(q0[iq : iq + 4], q1[iq : iq + 4])
            assert np.abs(mine[iv : iv + 3] - exact).max() <= 1e-14
            assert np.abs(theirs[iv : iv + 3] - exact).max() <= 1e-15 * (1 + np.abs(exact).max()) / (th * th)
            theirs[iv : iv + 3] = mine[iv : iv + 3]
    assert np.abs(mine - theirs).max() <= 1e-12, (q0, q1)
    return near


@needs_pinocchio
@pytest.mark.parametrize("floating", [False, True])
def test_integrate_and_difference_match_pinocchio(floating):
    robot = chain_robot(floating)
    model = pinocchio_model(robot)
    count, near = 0, 0
    for q, v in states(robot, 220, seed=1 + floating):
        q1 = integrate(robot, q, v)
        assert np.abs(q1 - pin.integrate(model, q, v)).max() <= 1e-12, (q, v)
        near += check_difference(robot, model, q, q1)  # the small turns too
        near += check_difference(robot, model, q, random_configuration(robot, np.random.default_rng(count)))
        count += 1
    assert count == 220 and near > 10


@pytest.mark.parametrize("floating", [False, True])
def test_integrate_of_difference_comes_back(floating):
    """``integrate(q, difference(q, q')) == q'`` (quaternions up to sign) and
    ``difference(q, integrate(q, v)) == v`` for turns below pi."""
    robot = chain_robot(floating)
    rng = np.random.default_rng(7)
    for q, v in states(robot, 200, seed=3):
        q2 = random_configuration(robot, rng)
        back = integrate(robot, q, difference(robot, q, q2))
        assert same_up_to_quaternion_sign(robot, back, q2) <= 1e-12
        if np.abs(v).max() < 1.0:  # every rotation angle below pi: the log gives v back
            assert np.abs(difference(robot, q, integrate(robot, q, v)) - v).max() <= 1e-12


def test_batches_are_row_by_row():
    robot = chain_robot(floating=True)
    rng = np.random.default_rng(11)
    Q = np.array([random_configuration(robot, rng) for _ in range(6)])
    Q2 = np.array([random_configuration(robot, rng) for _ in range(6)])
    V = rng.standard_normal((6, robot.nv))
    assert np.array_equal(integrate(robot, Q, V), np.array([integrate(robot, q, v) for q, v in zip(Q, V)]))
    assert np.array_equal(difference(robot, Q, Q2), np.array([difference(robot, a, b) for a, b in zip(Q, Q2)]))
    # one state against a batch
    assert np.array_equal(difference(robot, Q[0], Q2), np.array([difference(robot, Q[0], b) for b in Q2]))


def test_spherical_turn_about_a_child_axis():
    """A closed form: a ball joint at the identity turned at w = (0, 0, a) for unit time
    is the turn by a about z, quaternion (0, 0, sin a/2, cos a/2); from a turn by pi/2
    about x, w is in the child frame: integrate by (b, 0, 0) adds b about the same x."""
    robot = chain_robot(False, kinds=(("ball", "spherical", None),))
    a = 0.7
    assert np.allclose(integrate(robot, [0, 0, 0, 1], [0, 0, a]), [0, 0, np.sin(a / 2), np.cos(a / 2)], atol=1e-15)
    h = np.pi / 4
    q1 = integrate(robot, [np.sin(h), 0, 0, np.cos(h)], [0.3, 0, 0])
    assert np.allclose(q1, [np.sin(h + 0.15), 0, 0, np.cos(h + 0.15)], atol=1e-15)


def test_planar_drive_along_an_arc():
    """A closed form: a planar joint at x = 1, heading pi/2, moving at forward speed u
    and turn rate r for unit time runs an arc of radius u/r: it ends at
    (1 - (u/r)(1 - cos r), (u/r) sin r), heading pi/2 + r."""
    robot = chain_robot(False, kinds=(("table", "planar", None),))
    u, r = 0.8, 0.5
    q1 = integrate(robot, [1.0, 0.0, 0.0, 1.0], [u, 0.0, r])
    rho = u / r
    expected = [1 - rho * (1 - np.cos(r)), rho * np.sin(r), np.cos(np.pi / 2 + r), np.sin(np.pi / 2 + r)]
    assert np.abs(q1 - expected).max() <= 1e-15


@pytest.mark.parametrize(
    "slot, bad, message",
    [
        (slice(8, 12), [0, 0, 0, 1.1], r"quaternion \(x, y, z, w\) q\[8:12\] of joint 'ball' \(spherical\)"),
        (slice(15, 17), [1.0, 0.2], r"\(cos th, sin th\) pair q\[15:17\] of joint 'table' \(planar\)"),
        (slice(20, 24), [0, 0, 0, 0.5], r"quaternion \(x, y, z, w\) q\[20:24\] of joint 'free' \(floating\)"),
        (slice(3, 7), [0, 0, 0, 2.0], r"quaternion \(x, y, z, w\) q\[3:7\] of the base"),
    ],
)
def test_off_unit_length_is_refused_naming_joint_and_slice(slot, bad, message):
    robot = chain_robot(floating=True)
    q = neutral(robot)
    q[slot] = bad
    with pytest.raises(ValueError, match=message):
        integrate(robot, q, np.zeros(robot.nv))
    with pytest.raises(ValueError, match=message.replace(" q", " q1", 1)):
        difference(robot, neutral(robot), q)
    batch = np.array([neutral(robot)] * 3)
    batch[1] = q
    with pytest.raises(ValueError, match="in 1 of 3 rows"):
        integrate(robot, batch, np.zeros(robot.nv))


def test_a_quaternion_within_the_tolerance_is_taken():
    robot = chain_robot(False, kinds=(("ball", "spherical", None),))
    q = np.array([0, 0, 0, 1 + QUATERNION_TOL / 2])
    assert np.isfinite(integrate(robot, q, [0.1, 0.2, 0.3])).all()


def test_random_configuration_is_on_the_manifold():
    robot = chain_robot(floating=True)
    rng = np.random.default_rng(5)
    for _ in range(50):
        q = random_configuration(robot, rng)
        assert np.isclose(np.linalg.norm(q[3:7]), 1, atol=1e-14)
        assert np.isclose(np.linalg.norm(q[8:12]), 1, atol=1e-14)
        assert np.isclose(np.hypot(q[15], q[16]), 1, atol=1e-14)
        assert np.isclose(np.linalg.norm(q[20:24]), 1, atol=1e-14)
        assert np.all(np.abs(q[13:15]) <= 1) and np.all(np.abs(q[17:20]) <= 1)
