"""Moving on a robot's configuration space: ``integrate``, ``difference``, ``neutral``,
``random_configuration`` (Pinocchio's names and results), for a fixed base or a floating
one and for joints of one or several coordinates (re-exported by :mod:`armdyn.numeric`).

The space is a product, walked along ``robot.configuration_layout`` (each joint's first
index in q and in v; a floating base first, at q[0:7], v[0:6]):

* revolute and prismatic joints are flat: ``q + v``, ``q1 - q0``;
* a floating base (``robot.floating``, Pinocchio's free-flyer layout, see
  :mod:`armdyn.numeric`: the origin in the world frame, the orientation as a unit
  quaternion ``x, y, z, w``; v the linear then angular velocity in the base frame) and a
  ``floating`` joint (the same in its placement frame) move on SE(3) as Pinocchio's
  ``JointModelFreeFlyer``: ``integrate`` composes the pose with the exponential of the
  twist, ``M1 = M0 exp(v)`` (a constant twist in the moving frame for unit time, not
  R3 x SO(3)), and ``difference`` is its inverse, ``log(M0^-1 M1)``;
* a ``spherical`` joint (quaternion ``x, y, z, w``; v the angular velocity in the child
  frame) moves on SO(3) as ``JointModelSpherical``: ``quat1 = quat0 exp(v)``,
  ``difference`` ``log(quat0^-1 quat1)`` (the rotation angle at most pi);
* a ``planar`` joint (``x, y, cos th, sin th``; v the velocity along the moved x and y
  axes, then the turn rate) moves on SE(2) as ``JointModelPlanar``: ``M1 = M0 exp(v)``
  and ``log(M0^-1 M1)`` in the plane.

Arrays are one state (1-d) or a batch (one state per row). A quaternion, or a planar
joint's ``(cos, sin)`` pair, whose length differs from 1 by more than
:data:`QUATERNION_TOL` is refused (ValueError naming the joint and the slice of q); the
quaternions ``integrate`` returns are unit to rounding (on SE(3) with the sign that keeps
them on the side of ``q``'s, as Pinocchio's).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .model import Robot

#: How far a quaternion's (or a planar (cos, sin) pair's) length may be from 1 (the
#: numeric core's tolerance too).
QUATERNION_TOL = 1e-9

# Below this rotation angle (rad) the series of the SE(3), SO(3) and SE(2) maps are used:
# their closed forms divide 0 by 0 at 0 and lose digits near it.
_SMALL = 1e-4


def _array(robot: Robot, x, width: int, name: str) -> np.ndarray:
    a = np.asarray(x, dtype=float)
    if a.ndim not in (1, 2) or a.shape[-1] != width:
        raise ValueError(f"{name}: expected shape ({width},) or (N, {width}) for robot '{robot.name}', got {a.shape}")
    if not np.isfinite(a).all():
        raise ValueError(f"{name} contains NaN or inf")
    return a


@dataclass(frozen=True)
class _Layout:
    """Where each group of the configuration space sits: index arrays into q and v
    (one row per joint of the group) and, per row, what to call it in a message."""

    flat_q: np.ndarray  # (n,) revolute and prismatic coordinates
    flat_v: np.ndarray
    se3_q: np.ndarray  # (k, 7) floating base and floating joints
    se3_v: np.ndarray  # (k, 6)
    so3_q: np.ndarray  # (k, 4) spherical joints
    so3_v: np.ndarray  # (k, 3)
    se2_q: np.ndarray  # (k, 4) planar joints
    se2_v: np.ndarray  # (k, 3)
    se3_names: tuple[str, ...]
    so3_names: tuple[str, ...]
    se2_names: tuple[str, ...]


def group_layout(robot: Robot) -> _Layout:
    """The robot's configuration space as groups of joints of one kind."""
    return grouped_layout(robot.configuration_layout, robot.floating)


@lru_cache(maxsize=64)
def grouped_layout(configuration_layout: tuple, floating: bool) -> _Layout:
    """:func:`group_layout` of a layout (built once per layout: integrate runs in loops)."""
    groups: dict[str, tuple[list, list, list]] = {k: ([], [], []) for k in ("flat", "se3", "so3", "se2")}
    kinds = {"floating": ("se3", 7, 6), "spherical": ("so3", 4, 3), "planar": ("se2", 4, 3)}
    entries = [("the base", "floating", 0, 0)] if floating else []
    entries += [(f"joint '{name}' ({kind})", kind, iq, iv) for name, kind, iq, iv in configuration_layout]
    for label, kind, iq, iv in entries:
        group, nq, nv = kinds.get(kind, ("flat", 1, 1))
        qs, vs, names = groups[group]
        qs.append(np.arange(iq, iq + nq))
        vs.append(np.arange(iv, iv + nv))
        names.append(label)

    def rows(group: str, nq: int, nv: int):
        qs, vs, names = groups[group]
        shape_q, shape_v = (len(qs), nq), (len(vs), nv)
        return np.array(qs, dtype=int).reshape(shape_q), np.array(vs, dtype=int).reshape(shape_v), tuple(names)

    flat_q, flat_v, _ = rows("flat", 1, 1)
    se3_q, se3_v, se3_names = rows("se3", 7, 6)
    so3_q, so3_v, so3_names = rows("so3", 4, 3)
    se2_q, se2_v, se2_names = rows("se2", 4, 3)
    return _Layout(
        flat_q[:, 0], flat_v[:, 0], se3_q, se3_v, so3_q, so3_v, se2_q, se2_v, se3_names, so3_names, se2_names
    )


def require_unit_length(x: np.ndarray, index: np.ndarray, labels, what: str, name: str) -> None:
    """ValueError naming the first of the slices ``x[..., index[k]]`` (``index`` (k, w),
    one row a slice; ``labels[k]`` what it belongs to) whose length is off 1 by more than
    :data:`QUATERNION_TOL`, with the slice (``name[a:b]``) and, for a batch, how many rows.
    ``what``: the slice's kind and parts, e.g. ``"quaternion (x, y, z, w)"``."""
    if not len(labels):
        return
    err = np.abs(np.linalg.norm(x[..., index], axis=-1) - 1.0)  # (..., k)
    bad = (err > QUATERNION_TOL).reshape(-1, len(labels)).any(axis=0)
    if bad.any():
        k = int(np.argmax(bad))
        rows = ""
        if x.ndim == 2:
            rows = f" in {int(np.count_nonzero(err[:, k] > QUATERNION_TOL))} of {x.shape[0]} rows"
        raise ValueError(
            f"{name}: the {what} {name}[{index[k, 0]}:{index[k, -1] + 1}] of {labels[k]} does not have unit "
            f"length{rows} (off by {float(np.max(err[..., k])):.3g}; tolerance {QUATERNION_TOL:g}): normalise it first"
        )


def check_unit_blocks(layout: _Layout, q: np.ndarray, name: str) -> None:
    """ValueError naming the first joint whose quaternion (or planar (cos, sin) pair) in
    ``q`` is off unit length (:func:`require_unit_length`)."""
    require_unit_length(q, layout.se3_q[:, 3:7], layout.se3_names, "quaternion (x, y, z, w)", name)
    require_unit_length(q, layout.so3_q, layout.so3_names, "quaternion (x, y, z, w)", name)
    require_unit_length(q, layout.se2_q[:, 2:4], layout.se2_names, "(cos th, sin th) pair", name)


def check_configuration(robot: Robot, q, name: str = "q") -> np.ndarray:
    """``q`` as a float array (nq,) or (N, nq), checked: finite, every quaternion and
    planar (cos, sin) pair of unit length (ValueError naming the joint and the slice)."""
    q = _array(robot, q, robot.nq, name)
    if robot.nq != robot.nv:
        check_unit_blocks(group_layout(robot), q, name)
    return q


def quaternion_multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
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
    a = np.where(small, 0.5 - t2 / 24.0 + t2 * t2 / 720.0, 2.0 * np.sin(0.5 * t) ** 2 / (t * t))
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


def _se3_integrate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """SE(3) poses ``q`` (..., 7: position, quaternion x y z w) moved by the twists ``v``
    (..., 6: linear, angular, in the moving frame): ``M0 exp(v)``."""
    quat0 = q[..., 3:7]
    lin, w = v[..., :3], v[..., 3:6]
    theta = np.linalg.norm(w, axis=-1, keepdims=True)
    a, b = _se3_coefficients(theta)
    wxl = np.cross(w, lin)
    p = lin + a * wxl + b * np.cross(w, wxl)  # V(w) lin: the translation of exp(v), moving frame
    quat = quaternion_multiply(quat0, _exp_quaternion(w))
    quat = np.where(np.sum(quat * quat0, axis=-1, keepdims=True) < 0, -quat, quat)
    quat = quat / np.linalg.norm(quat, axis=-1, keepdims=True)
    return np.concatenate([q[..., :3] + rotate_vector(quat0, p), quat], axis=-1)


def _se3_difference(q0: np.ndarray, q1: np.ndarray) -> np.ndarray:
    """The twists (..., 6) ``log(M0^-1 M1)`` between SE(3) poses (..., 7)."""
    inv0 = quaternion_conjugate(q0[..., 3:7])
    p = rotate_vector(inv0, q1[..., :3] - q0[..., :3])  # M0^-1 M1's translation
    w = _log_quaternion(quaternion_multiply(inv0, q1[..., 3:7]))
    theta = np.linalg.norm(w, axis=-1, keepdims=True)
    # V(w)^-1 = 1 - [w]x / 2 + c [w]x^2, c = (1 - t sin t / (2 (1 - cos t))) / t^2,
    # written with t sin t / (2 (1 - cos t)) = (t/2) cot(t/2): no 1 - cos t to lose digits
    small = theta < _SMALL
    t = np.where(small, 1.0, theta)
    c = np.where(small, 1.0 / 12.0 + theta * theta / 720.0, (1.0 - 0.5 * t / np.tan(0.5 * t)) / (t * t))
    wxp = np.cross(w, p)
    return np.concatenate([p - 0.5 * wxp + c * np.cross(w, wxp), w], axis=-1)


def _so3_integrate(quat0: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Unit quaternions (..., 4) turned by the angular velocities ``w`` (..., 3, in the
    moving frame) for unit time: ``quat0 exp(w)``, normalised."""
    quat = quaternion_multiply(quat0, _exp_quaternion(w))
    return quat / np.linalg.norm(quat, axis=-1, keepdims=True)


def _so3_difference(quat0: np.ndarray, quat1: np.ndarray) -> np.ndarray:
    """``log(quat0^-1 quat1)`` (..., 3), the rotation angle at most pi."""
    return _log_quaternion(quaternion_multiply(quaternion_conjugate(quat0), quat1))


def _se2_coefficients(theta: np.ndarray):
    """``sin t / t`` and ``(1 - cos t) / t``: SE(2)'s ``V(t) = [[a, -b], [b, a]]``
    (series below _SMALL)."""
    small = np.abs(theta) < _SMALL
    t = np.where(small, 1.0, theta)
    t2 = theta * theta
    a = np.where(small, 1.0 - t2 / 6.0 + t2 * t2 / 120.0, np.sin(t) / t)
    b = np.where(small, theta * (0.5 - t2 / 24.0 + t2 * t2 / 720.0), 2.0 * np.sin(0.5 * t) ** 2 / t)
    return a, b


def _se2_integrate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Planar poses ``q`` (..., 4: x, y, cos, sin) moved by ``v`` (..., 3: vx, vy along
    the moving axes, turn rate) for unit time: ``M0 exp(v)`` in SE(2)."""
    c0, s0 = q[..., 2:3], q[..., 3:4]
    vx, vy, th = v[..., 0:1], v[..., 1:2], v[..., 2:3]
    a, b = _se2_coefficients(th)
    tx, ty = a * vx - b * vy, b * vx + a * vy  # V(th) (vx, vy), moving frame
    c, s = np.cos(th), np.sin(th)
    return np.concatenate(
        [q[..., 0:1] + c0 * tx - s0 * ty, q[..., 1:2] + s0 * tx + c0 * ty, c0 * c - s0 * s, s0 * c + c0 * s],
        axis=-1,
    )


def _se2_difference(q0: np.ndarray, q1: np.ndarray) -> np.ndarray:
    """``log(M0^-1 M1)`` (..., 3) between planar poses (..., 4); the turn in (-pi, pi]."""
    c0, s0, c1, s1 = q0[..., 2:3], q0[..., 3:4], q1[..., 2:3], q1[..., 3:4]
    th = np.arctan2(c0 * s1 - s0 * c1, c0 * c1 + s0 * s1)
    dx, dy = q1[..., 0:1] - q0[..., 0:1], q1[..., 1:2] - q0[..., 1:2]
    tx, ty = c0 * dx + s0 * dy, c0 * dy - s0 * dx  # R0^T (p1 - p0)
    # V(th)^-1 = [[e, th / 2], [-th / 2, e]], e = (th / 2) sin th / (1 - cos th) = (th / 2) cot(th / 2)
    small = np.abs(th) < _SMALL
    t = np.where(small, 1.0, th)
    e = np.where(small, 1.0 - th * th / 12.0 - th**4 / 720.0, 0.5 * t / np.tan(0.5 * t))
    return np.concatenate([e * tx + 0.5 * th * ty, e * ty - 0.5 * th * tx, th], axis=-1)


def _batch(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``a`` and ``b`` with the same number of rows (one state against a batch)."""
    rows = np.broadcast_shapes(a.shape[:-1], b.shape[:-1])
    return np.broadcast_to(a, rows + a.shape[-1:]), np.broadcast_to(b, rows + b.shape[-1:])


def integrate(robot: Robot, q, v) -> np.ndarray:
    """``q (+) v``: where the configuration ``q`` goes moving with velocity ``v`` for unit
    time (Pinocchio's ``integrate``): revolute and prismatic joints ``q + v``; a floating
    base or joint ``M1 = M0 exp(v)`` on SE(3) (``v`` its twist in its own frame); a
    spherical joint ``quat0 exp(w)``; a planar joint ``M0 exp(v)`` on SE(2) (see the
    module doc). ``q`` (nq,) or (N, nq), ``v`` (nv,) or (N, nv); returns (nq,) or (N, nq)."""
    q = _array(robot, q, robot.nq, "q")
    v = _array(robot, v, robot.nv, "v")
    if robot.nq == robot.nv:  # revolute and prismatic joints only
        return q + v
    layout = group_layout(robot)
    check_unit_blocks(layout, q, "q")
    q, v = _batch(q, v)
    out = np.array(q)
    out[..., layout.flat_q] = q[..., layout.flat_q] + v[..., layout.flat_v]
    for step, iq, iv in (
        (_se3_integrate, layout.se3_q, layout.se3_v),
        (_so3_integrate, layout.so3_q, layout.so3_v),
        (_se2_integrate, layout.se2_q, layout.se2_v),
    ):
        if len(iq):
            out[..., iq] = step(q[..., iq], v[..., iv])
    return out


def difference(robot: Robot, q0, q1) -> np.ndarray:
    """The velocity ``v`` with ``integrate(robot, q0, v) = q1`` (Pinocchio's
    ``difference``): revolute and prismatic joints ``q1 - q0``; a floating base or joint
    ``log(M0^-1 M1)``, its twist in ``q0``'s frame (linear, angular; rotation angle at most
    pi); a spherical joint ``log(quat0^-1 quat1)``; a planar joint ``log(M0^-1 M1)`` on
    SE(2). ``q0``, ``q1`` (nq,) or (N, nq); returns (nv,) or (N, nv)."""
    q0 = _array(robot, q0, robot.nq, "q0")
    q1 = _array(robot, q1, robot.nq, "q1")
    if robot.nq == robot.nv:
        return q1 - q0
    layout = group_layout(robot)
    check_unit_blocks(layout, q0, "q0")
    check_unit_blocks(layout, q1, "q1")
    q0, q1 = _batch(q0, q1)
    out = np.empty(q0.shape[:-1] + (robot.nv,))
    out[..., layout.flat_v] = q1[..., layout.flat_q] - q0[..., layout.flat_q]
    for step, iq, iv in (
        (_se3_difference, layout.se3_q, layout.se3_v),
        (_so3_difference, layout.so3_q, layout.so3_v),
        (_se2_difference, layout.se2_q, layout.se2_v),
    ):
        if len(iq):
            out[..., iv] = step(q0[..., iq], q1[..., iq])
    return out


def neutral(robot: Robot) -> np.ndarray:
    """The neutral configuration (nq,): revolute and prismatic joints at 0; a floating
    base or joint at its placement's origin with the identity orientation (quaternion
    ``0, 0, 0, 1``); a spherical joint at the identity (``0, 0, 0, 1``); a planar joint
    at ``0, 0, 1, 0`` (x, y, cos 0, sin 0)."""
    layout = group_layout(robot)
    q = np.zeros(robot.nq)
    q[layout.se3_q[:, 6]] = 1.0
    q[layout.so3_q[:, 3]] = 1.0
    q[layout.se2_q[:, 2]] = 1.0
    return q


def _limit(joint, name: str) -> float | None:
    """A joint's ``lower``/``upper`` limit as a float, None if absent or symbolic."""
    value = joint.floats(name)
    if value is None:
        value = getattr(joint, name)
        if value is None or getattr(value, "free_symbols", None):
            return None
    return float(value)


def _unit_quaternion(rng: np.random.Generator) -> np.ndarray:
    """A quaternion uniform on SO(3) (a normalised Gaussian)."""
    quat = rng.standard_normal(4)
    return quat / np.linalg.norm(quat)


def random_configuration(robot: Robot, rng: np.random.Generator, base_position: float = 1.0) -> np.ndarray:
    """A random configuration (nq,) from ``rng`` (a ``numpy.random.Generator``): a
    revolute or prismatic joint uniform between its limits where both are given and
    finite, else in [-pi, pi] (revolute) or [-1, 1] (prismatic); orientations (a floating
    base's or joint's, a spherical joint's) uniform on SO(3) (a normalised Gaussian
    quaternion); a floating base's or joint's position uniform in
    [-base_position, base_position]^3; a planar joint's x, y uniform in
    [-base_position, base_position] and its turn uniform in [-pi, pi]."""
    q = np.zeros(robot.nq)
    by_name = {j.name: j for j in robot.movable_joints}
    for name, kind, iq, _ in robot.configuration_layout:
        if kind == "spherical":
            q[iq : iq + 4] = _unit_quaternion(rng)
        elif kind == "planar":
            th = rng.uniform(-np.pi, np.pi)
            q[iq : iq + 4] = [*rng.uniform(-base_position, base_position, 2), np.cos(th), np.sin(th)]
        elif kind == "floating":
            quat = _unit_quaternion(rng)
            q[iq : iq + 7] = np.concatenate([rng.uniform(-base_position, base_position, 3), quat])
        else:
            j = by_name[name]
            lo, hi = _limit(j, "lower"), _limit(j, "upper")
            if lo is not None and hi is not None and np.isfinite(lo) and np.isfinite(hi) and lo <= hi:
                q[iq] = rng.uniform(lo, hi)
            else:
                half = np.pi if kind == "revolute" else 1.0
                q[iq] = rng.uniform(-half, half)
    if robot.floating:  # drawn after the joints (as before joints of several coordinates)
        quat = _unit_quaternion(rng)
        q[:7] = np.concatenate([rng.uniform(-base_position, base_position, 3), quat])
    return q


__all__ = ["QUATERNION_TOL", "integrate", "difference", "neutral", "random_configuration", "check_configuration"]
