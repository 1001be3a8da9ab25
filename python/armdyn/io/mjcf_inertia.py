"""Mass properties of MJCF bodies as MuJoCo's compiler computes them (for
:mod:`armdyn.io.mjcf`): an ``<inertial>`` element, or a primitive geom of uniform density
or given mass (the shapes' formulas are in :mod:`armdyn.io.mjcf_math`)."""

from __future__ import annotations

import numpy as np

from .mjcf_math import GEOM_SIZES, geom_volume_inertia, quat_matrix, zaxis_quat
from .mjcf_xml import clip

__all__ = ["inertial", "geom", "ORIENTATIONS"]

ORIENTATIONS = ("quat", "axisangle", "euler", "xyaxes", "zaxis")


def inertial(reader, elem, cls, Rf, pf) -> tuple[float, np.ndarray, np.ndarray]:
    """``(mass, com, inertia about com)`` in the body frame (``Rf, pf``: the pose of
    the frame the <inertial> sits in)."""
    reader.check_attributes(elem)
    attrs = elem.attrib
    for key in ("pos", "mass"):
        if key not in attrs:
            raise reader.error(elem, f"<inertial> has no '{key}'")
    mass = reader.number(elem, attrs, "mass", 0.0)
    if mass < 0:
        raise reader.error(elem, f"mass {mass} is negative")
    com = reader.numbers(elem, attrs, "pos", 3)
    if ("diaginertia" in attrs) == ("fullinertia" in attrs):
        raise reader.error(elem, "<inertial> needs one of 'diaginertia' and 'fullinertia'")
    if "fullinertia" in attrs:
        if set(attrs) & set(ORIENTATIONS):
            raise reader.error(elem, "fullinertia cannot be given with an orientation (it is in the body's axes)")
        xx, yy, zz, xy, xz, yz = reader.numbers(elem, attrs, "fullinertia", 6)
        return mass, pf + Rf @ com, Rf @ np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]) @ Rf.T
    R = Rf @ reader.rotation(elem, attrs)
    return mass, pf + Rf @ com, R @ np.diag(reader.numbers(elem, attrs, "diaginertia", 3)) @ R.T


def geom(reader, elem, R0, p0, cls, body) -> tuple | None:
    """``(mass, com, inertia about com)`` of a geom in the body frame, or None when its
    group is outside ``inertiagrouprange``."""
    attrs = reader.attrs(elem, cls)
    group = reader.number(elem, attrs, "group", 0.0)
    if not reader.groups[0] <= group <= reader.groups[1]:
        reader.ignored["<geom> outside inertiagrouprange"] += 1
        return None
    kind = attrs.get("type", "sphere")
    if kind not in GEOM_SIZES:
        raise reader.error(
            elem,
            f"body '{clip(body)}' has no <inertial> and MuJoCo would infer it from this {clip(kind)} geom: "
            "armdyn infers it from sphere, capsule, cylinder, box and ellipsoid geoms only; "
            "give the body an <inertial>",
        )
    if attrs.get("shellinertia", "false") != "false":
        raise reader.error(elem, "shellinertia is not supported: give the body an <inertial>")
    size = np.zeros(3)
    given = reader.numbers(elem, attrs, "size", 3, [], at_least=0)
    size[: len(given)] = given
    if "fromto" in attrs:
        if kind == "sphere":
            raise reader.error(elem, "fromto cannot be used with a sphere")
        ends = reader.numbers(elem, attrs, "fromto", 6)
        length = np.linalg.norm(ends[3:] - ends[:3])
        if length < 1e-10:
            raise reader.error(elem, "fromto has zero length")
        R, p = quat_matrix(zaxis_quat(ends[3:] - ends[:3])), (ends[:3] + ends[3:]) / 2
        if kind in ("capsule", "cylinder"):
            size[1] = length / 2
        else:  # a box or an ellipsoid: MuJoCo takes size[0] for both half-widths
            size[1:] = size[0], length / 2
    else:
        R, p = reader.pose(elem, attrs)
    if np.any(size[: GEOM_SIZES[kind]] <= 0):
        raise reader.error(elem, f"a {kind} needs {GEOM_SIZES[kind]} positive size numbers, got {size.tolist()}")
    volume, unit_inertia = geom_volume_inertia(kind, size)
    if "mass" in attrs:
        mass = reader.number(elem, attrs, "mass", 0.0)
        density = mass / volume
    else:
        density = reader.number(elem, attrs, "density", 1000.0)
        mass = density * volume
    if mass < 0:
        raise reader.error(elem, "mass (or density) is negative")
    R, p = R0 @ R, p0 + R0 @ p
    return mass, p, R @ (density * unit_inertia) @ R.T
