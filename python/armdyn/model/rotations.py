"""Rotation matrices (3x3 SymPy): elementary rotations, URDF's roll-pitch-yaw, axis-angle, and
the skew-symmetric cross-product matrix."""

from __future__ import annotations

import sympy as sp


def rot_x(a) -> sp.Matrix:
    """Rotation (3x3) by angle ``a`` about x."""
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_y(a) -> sp.Matrix:
    """Rotation (3x3) by angle ``a`` about y."""
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rot_z(a) -> sp.Matrix:
    """Rotation (3x3) by angle ``a`` about z."""
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def rpy_matrix(roll, pitch, yaw) -> sp.Matrix:
    """URDF roll-pitch-yaw: ``Rz(yaw) * Ry(pitch) * Rx(roll)`` (fixed axes x, y, z)."""
    # zero angles are identity factors: skipping them saves SymPy products (big URDFs)
    factors = [rot(a) for rot, a in ((rot_z, yaw), (rot_y, pitch), (rot_x, roll)) if a != 0]
    out = sp.eye(3)
    for f in factors:
        out = out * f
    return out


def axis_angle_matrix(axis, angle) -> sp.Matrix:
    """Rodrigues' rotation (3x3) by ``angle`` about the unit vector ``axis``.

    The coordinate axes give the exact ``rot_x/rot_y/rot_z`` forms, so symbolic
    results stay as simple as a hand derivation.
    """
    a = sp.Matrix(axis)
    for i, rot in enumerate((rot_x, rot_y, rot_z)):
        unit = [0, 0, 0]
        unit[i] = 1
        if list(a) == unit:
            return rot(angle)
        unit[i] = -1
        if list(a) == unit:
            return rot(-angle)
    c, s = sp.cos(angle), sp.sin(angle)
    k = skew(a)
    return sp.eye(3) + s * k + (1 - c) * k * k


def skew(v) -> sp.Matrix:
    """Cross-product matrix (3x3): ``skew(v) * w == v x w``."""
    x, y, z = v
    return sp.Matrix([[0, -z, y], [z, 0, -x], [-y, x, 0]])
