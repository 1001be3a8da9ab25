"""Kinematics of :mod:`armdyn.numeric`: link poses, Jacobians and their time derivative."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from .. import _core
from ..model import Link, Robot
from .checks import check_threads, overflow_error
from .compiled import RobotLike, compiled_model, core_model, frame_offsets, mimic_model


def forward_kinematics(robot: RobotLike, q: ArrayLike, *, threads: int | None = None) -> np.ndarray:
    """Homogeneous pose of every link frame in the base frame.

    q: (n,) or (N, n). Returns (nlinks, 4, 4) or (N, nlinks, 4, 4), links in
    ``list(robot.links)`` order (base first); each ``[[R, p], [0, 0, 0, 1]]`` with R the
    link's axes in base coordinates and p its origin.
    """
    if threads is not None:  # (a floating base too)
        threads = check_threads(threads)
    try:
        poses = compiled_model(robot).forward_kinematics(q, threads)
        offsets = frame_offsets(robot)
        return poses if offsets is None else poses @ offsets
    except FloatingPointError:  # the core checks its result: an overflow from finite inputs
        raise overflow_error("forward_kinematics", {"q": q}) from None


#: the reference frames of :func:`jacobian`, named as Pinocchio names them
REFERENCE_FRAMES = ("local_world_aligned", "local", "world")


def jacobian(
    robot: RobotLike,
    q: ArrayLike,
    link: str | int | Link,
    *,
    reference_frame: str = "local_world_aligned",
    threads: int | None = None,
) -> np.ndarray:
    """Geometric Jacobian of a link frame.

    q: (n,) or (N, n); link: a link name, index in ``list(robot.links)``, or Link.
    Returns J (6, n) or (N, 6, n) with ``[v; w] = J qd``, rows [v_x v_y v_z w_x w_y w_z],
    w the link's angular velocity. ``reference_frame`` (Pinocchio's names, any case):

    * ``"local_world_aligned"`` (default): v the velocity of the link frame's origin p,
      v and w in base-frame axes (Spong's [J_v; J_w]);
    * ``"local"``: the same v and w in the link frame's own axes (``R^T v``, ``R^T w``);
    * ``"world"``: the spatial velocity in the base frame: v the velocity of the body
      point passing through the base origin, ``v_p - w x p``; w in base axes.
    """
    if threads is not None:  # (a floating base too)
        threads = check_threads(threads)
    try:
        frame = str(getattr(reference_frame, "name", reference_frame)).lower()
        if frame not in REFERENCE_FRAMES:
            raise ValueError(f"reference_frame must be one of {', '.join(REFERENCE_FRAMES)}, got {reference_frame!r}")
        J = _aligned_jacobian(robot, q, link, threads)
        if frame == "local_world_aligned":
            return J
        name = link.name if isinstance(link, Link) else link
        k = name if isinstance(name, (int, np.integer)) else list(compiled_model(robot).link_names).index(name)
        pose = forward_kinematics(robot, q, threads=threads)[..., k, :, :]
        R, p = pose[..., :3, :3], pose[..., :3, 3]
        Jv, Jw = J[..., :3, :], J[..., 3:, :]
        if frame == "local":
            Rt = R.swapaxes(-1, -2)
            return np.concatenate([Rt @ Jv, Rt @ Jw], axis=-2)
        # world: v_O = v_p + w x (0 - p) = v_p + p x w, column by column
        return np.concatenate([Jv + np.cross(p[..., None, :], Jw.swapaxes(-1, -2)).swapaxes(-1, -2), Jw], axis=-2)
    except FloatingPointError:  # the core checks its result: an overflow from finite inputs
        raise overflow_error("jacobian", {"q": q}) from None


def _aligned_jacobian(robot, q, link, threads):
    """:func:`jacobian` in LOCAL_WORLD_ALIGNED."""
    if isinstance(link, Link):
        link = link.name
    J = compiled_model(robot).jacobian(q, link, threads)
    offsets = frame_offsets(robot)
    if offsets is None or not isinstance(robot, Robot):  # offsets: only a Robot has them
        return J
    # the compiled model's link frame is on the joint; move the point to the link frame's
    # origin: v' = v + w x (R pf), so J_v' = J_v - [R pf]x J_w
    k = link if isinstance(link, (int, np.integer)) else robot.link_index(link)
    R = compiled_model(robot).forward_kinematics(q, threads)[..., k, :3, :3]
    r = R @ offsets[k, :3, 3]
    Jv, Jw = J[..., :3, :], J[..., 3:, :]
    return np.concatenate([Jv - np.cross(r[..., None, :], Jw.swapaxes(-1, -2)).swapaxes(-1, -2), Jw], axis=-2)


def jacobian_dot(
    robot: RobotLike, q: ArrayLike, qd: ArrayLike, link: str | int | Link, *, threads: int | None = None
) -> np.ndarray:
    """Time derivative of :func:`jacobian`: ``dJ/dt`` (6, n) or (N, 6, n), same rows
    ``[v; w]`` in base-frame axes (Pinocchio's LOCAL_WORLD_ALIGNED), so that the link
    origin's acceleration and the link's angular acceleration are ``J qdd + Jdot qd``.
    link: a link name, index in ``list(robot.links)``, or Link."""
    threads = check_threads(threads)  # (a floating base too: free_root.rs)
    try:
        if isinstance(link, Link):
            link = link.name
        mimic = mimic_model(robot, "jacobian_dot")
        if mimic is not None:
            Jd = mimic.jacobian_dot(q, qd, link, threads)
        else:
            Jd = _core.jacobian_dot(core_model(robot, "jacobian_dot"), q, qd, link, threads)
        offsets = frame_offsets(robot)
        if offsets is None or not isinstance(robot, Robot):  # offsets: only a Robot has them
            return Jd
        # the point at r = R pf from the compiled (on-joint) frame's origin: J_v' = J_v - [r]x J_w,
        # so Jdot_v' = Jdot_v - [w x r]x J_w - [r]x Jdot_w, with w = J_w qd
        model = compiled_model(robot)
        k = link if isinstance(link, (int, np.integer)) else robot.link_index(link)
        r = model.forward_kinematics(q, threads)[..., k, :3, :3] @ offsets[k, :3, 3]
        Jw = model.jacobian(q, link, threads)[..., 3:, :]
        w = np.einsum("...ij,...j->...i", Jw, np.asarray(qd, dtype=float))
        rd = np.cross(w, r)

        def cross_cols(v, A):  # [v]x A, column by column
            return np.cross(v[..., None, :], A.swapaxes(-1, -2)).swapaxes(-1, -2)

        Jdv = Jd[..., :3, :] - cross_cols(rd, Jw) - cross_cols(r, Jd[..., 3:, :])
        return np.concatenate([Jdv, Jd[..., 3:, :]], axis=-2)
    except FloatingPointError:  # the core checks its result: an overflow from finite inputs
        raise overflow_error("jacobian_dot", {"q": q, "qd": qd}) from None
