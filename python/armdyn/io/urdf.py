"""URDF reader: ``load_urdf(path_or_xml, strict=True) -> Robot``.

What is read (the URDF 1.0 subset that describes a fixed-base arm's dynamics):

* ``<robot name>`` with ``<link>`` and ``<joint>`` children; any other child
  (``<material>``, ``<gazebo>``, ``<transmission>``, ``<ros2_control>``...) and a link's
  ``<visual>``/``<collision>`` are ignored.
* Joints ``revolute``, ``continuous`` (read as revolute, without position limits: q is
  its angle, where Pinocchio's parser keeps an unbounded joint's ``(cos, sin)``, nq 2;
  v, a and tau are the same, and q converts by the angle's cos and sin),
  ``prismatic`` and ``fixed``. Fixed joints stay fixed joints in the :class:`Robot`;
  the engines handle them.
* Joints of several coordinates, read as Pinocchio's URDF parser reads them (layouts:
  :data:`armdyn.model.joints.MULTI_DOF`): ``floating`` becomes a ``floating`` joint (a
  free-flyer anywhere in the tree; its ``<axis>`` is unused, as the URDF spec says) and
  ``planar`` a ``planar`` joint moving in its joint frame's x-y plane. Pinocchio ignores
  a planar joint's ``<axis>`` (the plane's normal in the URDF spec) and always moves in
  that x-y plane; so that both read the file alike, ``<axis xyz="0 0 1"/>`` is required
  here and any other axis, or none (URDF's default ``1 0 0``), is refused (turn the plane
  with the joint's ``<origin rpy>`` instead). Limits other than ``effort``, ``<dynamics>``
  and ``<mimic>`` are refused on them (not modelled; Pinocchio drops them).
* ``<mimic joint multiplier offset>`` (defaults 1 and 0): the joint follows its leader,
  ``q = multiplier * q_leader + offset``, and has no coordinate of its own (see
  :class:`armdyn.model.Mimic`). The leader must exist and be of the same type; a chain
  is composed, a loop is an error. On a fixed joint ``<mimic>`` is ignored (a fixed
  joint does not move; ``talos_reduced.urdf`` has such joints).
* ``<origin xyz rpy>`` (default zero, ``rpy`` is URDF's fixed-axis roll-pitch-yaw),
  ``<axis xyz>`` (default ``1 0 0``, as the URDF spec says; ignored on fixed and floating
  joints).
  An axis within 1e-6 of unit length is normalised (files often write ``0.7071``);
  a zero axis, or one further from unit length, is an error.
* ``<limit lower upper effort velocity>`` and ``<dynamics damping friction>`` are
  kept on the :class:`Joint`; an attribute that is absent stays ``None`` (no default
  is invented: URDF's "lower defaults to 0" is not applied).
* ``<inertial>``: ``<mass value>`` and all six ``<inertia>`` entries are required,
  ``<origin>`` is optional. The centre of mass is the inertial origin's ``xyz``; the
  tensor, given in the inertial frame, is rotated into the link frame
  (``I_link = R I R^T``, ``R`` from the inertial origin's ``rpy``).
* A link without ``<inertial>`` is massless (mass 0, zero tensor), never given a
  made-up 1 kg. Such links are listed in ``robot.meta["massless_links"]``. When a
  movable joint carries nothing with mass or inertia at all (so the mass matrix is
  singular), a :class:`MasslessWarning` names it.

Gravity is ``(0, 0, -9.81)`` in the base (root link) frame; URDF has no field for it.
Physical validity (mass >= 0, inertia positive semi-definite, triangle inequality) is
checked by the :class:`Robot` constructor; ``strict`` is passed to it.

Every problem is a :class:`ModelError` with one line ``"file: element: message"``
(``element`` like ``joint 'elbow'`` or ``link 'forearm'``); nothing else escapes.

Why not urdfdom-py (``urdf_parser_py``), the maintained ROS parser: tried (1.2.1)
and found unsuitable for clear errors. It writes unknown or repeated elements to
stderr and goes on (a second ``<origin>`` is dropped silently); a ``<child/>``
without ``link`` becomes the link named ``'None'``; duplicate link names pass;
``mass="abc"`` gives a bare ``ValueError`` with no element named; a 2-component
vector is an ``AssertionError`` (and vanishes under ``python -O``); errors span
several lines. The subset above is small, so it is read here with
:mod:`xml.etree.ElementTree` and checked element by element.
"""

from __future__ import annotations

import math
import os
import re
import warnings
import xml.etree.ElementTree as ET
from functools import partial

import numpy as np
import sympy as sp

from ..dispatch import register
from ..errors import ModelError
from ..inertia import rotate
from ..model import Joint, Link, Mimic, Numbers, Robot, rpy_matrix
from .expressions import check_name

__all__ = ["load_urdf", "MasslessWarning"]

#: URDF joint types read, and what they become in the model.
JOINT_TYPES = {
    "revolute": "revolute",
    "continuous": "revolute",
    "prismatic": "prismatic",
    "fixed": "fixed",
    "floating": "floating",
    "planar": "planar",
}
#: The one ``<axis>`` a planar joint may have: Pinocchio moves it in its frame's x-y plane.
PLANAR_NORMAL = (0.0, 0.0, 1.0)

# A plain decimal number, as URDF writes them (no "nan", "inf", "1_000" or hex).
_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")

AXIS_TOLERANCE = 1e-6


class MasslessWarning(UserWarning):
    """A movable joint of a URDF model moves no mass and no inertia."""


def load_urdf(path_or_xml, strict: bool = True) -> Robot:
    """Read a URDF file (a path) or URDF text (a string holding ``<`` or a line break).

    Returns a numeric :class:`Robot` (no parameters) whose base is the root link.
    ``robot.meta`` holds ``convention`` ("urdf"), ``file`` (the path, when read from
    a file), ``source`` (the file's first XML comment before ``<robot>``, if any: the
    bundled URDFs cite their origin there) and ``massless_links`` (names of links
    without ``<inertial>``). ``strict=False`` loads physically invalid inertias with a
    warning instead of an error.
    """
    text, source = _read(path_or_xml)
    try:
        return build_robot(parse_xml(text), text, source, strict)
    except ModelError as err:
        raise err.located(source=source)


@register("urdf", Robot)
def robot_from_urdf(cls: type, path_or_xml, strict: bool = True) -> Robot:
    """``Robot.from_urdf`` (through :mod:`armdyn.dispatch`): :func:`load_urdf`."""
    return load_urdf(path_or_xml, strict=strict)


# --------------------------------------------------------------------- input


def _read(path_or_xml) -> tuple[bytes, str]:
    if isinstance(path_or_xml, bytes):
        return path_or_xml, "<urdf>"
    # text holding markup or line breaks is URDF text, not a file name
    if isinstance(path_or_xml, str) and any(c in path_or_xml for c in "<\n\r"):
        return path_or_xml.encode("utf-8", "surrogatepass"), "<urdf>"
    if not isinstance(path_or_xml, (str, os.PathLike)):
        raise ModelError(f"expected a file path or URDF text, got {type(path_or_xml).__name__}")
    from .textfile import MODEL_MAX_BYTES, read_bytes

    return read_bytes(path_or_xml, "model", MODEL_MAX_BYTES), str(path_or_xml)


def parse_xml(text: bytes) -> ET.Element:
    """The ``<robot>`` root of URDF bytes (no DTD, no entities); ModelError with line and column."""
    refuse_dtd(text)
    try:
        root = ET.fromstring(text)
    except ET.ParseError as err:
        line, col = err.position
        reason = str(err).split(":")[0]
        raise ModelError(f"malformed XML: {reason}", f"line {line}, column {col + 1}") from None
    if root.tag != "robot":
        raise ModelError(f"the root element is <{root.tag}>, expected <robot>", f"<{root.tag}>")
    return root


class _DTD(Exception):
    pass


def refuse_dtd(text: bytes, fmt: str = "URDF") -> None:
    """ModelError if the document has a DTD (``<!DOCTYPE ...>``, with or without entity
    or ``<!ATTLIST>`` declarations), in whatever encoding it is written.

    Entity declarations are the one XML feature that can make a small file huge ("billion
    laughs"); they and ATTLIST defaults also change what the file says (a robot name, a
    mass) invisibly; URDF (and MJCF, ``fmt``) needs none of it. Looking for the bytes ``<!ENTITY`` misses a
    UTF-16 file, so expat itself (which decodes any encoding it accepts) reads the
    document up to its DTD and stops there, before anything is declared or expanded."""
    import xml.parsers.expat

    def refuse(*_args):
        raise _DTD

    parser = xml.parsers.expat.ParserCreate()
    parser.StartDoctypeDeclHandler = refuse
    parser.EntityDeclHandler = refuse  # a DTD cannot be skipped, but be explicit
    parser.AttlistDeclHandler = refuse
    try:
        parser.Parse(text, True)
    except _DTD:
        where = f"<!DOCTYPE> on line {parser.CurrentLineNumber}"
        raise ModelError(
            f"a DTD is not allowed in {fmt} (entity declarations are not allowed, nor ATTLIST defaults)", where
        ) from None
    except xml.parsers.expat.ExpatError:
        return  # malformed: ElementTree reports it with its own wording


# ------------------------------------------------------------------ elements


def _attr(elem: ET.Element, name: str, where: str | None) -> str:
    value = elem.get(name)
    if value is None:
        raise ModelError(f"<{elem.tag}> has no '{name}' attribute", where)
    if not value.strip():
        raise ModelError(f"<{elem.tag}> has an empty '{name}' attribute", where)
    return value.strip()


def _single(parent: ET.Element, tag: str, where: str, required: bool = False) -> ET.Element | None:
    found = parent.findall(tag)
    if len(found) > 1:
        raise ModelError(f"more than one <{tag}> in <{parent.tag}>", where)
    if not found and required:
        raise ModelError(f"<{parent.tag}> has no <{tag}>", where)
    return found[0] if found else None


def _clip(text: str, limit: int = 40) -> str:
    """``text`` shortened for an error message (a bad file may hold megabytes)."""
    return text if len(text) <= limit else f"{text[:limit]}... ({len(text)} characters)"


def _number(text: str, what: str, where: str) -> float:
    text = text.strip()
    if "${" in text or "$(" in text:
        raise ModelError(f"{what} is {_clip(text)!r}: a xacro expression (run xacro first)", where)
    if not _NUMBER.fullmatch(text):
        raise ModelError(f"{what} is {_clip(text)!r}, not a finite number", where)
    value = float(text)
    if not math.isfinite(value):
        raise ModelError(f"{what} is {_clip(text)!r}, not a finite number", where)
    return value


def parse_numbers(text: str, count: int, what: str, where: str) -> list[float]:
    parts = text.split()
    if len(parts) != count:
        raise ModelError(f"{what} is {_clip(text)!r}: expected {count} numbers", where)
    return [_number(p, what, where) for p in parts]


def _sym(value: float) -> sp.Expr:
    """A file number as SymPy: whole numbers exact (so 0 and 1 stay exact, which keeps
    zero tests and axis-aligned rotations exact), others as Float (all 53 bits)."""
    return sp.Integer(int(value)) if value.is_integer() and abs(value) < 2**53 else sp.Float(value)


def _angle(value: float) -> sp.Expr:
    """An rpy angle as SymPy: a multiple of pi/2 written to full double precision
    (1.5707963267948966, 3.14159265359 is not) becomes exact, so that axis-aligned
    rotations have exact 0/1 entries and symbolic derivations stay small; the number
    changes by less than 1e-12 rad, below what the file states."""
    k = round(value / (np.pi / 2))
    if k != 0 and abs(value - k * np.pi / 2) < 1e-12:
        return k * sp.pi / 2
    return _sym(value)


def rpy_floats(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """URDF roll-pitch-yaw in floats: ``Rz(yaw) Ry(pitch) Rx(roll)`` (3, 3)."""
    cr, sr, cp, sp_, cy, sy = (
        math.cos(roll),
        math.sin(roll),
        math.cos(pitch),
        math.sin(pitch),
        math.cos(yaw),
        math.sin(yaw),
    )
    return np.array(
        [
            [cy * cp, cy * sp_ * sr - sy * cr, cy * sp_ * cr + sy * sr],
            [sy * cp, sy * sp_ * sr + cy * cr, sy * sp_ * cr - cy * sr],
            [-sp_, cp * sr, cp * cr],
        ]
    )


def _rpy_exact(rpy: tuple) -> sp.Matrix:
    """The SymPy form of an rpy rotation (pi/2 multiples exact, see :func:`_angle`);
    built only when a symbolic function reads the joint."""
    return rpy_matrix(*(_angle(a) for a in rpy))


def _inertia_exact(entries: tuple, rpy: tuple) -> sp.Matrix:
    """The SymPy form of an inertia tensor given in a rotated inertial frame."""
    ixx, ixy, ixz, iyy, iyz, izz = (_sym(v) for v in entries)
    tensor = sp.Matrix([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    return rotate(tensor, _rpy_exact(rpy))


def _optional(elem: ET.Element | None, name: str, where: str) -> float | None:
    if elem is None or elem.get(name) is None:
        return None
    return _number(elem.get(name), f"<{elem.tag}> {name}", where)


def _optional_numbers(elem: ET.Element | None, name: str, where: str) -> Numbers | None:
    """An optional joint value as :class:`Numbers` (SymPy only when asked for: a Float,
    as these were always read)."""
    value = _optional(elem, name, where)
    return None if value is None else Numbers(value, partial(sp.Float, value))


def _origin(parent: ET.Element, where: str) -> tuple[Numbers, Numbers, tuple]:
    """``(xyz (3,), R (3, 3), rpy)`` of an optional ``<origin>`` child (default identity).

    xyz and R are :class:`Numbers`: floats now, SymPy (whole numbers and pi/2 angles
    exact) only when a symbolic function asks, so big URDFs load without SymPy."""
    origin = _single(parent, "origin", where)
    xyz, rpy = [0.0] * 3, [0.0] * 3
    if origin is not None:
        if origin.get("xyz") is not None:
            xyz = parse_numbers(origin.get("xyz"), 3, "<origin> xyz", where)
        if origin.get("rpy") is not None:
            rpy = parse_numbers(origin.get("rpy"), 3, "<origin> rpy", where)
    rpy = tuple(rpy)
    if not any(rpy):
        rotation = Numbers(np.eye(3))
    else:
        rotation = Numbers(rpy_floats(*rpy), partial(_rpy_exact, rpy))
    return Numbers(xyz), rotation, rpy


def _name(elem: ET.Element, where: str) -> str:
    """The element's ``name``: a non-empty one-line printable string, as in YAML models
    (a character reference such as ``&#10;`` would otherwise put a line break in it)."""
    return check_name(_attr(elem, "name", where), "name", where)


def _link(elem: ET.Element, index: int) -> tuple[Link, bool]:
    """The link and whether it had an ``<inertial>``."""
    name = _name(elem, f"link #{index + 1}")
    where = f"link '{_clip(name)}'"
    inertial = _single(elem, "inertial", where)
    if inertial is None:
        return Link(name), False
    mass_elem = _single(inertial, "mass", where, required=True)
    mass = _number(_attr(mass_elem, "value", where), "<mass> value", where)
    tensor = _single(inertial, "inertia", where, required=True)
    i = {
        k: _number(_attr(tensor, k, where), f"<inertia> {k}", where) for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
    }
    tensor = np.array(
        [
            [i["ixx"], i["ixy"], i["ixz"]],
            [i["ixy"], i["iyy"], i["iyz"]],
            [i["ixz"], i["iyz"], i["izz"]],
        ]
    )
    com, rotation, rpy = _origin(inertial, where)
    if any(rpy):  # given in the inertial frame: I_link = R I R^T
        R = rotation.floats
        entries = tuple(i[k] for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"))
        inertia = Numbers(R @ tensor @ R.T, partial(_inertia_exact, entries, rpy))
    else:
        inertia = Numbers(tensor)
    return Link(name, Numbers(mass), com, inertia), True


def _joint(elem: ET.Element, index: int) -> Joint:
    name = _name(elem, f"joint #{index + 1}")
    where = f"joint '{_clip(name)}'"
    kind = _attr(elem, "type", where)
    if kind not in JOINT_TYPES:
        raise ModelError(f"unknown joint type '{kind}' (expected one of {', '.join(JOINT_TYPES)})", where)
    parent = _attr(_single(elem, "parent", where, required=True), "link", where)
    child = _attr(_single(elem, "child", where, required=True), "link", where)
    xyz, rotation, _ = _origin(elem, where)

    axis = Numbers([1.0, 0.0, 0.0])
    axis_elem = _single(elem, "axis", where)
    if kind not in ("fixed", "floating") and axis_elem is not None:
        values = parse_numbers(_attr(axis_elem, "xyz", where), 3, "<axis> xyz", where)
        norm = math.sqrt(sum(v * v for v in values))
        if norm == 0:
            raise ModelError("axis is zero", where)
        if abs(norm - 1) > AXIS_TOLERANCE:
            raise ModelError(f"axis {values} is not a unit vector (norm {norm:.6g})", where)
        axis = Numbers([v / norm for v in values])
    if kind == "planar":
        _check_planar_axis(None if axis_elem is None else axis.floats, where)

    limit = _single(elem, "limit", where)
    dynamics = _single(elem, "dynamics", where)
    limits = {k: _optional_numbers(limit, k, where) for k in ("lower", "upper", "effort", "velocity")}
    if kind == "continuous":
        limits["lower"] = limits["upper"] = None  # URDF: ignored for continuous joints
    mimic = _mimic(elem, where)
    return Joint(
        name,
        JOINT_TYPES[kind],
        parent,
        child,
        xyz=xyz,
        rotation=rotation,
        axis=axis,
        damping=_optional_numbers(dynamics, "damping", where),
        friction=_optional_numbers(dynamics, "friction", where),
        mimic=None if kind == "fixed" else mimic,
        **limits,
    )


def _check_planar_axis(axis, where: str) -> None:
    """ModelError unless a planar joint's ``<axis>`` (None: absent) is +z, the one plane
    normal Pinocchio's parser honours (it ignores the axis and moves in the x-y plane)."""
    if axis is not None and np.abs(axis - PLANAR_NORMAL).max() <= AXIS_TOLERANCE:
        return
    got = "no <axis> (URDF's default normal 1 0 0)" if axis is None else f"<axis> {axis.tolist()}"
    raise ModelError(
        f"a planar joint moves in its joint frame's x-y plane (as Pinocchio reads every planar joint, "
        f'ignoring <axis>): give <axis xyz="0 0 1"/> and turn the plane with <origin rpy>; got {got}',
        where,
    )


def _mimic(elem: ET.Element, where: str) -> Mimic | None:
    """The joint's ``<mimic joint multiplier offset>``, or None."""
    mimic = _single(elem, "mimic", where)
    if mimic is None:
        return None
    leader = _attr(mimic, "joint", where)
    multiplier = _optional(mimic, "multiplier", where)
    offset = _optional(mimic, "offset", where)
    return Mimic(
        leader,
        sp.Integer(1) if multiplier is None else _sym(multiplier),
        sp.Integer(0) if offset is None else _sym(offset),
    )


# ----------------------------------------------------------------- the robot


def build_robot(root: ET.Element, text: bytes, source: str, strict: bool) -> Robot:
    """The Robot of a parsed ``<robot>`` element (``text``: the file's bytes, for its leading comment)."""
    if root.find("link") is None:
        raise ModelError("the robot has no <link>", "<robot>")
    name = _name(root, "<robot>")
    links, massless = [], []
    for i, elem in enumerate(root.findall("link")):
        link, has_inertial = _link(elem, i)
        links.append(link)
        if not has_inertial:
            massless.append(link.name)
    joints = [_joint(elem, i) for i, elem in enumerate(root.findall("joint"))]
    meta = {"convention": "urdf", "massless_links": massless}
    if source != "<urdf>":
        meta["file"] = source
    citation = _leading_comment(text)
    if citation:
        meta["source"] = citation
    robot = Robot(name, links, joints, gravity=(0, 0, -9.81), meta=meta, strict=strict)
    _warn_inert_joints(robot, source)
    return robot


def _leading_comment(text: bytes) -> str | None:
    """The first XML comment before ``<robot``, on one line (bundled URDFs cite their
    source there)."""
    head = text[: text.find(b"<robot")] if b"<robot" in text else b""
    found = re.search(rb"<!--(.*?)-->", head, re.DOTALL)
    if not found:
        return None
    return " ".join(found.group(1).decode("utf-8", "replace").split()) or None


def _warn_inert_joints(robot: Robot, source: str) -> None:
    """Warn about movable joints whose whole subtree has no mass and no inertia."""
    inert: dict[str, bool] = {}
    for joint in reversed(robot.joints):  # children before parents
        link = robot.links[joint.child]
        own = float(link.floats("mass")) == 0 and not np.any(link.floats("inertia"))
        inert[joint.child] = own and all(inert[j.child] for j in robot.children(joint.child))
    # a coordinate is idle when every joint it moves (itself and its mimics) moves nothing
    moves = [False] * robot.dof
    for joint in robot.movable_joints + robot.mimic_joints:
        moves[robot.follows(joint)[0]] |= not inert[joint.child]
    idle = [j.name for j in robot.movable_joints if not moves[robot.follows(j)[0]]]
    if idle:
        warnings.warn(
            f"{source}: joints {idle} move no mass or inertia (links without <inertial>?): the mass matrix is singular",
            MasslessWarning,
            stacklevel=3,
        )
