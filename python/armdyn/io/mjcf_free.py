"""Free and ball joints of an MJCF model (for :mod:`armdyn.io.mjcf`).

Free bodies (a body of the world body with a ``free`` joint: ``<freejoint/>`` or
``<joint type="free"/>``; MuJoCo allows them there only):

* one free body, and no joint in the world body's other bodies: it is the base of a
  floating robot (``root_joint="free-flyer"``; its frame, the body frame, is the base
  frame, and its pose as written is MuJoCo's ``qpos0``, kept in
  ``robot.meta["base_pose"]``). The other bodies of the world body are fixed to the
  world, not carried by the robot: listed as ignored;
* several free bodies, or free bodies beside bodies with joints (a free object next to a
  fixed arm): the robot's base is the world and each free body hangs from it on a
  ``floating`` joint named after the free joint, placed at the world origin, so that its
  q is MuJoCo's qpos (the quaternion reordered, see :mod:`armdyn.io.mjcf_state`); each
  pose as written (its ``qpos0``) is kept in ``robot.meta["free_poses"]``.

Either way the free joint must be its body's only joint; no ``align`` (MuJoCo would move
the body frame to the centre of mass); no damping, armature, friction loss or stiffness
on it (MuJoCo applies them to the body's six velocities, which armdyn's floating joints
do not model: a ``<joint type="free">`` takes them from its default class, a
``<freejoint/>`` never does). A free joint's ``pos`` is ignored, as MuJoCo ignores it.

A ``ball`` joint is a ``spherical`` joint rotating the body about the joint's ``pos``
(its axes the body's; MuJoCo ignores a ball's ``axis`` and ``ref``): MuJoCo's qpos
quaternion ``w x y z`` is armdyn's ``x y z w`` and its qvel, the angular velocity in the
body frame, is armdyn's v. Its ``damping``, ``armature`` and ``frictionloss`` (MuJoCo
applies them to the three velocities; armdyn's spherical joint has no joint dynamics)
and ``springdamper`` are refused; ``stiffness`` and a ``range`` (a cone limit; limits do
not enter the dynamics) are listed as ignored.

Each problem is a :class:`~armdyn.errors.ModelError` naming the file, line and element.
"""

from __future__ import annotations

import numpy as np

__all__ = ["floating_tree", "free_joint", "base_pose", "ball_joint_dynamics"]


def _has_free_joint(reader, body, cls: str) -> bool:
    """Whether ``body`` (in default class ``cls``) has a free joint of its own (in it or
    in its ``<frame>``s, not in its child bodies)."""
    stack = [(child, reader.childclass(body, cls)) for child in body]
    while stack:
        child, klass = stack.pop()
        if child.tag == "frame":
            stack += [(c, reader.childclass(child, klass)) for c in child]
        elif child.tag == "freejoint":
            return True
        elif child.tag == "joint" and reader.attrs(child, klass).get("type", "hinge") == "free":
            return True
    return False


def floating_tree(reader, root, bodies: list) -> list:
    """The bodies of the world body to read (``(element, parent, R, p, class)`` as the
    reader collects them). Sets ``reader.free_joints``: False when one free body is the
    floating base (then it alone is returned, the others ignored if they hold no joint),
    True when free bodies hang from the world on floating joints (all are returned)."""
    free = [b for b in bodies if _has_free_joint(reader, b[0], b[4])]
    reader.alignfree = any(c.get("alignfree", "false") == "true" for c in root.findall("compiler"))
    others = [b for b in bodies if not any(b is f for f in free)]
    jointed = [b for b in others if any(e.tag in ("joint", "freejoint") for e in b[0].iter())]
    reader.free_joints = len(free) > 1 or bool(free and jointed)
    if not free or reader.free_joints:
        return bodies
    reader.ignored["bodies fixed to the world beside the floating base"] += len(others)
    if not others:
        del reader.ignored["bodies fixed to the world beside the floating base"]
    return free


def free_joint(reader, elem, attrs: dict, at_root: bool, count: int) -> None:
    """Check a free joint ``elem`` (its attributes ``attrs``, defaults applied) of a body
    that is a child of the world body (``at_root``) with ``count`` joints."""
    if not at_root:
        raise reader.error(
            elem,
            "free joint in a body that is not a child of the world body: MuJoCo allows it on a top-level body only",
        )
    if count > 1:
        raise reader.error(elem, "a free joint must be its body's only joint (at most 6 degrees of freedom a body)")
    if reader.floating == "weld":
        return
    align = attrs.get("align", "auto")
    if align == "true" or align == "auto" and getattr(reader, "alignfree", False):
        raise reader.error(
            elem,
            "align (or <compiler alignfree>): MuJoCo would move the body frame to the centre of mass; "
            "armdyn's floating base keeps the body frame: not supported",
        )
    for key in ("damping", "armature", "frictionloss", "stiffness"):
        if np.any(reader.numbers(elem, attrs, key, 3, [0], at_least=1)):
            raise reader.error(
                elem,
                f"{key} on the free joint (MuJoCo applies it to the body's six velocities, armdyn's floating "
                "joints have none): not supported; <freejoint/> takes no defaults",
            )
    if np.any(reader.numbers(elem, attrs, "pos", 3, [0, 0, 0])):
        reader.ignored["free joint pos (MuJoCo ignores it)"] += 1


def base_pose(R: np.ndarray, p: np.ndarray) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """``(position, quaternion w x y z)`` of the pose ``(R, p)``: MuJoCo's ``qpos0`` of a
    free joint (its ``w >= 0``)."""
    trace = float(np.trace(R))
    # Shepperd's method: divide by the largest of 4 w^2, 4 x^2, 4 y^2, 4 z^2
    k = int(np.argmax([trace, R[0, 0], R[1, 1], R[2, 2]]))
    if k == 0:
        w = np.sqrt(1.0 + trace) / 2
        quat = [w, (R[2, 1] - R[1, 2]) / (4 * w), (R[0, 2] - R[2, 0]) / (4 * w), (R[1, 0] - R[0, 1]) / (4 * w)]
    else:
        i, j, m = k - 1, k % 3, (k + 1) % 3
        s = np.sqrt(1.0 + R[i, i] - R[j, j] - R[m, m]) * 2
        quat = [0.0] * 4
        quat[0] = (R[m, j] - R[j, m]) / s
        quat[1 + i] = s / 4
        quat[1 + j] = (R[j, i] + R[i, j]) / s
        quat[1 + m] = (R[m, i] + R[i, m]) / s
    quat = np.array(quat) * (1 if quat[0] >= 0 else -1)
    return tuple(float(x) for x in p), tuple(float(x) for x in quat / np.linalg.norm(quat))


def ball_joint_dynamics(reader, elem, attrs: dict) -> dict:
    """A ball joint's damping, armature and frictionloss (defaults applied), each applied
    by MuJoCo to the joint's three velocities as armdyn applies a joint's to each of its
    coordinates (``damping`` Fv, ``armature`` Ia, ``friction`` Fc); what a hinge refuses
    is refused the same way, a stiffness or a range (a cone) listed as ignored."""
    limits = reader.numbers(elem, attrs, "range", 2)
    if limits is not None and np.any(limits) and attrs.get("limited", "auto") != "false":
        reader.ignored["ball joint range (a cone limit; limits do not enter the dynamics)"] += 1
    rest = {k: v for k, v in attrs.items() if k not in ("range", "limited")}
    return reader.joint_dynamics(elem, rest, hinge=True)
