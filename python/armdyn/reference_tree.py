"""The NumPy oracle's ground floor: spatial algebra and a Robot as Featherstone's arrays.

:mod:`armdyn.reference` (its algorithms) and :mod:`armdyn.reference_derivatives` build
on these: the spatial cross products and transforms of RBDA ch. 2 (spatial_v2's crm,
crf, mcI, plux), and :class:`Tree`, a numeric Robot as parent indices, motion subspaces,
poses and spatial inertias (conventions in :mod:`armdyn.reference`'s docstring).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass
from typing import Callable

import numpy as np
import sympy as sp

from .errors import UnboundParameterError
from .model import Robot

# --------------------------------------------------------------------------- spatial algebra


def skew3(w: np.ndarray) -> np.ndarray:
    """3x3 cross-product matrix of a 3-vector: ``skew3(a) @ b == cross(a, b)``."""
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def crm(v: np.ndarray) -> np.ndarray:
    """Spatial cross product for motion vectors, ``crm(v) @ m = v x m`` (RBDA ch. 2)."""
    w, u = skew3(v[:3]), skew3(v[3:])
    return np.block([[w, np.zeros((3, 3))], [u, w]])


def crf(v: np.ndarray) -> np.ndarray:
    """Spatial cross product for force vectors, ``crf(v) @ f = v x* f = -crm(v)^T f`` (RBDA ch. 2)."""
    return -crm(v).T


def plux(E: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Plücker motion transform (6x6) to a frame rotated by ``E`` (new coordinates = E old)
    and displaced by ``r`` (origin of the new frame, old coordinates): ``rot(E) xlt(r)``."""
    return np.block([[E, np.zeros((3, 3))], [-E @ skew3(r), E]])


def inverse_motion_transform(X: np.ndarray) -> np.ndarray:
    """Inverse of ``plux(E, r)``: ``[[E^T, 0], [skew(r) E^T, E^T]]``, computed from the blocks."""
    Et = X[:3, :3].T
    r_cross = -Et @ X[3:, :3]  # X[3:, :3] = -E skew(r)
    return np.block([[Et, np.zeros((3, 3))], [r_cross @ Et, Et]])


def mcI(m: float, c: np.ndarray, Ic: np.ndarray) -> np.ndarray:
    """Spatial inertia (6x6) at the body frame's origin from mass ``m``, centre of mass ``c``
    and rotational inertia ``Ic`` about the centre of mass (RBDA ch. 2, spatial_v2's mcI)."""
    C = skew3(c)
    return np.block([[Ic + m * C @ C.T, m * C], [m * C.T, m * np.eye(3)]])


# --------------------------------------------------------------------------- the model as arrays


@dataclass
class Tree:
    """A numeric Robot as Featherstone's arrays (see the module docstring)."""

    n: int  # number of coordinates
    parent: list[int]  # parent body index, -1 = base
    kind: list[str]  # joint type: revolute, prismatic, fixed
    axis: list[np.ndarray]  # (3,) unit axis in the child frame's axes
    point: list[np.ndarray]  # (3,) a point on the joint's axis, child-frame coordinates
    pose: list[Callable[[float], tuple]]  # q_k -> (R (3,3), p (3,)) child in parent
    S: list[np.ndarray]  # motion subspace (6, 0 or 1) in body coordinates
    dofs: list[np.ndarray]  # coordinate indices of joint k (empty for a fixed joint)
    inertia: list[np.ndarray]  # spatial inertia (6, 6) at the body frame origin
    mass: list[float]
    com: list[np.ndarray]  # (3,) in body frame
    gravity: np.ndarray  # (3,) base frame
    base_mass: float
    base_com: np.ndarray
    link_names: list[str]  # base first, then body k's name at k + 1
    follow: list[tuple[float, float]]  # (c, o): joint k's own coordinate is c q[dofs[k]] + o
    mimic: bool  # whether some joint is a mimic joint
    # per coordinate: rotor inertia Ia, viscous Fv, Coulomb Fc, offset (docs/architecture.md), (n,) each
    armature: np.ndarray = None
    viscous: np.ndarray = None
    coulomb: np.ndarray = None
    offset: np.ndarray = None


_trees: "weakref.WeakKeyDictionary[Robot, Tree]" = weakref.WeakKeyDictionary()
_q = sp.Symbol("q")


def _floats(matrix) -> np.ndarray:
    return np.array([[float(x) for x in row] for row in matrix.tolist()])


def tree_of(robot: Robot) -> Tree:
    """Convert (once per robot) to arrays; refuse a robot with free symbols."""
    if robot in _trees:
        return _trees[robot]
    robot.require_one_dof_joints("armdyn.reference (the NumPy oracle)")
    free = robot.free_symbols()
    if free:
        names = ", ".join(sorted(str(s) for s in free))
        raise UnboundParameterError(
            f"robot '{robot.name}' has unbound parameters: {names}; bind them with robot.bind({{...}})"
        )
    index = {robot.base: -1}
    kind, axes, points = [j.type for j in robot.joints], [], []
    parent, pose, S, dofs, inertia, mass, com, follow = [], [], [], [], [], [], [], []
    for k, joint in enumerate(robot.joints):
        parent.append(index[joint.parent])
        index[joint.child] = k
        R, p = joint.transform(_q)  # model.py's convention, lambdified to NumPy
        pose.append(sp.lambdify(_q, (R, p), "numpy"))
        axis = _floats(joint.child_axis).ravel()  # in the child frame's axes
        axes.append(axis)
        f = robot.follows(joint)  # (coordinate, multiplier, offset), None when fixed
        c = 1.0 if f is None else float(f[1])
        follow.append((c, 0.0 if f is None else float(f[2])))
        if joint.type == "revolute":
            # the axis is invariant under Rot(axis, q); a child frame off the axis (joint
            # point jp in child coordinates, constant) moves with linear velocity jp x axis
            jp = _floats(joint.joint_point(0)).ravel()
            points.append(jp)
            S.append(c * np.concatenate([axis, np.cross(jp, axis)])[:, None])
        elif joint.type == "prismatic":
            S.append(c * np.concatenate([np.zeros(3), axis])[:, None])
            points.append(np.zeros(3))
        else:
            S.append(np.zeros((6, 0)))
            points.append(np.zeros(3))
        dofs.append(np.array([] if f is None else [f[0]], dtype=int))
        link = robot.links[joint.child]
        m, c, Ic = float(link.mass), _floats(link.com).ravel(), _floats(link.inertia)
        mass.append(m)
        com.append(c)
        inertia.append(mcI(m, c, Ic))
    base = robot.links[robot.base]
    tree = Tree(
        n=robot.dof,
        parent=parent,
        kind=kind,
        axis=axes,
        point=points,
        pose=pose,
        S=S,
        dofs=dofs,
        inertia=inertia,
        mass=mass,
        com=com,
        gravity=_floats(robot.gravity).ravel(),
        base_mass=float(base.mass),
        base_com=_floats(base.com).ravel(),
        link_names=list(robot.links),
        follow=follow,
        mimic=bool(robot.mimic_joints),
    )
    terms = [
        [float(getattr(j, k)) if getattr(j, k) is not None else 0.0 for j in robot.movable_joints]
        for k in ("armature", "damping", "friction", "torque_offset")
    ]
    tree.armature, tree.viscous, tree.coulomb, tree.offset = (np.array(x, dtype=float) for x in terms)
    _trees[robot] = tree
    return tree


def checked_state(tree: Tree, x, name: str) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    if x.shape != (tree.n,):
        raise ValueError(f"{name} must have shape ({tree.n},), got {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError(f"{name} contains NaN or inf")
    return x


def joint_value(tree: Tree, k: int, q: np.ndarray) -> float:
    c, o = tree.follow[k]
    return c * float(q[tree.dofs[k]][0]) + o if tree.dofs[k].size else 0.0


def poses(tree: Tree, q: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """(R, p) of each body in its parent, at ``q``."""
    out = []
    for k in range(len(tree.parent)):
        R, p = tree.pose[k](joint_value(tree, k, q))
        out.append((np.array(R, dtype=float).reshape(3, 3), np.array(p, dtype=float).ravel()))
    return out


def xup(tree: Tree, q: np.ndarray) -> list[np.ndarray]:
    """Plücker transforms parent -> body k: jcalc and Xtree in one, ``Xup = plux(R^T, p)``."""
    return [plux(R.T, p) for R, p in poses(tree, q)]


def a_gravity(tree: Tree) -> np.ndarray:
    return np.concatenate([np.zeros(3), tree.gravity])
