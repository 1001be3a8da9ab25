"""Moving on a robot's configuration space: ``integrate``, ``difference``, ``neutral``,
``random_configuration`` (Pinocchio's names and results), for a fixed base or a floating
one (re-exported by :mod:`armdyn.numeric`).

A fixed base: q and v are both ``(dof,)`` and the space is flat (``q + v``, ``q1 - q0``).
A floating base (``robot.floating``, Pinocchio's free-flyer layout, see
:mod:`armdyn.numeric`): ``q`` is ``(7 + dof,)``, the base origin in the world frame, the
base orientation as a unit quaternion ``x, y, z, w``, the joints; ``v`` is ``(6 + dof,)``,
the base's linear then angular velocity in the base frame, the joint rates. The base
moves on SE(3) as Pinocchio's ``JointModelFreeFlyer``: ``integrate`` composes the base
pose with the exponential of the base twist, ``M1 = M0 exp(v)`` (a constant twist in
the base frame for unit time, not R3 x SO(3)), and ``difference`` is its inverse,
``log(M0^-1 M1)``. Joint coordinates add.

Joints of several coordinates (spherical, planar, floating: :data:`armdyn.model.joints.MULTI_DOF`)
have their blocks of ``q`` in :attr:`~armdyn.model.Robot.configuration_layout`: ``neutral``
and ``random_configuration`` take them; ``integrate`` and ``difference`` do not yet (a
ModelError names the joint).

Arrays are one state (1-d) or a batch (one state per row). A quaternion whose length
differs from 1 by more than :data:`QUATERNION_TOL` is refused (ValueError); the
quaternions ``integrate`` returns are unit to rounding, with the sign that keeps them on
the side of ``q``'s (as Pinocchio's).
"""

from __future__ import annotations

import numpy as np

from .model import Robot
from .model.joints import MULTI_DOF

#: How far a quaternion's length may be from 1 (the numeric core's tolerance too).
QUATERNION_TOL = 1e-9

# Below this rotation angle (rad) the series of the SE(3) maps are used: their closed
# forms divide 0 by 0 at 0 and lose digits near it.
_SMALL = 1e-4


def _array(robot: Robot, x, width: int, name: str) -> np.ndarray:
    a = np.asarray(x, dtype=float)
    if a.ndim not in (1, 2) or a.shape[-1] != width:
        raise ValueError(f"{name}: expected shape ({width},) or (N, {width}) for robot '{robot.name}', got {a.shape}")
    if not np.isfinite(a).all():
        raise ValueError(f"{name} contains NaN or inf")
    return a


def _quaternions(q: np.ndarray, name: str) -> np.ndarray:
    quat = q[..., 3:7]
    err = np.abs(np.linalg.norm(quat, axis=-1) - 1.0)
    if (err > QUATERNION_TOL).any():
        raise ValueError(
            f"{name}: the base quaternion {name}[3:7] (x, y, z, w) does not have unit length "
            f"(off by {float(np.max(err)):.3g}; tolerance {QUATERNION_TOL:g}): normalise it first"
        )
    return quat


def _quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product of quaternions ``x, y, z, w`` (last axis)."""
    av, aw = a[..., :3], a[..., 3:]
    bv, bw = b[..., :3], b[..., 3:]
    v = aw * bv + bw * av + np.cross(av, bv)
    w = aw * bw - np.sum(av * bv, axis=-1, keepdims=True)
    return np.concatenate([v, w], axis=-1)


def quaternion_conjugate(a: np.ndarray) -> np.ndarray:
    """The conjugate (inverse rotation) of quaternions ``x, y, z, w`` (last axis)."""
    return np.concatenate([-a[..., :3], a[..., 3:]], axis=-1)


def rotate_vector(quat: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``R(quat) x`` (last axis), for unit quaternions ``x, y, z, w``."""
    v, w = quat[..., :3], quat[..., 3:]
    t = 2.0 * np.cross(v, x)
    return x + w * t + np.cross(v, t)


def _se3_coefficients(theta: np.ndarray):
    """``a = (1 - cos t) / t^2`` and ``b = (t - sin t) / t^3``: the left Jacobian of SO(3)
    is ``V = 1 + a [w]x + b [w]x^2`` (series below _SMALL)."""
    small = theta < _SMALL
    t = np.where(small, 1.0, theta)
    t2 = theta * theta
    a = np.where(small, 0.5 - t2 / 24.0 + t2 * t2 / 720.0, (1.0 - np.cos(t)) / (t * t))
    b = np.where(small, 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0, (t - np.sin(t)) / (t * t * t))
    return a, b


def _exp_quaternion(w: np.ndarray) -> np.ndarray:
    """The unit quaternion of the rotation ``exp([w]x)``."""
    theta = np.linalg.norm(w, axis=-1, keepdims=True)
    half = 0.5 * theta
    small = theta < _SMALL
    t = np.where(small, 1.0, theta)
    s = np.where(small, 0.5 - theta * theta / 48.0, np.sin(half) / t)  # sin(t/2) / t
    return np.concatenate([w * s, np.cos(half)], axis=-1)


def _log_quaternion(quat: np.ndarray) -> np.ndarray:
    """``w`` with ``exp([w]x) = R(quat)``, |w| in [0, pi] (the shorter way round)."""
    quat = np.where(quat[..., 3:] < 0, -quat, quat)
    v, c = quat[..., :3], quat[..., 3:]
    s = np.linalg.norm(v, axis=-1, keepdims=True)
    angle = 2.0 * np.arctan2(s, c)
    small = s < 1e-8
    scale = np.where(small, 2.0 / np.where(c == 0, 1.0, c), angle / np.where(small, 1.0, s))
    return v * scale


def integrate(robot: Robot, q, v) -> np.ndarray:
    """``q (+) v``: where the configuration ``q`` goes moving with velocity ``v`` for unit
    time (Pinocchio's ``integrate``). Fixed base: ``q + v``. Floating base: the base pose
    ``M1 = M0 exp(v_base)`` (SE(3), ``v_base`` the twist in the base frame), the joints
    ``q + v``. ``q`` (nq,) or (N, nq), ``v`` (nv,) or (N, nv); returns q's shape."""
    robot.require_one_dof_joints("armdyn.configuration.integrate")
    q = _array(robot, q, robot.nq, "q")
    v = _array(robot, v, robot.nv, "v")
    if not robot.floating:
        return q + v
    quat0 = _quaternions(q, "q")
    lin, w = v[..., :3], v[..., 3:6]
    theta = np.linalg.norm(w, axis=-1, keepdims=True)
    a, b = _se3_coefficients(theta)
    wxl = np.cross(w, lin)
    p = lin + a * wxl + b * np.cross(w, wxl)  # V(w) lin: the translation of exp(v), base frame
    quat = _quat_mul(quat0, _exp_quaternion(w))
    quat = np.where(np.sum(quat * quat0, axis=-1, keepdims=True) < 0, -quat, quat)
    quat = quat / np.linalg.norm(quat, axis=-1, keepdims=True)
    base = np.concatenate([q[..., :3] + rotate_vector(quat0, p), quat], axis=-1)
    return np.concatenate([base, q[..., 7:] + v[..., 6:]], axis=-1)


def difference(robot: Robot, q0, q1) -> np.ndarray:
    """The velocity ``v`` with ``integrate(robot, q0, v) = q1`` (Pinocchio's
    ``difference``). Fixed base: ``q1 - q0``. Floating base: ``log(M0^-1 M1)``, the base
    twist in ``q0``'s base frame (linear, angular; rotation angle at most pi), then the
    joints ``q1 - q0``. ``q0``, ``q1`` (nq,) or (N, nq); returns (nv,) or (N, nv)."""
    robot.require_one_dof_joints("armdyn.configuration.difference")
    q0 = _array(robot, q0, robot.nq, "q0")
    q1 = _array(robot, q1, robot.nq, "q1")
    if not robot.floating:
        return q1 - q0
    quat0, quat1 = _quaternions(q0, "q0"), _quaternions(q1, "q1")
    inv0 = quaternion_conjugate(quat0)
    p = rotate_vector(inv0, q1[..., :3] - q0[..., :3])  # M0^-1 M1's translation
    w = _log_quaternion(_quat_mul(inv0, quat1))
    theta = np.linalg.norm(w, axis=-1, keepdims=True)
    # V(w)^-1 = 1 - [w]x / 2 + c [w]x^2, c = (1 - t sin t / (2 (1 - cos t))) / t^2
    small = theta < _SMALL
    t = np.where(small, 1.0, theta)
    c = np.where(
        small,
        1.0 / 12.0 + theta * theta / 720.0,
        (1.0 - t * np.sin(t) / (2.0 * (1.0 - np.cos(t)))) / (t * t),
    )
    wxp = np.cross(w, p)
    lin = p - 0.5 * wxp + c * np.cross(w, wxp)
    return np.concatenate([lin, w, q1[..., 7:] - q0[..., 7:]], axis=-1)


def neutral(robot: Robot) -> np.ndarray:
    """The neutral configuration (nq,): joints at 0; a floating base at the world origin
    with the identity orientation (quaternion ``0, 0, 0, 1``); a joint of several
    coordinates unmoved (its quaternion ``0, 0, 0, 1``, a planar joint's ``0, 0, 1, 0``)."""
    q = np.zeros(robot.nq)
    if robot.floating:
        q[6] = 1.0
    for _, kind, iq, _ in robot.configuration_layout:
        if kind in MULTI_DOF:  # w = 1 ends each quaternion; a planar joint's cos comes third
            q[iq + (2 if kind == "planar" else MULTI_DOF[kind][0] - 1)] = 1.0
    return q


def _limit(joint, name: str) -> float | None:
    """A joint's ``lower``/``upper`` limit as a float, None if absent or symbolic."""
    value = joint.floats(name)
    if value is None:
        value = getattr(joint, name)
        if value is None or getattr(value, "free_symbols", None):
            return None
    return float(value)


def random_configuration(robot: Robot, rng: np.random.Generator, base_position: float = 1.0) -> np.ndarray:
    """A random configuration (nq,) from ``rng`` (a ``numpy.random.Generator``): each
    joint uniform between its limits where both are given and finite, else in
    [-pi, pi] (revolute) or [-1, 1] (prismatic); a floating base's position uniform in
    [-base_position, base_position]^3 and its orientation uniform on SO(3) (a normalised
    Gaussian quaternion), and so a floating joint's and a spherical joint's; a planar
    joint's x, y as a base's, its angle uniform in [-pi, pi]."""
    joints: list[float] = []
    for j in robot.movable_joints:
        if j.type in MULTI_DOF:
            joints += _random_block(j.type, rng, base_position)
            continue
        lo, hi = _limit(j, "lower"), _limit(j, "upper")
        if lo is not None and hi is not None and np.isfinite(lo) and np.isfinite(hi) and lo <= hi:
            joints.append(rng.uniform(lo, hi))
        else:
            half = np.pi if j.type == "revolute" else 1.0
            joints.append(rng.uniform(-half, half))
    if not robot.floating:
        return np.array(joints, dtype=float)
    quat = rng.standard_normal(4)
    quat /= np.linalg.norm(quat)
    return np.concatenate([rng.uniform(-base_position, base_position, 3), quat, joints])


def _random_block(kind: str, rng: np.random.Generator, base_position: float) -> list[float]:
    """A random configuration of a joint of several coordinates (:func:`random_configuration`)."""
    if kind == "planar":
        x, y = rng.uniform(-base_position, base_position, 2)
        angle = rng.uniform(-np.pi, np.pi)
        return [x, y, np.cos(angle), np.sin(angle)]
    position = list(rng.uniform(-base_position, base_position, 3)) if kind == "floating" else []
    quat = rng.standard_normal(4)
    return position + list(quat / np.linalg.norm(quat))


__all__ = ["QUATERNION_TOL", "integrate", "difference", "neutral", "random_configuration"]
