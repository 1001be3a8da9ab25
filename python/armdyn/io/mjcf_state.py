"""MuJoCo's state arrays and armdyn's, for a robot read from MJCF (or any robot, given
MuJoCo's joint order): ``from_mujoco_state``, ``to_mujoco_state``, ``from_mujoco_force``,
``to_mujoco_force``.

A floating base, a floating joint (a free body) and a spherical joint (a ball) differ in
layout (armdyn keeps Pinocchio's, :mod:`armdyn.numeric`); for a free joint (the base at
``qpos[0:7]``, or a floating joint at its own place; its placement the world frame, as
the MJCF reader makes it):

=========  ==========================================  ==========================================
           MuJoCo (free joint)                         armdyn (free-flyer, floating joint)
=========  ==========================================  ==========================================
position   ``qpos[0:3]`` body origin, world            ``q[0:3]`` the same
rotation   ``qpos[3:7]`` quaternion ``w x y z``         ``q[3:7]`` quaternion ``x y z w``
velocity   ``qvel[0:3]`` origin's velocity, WORLD axes  ``v[0:3] = R^T qvel[0:3]``, body axes
           ``qvel[3:6]`` angular velocity, body axes   ``v[3:6]`` the same
accel.     ``qacc = d/dt qvel``                        ``a[0:3] = R^T qacc[0:3] - w x v[0:3]``
                                                       (``d/dt`` of the body-frame ``v[0:3]``)
force      ``qfrc[0:3]`` force, world axes              ``tau[0:3] = R^T qfrc[0:3]``, body axes
           ``qfrc[3:6]`` moment about the origin,      ``tau[3:6]`` the same
           body axes
=========  ==========================================  ==========================================

(``R``: the body's rotation, body axes in world coordinates; ``w = qvel[3:6]``.) Both
pairs are dual (``qfrc . qvel = tau . v``), so ``M_mujoco = T^T M T`` with ``T`` the
block ``R^T`` on each free joint's linear velocity, 1 elsewhere. A ball joint's
quaternion is ``w x y z`` in MuJoCo, ``x y z w`` in armdyn; its velocity, acceleration
and torque (the angular velocity and the moment, in the body frame) are the same.

The joints are matched by name: MuJoCo numbers them depth first as written, armdyn's
floating robots as Pinocchio (siblings by name). ``joint_names`` (MuJoCo's joint names
in qpos order, the floating base's free joint left out) is by default the model's
``robot.meta["mujoco_joints"]`` (an MJCF read by armdyn), else armdyn's own order.
Arrays are one state ``(n,)`` or a batch ``(N, n)``. Every quaternion must have unit
length (to :data:`armdyn.configuration.QUATERNION_TOL`; ValueError naming the joint and
the slice otherwise): a rotation by another one would turn the velocities wrongly.

:func:`urdf_for_mujoco` prepares a URDF for MuJoCo's compiler: its root link on a
``floating`` joint from a ``world`` link (which MuJoCo makes a free joint) and without
meshes, so that ``mujoco.MjModel.from_xml_string`` then ``mujoco.mj_saveLastXML`` write
the floating robot's MJCF.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np

from ..configuration import check_configuration, quaternion_conjugate, require_unit_length, rotate_vector
from ..model.joints import MULTI_DOF

__all__ = ["from_mujoco_state", "to_mujoco_state", "from_mujoco_force", "to_mujoco_force", "urdf_for_mujoco"]

_WXYZ = np.array([3, 0, 1, 2])  # armdyn's x y z w -> MuJoCo's w x y z
_XYZW = np.array([1, 2, 3, 0])  # MuJoCo's w x y z -> armdyn's x y z w


@dataclass(frozen=True)
class _Map:
    """Where each joint sits in MuJoCo's arrays (``m``) and in armdyn's (``a``)."""

    flat: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]  # 1-dof: MuJoCo q, v; armdyn q, v
    balls: tuple[tuple[int, int, int, int], ...]  # (MuJoCo qpos, qvel, armdyn q, v) first indices
    frees: tuple[tuple[int, int, int, int], ...]
    labels: tuple[str, ...]  # the free joints' then the balls' names, for messages


def _map(robot, joint_names) -> _Map:
    """The robot's joints in MuJoCo's arrays and armdyn's."""
    layout = {name: (kind, iq, iv) for name, kind, iq, iv in robot.configuration_layout}
    mine = list(layout)
    names = robot.meta.get("mujoco_joints") if joint_names is None else joint_names
    names = mine if names is None else list(names)
    if sorted(names) != sorted(mine):
        raise ValueError(
            f"joint_names {names} are not the joints of '{robot.name}' ({mine}): give MuJoCo's joint "
            "names in qpos order, the floating base's free joint left out"
        )
    flat: list[list[int]] = [[], [], [], []]
    balls, frees, free_labels, ball_labels = [], [], [], []
    mq, mv = (7, 6) if robot.floating else (0, 0)
    if robot.floating:
        frees.append((0, 0, 0, 0))
        free_labels.append("the base")
    for name in names:
        kind, iq, iv = layout[name]
        if kind == "spherical":
            balls.append((mq, mv, iq, iv))
            ball_labels.append(f"joint '{name}' (ball)")
        elif kind == "floating":
            frees.append((mq, mv, iq, iv))
            free_labels.append(f"joint '{name}' (free)")
        elif kind in MULTI_DOF:  # a planar joint: MuJoCo has none
            raise ValueError(f"joint '{name}' of '{robot.name}' is {kind}: MuJoCo has no such joint")
        else:
            for column, index in zip(flat, (mq, mv, iq, iv)):
                column.append(index)
        nq, nv = MULTI_DOF[kind][:2] if kind in MULTI_DOF else (1, 1)
        mq, mv = mq + nq, mv + nv
    return _Map(
        tuple(np.array(c, dtype=int) for c in flat), tuple(balls), tuple(frees), tuple(free_labels + ball_labels)
    )


def _arrays(robot, arrays: dict) -> dict:
    out = {}
    for name, (x, width) in arrays.items():
        a = np.asarray(x, dtype=float)
        if a.ndim not in (1, 2) or a.shape[-1] != width:
            raise ValueError(f"{name}: expected shape ({width},) or (N, {width}) for '{robot.name}', got {a.shape}")
        out[name] = a
    return out


def _check_qpos(m: _Map, qpos: np.ndarray) -> None:
    """ValueError for a quaternion of ``qpos`` (MuJoCo's layout) off unit length."""
    index = [np.arange(i + 3, i + 7) for i, _, _, _ in m.frees] + [np.arange(i, i + 4) for i, _, _, _ in m.balls]
    require_unit_length(qpos, np.array(index, dtype=int).reshape(-1, 4), m.labels, "quaternion (w, x, y, z)", "qpos")


def from_mujoco_state(robot, qpos, qvel, qacc=None, *, joint_names=None):
    """armdyn's ``(q, v)``, or ``(q, v, a)`` with ``qacc``, from MuJoCo's ``qpos``,
    ``qvel`` (and ``qacc``): see the module doc for the layouts."""
    m = _map(robot, joint_names)
    got = _arrays(robot, {"qpos": (qpos, robot.nq), "qvel": (qvel, robot.nv)})
    if qacc is not None:
        got.update(_arrays(robot, {"qacc": (qacc, robot.nv)}))
    _check_qpos(m, got["qpos"])
    qpos, qvel, qacc = got["qpos"], got["qvel"], got.get("qacc")
    q, v = np.empty_like(qpos), np.empty_like(qvel)
    mq, mv, aq, av = m.flat
    q[..., aq], v[..., av] = qpos[..., mq], qvel[..., mv]
    a = None
    if qacc is not None:
        a = np.empty_like(qacc)
        a[..., av] = qacc[..., mv]
    for mq, mv, iq, iv in m.balls:
        q[..., iq : iq + 4] = qpos[..., mq + _XYZW]
        v[..., iv : iv + 3] = qvel[..., mv : mv + 3]
        if a is not None:
            a[..., iv : iv + 3] = qacc[..., mv : mv + 3]
    for mq, mv, iq, iv in m.frees:
        quat = qpos[..., mq + 3 + _XYZW]
        back = quaternion_conjugate(quat)
        q[..., iq : iq + 3], q[..., iq + 3 : iq + 7] = qpos[..., mq : mq + 3], quat
        lin, w = rotate_vector(back, qvel[..., mv : mv + 3]), qvel[..., mv + 3 : mv + 6]
        v[..., iv : iv + 3], v[..., iv + 3 : iv + 6] = lin, w
        if a is not None:
            a[..., iv : iv + 3] = rotate_vector(back, qacc[..., mv : mv + 3]) - np.cross(w, lin)
            a[..., iv + 3 : iv + 6] = qacc[..., mv + 3 : mv + 6]
    return (q, v) if a is None else (q, v, a)


def to_mujoco_state(robot, q, v, a=None, *, joint_names=None):
    """MuJoCo's ``(qpos, qvel)``, or ``(qpos, qvel, qacc)`` with ``a``, from armdyn's
    ``q``, ``v`` (and ``a``): the inverse of :func:`from_mujoco_state`."""
    m = _map(robot, joint_names)
    got = _arrays(robot, {"q": (q, robot.nq), "v": (v, robot.nv)})
    if a is not None:
        got.update(_arrays(robot, {"a": (a, robot.nv)}))
    q, v, a = check_configuration(robot, got["q"]), got["v"], got.get("a")
    qpos, qvel = np.empty_like(q), np.empty_like(v)
    mq, mv, aq, av = m.flat
    qpos[..., mq], qvel[..., mv] = q[..., aq], v[..., av]
    qacc = None
    if a is not None:
        qacc = np.empty_like(a)
        qacc[..., mv] = a[..., av]
    for mq, mv, iq, iv in m.balls:
        qpos[..., mq : mq + 4] = q[..., iq + _WXYZ]
        qvel[..., mv : mv + 3] = v[..., iv : iv + 3]
        if qacc is not None:
            qacc[..., mv : mv + 3] = a[..., iv : iv + 3]
    for mq, mv, iq, iv in m.frees:
        quat = q[..., iq + 3 : iq + 7]
        qpos[..., mq : mq + 3], qpos[..., mq + 3 : mq + 7] = q[..., iq : iq + 3], quat[..., _WXYZ]
        lin, w = v[..., iv : iv + 3], v[..., iv + 3 : iv + 6]
        qvel[..., mv : mv + 3], qvel[..., mv + 3 : mv + 6] = rotate_vector(quat, lin), w
        if qacc is not None:
            qacc[..., mv : mv + 3] = rotate_vector(quat, a[..., iv : iv + 3] + np.cross(w, lin))
            qacc[..., mv + 3 : mv + 6] = a[..., iv + 3 : iv + 6]
    return (qpos, qvel) if qacc is None else (qpos, qvel, qacc)


def from_mujoco_force(robot, qpos, qfrc, *, joint_names=None) -> np.ndarray:
    """armdyn's generalized force ``tau`` (e.g. from ``rnea``) from MuJoCo's ``qfrc``
    (e.g. ``qfrc_inverse``) at the configuration ``qpos``."""
    m = _map(robot, joint_names)
    got = _arrays(robot, {"qpos": (qpos, robot.nq), "qfrc": (qfrc, robot.nv)})
    _check_qpos(m, got["qpos"])
    qpos, qfrc = got["qpos"], got["qfrc"]
    tau = np.empty(np.broadcast_shapes(qpos.shape[:-1], qfrc.shape[:-1]) + (robot.nv,))
    _, mv, _, av = m.flat
    tau[..., av] = qfrc[..., mv]
    for _, mv, _, iv in m.balls:
        tau[..., iv : iv + 3] = qfrc[..., mv : mv + 3]
    for mq, mv, _, iv in m.frees:
        back = quaternion_conjugate(qpos[..., mq + 3 + _XYZW])
        tau[..., iv : iv + 3] = rotate_vector(back, qfrc[..., mv : mv + 3])
        tau[..., iv + 3 : iv + 6] = qfrc[..., mv + 3 : mv + 6]
    return tau


def to_mujoco_force(robot, q, tau, *, joint_names=None) -> np.ndarray:
    """MuJoCo's ``qfrc`` (e.g. for ``qfrc_applied``) from armdyn's ``tau`` at ``q``: the
    inverse of :func:`from_mujoco_force`."""
    m = _map(robot, joint_names)
    got = _arrays(robot, {"q": (q, robot.nq), "tau": (tau, robot.nv)})
    q, tau = check_configuration(robot, got["q"]), got["tau"]
    qfrc = np.empty(np.broadcast_shapes(q.shape[:-1], tau.shape[:-1]) + (robot.nv,))
    _, mv, _, av = m.flat
    qfrc[..., mv] = tau[..., av]
    for _, mv, _, iv in m.balls:
        qfrc[..., mv : mv + 3] = tau[..., iv : iv + 3]
    for _, mv, iq, iv in m.frees:
        qfrc[..., mv : mv + 3] = rotate_vector(q[..., iq + 3 : iq + 7], tau[..., iv : iv + 3])
        qfrc[..., mv + 3 : mv + 6] = tau[..., iv + 3 : iv + 6]
    return qfrc


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
