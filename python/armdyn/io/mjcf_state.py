"""MuJoCo's state arrays and armdyn's, for a robot read from MJCF (or any robot, given
MuJoCo's joint order): ``from_mujoco_state``, ``to_mujoco_state``, ``from_mujoco_force``,
``to_mujoco_force``.

A floating base differs in layout (armdyn keeps Pinocchio's, :mod:`armdyn.numeric`):

=========  ==========================================  ==========================================
           MuJoCo (free joint)                         armdyn (free-flyer)
=========  ==========================================  ==========================================
position   ``qpos[0:3]`` body origin, world            ``q[0:3]`` the same
rotation   ``qpos[3:7]`` quaternion ``w x y z``         ``q[3:7]`` quaternion ``x y z w``
velocity   ``qvel[0:3]`` origin's velocity, WORLD axes  ``v[0:3] = R^T qvel[0:3]``, base axes
           ``qvel[3:6]`` angular velocity, body axes   ``v[3:6]`` the same
accel.     ``qacc = d/dt qvel``                        ``a[0:3] = R^T qacc[0:3] - w x v[0:3]``
                                                       (``d/dt`` of the base-frame ``v[0:3]``)
force      ``qfrc[0:3]`` force, world axes              ``tau[0:3] = R^T qfrc[0:3]``, base axes
           ``qfrc[3:6]`` moment about the origin,      ``tau[3:6]`` the same
           body axes
=========  ==========================================  ==========================================

(``R``: the base's rotation, body axes in world coordinates; ``w = qvel[3:6]``.) Both
pairs are dual (``qfrc . qvel = tau . v``), so ``M_mujoco = T^T M T`` with ``T =
diag(R^T, 1, 1)``. The joints follow: MuJoCo numbers them depth first as written,
armdyn's floating robots as Pinocchio (siblings by name), so they are permuted by name:
``joint_names`` (MuJoCo's order, the free joint left out), by default the model's
``robot.meta["mujoco_joints"]`` (an MJCF read by armdyn), else armdyn's own order.
Fixed-base robots: the permutation alone. Arrays are one state ``(n,)`` or a batch
``(N, n)``; the functions only rearrange and rotate (a quaternion is not normalised).

:func:`urdf_for_mujoco` prepares a URDF for MuJoCo's compiler: its root link on a
``floating`` joint from a ``world`` link (which MuJoCo makes a free joint) and without
meshes, so that ``mujoco.MjModel.from_xml_string`` then ``mujoco.mj_saveLastXML`` write
the floating robot's MJCF.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import numpy as np

from ..configuration import quaternion_conjugate, rotate_vector

__all__ = ["from_mujoco_state", "to_mujoco_state", "from_mujoco_force", "to_mujoco_force", "urdf_for_mujoco"]


def _order(robot, joint_names) -> np.ndarray:
    """For each of MuJoCo's joint coordinates, its index among armdyn's."""
    names = robot.meta.get("mujoco_joints") if joint_names is None else joint_names
    mine = list(robot.coordinate_names)
    if names is None:
        return np.arange(len(mine))
    names = list(names)
    if sorted(names) != sorted(mine):
        raise ValueError(
            f"joint_names {names} are not the coordinates of '{robot.name}' ({mine}): give MuJoCo's joint "
            "names in qpos order, the free joint left out"
        )
    return np.array([mine.index(n) for n in names], dtype=int)


def _arrays(robot, arrays: dict) -> dict:
    out = {}
    for name, (x, width) in arrays.items():
        a = np.asarray(x, dtype=float)
        if a.ndim not in (1, 2) or a.shape[-1] != width:
            raise ValueError(f"{name}: expected shape ({width},) or (N, {width}) for '{robot.name}', got {a.shape}")
        out[name] = a
    return out


def _xyzw(qpos: np.ndarray) -> np.ndarray:
    return qpos[..., [4, 5, 6, 3]]


def _joints(x: np.ndarray, start: int, order: np.ndarray, to_armdyn: bool) -> np.ndarray:
    """The joint columns (from ``start``) reordered."""
    joints = x[..., start:]
    if not to_armdyn:
        return joints[..., order]
    out = np.empty_like(joints)
    out[..., order] = joints
    return out


def from_mujoco_state(robot, qpos, qvel, qacc=None, *, joint_names=None):
    """armdyn's ``(q, v)``, or ``(q, v, a)`` with ``qacc``, from MuJoCo's ``qpos``,
    ``qvel`` (and ``qacc``): see the module doc for the layouts."""
    order = _order(robot, joint_names)
    if not robot.floating:
        got = _arrays(robot, {"qpos": (qpos, robot.nq), "qvel": (qvel, robot.nv)})
        out = [_joints(got[k], 0, order, True) for k in ("qpos", "qvel")]
        if qacc is not None:
            out.append(_joints(_arrays(robot, {"qacc": (qacc, robot.nv)})["qacc"], 0, order, True))
        return tuple(out)
    got = _arrays(robot, {"qpos": (qpos, robot.nq), "qvel": (qvel, robot.nv)})
    qpos, qvel = got["qpos"], got["qvel"]
    quat = _xyzw(qpos)
    back = quaternion_conjugate(quat)
    q = np.concatenate([qpos[..., :3], quat, _joints(qpos, 7, order, True)], axis=-1)
    lin, w = rotate_vector(back, qvel[..., :3]), qvel[..., 3:6]
    v = np.concatenate([lin, w, _joints(qvel, 6, order, True)], axis=-1)
    if qacc is None:
        return q, v
    qacc = _arrays(robot, {"qacc": (qacc, robot.nv)})["qacc"]
    a_lin = rotate_vector(back, qacc[..., :3]) - np.cross(w, lin)
    return q, v, np.concatenate([a_lin, qacc[..., 3:6], _joints(qacc, 6, order, True)], axis=-1)


def to_mujoco_state(robot, q, v, a=None, *, joint_names=None):
    """MuJoCo's ``(qpos, qvel)``, or ``(qpos, qvel, qacc)`` with ``a``, from armdyn's
    ``q``, ``v`` (and ``a``): the inverse of :func:`from_mujoco_state`."""
    order = _order(robot, joint_names)
    if not robot.floating:
        got = _arrays(robot, {"q": (q, robot.nq), "v": (v, robot.nv)})
        out = [_joints(got[k], 0, order, False) for k in ("q", "v")]
        if a is not None:
            out.append(_joints(_arrays(robot, {"a": (a, robot.nv)})["a"], 0, order, False))
        return tuple(out)
    got = _arrays(robot, {"q": (q, robot.nq), "v": (v, robot.nv)})
    q, v = got["q"], got["v"]
    quat = q[..., 3:7]
    qpos = np.concatenate([q[..., :3], quat[..., 3:], quat[..., :3], _joints(q, 7, order, False)], axis=-1)
    lin, w = v[..., :3], v[..., 3:6]
    qvel = np.concatenate([rotate_vector(quat, lin), w, _joints(v, 6, order, False)], axis=-1)
    if a is None:
        return qpos, qvel
    a = _arrays(robot, {"a": (a, robot.nv)})["a"]
    acc_lin = rotate_vector(quat, a[..., :3] + np.cross(w, lin))
    return qpos, qvel, np.concatenate([acc_lin, a[..., 3:6], _joints(a, 6, order, False)], axis=-1)


def from_mujoco_force(robot, qpos, qfrc, *, joint_names=None) -> np.ndarray:
    """armdyn's generalized force ``tau`` (e.g. from ``rnea``) from MuJoCo's ``qfrc``
    (e.g. ``qfrc_inverse``) at the configuration ``qpos``."""
    order = _order(robot, joint_names)
    got = _arrays(robot, {"qpos": (qpos, robot.nq), "qfrc": (qfrc, robot.nv)})
    if not robot.floating:
        return _joints(got["qfrc"], 0, order, True)
    qfrc = got["qfrc"]
    f = rotate_vector(quaternion_conjugate(_xyzw(got["qpos"])), qfrc[..., :3])
    return np.concatenate([f, qfrc[..., 3:6], _joints(qfrc, 6, order, True)], axis=-1)


def to_mujoco_force(robot, q, tau, *, joint_names=None) -> np.ndarray:
    """MuJoCo's ``qfrc`` (e.g. for ``qfrc_applied``) from armdyn's ``tau`` at ``q``: the
    inverse of :func:`from_mujoco_force`."""
    order = _order(robot, joint_names)
    got = _arrays(robot, {"q": (q, robot.nq), "tau": (tau, robot.nv)})
    if not robot.floating:
        return _joints(got["tau"], 0, order, False)
    tau = got["tau"]
    f = rotate_vector(got["q"][..., 3:7], tau[..., :3])
    return np.concatenate([f, tau[..., 3:6], _joints(tau, 6, order, False)], axis=-1)


def urdf_for_mujoco(text: str, floating: bool = True) -> str:
    """The URDF ``text`` for MuJoCo's compiler: ``<visual>`` and ``<collision>`` dropped
    (their meshes are rarely where MuJoCo looks, and they only make contacts) and, with
    ``floating``, the root link on a ``floating`` joint named ``root`` from a new
    ``world`` link (MuJoCo's URDF reader makes it a free joint; without it, it welds the
    root to the world). ModelError for a DTD (see :func:`armdyn.io.urdf.refuse_dtd`) or
    not exactly one root link."""
    from ..errors import ModelError
    from .urdf import refuse_dtd

    refuse_dtd(text.encode("utf-8"))
    text = re.sub(r"<(visual|collision)\b.*?</\1>", "", text, flags=re.S)
    if not floating:
        return text
    root = ET.fromstring(text.encode("utf-8"))
    children = {j.find("child").get("link") for j in root.findall("joint") if j.find("child") is not None}
    roots = [link.get("name") for link in root.findall("link") if link.get("name") not in children]
    if len(roots) != 1:
        raise ModelError(f"expected one root link, found {roots}", "<robot>")
    head = re.search(r"<robot\b[^>]*>", text)
    assert head is not None  # ET parsed a <robot>
    joint = f'<link name="world"/><joint name="root" type="floating"><parent link="world"/><child link="{roots[0]}"/></joint>'
    return text[: head.end()] + joint + text[head.end() :]
