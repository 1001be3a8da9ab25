"""Valid URDFs with many joints, for the load benchmark (benchmarks/bench_load.py) and
the 10^4-joint correctness test (tests/test_big_models.py).

``big_urdf(n, tree, seed)`` returns the URDF text and the same model as plain NumPy
arrays (:class:`Spec`), so a test can compute what the model should do without going
through armdyn's reader.

* chain (``tree=False``): joint k's parent is link k-1;
* tree (``tree=True``): joint k's parent is a random earlier link (the base included).

Every joint has a random origin (xyz and a random rpy), a random unit axis (written to
full precision, so the reader keeps it as given), types revolute/continuous/prismatic/
fixed drawn at random; every link has a mass, a centre of mass and a random physical
inertia given in a rotated inertial frame. Joints are written in a shuffled order, so
the reader must sort them into a tree order.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def rpy_matrix(r: float, p: float, y: float) -> np.ndarray:
    """URDF rpy: Rz(y) Ry(p) Rx(r), here from elementary rotations (not armdyn's code)."""

    def rx(a):
        c, s = np.cos(a), np.sin(a)
        return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])

    def ry(a):
        c, s = np.cos(a), np.sin(a)
        return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])

    def rz(a):
        c, s = np.cos(a), np.sin(a)
        return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])

    return rz(y) @ ry(p) @ rx(r)


@dataclass
class Spec:
    """The model as arrays, body k = child of joint k (k = 0..n-1), base = -1.

    parent (n,): parent body of joint k (-1: the base); kind (n,): 'R', 'P' or 'F';
    xyz (n, 3), R (n, 3, 3): joint placement in the parent frame; axis (n, 3);
    mass (n,), com (n, 3) in the link frame, inertia (n, 3, 3) about the com, link axes.
    The base link is massless. Gravity (0, 0, -9.81).
    """

    parent: np.ndarray
    kind: list
    xyz: np.ndarray
    R: np.ndarray
    axis: np.ndarray
    mass: np.ndarray
    com: np.ndarray
    inertia: np.ndarray


def _fmt(x: float) -> str:
    return repr(float(x))  # shortest text that reads back to the same double


def big_urdf(n: int, tree: bool = False, seed: int = 0) -> tuple[str, Spec]:
    rng = np.random.default_rng(seed)
    parent = np.array([k - 1 if not tree else int(rng.integers(-1, k)) for k in range(n)])
    kind = list(rng.choice(["R", "R", "R", "P", "F"], size=n))
    continuous = rng.random(n) < 0.3
    xyz = rng.uniform(-0.05, 0.05, (n, 3))
    rpy = rng.uniform(-np.pi, np.pi, (n, 3))
    R = np.array([rpy_matrix(*a) for a in rpy])
    axis = rng.normal(size=(n, 3))
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    mass = rng.uniform(0.1, 2.0, n)
    com = rng.uniform(-0.03, 0.03, (n, 3))
    principal = rng.uniform(0.5, 1.0, (n, 3)) * 1e-3  # any two exceed the third
    inertial_rpy = rng.uniform(-np.pi, np.pi, (n, 3))
    inertia = np.empty((n, 3, 3))
    links = ['<link name="base"/>']
    for k in range(n):
        Ri = rpy_matrix(*inertial_rpy[k])
        inertia[k] = Ri @ np.diag(principal[k]) @ Ri.T  # given in the inertial frame: diagonal
        links.append(
            f'<link name="l{k}"><inertial><origin xyz="{" ".join(map(_fmt, com[k]))}" '
            f'rpy="{" ".join(map(_fmt, inertial_rpy[k]))}"/><mass value="{_fmt(mass[k])}"/>'
            f'<inertia ixx="{_fmt(principal[k, 0])}" ixy="0" ixz="0" iyy="{_fmt(principal[k, 1])}" iyz="0" '
            f'izz="{_fmt(principal[k, 2])}"/></inertial></link>'
        )
    joints = []
    for k in range(n):
        urdf_type = {"R": "continuous" if continuous[k] else "revolute", "P": "prismatic", "F": "fixed"}[kind[k]]
        limit = (
            '<limit lower="-3" upper="3" effort="10" velocity="2"/>' if urdf_type in ("revolute", "prismatic") else ""
        )
        joints.append(
            f'<joint name="j{k}" type="{urdf_type}"><parent link="{"base" if parent[k] < 0 else f"l{parent[k]}"}"/>'
            f'<child link="l{k}"/><origin xyz="{" ".join(map(_fmt, xyz[k]))}" rpy="{" ".join(map(_fmt, rpy[k]))}"/>'
            f'<axis xyz="{" ".join(map(_fmt, axis[k]))}"/>{limit}</joint>'
        )
    order = rng.permutation(n)
    text = (
        '<?xml version="1.0"?>\n<robot name="big">\n'
        + "\n".join(links)
        + "\n"
        + "\n".join(joints[k] for k in order)
        + "\n</robot>\n"
    )
    return text, Spec(parent, kind, xyz, R, axis, mass, com, inertia)
