"""Frames and mass properties as MuJoCo's compiler computes them, in floats (for
:mod:`armdyn.io.mjcf`).

Orientations (MJCF "frame orientations"): ``quat`` (w x y z, normalised), ``axisangle``
(axis normalised, angle in the compiler's unit), ``euler`` (the compiler's ``eulerseq``:
a lower-case letter turns about the moving axis, an upper-case one about the fixed axis),
``xyaxes`` (x normalised, y made orthogonal to it, z = x × y) and ``zaxis`` (the
shortest turn taking z onto the vector). Geom inertias of the primitive shapes, uniform
density, about the geom's centre in the geom's axes.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "quat_matrix",
    "axis_angle_quat",
    "euler_quat",
    "xyaxes_matrix",
    "zaxis_quat",
    "GEOM_SIZES",
    "geom_volume_inertia",
    "combine",
]


def quat_matrix(q) -> np.ndarray:
    """Rotation matrix of the quaternion ``(w, x, y, z)`` (normalised here; not zero)."""
    w, x, y, z = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def _mul(a, b) -> np.ndarray:
    """Quaternion product ``a b``."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return np.array(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ]
    )


def axis_angle_quat(axis, angle: float) -> np.ndarray:
    """Quaternion of a turn by ``angle`` (rad) about ``axis`` (normalised here; not zero)."""
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    return np.concatenate([[math.cos(angle / 2)], math.sin(angle / 2) * axis])


def euler_quat(angles, seq: str) -> np.ndarray:
    """Quaternion of three turns (rad) about the axes ``seq`` names, in order: lower-case
    about the moving (body) axis (multiplied on the right), upper-case about the fixed
    axis (on the left)."""
    quat = np.array([1.0, 0.0, 0.0, 0.0])
    for angle, letter in zip(angles, seq):
        turn = axis_angle_quat(np.eye(3)["xyz".index(letter.lower())], angle)
        quat = _mul(quat, turn) if letter.islower() else _mul(turn, quat)
    return quat


def xyaxes_matrix(x, y) -> np.ndarray | None:
    """Rotation whose columns are ``x`` (normalised), ``y`` made orthogonal to x and
    normalised, and ``x × y``; None if x is zero or y is parallel to x."""
    x = np.asarray(x, dtype=float)
    nx = np.linalg.norm(x)
    if nx < 1e-12:
        return None
    x = x / nx
    y = np.asarray(y, dtype=float)
    y = y - x * (x @ y)
    ny = np.linalg.norm(y)
    if ny < 1e-12:
        return None
    y = y / ny
    return np.column_stack([x, y, np.cross(x, y)])


def zaxis_quat(z) -> np.ndarray:
    """Quaternion of the shortest turn taking (0, 0, 1) onto ``z`` (normalised here; not
    zero); a turn by pi about x when z points down."""
    z = np.asarray(z, dtype=float) / np.linalg.norm(z)
    axis = np.cross([0.0, 0.0, 1.0], z)
    s = np.linalg.norm(axis)
    axis = np.array([1.0, 0.0, 0.0]) if s < 1e-10 else axis / s
    return axis_angle_quat(axis, math.atan2(s, z[2]))


#: how many ``size`` numbers each primitive geom reads
GEOM_SIZES = {"sphere": 1, "capsule": 2, "cylinder": 2, "box": 3, "ellipsoid": 3}


def geom_volume_inertia(kind: str, size) -> tuple[float, np.ndarray]:
    """``(volume, inertia per unit density)`` of a primitive geom about its centre, in its
    own axes (the long axis is z). ``size``: radius; radius, half-length; or half-extents
    (``GEOM_SIZES``)."""
    if kind == "sphere":
        (r,) = size[:1]
        v = 4 / 3 * math.pi * r**3
        return v, np.diag([2 / 5 * v * r * r] * 3)
    if kind == "ellipsoid":
        a, b, c = size[:3]
        v = 4 / 3 * math.pi * a * b * c
        return v, np.diag([v * (b * b + c * c) / 5, v * (a * a + c * c) / 5, v * (a * a + b * b) / 5])
    if kind == "box":
        a, b, c = size[:3]
        v = 8 * a * b * c
        return v, np.diag([v * (b * b + c * c) / 3, v * (a * a + c * c) / 3, v * (a * a + b * b) / 3])
    r, h = size[:2]
    cylinder = math.pi * r * r * 2 * h
    if kind == "cylinder":
        across = cylinder * (r * r / 4 + h * h / 3)
        return cylinder, np.diag([across, across, cylinder * r * r / 2])
    # capsule: a cylinder of length 2h and two hemispheres (each with its centre of mass
    # 3r/8 from its flat face), by the parallel-axis theorem about the capsule's centre
    sphere = 4 / 3 * math.pi * r**3
    across = cylinder * (r * r / 4 + h * h / 3) + sphere * (2 * r * r / 5 + h * h + 3 * h * r / 4)
    return cylinder + sphere, np.diag([across, across, (cylinder / 2 + 2 * sphere / 5) * r * r])


def combine(parts) -> tuple[float, np.ndarray, np.ndarray]:
    """``(mass, com, inertia about com)`` of rigid parts ``(mass, com, inertia about
    its own com)`` given in one frame (parallel-axis theorem)."""
    parts = [p for p in parts if p[0] > 0]
    mass = sum(p[0] for p in parts)
    if mass == 0:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    com = sum(p[0] * np.asarray(p[1]) for p in parts) / mass
    inertia = np.zeros((3, 3))
    for m, c, tensor in parts:
        d = np.asarray(c) - com
        inertia += tensor + m * ((d @ d) * np.eye(3) - np.outer(d, d))
    return mass, com, inertia
