"""Random robots for property tests: chains and branched trees with mixed revolute,
prismatic and fixed joints, arbitrary placements (random rotations), axes that are
either coordinate axes (either sign) or arbitrary unit vectors, physically valid random
inertias, and sometimes a gravity vector that is not along -z.

Built directly with armdyn.model's Joint/Link/Robot (numbers become SymPy Floats, which
convert back to the same doubles).
"""

from __future__ import annotations

import numpy as np

from armdyn.model import Joint, Link, Robot


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    """Uniformly random rotation matrix (3x3) from a normalised Gaussian quaternion."""
    qv = rng.normal(size=4)
    w, x, y, z = qv / np.linalg.norm(qv)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def random_axis(rng: np.random.Generator) -> np.ndarray:
    """A unit axis: a signed coordinate axis one time in three, else a random direction."""
    if rng.random() < 1 / 3:
        axis = np.zeros(3)
        axis[rng.integers(3)] = rng.choice([-1.0, 1.0])
        return axis
    a = rng.normal(size=3)
    return a / np.linalg.norm(a)


def random_link(rng: np.random.Generator, name: str) -> Link:
    """A physical rigid body: mass in [0.2, 5] kg, com within 0.3 m, and an inertia tensor
    from a random second-moment matrix (principal moments obey the triangle inequality)."""
    mass = rng.uniform(0.2, 5.0)
    com = rng.uniform(-0.3, 0.3, size=3)
    second_moments = mass * rng.uniform(0.001, 0.05, size=3)  # sum m x^2, m y^2, m z^2
    principal = second_moments.sum() - second_moments  # Ixx = m(y^2 + z^2), ...
    R = random_rotation(rng)
    inertia = R @ np.diag(principal) @ R.T
    inertia = 0.5 * (inertia + inertia.T)
    return Link(name, mass, com.tolist(), inertia.tolist())


def random_robot(
    rng: np.random.Generator,
    n_joints: int = 7,
    tree: bool = False,
    kinds: str = "RRPF",
    random_gravity: bool | None = None,
    frame_offsets: bool = False,
) -> Robot:
    """A random fixed-base robot with ``n_joints`` joints.

    tree:  False -> a serial chain; True -> each joint's parent is a random earlier link
           (the base included), so the robot branches.
    kinds: letters R, P, F (and S spherical, L planar, X floating) drawn uniformly for each
           joint's type (at least one joint is made movable).
    random_gravity: gravity of norm 9.81 in a random direction (default: at random).
    frame_offsets: give the first joint and about half the others a child frame off the joint's axis
           (random ``frame_xyz`` and ``frame_rotation``).
    """
    types = {"R": "revolute", "P": "prismatic", "F": "fixed", "S": "spherical", "L": "planar", "X": "floating"}
    links = [random_link(rng, "base")]
    joints = []
    drawn = [types[rng.choice(list(kinds))] for _ in range(n_joints)]
    if all(t == "fixed" for t in drawn):
        drawn[0] = "revolute"
    for k, kind in enumerate(drawn):
        parent = links[rng.integers(len(links))].name if tree else links[-1].name
        child = random_link(rng, f"link{k + 1}")
        rotation = np.eye(3) if rng.random() < 0.2 else random_rotation(rng)
        offset = {}
        if frame_offsets and (k == 0 or rng.random() < 0.6):
            offset = {
                "frame_xyz": rng.uniform(-0.4, 0.4, size=3).tolist(),
                "frame_rotation": random_rotation(rng).tolist(),
            }
        joints.append(
            Joint(
                f"j{k + 1}",
                kind,
                parent,
                child.name,
                xyz=rng.uniform(-0.5, 0.5, size=3).tolist(),
                rotation=rotation.tolist(),
                axis=random_axis(rng).tolist(),
                **offset,
            )
        )
        links.append(child)
    if random_gravity is None:
        random_gravity = rng.random() < 0.5
    g = (0.0, 0.0, -9.81)
    if random_gravity:
        d = rng.normal(size=3)
        g = tuple(9.81 * d / np.linalg.norm(d))
    return Robot(f"random_{'tree' if tree else 'chain'}", links, joints, gravity=g)


def random_state(rng: np.random.Generator, n: int, scale: float = 1.0) -> np.ndarray:
    """A random (n,) vector with entries in [-scale*pi, scale*pi]."""
    return rng.uniform(-np.pi, np.pi, size=n) * scale


def random_case(seed: int, tree: bool, max_joints: int):
    """A random robot of 3..max_joints-1 joints, its Pinocchio twin and two random
    (q, qd, qdd) states: the shared fixture of the reference and numeric tests."""
    from pinocchio_bridge import PinocchioRobot

    rng = np.random.default_rng(seed)
    robot = random_robot(rng, n_joints=int(rng.integers(3, max_joints)), tree=tree)
    states = [tuple(random_state(rng, robot.dof) for _ in range(3)) for _ in range(2)]
    return robot, PinocchioRobot(robot), states
