"""Joint friction, rotor inertia and torque offset, symbolically.

the architecture's convention, per movable joint k (sign(0) = 0)::

    tau_k = [M qdd + C qd + g]_k + Ia_k qdd_k + Fv_k qd_k + Fc_k sign(qd_k) + offset_k

with ``Ia = joint.armature`` (rotor inertia reflected to the joint), ``Fv =
joint.damping``, ``Fc = joint.friction``, ``offset = joint.torque_offset`` (absent = 0).
``Ia`` belongs to the inertia matrix (M includes it); the offset is part of ``g = tau(qd =
0, qdd = 0)``; the friction ``Fv qd + Fc sign(qd)`` is the one term outside
``M qdd + C qd + g``.
"""

from __future__ import annotations

import sympy as sp

from ..model import Robot


def _value(joint, name) -> sp.Expr:
    value = getattr(joint, name)
    return sp.Integer(0) if value is None else value


def _per_coordinate(robot: Robot, name: str) -> list:
    """The joints' ``name`` value per velocity coordinate (a joint of several coordinates
    carries none: 0 at each of its rows)."""
    return [_value(j, name) for j in robot.movable_joints for _ in range(j.nv)]


def armature(robot: Robot) -> sp.Matrix:
    """(n, 1) reflected rotor inertias ``Ia`` of the movable joints (0 where absent)."""
    return sp.Matrix(_per_coordinate(robot, "armature"))


def friction_torques(robot: Robot, qd) -> sp.Matrix:
    """(n, 1) ``Fv qd + Fc sign(qd)`` per joint, for velocities ``qd`` (n,)."""
    out = []
    for k, (fv, fc) in enumerate(zip(_per_coordinate(robot, "damping"), _per_coordinate(robot, "friction"))):
        out.append(fv * qd[k] + (fc * sp.sign(qd[k]) if fc != 0 else sp.Integer(0)))
    return sp.Matrix(out)


def offsets(robot: Robot) -> sp.Matrix:
    """(n, 1) constant torque offsets (0 where absent)."""
    return sp.Matrix(_per_coordinate(robot, "torque_offset"))


def joint_torques(robot: Robot, qd, qdd) -> sp.Matrix:
    """(n, 1) ``Ia qdd + Fv qd + Fc sign(qd) + offset``: what the joints add to the
    rigid-body torque."""
    ia = armature(robot)
    return sp.Matrix([ia[k] * qdd[k] for k in range(robot.dof)]) + friction_torques(robot, qd) + offsets(robot)


def has_joint_terms(robot: Robot) -> bool:
    """Whether any movable joint has a nonzero friction, armature or offset."""
    return any(
        _value(j, name) != 0
        for j in robot.movable_joints
        for name in ("damping", "friction", "armature", "torque_offset")
    )
